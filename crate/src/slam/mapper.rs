//! # The two mappers: at odometry poses, and with scan-to-map matching
//!
//! The thesis built each robot's map at the poses its wheel odometry
//! reported (§4.2, §6.2.1) and names sensor noise as its first open problem
//! (Chapter 7): odometry errors accumulate, and every scan placed at a
//! drifted pose smears the map. [`RobotMapping`] runs that baseline and a
//! SLAM mapper side by side, fed the same odometry and scans, online, one
//! step at a time:
//!
//! * **odometry mapper** — integrate each scan the motion filter passes at
//!   the odometry pose.
//! * **SLAM mapper** (online SLAM in the thesis's §4.3 sense: only the
//!   current pose is estimated, by an extended Kalman filter whose
//!   measurement is a scan match, [`super::filter`]) — each step
//!   1. *predict*: move the estimate by the odometry increment,
//!      `prior = x̂_{t−1} ⊕ (o_{t−1}⁻¹ ⊕ o_t)` (the motion model
//!      `P(x_t | x_{t−1}, u_t)`), corrected by the odometry bias the filter
//!      has calibrated so far, and grow the covariance;
//!   2. *match*: refine the prior until the scan's points lie on the
//!      surfaces mapped so far ([`super::surface`]); when too few find one
//!      (the prior is off by more than a few centimetres), search a window
//!      first ([`super::correlative`], Olson 2009) — the measurement model
//!      `P(z_t | x_t, M)`;
//!   3. *guard*: where the scan does not constrain a direction
//!      ([`super::degeneracy`]) keep odometry's word along it; with too few
//!      points on the map (open space, a new room) keep the prior;
//!   4. *fuse*: weigh the match by its information `JᵀJ / σ²` (σ = 1 cm,
//!      the residual of one point) against the prior's covariance. A scan
//!      with walls in every direction outweighs odometry by far and sets
//!      the pose; a few points on one wall mostly correct the heading;
//!   5. *map*: integrate the scan at the fused pose.
//!
//!   Steps 2–5 run only for the scans the motion filter lets through.
//!
//! ## The motion filter
//! A robot moves about 3 cm in a 0.1 s step, so consecutive scans see
//! nearly the same walls from nearly the same place: matching each one and
//! fan-filling it into both maps was over half of the simulation's time
//! (`perf`: `integrate_scan` 28 %, `refine_to_surface` 27 %). GMapping
//! processes a scan only after the robot has travelled `linearUpdate` or
//! turned `angularUpdate` (G. Grisetti, C. Stachniss, W. Burgard, *Improved
//! Techniques for Grid Mapping with Rao-Blackwellized Particle Filters*,
//! IEEE T-RO 2007: 0.5–1 m and 0.25–0.5 rad, sized for its particles), and
//! Cartographer's local SLAM drops a scan unless it is `max_distance`,
//! `max_angle` or `max_time` from the last one it kept (W. Hess, D. Kohler,
//! H. Rapp, D. Andor, *Real-Time Loop Closure in 2D LIDAR SLAM*, ICRA
//! 2016; defaults 0.2 m, 1°, 5 s). [`MotionFilter`] does the same with the
//! odometry since the last processed scan: a scan is matched and mapped
//! (both mappers) once odometry has moved `min_distance_m` or turned
//! `min_angle_rad`, or `max_interval_s` has passed (a robot standing still
//! still sees the others move). Every other step only *predicts*: the
//! estimate is the filter's prior, its covariance grows, and
//! [`RobotMapping::estimates`] keeps one row per step.
//!
//! The thresholds were chosen by a sweep over the presets and mazes 11, 23
//! and 37 (`SLAM_MOTION_M=… SLAM_MOTION_DEG=… SLAM_MOTION_S=…
//! cargo run --release -p slamlab --example slam_trace -- all`; 14 robots;
//! CPU of the whole tool, which times three extra matches per processed
//! scan):
//!
//! | filter (m, °, s) | mean ATE | worst ATE | worst SLAM/odometry | CPU |
//! |---|---|---|---|---|
//! | every scan        | 0.013 m | 0.029 m | 0.040 | 13.2 s |
//! | 0.05, 2, 1        | 0.018 m | 0.049 m | 0.047 |  8.6 s |
//! | 0.06, 1.5, 1      | 0.016 m | 0.037 m | 0.034 |  9.3 s |
//! | **0.1, 3, 2**     | 0.021 m | 0.045 m | 0.065 |  6.1 s |
//! | 0.2, 5, 2         | 0.024 m | 0.055 m | 0.091 |  4.4 s |
//!
//! Map precision stayed 1.000 on every run. The price is accuracy: with
//! every scan the filter averages ~10 matches and the surface means ~10
//! scans per 10 cm travelled. Matching every scan but mapping only the
//! filtered ones (mean 0.021 m), or mapping every scan at the predicted
//! pose but matching only the filtered ones (0.025 m), gave no better, so
//! both the averaged matches and the denser surface means carry the
//! accuracy. 0.1 m, 3°, 2 s ([`MotionFilter::KNEE`]) is the knee: half
//! the SLAM time of every scan for ATE still four times inside the issue's
//! 0.1 m, and a sixth the distance of Cartographer's default.
//!
//! It is nevertheless **off for a robot's first ten minutes**
//! ([`MotionFilter::every_scan_first_s`], 600 s): the presets' figures may
//! not get worse, and with the knee from the start 50 of the 76 robot runs
//! of `tests/slam_accuracy.rs` lost accuracy (the thesis preset 0.006 →
//! 0.023 m), and the merge benchmark's maze 4 merged wrongly (maps alone,
//! 14 m / 179° off: its slightly blurrier maps let a 180°-symmetric
//! overlay through). Every preset, exercise and merge benchmark run lasts
//! at most 400 s, so all of them process every scan, as before.
//!
//! Beyond ten minutes a scan is processed after 0.2 m, 5° or 2 s
//! ([`MotionFilter::MATURE`]). That is where the long, crowded runs spend
//! their time (16 robots × 3,600 s), and there it costs nothing
//! measurable. Over that run's four maze seeds (22–25, 64 robot-hours,
//! natively, `examples/run.rs SCENARIO simulate`):
//!
//! | after 600 s (m, °, s) | mean SLAM ATE | robot-hours over 0.1 m |
//! |---|---|---|
//! | every scan            | 0.0415 m | 6 |
//! | 0.1, 3, 2 (the knee)  | 0.0418 m | 6 |
//! | **0.2, 5, 2**         | 0.0410 m | 5 |
//! | 0.3, 8, 3             | 0.0437 m | 6 |
//!
//! Side by side on the hour of seed 22, 0.2 m takes 12 % less CPU than the
//! knee and about a third less of the SLAM's CPU in node than every scan
//! (docs/history/issue-22-many-robots.md, round 23); 0.3 m saves a little
//! more but starts to cost accuracy.
//!
//! The robot-hours over 0.1 m are whole maps turned in their first seconds
//! (docs/history/issue-22-many-robots.md, round 19), the same robots in
//! every row. The first minutes are where a map can be turned for good (a
//! few scans, a degenerate view); a map ten minutes old is matched against
//! walls seen many times. [`MotionFilter::EVERY_SCAN`] processes every scan throughout
//! (`SlamConfig::motion`; `SLAM_MOTION_M`, `SLAM_MOTION_DEG`,
//! `SLAM_MOTION_S`, `SLAM_MOTION_FIRST_S` in `examples/slam_trace.rs` and
//! `examples/sim_drift.rs`).
//!
//! ## What the numbers taught
//! Measured against ground truth per step (`examples/slam_trace.rs`), an
//! earlier version of this mapper had three faults, each a cause rather
//! than a tuning:
//!
//! * **Half-cell lock.** It refined on the occupancy map interpolated
//!   bilinearly; that interpolant peaks at cell centres, so every run whose
//!   walls lay on cell boundaries settled exactly (±0.025, ±0.025) m off.
//!   The refinement now measures points against per-cell hit means.
//! * **Edge pull.** Points just past the mapped end of a wall scored more
//!   when slid back onto it, which turned the pose by a degree each time the
//!   robot turned into new space. Point-to-surface distances along the
//!   normal cannot pull along a wall.
//! * **Leaking drift.** It moved a fixed quarter of the way to each match.
//!   The match is relative to the map, so its noise does not accumulate,
//!   but odometry's drift does; a quarter-gain lets three quarters of each
//!   step's odometry error into every newly mapped wall, and the map bends
//!   with it. The filter weighs each match by what it actually constrains.
//!
//! Poses and maps are in the robot's odometry frame (origin at its start
//! pose). Neither mapper ever sees the true pose.

use super::correlative::{search, CorrelativeConfig};
use super::degeneracy::{constraint_of, scan_normals, ScanConstraint};
pub use super::filter::OdometryNoise;
use super::filter::PoseFilter;
use super::gauss_newton;
use super::grid::{beam_directions, GridConfig, OccupancyGrid};
use super::likelihood::LikelihoodField;
use super::robot_graph::{FrontEnd, RobotGraph, RobotGraphConfig, StepMatch};
use super::surface::{information_at, refine_to_surface, RefineConfig, Refinement};
use crate::geom::{wrap_angle, Pose2};
use crate::kinematics::CONTROL_DT_S;
use crate::sensors::LaserScan;
use glam::DVec2;

/// Settings of the SLAM mapper.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SlamConfig {
    pub grid: GridConfig,
    pub search: CorrelativeConfig,
    pub refine: RefineConfig,
    /// Fewer usable points than this (or fewer on mapped surfaces): no
    /// matching, odometry only.
    pub min_points: usize,
    /// Weak eigenvalue of the scan's information below this: degenerate.
    pub min_constraint: f64,
    /// Share of the scan's points on mapped surfaces below which a match is
    /// not trusted.
    pub min_score: f64,
    /// When fewer than this share of the points with a normal find a
    /// surface from the prior, the correlative search runs first.
    pub search_below: f64,
    /// Standard deviation of one point's distance to its surface (m): the
    /// match's information is `JᵀJ / σ²`.
    pub match_noise_m: f64,
    /// A match whose normalised innovation squared exceeds this is not
    /// fused ([`super::filter`]'s validation gate).
    pub innovation_gate: f64,
    pub odometry_noise: OdometryNoise,
    /// When a scan is worth matching and mapping ([`MotionFilter`]).
    pub motion: MotionFilter,
    /// Whether [`RobotMapping::new`] runs the loop-closing back end
    /// ([`super::robot_graph`]) beside the filter.
    pub back_end: bool,
    /// The back end's settings (its odometry noise is taken from
    /// `odometry_noise`).
    pub graph: RobotGraphConfig,
}

impl Default for SlamConfig {
    fn default() -> Self {
        SlamConfig {
            grid: GridConfig::default(),
            search: CorrelativeConfig::default(),
            refine: RefineConfig::default(),
            min_points: 10,
            min_constraint: 6.0,
            min_score: 0.15,
            search_below: 0.5,
            match_noise_m: 0.01,
            innovation_gate: 30.0,
            odometry_noise: OdometryNoise::default(),
            motion: MotionFilter::default(),
            back_end: true,
            graph: RobotGraphConfig::default(),
        }
    }
}

/// GMapping's `linearUpdate` / `angularUpdate` and Cartographer's
/// `motion_filter`: a scan is matched and mapped only once odometry has
/// moved `min_distance_m` or turned `min_angle_rad` since the last scan
/// that was, or after `max_interval_s` whatever the motion; every scan of
/// the run's first `every_scan_first_s` seconds is (see the module's
/// "Motion filter" section for how the values were chosen).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MotionFilter {
    pub min_distance_m: f64,
    pub min_angle_rad: f64,
    pub max_interval_s: f64,
    /// Every scan taken up to this time of the run (s) is processed.
    pub every_scan_first_s: f64,
}

impl Default for MotionFilter {
    /// Every scan for the first ten minutes, then [`MotionFilter::MATURE`]
    /// (see the module doc: from the start it costs accuracy the presets'
    /// figures may not lose).
    fn default() -> Self {
        MotionFilter {
            every_scan_first_s: 600.0,
            ..MotionFilter::MATURE
        }
    }
}

impl MotionFilter {
    /// The knee of the measured sweep: 0.1 m, 3°, 2 s.
    pub const KNEE: MotionFilter = MotionFilter {
        min_distance_m: 0.1,
        min_angle_rad: 3.0 * std::f64::consts::PI / 180.0,
        max_interval_s: 2.0,
        every_scan_first_s: 0.0,
    };

    /// For a map ten minutes old: 0.2 m, 5°, 2 s (the sweep's last row).
    pub const MATURE: MotionFilter = MotionFilter {
        min_distance_m: 0.2,
        min_angle_rad: 5.0 * std::f64::consts::PI / 180.0,
        max_interval_s: 2.0,
        every_scan_first_s: 0.0,
    };

    /// Every scan processed: the mapper as it was before the filter.
    pub const EVERY_SCAN: MotionFilter = MotionFilter {
        min_distance_m: 0.0,
        min_angle_rad: 0.0,
        max_interval_s: 0.0,
        every_scan_first_s: 0.0,
    };

    /// Whether a scan taken `moved` (odometry, since the last processed
    /// scan) and `steps` control steps after that scan, at step `step` of
    /// the run, is processed.
    pub fn passes(&self, moved: &Pose2, steps: usize, step: usize) -> bool {
        step as f64 * CONTROL_DT_S <= self.every_scan_first_s + 1e-9
            || moved.position().length() >= self.min_distance_m
            || wrap_angle(moved.theta).abs() >= self.min_angle_rad
            || steps as f64 * CONTROL_DT_S >= self.max_interval_s - 1e-9
    }
}

/// What the matcher did with a scan.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MatchStatus {
    /// Corrected in every direction.
    Matched,
    /// Corrected across the weak direction only (corridor).
    Degenerate,
    /// Too little to match (or an empty map): the odometry prior kept.
    OdometryOnly,
}

/// The outcome of matching one scan.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MatchOutcome {
    pub pose: Pose2,
    pub status: MatchStatus,
    /// Share of the scan's points that lie on mapped surfaces.
    pub score: f64,
    pub constraint: ScanConstraint,
    /// The match's information about `(x, y, θ)` (zero when unmatched).
    pub information: [[f64; 3]; 3],
}

/// Scan end points usable for matching (walls within range), robot frame,
/// in beam order.
pub fn scan_points(scan: &LaserScan) -> Vec<DVec2> {
    beam_directions(0.0, scan.ranges_m.len())
        .enumerate()
        .filter(|&(i, _)| {
            scan.max_range.get(i) == Some(&false)
                && scan.reflective.get(i) == Some(&false)
                && scan.ranges_m[i] > 0.05
        })
        .map(|(i, d)| d * scan.ranges_m[i])
        .collect()
}

/// Matches `scan` against `map` around `prior`: Gauss–Newton onto the
/// mapped surfaces from the prior; if too few points find a surface there
/// (the prior is off by more than the refinement can see), the correlative
/// search first; then the degeneracy guard.
pub fn match_scan(
    map: &OccupancyGrid,
    scan: &LaserScan,
    prior: &Pose2,
    cfg: &SlamConfig,
) -> MatchOutcome {
    let points = scan_points(scan);
    let normals = scan_normals(&points);
    let keep = MatchOutcome {
        pose: *prior,
        status: MatchStatus::OdometryOnly,
        score: 0.0,
        constraint: constraint_of(&normals, &vec![false; points.len()]),
        information: [[0.0; 3]; 3],
    };
    if points.len() < cfg.min_points || map.width() == 0 {
        return keep;
    }
    let best = if map.has_surface() {
        let with_normal = normals.iter().filter(|n| n.is_some()).count();
        let mut best = refine_to_surface(map, &points, &normals, prior, &cfg.refine);
        if (best.count as f64) < cfg.search_below * with_normal as f64 {
            if let Some((_, coarse)) = coarse_search(map, scan, &points, prior, cfg) {
                let from_search = refine_to_surface(map, &points, &normals, &coarse, &cfg.refine);
                if from_search.count as f64 > 1.2 * best.count as f64 {
                    best = from_search;
                }
            }
        }
        best
    } else {
        // A grid without the sub-cell surface layer: Olson's search, then
        // Hector's Gauss–Newton on the smoothed map (good to about a
        // cell; see [`super::surface`] on why it is not the default).
        let Some((field, coarse)) = coarse_search(map, scan, &points, prior, cfg) else {
            return keep;
        };
        let (pose, _) = gauss_newton::refine(&field, &points, &coarse, FIELD_REFINE_ITERATIONS);
        let associated: Vec<bool> = points
            .iter()
            .map(|&p| field.bilinear(pose.transform_point(p)).0 >= ON_WALL_FIELD)
            .collect();
        Refinement {
            pose,
            count: associated.iter().filter(|&&a| a).count(),
            cost: 0.0,
            information: information_at(&points, &normals, &associated, &pose),
            associated,
        }
    };
    let score = best.count as f64 / points.len() as f64;
    if score < cfg.min_score || best.count < cfg.min_points {
        return MatchOutcome { score, ..keep };
    }
    let refined = best.pose;
    let scale = 1.0 / (cfg.match_noise_m * cfg.match_noise_m).max(1e-12);
    let information = best.information.map(|row| row.map(|v| v * scale));
    // Only points that land on walls already in the map constrain the match:
    // the end wall of a corridor seen for the first time says nothing yet.
    let constraint = constraint_of(&normals, &best.associated);
    if constraint.is_degenerate(cfg.min_constraint) {
        // Keep the correction across the weak direction only.
        let weak = Pose2::new(0.0, 0.0, refined.theta).transform_point(constraint.weak_direction);
        let d = refined.position() - prior.position();
        let across = d - weak * d.dot(weak);
        return MatchOutcome {
            pose: Pose2::new(prior.x + across.x, prior.y + across.y, refined.theta),
            status: MatchStatus::Degenerate,
            score,
            constraint,
            information,
        };
    }
    MatchOutcome {
        pose: refined,
        status: MatchStatus::Matched,
        score,
        constraint,
        information,
    }
}

/// Smoothed-map value above which a point counts as on a wall, and
/// Gauss–Newton steps on the smoothed map (for grids without surface means).
const ON_WALL_FIELD: f64 = 0.15;
const FIELD_REFINE_ITERATIONS: usize = 6;

/// Olson's correlative search around `prior` on the smoothed map (which it
/// returns too).
fn coarse_search(
    map: &OccupancyGrid,
    scan: &LaserScan,
    points: &[DVec2],
    prior: &Pose2,
    cfg: &SlamConfig,
) -> Option<(LikelihoodField, Pose2)> {
    // The field covers the points at the prior, plus the search window and
    // the rotation's sweep, plus a blur margin.
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    let frame = prior.frame();
    for &p in points {
        let q = frame.to_parent(p);
        lo = lo.min(q);
        hi = hi.max(q);
    }
    let sweep = cfg.search.angular_window_rad * scan.range_max_m;
    let margin = cfg.search.linear_window_m + sweep + 4.0 * map.resolution_m();
    let field = LikelihoodField::build(
        map,
        map.global_cell(lo - margin),
        map.global_cell(hi + margin),
        cfg.search.coarse_cells,
    );
    let pose = search(&field, points, prior, &cfg.search)?.pose;
    Some((field, pose))
}

/// How often each outcome happened.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MatchCounts {
    pub matched: usize,
    pub degenerate: usize,
    pub odometry_only: usize,
    /// Steps the motion filter left to the prediction alone (no match,
    /// nothing mapped).
    pub predicted: usize,
}

/// One robot's two mappers, run online inside the simulation.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct RobotMapping {
    pub config: SlamConfig,
    /// The thesis's baseline: scans at raw odometry poses.
    pub odometry_map: OccupancyGrid,
    /// Scans at the matched poses.
    pub slam_map: OccupancyGrid,
    /// SLAM pose per step (row 0 = the start, identity), odometry frame.
    estimates: Vec<Pose2>,
    /// The current pose and odometry's calibration (odometry frame).
    filter: PoseFilter,
    last_odometry: Pose2,
    /// Odometry pose and step of the last processed scan (`None` before
    /// the first).
    last_processed: Option<(Pose2, usize)>,
    pub counts: MatchCounts,
    pub last_outcome: Option<MatchOutcome>,
    /// The loop-closing back end ([`super::robot_graph`]), made when
    /// [`SlamConfig::back_end`] is set (the default); `None` runs the
    /// filter alone.
    pub graph: Option<RobotGraph>,
}

impl Default for RobotMapping {
    fn default() -> Self {
        RobotMapping::new(SlamConfig::default())
    }
}

impl RobotMapping {
    pub fn new(config: SlamConfig) -> RobotMapping {
        let noise = config.odometry_noise.clone();
        let graph = config.back_end.then(|| {
            RobotGraph::new(RobotGraphConfig {
                odometry: config.odometry_noise.clone(),
                ..config.graph.clone()
            })
        });
        RobotMapping {
            odometry_map: OccupancyGrid::new(GridConfig {
                surface_points: false,
                ..config.grid.clone()
            }),
            slam_map: OccupancyGrid::new(GridConfig {
                surface_points: true,
                ..config.grid.clone()
            }),
            config,
            estimates: vec![Pose2::IDENTITY],
            // The start pose is the frame's origin: known exactly.
            filter: PoseFilter::new(Pose2::IDENTITY, &noise),
            last_odometry: Pose2::IDENTITY,
            last_processed: None,
            counts: MatchCounts::default(),
            last_outcome: None,
            graph,
        }
    }

    /// SLAM poses so far, one per step from the start (odometry frame).
    pub fn estimates(&self) -> &[Pose2] {
        &self.estimates
    }

    /// The current SLAM pose.
    pub fn estimate(&self) -> Pose2 {
        *self.estimates.last().unwrap_or(&Pose2::IDENTITY)
    }

    /// The SLAM pose the next scan would be matched from: the current
    /// estimate moved by the odometry increment since the last step
    /// (corrected by the calibrated odometry bias).
    pub fn prior(&self, odometry: &Pose2) -> Pose2 {
        self.filter.predicted(&self.last_odometry.between(odometry))
    }

    /// Covariance of the current estimate (x, y in m, θ in rad).
    pub fn covariance(&self) -> [[f64; 3]; 3] {
        self.filter.pose_covariance()
    }

    /// Odometry's heading bias as calibrated so far: radians per metre
    /// driven and per radian turned.
    pub fn odometry_bias(&self) -> [f64; 2] {
        self.filter.bias
    }

    /// Whether the motion filter lets the scan taken at `odometry` (the
    /// next step's) be matched and mapped.
    pub fn will_process(&self, odometry: &Pose2) -> bool {
        match self.last_processed {
            None => true,
            Some((at, step)) => self.config.motion.passes(
                &at.between(odometry),
                self.estimates.len() - step,
                self.estimates.len(),
            ),
        }
    }

    /// One step: the new odometry pose and the scan taken there. The
    /// filter always predicts; the scan is matched and integrated into
    /// both maps only when the motion filter passes it.
    pub fn observe(&mut self, odometry: &Pose2, scan: &LaserScan) {
        let process = self.will_process(odometry);
        let step = self.last_odometry.between(odometry);
        self.filter.predict(&step, &self.config.odometry_noise);
        self.last_odometry = *odometry;
        if !process {
            self.counts.predicted += 1;
            self.estimates.push(self.filter.pose);
            return;
        }
        self.last_processed = Some((*odometry, self.estimates.len()));
        self.odometry_map.integrate_scan(odometry, scan);
        let prior = self.filter.pose;
        let mut outcome = match_scan(&self.slam_map, scan, &prior, &self.config);
        if outcome.status != MatchStatus::OdometryOnly
            && !self.filter.update(
                &outcome.pose,
                &outcome.information,
                self.config.innovation_gate,
            )
        {
            // Outside the gate: this step is odometry's (see super::filter).
            outcome.status = MatchStatus::OdometryOnly;
        }
        outcome.pose = self.filter.pose;
        match outcome.status {
            MatchStatus::Matched => self.counts.matched += 1,
            MatchStatus::Degenerate => self.counts.degenerate += 1,
            MatchStatus::OdometryOnly => self.counts.odometry_only += 1,
        }
        self.slam_map.integrate_scan(&outcome.pose, scan);
        self.estimates.push(outcome.pose);
        if let Some(graph) = &mut self.graph {
            graph.add_scan(
                scan,
                step_match(&outcome),
                FrontEnd {
                    estimates: &mut self.estimates,
                    pose: &mut self.filter.pose,
                    map: &mut self.slam_map,
                },
            );
        }
        self.last_outcome = Some(outcome);
    }

    /// Completes a SLAM map the back end is still redrawing after a loop
    /// closure (it draws a few key scans per step): call at the end of a
    /// run, before the map is read as the run's result.
    pub fn settle(&mut self) {
        if let Some(graph) = &mut self.graph {
            graph.settle(&mut self.slam_map);
        }
    }

    /// The map of one mapper as it will be once a redraw the back end
    /// spreads over the next scans is done ([`RobotGraph::draw_remaining`]):
    /// the map itself, or a completed copy while a redraw is under way. For
    /// readers of a paused run (a map downloaded or exported), which must
    /// not settle the map themselves: the run would then go on differently.
    pub fn settled_map(&self, which: MapperKind) -> std::borrow::Cow<'_, OccupancyGrid> {
        match (&self.graph, which) {
            (Some(g), MapperKind::Slam) if g.redrawing() => {
                let mut map = self.slam_map.clone();
                g.draw_remaining(&mut map);
                std::borrow::Cow::Owned(map)
            }
            _ => std::borrow::Cow::Borrowed(self.map(which)),
        }
    }

    /// The map of one mapper.
    pub fn map(&self, which: MapperKind) -> &OccupancyGrid {
        match which {
            MapperKind::Odometry => &self.odometry_map,
            MapperKind::Slam => &self.slam_map,
        }
    }
}

/// What the back end needs of a match (see [`super::key_chain`]): its
/// information and, when degenerate, the weak direction in the world frame.
fn step_match(outcome: &MatchOutcome) -> Option<StepMatch> {
    let weak_direction = match outcome.status {
        MatchStatus::OdometryOnly => return None,
        MatchStatus::Matched => None,
        MatchStatus::Degenerate => Some(
            Pose2::new(0.0, 0.0, outcome.pose.theta)
                .transform_point(outcome.constraint.weak_direction),
        ),
    };
    Some(StepMatch {
        information: outcome.information,
        weak_direction,
    })
}

/// Which of a robot's two maps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MapperKind {
    Odometry,
    Slam,
}

impl MapperKind {
    /// `"slam"` or `"odometry"`.
    pub fn parse(s: &str) -> Result<MapperKind, String> {
        match s {
            "slam" => Ok(MapperKind::Slam),
            "odometry" => Ok(MapperKind::Odometry),
            other => Err(format!("mapper: '{other}' is not 'slam' or 'odometry'")),
        }
    }
}
