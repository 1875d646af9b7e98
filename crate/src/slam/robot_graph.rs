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
//!    new key whose scan pins more than a line (`min_constraint`) is
//!    matched, by Olson's correlative search, against the older keys near
//!    its estimate, then refined as the front end refines its matches
//!    (Gauss–Newton onto the surfaces of the old keys' scans): the search is
//!    good to a cell and half a degree, and half a degree at the seam of a
//!    500 m lap puts the far side of it metres off.
//! 3. **Verification.** A closure is a claim that two scans, often taken
//!    walking the opposite ways along a corridor, show the same walls; a
//!    wrong one bends the whole graph. It must pass every one of these:
//!    - its refinement stands: at least half the new key's points, or
//!      `refine_min_points` of them, lie on the old keys' surfaces. A match
//!      of the search alone is dropped, since at a low score it is often
//!      wrong by degrees (see below);
//!    - it is pinned in every direction: the refinement's covariance
//!      `σ² (JᵀJ)⁻¹` (σ = `closure_residual_m`, the laser's noise) is
//!      within `closure_max_weak_m` along its weakest direction. Along a
//!      corridor a match can slide by several centimetres, and the closures
//!      looser than this are the ones that slide;
//!    - it asks the graph for no larger a correction than the front end can
//!      have drifted along the path between its two keys
//!      (`max_correction_m` plus `drift_per_metre` of it);
//!    - a second closure found within `confirm_keys` keys, reaching another
//!      old key, agrees with it to `confirm_m` and `confirm_rad` (Olson's
//!      pairwise consistency, as the log SLAM does, [`super::logs::logslam`]): in
//!      a maze of identical cells a single match can be wrong by a cell;
//!    - the optimisation that takes the pair leaves both satisfied (χ² at
//!      most `max_closure_chi2`), or it is undone.
//!
//!    A confirmed pair the graph already satisfies (within `satisfied_m`)
//!    is not added, and after a pair the search rests for `cooldown_keys`
//!    keys: on the second lap of a tour every key would close, and each
//!    optimisation of the whole graph costs.
//! 4. **Correction.** After an accepted closure the graph is optimised (sparse
//!    least squares), and every step's estimate moves with its key: step `k`
//!    of key `j` goes to `x_j' ⊕ x_j⁻¹ ⊕ x̂_k`, so the trajectory the lab scores
//!    is the corrected one, and the filter's current pose moves with the
//!    newest key. When some key moved by more than `rebuild_m` (a cell), the
//!    SLAM map is drawn again from the key scans at their new poses: the
//!    filter must match against walls where the graph now puts them, or it
//!    would pull the pose straight back. The keys near the robot are drawn
//!    at once, the rest `redraw_keys_per_scan` at a time over the next
//!    scans, so a redraw is never one long task in the page;
//!    [`RobotGraph::settle`] completes the map at the end of a run.
//!
//! 5. **Square walls** ([`super::manhattan`]). A lap's middle keeps the
//!    front end's slow heading meander: the lap's closures make it
//!    consistent, not straight. Each key whose scan's normals bundle into
//!    one direction modulo 90° is a vote; the building's direction is
//!    measured from the first `manhattan_anchor_keys` votes, near the
//!    start, where the heading has not wandered yet (the start pose is
//!    known), and every later square key within 2° of it gets a loose
//!    (σ 2°) heading-only edge from the anchored first key. The graph is
//!    optimised after every `manhattan_every` such edges (and with every
//!    accepted closure), and the front end moves with it as after a
//!    closure. A world that is not square gives no votes and nothing
//!    changes.
//!
//! ## Why the gates are what they are
//! The gates of item 3 come from scoring every closure the search finds
//! against the truth (`GRAPH_TRIALS=1` with the examples `slam_trace` and
//! `sim_drift`, [`ClosureTrial`]; the figures are in BENCHMARKS.md). A
//! wall-follower walks each dead end twice, along either wall, facing the
//! other way; the scan walking back scores only 0.4–0.6 against the keys
//! walking in and pins little across, so the closures a first lap needs
//! are low-scoring ones. Among those, the wrong ones are the matches whose
//! refinement did not stand, whose answer is the search's (wrong by
//! degrees in heading), and the ones that slid along a corridor, whose
//! refinement covariance is loose along it. Refined from
//! `refine_min_points` points on, a match is right to a few tenths of a
//! degree, so the pairwise test can be tight (`confirm_m`, `confirm_rad`).
//! With those gates the score gate matters little; it stays at 0.6, which
//! keeps two low-scoring closures of an exercise out, and the constraint
//! gate is 5.
//!
//! ## What the back end cannot mend
//! The middle of a first lap. Against the truth (`sim_drift --graph
//! --probe` with `GRAPH_NO_LOOPS=1`) the front end's relative pose between
//! keys is off by about a tenth of a degree for neighbours and by a few
//! tenths of a degree over hundreds of keys, with a mean near zero: not a
//! bias, and not a random walk of independent key steps either, which
//! would grow as the square root of the keys. Much of a key's heading
//! error is jitter that later keys take back; what accumulates is a slow
//! meander over a lap. A lap's dead ends close within centimetres (the
//! local shape is right) and its seam closes, but one closure per lap
//! measures where the lap ended, not its path: least squares bends the lap
//! between them as the key chain's covariance says (a Brownian bridge),
//! which leaves the meander's spread mid-lap. Later laps are matched
//! against the map of the first, so the corrected trajectory repeats the
//! first lap's error every lap. The square walls' prior (item 5) takes out
//! what a square building can.
//!
//! Karto's scan-to-scan links ("chain of recent scans") would not help
//! either. [`RobotGraph::match_keys`] refines a key's scan onto the
//! surfaces of an older key's scan alone (or a few keys around it), and
//! against the truth that match is *worse* than the front end's chain it
//! would constrain, at every span where the scans still overlap: a single
//! scan's surfaces carry its laser noise, where the front end's map
//! averages hundreds of scans. So such edges are not added. Mending the
//! first lap needs information the robot's own scans do not hold about its
//! shape (other robots' maps), or a front end whose later laps are not
//! locked to the first lap's map.

use super::degeneracy::{constraint_of, scan_normals};
use super::filter::{inverse3, OdometryNoise};
use super::grid::{beam_directions, GridConfig, OccupancyGrid};
use super::key_chain::KeyChain;
pub use super::key_chain::StepMatch;
use super::loop_closure::{closures_agree, find_closure, Closure, LoopConfig};
use super::manhattan::{building_direction, fold, priors_towards, scan_direction, ManhattanConfig};
use super::multires::Window;
use super::posegraph::{Edge, PoseGraph};
use super::surface::{refine_to_surface, RefineConfig};
use crate::geom::{wrap_angle, Pose2};
use crate::sensors::LaserScan;
use glam::DVec2;

/// Settings of the back end.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
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
    /// A closure's refinement ([`RobotGraph::refine_closure`]) stands when
    /// half the new key's points, or at least this many, find an old
    /// surface; a closure whose refinement does not stand is dropped.
    pub refine_min_points: usize,
    /// Standard deviation of a point's distance to an old surface (m): the
    /// refinement's covariance is `σ² (JᵀJ)⁻¹`.
    pub closure_residual_m: f64,
    /// A refined closure whose covariance is looser than this (standard
    /// deviation, m) along its weakest position direction may have slid
    /// along a corridor, and is dropped.
    pub closure_max_weak_m: f64,
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
    /// Key scans drawn into a redrawn map per scan the front end hands
    /// over, beyond those near the robot, drawn at once (see
    /// [`RobotGraph::apply`]).
    pub redraw_keys_per_scan: usize,
    /// Keep a [`ClosureTrial`] of every closure found (experiments).
    pub record_trials: bool,
    /// Square walls' heading prior ([`super::manhattan`]; `None`: off).
    /// The building's direction is measured from the first
    /// `manhattan_anchor_keys` square keys, near the start, where the
    /// heading has not wandered yet; each later square key within the gate
    /// gets a prior, and the graph is optimised after every
    /// `manhattan_every` of them.
    pub manhattan: Option<ManhattanConfig>,
    pub manhattan_anchor_keys: usize,
    pub manhattan_every: usize,
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
                window_per_m: 0.0,
                max_window_m: 1.2,
                unique_ratio: 0.9,
                min_score: 0.6,
                sigma_m: 0.03,
                sigma_rad: 1f64.to_radians(),
            },
            refine_min_points: 20,
            closure_residual_m: 0.01,
            closure_max_weak_m: 0.008,
            loop_every: 2,
            min_constraint: 5.0,
            confirm_keys: 10,
            confirm_spread_keys: 2,
            max_correction_m: 0.1,
            drift_per_metre: 0.01,
            confirm_m: 0.05,
            confirm_rad: 0.5f64.to_radians(),
            max_closure_chi2: 20.0,
            cooldown_keys: 10,
            satisfied_m: 0.02,
            rebuild_m: 0.05,
            redraw_keys_per_scan: 48,
            record_trials: false,
            manhattan: Some(ManhattanConfig::default()),
            manhattan_anchor_keys: 50,
            manhattan_every: 200,
        }
    }
}

/// A key scan: ranges in millimetres ([`NO_RETURN`] for none, the top bit
/// set for a reflective return) and the step it was taken at.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
struct KeyScan {
    #[serde(with = "super::keep_capacity")]
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
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RobotGraphStats {
    pub keys: usize,
    pub closures_tried: usize,
    pub closures_found: usize,
    pub closures_accepted: usize,
    pub closures_rejected: usize,
    /// Closures whose refinement did not stand (too few points on the old
    /// keys' surfaces: the search's answer alone is good to a cell and
    /// half a degree, and at a low score often worse).
    pub closures_unrefined: usize,
    /// Refined closures loose along a corridor (`closure_max_weak_m`).
    pub closures_sliding: usize,
    /// Closures asking a larger correction than the front end can have
    /// drifted (dropped).
    pub closures_implausible: usize,
    /// Confirmed closures the graph already satisfied (not added).
    pub closures_satisfied: usize,
    pub map_rebuilds: usize,
    /// Keys given a square walls' heading prior.
    pub square_keys: usize,
}

/// An accepted loop closure: its keys, the steps they were taken at, the
/// measured relative pose and the match score.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ClosureRecord {
    pub from_key: usize,
    pub to_key: usize,
    pub from_step: usize,
    pub to_step: usize,
    pub measurement: Pose2,
    pub score: f64,
}

/// What refining a closure said ([`RobotGraph::refine_closure`]).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ClosureFit {
    /// The new key's refined pose (world).
    pub pose: Pose2,
    /// Points that found an old surface, and points with a normal.
    pub count: usize,
    pub with_normal: usize,
    /// The refinement's mean Huber cost (m²).
    pub cost: f64,
    /// The refinement's `Σ w JᵀJ` (x, y in m, θ in rad).
    pub information: [[f64; 3]; 3],
    /// Standard deviation along the weakest position direction of the
    /// covariance `σ² (JᵀJ)⁻¹` (m); infinite where `JᵀJ` is singular.
    pub weak_m: f64,
    /// Standard deviation of the heading (rad), likewise.
    pub heading_rad: f64,
}

/// A closure found by the search, as the experiments see it: the match,
/// what its refinement said, the correction it asks of the graph and the
/// gates it met.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ClosureTrial {
    /// Its keys, steps, score and measurement: the refined one if the
    /// refinement stood, else the search's.
    pub closure: ClosureRecord,
    pub fit: ClosureFit,
    /// Whether the refinement stood (enough points on old surfaces).
    pub refined: bool,
    /// The correction asked: the graph's relative pose to the measurement.
    pub correction: Pose2,
    /// The path driven between the two keys (m).
    pub path_m: f64,
    pub plausible: bool,
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
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct RobotGraph {
    pub config: RobotGraphConfig,
    pub graph: PoseGraph,
    #[serde(with = "super::keep_capacity")]
    keys: Vec<KeyScan>,
    /// The step (index into the estimates) each key was taken at.
    #[serde(with = "super::keep_capacity")]
    key_step: Vec<usize>,
    /// The path driven up to each key (m, along the key edges).
    #[serde(with = "super::keep_capacity")]
    key_path_m: Vec<f64>,
    /// The key each step's estimate follows (the last key at or before it).
    #[serde(with = "super::keep_capacity")]
    step_key: Vec<u32>,
    /// The pose since the last key and its covariance (`None` before the
    /// first key).
    chain: Option<KeyChain>,
    pending: Vec<Closure>,
    /// The key of the last accepted pair (for the cool-down).
    last_accepted: Option<usize>,
    #[serde(with = "super::keep_capacity")]
    pub closures: Vec<ClosureRecord>,
    /// Keys still to be drawn into the SLAM map after a correction moved
    /// them, the nearest to the robot last (they are popped).
    #[serde(with = "super::keep_capacity")]
    redraw: Vec<usize>,
    /// Every closure found, with `config.record_trials`.
    #[serde(with = "super::keep_capacity")]
    pub trials: Vec<ClosureTrial>,
    pub stats: RobotGraphStats,
    /// Square keys waiting for a heading prior: (key, scan direction).
    #[serde(with = "super::keep_capacity")]
    square: Vec<(usize, f64)>,
    /// The building's direction modulo 90°, once measured.
    building: Option<f64>,
    /// Priors added since the last optimisation.
    priors_pending: usize,
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
        self.draw_pending(front.map, self.config.redraw_keys_per_scan);
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
                return;
            }
        }
        if is_key && self.priors_pending >= self.config.manhattan_every.max(1) {
            self.priors_pending = 0;
            let before = self.graph.nodes.clone();
            if self.graph.optimise(10).is_ok() {
                self.apply(&before, front);
            } else {
                self.graph.nodes = before;
            }
        }
    }

    /// Square walls (see [`RobotGraphConfig::manhattan`]): notes key `id`'s
    /// wall direction, measures the building's once enough keys are square,
    /// and gives the waiting keys within the gate their heading prior.
    fn square_walls(&mut self, id: usize) {
        let Some(m) = &self.config.manhattan else {
            return;
        };
        if let Some((d, _)) = scan_direction(&self.keys[id].points(), m) {
            self.square.push((id, d));
        }
        let nodes = &self.graph.nodes;
        if self.building.is_none() {
            if self.square.len() < self.config.manhattan_anchor_keys.max(1) {
                return;
            }
            let votes: Vec<f64> = self
                .square
                .iter()
                .map(|&(k, d)| fold(nodes[k].theta + d))
                .collect();
            self.building = building_direction(&votes, m.window_rad);
        }
        let Some(building) = self.building else {
            return;
        };
        let edges = priors_towards(nodes, &self.square, building, m);
        self.square.clear();
        self.stats.square_keys += edges.len();
        self.priors_pending += edges.len();
        self.graph.edges.extend(edges);
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
        self.square_walls(id);
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
        )?;
        self.stats.closures_found += 1;
        let fit = self.refine_closure(&found, &points[id], resolution_m);
        let min = self.config.refine_min_points;
        let refined =
            fit.pose.is_finite() && (fit.count * 2 >= fit.with_normal || fit.count >= min);
        if refined {
            found.edge.measurement = self.graph.nodes[found.edge.from].between(&fit.pose);
        }
        let plausible = self.plausible(&found);
        if self.config.record_trials {
            let n = &self.graph.nodes;
            let (f, t) = (found.edge.from, found.edge.to);
            self.trials.push(ClosureTrial {
                closure: ClosureRecord {
                    from_key: f,
                    to_key: t,
                    from_step: self.key_step[f],
                    to_step: self.key_step[t],
                    measurement: found.edge.measurement,
                    score: found.score,
                },
                fit,
                refined,
                correction: n[f].between(&n[t]).between(&found.edge.measurement),
                path_m: self.key_path_m[t] - self.key_path_m[f],
                plausible,
            });
        }
        if !refined {
            self.stats.closures_unrefined += 1;
            return None;
        }
        if fit.weak_m > self.config.closure_max_weak_m {
            self.stats.closures_sliding += 1;
            return None;
        }
        if !plausible {
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
    /// of the lap a quarter of a metre off. The fit also says how well the
    /// closure is pinned: the refinement's covariance `σ² (JᵀJ)⁻¹` is long
    /// along a corridor, where the match may have slid.
    fn refine_closure(&self, c: &Closure, points: &[DVec2], resolution_m: f64) -> ClosureFit {
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
        // σ² (JᵀJ)⁻¹: its largest position eigenvalue and its heading entry.
        let s2 = self.config.closure_residual_m.powi(2);
        let cov = inverse3(&r.information).map(|c| c.map(|row| row.map(|v| s2 * v)));
        let sigma = |v: f64| {
            if v.is_finite() && v > 0.0 {
                v.sqrt()
            } else {
                f64::INFINITY
            }
        };
        let (weak_m, heading_rad) = cov.map_or((f64::INFINITY, f64::INFINITY), |c| {
            let (a, b, d) = (c[0][0], c[0][1], c[1][1]);
            let largest = 0.5 * (a + d) + (0.25 * (a - d).powi(2) + b * b).sqrt();
            (sigma(largest), sigma(c[2][2]))
        });
        ClosureFit {
            heading_rad,
            pose: r.pose,
            count: r.count,
            with_normal: normals.iter().filter(|n| n.is_some()).count(),
            cost: r.cost,
            information: r.information,
            weak_m,
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
            self.start_redraw(front.map, front.pose.position());
            self.stats.map_rebuilds += 1;
        }
    }

    /// Redraws the SLAM map from the key scans at their current poses: at
    /// once those that can reach the robot's surroundings (the filter must
    /// match against the moved walls at its next scan, or it would pull the
    /// pose straight back), the rest a few per scan, nearest first
    /// ([`RobotGraph::draw_pending`]). Drawing all of an hour's 3,000 keys
    /// at once took half a second in the page's wasm build, one long task.
    /// The occupancy's log-odds add up the same in any order; the surface
    /// layer's running mean is order-dependent, but its cells near the
    /// robot, the ones the next matches read, are drawn at once.
    fn start_redraw(&mut self, map: &mut OccupancyGrid, here: DVec2) {
        *map = OccupancyGrid::new(map.config.clone());
        let reach = self.keys.first().map_or(0.0, |k| k.range_max_m);
        let near = 2.0 * reach + self.config.key_distance_m;
        let distance = |k: usize| self.graph.nodes[k].position().distance(here);
        let mut order: Vec<usize> = (0..self.keys.len()).collect();
        order.sort_by(|&a, &b| distance(b).total_cmp(&distance(a)).then(b.cmp(&a)));
        let far = order.partition_point(|&k| distance(k) > near);
        for &k in &order[far..] {
            map.integrate_scan(&self.graph.nodes[k], &self.keys[k].unpack());
        }
        order.truncate(far);
        self.redraw = order;
    }

    /// Draws up to `count` of the keys a redraw left (nearest to the robot
    /// when it began first).
    fn draw_pending(&mut self, map: &mut OccupancyGrid, count: usize) {
        for _ in 0..count {
            let Some(k) = self.redraw.pop() else {
                return;
            };
            map.integrate_scan(&self.graph.nodes[k], &self.keys[k].unpack());
        }
    }

    /// Draws every key a redraw left into `map`: the map is whole again
    /// (the end of a run).
    pub fn settle(&mut self, map: &mut OccupancyGrid) {
        self.draw_pending(map, usize::MAX);
    }

    /// Draws the keys a redraw left into `map` (a copy of the map being
    /// redrawn), in the order [`RobotGraph::settle`] would, leaving the
    /// redraw itself as it is: a paused run's map, whole, for a reader,
    /// without changing what the run does next.
    pub fn draw_remaining(&self, map: &mut OccupancyGrid) {
        for &k in self.redraw.iter().rev() {
            map.integrate_scan(&self.graph.nodes[k], &self.keys[k].unpack());
        }
    }

    /// Whether a redrawn map still lacks some key scans.
    pub fn redrawing(&self) -> bool {
        !self.redraw.is_empty()
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
        self.keys.iter().map(|k| 2 * k.ranges_mm.capacity()).sum()
    }

    /// Heap bytes the back end holds: key scans, the pose graph, the
    /// step-to-key table and the records (capacity, as the lab counts).
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of;
        self.key_bytes()
            + self.keys.capacity() * size_of::<KeyScan>()
            + self.graph.nodes.capacity() * size_of::<Pose2>()
            + self.graph.edges.capacity() * size_of::<Edge>()
            + self.key_step.capacity() * size_of::<usize>()
            + self.key_path_m.capacity() * size_of::<f64>()
            + self.step_key.capacity() * size_of::<u32>()
            + self.closures.capacity() * size_of::<ClosureRecord>()
            + self.trials.capacity() * size_of::<ClosureTrial>()
            + self.redraw.capacity() * size_of::<usize>()
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

    /// One robot's front end driving straight along x, `step_m` a scan,
    /// and its back end.
    struct Drive {
        g: RobotGraph,
        s: LaserScan,
        estimates: Vec<Pose2>,
        pose: Pose2,
        map: OccupancyGrid,
    }

    impl Drive {
        /// `steps` scans handed over, the first at the origin.
        fn new(config: RobotGraphConfig, step_m: f64, steps: usize) -> Drive {
            let mut d = Drive {
                g: RobotGraph::new(config),
                s: scan(&[1.0; 5], &[false; 5], &[false; 5]),
                estimates: vec![Pose2::IDENTITY],
                pose: Pose2::IDENTITY,
                map: OccupancyGrid::new(GridConfig::default()),
            };
            for k in 0..steps {
                if k > 0 {
                    d.estimates.push(Pose2::new(step_m * k as f64, 0.0, 0.0));
                }
                d.hand_over();
            }
            d
        }

        /// Hands the newest estimate's scan to the back end.
        fn hand_over(&mut self) {
            let Drive {
                g,
                s,
                estimates,
                pose,
                map,
            } = self;
            g.add_scan(
                s,
                None,
                FrontEnd {
                    estimates,
                    pose,
                    map,
                },
            );
        }

        /// Moves the front end as the graph moved from `before`.
        fn apply(&mut self, before: &[Pose2]) {
            let Drive {
                g,
                estimates,
                pose,
                map,
                ..
            } = self;
            g.apply(
                before,
                FrontEnd {
                    estimates,
                    pose,
                    map,
                },
            );
        }
    }

    #[test]
    fn keys_come_every_key_distance_and_steps_follow_their_key() {
        // 0.1 m a step along x: a key every 0.4 m (steps 0, 4, 8).
        let mut d = Drive::new(RobotGraphConfig::default(), 0.1, 10);
        assert_eq!(d.g.key_steps(), &[0, 4, 8]);
        assert_eq!(d.g.step_key, vec![0, 0, 0, 0, 1, 1, 1, 1, 2, 2]);
        assert_eq!(d.g.graph.edges.len(), 2);
        // Moving key 1 by 0.5 m in y moves steps 4..8 with it, not the rest.
        let before = d.g.graph.nodes.clone();
        d.g.graph.nodes[1].y += 0.5;
        d.g.graph.nodes[2].y += 0.5;
        d.apply(&before);
        assert_eq!(d.estimates[3].y, 0.0);
        assert!((d.estimates[5].y - 0.5).abs() < 1e-12);
        assert!((d.estimates[5].x - 0.5).abs() < 1e-12);
        assert!((d.pose.y - 0.5).abs() < 1e-12);
        // The map was drawn again from the three keys.
        assert_eq!(d.g.stats.map_rebuilds, 1);
        assert_eq!(d.map.scans(), 3);
    }

    #[test]
    fn a_redrawn_map_gets_the_far_keys_a_few_per_scan() {
        let config = RobotGraphConfig {
            redraw_keys_per_scan: 10,
            ..RobotGraphConfig::default()
        };
        // 0.5 m a step along x, a key each: 100 keys over 49.5 m.
        let mut d = Drive::new(config, 0.5, 100);
        assert_eq!(d.g.graph.nodes.len(), 100);
        // Every key moves 0.1 m across; the robot is at the last key.
        d.pose = Pose2::new(49.5, 0.0, 0.0);
        let before = d.g.graph.nodes.clone();
        for n in &mut d.g.graph.nodes {
            n.y += 0.1;
        }
        d.apply(&before);
        // Drawn at once: the keys within twice the reach (4 m) plus a key
        // distance (0.4 m) of the robot, 8.4 m: from x = 41.5 on, 17 keys.
        assert_eq!(d.map.scans(), 17);
        assert!(d.g.redrawing());
        // The next scan handed over draws ten more (its own is drawn by
        // the front end, not here).
        d.estimates.push(Pose2::new(49.6, 0.1, 0.0));
        d.hand_over();
        assert_eq!(d.map.scans(), 27);
        // A reader's completed copy is the map settling would make, and
        // leaves the redraw as it was.
        let mut copy = d.map.clone();
        d.g.draw_remaining(&mut copy);
        assert!(d.g.redrawing());
        assert_eq!(d.map.scans(), 27);
        d.g.settle(&mut d.map);
        assert_eq!(d.map.scans(), 100);
        assert!(!d.g.redrawing());
        assert_eq!(copy.scans(), 100);
        assert_eq!(copy.raw_units(), d.map.raw_units());
        assert_eq!(copy.origin_cell(), d.map.origin_cell());
    }
}
