//! # A rigid transform between two point sets, robustly (MSAC)
//!
//! Matched keypoints lifted into two maps ([`super::lift`]) give pairs
//! `(aᵢ, bᵢ)`: the same bit of wall in map A and in map B. If the match is
//! right, `aᵢ ≈ T(bᵢ) = R(θ)·bᵢ + t` for the one rigid transform `T` that
//! carries B's map frame into A's (a [`Pose2`]: B's frame seen from A's).
//! Two things make the fit hard: some matches are wrong (repeated texture,
//! similar blobs), and every point is a little noisy (laser range noise,
//! a pixel of bearing, the SLAM poses).
//!
//! ## Least squares (the refit)
//! With correspondences known, the best rotation and translation in the
//! least-squares sense have a closed form (the 2-D case of Arun, Huang and
//! Blostein, *Least-squares fitting of two 3-D point sets*, PAMI 1987, and
//! of Umeyama 1991 without scale): centre both sets on their centroids
//! `ā`, `b̄`, then
//!
//! ```text
//! θ = atan2( Σ (b'ᵢ × a'ᵢ), Σ (b'ᵢ · a'ᵢ) )       a' = a − ā, b' = b − b̄
//! t = ā − R(θ)·b̄
//! ```
//!
//! (the 2-D cross product `p × q = pₓq_y − p_yqₓ`). It needs two distinct
//! points; it fails (returns `None`) when all points of B coincide.
//!
//! ## MSAC (the robust part)
//! Torr and Zisserman's MSAC (*MLESAC*, CVIU 78 (2000) 138-156), as in
//! [`crate::surf::msac`], with the rigid transform's *2-point* minimal
//! sample. A sample whose two points are closer than `min_sample_span_m`
//! is skipped (its angle would be noise), and so is one whose two distances
//! `|a₀a₁|` and `|b₀b₁|` differ by more than the inlier threshold: a rigid
//! motion keeps distances, so such a sample holds a wrong match. Each
//! hypothesis is scored by `C = Σ min(eᵢ², T²)` with `eᵢ = |aᵢ − T(bᵢ)|`,
//! and the loop stops early once another all-inlier sample is unlikely to
//! be missed: `N = ln(1 − p) / ln(1 − w²)`. The winner is refitted by least
//! squares on its inliers, inliers re-selected, twice.
//!
//! The samples come from [`SplitMix64`] seeded by the caller, so a fit is a
//! function of its inputs and the seed.

use crate::geom::{cross, Pose2};
use crate::surf::prng::SplitMix64;
use glam::DVec2;

/// Settings of [`fit_rigid_msac`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidConfig {
    /// Inlier threshold on `|a − T(b)|`, metres. Default 0.08: laser noise
    /// (1 cm), a pixel of bearing at 4 m (1.4 cm) and interpolation on
    /// slanted walls stay well inside it.
    pub threshold_m: f64,
    /// Upper bound on hypotheses. Default 500.
    pub max_iterations: usize,
    /// Probability of drawing one all-inlier sample. Default 0.999.
    pub confidence: f64,
    /// Fewer inliers and no fit is returned. Default 5.
    pub min_inliers: usize,
    /// The two points of a sample must be at least this far apart, metres.
    /// Default 0.3.
    pub min_sample_span_m: f64,
    /// The inliers must spread at least this far from their centroid (RMS,
    /// metres), or the fit is degenerate: all points within a few
    /// centimetres fix no angle. Default 0.25.
    pub min_spread_m: f64,
}

impl Default for RigidConfig {
    fn default() -> Self {
        RigidConfig {
            threshold_m: 0.08,
            max_iterations: 500,
            confidence: 0.999,
            min_inliers: 5,
            min_sample_span_m: 0.3,
            min_spread_m: 0.25,
        }
    }
}

/// A robust fit: `a[i] ≈ pose.transform_point(b[i])` for `i` in `inliers`.
#[derive(Clone, Debug, PartialEq)]
pub struct RigidFit {
    pub pose: Pose2,
    /// Indices into the point lists, ascending.
    pub inliers: Vec<usize>,
    /// RMS of `|a − T(b)|` over the inliers, metres.
    pub rms_m: f64,
}

/// The least-squares rigid transform with `a[i] ≈ T(b[i])` over all pairs
/// (see the module doc). `None` with no pairs, non-finite input, or when
/// B's points all coincide (no angle is defined).
pub fn fit_rigid_least_squares(a: &[DVec2], b: &[DVec2]) -> Option<Pose2> {
    let n = a.len().min(b.len());
    if n == 0 {
        return None;
    }
    let (a, b) = (&a[..n], &b[..n]);
    let ca = a.iter().copied().sum::<DVec2>() / n as f64;
    let cb = b.iter().copied().sum::<DVec2>() / n as f64;
    if !ca.is_finite() || !cb.is_finite() {
        return None;
    }
    let (mut sin_sum, mut cos_sum, mut spread) = (0.0, 0.0, 0.0);
    for (&p, &q) in a.iter().zip(b) {
        let (pa, qb) = (p - ca, q - cb);
        sin_sum += cross(qb, pa);
        cos_sum += qb.dot(pa);
        spread += qb.length_squared();
    }
    if spread < 1e-12 || sin_sum.hypot(cos_sum) < 1e-12 {
        return None;
    }
    let theta = sin_sum.atan2(cos_sum);
    let t = ca - DVec2::from_angle(theta).rotate(cb);
    Some(Pose2::new(t.x, t.y, theta))
}

/// Squared residuals of every pair under `pose`.
fn residuals2<'a>(a: &'a [DVec2], b: &'a [DVec2], pose: &Pose2) -> impl Iterator<Item = f64> + 'a {
    let pose = *pose;
    a.iter()
        .zip(b)
        .map(move |(&p, &q)| (p - pose.transform_point(q)).length_squared())
}

/// MSAC cost and inlier count.
fn score(a: &[DVec2], b: &[DVec2], pose: &Pose2, t2: f64) -> (f64, usize) {
    residuals2(a, b, pose).fold((0.0, 0), |(c, n), e2| {
        if e2 < t2 {
            (c + e2, n + 1)
        } else {
            (c + t2, n)
        }
    })
}

/// Hypotheses needed to draw one all-inlier 2-point sample with
/// probability `confidence` when a share `w` of pairs are inliers.
fn needed_iterations(w: f64, confidence: f64, max: usize) -> usize {
    let good = w * w;
    if good >= 1.0 - 1e-12 {
        return 1;
    }
    if good <= 1e-12 {
        return max;
    }
    let n = (1.0 - confidence).ln() / (1.0 - good).ln();
    if n.is_finite() {
        (n.ceil() as usize).clamp(1, max)
    } else {
        max
    }
}

/// RMS distance of points from their centroid.
fn spread_m(points: &[DVec2]) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    let c = points.iter().copied().sum::<DVec2>() / points.len() as f64;
    (points
        .iter()
        .map(|p| (*p - c).length_squared())
        .sum::<f64>()
        / points.len() as f64)
        .sqrt()
}

/// Robust rigid fit with `a[i] ≈ pose.transform_point(b[i])` (see the
/// module doc). `None` with fewer than `min_inliers` (at least 2) pairs or
/// inliers, when no sample is usable, or when the inliers are degenerate
/// (spread less than `min_spread_m`).
pub fn fit_rigid_msac(a: &[DVec2], b: &[DVec2], cfg: &RigidConfig, seed: u64) -> Option<RigidFit> {
    let n = a.len().min(b.len());
    let min_inliers = cfg.min_inliers.max(2);
    if n < min_inliers {
        return None;
    }
    let (a, b) = (&a[..n], &b[..n]);
    if a.iter().chain(b).any(|p| !p.is_finite()) {
        return None;
    }
    let t2 = cfg.threshold_m * cfg.threshold_m;
    let span2 = cfg.min_sample_span_m * cfg.min_sample_span_m;
    let mut rng = SplitMix64::new(seed);
    let mut best: Option<(f64, Pose2)> = None;
    let mut needed = cfg.max_iterations;
    let mut it = 0;
    while it < needed.max(1) && it < cfg.max_iterations {
        it += 1;
        let [i, j] = rng.distinct::<2>(n);
        let (db, da) = (b[j] - b[i], a[j] - a[i]);
        if db.length_squared() < span2 || (db.length() - da.length()).abs() > cfg.threshold_m {
            continue;
        }
        let theta = cross(db, da).atan2(db.dot(da));
        let mid_a = (a[i] + a[j]) * 0.5;
        let mid_b = (b[i] + b[j]) * 0.5;
        let t = mid_a - DVec2::from_angle(theta).rotate(mid_b);
        let pose = Pose2::new(t.x, t.y, theta);
        let (cost, inl) = score(a, b, &pose, t2);
        if best.as_ref().is_none_or(|(c, _)| cost < *c) {
            needed = needed_iterations(inl as f64 / n as f64, cfg.confidence, cfg.max_iterations);
            best = Some((cost, pose));
        }
    }
    let (mut cost, mut pose) = best?;
    // Least-squares refit on the inliers, re-selecting them in between.
    for _ in 0..2 {
        let inl: Vec<usize> = residuals2(a, b, &pose)
            .enumerate()
            .filter(|&(_, e2)| e2 < t2)
            .map(|(i, _)| i)
            .collect();
        let pa: Vec<DVec2> = inl.iter().map(|&i| a[i]).collect();
        let pb: Vec<DVec2> = inl.iter().map(|&i| b[i]).collect();
        let Some(refit) = fit_rigid_least_squares(&pa, &pb) else {
            break;
        };
        let (c, _) = score(a, b, &refit, t2);
        if c > cost {
            break;
        }
        (cost, pose) = (c, refit);
    }
    let inliers: Vec<usize> = residuals2(a, b, &pose)
        .enumerate()
        .filter(|&(_, e2)| e2 < t2)
        .map(|(i, _)| i)
        .collect();
    if inliers.len() < min_inliers {
        return None;
    }
    let pb: Vec<DVec2> = inliers.iter().map(|&i| b[i]).collect();
    if spread_m(&pb) < cfg.min_spread_m {
        return None;
    }
    let rms_m = (inliers
        .iter()
        .map(|&i| (a[i] - pose.transform_point(b[i])).length_squared())
        .sum::<f64>()
        / inliers.len() as f64)
        .sqrt();
    Some(RigidFit {
        pose,
        inliers,
        rms_m,
    })
}
