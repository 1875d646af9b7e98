//! # Scan points onto the mapped surfaces: point-to-surface Gauss–Newton
//!
//! A step's odometry puts the prior within millimetres of the pose; when it
//! does not, the correlative search ([`super::correlative`]) finds it to a
//! cell and half a degree. This step refines either to a millimetre and a
//! twentieth of a degree by Gauss–Newton on point-to-surface distances — the "point-to-plane" error of
//! Y. Chen and G. Medioni (*Object Modelling by Registration of Multiple
//! Range Images*, 1992), which is what Hector SLAM's map gradient
//! (Kohlbrecher et al., SSRR 2011, §IV-A) approximates.
//!
//! ## Why not Hector's interpolated map
//! Hector SLAM maximises the occupancy map interpolated bilinearly between
//! cell centres. A bilinear interpolant peaks *at a cell centre*, so a scan
//! is drawn towards placing each wall on a row of cell centres, and the map
//! then integrates it there: the pose locks half a cell off wherever the
//! true walls lie on cell boundaries. In this lab's mazes (axis-aligned walls
//! on a 2.5 m lattice, robots starting at cell centres) every run settled
//! exactly (±0.025, ±0.025) m off, and along a wall whose mapped part ends,
//! points beyond the end were pulled back onto it, which turned a robot's
//! heading by a degree whenever it turned into unmapped space.
//!
//! ## The error
//! The grid keeps, per cell, the mean of the hits that ended in it
//! ([`OccupancyGrid::surface_point`]): the surface to sub-millimetre
//! precision. With the scan point `s_i` (robot frame), its surface normal
//! `n_i` from its neighbours ([`super::degeneracy::scan_normals`]) and the
//! pose `ξ = (x, y, θ)`, the world point is `q_i = R(θ)·s_i + t` and
//!
//! ```text
//! r_i = R(θ)n_i · q_i − d_i,   d_i = Σ_c h_c R(θ)n_i·m_c / Σ_c h_c
//! ```
//!
//! where `m_c` are the surface means of the cells near `q_i` that lie within
//! a cell of the line through `q_i` along the normal, weighted by their hit
//! counts `h_c` (a wall on a cell boundary splits its hits between two rows;
//! the weighted mean of the two halves is the whole). Only the distance
//! *along the normal* counts, so nothing pulls a point along a wall.
//!
//! ## The step
//! With the association fixed, `J_i = [n_x, n_y, n·R'(θ)s_i]` and the
//! Gauss–Newton step solves `(Σ w_i J_iᵀJ_i + λI) Δξ = −Σ w_i J_iᵀ r_i`
//! (eq. 12–13 of Hector SLAM, with its map gradient replaced by the normal);
//! `w_i` is Huber's weight (residuals beyond 1.5 cm count linearly, so a
//! point on a surface not yet mapped cannot drag the pose), and a small `λ`
//! keeps a corridor's unconstrained direction still instead of singular.
//! Points re-associate (iterated closest point) once a step has moved them
//! a fifth of a cell since the last association; smaller moves keep the
//! surface points they had, which leaves the answer as it was and saves
//! most of the map lookups. Points with no surface within
//! `association_radius_m` sit out. A step never moves points further than
//! half that radius, so the association can follow.
//!
//! The normal equations at the answer, `Σ w JᵀJ`, are the match's
//! information: [`super::filter`] weighs the match with them, and their
//! translational part is what [`super::degeneracy`] inspects.

use super::gauss_newton::solve3;
use super::grid::OccupancyGrid;
use crate::geom::{wrap_angle, Pose2};
use glam::DVec2;

/// Settings of the refinement.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RefineConfig {
    /// Gauss–Newton steps at most.
    pub iterations: usize,
    /// A point further than this from every mapped surface sits out (m).
    pub association_radius_m: f64,
    /// Huber threshold of the residual (m).
    pub huber_m: f64,
}

impl Default for RefineConfig {
    fn default() -> Self {
        RefineConfig {
            iterations: 20,
            association_radius_m: 0.1,
            huber_m: 0.015,
        }
    }
}

/// The refined pose and how well the scan sits on the map there.
#[derive(Clone, Debug, PartialEq)]
pub struct Refinement {
    pub pose: Pose2,
    /// Which points lie on a mapped surface at `pose`.
    pub associated: Vec<bool>,
    /// How many do.
    pub count: usize,
    /// Mean Huber cost per point with a normal; points off the map count
    /// as at the association radius (m²). Lower is better.
    pub cost: f64,
    /// `Σ w JᵀJ` at `pose` (x, y in m, θ in rad): the scan's information
    /// about the pose for unit residual variance.
    pub information: [[f64; 3]; 3],
}

/// Signed distance of `q` from the mapped surface along the unit normal
/// `n` (`n·q − d` above), or `None` if no surface lies within `radius`.
pub fn surface_residual(map: &OccupancyGrid, q: DVec2, n: DVec2, radius: f64) -> Option<f64> {
    surface_centroid(map, q, n, radius).map(|m| n.dot(q - m))
}

/// The hit-weighted mean of the surface means near `q` that lie within
/// `radius` of it along `n` and within 0.75 cell of the line through it
/// along `n`: the point of the mapped surface `q` is measured against.
pub fn surface_centroid(map: &OccupancyGrid, q: DVec2, n: DVec2, radius: f64) -> Option<DVec2> {
    let res = map.resolution_m();
    let reach = (radius / res).ceil() as i64;
    let band = 0.75 * res;
    let t = n.perp();
    let [gx, gy] = map.global_cell(q);
    let [ox, oy] = map.origin_cell();
    let (w, h) = (map.width() as i64, map.height() as i64);
    let (mut sum_w, mut sum) = (0.0, DVec2::ZERO);
    let (x0, x1) = ((gx - reach - ox).max(0), (gx + reach - ox).min(w - 1));
    let (y0, y1) = ((gy - reach - oy).max(0), (gy + reach - oy).min(h - 1));
    if x0 > x1 || y0 > y1 {
        return None;
    }
    let window = |a: i64, b: i64| [a as usize, b as usize];
    map.for_surface_points(window(x0, x1), window(y0, y1), |s| {
        let d = s.position - q;
        if n.dot(d).abs() > radius || t.dot(d).abs() > band {
            return;
        }
        let wt = s.hits as f64;
        sum_w += wt;
        sum += wt * s.position;
    });
    (sum_w > 0.0).then(|| sum / sum_w)
}

/// `Σ JᵀJ` of the points with `associated[i]` and a normal at `pose`: the
/// information a match at `pose` carries for unit residual variance.
pub fn information_at(
    points: &[DVec2],
    normals: &[Option<DVec2>],
    associated: &[bool],
    pose: &Pose2,
) -> [[f64; 3]; 3] {
    let (s, c) = pose.theta.sin_cos();
    let mut h = [[0.0; 3]; 3];
    for ((&p, n), &a) in points.iter().zip(normals).zip(associated) {
        let (Some(n), true) = (n, a) else { continue };
        let nw = DVec2::new(c * n.x - s * n.y, s * n.x + c * n.y);
        let dq = DVec2::new(-s * p.x - c * p.y, c * p.x - s * p.y);
        let j = [nw.x, nw.y, nw.dot(dq)];
        for a in 0..3 {
            for b in 0..3 {
                h[a][b] += j[a] * j[b];
            }
        }
    }
    h
}

/// Huber's cost and weight of residual `r` with threshold `k`.
fn huber(r: f64, k: f64) -> (f64, f64) {
    let a = r.abs();
    if a <= k {
        (0.5 * r * r, 1.0)
    } else {
        (k * (a - 0.5 * k), k / a)
    }
}

/// Refines `start` by Gauss–Newton on point-to-surface distances (see the
/// module doc). `normals[i]` belongs to `points[i]` (robot frame); points
/// without a normal take no part. Never fails: with nothing to align it
/// returns `start` with no point associated.
pub fn refine_to_surface(
    map: &OccupancyGrid,
    points: &[DVec2],
    normals: &[Option<DVec2>],
    start: &Pose2,
    cfg: &RefineConfig,
) -> Refinement {
    let radius = cfg.association_radius_m;
    let k = cfg.huber_m;
    // Re-associate once the points may have moved this far since the last
    // association (the surface a point is measured against is a band a
    // cell and a half wide: a fifth of a cell changes little).
    let reassociate_m = 0.2 * map.resolution_m();
    let reach = points.iter().map(|p| p.length()).fold(0.0, f64::max);
    // The surface point each point is measured against, at `pose`.
    let associate = |pose: &Pose2| -> Vec<Option<DVec2>> {
        let frame = pose.frame();
        points
            .iter()
            .zip(normals)
            .map(|(&p, n)| {
                let nw = frame.rotate((*n)?);
                surface_centroid(map, frame.to_parent(p), nw, radius)
            })
            .collect()
    };
    // The normal equations and cost at `pose` with association `surface`.
    let evaluate = |pose: &Pose2, surface: &[Option<DVec2>]| {
        // The pose's sine and cosine once, not once a point (the same
        // numbers `transform_point` works out).
        let frame = pose.frame();
        let (s, c) = pose.theta.sin_cos();
        let mut h = [[0.0; 3]; 3];
        let mut g = [0.0; 3];
        let (mut cost, mut used, mut count) = (0.0, 0usize, 0usize);
        for ((&p, n), m) in points.iter().zip(normals).zip(surface) {
            let Some(n) = n else { continue };
            used += 1;
            let Some(m) = m else {
                cost += huber(radius, k).0;
                continue;
            };
            count += 1;
            let nw = DVec2::new(c * n.x - s * n.y, s * n.x + c * n.y);
            let r = nw.dot(frame.to_parent(p) - *m);
            let (rho, w) = huber(r, k);
            cost += rho;
            let dq = DVec2::new(-s * p.x - c * p.y, c * p.x - s * p.y);
            let j = [nw.x, nw.y, nw.dot(dq)];
            for a in 0..3 {
                g[a] += w * j[a] * r;
                for b in 0..3 {
                    h[a][b] += w * j[a] * j[b];
                }
            }
        }
        let cost = if used == 0 { 0.0 } else { cost / used as f64 };
        (h, g, cost, count)
    };
    let mut pose = *start;
    let mut anchor = pose;
    let mut surface = associate(&pose);
    let (mut h, mut g, mut cost, mut count) = evaluate(&pose, &surface);
    for _ in 0..cfg.iterations {
        if count < 3 {
            break;
        }
        let mut damped = h;
        for (a, row) in damped.iter_mut().enumerate() {
            row[a] += 1e-3 * row[a] + 1.0;
        }
        let Some(d) = solve3(damped, [-g[0], -g[1], -g[2]]) else {
            break;
        };
        // Never jump further than the association can follow.
        let scale = (0.5 * radius / DVec2::new(d[0], d[1]).length().max(1e-12))
            .min(2f64.to_radians() / d[2].abs().max(1e-12))
            .min(1.0);
        let next = Pose2::new(
            pose.x + d[0] * scale,
            pose.y + d[1] * scale,
            wrap_angle(pose.theta + d[2] * scale),
        );
        let moved = (next.position() - anchor.position()).length()
            + wrap_angle(next.theta - anchor.theta).abs() * reach;
        let fresh = (moved > reassociate_m).then(|| associate(&next));
        let (nh, ng, ncost, ncount) = evaluate(&next, fresh.as_deref().unwrap_or(&surface));
        if ncost > cost + 1e-12 {
            break;
        }
        pose = next;
        (h, g, cost, count) = (nh, ng, ncost, ncount);
        if let Some(fresh) = fresh {
            surface = fresh;
            anchor = next;
        }
        if DVec2::new(d[0], d[1]).length() * scale < 1e-5 && (d[2] * scale).abs() < 1e-6 {
            break;
        }
    }
    Refinement {
        pose,
        associated: surface.iter().map(Option::is_some).collect(),
        count,
        cost,
        information: h,
    }
}
