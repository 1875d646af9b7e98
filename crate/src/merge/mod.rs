//! # Map merging: where did the other robot's map go?
//!
//! Each robot maps in its own odometry frame (see [`crate::slam`]). To merge
//! two maps we need the pose of robot B's frame in robot A's frame — the
//! *relative transform* — and a verdict on whether we trust it. This module
//! finds both from what the robots saw (thesis chapters 5 and 6.2), in two
//! ways:
//!
//! * **the thesis's method** ([`selection`], [`pinhole`]): frames taken while
//!   a robot faces a wall squarely are compared pairwise with SURF + MSAC;
//!   the pair with the most inliers gives the distance between the robots by
//!   the pinhole relations of §6.2.4, and one map is rotated and translated
//!   into the other;
//! * **the automatic method** (the default): every frame is a candidate; a
//!   bag of visual words ([`vocabulary`]) proposes frame pairs that may show
//!   the same place; each is verified geometrically by lifting matched
//!   keypoints to 2-D points with the laser range at their bearing
//!   ([`lift`]) and fitting a rigid transform with MSAC ([`rigid`]). The
//!   candidates that agree with each other ([`consistency`], after PCM) are
//!   refined by aligning the two occupancy grids ([`align`]), and the
//!   overlaid maps must not contradict each other ([`verdict`]). When the
//!   cameras never saw a common place from close enough viewpoints, the
//!   maps alone are searched for the overlay ([`mapsearch`], after Carpin
//!   2008), judged by the same contradiction test with stricter demands.
//!   Otherwise the answer is "no merge", with the reasons;
//! * **a map-only baseline** ([`baseline`]), as existing tools do: features
//!   on the grid images and a robust similarity fit, shown beside the
//!   others so users see what vision adds.
//!
//! With three or more robots the pairwise results form a graph and the maps
//! are joined along its most confident spanning tree ([`graph`]); the grids
//! are fused by adding log-odds ([`fuse`]).
//!
//! One driver runs every method: [`job`] goes through the stages in small
//! increments so the page can show the matched-pair table filling in, and
//! asks the method's own stages ([`method`], one file per method behind one
//! trait) what to select, propose, check and decide. [`frames`] chooses and
//! describes the frames that take part (and says what a merge reads,
//! [`frames::MergeInput`]); [`work`] holds what the job works on; [`config`]
//! every setting; [`described_ahead`] lets other threads describe the frames
//! ahead of the job.
//!
//! Saved maps without robots (ROS `map_server` files, [`crate::formats::rosmap`])
//! are merged by [`saved`], with its own search
//! ([`saved::search`]) and verdict ([`saved::evidence`]) made for real maps;
//! [`saved::refine`] aligns a pair again from a person's rough overlay.
//!
//! Ground truth is never read here: the session layer (`crate::lab`) scores
//! the result.

pub mod align;
pub mod baseline;
pub mod config;
pub mod consistency;
pub mod described_ahead;
pub mod frames;
pub mod fuse;
pub mod graph;
pub mod job;
pub mod lift;
pub mod mapsearch;
pub mod method;
pub mod pairbudget;
pub mod peaksearch;
pub mod pinhole;
pub mod raster_correlation;
pub mod rigid;
pub mod saved;
pub mod selection;
pub mod verdict;
pub mod verify;
pub mod vocabulary;
pub mod work;

use crate::geom::Pose2;
use crate::sensors::laser::LASER_BEAMS;
use crate::sensors::sonar::SONAR_COUNT;
use glam::DVec2;
use serde::Serialize;

/// Which way to merge (`run --method`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum MergeMethod {
    Auto,
    Thesis,
    MapOnly,
}

impl MergeMethod {
    pub fn parse(s: &str) -> Result<MergeMethod, String> {
        match s {
            "auto" => Ok(MergeMethod::Auto),
            "thesis" => Ok(MergeMethod::Thesis),
            "map-only" => Ok(MergeMethod::MapOnly),
            other => Err(format!(
                "method: unknown merge method '{other}' (expected auto, thesis or map-only)"
            )),
        }
    }
    pub fn name(&self) -> &'static str {
        match self {
            MergeMethod::Auto => "auto",
            MergeMethod::Thesis => "thesis",
            MergeMethod::MapOnly => "map-only",
        }
    }
}

/// What a robot knew when it took one frame: never the truth.
#[derive(Clone, Debug)]
pub struct FrameInfo {
    /// Index of the frame in the robot's frame store (the report's `rows` /
    /// `cols`).
    pub index: usize,
    /// Control step at capture.
    pub step: usize,
    /// SLAM pose at capture, in the robot's odometry (map) frame.
    pub pose: Pose2,
    /// Raw odometry pose at capture.
    pub odometry: Pose2,
    /// Heading change over the last control step, rad (from odometry):
    /// the thesis's "not turning" test.
    pub turn_rad: f64,
    /// Sonar ranges at capture (thesis numbering: sonar 4 and 5 are indices
    /// 3 and 4, the two forward-facing ones).
    pub sonar_m: [f32; SONAR_COUNT],
    /// Laser ranges in mm at capture (`u16::MAX`: no return), beam `k` at
    /// bearing `(k - 90)°`.
    pub laser_mm: [u16; LASER_BEAMS],
}

/// One candidate relative transform, from one verified frame pair.
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    /// Frame indices (in each robot's store).
    pub a_frame: usize,
    pub b_frame: usize,
    /// Pose of robot B's map frame in robot A's map frame: a point `p` in
    /// B's frame is at `pose.transform_point(p)` in A's.
    pub pose: Pose2,
    /// Correspondences that support it (rigid-fit inliers).
    pub inliers: usize,
    /// RMS residual of the inliers, metres.
    pub rms_m: f64,
    /// Where the common place is, in A's and in B's map frame (centroid of
    /// the inlier points): the consistency test scales its tolerance with
    /// the distance between places.
    pub place_a: DVec2,
    pub place_b: DVec2,
}

/// The verdict on one pair of robots (or the whole merge).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MergeStatus {
    Merged,
    NoMerge,
}
