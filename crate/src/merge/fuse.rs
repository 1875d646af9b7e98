//! # Fusing the maps into one grid
//!
//! Once every robot's map frame has a pose in the merged frame (robot 0's),
//! the grids are combined cell by cell. Log-odds make it one line of
//! probability: two independent observations of a cell combine by
//! *adding* their log-odds (Thrun, Burgard and Fox, *Probabilistic
//! Robotics*, §9.2, eq. 9.7, the same rule each robot's mapper applies per
//! beam), clamped to the grid's range like any other update. A cell one map
//! calls free and the other a wall ends up in between, as it should.
//!
//! Resampling is done *backwards*: for each cell of the merged grid, its
//! centre is carried into each map's frame (the inverse of that map's pose)
//! and the map's cell there is read. Pushing cells forwards instead would
//! leave holes wherever a rotated cell lattice misses a target cell;
//! pulling visits every merged cell exactly once. Nearest-cell reading keeps
//! every value a whole number of log-odds units, so the result is the same
//! on every machine.

use crate::geom::Pose2;
use crate::slam::grid::{GridConfig, OccupancyGrid};
use glam::DVec2;

/// Corners of the part of a grid that holds anything (known cells), in its
/// own frame; `None` if every cell is unknown. A grid grows in whole blocks,
/// so its allocated extent can be much larger than what was mapped, and the
/// merged map (and its PGM) should not carry that margin.
fn known_corners(grid: &OccupancyGrid) -> Option<[DVec2; 4]> {
    let (w, units) = (grid.width(), grid.raw_units());
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    for (iy, row) in units.chunks(w.max(1)).enumerate() {
        let Some(first) = row.iter().position(|&u| u != 0) else {
            continue;
        };
        let last = row.iter().rposition(|&u| u != 0).unwrap_or(first);
        (x0, x1) = (x0.min(first), x1.max(last + 1));
        (y0, y1) = (y0.min(iy), y1.max(iy + 1));
    }
    if x0 == usize::MAX {
        return None;
    }
    let res = grid.resolution_m();
    let lo = grid.origin_m() + DVec2::new(x0 as f64, y0 as f64) * res;
    let hi = grid.origin_m() + DVec2::new(x1 as f64, y1 as f64) * res;
    Some([lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)])
}

/// Writes log-odds `units` into the (empty) cell holding `p` of `grid`.
///
/// [`OccupancyGrid`] exposes no cell setter, only its beam model, so this
/// uses the model's own path: a zero-length beam that "hits" adds
/// `config.hit` to its end cell (clamped, like every update), with the
/// config's `hit` set to the value wanted for the duration of the call.
fn write_cell(grid: &mut OccupancyGrid, p: DVec2, units: i8) {
    if units == 0 {
        return;
    }
    let hit = grid.config.hit;
    grid.config.hit = units;
    grid.integrate_beam(p, p, true);
    grid.config.hit = hit;
}

/// Fills row `iy` of the merged grid: the clamped sum of what every map
/// holds under each cell's centre. (A function per row: a wasm engine
/// optimises a function after a few calls, never a loop already running.)
fn fuse_row(
    merged: &mut OccupancyGrid,
    iy: usize,
    maps: &[&OccupancyGrid],
    to_maps: &[impl Fn(DVec2) -> DVec2],
) {
    let (min, max) = (merged.config.min as i32, merged.config.max as i32);
    for ix in 0..merged.width() {
        let centre = merged.cell_centre(ix, iy);
        let mut sum = 0i32;
        for (g, to_map) in maps.iter().zip(to_maps) {
            if let Some((x, y)) = g.local(g.global_cell(to_map(centre))) {
                sum += g.units(x, y) as i32;
            }
        }
        write_cell(merged, centre, sum.clamp(min, max) as i8);
    }
}

/// The merged grid: each map's frame at its pose in the merged frame,
/// log-odds added and clamped to `config`'s range (see the module doc).
/// The merged grid covers what the maps know (not their allocated margins).
/// Maps that are empty or have a non-finite pose are skipped; with nothing
/// to fuse the result is an empty grid.
pub fn fuse(maps: &[(&OccupancyGrid, Pose2)], config: GridConfig) -> OccupancyGrid {
    let mut steps = FuseSteps::new(maps, config);
    while !steps.step(maps, usize::MAX) {}
    steps.into_grid()
}

/// [`fuse`] a band of rows at a time, so that a caller with a page to draw
/// need not wait for the whole grid: the merged grid is sized at the
/// start, then each step pulls the next rows from the maps. The result is
/// the same however the rows are cut.
pub struct FuseSteps {
    merged: OccupancyGrid,
    /// Positions in the maps of those that are fused (finite pose, known
    /// cells).
    usable: Vec<usize>,
    next_row: usize,
}

impl FuseSteps {
    /// The merged grid for `maps` (each with its pose in the merged
    /// frame), sized to cover what they know; no row fused yet.
    pub fn new(maps: &[(&OccupancyGrid, Pose2)], config: GridConfig) -> FuseSteps {
        let mut merged = OccupancyGrid::new(config.clone());
        let usable: Vec<(usize, [DVec2; 4])> = maps
            .iter()
            .enumerate()
            .filter(|(_, (_, pose))| pose.is_finite())
            .filter_map(|(i, (g, _))| known_corners(g).map(|c| (i, c)))
            .collect();
        let nothing = FuseSteps {
            merged: OccupancyGrid::new(config.clone()),
            usable: Vec::new(),
            next_row: 0,
        };
        if usable.is_empty() || config.resolution_m.is_nan() || config.resolution_m <= 0.0 {
            return nothing;
        }
        let mut lo = DVec2::splat(f64::INFINITY);
        let mut hi = DVec2::splat(f64::NEG_INFINITY);
        for (i, corners) in &usable {
            for &c in corners {
                let q = maps[*i].1.transform_point(c);
                lo = lo.min(q);
                hi = hi.max(q);
            }
        }
        if !merged.ensure_contains(lo, hi) {
            // Too large for the cell budget: fuse what fits around the first map.
            let (i, corners) = usable[0];
            let [a, b, c, d] = corners.map(|c| maps[i].1.transform_point(c));
            let (l, h) = (a.min(b).min(c).min(d), a.max(b).max(c).max(d));
            if !merged.ensure_contains(l, h) {
                return FuseSteps { merged, ..nothing };
            }
        }
        FuseSteps {
            merged,
            usable: usable.into_iter().map(|(i, _)| i).collect(),
            next_row: 0,
        }
    }

    /// Rows (done, in all).
    pub fn progress(&self) -> (usize, usize) {
        let rows = if self.usable.is_empty() {
            0
        } else {
            self.merged.height()
        };
        (self.next_row.min(rows), rows)
    }

    /// Fuses up to `rows` more rows (the same `maps` as at the start);
    /// whether every row is fused.
    pub fn step(&mut self, maps: &[(&OccupancyGrid, Pose2)], rows: usize) -> bool {
        let (done, all) = self.progress();
        if done >= all {
            return true;
        }
        // Each map's inverse pose as a function, its sine and cosine taken once.
        let to_maps: Vec<_> = self
            .usable
            .iter()
            .map(|&i| {
                let inv = maps[i].1.inverse();
                let (s, c) = inv.theta.sin_cos();
                move |q: DVec2| inv.position() + DVec2::new(c * q.x - s * q.y, s * q.x + c * q.y)
            })
            .collect();
        let grids: Vec<&OccupancyGrid> = self.usable.iter().map(|&i| maps[i].0).collect();
        let end = done.saturating_add(rows).min(all);
        for iy in done..end {
            fuse_row(&mut self.merged, iy, &grids, &to_maps);
        }
        self.next_row = end;
        end >= all
    }

    /// The merged grid (whole once [`FuseSteps::step`] has said so).
    pub fn into_grid(self) -> OccupancyGrid {
        self.merged
    }
}
