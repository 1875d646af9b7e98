//! # Scan-to-map matching for real lasers: the tables from points
//!
//! The simulator's mapper matches a scan against its occupancy grid. A
//! laser log's SLAM ([`super::logslam`]) matches against a *set of scans*
//! instead: the last few key scans (for the next scan's pose), or the key
//! scans around an old place (for a loop closure), each at its current
//! estimate. This module turns such a point set into the tables of Olson's
//! multi-resolution correlative matcher (E. Olson, *Real-Time Correlative
//! Scan Matching*, ICRA 2009):
//!
//! 1. every point marks its cell (the "rasterised" scans, §III-B);
//! 2. each mark spreads to the cells within two of it with weight
//!    `exp(−d² / 2)` (d in cells; the maximum where marks overlap, as in
//!    Olson's rasterised table), so a point a cell off a wall still scores;
//! 3. the low-resolution table holds the maximum of each `k × k` block of
//!    the fine one (§IV), so the search over translations can skip whole
//!    blocks whose bound cannot beat the best pose found: the answer is the
//!    exact optimum of the brute-force search.
//!
//! The search itself is [`super::correlative::search`], then a few
//! Gauss–Newton steps on the bilinear field ([`super::gauss_newton`],
//! Kohlbrecher et al. 2011) take the pose below the cell size. The angular
//! step is chosen so that the farthest point used moves by about one cell,
//! the choice Olson recommends: a real laser's beams reach 20 m, where the
//! simulator's 4 m beams allowed steps five times coarser.

use super::correlative::{search, CorrelativeConfig};
use super::gauss_newton::refine;
use super::likelihood::LikelihoodField;
use crate::geom::Pose2;
use glam::DVec2;

/// Blur weights `exp(−d² / 2)` for d = 0, 1, 2 cells.
const BLUR: [f32; 3] = [1.0, 0.606_530_66, 0.135_335_28];

/// Builds the fine and coarse tables over the points (world frame), with
/// cells of `resolution_m`, coarse blocks of `k` cells and a margin of
/// `margin_m` around the points' bounding box (the search reaches there).
pub fn field_from_points(
    points: &[DVec2],
    resolution_m: f64,
    k: usize,
    margin_m: f64,
) -> LikelihoodField {
    let cell = |p: DVec2| {
        [
            (p.x / resolution_m).floor() as i64,
            (p.y / resolution_m).floor() as i64,
        ]
    };
    let (mut lo, mut hi) = ([i64::MAX; 2], [i64::MIN; 2]);
    for &p in points {
        let c = cell(p);
        for a in 0..2 {
            lo[a] = lo[a].min(c[a]);
            hi[a] = hi[a].max(c[a]);
        }
    }
    if points.is_empty() {
        (lo, hi) = ([0, 0], [0, 0]);
    }
    let m = (margin_m / resolution_m).ceil() as i64 + 3;
    let (x0, y0) = (lo[0] - m, lo[1] - m);
    let width = (hi[0] - lo[0] + 1 + 2 * m) as usize;
    let height = (hi[1] - lo[1] + 1 + 2 * m) as usize;
    let mut raw = vec![0f32; width * height];
    for &p in points {
        let c = cell(p);
        raw[(c[1] - y0) as usize * width + (c[0] - x0) as usize] = 1.0;
    }
    let fine = blur(&raw, width, height);
    let coarse = block_max(&fine, width, height, k.max(1));
    LikelihoodField {
        x0,
        y0,
        width,
        height,
        fine,
        coarse,
        k: k.max(1),
        resolution_m,
    }
}

/// Spreads marks by a separable Gaussian of σ = 1 cell, radius 2, taking
/// the maximum where spreads overlap: a point's own cell scores 1, as a
/// confident wall does in the grid's field.
fn blur(raw: &[f32], width: usize, height: usize) -> Vec<f32> {
    let mut rows = vec![0f32; width * height];
    for y in 0..height {
        for x in 0..width {
            let v = raw[y * width + x];
            if v == 0.0 {
                continue;
            }
            for d in 0..3usize {
                let w = v * BLUR[d];
                if x + d < width {
                    let o = &mut rows[y * width + x + d];
                    *o = o.max(w);
                }
                if x >= d {
                    let o = &mut rows[y * width + x - d];
                    *o = o.max(w);
                }
            }
        }
    }
    let mut out = vec![0f32; width * height];
    for y in 0..height {
        for x in 0..width {
            let v = rows[y * width + x];
            if v == 0.0 {
                continue;
            }
            for d in 0..3usize {
                let w = v * BLUR[d];
                if y + d < height {
                    let o = &mut out[(y + d) * width + x];
                    *o = o.max(w);
                }
                if y >= d {
                    let o = &mut out[(y - d) * width + x];
                    *o = o.max(w);
                }
            }
        }
    }
    out
}

/// Maxima of `fine` over the blocks `[x, x + k) × [y, y + k)`.
fn block_max(fine: &[f32], width: usize, height: usize, k: usize) -> Vec<f32> {
    let mut cx = vec![0f32; width * height];
    for y in 0..height {
        let row = &fine[y * width..(y + 1) * width];
        for x in 0..width {
            cx[y * width + x] = row[x..(x + k).min(width)]
                .iter()
                .fold(0f32, |a, &b| a.max(b));
        }
    }
    let mut out = vec![0f32; width * height];
    for y in 0..height {
        for x in 0..width {
            let mut m = 0f32;
            for yy in y..(y + k).min(height) {
                m = m.max(cx[yy * width + x]);
            }
            out[y * width + x] = m;
        }
    }
    out
}

/// A search window for [`match_scan`].
#[derive(Clone, Debug, PartialEq)]
pub struct Window {
    pub linear_m: f64,
    pub angular_rad: f64,
}

/// The result of [`match_scan`].
#[derive(Clone, Debug, PartialEq)]
pub struct ScanMatch {
    pub pose: Pose2,
    /// Mean field value at the points after refinement (0..1).
    pub score: f64,
}

/// Matches `points` (robot frame) against `field` in `window` around
/// `prior`: the exact correlative optimum, then Gauss–Newton refinement.
pub fn match_scan(
    field: &LikelihoodField,
    points: &[DVec2],
    prior: &Pose2,
    window: &Window,
) -> Option<ScanMatch> {
    let reach = points.iter().map(|p| p.length()).fold(1.0f64, f64::max);
    let cfg = CorrelativeConfig {
        linear_window_m: window.linear_m,
        angular_window_rad: window.angular_rad,
        angular_step_rad: (field.resolution_m / reach).clamp(0.001, 0.02),
        coarse_cells: field.k,
    };
    let coarse = search(field, points, prior, &cfg)?;
    let (pose, score) = refine(field, points, &coarse.pose, 10);
    Some(ScanMatch { pose, score })
}
