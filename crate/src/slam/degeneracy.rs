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
//! Normals come from each point's neighbours in beam order ([`scan_normals`]):
//! the principal axes of the points near it along the same surface (no gap
//! over 0.3 m between consecutive beams), a line fit that averages the
//! range noise; where the points do not lie on a line (a corner, a pillar
//! narrower than the window) the point gets no normal. Only points that
//! land on walls *already in the map* count: a corridor's end wall seen for
//! the first time constrains nothing until it is mapped.
//!
//! ## How near: a neighbourhood sized by the points' spacing
//! Neighbouring beams land `r·Δφ` apart at range `r` (more on a wall seen
//! obliquely): 1.6 cm at 0.9 m, 7 cm at 4 m for the lab's 1° laser. A fixed
//! 0.12 m neighbourhood therefore holds some fifteen points on the near wall
//! but only two or three on a far one, and whether a far point gets a
//! normal at all then hangs on its own range noise: a point pushed along
//! its beam moves along the wall too, closer to one neighbour and out of
//! reach of the other. The points kept are thus a biased sample, and the
//! match inherits the bias. Measured in a straight 3 m corridor with perfect
//! odometry and 1 cm range noise, a robot following one wall veered towards
//! it, 0.45 m after 100 m, and only when the far wall was in range; the
//! outer-wall robots of the 16-robot hour drifted a degree a lap the same
//! way (docs/history/issue-22-many-robots.md, rounds 13 and 14). So the
//! neighbourhood grows with the range: its radius is the larger of 0.12 m
//! and the spacing of [`SPACING_BEAMS`] beams at the point's range (0.56 m
//! at 4 m). Near the robot nothing changes; far points get enough
//! neighbours that noise no longer decides which of them count.

use crate::sensors::laser::{LASER_BEAMS, LASER_FOV_RAD};
use glam::DVec2;

/// How well a scan pins the robot's position, in its own frame.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
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

/// The covariance `[xx, xy, yy]` of `points` (not empty) about their
/// mean: with [`symmetric_eigen2`], a line fit by total least squares —
/// the larger eigenvalue the spread along the line, the smaller the mean
/// squared distance from it, and its eigenvector the line's normal.
pub fn covariance2(points: &[DVec2]) -> [f64; 3] {
    let mean = points.iter().copied().sum::<DVec2>() / points.len() as f64;
    let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
    for &q in points {
        let d = q - mean;
        a += d.x * d.x;
        b += d.x * d.y;
        c += d.y * d.y;
    }
    let n = points.len() as f64;
    [a / n, b / n, c / n]
}

/// Neighbourhood of a point for its normal (m), at least.
const NORMAL_RADIUS_M: f64 = 0.12;
/// A point's neighbourhood reaches at least this many beam spacings at its
/// range (see the module doc).
pub const SPACING_BEAMS: f64 = 8.0;
/// Consecutive beams farther apart than this lie on different surfaces (m).
pub const MAX_GAP_M: f64 = 0.3;
/// At most this many beams on each side take part in a normal.
const REACH: usize = 8;
/// A neighbourhood narrower than this along its main axis is too short to
/// orient (m).
const MIN_EXTENT_M: f64 = 0.05;
/// A neighbourhood whose variance across its main axis exceeds this share
/// of its variance along it is not a line: no normal. Range noise alone
/// gives σ² / (L² / 12), 0.08 for σ = 1 cm over L = 0.12 m; a right-angled
/// corner with equal arms gives 0.25.
const MAX_FLATNESS: f64 = 0.15;

/// The unit surface normal at every point of a scan of the lab's laser
/// (robot frame, beam order), or `None` where the neighbours do not define
/// one. The sign is arbitrary: only `n nᵀ` and `n·(q − s)` use it. The
/// neighbourhood grows with the range (see the module doc).
pub fn scan_normals(points: &[DVec2]) -> Vec<Option<DVec2>> {
    let step = LASER_FOV_RAD / (LASER_BEAMS - 1) as f64;
    let per_metre = SPACING_BEAMS * step;
    normals_within(points, |p| {
        let r = NORMAL_RADIUS_M.max(per_metre * p.length());
        r * r
    })
}

/// [`scan_normals`] over neighbourhoods of a fixed `radius_m` (a scan
/// thinned to one point per 10 cm needs more than the 0.12 m of a full
/// one).
pub fn scan_normals_within(points: &[DVec2], radius_m: f64) -> Vec<Option<DVec2>> {
    // The distance tests on squared lengths, with a bound that gives the
    // same answers as on lengths (a square root per test was a third of
    // this).
    let radius2 = squared_bound(radius_m);
    normals_within(points, |_| radius2)
}

/// The normals, with the squared radius of each point's neighbourhood
/// from `radius2_at(point)`.
fn normals_within(points: &[DVec2], radius2_at: impl Fn(DVec2) -> f64) -> Vec<Option<DVec2>> {
    let gap2 = squared_bound(MAX_GAP_M);
    (0..points.len())
        .map(|i| {
            let p = points[i];
            let radius2 = radius2_at(p);
            // Walk out along the beam order while the surface continues.
            let mut lo = i;
            while lo > 0
                && i - lo < REACH
                && (points[lo - 1] - points[lo]).length_squared() <= gap2
                && (points[lo - 1] - p).length_squared() <= radius2
            {
                lo -= 1;
            }
            let mut hi = i;
            while hi + 1 < points.len()
                && hi - i < REACH
                && (points[hi + 1] - points[hi]).length_squared() <= gap2
                && (points[hi + 1] - p).length_squared() <= radius2
            {
                hi += 1;
            }
            if lo == i || hi == i {
                return None;
            }
            let [a, b, c] = covariance2(&points[lo..=hi]);
            let (along, across, normal) = symmetric_eigen2(a, b, c);
            // Spread along the line: a uniform spread of extent L has
            // variance L²/12.
            if (12.0 * along).sqrt() < MIN_EXTENT_M || across > MAX_FLATNESS * along {
                return None;
            }
            Some(normal)
        })
        .collect()
}

/// The largest `x ≥ 0` whose square root is at most `c` (for `c ≥ 0`):
/// since the square root is correctly rounded, and so never decreases,
/// `v.length() <= c` exactly when `v.length_squared() <= squared_bound(c)`,
/// bit for bit. `c * c` rounded may miss the bound by an ulp either way,
/// so it is walked to it.
pub fn squared_bound(c: f64) -> f64 {
    let next =
        |x: f64, up: bool| f64::from_bits(if up { x.to_bits() + 1 } else { x.to_bits() - 1 });
    let mut x = c * c;
    while x > 0.0 && x.sqrt() > c {
        x = next(x, false);
    }
    while next(x, true).sqrt() <= c {
        x = next(x, true);
    }
    x
}

/// The translational information `A = Σ n nᵀ` of the normals with
/// `counts[i]`, decomposed.
pub fn constraint_of(normals: &[Option<DVec2>], counts: &[bool]) -> ScanConstraint {
    let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
    let mut count = 0;
    for (n, &k) in normals.iter().zip(counts) {
        let (Some(n), true) = (n, k) else { continue };
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
