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
//!    trusted as `key_sigma_*`, or `loose_sigma_*` when the filter matched
//!    nothing in between (odometry alone carried it).
//! 2. **Loop closures** ([`super::loop_closure`]): every `loop_every` keys a
//!    new key whose scan constrains every direction (not a corridor, where a
//!    match slides along the walls) is matched, by Olson's correlative
//!    search, against the older keys near its estimate.
//! 3. **Consistency.** In a maze of identical cells a closure can be wrong by
//!    a cell, the worst outcome there is: it bends the whole graph onto the
//!    wrong place. A closure is accepted only when a second one found within
//!    `confirm_keys` keys agrees with it (Olson's pairwise consistency, as
//!    the log SLAM does, [`super::logslam`]), and the optimisation that takes
//!    them must leave both satisfied (χ² at most `max_closure_chi2`), or it is
//!    undone.
//! 4. **Correction.** After an accepted closure the graph is optimised (sparse
//!    least squares), and every step's estimate moves with its key: step `k`
//!    of key `j` goes to `x_j' ⊕ x_j⁻¹ ⊕ x̂_k`, so the trajectory the lab scores
//!    is the corrected one, and the filter's current pose moves with the
//!    newest key. When some key moved by more than `rebuild_m` (a cell), the
//!    SLAM map is drawn again from the key scans at their new poses: the
//!    filter must match against walls where the graph now puts them, or it
//!    would pull the pose straight back.

use super::degeneracy::{constraint_of, scan_normals};
use super::grid::{beam_directions, GridConfig, OccupancyGrid};
use super::loop_closure::{closures_agree, find_closure, Closure, LoopConfig};
use super::multires::Window;
use super::posegraph::{Edge, PoseGraph};
use crate::geom::{wrap_angle, Pose2};
use crate::sensors::LaserScan;
use glam::DVec2;

/// Settings of the back end.
#[derive(Clone, Debug, PartialEq)]
pub struct RobotGraphConfig {
    pub key_distance_m: f64,
    pub key_angle_rad: f64,
    /// Standard deviations of a key-to-key edge where the filter matched.
    pub key_sigma_m: f64,
    pub key_sigma_rad: f64,
    /// … and where it ran on odometry alone for a step or more.
    pub loose_sigma_m: f64,
    pub loose_sigma_rad: f64,
    pub loops: LoopConfig,
    pub loop_every: usize,
    /// A key is tried for a closure only if its scan's weak eigenvalue
    /// ([`super::degeneracy`]) reaches this.
    pub min_constraint: f64,
    pub confirm_keys: usize,
    pub confirm_m: f64,
    pub confirm_rad: f64,
    pub max_closure_chi2: f64,
    /// A correction moving some key by more than this (m, or radians times
    /// the laser's reach) redraws the SLAM map.
    pub rebuild_m: f64,
}

impl Default for RobotGraphConfig {
    fn default() -> Self {
        RobotGraphConfig {
            key_distance_m: 0.4,
            key_angle_rad: 20f64.to_radians(),
            key_sigma_m: 0.02,
            key_sigma_rad: 0.5f64.to_radians(),
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
            loop_every: 2,
            min_constraint: 20.0,
            confirm_keys: 10,
            confirm_m: 0.1,
            confirm_rad: 1.5f64.to_radians(),
            max_closure_chi2: 20.0,
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
    /// The key each step's estimate follows (the last key at or before it).
    step_key: Vec<u32>,
    /// The filter ran on odometry alone since the last key.
    loose: bool,
    pending: Vec<Closure>,
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
    /// last of `front.estimates`), `matched` unless it kept odometry's word: makes a key if the
    /// robot moved far enough, looks for a loop closure, and applies an
    /// accepted one to the front end.
    pub fn add_scan(&mut self, scan: &LaserScan, matched: bool, front: FrontEnd<'_>) {
        self.loose |= !matched;
        let Some(&pose) = front.estimates.last() else {
            return;
        };
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
            let (sm, sr) = if self.loose {
                (c.loose_sigma_m, c.loose_sigma_rad)
            } else {
                (c.key_sigma_m, c.key_sigma_rad)
            };
            self.graph.edges.push(Edge::new(prev, id, z, sm, sr));
        }
        self.graph.nodes.push(pose);
        self.keys.push(KeyScan::pack(scan));
        self.loose = false;
        self.stats.keys += 1;
    }

    /// Whether the newest key is due for a closure search and its scan pins
    /// every direction.
    fn should_try(&self) -> bool {
        let id = self.graph.nodes.len() - 1;
        if id < self.config.loops.min_key_gap || id % self.config.loop_every.max(1) != 0 {
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
        let found = find_closure(
            &self.graph.nodes,
            &points,
            id,
            resolution_m,
            &self.config.loops,
        )?;
        self.stats.closures_found += 1;
        let cfg = &self.config;
        self.pending
            .retain(|c| c.edge.to + cfg.confirm_keys >= id && c.edge.to != id);
        let agreeing = self.pending.iter().position(|c| {
            closures_agree(&self.graph.nodes, c, &found, cfg.confirm_m, cfg.confirm_rad)
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

    /// Adds two agreeing closures, optimises, and moves the front end with
    /// the graph; undoes it all if a closure stays badly unsatisfied.
    fn accept(&mut self, closures: Vec<Closure>, front: FrontEnd<'_>) {
        let before = self.graph.nodes.clone();
        let edges = self.graph.edges.len();
        self.graph
            .edges
            .extend(closures.iter().map(|c| c.edge.clone()));
        let ok = self.graph.optimise(10).is_ok()
            && closures
                .iter()
                .all(|c| self.graph.chi2(&c.edge) <= self.config.max_closure_chi2);
        if !ok {
            self.graph.nodes = before;
            self.graph.edges.truncate(edges);
            self.stats.closures_rejected += closures.len();
            return;
        }
        self.stats.closures_accepted += closures.len();
        self.pending.clear();
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
        let mut map = OccupancyGrid::new(config);
        for (pose, key) in self.graph.nodes.iter().zip(&self.keys) {
            map.integrate_scan(pose, &key.unpack());
        }
        map
    }

    /// Memory the key scans hold (bytes), for the lab's budget figures.
    pub fn key_bytes(&self) -> usize {
        self.keys.iter().map(|k| 2 * k.ranges_mm.len()).sum()
    }
}
