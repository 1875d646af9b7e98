//! # Multi-resolution correlative scan matching
//!
//! E. Olson, *Real-Time Correlative Scan Matching*, ICRA 2009. Given a prior
//! pose (here: the last estimate moved by the odometry increment), search a
//! window of poses around it — every rotation in `±angular_window` at
//! `angular_step`, and every whole-cell translation in `±linear_window` —
//! for the one whose laser end points land on the most wall-like cells of
//! the [`LikelihoodField`] (§III: the score is the sum of the field over
//! the points).
//!
//! Brute force would score every (θ, x, y). Olson's two-level trick (§IV):
//! for each rotation the points are rotated once; then translations are
//! scored first on the *coarse* table, whose entries are maxima over `K × K`
//! fine cells, so one coarse score bounds all `K²` fine scores of its block.
//! Candidates are sorted best first and expanded to fine resolution until
//! the next coarse bound cannot beat the best fine score found: the answer
//! is the exact optimum of the full fine search at a small part of its cost.
//! Ties go to the candidate nearest the prior, so a flat response (a
//! featureless corridor) does not pull the pose anywhere.
//!
//! The result is accurate to one cell and `angular_step`; the mapper
//! refines it with [`super::surface`] (or, on a grid without surface means,
//! [`super::gauss_newton`]). The mapper searches only when refining from
//! the prior finds too few points on mapped surfaces — the prior is then off
//! by more than the refinement can see, as after a long stretch without
//! matches or on returning to an area mapped long ago; a step's odometry is
//! otherwise good to millimetres and the search would cost ten times the
//! refinement for nothing.

use super::likelihood::LikelihoodField;
use crate::geom::{wrap_angle, Pose2};
use glam::DVec2;

/// The search window.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CorrelativeConfig {
    pub linear_window_m: f64,
    pub angular_window_rad: f64,
    pub angular_step_rad: f64,
    /// Coarse block size in fine cells (Olson's low-resolution factor).
    pub coarse_cells: usize,
}

impl Default for CorrelativeConfig {
    fn default() -> Self {
        CorrelativeConfig {
            linear_window_m: 0.3,
            angular_window_rad: 3f64.to_radians(),
            angular_step_rad: 0.5f64.to_radians(),
            coarse_cells: 4,
        }
    }
}

/// The best pose of the search.
#[derive(Clone, Debug, PartialEq)]
pub struct CorrelativeMatch {
    pub pose: Pose2,
    /// Mean field value at the points (0..1).
    pub score: f64,
    /// Fine-resolution poses scored (for the benchmark's curiosity).
    pub fine_evaluations: usize,
}

/// Searches the window around `prior` for the pose that best lays
/// `points` (robot frame) on the field. `None` without points.
pub fn search(
    field: &LikelihoodField,
    points: &[DVec2],
    prior: &Pose2,
    cfg: &CorrelativeConfig,
) -> Option<CorrelativeMatch> {
    search_outside(field, points, prior, cfg, None)
}

/// Positions a search leaves out: every pose whose position lies within
/// `radius_m` of `centre` along both axes, at any heading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Exclusion {
    pub centre: DVec2,
    pub radius_m: f64,
}

/// [`search`] over the window less `exclude`: the best pose elsewhere, to
/// tell a unique match from one of a pattern that repeats (a corridor's
/// doors). The coarse bounds still bound every pose they cover, so the
/// branch and bound stays exact over what is left. `None` without points
/// or when nothing is left.
pub fn search_outside(
    field: &LikelihoodField,
    points: &[DVec2],
    prior: &Pose2,
    cfg: &CorrelativeConfig,
    exclude: Option<Exclusion>,
) -> Option<CorrelativeMatch> {
    if points.is_empty() {
        return None;
    }
    let res = field.resolution_m;
    // The excluded box in cell offsets from the prior (none: an empty box).
    let (ex, ey, er) = match exclude {
        Some(e) => {
            let c = (e.centre - prior.position()) / res;
            (
                c.x.round() as i64,
                c.y.round() as i64,
                (e.radius_m / res).ceil() as i64,
            )
        }
        None => (0, 0, -1),
    };
    let w = (cfg.linear_window_m / res).round() as i64;
    let k = field.k as i64;
    let nt = (cfg.angular_window_rad / cfg.angular_step_rad).round() as i64;
    let n_theta = (2 * nt + 1) as usize;
    let n = points.len();
    // Window cells of every point for every rotation, as indices into the
    // tables when every offset the search reads (±w cells, plus a coarse
    // block) stays inside the window, so the sums below need no bounds
    // tests; rotations where some point comes nearer an edge keep the
    // checked reads. Both read the same values in the same order.
    let mut cells = Vec::with_capacity(n * n_theta);
    let mut inside = Vec::with_capacity(n_theta);
    let mut index = Vec::with_capacity(n * n_theta);
    let (wd, ht) = (field.width as i64, field.height as i64);
    for t in -nt..=nt {
        let theta = prior.theta + t as f64 * cfg.angular_step_rad;
        let frame = Pose2::new(prior.x, prior.y, theta).frame();
        let mut all = true;
        for &p in points {
            let c = field.cell_of(frame.to_parent(p));
            all &= c[0] - w >= 0 && c[1] - w >= 0 && c[0] + w + k < wd && c[1] + w + k < ht;
            cells.push(c);
            index.push(c[1] * wd + c[0]);
        }
        inside.push(all);
    }
    let score_at = |table: &[f32], ti: usize, ox: i64, oy: i64| -> f32 {
        let off = oy * wd + ox;
        index[ti * n..(ti + 1) * n]
            .iter()
            .fold(0f32, |a, &i| a + table[(i + off) as usize])
    };
    // Coarse candidates.
    struct Candidate {
        score: f32,
        t: i64,
        ox: i64,
        oy: i64,
        order: u32,
    }
    let mut candidates = Vec::new();
    let starts: Vec<i64> = (0..).map(|i| -w + i * k).take_while(|&o| o <= w).collect();
    for (ti, t) in (-nt..=nt).enumerate() {
        let pc = &cells[ti * n..(ti + 1) * n];
        for &oy in &starts {
            for &ox in &starts {
                let score: f32 = if inside[ti] {
                    score_at(&field.coarse, ti, ox, oy)
                } else {
                    pc.iter()
                        .map(|c| field.coarse_at(c[0] + ox, c[1] + oy))
                        .sum()
                };
                let order = candidates.len() as u32;
                candidates.push(Candidate {
                    score,
                    t,
                    ox,
                    oy,
                    order,
                });
            }
        }
    }
    // Best first; equal scores in the order scored (as a stable sort would).
    candidates.sort_unstable_by(|a, b| b.score.total_cmp(&a.score).then(a.order.cmp(&b.order)));
    // Branch and bound at fine resolution.
    let dist = |t: i64, x: i64, y: i64| t.abs() + x.abs() + y.abs();
    let mut best: Option<(f32, i64, i64, i64)> = None;
    let mut evaluations = 0;
    for c in &candidates {
        if let Some((b, ..)) = best {
            if c.score < b - 1e-4 {
                break;
            }
        }
        let ti = (c.t + nt) as usize;
        let pc = &cells[ti * n..(ti + 1) * n];
        // Whether this block meets the excluded box (never without one).
        let meets = er >= 0
            && c.ox <= ex + er
            && c.ox + k > ex - er
            && c.oy <= ey + er
            && c.oy + k > ey - er;
        for oy in c.oy..(c.oy + k).min(w + 1) {
            for ox in c.ox..(c.ox + k).min(w + 1) {
                if meets && (ox - ex).abs() <= er && (oy - ey).abs() <= er {
                    continue;
                }
                let s: f32 = if inside[ti] {
                    score_at(&field.fine, ti, ox, oy)
                } else {
                    pc.iter().map(|q| field.fine_at(q[0] + ox, q[1] + oy)).sum()
                };
                evaluations += 1;
                let better = match best {
                    None => true,
                    Some((b, bt, bx, by)) => {
                        s > b + 1e-4 || (s >= b - 1e-4 && dist(c.t, ox, oy) < dist(bt, bx, by))
                    }
                };
                if better {
                    best = Some((s, c.t, ox, oy));
                }
            }
        }
    }
    let (s, t, ox, oy) = best?;
    Some(CorrelativeMatch {
        pose: Pose2::new(
            prior.x + ox as f64 * res,
            prior.y + oy as f64 * res,
            wrap_angle(prior.theta + t as f64 * cfg.angular_step_rad),
        ),
        score: s as f64 / n as f64,
        fine_evaluations: evaluations,
    })
}
