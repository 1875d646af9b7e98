//! # Range sensors: the sonar ring and the laser range finder
//!
//! Both sensors are simulated the same way: rays cast from the sensor into
//! the [`World`] (and against the bodies of the *other* robots), the nearest
//! hit taken as the range, then Gaussian noise added (thesis §3.2.3.2,
//! §6.1.1.1, Figure 15). Readings are expressed in the robot's own frame and
//! are all a robot ever learns about its surroundings.
//!
//! * [`sonar`] — eight sonars on the front ring, 2 m range, each a cone.
//! * [`laser`] — 181 beams over 180° at 1°, 4 m range; max-range returns
//!   are flagged, since "nothing within 4 m" is not a wall at 4 m.

pub mod laser;
pub mod sonar;

use crate::geom::Segment;
use crate::world::{RayHit, World};
use glam::DVec2;

pub use laser::{Laser, LaserScan, LASER_BEAMS, LASER_FOV_RAD};
pub use sonar::{Sonar, SonarReading, SONAR_COUNT};

/// What rays can hit: the static walls plus moving obstacles (the edges of
/// other robots' bodies).
#[derive(Clone, Copy)]
pub struct RangeScene<'a> {
    pub world: &'a World,
    pub obstacles: &'a [Segment],
}

impl RangeScene<'_> {
    /// The nearest wall or obstacle along the unit ray, within `max_range_m`.
    pub fn cast(&self, origin: DVec2, dir: DVec2, max_range_m: f64) -> Option<RayHit> {
        self.cast_near(None, origin, dir, max_range_m)
    }

    /// [`RangeScene::cast`] for rays from `origin`, given the walls near it
    /// ([`World::walls_within`] for `origin` and at least `max_range_m`; `None`
    /// casts among all walls as `cast` does). The same answer, cheaper when a
    /// scan casts many rays from one point.
    pub fn cast_near(
        &self,
        near: Option<&[u32]>,
        origin: DVec2,
        dir: DVec2,
        max_range_m: f64,
    ) -> Option<RayHit> {
        let mut hit = match near {
            Some(walls) => self.world.cast_among(walls, origin, dir, max_range_m),
            None => self.world.cast_range(origin, dir, max_range_m),
        };
        for s in self.obstacles {
            if let Some(t) = s.ray_hit(origin, dir) {
                if t <= max_range_m && hit.is_none_or(|h| t < h.range_m) {
                    hit = Some(RayHit {
                        range_m: t,
                        wall: None,
                    });
                }
            }
        }
        hit
    }
}
