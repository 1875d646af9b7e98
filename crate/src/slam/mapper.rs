//! # The two mappers: at odometry poses, and with scan-to-map matching
//!
//! The thesis built each robot's map at the poses its wheel odometry
//! reported (§4.2, §6.2.1) and names sensor noise as its first open problem
//! (Chapter 7): odometry errors accumulate, and every scan placed at a
//! drifted pose smears the map. [`RobotMapping`] runs that baseline and a
//! SLAM mapper side by side, fed the same odometry and scans, online, one
//! step at a time:
//!
//! * **odometry mapper** — integrate each scan at the odometry pose.
//! * **SLAM mapper** (online SLAM in the thesis's §4.3 sense: only the
//!   current pose is estimated) — each step
//!   1. *predict*: move the last estimate by the odometry increment,
//!      `prior = x̂_{t−1} ⊕ (o_{t−1}⁻¹ ⊕ o_t)` (the motion model
//!      `P(x_t | x_{t−1}, u_t)`);
//!   2. *match*: search around the prior for the pose that best lays the
//!      scan on the map built so far ([`super::correlative`], Olson 2009),
//!      then refine it to sub-cell precision ([`super::gauss_newton`],
//!      Hector SLAM) — the measurement model `P(z_t | x_t, M)`;
//!   3. *fuse*: move the prior a share `gain` (¼) of the way to the match.
//!      Per step, odometry's increment is far more precise (≈ 0.4 mm of
//!      slip) than one match (about a cell, a fraction of a degree), while
//!      odometry's *drift* is slow; a fixed-gain filter keeps the best of
//!      both: the match's noise averages out over a few steps, the drift
//!      is corrected within a second. (It is the steady state of a Kalman
//!      filter with constant noise, the simplest fusion of the two.)
//!   4. *guard*: where the scan does not constrain a direction
//!      ([`super::degeneracy`]) keep odometry's word along it; with too few
//!      points (open space, all beams max-range) keep the prior;
//!   5. *map*: integrate the scan at the corrected pose.
//!
//! Poses and maps are in the robot's odometry frame (origin at its start
//! pose). Neither mapper ever sees the true pose.

use super::correlative::{search, CorrelativeConfig};
use super::degeneracy::{analyse, ScanConstraint};
use super::gauss_newton::refine;
use super::grid::{GridConfig, OccupancyGrid};
use super::likelihood::LikelihoodField;
use crate::geom::{wrap_angle, Pose2};
use crate::sensors::laser::beam_bearing;
use crate::sensors::LaserScan;
use glam::DVec2;

/// Settings of the SLAM mapper.
#[derive(Clone, Debug, PartialEq)]
pub struct SlamConfig {
    pub grid: GridConfig,
    pub search: CorrelativeConfig,
    pub gauss_newton_iterations: usize,
    /// Fewer usable points than this: no matching, odometry only.
    pub min_points: usize,
    /// Weak eigenvalue of the scan's information below this: degenerate.
    pub min_constraint: f64,
    /// Mean smoothed-map score below which a match is not trusted.
    pub min_score: f64,
    /// Share of the match's correction applied each step (a fixed-gain
    /// fusion of the match with odometry's prior, see the module doc).
    pub gain: f64,
}

impl Default for SlamConfig {
    fn default() -> Self {
        SlamConfig {
            grid: GridConfig::default(),
            search: CorrelativeConfig::default(),
            gauss_newton_iterations: 6,
            min_points: 20,
            min_constraint: 6.0,
            min_score: 0.15,
            gain: 0.25,
        }
    }
}

/// What the matcher did with a scan.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
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
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MatchOutcome {
    pub pose: Pose2,
    pub status: MatchStatus,
    pub score: f64,
    pub constraint: ScanConstraint,
}

/// Scan end points usable for matching (walls within range), robot frame,
/// in beam order.
pub fn scan_points(scan: &LaserScan) -> Vec<DVec2> {
    (0..scan.ranges_m.len())
        .filter(|&i| !scan.max_range[i] && !scan.reflective[i] && scan.ranges_m[i] > 0.05)
        .map(|i| {
            let a = beam_bearing(i);
            DVec2::new(a.cos(), a.sin()) * scan.ranges_m[i]
        })
        .collect()
}

/// Matches `scan` against `map` around `prior`: correlative search, then
/// Gauss–Newton, then the degeneracy guard.
pub fn match_scan(
    map: &OccupancyGrid,
    scan: &LaserScan,
    prior: &Pose2,
    cfg: &SlamConfig,
) -> MatchOutcome {
    let points = scan_points(scan);
    let constraint = analyse(&points, &vec![true; points.len()]);
    let keep = MatchOutcome {
        pose: *prior,
        status: MatchStatus::OdometryOnly,
        score: 0.0,
        constraint,
    };
    if points.len() < cfg.min_points || map.width() == 0 {
        return keep;
    }
    // The field covers the points at the prior, plus the search window and
    // the rotation's sweep, plus a blur margin.
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for &p in &points {
        let q = prior.transform_point(p);
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
    let Some(coarse) = search(&field, &points, prior, &cfg.search) else {
        return keep;
    };
    let (refined, score) = refine(&field, &points, &coarse.pose, cfg.gauss_newton_iterations);
    if score < cfg.min_score {
        return MatchOutcome { score, ..keep };
    }
    // Only points that land on walls already in the map constrain the match:
    // the end wall of a corridor seen for the first time says nothing yet.
    let on_map: Vec<bool> = points
        .iter()
        .map(|&p| field.bilinear(refined.transform_point(p)).0 >= cfg.min_score)
        .collect();
    let constraint = analyse(&points, &on_map);
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
        };
    }
    MatchOutcome {
        pose: refined,
        status: MatchStatus::Matched,
        score,
        constraint,
    }
}

/// `prior` moved a share `gain` of the way to `matched`.
pub fn blend(prior: &Pose2, matched: &Pose2, gain: f64) -> Pose2 {
    Pose2::new(
        prior.x + gain * (matched.x - prior.x),
        prior.y + gain * (matched.y - prior.y),
        wrap_angle(prior.theta + gain * wrap_angle(matched.theta - prior.theta)),
    )
}

/// How often each outcome happened.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct MatchCounts {
    pub matched: usize,
    pub degenerate: usize,
    pub odometry_only: usize,
}

/// One robot's two mappers, run online inside the simulation.
#[derive(Clone, Debug)]
pub struct RobotMapping {
    pub config: SlamConfig,
    /// The thesis's baseline: scans at raw odometry poses.
    pub odometry_map: OccupancyGrid,
    /// Scans at the matched poses.
    pub slam_map: OccupancyGrid,
    /// SLAM pose per step (row 0 = the start, identity), odometry frame.
    estimates: Vec<Pose2>,
    last_odometry: Pose2,
    pub counts: MatchCounts,
    pub last_outcome: Option<MatchOutcome>,
}

impl Default for RobotMapping {
    fn default() -> Self {
        RobotMapping::new(SlamConfig::default())
    }
}

impl RobotMapping {
    pub fn new(config: SlamConfig) -> RobotMapping {
        RobotMapping {
            odometry_map: OccupancyGrid::new(config.grid.clone()),
            slam_map: OccupancyGrid::new(config.grid.clone()),
            config,
            estimates: vec![Pose2::IDENTITY],
            last_odometry: Pose2::IDENTITY,
            counts: MatchCounts::default(),
            last_outcome: None,
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
    /// estimate moved by the odometry increment since the last step.
    pub fn prior(&self, odometry: &Pose2) -> Pose2 {
        self.estimate()
            .compose(&self.last_odometry.between(odometry))
    }

    /// One step: the new odometry pose and the scan taken there.
    pub fn observe(&mut self, odometry: &Pose2, scan: &LaserScan) {
        self.odometry_map.integrate_scan(odometry, scan);
        let prior = self.prior(odometry);
        let mut outcome = match_scan(&self.slam_map, scan, &prior, &self.config);
        outcome.pose = blend(&prior, &outcome.pose, self.config.gain);
        match outcome.status {
            MatchStatus::Matched => self.counts.matched += 1,
            MatchStatus::Degenerate => self.counts.degenerate += 1,
            MatchStatus::OdometryOnly => self.counts.odometry_only += 1,
        }
        self.slam_map.integrate_scan(&outcome.pose, scan);
        self.estimates.push(outcome.pose);
        self.last_odometry = *odometry;
        self.last_outcome = Some(outcome);
    }

    /// The map of one mapper.
    pub fn map(&self, which: MapperKind) -> &OccupancyGrid {
        match which {
            MapperKind::Odometry => &self.odometry_map,
            MapperKind::Slam => &self.slam_map,
        }
    }
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
