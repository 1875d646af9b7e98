//! # Scoring the mappers against ground truth
//!
//! The truth is read here and nowhere upstream: these figures grade the
//! estimators, they never feed them.
//!
//! * **Absolute trajectory error** (Sturm et al., *A Benchmark for the
//!   Evaluation of RGB-D SLAM Systems*, IROS 2012, §V-A): the RMSE of
//!   position over every step. The odometry frame's origin *is* the true
//!   start pose, so an estimate `x̂` maps into the world as `start ⊕ x̂` with
//!   no fitted alignment: a fit would hide a heading error made early.
//!   Beside it, **the aligned ATE**: the same RMSE after the rigid motion
//!   (rotation and shift in the plane) that best fits the estimate onto
//!   the truth, as Sturm et al. define the benchmark's figure (Horn's
//!   closed form, here in 2-D). The two differ by what no SLAM can see: a
//!   heading error odometry made before the first wall came into view
//!   turns the whole map, and only the start-aligned figure counts it.
//! * **Final-pose error**: the same at the last step.
//! * **Occupied precision**: the share of occupied cells whose centre lies
//!   within 0.15 m of a true wall (a smeared map puts walls where none are).
//! * **Wall coverage**: the share of true wall length (sampled every
//!   0.05 m) with an occupied cell within 0.15 m — how much the robot saw.

use crate::geom::Pose2;
use crate::slam::grid::{CellState, OccupancyGrid};
use crate::world::World;
use glam::DVec2;

/// Distance within which a cell counts as on a wall (m).
pub const WALL_TOLERANCE_M: f64 = 0.15;

/// RMSE of position between `start ⊕ estimate[k]` and `truth[k]` over the
/// common steps (0 when there are none).
pub fn ate_m(start: &Pose2, estimates: &[Pose2], truth: &[Pose2]) -> f64 {
    let n = estimates.len().min(truth.len());
    if n == 0 {
        return 0.0;
    }
    let sum: f64 = estimates
        .iter()
        .zip(truth)
        .map(|(e, t)| (start.compose(e).position() - t.position()).length_squared())
        .sum();
    (sum / n as f64).sqrt()
}

/// RMSE of position between `start ⊕ estimate[k]` and `truth[k]` after the
/// rigid motion that best fits the one onto the other (see the module doc;
/// 0 when there are no common steps). With centroids `p̄`, `q̄` of the
/// estimate's and the truth's positions and `a = p − p̄`, `b = q − q̄`, the
/// least-squares rotation is `φ = atan2(Σ a × b, Σ a · b)` and the shift
/// `q̄ − R(φ) p̄`.
pub fn ate_aligned_m(start: &Pose2, estimates: &[Pose2], truth: &[Pose2]) -> f64 {
    let n = estimates.len().min(truth.len());
    if n == 0 {
        return 0.0;
    }
    let p: Vec<DVec2> = estimates[..n]
        .iter()
        .map(|e| start.compose(e).position())
        .collect();
    let q: Vec<DVec2> = truth[..n].iter().map(Pose2::position).collect();
    let (pc, qc) = (
        p.iter().copied().sum::<DVec2>() / n as f64,
        q.iter().copied().sum::<DVec2>() / n as f64,
    );
    let (mut cross, mut dot) = (0.0, 0.0);
    for (a, b) in p.iter().zip(&q) {
        let (a, b) = (*a - pc, *b - qc);
        cross += a.perp_dot(b);
        dot += a.dot(b);
    }
    let rotation = DVec2::from_angle(cross.atan2(dot));
    let sum: f64 = p
        .iter()
        .zip(&q)
        .map(|(a, b)| (rotation.rotate(*a - pc) + qc - *b).length_squared())
        .sum();
    (sum / n as f64).sqrt()
}

/// The rigid transform that best lays the points `p` onto `q` (least
/// squares over the pairs, Horn's closed form in 2-D): `q[i] ≈ fit ⊕ p[i]`,
/// the alignment [`ate_aligned_m`] scores after. `None` without pairs.
pub fn best_fit(p: &[DVec2], q: &[DVec2]) -> Option<Pose2> {
    let n = p.len().min(q.len());
    if n == 0 {
        return None;
    }
    let pc = p[..n].iter().copied().sum::<DVec2>() / n as f64;
    let qc = q[..n].iter().copied().sum::<DVec2>() / n as f64;
    let (mut cross, mut dot) = (0.0, 0.0);
    for (a, b) in p.iter().zip(q) {
        let (a, b) = (*a - pc, *b - qc);
        cross += a.perp_dot(b);
        dot += a.dot(b);
    }
    let theta = cross.atan2(dot);
    let t = qc - DVec2::from_angle(theta).rotate(pc);
    Some(Pose2::new(t.x, t.y, theta))
}

/// Position error per step (m), same alignment as [`ate_m`].
pub fn position_errors_m(start: &Pose2, estimates: &[Pose2], truth: &[Pose2]) -> Vec<f64> {
    estimates
        .iter()
        .zip(truth)
        .map(|(e, t)| (start.compose(e).position() - t.position()).length())
        .collect()
}

/// Map accuracy against the true walls.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct MapAccuracy {
    pub occupied_cells: usize,
    /// Share of occupied cells within [`WALL_TOLERANCE_M`] of a true wall
    /// (1 when there are none).
    pub occupied_precision: f64,
    /// Share of true wall length with an occupied cell within tolerance.
    pub wall_coverage: f64,
}

/// Scores a map kept in the odometry frame of a robot that started at
/// `start` (world frame).
pub fn map_accuracy(grid: &OccupancyGrid, start: &Pose2, world: &World) -> MapAccuracy {
    let mut near = Vec::new();
    let (mut occupied, mut on_wall) = (0usize, 0usize);
    let tol = DVec2::splat(WALL_TOLERANCE_M);
    for iy in 0..grid.height() {
        for ix in 0..grid.width() {
            if grid.state(ix, iy) != CellState::Occupied {
                continue;
            }
            occupied += 1;
            let p = start.transform_point(grid.cell_centre(ix, iy));
            world.walls_in_box(p - tol, p + tol, &mut near);
            if near
                .iter()
                .any(|&w| world.walls()[w].distance_to_point(p) <= WALL_TOLERANCE_M)
            {
                on_wall += 1;
            }
        }
    }
    // Coverage: wall samples with an occupied cell within tolerance.
    let (mut samples, mut seen) = (0usize, 0usize);
    let r = grid.resolution_m();
    let reach = (WALL_TOLERANCE_M / r).ceil() as i64 + 1;
    let inv = start.inverse();
    for w in world.walls() {
        let n = (w.length() / 0.05).ceil().max(1.0) as usize;
        for k in 0..=n {
            let p = w.a + (w.b - w.a) * (k as f64 / n as f64);
            samples += 1;
            let q = inv.transform_point(p);
            let c = grid.global_cell(q);
            let mut found = false;
            'search: for dy in -reach..=reach {
                for dx in -reach..=reach {
                    let g = [c[0] + dx, c[1] + dy];
                    if let Some((x, y)) = grid.local(g) {
                        if grid.state(x, y) == CellState::Occupied
                            && grid.cell_centre(x, y).distance(q) <= WALL_TOLERANCE_M
                        {
                            found = true;
                            break 'search;
                        }
                    }
                }
            }
            seen += found as usize;
        }
    }
    MapAccuracy {
        occupied_cells: occupied,
        occupied_precision: if occupied == 0 {
            1.0
        } else {
            on_wall as f64 / occupied as f64
        },
        wall_coverage: if samples == 0 {
            0.0
        } else {
            seen as f64 / samples as f64
        },
    }
}
