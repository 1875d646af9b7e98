//! # The smoothed grid the matcher scores scans against
//!
//! Scan matching asks "how well do these laser end points land on walls of
//! the map?". The correlative search (and map merging's alignment) read the
//! answer from a *likelihood field*: a local window of the occupancy grid
//! around the search area, where each cell holds how wall-like it is (0 for
//! free or unknown, rising to 1 for a confidently occupied cell), blurred
//! so that a point a cell away from a wall still scores a little:
//!
//! ```text
//! F(c) = Σ_d w(d) · H(c + d),   w(d) ∝ exp(−|d|² / 2σ²),  Σ w = 1
//!                                               (|dx|, |dy| ≤ 2 cells)
//! ```
//!
//! That is Olson's "rasterised cost table" (E. Olson, *Real-Time Correlative
//! Scan Matching*, ICRA 2009, §III-B) with σ of one cell, except that Olson
//! takes the maximum over `d` where this sums (a normalised Gaussian blur);
//! on a wall, a line of cells, the two differ by a constant factor. The
//! kernel is separable, so the blur is a row pass then a column pass.
//!
//! Two views of the same field serve the two matchers:
//!
//! * [`LikelihoodField::coarse`] — Olson's low-resolution table (§IV): each
//!   entry is the **maximum** of the `K × K` fine cells starting at it, so a
//!   scan's coarse score at an offset bounds from above its fine score at
//!   every offset inside that block. That is what makes branch and bound
//!   exact.
//! * [`LikelihoodField::bilinear`] — the continuous map value and its
//!   gradient, interpolated bilinearly between cell centres, which Hector
//!   SLAM's Gauss–Newton step needs (Kohlbrecher et al., SSRR 2011, §IV-A,
//!   eq. 4–6).

use super::grid::OccupancyGrid;
use glam::DVec2;

/// A window of the smoothed map, in global cell indices of the grid.
#[derive(Clone, Debug)]
pub struct LikelihoodField {
    /// Global index of the window's cell (0, 0).
    pub x0: i64,
    pub y0: i64,
    pub width: usize,
    pub height: usize,
    /// Smoothed values, row by row (y up).
    pub fine: Vec<f32>,
    /// Block maxima of `fine` over `[c, c + k)²`.
    pub coarse: Vec<f32>,
    /// Coarse block size in cells.
    pub k: usize,
    pub resolution_m: f64,
}

/// Blur radius in cells and the weights `exp(−d² / 2)` for d = 0, 1, 2.
const BLUR: [f32; 3] = [1.0, 0.606_530_66, 0.135_335_28];

impl LikelihoodField {
    /// Builds the field over global cells `lo..=hi` of `grid`, with coarse
    /// blocks of `k` cells.
    pub fn build(grid: &OccupancyGrid, lo: [i64; 2], hi: [i64; 2], k: usize) -> LikelihoodField {
        let width = (hi[0] - lo[0] + 1).max(1) as usize;
        let height = (hi[1] - lo[1] + 1).max(1) as usize;
        let max = grid.config.max.max(1) as f32;
        // Wall-likeness of stored log-odds: 0 up to unknown, linear to 1.
        let mut table = [0f32; 256];
        for (u, t) in table.iter_mut().enumerate() {
            *t = ((u as u8 as i8) as f32 / max).clamp(0.0, 1.0);
        }
        let mut raw = vec![0f32; width * height];
        let (gw, gh) = (grid.width() as i64, grid.height() as i64);
        let [ox, oy] = grid.origin_cell();
        let cells = grid.raw_units();
        for y in 0..height {
            let gy = lo[1] + y as i64 - oy;
            if gy < 0 || gy >= gh {
                continue;
            }
            // The part of this row that lies inside the grid.
            let gx_start = (lo[0] - ox).max(0);
            let gx_end = (lo[0] + width as i64 - ox).min(gw);
            if gx_start >= gx_end {
                continue;
            }
            let src = &cells[(gy * gw + gx_start) as usize..(gy * gw + gx_end) as usize];
            let dst_start = (gx_start + ox - lo[0]) as usize;
            for (d, &s) in raw[y * width + dst_start..].iter_mut().zip(src) {
                *d = table[s as u8 as usize];
            }
        }
        // Separable Gaussian blur (σ = 1 cell, radius 2, unit sum): rows,
        // then columns.
        let norm = BLUR[0] + 2.0 * (BLUR[1] + BLUR[2]);
        let wgt = BLUR.map(|w| w / norm);
        let mut rows = vec![0f32; width * height];
        for y in 0..height {
            blur_row(
                &raw[y * width..(y + 1) * width],
                &mut rows[y * width..(y + 1) * width],
                wgt,
            );
        }
        let fine = blur_columns(&rows, width, height, wgt);
        // Coarse: forward block maxima over [x, x + k) then [y, y + k).
        // The values are never NaN, so a comparison is `f32::max` (which
        // wasm calls as a function, `fmaxf`, for its NaN rule).
        let k = k.max(1);
        let larger = |a: f32, b: f32| if b > a { b } else { a };
        let mut cx = vec![0f32; width * height];
        for y in 0..height {
            for x in 0..width {
                let end = (x + k).min(width);
                cx[y * width + x] = fine[y * width + x..y * width + end]
                    .iter()
                    .fold(0f32, |a, &b| larger(a, b));
            }
        }
        let mut coarse = vec![0f32; width * height];
        for y in 0..height {
            let out = &mut coarse[y * width..(y + 1) * width];
            for yy in y..(y + k).min(height) {
                for (o, &c) in out.iter_mut().zip(&cx[yy * width..(yy + 1) * width]) {
                    *o = larger(*o, c);
                }
            }
        }
        LikelihoodField {
            x0: lo[0],
            y0: lo[1],
            width,
            height,
            fine,
            coarse,
            k,
            resolution_m: grid.resolution_m(),
        }
    }

    /// Fine value at window cell `(x, y)` (0 outside).
    #[inline]
    pub fn fine_at(&self, x: i64, y: i64) -> f32 {
        if x < 0 || y < 0 || x >= self.width as i64 || y >= self.height as i64 {
            0.0
        } else {
            self.fine[y as usize * self.width + x as usize]
        }
    }

    /// Coarse value at window cell `(x, y)` (0 outside).
    #[inline]
    pub fn coarse_at(&self, x: i64, y: i64) -> f32 {
        if x < 0 || y < 0 || x >= self.width as i64 || y >= self.height as i64 {
            0.0
        } else {
            self.coarse[y as usize * self.width + x as usize]
        }
    }

    /// Window cell holding point `p` (odometry frame).
    #[inline]
    pub fn cell_of(&self, p: DVec2) -> [i64; 2] {
        [
            (p.x / self.resolution_m).floor() as i64 - self.x0,
            (p.y / self.resolution_m).floor() as i64 - self.y0,
        ]
    }

    /// The field's value at `p` interpolated bilinearly between cell centres,
    /// and its gradient (per metre).
    pub fn bilinear(&self, p: DVec2) -> (f64, DVec2) {
        let u = p.x / self.resolution_m - 0.5 - self.x0 as f64;
        let v = p.y / self.resolution_m - 0.5 - self.y0 as f64;
        let (ix, iy) = (u.floor(), v.floor());
        let (fx, fy) = (u - ix, v - iy);
        let (ix, iy) = (ix as i64, iy as i64);
        let m00 = self.fine_at(ix, iy) as f64;
        let m10 = self.fine_at(ix + 1, iy) as f64;
        let m01 = self.fine_at(ix, iy + 1) as f64;
        let m11 = self.fine_at(ix + 1, iy + 1) as f64;
        let value = (1.0 - fy) * ((1.0 - fx) * m00 + fx * m10) + fy * ((1.0 - fx) * m01 + fx * m11);
        let dx = (1.0 - fy) * (m10 - m00) + fy * (m11 - m01);
        let dy = (1.0 - fx) * (m01 - m00) + fx * (m11 - m10);
        (value, DVec2::new(dx, dy) / self.resolution_m)
    }
}

/// One row of the blur: `out[x] = Σ_d w(|d|) · row[x + d]`, the terms
/// added centre, then ±1, then ±2, those outside the row left out. Cells
/// two or more from either end have every term, added in that same order
/// without a test (a loop the compiler vectorises); the ends test.
fn blur_row(row: &[f32], out: &mut [f32], wgt: [f32; 3]) {
    let width = row.len();
    let edge = |x: usize| {
        let mut m = row[x] * wgt[0];
        for (d, &w) in wgt.iter().enumerate().skip(1) {
            if x >= d {
                m += row[x - d] * w;
            }
            if x + d < width {
                m += row[x + d] * w;
            }
        }
        m
    };
    if width < 5 {
        for (x, o) in out.iter_mut().enumerate() {
            *o = edge(x);
        }
        return;
    }
    for x in [0, 1, width - 2, width - 1] {
        out[x] = edge(x);
    }
    for (x, o) in out.iter_mut().enumerate().take(width - 2).skip(2) {
        let mut m = row[x] * wgt[0];
        m += row[x - 1] * wgt[1];
        m += row[x + 1] * wgt[1];
        m += row[x - 2] * wgt[2];
        m += row[x + 2] * wgt[2];
        *o = m;
    }
}

/// The column pass of the blur over `rows` (`width` × `height`, row by
/// row): the same sums as [`blur_row`] down each column, in the same
/// order, computed a whole row at a time.
fn blur_columns(rows: &[f32], width: usize, height: usize, wgt: [f32; 3]) -> Vec<f32> {
    let mut fine = vec![0f32; width * height];
    let row = |y: usize| &rows[y * width..(y + 1) * width];
    for y in 0..height {
        let out = &mut fine[y * width..(y + 1) * width];
        for (o, &c) in out.iter_mut().zip(row(y)) {
            *o = c * wgt[0];
        }
        for (d, &w) in wgt.iter().enumerate().skip(1) {
            if y >= d {
                for (o, &c) in out.iter_mut().zip(row(y - d)) {
                    *o += c * w;
                }
            }
            if y + d < height {
                for (o, &c) in out.iter_mut().zip(row(y + d)) {
                    *o += c * w;
                }
            }
        }
    }
    fine
}
