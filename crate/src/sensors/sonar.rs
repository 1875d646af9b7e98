//! # The P2DX sonar ring
//!
//! Eight ultrasonic sonars look out from the front of the robot at +90, +50,
//! +30, +10, −10, −30, −50 and −90 degrees, numbered 1 to 8 from left to
//! right as in the thesis (so sonar 1 looks left, sonar 8 right, and sonars 4
//! and 5 look 10° either side of straight ahead). Their positions on the ring
//! follow the Pioneer's published geometry.
//!
//! A sonar does not see along a line: its sound spreads in a cone (15° by
//! default) and the first echo comes from the nearest surface in it. We cast
//! five rays across the cone and keep the shortest, then add Gaussian noise.
//! No echo within range reads as the maximum range and is flagged.

use super::RangeScene;
use crate::geom::Pose2;
use crate::rng::Rng;
use glam::DVec2;

/// Number of sonars on the ring.
pub const SONAR_COUNT: usize = 8;

/// Bearing of each sonar in the robot frame (degrees), sonar 1 first.
pub const SONAR_BEARINGS_DEG: [f64; SONAR_COUNT] =
    [90.0, 50.0, 30.0, 10.0, -10.0, -30.0, -50.0, -90.0];

/// Position of each sonar on the robot (m, robot frame: x forward, y left).
pub const SONAR_POSITIONS_M: [[f64; 2]; SONAR_COUNT] = [
    [0.069, 0.136],
    [0.114, 0.119],
    [0.148, 0.078],
    [0.166, 0.027],
    [0.166, -0.027],
    [0.148, -0.078],
    [0.114, -0.119],
    [0.069, -0.136],
];

/// Rays cast across each cone.
const CONE_RAYS: usize = 5;

/// One reading of the whole ring.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct SonarReading {
    /// Ranges of sonars 1..8 (index 0..7), metres.
    pub ranges_m: [f64; SONAR_COUNT],
    /// True where no echo came back within range.
    pub no_echo: [bool; SONAR_COUNT],
}

/// The sonar model of one robot.
#[derive(Clone, Debug)]
pub struct Sonar {
    pub range_m: f64,
    pub cone_rad: f64,
    pub noise_std_m: f64,
    rng: Rng,
}

impl Sonar {
    pub fn new(range_m: f64, cone_deg: f64, noise_std_m: f64, rng: Rng) -> Self {
        Sonar {
            range_m,
            cone_rad: cone_deg.to_radians(),
            noise_std_m,
            rng,
        }
    }

    /// World position and unit direction of sonar `i`'s axis at `pose`.
    pub fn axis(pose: &Pose2, i: usize) -> (DVec2, f64) {
        let p = pose.transform_point(DVec2::from(SONAR_POSITIONS_M[i]));
        (p, pose.theta + SONAR_BEARINGS_DEG[i].to_radians())
    }

    /// The range sonar `i` would read with no noise.
    pub fn exact_range(&self, scene: &RangeScene, pose: &Pose2, i: usize) -> Option<f64> {
        self.exact_range_near(scene, None, pose, i)
    }

    /// [`Sonar::exact_range`] given the walls near the robot (see
    /// [`RangeScene::cast_near`]).
    fn exact_range_near(
        &self,
        scene: &RangeScene,
        near: Option<&[u32]>,
        pose: &Pose2,
        i: usize,
    ) -> Option<f64> {
        let (origin, axis) = Self::axis(pose, i);
        let mut best: Option<f64> = None;
        for k in 0..CONE_RAYS {
            let off = if CONE_RAYS == 1 || self.cone_rad == 0.0 {
                0.0
            } else {
                self.cone_rad * (k as f64 / (CONE_RAYS - 1) as f64 - 0.5)
            };
            let a = axis + off;
            if let Some(h) =
                scene.cast_near(near, origin, DVec2::new(a.cos(), a.sin()), self.range_m)
            {
                best = Some(best.map_or(h.range_m, |b: f64| b.min(h.range_m)));
            }
            if self.cone_rad == 0.0 {
                break;
            }
        }
        best
    }

    /// Reads all eight sonars at the true pose `pose`.
    pub fn read(&mut self, scene: &RangeScene, pose: &Pose2) -> SonarReading {
        let mut out = SonarReading::default();
        // Every sonar sits within `ring` of the robot's centre, so only
        // walls within range + ring of it can echo.
        let ring = SONAR_POSITIONS_M
            .iter()
            .map(|p| DVec2::from(*p).length())
            .fold(0.0, f64::max);
        let near = scene
            .world
            .walls_within(pose.position(), self.range_m + ring);
        for i in 0..SONAR_COUNT {
            match self.exact_range_near(scene, near.as_deref(), pose, i) {
                Some(r) => {
                    let noisy = r + self.rng.normal(self.noise_std_m);
                    out.ranges_m[i] = noisy.clamp(0.0, self.range_m);
                }
                None => {
                    out.ranges_m[i] = self.range_m;
                    out.no_echo[i] = true;
                }
            }
        }
        out
    }
}
