//! # Refining the transform by aligning the two occupancy grids
//!
//! A candidate from vision rests on the points of a few frames: a few
//! dozen points, a few metres apart, each a centimetre or two off. Its
//! angle is good to a degree or so. The maps themselves hold far more
//! evidence: every wall both robots mapped. Once vision has put B's map
//! near the right place, the two grids can be laid onto each other exactly
//! as a scan is laid onto a map in SLAM ([`crate::slam`]), with B's
//! occupied cells playing the laser points:
//!
//! 1. the occupied cells of B (cell centres, in B's frame) are the "scan";
//! 2. A's grid becomes a smoothed likelihood field
//!    ([`crate::slam::likelihood`], Olson 2009 §III-B);
//! 3. Olson's multi-resolution correlative search
//!    ([`crate::slam::correlative`]) finds the best whole-cell translation
//!    and rotation step in a window around the guess;
//! 4. Gauss–Newton on the bilinear field ([`crate::slam::gauss_newton`],
//!    Kohlbrecher et al. 2011) refines it below a cell.
//!
//! Cells of B that land far outside A's grid at the guess cannot score and
//! are left out, which keeps the search proportional to the overlap. The
//! search turns B's cells about their centroid, not about B's origin: a
//! degree about an origin 20 m away would move the overlap by 0.35 m, out
//! of the translation window.
//!
//! The window is small on purpose (`±linear_window_m`, `±angular_window_rad`):
//! this step polishes a transform that vision found; it does not search
//! for one. A map-only search over all poses would find *some* overlay of
//! two corridors, which is the failure the vision step exists to avoid.

use crate::geom::Pose2;
use crate::slam::correlative::{search, CorrelativeConfig};
use crate::slam::gauss_newton::{mean_score, refine};
use crate::slam::grid::{CellState, OccupancyGrid};
use crate::slam::likelihood::LikelihoodField;
use glam::DVec2;

/// Settings of [`refine_alignment`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlignConfig {
    /// Translation window of the correlative search, metres. Default 0.4.
    pub linear_window_m: f64,
    /// Rotation window, radians. Default 3°.
    pub angular_window_rad: f64,
    /// Rotation step, radians. Default 0.25°.
    pub angular_step_rad: f64,
    /// Gauss–Newton iterations. Default 20.
    pub gauss_newton_iterations: usize,
    /// Fewer of B's occupied cells near A's grid and there is nothing to
    /// align. Default 30.
    pub min_cells: usize,
    /// A cell of B counts as on one of A's walls when the smoothed field
    /// there is at least this (the field of a saturated wall is about 0.4 at
    /// its centre, 0.24 one cell away). Default 0.2.
    pub on_wall_field: f64,
}

impl Default for AlignConfig {
    fn default() -> Self {
        AlignConfig {
            linear_window_m: 0.4,
            angular_window_rad: 3f64.to_radians(),
            angular_step_rad: 0.25f64.to_radians(),
            gauss_newton_iterations: 20,
            min_cells: 30,
            on_wall_field: 0.2,
        }
    }
}

/// The refined transform.
#[derive(Clone, Debug, PartialEq)]
pub struct Alignment {
    /// Pose of B's map frame in A's.
    pub pose: Pose2,
    /// Mean smoothed-field value of B's cells near A's grid (0..1).
    pub score: f64,
    /// B's occupied cells that land on A's walls at `pose`.
    pub matched_cells: usize,
}

/// Occupied cell centres of a grid, in its own frame.
pub fn occupied_cells(grid: &OccupancyGrid) -> Vec<DVec2> {
    let mut out = Vec::new();
    for iy in 0..grid.height() {
        occupied_in_row(grid, iy, &mut out);
    }
    out
}

/// The occupied cell centres of row `iy`. (A function per row: a wasm
/// engine optimises a function after a few calls, never a running loop.)
fn occupied_in_row(grid: &OccupancyGrid, iy: usize, out: &mut Vec<DVec2>) {
    for ix in 0..grid.width() {
        if grid.state(ix, iy) == CellState::Occupied {
            out.push(grid.cell_centre(ix, iy));
        }
    }
}

/// The extent of a grid in its own frame, as (lower-left, upper-right).
fn extent(grid: &OccupancyGrid) -> (DVec2, DVec2) {
    let lo = grid.origin_m();
    let size = DVec2::new(grid.width() as f64, grid.height() as f64) * grid.resolution_m();
    (lo, lo + size)
}

/// Lays B's occupied cells onto A's grid around `guess` (B's frame in
/// A's): correlative search, then Gauss–Newton. `None` when either grid is
/// empty, the guess is not finite, or fewer than `min_cells` of B's walls
/// come near A's grid.
pub fn refine_alignment(
    a: &OccupancyGrid,
    b: &OccupancyGrid,
    guess: &Pose2,
    cfg: &AlignConfig,
) -> Option<Alignment> {
    if a.width() == 0 || b.width() == 0 || !guess.is_finite() {
        return None;
    }
    let reach = cfg.linear_window_m + 1.0;
    let (lo_a, hi_a) = extent(a);
    let (sin, cos) = guess.theta.sin_cos();
    let to_a =
        |p: DVec2| guess.position() + DVec2::new(cos * p.x - sin * p.y, sin * p.x + cos * p.y);
    let points: Vec<DVec2> = occupied_cells(b)
        .into_iter()
        .filter(|&p| {
            let q = to_a(p);
            q.x >= lo_a.x - reach
                && q.y >= lo_a.y - reach
                && q.x <= hi_a.x + reach
                && q.y <= hi_a.y + reach
        })
        .collect();
    if points.len() < cfg.min_cells.max(1) {
        return None;
    }
    // Work about the cells' centroid, so that a rotation in the search
    // turns the overlap in place instead of swinging it around B's origin.
    let centre = points.iter().copied().sum::<DVec2>() / points.len() as f64;
    let points: Vec<DVec2> = points.iter().map(|&p| p - centre).collect();
    let to_centre = Pose2::new(centre.x, centre.y, 0.0);
    let prior = guess.compose(&to_centre);
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    let mut far = 0f64;
    for &p in &points {
        let q = prior.transform_point(p);
        lo = lo.min(q);
        hi = hi.max(q);
        far = far.max(p.length());
    }
    let margin = cfg.linear_window_m + cfg.angular_window_rad * far + 4.0 * a.resolution_m();
    let lo = (lo - margin).max(lo_a);
    let hi = (hi + margin).min(hi_a);
    if lo.x >= hi.x || lo.y >= hi.y {
        return None;
    }
    let search_cfg = CorrelativeConfig {
        linear_window_m: cfg.linear_window_m,
        angular_window_rad: cfg.angular_window_rad,
        angular_step_rad: cfg.angular_step_rad.max(1e-4),
        coarse_cells: 4,
    };
    let field = LikelihoodField::build(
        a,
        a.global_cell(lo),
        a.global_cell(hi),
        search_cfg.coarse_cells,
    );
    let coarse = search(&field, &points, &prior, &search_cfg)?;
    let (mut refined, mut score) =
        refine(&field, &points, &coarse.pose, cfg.gauss_newton_iterations);
    if !score.is_finite() || !refined.is_finite() {
        refined = coarse.pose;
        score = mean_score(&field, &points, &refined);
    }
    let matched_cells = points
        .iter()
        .filter(|&&p| field.bilinear(refined.transform_point(p)).0 >= cfg.on_wall_field)
        .count();
    Some(Alignment {
        pose: refined.compose(&to_centre.inverse()),
        score,
        matched_cells,
    })
}
