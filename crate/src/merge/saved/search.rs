//! # Finding one saved map in another: rotation, translation, refinement
//!
//! The search of the saved-maps merge ([`super`]) proposes overlays
//! of map B on map A (B's image frame in A's); [`super::evidence`] judges
//! them. It is a multi-resolution correlative search in the spirit of
//! E. Olson, *Real-time correlative scan matching* (ICRA 2009), with the
//! rotation taken from the maps' wall directions as S. Carpin does in
//! *Fast and accurate map merging for multi-robot systems* (Autonomous
//! Robots 25, 2008), the same idea as the lab's own map search
//! ([`crate::merge::mapsearch`]) but made for real maps:
//!
//! 1. **Rotations from the Hough spectrum.** For each normal direction
//!    `φ` (0.25° steps over 180°) the wall-surface points are binned by
//!    `ρ = x cos φ + y sin φ` (0.1 m bins) and the spectrum at `φ` is the
//!    sum of squared bin counts: it peaks where many walls face. Turning a
//!    map shifts its spectrum, so the circular cross-correlation of the two
//!    spectra peaks at the rotations that line B's walls up with A's. Real
//!    buildings are not all rectilinear, so the spectrum is *not* folded
//!    modulo 90° as the lab's is: the best few peaks of the correlation are
//!    kept (a rectilinear building gives δ and δ + 90° among them), each
//!    with its twin δ + 180° (a spectrum over 180° cannot tell them apart).
//! 2. **Translations by coarse correlation.** Both maps' wall points are
//!    drawn at a coarse cell (0.3 m, coarser for huge maps so a raster
//!    stays near 200 cells a side): A's cells score 2 where a wall point
//!    falls and 1 beside one, and for each rotation every whole-cell
//!    translation of B's wall cells over A's raster is scored at once, by
//!    adding rows of A's scores (the correlation of the lab's map search,
//!    without its free-space penalty: on real maps the true overlay puts
//!    much wall in the other's free space, and the penalty ranked wrong
//!    overlays first). The best few well-separated peaks of each rotation
//!    go on.
//! 3. **Local refinement on the distance field.** Each peak is polished by
//!    a pattern search (Hooke and Jeeves 1961) over `(x, y, θ)`, maximising
//!    `Σ max(0, 1 − d/τ)` over B's wall points, `d` their distance to A's
//!    nearest wall ([`super::wallmap`]): first with a wide `τ` (0.5 m, a
//!    basin wide enough to pull in a coarse peak), then a narrow one
//!    (0.15 m, for precision). Thick or slightly bent walls still score,
//!    because the score falls off gently with distance.
//!
//! Everything is deterministic; no random sampling.

use super::wallmap::WallMap;
use crate::geom::{wrap_angle, Pose2};
use crate::merge::raster_correlation::{add_row, Correlation};
use glam::DVec2;
use std::f64::consts::PI;

/// Settings of the search.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SearchConfig {
    /// Smallest coarse cell, m. Default 0.3.
    pub coarse_m: f64,
    /// Coarse rasters are kept near this many cells a side. Default 200.
    pub coarse_side: f64,
    /// Peaks of the spectra's correlation kept (each also turned by 180°).
    /// Default 4.
    pub rotation_peaks: usize,
    /// Translation peaks kept per rotation. Default 6.
    pub peaks_per_rotation: usize,
    /// Overlays refined, best coarse score first. Default 32.
    pub max_hypotheses: usize,
    /// Peaks closer than this are one. Default 1.5 m.
    pub distinct_m: f64,
    /// Wide and narrow `τ` of the refinement, m. Defaults 0.5, 0.15.
    pub tau_wide_m: f64,
    pub tau_narrow_m: f64,
}

impl Default for SearchConfig {
    fn default() -> Self {
        SearchConfig {
            coarse_m: 0.3,
            coarse_side: 200.0,
            rotation_peaks: 4,
            peaks_per_rotation: 6,
            max_hypotheses: 32,
            distinct_m: 1.5,
            tau_wide_m: 0.5,
            tau_narrow_m: 0.15,
        }
    }
}

/// Settings of the search around a person's guess ([`super::refine`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefineConfig {
    /// Half the translation window, in cells of the coarser map. Default 50.
    pub window_cells: f64,
    /// The translation window is never smaller than this, m. Default 2.5.
    pub min_window_m: f64,
    /// Half the rotation window, degrees. Default 20.
    pub window_deg: f64,
    /// Translation step of the coarse search, cells. Default 4.
    pub step_cells: f64,
    /// Rotation step of the coarse search, degrees. Default 1.
    pub step_deg: f64,
    /// Distinct coarse overlays refined. Default 6.
    pub peaks: usize,
    /// B's wall points scored in the coarse search (evenly thinned).
    /// Default 1500.
    pub points: usize,
}

impl Default for RefineConfig {
    fn default() -> Self {
        RefineConfig {
            window_cells: 50.0,
            min_window_m: 2.5,
            window_deg: 20.0,
            step_cells: 4.0,
            step_deg: 1.0,
            peaks: 6,
            points: 1500,
        }
    }
}

impl RefineConfig {
    /// The translation window's half width and the step (m) for maps of
    /// resolutions `ra` and `rb`: both scale with the coarser map.
    pub fn window_m(&self, ra: f64, rb: f64) -> (f64, f64) {
        let res = ra.max(rb);
        let half = (self.window_cells * res).max(self.min_window_m);
        (half, half * self.step_cells / self.window_cells)
    }
}

/// One proposed overlay: B's image frame in A's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Proposal {
    pub coarse: Pose2,
    pub coarse_score: i64,
    pub pose: Pose2,
    /// The narrow field score after refinement (wall points' worth).
    pub score: f64,
}

/// Angles of the spectrum over 180°.
const ANGLES: usize = 720;

/// At most this many points go into a spectrum (evenly thinned).
const SPECTRUM_POINTS: usize = 20_000;

pub fn thinned(points: &[DVec2], most: usize) -> Vec<DVec2> {
    let stride = points.len().div_ceil(most.max(1)).max(1);
    points.iter().step_by(stride).copied().collect()
}

/// Carpin's Hough spectrum over 180° (mean removed, unit norm).
fn spectrum(points: &[DVec2]) -> Vec<f64> {
    let pts = thinned(points, SPECTRUM_POINTS);
    let bin = 0.1;
    let far = pts.iter().map(|p| p.length()).fold(0.0, f64::max);
    let n_bins = (2.0 * far / bin).ceil() as usize + 2;
    let mut bins = vec![0u32; n_bins];
    let mut s: Vec<f64> = (0..ANGLES)
        .map(|j| {
            let phi = (j as f64 * 180.0 / ANGLES as f64).to_radians();
            let (sin, cos) = phi.sin_cos();
            bins.iter_mut().for_each(|b| *b = 0);
            for p in &pts {
                bins[((p.x * cos + p.y * sin + far) / bin) as usize] += 1;
            }
            bins.iter().map(|&b| (b as f64) * (b as f64)).sum()
        })
        .collect();
    let mean = s.iter().sum::<f64>() / ANGLES as f64;
    s.iter_mut().for_each(|v| *v -= mean);
    let norm = s.iter().map(|v| v * v).sum::<f64>().sqrt().max(1e-12);
    s.iter_mut().for_each(|v| *v /= norm);
    s
}

/// Rotations (rad) that may turn B's walls onto A's: the best
/// `peaks` local maxima of the spectra's circular cross-correlation,
/// refined by a parabola, each with its twin turned by 180°.
pub fn rotation_candidates(a: &WallMap, b: &WallMap, peaks: usize) -> Vec<f64> {
    if a.walls.len() < 10 || b.walls.len() < 10 {
        return Vec::new();
    }
    let (ha, hb) = (spectrum(&a.walls), spectrum(&b.walls));
    let n = ANGLES;
    // B turned by s steps puts its direction j at j + s.
    let c: Vec<f64> = (0..n)
        .map(|s| (0..n).map(|j| hb[j] * ha[(j + s) % n]).sum())
        .collect();
    let mut maxima: Vec<usize> = (0..n)
        .filter(|&s| c[s] > c[(s + n - 1) % n] && c[s] >= c[(s + 1) % n])
        .collect();
    maxima.sort_by(|&p, &q| c[q].total_cmp(&c[p]).then(p.cmp(&q)));
    let step = PI / n as f64;
    let mut out = Vec::new();
    // Peaks at least 5° apart (a broad peak has shoulders).
    let apart = (5.0 / 0.25) as usize;
    let mut kept: Vec<usize> = Vec::new();
    for s in maxima {
        if kept.len() >= peaks.max(1) {
            break;
        }
        if kept.iter().all(|&k| {
            let d = s.abs_diff(k);
            d.min(n - d) >= apart
        }) {
            kept.push(s);
        }
    }
    for s in kept {
        let (l, m, r) = (c[(s + n - 1) % n], c[s], c[(s + 1) % n]);
        let denom = l - 2.0 * m + r;
        let offset = if denom < 0.0 {
            (0.5 * (l - r) / denom).clamp(-0.5, 0.5)
        } else {
            0.0
        };
        let delta = (s as f64 + offset) * step;
        out.push(wrap_angle(delta));
        out.push(wrap_angle(delta + PI));
    }
    out
}

/// A coarse raster of wall points (see step 2).
struct Coarse {
    /// Cell index of local (0, 0).
    origin: [i64; 2],
    width: usize,
    height: usize,
    score: Vec<i32>,
    walls: Vec<[usize; 2]>,
}

impl Coarse {
    fn draw(points: impl Iterator<Item = DVec2> + Clone, cell: f64) -> Option<Coarse> {
        let idx = |p: DVec2| [(p.x / cell).floor() as i64, (p.y / cell).floor() as i64];
        let (mut lo, mut hi) = ([i64::MAX; 2], [i64::MIN; 2]);
        for p in points.clone() {
            let g = idx(p);
            for k in 0..2 {
                lo[k] = lo[k].min(g[k]);
                hi[k] = hi[k].max(g[k]);
            }
        }
        if lo[0] > hi[0] {
            return None;
        }
        let origin = [lo[0] - 1, lo[1] - 1];
        let width = (hi[0] - origin[0] + 2) as usize;
        let height = (hi[1] - origin[1] + 2) as usize;
        let mut hit = vec![false; width * height];
        for p in points {
            let g = idx(p);
            hit[(g[1] - origin[1]) as usize * width + (g[0] - origin[0]) as usize] = true;
        }
        let mut score = vec![0i32; width * height];
        let mut walls = Vec::new();
        for y in 0..height {
            for x in 0..width {
                if !hit[y * width + x] {
                    continue;
                }
                walls.push([x, y]);
                for yy in y.saturating_sub(1)..(y + 2).min(height) {
                    for xx in x.saturating_sub(1)..(x + 2).min(width) {
                        let s = &mut score[yy * width + xx];
                        *s = (*s).max(if (xx, yy) == (x, y) { 2 } else { 1 });
                    }
                }
            }
        }
        Some(Coarse {
            origin,
            width,
            height,
            score,
            walls,
        })
    }
}

/// Best `count` translation peaks (cells, score) of B's raster over A's,
/// at least `apart` cells from each other.
fn translation_peaks(a: &Coarse, b: &Coarse, count: usize, apart: f64) -> Vec<([i64; 2], i32)> {
    let nx = a.width + b.width - 1;
    let ny = a.height + b.height - 1;
    let mut acc = vec![0i32; nx * ny];
    for &[lx, ly] in &b.walls {
        let (cx, cy) = (b.width - 1 - lx, b.height - 1 - ly);
        for ay in 0..a.height {
            add_row(
                &mut acc[(cy + ay) * nx + cx..][..a.width],
                &a.score[ay * a.width..][..a.width],
            );
        }
    }
    // Translation of index (ix, iy), in cells: B's global cell g lands on
    // A's global cell g + t.
    let t0 = [
        a.origin[0] - b.origin[0] - b.width as i64 + 1,
        a.origin[1] - b.origin[1] - b.height as i64 + 1,
    ];
    Correlation { t0, nx, ny, acc }.peaks(count, apart)
}

/// The coarse cell for two maps (step 2).
pub fn coarse_cell(a: &WallMap, b: &WallMap, cfg: &SearchConfig) -> f64 {
    let side = a.extent_m().max_element().max(b.extent_m().max_element());
    cfg.coarse_m.max(side / cfg.coarse_side)
}

/// The coarse overlays (steps 1 and 2), best first.
pub fn coarse_overlays(a: &WallMap, b: &WallMap, cfg: &SearchConfig) -> Vec<(Pose2, i64)> {
    let cell = coarse_cell(a, b, cfg);
    let Some(ra) = Coarse::draw(a.walls.iter().copied(), cell) else {
        return Vec::new();
    };
    let mut out: Vec<(Pose2, i64)> = Vec::new();
    for theta in rotation_candidates(a, b, cfg.rotation_peaks) {
        let (s, c) = theta.sin_cos();
        let turned = b
            .walls
            .iter()
            .map(move |p| DVec2::new(c * p.x - s * p.y, s * p.x + c * p.y));
        let Some(rb) = Coarse::draw(turned, cell) else {
            continue;
        };
        for (t, score) in translation_peaks(&ra, &rb, cfg.peaks_per_rotation, cfg.distinct_m / cell)
        {
            // The cell's centre error is at most one cell; refinement fixes it.
            out.push((
                Pose2::new(t[0] as f64 * cell, t[1] as f64 * cell, theta),
                score as i64,
            ));
        }
    }
    out.sort_by(|p, q| {
        q.1.cmp(&p.1)
            .then(p.0.theta.total_cmp(&q.0.theta))
            .then(p.0.x.total_cmp(&q.0.x))
            .then(p.0.y.total_cmp(&q.0.y))
    });
    out
}

/// `Σ max(0, 1 − d/τ)` over `points` of B moved by `pose`, `d` the
/// distance to A's nearest wall.
pub fn field_score(a: &WallMap, points: &[DVec2], pose: &Pose2, tau: f64) -> f64 {
    let f = pose.frame();
    let mut sum = 0.0;
    for p in points {
        if let Some(d) = a.wall_distance(f.to_parent(*p)) {
            if d < tau {
                sum += 1.0 - d / tau;
            }
        }
    }
    sum
}

/// Pattern search from `start` on the field score with `tau` (step 3):
/// try a step each way along x, y and θ, take the best improvement, halve
/// the steps when none improves, stop under `min_step_m`.
fn climb(
    a: &WallMap,
    points: &[DVec2],
    start: Pose2,
    tau: f64,
    step_m: f64,
    step_rad: f64,
    min_step_m: f64,
) -> (Pose2, f64) {
    let (mut pose, mut best) = (start, field_score(a, points, &start, tau));
    let (mut sm, mut sr) = (step_m, step_rad);
    let mut evaluations = 0;
    while sm >= min_step_m && evaluations < 2000 {
        let moves = [
            (sm, 0.0, 0.0),
            (-sm, 0.0, 0.0),
            (0.0, sm, 0.0),
            (0.0, -sm, 0.0),
            (0.0, 0.0, sr),
            (0.0, 0.0, -sr),
        ];
        let mut improved = None;
        for (dx, dy, dt) in moves {
            // Turn about B's wall centre in A (so a turn does not also
            // swing the map far away).
            let cand = Pose2::new(pose.x + dx, pose.y + dy, pose.theta + dt);
            evaluations += 1;
            let s = field_score(a, points, &cand, tau);
            if s > best && improved.is_none_or(|(_, b)| s > b) {
                improved = Some((cand, s));
            }
        }
        match improved {
            Some((p, s)) => {
                pose = p;
                best = s;
            }
            None => {
                sm *= 0.5;
                sr *= 0.5;
            }
        }
    }
    (Pose2::new(pose.x, pose.y, wrap_angle(pose.theta)), best)
}

/// A pose turned by `dt` about the point `pivot` of B (in B's frame):
/// used so the search's rotation steps turn B about its own middle.
fn about(pose: &Pose2, pivot: DVec2) -> (Pose2, Pose2) {
    // B' frame = B frame shifted to the pivot: pose' = pose ⊕ (pivot, 0).
    let shift = Pose2::new(pivot.x, pivot.y, 0.0);
    (pose.compose(&shift), shift.inverse())
}

/// Refines one coarse overlay (step 3): B's image frame in A's and its
/// narrow field score.
pub fn refine(
    a: &WallMap,
    b: &WallMap,
    coarse: Pose2,
    cell: f64,
    cfg: &SearchConfig,
) -> (Pose2, f64) {
    // Work in a frame of B centred on its walls, so that turning is
    // about the middle of B.
    let centre = b.walls.iter().copied().sum::<DVec2>() / b.walls.len().max(1) as f64;
    let centred: Vec<DVec2> = b.walls.iter().map(|p| *p - centre).collect();
    let (start, back) = about(&coarse, centre);
    let wide = thinned(&centred, 4000);
    let (p1, _) = climb(
        a,
        &wide,
        start,
        cfg.tau_wide_m,
        0.5 * cell,
        1f64.to_radians(),
        0.02,
    );
    let narrow = thinned(&centred, 30_000);
    let (p2, score) = climb(
        a,
        &narrow,
        p1,
        cfg.tau_narrow_m,
        0.1,
        0.25f64.to_radians(),
        0.004,
    );
    let scale = b.walls.len() as f64 / narrow.len().max(1) as f64;
    (p2.compose(&back), score * scale)
}

/// Steps 1–3: the refined overlays, best narrow score first.
pub fn propose(a: &WallMap, b: &WallMap, cfg: &SearchConfig) -> Vec<Proposal> {
    let cell = coarse_cell(a, b, cfg);
    let mut coarse = coarse_overlays(a, b, cfg);
    coarse.truncate(cfg.max_hypotheses.max(1));
    let mut out: Vec<Proposal> = coarse
        .into_iter()
        .map(|(c, s)| {
            let (pose, score) = refine(a, b, c, cell, cfg);
            Proposal {
                coarse: c,
                coarse_score: s,
                pose,
                score,
            }
        })
        .collect();
    out.sort_by(|p, q| {
        q.score
            .total_cmp(&p.score)
            .then(q.coarse_score.cmp(&p.coarse_score))
    });
    out
}
