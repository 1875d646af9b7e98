//! # The SURF descriptor (paper §4.2)
//!
//! Around each keypoint Bay et al. lay a square of side 20s (s the
//! keypoint's scale), turned to the keypoint's orientation, and split it
//! into 4 × 4 sub-regions. In each sub-region, 5 × 5 regularly spaced sample
//! points get Haar wavelet responses of side 2s: dx along the keypoint's
//! orientation and dy across it. Each sub-region contributes four numbers,
//!
//! ```text
//!   v = ( Σ dx, Σ dy, Σ |dx|, Σ |dy| )
//! ```
//!
//! so the descriptor has 4 × 4 × 4 = 64 entries. The sums tell the
//! polarity and the amount of intensity change in each direction: a uniform
//! region has all four small, stripes across x have a large Σ|dx| but a
//! small Σdx, a ramp has both large. Responses are first weighted with a
//! Gaussian of σ = 3.3s centred on the keypoint (robustness to
//! misregistration), and the vector is finally scaled to unit length
//! (invariance to contrast). Adding a constant brightness changes nothing,
//! since wavelets respond only to differences.
//!
//! Implementation (as in OpenCV, an equivalent of Bay's sampling that
//! stays smooth across scales): the 20s window is first resampled, turned
//! to the keypoint's orientation, into a 21 × 21 patch whose samples lie s
//! apart and are each the sum of an s × s box ([`simd::patch_box_sums`],
//! four integral look-ups per sample). A Haar wavelet of side 2s is then just a
//! 2 × 2 block of the patch, and its responses are already in the keypoint
//! frame ([`simd::patch_wavelets`], which also applies the Gaussian). In
//! units of s the grid and the weights do not depend on the keypoint, so
//! the weights are a precomputed table. [`simd::descriptor_sums`] forms the
//! 64 sums. Near the border the boxes are clipped to the image (pixels
//! outside count as zero) by clamping their corners; patches wholly inside
//! take a faster kernel that needs no clipping.

use super::integral::IntegralImage;
use super::simd;
use super::Keypoint;

/// Samples per side of the descriptor window (20, spaced s apart).
pub const GRID: usize = 20;
/// σ of the Gaussian weight, in units of s.
pub const SIGMA: f32 = 3.3;

/// A 64-entry SURF descriptor of unit length (all zeros only for a patch
/// without any contrast). Entry `4 * (4 * row + col) + q` is sum q (Σdx,
/// Σdy, Σ|dx|, Σ|dy|) of sub-region (row, col), row 0 at the top in the
/// keypoint frame.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(16))]
pub struct Descriptor(pub [f32; 64]);

impl Default for Descriptor {
    fn default() -> Self {
        Descriptor([0.0; 64])
    }
}

impl Descriptor {
    /// Euclidean distance to `other`.
    pub fn distance(&self, other: &Descriptor) -> f32 {
        self.0
            .iter()
            .zip(&other.0)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f32>()
            .sqrt()
    }
}

/// Side of the resampled patch: 21 × 21 samples give 20 × 20 wavelets.
pub const PATCH: usize = GRID + 1;

/// Reusable buffers for describing many keypoints.
pub struct DescriptorScratch {
    weights: [f32; GRID * GRID],
    patch: [f32; PATCH * PATCH],
    du: [f32; GRID * GRID],
    dv: [f32; GRID * GRID],
}

impl Default for DescriptorScratch {
    fn default() -> Self {
        let mut weights = [0f32; GRID * GRID];
        for j in 0..GRID {
            for i in 0..GRID {
                let (u, v) = (i as f32 - 9.5, j as f32 - 9.5);
                weights[j * GRID + i] = (-(u * u + v * v) / (2.0 * SIGMA * SIGMA)).exp();
            }
        }
        DescriptorScratch {
            weights,
            patch: [0.0; PATCH * PATCH],
            du: [0.0; GRID * GRID],
            dv: [0.0; GRID * GRID],
        }
    }
}

/// Describes every keypoint (their orientation must already be set; 0 for
/// U-SURF).
pub fn describe_all(ii: &IntegralImage, keypoints: &[Keypoint]) -> Vec<Descriptor> {
    let mut scratch = Box::<DescriptorScratch>::default();
    keypoints
        .iter()
        .map(|kp| describe(ii, kp, &mut scratch))
        .collect()
}

/// The descriptor of one keypoint.
pub fn describe(ii: &IntegralImage, kp: &Keypoint, scratch: &mut DescriptorScratch) -> Descriptor {
    let s = kp.scale;
    // Each patch sample is the sum of an n × n box, n ≈ s.
    let n = (s.round_ties_even() as i64).max(1) as usize;
    let (sin, cos) = kp.orientation.sin_cos();
    // Top-left integral corner of a box of side n centred on pixel position p:
    // the box's left edge is at p + 0.5 - n/2 in corner coordinates.
    let edge = 0.5 - n as f32 / 2.0;
    let g = simd::PatchGeometry {
        x0: kp.x + edge,
        y0: kp.y + edge,
        cos,
        sin,
        s,
        n,
    };
    // Farthest a box reaches from the keypoint: the patch's half diagonal
    // plus the box side, plus two for rounding.
    let reach = (10.0 * std::f32::consts::SQRT_2 * s).ceil() + n as f32 + 2.0;
    let (w, h) = (ii.width() as f32, ii.height() as f32);
    if kp.x - reach >= 0.0 && kp.y - reach >= 0.0 && kp.x + reach <= w && kp.y + reach <= h {
        simd::patch_box_sums_inside(ii.data(), ii.stride(), &g, &mut scratch.patch);
    } else {
        simd::patch_box_sums(ii.data(), ii.width(), ii.height(), &g, &mut scratch.patch);
    }
    simd::patch_wavelets(
        &scratch.patch,
        &scratch.weights,
        &mut scratch.du,
        &mut scratch.dv,
    );
    let mut d = Descriptor::default();
    simd::descriptor_sums(&scratch.du, &scratch.dv, &mut d.0);
    let norm = d.0.iter().map(|v| v * v).sum::<f32>().sqrt();
    if norm > 0.0 && norm.is_finite() {
        let inv = 1.0 / norm;
        d.0.iter_mut().for_each(|v| *v *= inv);
    } else {
        d = Descriptor::default();
    }
    d
}
