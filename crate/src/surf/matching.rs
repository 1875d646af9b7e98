//! # Matching descriptors (paper §4.3 and §5; thesis §5.3.4)
//!
//! Two keypoints correspond when their descriptors are close in Euclidean
//! distance. For each keypoint of the first image we find the nearest and
//! second-nearest descriptor in the second image and keep the pair only if
//!
//! ```text
//!   d(nearest) < ratio · d(second nearest)           (Lowe 2004, ratio 0.8)
//! ```
//!
//! which discards ambiguous matches on repeated texture far better than a
//! fixed distance threshold. Bay et al. add a free test (§4.3): blobs of
//! opposite contrast (a dark blob on light ground and a light blob on dark
//! ground) can never correspond, so only keypoints with the same sign of the
//! Laplacian are compared. That halves the work and removes mismatches. An
//! optional mutual check keeps a pair only if each is the other's nearest.
//!
//! Descriptors have unit length, so ‖a - b‖² = 2 - 2 a·b: the search is a
//! brute-force run of 64-d dot products ([`simd::dot64_many`]), one
//! query against every candidate of the same Laplacian sign.

use super::descriptor::Descriptor;
use super::simd;
use super::Features;

/// Matching settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MatchConfig {
    /// Lowe's ratio: keep a match if nearest < ratio × second nearest. Default 0.8.
    pub ratio: f32,
    /// Compare only keypoints with the same sign of the Laplacian. Default true.
    pub laplacian_gating: bool,
    /// Keep a pair only when each is the other's nearest neighbour. Default false.
    pub mutual: bool,
}

impl Default for MatchConfig {
    fn default() -> Self {
        MatchConfig {
            ratio: 0.8,
            laplacian_gating: true,
            mutual: false,
        }
    }
}

/// A correspondence: keypoint `query` of the first image and `train` of the
/// second, with their descriptor distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Match {
    pub query: usize,
    pub train: usize,
    pub distance: f32,
}

/// Candidates of one Laplacian sign: contiguous descriptors and their
/// indices in the second image.
struct Group {
    descriptors: Vec<[f32; 64]>,
    index: Vec<usize>,
}

fn groups(features: &Features, gating: bool) -> [Group; 2] {
    let mut g = [
        Group {
            descriptors: Vec::new(),
            index: Vec::new(),
        },
        Group {
            descriptors: Vec::new(),
            index: Vec::new(),
        },
    ];
    for (i, (kp, d)) in features
        .keypoints
        .iter()
        .zip(&features.descriptors)
        .enumerate()
    {
        let which = usize::from(gating && kp.laplacian < 0);
        g[which].descriptors.push(d.0);
        g[which].index.push(i);
    }
    g
}

/// Matches `a` against `b` (see the module doc). Results are in order of
/// `query`.
pub fn match_features(a: &Features, b: &Features, config: &MatchConfig) -> Vec<Match> {
    let groups = groups(b, config.laplacian_gating);
    let mut dots = vec![0f32; b.len()];
    // For the mutual check: best (dot, query) seen by each train keypoint.
    let mut reverse = vec![(f32::NEG_INFINITY, usize::MAX); b.len()];
    let mut matches = Vec::new();
    let ratio2 = config.ratio * config.ratio;
    for (qi, (kp, d)) in a.keypoints.iter().zip(&a.descriptors).enumerate() {
        if d == &Descriptor::default() {
            continue;
        }
        let g = &groups[usize::from(config.laplacian_gating && kp.laplacian < 0)];
        let n = g.descriptors.len();
        if n == 0 {
            continue;
        }
        simd::dot64_many(&d.0, &g.descriptors, &mut dots[..n]);
        let (mut best, mut second, mut best_j) = (f32::NEG_INFINITY, f32::NEG_INFINITY, 0);
        for (j, &dot) in dots[..n].iter().enumerate() {
            if dot > best {
                second = best;
                best = dot;
                best_j = j;
            } else if dot > second {
                second = dot;
            }
            if config.mutual {
                let r = &mut reverse[g.index[j]];
                if dot > r.0 {
                    *r = (dot, qi);
                }
            }
        }
        let d1 = (2.0 - 2.0 * best).max(0.0);
        let d2 = (2.0 - 2.0 * second).max(0.0);
        if n >= 2 && d1 < ratio2 * d2 {
            matches.push(Match {
                query: qi,
                train: g.index[best_j],
                distance: d1.sqrt(),
            });
        }
    }
    if config.mutual {
        matches.retain(|m| reverse[m.train].1 == m.query);
    }
    matches
}
