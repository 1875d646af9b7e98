//! # The simulated robot's back end: key scans, loop closures, a pose graph
//!
//! The online mapper ([`super::mapper`]) estimates only the current pose: a
//! filter whose measurement is the scan matched to the map built so far. Its
//! small errors add up on a long run, and where it goes wrong once (a
//! stretch the laser cannot pin, a robot in the way) every later wall is
//! drawn where the wrong pose put it, so the map itself holds the error and
//! the matcher keeps it. Returning to a place mapped long ago is what can
//! undo that: this file is the loop-closing back end of graph SLAM, in the
//! manner of Karto / slam_toolbox (K. Konolige, G. Grisetti, R. Kümmerle,
//! W. Burgard, B. Limketkai, R. Vincent, "Efficient sparse pose adjustment
//! for 2D mapping", IROS 2010) and Cartographer (W. Hess, D. Kohler, H. Rapp,
//! D. Andor, "Real-time loop closure in 2D LIDAR SLAM", ICRA 2016), run
//! beside the filter, which stays the front end:
//!
//! 1. **Key scans.** Every `key_distance_m` of motion (or `key_angle_rad` of
//!    turn) of the filter's estimate, the scan becomes a key: a node of the
//!    pose graph ([`super::posegraph`]) at the estimate, and its ranges kept
//!    compactly, one `u16` in millimetres per beam, as the robot's log keeps
//!    them. Consecutive keys are linked by the filter's relative motion,
//!    weighed by the uncertainty the front end really had between them
//!    ([`super::key_chain`]): odometry's noise compounded step by step,
//!    tightened by each match's information except along the weak
//!    direction of a degenerate match (where the filter kept odometry's
//!    word), plus a floor (`floor_m`, `floor_rad`). A corridor edge is
//!    loose along the corridor, a stretch on odometry alone loose in every
//!    direction.
//! 2. **Loop closures** ([`super::loop_closure`]): every `loop_every` keys a
//!    new key whose scan constrains every direction (not a corridor, where a
//!    match slides along the walls) is matched, by Olson's correlative
//!    search, against the older keys near its estimate, then refined as the
//!    front end refines its matches (Gauss–Newton onto the surfaces of the
//!    old keys' scans, `refine_closures`): the search is good to a cell and
//!    half a degree, and half a degree at the seam of a 240 m loop puts the
//!    far side a quarter of a metre off.
//! 3. **Consistency.** A closure may ask the graph for no larger a
//!    correction than the front end can have drifted along the path between
//!    its two keys (`max_correction_m` plus `drift_per_metre` of it: the
//!    gate a Mahalanobis test on the chain's covariance would make); a match
//!    that asks more slid along a corridor. In a maze of identical cells a closure can be wrong by
//!    a cell, the worst outcome there is: it bends the whole graph onto the
//!    wrong place. A closure is accepted only when a second one found within
//!    `confirm_keys` keys agrees with it (Olson's pairwise consistency, as
//!    the log SLAM does, [`super::logslam`]), and the optimisation that takes
//!    them must leave both satisfied (χ² at most `max_closure_chi2`), or it is
//!    undone. A confirmed pair the graph already satisfies (within
//!    `satisfied_m`) is not added, and after a pair the search rests for
//!    `cooldown_keys` keys: on the second lap of a tour every key would
//!    close, and each optimisation of the whole graph costs.
//! 4. **Correction.** After an accepted closure the graph is optimised (sparse
//!    least squares), and every step's estimate moves with its key: step `k`
//!    of key `j` goes to `x_j' ⊕ x_j⁻¹ ⊕ x̂_k`, so the trajectory the lab scores
//!    is the corrected one, and the filter's current pose moves with the
//!    newest key. When some key moved by more than `rebuild_m` (a cell), the
//!    SLAM map is drawn again from the key scans at their new poses: the
//!    filter must match against walls where the graph now puts them, or it
//!    would pull the pose straight back.
//!
//! ## What the numbers say (why it is still off by default)
//! On the one-hour, 16-robot, 60 × 60 m maze of issue 22
//! (`examples/sim_drift.rs`), the robots whose SLAM drifts follow the maze's
//! outer wall, a 240 m loop where more than half the scans pin only the
//! direction across the wall. Without the back end their ATE is 0.880,
//! 0.485, 0.625, 1.205, 0.149 m (robots 5, 7, 11, 15, 16). With it:
//!
//! | key edges; closures | 5 | 7 | 11 | 15 | 16 |
//! |---|---|---|---|---|---|
//! | fixed σ (2 cm, 0.5°); search only (session 15) | 0.081 | 0.650 | 0.251 | 0.218 | 0.104 |
//! | compounded covariance; search only | 0.145 | 0.541 | 0.209 | 0.210 | 0.118 |
//! | compounded; refined (the default settings) | 0.138 | 0.525 | 0.226 | 0.202 | 0.097 |
//! | compounded; refined, closures σ 1 cm, 0.1° | 0.126 | 0.660 | 0.156 | 0.188 | 0.100 |
//!
//! Heading floor 0.3° or 0.02° with a closure tried at every key changed
//! these by a few centimetres either way. The refined closures are right to
//! 0.1° (the search's alone were off by up to 0.44°), each lap's first
//! closure snaps the pose back to within 2 cm, and yet the middle of the
//! lap stays 0.2–0.8 m off.
//!
//! Why, measured against the truth (`sim_drift --graph --probe` with
//! `GRAPH_NO_LOOPS=1`, the front end's own key poses, rms over the five
//! robots' hour): the front end's relative pose between keys `m` apart is
//! off in heading by
//!
//! | keys apart | 1 | 10 | 50 | 150 | 300 | 600 |
//! |---|---|---|---|---|---|---|
//! | heading error rms | 0.09–0.10° | 0.19–0.28° | 0.23–0.43° | 0.25–0.45° | 0.23–0.66° | 0.26–0.90° |
//! | position error rms | 3–4 mm | 0.9–1.4 cm | 3–5 cm | 7–17 cm | 11–28 cm | 18–65 cm |
//!
//! with a signed mean near zero: not a bias, and not a random walk of
//! independent key steps either (that would give √600 × 0.09° ≈ 2.2° over
//! 600 keys). Much of a key's heading error is jitter that later keys
//! take back; what accumulates is a slow meander of a few tenths of a
//! degree over a lap. One closure per lap measures where it ended, not its
//! path; least squares then bends the lap as the chain's covariance says
//! (a Brownian bridge), which leaves the meander's spread mid-lap — and for
//! robot 7, whose error rose early and then stayed, bends the middle of
//! the lap further off than the filter alone had it (0.75 m at 900 s against
//! 0.48 m). Later laps are matched against the map of the first, so the
//! corrected trajectory repeats the first lap's error every lap (robot 5 at
//! 300 s intervals: 0.03 0.19 0.26 0.16 0.01 | 0.04 0.19 0.27 0.16 0.02).
//!
//! ## The first lap's closures (session 22)
//! Those robots' "loop" is not a 240 m square: robot 7's lap is 1,385 keys
//! (550 m), a left-wall tour of the outer wall and every wall joined to it,
//! and its first lap, where the error is made, accepted no closure. A
//! wall-follower walks each corridor twice, along either wall, 1.8 m apart
//! and facing the other way; the scan walking back scores only 0.4–0.6
//! against the keys walking in, and in a corridor it pins little across,
//! so `min_score` (0.6) and `min_constraint` (20) refuse it. At 0.4 and 5
//! the first lap closes (robot 7 at 1,450 s: 0.381 → 0.049 m) and the
//! hour's worst robot is 0.171 m (robot 7 0.068), but on the 300 s mazes
//! those low-scoring closures cost precision (maze 11's robots: 0.012 and
//! 0.011 → 0.040 and 0.047 m), so the defaults stay (BENCHMARKS.md,
//! "Session 22", with the variants tried since).
//!
//! ## Scan-to-scan key edges: measured, not added
//! Karto's "chain of recent scans" links each key to the previous keys its
//! laser still overlaps by matching the scans directly. [`RobotGraph::match_keys`]
//! refines a key's scan onto the surfaces of an older key's scan alone (or
//! of a few keys around it) from the front end's relative pose; against the
//! truth (same run, rms heading error; the front end's in brackets):
//!
//! | keys apart (matched onto) | 1 (1) | 2 (1) | 3 (1) | 5 (1) | 10 (1) | 3 (5) | 5 (5) | 10 (7) |
//! |---|---|---|---|---|---|---|---|---|
//! | all five robots, hour | 0.11–0.12° (0.08–0.10°) | 0.12–0.13° (0.10–0.13°) | 0.13–0.15° (0.10–0.15°) | 0.15–0.17° (0.11–0.13°) | 0.21–0.22° (0.10–0.15°) | — | — | — |
//! | robots 7, 15, first 900 s | 0.10° (0.07–0.08°) | 0.11–0.12° (0.07–0.08°) | 0.12–0.13° (0.07–0.08°) | 0.15° (0.08–0.09°) | 0.21–0.22° (0.08–0.11°) | 0.10° (0.08°) | 0.11–0.12° (0.08–0.09°) | 0.14° (0.08–0.09°) |
//!
//! and 1–1.4 cm in position against the front end's 2–7 mm. A single scan's
//! surfaces carry its laser noise (1 cm, a hit or two a cell) where the
//! front end's map averages hundreds of scans, so the direct match is
//! *worse* than the chain it would constrain, at every span where the scans
//! still overlap (beyond 5 keys, 0.4 m apart, fewer than half the pairs
//! do): such edges cannot straighten the meander, and are not added.
//! Helping every robot needs information the robot's own scans do not
//! hold about the first lap's shape (other robots' maps), or a front end
//! whose later laps are not locked to the first lap's map. Until then
//! `SlamConfig::back_end` is `false`; `sim_drift --graph` runs it.

use super::degeneracy::{constraint_of, scan_normals};
use super::filter::OdometryNoise;
use super::grid::{beam_directions, GridConfig, OccupancyGrid};
use super::key_chain::KeyChain;
pub use super::key_chain::StepMatch;
use super::loop_closure::{closures_agree, find_closure, Closure, LoopConfig};
use super::multires::Window;
use super::posegraph::{Edge, PoseGraph};
use super::surface::{refine_to_surface, RefineConfig};
use crate::geom::{wrap_angle, Pose2};
use crate::sensors::LaserScan;
use glam::DVec2;

/// Settings of the back end.
#[derive(Clone, Debug, PartialEq)]
pub struct RobotGraphConfig {
    pub key_distance_m: f64,
    pub key_angle_rad: f64,
    /// Odometry's noise per step, as the front end's filter models it: the
    /// key edges' covariance is compounded from it ([`super::key_chain`]).
    pub odometry: OdometryNoise,
    /// Standard deviations added to every key edge's compounded covariance
    /// (a key's own match is not exact).
    pub floor_m: f64,
    pub floor_rad: f64,
    /// A key edge whose compounded covariance cannot be inverted.
    pub loose_sigma_m: f64,
    pub loose_sigma_rad: f64,
    pub loops: LoopConfig,
    /// Refine each closure onto the old keys' surfaces (see
    /// [`RobotGraph::refine_closure`]).
    pub refine_closures: bool,
    pub loop_every: usize,
    /// A key is tried for a closure only if its scan's weak eigenvalue
    /// ([`super::degeneracy`]) reaches this.
    pub min_constraint: f64,
    pub confirm_keys: usize,
    /// The two closures of a pair must reach old keys at least this many
    /// keys apart: two matches of one old place agree with each other even
    /// when both slid along the same corridor.
    pub confirm_spread_keys: usize,
    /// Largest correction a closure may ask of the graph: this much plus
    /// `drift_per_metre` of the path driven between its keys (the front
    /// end's drift cannot be larger; a match that asks more slid).
    pub max_correction_m: f64,
    pub drift_per_metre: f64,
    pub confirm_m: f64,
    pub confirm_rad: f64,
    pub max_closure_chi2: f64,
    /// Keys after an accepted pair of closures before the next search: the
    /// graph has just been settled there, and each optimisation costs.
    pub cooldown_keys: usize,
    /// A confirmed closure the graph already satisfies within this (m, and
    /// radians times the laser's reach) adds nothing worth an optimisation.
    pub satisfied_m: f64,
    /// A correction moving some key by more than this (m, or radians times
    /// the laser's reach) redraws the SLAM map.
    pub rebuild_m: f64,
}

impl Default for RobotGraphConfig {
    fn default() -> Self {
        RobotGraphConfig {
            key_distance_m: 0.4,
            key_angle_rad: 20f64.to_radians(),
            odometry: OdometryNoise::default(),
            floor_m: 0.001,
            floor_rad: 0.05f64.to_radians(),
            loose_sigma_m: 0.1,
            loose_sigma_rad: 3f64.to_radians(),
            loops: LoopConfig {
                search_radius_m: 2.0,
                min_key_gap: 50,
                submap_half: 8,
                window: Window {
                    linear_m: 1.2,
                    angular_rad: 10f64.to_radians(),
                },
                min_score: 0.6,
                sigma_m: 0.03,
                sigma_rad: 1f64.to_radians(),
            },
            refine_closures: true,
            loop_every: 2,
            min_constraint: 20.0,
            confirm_keys: 10,
            confirm_spread_keys: 2,
            max_correction_m: 0.1,
            drift_per_metre: 0.01,
            confirm_m: 0.1,
            confirm_rad: 1.5f64.to_radians(),
            max_closure_chi2: 20.0,
            cooldown_keys: 10,
            satisfied_m: 0.02,
            rebuild_m: 0.05,
        }
    }
}

/// A key scan: ranges in millimetres ([`NO_RETURN`] for none, the top bit
/// set for a reflective return) and the step it was taken at.
#[derive(Clone, Debug, PartialEq)]
struct KeyScan {
    ranges_mm: Vec<u16>,
    range_max_m: f64,
}

/// A beam that met nothing in range.
const NO_RETURN: u16 = u16::MAX;
/// The flag bit of a reflective return (another robot).
const REFLECTIVE: u16 = 0x8000;
/// Returns this short are not matched (as the front end's points).
const MIN_RANGE_MM: u16 = 50;

impl KeyScan {
    fn pack(scan: &LaserScan) -> KeyScan {
        let ranges_mm = (0..scan.ranges_m.len())
            .map(|i| {
                if scan.max_range.get(i) != Some(&false) {
                    return NO_RETURN;
                }
                let mm = (scan.ranges_m[i] * 1000.0).round().clamp(0.0, 32_767.0) as u16;
                if scan.reflective.get(i) == Some(&true) {
                    mm | REFLECTIVE
                } else {
                    mm
                }
            })
            .collect();
        KeyScan {
            ranges_mm,
            range_max_m: scan.range_max_m,
        }
    }

    /// The returns off walls (not other robots), robot frame, beam order.
    fn points(&self) -> Vec<DVec2> {
        beam_directions(0.0, self.ranges_mm.len())
            .zip(&self.ranges_mm)
            .filter(|&(_, &v)| v != NO_RETURN && v & REFLECTIVE == 0 && v > MIN_RANGE_MM)
            .map(|(d, &v)| d * (v as f64 / 1000.0))
            .collect()
    }

    fn unpack(&self) -> LaserScan {
        let n = self.ranges_mm.len();
        let mut scan = LaserScan {
            ranges_m: vec![self.range_max_m; n],
            max_range: vec![true; n],
            reflective: vec![false; n],
            range_max_m: self.range_max_m,
        };
        for (i, &v) in self.ranges_mm.iter().enumerate() {
            if v != NO_RETURN {
                scan.ranges_m[i] = (v & !REFLECTIVE) as f64 / 1000.0;
                scan.max_range[i] = false;
                scan.reflective[i] = v & REFLECTIVE != 0;
            }
        }
        scan
    }
}

/// Counts of what the back end did.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct RobotGraphStats {
    pub keys: usize,
    pub closures_tried: usize,
    pub closures_found: usize,
    pub closures_accepted: usize,
    pub closures_rejected: usize,
    /// Closures asking a larger correction than the front end can have
    /// drifted (dropped).
    pub closures_implausible: usize,
    /// Confirmed closures the graph already satisfied (not added).
    pub closures_satisfied: usize,
    pub map_rebuilds: usize,
}

/// An accepted loop closure: its keys, the steps they were taken at, the
/// measured relative pose and the match score.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosureRecord {
    pub from_key: usize,
    pub to_key: usize,
    pub from_step: usize,
    pub to_step: usize,
    pub measurement: Pose2,
    pub score: f64,
}

/// A scan-to-scan match of two keys ([`RobotGraph::match_keys`]): the
/// newer key's pose in the older key's frame, the refinement's information
/// `Σ w JᵀJ` (unit residual variance) and how many points found a surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KeyMatch {
    pub relative: Pose2,
    pub information: [[f64; 3]; 3],
    pub count: usize,
}

/// What the front end hands the back end after each integrated scan, and
/// what the back end may correct: every step's estimate, the filter's pose
/// and the SLAM map.
pub struct FrontEnd<'a> {
    pub estimates: &'a mut Vec<Pose2>,
    pub pose: &'a mut Pose2,
    pub map: &'a mut OccupancyGrid,
}

/// One robot's pose graph of key scans.
#[derive(Clone, Debug, Default)]
pub struct RobotGraph {
    pub config: RobotGraphConfig,
    pub graph: PoseGraph,
    keys: Vec<KeyScan>,
    /// The step (index into the estimates) each key was taken at.
    key_step: Vec<usize>,
    /// The path driven up to each key (m, along the key edges).
    key_path_m: Vec<f64>,
    /// The key each step's estimate follows (the last key at or before it).
    step_key: Vec<u32>,
    /// The pose since the last key and its covariance (`None` before the
    /// first key).
    chain: Option<KeyChain>,
    pending: Vec<Closure>,
    /// The key of the last accepted pair (for the cool-down).
    last_accepted: Option<usize>,
    pub closures: Vec<ClosureRecord>,
    pub stats: RobotGraphStats,
}

impl RobotGraph {
    pub fn new(config: RobotGraphConfig) -> RobotGraph {
        RobotGraph {
            config,
            ..RobotGraph::default()
        }
    }

    /// After the front end integrated `scan` at its newest estimate (the
    /// last of `front.estimates`), with what its match said (`None` where
    /// it kept odometry's word): makes a key if the robot moved far enough,
    /// looks for a loop closure, and applies an accepted one to the front
    /// end.
    pub fn add_scan(&mut self, scan: &LaserScan, matched: Option<StepMatch>, front: FrontEnd<'_>) {
        let Some(&pose) = front.estimates.last() else {
            return;
        };
        if let Some(chain) = &mut self.chain {
            chain.step(&pose, &self.config.odometry);
            if let Some(m) = &matched {
                chain.observe(m);
            }
        }
        let is_key = match self.graph.nodes.last() {
            None => true,
            Some(last) => {
                let rel = last.between(&pose);
                rel.position().length() >= self.config.key_distance_m
                    || rel.theta.abs() >= self.config.key_angle_rad
            }
        };
        if is_key {
            self.add_key(scan, pose);
            self.key_step.push(front.estimates.len() - 1);
        }
        // Steps the front end did not hand over follow the last key too.
        let last_key = (self.graph.nodes.len() - 1) as u32;
        self.step_key.resize(front.estimates.len(), last_key);
        if is_key && self.should_try() {
            if let Some(closures) = self.try_close(front.map.resolution_m()) {
                self.accept(closures, front);
            }
        }
    }

    fn add_key(&mut self, scan: &LaserScan, pose: Pose2) {
        let id = self.graph.nodes.len();
        if let Some(prev) = id.checked_sub(1) {
            let z = self.graph.nodes[prev].between(&pose);
            let c = &self.config;
            let mut edge = Edge::new(prev, id, z, c.loose_sigma_m, c.loose_sigma_rad);
            if let Some(info) = self
                .chain
                .as_ref()
                .and_then(|ch| ch.edge_information(&z, c.floor_m, c.floor_rad))
            {
                edge.information = info;
            }
            self.graph.edges.push(edge);
        }
        let path = match (self.graph.nodes.last(), self.key_path_m.last()) {
            (Some(prev), Some(&p)) => p + prev.position().distance(pose.position()),
            _ => 0.0,
        };
        self.key_path_m.push(path);
        self.graph.nodes.push(pose);
        self.keys.push(KeyScan::pack(scan));
        self.chain = Some(KeyChain::start(pose));
        self.stats.keys += 1;
    }

    /// Whether the newest key is due for a closure search and its scan pins
    /// every direction.
    fn should_try(&self) -> bool {
        let id = self.graph.nodes.len() - 1;
        if id < self.config.loops.min_key_gap || !id.is_multiple_of(self.config.loop_every.max(1)) {
            return false;
        }
        if self
            .last_accepted
            .is_some_and(|k| id < k + self.config.cooldown_keys)
        {
            return false;
        }
        let points = self.keys[id].points();
        let normals = scan_normals(&points);
        let constraint = constraint_of(&normals, &vec![true; points.len()]);
        !constraint.is_degenerate(self.config.min_constraint)
    }

    /// The newest key's points and those of the older keys that a closure
    /// search may read (near its estimate); the rest left empty.
    fn key_points(&self, i: usize) -> Vec<Vec<DVec2>> {
        let cfg = &self.config.loops;
        let here = self.graph.nodes[i].position();
        let newest_old = i - cfg.min_key_gap;
        let mut wanted = vec![false; i + 1];
        wanted[i] = true;
        for j in 0..=newest_old {
            if self.graph.nodes[j].position().distance(here) <= cfg.search_radius_m {
                let hi = (j + cfg.submap_half).min(newest_old);
                for w in &mut wanted[j.saturating_sub(cfg.submap_half)..=hi] {
                    *w = true;
                }
            }
        }
        wanted
            .iter()
            .enumerate()
            .map(|(k, &w)| if w { self.keys[k].points() } else { Vec::new() })
            .collect()
    }

    /// Looks for a closure of the newest key; returns two closures that
    /// agree (the new one and a pending one), else keeps the new one
    /// pending.
    fn try_close(&mut self, resolution_m: f64) -> Option<Vec<Closure>> {
        let id = self.graph.nodes.len() - 1;
        self.stats.closures_tried += 1;
        let points = self.key_points(id);
        let mut found = find_closure(
            &self.graph.nodes,
            &points,
            id,
            resolution_m,
            &self.config.loops,
            None,
        )?;
        self.stats.closures_found += 1;
        if self.config.refine_closures {
            self.refine_closure(&mut found, &points[id], resolution_m);
        }
        if !self.plausible(&found) {
            self.stats.closures_implausible += 1;
            return None;
        }
        let cfg = &self.config;
        self.pending
            .retain(|c| c.edge.to + cfg.confirm_keys >= id && c.edge.to != id);
        let agreeing = self.pending.iter().position(|c| {
            c.edge.from.abs_diff(found.edge.from) >= cfg.confirm_spread_keys
                && closures_agree(&self.graph.nodes, c, &found, cfg.confirm_m, cfg.confirm_rad)
        });
        match agreeing {
            Some(k) => {
                let other = self.pending.remove(k);
                Some(vec![other, found])
            }
            None => {
                self.pending.push(found);
                None
            }
        }
    }

    /// Refines a closure found by the correlative search (good to about a
    /// cell and, over a 4 m scan, half a degree) as the front end refines
    /// its matches: Gauss–Newton of the new key's points onto the surfaces
    /// of the old keys' scans drawn at their poses ([`super::surface`]).
    /// Half a degree wrong at the seam of a 240 m loop puts the far side
    /// of the lap a quarter of a metre off. Keeps the search's answer if
    /// too few points find a surface.
    fn refine_closure(&self, c: &mut Closure, points: &[DVec2], resolution_m: f64) {
        let cfg = &self.config.loops;
        let newest_old = c.edge.to - cfg.min_key_gap;
        let lo = c.edge.from.saturating_sub(cfg.submap_half);
        let hi = (c.edge.from + cfg.submap_half).min(newest_old);
        let config = GridConfig {
            resolution_m,
            surface_points: true,
            ..GridConfig::default()
        };
        let poses = self.graph.nodes[lo..=hi].iter().copied();
        let map = OccupancyGrid::drawn_at(config, poses, |m, k, pose| {
            m.integrate_scan(pose, &self.keys[lo + k].unpack())
        });
        let start = self.graph.nodes[c.edge.from].compose(&c.edge.measurement);
        let normals = scan_normals(points);
        let r = refine_to_surface(&map, points, &normals, &start, &RefineConfig::default());
        let with_normal = normals.iter().filter(|n| n.is_some()).count();
        if r.count * 2 >= with_normal && r.pose.is_finite() {
            c.edge.measurement = self.graph.nodes[c.edge.from].between(&r.pose);
        }
    }

    /// Whether the correction a closure asks of the graph (its disagreement
    /// with the graph's relative pose, in metres and radians times the
    /// laser's reach) is within what the front end can have drifted over
    /// the path between its two keys.
    fn plausible(&self, c: &Closure) -> bool {
        let n = &self.graph.nodes;
        let e = n[c.edge.from]
            .between(&n[c.edge.to])
            .between(&c.edge.measurement);
        let reach = self.keys.first().map_or(0.0, |k| k.range_max_m);
        let path = self.key_path_m[c.edge.to] - self.key_path_m[c.edge.from];
        e.position().length() + reach * wrap_angle(e.theta).abs()
            <= self.config.max_correction_m + self.config.drift_per_metre * path
    }

    /// Adds two agreeing closures, optimises, and moves the front end with
    /// the graph; undoes it all if a closure stays badly unsatisfied.
    fn accept(&mut self, closures: Vec<Closure>, front: FrontEnd<'_>) {
        let id = self.graph.nodes.len() - 1;
        self.pending.clear();
        self.last_accepted = Some(id);
        let reach = self.keys.first().map_or(0.0, |k| k.range_max_m);
        let satisfied = closures.iter().all(|c| {
            let n = &self.graph.nodes;
            let e = n[c.edge.from]
                .between(&n[c.edge.to])
                .between(&c.edge.measurement);
            e.position().length() + reach * wrap_angle(e.theta).abs() <= self.config.satisfied_m
        });
        if satisfied {
            self.stats.closures_satisfied += closures.len();
            return;
        }
        let before = self.graph.nodes.clone();
        let edges: Vec<Edge> = closures.iter().map(|c| c.edge.clone()).collect();
        if !self
            .graph
            .try_closures(&edges, 10, None, self.config.max_closure_chi2)
        {
            self.stats.closures_rejected += closures.len();
            return;
        }
        self.stats.closures_accepted += closures.len();
        self.closures.extend(closures.iter().map(|c| ClosureRecord {
            from_key: c.edge.from,
            to_key: c.edge.to,
            from_step: self.key_step[c.edge.from],
            to_step: self.key_step[c.edge.to],
            measurement: c.edge.measurement,
            score: c.score,
        }));
        self.apply(&before, front);
    }

    /// Moves every step's estimate and the filter's pose with its key, and
    /// redraws the map if some key moved by more than a cell.
    fn apply(&mut self, before: &[Pose2], front: FrontEnd<'_>) {
        let moves: Vec<Pose2> = before
            .iter()
            .zip(&self.graph.nodes)
            .map(|(old, new)| new.compose(&old.inverse()))
            .collect();
        for (e, &k) in front.estimates.iter_mut().zip(&self.step_key) {
            *e = moves[k as usize].compose(e);
        }
        if let Some(m) = moves.last() {
            *front.pose = m.compose(front.pose);
        }
        if let (Some(chain), Some(key), Some(last)) = (
            &mut self.chain,
            self.graph.nodes.last(),
            front.estimates.last(),
        ) {
            chain.moved(*key, *last);
        }
        let reach = self.keys.first().map_or(0.0, |k| k.range_max_m);
        let largest = before
            .iter()
            .zip(&self.graph.nodes)
            .map(|(a, b)| {
                a.position().distance(b.position()) + reach * wrap_angle(a.theta - b.theta).abs()
            })
            .fold(0.0, f64::max);
        if largest > self.config.rebuild_m {
            *front.map = self.rebuild(front.map.config.clone());
            self.stats.map_rebuilds += 1;
        }
    }

    /// The SLAM map drawn from the key scans at their current poses.
    fn rebuild(&self, config: GridConfig) -> OccupancyGrid {
        OccupancyGrid::drawn_at(config, self.graph.nodes.iter().copied(), |map, k, pose| {
            map.integrate_scan(pose, &self.keys[k].unpack())
        })
    }

    /// Refines key `newer`'s scan onto the surfaces of the scans of keys
    /// `older − half ..= older + half` (those before `newer`), drawn at
    /// their poses relative to key `older`, starting from the graph's
    /// relative pose: with `half = 0` a scan-to-scan match, no map in
    /// between; wider, a small submap whose surfaces average several scans'
    /// noise. `None` when fewer than half of the newer scan's points find a
    /// surface (the scans hardly overlap).
    pub fn match_keys(
        &self,
        older: usize,
        half: usize,
        newer: usize,
        resolution_m: f64,
    ) -> Option<KeyMatch> {
        let config = GridConfig {
            resolution_m,
            surface_points: true,
            ..GridConfig::default()
        };
        let anchor = self.graph.nodes[older];
        let (lo, hi) = (older.saturating_sub(half), (older + half).min(newer - 1));
        let poses = self.graph.nodes[lo..=hi].iter().map(|p| anchor.between(p));
        let map = OccupancyGrid::drawn_at(config, poses, |m, k, pose| {
            m.integrate_scan(pose, &self.keys[lo + k].unpack())
        });
        let start = anchor.between(&self.graph.nodes[newer]);
        let points = self.keys[newer].points();
        let normals = scan_normals(&points);
        let r = refine_to_surface(&map, &points, &normals, &start, &RefineConfig::default());
        let with_normal = normals.iter().filter(|n| n.is_some()).count();
        (r.count * 2 >= with_normal && r.count >= 10 && r.pose.is_finite()).then_some(KeyMatch {
            relative: r.pose,
            information: r.information,
            count: r.count,
        })
    }

    /// The step (index into the estimates) each key was taken at.
    pub fn key_steps(&self) -> &[usize] {
        &self.key_step
    }

    /// Memory the key scans hold (bytes), for the lab's budget figures.
    pub fn key_bytes(&self) -> usize {
        self.keys.iter().map(|k| 2 * k.ranges_mm.len()).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scan(ranges: &[f64], max: &[bool], bright: &[bool]) -> LaserScan {
        LaserScan {
            ranges_m: ranges.to_vec(),
            max_range: max.to_vec(),
            reflective: bright.to_vec(),
            range_max_m: 4.0,
        }
    }

    #[test]
    fn a_key_scan_keeps_millimetres_and_its_flags() {
        let s = scan(
            &[1.2344, 4.0, 0.5, 3.9996],
            &[false, true, false, false],
            &[false, false, true, false],
        );
        let k = KeyScan::pack(&s);
        assert_eq!(k.ranges_mm, vec![1234, NO_RETURN, 500 | REFLECTIVE, 4000]);
        let back = k.unpack();
        assert_eq!(back.ranges_m, vec![1.234, 4.0, 0.5, 4.0]);
        assert_eq!(back.max_range, vec![false, true, false, false]);
        assert_eq!(back.reflective, vec![false, false, true, false]);
        // Only the two wall returns are matched.
        assert_eq!(k.points().len(), 2);
    }

    #[test]
    fn keys_come_every_key_distance_and_steps_follow_their_key() {
        let mut g = RobotGraph::new(RobotGraphConfig::default());
        let s = scan(&[1.0; 5], &[false; 5], &[false; 5]);
        let mut estimates = vec![Pose2::IDENTITY];
        let mut pose = Pose2::IDENTITY;
        let mut map = OccupancyGrid::new(GridConfig::default());
        // 0.1 m a step along x: a key every 0.4 m (steps 0, 4, 8).
        for k in 0..=9 {
            if k > 0 {
                estimates.push(Pose2::new(0.1 * k as f64, 0.0, 0.0));
            }
            let front = FrontEnd {
                estimates: &mut estimates,
                pose: &mut pose,
                map: &mut map,
            };
            g.add_scan(&s, None, front);
        }
        assert_eq!(g.key_steps(), &[0, 4, 8]);
        assert_eq!(g.step_key, vec![0, 0, 0, 0, 1, 1, 1, 1, 2, 2]);
        assert_eq!(g.graph.edges.len(), 2);
        // Moving key 1 by 0.5 m in y moves steps 4..8 with it, not the rest.
        let before = g.graph.nodes.clone();
        g.graph.nodes[1].y += 0.5;
        g.graph.nodes[2].y += 0.5;
        let front = FrontEnd {
            estimates: &mut estimates,
            pose: &mut pose,
            map: &mut map,
        };
        g.apply(&before, front);
        assert_eq!(estimates[3].y, 0.0);
        assert!((estimates[5].y - 0.5).abs() < 1e-12);
        assert!((estimates[5].x - 0.5).abs() < 1e-12);
        assert!((pose.y - 0.5).abs() < 1e-12);
        // The map was drawn again from the three keys.
        assert_eq!(g.stats.map_rebuilds, 1);
        assert_eq!(map.scans(), 3);
    }
}
