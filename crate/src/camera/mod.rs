//! # The robot's camera: a pinhole looking at textured walls
//!
//! The thesis merges maps by comparing what the robots *see* (chapter 5), so
//! each robot carries a forward camera. It is a pinhole camera (thesis §5.4,
//! Figure 9): a point at depth `Z` in front of the camera, `X` to its right
//! and `Y` above it, lands on the image at
//!
//! ```text
//! u = c_x + f·X/Z        v = c_y − f·Y/Z        f = (W/2) / tan(hfov/2)
//! ```
//!
//! with `(c_x, c_y) = (W/2, H/2)` in pixel units where pixel `i` covers
//! `[i, i+1)` (so its centre is `i + ½`). Square pixels: the vertical field
//! of view follows from `H` and `f`.
//!
//! The world is 2½-D — vertical walls of one height standing on a flat floor
//! — so the image can be rendered by **casting one ray per column**, as in
//! classic ray-casting engines: the column's ray meets the nearest wall at
//! distance `t`; its depth along the optical axis is `Z = t·cos α` (α the
//! column's angle off-axis); the wall spans rows from `c_y − f·(h_w − h_c)/Z`
//! (top, `h_w` the wall height, `h_c` the camera height) to `c_y + f·h_c/Z`
//! (bottom). Down that span the texture column is fixed (the point along the
//! wall where the ray hit) and the height on the wall is exactly linear in
//! the row, `z = h_c − (v − c_y)·Z/f`: perspective-correct by construction.
//! Above the wall is ceiling, below it floor, both shaded by distance. Other
//! robots are boxes [`ROBOT_HEIGHT_M`] tall that hide what is behind them.
//!
//! Distant walls are sampled from coarser mip levels of the texture (one
//! texel per pixel or fewer), so they blur as a real lens would instead of
//! aliasing into speckle that a feature detector would mistake for corners.
//! Sensor noise (Gaussian per pixel) and a small per-frame exposure change
//! come from the robot's camera noise stream: deterministic from the seed.
//!
//! The images move as thesis §5.5 says they must: sideways motion shifts
//! them (§5.5.1), moving toward a wall scales them by `Z₁/Z₂` (§5.5.2), and
//! turning the camera shifts and keystones them (§5.5.3) — the tests check
//! each against the formulas.

pub mod capture;
pub mod texture;

use crate::geom::{cross, Pose2};
use crate::rng::Rng;
use crate::scenario::{CameraSpec, WallSpec};
use crate::world::World;
use glam::DVec2;
use texture::{TextureBank, TextureKey, TEXELS_PER_M};

/// Height of a robot's body as the camera sees it (m).
pub const ROBOT_HEIGHT_M: f64 = 0.35;
/// The camera sees no farther than this (m).
pub const MAX_VIEW_M: f64 = 60.0;

/// Intrinsics and mounting of the camera.
#[derive(Clone, Debug, PartialEq)]
pub struct PinholeCamera {
    pub width: u32,
    pub height: u32,
    /// Focal length in pixels.
    pub f_px: f64,
    pub hfov_rad: f64,
    pub mount_height_m: f64,
    pub wall_height_m: f64,
}

impl PinholeCamera {
    pub fn new(spec: &CameraSpec) -> Self {
        let hfov = spec.hfov_deg.to_radians();
        PinholeCamera {
            width: spec.width,
            height: spec.height,
            f_px: (spec.width as f64 / 2.0) / (hfov / 2.0).tan(),
            hfov_rad: hfov,
            mount_height_m: spec.mount_height_m,
            wall_height_m: spec.wall_height_m,
        }
    }

    /// Horizontal offset of column `c`'s centre from the principal point
    /// (pixels, positive to the right).
    pub fn column_offset(&self, c: u32) -> f64 {
        c as f64 + 0.5 - self.width as f64 / 2.0
    }

    /// Unit direction of column `c`'s ray in the robot frame (x forward,
    /// y left).
    pub fn column_ray(&self, c: u32) -> DVec2 {
        DVec2::new(self.f_px, -self.column_offset(c)).normalize()
    }

    /// Image row (continuous, pixel edges at integers) of a point `z` metres
    /// above the floor at depth `depth_m`.
    pub fn row_of(&self, z_m: f64, depth_m: f64) -> f64 {
        self.height as f64 / 2.0 - self.f_px * (z_m - self.mount_height_m) / depth_m
    }

    /// Image column (continuous) of a point in the robot frame.
    pub fn column_of(&self, p_robot: DVec2) -> f64 {
        self.width as f64 / 2.0 - self.f_px * p_robot.y / p_robot.x
    }
}

/// A rendered frame: 8-bit grayscale (the vision input), and optionally
/// straight RGBA for display.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraImage {
    pub width: u32,
    pub height: u32,
    pub gray: Vec<u8>,
    pub rgba: Option<Vec<u8>>,
}

/// Per-frame sensor noise.
pub struct CameraNoise<'a> {
    pub rng: &'a mut Rng,
    /// Standard deviation of the per-pixel Gaussian noise (grey levels).
    pub pixel_std: f64,
    /// Standard deviation of the per-frame exposure gain around 1.
    pub exposure_std: f64,
}

/// Another robot as the camera sees it: its body polygon and colour.
pub struct RobotBox {
    pub corners: Vec<DVec2>,
    pub rgb: [u8; 3],
}

/// The texture a wall face shows.
pub fn wall_texture_key(walls: &[WallSpec], i: usize, back: bool) -> TextureKey {
    TextureKey {
        name: walls[i]
            .texture
            .clone()
            .unwrap_or_else(|| format!("wall#{i}")),
        back,
    }
}

fn bilinear(tex: &[u8], w: u32, h: u32, x: f64, y: f64) -> f64 {
    let x = (x - 0.5).clamp(0.0, (w - 1) as f64);
    let y = (y - 0.5).clamp(0.0, (h - 1) as f64);
    let (x0, y0) = (x as u32, y as u32);
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (fx, fy) = (x - x0 as f64, y - y0 as f64);
    let at = |xx: u32, yy: u32| tex[(yy * w + xx) as usize] as f64;
    let top = at(x0, y0) * (1.0 - fx) + at(x1, y0) * fx;
    let bot = at(x0, y1) * (1.0 - fx) + at(x1, y1) * fx;
    top * (1.0 - fy) + bot * fy
}

/// Shade of the floor at a row below the horizon, darker with distance.
fn floor_shade(cam: &PinholeCamera, yc: f64) -> f64 {
    let below = (yc - cam.height as f64 / 2.0).max(1e-3);
    let dist = cam.mount_height_m * cam.f_px / below;
    70.0 + 60.0 * (-dist / 6.0).exp()
}

/// Shade of the ceiling at a row above the horizon.
fn ceiling_shade(cam: &PinholeCamera, yc: f64) -> f64 {
    let above = (cam.height as f64 / 2.0 - yc).max(1e-3);
    let dist = (cam.wall_height_m - cam.mount_height_m) * cam.f_px / above;
    175.0 + 50.0 * (-dist / 6.0).exp()
}

/// Renders what a camera at `pose` (the robot's true pose) sees.
#[allow(clippy::too_many_arguments)]
pub fn render(
    cam: &PinholeCamera,
    pose: &Pose2,
    world: &World,
    walls: &[WallSpec],
    robots: &[RobotBox],
    bank: &mut TextureBank,
    colour: bool,
    noise: Option<CameraNoise>,
) -> CameraImage {
    let (w, h) = (cam.width, cam.height);
    let mut gray = vec![0u8; (w * h) as usize];
    let mut rgba = colour.then(|| vec![255u8; (w * h * 4) as usize]);
    let mut noise = noise;
    let gain = match &mut noise {
        Some(n) => 1.0 + n.rng.normal(n.exposure_std),
        None => 1.0,
    };
    let origin = pose.position();
    let cy = h as f64 / 2.0;
    let ppm = TEXELS_PER_M as f64;
    let mut column = vec![0f64; h as usize];
    let mut column_rgb = vec![[0u8; 3]; if colour { h as usize } else { 0 }];
    for c in 0..w {
        let local = cam.column_ray(c);
        let cos_a = local.x;
        let dir = DVec2::from_angle(pose.theta).rotate(local);
        // The nearest wall, and the nearest robot if it is nearer still.
        let hit = world.cast(origin, dir, MAX_VIEW_M);
        let mut robot_hit: Option<(f64, [u8; 3], f64)> = None;
        for rb in robots {
            let n = rb.corners.len();
            for k in 0..n {
                let (a, b) = (rb.corners[k], rb.corners[(k + 1) % n]);
                let seg = crate::geom::Segment::new(a, b);
                if let Some(t) = seg.ray_hit(origin, dir) {
                    if robot_hit.is_none_or(|(tb, _, _)| t < tb) {
                        // Faces turned away from the light are darker.
                        let e = (b - a).normalize_or_zero();
                        let shade = 0.65 + 0.35 * e.x.abs();
                        robot_hit = Some((t, rb.rgb, shade));
                    }
                }
            }
        }
        // Wall span and texture column.
        let mut wall_span = (f64::INFINITY, f64::NEG_INFINITY);
        let mut tex: Option<(TextureKey, i64, f64, f64, usize)> = None; // key, chunk, local x, depth, level
        if let Some(hit) = hit {
            if let Some(wi) = hit.wall {
                let depth = hit.range_m * cos_a;
                let seg = world.walls()[wi];
                let p = origin + dir * hit.range_m;
                let back = cross(seg.b - seg.a, origin - seg.a) < 0.0;
                // Measured so that the texture reads left to right for the
                // viewer: from `b` on the left side of a→b, from `a` on its
                // right side.
                let along = if back {
                    (p - seg.a).length()
                } else {
                    (p - seg.b).length()
                };
                let footprint = ppm * depth / cam.f_px; // texels per pixel
                let level = if footprint < 1.6 {
                    0
                } else if footprint < 3.2 {
                    1
                } else {
                    2
                };
                let k = along.floor() as i64;
                tex = Some((
                    wall_texture_key(walls, wi, back),
                    k,
                    (along - k as f64) * ppm,
                    depth,
                    level,
                ));
                wall_span = (cam.row_of(cam.wall_height_m, depth), cam.row_of(0.0, depth));
            }
        }
        let robot_span = robot_hit
            .filter(|(t, _, _)| hit.is_none_or(|hw| *t < hw.range_m))
            .map(|(t, rgb, shade)| {
                let depth = t * cos_a;
                (
                    cam.row_of(ROBOT_HEIGHT_M, depth),
                    cam.row_of(0.0, depth),
                    rgb,
                    shade,
                )
            });
        let wall = tex
            .as_ref()
            .map(|(key, k, lx, depth, level)| (bank.chunk(key, *k), *lx, *depth, *level));
        for r in 0..h {
            let yc = r as f64 + 0.5;
            let mut value;
            let mut rgb = [0u8; 3];
            if let Some((_, _, col, shade)) = robot_span.filter(|s| yc >= s.0 && yc <= s.1) {
                value =
                    (0.299 * col[0] as f64 + 0.587 * col[1] as f64 + 0.114 * col[2] as f64) * shade;
                rgb = [
                    (col[0] as f64 * shade) as u8,
                    (col[1] as f64 * shade) as u8,
                    (col[2] as f64 * shade) as u8,
                ];
            } else if let Some((chunk, lx, depth, level)) =
                wall.filter(|_| yc >= wall_span.0 && yc <= wall_span.1)
            {
                let z = cam.mount_height_m - (yc - cy) * depth / cam.f_px;
                let ty = (cam.wall_height_m - z) * ppm;
                let scale = (1u32 << level) as f64;
                value = bilinear(
                    &chunk.gray[level],
                    chunk.width[level],
                    chunk.height[level],
                    lx / scale,
                    ty / scale,
                );
                if colour {
                    let (tw, th) = (chunk.width[0], chunk.height[0]);
                    let tx = (lx as u32).min(tw - 1);
                    let tyy = (ty.max(0.0) as u32).min(th - 1);
                    let i = ((tyy * tw + tx) * 4) as usize;
                    rgb = [chunk.rgba[i], chunk.rgba[i + 1], chunk.rgba[i + 2]];
                }
            } else if yc < cy {
                value = ceiling_shade(cam, yc);
                let v = value as u8;
                rgb = [v, v, (value + 8.0).min(255.0) as u8];
            } else {
                value = floor_shade(cam, yc);
                let v = value as u8;
                rgb = [
                    (value + 10.0).min(255.0) as u8,
                    v,
                    (value - 10.0).max(0.0) as u8,
                ];
            }
            value *= gain;
            if let Some(n) = &mut noise {
                if n.pixel_std > 0.0 {
                    value += n.pixel_std * n.rng.approx_gaussian();
                }
            }
            column[r as usize] = value;
            if colour {
                column_rgb[r as usize] = rgb;
            }
        }
        for r in 0..h as usize {
            gray[r * w as usize + c as usize] = column[r].round().clamp(0.0, 255.0) as u8;
        }
        if let Some(out) = rgba.as_mut() {
            for (r, px) in column_rgb.iter().enumerate() {
                let i = (r * w as usize + c as usize) * 4;
                for ch in 0..3 {
                    out[i + ch] = (px[ch] as f64 * gain).clamp(0.0, 255.0) as u8;
                }
            }
        }
    }
    CameraImage {
        width: w,
        height: h,
        gray,
        rgba,
    }
}
