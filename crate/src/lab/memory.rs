//! # Where a run's bytes are: the session's memory accounting
//!
//! A long crowded run (sixteen robots for an hour, issue 22) must stay
//! under a memory target, and a target is met by measuring first. This
//! file adds up, structure by structure, the heap bytes the session holds
//! now: each robot's log (times, odometry, truth; the capped sensor rows),
//! its SLAM estimates, its two occupancy grids, its loop-closing back end's
//! key scans and pose graph, its stored camera frames;
//! the texture cache; features described ahead by other threads; and a
//! merge in progress (its frames' features, their infos, the checked
//! cells, the merged map).
//!
//! The figures count *capacity*, not length (a `Vec` that doubled holds
//! the room it reserved), of the big buffers only: small fixed parts
//! (names, a robot's current state) are left out, and a `HashMap`'s own
//! table is counted by its entries. What they cannot show is a high-water
//! mark: a `Vec` that grows copies, so for a moment it holds old and new
//! at once, and a wasm instance's linear memory never shrinks. For that,
//! `crate/examples/memory.rs` counts every allocation with a counting
//! allocator and prints the peak beside these figures.

use super::Lab;
use crate::merge::work::RobotFrames;
use crate::surf::{Descriptor, Features, Keypoint};
use serde::Serialize;
use std::mem::size_of;

/// One robot's share (bytes).
#[derive(Clone, Debug, Default, Serialize)]
pub struct RobotMemory {
    pub name: String,
    /// Times, odometry and true poses, one of each per control step.
    pub log_poses: usize,
    /// The logged sensor rows (capped, [`crate::sim::LOG_SENSOR_CAP`]).
    pub log_sensors: usize,
    /// SLAM poses, one per step (counted by length: the mapper does not
    /// say what it reserved).
    pub estimates: usize,
    pub odometry_map: usize,
    pub slam_map: usize,
    /// The loop-closing back end: key scans and its pose graph.
    pub back_end: usize,
    /// Stored camera frames ([`crate::camera::capture::FrameStore`]).
    pub frames: usize,
    pub frames_kept: usize,
}

/// The whole session's (bytes).
#[derive(Clone, Debug, Default, Serialize)]
pub struct MemoryUse {
    pub robots: Vec<RobotMemory>,
    /// The wall texture cache (painted chunks) and loaded pictures.
    pub textures: usize,
    /// Features other threads described ahead of a merge, not yet taken.
    pub described: usize,
    /// A merge in progress or done: its frames' features.
    pub merge_features: usize,
    pub merge_frames_described: usize,
    /// The merge's frame infos and selections.
    pub merge_infos: usize,
    /// The merge's checked frame pairs and to-do lists.
    pub merge_cells: usize,
    /// The merged map, once made.
    pub merged_map: usize,
    /// Everything above.
    pub total: usize,
}

/// Heap bytes of one frame's features.
pub fn features_bytes(f: &Features) -> usize {
    f.keypoints.capacity() * size_of::<Keypoint>()
        + f.descriptors.capacity() * size_of::<Descriptor>()
}

fn vec_bytes<T>(v: &Vec<T>) -> usize {
    v.capacity() * size_of::<T>()
}

impl Lab {
    /// What the session holds now, structure by structure (see the module doc).
    pub fn memory_use(&self) -> MemoryUse {
        let mut m = MemoryUse::default();
        if let Some(sim) = &self.sim {
            for r in &sim.robots {
                let log = &r.log;
                m.robots.push(RobotMemory {
                    name: r.spec.name.clone(),
                    log_poses: vec_bytes(&log.times_s)
                        + vec_bytes(&log.odometry)
                        + vec_bytes(&log.truth),
                    log_sensors: log.sensors.capacity() * size_of::<crate::sim::SensorRow>(),
                    estimates: std::mem::size_of_val(r.mapping.estimates()),
                    odometry_map: r.mapping.odometry_map.memory_bytes(),
                    slam_map: r.mapping.slam_map.memory_bytes(),
                    back_end: r.mapping.graph.as_ref().map_or(0, |g| g.memory_bytes()),
                    frames: vec_bytes(&r.frames.frames) + r.frames.bytes()
                        - r.frames.frames.len()
                            * size_of::<crate::camera::capture::CapturedFrame>(),
                    frames_kept: r.frames.frames.len(),
                });
            }
            m.textures = sim.textures.lock().memory_bytes();
        } else if let Some(bank) = &self.textures {
            m.textures = bank.memory_bytes();
        }
        m.described = self.described.memory_bytes();
        if let Some(job) = &self.merge {
            for r in &job.robots {
                add_robot_frames(&mut m, r);
            }
            m.merge_cells = job
                .pairs
                .iter()
                .map(|p| vec_bytes(&p.cells) + vec_bytes(&p.todo))
                .sum();
            m.merged_map = job.merged_map().map_or(0, |g| g.memory_bytes());
        }
        m.total = m
            .robots
            .iter()
            .map(|r| {
                r.log_poses
                    + r.log_sensors
                    + r.estimates
                    + r.odometry_map
                    + r.slam_map
                    + r.back_end
                    + r.frames
            })
            .sum::<usize>()
            + m.textures
            + m.described
            + m.merge_features
            + m.merge_infos
            + m.merge_cells
            + m.merged_map;
        m
    }
}

fn add_robot_frames(m: &mut MemoryUse, r: &RobotFrames) {
    m.merge_features +=
        r.features.iter().map(features_bytes).sum::<usize>() + vec_bytes(&r.features);
    m.merge_frames_described += r
        .features
        .iter()
        .filter(|f| f.keypoints.capacity() > 0)
        .count();
    m.merge_infos += vec_bytes(&r.infos) + vec_bytes(&r.selected);
}
