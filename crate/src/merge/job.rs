//! # The merge, step by step
//!
//! [`MergeJob`] runs a whole merge — any of the three methods — in small
//! increments, so the page can draw the matched-pair table as it fills in
//! and stay responsive, and the command line can time each stage. The
//! stages are those of thesis §6.2, generalised. The job is the driver: at
//! each stage it asks the method's own stages ([`super::method`], one file
//! per method behind the [`MethodStages`] trait) what to do, and never
//! which method it runs.
//!
//! 1. **Selection.** The thesis keeps only frames taken facing a wall
//!    squarely, thinned by distance (§6.2.2, [`super::selection`]); the
//!    automatic method keeps every frame, thinned by place; the map-only
//!    baseline uses none, and the job goes straight to the decision.
//! 2. **Features.** Upright SURF on each kept frame (the cameras never
//!    roll, so orientation assignment would only cost time and
//!    distinctiveness: Bay et al. 2008 §4.1). One unit of work per frame.
//! 3. **Proposals.** The thesis compares every kept frame of one robot with
//!    every kept frame of the other (§6.2.3). The automatic method cannot
//!    afford that on hundreds of frames, so a bag of visual words trained on
//!    this run's descriptors proposes the pairs most likely to show the same
//!    place ([`super::vocabulary`]); with many robots a pair budget chooses
//!    which pairs of robots to check at all ([`super::pairbudget`]). A step
//!    at a time ([`super::method::auto::ProposalSteps`]).
//! 4. **Verification.** Each proposed pair is matched (ratio test), fitted
//!    with MSAC ([`super::verify`]); the inlier count fills one cell of the
//!    table. One unit of work per pair.
//! 5. **Decision.** Per pair of robots: the thesis's distance computation
//!    (§6.2.4, [`super::pinhole`]), the automatic verdict (consistency, grid
//!    alignment and map agreement, [`super::verdict`]; when vision finds no
//!    transform the maps confirm, a search of the maps alone,
//!    [`super::mapsearch`], judged as strictly), or the baseline's
//!    grid-image fit ([`super::baseline`]). The pairwise results are joined
//!    along the most confident spanning tree ([`super::graph`]).
//! 6. **Fusion.** The joined maps are fused into one grid in the first
//!    robot's frame ([`super::fuse`]), a band of rows a unit.
//!
//! The job reads only what the robots knew: their frames, their SLAM poses
//! and their maps. It never looks at the truth; the session layer
//! (`crate::lab`) scores it.

mod decision;

use super::described_ahead::{describe_image, DescribedFrames};
use super::frames::MergeInput;
use super::fuse::FuseSteps;
use super::graph::{groups, spanning_tree, Joined, PairEdge};
use super::method::auto::ProposalSteps;
use super::method::{pose3, stages_of, MethodStages, PairInput};
use super::pairbudget::{BudgetSummary, PairBudget, PairPlan};
use super::verify::{verify_pair, PairCheck, VerifyConfig};
use super::MergeStatus;
use crate::camera::PinholeCamera;
use crate::geom::Pose2;
use crate::scenario::CameraSpec;
use crate::slam::OccupancyGrid;
use serde::Serialize;

// Also here for the job's callers: the settings, and the pieces a job
// works on.
pub use super::config::MergeConfig;
pub use super::work::{Cell, PairOutcome, PairWork, RobotFrames};

/// Rows of the merged map fused per unit of the fusion stage.
const ROWS_PER_UNIT: usize = 32;

/// The stage a job is in; [`MergeJob::advance`] never crosses a stage
/// boundary in one call, so a caller can time each stage.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stage {
    Features,
    Proposals,
    Matching,
    Decision,
    Fusion,
    Done,
}

impl Stage {
    pub fn name(&self) -> &'static str {
        match self {
            Stage::Features => "features",
            Stage::Proposals => "proposals",
            Stage::Matching => "matching",
            Stage::Decision => "decision",
            Stage::Fusion => "fusion",
            Stage::Done => "done",
        }
    }
}

/// Milliseconds per merge stage (zero without a clock; measured by the
/// caller, as the job reads no clock).
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct MergeTimes {
    pub features: f64,
    pub matching: f64,
    pub merge: f64,
}

/// The pose of one robot's map frame in the merged frame.
#[derive(Clone, Debug, Serialize)]
pub struct RobotTransform {
    pub robot: String,
    pub pose: [f64; 3],
}

/// One connected group of robots the merge joined: the robots, in order,
/// and each one's map frame in the frame of the group's first robot. A
/// robot no merged pair reaches is a group of its own, with the reason.
#[derive(Clone, Debug, Serialize)]
pub struct RobotGroup {
    pub robots: Vec<String>,
    pub transforms: Vec<RobotTransform>,
    /// Why a robot stands alone (only on groups of one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

/// The overall result.
#[derive(Clone, Debug, Serialize)]
pub struct MergeOutcome {
    pub status: MergeStatus,
    pub reason: String,
    pub confidence: f64,
    /// Joined robots only; the first robot is always `[0, 0, 0]`.
    pub transforms: Vec<RobotTransform>,
    /// Robots that could not be joined to the first.
    pub unjoined: Vec<String>,
    /// Every connected group of robots, robot 0's first (its transforms
    /// are [`MergeOutcome::transforms`]).
    pub groups: Vec<RobotGroup>,
    pub pairs: Vec<PairOutcome>,
    /// What the pair budget did (many robots only, [`super::pairbudget`]).
    pub budget: Option<BudgetSummary>,
}

/// A matched-pair table in the report's layout (`interfaces.md`).
#[derive(Clone, Debug, Serialize)]
pub struct MatchTable {
    pub a: String,
    pub b: String,
    /// Frame indices (in each robot's frame store) of the rows / columns.
    pub rows: Vec<usize>,
    pub cols: Vec<usize>,
    /// Inlier counts, `rows.len()` × `cols.len()`; 0 where a pair was not
    /// checked or gave nothing.
    pub inliers: Vec<Vec<u32>>,
    /// How many cells were checked (the rest were not proposed).
    pub checked: usize,
}

/// A whole merge in progress.
pub struct MergeJob {
    pub config: MergeConfig,
    pub camera: PinholeCamera,
    pub robots: Vec<RobotFrames>,
    pub pairs: Vec<PairWork>,
    stage: Stage,
    /// Features stage: next (robot, selected position).
    cursor: (usize, usize),
    /// Matching stage: next pair of robots.
    pair_cursor: usize,
    /// The method's stages ([`super::method`]).
    method: &'static dyn MethodStages,
    outcome: Option<MergeOutcome>,
    merged: Option<OccupancyGrid>,
    /// Time per stage, measured by the caller's clock (the session's).
    pub times_ms: MergeTimes,
    /// Frames described ahead, elsewhere ([`super::described_ahead`]): taken
    /// instead of describing them again.
    described: DescribedFrames,
    /// The proposal stage between calls ([`ProposalSteps`]).
    proposing: Option<ProposalSteps>,
    /// The decision stage between calls ([`decision`]).
    deciding: Option<decision::Deciding>,
    /// The fusion between calls ([`FuseSteps`]).
    fusing: Option<FuseSteps>,
}

impl MergeJob {
    /// A merge of the robots of a finished (or paused) simulation, or of
    /// any other [`MergeInput`]. Fails when there is nothing to merge.
    pub fn new(input: &impl MergeInput, config: MergeConfig) -> Result<MergeJob, String> {
        let method = stages_of(config.method);
        let robots: Vec<RobotFrames> = input
            .robot_names()
            .into_iter()
            .enumerate()
            .map(|(i, name)| {
                let infos = input.frame_infos(i);
                let selected = method.select(&infos, &config);
                RobotFrames {
                    name,
                    infos,
                    selected,
                    features: Vec::new(),
                }
            })
            .collect();
        let mut pairs = Vec::new();
        for a in 0..robots.len() {
            for b in a + 1..robots.len() {
                pairs.push(PairWork {
                    a,
                    b,
                    todo: Vec::new(),
                    cells: Vec::new(),
                    outcome: None,
                    budget: None,
                });
            }
        }
        // A lone robot has nothing to match: straight to the verdict (which
        // says so) without describing a single frame.
        let stage = if method.uses_frames() && !pairs.is_empty() {
            Stage::Features
        } else {
            Stage::Decision
        };
        Ok(MergeJob {
            camera: input
                .camera()
                .unwrap_or_else(|| PinholeCamera::new(&CameraSpec::default())),
            config,
            robots,
            pairs,
            stage,
            cursor: (0, 0),
            pair_cursor: 0,
            method,
            outcome: None,
            merged: None,
            times_ms: Default::default(),
            described: DescribedFrames::default(),
            proposing: None,
            deciding: None,
            fusing: None,
        })
    }

    /// Hands the job features described ahead of it (by another thread);
    /// the features stage takes those it needs instead of computing them.
    /// They are what it would compute (same frames, same settings), so the
    /// merge comes out the same.
    pub fn adopt_described(&mut self, described: DescribedFrames) {
        self.described = described;
    }

    pub fn stage(&self) -> Stage {
        self.stage
    }

    pub fn is_done(&self) -> bool {
        self.stage == Stage::Done
    }

    pub fn outcome(&self) -> Option<&MergeOutcome> {
        self.outcome.as_ref()
    }

    /// The fused map (once merged), in the first robot's map frame.
    pub fn merged_map(&self) -> Option<&OccupancyGrid> {
        self.merged.as_ref()
    }

    /// Units of work in the current stage: (done, total).
    pub fn progress(&self) -> (usize, usize) {
        match self.stage {
            Stage::Features => {
                let total: usize = self.robots.iter().map(|r| r.selected.len()).sum();
                let done: usize = self.robots.iter().map(|r| r.features.len()).sum();
                (done, total)
            }
            Stage::Matching => {
                let total: usize = self.pairs.iter().map(|p| p.todo.len()).sum();
                let done: usize = self.pairs.iter().map(|p| p.cells.len()).sum();
                (done, total)
            }
            Stage::Proposals => self
                .proposing
                .as_ref()
                .map_or((0, 1), |p| p.progress(self.robots.len(), &self.config)),
            Stage::Decision => self
                .deciding
                .as_ref()
                .map_or((0, self.pairs.len().max(1)), |d| {
                    d.progress(self.pairs.len())
                }),
            Stage::Fusion => self.fusing.as_ref().map_or((0, 1), FuseSteps::progress),
            Stage::Done => (1, 1),
        }
    }

    /// Does up to `units` units of work (frames described, pairs checked,
    /// proposal steps, pairs decided or searched, bands of the merged map's
    /// rows) without
    /// leaving the current stage. `input` must be what the job was made
    /// from. Returns the units done (0 once finished).
    pub fn advance(&mut self, input: &impl MergeInput, units: usize) -> Result<usize, String> {
        let units = units.max(1);
        match self.stage {
            Stage::Features => Ok(self.advance_features(input, units)),
            Stage::Proposals => Ok(self.advance_proposals(input, units)),
            Stage::Matching => Ok(self.advance_matching(units)),
            Stage::Decision => {
                let done = self.advance_decision(input, units);
                if self.decision_finished() {
                    self.finish_decision();
                    self.stage = Stage::Fusion;
                }
                Ok(done.max(1))
            }
            Stage::Fusion => Ok(self.advance_fusion(input, units)),
            Stage::Done => Ok(0),
        }
    }

    /// Runs the job to the end (also through stages with no work, such as
    /// the features of robots that stored no frame).
    pub fn run(&mut self, input: &impl MergeInput) -> Result<(), String> {
        while !self.is_done() {
            self.advance(input, usize::MAX)?;
        }
        Ok(())
    }

    fn advance_features(&mut self, input: &impl MergeInput, units: usize) -> usize {
        let mut done = 0;
        while done < units {
            let (ri, k) = self.cursor;
            if ri >= self.robots.len() {
                self.stage = Stage::Proposals;
                break;
            }
            let robot = &mut self.robots[ri];
            if k >= robot.selected.len() {
                self.cursor = (ri + 1, 0);
                continue;
            }
            let info = &robot.infos[robot.selected[k]];
            let features = match self.described.take(&self.config, ri, info.index) {
                Some(ready) => ready,
                None => input
                    .frame_image(ri, info.index)
                    .map(|img| describe_image(img, &self.config))
                    .unwrap_or_default(),
            };
            robot.features.push(features);
            self.cursor = (ri, k + 1);
            done += 1;
        }
        if self.cursor.0 >= self.robots.len() {
            self.stage = Stage::Proposals;
        }
        if self.stage != Stage::Features {
            // Whatever was described ahead and not used is not needed.
            self.described = DescribedFrames::default();
        }
        done
    }

    /// Checks one frame pair (positions in the robots' selected lists).
    pub fn check(&self, a: usize, row: usize, b: usize, col: usize) -> Option<PairCheck> {
        self.check_with(a, row, b, col, &self.config.verify)
    }

    /// [`MergeJob::check`] with other verification settings.
    fn check_with(
        &self,
        a: usize,
        row: usize,
        b: usize,
        col: usize,
        verify: &VerifyConfig,
    ) -> Option<PairCheck> {
        let (ra, rb) = (self.robots.get(a)?, self.robots.get(b)?);
        let (fa, fb) = (ra.features.get(row)?, rb.features.get(col)?);
        let (ia, ib) = (&ra.infos[ra.selected[row]], &rb.infos[rb.selected[col]]);
        let seed = self.config.seed
            ^ ((ia.index as u64) << 20)
            ^ ((ib.index as u64) << 40)
            ^ ((a * 16 + b) as u64);
        Some(verify_pair(&self.camera, ia, fa, ib, fb, verify, seed))
    }

    /// Up to `units` steps of the method's proposals ([`ProposalSteps`]);
    /// on to matching once every pair's to-do list is filled.
    fn advance_proposals(&mut self, input: &impl MergeInput, units: usize) -> usize {
        let maps: Vec<&OccupancyGrid> = (0..self.robots.len())
            .map(|i| input.map(i, self.config.mapper))
            .collect();
        let steps = self.proposing.get_or_insert_with(ProposalSteps::default);
        for done in 1..=units {
            if self
                .method
                .propose_step(&self.robots, &mut self.pairs, &maps, &self.config, steps)
            {
                self.proposing = None;
                self.stage = Stage::Matching;
                return done;
            }
        }
        units
    }

    fn advance_matching(&mut self, units: usize) -> usize {
        let mut done = 0;
        while done < units {
            let Some(p) = self.pairs.get(self.pair_cursor) else {
                self.stage = Stage::Decision;
                break;
            };
            if p.cells.len() >= p.todo.len() {
                self.pair_cursor += 1;
                continue;
            }
            let (row, col) = p.todo[p.cells.len()];
            let (a, b) = (p.a, p.b);
            let verify = self.method.verify_config(&self.config);
            let cell = match self.check_with(a, row, b, col, &verify) {
                Some(check) => {
                    let inliers = self.method.table_figure(&check);
                    Cell {
                        row,
                        col,
                        inliers: inliers as u32,
                        matches: check.matches.len() as u32,
                        rigid_inliers: check.rigid_inliers as u32,
                        candidate: check.candidate,
                        homography: check.homography,
                        quad: check.quad,
                    }
                }
                None => Cell {
                    row,
                    col,
                    inliers: 0,
                    matches: 0,
                    rigid_inliers: 0,
                    candidate: None,
                    homography: None,
                    quad: None,
                },
            };
            self.pairs[self.pair_cursor].cells.push(cell);
            done += 1;
        }
        if self.pair_cursor >= self.pairs.len() {
            self.stage = Stage::Decision;
        }
        done
    }

    /// What the decision on pair `p` reads.
    fn pair_input<'a>(
        &'a self,
        input: &'a impl MergeInput,
        p: &'a PairWork,
        search_maps: bool,
    ) -> PairInput<'a> {
        let mapper = self.config.mapper;
        PairInput {
            work: p,
            robot_a: &self.robots[p.a],
            robot_b: &self.robots[p.b],
            map_a: input.map(p.a, mapper),
            map_b: input.map(p.b, mapper),
            camera: &self.camera,
            config: &self.config,
            search_maps,
        }
    }

    /// The outcome of a pair whose frames the budget left unmatched: not
    /// checked, or (plan `MapsOnly`) waiting for its map search.
    fn unmatched(&self, p: &PairWork, b: &PairBudget) -> PairOutcome {
        let k = b.partners;
        let (reason, check) = match b.plan {
            PairPlan::MapsOnly => (
                format!(
                    "frames not matched within the budget: by visual votes ({:.3}) neither robot ranks the other among its {k} likeliest partners, by coarse map overlap ({:.2}) one does",
                    b.votes, b.overlap
                ),
                "maps",
            ),
            _ => (
                format!(
                    "not checked within the budget: neither robot ranks the other among its {k} likeliest partners by visual votes ({:.3}) or by coarse map overlap ({:.2})",
                    b.votes, b.overlap
                ),
                "none",
            ),
        };
        PairOutcome {
            a: self.robots[p.a].name.clone(),
            b: self.robots[p.b].name.clone(),
            status: MergeStatus::NoMerge,
            reason,
            confidence: 0.0,
            pose: None,
            candidates: 0,
            support: 0,
            best: None,
            second: None,
            distance: None,
            check: Some(check),
            verdict: None,
        }
    }

    /// Joins the pairwise results along the most confident spanning tree.
    fn join(&self, pairs: Vec<PairOutcome>) -> MergeOutcome {
        let n = self.robots.len();
        let edges: Vec<PairEdge> = self
            .pairs
            .iter()
            .zip(&pairs)
            .filter(|(_, o)| o.status == MergeStatus::Merged)
            .filter_map(|(p, o)| {
                let [x, y, theta] = o.pose?;
                Some(PairEdge {
                    a: p.a,
                    b: p.b,
                    pose: Pose2::new(x, y, theta),
                    confidence: o.confidence,
                })
            })
            .collect();
        let joined = spanning_tree(n, &edges);
        let groups = self.groups(&edges, &pairs);
        let transforms: Vec<RobotTransform> = joined
            .poses
            .iter()
            .enumerate()
            .filter_map(|(i, p)| {
                p.as_ref().map(|p| RobotTransform {
                    robot: self.robots[i].name.clone(),
                    pose: pose3(p),
                })
            })
            .collect();
        let unjoined: Vec<String> = joined
            .poses
            .iter()
            .enumerate()
            .filter(|(_, p)| p.is_none())
            .map(|(i, _)| self.robots[i].name.clone())
            .collect();
        let confidence = joined
            .edges_used
            .iter()
            .filter_map(|&e| edges.get(e))
            .map(|e| e.confidence)
            .fold(f64::INFINITY, f64::min);
        let first = self.robots[0].name.clone();
        let (status, reason, confidence) = if n < 2 {
            (
                MergeStatus::NoMerge,
                format!("{first} is the only robot: there is nothing to merge"),
                0.0,
            )
        } else if transforms.len() < 2 {
            // Nothing joined the first robot: say why, pair by pair.
            let why: Vec<String> = pairs
                .iter()
                .map(|o| format!("{} + {}: {}", o.a, o.b, o.reason))
                .collect();
            (MergeStatus::NoMerge, why.join("; "), 0.0)
        } else if unjoined.is_empty() {
            let used: Vec<String> = joined
                .edges_used
                .iter()
                .filter_map(|&e| edges.get(e))
                .map(|e| {
                    let o = pairs
                        .iter()
                        .find(|o| o.a == self.robots[e.a].name && o.b == self.robots[e.b].name);
                    let reason = o.map_or(String::new(), |o| o.reason.clone());
                    format!(
                        "{} + {}: {}",
                        self.robots[e.a].name, self.robots[e.b].name, reason
                    )
                })
                .collect();
            (MergeStatus::Merged, used.join("; "), confidence)
        } else {
            (
                MergeStatus::Merged,
                format!(
                    "joined {} of {} robots to {first}; not joined: {}",
                    transforms.len(),
                    n,
                    unjoined.join(", ")
                ),
                confidence,
            )
        };
        MergeOutcome {
            budget: None,
            status,
            reason,
            confidence: if confidence.is_finite() {
                confidence
            } else {
                0.0
            },
            transforms,
            unjoined,
            groups,
            pairs,
        }
    }

    /// Every connected group the merged pairs `edges` make
    /// ([`super::graph::groups`]); a robot alone gets the reason, from the
    /// decisions `pairs` on its pairs.
    fn groups(&self, edges: &[PairEdge], pairs: &[PairOutcome]) -> Vec<RobotGroup> {
        let n = self.robots.len();
        groups(n, edges)
            .iter()
            .map(|g: &Joined| {
                let members: Vec<(usize, Pose2)> = g
                    .poses
                    .iter()
                    .enumerate()
                    .filter_map(|(i, p)| p.map(|p| (i, p)))
                    .collect();
                let reason = match members.as_slice() {
                    [(i, _)] => Some(self.alone_reason(*i, pairs)),
                    _ => None,
                };
                RobotGroup {
                    robots: members
                        .iter()
                        .map(|(i, _)| self.robots[*i].name.clone())
                        .collect(),
                    transforms: members
                        .iter()
                        .map(|(i, p)| RobotTransform {
                            robot: self.robots[*i].name.clone(),
                            pose: pose3(p),
                        })
                        .collect(),
                    reason,
                }
            })
            .collect()
    }

    /// Why robot `i` joined no one: the decision on its closest pair (the
    /// most confident, then the one with the most candidates).
    fn alone_reason(&self, i: usize, pairs: &[PairOutcome]) -> String {
        let name = &self.robots[i].name;
        let mine: Vec<&PairOutcome> = pairs
            .iter()
            .filter(|o| &o.a == name || &o.b == name)
            .collect();
        let closest = mine.iter().copied().reduce(|best, o| {
            let better = o.confidence.total_cmp(&best.confidence).is_gt()
                || (o.confidence == best.confidence && o.candidates > best.candidates);
            if better {
                o
            } else {
                best
            }
        });
        match closest {
            None => format!("{name} is the only robot: there is nothing to merge"),
            Some(o) => {
                let unchecked = mine.iter().filter(|o| o.check == Some("none")).count();
                let budget = if unchecked > 0 {
                    format!(" ({unchecked} of them not checked within the budget)")
                } else {
                    String::new()
                };
                format!(
                    "{name} joined no other robot: none of its {} pairs merged{budget}; closest, {} + {}: {}",
                    mine.len(),
                    o.a,
                    o.b,
                    o.reason
                )
            }
        }
    }

    /// Up to `units` bands of [`ROWS_PER_UNIT`] rows of the merged map
    /// ([`FuseSteps`]); done at once when nothing merged.
    fn advance_fusion(&mut self, input: &impl MergeInput, units: usize) -> usize {
        let Some(maps) = self.fused_maps(input) else {
            self.stage = Stage::Done;
            return 1;
        };
        let mapper = self.config.mapper;
        let steps = self
            .fusing
            .get_or_insert_with(|| FuseSteps::new(&maps, input.map(0, mapper).config.clone()));
        if steps.step(&maps, units.saturating_mul(ROWS_PER_UNIT)) {
            self.merged = self.fusing.take().map(FuseSteps::into_grid);
            self.stage = Stage::Done;
        }
        units
    }

    /// The maps the merge joined to the first robot, with their poses in
    /// its frame; `None` when nothing merged.
    fn fused_maps<'i>(
        &self,
        input: &'i impl MergeInput,
    ) -> Option<Vec<(&'i OccupancyGrid, Pose2)>> {
        let outcome = self.outcome.as_ref()?;
        if outcome.status != MergeStatus::Merged {
            return None;
        }
        let maps: Vec<(&OccupancyGrid, Pose2)> = outcome
            .transforms
            .iter()
            .filter_map(|t| {
                let i = self.robots.iter().position(|r| r.name == t.robot)?;
                Some((
                    input.map(i, self.config.mapper),
                    Pose2::new(t.pose[0], t.pose[1], t.pose[2]),
                ))
            })
            .collect();
        Some(maps)
    }

    /// The matched-pair tables in the report's layout.
    pub fn tables(&self) -> Vec<MatchTable> {
        self.pairs
            .iter()
            .map(|p| {
                let (ra, rb) = (&self.robots[p.a], &self.robots[p.b]);
                let mut rows: Vec<usize> = p.todo.iter().map(|&(i, _)| i).collect();
                let mut cols: Vec<usize> = p.todo.iter().map(|&(_, j)| j).collect();
                rows.sort_unstable();
                rows.dedup();
                cols.sort_unstable();
                cols.dedup();
                let mut inliers = vec![vec![0u32; cols.len()]; rows.len()];
                for c in &p.cells {
                    if let (Ok(r), Ok(k)) = (rows.binary_search(&c.row), cols.binary_search(&c.col))
                    {
                        inliers[r][k] = c.inliers;
                    }
                }
                MatchTable {
                    a: ra.name.clone(),
                    b: rb.name.clone(),
                    rows: rows
                        .iter()
                        .map(|&i| ra.infos[ra.selected[i]].index)
                        .collect(),
                    cols: cols
                        .iter()
                        .map(|&j| rb.infos[rb.selected[j]].index)
                        .collect(),
                    inliers,
                    checked: p.cells.len(),
                }
            })
            .collect()
    }
}
