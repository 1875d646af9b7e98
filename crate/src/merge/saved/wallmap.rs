//! # A saved map made ready to merge: its walls and their distance field
//!
//! The saved-maps merge ([`super`]) compares real maps that were
//! made on different days, by different robots, perhaps with different
//! sensors. Their walls are 1 to 5 cells thick, a little bent against each
//! other, and cluttered with furniture that one run saw and the other did
//! not. Two things about a map are therefore kept here:
//!
//! * **its wall surface**: the occupied cells that touch a free cell (the
//!   face a robot saw), as points in the map's *image frame* (origin at the
//!   lower-left corner of the image, x along its rows, y up its columns).
//!   A 5-cell-thick wall drawn by one map and a 1-cell one drawn by the
//!   other share their faces, not their interiors;
//! * **the distance from every cell to the nearest occupied cell** (any
//!   occupied cell, interior included), the exact Euclidean distance
//!   transform of P. Felzenszwalb and D. Huttenlocher, *Distance transforms
//!   of sampled functions* (Theory of Computing 8, 2012): one pass down
//!   each column gives the vertical distance to the nearest wall, then one
//!   pass along each row takes the lower envelope of the parabolas
//!   `(x − q)² + f(q)`. Only short distances matter (a wall further than a
//!   metre is simply "not near"), so the field is stored in one byte a
//!   cell, in sixteenths of a cell, saturating at [`FAR`].
//!
//! Scoring a wall point of the other map against this field instead of
//! against the occupied cells themselves is what makes the evidence
//! tolerant: a wall 2 cells off still scores, less than one dead on (the
//! *likelihood field* of Thrun, Burgard and Fox, *Probabilistic Robotics*
//! §6.4, used for scan matching; here for map matching).

use crate::formats::rosmap::RosMap;
use crate::slam::grid::CellState;
use glam::DVec2;

/// Stored distances are in sixteenths of a cell; this value means "at
/// least 15.9 cells away".
pub const FAR: u8 = 255;

/// Cell states as bytes.
const UNKNOWN: u8 = 0;
const FREE: u8 = 1;
const WALL: u8 = 2;

/// A map's walls, states and distance field, in its image frame.
#[derive(Clone, Debug)]
pub struct WallMap {
    pub width: usize,
    pub height: usize,
    /// Metres per cell.
    pub resolution: f64,
    state: Vec<u8>,
    near: Vec<u8>,
    /// Centres of the wall-surface cells (image frame, metres).
    pub walls: Vec<DVec2>,
    /// Occupied and free cells.
    pub occupied: usize,
    pub free: usize,
}

impl WallMap {
    pub fn new(map: &RosMap) -> WallMap {
        let (w, h) = (map.width, map.height);
        let state: Vec<u8> = map
            .data
            .iter()
            .map(|&v| match crate::formats::rosmap::state_of_value(v) {
                CellState::Occupied => WALL,
                CellState::Free => FREE,
                CellState::Unknown => UNKNOWN,
            })
            .collect();
        let occupied = state.iter().filter(|&&s| s == WALL).count();
        let free = state.iter().filter(|&&s| s == FREE).count();
        let mut walls = Vec::new();
        for y in 0..h {
            for x in 0..w {
                if state[y * w + x] != WALL {
                    continue;
                }
                let touches_free = (y.saturating_sub(1)..(y + 2).min(h)).any(|yy| {
                    (x.saturating_sub(1)..(x + 2).min(w)).any(|xx| state[yy * w + xx] == FREE)
                });
                if touches_free {
                    walls.push(map.cell_centre_image(x, y));
                }
            }
        }
        // A map drawn without free space (walls on unknown only): every
        // occupied cell is surface.
        if walls.len() * 10 < occupied {
            walls = (0..w * h)
                .filter(|&k| state[k] == WALL)
                .map(|k| map.cell_centre_image(k % w, k / w))
                .collect();
        }
        let near = distance_field(&state, w, h);
        WallMap {
            width: w,
            height: h,
            resolution: map.resolution,
            state,
            near,
            walls,
            occupied,
            free,
        }
    }

    /// The cell under image-frame point `p`.
    #[inline]
    fn index(&self, p: DVec2) -> Option<usize> {
        let x = (p.x / self.resolution).floor();
        let y = (p.y / self.resolution).floor();
        (x >= 0.0 && y >= 0.0 && x < self.width as f64 && y < self.height as f64)
            .then(|| y as usize * self.width + x as usize)
    }

    /// Distance (m) from `p` to the nearest occupied cell's centre, or
    /// `None` when that is further than 15.9 cells or `p` is off the map.
    #[inline]
    pub fn wall_distance(&self, p: DVec2) -> Option<f64> {
        let k = self.index(p)?;
        let d = self.near[k];
        (d != FAR).then(|| d as f64 / 16.0 * self.resolution)
    }

    /// The largest distance [`Self::wall_distance`] reports, metres.
    pub fn reach_m(&self) -> f64 {
        (FAR as f64 - 1.0) / 16.0 * self.resolution
    }

    /// State of the cell under `p` (unknown off the map).
    #[inline]
    pub fn state_at(&self, p: DVec2) -> CellState {
        match self.index(p).map(|k| self.state[k]) {
            Some(WALL) => CellState::Occupied,
            Some(FREE) => CellState::Free,
            _ => CellState::Unknown,
        }
    }

    /// Size of the image in metres.
    pub fn extent_m(&self) -> DVec2 {
        DVec2::new(self.width as f64, self.height as f64) * self.resolution
    }
}

/// Felzenszwalb–Huttenlocher's 1-D transform: `d[q] = min_p (q − p)² + f[p]`
/// (lower envelope of parabolas). `v`, `z` are scratch of length n, n + 1.
fn envelope(f: &[f64], d: &mut [f64], v: &mut [usize], z: &mut [f64]) {
    let n = f.len();
    let mut k = 0usize;
    v[0] = 0;
    z[0] = f64::NEG_INFINITY;
    z[1] = f64::INFINITY;
    for q in 1..n {
        let fq = f[q] + (q * q) as f64;
        // z[0] is −∞, so the loop always stops at k ≥ 0.
        let mut s;
        loop {
            let p = v[k];
            s = (fq - (f[p] + (p * p) as f64)) / (2.0 * (q as f64 - p as f64));
            if s <= z[k] {
                k -= 1;
            } else {
                break;
            }
        }
        k += 1;
        v[k] = q;
        z[k] = s;
        z[k + 1] = f64::INFINITY;
    }
    k = 0;
    for (q, dq) in d.iter_mut().enumerate() {
        while z[k + 1] < q as f64 {
            k += 1;
        }
        let p = v[k];
        let dx = q as f64 - p as f64;
        *dq = dx * dx + f[p];
    }
}

/// The distance field of the occupied cells (see the module doc): one
/// byte a cell, sixteenths of a cell, [`FAR`] beyond 15.9 cells.
fn distance_field(state: &[u8], w: usize, h: usize) -> Vec<u8> {
    // Vertical distance to the nearest wall in each column, capped.
    const CAP: u16 = 255;
    let mut column = vec![CAP as u8; w * h];
    for x in 0..w {
        let mut run = CAP;
        for y in 0..h {
            run = if state[y * w + x] == WALL {
                0
            } else {
                (run + 1).min(CAP)
            };
            column[y * w + x] = run as u8;
        }
        run = CAP;
        for y in (0..h).rev() {
            run = if state[y * w + x] == WALL {
                0
            } else {
                (run + 1).min(CAP)
            };
            let c = &mut column[y * w + x];
            *c = (*c).min(run as u8);
        }
    }
    let mut near = vec![FAR; w * h];
    let (mut f, mut d) = (vec![0f64; w], vec![0f64; w]);
    let (mut v, mut z) = (vec![0usize; w], vec![0f64; w + 1]);
    for y in 0..h {
        let row = &column[y * w..][..w];
        if row.iter().all(|&c| c as u16 >= CAP) {
            continue;
        }
        for (fx, &c) in f.iter_mut().zip(row) {
            *fx = (c as f64) * (c as f64);
        }
        envelope(&f, &mut d, &mut v, &mut z);
        for (out, &dd) in near[y * w..][..w].iter_mut().zip(&d) {
            let cells = dd.sqrt();
            *out = if cells * 16.0 >= (FAR - 1) as f64 {
                FAR
            } else {
                (cells * 16.0).round() as u8
            };
        }
    }
    near
}
