//! # Which frames take part, and their features
//!
//! What a merge reads of a robot's camera: for each stored frame, what the
//! robot knew when it took it ([`frame_infos`]: the SLAM pose, the odometry
//! turn, the sonar and laser readings, never the truth); which of them take
//! part ([`frames_taking_part`]: every frame thinned by place for the
//! automatic method, the thesis's selection of §6.2.2 for its method, none
//! for a method that reads the maps only); and the SURF features of one
//! frame, the strongest keypoints only ([`strongest_features`]). The merge
//! job ([`super::job`]) and the frames described ahead on other threads
//! ([`super::described_ahead`]) both choose and describe frames here, so they
//! make the same choice.

use super::config::MergeConfig;
use super::method::stages_of;
use super::FrameInfo;
use crate::camera::{CameraImage, PinholeCamera};
use crate::geom::wrap_angle;
use crate::sim::Simulation;
use crate::slam::{MapperKind, OccupancyGrid};
use crate::surf::descriptor::describe_all;
use crate::surf::orientation::assign_orientations;
use crate::surf::{FastHessian, Features, GrayImage, IntegralImage, SurfConfig};

/// What robot `i` knew at each of its frames (never the truth).
pub fn frame_infos(sim: &Simulation, i: usize) -> Vec<FrameInfo> {
    let r = &sim.robots[i];
    let estimates = r.slam_estimates();
    let odometry = &r.log.odometry;
    r.frames
        .frames
        .iter()
        .map(|f| {
            let odo = odometry.get(f.step).copied().unwrap_or(f.odometry);
            let before = f
                .step
                .checked_sub(1)
                .and_then(|s| odometry.get(s))
                .copied()
                .unwrap_or(odo);
            FrameInfo {
                index: f.index,
                step: f.step,
                pose: estimates.get(f.step).copied().unwrap_or(f.odometry),
                odometry: f.odometry,
                turn_rad: wrap_angle(odo.theta - before.theta),
                sonar_m: f.sonar_m,
                laser_mm: f.laser_mm,
            }
        })
        .collect()
}

/// Positions in `infos` of the frames a merge with `config` describes: all
/// of them thinned by place for the automatic method, the thesis's
/// selection for its method, none for the map-only one.
pub fn frames_taking_part(infos: &[FrameInfo], config: &MergeConfig) -> Vec<usize> {
    stages_of(config.method).select(infos, config)
}

/// SURF on one frame, keeping the `max` strongest keypoints (ties broken
/// by position, so the result is deterministic) before describing them.
pub fn strongest_features(image: &GrayImage, config: &SurfConfig, max: usize) -> Features {
    let integral = IntegralImage::new(image);
    let mut keypoints = FastHessian::new(config).detect(&integral);
    keypoints.sort_by(|a, b| {
        b.response
            .total_cmp(&a.response)
            .then(a.y.total_cmp(&b.y))
            .then(a.x.total_cmp(&b.x))
    });
    keypoints.truncate(max);
    if !config.upright {
        assign_orientations(&integral, &mut keypoints);
    }
    let descriptors = describe_all(&integral, &keypoints);
    Features {
        keypoints,
        descriptors,
    }
}

/// What a merge reads: each robot's name and map and, for the methods that
/// look, its stored frames. A [`Simulation`] gives all of it; a set of maps
/// made elsewhere (real robots' ROS maps) gives maps only, keeping the
/// defaults below, and suits a method that reads the maps only
/// ([`super::method::MethodStages::uses_frames`]).
pub trait MergeInput {
    /// The robots' names, in order.
    fn robot_names(&self) -> Vec<String>;
    /// Robot `robot`'s map from `mapper`.
    fn map(&self, robot: usize, mapper: MapperKind) -> &OccupancyGrid;
    /// What robot `robot` knew at each stored frame, in capture order.
    fn frame_infos(&self, _robot: usize) -> Vec<FrameInfo> {
        Vec::new()
    }
    /// The picture of robot `robot`'s stored frame `index`.
    fn frame_image(&self, _robot: usize, _index: usize) -> Option<CameraImage> {
        None
    }
    /// The camera the frames were taken with.
    fn camera(&self) -> Option<PinholeCamera> {
        None
    }
}

impl MergeInput for Simulation {
    fn robot_names(&self) -> Vec<String> {
        self.robots.iter().map(|r| r.spec.name.clone()).collect()
    }

    fn map(&self, robot: usize, mapper: MapperKind) -> &OccupancyGrid {
        self.robots[robot].mapping.map(mapper)
    }

    fn frame_infos(&self, robot: usize) -> Vec<FrameInfo> {
        frame_infos(self, robot)
    }

    fn frame_image(&self, robot: usize, index: usize) -> Option<CameraImage> {
        self.robots[robot]
            .frames
            .frames
            .iter()
            .find(|f| f.index == index)
            .map(|f| Simulation::frame_image(self, f))
    }

    fn camera(&self) -> Option<PinholeCamera> {
        Some(self.camera.clone())
    }
}
