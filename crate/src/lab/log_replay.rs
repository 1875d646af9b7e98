//! # The log replay session: what the CLI's `run-log` and "Your log…" drive
//!
//! Holds a recorded log's scans — a CARMEN log's ([`crate::formats::carmen`])
//! or a ROS bag's ([`super::bag_file`]), in the same canonical form — the
//! stretch of them to replay (`from..=to`, positions among the log's laser
//! records), and the [`LogSlam`] fed with them in order, a few at a time (so
//! a page can animate it and a CLI can time it). A bag may carry a ground
//! truth: it is kept here, apart from the SLAM, and only scores the result
//! (the report's `ground_truth` and `ate_m`). While it runs, the page
//! reads its view ([`LogReplay::view`]: the paths and loop closures so far)
//! and the live map ([`LogReplay::draw_live`]); at the end it draws the map
//! at the final poses and writes the report of `docs/interfaces.md`
//! ("Real laser logs: run-log").
//!
//! Every map it hands out is cut to what the scans saw, plus
//! [`CROP_MARGIN_M`] around it ([`OccupancyGrid::cropped_to_known`]): the
//! grid grows by the laser's full reach around every pose, so uncut it
//! would carry a wide band of unknown cells no beam ever touched.
//!
//! ## Looking back at an earlier moment
//!
//! A page that lets the user drag a timeline back to scan `k` must show
//! what the SLAM believed *then*: the map of scans `0..k` drawn at the
//! poses they had after scan `k`, and the loop closures found by then —
//! not today's poses cut short. Between two loop closures the pose graph
//! only grows (a new key node is appended, the others keep their values);
//! only an accepted closure (and the settling at the end) moves nodes that
//! were there before. So the session keeps one *version* of the key nodes
//! per such move: the nodes as they were just before it, and the number of
//! scans replayed when it happened. Scan `j`'s pose at moment `k` is then
//! its key's node in the first version that ends after `k` (or in the
//! graph now, past the last move), composed with the scan's pose relative
//! to its key, which changes only in the smoothing at the end (the session
//! keeps it from before, for the moments before the end). The versions
//! cost one copy of the key nodes per loop closure ([`LogReplay::view_at`],
//! [`LogReplay::draw_at`]).

use crate::formats::bag::recording::{BagLog, Picked};
use crate::formats::carmen::{parse_bytes, LogError};
use crate::geom::{wrap_angle, Pose2};
use crate::slam::eval::benchmark_relations::{
    parse_relations, score_relations, Relation, RelationScore,
};
use crate::slam::eval::relation_check::{check_relations, RelationCheck, Witnesses};
use crate::slam::eval::scoring::{ate_aligned_m, best_fit};
use crate::slam::eval::verified::VerifyConfig;
use crate::slam::export::{self, MapInfo};
use crate::slam::grid::OccupancyGrid;
use crate::slam::logs::logslam::{laser_points, ClosureInfo, LogSlam, LogSlamConfig, LogSlamStats};
use crate::slam::logs::LogScan;
use serde::Serialize;

/// Where a log came from, for its report.
#[derive(Clone, Debug, PartialEq)]
pub enum LogSource {
    Carmen {
        params: usize,
        odometry_records: usize,
        skipped: Vec<(String, usize)>,
    },
    Bag(Box<BagSource>),
}

/// A bag's part of the report: the file, its container, what was lost,
/// and what was picked from it and why.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BagSource {
    pub file: String,
    pub container: String,
    pub compression: Vec<String>,
    pub lost: Vec<String>,
    pub picked: Picked,
}

/// A replay of one log.
pub struct LogReplay {
    scans: Vec<LogScan>,
    source: LogSource,
    /// Ground truth `(time s, pose)` (a bag's), never given to the SLAM.
    truth: Vec<(f64, Pose2)>,
    /// A benchmark's relations to score against (`run-log --relations`),
    /// never given to the SLAM.
    relations: Vec<Relation>,
    /// Whether the report checks the relations against their own scans
    /// and the wheels (`run-log --check-relations`).
    check_relations: bool,
    pub slam: LogSlam,
    from: usize,
    to: usize,
    next: usize,
    map: Option<OccupancyGrid>,
    /// The map of the scans replayed so far at their current poses, drawn
    /// by [`LogReplay::draw_live`] (or at an earlier moment's poses, by
    /// [`LogReplay::draw_at`]).
    live: Option<OccupancyGrid>,
    /// The key nodes before each move of the graph, oldest first
    /// ("Looking back at an earlier moment" above).
    versions: Vec<NodeVersion>,
    /// The key nodes as they are now, kept in step with the graph.
    nodes_now: Vec<Pose2>,
    /// Each scan's pose relative to its key as the replay placed it, kept
    /// when the smoothing at the end replaces it (empty until then).
    relatives_then: Vec<Pose2>,
    /// For each loop closure, how many scans were replayed when it was
    /// accepted.
    closed_after: Vec<usize>,
}

/// The pose graph's key nodes as they were for every moment (scans
/// replayed) before `until`.
struct NodeVersion {
    until: usize,
    nodes: Vec<Pose2>,
}

/// The replay so far, for a page that animates it.
#[derive(Serialize)]
pub struct ReplayView {
    /// Scans replayed, of `total`.
    pub done: usize,
    pub total: usize,
    /// Each replayed scan's odometry, flat `[x, y, theta, ...]` (the first
    /// scan at its odometry pose); empty when the log has none.
    pub odometry: Vec<f64>,
    /// Each replayed scan's current SLAM pose, flat, same frame.
    pub poses: Vec<f64>,
    /// Each loop closure found so far.
    pub closures: Vec<ClosureView>,
}

/// A loop closure as the page draws it: the segment between its two key
/// scans' current poses.
#[derive(Serialize)]
pub struct ClosureView {
    /// `[x1, y1, x2, y2]`.
    pub segment: [f64; 4],
    pub from_scan: usize,
    pub to_scan: usize,
    pub score: f64,
}

impl ClosureView {
    /// Closure `c` drawn between its keys' poses in `nodes`.
    fn between(c: &ClosureInfo, nodes: &[Pose2]) -> ClosureView {
        let node = |k: usize| nodes.get(k).copied().unwrap_or_default();
        let (a, b) = (node(c.from_key), node(c.to_key));
        ClosureView {
            segment: [a.x, a.y, b.x, b.y],
            from_scan: c.from_scan,
            to_scan: c.to_scan,
            score: c.score,
        }
    }
}

/// One scan of the report.
#[derive(Serialize)]
pub struct ScanReport {
    pub index: usize,
    pub time: f64,
    /// `null` when the log has no odometry.
    pub odometry: Option<[f64; 3]>,
    pub pose: [f64; 3],
}

/// The ground truth beside the SLAM path, for a page to draw: the truth
/// at each replayed scan's time laid onto the SLAM's frame by the rigid
/// fit the ATE is scored after, and each scan's position error.
#[derive(Serialize)]
pub struct TruthView {
    /// `[x, y, theta, ...]` in the SLAM's frame, one per scan the truth
    /// covers.
    pub poses: Vec<f64>,
    /// `[time s, error m, ...]` of those scans.
    pub errors: Vec<f64>,
    /// The ATE over them (m).
    pub ate_m: f64,
}

/// One ground-truth pose of the report.
#[derive(Serialize)]
pub struct TruthReport {
    pub time: f64,
    pub pose: [f64; 3],
}

/// The `run-log` report.
#[derive(Serialize)]
pub struct LogReport {
    pub frame: &'static str,
    pub laser_records: usize,
    pub from: usize,
    pub to: usize,
    pub scans: Vec<ScanReport>,
    pub map: MapInfo,
    pub loop_closures: Vec<ClosureInfo>,
    pub slam: LogSlamStats,
    pub params: usize,
    pub odometry_records: usize,
    pub skipped: Vec<(String, usize)>,
    /// A bag's file, container, what was lost and what was picked.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bag: Option<BagSource>,
    /// The ground truth read from a bag, and the SLAM's ATE against it
    /// (RMSE of position after the best rigid fit, the truth interpolated
    /// at each scan's time; m), over `ate_scans` scans.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ground_truth: Option<Vec<TruthReport>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ate_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ate_scans: Option<usize>,
    /// The errors against a benchmark's relations (`--relations`), with
    /// every relation's error and the worst ones.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relations: Option<RelationScore>,
    /// Those relations checked against their own scans and the wheel
    /// odometry (`--check-relations`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relation_check: Option<RelationCheck>,
    pub timings_ms: serde_json::Value,
}

/// The unknown margin (m) kept around the known cells of a log's map.
pub const CROP_MARGIN_M: f64 = 1.0;

/// `grid` cut to its known cells plus [`CROP_MARGIN_M`].
fn cropped(grid: OccupancyGrid) -> OccupancyGrid {
    let margin = (CROP_MARGIN_M / grid.resolution_m()).ceil() as usize;
    grid.cropped_to_known(margin)
}

/// What the report's `frame` says.
pub const FRAME: &str =
    "log: the log's own odometry frame (the first scan replayed is placed at its odometry pose)";

impl LogReplay {
    /// Parses a CARMEN log (plain or gzip-compressed) and prepares to
    /// replay all of it.
    pub fn new(bytes: &[u8]) -> Result<LogReplay, LogError> {
        let log = parse_bytes(bytes)?;
        let source = LogSource::Carmen {
            params: log.params.len(),
            odometry_records: log.odometry_records,
            skipped: log.skipped,
        };
        Ok(LogReplay::of(log.scans, true, Vec::new(), source))
    }

    /// A bag's laser log ([`super::bag_file::BagFile::replay`]).
    pub fn from_bag(log: BagLog, source: BagSource) -> LogReplay {
        LogReplay::of(
            log.scans,
            log.has_odometry,
            log.truth,
            LogSource::Bag(Box::new(source)),
        )
    }

    fn of(
        scans: Vec<LogScan>,
        has_odometry: bool,
        truth: Vec<(f64, Pose2)>,
        source: LogSource,
    ) -> LogReplay {
        let config = LogSlamConfig {
            odometry: has_odometry,
            ..LogSlamConfig::default()
        };
        LogReplay {
            to: scans.len().saturating_sub(1),
            scans,
            source,
            truth,
            relations: Vec::new(),
            check_relations: false,
            slam: LogSlam::new(config),
            from: 0,
            next: 0,
            map: None,
            live: None,
            versions: Vec::new(),
            nodes_now: Vec::new(),
            relatives_then: Vec::new(),
            closed_after: Vec::new(),
        }
    }

    /// Changes the SLAM's settings (examples and tests measure them);
    /// before the first step only. Whether the log has odometry is the
    /// log's, not a setting.
    pub fn configure(&mut self, change: impl FnOnce(&mut LogSlamConfig)) -> Result<(), String> {
        if self.next > 0 {
            return Err("the replay has started: configure it first".into());
        }
        let mut config = self.slam.config.clone();
        change(&mut config);
        config.odometry = self.slam.config.odometry;
        self.slam = LogSlam::new(config);
        Ok(())
    }

    /// Number of laser records in the log.
    pub fn laser_records(&self) -> usize {
        self.scans.len()
    }

    /// Every scan of the log (canonical).
    pub fn scans(&self) -> &[LogScan] {
        &self.scans
    }

    /// What was picked from a bag, and why (`None` for a CARMEN log).
    pub fn picked(&self) -> Option<&Picked> {
        match &self.source {
            LogSource::Bag(b) => Some(&b.picked),
            LogSource::Carmen { .. } => None,
        }
    }

    /// The ground truth `(time s, pose)` read from a bag (empty without);
    /// for scoring only.
    pub fn truth(&self) -> &[(f64, Pose2)] {
        &self.truth
    }

    /// Whether the log has odometry.
    pub fn has_odometry(&self) -> bool {
        self.slam.config.odometry
    }

    /// Replays only laser records `from..=to` (`to` clipped to the last);
    /// before the first step only.
    pub fn set_range(&mut self, from: usize, to: Option<usize>) -> Result<(), String> {
        if self.next > 0 {
            return Err("the replay has started: set the range first".into());
        }
        let last = self.scans.len() - 1;
        let to = to.unwrap_or(last).min(last);
        if from > to {
            return Err(format!(
                "--from {from} is past --to {to} (the log has {} laser records, 0 to {last})",
                last + 1
            ));
        }
        self.from = from;
        self.to = to;
        Ok(())
    }

    /// Replays up to `n` more scans; returns how many are left.
    pub fn step(&mut self, n: usize) -> usize {
        let mut done = 0;
        while done < n && self.from + self.next <= self.to {
            let scan = &self.scans[self.from + self.next];
            let closures = self.slam.closures.len();
            self.slam.add_scan(scan);
            self.next += 1;
            done += 1;
            let closed = self.slam.closures.len() - closures;
            if closed > 0 {
                self.keep_version();
                self.closed_after
                    .extend(std::iter::repeat_n(self.next, closed));
            } else {
                let have = self.nodes_now.len();
                let added = self.slam.graph.nodes.get(have..).unwrap_or_default();
                self.nodes_now.extend_from_slice(added);
            }
        }
        self.remaining()
    }

    /// Keeps the key nodes as they were before the graph moved (a loop
    /// closure, the settling at the end), for moments before now.
    fn keep_version(&mut self) {
        let before = std::mem::replace(&mut self.nodes_now, self.slam.graph.nodes.clone());
        self.versions.push(NodeVersion {
            until: self.next,
            nodes: before,
        });
    }

    /// The laser records replayed so far (a page draws the map as it grows
    /// from them with [`LogSlam::build_map`]).
    pub fn replayed(&self) -> &[crate::slam::logs::LogScan] {
        &self.scans[self.from..self.from + self.next]
    }

    pub fn remaining(&self) -> usize {
        self.to + 1 - self.from - self.next
    }

    /// Settles the pose graph and draws the map at the final poses.
    pub fn finish(&mut self) -> Result<(), String> {
        self.step(usize::MAX);
        if self.map.is_some() {
            return Ok(());
        }
        if self.slam.config.smooth_keys > 0 {
            self.relatives_then = self.slam.scans.iter().map(|s| s.relative).collect();
        }
        self.slam.finish(&self.scans[self.from..=self.to])?;
        self.keep_version();
        let scans = &self.scans[self.from..=self.to];
        self.map = Some(cropped(self.slam.build_map(scans)));
        Ok(())
    }

    /// The map drawn by [`LogReplay::finish`].
    pub fn map(&self) -> Result<&OccupancyGrid, String> {
        self.map
            .as_ref()
            .ok_or_else(|| "the replay has not finished: no map yet".to_string())
    }

    /// The report; `timings_ms` is passed through as given.
    pub fn report(&self, timings_ms: serde_json::Value) -> Result<LogReport, String> {
        let grid = self.map()?;
        let poses = self.slam.poses();
        let scans = self
            .slam
            .scans
            .iter()
            .zip(&poses)
            .map(|(s, p)| ScanReport {
                index: s.index,
                time: s.time,
                odometry: self.has_odometry().then_some([
                    s.odometry.x,
                    s.odometry.y,
                    s.odometry.theta,
                ]),
                pose: [p.x, p.y, p.theta],
            })
            .collect();
        let (params, odometry_records, skipped, bag) = match &self.source {
            LogSource::Carmen {
                params,
                odometry_records,
                skipped,
            } => (*params, *odometry_records, skipped.clone(), None),
            LogSource::Bag(b) => (0, 0, Vec::new(), Some((**b).clone())),
        };
        let (ground_truth, ate) = if self.truth.is_empty() {
            (None, None)
        } else {
            let rows = self
                .truth
                .iter()
                .map(|(t, p)| TruthReport {
                    time: *t,
                    pose: [p.x, p.y, p.theta],
                })
                .collect();
            (Some(rows), self.ate(&poses))
        };
        let relations = (!self.relations.is_empty()).then(|| self.relation_score());
        let relation_check = match &relations {
            Some(score) if self.check_relations => Some(self.check_against(score)),
            _ => None,
        };
        Ok(LogReport {
            frame: FRAME,
            laser_records: self.scans.len(),
            from: self.from,
            to: self.to,
            scans,
            map: MapInfo::of(grid),
            loop_closures: self.slam.closures.clone(),
            slam: self.slam.stats.clone(),
            params,
            odometry_records,
            skipped,
            bag,
            ground_truth,
            ate_m: ate.map(|a| a.0),
            ate_scans: ate.map(|a| a.1),
            relations,
            relation_check,
            timings_ms,
        })
    }

    /// The relations of a benchmark file (Kümmerle et al. 2009) to score
    /// the replay against; a malformed file is an error naming its line.
    pub fn set_relations(&mut self, text: &str) -> Result<usize, String> {
        self.relations = parse_relations(text).map_err(|e| format!("relations: {e}"))?;
        Ok(self.relations.len())
    }

    /// Whether the report checks the relations against their own scans
    /// and the wheels ([`crate::slam::eval::relation_check`]; it aligns
    /// two scans per relation, a few seconds for a benchmark log).
    pub fn set_check_relations(&mut self, on: bool) {
        self.check_relations = on;
    }

    /// The relations set checked against their own scans and the wheel
    /// odometry ([`crate::slam::eval::relation_check`]); `None` without
    /// relations.
    pub fn relation_check(&self) -> Option<RelationCheck> {
        (!self.relations.is_empty()).then(|| self.check_against(&self.relation_score()))
    }

    /// [`LogReplay::relation_check`] of the relations `score` matched.
    fn check_against(&self, score: &RelationScore) -> RelationCheck {
        let scans = &self.scans[self.from..];
        let lasers = self.laser_poses();
        let wheels: Vec<Pose2> = self
            .slam
            .scans
            .iter()
            .zip(scans)
            .map(|(e, s)| e.odometry.compose(&s.laser_offset))
            .collect();
        let noise = self.slam.stats.fusion_noise;
        let seen = Witnesses {
            lasers: &lasers,
            wheels: match noise {
                Some(n) if self.has_odometry() => {
                    Some((&wheels[..], [n.odometry_step[0], n.odometry_step[1]]))
                }
                _ => None,
            },
        };
        // Every return within the matching range, in the laser's frame.
        let range_m = self.slam.config.match_range_m;
        let points = |k: usize| laser_points(&scans[k], range_m);
        check_relations(
            &self.relations,
            score,
            &seen,
            points,
            &VerifyConfig::default(),
        )
    }

    /// Each replayed scan's laser pose: the robot's pose composed with the
    /// laser's offset on it.
    fn laser_poses(&self) -> Vec<Pose2> {
        self.slam
            .poses()
            .iter()
            .zip(&self.scans[self.from..])
            .map(|(p, s)| p.compose(&s.laser_offset))
            .collect()
    }

    /// The replay so far scored against the relations set (empty score
    /// without). A relation relates two scans, so a scan's pose is the
    /// laser's when it took the scan: the robot's pose composed with the
    /// laser's offset on the robot.
    pub fn relation_score(&self) -> RelationScore {
        let times: Vec<f64> = self.slam.scans.iter().map(|s| s.time).collect();
        score_relations(&times, &self.laser_poses(), &self.relations)
    }

    /// The ground truth beside the SLAM path so far (`None` without one,
    /// or before a scan the truth covers).
    pub fn truth_view(&self) -> Option<TruthView> {
        if self.truth.is_empty() {
            return None;
        }
        let poses = self.slam.poses();
        let mut pairs = Vec::new();
        for (s, p) in self.slam.scans.iter().zip(&poses) {
            if let Some(t) = truth_at(&self.truth, s.time) {
                pairs.push((s.time, *p, t));
            }
        }
        let est: Vec<_> = pairs.iter().map(|(_, p, _)| p.position()).collect();
        let truth: Vec<_> = pairs.iter().map(|(_, _, t)| t.position()).collect();
        let fit = best_fit(&est, &truth)?;
        let back = fit.inverse();
        let mut view = TruthView {
            poses: Vec::with_capacity(3 * pairs.len()),
            errors: Vec::with_capacity(2 * pairs.len()),
            ate_m: 0.0,
        };
        let mut sum = 0.0;
        for (time, p, t) in &pairs {
            let laid = back.compose(t);
            view.poses.extend([laid.x, laid.y, laid.theta]);
            let e = (fit.transform_point(p.position()) - t.position()).length();
            view.errors.extend([*time, e]);
            sum += e * e;
        }
        view.ate_m = (sum / pairs.len() as f64).sqrt();
        Some(view)
    }

    /// The SLAM's ATE against the ground truth (m, after the best rigid
    /// fit) and the number of scans it was taken over: those within the
    /// truth's time span, the truth interpolated at each.
    fn ate(&self, poses: &[Pose2]) -> Option<(f64, usize)> {
        let mut est = Vec::new();
        let mut truth = Vec::new();
        for (s, p) in self.slam.scans.iter().zip(poses) {
            if let Some(t) = truth_at(&self.truth, s.time) {
                est.push(*p);
                truth.push(t);
            }
        }
        (!est.is_empty()).then(|| (ate_aligned_m(&Pose2::IDENTITY, &est, &truth), est.len()))
    }

    /// The map as a binary PGM (ROS map_server).
    pub fn map_pgm(&self) -> Result<Vec<u8>, String> {
        Ok(export::to_pgm(self.map()?))
    }

    /// The map as a PNG.
    pub fn map_png(&self) -> Result<Vec<u8>, String> {
        export::to_png(self.map()?).map_err(|e| e.to_string())
    }

    /// The map_server YAML naming `image` (the PGM's file name).
    pub fn map_yaml(&self, image: &str) -> Result<String, String> {
        Ok(export::to_yaml(self.map()?, image))
    }

    /// The replay so far: paths and loop closures.
    pub fn view(&self) -> ReplayView {
        let slam = &self.slam;
        let flat = |poses: &mut dyn Iterator<Item = Pose2>| -> Vec<f64> {
            poses.flat_map(|p| [p.x, p.y, p.theta]).collect()
        };
        let closures = slam
            .closures
            .iter()
            .map(|c| ClosureView::between(c, &slam.graph.nodes))
            .collect();
        ReplayView {
            done: self.replayed().len(),
            total: self.replayed().len() + self.remaining(),
            odometry: if self.has_odometry() {
                flat(&mut slam.scans.iter().map(|s| s.odometry))
            } else {
                Vec::new()
            },
            poses: flat(&mut slam.poses().into_iter()),
            closures,
        }
    }

    /// Draws the map of the scans replayed so far at their current poses
    /// (kept for [`LogReplay::live_info`] and [`LogReplay::live_pixels`]);
    /// returns false before the first scan.
    pub fn draw_live(&mut self) -> bool {
        let scans = self.replayed();
        if scans.is_empty() {
            return false;
        }
        self.live = Some(cropped(self.slam.build_map(scans)));
        true
    }

    /// Each scan's time (s, the log's clock) of the stretch replayed
    /// (`from..=to`), replayed or not: a page's timeline.
    pub fn times(&self) -> Vec<f64> {
        self.scans
            .get(self.from..=self.to)
            .unwrap_or_default()
            .iter()
            .map(|s| s.time)
            .collect()
    }

    /// The key nodes as the SLAM had them once `k` scans were replayed.
    fn nodes_at(&self, k: usize) -> &[Pose2] {
        match self.version_at(k) {
            Some(v) => &v.nodes,
            None => &self.slam.graph.nodes,
        }
    }

    /// The version of the key nodes in force once `k` scans were replayed
    /// (`None`: the graph now, past its last move).
    fn version_at(&self, k: usize) -> Option<&NodeVersion> {
        self.versions.iter().find(|v| v.until > k)
    }

    /// Checks that `k` scans have been replayed (a moment to look back at).
    fn moment(&self, k: usize) -> Result<usize, String> {
        let done = self.replayed().len();
        if k == 0 || k > done {
            return Err(format!(
                "moment {k}: only scans 1 to {done} have been replayed"
            ));
        }
        Ok(k)
    }

    /// The poses of the first `k` scans as the SLAM had them once scan `k`
    /// was replayed (`k` from 1 to the scans replayed).
    pub fn poses_at(&self, k: usize) -> Result<Vec<Pose2>, String> {
        let k = self.moment(k)?;
        let nodes = self.nodes_at(k);
        // Before the end, the scans sat where the replay placed them.
        let before_end = self.version_at(k).is_some();
        self.slam.scans[..k]
            .iter()
            .enumerate()
            .map(|(j, s)| {
                let relative = match self.relatives_then.get(j) {
                    Some(r) if before_end => r,
                    _ => &s.relative,
                };
                nodes
                    .get(s.key)
                    .map(|n| n.compose(relative))
                    .ok_or_else(|| format!("scan {}: its key {} is missing", s.index, s.key))
            })
            .collect()
    }

    /// The replay as it was once `k` scans were replayed: the paths of the
    /// first `k` scans at the poses they had then and the loop closures
    /// found by then, between their keys' poses then.
    pub fn view_at(&self, k: usize) -> Result<ReplayView, String> {
        let poses = self.poses_at(k)?;
        let nodes = self.nodes_at(k);
        let closures = self
            .slam
            .closures
            .iter()
            .zip(&self.closed_after)
            .filter(|(_, at)| **at <= k)
            .map(|(c, _)| ClosureView::between(c, nodes))
            .collect();
        let odometry = if self.has_odometry() {
            self.slam.scans[..k]
                .iter()
                .flat_map(|s| [s.odometry.x, s.odometry.y, s.odometry.theta])
                .collect()
        } else {
            Vec::new()
        };
        Ok(ReplayView {
            done: k,
            total: self.replayed().len() + self.remaining(),
            odometry,
            poses: poses.iter().flat_map(|p| [p.x, p.y, p.theta]).collect(),
            closures,
        })
    }

    /// Draws the map of the first `k` scans at the poses they had once
    /// scan `k` was replayed, as the live map (read with
    /// [`LogReplay::live_info`] and [`LogReplay::live_pixels`]).
    pub fn draw_at(&mut self, k: usize) -> Result<(), String> {
        let poses = self.poses_at(k)?;
        let scans = &self.scans[self.from..self.from + k];
        self.live = Some(cropped(self.slam.build_map_at(scans, &poses)));
        Ok(())
    }

    fn live(&self) -> Result<&OccupancyGrid, String> {
        self.live
            .as_ref()
            .ok_or_else(|| "drawLive first".to_string())
    }

    /// Size, resolution and origin of the live map.
    pub fn live_info(&self) -> Result<MapInfo, String> {
        Ok(MapInfo::of(self.live()?))
    }

    /// The live map's grey pixels (PGM shades), top row first.
    pub fn live_pixels(&self) -> Result<Vec<u8>, String> {
        Ok(export::grey_rows_top_first(self.live()?))
    }
}

/// The truth at time `t`, linear between the samples around it; `None`
/// outside their span.
fn truth_at(truth: &[(f64, Pose2)], t: f64) -> Option<Pose2> {
    let k = truth.partition_point(|(s, _)| *s < t);
    let (tb, b) = truth.get(k)?;
    if *tb == t {
        return Some(*b);
    }
    let (ta, a) = truth.get(k.checked_sub(1)?)?;
    let u = (t - ta) / (tb - ta);
    Some(Pose2::new(
        a.x + u * (b.x - a.x),
        a.y + u * (b.y - a.y),
        wrap_angle(a.theta + u * wrap_angle(b.theta - a.theta)),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Walls `[x1, y1, x2, y2]` of a ring corridor: an outer 16 × 10 m box
    /// round an inner block with notches, so places along it differ.
    fn ring_walls() -> Vec<[f64; 4]> {
        let poly = |pts: &[[f64; 2]]| -> Vec<[f64; 4]> {
            (0..pts.len())
                .map(|i| {
                    let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
                    [a[0], a[1], b[0], b[1]]
                })
                .collect()
        };
        let mut walls = poly(&[[-8.0, -5.0], [8.0, -5.0], [8.0, 5.0], [-8.0, 5.0]]);
        walls.extend(poly(&[
            [-5.0, -2.0],
            [-1.0, -2.0],
            [-1.0, -2.6],
            [1.0, -2.6],
            [1.0, -2.0],
            [5.0, -2.0],
            [5.0, 2.0],
            [2.0, 2.0],
            [2.0, 2.5],
            [-3.0, 2.5],
            [-3.0, 2.0],
            [-5.0, 2.0],
        ]));
        walls.extend([
            [6.6, -5.0, 6.6, -4.2],
            [-8.0, 0.3, -7.3, 0.3],
            [0.0, 5.0, 0.0, 4.3],
        ]);
        walls
    }

    /// The range from `(x, y)` along heading `a` to the nearest wall, or 80.
    fn ray(walls: &[[f64; 4]], x: f64, y: f64, a: f64) -> f64 {
        let (dx, dy) = (a.cos(), a.sin());
        let mut best = 80.0f64;
        for w in walls {
            let (ex, ey) = (w[2] - w[0], w[3] - w[1]);
            let (wx, wy) = (w[0] - x, w[1] - y);
            let cross = dx * ey - dy * ex;
            if cross.abs() < 1e-12 {
                continue;
            }
            let along = (wx * ey - wy * ex) / cross;
            let on = (wx * dy - wy * dx) / cross;
            if along > 0.0 && (0.0..=1.0).contains(&on) {
                best = best.min(along);
            }
        }
        best
    }

    /// A CARMEN log of two laps round the ring, 140 scans a lap, 0.25 s
    /// apart, its odometry turning 0.004 rad a step too far, so the second
    /// lap meets the first displaced and a loop closure mends it.
    fn ring_log() -> String {
        let walls = ring_walls();
        let pose_at = |s: f64| {
            let u = 2.0 * std::f64::consts::PI * s.fract();
            let (x, y) = (6.5 * u.cos(), 3.5 * u.sin());
            (x, y, (3.5 * u.cos()).atan2(-6.5 * u.sin()))
        };
        let mut lines = Vec::new();
        let mut odo = pose_at(0.0);
        let mut last = odo;
        for i in 0..=280 {
            let p = pose_at(i as f64 / 140.0);
            if i > 0 {
                let (c, s) = (last.2.cos(), last.2.sin());
                let (dx, dy) = (p.0 - last.0, p.1 - last.1);
                let (fwd, side) = (c * dx + s * dy, -s * dx + c * dy);
                let turn = wrap_angle(p.2 - last.2) + 0.004;
                let (oc, os) = (odo.2.cos(), odo.2.sin());
                odo = (
                    odo.0 + oc * fwd - os * side,
                    odo.1 + os * fwd + oc * side,
                    odo.2 + turn,
                );
            }
            last = p;
            let ranges: Vec<String> = (0..=180)
                .map(|b| {
                    let a = p.2 + (b as f64 - 90.0).to_radians();
                    format!("{:.3}", ray(&walls, p.0, p.1, a))
                })
                .collect();
            let pose = format!("{:.5} {:.5} {:.5}", odo.0, odo.1, odo.2);
            let t = 1000.0 + 0.25 * i as f64;
            lines.push(format!(
                "FLASER 181 {} {pose} {pose} {t:.3} sim {t:.3}",
                ranges.join(" ")
            ));
        }
        lines.join("\n")
    }

    /// Scrubbing back to scan `k` shows the trajectory exactly as the SLAM
    /// had it then: before a loop closure moved the first lap, after it
    /// with the move, and the map of scans `0..k` only.
    #[test]
    fn a_moment_looked_back_at_is_the_trajectory_the_slam_had_then() {
        let mut replay = LogReplay::new(ring_log().as_bytes()).unwrap();
        assert_eq!(replay.times().len(), 281);
        assert_eq!(replay.times()[4] - replay.times()[0], 1.0);
        let mut seen = vec![Vec::new()];
        let mut closures_seen = vec![0];
        while replay.step(1) > 0 {
            seen.push(replay.slam.poses());
            closures_seen.push(replay.slam.closures.len());
        }
        seen.push(replay.slam.poses());
        closures_seen.push(replay.slam.closures.len());
        let first = closures_seen.iter().position(|&c| c > 0);
        let first = first.expect("the second lap closes a loop");
        assert!(first > 100, "the first closure at scan {first}");
        replay.finish().unwrap();

        // Every moment before the end: the poses exactly as they were then.
        for k in 1..281 {
            let then = replay.poses_at(k).unwrap();
            assert_eq!(then, seen[k], "the trajectory at scan {k}");
            let view = replay.view_at(k).unwrap();
            assert_eq!(
                view.closures.len(),
                closures_seen[k],
                "closures at scan {k}"
            );
            assert_eq!(view.poses.len(), 3 * k);
        }
        // The closure moved the first lap: just before it, a scan of the
        // first lap sat elsewhere than where the settled graph has it.
        let before = replay.poses_at(first - 1).unwrap();
        let end = replay.poses_at(281).unwrap();
        let moved = before
            .iter()
            .zip(&end)
            .map(|(a, b)| (a.position() - b.position()).length())
            .fold(0.0, f64::max);
        assert!(moved > 0.05, "the closure moved the path by {moved} m");
        assert_eq!(end, replay.slam.poses(), "the end is the settled graph");

        // The map of the first 40 scans holds a fraction of the walls (at
        // the end they are drawn at the smoothed poses, thinner: 2,212
        // cells, against 2,769 unsmoothed).
        replay.draw_at(40).unwrap();
        let early = replay.live_info().unwrap().occupied_cells;
        replay.draw_at(281).unwrap();
        let all = replay.live_info().unwrap().occupied_cells;
        assert!(
            early * 2 < all,
            "{early} walls at scan 40, {all} at the end"
        );
        assert!(early > 50, "{early} walls at scan 40");
        assert!(replay.poses_at(0).is_err());

        // The map is cut to what was seen plus 1 m: the ring's outer wall
        // (16 x 10 m) and a margin of 20 cells, not the laser's 20 m+ of
        // reach around every pose.
        let map = replay.map().unwrap();
        let (w, h) = (map.width() as f64 * 0.05, map.height() as f64 * 0.05);
        assert!(
            (17.0..=19.0).contains(&w) && (11.0..=13.0).contains(&h),
            "{w} x {h} m"
        );
        let origin = map.origin_m();
        assert!(origin.x > -9.5 && origin.y > -6.5, "origin {origin}");
        let Err(e) = replay.view_at(282) else {
            panic!("a moment past the replay")
        };
        assert!(e.contains("1 to 281"), "{e}");
    }
}
