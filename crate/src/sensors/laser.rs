//! # The laser range finder
//!
//! A SICK-like scanner at the robot's centre sweeps 180° in front of it:
//! 181 beams from −90° (right) to +90° (left) at 1° steps, each reporting the
//! distance to the nearest surface up to 4 m (thesis §6.1.1.1). Each range
//! gets Gaussian noise. A beam that meets nothing reads the maximum range and
//! is *flagged*: a mapper must treat it as "free for 4 m", not as a wall.
//!
//! Like a SICK scanner, the laser also reports a coarse return *intensity*.
//! Each robot carries retro-reflective tape around its body (a common
//! multi-robot practice), so returns off another robot come back bright and
//! are flagged [`LaserScan::reflective`]. Walls never are. The wall follower
//! uses this to avoid following another robot as if it were a wall.

use super::RangeScene;
use crate::geom::Pose2;
use crate::rng::Rng;
use glam::DVec2;

/// Number of beams per scan.
pub const LASER_BEAMS: usize = 181;
/// Field of view (rad).
pub const LASER_FOV_RAD: f64 = std::f64::consts::PI;

/// Bearing of beam `i` in the robot frame (rad): beam 0 looks right (−90°),
/// beam 90 straight ahead, beam 180 left (+90°).
pub fn beam_bearing(i: usize) -> f64 {
    -0.5 * LASER_FOV_RAD + LASER_FOV_RAD * i as f64 / (LASER_BEAMS - 1) as f64
}

/// Unit vector of beam `i` in the robot frame, `(cos, sin)` of its bearing,
/// worked out once for all scans.
pub fn beam_unit(i: usize) -> DVec2 {
    static UNITS: std::sync::OnceLock<[DVec2; LASER_BEAMS]> = std::sync::OnceLock::new();
    let unit = |k: usize| {
        let a = beam_bearing(k);
        DVec2::new(a.cos(), a.sin())
    };
    let units = UNITS.get_or_init(|| std::array::from_fn(unit));
    units.get(i).copied().unwrap_or_else(|| unit(i))
}

/// One scan.
#[derive(Clone, Debug, PartialEq)]
pub struct LaserScan {
    pub ranges_m: Vec<f64>,
    /// True where the beam met nothing within range.
    pub max_range: Vec<bool>,
    /// True where the return was bright (off another robot's reflective tape).
    pub reflective: Vec<bool>,
    pub range_max_m: f64,
}

impl LaserScan {
    /// The end point of beam `i` in the robot frame.
    pub fn point(&self, i: usize) -> DVec2 {
        beam_unit(i) * self.ranges_m[i]
    }
}

/// The laser model of one robot.
#[derive(Clone, Debug)]
pub struct Laser {
    pub range_m: f64,
    pub noise_std_m: f64,
    rng: Rng,
}

impl Laser {
    pub fn new(range_m: f64, noise_std_m: f64, rng: Rng) -> Self {
        Laser {
            range_m,
            noise_std_m,
            rng,
        }
    }

    /// Scans at the true pose `pose`.
    pub fn scan(&mut self, scene: &RangeScene, pose: &Pose2) -> LaserScan {
        let mut ranges_m = Vec::with_capacity(LASER_BEAMS);
        let mut max_range = Vec::with_capacity(LASER_BEAMS);
        let mut reflective = Vec::with_capacity(LASER_BEAMS);
        let origin = pose.position();
        // 181 rays from one point: only walls within range can answer.
        let near = scene.world.walls_within(origin, self.range_m);
        for i in 0..LASER_BEAMS {
            let a = pose.theta + beam_bearing(i);
            let dir = DVec2::new(a.cos(), a.sin());
            match scene.cast_near(near.as_deref(), origin, dir, self.range_m) {
                Some(h) => {
                    let r = h.range_m + self.rng.normal(self.noise_std_m);
                    ranges_m.push(r.clamp(0.0, self.range_m));
                    max_range.push(false);
                    reflective.push(h.wall.is_none());
                }
                None => {
                    ranges_m.push(self.range_m);
                    max_range.push(true);
                    reflective.push(false);
                }
            }
        }
        LaserScan {
            ranges_m,
            max_range,
            reflective,
            range_max_m: self.range_m,
        }
    }
}
