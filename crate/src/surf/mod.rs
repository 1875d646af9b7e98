//! # SURF: Speeded-Up Robust Features, read beside the paper
//!
//! This module follows H. Bay, A. Ess, T. Tuytelaars and L. Van Gool,
//! *Speeded-Up Robust Features (SURF)*, Computer Vision and Image
//! Understanding 110 (2008) 346-359, and section 5.3 of the thesis this lab
//! re-creates (H. Li, Auburn 2015), which uses SURF to find where two robots
//! saw the same place. Each stage of the paper lives in its own file, so the
//! folder reads like the algorithm:
//!
//! | file | paper | what it does |
//! |---|---|---|
//! | [`gray`] | - | the 8-bit grey image every stage reads, decoded from PNG/JPEG |
//! | [`integral`] | §2 | the integral image: any box sum in four look-ups |
//! | [`hessian`] | §3 | Fast-Hessian: box-filter det(H) scale space, non-maximum suppression, sub-pixel fit |
//! | [`orientation`] | §4.1 | the dominant orientation from Haar responses in a sliding π/3 window |
//! | [`descriptor`] | §4.2 | the 64-number descriptor: 4 × 4 sub-regions of Σdx, Σdy, Σ|dx|, Σ|dy| |
//! | [`matching`] | §4.3, §5 | nearest neighbours, Lowe's ratio, the sign of the Laplacian |
//! | [`msac`] | - | Torr and Zisserman's MSAC: homography and similarity, the matched region |
//! | [`prng`] | - | the small seeded generator that makes MSAC a function of its inputs |
//! | [`simd`] | - | the hot loops, once portable and once in wasm SIMD128 |
//!
//! ## Conventions
//! - Pixel coordinates: x right, y down, (0, 0) the **centre** of the
//!   top-left pixel (OpenCV's convention). A box filter of odd size centred on
//!   pixel (x, y) therefore has its centre exactly at (x, y).
//! - Intensities are the 8-bit grey values 0..=255, so the Hessian threshold
//!   is in the same units as OpenCV's `hessianThreshold`.
//! - `scale` is the σ of the Gaussian the box filter approximates:
//!   s = 1.2 · L / 9 for a filter of side L (the 9 × 9 filter is σ = 1.2).
//!   It is a nominal scale: a Gaussian blob of standard deviation σ_b is
//!   reported at s ≈ 0.72 σ_b (measured, `tests/surf_detect.rs`).
//! - `orientation` is in radians, measured from +x towards +y in image
//!   coordinates (so clockwise on screen), in (-π, π].
//! - `laplacian` is the sign of the trace Dxx + Dyy: +1 for a dark blob on a
//!   bright background, -1 for a bright blob on a dark one.
//!
//! ## Quick use
//! ```
//! use slamlab::surf::{extract, GrayImage, SurfConfig};
//! let img = GrayImage::new(64, 64, vec![0; 64 * 64]).unwrap();
//! let features = extract(&img, &SurfConfig::default());
//! assert!(features.keypoints.is_empty()); // a constant image has no blobs
//! ```

pub mod descriptor;
pub mod gray;
pub mod hessian;
pub mod integral;
pub mod matching;
pub mod msac;
pub mod orientation;
pub mod prng;
pub mod simd;

pub use descriptor::Descriptor;
pub use gray::{GrayImage, SurfError};
pub use hessian::FastHessian;
pub use integral::IntegralImage;
pub use matching::{match_features, Match, MatchConfig};
pub use msac::{
    fit_homography, fit_similarity, Homography, MatchedRegion, MsacConfig, MsacFit, Similarity,
};

/// Settings of the detector and descriptor. `SurfConfig::default()` is what
/// the CLI's `features` command and the lab use.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfConfig {
    /// Minimum det(H) (box responses normalised by filter area, intensities
    /// 0..=255, the units of OpenCV's `hessianThreshold`) of a keypoint.
    /// Default 10.0: 700-1000 keypoints on the 640 × 480 test photographs.
    /// Lower finds more, weaker blobs.
    pub threshold: f32,
    /// Number of octaves, each doubling the filter-size increment and the
    /// sampling step. Default 4 (filters up to 195 pixels).
    pub octaves: usize,
    /// Filter sizes per octave (the paper's 4: 9, 15, 21, 27 in the first).
    /// Maxima are searched in the inner `intervals - 2` layers. Default 4.
    pub intervals: usize,
    /// Sampling step of the first octave in pixels; it doubles every octave.
    /// Default 2, as in Bay's original implementation (1 is OpenCV's choice:
    /// finer localisation of the smallest blobs, about three times the work).
    pub initial_step: usize,
    /// U-SURF: skip the orientation assignment and describe every keypoint
    /// in the image axes (paper §4.1, last paragraph). Default false.
    pub upright: bool,
}

impl Default for SurfConfig {
    fn default() -> Self {
        SurfConfig {
            threshold: 10.0,
            octaves: 4,
            intervals: 4,
            initial_step: 2,
            upright: false,
        }
    }
}

/// One interest point (see the module doc for the conventions).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Keypoint {
    /// Column in pixels, 0 at the centre of the left-most pixel.
    pub x: f32,
    /// Row in pixels, 0 at the centre of the top-most pixel.
    pub y: f32,
    /// σ of the approximated Gaussian, in pixels (1.2 for the 9 × 9 filter).
    pub scale: f32,
    /// Dominant orientation in radians (0 for upright keypoints).
    pub orientation: f32,
    /// Sign of the Laplacian: +1 (dark blob) or -1 (bright blob).
    pub laplacian: i8,
    /// det(H) at the keypoint (its strength).
    pub response: f32,
}

/// Keypoints and their descriptors, index for index.
#[derive(Clone, Debug, Default)]
pub struct Features {
    pub keypoints: Vec<Keypoint>,
    pub descriptors: Vec<Descriptor>,
}

impl Features {
    pub fn len(&self) -> usize {
        self.keypoints.len()
    }
    pub fn is_empty(&self) -> bool {
        self.keypoints.is_empty()
    }
}

/// The whole pipeline on one image: integral image, Fast-Hessian detection,
/// orientation (unless `upright`) and description. Never panics: an image
/// too small for the 9 × 9 filter, or without contrast, gives no keypoints.
pub fn extract(image: &GrayImage, config: &SurfConfig) -> Features {
    let integral = IntegralImage::new(image);
    extract_from_integral(&integral, config)
}

/// [`extract`] for an integral image already built (the lab reuses it).
pub fn extract_from_integral(integral: &IntegralImage, config: &SurfConfig) -> Features {
    let mut keypoints = FastHessian::new(config).detect(integral);
    if !config.upright {
        orientation::assign_orientations(integral, &mut keypoints);
    }
    let descriptors = descriptor::describe_all(integral, &keypoints);
    Features {
        keypoints,
        descriptors,
    }
}
