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

use super::correlative::{search, search_outside, CorrelativeConfig, Exclusion};
use super::gauss_newton::refine;
use super::likelihood::LikelihoodField;
use crate::geom::Pose2;
use glam::DVec2;

/// Blur weights `exp(−d² / 2)` for d = 0, 1, 2 cells.
const BLUR: [f32; 3] = [1.0, 0.606_530_66, 0.135_335_28];

/// Builds the fine and coarse tables over the points (world frame), with
/// cells of `resolution_m`, coarse blocks of `k` cells and a margin of
/// `margin_m` around the points' bounding box (the search reaches there).
///
/// Both tables are maxima of per-point stamps, so they are written point by
/// point rather than by passes over the whole window: a real laser's 20 m
/// beams make the window up to a million cells, of which the points touch a
/// few per cent. A point's fine stamp is `w(dx)·w(dy)` for `|dx|, |dy| ≤ 2`
/// (the separable blur, maxima taken where stamps overlap). Its coarse stamp
/// at block `[c, c + k)²` is the largest fine value inside the block, the
/// stamp's weight at the block cell nearest the point on each axis.
pub fn field_from_points(
    points: &[DVec2],
    resolution_m: f64,
    k: usize,
    margin_m: f64,
) -> LikelihoodField {
    field_covering(points, resolution_m, k, margin_m, None)
}

/// [`field_from_points`] over a window that also covers the disc `around`
/// (centre, radius in m), plus the margin: the cells there hold 0 unless a
/// point is near. A scan searched from the disc's centre whose farthest
/// point lies within the radius then reads the tables without a bounds
/// test at every rotation and shift of a window up to the margin (the
/// search's fast path), and scores exactly as on the smaller window, where
/// a read outside counts 0.
pub fn field_covering(
    points: &[DVec2],
    resolution_m: f64,
    k: usize,
    margin_m: f64,
    around: Option<(DVec2, f64)>,
) -> LikelihoodField {
    let k = k.max(1);
    let mut marks: Vec<[i64; 2]> = points
        .iter()
        .map(|p| {
            [
                (p.x / resolution_m).floor() as i64,
                (p.y / resolution_m).floor() as i64,
            ]
        })
        .collect();
    marks.sort_unstable();
    marks.dedup();
    let (mut lo, mut hi) = ([0i64; 2], [0i64; 2]);
    if let Some(first) = marks.first() {
        (lo, hi) = (*first, *first);
        for c in &marks {
            for a in 0..2 {
                lo[a] = lo[a].min(c[a]);
                hi[a] = hi[a].max(c[a]);
            }
        }
    }
    if let Some((c, r)) = around {
        let cell = |v: f64| (v / resolution_m).floor() as i64;
        let (a, b) = (
            [cell(c.x - r), cell(c.y - r)],
            [cell(c.x + r), cell(c.y + r)],
        );
        if marks.is_empty() {
            (lo, hi) = (a, b);
        }
        for i in 0..2 {
            lo[i] = lo[i].min(a[i]);
            hi[i] = hi[i].max(b[i]);
        }
    }
    let m = (margin_m / resolution_m).ceil() as i64 + 3 + k as i64;
    let (x0, y0) = (lo[0] - m, lo[1] - m);
    let width = (hi[0] - lo[0] + 1 + 2 * m) as usize;
    let height = (hi[1] - lo[1] + 1 + 2 * m) as usize;
    let mut fine = vec![0f32; width * height];
    let mut coarse = vec![0f32; width * height];
    let near = coarse_weights(k);
    for c in &marks {
        let (x, y) = ((c[0] - x0) as usize, (c[1] - y0) as usize);
        stamp(&mut fine, width, x - 2, y - 2, &BLUR_ROW);
        stamp(&mut coarse, width, x + 1 - k - 2, y + 1 - k - 2, &near);
    }
    LikelihoodField {
        x0,
        y0,
        width,
        height,
        fine,
        coarse,
        k,
        resolution_m,
    }
}

/// The fine stamp's weights along one axis, offsets −2..=2.
const BLUR_ROW: [f32; 5] = [BLUR[2], BLUR[1], BLUR[0], BLUR[1], BLUR[2]];

/// The coarse stamp's weights along one axis: for block starts from
/// `k + 1` cells before the point to 2 after, the weight of the block cell
/// nearest the point (0 cells inside the block).
fn coarse_weights(k: usize) -> Vec<f32> {
    (0..k + 4)
        .map(|i| {
            // Block [s, s + k) with s = i − (k − 1) − 2 relative to the point.
            let s = i as i64 - (k as i64 - 1) - 2;
            let d = if s > 0 {
                s
            } else if s + k as i64 - 1 < 0 {
                -(s + k as i64 - 1)
            } else {
                0
            };
            BLUR[d as usize]
        })
        .collect()
}

/// Writes the maximum of `table` and the outer product `w ⊗ w` into the
/// square of `w.len()` cells starting at `(x, y)`.
fn stamp(table: &mut [f32], width: usize, x: usize, y: usize, w: &[f32]) {
    for (j, &wy) in w.iter().enumerate() {
        let row = &mut table[(y + j) * width + x..(y + j) * width + x + w.len()];
        for (o, &wx) in row.iter_mut().zip(w) {
            *o = o.max(wx * wy);
        }
    }
}

/// A search window for [`match_scan`].
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
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
    /// The correlative search's score of its best pose, before refinement
    /// (comparable with [`rival_score`]).
    pub search_score: f64,
}

/// Matches `points` (robot frame) against `field` in `window` around
/// `prior`: the exact correlative optimum, then Gauss–Newton refinement.
pub fn match_scan(
    field: &LikelihoodField,
    points: &[DVec2],
    prior: &Pose2,
    window: &Window,
) -> Option<ScanMatch> {
    let cfg = search_config(field, points, window);
    let coarse = search(field, points, prior, &cfg)?;
    let (pose, score) = refine(field, points, &coarse.pose, 10);
    Some(ScanMatch {
        pose,
        score,
        search_score: coarse.score,
    })
}

/// The correlative search of `window` on `field` for `points`: its angular
/// step moves the farthest point by about a cell.
fn search_config(field: &LikelihoodField, points: &[DVec2], window: &Window) -> CorrelativeConfig {
    let reach = points.iter().map(|p| p.length()).fold(1.0f64, f64::max);
    CorrelativeConfig {
        linear_window_m: window.linear_m,
        angular_window_rad: window.angular_rad,
        angular_step_rad: (field.resolution_m / reach).clamp(0.001, 0.02),
        coarse_cells: field.k,
    }
}

/// The search's score of the best pose in `window` around `prior` whose
/// position lies more than `exclude_m` (along either axis) from `found`:
/// the strongest rival of a match at `found` (0 when there is none).
pub fn rival_score(
    field: &LikelihoodField,
    points: &[DVec2],
    prior: &Pose2,
    window: &Window,
    found: &Pose2,
    exclude_m: f64,
) -> f64 {
    let cfg = search_config(field, points, window);
    let exclusion = Exclusion {
        centre: found.position(),
        radius_m: exclude_m,
    };
    search_outside(field, points, prior, &cfg, Some(exclusion)).map_or(0.0, |m| m.score)
}
