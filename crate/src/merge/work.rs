//! # What a merge works on
//!
//! The pieces of a merge in progress that the driver ([`super::job`]) and
//! the methods' stages ([`super::method`]) share: each robot's frames and
//! their features, each pair of robots' to-do list of frame pairs and its
//! checked cells (the matched-pair table), and the decision on each pair.

use super::pairbudget::PairBudget;
use super::pinhole::DistanceSolution;
use super::verdict::PairDecision;
use super::{Candidate, FrameInfo, MergeStatus};
use crate::surf::{Features, Homography};
use serde::Serialize;

/// One robot's side of the merge.
pub struct RobotFrames {
    pub name: String,
    /// What the robot knew at each captured frame, in capture order.
    pub infos: Vec<FrameInfo>,
    /// Positions in `infos` that take part (all of them for the automatic
    /// method, the thesis's selection otherwise).
    pub selected: Vec<usize>,
    /// SURF features per selected frame (same order as `selected`).
    pub features: Vec<Features>,
}

/// One checked frame pair: a cell of the matched-pair table.
#[derive(Clone, Debug, Serialize)]
pub struct Cell {
    /// Positions in the two robots' `selected` lists.
    pub row: usize,
    pub col: usize,
    /// The figure the table shows: MSAC homography inliers for the thesis's
    /// method (its Table 1), rigid-transform inliers for the automatic one.
    pub inliers: u32,
    /// Ratio-test matches.
    pub matches: u32,
    /// Rigid-fit inliers, also when too few for a candidate (automatic
    /// method): the "too few inliers" reason quotes the best.
    #[serde(skip)]
    pub rigid_inliers: u32,
    /// The candidate transform this pair gives (automatic method).
    #[serde(skip)]
    pub candidate: Option<Candidate>,
    /// The MSAC homography and the matched-region quad (thesis Figure 8).
    #[serde(skip)]
    pub homography: Option<Homography>,
    pub quad: Option<[[f64; 2]; 4]>,
}

/// The work on one pair of robots.
pub struct PairWork {
    pub a: usize,
    pub b: usize,
    /// Frame pairs to check, as positions in the `selected` lists.
    pub todo: Vec<(usize, usize)>,
    pub cells: Vec<Cell>,
    pub outcome: Option<PairOutcome>,
    /// The pair budget's plan for this pair ([`super::pairbudget`]);
    /// `None` when every pair is checked in full (few robots, or a method
    /// without a budget).
    pub budget: Option<PairBudget>,
}

/// The decision on one pair of robots.
#[derive(Clone, Debug, Serialize)]
pub struct PairOutcome {
    pub a: String,
    pub b: String,
    pub status: MergeStatus,
    pub reason: String,
    pub confidence: f64,
    /// Pose of b's map frame in a's map frame, `[x, y, theta]`.
    pub pose: Option<[f64; 3]>,
    /// Candidates found and how many of them agree (automatic method).
    pub candidates: usize,
    pub support: usize,
    /// Thesis method: the best pair and the second (table positions), and
    /// the numbers of §6.2.4.
    pub best: Option<[usize; 2]>,
    pub second: Option<[usize; 2]>,
    pub distance: Option<DistanceSolution>,
    /// With many robots ([`super::pairbudget`]), how much of the pair was
    /// checked: `"full"` (frames matched; maps searched if needed),
    /// `"frames"` (frames matched; maps not searched: the robots were
    /// joined already, or the maps did not rank the pair), `"maps"` (maps searched alone), `"none"` (not
    /// checked within the budget). Absent when every pair is checked in
    /// full.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub check: Option<&'static str>,
    /// Automatic method: the verdict behind the outcome, with the agreeing
    /// candidates (indices into the pair's candidates, in cell order) and
    /// the independent places they show. Not part of the report.
    #[serde(skip)]
    pub verdict: Option<PairDecision>,
}
