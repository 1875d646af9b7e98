//! # The merge, step by step
//!
//! [`MergeJob`] runs a whole merge — any of the three methods — in small
//! increments, so the page can draw the matched-pair table as it fills in
//! and stay responsive, and the command line can time each stage. The
//! stages are those of thesis §6.2, generalised:
//!
//! 1. **Selection.** The thesis keeps only frames taken facing a wall
//!    squarely, thinned by distance (§6.2.2, [`super::selection`]); the
//!    automatic method keeps every frame; the map-only baseline uses none.
//! 2. **Features.** Upright SURF on each kept frame (the cameras never
//!    roll, so orientation assignment would only cost time and
//!    distinctiveness: Bay et al. 2008 §4.1). One unit of work per frame.
//! 3. **Proposals.** The thesis compares every kept frame of one robot with
//!    every kept frame of the other (§6.2.3). The automatic method cannot
//!    afford that on hundreds of frames, so a bag of visual words trained on
//!    this run's descriptors proposes the pairs most likely to show the same
//!    place ([`super::vocabulary`]).
//! 4. **Verification.** Each proposed pair is matched (ratio test), fitted
//!    with MSAC ([`super::verify`]); the inlier count fills one cell of the
//!    table. One unit of work per pair.
//! 5. **Decision.** Per pair of robots: the thesis's distance computation
//!    (§6.2.4, [`super::thesis`]), the automatic verdict (consistency, grid
//!    alignment and map agreement, [`super::verdict`]; when vision finds no
//!    transform the maps confirm, a search of the maps alone,
//!    [`super::mapsearch`], judged as strictly), or the baseline's
//!    grid-image fit ([`super::baseline`]). The pairwise results are joined
//!    along the most confident spanning tree ([`super::graph`]).
//! 6. **Fusion.** The joined maps are fused into one grid in the first
//!    robot's frame ([`super::fuse`]).
//!
//! The job reads only what the robots knew: their frames, their SLAM poses
//! and their maps. It never looks at the truth; [`crate::lab`] scores it.

use super::baseline::{map_only_merge, BaselineConfig};
use super::described::{describe_image, DescribedFrames};
use super::fuse::fuse;
use super::graph::{spanning_tree, PairEdge};
use super::mapsearch::{search_maps, MapSearchConfig};
use super::selection::{select_frames, SelectionConfig};
use super::thesis::{thesis_merge, DistanceSolution, PairMatch};
use super::verdict::{decide_pair_after_search, SearchSummary, VerdictConfig};
use super::verify::{verify_pair, PairCheck, VerifyConfig};
use super::vocabulary::{propose_pairs, Bag, Vocabulary, VocabularyConfig};
use super::{Candidate, FrameInfo, MergeMethod, MergeStatus};
use crate::camera::PinholeCamera;
use crate::geom::{wrap_angle, Pose2};
use crate::sim::Simulation;
use crate::slam::{MapperKind, OccupancyGrid};
use crate::surf::descriptor::describe_all;
use crate::surf::orientation::assign_orientations;
use crate::surf::{FastHessian, Features, GrayImage, Homography, IntegralImage, SurfConfig};
use serde::Serialize;

/// Every setting of a merge. `MergeConfig::new(method)` gives the defaults.
#[derive(Clone, Debug)]
pub struct MergeConfig {
    pub method: MergeMethod,
    /// SURF on the robots' frames (upright by default).
    pub surf: SurfConfig,
    pub selection: SelectionConfig,
    pub verify: VerifyConfig,
    pub vocabulary: VocabularyConfig,
    /// At most this many keypoints per frame, the strongest (det H) kept:
    /// description and matching cost grow with the count, and the weakest
    /// blobs are the least repeatable.
    pub max_keypoints: usize,
    /// Automatic method: a frame takes part only if the robot moved at
    /// least `min_motion_m` or turned `min_turn_rad` since the last frame
    /// that does (consecutive views 0.3 m apart show nearly the same).
    pub min_motion_m: f64,
    pub min_turn_rad: f64,
    /// Automatic method: frames of the other robot proposed per frame.
    pub proposals_per_frame: usize,
    /// Automatic method: at most this many pairs verified per robot pair.
    pub max_pairs: usize,
    pub verdict: VerdictConfig,
    /// Automatic method: when vision finds no transform the maps confirm,
    /// search the maps alone ([`super::mapsearch`]); `None` turns that off.
    pub map_search: Option<MapSearchConfig>,
    pub baseline: BaselineConfig,
    /// Which map each robot contributes (SLAM by default).
    pub mapper: MapperKind,
    /// Seed of every random choice (MSAC samples, k-means seeding).
    pub seed: u64,
}

impl MergeConfig {
    pub fn new(method: MergeMethod, seed: u64) -> MergeConfig {
        MergeConfig {
            method,
            // Three octaves: the fourth's filters (up to 195 px) hardly fit
            // a 240-pixel-high frame.
            surf: SurfConfig {
                upright: true,
                octaves: 3,
                ..SurfConfig::default()
            },
            selection: SelectionConfig::default(),
            max_keypoints: 160,
            min_motion_m: 0.5,
            min_turn_rad: 15f64.to_radians(),
            verify: VerifyConfig::default(),
            vocabulary: VocabularyConfig::default(),
            proposals_per_frame: 3,
            max_pairs: 600,
            verdict: VerdictConfig::default(),
            map_search: Some(MapSearchConfig::default()),
            baseline: BaselineConfig::default(),
            mapper: MapperKind::Slam,
            seed,
        }
    }
}

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
}

/// The pose of one robot's map frame in the merged frame.
#[derive(Clone, Debug, Serialize)]
pub struct RobotTransform {
    pub robot: String,
    pub pose: [f64; 3],
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
    pub pairs: Vec<PairOutcome>,
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
    bags: Vec<Vec<Bag>>,
    outcome: Option<MergeOutcome>,
    merged: Option<OccupancyGrid>,
    /// Time per stage, measured by the caller's clock ([`crate::merge::lab`]).
    pub times_ms: super::lab::MergeTimes,
    /// Frames described ahead, elsewhere ([`super::described`]): taken
    /// instead of describing them again.
    described: DescribedFrames,
}

fn pose3(p: &Pose2) -> [f64; 3] {
    [p.x, p.y, p.theta]
}

/// What robot `i` knew at each of its frames (never the truth).
pub fn frame_infos(sim: &Simulation, i: usize) -> Vec<FrameInfo> {
    let r = &sim.robots[i];
    let estimates = r.mapping.estimates();
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

/// Positions in `infos` of the frames taken after the robot moved at least
/// `min_m` or turned `min_rad` (SLAM pose) since the last frame kept; the
/// first frame is always kept.
pub fn thin_by_motion(infos: &[FrameInfo], min_m: f64, min_rad: f64) -> Vec<usize> {
    let mut kept: Vec<usize> = Vec::new();
    for (k, f) in infos.iter().enumerate() {
        let keep = match kept.last() {
            None => true,
            Some(&j) => {
                let last = &infos[j].pose;
                (f.pose.position() - last.position()).length() >= min_m
                    || wrap_angle(f.pose.theta - last.theta).abs() >= min_rad
            }
        };
        if keep {
            kept.push(k);
        }
    }
    kept
}

/// Positions in `infos` of the frames a merge with `config` describes: all
/// of them thinned by motion for the automatic method, the thesis's
/// selection for its method, none for the map-only one.
pub fn frames_taking_part(infos: &[FrameInfo], config: &MergeConfig) -> Vec<usize> {
    match config.method {
        MergeMethod::Auto => thin_by_motion(infos, config.min_motion_m, config.min_turn_rad),
        MergeMethod::Thesis => select_frames(infos, &config.selection),
        MergeMethod::MapOnly => Vec::new(),
    }
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

impl MergeJob {
    /// A merge of the robots of a finished (or paused) simulation.
    /// Fails when there is nothing to merge.
    pub fn new(sim: &Simulation, config: MergeConfig) -> Result<MergeJob, String> {
        let method = config.method;
        let robots: Vec<RobotFrames> = (0..sim.robots.len())
            .map(|i| {
                let infos = frame_infos(sim, i);
                let selected = frames_taking_part(&infos, &config);
                RobotFrames {
                    name: sim.robots[i].spec.name.clone(),
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
                });
            }
        }
        // A lone robot has nothing to match: straight to the verdict (which
        // says so) without describing a single frame.
        let stage = match method {
            MergeMethod::MapOnly => Stage::Decision,
            _ if pairs.is_empty() => Stage::Decision,
            _ => Stage::Features,
        };
        Ok(MergeJob {
            camera: sim.camera.clone(),
            config,
            robots,
            pairs,
            stage,
            cursor: (0, 0),
            pair_cursor: 0,
            bags: Vec::new(),
            outcome: None,
            merged: None,
            times_ms: Default::default(),
            described: DescribedFrames::default(),
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
            Stage::Done => (1, 1),
            _ => (0, 1),
        }
    }

    /// Does up to `units` units of work (frames described, pairs checked;
    /// the proposal, decision and fusion stages are one unit each) without
    /// leaving the current stage. `sim` must be the simulation the job was
    /// made from. Returns the units done (0 once finished).
    pub fn advance(&mut self, sim: &Simulation, units: usize) -> Result<usize, String> {
        let units = units.max(1);
        match self.stage {
            Stage::Features => Ok(self.advance_features(sim, units)),
            Stage::Proposals => {
                self.propose();
                self.stage = Stage::Matching;
                Ok(1)
            }
            Stage::Matching => Ok(self.advance_matching(units)),
            Stage::Decision => {
                self.decide(sim);
                self.stage = Stage::Fusion;
                Ok(1)
            }
            Stage::Fusion => {
                self.fuse_maps(sim);
                self.stage = Stage::Done;
                Ok(1)
            }
            Stage::Done => Ok(0),
        }
    }

    /// Runs the job to the end.
    pub fn run(&mut self, sim: &Simulation) -> Result<(), String> {
        while self.advance(sim, usize::MAX)? > 0 {}
        Ok(())
    }

    fn advance_features(&mut self, sim: &Simulation, units: usize) -> usize {
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
                None => sim.robots[ri]
                    .frames
                    .frames
                    .iter()
                    .find(|f| f.index == info.index)
                    .map(|f| describe_image(sim.frame_image(f), &self.config))
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

    /// Fills every robot pair's to-do list: all pairs for the thesis's
    /// method, the vocabulary's proposals for the automatic one.
    fn propose(&mut self) {
        match self.config.method {
            MergeMethod::Thesis => {
                for p in &mut self.pairs {
                    let (na, nb) = (
                        self.robots[p.a].selected.len(),
                        self.robots[p.b].selected.len(),
                    );
                    p.todo = (0..na).flat_map(|i| (0..nb).map(move |j| (i, j))).collect();
                }
            }
            MergeMethod::Auto => {
                let sets: Vec<&Features> =
                    self.robots.iter().flat_map(|r| r.features.iter()).collect();
                let vocabulary = Vocabulary::train(
                    &sets,
                    &self.config.vocabulary,
                    self.config.seed ^ 0x766f_6361,
                );
                self.bags = self
                    .robots
                    .iter()
                    .map(|r| r.features.iter().map(|f| vocabulary.bag(f)).collect())
                    .collect();
                for p in &mut self.pairs {
                    let proposals = propose_pairs(
                        &self.bags[p.a],
                        &self.bags[p.b],
                        self.config.proposals_per_frame,
                        self.config.max_pairs,
                    );
                    p.todo = proposals.into_iter().map(|(i, j, _)| (i, j)).collect();
                }
            }
            MergeMethod::MapOnly => {}
        }
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
            // The automatic method decides on the rigid fit alone: the
            // homography (the thesis's table figure) is fitted again only
            // for a pair the user opens (`check`).
            let verify = VerifyConfig {
                homography: self.config.verify.homography
                    && self.config.method == MergeMethod::Thesis,
                ..self.config.verify
            };
            let cell = match self.check_with(a, row, b, col, &verify) {
                Some(check) => {
                    let inliers = match self.config.method {
                        MergeMethod::Thesis => check.homography_inliers,
                        _ => check.candidate.as_ref().map_or(0, |c| c.inliers),
                    };
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

    fn map<'s>(&self, sim: &'s Simulation, i: usize) -> &'s OccupancyGrid {
        sim.robots[i].mapping.map(self.config.mapper)
    }

    fn decide(&mut self, sim: &Simulation) {
        let mut outcomes = Vec::with_capacity(self.pairs.len());
        for p in &self.pairs {
            let (map_a, map_b) = (self.map(sim, p.a), self.map(sim, p.b));
            let (name_a, name_b) = (self.robots[p.a].name.clone(), self.robots[p.b].name.clone());
            let outcome = match self.config.method {
                MergeMethod::Auto => {
                    let cands: Vec<Candidate> =
                        p.cells.iter().filter_map(|c| c.candidate.clone()).collect();
                    let summary = SearchSummary {
                        proposed_pairs: p.cells.len(),
                        best_rigid_inliers: p
                            .cells
                            .iter()
                            .map(|c| c.rigid_inliers as usize)
                            .max()
                            .unwrap_or(0),
                        min_inliers: self.config.verify.min_inliers,
                    };
                    let mut d = decide_pair_after_search(
                        &cands,
                        &summary,
                        map_a,
                        map_b,
                        &self.config.verdict,
                    );
                    // Vision found nothing the maps confirm (and was not
                    // torn between two transforms): ask the maps alone.
                    if let Some(ms) = self
                        .config
                        .map_search
                        .as_ref()
                        .filter(|_| d.status != MergeStatus::Merged && !d.ambiguous)
                    {
                        let m = search_maps(map_a, map_b, ms, &self.config.verdict);
                        if m.status == MergeStatus::Merged {
                            d.status = MergeStatus::Merged;
                            d.pose = m.pose;
                            d.confidence = m.confidence;
                            d.support.clear();
                            d.reason = format!("merged: {} (vision: {})", m.reason, d.reason);
                        } else {
                            d.reason = format!("{}; {}", d.reason, m.reason);
                        }
                    }
                    PairOutcome {
                        a: name_a,
                        b: name_b,
                        status: d.status,
                        reason: d.reason,
                        confidence: d.confidence,
                        pose: d.pose.as_ref().map(pose3),
                        candidates: cands.len(),
                        support: d.support.len(),
                        best: None,
                        second: None,
                        distance: None,
                    }
                }
                MergeMethod::Thesis => {
                    let (ra, rb) = (&self.robots[p.a], &self.robots[p.b]);
                    let a_frames: Vec<FrameInfo> =
                        ra.selected.iter().map(|&k| ra.infos[k].clone()).collect();
                    let b_frames: Vec<FrameInfo> =
                        rb.selected.iter().map(|&k| rb.infos[k].clone()).collect();
                    let table: Vec<PairMatch> = p
                        .cells
                        .iter()
                        .map(|c| PairMatch {
                            a: c.row,
                            b: c.col,
                            inliers: c.inliers as usize,
                            homography: c.homography,
                            quad: c.quad,
                        })
                        .collect();
                    let t = thesis_merge(&self.camera, &a_frames, &b_frames, &table);
                    PairOutcome {
                        a: name_a,
                        b: name_b,
                        status: t.status,
                        reason: t.reason,
                        confidence: t.confidence,
                        pose: t.pose.as_ref().map(pose3),
                        candidates: table.len(),
                        support: usize::from(t.best.is_some()),
                        best: t.best.map(|(i, j)| [i, j]),
                        second: t.second.map(|(i, j)| [i, j]),
                        distance: t.distance,
                    }
                }
                MergeMethod::MapOnly => {
                    let seed = self.config.seed ^ ((p.a * 16 + p.b) as u64);
                    let o = map_only_merge(map_a, map_b, &self.config.baseline, seed);
                    PairOutcome {
                        a: name_a,
                        b: name_b,
                        status: o.status,
                        reason: o.reason,
                        confidence: o.confidence,
                        pose: o.pose.as_ref().map(pose3),
                        candidates: o.matches,
                        support: o.inliers,
                        best: None,
                        second: None,
                        distance: None,
                    }
                }
            };
            outcomes.push(outcome);
        }
        for (p, o) in self.pairs.iter_mut().zip(&outcomes) {
            p.outcome = Some(o.clone());
        }
        self.outcome = Some(self.join(outcomes));
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
            status,
            reason,
            confidence: if confidence.is_finite() {
                confidence
            } else {
                0.0
            },
            transforms,
            unjoined,
            pairs,
        }
    }

    fn fuse_maps(&mut self, sim: &Simulation) {
        let Some(outcome) = &self.outcome else {
            return;
        };
        if outcome.status != MergeStatus::Merged {
            return;
        }
        let maps: Vec<(&OccupancyGrid, Pose2)> = outcome
            .transforms
            .iter()
            .filter_map(|t| {
                let i = self.robots.iter().position(|r| r.name == t.robot)?;
                Some((
                    self.map(sim, i),
                    Pose2::new(t.pose[0], t.pose[1], t.pose[2]),
                ))
            })
            .collect();
        let config = self.map(sim, 0).config.clone();
        self.merged = Some(fuse(&maps, config));
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
