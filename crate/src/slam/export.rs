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
    let (w, h, pixels) = if grid.width() == 0 {
        (1, 1, vec![PGM_UNKNOWN])
    } else {
        (grid.width(), grid.height(), grey_rows_top_first(grid))
    };
    let mut out = format!(
        "P5\n# slamlab occupancy grid, {} m/cell\n{w} {h}\n255\n",
        grid.resolution_m()
    )
    .into_bytes();
    out.extend(pixels);
    out
}

/// The map_server YAML for an image called `image`.
pub fn to_yaml(grid: &OccupancyGrid, image: &str) -> String {
    let o = grid.origin_m();
    let quoted = serde_json::to_string(image).unwrap_or_else(|_| "\"map.pgm\"".into());
    format!(
        "image: {quoted}\nresolution: {}\norigin: [{}, {}, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
        grid.resolution_m(),
        o.x,
        o.y
    )
}

/// The grid as a grey PNG (same pixels as the PGM).
pub fn to_png(grid: &OccupancyGrid) -> Result<Vec<u8>, String> {
    use image::ImageEncoder;
    let (w, h, pixels) = if grid.width() == 0 {
        (1, 1, vec![PGM_UNKNOWN])
    } else {
        (grid.width(), grid.height(), grey_rows_top_first(grid))
    };
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(&pixels, w as u32, h as u32, image::ExtendedColorType::L8)
        .map_err(|e| format!("PNG encoding failed: {e}"))?;
    Ok(out)
}
