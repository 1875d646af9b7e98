//! # Orientation assignment (paper §4.1)
//!
//! To be invariant to image rotation, each keypoint gets a reproducible
//! orientation, and its descriptor is later built in a frame turned by it.
//! Bay et al. compute Haar wavelet responses of side 4s (s the keypoint's
//! scale) in x and y at points sampled every s inside a circle of radius
//! 6s, weight them with a Gaussian of σ = 2s centred on the keypoint, and
//! plot each as a point (dx, dy) in a plane. A window covering an angle of
//! π/3 slides round the origin; the responses inside it are summed into a
//! vector, and the longest such vector gives the orientation (Fig. 6 of the
//! thesis, Fig. 2 of the paper).
//!
//! Implementation notes:
//! - In units of s the sample grid and the Gaussian weights do not depend on
//!   the keypoint, so they are one precomputed table of the 109 grid points
//!   (i, j) with i² + j² < 36.
//! - The sliding window is evaluated on 72 bins of 5°: each response is
//!   added to the bin of its angle, and a window is 12 consecutive bins, so
//!   sliding costs a running sum instead of a pass over all responses per
//!   window position. The winning window's summed vector gives the angle
//!   exactly (`atan2`); only the window boundaries are quantised to 5°.
//! - All the wavelets' corners lie on one lattice: with S = s rounded to
//!   whole pixels (at least 1), corner (k, l) is the integral-image corner
//!   (X + k·S, Y + l·S), (X, Y) the corner nearest the keypoint, for k, l in
//!   -8..=8; a wavelet of side 4S at grid point (i, j) has its corners at
//!   lattice points i - 2, i, i + 2 and j - 2, j, j + 2. (S is whole so that
//!   both halves of every wavelet are equal: unequal halves would respond to
//!   flat regions. This is Bay's own rounding.) So we read the integral image
//!   once at the 17 × 17 lattice points, and the 109 wavelets
//!   become contiguous arithmetic on that small table
//!   ([`simd::lattice_haar`]) instead of 872 scattered look-ups. Lattice
//!   points outside the image are clamped to its border, which is the same
//!   as counting pixels outside as zero.
//! - The responses are weighted and binned by [`simd::orientation_bins`]
//!   (a polynomial atan2); the sample grid is 13 × 16 with zero weights
//!   outside the circle and in the padding, so every row is whole vectors.

use super::integral::IntegralImage;
use super::simd;
use super::Keypoint;

/// Number of angle bins the response plane is split into (5° each).
pub const BINS: usize = 72;
/// Bins per sliding window: π/3.
pub const WINDOW_BINS: usize = BINS / 6;
/// Radius of the sampling circle, in units of s.
pub const RADIUS: i32 = 6;
/// σ of the Gaussian weight, in units of s.
pub const SIGMA: f32 = 2.0;

/// Side of the sample grid: offsets -6..=6 (in units of s).
pub const GRID_SIDE: usize = 13;
/// Elements per grid row (padded to whole vectors).
pub const GRID_STRIDE: usize = 16;
/// Samples in the padded grid.
pub const GRID_LEN: usize = GRID_SIDE * GRID_STRIDE;
/// Side of the lattice of wavelet corners: offsets -8..=8.
pub const LATTICE_SIDE: usize = 17;
/// Elements per lattice row (padded).
pub const LATTICE_STRIDE: usize = 20;
/// Elements of the lattice table.
pub const LATTICE_LEN: usize = LATTICE_SIDE * LATTICE_STRIDE;

/// Gaussian weights of the padded 13 × 16 sample grid: σ = 2s inside the
/// circle of radius 6s, zero outside it and in the padding.
pub fn grid_weights() -> [f32; GRID_LEN] {
    let mut w = [0f32; GRID_LEN];
    for j in 0..GRID_SIDE {
        for i in 0..GRID_SIDE {
            let (di, dj) = (i as i32 - RADIUS, j as i32 - RADIUS);
            if di * di + dj * dj < RADIUS * RADIUS {
                w[j * GRID_STRIDE + i] =
                    (-((di * di + dj * dj) as f32) / (2.0 * SIGMA * SIGMA)).exp();
            }
        }
    }
    w
}

/// Sets `orientation` of every keypoint (see the module doc).
pub fn assign_orientations(ii: &IntegralImage, keypoints: &mut [Keypoint]) {
    let weights = grid_weights();
    let mut scratch = Box::<OrientationScratch>::default();
    for kp in keypoints.iter_mut() {
        let OrientationScratch { dx, dy, .. } = &mut *scratch;
        haar_responses(ii, kp, dx, dy);
        kp.orientation = scratch.dominant_orientation(&weights);
    }
}

/// Reusable buffers for [`assign_orientations`] (no zeroing per keypoint).
pub struct OrientationScratch {
    dx: [f32; GRID_LEN],
    dy: [f32; GRID_LEN],
    gx: [f32; GRID_LEN],
    gy: [f32; GRID_LEN],
    bin: [u32; GRID_LEN],
}

impl Default for OrientationScratch {
    fn default() -> Self {
        OrientationScratch {
            dx: [0.0; GRID_LEN],
            dy: [0.0; GRID_LEN],
            gx: [0.0; GRID_LEN],
            gy: [0.0; GRID_LEN],
            bin: [0; GRID_LEN],
        }
    }
}

impl OrientationScratch {
    /// [`dominant_orientation`] of the responses in `self.dx`, `self.dy`.
    fn dominant_orientation(&mut self, weights: &[f32; GRID_LEN]) -> f32 {
        simd::orientation_bins(
            weights,
            &self.dx,
            &self.dy,
            BINS,
            &mut self.gx,
            &mut self.gy,
            &mut self.bin,
        );
        window_maximum(weights, &self.gx, &self.gy, &self.bin)
    }
}

/// The unweighted Haar responses (side 4s) on the padded sample grid of `kp`
/// (sample (i, j) at offset ((i - 6) s, (j - 6) s), index `j * 16 + i`).
pub fn haar_responses(
    ii: &IntegralImage,
    kp: &Keypoint,
    dx: &mut [f32; GRID_LEN],
    dy: &mut [f32; GRID_LEN],
) {
    // Whole-pixel lattice spacing, so that both halves of every wavelet
    // have the same size (unequal halves would respond to flat regions).
    let s = (kp.scale.round_ties_even() as i64).max(1);
    let (w, h) = (ii.width() as i64, ii.height() as i64);
    let corner = |p: f32, k: usize, max: i64| {
        ((p + 0.5).round_ties_even() as i64 + (k as i64 - 8) * s).clamp(0, max) as usize
    };
    let mut cols = [0usize; LATTICE_SIDE];
    let mut rows = [0usize; LATTICE_SIDE];
    for k in 0..LATTICE_SIDE {
        cols[k] = corner(kp.x, k, w);
        rows[k] = corner(kp.y, k, h) * ii.stride();
    }
    let data = ii.data();
    let mut table = [0u32; LATTICE_LEN];
    for (l, &row) in rows.iter().enumerate() {
        let t = &mut table[l * LATTICE_STRIDE..(l + 1) * LATTICE_STRIDE];
        for (k, &col) in cols.iter().enumerate() {
            t[k] = data[row + col];
        }
        let last = t[LATTICE_SIDE - 1];
        t[LATTICE_SIDE..].fill(last);
    }
    simd::lattice_haar(&table, dx, dy);
}

/// The angle of the longest summed response vector over all π/3 windows,
/// in (-π, π]; 0 when every response is zero.
pub fn dominant_orientation(weights: &[f32], dx: &[f32], dy: &[f32]) -> f32 {
    const MAX: usize = GRID_LEN;
    let n = weights.len().min(dx.len()).min(dy.len()).min(MAX);
    let (mut gx, mut gy, mut bin) = ([0f32; MAX], [0f32; MAX], [0u32; MAX]);
    simd::orientation_bins(&weights[..n], dx, dy, BINS, &mut gx, &mut gy, &mut bin);
    window_maximum(&weights[..n], &gx[..n], &gy[..n], &bin[..n])
}

/// The sliding π/3 window over the binned, weighted responses.
fn window_maximum(weights: &[f32], gx: &[f32], gy: &[f32], bin: &[u32]) -> f32 {
    let n = weights.len().min(gx.len()).min(gy.len()).min(bin.len());
    // Bins, repeated once more at the end so that windows need no wrap.
    let mut bx = [0f32; BINS + WINDOW_BINS];
    let mut by = [0f32; BINS + WINDOW_BINS];
    for i in 0..n {
        // Zero weights (outside the circle, padding) are the same every
        // call, so this branch is well predicted and skips half the grid.
        if weights[i] != 0.0 {
            let b = bin[i] as usize % BINS;
            bx[b] += gx[i];
            by[b] += gy[i];
        }
    }
    for b in 0..WINDOW_BINS {
        bx[BINS + b] = bx[b];
        by[BINS + b] = by[b];
    }
    // Running sums over WINDOW_BINS consecutive bins.
    let (mut sx, mut sy) = (0f32, 0f32);
    for b in 0..WINDOW_BINS {
        sx += bx[b];
        sy += by[b];
    }
    let (mut best, mut best_x, mut best_y) = (sx * sx + sy * sy, sx, sy);
    for start in 1..BINS {
        sx += bx[start + WINDOW_BINS - 1] - bx[start - 1];
        sy += by[start + WINDOW_BINS - 1] - by[start - 1];
        let m = sx * sx + sy * sy;
        if m > best {
            (best, best_x, best_y) = (m, sx, sy);
        }
    }
    if best <= 0.0 {
        return 0.0;
    }
    best_y.atan2(best_x)
}
