//! # Drawing a grid, and exporting it as a ROS map
//!
//! ROS's `map_server` reads a map as an image plus a YAML file
//! (<http://wiki.ros.org/map_server>): with `negate: 0`, a pixel of value
//! `v` has occupancy `p = (255 − v) / 255`; `p > occupied_thresh` (0.65)
//! is occupied, `p < free_thresh` (0.196) free, anything between unknown.
//! We write the conventional values — free 254, occupied 0, unknown 205 —
//! in a binary PGM (P5) whose row 0 is the *top* of the map (image rows go
//! down, y goes up), and `origin` is the pose of the *lower-left* pixel in
//! the map frame (here the robot's odometry frame), `[x, y, yaw]`.
//!
//! The same three shades (free light, occupied dark, unknown grey) make the
//! picture the page draws and the PNG written beside the PGM.

use super::grid::{state_of, CellState, OccupancyGrid};
use glam::DVec2;

/// ROS map_server values.
pub const PGM_FREE: u8 = 254;
pub const PGM_OCCUPIED: u8 = 0;
pub const PGM_UNKNOWN: u8 = 205;

/// Grey value of a cell (top row first), `width × height` bytes.
pub fn grey_rows_top_first(grid: &OccupancyGrid) -> Vec<u8> {
    let (w, h) = (grid.width(), grid.height());
    let units = grid.raw_units();
    let mut out = Vec::with_capacity(w * h);
    for row in (0..h).rev() {
        out.extend(
            units[row * w..(row + 1) * w]
                .iter()
                .map(|&u| match state_of(u) {
                    CellState::Free => PGM_FREE,
                    CellState::Occupied => PGM_OCCUPIED,
                    CellState::Unknown => PGM_UNKNOWN,
                }),
        );
    }
    out
}

/// The grid as a binary PGM (P5). An empty grid (nothing mapped yet) is
/// written as one unknown pixel, since an image cannot be 0 × 0.
pub fn to_pgm(grid: &OccupancyGrid) -> Vec<u8> {
    let (w, h, pixels) = grid_pixels(grid);
    pgm_bytes(w, h, &pixels, grid.resolution_m())
}

/// Size and grey pixels (top row first) of a grid; one unknown pixel for
/// an empty grid.
fn grid_pixels(grid: &OccupancyGrid) -> (usize, usize, Vec<u8>) {
    if grid.width() == 0 {
        (1, 1, vec![PGM_UNKNOWN])
    } else {
        (grid.width(), grid.height(), grey_rows_top_first(grid))
    }
}

/// A binary PGM (P5) of `w × h` grey `pixels` (top row first), with a
/// comment giving the resolution. Shared by the lab's grids and the
/// merged real maps ([`crate::formats::rosmap::write`]).
pub fn pgm_bytes(w: usize, h: usize, pixels: &[u8], resolution_m: f64) -> Vec<u8> {
    let mut out =
        format!("P5\n# slamlab occupancy grid, {resolution_m} m/cell\n{w} {h}\n255\n").into_bytes();
    out.extend_from_slice(pixels);
    out
}

/// The map_server YAML for an image called `image`.
pub fn to_yaml(grid: &OccupancyGrid, image: &str) -> String {
    yaml_text(image, grid.resolution_m(), grid.origin_m())
}

/// The map_server YAML for an image called `image` whose lower-left
/// corner lies at `origin` (yaw 0), `resolution_m` metres a pixel.
pub fn yaml_text(image: &str, resolution_m: f64, origin: DVec2) -> String {
    let quoted = serde_json::to_string(image).unwrap_or_else(|_| "\"map.pgm\"".into());
    format!(
        "image: {quoted}\nresolution: {}\norigin: [{}, {}, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
        resolution_m, origin.x, origin.y
    )
}

/// The grid as a grey PNG (same pixels as the PGM).
pub fn to_png(grid: &OccupancyGrid) -> Result<Vec<u8>, String> {
    let (w, h, pixels) = grid_pixels(grid);
    png_bytes(w, h, &pixels)
}

/// A grey PNG of `w × h` `pixels` (top row first).
pub fn png_bytes(w: usize, h: usize, pixels: &[u8]) -> Result<Vec<u8>, String> {
    use image::ImageEncoder;
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(pixels, w as u32, h as u32, image::ExtendedColorType::L8)
        .map_err(|e| format!("PNG encoding failed: {e}"))?;
    Ok(out)
}

/// A grid drawn to fit an RGBA image (y up, centred, cells as the three
/// shades of the PGM but lighter free space), with paths and dots drawn over
/// it in map coordinates. The page's map views (one robot's grid, the
/// merged grid) are all made this way.
pub struct GridPicture {
    pixmap: tiny_skia::Pixmap,
    scale: f64,
    offset: DVec2,
    origin: DVec2,
    resolution: f64,
}

impl GridPicture {
    /// `grid` fitted into `width × height` pixels; an empty grid gives an
    /// all-unknown image.
    pub fn new(grid: &OccupancyGrid, width: u32, height: u32) -> Result<Self, String> {
        let mut pixmap = tiny_skia::Pixmap::new(width, height)
            .ok_or_else(|| format!("cannot make a {width}x{height} image"))?;
        pixmap.fill(tiny_skia::Color::from_rgba8(205, 205, 205, 255));
        let (gw, gh) = (grid.width().max(1) as f64, grid.height().max(1) as f64);
        let scale = (width as f64 / gw).min(height as f64 / gh);
        let offset = DVec2::new(
            (width as f64 - scale * gw) / 2.0,
            (height as f64 - scale * gh) / 2.0,
        );
        if grid.width() > 0 {
            let data = pixmap.data_mut();
            for py in 0..height as usize {
                let gy = ((height as f64 - 0.5 - py as f64 - offset.y) / scale).floor();
                if gy < 0.0 || gy >= gh {
                    continue;
                }
                for px in 0..width as usize {
                    let gx = ((px as f64 + 0.5 - offset.x) / scale).floor();
                    if gx < 0.0 || gx >= gw {
                        continue;
                    }
                    let v = match grid.state(gx as usize, gy as usize) {
                        CellState::Free => 250,
                        CellState::Occupied => 30,
                        CellState::Unknown => 205,
                    };
                    let i = (py * width as usize + px) * 4;
                    data[i..i + 3].fill(v);
                }
            }
        }
        Ok(GridPicture {
            pixmap,
            scale,
            offset,
            origin: grid.origin_m(),
            resolution: grid.resolution_m(),
        })
    }

    /// Pixel position of map point `p` (metres, the grid's frame).
    pub fn to_px(&self, p: DVec2) -> (f32, f32) {
        let u = (p - self.origin) / self.resolution;
        (
            (self.offset.x + u.x * self.scale) as f32,
            (self.pixmap.height() as f64 - self.offset.y - u.y * self.scale) as f32,
        )
    }

    /// A polyline through `points` (at most about 2000 of them are used,
    /// evenly, always including the last).
    pub fn polyline(&mut self, points: &[DVec2], rgba: [u8; 4], width: f32) {
        let mut pb = tiny_skia::PathBuilder::new();
        let stride = (points.len() / 2000).max(1);
        for (k, p) in points.iter().step_by(stride).enumerate() {
            let (x, y) = self.to_px(*p);
            if k == 0 {
                pb.move_to(x, y);
            } else {
                pb.line_to(x, y);
            }
        }
        if let Some(last) = points.last().filter(|_| points.len() > 1) {
            let (x, y) = self.to_px(*last);
            pb.line_to(x, y);
        }
        if let Some(path) = pb.finish() {
            let stroke = tiny_skia::Stroke {
                width,
                ..tiny_skia::Stroke::default()
            };
            self.pixmap.stroke_path(
                &path,
                &paint(rgba),
                &stroke,
                tiny_skia::Transform::identity(),
                None,
            );
        }
    }

    /// A filled dot of `radius_px` at map point `p`.
    pub fn dot(&mut self, p: DVec2, radius_px: f32, rgba: [u8; 4]) {
        let (x, y) = self.to_px(p);
        if let Some(dot) = tiny_skia::PathBuilder::from_circle(x, y, radius_px) {
            self.pixmap.fill_path(
                &dot,
                &paint(rgba),
                tiny_skia::FillRule::Winding,
                tiny_skia::Transform::identity(),
                None,
            );
        }
    }

    /// The RGBA bytes. Everything drawn is blended onto an opaque
    /// background, so the premultiplied pixels are plain RGBA.
    pub fn into_rgba(self) -> Vec<u8> {
        self.pixmap.take()
    }
}

fn paint(rgba: [u8; 4]) -> tiny_skia::Paint<'static> {
    let mut p = tiny_skia::Paint::default();
    p.set_color_rgba8(rgba[0], rgba[1], rgba[2], rgba[3]);
    p.anti_alias = true;
    p
}

/// A grid's size and place, as the page and the reports show them.
#[derive(Clone, Debug, serde::Serialize)]
pub struct MapInfo {
    pub width: usize,
    pub height: usize,
    pub resolution_m: f64,
    /// Lower-left corner of cell (0, 0) in the map's frame (the robot's
    /// odometry frame).
    pub origin_m: [f64; 2],
    pub occupied_cells: usize,
    pub scans: u64,
    pub dropped_updates: u64,
}

impl MapInfo {
    /// The figures of `grid`.
    pub fn of(grid: &OccupancyGrid) -> MapInfo {
        let o = grid.origin_m();
        MapInfo {
            width: grid.width(),
            height: grid.height(),
            resolution_m: grid.resolution_m(),
            origin_m: [o.x, o.y],
            occupied_cells: grid.occupied_count(),
            scans: grid.scans(),
            dropped_updates: grid.dropped_updates(),
        }
    }
}
