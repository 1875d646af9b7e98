//! # The hot loops, portable and in wasm SIMD128
//!
//! SURF spends almost all of its time in a few small loops. Each appears here
//! twice, with the same signature and the same arithmetic in the same order:
//!
//! | kernel | stage | SIMD128 idea |
//! |---|---|---|
//! | [`integral_image`] | §2 integral image | 16 pixels widened u8 → u32, prefix sums by lane shifts |
//! | [`phase_split`] | §3.2 | deinterleave the integral image's columns for strided layers (even/odd lane shuffles, 4 × 4 transposes) |
//! | [`hessian_row`] | §3.2 box filters | 4 samples at once from contiguous loads; strided layers come pre-split ([`crate::surf::hessian::PhasePlanes`]), or by two loads and an even-lane shuffle (step 2), or gathers |
//! | [`lattice_haar`] | §4.1 | the orientation wavelets from a 17 × 17 table of integral values, contiguous |
//! | [`orientation_bins`] | §4.1 | weighted responses and their angle bins (polynomial atan2), 4 at once |
//! | [`patch_box_sums`] | §4.2 | rotated sample positions and the (clipped) box sums that resample the descriptor patch, 4 at once |
//! | [`patch_box_sums_inside`] | §4.2 | the same for patches inside the image: one index per sample, three fixed offsets |
//! | [`patch_wavelets`] | §4.2 | 2 × 2 Haar wavelets on the patch, Gaussian weight, 4 at once |
//! | [`descriptor_sums`] | §4.2 | Σdx, Σdy, Σ\|dx\|, Σ\|dy\| by column sums, then across |
//! | [`dot64_many`] | §4.3 matching | 64-d dot products, 4 lanes, fixed reduction order |
//!
//! [`scalar`] is the portable twin; `simd128` (only on `wasm32`) holds the
//! hand-written `core::arch::wasm32` kernels. The free functions of this
//! module pick one at compile time, so callers never see an intrinsic: a
//! build with `-C target-feature=+simd128` uses SIMD, any other uses the
//! scalar code. Because every `simd128` function carries
//! `#[target_feature(enable = "simd128")]`, it also exists in a scalar wasm
//! build, and one test binary (`tests/surf_kernels.rs`) runs both twins in
//! node and compares them. Integer stages are bit-exact; the float kernels
//! are too, because each scalar twin performs the same operations in the
//! same order as the 4 lanes (no fused multiply-add exists on either side).
//!
//! Bounds: each kernel checks its index range once, up front, with an
//! `assert!`, and then reads without per-element checks. The integral image
//! buffer carries [`INTEGRAL_PAD`] spare elements so that vector loads of the
//! last samples of a row stay inside it.

/// True when this build uses the SIMD128 kernels.
pub const SIMD128: bool = cfg!(all(target_arch = "wasm32", target_feature = "simd128"));

/// Spare zero elements at the end of every integral-image buffer: the step-2
/// Hessian kernel loads 8 consecutive values starting at its last sample.
pub const INTEGRAL_PAD: usize = 8;

/// Flat-index offsets of a box's four integral-image corners, relative to
/// the filter centre: sum = BR - TR - BL + TL.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BoxTaps {
    pub tl: isize,
    pub tr: isize,
    pub bl: isize,
    pub br: isize,
}

impl BoxTaps {
    /// Box covering pixel rows `r0..=r1` and columns `c0..=c1` relative to
    /// the centre pixel, in an integral image whose rows are `stride` long
    /// (the integral has one leading zero row and column, see
    /// [`crate::surf::integral`]).
    pub fn new(r0: isize, r1: isize, c0: isize, c1: isize, stride: usize) -> Self {
        let s = stride as isize;
        BoxTaps {
            tl: r0 * s + c0,
            tr: r0 * s + c1 + 1,
            bl: (r1 + 1) * s + c0,
            br: (r1 + 1) * s + c1 + 1,
        }
    }
    /// The same box in any layout: `at(dy, dx)` is the flat offset of the
    /// integral corner `dy` rows and `dx` columns from the centre's corner.
    pub fn with_layout(
        r0: isize,
        r1: isize,
        c0: isize,
        c1: isize,
        at: &impl Fn(isize, isize) -> isize,
    ) -> Self {
        BoxTaps {
            tl: at(r0, c0),
            tr: at(r0, c1 + 1),
            bl: at(r1 + 1, c0),
            br: at(r1 + 1, c1 + 1),
        }
    }
    fn min(&self) -> isize {
        self.tl.min(self.tr).min(self.bl).min(self.br)
    }
    fn max(&self) -> isize {
        self.tl.max(self.tr).max(self.bl).max(self.br)
    }
}

/// The eight boxes of one scale-space layer (paper Fig. 1):
/// Dxx = box0 - 3·box1, Dyy likewise, Dxy = box0 + box1 - box2 - box3,
/// each divided by the filter area L².
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HessianTaps {
    pub dxx: [BoxTaps; 2],
    pub dyy: [BoxTaps; 2],
    pub dxy: [BoxTaps; 4],
    pub inv_area: f32,
}

impl HessianTaps {
    fn all(&self) -> [BoxTaps; 8] {
        [
            self.dxx[0],
            self.dxx[1],
            self.dyy[0],
            self.dyy[1],
            self.dxy[0],
            self.dxy[1],
            self.dxy[2],
            self.dxy[3],
        ]
    }
    /// Smallest and largest corner offset over all eight boxes.
    pub fn span(&self) -> (isize, isize) {
        let all = self.all();
        let lo = all.iter().map(BoxTaps::min).min().unwrap_or(0);
        let hi = all.iter().map(BoxTaps::max).max().unwrap_or(0);
        (lo, hi)
    }
}

/// Check shared by both twins of [`hessian_row`].
fn check_hessian_row(ii_len: usize, taps: &HessianTaps, p0: usize, step: usize, n: usize) {
    if n == 0 {
        return;
    }
    let (lo, hi) = taps.span();
    let last = p0 + (n - 1) * step;
    assert!(step >= 1, "hessian_row: step 0");
    assert!(
        p0 as isize + lo >= 0,
        "hessian_row: filter leaves the integral image (start)"
    );
    assert!(
        (last as isize + hi) as usize + INTEGRAL_PAD < ii_len,
        "hessian_row: filter leaves the integral image (end)"
    );
}

/// Check shared by both twins of [`orientation_bins`].
fn check_bins(
    w: &[f32],
    dx: &[f32],
    dy: &[f32],
    bins: usize,
    gx: &[f32],
    gy: &[f32],
    bin: &[u32],
) -> usize {
    let n = w.len();
    assert!(
        dx.len() >= n && dy.len() >= n && gx.len() >= n && gy.len() >= n && bin.len() >= n,
        "orientation_bins: lengths"
    );
    assert!(bins >= 1, "orientation_bins: no bins");
    n
}

/// Builds the integral image of `pixels` (`width × height`, row-major) into
/// `out`, which must hold at least `(width + 1) * (height + 1)` elements:
/// `out[(y + 1) * (width + 1) + x + 1]` = sum of pixels in rows `..=y`,
/// columns `..=x`; row 0 and column 0 are zero. Sums wrap modulo 2³²; box
/// sums taken by differences are exact while the box sum itself fits.
pub fn integral_image(pixels: &[u8], width: usize, height: usize, out: &mut [u32]) {
    #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
    // SAFETY: this build targets simd128; the kernel checks its bounds.
    unsafe {
        simd128::integral_image(pixels, width, height, out)
    }
    #[cfg(not(all(target_arch = "wasm32", target_feature = "simd128")))]
    scalar::integral_image(pixels, width, height, out)
}

/// Splits an integral image (`rows` rows of `cols` values) into `step`
/// planes for strided sampling ([`crate::surf::hessian::PhasePlanes`]):
/// with `pstride = ceil(cols / step)` and `plane_len = pstride · rows`,
/// `out[k · plane_len + y · pstride + j] = src[y · cols + j · step + k]`
/// wherever `j · step + k < cols`. Other entries are left as they are.
pub fn phase_split(src: &[u32], cols: usize, rows: usize, step: usize, out: &mut [u32]) {
    #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
    // SAFETY: this build targets simd128; the kernel checks its bounds.
    unsafe {
        simd128::phase_split(src, cols, rows, step, out)
    }
    #[cfg(not(all(target_arch = "wasm32", target_feature = "simd128")))]
    scalar::phase_split(src, cols, rows, step, out)
}

/// Check shared by both twins of [`phase_split`]; returns (pstride, plane_len).
fn check_split(
    src_len: usize,
    cols: usize,
    rows: usize,
    step: usize,
    out_len: usize,
) -> (usize, usize) {
    assert!(step >= 1, "phase_split: step 0");
    assert!(src_len >= cols * rows, "phase_split: source too short");
    let pstride = cols.div_ceil(step);
    let plane_len = pstride * rows;
    assert!(out_len >= plane_len * step, "phase_split: output too short");
    (pstride, plane_len)
}

/// det(H) of `out.len()` consecutive samples of one layer: sample k is the
/// filter centred at flat integral index `p0 + k * step` (the index of the
/// centre pixel's top-left integral corner). Panics if a filter would read
/// outside `ii` (callers only ask for samples where the filter fits).
pub fn hessian_row(ii: &[u32], taps: &HessianTaps, p0: usize, step: usize, out: &mut [f32]) {
    #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
    // SAFETY: this build targets simd128; the kernel checks its bounds.
    unsafe {
        simd128::hessian_row(ii, taps, p0, step, out)
    }
    #[cfg(not(all(target_arch = "wasm32", target_feature = "simd128")))]
    scalar::hessian_row(ii, taps, p0, step, out)
}

/// Haar wavelets of side 4 lattice steps on a 17 × 20 table of integral
/// values (row-major, rows 20 apart): for grid sample (i, j), i < 16,
/// j < 13, with a_rc = table[(j + 2r) · 20 + i + 2c]:
/// dx = a22 - a02 - 2 a21 + 2 a01 + a20 - a00,
/// dy = a22 - 2 a12 - a20 + 2 a10 + a02 - a00, at index j · 16 + i.
pub fn lattice_haar(table: &[u32; 340], dx: &mut [f32; 208], dy: &mut [f32; 208]) {
    #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
    // SAFETY: this build targets simd128; fixed-size arrays.
    unsafe {
        simd128::lattice_haar(table, dx, dy)
    }
    #[cfg(not(all(target_arch = "wasm32", target_feature = "simd128")))]
    scalar::lattice_haar(table, dx, dy)
}

/// Where the descriptor patch of one keypoint lies: sample (i, j) of the
/// 21 × 21 patch is the sum of the `n × n` box whose top-left integral
/// corner is (round(x0 + u cos - v sin), round(y0 + u sin + v cos)) with
/// u = (i - 10) s, v = (j - 10) s; `x0`, `y0` already include the shift from
/// the box centre to its corner.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchGeometry {
    pub x0: f32,
    pub y0: f32,
    pub cos: f32,
    pub sin: f32,
    pub s: f32,
    pub n: usize,
}

/// The 441 box sums of a descriptor patch ([`PatchGeometry`]) in the
/// integral image `ii` of a `w × h` image. Each box is clipped to the image
/// (its corners clamped to 0..=w, 0..=h), so pixels outside count as zero
/// and no read leaves `ii`.
pub fn patch_box_sums(ii: &[u32], w: usize, h: usize, g: &PatchGeometry, out: &mut [f32; 441]) {
    #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
    // SAFETY: this build targets simd128; corners are clamped into the image.
    unsafe {
        simd128::patch_box_sums(ii, w, h, g, out)
    }
    #[cfg(not(all(target_arch = "wasm32", target_feature = "simd128")))]
    scalar::patch_box_sums(ii, w, h, g, out)
}

/// [`patch_box_sums`] for a patch whose boxes all lie inside the image
/// (the caller checks): no clipping, so one corner index per sample and
/// the other three at fixed offsets. Indices are clamped into `ii`, so a
/// wrong caller gets wrong numbers, never a read outside.
pub fn patch_box_sums_inside(ii: &[u32], stride: usize, g: &PatchGeometry, out: &mut [f32; 441]) {
    #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
    // SAFETY: this build targets simd128; indices are clamped in range.
    unsafe {
        simd128::patch_box_sums_inside(ii, stride, g, out)
    }
    #[cfg(not(all(target_arch = "wasm32", target_feature = "simd128")))]
    scalar::patch_box_sums_inside(ii, stride, g, out)
}

/// Largest top-left corner index a box of side `n` may have in `ii`.
fn inside_limit(ii_len: usize, stride: usize, n: usize) -> i32 {
    assert!(
        stride < 1 << 20 && n < 1 << 20,
        "patch_box_sums_inside: sizes"
    );
    assert!(
        ii_len > n * stride + n + 1,
        "patch_box_sums_inside: integral image too small"
    );
    (ii_len - n * stride - n - 1).min(i32::MAX as usize) as i32
}

/// Check shared by both twins of [`patch_box_sums`]: the integral image of a
/// `w × h` image, with sides that fit in i32.
fn check_patch(ii_len: usize, w: usize, h: usize) {
    assert!(
        w < 1 << 20 && h < 1 << 20,
        "patch_box_sums: image too large"
    );
    assert!(
        ii_len >= (w + 1) * (h + 1),
        "patch_box_sums: integral image too small"
    );
}

/// Orientation binning: `gx = w dx`, `gy = w dy` and the bin of the angle
/// atan2(gy, gx) among `bins` equal sectors of [0, 2π) (a polynomial atan2,
/// accurate to about 1e-5 rad). Zero responses fall in bin 0 and add nothing.
pub fn orientation_bins(
    w: &[f32],
    dx: &[f32],
    dy: &[f32],
    bins: usize,
    gx: &mut [f32],
    gy: &mut [f32],
    bin: &mut [u32],
) {
    #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
    // SAFETY: this build targets simd128; the kernel checks its bounds.
    unsafe {
        simd128::orientation_bins(w, dx, dy, bins, gx, gy, bin)
    }
    #[cfg(not(all(target_arch = "wasm32", target_feature = "simd128")))]
    scalar::orientation_bins(w, dx, dy, bins, gx, gy, bin)
}

/// Haar wavelets of a 21 × 21 patch P (row-major), one per 2 × 2 block,
/// weighted: for block (i, j), with a = P(i, j), b = P(i+1, j),
/// c = P(i, j+1), d = P(i+1, j+1):
/// du = w ((b - a) + (d - c)), dv = w ((c - a) + (d - b)).
pub fn patch_wavelets(
    patch: &[f32; 441],
    w: &[f32; 400],
    du: &mut [f32; 400],
    dv: &mut [f32; 400],
) {
    #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
    // SAFETY: this build targets simd128; fixed-size arrays.
    unsafe {
        simd128::patch_wavelets(patch, w, du, dv)
    }
    #[cfg(not(all(target_arch = "wasm32", target_feature = "simd128")))]
    scalar::patch_wavelets(patch, w, du, dv)
}

/// The 64 sums of a 20 × 20 grid of responses (row-major, 400 each) over
/// its 4 × 4 sub-regions of 5 × 5: `out[4 * (4 * sj + si) + q]` for
/// q = Σdu, Σdv, Σ|du|, Σ|dv| of sub-region row `sj`, column `si`.
pub fn descriptor_sums(du: &[f32; 400], dv: &[f32; 400], out: &mut [f32; 64]) {
    #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
    // SAFETY: this build targets simd128; fixed-size arrays.
    unsafe {
        simd128::descriptor_sums(du, dv, out)
    }
    #[cfg(not(all(target_arch = "wasm32", target_feature = "simd128")))]
    scalar::descriptor_sums(du, dv, out)
}

/// `out[i]` = dot product of `query` and `candidates[i]`.
pub fn dot64_many(query: &[f32; 64], candidates: &[[f32; 64]], out: &mut [f32]) {
    #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
    // SAFETY: this build targets simd128; the kernel checks its bounds.
    unsafe {
        simd128::dot64_many(query, candidates, out)
    }
    #[cfg(not(all(target_arch = "wasm32", target_feature = "simd128")))]
    scalar::dot64_many(query, candidates, out)
}

/// The portable twins: plain Rust, the reference the SIMD kernels are tested
/// against, and what native and scalar-wasm builds run.
pub mod scalar {
    use super::*;

    pub fn integral_image(pixels: &[u8], width: usize, height: usize, out: &mut [u32]) {
        let stride = width + 1;
        assert!(
            pixels.len() >= width * height,
            "integral_image: too few pixels"
        );
        assert!(
            out.len() >= stride * (height + 1),
            "integral_image: output too short"
        );
        out[..stride].fill(0);
        for y in 0..height {
            let (above, rest) = out.split_at_mut((y + 1) * stride);
            let above = &above[y * stride..];
            let row = &mut rest[..stride];
            row[0] = 0;
            let src = &pixels[y * width..(y + 1) * width];
            let mut run = 0u32;
            for x in 0..width {
                run = run.wrapping_add(src[x] as u32);
                row[x + 1] = run.wrapping_add(above[x + 1]);
            }
        }
    }

    pub fn phase_split(src: &[u32], cols: usize, rows: usize, step: usize, out: &mut [u32]) {
        let (pstride, plane_len) = check_split(src.len(), cols, rows, step, out.len());
        for y in 0..rows {
            let row = &src[y * cols..(y + 1) * cols];
            for k in 0..step {
                let dst = &mut out[k * plane_len + y * pstride..k * plane_len + (y + 1) * pstride];
                for (d, v) in dst.iter_mut().zip(row.iter().skip(k).step_by(step)) {
                    *d = *v;
                }
            }
        }
    }

    #[inline(always)]
    fn box_sum(ii: &[u32], p: usize, b: &BoxTaps) -> i32 {
        // SAFETY: hessian_row checked p + every offset against ii.len().
        unsafe {
            let at = |o: isize| *ii.get_unchecked((p as isize + o) as usize);
            at(b.br)
                .wrapping_sub(at(b.tr))
                .wrapping_sub(at(b.bl))
                .wrapping_add(at(b.tl)) as i32
        }
    }

    pub fn hessian_row(ii: &[u32], taps: &HessianTaps, p0: usize, step: usize, out: &mut [f32]) {
        check_hessian_row(ii.len(), taps, p0, step, out.len());
        for (k, o) in out.iter_mut().enumerate() {
            let p = p0 + k * step;
            let dxx = box_sum(ii, p, &taps.dxx[0]).wrapping_sub(3i32.wrapping_mul(box_sum(
                ii,
                p,
                &taps.dxx[1],
            )));
            let dyy = box_sum(ii, p, &taps.dyy[0]).wrapping_sub(3i32.wrapping_mul(box_sum(
                ii,
                p,
                &taps.dyy[1],
            )));
            let dxy = box_sum(ii, p, &taps.dxy[0])
                .wrapping_add(box_sum(ii, p, &taps.dxy[1]))
                .wrapping_sub(box_sum(ii, p, &taps.dxy[2]))
                .wrapping_sub(box_sum(ii, p, &taps.dxy[3]));
            let dxx = dxx as f32 * taps.inv_area;
            let dyy = dyy as f32 * taps.inv_area;
            let dxy = dxy as f32 * taps.inv_area;
            *o = dxx * dyy - 0.81 * (dxy * dxy);
        }
    }

    pub fn lattice_haar(table: &[u32; 340], dx: &mut [f32; 208], dy: &mut [f32; 208]) {
        for j in 0..13 {
            for i in 0..16 {
                let a = |r: usize, c: usize| table[(j + 2 * r) * 20 + i + 2 * c] as i32;
                let x = a(2, 2)
                    .wrapping_sub(a(0, 2))
                    .wrapping_sub(a(2, 1).wrapping_mul(2))
                    .wrapping_add(a(0, 1).wrapping_mul(2))
                    .wrapping_add(a(2, 0))
                    .wrapping_sub(a(0, 0));
                let y = a(2, 2)
                    .wrapping_sub(a(1, 2).wrapping_mul(2))
                    .wrapping_sub(a(2, 0))
                    .wrapping_add(a(1, 0).wrapping_mul(2))
                    .wrapping_add(a(0, 2))
                    .wrapping_sub(a(0, 0));
                dx[j * 16 + i] = x as f32;
                dy[j * 16 + i] = y as f32;
            }
        }
    }

    pub fn patch_box_sums(ii: &[u32], w: usize, h: usize, g: &PatchGeometry, out: &mut [f32; 441]) {
        check_patch(ii.len(), w, h);
        let (wi, hi, st, n) = (w as i32, h as i32, (w + 1) as i32, g.n as i32);
        for j in 0..21 {
            let v = (j as f32 - 10.0) * g.s;
            for i in 0..21 {
                let u = (i as f32 - 10.0) * g.s;
                let x = (g.x0 + u * g.cos - v * g.sin).round_ties_even() as i32;
                let y = (g.y0 + u * g.sin + v * g.cos).round_ties_even() as i32;
                let (x0, x1) = (x.clamp(0, wi), x.wrapping_add(n).clamp(0, wi));
                let (y0, y1) = (y.clamp(0, hi) * st, y.wrapping_add(n).clamp(0, hi) * st);
                // SAFETY: all four corners are inside the checked table.
                let a = |k: i32| unsafe { *ii.get_unchecked(k as usize) };
                out[j * 21 + i] = a(y1 + x1)
                    .wrapping_sub(a(y0 + x1))
                    .wrapping_sub(a(y1 + x0))
                    .wrapping_add(a(y0 + x0)) as i32 as f32;
            }
        }
    }

    pub fn patch_box_sums_inside(
        ii: &[u32],
        stride: usize,
        g: &PatchGeometry,
        out: &mut [f32; 441],
    ) {
        let limit = inside_limit(ii.len(), stride, g.n);
        let (r, c1) = (g.n * stride, g.n);
        for j in 0..21 {
            let v = (j as f32 - 10.0) * g.s;
            for i in 0..21 {
                let u = (i as f32 - 10.0) * g.s;
                let x = (g.x0 + u * g.cos - v * g.sin).round_ties_even() as i32;
                let y = (g.y0 + u * g.sin + v * g.cos).round_ties_even() as i32;
                let c = y
                    .wrapping_mul(stride as i32)
                    .wrapping_add(x)
                    .clamp(0, limit) as usize;
                // SAFETY: c ≤ limit keeps c + r + c1 inside ii.
                let a = |k: usize| unsafe { *ii.get_unchecked(c + k) };
                out[j * 21 + i] = a(r + c1)
                    .wrapping_sub(a(c1))
                    .wrapping_sub(a(r))
                    .wrapping_add(a(0)) as i32 as f32;
            }
        }
    }

    /// The polynomial atan2 of [`orientation_bins`], one value.
    #[inline]
    pub fn atan2(y: f32, x: f32) -> f32 {
        use std::f32::consts::{FRAC_PI_2, PI};
        let (ax, ay) = (x.abs(), y.abs());
        let (num, den) = (ax.min(ay), ax.max(ay));
        let a = if den > 0.0 { num / den } else { 0.0 };
        let a2 = a * a;
        let p = 0.020_835_1f32;
        let p = p * a2 + -0.085_133;
        let p = p * a2 + 0.180_141;
        let p = p * a2 + -0.330_299_5;
        let p = p * a2 + 0.999_866;
        let r = p * a;
        let r = if ay > ax { FRAC_PI_2 - r } else { r };
        let r = if x < 0.0 { PI - r } else { r };
        r.copysign(y)
    }

    pub fn orientation_bins(
        w: &[f32],
        dx: &[f32],
        dy: &[f32],
        bins: usize,
        gx: &mut [f32],
        gy: &mut [f32],
        bin: &mut [u32],
    ) {
        let n = check_bins(w, dx, dy, bins, gx, gy, bin);
        let to_bin = bins as f32 / std::f32::consts::TAU;
        for i in 0..n {
            let (x, y) = (w[i] * dx[i], w[i] * dy[i]);
            gx[i] = x;
            gy[i] = y;
            let a = atan2(y, x) * to_bin;
            let a = if a < 0.0 { a + bins as f32 } else { a };
            bin[i] = (a as u32).min(bins as u32 - 1);
        }
    }

    pub fn patch_wavelets(
        patch: &[f32; 441],
        w: &[f32; 400],
        du: &mut [f32; 400],
        dv: &mut [f32; 400],
    ) {
        for j in 0..20 {
            for i in 0..20 {
                let (a, b) = (patch[j * 21 + i], patch[j * 21 + i + 1]);
                let (c, d) = (patch[(j + 1) * 21 + i], patch[(j + 1) * 21 + i + 1]);
                let k = j * 20 + i;
                du[k] = w[k] * ((b - a) + (d - c));
                dv[k] = w[k] * ((c - a) + (d - b));
            }
        }
    }

    pub fn descriptor_sums(du: &[f32; 400], dv: &[f32; 400], out: &mut [f32; 64]) {
        for sj in 0..4 {
            // Column sums over the 5 rows of this band of sub-regions.
            let mut c = [[0f32; 20]; 4];
            for j in sj * 5..sj * 5 + 5 {
                for i in 0..20 {
                    let (u, v) = (du[j * 20 + i], dv[j * 20 + i]);
                    c[0][i] += u;
                    c[1][i] += v;
                    c[2][i] += u.abs();
                    c[3][i] += v.abs();
                }
            }
            for si in 0..4 {
                for q in 0..4 {
                    let s = &c[q][si * 5..si * 5 + 5];
                    out[(sj * 4 + si) * 4 + q] = (((s[0] + s[1]) + s[2]) + s[3]) + s[4];
                }
            }
        }
    }

    pub fn dot64_many(query: &[f32; 64], candidates: &[[f32; 64]], out: &mut [f32]) {
        assert!(
            out.len() >= candidates.len(),
            "dot64_many: output too short"
        );
        for (o, c) in out.iter_mut().zip(candidates) {
            let mut acc = [0f32; 4];
            for i in (0..64).step_by(4) {
                for k in 0..4 {
                    acc[k] += query[i + k] * c[i + k];
                }
            }
            *o = (acc[0] + acc[2]) + (acc[1] + acc[3]);
        }
    }
}

/// The SIMD128 twins. Each function is `unsafe` only because of its
/// `#[target_feature]`: it must run on a wasm engine with SIMD128 (node ≥ 16,
/// every current browser). Memory safety is checked as in [`scalar`].
#[cfg(target_arch = "wasm32")]
pub mod simd128 {
    use super::*;
    use core::arch::wasm32::*;

    /// # Safety
    /// The engine must support SIMD128.
    #[target_feature(enable = "simd128")]
    pub unsafe fn integral_image(pixels: &[u8], width: usize, height: usize, out: &mut [u32]) {
        let stride = width + 1;
        assert!(
            pixels.len() >= width * height,
            "integral_image: too few pixels"
        );
        assert!(
            out.len() >= stride * (height + 1),
            "integral_image: output too short"
        );
        out[..stride].fill(0);
        let zero = i32x4_splat(0);
        let src = pixels.as_ptr();
        let dst = out.as_mut_ptr();
        for y in 0..height {
            let row_in = src.add(y * width);
            let above = dst.add(y * stride + 1);
            let row = dst.add((y + 1) * stride + 1);
            *row.sub(1) = 0;
            let mut carry = zero;
            let mut x = 0;
            while x + 16 <= width {
                let bytes = v128_load(row_in.add(x) as *const v128);
                let lo = u16x8_extend_low_u8x16(bytes);
                let hi = u16x8_extend_high_u8x16(bytes);
                let quads = [
                    u32x4_extend_low_u16x8(lo),
                    u32x4_extend_high_u16x8(lo),
                    u32x4_extend_low_u16x8(hi),
                    u32x4_extend_high_u16x8(hi),
                ];
                for (q, &v) in quads.iter().enumerate() {
                    // Prefix sum inside the vector: v += v << 1 lane; v += v << 2 lanes.
                    let v = i32x4_add(v, i32x4_shuffle::<4, 0, 1, 2>(v, zero));
                    let v = i32x4_add(v, i32x4_shuffle::<4, 5, 0, 1>(v, zero));
                    let v = i32x4_add(v, carry);
                    carry = i32x4_shuffle::<3, 3, 3, 3>(v, v);
                    let off = x + 4 * q;
                    let up = v128_load(above.add(off) as *const v128);
                    v128_store(row.add(off) as *mut v128, i32x4_add(v, up));
                }
                x += 16;
            }
            let mut run = i32x4_extract_lane::<0>(carry) as u32;
            while x < width {
                run = run.wrapping_add(*row_in.add(x) as u32);
                *row.add(x) = run.wrapping_add(*above.add(x));
                x += 1;
            }
        }
    }

    /// # Safety
    /// The engine must support SIMD128.
    #[target_feature(enable = "simd128")]
    pub unsafe fn phase_split(src: &[u32], cols: usize, rows: usize, step: usize, out: &mut [u32]) {
        if step != 2 && step != 4 {
            return scalar::phase_split(src, cols, rows, step, out);
        }
        let (pstride, plane_len) = check_split(src.len(), cols, rows, step, out.len());
        let (sp, op) = (src.as_ptr(), out.as_mut_ptr());
        for y in 0..rows {
            let row = sp.add(y * cols);
            let dst = op.add(y * pstride);
            // Whole blocks of 4 outputs per plane: 4·step source values.
            let blocks = cols / (4 * step);
            for b in 0..blocks {
                let s0 = row.add(b * 4 * step);
                if step == 2 {
                    let (v0, v1) = (
                        v128_load(s0 as *const v128),
                        v128_load(s0.add(4) as *const v128),
                    );
                    v128_store(
                        dst.add(4 * b) as *mut v128,
                        i32x4_shuffle::<0, 2, 4, 6>(v0, v1),
                    );
                    v128_store(
                        dst.add(plane_len + 4 * b) as *mut v128,
                        i32x4_shuffle::<1, 3, 5, 7>(v0, v1),
                    );
                } else {
                    // A 4 × 4 transpose: plane k takes lane k of each vector.
                    let v = [0, 4, 8, 12].map(|o| v128_load(s0.add(o) as *const v128));
                    let t01 = i32x4_shuffle::<0, 4, 1, 5>(v[0], v[1]);
                    let t23 = i32x4_shuffle::<0, 4, 1, 5>(v[2], v[3]);
                    let u01 = i32x4_shuffle::<2, 6, 3, 7>(v[0], v[1]);
                    let u23 = i32x4_shuffle::<2, 6, 3, 7>(v[2], v[3]);
                    let planes = [
                        i32x4_shuffle::<0, 1, 4, 5>(t01, t23),
                        i32x4_shuffle::<2, 3, 6, 7>(t01, t23),
                        i32x4_shuffle::<0, 1, 4, 5>(u01, u23),
                        i32x4_shuffle::<2, 3, 6, 7>(u01, u23),
                    ];
                    for (k, p) in planes.iter().enumerate() {
                        v128_store(dst.add(k * plane_len + 4 * b) as *mut v128, *p);
                    }
                }
            }
            // The rest of the row, one value at a time.
            for x in blocks * 4 * step..cols {
                *dst.add((x % step) * plane_len + x / step) = *row.add(x);
            }
        }
    }

    #[inline]
    #[target_feature(enable = "simd128")]
    unsafe fn gather<const S: usize>(p: *const u32, step: usize) -> v128 {
        match S {
            1 => v128_load(p as *const v128),
            2 => {
                let a = v128_load(p as *const v128);
                let b = v128_load(p.add(4) as *const v128);
                i32x4_shuffle::<0, 2, 4, 6>(a, b)
            }
            _ => u32x4(*p, *p.add(step), *p.add(2 * step), *p.add(3 * step)),
        }
    }

    #[inline]
    #[target_feature(enable = "simd128")]
    unsafe fn box4<const S: usize>(base: *const u32, step: usize, b: &BoxTaps) -> v128 {
        let br = gather::<S>(base.offset(b.br), step);
        let tr = gather::<S>(base.offset(b.tr), step);
        let bl = gather::<S>(base.offset(b.bl), step);
        let tl = gather::<S>(base.offset(b.tl), step);
        i32x4_add(i32x4_sub(i32x4_sub(br, tr), bl), tl)
    }

    #[target_feature(enable = "simd128")]
    unsafe fn hessian_row_s<const S: usize>(
        ii: &[u32],
        taps: &HessianTaps,
        p0: usize,
        step: usize,
        out: &mut [f32],
    ) {
        let n = out.len();
        let three = i32x4_splat(3);
        let inv = f32x4_splat(taps.inv_area);
        let w = f32x4_splat(0.81);
        let mut k = 0;
        while k + 4 <= n {
            let base = ii.as_ptr().add(p0 + k * step);
            let dxx = i32x4_sub(
                box4::<S>(base, step, &taps.dxx[0]),
                i32x4_mul(three, box4::<S>(base, step, &taps.dxx[1])),
            );
            let dyy = i32x4_sub(
                box4::<S>(base, step, &taps.dyy[0]),
                i32x4_mul(three, box4::<S>(base, step, &taps.dyy[1])),
            );
            let dxy = i32x4_sub(
                i32x4_sub(
                    i32x4_add(
                        box4::<S>(base, step, &taps.dxy[0]),
                        box4::<S>(base, step, &taps.dxy[1]),
                    ),
                    box4::<S>(base, step, &taps.dxy[2]),
                ),
                box4::<S>(base, step, &taps.dxy[3]),
            );
            let dxx = f32x4_mul(f32x4_convert_i32x4(dxx), inv);
            let dyy = f32x4_mul(f32x4_convert_i32x4(dyy), inv);
            let dxy = f32x4_mul(f32x4_convert_i32x4(dxy), inv);
            let det = f32x4_sub(f32x4_mul(dxx, dyy), f32x4_mul(w, f32x4_mul(dxy, dxy)));
            v128_store(out.as_mut_ptr().add(k) as *mut v128, det);
            k += 4;
        }
        if k < n {
            scalar::hessian_row(ii, taps, p0 + k * step, step, &mut out[k..]);
        }
    }

    /// # Safety
    /// The engine must support SIMD128.
    #[target_feature(enable = "simd128")]
    pub unsafe fn hessian_row(
        ii: &[u32],
        taps: &HessianTaps,
        p0: usize,
        step: usize,
        out: &mut [f32],
    ) {
        check_hessian_row(ii.len(), taps, p0, step, out.len());
        match step {
            1 => hessian_row_s::<1>(ii, taps, p0, step, out),
            2 => hessian_row_s::<2>(ii, taps, p0, step, out),
            _ => hessian_row_s::<0>(ii, taps, p0, step, out),
        }
    }

    /// # Safety
    /// The engine must support SIMD128.
    #[target_feature(enable = "simd128")]
    pub unsafe fn lattice_haar(table: &[u32; 340], dx: &mut [f32; 208], dy: &mut [f32; 208]) {
        let t = table.as_ptr();
        let two = i32x4_splat(2);
        for j in 0..13 {
            for i in (0..16).step_by(4) {
                // i + 2c + 3 ≤ 12 + 4 + 3 = 19 < 20: inside the row.
                let a = |r: usize, c: usize| {
                    v128_load(t.add((j + 2 * r) * 20 + i + 2 * c) as *const v128)
                };
                let (a00, a01, a02) = (a(0, 0), a(0, 1), a(0, 2));
                let (a10, a12) = (a(1, 0), a(1, 2));
                let (a20, a21, a22) = (a(2, 0), a(2, 1), a(2, 2));
                let x = i32x4_sub(
                    i32x4_add(
                        i32x4_add(
                            i32x4_sub(i32x4_sub(a22, a02), i32x4_mul(a21, two)),
                            i32x4_mul(a01, two),
                        ),
                        a20,
                    ),
                    a00,
                );
                let y = i32x4_sub(
                    i32x4_add(
                        i32x4_add(
                            i32x4_sub(i32x4_sub(a22, i32x4_mul(a12, two)), a20),
                            i32x4_mul(a10, two),
                        ),
                        a02,
                    ),
                    a00,
                );
                v128_store(
                    dx.as_mut_ptr().add(j * 16 + i) as *mut v128,
                    f32x4_convert_i32x4(x),
                );
                v128_store(
                    dy.as_mut_ptr().add(j * 16 + i) as *mut v128,
                    f32x4_convert_i32x4(y),
                );
            }
        }
    }

    /// # Safety
    /// The engine must support SIMD128.
    #[target_feature(enable = "simd128")]
    pub unsafe fn patch_box_sums(
        ii: &[u32],
        w: usize,
        h: usize,
        g: &PatchGeometry,
        out: &mut [f32; 441],
    ) {
        check_patch(ii.len(), w, h);
        let p = ii.as_ptr();
        let (x0, y0) = (f32x4_splat(g.x0), f32x4_splat(g.y0));
        let (cs, sn, sv) = (f32x4_splat(g.cos), f32x4_splat(g.sin), f32x4_splat(g.s));
        let (zero, wv, hv) = (i32x4_splat(0), i32x4_splat(w as i32), i32x4_splat(h as i32));
        let (st, nv) = (i32x4_splat((w + 1) as i32), i32x4_splat(g.n as i32));
        let clamp = |v: v128, max: v128| i32x4_min(i32x4_max(v, zero), max);
        let lane = |v: v128| {
            [
                i32x4_extract_lane::<0>(v) as usize,
                i32x4_extract_lane::<1>(v) as usize,
                i32x4_extract_lane::<2>(v) as usize,
                i32x4_extract_lane::<3>(v) as usize,
            ]
        };
        let gather = |c: [usize; 4]| u32x4(*p.add(c[0]), *p.add(c[1]), *p.add(c[2]), *p.add(c[3]));
        for j in 0..21 {
            let v = f32x4_splat((j as f32 - 10.0) * g.s);
            // Columns 0..20 in vectors, column 20 with the last vector
            // shifted to 17..=20 (its first three lanes recompute 17..=19).
            for i in [0usize, 4, 8, 12, 16, 17] {
                let idx = f32x4(
                    i as f32 - 10.0,
                    i as f32 - 9.0,
                    i as f32 - 8.0,
                    i as f32 - 7.0,
                );
                let u = f32x4_mul(idx, sv);
                let x = f32x4_nearest(f32x4_sub(f32x4_add(x0, f32x4_mul(u, cs)), f32x4_mul(v, sn)));
                let y = f32x4_nearest(f32x4_add(f32x4_add(y0, f32x4_mul(u, sn)), f32x4_mul(v, cs)));
                let (x, y) = (i32x4_trunc_sat_f32x4(x), i32x4_trunc_sat_f32x4(y));
                let (xa, xb) = (clamp(x, wv), clamp(i32x4_add(x, nv), wv));
                let (ya, yb) = (
                    i32x4_mul(clamp(y, hv), st),
                    i32x4_mul(clamp(i32x4_add(y, nv), hv), st),
                );
                let sum = i32x4_add(
                    i32x4_sub(
                        i32x4_sub(
                            gather(lane(i32x4_add(yb, xb))),
                            gather(lane(i32x4_add(ya, xb))),
                        ),
                        gather(lane(i32x4_add(yb, xa))),
                    ),
                    gather(lane(i32x4_add(ya, xa))),
                );
                v128_store(
                    out.as_mut_ptr().add(j * 21 + i) as *mut v128,
                    f32x4_convert_i32x4(sum),
                );
            }
        }
    }

    /// # Safety
    /// The engine must support SIMD128.
    #[target_feature(enable = "simd128")]
    pub unsafe fn patch_box_sums_inside(
        ii: &[u32],
        stride: usize,
        g: &PatchGeometry,
        out: &mut [f32; 441],
    ) {
        let limit = inside_limit(ii.len(), stride, g.n);
        let (r, c1) = (g.n * stride, g.n);
        let p = ii.as_ptr();
        let (x0, y0) = (f32x4_splat(g.x0), f32x4_splat(g.y0));
        let (cs, sn, sv) = (f32x4_splat(g.cos), f32x4_splat(g.sin), f32x4_splat(g.s));
        let (zero, lim, st) = (
            i32x4_splat(0),
            i32x4_splat(limit),
            i32x4_splat(stride as i32),
        );
        for j in 0..21 {
            let v = f32x4_splat((j as f32 - 10.0) * g.s);
            // Columns 0..20 in vectors, column 20 with the last vector
            // shifted to 17..=20 (its first three lanes recompute 17..=19).
            for i in [0usize, 4, 8, 12, 16, 17] {
                let idx = f32x4(
                    i as f32 - 10.0,
                    i as f32 - 9.0,
                    i as f32 - 8.0,
                    i as f32 - 7.0,
                );
                let u = f32x4_mul(idx, sv);
                let x = f32x4_nearest(f32x4_sub(f32x4_add(x0, f32x4_mul(u, cs)), f32x4_mul(v, sn)));
                let y = f32x4_nearest(f32x4_add(f32x4_add(y0, f32x4_mul(u, sn)), f32x4_mul(v, cs)));
                let (x, y) = (i32x4_trunc_sat_f32x4(x), i32x4_trunc_sat_f32x4(y));
                let c = i32x4_min(i32x4_max(i32x4_add(i32x4_mul(y, st), x), zero), lim);
                let b = [
                    p.add(i32x4_extract_lane::<0>(c) as usize),
                    p.add(i32x4_extract_lane::<1>(c) as usize),
                    p.add(i32x4_extract_lane::<2>(c) as usize),
                    p.add(i32x4_extract_lane::<3>(c) as usize),
                ];
                let g4 = |o: usize| u32x4(*b[0].add(o), *b[1].add(o), *b[2].add(o), *b[3].add(o));
                let sum = i32x4_add(i32x4_sub(i32x4_sub(g4(r + c1), g4(c1)), g4(r)), g4(0));
                v128_store(
                    out.as_mut_ptr().add(j * 21 + i) as *mut v128,
                    f32x4_convert_i32x4(sum),
                );
            }
        }
    }

    /// # Safety
    /// The engine must support SIMD128.
    #[target_feature(enable = "simd128")]
    pub unsafe fn orientation_bins(
        w: &[f32],
        dx: &[f32],
        dy: &[f32],
        bins: usize,
        gx: &mut [f32],
        gy: &mut [f32],
        bin: &mut [u32],
    ) {
        use std::f32::consts::{FRAC_PI_2, PI};
        let n = check_bins(w, dx, dy, bins, gx, gy, bin);
        let to_bin = f32x4_splat(bins as f32 / std::f32::consts::TAU);
        let (zero, nb, top) = (
            f32x4_splat(0.0),
            f32x4_splat(bins as f32),
            u32x4_splat(bins as u32 - 1),
        );
        let sign = u32x4_splat(0x8000_0000);
        let c = [
            f32x4_splat(0.020_835_1),
            f32x4_splat(-0.085_133),
            f32x4_splat(0.180_141),
            f32x4_splat(-0.330_299_5),
            f32x4_splat(0.999_866),
        ];
        let mut i = 0;
        while i + 4 <= n {
            let wi = v128_load(w.as_ptr().add(i) as *const v128);
            let x = f32x4_mul(wi, v128_load(dx.as_ptr().add(i) as *const v128));
            let y = f32x4_mul(wi, v128_load(dy.as_ptr().add(i) as *const v128));
            v128_store(gx.as_mut_ptr().add(i) as *mut v128, x);
            v128_store(gy.as_mut_ptr().add(i) as *mut v128, y);
            let (ax, ay) = (f32x4_abs(x), f32x4_abs(y));
            let (num, den) = (f32x4_min(ax, ay), f32x4_max(ax, ay));
            let a = v128_bitselect(f32x4_div(num, den), zero, f32x4_gt(den, zero));
            let a2 = f32x4_mul(a, a);
            let mut p = c[0];
            for ck in &c[1..] {
                p = f32x4_add(f32x4_mul(p, a2), *ck);
            }
            let r = f32x4_mul(p, a);
            let r = v128_bitselect(f32x4_sub(f32x4_splat(FRAC_PI_2), r), r, f32x4_gt(ay, ax));
            let r = v128_bitselect(f32x4_sub(f32x4_splat(PI), r), r, f32x4_lt(x, zero));
            let r = v128_or(r, v128_and(y, sign)); // r ≥ 0: copysign(r, y)
            let a = f32x4_mul(r, to_bin);
            let a = v128_bitselect(f32x4_add(a, nb), a, f32x4_lt(a, zero));
            let b = u32x4_min(u32x4_trunc_sat_f32x4(a), top);
            v128_store(bin.as_mut_ptr().add(i) as *mut v128, b);
            i += 4;
        }
        if i < n {
            scalar::orientation_bins(
                &w[i..n],
                &dx[i..],
                &dy[i..],
                bins,
                &mut gx[i..],
                &mut gy[i..],
                &mut bin[i..],
            );
        }
    }

    /// # Safety
    /// The engine must support SIMD128.
    #[target_feature(enable = "simd128")]
    pub unsafe fn patch_wavelets(
        patch: &[f32; 441],
        w: &[f32; 400],
        du: &mut [f32; 400],
        dv: &mut [f32; 400],
    ) {
        let p = patch.as_ptr();
        for j in 0..20 {
            for i in (0..20).step_by(4) {
                let a = v128_load(p.add(j * 21 + i) as *const v128);
                let b = v128_load(p.add(j * 21 + i + 1) as *const v128);
                let c = v128_load(p.add((j + 1) * 21 + i) as *const v128);
                let d = v128_load(p.add((j + 1) * 21 + i + 1) as *const v128);
                let k = j * 20 + i;
                let wk = v128_load(w.as_ptr().add(k) as *const v128);
                let x = f32x4_mul(wk, f32x4_add(f32x4_sub(b, a), f32x4_sub(d, c)));
                let y = f32x4_mul(wk, f32x4_add(f32x4_sub(c, a), f32x4_sub(d, b)));
                v128_store(du.as_mut_ptr().add(k) as *mut v128, x);
                v128_store(dv.as_mut_ptr().add(k) as *mut v128, y);
            }
        }
    }

    /// # Safety
    /// The engine must support SIMD128.
    #[target_feature(enable = "simd128")]
    #[allow(clippy::needless_range_loop)] // b indexes both the input blocks and the accumulators
    pub unsafe fn descriptor_sums(du: &[f32; 400], dv: &[f32; 400], out: &mut [f32; 64]) {
        let (pu, pv) = (du.as_ptr(), dv.as_ptr());
        for sj in 0..4 {
            let z = f32x4_splat(0.0);
            let mut c = [[z; 5]; 4];
            for j in sj * 5..sj * 5 + 5 {
                for b in 0..5 {
                    let u = v128_load(pu.add(j * 20 + 4 * b) as *const v128);
                    let v = v128_load(pv.add(j * 20 + 4 * b) as *const v128);
                    c[0][b] = f32x4_add(c[0][b], u);
                    c[1][b] = f32x4_add(c[1][b], v);
                    c[2][b] = f32x4_add(c[2][b], f32x4_abs(u));
                    c[3][b] = f32x4_add(c[3][b], f32x4_abs(v));
                }
            }
            for q in 0..4 {
                let mut col = [0f32; 20];
                for b in 0..5 {
                    v128_store(col.as_mut_ptr().add(4 * b) as *mut v128, c[q][b]);
                }
                for si in 0..4 {
                    let s = &col[si * 5..si * 5 + 5];
                    out[(sj * 4 + si) * 4 + q] = (((s[0] + s[1]) + s[2]) + s[3]) + s[4];
                }
            }
        }
    }

    /// # Safety
    /// The engine must support SIMD128.
    #[target_feature(enable = "simd128")]
    pub unsafe fn dot64_many(query: &[f32; 64], candidates: &[[f32; 64]], out: &mut [f32]) {
        assert!(
            out.len() >= candidates.len(),
            "dot64_many: output too short"
        );
        let qp = query.as_ptr();
        let mut q = [f32x4_splat(0.0); 16];
        for (i, qi) in q.iter_mut().enumerate() {
            *qi = v128_load(qp.add(4 * i) as *const v128);
        }
        for (o, c) in out.iter_mut().zip(candidates) {
            let cp = c.as_ptr();
            let mut acc = f32x4_splat(0.0);
            for (i, qi) in q.iter().enumerate() {
                acc = f32x4_add(acc, f32x4_mul(*qi, v128_load(cp.add(4 * i) as *const v128)));
            }
            let t = f32x4_add(acc, i32x4_shuffle::<2, 3, 0, 1>(acc, acc));
            *o = f32x4_extract_lane::<0>(t) + f32x4_extract_lane::<1>(t);
        }
    }
}
