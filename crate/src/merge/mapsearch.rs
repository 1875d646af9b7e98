//! # Searching one map for the other: hypotheses from the maps alone
//!
//! Vision proposes a transform only where the two cameras saw one place
//! from nearby viewpoints. Two robots can share many metres of wall and
//! never have looked at the same stretch from the same side: then there is
//! no true visual evidence at all, yet the overlap is plain in the maps.
//! This module is a second, independent source of hypotheses, taken from
//! the grids themselves, and judged by the same contradiction test as the
//! vision's ([`super::verdict`]) with stricter demands on the evidence.
//!
//! The search follows S. Carpin, *Fast and accurate map merging for
//! multi-robot systems* (Autonomous Robots 25, 2008): first the rotation,
//! from the directions the walls run in; then the translation, by
//! correlating the two maps. It differs from Carpin's in two places: the
//! translation is searched in two dimensions at once (Carpin correlates the
//! maps' x and y projections, which two unrelated lattices of walls also
//! fill), and the score punishes walls that fall in the other map's
//! observed free space, as the verdict does. The overlays found are then
//! judged as the verdict judges vision's (Birk and Carpin 2006 count
//! agreement and disagreement; we also demand absolute evidence).
//!
//! 1. **Rotation.** Carpin's *Hough spectrum*: for each normal direction
//!    `φ` (0.25° steps over 180°) the wall cells are binned by their
//!    distance `ρ = x cos φ + y sin φ` from the origin, and the spectrum at
//!    `φ` is the sum of the squared bin counts. Along a wall's normal all
//!    its cells fall into one bin, so the spectrum peaks sharply at the
//!    directions the walls face, and turning a map shifts its spectrum by
//!    the same angle. The circular cross-correlation of the two maps'
//!    spectra peaks at the rotation `δ` that lines B's walls up with A's,
//!    refined to a fraction of a step by a parabola. Indoor walls, and the
//!    walls of our mazes, run in two perpendicular directions, so the
//!    spectra are folded modulo 90° first (`φ` and `φ + 90°` added), and a
//!    fold of 90° cannot tell `δ` from `δ + 90°`, `δ + 180°` or `δ + 270°`:
//!    all four are searched. (A histogram of per-cell wall normals was
//!    tried first: the normals of a digital line a few cells long are
//!    biased toward the grid axes, and the rotation came out up to 9° off.)
//! 2. **Translation.** For each of the four rotations, both maps are drawn
//!    at a coarse cell size (`cell_m`, 0.1 m) in A's axes. Each coarse cell
//!    of a map scores `+1` when a wall lies within one cell, `−free_penalty`
//!    when it and its eight neighbours are all free (the robot drove or saw
//!    through there), and 0 when unknown. The score of a translation `t` is
//!    the sum, over B's wall cells moved by `t`, of A's cell scores, plus the
//!    sum, over A's wall cells moved by `−t`, of B's: walls on walls count,
//!    walls where the other robot saw nothing count nothing, walls in the
//!    other's free space count against. The best few well-separated peaks
//!    of each rotation (`distinct_m` apart) are kept: exactly those that
//!    scoring every whole-cell translation at which the maps overlap would
//!    give ([`correlate`], the reference), found by a multi-resolution
//!    branch and bound ([`super::peaksearch`], after Olson 2009) that
//!    scores only the translations whose upper bound can still beat the
//!    peaks kept (on 60 m maps, a fraction of a percent of them).
//! 3. **Refinement and the verdict.** Each peak, strongest first, is
//!    refined by the verdict's grid alignment ([`super::align`], a window of
//!    ±0.4 m and ±3° around it) and the overlaid maps are compared cell by
//!    cell ([`super::verdict::map_agreement`]). A hypothesis passes only if
//!    the maps do not contradict each other by the verdict's own test (no
//!    piece of wall 0.8 m long in the other map's free space, at most 2 %
//!    of the overlapping walls), and if the evidence is strong in absolute
//!    terms: at least `min_agree_cells` wall cells of *each* map on the
//!    other's walls (the vision verdict asks 60, because there the frames
//!    already vouch for the transform), walls crossing in every direction
//!    (`min_weak_constraint`), and **shared floor**: at least
//!    `min_free_cells` free cells on free cells. Two robots that mapped the
//!    same place both saw its floor. Two *different* buildings whose outer
//!    walls are laid corner on corner agree on many metres of crossing wall
//!    without a single contradiction (the inside of one lies on the unknown
//!    outside of the other), and share no floor at all: on the benchmark's
//!    separate mazes, such overlays reached 450 wall cells each way with 0
//!    free cells in common, and the one wrong overlay that did share some
//!    floor had 2,300 free cells and 540 wall cells.
//! 4. **A clear winner.** A maze is a lattice (corridors 2.5 m apart), and
//!    a building's outline is symmetric, so one map turned or shifted can
//!    lie on part of the other without contradiction. The *rivals* of the
//!    best passing hypothesis are the different transforms (`distinct_m` or
//!    `distinct_rad` away) that the maps do not contradict and whose
//!    agreeing walls cross (the verdict's `min_weak_constraint`), whether
//!    or not they share floor or pass the absolute thresholds. The merge is
//!    proposed only if the winner has at least `min_margin` times as many
//!    wall cells on the other map's walls (the weaker direction) as the
//!    best rival. (On the benchmark, the rivals that passed every absolute
//!    test had less than a quarter of the true overlay's wall.)
//!
//! The answer is a transform and the numbers behind it, or the reason there
//! is none. The automatic method ([`super::job`]) asks for it only when
//! vision found no transform the maps confirm, and says in its reason that
//! the maps alone agree. Nothing here reads the truth; everything is
//! deterministic (no random sampling at all).
//!
//! Limits: rotations come only from the dominant wall directions, so maps
//! of buildings without a dominant pair of perpendicular wall directions
//! are not searched well (the search then finds nothing, and says so; it
//! does not guess). And the maps alone cannot merge what they do not both
//! show: a small overlap gives too little evidence by design.

mod steps;

pub use steps::MapSearchSteps;
use steps::RotationSearch;

use super::align::refine_alignment;
use super::peaksearch::ScoreImage;
use super::raster_correlation::{add_row, Correlation};
use super::verdict::{contradiction_reason, map_agreement, Agreement, VerdictConfig};
use super::MergeStatus;
use crate::geom::{wrap_angle, Pose2};
use crate::slam::grid::{state_of, CellState, OccupancyGrid};
use glam::DVec2;

/// Settings of [`search_maps`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapSearchConfig {
    /// Coarse cell size of the translation search, metres. Default 0.1.
    pub cell_m: f64,
    /// What a wall in the other map's sure free space costs, in agreeing
    /// wall cells. Default 3.
    pub free_penalty: i32,
    /// Peaks kept per rotation. Default 4.
    pub peaks_per_rotation: usize,
    /// Hypotheses refined and judged, strongest first. Default 12.
    pub max_hypotheses: usize,
    /// Two transforms closer than this (at B's walls) and
    /// `distinct_rad` are one. Default 1.0 m (well under a maze corridor's
    /// 2.5 m, well over the search's error).
    pub distinct_m: f64,
    /// Default 3°.
    pub distinct_rad: f64,
    /// Wall cells of *each* map that must lie on the other's walls.
    /// Default 600 (30 m of wall at 0.05 m cells).
    pub min_agree_cells: usize,
    /// Least `weak_constraint` of the agreement (cells of agreeing wall
    /// crossing the weakest direction). Default 300.
    pub min_weak_constraint: f64,
    /// Free cells of one map on free cells of the other (both directions
    /// summed) that must overlap: both robots saw the floor of the common
    /// region. Default 3000 (about 3.75 m² each way at 0.05 m cells).
    pub min_free_cells: usize,
    /// The winner's `min_direction_agree` over that of the best different
    /// transform the maps do not contradict. Default 2.5.
    pub min_margin: f64,
}

impl Default for MapSearchConfig {
    fn default() -> Self {
        MapSearchConfig {
            cell_m: 0.1,
            free_penalty: 3,
            peaks_per_rotation: 4,
            max_hypotheses: 12,
            distinct_m: 1.0,
            distinct_rad: 3f64.to_radians(),
            min_agree_cells: 600,
            min_weak_constraint: 300.0,
            min_free_cells: 3000,
            min_margin: 2.5,
        }
    }
}

/// One overlay the search looked at.
#[derive(Clone, Debug, PartialEq)]
pub struct MapHypothesis {
    /// The correlation peak: B's frame in A's, to a coarse cell.
    pub coarse: Pose2,
    /// Its correlation score.
    pub coarse_score: i64,
    /// After the grid alignment (`None` when it found too little to align).
    pub pose: Option<Pose2>,
    pub agreement: Option<Agreement>,
    /// Agreeing wall cells minus `free_penalty` per contradicting one.
    pub net: f64,
    /// The maps do not contradict each other here (the verdict's test),
    /// and the agreeing walls cross (`weak_constraint` at least the
    /// verdict's minimum): a rival the winner must clearly beat.
    pub plausible: bool,
    /// Why it fails the verdict; `None` when it passes.
    pub failure: Option<String>,
}

/// What the search found.
#[derive(Clone, Debug, PartialEq)]
pub struct MapSearch {
    pub status: MergeStatus,
    /// A sentence with numbers: "maps alone agree: …" or why not.
    pub reason: String,
    /// B's frame in A's, when merged.
    pub pose: Option<Pose2>,
    /// 0..1 (0 unless merged).
    pub confidence: f64,
    /// The rotation the wall directions gave (modulo 90°), rad.
    pub rotation_rad: Option<f64>,
    /// Every hypothesis judged, strongest correlation first.
    pub hypotheses: Vec<MapHypothesis>,
    /// Index of the winner and of the best different transform.
    pub winner: Option<usize>,
    pub runner_up: Option<usize>,
}

impl MapSearch {
    fn refuse(reason: String) -> MapSearch {
        MapSearch {
            status: MergeStatus::NoMerge,
            reason,
            pose: None,
            confidence: 0.0,
            rotation_rad: None,
            hypotheses: Vec::new(),
            winner: None,
            runner_up: None,
        }
    }
}

/// Angles of the Hough spectrum: 0.25° steps over 180°.
const ANGLES: usize = 720;

/// Carpin's Hough spectrum of a map's walls, folded modulo 90°: for each
/// normal direction `φ` (0.25° steps), the wall cells are binned by their
/// distance `ρ = x cos φ + y sin φ` from the origin (one bin per grid
/// cell), and the spectrum is the sum of the squared bin counts. Along a
/// wall's normal all its cells fall into one bin, so the spectrum peaks
/// sharply at the directions the walls face, and a rotation of the map
/// shifts the spectrum by the same angle. The fold adds `φ` and `φ + 90°`.
/// Returns the folded spectrum (mean removed) and the number of wall cells.
fn hough_spectrum(grid: &OccupancyGrid) -> (Vec<f64>, usize) {
    let cells = super::align::occupied_cells(grid);
    let half = ANGLES / 2;
    if cells.is_empty() {
        return (vec![0.0; half], 0);
    }
    let r = grid.resolution_m();
    let far = cells.iter().map(|p| p.length()).fold(0.0, f64::max);
    let n_bins = (2.0 * far / r).ceil() as usize + 2;
    let mut bins = vec![0u32; n_bins];
    let mut spectrum = vec![0.0; ANGLES];
    for (j, s) in spectrum.iter_mut().enumerate() {
        let phi = (j as f64 * 180.0 / ANGLES as f64).to_radians();
        let (sin, cos) = phi.sin_cos();
        bins.iter_mut().for_each(|b| *b = 0);
        for p in &cells {
            let rho = p.x * cos + p.y * sin;
            bins[((rho + far) / r) as usize] += 1;
        }
        *s = bins.iter().map(|&b| (b as f64) * (b as f64)).sum();
    }
    let mut folded: Vec<f64> = (0..half)
        .map(|j| spectrum[j] + spectrum[j + half])
        .collect();
    let mean = folded.iter().sum::<f64>() / half as f64;
    folded.iter_mut().for_each(|v| *v -= mean);
    (folded, cells.len())
}

/// The rotation (modulo 90°, rad) that turns B's walls onto A's
/// directions: the peak of the circular cross-correlation of the two maps'
/// folded Hough spectra, refined by a parabola through it and its
/// neighbours.
pub fn dominant_rotation(a: &OccupancyGrid, b: &OccupancyGrid) -> Option<f64> {
    rotation_between(&WallSpectrum::of(a), &WallSpectrum::of(b))
}

/// A map's folded Hough spectrum ([`hough_spectrum`]), computed once per
/// map when many pairs are compared ([`super::pairbudget`], and the
/// searches of [`MapSearchSteps::with_spectra`]).
#[derive(Clone, Debug)]
pub struct WallSpectrum {
    folded: Vec<f64>,
    walls: usize,
}

impl WallSpectrum {
    pub fn of(grid: &OccupancyGrid) -> WallSpectrum {
        let (folded, walls) = hough_spectrum(grid);
        WallSpectrum { folded, walls }
    }
}

/// [`dominant_rotation`] from the two maps' spectra.
pub fn rotation_between(a: &WallSpectrum, b: &WallSpectrum) -> Option<f64> {
    let (ha, hb) = (&a.folded, &b.folded);
    if a.walls < 10 || b.walls < 10 {
        return None;
    }
    let n = ha.len();
    // B turned by s steps puts its direction j at j + s.
    let c: Vec<f64> = (0..n)
        .map(|s| (0..n).map(|j| hb[j] * ha[(j + s) % n]).sum())
        .collect();
    let best = (0..n).fold(0, |m, s| if c[s] > c[m] { s } else { m });
    let (l, m, r) = (c[(best + n - 1) % n], c[best], c[(best + 1) % n]);
    let denom = l - 2.0 * m + r;
    let offset = if denom < 0.0 {
        (0.5 * (l - r) / denom).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    let step_deg = 180.0 / ANGLES as f64;
    Some(((best as f64 + offset) * step_deg).to_radians())
}

/// A map drawn at the coarse cell size in A's axes (see step 2 of the
/// module doc).
struct Raster {
    /// Global coarse index (in A's axes) of local cell (0, 0).
    origin: [i64; 2],
    width: usize,
    height: usize,
    /// 0 unknown, 1 free, 2 wall, row by row (what the scores are made of).
    state: Vec<u8>,
    /// Cell scores, row by row.
    score: Vec<i32>,
    /// Each row's stretches of non-zero score ([`RowRuns`]).
    runs: RowRuns,
    /// Local indices of the wall cells.
    walls: Vec<[usize; 2]>,
}

impl Raster {
    /// `grid` turned by `theta` about its frame's origin, at `cell_m`.
    fn draw(grid: &OccupancyGrid, theta: f64, cell_m: f64, free_penalty: i32) -> Option<Raster> {
        let (s, c) = theta.sin_cos();
        let turn = |p: DVec2| DVec2::new(c * p.x - s * p.y, s * p.x + c * p.y);
        let (lo, hi) = turned_bounds(grid, &turn)?;
        // One empty cell of margin on each side, for the neighbourhoods.
        let origin = [
            (lo.x / cell_m).floor() as i64 - 1,
            (lo.y / cell_m).floor() as i64 - 1,
        ];
        let width = ((hi.x / cell_m).floor() as i64 - origin[0] + 2) as usize;
        let height = ((hi.y / cell_m).floor() as i64 - origin[1] + 2) as usize;
        // 0 unknown, 1 free, 2 wall (a wall anywhere in the cell wins).
        let mut state = vec![0u8; width * height];
        let at = |q: DVec2| {
            let x = ((q.x / cell_m).floor() as i64 - origin[0]) as usize;
            let y = ((q.y / cell_m).floor() as i64 - origin[1]) as usize;
            y * width + x
        };
        for iy in 0..grid.height() {
            mark_row(grid, iy, &turn, &at, &mut state);
        }
        Some(Raster::of_states(
            origin,
            width,
            height,
            state,
            free_penalty,
        ))
    }

    /// The raster of the cell states `state` (`width` × `height`, with the
    /// empty margin [`Raster::draw`] leaves): each cell's score from its
    /// 3 × 3 neighbourhood, and the wall cells in row order.
    fn of_states(
        origin: [i64; 2],
        width: usize,
        height: usize,
        state: Vec<u8>,
        free_penalty: i32,
    ) -> Raster {
        let mut score = vec![0i32; width * height];
        let mut walls = Vec::new();
        for y in 1..height - 1 {
            for x in 1..width - 1 {
                let mut near_wall = false;
                let mut all_free = true;
                for dy in 0..3 {
                    for dx in 0..3 {
                        let v = state[(y + dy - 1) * width + x + dx - 1];
                        near_wall |= v == 2;
                        all_free &= v == 1;
                    }
                }
                score[y * width + x] = if near_wall {
                    1
                } else if all_free {
                    -free_penalty
                } else {
                    0
                };
                if state[y * width + x] == 2 {
                    walls.push([x, y]);
                }
            }
        }
        let runs = RowRuns::of(&score, width);
        Raster {
            origin,
            width,
            height,
            state,
            score,
            runs,
            walls,
        }
    }

    /// This raster turned a quarter turn counter-clockwise about its
    /// frame's origin, cell for cell: global coarse cell `(gx, gy)` (the
    /// square `[gx, gx + 1) × [gy, gy + 1)` in cells) becomes `(−gy − 1,
    /// gx)`. The four quarter turns of a map are then one drawing of the
    /// fine grid and three permutations of its coarse cells, the same
    /// cells turned (drawing each turn anew costs the whole fine grid
    /// again, and bins a few cells differently for the rounding of the
    /// turned sine and cosine).
    fn quarter_turn(&self, free_penalty: i32) -> Raster {
        let (w, h) = (self.width, self.height);
        // Local (x, y) goes to (h − 1 − y, x) of a raster h wide, w high.
        let mut state = vec![0u8; w * h];
        for y in 0..h {
            for x in 0..w {
                state[x * h + (h - 1 - y)] = self.state[y * w + x];
            }
        }
        let origin = [-self.origin[1] - h as i64, self.origin[0]];
        Raster::of_states(origin, h, w, state, free_penalty)
    }

    /// The raster as the branch and bound reads it.
    fn image(&self) -> ScoreImage<'_> {
        ScoreImage {
            width: self.width,
            height: self.height,
            score: &self.score,
            walls: &self.walls,
        }
    }

    /// The scores with both axes reversed (for the second half of the
    /// correlation) and their rows' runs.
    fn reversed_scores(&self) -> (Vec<i32>, RowRuns) {
        let mut out = self.score.clone();
        out.reverse();
        let runs = RowRuns::of(&out, self.width);
        (out, runs)
    }
}

/// Where a raster's rows are not zero: for each row, its stretches of
/// non-zero cells (gaps shorter than [`RowRuns::GAP`] bridged), as
/// `[start, end)` columns. The correlation adds only these: most of a
/// robot's coarse map is unknown ground, whose zeros add nothing, so the
/// sums are the same to the bit and the rows shorter.
struct RowRuns {
    /// Row `y`'s runs are `runs[first[y]..first[y + 1]]`.
    first: Vec<usize>,
    runs: Vec<[usize; 2]>,
}

impl RowRuns {
    /// Zero gaps shorter than this are added through: a run's set-up costs
    /// about as much as adding a few cells.
    const GAP: usize = 8;

    fn of(score: &[i32], width: usize) -> RowRuns {
        let mut first = vec![0];
        let mut runs: Vec<[usize; 2]> = Vec::new();
        for row in score.chunks_exact(width.max(1)) {
            let row_first = runs.len();
            for (x, _) in row.iter().enumerate().filter(|(_, &v)| v != 0) {
                let in_row = runs.len() > row_first;
                match runs.last_mut() {
                    Some(r) if in_row && x - r[1] < Self::GAP => r[1] = x + 1,
                    _ => runs.push([x, x + 1]),
                }
            }
            first.push(runs.len());
        }
        RowRuns { first, runs }
    }

    /// Row `y`'s runs.
    fn row(&self, y: usize) -> &[[usize; 2]] {
        &self.runs[self.first[y]..self.first[y + 1]]
    }
}

/// The box of `grid`'s known cell centres turned by `turn`, or `None`
/// when no cell is known. Along a row each turned coordinate is monotonic
/// in the column (every floating-point step from the column index to it —
/// add, multiply by a constant, add a constant — is), so a row's extremes
/// lie at its first and last known cells: two cells a row are turned
/// instead of all of them, and the box is the same to the bit.
fn turned_bounds(grid: &OccupancyGrid, turn: &impl Fn(DVec2) -> DVec2) -> Option<(DVec2, DVec2)> {
    let known = |u: &i8| state_of(*u) != CellState::Unknown;
    let w = grid.width();
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for (iy, row) in grid.raw_units().chunks_exact(w.max(1)).enumerate() {
        let (Some(first), Some(last)) = (row.iter().position(known), row.iter().rposition(known))
        else {
            continue;
        };
        for ix in [first, last] {
            let q = turn(grid.cell_centre(ix, iy));
            lo = lo.min(q);
            hi = hi.max(q);
        }
    }
    lo.is_finite().then_some((lo, hi))
}

/// Marks row `iy`'s known cells in the raster's states (`at` gives a
/// turned centre's raster index); a wall wins over free. (A function per
/// row: a wasm engine optimises a function after a few calls.)
fn mark_row(
    grid: &OccupancyGrid,
    iy: usize,
    turn: &impl Fn(DVec2) -> DVec2,
    at: &impl Fn(DVec2) -> usize,
    state: &mut [u8],
) {
    let w = grid.width();
    for (ix, &u) in grid.raw_units()[iy * w..][..w].iter().enumerate() {
        let v = match state_of(u) {
            CellState::Unknown => continue,
            CellState::Free => 1,
            CellState::Occupied => 2,
        };
        let k = at(turn(grid.cell_centre(ix, iy)));
        state[k] = state[k].max(v);
    }
}

/// The translation (in cells) of the correlation's index (0, 0).
fn translation_origin(a: &Raster, b: &Raster) -> [i64; 2] {
    [
        a.origin[0] - b.origin[0] - b.width as i64 + 1,
        a.origin[1] - b.origin[1] - b.height as i64 + 1,
    ]
}

fn correlate(a: &Raster, b: &Raster) -> Correlation {
    let nx = a.width + b.width - 1;
    let ny = a.height + b.height - 1;
    let t0 = translation_origin(a, b);
    let mut acc = vec![0i32; nx * ny];
    // B's walls on A's scores: B's local cell l lands on A's local cell
    // l + t + b.origin − a.origin, so its row of translations starts at
    // index (b.width − 1 − l.x) and spans A's whole row (of which only
    // the runs of non-zero scores are added).
    for &[lx, ly] in &b.walls {
        let (cx, cy) = (b.width - 1 - lx, b.height - 1 - ly);
        for ay in 0..a.height {
            let at = (cy + ay) * nx + cx;
            for &[s, e] in a.runs.row(ay) {
                add_row(
                    &mut acc[at + s..at + e],
                    &a.score[ay * a.width + s..][..e - s],
                );
            }
        }
    }
    // A's walls on B's scores: A's local cell l sees B's local cell m at
    // index l + (b.size − 1 − m); with B's scores reversed in both axes the
    // row is again a contiguous slice.
    let (rev, rev_runs) = b.reversed_scores();
    for &[lx, ly] in &a.walls {
        for ry in 0..b.height {
            let at = (ly + ry) * nx + lx;
            for &[s, e] in rev_runs.row(ry) {
                add_row(&mut acc[at + s..at + e], &rev[ry * b.width + s..][..e - s]);
            }
        }
    }
    Correlation { t0, nx, ny, acc }
}

/// A map prepared once for the coarse comparisons of many pairs
/// ([`super::pairbudget`]): its wall spectrum and its raster at the
/// coarse cell in its own axes (the part of [`coarse_overlap`] that does
/// not depend on the other map). It owns what it holds, so a caller that
/// works a step at a time can keep it between calls.
pub struct CoarseMap {
    spectrum: WallSpectrum,
    cell_m: f64,
    raster: Option<Raster>,
}

impl CoarseMap {
    /// `grid` drawn at `cell_m` (at least its own cell).
    pub fn new(grid: &OccupancyGrid, cell_m: f64, free_penalty: i32) -> CoarseMap {
        CoarseMap::with_spectrum(grid, WallSpectrum::of(grid), cell_m, free_penalty)
    }

    /// [`CoarseMap::new`] given the grid's spectrum (`WallSpectrum::of(grid)`),
    /// for a caller that computes the two halves in separate steps.
    pub fn with_spectrum(
        grid: &OccupancyGrid,
        spectrum: WallSpectrum,
        cell_m: f64,
        free_penalty: i32,
    ) -> CoarseMap {
        let cell_m = cell_m.max(grid.resolution_m());
        CoarseMap {
            spectrum,
            cell_m,
            raster: Raster::draw(grid, 0.0, cell_m, free_penalty),
        }
    }
}

/// How well map B can lie on map A at all, from a coarse search: the
/// rotation from the spectra, then the best translation of each of the
/// four rotations at A's coarse cell (steps 1 and 2 of the module doc,
/// without refinement or verdict). Returns the best correlation score over
/// the coarse wall cells of the smaller map, counted both ways (about 1
/// when one map's walls all lie on the other's, lower where they fall on
/// unknown ground or in free space, 0 when nothing fits). A ranking figure
/// for [`super::pairbudget`], never a reason to merge: a maze's lattice
/// lays unrelated maps partly on each other too. (At this coarse cell the
/// exhaustive correlation is cheaper than the branch and bound's bounds.)
/// `grid_b` is the map `b` was made from: B is drawn once, turned by the
/// spectra's rotation, and the other three rotations are that raster
/// turned a quarter at a time, cell for cell ([`Raster::quarter_turn`]);
/// the correlation adds only the rows' non-zero runs ([`RowRuns`]). (On
/// the hour's sixteen maps both halve the 120 overlaps' time, every overlap
/// the same to the bit: docs/history/issue-22-many-robots.md, round 16.)
pub fn coarse_overlap(
    a: &CoarseMap,
    b: &CoarseMap,
    grid_b: &OccupancyGrid,
    free_penalty: i32,
) -> f64 {
    let mut overlap = CoarseOverlap::new(a, b);
    loop {
        if let Some(score) = overlap.step(a, grid_b, free_penalty) {
            return score;
        }
    }
}

/// [`coarse_overlap`] a rotation at a time (a correlation of 60 m maps
/// at the coarse cell is tens of milliseconds in wasm, four of them too
/// long for one call of the page): the best score so far between steps.
pub struct CoarseOverlap {
    /// The rotation between the maps' wall directions (`None`: too few
    /// walls, no overlap).
    delta: Option<f64>,
    /// Quarter turns done.
    turns: usize,
    best: i64,
    /// B drawn at the last turn done (the next is this turned a quarter,
    /// [`Raster::quarter_turn`]).
    last: Option<Raster>,
}

impl CoarseOverlap {
    /// The comparison of B (`b`) with A (`a`), no rotation tried yet.
    pub fn new(a: &CoarseMap, b: &CoarseMap) -> CoarseOverlap {
        CoarseOverlap {
            delta: rotation_between(&a.spectrum, &b.spectrum),
            turns: 0,
            best: 0,
            last: None,
        }
    }

    /// Quarter turns tried so far (four in all).
    pub fn turns(&self) -> usize {
        self.turns
    }

    /// The next quarter turn's correlation, with the same arguments on
    /// every call (`grid_b` is the map `b` was made from); the overlap
    /// after the fourth, or as soon as there can be none.
    pub fn step(
        &mut self,
        a: &CoarseMap,
        grid_b: &OccupancyGrid,
        free_penalty: i32,
    ) -> Option<f64> {
        let (Some(delta), Some(ra)) = (self.delta, a.raster.as_ref()) else {
            return Some(0.0);
        };
        let rb = match self.last.take() {
            Some(last) => last.quarter_turn(free_penalty),
            None => match Raster::draw(grid_b, wrap_angle(delta), a.cell_m, free_penalty) {
                Some(rb) => rb,
                None => return Some(0.0),
            },
        };
        let corr = correlate(ra, &rb);
        self.best = self
            .best
            .max(corr.acc.iter().copied().max().unwrap_or(0) as i64);
        // B has as many wall cells at every quarter turn.
        let walls_b = rb.walls.len();
        self.last = Some(rb);
        self.turns += 1;
        if self.turns < 4 {
            return None;
        }
        let smaller = ra.walls.len().min(walls_b);
        if smaller == 0 {
            return Some(0.0);
        }
        Some((self.best as f64 / (2 * smaller) as f64).max(0.0))
    }
}

/// Whether two transforms of B differ by more than the settings allow, at
/// the centroid `at` of B's walls.
fn distinct(p: &Pose2, q: &Pose2, at: DVec2, cfg: &MapSearchConfig) -> bool {
    (p.transform_point(at) - q.transform_point(at)).length() >= cfg.distinct_m
        || wrap_angle(p.theta - q.theta).abs() >= cfg.distinct_rad
}

/// Step 3 of the module doc, its first half: a correlation peak refined
/// to a pose of B's frame in A's (`None` when too few walls overlap to align).
fn refine(
    a: &OccupancyGrid,
    b: &OccupancyGrid,
    coarse: Pose2,
    verdict: &VerdictConfig,
) -> Option<Pose2> {
    refine_alignment(a, b, &coarse, &verdict.align).map(|aligned| aligned.pose)
}

/// Step 3's second half: the maps' agreement at the refined pose ([`refine`])
/// of the peak `(coarse pose, score)`, and the verdict on it.
fn judge_refined(
    a: &OccupancyGrid,
    b: &OccupancyGrid,
    (coarse, coarse_score): (Pose2, i64),
    refined: Option<Pose2>,
    cfg: &MapSearchConfig,
    verdict: &VerdictConfig,
) -> MapHypothesis {
    let mut h = MapHypothesis {
        coarse,
        coarse_score,
        pose: None,
        agreement: None,
        net: 0.0,
        plausible: false,
        failure: None,
    };
    let Some(pose) = refined else {
        h.failure = Some("too few walls overlap to align".into());
        return h;
    };
    let agreement = map_agreement(a, b, &pose);
    h.pose = Some(pose);
    h.agreement = Some(agreement);
    h.net = agreement.occupied_agree as f64
        - cfg.free_penalty as f64 * agreement.occupied_contradict as f64;
    let contradiction = contradiction_reason(&agreement, verdict, a.resolution_m());
    h.plausible =
        contradiction.is_none() && agreement.weak_constraint >= verdict.min_weak_constraint;
    h.failure = if let Some(r) = contradiction {
        Some(r)
    } else if agreement.min_direction_agree < cfg.min_agree_cells {
        Some(format!(
            "too little common wall ({} of one map on the other's walls; {} needed)",
            agreement.min_direction_agree, cfg.min_agree_cells
        ))
    } else if agreement.weak_constraint < cfg.min_weak_constraint {
        Some(format!(
            "the common walls barely cross ({:.0} cells of crossing wall; {:.0} needed)",
            agreement.weak_constraint, cfg.min_weak_constraint
        ))
    } else if agreement.free_agree < cfg.min_free_cells {
        Some(format!(
            "the maps share walls but hardly any floor ({} free cells on free cells; {} needed)",
            agreement.free_agree, cfg.min_free_cells
        ))
    } else {
        None
    };
    h
}

/// Centroid of a grid's wall cells (its own frame), or of its extent.
fn wall_centroid(grid: &OccupancyGrid) -> DVec2 {
    let cells = super::align::occupied_cells(grid);
    if cells.is_empty() {
        let size = DVec2::new(grid.width() as f64, grid.height() as f64) * grid.resolution_m();
        return grid.origin_m() + 0.5 * size;
    }
    cells.iter().copied().sum::<DVec2>() / cells.len() as f64
}

/// How [`coarse_peaks`] finds the best translations of each rotation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TranslationSearch {
    /// Score every translation ([`correlate`]): the reference.
    Exhaustive,
    /// Olson's multi-resolution branch and bound
    /// ([`super::peaksearch`]): the same peaks, far fewer scores.
    BranchAndBound,
}

/// Steps 1 and 2 of the module doc: the rotation from the wall
/// directions, then the best `peaks_per_rotation` translations of each of
/// the four rotations, all of them strongest first (ties by angle, then
/// position), at most `max_hypotheses`. Returns the rotation and the
/// peaks (B's frame in A's, to a coarse cell, with its score), or why
/// there are none.
pub fn coarse_peaks(
    a: &OccupancyGrid,
    b: &OccupancyGrid,
    cfg: &MapSearchConfig,
    how: TranslationSearch,
) -> Result<(f64, Vec<(Pose2, i64)>), String> {
    let (delta, ra) = coarse_start(a, &WallSpectrum::of(a), &WallSpectrum::of(b), cfg)?;
    let mut a_max = None;
    let mut coarse: Vec<(Pose2, i64)> = Vec::new();
    for k in 0..4 {
        let mut rotation = RotationSearch::start(a, &ra, &mut a_max, b, delta, k, cfg, how)?;
        coarse.extend(rotation.run_to_end(&mut a_max));
    }
    Ok((delta, coarse_ranked(coarse, cfg)))
}

/// Step 1 of [`coarse_peaks`]: the rotation from the wall directions
/// (`sa`, `sb`: the two maps' spectra), and A drawn unturned.
fn coarse_start(
    a: &OccupancyGrid,
    sa: &WallSpectrum,
    sb: &WallSpectrum,
    cfg: &MapSearchConfig,
) -> Result<(f64, Raster), String> {
    let Some(delta) = rotation_between(sa, sb) else {
        return Err("maps alone: too few walls to find their directions".into());
    };
    let cell = cfg.cell_m.max(a.resolution_m());
    let Some(ra) = Raster::draw(a, 0.0, cell, cfg.free_penalty) else {
        return Err("maps alone: a map is empty".into());
    };
    Ok((delta, ra))
}

/// Step 3 of [`coarse_peaks`]: every rotation's peaks, strongest first
/// (ties by angle, then position), at most `max_hypotheses`.
fn coarse_ranked(mut coarse: Vec<(Pose2, i64)>, cfg: &MapSearchConfig) -> Vec<(Pose2, i64)> {
    coarse.sort_by(|p, q| {
        q.1.cmp(&p.1)
            .then(p.0.theta.total_cmp(&q.0.theta))
            .then(p.0.x.total_cmp(&q.0.x))
            .then(p.0.y.total_cmp(&q.0.y))
    });
    coarse.truncate(cfg.max_hypotheses.max(1));
    coarse
}

/// Searches map A for map B (see the module doc): B's frame in A's, from
/// the maps alone, with the verdict's contradiction test and a clear
/// margin over every other transform found.
pub fn search_maps(
    a: &OccupancyGrid,
    b: &OccupancyGrid,
    cfg: &MapSearchConfig,
    verdict: &VerdictConfig,
) -> MapSearch {
    let mut steps = MapSearchSteps::default();
    loop {
        if let Some(found) = steps.step(a, b, cfg, verdict) {
            return found;
        }
    }
}

/// Step 4 of the module doc: one passing transform, clearly ahead of
/// every different one the maps do not contradict.
fn decide(
    hypotheses: Vec<MapHypothesis>,
    centroid_b: DVec2,
    delta: f64,
    cfg: &MapSearchConfig,
) -> MapSearch {
    let mut out = MapSearch::refuse(String::new());
    out.rotation_rad = Some(delta);
    let final_pose = |h: &MapHypothesis| h.pose.unwrap_or(h.coarse);
    let evidence = |h: &MapHypothesis| h.agreement.map_or(0, |a| a.min_direction_agree);
    // The passing hypothesis with the most evidence (ties: the stronger
    // correlation, which comes first).
    let best_of = |candidates: &mut dyn Iterator<Item = usize>| {
        candidates.fold(None, |best: Option<usize>, i| match best {
            Some(j) if evidence(&hypotheses[j]) >= evidence(&hypotheses[i]) => Some(j),
            _ => Some(i),
        })
    };
    let winner = best_of(&mut (0..hypotheses.len()).filter(|&i| hypotheses[i].failure.is_none()));
    let Some(w) = winner else {
        out.reason = match hypotheses.first() {
            None => "maps alone: no overlay of the walls scores above zero".into(),
            Some(h) => format!(
                "maps alone do not agree: at the best of {} overlays, {}",
                hypotheses.len(),
                h.failure.clone().unwrap_or_default()
            ),
        };
        out.hypotheses = hypotheses;
        return out;
    };
    let wp = final_pose(&hypotheses[w]);
    let runner = best_of(&mut (0..hypotheses.len()).filter(|&i| {
        hypotheses[i].plausible && distinct(&final_pose(&hypotheses[i]), &wp, centroid_b, cfg)
    }));
    out.winner = Some(w);
    out.runner_up = runner;
    let win = &hypotheses[w];
    let agreement = win.agreement.unwrap_or_default();
    let ours = agreement.min_direction_agree as f64;
    let second = runner.map_or(0.0, |r| evidence(&hypotheses[r]) as f64);
    if ours < cfg.min_margin * second {
        out.reason = format!(
            "maps alone are ambiguous: another overlay fits without contradiction ({:.0} and {:.0} wall cells of each map on the other's; {:.1} times needed)",
            ours, second, cfg.min_margin
        );
    } else {
        out.status = MergeStatus::Merged;
        out.pose = Some(wp);
        let margin = if second > 0.0 {
            format!(
                "{:.1} times the wall of any other overlay the maps do not contradict",
                ours / second
            )
        } else {
            "the maps contradict every other overlay".to_string()
        };
        out.reason = format!(
            "maps alone agree: {} wall cells on the other map's walls ({} in its free space), {} free cells on free cells; {}",
            agreement.occupied_agree, agreement.occupied_contradict, agreement.free_agree, margin
        );
        let evidence = 1.0 - (-ours / 1000.0).exp();
        out.confidence = (0.5 * agreement.ratio * evidence).clamp(0.0, 1.0);
    }
    out.hypotheses = hypotheses;
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::slam::grid::GridConfig;
    use std::f64::consts::FRAC_PI_2;

    /// A room seen from inside: an `w` × `h` m rectangle with a stub of
    /// wall from its south side, every wall cell hit three times from
    /// `eye` (so it is occupied) and the beams' cells free.
    fn room(w: f64, h: f64, eye: DVec2) -> OccupancyGrid {
        let mut grid = OccupancyGrid::new(GridConfig::default());
        let mut walls: Vec<DVec2> = Vec::new();
        let step = 0.02;
        for i in 0..=(w / step) as usize {
            let x = i as f64 * step;
            walls.push(DVec2::new(x, 0.0));
            walls.push(DVec2::new(x, h));
        }
        for i in 0..=(h / step) as usize {
            let y = i as f64 * step;
            walls.push(DVec2::new(0.0, y));
            walls.push(DVec2::new(w, y));
        }
        for i in 0..=(0.4 * h / step) as usize {
            walls.push(DVec2::new(0.6 * w, i as f64 * step));
        }
        grid.ensure_contains(DVec2::splat(-1.0), DVec2::new(w, h) + 1.0);
        for _ in 0..3 {
            for &p in &walls {
                grid.integrate_beam(eye, p, true);
            }
        }
        grid
    }

    /// The correlation written out plainly from the formula of the module
    /// doc: every translation's sum over B's walls of A's scores and over
    /// A's walls of B's (zero outside the rasters).
    fn correlate_by_definition(a: &Raster, b: &Raster) -> Vec<i32> {
        let at = |r: &Raster, x: i64, y: i64| {
            let inside = x >= 0 && y >= 0 && x < r.width as i64 && y < r.height as i64;
            if inside {
                r.score[y as usize * r.width + x as usize]
            } else {
                0
            }
        };
        let (bw, bh) = (b.width as i64, b.height as i64);
        let (nx, ny) = (a.width + b.width - 1, a.height + b.height - 1);
        let mut acc = vec![0i32; nx * ny];
        for iy in 0..ny as i64 {
            for ix in 0..nx as i64 {
                let mut s = 0;
                for &[x, y] in &b.walls {
                    s += at(a, ix + x as i64 - (bw - 1), iy + y as i64 - (bh - 1));
                }
                for &[x, y] in &a.walls {
                    s += at(b, bw - 1 - (ix - x as i64), bh - 1 - (iy - y as i64));
                }
                acc[iy as usize * nx + ix as usize] = s;
            }
        }
        acc
    }

    #[test]
    fn the_correlation_over_row_runs_is_the_definitions() {
        let a = room(6.0, 4.0, DVec2::new(1.0, 2.0));
        let b = room(5.0, 4.5, DVec2::new(4.0, 3.0));
        let ra = Raster::draw(&a, 0.0, 0.1, 3).expect("a has cells");
        for theta in [0.0, 0.3, -2.0] {
            let rb = Raster::draw(&b, theta, 0.1, 3).expect("b has cells");
            let runs = correlate(&ra, &rb);
            assert_eq!(runs.acc, correlate_by_definition(&ra, &rb), "theta {theta}");
            assert!(runs.acc.iter().any(|&v| v > 0) && runs.acc.iter().any(|&v| v < 0));
        }
        // The runs skip something: the room's unknown outside, and a row
        // of a 1 m wide gap holds two runs.
        let skipped: usize = (0..ra.height)
            .map(|y| ra.width - ra.runs.row(y).iter().map(|r| r[1] - r[0]).sum::<usize>())
            .sum();
        assert!(skipped > 0);
        let mut score = vec![0i32; 30];
        score[2] = 1;
        score[5] = -3;
        score[20] = 1;
        let runs = RowRuns::of(&score, 30);
        assert_eq!(runs.row(0), &[[2, 6], [20, 21]]);
    }

    #[test]
    fn a_quarter_turn_moves_each_coarse_cell_as_the_turn_moves_its_square() {
        let grid = room(6.0, 4.0, DVec2::new(1.0, 2.0));
        let r = Raster::draw(&grid, 0.3, 0.4, 3).expect("cells");
        let q = r.quarter_turn(3);
        assert_eq!((q.width, q.height), (r.height, r.width));
        // Global cell (gx, gy), the square [gx, gx + 1) × [gy, gy + 1),
        // turned by 90° is the square (−gy − 1, −gy] × [gx, gx + 1): cell
        // (−gy − 1, gx).
        let state_at = |r: &Raster, g: [i64; 2]| {
            let (x, y) = (g[0] - r.origin[0], g[1] - r.origin[1]);
            assert!(x >= 0 && y >= 0 && (x as usize) < r.width && (y as usize) < r.height);
            r.state[y as usize * r.width + x as usize]
        };
        for y in 0..r.height as i64 {
            for x in 0..r.width as i64 {
                let g = [r.origin[0] + x, r.origin[1] + y];
                assert_eq!(state_at(&q, [-g[1] - 1, g[0]]), state_at(&r, g));
            }
        }
        assert_eq!(q.walls.len(), r.walls.len());
        // Four quarter turns give the raster back.
        let back = q.quarter_turn(3).quarter_turn(3).quarter_turn(3);
        assert_eq!(
            (back.origin, back.width, back.height),
            (r.origin, r.width, r.height)
        );
        assert_eq!((&back.state, &back.score), (&r.state, &r.score));
        // And it is, but for cells whose fine cells straddle a coarse
        // edge after rounding, the map drawn a quarter turn further.
        let anew = Raster::draw(&grid, 0.3 + FRAC_PI_2, 0.4, 3).expect("cells");
        assert_eq!(
            (anew.origin, anew.width, anew.height),
            (q.origin, q.width, q.height)
        );
        let known = q.state.iter().filter(|&&s| s != 0).count();
        let differ = q
            .state
            .iter()
            .zip(&anew.state)
            .filter(|(a, b)| a != b)
            .count();
        assert!(
            known > 100 && differ * 100 <= known,
            "{differ} of {known} differ"
        );
    }

    #[test]
    fn the_coarse_overlap_of_a_map_with_itself_turned_is_whole() {
        // B is A's room turned by 100° about the origin and moved: its
        // walls lie on A's at one of the four quarter turns of the
        // spectra's rotation, which the turned rasters find.
        let a = room(6.0, 4.0, DVec2::new(1.0, 2.0));
        let turn = Pose2::new(0.7, -1.3, 100f64.to_radians());
        let mut b = OccupancyGrid::new(GridConfig::default());
        let mut walls: Vec<DVec2> = Vec::new();
        for i in 0..=300 {
            let x = i as f64 * 0.02;
            walls.push(DVec2::new(x, 0.0));
            walls.push(DVec2::new(x, 4.0));
        }
        for i in 0..=200 {
            let y = i as f64 * 0.02;
            walls.push(DVec2::new(0.0, y));
            walls.push(DVec2::new(6.0, y));
        }
        for i in 0..=80 {
            walls.push(DVec2::new(3.6, i as f64 * 0.02));
        }
        let from = turn.inverse();
        b.ensure_contains(DVec2::splat(-8.0), DVec2::splat(8.0));
        for _ in 0..3 {
            for &p in &walls {
                b.integrate_beam(
                    from.transform_point(DVec2::new(1.0, 2.0)),
                    from.transform_point(p),
                    true,
                );
            }
        }
        let (ca, cb) = (CoarseMap::new(&a, 0.4, 3), CoarseMap::new(&b, 0.4, 3));
        let whole = coarse_overlap(&ca, &cb, &b, 3);
        assert!(whole > 0.8, "overlap {whole}");
        // A room of another shape overlaps less.
        let other = room(3.0, 7.0, DVec2::new(1.5, 1.0));
        let part = coarse_overlap(&ca, &CoarseMap::new(&other, 0.4, 3), &other, 3);
        assert!(part < whole - 0.1, "{part} against {whole}");
    }
}
