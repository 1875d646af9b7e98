//! # The world: walls, and a spatial index for casting rays among them
//!
//! The world is a set of wall segments (the scenario's `walls`). Every sensor
//! reading is a ray cast into it, hundreds per robot per step, so walls are
//! binned into a uniform grid of square cells and a ray visits only the cells
//! it crosses, in order, with the traversal of Amanatides and Woo ("A fast
//! voxel traversal algorithm for ray tracing", Eurographics 1987).
//!
//! A wall is listed in every cell it passes through, so one wall can be tested
//! more than once; that is harmless because we keep the nearest hit, and we
//! stop as soon as the nearest hit so far lies before the exit of the current
//! cell (nothing in a later cell can be nearer). Scenes with few walls skip
//! the grid: testing 64 segments is cheaper than walking cells.
//!
//! The cells are sized to the walls (about two walls' length), which suits
//! the camera's long rays; the laser and sonar cast through a second grid
//! of 1 m cells ([`World::cast_range`]), since their rays are 2–4 m and a
//! maze's long wall runs made the first grid's cells 10 m and more. The
//! nearest hit does not depend on the cells, so the ranges are the same
//! bit for bit.

use crate::geom::{ConvexPolygon, Segment};
use glam::DVec2;

/// Below this many walls, rays test every wall directly.
const BRUTE_FORCE_WALLS: usize = 64;
/// The grid never has more cells than this.
const MAX_CELLS: f64 = 1_000_000.0;
/// Cell size of the range sensors' own grid (m), see [`World::cast_range`].
const SENSOR_CELL_M: f64 = 1.0;

/// The nearest thing a ray met.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// Distance from the ray origin (m).
    pub range_m: f64,
    /// Index of the wall in the scenario, or `None` for an obstacle that is
    /// not a wall (another robot).
    pub wall: Option<usize>,
}

#[derive(Clone, Debug)]
struct WallGrid {
    origin: DVec2,
    cell_m: f64,
    nx: usize,
    ny: usize,
    /// Compressed rows: the walls of cell `c` are
    /// `indices[offsets[c]..offsets[c + 1]]`.
    offsets: Vec<u32>,
    indices: Vec<u32>,
}

impl WallGrid {
    /// A grid over `walls` with cells of `cell_m` (or, if given `None`,
    /// about two walls' worth of length), never more than [`MAX_CELLS`].
    fn build(walls: &[Segment], cell_m: Option<f64>) -> WallGrid {
        let mut lo = DVec2::splat(f64::INFINITY);
        let mut hi = DVec2::splat(f64::NEG_INFINITY);
        let mut total_len = 0.0;
        for w in walls {
            let (a, b) = w.bounds();
            lo = lo.min(a);
            hi = hi.max(b);
            total_len += w.length();
        }
        lo -= DVec2::splat(0.01);
        hi += DVec2::splat(0.01);
        let size = hi - lo;
        // About two walls' worth of length per cell, at least 0.5 m, and a
        // bounded number of cells.
        let mut cell_m = cell_m.unwrap_or((2.0 * total_len / walls.len() as f64).max(0.5));
        cell_m = cell_m.max((size.x * size.y / MAX_CELLS).sqrt());
        let nx = ((size.x / cell_m).ceil() as usize).max(1);
        let ny = ((size.y / cell_m).ceil() as usize).max(1);
        let mut buckets: Vec<Vec<u32>> = vec![Vec::new(); nx * ny];
        let half_diag = cell_m * std::f64::consts::FRAC_1_SQRT_2;
        for (i, w) in walls.iter().enumerate() {
            let (a, b) = w.bounds();
            let cx0 = (((a.x - lo.x) / cell_m).floor() as usize).min(nx - 1);
            let cx1 = (((b.x - lo.x) / cell_m).floor() as usize).min(nx - 1);
            let cy0 = (((a.y - lo.y) / cell_m).floor() as usize).min(ny - 1);
            let cy1 = (((b.y - lo.y) / cell_m).floor() as usize).min(ny - 1);
            for cy in cy0..=cy1 {
                for cx in cx0..=cx1 {
                    let centre =
                        lo + DVec2::new((cx as f64 + 0.5) * cell_m, (cy as f64 + 0.5) * cell_m);
                    // Conservative: a wall within the cell's circumcircle.
                    if w.distance_to_point(centre) <= half_diag + 1e-9 {
                        buckets[cy * nx + cx].push(i as u32);
                    }
                }
            }
        }
        let mut offsets = Vec::with_capacity(nx * ny + 1);
        let mut indices = Vec::new();
        offsets.push(0);
        for b in buckets {
            indices.extend_from_slice(&b);
            offsets.push(indices.len() as u32);
        }
        WallGrid {
            origin: lo,
            cell_m,
            nx,
            ny,
            offsets,
            indices,
        }
    }

    fn cell_walls(&self, cx: usize, cy: usize) -> &[u32] {
        let c = cy * self.nx + cx;
        &self.indices[self.offsets[c] as usize..self.offsets[c + 1] as usize]
    }
}

/// The static environment.
#[derive(Clone, Debug)]
pub struct World {
    walls: Vec<Segment>,
    grid: Option<WallGrid>,
    /// A finer grid for the range sensors' short rays
    /// ([`World::cast_range`]); `None` where `grid`'s cells are no larger.
    sensor_grid: Option<WallGrid>,
}

impl World {
    pub fn new(walls: Vec<Segment>) -> World {
        let grid = (walls.len() > BRUTE_FORCE_WALLS).then(|| WallGrid::build(&walls, None));
        let sensor_grid = grid
            .as_ref()
            .filter(|g| g.cell_m > SENSOR_CELL_M)
            .map(|_| WallGrid::build(&walls, Some(SENSOR_CELL_M)));
        World {
            walls,
            grid,
            sensor_grid,
        }
    }

    pub fn walls(&self) -> &[Segment] {
        &self.walls
    }

    /// The nearest wall along the unit ray `origin + t·dir`, `0 ≤ t ≤ max_range_m`.
    pub fn cast(&self, origin: DVec2, dir: DVec2, max_range_m: f64) -> Option<RayHit> {
        let mut best = f64::INFINITY;
        let mut best_wall = usize::MAX;
        match &self.grid {
            None => {
                for (i, w) in self.walls.iter().enumerate() {
                    if let Some(t) = w.ray_hit(origin, dir) {
                        if t < best {
                            best = t;
                            best_wall = i;
                        }
                    }
                }
            }
            Some(g) => self.cast_grid(g, origin, dir, max_range_m, &mut best, &mut best_wall),
        }
        (best <= max_range_m).then_some(RayHit {
            range_m: best,
            wall: Some(best_wall),
        })
    }

    /// The distance [`World::cast`] finds along the unit ray (bit for bit:
    /// the nearest of the walls the ray meets, each hit computed by the
    /// same [`Segment::ray_hit`]), through a grid of 1 m cells sized for
    /// the sensors' 2–4 m rays. The world's own grid sizes its cells to
    /// the walls (about two walls' length, 10 m and more where a maze's
    /// walls are long runs), which suits the camera's 12 m rays; a 4 m
    /// laser beam in such a cell tested every wall in it (`perf`: 11 % of
    /// a 16-robot run). Only the wall of an exact tie (a ray through the
    /// point where two walls meet) may differ from `cast`'s; the sensors
    /// read the range alone, the camera (which textures by wall) keeps
    /// `cast`.
    pub fn cast_range(&self, origin: DVec2, dir: DVec2, max_range_m: f64) -> Option<RayHit> {
        let Some(g) = &self.sensor_grid else {
            return self.cast(origin, dir, max_range_m);
        };
        let mut best = f64::INFINITY;
        let mut best_wall = usize::MAX;
        self.cast_grid(g, origin, dir, max_range_m, &mut best, &mut best_wall);
        (best <= max_range_m).then_some(RayHit {
            range_m: best,
            wall: Some(best_wall),
        })
    }

    /// For many rays from `p` out to `range_m` (a laser scan): the walls
    /// that come within `range_m` of `p`, in index order, or `None` when
    /// the world casts through its grid (whose cells already skip far
    /// walls). A ray from `p` can only hit a wall within its range at a
    /// distance no less than the wall's distance from `p`, so the others
    /// can be left out; a micrometre of slack keeps a wall at exactly the
    /// range in.
    pub fn walls_within(&self, p: DVec2, range_m: f64) -> Option<Vec<u32>> {
        if self.grid.is_some() {
            return None;
        }
        let keep = range_m + 1e-6;
        Some(
            (0..self.walls.len() as u32)
                .filter(|&i| {
                    let w = &self.walls[i as usize];
                    (w.closest_point(p) - p).length_squared() <= keep * keep
                })
                .collect(),
        )
    }

    /// [`World::cast`] among `walls` only (from [`World::walls_within`] for
    /// this ray's origin and a range no shorter than `max_range_m`): the
    /// same answer, since the nearest wall is kept and ties still go to
    /// the lower index.
    pub fn cast_among(
        &self,
        walls: &[u32],
        origin: DVec2,
        dir: DVec2,
        max_range_m: f64,
    ) -> Option<RayHit> {
        let mut best = f64::INFINITY;
        let mut best_wall = usize::MAX;
        for &i in walls {
            if let Some(t) = self.walls[i as usize].ray_hit(origin, dir) {
                if t < best {
                    best = t;
                    best_wall = i as usize;
                }
            }
        }
        (best <= max_range_m).then_some(RayHit {
            range_m: best,
            wall: Some(best_wall),
        })
    }

    fn cast_grid(
        &self,
        g: &WallGrid,
        origin: DVec2,
        dir: DVec2,
        max_range_m: f64,
        best: &mut f64,
        best_wall: &mut usize,
    ) {
        // Clip the ray to the grid's box (slab method).
        let size = DVec2::new(g.nx as f64, g.ny as f64) * g.cell_m;
        let (mut t0, mut t1) = (0.0f64, max_range_m);
        for k in 0..2 {
            let (o, d, lo, hi) = if k == 0 {
                (origin.x, dir.x, g.origin.x, g.origin.x + size.x)
            } else {
                (origin.y, dir.y, g.origin.y, g.origin.y + size.y)
            };
            if d.abs() < 1e-15 {
                if o < lo || o > hi {
                    return;
                }
            } else {
                let (mut ta, mut tb) = ((lo - o) / d, (hi - o) / d);
                if ta > tb {
                    std::mem::swap(&mut ta, &mut tb);
                }
                t0 = t0.max(ta);
                t1 = t1.min(tb);
            }
        }
        if t0 > t1 {
            return;
        }
        let p = origin + dir * t0 - g.origin;
        let mut cx = ((p.x / g.cell_m).floor() as isize).clamp(0, g.nx as isize - 1);
        let mut cy = ((p.y / g.cell_m).floor() as isize).clamp(0, g.ny as isize - 1);
        let step_x: isize = if dir.x >= 0.0 { 1 } else { -1 };
        let step_y: isize = if dir.y >= 0.0 { 1 } else { -1 };
        let next_boundary =
            |c: isize, step: isize| (c + if step > 0 { 1 } else { 0 }) as f64 * g.cell_m;
        let rel = origin - g.origin;
        let mut t_max_x = if dir.x.abs() < 1e-15 {
            f64::INFINITY
        } else {
            (next_boundary(cx, step_x) - rel.x) / dir.x
        };
        let mut t_max_y = if dir.y.abs() < 1e-15 {
            f64::INFINITY
        } else {
            (next_boundary(cy, step_y) - rel.y) / dir.y
        };
        let t_delta_x = if dir.x.abs() < 1e-15 {
            f64::INFINITY
        } else {
            g.cell_m / dir.x.abs()
        };
        let t_delta_y = if dir.y.abs() < 1e-15 {
            f64::INFINITY
        } else {
            g.cell_m / dir.y.abs()
        };
        loop {
            for &wi in g.cell_walls(cx as usize, cy as usize) {
                let wi = wi as usize;
                if let Some(t) = self.walls[wi].ray_hit(origin, dir) {
                    if t < *best {
                        *best = t;
                        *best_wall = wi;
                    }
                }
            }
            let t_exit = t_max_x.min(t_max_y);
            if *best <= t_exit || t_exit > t1 {
                return;
            }
            if t_max_x < t_max_y {
                cx += step_x;
                t_max_x += t_delta_x;
                if cx < 0 || cx >= g.nx as isize {
                    return;
                }
            } else {
                cy += step_y;
                t_max_y += t_delta_y;
                if cy < 0 || cy >= g.ny as isize {
                    return;
                }
            }
        }
    }

    /// Indices of walls whose bounding boxes overlap the box `lo..hi`.
    pub fn walls_in_box(&self, lo: DVec2, hi: DVec2, out: &mut Vec<usize>) {
        out.clear();
        let overlaps = |w: &Segment| {
            let (a, b) = w.bounds();
            !(b.x < lo.x || a.x > hi.x || b.y < lo.y || a.y > hi.y)
        };
        match &self.grid {
            None => out.extend((0..self.walls.len()).filter(|&i| overlaps(&self.walls[i]))),
            Some(g) => {
                let cell = |v: f64, o: f64, n: usize| {
                    ((((v - o) / g.cell_m).floor()).max(0.0) as usize).min(n - 1)
                };
                let (cx0, cx1) = (cell(lo.x, g.origin.x, g.nx), cell(hi.x, g.origin.x, g.nx));
                let (cy0, cy1) = (cell(lo.y, g.origin.y, g.ny), cell(hi.y, g.origin.y, g.ny));
                for cy in cy0..=cy1 {
                    for cx in cx0..=cx1 {
                        for &wi in g.cell_walls(cx, cy) {
                            let wi = wi as usize;
                            if overlaps(&self.walls[wi]) && !out.contains(&wi) {
                                out.push(wi);
                            }
                        }
                    }
                }
            }
        }
    }

    /// Whether a body polygon touches or overlaps any wall.
    pub fn body_hits_wall(&self, body: &ConvexPolygon) -> bool {
        let (lo, hi) = body.bounds();
        let mut near = Vec::new();
        self.walls_in_box(lo, hi, &mut near);
        near.iter()
            .any(|&i| body.distance_to_segment(&self.walls[i]) <= 0.0)
    }

    /// Clearance from a body polygon to the nearest wall within `radius` of
    /// it (`radius` if none is nearer).
    pub fn clearance(&self, body: &ConvexPolygon, radius: f64) -> f64 {
        let (lo, hi) = body.bounds();
        let mut near = Vec::new();
        self.walls_in_box(lo - radius, hi + radius, &mut near);
        near.iter()
            .map(|&i| body.distance_to_segment(&self.walls[i]))
            .fold(radius, f64::min)
    }
}
