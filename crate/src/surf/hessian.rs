//! # Fast-Hessian: where the blobs are, and how big (paper §3)
//!
//! SURF finds blob-like structures where the determinant of the Hessian
//! matrix of the Gaussian-smoothed image peaks, in space and in scale
//! (§3.1). Instead of smoothing and differentiating, it convolves the image
//! with **box filters** that approximate the second-order Gaussian
//! derivatives: a 9 × 9 filter stands for σ = 1.2 (Fig. 1). With the
//! integral image each box costs four look-ups, so a big filter costs the
//! same as a small one. The responses Dxx, Dyy, Dxy are divided by the filter
//! area (so different sizes are comparable) and combined as
//!
//! ```text
//!   det(H_approx) = Dxx · Dyy - (0.9 · Dxy)²                  (paper eq. 4)
//! ```
//!
//! where 0.9 balances the box approximation against the true Gaussians.
//!
//! ## Scale space (§3.2)
//! Rather than shrinking the image, SURF grows the filter. An *octave* is a
//! series of filter sizes whose increment doubles from one octave to the
//! next: 9, 15, 21, 27, then 15, 27, 39, 51, then 27, 51, 75, 99, then 51,
//! 99, 147, 195. In general `L = 3 · (2^(o+1) · (i + 1) + 1)` for octave `o`
//! and interval `i`. Because big filters see only coarse structure, the
//! responses of octave `o` are sampled every `initial_step · 2^o` pixels.
//! Each filter keeps the pixel at its centre, so sample (c, r) of a layer is
//! the filter centred on pixel (c · step, r · step), and samples are computed
//! only where the whole filter lies inside the image.
//!
//! ## Localisation (§3.3)
//! A sample is a keypoint candidate when its det(H) exceeds the threshold
//! and all 26 neighbours in its 3 × 3 × 3 neighbourhood (space × scale).
//! The maximum is then refined to sub-sample position and sub-interval scale
//! by fitting a 3-D quadratic (Brown and Lowe 2002): with the gradient g and
//! Hessian H of det(H) over (x, y, layer) from finite differences, the
//! offset is `-H⁻¹ g`; a fit moving more than one sample (or one layer) in
//! any direction is rejected as unstable (OpenCV's bound; the stricter
//! half-sample bound measured slightly worse repeatability here, because with
//! sampling steps of 2 or more pixels a true maximum is often more than half
//! a sample from the nearest sample). Finally the sign of the trace
//! Dxx + Dyy (the Laplacian) is kept: matching later compares only blobs of
//! the same contrast (§4.3).
//!
//! ## Implementation
//! Each layer is computed row by row by [`simd::hessian_row`] (eight box
//! sums, 32 look-ups per sample). Sampling every 2 or 4 pixels would make
//! those look-ups strided, which neither the compiler nor SIMD128 handles
//! well, so each such octave first splits the integral image into
//! [`PhasePlanes`]: after that, the samples of a row are consecutive and
//! every look-up is a contiguous vector load. Coarser octaves have so few
//! samples that they gather directly.

use super::integral::IntegralImage;
use super::simd::{self, BoxTaps, HessianTaps};
use super::{Keypoint, SurfConfig};

/// Largest number of octaves honoured (filters up to 3 · (2⁹ · 4 + 1) pixels).
pub const MAX_OCTAVES: usize = 8;
/// Largest number of intervals per octave honoured.
pub const MAX_INTERVALS: usize = 8;
/// Largest sampling step computed from [`PhasePlanes`]; coarser octaves
/// have so few samples that they gather from the integral image directly.
pub const MAX_SPLIT_STEP: usize = 4;
/// A fitted maximum may move at most this far (in samples / layers).
pub const MAX_INTERPOLATION_OFFSET: f32 = 1.0;

/// Side of the box filter for octave `o`, interval `i` (both from 0):
/// 9, 15, 21, 27 for octave 0.
pub fn filter_size(octave: usize, interval: usize) -> usize {
    3 * ((1 << (octave + 1)) * (interval + 1) + 1)
}

/// The eight boxes of the filter of side `size` (a multiple of 3 with an odd
/// lobe `size / 3`), as flat offsets in an integral image of row `stride`.
pub fn hessian_taps(size: usize, stride: usize) -> HessianTaps {
    let s = stride as isize;
    hessian_taps_with(size, &|dy, dx| dy * s + dx)
}

/// [`hessian_taps`] in any layout (`at(dy, dx)`: see [`BoxTaps::with_layout`]).
pub fn hessian_taps_with(size: usize, at: &impl Fn(isize, isize) -> isize) -> HessianTaps {
    let l = (size / 3) as isize; // lobe length
    let half = (size / 2) as isize; // half the filter side
    let w = l - 1; // half the width of the Dxx/Dyy filter (2l - 1 wide)
    let m = (l - 1) / 2; // half the central lobe
    let b = |r0, r1, c0, c1| BoxTaps::with_layout(r0, r1, c0, c1, at);
    HessianTaps {
        // Dxx: the whole 3l × (2l-1) box minus 3 × its middle lobe.
        dxx: [b(-w, w, -half, half), b(-w, w, -m, m)],
        // Dyy: the transpose.
        dyy: [b(-half, half, -w, w), b(-m, m, -w, w)],
        // Dxy: + top-left, + bottom-right, - top-right, - bottom-left.
        dxy: [
            b(-l, -1, -l, -1),
            b(1, l, 1, l),
            b(-l, -1, 1, l),
            b(1, l, -l, -1),
        ],
        inv_area: 1.0 / (size * size) as f32,
    }
}

/// The integral image re-laid for sampling every `step` columns: `step`
/// planes, plane k holding columns k, k + step, k + 2·step, … of every
/// row. Columns `x + dx` of samples x = 0, step, 2·step, … are then
/// consecutive in plane `dx mod step`, so a strided layer is computed with
/// the contiguous loads of a full-resolution one (no gathers or shuffles:
/// the shuffling is done once, here, for the whole octave).
#[derive(Clone, Debug)]
pub struct PhasePlanes {
    pub step: usize,
    /// Elements per plane row: ceil((width + 1) / step).
    pub pstride: usize,
    /// Elements per plane: pstride × (height + 1).
    pub plane_len: usize,
    /// The planes one after the other, plus padding zeros.
    pub data: Vec<u32>,
}

impl PhasePlanes {
    pub fn new(ii: &IntegralImage, step: usize) -> Self {
        let step = step.max(1);
        let (cols, rows) = (ii.stride(), ii.height() + 1);
        let pstride = cols.div_ceil(step);
        let plane_len = pstride * rows;
        let mut data = vec![0u32; plane_len * step + simd::INTEGRAL_PAD];
        simd::phase_split(ii.data(), cols, rows, step, &mut data);
        PhasePlanes {
            step,
            pstride,
            plane_len,
            data,
        }
    }

    /// Filter taps in this layout.
    pub fn taps(&self, size: usize) -> HessianTaps {
        let (s, ps, pl) = (
            self.step as isize,
            self.pstride as isize,
            self.plane_len as isize,
        );
        hessian_taps_with(size, &|dy, dx| {
            dx.rem_euclid(s) * pl + dy * ps + dx.div_euclid(s)
        })
    }
}

/// One layer of the box-filter scale space: det(H) on a grid of samples.
#[derive(Clone, Debug)]
pub struct ResponseLayer {
    /// Filter side L in pixels.
    pub size: usize,
    /// Sampling step in pixels.
    pub step: usize,
    /// Samples per row (= ceil(width / step)).
    pub cols: usize,
    /// Rows of samples (= ceil(height / step)).
    pub rows: usize,
    /// det(H), row-major; only the `valid` window is meaningful.
    pub det: Vec<f32>,
    /// Inclusive sample window where the filter fits in the image:
    /// (c_min, c_max, r_min, r_max); `None` if it fits nowhere.
    pub valid: Option<(usize, usize, usize, usize)>,
}

/// Inclusive range of samples c with c·step - half ≥ 0 and
/// c·step + half ≤ len - 1.
fn valid_range(len: usize, half: usize, step: usize) -> Option<(usize, usize)> {
    if len < 2 * half + 1 {
        return None;
    }
    let lo = half.div_ceil(step);
    let hi = (len - 1 - half) / step;
    (lo <= hi).then_some((lo, hi))
}

impl ResponseLayer {
    /// A layer with no responses yet, to be filled by `recompute`.
    fn empty(size: usize, step: usize) -> Self {
        ResponseLayer {
            size,
            step,
            cols: 0,
            rows: 0,
            det: Vec::new(),
            valid: None,
        }
    }

    /// Computes det(H) for the filter of side `size`, sampled every `step`
    /// pixels, wherever the filter fits in the image.
    pub fn compute(ii: &IntegralImage, size: usize, step: usize) -> Self {
        let mut layer = ResponseLayer::empty(size, step);
        let planes = (step > 1).then(|| PhasePlanes::new(ii, step));
        layer.recompute(ii, planes.as_ref(), size, step);
        layer
    }

    /// [`ResponseLayer::compute`] reusing this layer's buffer; `planes` must
    /// be `ii` split for `step` when `step > 1` (it is shared by the layers
    /// of an octave).
    pub fn recompute(
        &mut self,
        ii: &IntegralImage,
        planes: Option<&PhasePlanes>,
        size: usize,
        step: usize,
    ) {
        let (w, h) = (ii.width(), ii.height());
        self.size = size;
        self.step = step;
        self.cols = w.div_ceil(step);
        self.rows = h.div_ceil(step);
        if self.det.len() < self.cols * self.rows {
            self.det.resize(self.cols * self.rows, 0.0);
        }
        let half = size / 2;
        self.valid = match (valid_range(w, half, step), valid_range(h, half, step)) {
            (Some((c0, c1)), Some((r0, r1))) => Some((c0, c1, r0, r1)),
            _ => None,
        };
        let Some((c0, c1, r0, r1)) = self.valid else {
            return;
        };
        match planes.filter(|p| p.step == step && step > 1) {
            Some(p) => {
                let taps = p.taps(size);
                for r in r0..=r1 {
                    let p0 = r * step * p.pstride + c0;
                    let out = &mut self.det[r * self.cols + c0..=r * self.cols + c1];
                    simd::hessian_row(&p.data, &taps, p0, 1, out);
                }
            }
            None => {
                let stride = ii.stride();
                let taps = hessian_taps(size, stride);
                for r in r0..=r1 {
                    let p0 = r * step * stride + c0 * step;
                    let out = &mut self.det[r * self.cols + c0..=r * self.cols + c1];
                    simd::hessian_row(ii.data(), &taps, p0, step, out);
                }
            }
        }
    }

    /// det(H) at sample (c, r).
    #[inline]
    pub fn at(&self, c: usize, r: usize) -> f32 {
        self.det[r * self.cols + c]
    }
}

/// The Fast-Hessian detector with its settings (see [`SurfConfig`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FastHessian {
    pub threshold: f32,
    pub octaves: usize,
    pub intervals: usize,
    pub initial_step: usize,
}

impl FastHessian {
    /// Takes the detector settings of `config`. Octaves and intervals are
    /// capped at [`MAX_OCTAVES`] and [`MAX_INTERVALS`]; a step of 0 counts as 1.
    pub fn new(config: &SurfConfig) -> Self {
        FastHessian {
            threshold: config.threshold,
            octaves: config.octaves.min(MAX_OCTAVES),
            intervals: config.intervals.min(MAX_INTERVALS),
            initial_step: config.initial_step.clamp(1, 64),
        }
    }

    /// Detects keypoints (orientation 0, to be assigned later), in order of
    /// octave, interval, row, column.
    pub fn detect(&self, ii: &IntegralImage) -> Vec<Keypoint> {
        let mut keypoints = Vec::new();
        if self.intervals < 3 || ii.width() < 9 || ii.height() < 9 {
            return keypoints;
        }
        let mut layers: Vec<ResponseLayer> = Vec::with_capacity(self.intervals);
        for o in 0..self.octaves {
            let step = self.initial_step << o;
            if ii.width() < filter_size(o, self.intervals - 1) {
                break; // the largest filter no longer fits
            }
            // Splitting costs a pass over the whole integral image; it pays
            // for itself where layers have many samples (steps 2 and 4).
            let planes = (step > 1 && step <= MAX_SPLIT_STEP).then(|| PhasePlanes::new(ii, step));
            for i in 0..self.intervals {
                let size = filter_size(o, i);
                if layers.len() <= i {
                    layers.push(ResponseLayer::empty(size, step));
                }
                layers[i].recompute(ii, planes.as_ref(), size, step);
            }
            if layers[self.intervals - 1].valid.is_none() {
                break; // the largest filter no longer fits: later octaves won't either
            }
            for i in 1..self.intervals - 1 {
                self.local_maxima(
                    ii,
                    &layers[i - 1],
                    &layers[i],
                    &layers[i + 1],
                    &mut keypoints,
                );
            }
        }
        keypoints
    }

    /// 3 × 3 × 3 non-maximum suppression in the middle layer `mid`, then the
    /// quadratic fit; appends the accepted keypoints.
    fn local_maxima(
        &self,
        ii: &IntegralImage,
        lo: &ResponseLayer,
        mid: &ResponseLayer,
        hi: &ResponseLayer,
        out: &mut Vec<Keypoint>,
    ) {
        // Neighbours must exist in the largest filter's window.
        let Some((c0, c1, r0, r1)) = hi.valid else {
            return;
        };
        if c1 < c0 + 2 || r1 < r0 + 2 {
            return;
        }
        let cols = mid.cols;
        let threshold = self.threshold;
        for r in r0 + 1..r1 {
            let row = &mid.det[r * cols..(r + 1) * cols];
            for (c, &v) in row.iter().enumerate().take(c1).skip(c0 + 1) {
                // Cheapest rejections first: the threshold, then the two
                // neighbours in the same row, then the other 24.
                if v <= threshold
                    || v <= row[c - 1]
                    || v <= row[c + 1]
                    || !is_maximum(v, lo, mid, hi, c, r)
                {
                    continue;
                }
                if let Some(kp) = interpolate(ii, lo, mid, hi, c, r) {
                    out.push(kp);
                }
            }
        }
    }
}

/// True if `v` (sample (c, r) of `mid`) exceeds all 26 neighbours.
#[inline]
fn is_maximum(
    v: f32,
    lo: &ResponseLayer,
    mid: &ResponseLayer,
    hi: &ResponseLayer,
    c: usize,
    r: usize,
) -> bool {
    let cols = mid.cols;
    for rr in r - 1..=r + 1 {
        let base = rr * cols;
        for cc in c - 1..=c + 1 {
            let i = base + cc;
            if lo.det[i] >= v || hi.det[i] >= v || ((rr != r || cc != c) && mid.det[i] >= v) {
                return false;
            }
        }
    }
    true
}

/// Brown and Lowe's quadratic fit around sample (c, r) of `mid`.
fn interpolate(
    ii: &IntegralImage,
    lo: &ResponseLayer,
    mid: &ResponseLayer,
    hi: &ResponseLayer,
    c: usize,
    r: usize,
) -> Option<Keypoint> {
    let m = |c: usize, r: usize| mid.at(c, r) as f64;
    let v = m(c, r);
    // Gradient of det(H) in (x, y, scale), central differences.
    let g = [
        (m(c + 1, r) - m(c - 1, r)) / 2.0,
        (m(c, r + 1) - m(c, r - 1)) / 2.0,
        (hi.at(c, r) as f64 - lo.at(c, r) as f64) / 2.0,
    ];
    // Hessian of det(H) in (x, y, scale).
    let dxx = m(c + 1, r) + m(c - 1, r) - 2.0 * v;
    let dyy = m(c, r + 1) + m(c, r - 1) - 2.0 * v;
    let dss = hi.at(c, r) as f64 + lo.at(c, r) as f64 - 2.0 * v;
    let dxy = (m(c + 1, r + 1) - m(c - 1, r + 1) - m(c + 1, r - 1) + m(c - 1, r - 1)) / 4.0;
    let dxs = (hi.at(c + 1, r) as f64 - hi.at(c - 1, r) as f64 - lo.at(c + 1, r) as f64
        + lo.at(c - 1, r) as f64)
        / 4.0;
    let dys = (hi.at(c, r + 1) as f64 - hi.at(c, r - 1) as f64 - lo.at(c, r + 1) as f64
        + lo.at(c, r - 1) as f64)
        / 4.0;
    let h = [[dxx, dxy, dxs], [dxy, dyy, dys], [dxs, dys, dss]];
    let offset = solve3(&h, &[-g[0], -g[1], -g[2]])?;
    let limit = MAX_INTERPOLATION_OFFSET as f64;
    if offset.iter().any(|o| !o.is_finite() || o.abs() > limit) {
        return None;
    }
    let step = mid.step as f64;
    let size_step = (hi.size - mid.size) as f64;
    let size = mid.size as f64 + offset[2] * size_step;
    let response = v + 0.5 * (g[0] * offset[0] + g[1] * offset[1] + g[2] * offset[2]);
    Some(Keypoint {
        x: ((c as f64 + offset[0]) * step) as f32,
        y: ((r as f64 + offset[1]) * step) as f32,
        scale: (1.2 / 9.0 * size) as f32,
        orientation: 0.0,
        laplacian: laplacian_sign(ii, mid.size, c * mid.step, r * mid.step),
        response: response as f32,
    })
}

/// Sign of Dxx + Dyy for the filter of side `size` centred on pixel (x, y):
/// +1 for a dark blob on a bright background, -1 for a bright blob.
pub fn laplacian_sign(ii: &IntegralImage, size: usize, x: usize, y: usize) -> i8 {
    let taps = hessian_taps(size, ii.stride());
    let p = (y * ii.stride() + x) as isize;
    let d = ii.data();
    let sum = |b: &BoxTaps| -> i64 {
        let at = |o: isize| d[(p + o) as usize];
        at(b.br)
            .wrapping_sub(at(b.tr))
            .wrapping_sub(at(b.bl))
            .wrapping_add(at(b.tl)) as i32 as i64
    };
    let dxx = sum(&taps.dxx[0]) - 3 * sum(&taps.dxx[1]);
    let dyy = sum(&taps.dyy[0]) - 3 * sum(&taps.dyy[1]);
    if dxx + dyy > 0 {
        1
    } else {
        -1
    }
}

/// Solves the 3 × 3 system `a x = b` by Cramer's rule; `None` if singular.
fn solve3(a: &[[f64; 3]; 3], b: &[f64; 3]) -> Option<[f64; 3]> {
    let det3 = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det3(a);
    if d.abs() < 1e-30 || !d.is_finite() {
        return None;
    }
    let mut x = [0.0; 3];
    for (k, xk) in x.iter_mut().enumerate() {
        let mut m = *a;
        for row in 0..3 {
            m[row][k] = b[row];
        }
        *xk = det3(&m) / d;
    }
    Some(x)
}
