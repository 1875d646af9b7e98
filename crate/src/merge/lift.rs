//! # Lifting a keypoint to a point on the map
//!
//! A matched keypoint says "this bit of texture is in the same place in both
//! images", but a rigid transform between two maps needs *points in the
//! plane*. A single camera gives a keypoint's direction, not its distance;
//! the laser, mounted at the same spot (the robot's centre) and sweeping the
//! same horizontal plane, gives the distance along every direction. So
//! each keypoint is lifted in three steps:
//!
//! 1. **bearing from the column** (the pinhole model, thesis §5.4, eq. of
//!    Figure 9): a point `X` to the camera's right at depth `Z` lands at
//!    column `u = c_x + f·X/Z`, so the column gives `X/Z` and the bearing
//!    in the robot frame (x forward, y left, angles counter-clockwise) is
//!    `β = −atan((u − c_x)/f)`: right of centre is a negative bearing.
//!    SURF reports keypoints with pixel centres at integers (OpenCV's
//!    convention) while the camera model puts pixel `i` over `[i, i+1)`,
//!    so `u = x_kp + ½`.
//! 2. **range at that bearing** from the laser scan taken at the same
//!    instant: beam `k` looks along `(k − 90)°`, so the bearing falls
//!    between two beams and the range is interpolated linearly between
//!    them. Nothing is returned where the scan cannot be trusted: outside
//!    its 180°, where either beam saw nothing within range, and at a depth
//!    discontinuity (a wall's end in front of a farther wall), where
//!    interpolation would invent a point in mid-air and a keypoint is likely
//!    to straddle the two surfaces anyway.
//! 3. **into the map**: the point `r·(cos β, sin β)` in the robot frame is
//!    carried into the robot's map frame by the SLAM pose at capture.
//!
//! Walls are vertical and span the whole image height, so the wall the
//! laser meets along a bearing is the wall the camera sees in that column.
//! The keypoint's row adds a third coordinate for free: the height of the
//! textured point on the wall, `z = h_c − (v − c_y)·Z/f` with `Z = r·cos β`
//! the depth along the optical axis. Two views of one point must agree on
//! it, which [`super::verify`] uses to discard matches between different
//! heights of a repeated texture.

use super::FrameInfo;
use crate::camera::PinholeCamera;
use crate::sensors::laser::{beam_bearing, LASER_BEAMS};
use crate::sim::LASER_LOG_NO_RETURN;
use glam::{DVec2, DVec3};

/// Neighbouring beams further apart than `JUMP_ABS_M + JUMP_REL · r` mark a
/// depth discontinuity. A wall seen at 75° incidence 4 m away changes by
/// about 0.26 m per degree, so the relative term leaves grazing walls
/// alone, while a corridor wall's end in front of a far wall (a jump of
/// metres) is caught.
const JUMP_ABS_M: f64 = 0.15;
const JUMP_REL: f64 = 0.08;

/// Bearing (rad, robot frame: 0 ahead, positive to the left) of the ray
/// through column `x_px` in SURF's convention (pixel centres at integers).
pub fn column_bearing_rad(camera: &PinholeCamera, x_px: f64) -> f64 {
    let u = x_px + 0.5;
    let offset = u - camera.width as f64 / 2.0;
    (-offset).atan2(camera.f_px)
}

/// Range in metres of beam `k`, `None` for no return.
fn beam_range_m(laser_mm: &[u16; LASER_BEAMS], k: usize) -> Option<f64> {
    let mm = *laser_mm.get(k)?;
    (mm != LASER_LOG_NO_RETURN).then_some(mm as f64 / 1000.0)
}

fn is_jump(r0: f64, r1: f64) -> bool {
    (r1 - r0).abs() > JUMP_ABS_M + JUMP_REL * r0.min(r1)
}

/// The laser range (m) along `bearing_rad` (robot frame), interpolated
/// between the two beams on either side. `None` outside the scan's 180°,
/// when either beam had no return, or when the ranges around the bearing
/// jump (the two beams, and each of them with its outer neighbour).
pub fn laser_range_at(laser_mm: &[u16; LASER_BEAMS], bearing_rad: f64) -> Option<f64> {
    if !bearing_rad.is_finite() {
        return None;
    }
    let step = beam_bearing(1) - beam_bearing(0);
    let s = (bearing_rad - beam_bearing(0)) / step;
    let last = (LASER_BEAMS - 1) as f64;
    if !(0.0..=last).contains(&s) {
        return None;
    }
    let k0 = (s.floor() as usize).min(LASER_BEAMS - 2);
    let frac = s - k0 as f64;
    let r0 = beam_range_m(laser_mm, k0)?;
    let r1 = beam_range_m(laser_mm, k0 + 1)?;
    if is_jump(r0, r1) {
        return None;
    }
    // The outer neighbours, where they exist, must continue the surface:
    // a keypoint one beam away from a wall's end straddles the edge.
    if k0 > 0 {
        if let Some(rm) = beam_range_m(laser_mm, k0 - 1) {
            if is_jump(rm, r0) {
                return None;
            }
        }
    }
    if let Some(rp) = beam_range_m(laser_mm, k0 + 2) {
        if is_jump(r1, rp) {
            return None;
        }
    }
    let r = r0 + (r1 - r0) * frac;
    (r > 0.0).then_some(r)
}

/// The point on the wall that keypoint (`x_px`, `y_px`) shows (SURF's
/// pixel convention): `x`, `y` in the robot's map frame (via the SLAM pose
/// `frame.pose`) and `z` its height on the wall (m above the floor). `None`
/// where the laser gives no trustworthy range (see [`laser_range_at`]).
pub fn lift_keypoint_3d(
    camera: &PinholeCamera,
    frame: &FrameInfo,
    x_px: f64,
    y_px: f64,
) -> Option<DVec3> {
    let bearing = column_bearing_rad(camera, x_px);
    let r = laser_range_at(&frame.laser_mm, bearing)?;
    let depth = r * bearing.cos();
    let v = y_px + 0.5;
    let z = camera.mount_height_m - (v - camera.height as f64 / 2.0) * depth / camera.f_px;
    let p = frame
        .pose
        .transform_point(DVec2::new(bearing.cos(), bearing.sin()) * r);
    Some(DVec3::new(p.x, p.y, z))
}
