//! # Gauss–Newton refinement on the smoothed map (Hector SLAM)
//!
//! S. Kohlbrecher, O. von Stryk, J. Meyer, U. Klingauf, *A Flexible and
//! Scalable SLAM System with Full 3D Motion Estimation*, SSRR 2011, §IV-A.
//! With the scan end points `s_i` (robot frame) and the pose
//! `ξ = (x, y, θ)`, the world point is `S_i(ξ) = R(θ)·s_i + (x, y)` and we
//! seek the pose that puts every point on a wall:
//!
//! ```text
//! ξ* = argmin Σ_i [1 − M(S_i(ξ))]²                                 (eq. 7)
//! ```
//!
//! where `M` is the map value interpolated bilinearly (eq. 4–6; here the
//! smoothed [`LikelihoodField`]). Linearising `M(S_i(ξ + Δξ))` gives the
//! Gauss–Newton step (eq. 12–13)
//!
//! ```text
//! H = Σ J_iᵀ J_i,   J_i = ∇M(S_i) · ∂S_i/∂ξ,   Δξ = H⁻¹ Σ J_iᵀ [1 − M(S_i)]
//! ∂S_i/∂ξ = [ 1  0  −sin θ·s_x − cos θ·s_y ]
//!           [ 0  1   cos θ·s_x − sin θ·s_y ]
//! ```
//!
//! The SLAM mapper refines scans with [`super::surface`] instead: a
//! bilinear interpolant peaks at cell centres, so this refinement draws a
//! wall that lies on a cell boundary half a cell off (see that module). It
//! serves grids without surface means, and map merging's alignment of whole
//! maps, where hundreds of cells at all sub-cell phases average it out.
//!
//! The correlative search has already put the pose within a cell of the
//! optimum, inside the basin the gradient can see. Each step is damped
//! (Levenberg), limited to a cell and a degree, and halved until it scores
//! better than where it started (backtracking: the bilinear map is only
//! piecewise smooth, so a full step can overshoot a ridge).

use super::likelihood::LikelihoodField;
use crate::geom::{wrap_angle, Pose2};
use glam::DVec2;

/// Mean field value of the points at `pose` (0..1).
pub fn mean_score(field: &LikelihoodField, points: &[DVec2], pose: &Pose2) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    points
        .iter()
        .map(|&p| field.bilinear(pose.transform_point(p)).0)
        .sum::<f64>()
        / points.len() as f64
}

/// Solves the 3×3 system `a·x = b` by Gaussian elimination with partial
/// pivoting; `None` if singular.
pub fn solve3(mut a: [[f64; 3]; 3], mut b: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let piv = (col..3).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col].abs() < 1e-12 {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        for row in col + 1..3 {
            let f = a[row][col] / a[col][col];
            let pivot_row = a[col];
            for (x, p) in a[row].iter_mut().zip(pivot_row).skip(col) {
                *x -= f * p;
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 3];
    for row in (0..3).rev() {
        let s: f64 = (row + 1..3).map(|c| a[row][c] * x[c]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    Some(x)
}

/// Refines `start` by up to `iterations` Gauss–Newton steps. Returns the
/// refined pose and its mean score (the start pose if no step helped).
pub fn refine(
    field: &LikelihoodField,
    points: &[DVec2],
    start: &Pose2,
    iterations: usize,
) -> (Pose2, f64) {
    let mut pose = *start;
    let mut score = mean_score(field, points, &pose);
    let max_step_m = field.resolution_m;
    let max_step_rad = 1f64.to_radians();
    for _ in 0..iterations {
        let (s, c) = pose.theta.sin_cos();
        let mut h = [[0.0; 3]; 3];
        let mut g = [0.0; 3];
        for &p in points {
            let (m, grad) = field.bilinear(pose.transform_point(p));
            let dth = grad.x * (-s * p.x - c * p.y) + grad.y * (c * p.x - s * p.y);
            let j = [grad.x, grad.y, dth];
            let r = 1.0 - m;
            for a in 0..3 {
                g[a] += j[a] * r;
                for b in 0..3 {
                    h[a][b] += j[a] * j[b];
                }
            }
        }
        for (a, row) in h.iter_mut().enumerate() {
            row[a] = row[a] * 1.1 + 1e-6;
        }
        let Some(d) = solve3(h, g) else { break };
        let scale = (max_step_m / DVec2::new(d[0], d[1]).length().max(1e-12))
            .min(max_step_rad / d[2].abs().max(1e-12))
            .min(1.0);
        // Backtracking: halve the step until it improves the score.
        let mut improved = false;
        let mut step = scale;
        for _ in 0..5 {
            let next = Pose2::new(
                pose.x + d[0] * step,
                pose.y + d[1] * step,
                wrap_angle(pose.theta + d[2] * step),
            );
            let next_score = mean_score(field, points, &next);
            if next_score > score {
                pose = next;
                score = next_score;
                improved = true;
                break;
            }
            step *= 0.5;
        }
        if !improved
            || (DVec2::new(d[0], d[1]).length() * step < 1e-4 && (d[2] * step).abs() < 1e-5)
        {
            break;
        }
    }
    (pose, score)
}
