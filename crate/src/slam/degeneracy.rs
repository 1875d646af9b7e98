//! # Degeneracy: which directions a scan constrains
//!
//! In a long corridor with no features along it, every pose slid along the
//! corridor explains the scan equally well: the matcher's response is flat
//! in that direction, and a matcher that trusts it will *slide* (the classic
//! failure of scan matching in corridors). We detect it from the scan's
//! geometry, the same information the matcher's Hessian carries
//! (J. Zhang, M. Kaess, S. Singh, *On Degeneracy of Optimization-based State
//! Estimation Problems*, ICRA 2016): a point on a surface with unit normal
//! `n` pins the pose only along `n`, so the translational information of a
//! scan is
//!
//! ```text
//! A = Σ_i n_i n_iᵀ          (2 × 2, robot frame)
//! ```
//!
//! Its eigenvalues count, roughly, how many points constrain each principal
//! direction. A corridor gives one large eigenvalue (across) and one near
//! zero (along); an end wall or a doorway lifts the small one. When the
//! small eigenvalue is below a threshold, the mapper keeps the match's
//! correction only across the weak direction and takes odometry's word
//! along it ([`super::mapper`]).
//!
//! Normals come from each point's neighbours in beam order: the chord
//! between the nearest neighbours at least 0.1 m away on each side (closer
//! ones are dominated by range noise), skipped across depth jumps. Only
//! points that land on walls *already in the map* count: a corridor's end
//! wall seen for the first time constrains nothing until it is mapped.

use glam::DVec2;

/// How well a scan pins the robot's position, in its own frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScanConstraint {
    /// Points with a usable normal.
    pub normals: usize,
    /// Eigenvalues of `A`, largest first.
    pub strong: f64,
    pub weak: f64,
    /// Unit eigenvector of the weak eigenvalue (robot frame).
    pub weak_direction: DVec2,
}

impl ScanConstraint {
    /// Whether the weak direction is too poorly constrained to trust.
    pub fn is_degenerate(&self, min_eigenvalue: f64) -> bool {
        self.weak < min_eigenvalue
    }
}

/// Eigen-decomposition of the symmetric 2×2 `[[a, b], [b, c]]`: the
/// eigenvalues (largest first) and the unit eigenvector of the smaller.
pub fn symmetric_eigen2(a: f64, b: f64, c: f64) -> (f64, f64, DVec2) {
    let mean = 0.5 * (a + c);
    let r = (0.25 * (a - c) * (a - c) + b * b).sqrt();
    let (l1, l2) = (mean + r, mean - r);
    // (A − l2 I) v = 0: v ⟂ rows of A − l2 I.
    let v = if b.abs() > 1e-12 {
        DVec2::new(l2 - c, b)
    } else if a <= c {
        DVec2::X
    } else {
        DVec2::Y
    };
    (l1, l2, v.normalize_or(DVec2::X))
}

/// Analyses the end points of a scan, given in beam order (robot frame).
/// Only points with `counts[i]` contribute a normal (all serve as
/// neighbours).
pub fn analyse(points: &[DVec2], counts: &[bool]) -> ScanConstraint {
    const MIN_CHORD_M: f64 = 0.1;
    const MAX_GAP_M: f64 = 0.3;
    const REACH: usize = 8;
    let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
    let mut count = 0;
    for i in 0..points.len() {
        if !counts.get(i).copied().unwrap_or(false) {
            continue;
        }
        let p = points[i];
        let find = |range: &mut dyn Iterator<Item = usize>| -> Option<DVec2> {
            let mut prev = p;
            for j in range {
                let q = points[j];
                if (q - prev).length() > MAX_GAP_M {
                    return None;
                }
                if (q - p).length() >= MIN_CHORD_M {
                    return Some(q);
                }
                prev = q;
            }
            None
        };
        let before = find(&mut (i.saturating_sub(REACH)..i).rev());
        let after = find(&mut (i + 1..(i + 1 + REACH).min(points.len())));
        let (Some(q0), Some(q1)) = (before, after) else {
            continue;
        };
        let t = (q1 - q0).normalize_or_zero();
        if t == DVec2::ZERO {
            continue;
        }
        let n = t.perp();
        a += n.x * n.x;
        b += n.x * n.y;
        c += n.y * n.y;
        count += 1;
    }
    let (strong, weak, weak_direction) = symmetric_eigen2(a, b, c);
    ScanConstraint {
        normals: count,
        strong,
        weak: weak.max(0.0),
        weak_direction,
    }
}
