//! # Colours and name hashes
//!
//! The few colour rules more than one part of the lab shares: each robot's
//! display colour (the top view, the camera's picture of other robots, the
//! merged map, the page's legend), a wall's hint colour in the top view,
//! the HSL conversion the wall textures draw their palettes with, and the
//! FNV-1a hash (Fowler, Noll and Vo) that turns a texture's name into a
//! stable number. It sits at the bottom of the crate, beside [`crate::geom`],
//! so the renderer and the camera both use it without importing each other.

/// Robot colours, by robot index (the page's legend uses the same list).
pub const ROBOT_COLOURS: [[u8; 3]; 8] = [
    [31, 119, 180],
    [230, 110, 20],
    [44, 160, 44],
    [200, 40, 60],
    [148, 103, 189],
    [140, 86, 75],
    [220, 100, 180],
    [23, 170, 190],
];

/// The hint colour for a wall's texture (a muted hue from the name; plain
/// walls are grey).
pub fn texture_hint(name: Option<&str>, wall_index: usize, seed: u64) -> [u8; 3] {
    let key = match name {
        Some("plain") => return [150, 150, 150],
        Some(n) => name_hash(n),
        None => name_hash(&format!("wall#{wall_index}/{seed}")),
    };
    let hue = (key % 360) as f64;
    hsl_to_rgb(hue, 0.45, 0.45)
}

/// HSL (hue in degrees, saturation and lightness in 0..1) to 8-bit RGB.
pub fn hsl_to_rgb(h: f64, s: f64, l: f64) -> [u8; 3] {
    let c = (1.0 - (2.0 * l - 1.0).abs()) * s;
    let hp = h / 60.0;
    let x = c * (1.0 - (hp % 2.0 - 1.0).abs());
    let (r, g, b) = match hp as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = l - c / 2.0;
    [
        ((r + m) * 255.0).round() as u8,
        ((g + m) * 255.0).round() as u8,
        ((b + m) * 255.0).round() as u8,
    ]
}

/// FNV-1a hash of a string.
pub fn name_hash(s: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in s.bytes() {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// Robot `i`'s display colour (the list repeats after eight robots).
pub fn robot_colour(i: usize) -> [u8; 3] {
    ROBOT_COLOURS[i % ROBOT_COLOURS.len()]
}
