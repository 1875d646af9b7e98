//! # The merge methods, each behind one interface
//!
//! A merge method is what [`super::job::MergeJob`]'s stages ask of it: which
//! frames take part, which frame pairs to check, how to check one and what
//! its table cell shows, and the decision on a pair of robots.
//! [`MethodStages`] is that interface; each method is one file:
//!
//! | method | file | follows |
//! |---|---|---|
//! | `thesis` | [`thesis`] | thesis §6.2: square frames, every pair, the distance computation |
//! | `auto` | [`auto`] | every frame, visual-word proposals, rigid fits, the verdict, the map search |
//! | `map-only` | [`map_only`] | features on the grid images (the baseline) |
//!
//! The driver never asks which method it runs; adding a method is adding a
//! file here, a [`MergeMethod`] name, and its line in [`stages_of`]. A
//! method that reads the maps only says so with
//! [`MethodStages::uses_frames`]: the job then goes straight to the
//! decision, and its input may have no frames at all
//! ([`super::frames::MergeInput`]).

pub mod auto;
pub mod map_only;
pub mod thesis;

use super::config::MergeConfig;
use super::mapsearch::MapSearchSteps;
use super::verdict::VerdictSteps;
use super::verify::{PairCheck, VerifyConfig};
use super::work::{PairOutcome, PairWork, RobotFrames};
use super::{FrameInfo, MergeMethod};
use crate::camera::PinholeCamera;
use crate::slam::OccupancyGrid;
use auto::ProposalSteps;

/// What the decision on one pair of robots reads: both robots' frames
/// (empty for a method that reads the maps only), the checked cells, both
/// maps, the camera and the settings.
pub struct PairInput<'a> {
    /// Robot pair `a`-`b`, as positions in the job's robot list.
    pub work: &'a PairWork,
    pub robot_a: &'a RobotFrames,
    pub robot_b: &'a RobotFrames,
    pub map_a: &'a OccupancyGrid,
    pub map_b: &'a OccupancyGrid,
    pub camera: &'a PinholeCamera,
    pub config: &'a MergeConfig,
    /// Whether [`MethodStages::decide`] may also search the maps when the
    /// frames find nothing. With many robots the job asks for the searches
    /// later, in rank order ([`MethodStages::search_after`]), and skips
    /// those of robots already joined ([`super::pairbudget`]).
    pub search_maps: bool,
}

/// The stages of one merge method, as [`super::job::MergeJob`] calls them.
pub trait MethodStages: Sync {
    /// Whether the method looks at camera frames. One that does not reads
    /// the maps only: the job skips the features, proposals and matching
    /// stages.
    fn uses_frames(&self) -> bool {
        true
    }

    /// Positions in `infos` (one robot's frames, in capture order) of the
    /// frames that take part.
    fn select(&self, infos: &[FrameInfo], config: &MergeConfig) -> Vec<usize>;

    /// Fills every robot pair's to-do list (`todo`, positions in the two
    /// robots' `selected` lists), once every selected frame is described;
    /// a method may also set each pair's budget (`budget`) from the frames
    /// and the robots' `maps`.
    fn propose(
        &self,
        _robots: &[RobotFrames],
        _pairs: &mut [PairWork],
        _maps: &[&OccupancyGrid],
        _config: &MergeConfig,
    ) {
    }

    /// [`MethodStages::propose`] a step at a time, so that the stage need
    /// not be one long call (the automatic method's vocabulary, then its
    /// pair budget piece by piece, [`ProposalSteps`]): true once every
    /// to-do list is filled. `steps` is fresh for each job.
    fn propose_step(
        &self,
        robots: &[RobotFrames],
        pairs: &mut [PairWork],
        maps: &[&OccupancyGrid],
        config: &MergeConfig,
        _steps: &mut ProposalSteps,
    ) -> bool {
        self.propose(robots, pairs, maps, config);
        true
    }

    /// The verification settings of the matching stage (a pair the user
    /// opens is always checked with every setting on).
    fn verify_config(&self, config: &MergeConfig) -> VerifyConfig {
        config.verify
    }

    /// The figure a checked pair's table cell shows.
    fn table_figure(&self, check: &PairCheck) -> usize;

    /// The decision on one pair of robots.
    fn decide(&self, pair: &PairInput) -> PairOutcome;

    /// [`MethodStages::decide`] a step at a time, so that one decision
    /// need not be one long call (the automatic method judges a rival
    /// transform a step, [`VerdictSteps`]): `None` until the last step,
    /// then the outcome. `steps` is fresh for each pair.
    fn decide_step(&self, pair: &PairInput, _steps: &mut VerdictSteps) -> Option<PairOutcome> {
        Some(self.decide(pair))
    }

    /// A second look at a pair [`MethodStages::decide`] did not merge
    /// (asked with `search_maps` false): the automatic method's search of
    /// the maps alone. The default changes nothing.
    fn search_after(&self, _pair: &PairInput, decided: PairOutcome) -> PairOutcome {
        decided
    }

    /// [`MethodStages::search_after`] a step at a time, so that one search
    /// need not be one long call ([`MapSearchSteps`]): `None` until the
    /// last step, then the outcome. `steps` is fresh for each pair.
    fn search_step(
        &self,
        pair: &PairInput,
        decided: &PairOutcome,
        _steps: &mut MapSearchSteps,
    ) -> Option<PairOutcome> {
        Some(self.search_after(pair, decided.clone()))
    }
}

/// The stages of `method`.
pub fn stages_of(method: MergeMethod) -> &'static dyn MethodStages {
    match method {
        MergeMethod::Auto => &auto::Auto,
        MergeMethod::Thesis => &thesis::Thesis,
        MergeMethod::MapOnly => &map_only::MapOnly,
    }
}

/// `[x, y, theta]` of a pose, the form outcomes carry.
pub(crate) fn pose3(p: &crate::geom::Pose2) -> [f64; 3] {
    [p.x, p.y, p.theta]
}
