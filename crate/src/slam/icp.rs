//! # Point-to-line ICP against a set of points with normals
//!
//! The correlative matchers ([`super::multires`]) find a pose to a cell and
//! refine it on a smoothed raster of the map points. A raster has a grain:
//! a wall that lies between two rows of cells pulls the refined pose
//! towards a row, so a match carries an error of up to half a cell (2.5 cm
//! at 5 cm cells) that depends on where the walls fall on the raster.
//! Where that matters — many matches of one place that must agree to the
//! centimetre — this refines a pose on the points themselves: iterated
//! closest points (Besl & McKay 1992) with the point-to-line error of
//! Chen & Medioni (1992), each point measured along the normal of the
//! nearest target point, Huber-weighted so a point on a surface the target
//! never saw cannot drag the pose.
//!
//! With the nearest target point `a_i` (normal `n_i`) of the scan point
//! `s_i` placed at `q_i = R(θ)s_i + t`, the residual is `r_i = n_i·(q_i − a_i)`
//! and its Jacobian `[n_x, n_y, n·R'(θ)s_i]`; each step solves the 3 × 3
//! normal equations and re-associates. The smaller eigenvalue of the
//! translational block `Σ w n nᵀ` says how well the answer is pinned in its
//! weakest direction: a corridor leaves it near zero.

use super::degeneracy::symmetric_eigen2;
use super::gauss_newton::solve3;
use crate::geom::{wrap_angle, Pose2};
use glam::DVec2;
use std::collections::HashMap;

/// The points a scan is aligned to, with their normals, bucketed for the
/// nearest-point search.
pub struct IcpTarget {
    points: Vec<DVec2>,
    normals: Vec<DVec2>,
    radius_m: f64,
    buckets: HashMap<(i64, i64), Vec<usize>>,
}

/// The result of [`IcpTarget::align`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IcpFit {
    pub pose: Pose2,
    /// Scan points with a target point within the radius at `pose`.
    pub associated: usize,
    /// Smaller eigenvalue of the translational information (points' worth
    /// of constraint in the weakest direction).
    pub weak: f64,
    /// The larger eigenvalue, and the weakest direction (world frame).
    pub strong: f64,
    pub weak_direction: DVec2,
    /// The normal equations' matrix of the last step (`Σ w JᵀJ`, world
    /// frame `[x, y, θ]`): the fit's information in points' worth.
    pub information: [[f64; 3]; 3],
}

impl IcpTarget {
    /// A target of `points` (world frame) with unit `normals` (points
    /// without one take no part); a scan point is associated with the
    /// nearest target point within `radius_m`.
    pub fn new(points: &[DVec2], normals: &[Option<DVec2>], radius_m: f64) -> IcpTarget {
        let mut t = IcpTarget {
            points: Vec::new(),
            normals: Vec::new(),
            radius_m,
            buckets: HashMap::new(),
        };
        for (&p, n) in points.iter().zip(normals) {
            let Some(n) = n else { continue };
            t.buckets
                .entry(t.bucket(p))
                .or_default()
                .push(t.points.len());
            t.points.push(p);
            t.normals.push(*n);
        }
        t
    }

    fn bucket(&self, p: DVec2) -> (i64, i64) {
        let b = p / self.radius_m;
        (b.x.floor() as i64, b.y.floor() as i64)
    }

    /// The nearest target point within the radius of `q`, and its normal.
    pub fn nearest(&self, q: DVec2) -> Option<(DVec2, DVec2)> {
        let (bx, by) = self.bucket(q);
        let mut best: Option<(f64, usize)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for &i in self.buckets.get(&(bx + dx, by + dy)).into_iter().flatten() {
                    let d = self.points[i].distance_squared(q);
                    if d < self.radius_m * self.radius_m && best.is_none_or(|b| d < b.0) {
                        best = Some((d, i));
                    }
                }
            }
        }
        best.map(|(_, i)| (self.points[i], self.normals[i]))
    }

    /// Point-to-line residuals of `points` (robot frame) placed at `pose`,
    /// with the Jacobian of each (None: no target point near).
    pub fn residuals(&self, points: &[DVec2], pose: &Pose2) -> Vec<Option<(f64, [f64; 3])>> {
        let (s, c) = pose.theta.sin_cos();
        let f = pose.frame();
        points
            .iter()
            .map(|&p| {
                let q = f.to_parent(p);
                let (a, n) = self.nearest(q)?;
                let dq = DVec2::new(-s * p.x - c * p.y, c * p.x - s * p.y);
                Some((n.dot(q - a), [n.x, n.y, n.dot(dq)]))
            })
            .collect()
    }

    /// Point-to-line ICP of `points` (robot frame) from `start`, Huber
    /// threshold `huber_m`, at most `iterations` steps.
    pub fn align(
        &self,
        points: &[DVec2],
        start: &Pose2,
        huber_m: f64,
        iterations: usize,
    ) -> IcpFit {
        let mut pose = *start;
        let (mut weak, mut associated) = (0.0, 0);
        let (mut strong, mut weak_direction) = (0.0, DVec2::X);
        let mut information = [[0.0; 3]; 3];
        for _ in 0..iterations {
            let mut h = [[0.0; 3]; 3];
            let mut g = [0.0; 3];
            associated = 0;
            for (r, j) in self.residuals(points, &pose).into_iter().flatten() {
                associated += 1;
                let w = if r.abs() <= huber_m {
                    1.0
                } else {
                    huber_m / r.abs()
                };
                for a in 0..3 {
                    g[a] += w * j[a] * r;
                    for b in 0..3 {
                        h[a][b] += w * j[a] * j[b];
                    }
                }
            }
            let (l1, l2, along) = symmetric_eigen2(h[0][0], h[0][1], h[1][1]);
            (strong, weak, weak_direction) = (l1, l2, along);
            information = h;
            for (a, row) in h.iter_mut().enumerate() {
                row[a] += 1e-6;
            }
            let Some(d) = solve3(h, [-g[0], -g[1], -g[2]]) else {
                break;
            };
            pose = Pose2::new(pose.x + d[0], pose.y + d[1], wrap_angle(pose.theta + d[2]));
            if DVec2::new(d[0], d[1]).length() < 1e-6 && d[2].abs() < 1e-7 {
                break;
            }
        }
        IcpFit {
            pose,
            associated,
            weak,
            strong,
            weak_direction,
            information,
        }
    }
}
