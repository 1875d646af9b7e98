//! # Merging in a lab session
//!
//! The [`Lab`] methods the page and the command line use to merge the maps
//! of the current run: start a merge with a method, advance it a little at
//! a time (the page redraws the matched-pair table between calls), look at
//! one frame pair's matches, and read the verdict with its errors against
//! the ground truth.
//!
//! Scoring is the only place the truth enters: the true pose of robot `i`'s
//! map frame in the first robot's frame is `start₀⁻¹ ∘ startᵢ` (both map
//! frames are the robots' odometry frames, whose origins are their start
//! poses).

use super::frame_spec::{describe_spec, render_spec, FrameSpec};
use super::Lab;
use crate::camera::CameraImage;
use crate::geom::{wrap_angle, Pose2};
use crate::merge::described_ahead::{describe_image, frames_to_describe};
use crate::merge::job::{
    MergeConfig, MergeJob, MergeOutcome, MergeTimes, PairOutcome, RobotGroup, RobotTransform, Stage,
};
use crate::merge::pairbudget::BudgetSummary;
use crate::merge::{MergeMethod, MergeStatus};
use crate::slam::export::{to_pgm, to_png, to_yaml, GridPicture};
use crate::slam::OccupancyGrid;
use glam::DVec2;
use serde::Serialize;

/// Where a merge stands.
#[derive(Clone, Debug, Serialize)]
pub struct MergeProgress {
    pub stage: &'static str,
    /// Units of the current stage done and in all.
    pub done: usize,
    pub total: usize,
    pub finished: bool,
}

/// Error of one estimated transform against the truth.
#[derive(Clone, Debug, Serialize)]
pub struct TransformError {
    pub robot: String,
    /// The true pose of this robot's map frame in the merged frame.
    pub truth: [f64; 3],
    pub error_m: f64,
    pub error_deg: f64,
}

/// Error of one pairwise result (b's frame in a's) against the truth.
#[derive(Clone, Debug, Serialize)]
pub struct PairError {
    pub a: String,
    pub b: String,
    pub truth: [f64; 3],
    /// Null when the pair gave no transform.
    pub error_m: Option<f64>,
    pub error_deg: Option<f64>,
}

/// A robot's current pose on the merged map.
#[derive(Clone, Debug, Serialize)]
pub struct RobotOnMap {
    pub robot: String,
    pub pose: [f64; 3],
}

/// The report's `merge` object: the fixed fields of `interfaces.md`
/// (`status`, `reason`, `confidence`, `transforms`) and what a user wants
/// next to them.
#[derive(Clone, Debug, Serialize)]
pub struct MergeReport {
    pub method: &'static str,
    pub status: MergeStatus,
    pub reason: String,
    pub confidence: f64,
    pub transforms: Vec<RobotTransform>,
    pub unjoined: Vec<String>,
    /// Every connected group of robots, each in its first robot's frame
    /// (`interfaces.md`); robot 1's group first.
    pub groups: Vec<RobotGroup>,
    pub pairs: Vec<PairOutcome>,
    /// What the pair budget did, with many robots only
    /// ([`crate::merge::pairbudget`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub budget: Option<BudgetSummary>,
    /// Scored against the ground truth (never used by the merge).
    pub errors: Vec<TransformError>,
    pub pair_errors: Vec<PairError>,
    /// Each joined robot's current SLAM pose on the merged map.
    pub robot_poses: Vec<RobotOnMap>,
    pub merged_map: Option<MergedMapInfo>,
    pub timings_ms: MergeTimes,
}

/// One frame pair's matches for display: `[x1, y1, x2, y2, homography
/// inlier (0/1), rigid inlier (0/1)]` per ratio-test match.
#[derive(Clone, Debug, Serialize)]
pub struct PairView {
    pub a: String,
    pub b: String,
    pub a_frame: usize,
    pub b_frame: usize,
    pub matches: Vec<[f64; 6]>,
    pub homography_inliers: usize,
    pub homography: Option<[[f64; 3]; 3]>,
    pub quad: Option<[[f64; 2]; 4]>,
    /// The rigid transform this pair alone gives (b's frame in a's).
    pub candidate: Option<[f64; 3]>,
    pub rigid_inliers: usize,
}

/// What the page draws: progress, the tables as they fill, the outcome.
#[derive(Clone, Debug, Serialize)]
pub struct MergeView {
    pub method: &'static str,
    pub progress: MergeProgress,
    pub robots: Vec<RobotSelection>,
    pub tables: Vec<TableView>,
    pub report: Option<MergeReport>,
}

#[derive(Clone, Debug, Serialize)]
pub struct RobotSelection {
    pub name: String,
    /// Frame indices taking part.
    pub frames: Vec<usize>,
    /// Frames captured in all.
    pub captured: usize,
}

/// One pair of robots' table, sparse: `cells` are `[row, col, inliers,
/// matches]` for the checked pairs, rows and columns positions in the
/// robots' `frames` lists.
#[derive(Clone, Debug, Serialize)]
pub struct TableView {
    pub pair: usize,
    pub a: usize,
    pub b: usize,
    pub rows: usize,
    pub cols: usize,
    pub planned: usize,
    pub cells: Vec<[u32; 4]>,
    /// The cell with the most inliers so far.
    pub best: Option<[u32; 2]>,
}

fn pose3(p: &Pose2) -> [f64; 3] {
    [p.x, p.y, p.theta]
}

pub(super) fn pose_of(p: [f64; 3]) -> Pose2 {
    Pose2::new(p[0], p[1], p[2])
}

fn round6(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

/// Transforms with their poses rounded for the report.
pub(super) fn rounded(transforms: &[RobotTransform]) -> Vec<RobotTransform> {
    transforms
        .iter()
        .map(|t| RobotTransform {
            robot: t.robot.clone(),
            pose: t.pose.map(round6),
        })
        .collect()
}

/// Position (m) and heading (deg) error of `estimate` against `truth`.
pub fn pose_error(estimate: &Pose2, truth: &Pose2) -> (f64, f64) {
    (
        (estimate.position() - truth.position()).length(),
        wrap_angle(estimate.theta - truth.theta).to_degrees(),
    )
}

/// The error of transform `t` against `truth` (the true pose of its map
/// frame), rounded as the report gives it.
pub(super) fn transform_error(t: &RobotTransform, truth: &Pose2) -> TransformError {
    let (m, deg) = pose_error(&pose_of(t.pose), truth);
    TransformError {
        robot: t.robot.clone(),
        truth: pose3(truth).map(round6),
        error_m: round6(m),
        error_deg: round6(deg),
    }
}

impl Lab {
    /// Starts merging the current run's maps with `method`, replacing any
    /// earlier merge. The run may be finished or paused.
    pub fn merge_start(&mut self, method: MergeMethod) -> Result<MergeProgress, String> {
        if let Some(sim) = &mut self.sim {
            sim.settle_maps();
        }
        let sim = self
            .simulation()
            .ok_or("nothing has run yet: run the robots before merging")?;
        if sim.steps() == 0 {
            return Err("the robots have not moved yet: run them before merging".into());
        }
        let config = MergeConfig::new(method, sim.scenario.seed);
        let mut job = MergeJob::new(sim, config)?;
        job.adopt_described(std::mem::take(&mut self.described));
        self.merge = Some(job);
        self.merge_progress()
    }

    /// The frames (robot, frame index) a merge with `method` would describe
    /// now and that no other thread has described yet
    /// ([`crate::merge::described_ahead`]); empty before a run.
    pub fn frames_to_describe(&self, method: MergeMethod) -> Vec<(usize, usize)> {
        let Some(sim) = self.simulation() else {
            return Vec::new();
        };
        let config = MergeConfig::new(method, sim.scenario.seed);
        frames_to_describe(sim, &config)
            .into_iter()
            .filter(|&(r, i)| !self.described.contains(&config, r, i))
            .collect()
    }

    /// Whether robot `robot` of this run holds frame `index` now (frames
    /// the store thinned are gone: see [`crate::camera::capture`]).
    pub fn has_frame(&self, robot: usize, index: usize) -> bool {
        self.simulation()
            .and_then(|sim| sim.robots.get(robot))
            .is_some_and(|r| r.frames.holds(index))
    }

    /// Frame `index` of robot `robot` of this run, for another lab of the
    /// same scenario to describe.
    pub fn frame_spec(&self, robot: usize, index: usize) -> Result<FrameSpec, String> {
        let sim = self.simulation().ok_or("nothing has run yet")?;
        FrameSpec::of(sim, robot, index)
    }

    /// Describes a frame of *another* lab's run of this same scenario, as a
    /// merge with `method` would (this lab's own run is not touched; one is
    /// started, at time 0, if there is none, for its world and textures).
    pub fn describe_frame_spec(
        &mut self,
        spec: &FrameSpec,
        method: MergeMethod,
    ) -> Result<crate::surf::Features, String> {
        let sim = self.start().map_err(|e| e.to_string())?;
        let config = MergeConfig::new(method, sim.scenario.seed);
        Ok(describe_spec(sim, spec, &config))
    }

    /// Renders a frame of *another* lab's run of this same scenario (see
    /// [`Lab::describe_frame_spec`]), for that lab to describe with
    /// [`Lab::describe_rendered`].
    pub fn render_frame_spec(&mut self, spec: &FrameSpec) -> Result<CameraImage, String> {
        let sim = self.start().map_err(|e| e.to_string())?;
        Ok(render_spec(sim, spec))
    }

    /// Describes frame `index` of robot `robot` of this run from its grey
    /// pixels, rendered by another lab of the same scenario
    /// ([`Lab::render_frame_spec`]), and keeps the features for the next
    /// merge with `method`. Returns false, keeping nothing, when the store
    /// has thinned the frame since it was handed out; fails if the frame
    /// was never captured or `gray` is not the camera's size.
    pub fn describe_rendered(
        &mut self,
        robot: usize,
        index: usize,
        method: MergeMethod,
        gray: Vec<u8>,
    ) -> Result<bool, String> {
        let sim = self.simulation().ok_or("nothing has run yet")?;
        if !frame_held(sim, robot, index)? {
            return Ok(false);
        }
        let cam = &sim.scenario.camera;
        let (width, height) = (cam.width, cam.height);
        if gray.len() != (width * height) as usize {
            return Err(format!(
                "{} grey bytes for a {width} x {height} camera ({} expected)",
                gray.len(),
                width * height
            ));
        }
        let config = MergeConfig::new(method, sim.scenario.seed);
        let img = CameraImage {
            width,
            height,
            gray,
            rgba: None,
        };
        self.store_described(robot, index, method, describe_image(img, &config))
    }

    /// Keeps features another lab described for frame `index` of robot
    /// `robot` of this run, for the next merge with `method` to take.
    /// Returns false, keeping nothing, when the store has thinned the frame
    /// since it was handed out (no merge will ask for it); fails if the
    /// frame was never captured.
    pub fn store_described(
        &mut self,
        robot: usize,
        index: usize,
        method: MergeMethod,
        features: crate::surf::Features,
    ) -> Result<bool, String> {
        let sim = self.simulation().ok_or("nothing has run yet")?;
        if !frame_held(sim, robot, index)? {
            return Ok(false);
        }
        let config = MergeConfig::new(method, sim.scenario.seed);
        self.described.insert(&config, robot, index, features);
        Ok(true)
    }

    /// [`Lab::describe_frame_spec`], packed in a flat `f32` array for
    /// another thread ([`crate::merge::described_ahead::encode`]).
    pub fn describe_frame_spec_packed(
        &mut self,
        spec: &FrameSpec,
        method: MergeMethod,
    ) -> Result<Vec<f32>, String> {
        let f = self.describe_frame_spec(spec, method)?;
        Ok(crate::merge::described_ahead::encode(&f))
    }

    /// [`Lab::store_described`] of features packed by
    /// [`Lab::describe_frame_spec_packed`] on another thread.
    pub fn store_described_packed(
        &mut self,
        robot: usize,
        index: usize,
        method: MergeMethod,
        packed: &[f32],
    ) -> Result<bool, String> {
        let f = crate::merge::described_ahead::decode(packed)?;
        self.store_described(robot, index, method, f)
    }

    /// Where the merge stands.
    pub fn merge_progress(&self) -> Result<MergeProgress, String> {
        let job = self.merge.as_ref().ok_or("no merge has been started")?;
        let (done, total) = job.progress();
        Ok(MergeProgress {
            stage: job.stage().name(),
            done,
            total,
            finished: job.is_done(),
        })
    }

    /// Does up to `units` units of the current stage (frames described or
    /// pairs checked); see [`MergeJob::advance`].
    pub fn merge_advance(&mut self, units: usize) -> Result<MergeProgress, String> {
        let clock = self.clock;
        let (Some(job), Some(sim)) = (self.merge.as_mut(), self.sim.as_ref()) else {
            return Err("no merge has been started".into());
        };
        let stage = job.stage();
        let t0 = clock.map_or(0.0, |now| now());
        job.advance(sim, units)?;
        if let Some(now) = clock {
            let dt = now() - t0;
            match stage {
                Stage::Features => job.times_ms.features += dt,
                Stage::Proposals | Stage::Matching => job.times_ms.matching += dt,
                _ => job.times_ms.merge += dt,
            }
        }
        self.merge_progress()
    }

    /// Runs the merge to the end.
    pub fn merge_finish(&mut self) -> Result<MergeProgress, String> {
        while !self.merge_progress()?.finished {
            self.merge_advance(usize::MAX)?;
        }
        self.merge_progress()
    }

    /// The verdict, transforms and errors, once the merge is done.
    pub fn merge_report(&self) -> Option<MergeReport> {
        let job = self.merge.as_ref()?;
        let sim = self.simulation()?;
        let outcome: &MergeOutcome = job.outcome()?;
        let starts: Vec<Pose2> = sim.robots.iter().map(|r| r.spec.start_pose()).collect();
        let index = |name: &str| sim.robots.iter().position(|r| r.spec.name == name);
        let truth_in_first = |i: usize| starts[0].inverse().compose(&starts[i]);
        let errors = outcome
            .transforms
            .iter()
            .filter_map(|t| Some(transform_error(t, &truth_in_first(index(&t.robot)?))))
            .collect();
        let pair_errors = outcome
            .pairs
            .iter()
            .filter_map(|p| {
                let (a, b) = (index(&p.a)?, index(&p.b)?);
                let truth = starts[a].inverse().compose(&starts[b]);
                let e = p.pose.map(|q| pose_error(&pose_of(q), &truth));
                Some(PairError {
                    a: p.a.clone(),
                    b: p.b.clone(),
                    truth: pose3(&truth).map(round6),
                    error_m: e.map(|e| round6(e.0)),
                    error_deg: e.map(|e| round6(e.1)),
                })
            })
            .collect();
        let robot_poses = outcome
            .transforms
            .iter()
            .filter_map(|t| {
                let r = &sim.robots[index(&t.robot)?];
                let on_map = pose_of(t.pose).compose(&r.mapping.estimate());
                Some(RobotOnMap {
                    robot: t.robot.clone(),
                    pose: pose3(&on_map).map(round6),
                })
            })
            .collect();
        Some(MergeReport {
            method: job.config.method.name(),
            status: outcome.status,
            reason: outcome.reason.clone(),
            confidence: round6(outcome.confidence),
            transforms: rounded(&outcome.transforms),
            unjoined: outcome.unjoined.clone(),
            groups: outcome
                .groups
                .iter()
                .map(|g| RobotGroup {
                    transforms: rounded(&g.transforms),
                    ..g.clone()
                })
                .collect(),
            pairs: outcome.pairs.clone(),
            budget: outcome.budget.clone(),
            errors,
            pair_errors,
            robot_poses,
            merged_map: job.merged_map().map(map_info),
            timings_ms: job.times_ms,
        })
    }

    /// Everything the page's merge panel draws.
    pub fn merge_view(&self) -> Result<MergeView, String> {
        let job = self.merge.as_ref().ok_or("no merge has been started")?;
        let robots = job
            .robots
            .iter()
            .map(|r| RobotSelection {
                name: r.name.clone(),
                frames: r.selected.iter().map(|&k| r.infos[k].index).collect(),
                captured: r.infos.len(),
            })
            .collect();
        let tables = job
            .pairs
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let best = p
                    .cells
                    .iter()
                    .filter(|c| c.inliers > 0)
                    .max_by_key(|c| (c.inliers, std::cmp::Reverse((c.row, c.col))))
                    .map(|c| [c.row as u32, c.col as u32]);
                TableView {
                    pair: k,
                    a: p.a,
                    b: p.b,
                    rows: job.robots[p.a].selected.len(),
                    cols: job.robots[p.b].selected.len(),
                    planned: p.todo.len(),
                    cells: p
                        .cells
                        .iter()
                        .map(|c| [c.row as u32, c.col as u32, c.inliers, c.matches])
                        .collect(),
                    best,
                }
            })
            .collect();
        Ok(MergeView {
            method: job.config.method.name(),
            progress: self.merge_progress()?,
            robots,
            tables,
            report: self.merge_report(),
        })
    }

    /// The matches of one checked frame pair: robot pair `pair`, `row` and
    /// `col` positions in the two robots' frame lists.
    pub fn merge_pair_view(&self, pair: usize, row: usize, col: usize) -> Result<PairView, String> {
        let job = self.merge.as_ref().ok_or("no merge has been started")?;
        let p = job
            .pairs
            .get(pair)
            .ok_or_else(|| format!("no robot pair {pair}"))?;
        let check = job
            .check(p.a, row, p.b, col)
            .ok_or_else(|| format!("frame pair ({row}, {col}) has not been described yet"))?;
        let (ra, rb) = (&job.robots[p.a], &job.robots[p.b]);
        let (fa, fb) = (&ra.features[row], &rb.features[col]);
        let matches = check
            .matches
            .iter()
            .enumerate()
            .map(|(k, m)| {
                let (ka, kb) = (&fa.keypoints[m.query], &fb.keypoints[m.train]);
                let h = check
                    .homography_inlier_mask
                    .get(k)
                    .copied()
                    .unwrap_or(false);
                let r = check.rigid_inlier_mask.get(k).copied().unwrap_or(false);
                [
                    ka.x as f64,
                    ka.y as f64,
                    kb.x as f64,
                    kb.y as f64,
                    f64::from(u8::from(h)),
                    f64::from(u8::from(r)),
                ]
            })
            .collect();
        Ok(PairView {
            a: ra.name.clone(),
            b: rb.name.clone(),
            a_frame: ra.infos[ra.selected[row]].index,
            b_frame: rb.infos[rb.selected[col]].index,
            matches,
            homography_inliers: check.homography_inliers,
            homography: check.homography.map(|h| h.0),
            quad: check.quad,
            candidate: check.candidate.as_ref().map(|c| pose3(&c.pose)),
            rigid_inliers: check.candidate.as_ref().map_or(0, |c| c.inliers),
        })
    }

    fn merged(&self) -> Result<&OccupancyGrid, String> {
        let job = self.merge.as_ref().ok_or("no merge has been started")?;
        match job.outcome() {
            None => Err("the merge has not finished yet".into()),
            Some(o) if o.status != MergeStatus::Merged => {
                Err(format!("there is no merged map: {}", o.reason))
            }
            Some(_) => job
                .merged_map()
                .ok_or_else(|| "the merged map is not ready".into()),
        }
    }

    pub fn merged_pgm(&self) -> Result<Vec<u8>, String> {
        Ok(to_pgm(self.merged()?))
    }

    pub fn merged_png(&self) -> Result<Vec<u8>, String> {
        to_png(self.merged()?)
    }

    pub fn merged_yaml(&self, image: &str) -> Result<String, String> {
        Ok(to_yaml(self.merged()?, image))
    }

    /// The merged map as RGBA pixels fitted to `width × height`, with each
    /// joined robot's SLAM path (in the merged frame) in its colour.
    pub fn merged_rgba(&self, width: u32, height: u32) -> Result<Vec<u8>, String> {
        let g = self.merged()?;
        let sim = self.simulation().ok_or("nothing has run yet")?;
        let job = self.merge.as_ref().ok_or("no merge has been started")?;
        let outcome = job.outcome().ok_or("the merge has not finished yet")?;
        picture(sim, g, &outcome.transforms, width, height)
    }
}

/// The grid `g` fitted to `width × height` as RGBA pixels, with the SLAM
/// path of each robot of `transforms` (its map frame placed at its pose in
/// `g`'s frame) in the robot's colour, and a dot where it stands.
pub(super) fn picture(
    sim: &crate::sim::Simulation,
    g: &OccupancyGrid,
    transforms: &[RobotTransform],
    width: u32,
    height: u32,
) -> Result<Vec<u8>, String> {
    let mut pic = GridPicture::new(g, width, height)?;
    if g.width() == 0 {
        return Ok(pic.into_rgba());
    }
    for t in transforms {
        let Some(i) = sim.robots.iter().position(|r| r.spec.name == t.robot) else {
            continue;
        };
        let frame = pose_of(t.pose);
        let est = sim.robots[i].mapping.estimates();
        let path: Vec<DVec2> = est
            .iter()
            .map(|p| frame.transform_point(p.position()))
            .collect();
        let [r, gr, b] = crate::palette::robot_colour(i);
        pic.polyline(&path, [r, gr, b, 220], 1.5);
        if let Some(last) = est.last() {
            pic.dot(frame.compose(last).position(), 4.0, [r, gr, b, 220]);
        }
    }
    Ok(pic.into_rgba())
}

/// Size, resolution and origin of the merged map.
#[derive(Clone, Debug, Serialize)]
pub struct MergedMapInfo {
    pub width: usize,
    pub height: usize,
    pub resolution_m: f64,
    /// Where cell (0, 0)'s lower-left corner lies in the merged frame.
    pub origin_m: [f64; 2],
    pub occupied_cells: usize,
}

fn map_info(g: &OccupancyGrid) -> MergedMapInfo {
    let o = g.origin_m();
    MergedMapInfo {
        width: g.width(),
        height: g.height(),
        resolution_m: g.resolution_m(),
        origin_m: [o.x, o.y],
        occupied_cells: g.occupied_count(),
    }
}

/// Whether robot `robot` of `sim` holds frame `index`: true if stored,
/// false if captured and thinned since; an error if there is no such robot
/// or the frame was never captured.
fn frame_held(sim: &crate::sim::Simulation, robot: usize, index: usize) -> Result<bool, String> {
    let store = &sim
        .robots
        .get(robot)
        .ok_or_else(|| format!("no robot {robot}"))?
        .frames;
    if store.holds(index) {
        Ok(true)
    } else if store.thinned(index) {
        Ok(false)
    } else {
        Err(format!("robot {robot} has no frame {index}"))
    }
}
