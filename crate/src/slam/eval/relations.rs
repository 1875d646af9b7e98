//! # Scoring a trajectory by relation errors, and drifting odometry
//!
//! R. Kümmerle, B. Steder, C. Dornhege, M. Ruhnke, G. Grisetti,
//! C. Stachniss, A. Kleiner, "On measuring the accuracy of SLAM
//! algorithms", Autonomous Robots 27(4), 2009. A real log has no ground
//! truth for absolute poses, and an absolute error (ATE) punishes an early
//! heading error everywhere after it. Kümmerle et al. compare *relations*
//! instead: for pairs of scans `(i, j)` the relative pose `δ_ij = x_i⁻¹ ⊕
//! x_j` of the estimate against the reference's `δ*_ij`:
//!
//! ```text
//! ε(δ) = (1 / N) Σ_ij |trans(δ_ij ⊖ δ*_ij)|   and the same for rotation
//! ```
//!
//! Pairs `k` scans apart (k = 1, 5, 20, 50, 100) measure local accuracy at
//! growing scales; random far pairs measure global consistency (whether
//! the loops were closed). This is a scoring tool: the SLAM never sees it.
//!
//! ## Drifting odometry
//!
//! The corrected logs carry GMapping's poses as their odometry. To test a
//! SLAM against drift, [`drift_odometry`] makes odometry from a reference
//! trajectory with a seeded, documented noise model, step by step: with the
//! reference step `δ = (dx, dy, dθ)` of length `d`,
//!
//! ```text
//! dx' = (1 + s)·dx + σ_t·d·g₁        dy' = (1 + s)·dy + σ_t·d·g₂
//! dθ' = dθ + σ_r·|dθ|·g₃ + σ_h·d·g₄ + b·d
//! ```
//!
//! with `g` standard normal draws, `σ_t` the translational noise per metre,
//! `σ_r` the rotational noise per radian turned, `σ_h` the heading noise
//! per metre driven and `b` a heading bias per metre (an unequal wheel
//! diameter): the classic odometry error model of *Probabilistic
//! Robotics* §5.4 plus a systematic term. `s` is a distance error (a wheel
//! radius off by that fraction), 0 by default: the raw MIT CSAIL log's
//! wheels read about 2 % short of GMapping's path (over 369 m of
//! odometry, 377 m of GMapping's poses), and a method that trusts the
//! odometry along a corridor should be measured with it.

use crate::geom::{wrap_angle, Pose2};
use crate::rng::Rng;

/// The noise model of [`drift_odometry`].
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct DriftModel {
    /// Translational noise per metre (σ_t).
    pub trans_per_m: f64,
    /// Rotational noise per radian turned (σ_r).
    pub rot_per_rad: f64,
    /// Heading noise per metre driven (σ_h, rad/m).
    pub heading_per_m: f64,
    /// Heading bias per metre driven (b, rad/m).
    pub bias_rad_per_m: f64,
    /// Distance error (s: the odometry reads `1 + s` times each true
    /// step; a wheel radius off by that fraction).
    pub distance_error: f64,
}

impl Default for DriftModel {
    fn default() -> Self {
        DriftModel {
            trans_per_m: 0.05,
            rot_per_rad: 0.05,
            heading_per_m: 0.01,
            bias_rad_per_m: 0.3f64.to_radians(),
            distance_error: 0.0,
        }
    }
}

/// Odometry with drift, made from `reference` (see the module doc); starts
/// at the reference's first pose.
pub fn drift_odometry(reference: &[Pose2], model: &DriftModel, seed: u64) -> Vec<Pose2> {
    let mut rng = Rng::new(seed);
    let mut out = Vec::with_capacity(reference.len());
    let Some(&first) = reference.first() else {
        return out;
    };
    out.push(first);
    let mut odom = first;
    for w in reference.windows(2) {
        let d = w[0].between(&w[1]);
        let len = d.position().length();
        let step = Pose2::new(
            d.x * (1.0 + model.distance_error) + model.trans_per_m * len * rng.gaussian(),
            d.y * (1.0 + model.distance_error) + model.trans_per_m * len * rng.gaussian(),
            wrap_angle(
                d.theta
                    + model.rot_per_rad * d.theta.abs() * rng.gaussian()
                    + model.heading_per_m * len * rng.gaussian()
                    + model.bias_rad_per_m * len,
            ),
        );
        odom = odom.compose(&step);
        out.push(odom);
    }
    out
}

/// Mean relation errors of one set of pairs.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct RelationErrors {
    /// `"k=1"`, …, `"random"` or `"all"`.
    pub pairs_of: String,
    pub pairs: usize,
    pub trans_m: f64,
    pub rot_deg: f64,
}

/// The error of the estimate's relation `(i, j)` against the reference's:
/// (translation m, rotation rad, both absolute).
pub fn relation_error(est: &[Pose2], reference: &[Pose2], i: usize, j: usize) -> (f64, f64) {
    let de = est[i].between(&est[j]);
    let dr = reference[i].between(&reference[j]);
    let e = dr.between(&de);
    (e.position().length(), wrap_angle(e.theta).abs())
}

fn mean_of(
    label: String,
    pairs: &[(usize, usize)],
    est: &[Pose2],
    reference: &[Pose2],
) -> RelationErrors {
    let (mut t, mut r) = (0.0, 0.0);
    for &(i, j) in pairs {
        let (et, er) = relation_error(est, reference, i, j);
        t += et;
        r += er;
    }
    let n = pairs.len().max(1) as f64;
    RelationErrors {
        pairs_of: label,
        pairs: pairs.len(),
        trans_m: t / n,
        rot_deg: (r / n).to_degrees(),
    }
}

/// Relation errors of `est` against `reference` (same length, same scans):
/// pairs `k` apart for k = 1, 5, 20, 50, 100 (those the trajectory is long
/// enough for), `random_pairs` random far pairs (at least a tenth of the
/// trajectory apart, drawn with `seed`), and all of them pooled (`"all"`,
/// last).
pub fn relation_errors(
    est: &[Pose2],
    reference: &[Pose2],
    random_pairs: usize,
    seed: u64,
) -> Vec<RelationErrors> {
    assert_eq!(
        est.len(),
        reference.len(),
        "one estimate per reference pose"
    );
    let n = est.len();
    let mut out = Vec::new();
    let mut all = Vec::new();
    for k in [1usize, 5, 20, 50, 100] {
        if k >= n {
            continue;
        }
        let pairs: Vec<(usize, usize)> = (0..n - k).map(|i| (i, i + k)).collect();
        out.push(mean_of(format!("k={k}"), &pairs, est, reference));
        all.extend(pairs);
    }
    let gap = (n / 10).max(1);
    if n > gap + 1 {
        let mut rng = Rng::new(seed);
        let mut pairs = Vec::with_capacity(random_pairs);
        while pairs.len() < random_pairs {
            let i = (rng.uniform() * n as f64) as usize % n;
            let j = (rng.uniform() * n as f64) as usize % n;
            let (i, j) = (i.min(j), i.max(j));
            if j - i >= gap {
                pairs.push((i, j));
            }
        }
        out.push(mean_of("random".into(), &pairs, est, reference));
        all.extend(pairs);
    }
    out.push(mean_of("all".into(), &all, est, reference));
    out
}
