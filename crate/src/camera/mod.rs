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

    /// The same camera with an image `width` pixels wide and the height in
    /// proportion (at least one row): the same field of view and mount at a
    /// coarser pixel pitch. The page's film strip renders its thumbnails
    /// with it — a 64-pixel-wide frame costs about a twenty-fifth of a
    /// 320-pixel one, and its coarser pitch samples the coarser mip levels,
    /// as a downscaled full frame would look.
    pub fn scaled(&self, width: u32) -> PinholeCamera {
        let k = width as f64 / self.width as f64;
        PinholeCamera {
            width,
            height: ((self.height as f64 * k).round() as u32).max(1),
            f_px: self.f_px * k,
            ..*self
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
#[derive(Clone, Debug, PartialEq)]
pub struct RobotBox {
    pub corners: Vec<DVec2>,
    pub rgb: [u8; 3],
}

/// The robots a camera on robot `skip` can see: every other robot's body at
/// its pose, in its display colour.
pub fn robot_boxes(poses: &[Pose2], skip: usize) -> Vec<RobotBox> {
    poses
        .iter()
        .enumerate()
        .filter(|(j, _)| *j != skip)
        .map(|(j, pose)| RobotBox {
            corners: crate::kinematics::P2dx::body(pose).corners,
            rgb: crate::palette::robot_colour(j),
        })
        .collect()
}

/// The texture a wall face shows. A named texture may be shared by walls
/// of any length, so its chunks are whole; an unnamed wall's texture is its
/// own, so its chunks are painted only as far as the wall reaches.
pub fn wall_texture_key(walls: &[WallSpec], i: usize, back: bool) -> TextureKey {
    match &walls[i].texture {
        Some(name) => TextureKey::new(name.clone(), back),
        None => TextureKey::new(format!("wall#{i}"), back).for_length(walls[i].segment().length()),
    }
}

/// A grey value rounded to the nearest byte (halves up), clamped to
/// 0..=255: `(v + 0.5).floor().clamp(0.0, 255.0)`, written as a cast.
/// Rust's float-to-int `as` truncates toward zero and saturates (NaN gives
/// 0); for `v + 0.5 ≥ 0` truncation is `floor`, and anything below 0 goes
/// to 0 either way. No library `round` (wasm has none) and no separate
/// clamp, per pixel.
#[inline]
fn to_byte(v: f64) -> u8 {
    (v + 0.5) as u8
}

/// Rows whose pixel centres lie between the continuous rows `top` and
/// `bottom`, clipped to the image: `first..end`.
fn row_span(top: f64, bottom: f64, h: u32) -> (u32, u32) {
    let first = (top - 0.5).ceil().max(0.0);
    let end = ((bottom - 0.5).floor() + 1.0).clamp(0.0, h as f64);
    (first.min(h as f64) as u32, end as u32)
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
    // Columns are drawn one after another, so the grey values are written
    // column-major (each column contiguous) and transposed once at the end.
    let mut by_column = vec![0u8; (w * h) as usize];
    let mut rgba = colour.then(|| vec![255u8; (w * h * 4) as usize]);
    let mut noise = noise;
    let gain = match &mut noise {
        Some(n) => 1.0 + n.rng.normal(n.exposure_std),
        None => 1.0,
    };
    let origin = pose.position();
    let (row_shade, row_rgb) = floor_and_ceiling(cam);
    let mut sampler = WallSampler {
        cam,
        walls,
        bank,
        memo: None,
        across: Vec::with_capacity(h as usize + 2),
    };
    let mut column = vec![0f64; h as usize];
    let mut column_rgb = vec![[0u8; 3]; if colour { h as usize } else { 0 }];
    for c in 0..w {
        let local = cam.column_ray(c);
        let cos_a = local.x;
        let dir = DVec2::from_angle(pose.theta).rotate(local);
        column.copy_from_slice(&row_shade);
        if colour {
            column_rgb.copy_from_slice(&row_rgb);
        }
        // The nearest wall: its span of rows, sampled from the texture.
        let hit = world.cast(origin, dir, MAX_VIEW_M);
        if let Some((hit, wi)) = hit.and_then(|hit| hit.wall.map(|wi| (hit, wi))) {
            let ray = WallRay {
                seg: world.walls()[wi],
                wi,
                origin,
                dir,
                range_m: hit.range_m,
                cos_a,
            };
            sampler.paint(&ray, &mut column, colour.then_some(&mut column_rgb[..]));
        }
        // Other robots in front of the wall hide it up to their height.
        let wall_range = hit.map_or(f64::INFINITY, |h| h.range_m);
        if let Some((t, col, shade)) = nearest_robot(robots, origin, dir, wall_range) {
            let depth = t * cos_a;
            let (r0, r1) = row_span(cam.row_of(ROBOT_HEIGHT_M, depth), cam.row_of(0.0, depth), h);
            let v = (0.299 * col[0] as f64 + 0.587 * col[1] as f64 + 0.114 * col[2] as f64) * shade;
            let rgb = col.map(|ch| (ch as f64 * shade) as u8);
            for r in r0..r1 {
                column[r as usize] = v;
                if colour {
                    column_rgb[r as usize] = rgb;
                }
            }
        }
        // Exposure and sensor noise, then out.
        let out = &mut by_column[(c * h) as usize..((c + 1) * h) as usize];
        match &mut noise {
            Some(n) if n.pixel_std > 0.0 => {
                // The generator's state in locals for the column, not
                // behind a pointer the byte stores might alias.
                let mut rng = n.rng.clone();
                let std = n.pixel_std;
                for (o, v) in out.iter_mut().zip(&column) {
                    *o = to_byte(v * gain + std * rng.approx_gaussian());
                }
                *n.rng = rng;
            }
            _ => {
                for (o, v) in out.iter_mut().zip(&column) {
                    *o = to_byte(v * gain);
                }
            }
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
    let mut gray = vec![0u8; (w * h) as usize];
    for (c, col) in by_column.chunks_exact(h as usize).enumerate() {
        for (r, &v) in col.iter().enumerate() {
            gray[r * w as usize + c] = v;
        }
    }
    CameraImage {
        width: w,
        height: h,
        gray,
        rgba,
    }
}

/// Floor and ceiling depend only on the row: their grey shade and colour
/// for every row, computed once per frame.
fn floor_and_ceiling(cam: &PinholeCamera) -> (Vec<f64>, Vec<[u8; 3]>) {
    let cy = cam.height as f64 / 2.0;
    let row_shade: Vec<f64> = (0..cam.height)
        .map(|r| {
            let yc = r as f64 + 0.5;
            if yc < cy {
                ceiling_shade(cam, yc)
            } else {
                floor_shade(cam, yc)
            }
        })
        .collect();
    let row_rgb: Vec<[u8; 3]> = row_shade
        .iter()
        .enumerate()
        .map(|(r, &v)| {
            if (r as f64 + 0.5) < cy {
                [v as u8, v as u8, (v + 8.0).min(255.0) as u8]
            } else {
                [
                    (v + 10.0).min(255.0) as u8,
                    v as u8,
                    (v - 10.0).max(0.0) as u8,
                ]
            }
        })
        .collect();
    (row_shade, row_rgb)
}

/// The nearest robot face a column's ray meets before the wall at
/// `wall_range`: its distance along the ray, colour, and shade (faces
/// turned away from the light are darker).
fn nearest_robot(
    robots: &[RobotBox],
    origin: DVec2,
    dir: DVec2,
    wall_range: f64,
) -> Option<(f64, [u8; 3], f64)> {
    let mut robot_hit: Option<(f64, [u8; 3], f64)> = None;
    for rb in robots {
        let n = rb.corners.len();
        for k in 0..n {
            let (a, b) = (rb.corners[k], rb.corners[(k + 1) % n]);
            if let Some(t) = crate::geom::Segment::new(a, b).ray_hit(origin, dir) {
                if t < wall_range && robot_hit.is_none_or(|(tb, _, _)| t < tb) {
                    let e = (b - a).normalize_or_zero();
                    robot_hit = Some((t, rb.rgb, 0.65 + 0.35 * e.x.abs()));
                }
            }
        }
    }
    robot_hit
}

/// One column's ray meeting wall `wi` (segment `seg`): from `origin` along
/// `dir`, at `range_m`; `cos_a` is the cosine of the column's angle off the
/// optical axis.
struct WallRay {
    seg: crate::geom::Segment,
    wi: usize,
    origin: DVec2,
    dir: DVec2,
    range_m: f64,
    cos_a: f64,
}

/// Wall sampling across a frame's columns: the textures, the chunk last
/// looked up, and a scratch buffer of texel rows.
struct WallSampler<'a> {
    cam: &'a PinholeCamera,
    walls: &'a [WallSpec],
    bank: &'a mut TextureBank,
    memo: Option<(usize, bool, i64, std::sync::Arc<texture::Chunk>)>,
    /// One wall column's texel rows, interpolated across x.
    across: Vec<f64>,
}

impl WallSampler<'_> {
    /// Paints the wall's span of rows into `column` (and `column_rgb` when
    /// the frame is in colour), sampled from the wall face's texture.
    fn paint(&mut self, ray: &WallRay, column: &mut [f64], column_rgb: Option<&mut [[u8; 3]]>) {
        let cam = self.cam;
        let h = cam.height;
        let cy = h as f64 / 2.0;
        let ppm = TEXELS_PER_M as f64;
        let (seg, wi, origin) = (ray.seg, ray.wi, ray.origin);
        let depth = ray.range_m * ray.cos_a;
        let p = origin + ray.dir * ray.range_m;
        let back = cross(seg.b - seg.a, origin - seg.a) < 0.0;
        // Measured so that the texture reads left to right for the
        // viewer: from `b` on the left side of a→b, from `a` on its
        // right side.
        let along = if back {
            (p - seg.a).length()
        } else {
            (p - seg.b).length()
        };
        // Texels per pixel decides the mip level.
        let footprint = ppm * depth / cam.f_px;
        let level = if footprint < 1.6 {
            0
        } else if footprint < 3.2 {
            1
        } else {
            2
        };
        let k = along.floor() as i64;
        let lx = (along - k as f64) * ppm;
        // Neighbouring columns mostly draw from the same chunk: look it
        // up (a string key and a hash) only when it changes.
        let colour = column_rgb.is_some();
        let chunk = match &self.memo {
            Some((w, b, c, chunk))
                if (*w, *b, *c) == (wi, back, k) && (!colour || !chunk.rgba.is_empty()) =>
            {
                chunk.clone()
            }
            _ => {
                let key = wall_texture_key(self.walls, wi, back);
                let chunk = self.bank.chunk_for(&key, k, colour);
                self.memo = Some((wi, back, k, chunk.clone()));
                chunk
            }
        };
        let (top, bottom) = (cam.row_of(cam.wall_height_m, depth), cam.row_of(0.0, depth));
        let (r0, r1) = row_span(top, bottom, h);
        // On the wall, texel row = (h_w - z) * ppm with z linear in the
        // row: ty(r) = ty0 + r * dty.
        let scale = (1u32 << level) as f64;
        let dty = ppm * depth / (cam.f_px * scale);
        let ty0 = ((cam.wall_height_m - cam.mount_height_m) * ppm
            + (0.5 - cy) * ppm * depth / cam.f_px)
            / scale;
        let (tw, th) = (chunk.width[level], chunk.height[level]);
        let tex = &chunk.gray[level];
        let x = (lx / scale - 0.5).clamp(0.0, (tw - 1) as f64);
        let x0 = x as usize;
        let x1 = (x0 + 1).min(tw as usize - 1);
        let fx = x - x0 as f64;
        let tw = tw as usize;
        let y_at = |r: u32| (ty0 + r as f64 * dty - 0.5).clamp(0.0, (th - 1) as f64);
        if r0 < r1 {
            // The texel rows this span reads (y only grows with r),
            // interpolated across x once each: close to a wall, many
            // pixel rows share a texel row.
            let y_lo = y_at(r0) as usize;
            let y_hi = (y_at(r1 - 1) as usize + 1).min(th as usize - 1);
            let across = &mut self.across;
            across.clear();
            across.extend((y_lo..=y_hi).map(|ty| {
                let (a, b) = (tex[ty * tw + x0] as f64, tex[ty * tw + x1] as f64);
                a + (b - a) * fx
            }));
            for r in r0..r1 {
                let y = y_at(r);
                let y0 = y as usize;
                let y1 = (y0 + 1).min(th as usize - 1);
                let fy = y - y0 as f64;
                let (top_v, bot_v) = (across[y0 - y_lo], across[y1 - y_lo]);
                column[r as usize] = top_v + (bot_v - top_v) * fy;
            }
        }
        if let Some(column_rgb) = column_rgb {
            let (tw0, th0) = (chunk.width[0], chunk.height[0]);
            let tx = (lx as u32).min(tw0 - 1);
            for r in r0..r1 {
                let ty = ((ty0 + r as f64 * dty) * scale).max(0.0) as u32;
                let i = ((ty.min(th0 - 1) * tw0 + tx) * 4) as usize;
                column_rgb[r as usize] = [chunk.rgba[i], chunk.rgba[i + 1], chunk.rgba[i + 2]];
            }
        }
    }
}
