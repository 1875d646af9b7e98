//! # How sure is a scan match? Its covariance from the matcher's response
//!
//! A pose graph ([`super::posegraph`]) weighs every edge by its information
//! (inverse covariance). One fixed σ for every matched key-to-key edge says
//! that a scan in a long featureless corridor pins the robot's position
//! along the corridor as well as a scan in a cluttered office does — it
//! pins it across the corridor only. When a loop closes, the optimisation
//! then spreads the loop's error as if every edge were equally stiff in
//! every direction, and bends headings or slides walls sideways where it
//! should have stretched the corridor.
//!
//! The correlative matcher already knows better. E. Olson, *Real-Time
//! Correlative Scan Matching* (ICRA 2009), §IV-C: the search evaluates the
//! match's score over a whole window of poses, and the spread of that
//! response around the best pose is the match's uncertainty — a sharp peak
//! means a well-constrained match, a ridge means a corridor, with the
//! ridge's direction as the long axis of the covariance:
//!
//! ```text
//! K = Σ_i w_i x_i x_iᵀ,  u = Σ_i w_i x_i,  s = Σ_i w_i
//! Σ = K / s − u uᵀ / s²
//! ```
//!
//! over the poses `x_i` of the window with weights `w_i`. Olson weighs by
//! the likelihood `exp(score)`; Karto (the scan matcher of Konolige et al.,
//! "Efficient sparse pose adjustment for 2D mapping", IROS 2010, as in
//! slam_toolbox) uses the same second moment with the response itself (the
//! mean field value of the scan's points, 0..1, which is also this project's
//! score) as the weight, counting only poses whose response is within
//! `drop` of the best — the poses the matcher could not tell apart from the
//! best — and takes the moments about the best pose rather than their mean
//! (the mean of a one-sided ridge is not where the matcher put the scan).
//! That is what this module computes, in two parts as Karto does:
//!
//! 1. **position**: the 2 × 2 moment over whole-cell offsets of the best
//!    pose within `half_m`, at the best heading;
//! 2. **heading**: the variance over rotations within `half_rad`, in steps
//!    that move the farthest point by about a cell, at the best position.
//!
//! Each variance is at least the search's own quantisation, `step² / 12`
//! (a uniform error within one cell, one angular step): a match is never
//! trusted beyond the resolution it was found at.
//!
//! The result is in the world frame of the field (the odometry frame); a
//! pose-graph edge measures its error in the frame of the node it ends at,
//! so [`edge_information`] rotates it there and inverts it.

use super::likelihood::LikelihoodField;
use crate::geom::Pose2;
use glam::DVec2;

/// Where and how finely the response is sampled.
#[derive(Clone, Debug, PartialEq)]
pub struct ResponseWindow {
    /// Half-width of the positional window (m).
    pub half_m: f64,
    /// Half-width of the angular window (rad).
    pub half_rad: f64,
    /// Poses scoring more than this below the best are not counted (mean
    /// field value, 0..1; Karto's 0.1).
    pub drop: f64,
}

/// The response (mean fine-table value) of `points` at `pose`.
fn response(field: &LikelihoodField, points: &[DVec2], pose: &Pose2) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    let s: f32 = points
        .iter()
        .map(|&p| {
            let c = field.cell_of(pose.transform_point(p));
            field.fine_at(c[0], c[1])
        })
        .sum();
    s as f64 / points.len() as f64
}

/// The covariance of the match of `points` (robot frame) at `best` (world
/// frame), row-major 3 × 3 over (x, y, θ); `None` without points.
pub fn response_covariance(
    field: &LikelihoodField,
    points: &[DVec2],
    best: &Pose2,
    window: &ResponseWindow,
) -> Option<[[f64; 3]; 3]> {
    if points.is_empty() {
        return None;
    }
    let res = field.resolution_m;
    let top = response(field, points, best);
    let floor = top - window.drop;
    // Position: whole-cell offsets at the best heading. The points' cells
    // are found once; an offset shifts every cell alike.
    let cells: Vec<[i64; 2]> = points
        .iter()
        .map(|&p| field.cell_of(best.transform_point(p)))
        .collect();
    let n = (window.half_m / res).round() as i64;
    let (mut s, mut xx, mut xy, mut yy) = (0.0, 0.0, 0.0, 0.0);
    for oy in -n..=n {
        for ox in -n..=n {
            let sum: f32 = cells
                .iter()
                .map(|c| field.fine_at(c[0] + ox, c[1] + oy))
                .sum();
            let w = sum as f64 / points.len() as f64;
            if w < floor || w <= 0.0 {
                continue;
            }
            let (dx, dy) = (ox as f64 * res, oy as f64 * res);
            s += w;
            xx += w * dx * dx;
            xy += w * dx * dy;
            yy += w * dy * dy;
        }
    }
    // Heading: rotations about the best position.
    let reach = points.iter().map(|p| p.length()).fold(1.0f64, f64::max);
    let step = (res / reach).clamp(0.001, 0.02);
    let m = (window.half_rad / step).round() as i64;
    let (mut sa, mut tt) = (0.0, 0.0);
    for k in -m..=m {
        let d = k as f64 * step;
        let pose = Pose2::new(best.x, best.y, best.theta + d);
        let w = response(field, points, &pose);
        if w < floor || w <= 0.0 {
            continue;
        }
        sa += w;
        tt += w * d * d;
    }
    let q = res * res / 12.0;
    let qa = step * step / 12.0;
    let (vx, vy, cxy) = if s > 0.0 {
        ((xx / s).max(q), (yy / s).max(q), xy / s)
    } else {
        (q, q, 0.0)
    };
    // Keep the 2 × 2 block positive definite after the floors.
    let cxy = cxy.clamp(-0.99 * (vx * vy).sqrt(), 0.99 * (vx * vy).sqrt());
    let vt = if sa > 0.0 { (tt / sa).max(qa) } else { qa };
    Some([[vx, cxy, 0.0], [cxy, vy, 0.0], [0.0, 0.0, vt]])
}

/// The information matrix of a pose-graph edge ending at a node with
/// heading `theta_rad`, from a world-frame covariance: `(Rᵀ Σ R)⁻¹` with `R`
/// the node's rotation (the edge's error is expressed in that node's frame,
/// see [`super::posegraph`]). `None` if the covariance is singular.
pub fn edge_information(cov: &[[f64; 3]; 3], theta_rad: f64) -> Option<[[f64; 3]; 3]> {
    let (s, c) = theta_rad.sin_cos();
    // Rᵀ Σ R for the 2 × 2 block; θ unchanged, cross terms rotated.
    let (a, b, d) = (cov[0][0], cov[0][1], cov[1][1]);
    let lxx = c * c * a + 2.0 * c * s * b + s * s * d;
    let lyy = s * s * a - 2.0 * c * s * b + c * c * d;
    let lxy = -c * s * a + (c * c - s * s) * b + c * s * d;
    let (tx, ty) = (cov[0][2], cov[1][2]);
    let ltx = c * tx + s * ty;
    let lty = -s * tx + c * ty;
    let local = [[lxx, lxy, ltx], [lxy, lyy, lty], [ltx, lty, cov[2][2]]];
    invert3(&local)
}

/// The inverse of a symmetric 3 × 3 matrix by cofactors; `None` if
/// (nearly) singular.
fn invert3(m: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
    let c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
    let c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
    let det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
    let scale = m.iter().flatten().fold(0f64, |a, v| a.max(v.abs()));
    if !det.is_finite() || det.abs() <= 1e-12 * scale.powi(3) {
        return None;
    }
    let inv = [
        [
            c00,
            m[0][2] * m[2][1] - m[0][1] * m[2][2],
            m[0][1] * m[1][2] - m[0][2] * m[1][1],
        ],
        [
            c01,
            m[0][0] * m[2][2] - m[0][2] * m[2][0],
            m[0][2] * m[1][0] - m[0][0] * m[1][2],
        ],
        [
            c02,
            m[0][1] * m[2][0] - m[0][0] * m[2][1],
            m[0][0] * m[1][1] - m[0][1] * m[1][0],
        ],
    ];
    Some(inv.map(|row| row.map(|v| v / det)))
}
