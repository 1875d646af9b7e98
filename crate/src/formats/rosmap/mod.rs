//! # ROS `map_server` maps: reading them, classifying cells, writing them
//!
//! People who merge maps for a living have them on disk as ROS
//! `map_server` maps (<http://wiki.ros.org/map_server>): an image (PGM or
//! PNG) and a YAML file that says how big a pixel is, where the image lies
//! ([`yaml`]), and how grey values become occupancy. This module reads them
//! exactly as `map_server` does, so a map means here what it means in ROS:
//!
//! * the image ([`pgm`], written here; [`png`], decoded by the `image`
//!   crate) becomes one grey value `v` in 0..255 per pixel (the mean of
//!   the colour channels; see [`png`] for alpha);
//! * with `negate: 1`, `v ← 255 − v`;
//! * `trinary` mode: `p = (255 − v) / 255`; `p > occupied_thresh` is
//!   occupied (100), `p < free_thresh` free (0), anything else unknown (−1);
//! * `scale` mode: the same, except that between the thresholds (and not
//!   fully transparent) the cell gets `1 + 98 (p − free) / (occ − free)`;
//! * `raw` mode: the value *is* the cell (`v` as an occupancy 0..100;
//!   anything above 100, such as 255, is unknown).
//!
//! The result is a [`RosMap`]: `nav_msgs/OccupancyGrid` values (−1, 0..100)
//! row by row from the **bottom** (image rows go down, y goes up), and the
//! map's geometry. Cell `(i, j)` has its centre at
//! `origin ⊕ ((i + ½) r, (j + ½) r)`: `origin` is the pose of the lower-left
//! corner of the image in the map frame, yaw included (many ROS tools
//! ignore the yaw; we honour it).
//!
//! For merging, a cell is a wall when its value is 100 (above
//! `occupied_thresh`), free when 0, and unknown otherwise: `scale` mode's
//! graded cells are neither ([`RosMap::state`]).
//!
//! **Limits.** A map may hold at most [`MAX_CELLS`] cells (4096 × 4096, a
//! 205 m square at 5 cm); a larger image is refused as bad input before it
//! is decoded, so memory stays bounded (one byte a cell for the map, a few
//! more while decoding).
//!
//! Errors are [`MapError`]s: the file, the field (`image`, `resolution`,
//! ...) and what is wrong, so a command line can print
//! `maps/a.yaml: resolution: -1 is not a positive finite number`.
//!
//! [`write`] goes the other way: a merged map as PGM, PNG and YAML, with
//! the lab's own exporter ([`crate::slam::export`]).

pub mod pgm;
pub mod png;
pub mod write;
pub mod yaml;

use crate::geom::Pose2;
use crate::slam::grid::CellState;
use glam::DVec2;
pub use yaml::{MapYaml, Mode};

/// The most cells a map may hold: 4096 × 4096.
pub const MAX_CELLS: usize = 4096 * 4096;

/// Bad input: which file, which field, what is wrong.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MapError {
    pub file: String,
    pub field: String,
    pub message: String,
}

impl MapError {
    pub fn new(file: &str, field: &str, message: String) -> MapError {
        MapError {
            file: file.to_string(),
            field: field.to_string(),
            message,
        }
    }
}

impl std::fmt::Display for MapError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}: {}", self.file, self.field, self.message)
    }
}

impl std::error::Error for MapError {}

/// A map as `map_server` publishes it.
#[derive(Clone, Debug, PartialEq)]
pub struct RosMap {
    /// The YAML's name as given (for messages and reports).
    pub name: String,
    pub width: usize,
    pub height: usize,
    /// Metres per cell.
    pub resolution: f64,
    /// Pose of the lower-left corner of cell (0, 0) in the map frame.
    pub origin: Pose2,
    /// `nav_msgs/OccupancyGrid` values, row 0 at the bottom: −1 unknown,
    /// 0 free, 100 occupied, 1..99 graded (`scale` mode).
    pub data: Vec<i8>,
}

impl RosMap {
    /// The state used for merging: 100 is a wall, 0 free, the rest unknown.
    pub fn state(&self, ix: usize, iy: usize) -> CellState {
        state_of_value(self.data[iy * self.width + ix])
    }

    /// Centre of cell `(ix, iy)` in the image frame (the frame whose origin
    /// is the lower-left corner of the image, axes along its edges).
    pub fn cell_centre_image(&self, ix: usize, iy: usize) -> DVec2 {
        DVec2::new(ix as f64 + 0.5, iy as f64 + 0.5) * self.resolution
    }

    /// The cell holding image-frame point `p`, if inside the map.
    pub fn cell_at_image(&self, p: DVec2) -> Option<(usize, usize)> {
        let (x, y) = (
            (p.x / self.resolution).floor(),
            (p.y / self.resolution).floor(),
        );
        (x >= 0.0 && y >= 0.0 && x < self.width as f64 && y < self.height as f64)
            .then_some((x as usize, y as usize))
    }

    /// Builds a map from values (row 0 at the bottom), for tests and
    /// synthetic maps.
    pub fn from_values(
        name: &str,
        width: usize,
        height: usize,
        resolution: f64,
        origin: Pose2,
        data: Vec<i8>,
    ) -> Result<RosMap, MapError> {
        if data.len() != width * height || width == 0 || height == 0 {
            return Err(MapError::new(
                name,
                "image",
                format!("{} values for {width} x {height} cells", data.len()),
            ));
        }
        if !resolution.is_finite() || resolution <= 0.0 {
            return Err(MapError::new(
                name,
                "resolution",
                format!("{resolution} is not a positive finite number"),
            ));
        }
        Ok(RosMap {
            name: name.to_string(),
            width,
            height,
            resolution,
            origin,
            data,
        })
    }
}

/// Merge state of an occupancy value.
pub fn state_of_value(v: i8) -> CellState {
    match v {
        100 => CellState::Occupied,
        0 => CellState::Free,
        _ => CellState::Unknown,
    }
}

/// `map_server`'s value for a pixel of grey mean `v` (0..255) that is
/// fully transparent or not (see the module doc).
pub fn occupancy_value(y: &MapYaml, v: f32, transparent: bool) -> i8 {
    let v = if y.negate { 255.0 - v as f64 } else { v as f64 };
    if y.mode == Mode::Raw {
        let r = v.round();
        return if r <= 100.0 { r as i8 } else { -1 };
    }
    let p = (255.0 - v) / 255.0;
    if p > y.occupied_thresh {
        100
    } else if p < y.free_thresh {
        0
    } else if y.mode == Mode::Trinary || transparent {
        -1
    } else {
        let ratio = (p - y.free_thresh) / (y.occupied_thresh - y.free_thresh);
        (1.0 + 98.0 * ratio) as i8
    }
}

/// Refuses an image over the size limit (before decoding it).
fn check_size(file: &str, width: usize, height: usize) -> Result<(), MapError> {
    let cells = width.saturating_mul(height);
    if cells > MAX_CELLS || width == 0 || height == 0 {
        return Err(MapError::new(
            file,
            "image",
            format!(
                "{width} x {height} pixels is {} (the limit is {MAX_CELLS} cells, 4096 x 4096)",
                if cells == 0 {
                    "empty".to_string()
                } else {
                    format!("{cells} cells")
                }
            ),
        ));
    }
    Ok(())
}

/// Reads a map: `yaml_name` (for messages and the report), the YAML's
/// text, and the bytes of the image it names (the caller resolves and
/// reads the file, so this works the same in a browser). `image_name` is
/// the image's path for messages.
pub fn load(
    yaml_name: &str,
    yaml_text: &str,
    image_name: &str,
    image: &[u8],
) -> Result<RosMap, MapError> {
    let y = MapYaml::parse(yaml_name, yaml_text)?;
    let bad = |m: String| MapError::new(yaml_name, "image", format!("{image_name}: {m}"));
    let (grey, transparent) = if pgm::is_pgm(image) {
        let h = pgm::read_header(image).map_err(bad)?;
        check_size(yaml_name, h.width, h.height)?;
        (pgm::read_raster(image, &h).map_err(bad)?, None)
    } else if png::is_png(image) {
        let (w, h) = png::dimensions(image).map_err(bad)?;
        check_size(yaml_name, w, h)?;
        png::decode(image, y.mode == Mode::Trinary).map_err(bad)?
    } else {
        return Err(bad("not a PGM (P5 or P2) or PNG image".into()));
    };
    let (w, h) = (grey.width, grey.height);
    let mut data = vec![-1i8; w * h];
    // Image rows go down; map rows go up.
    for row in 0..h {
        let out = &mut data[(h - 1 - row) * w..][..w];
        for (col, cell) in out.iter_mut().enumerate() {
            let k = row * w + col;
            let t = transparent.as_ref().is_some_and(|t| t[k]);
            *cell = occupancy_value(&y, grey.samples[k], t);
        }
    }
    Ok(RosMap {
        name: yaml_name.to_string(),
        width: w,
        height: h,
        resolution: y.resolution,
        origin: Pose2::new(y.origin[0], y.origin[1], y.origin[2]),
        data,
    })
}
