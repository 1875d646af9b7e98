//! # Writing a merged map
//!
//! The maps that the merge joined are drawn into one grid in the first
//! map's frame, at the finest of their resolutions, covering all of them.
//! Each cell of the merged grid looks up, in every map, the cell under its
//! centre (nearest neighbour; maps of different resolutions mix freely):
//! a wall in any map is a wall (a wall one robot saw is there, even if the
//! other passed it by: `multirobot_map_merge` keeps the more occupied value
//! too), otherwise free in any map is free, otherwise unknown. The result
//! is written by the lab's own ROS exporter ([`crate::slam::export`]): a
//! binary PGM (free 254, occupied 0, unknown 205), the same pixels as PNG,
//! and a YAML with `origin` the lower-left corner in the first map's frame
//! (yaw 0).

use super::{MapError, RosMap, MAX_CELLS};
use crate::geom::Pose2;
use crate::slam::export::{pgm_bytes, png_bytes, yaml_text, PGM_FREE, PGM_OCCUPIED, PGM_UNKNOWN};
use crate::slam::grid::CellState;
use glam::DVec2;

/// A merged map: grey pixels (top row first) and its geometry.
#[derive(Clone, Debug, PartialEq)]
pub struct MergedMap {
    pub width: usize,
    pub height: usize,
    pub resolution: f64,
    /// Lower-left corner in the first map's frame.
    pub origin: DVec2,
    /// PGM grey values, top row first.
    pub pixels: Vec<u8>,
}

/// The merged grid may be larger than one map: up to this many cells.
pub const MAX_MERGED_CELLS: usize = 4 * MAX_CELLS;

/// Fuses `maps`, each with `pose` = its map frame in the merged frame.
pub fn merge_maps(maps: &[(&RosMap, Pose2)]) -> Result<MergedMap, MapError> {
    let name = maps.first().map_or("", |(m, _)| m.name.as_str());
    let Some(res) = maps.iter().map(|(m, _)| m.resolution).reduce(f64::min) else {
        return Err(MapError::new(name, "image", "no maps to merge".into()));
    };
    // Each map's image frame in the merged frame.
    let frames: Vec<Pose2> = maps.iter().map(|(m, p)| p.compose(&m.origin)).collect();
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for ((m, _), f) in maps.iter().zip(&frames) {
        let size = DVec2::new(m.width as f64, m.height as f64) * m.resolution;
        for c in [
            DVec2::ZERO,
            DVec2::new(size.x, 0.0),
            size,
            DVec2::new(0.0, size.y),
        ] {
            let q = f.transform_point(c);
            lo = lo.min(q);
            hi = hi.max(q);
        }
    }
    let width = ((hi.x - lo.x) / res).ceil().max(1.0) as usize;
    let height = ((hi.y - lo.y) / res).ceil().max(1.0) as usize;
    if width.saturating_mul(height) > MAX_MERGED_CELLS {
        return Err(MapError::new(
            name,
            "image",
            format!("the merged map would be {width} x {height} cells, over the limit of {MAX_MERGED_CELLS}"),
        ));
    }
    let inverse: Vec<_> = frames.iter().map(|f| f.inverse().frame()).collect();
    let mut pixels = vec![PGM_UNKNOWN; width * height];
    for row in 0..height {
        let y = lo.y + (height - 1 - row) as f64 * res + 0.5 * res;
        for col in 0..width {
            let c = DVec2::new(lo.x + (col as f64 + 0.5) * res, y);
            let mut state = CellState::Unknown;
            for ((m, _), inv) in maps.iter().zip(&inverse) {
                let Some((ix, iy)) = m.cell_at_image(inv.to_parent(c)) else {
                    continue;
                };
                match m.state(ix, iy) {
                    CellState::Occupied => {
                        state = CellState::Occupied;
                        break;
                    }
                    CellState::Free => state = CellState::Free,
                    CellState::Unknown => {}
                }
            }
            pixels[row * width + col] = match state {
                CellState::Occupied => PGM_OCCUPIED,
                CellState::Free => PGM_FREE,
                CellState::Unknown => PGM_UNKNOWN,
            };
        }
    }
    Ok(MergedMap {
        width,
        height,
        resolution: res,
        origin: lo,
        pixels,
    })
}

impl MergedMap {
    pub fn pgm(&self) -> Vec<u8> {
        pgm_bytes(self.width, self.height, &self.pixels, self.resolution)
    }
    pub fn png(&self) -> Result<Vec<u8>, String> {
        png_bytes(self.width, self.height, &self.pixels)
    }
    /// The YAML naming `image`.
    pub fn yaml(&self, image: &str) -> String {
        yaml_text(image, self.resolution, self.origin)
    }
}
