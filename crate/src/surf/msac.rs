//! # MSAC: the geometry behind the matches (thesis §5.3.4, Fig. 8)
//!
//! Ratio-tested matches still contain mistakes. If the two views see the
//! same roughly planar scene (a wall, in the thesis), the true matches obey
//! one homography H: x₂ ~ H x₁. We estimate it robustly with MSAC (Torr and
//! Zisserman, *MLESAC*, CVIU 78 (2000) 138-156): repeatedly fit H to a
//! random minimal sample of 4 matches and score it by
//!
//! ```text
//!   C(H) = Σ_i min(e_i², T²),   e_i = ‖H x₁ᵢ - x₂ᵢ‖ (pixels)
//! ```
//!
//! RANSAC would count inliers (every inlier costs 0); MSAC charges inliers
//! their squared error, so among hypotheses with equally many inliers the
//! tighter one wins, at no extra cost. The loop stops when, with the best
//! inlier ratio w seen so far, another all-inlier sample is unlikely to be
//! missed: N = ln(1 - p) / ln(1 - w⁴). The winner is then refitted on all
//! its inliers by the normalised DLT (Hartley and Zisserman, Alg. 4.2:
//! centre both point sets, scale them to mean distance √2, take the right
//! singular vector of the 2n × 9 system, here as the smallest eigenvector
//! of AᵀA by Jacobi rotations), twice, re-selecting inliers in between, and
//! finally polished by Levenberg-Marquardt on the geometric transfer error
//! (Hartley and Zisserman §4.2: the DLT minimises an algebraic error).
//! Minimal samples are solved as an 8 × 8 linear system (h₃₃ = 1), and
//! samples with three collinear points, or that would mirror the image, are
//! skipped. A similarity (rotation, uniform scale, shift; 2-point samples)
//! is fitted the same way for views that differ only in-plane.
//!
//! Randomness comes from [`SplitMix64`] seeded by [`MsacConfig::seed`], so a
//! fit is a function of its inputs and the seed.
//!
//! ## The matched region (thesis Fig. 8, §5.3.4 and §5.5)
//! Projecting the corners of image 1 through H gives the quadrilateral
//! where image 1 lies in image 2 (the thesis's green quadrangle). Comparing
//! its sides with the image's sides gives the *shrinkage* (below 1 when image
//! 2 was taken from farther away, §5.5.2), comparing its centre with image
//! 2's centre gives the *shift* in pixels (§5.5.1), and the ratio of its left
//! and right sides shows the trapezoid a camera turn makes (§5.5.3).

// Small dense matrices read best with explicit indices, as in the textbooks.
#![allow(clippy::needless_range_loop)]

use super::prng::SplitMix64;

/// MSAC settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MsacConfig {
    /// Inlier threshold T on the transfer error, pixels. Default 3.0 (OpenCV's).
    pub threshold_px: f64,
    /// Upper bound on hypotheses. Default 2000.
    pub max_iterations: usize,
    /// Probability of having drawn one all-inlier sample. Default 0.995.
    pub confidence: f64,
    /// Fewer inliers than this and no model is returned. Default 8.
    pub min_inliers: usize,
    /// Seed of the sample generator. Default 0x5EED.
    pub seed: u64,
}

impl Default for MsacConfig {
    fn default() -> Self {
        MsacConfig {
            threshold_px: 3.0,
            max_iterations: 2000,
            confidence: 0.995,
            min_inliers: 8,
            seed: 0x5EED,
        }
    }
}

/// A fitted model with its inliers (indices into the point lists) and its
/// MSAC cost.
#[derive(Clone, Debug, PartialEq)]
pub struct MsacFit<M> {
    pub model: M,
    pub inliers: Vec<usize>,
    pub cost: f64,
}

/// A plane projective transformation, row-major, mapping image-1 pixels to
/// image-2 pixels (x₂ ~ H x₁), scaled so that h₃₃ = 1 when possible.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Homography(pub [[f64; 3]; 3]);

impl Homography {
    pub const IDENTITY: Homography =
        Homography([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);

    /// H applied to (x, y); `None` when the point maps to infinity.
    pub fn apply(&self, p: [f64; 2]) -> Option<[f64; 2]> {
        let h = &self.0;
        let w = h[2][0] * p[0] + h[2][1] * p[1] + h[2][2];
        if w.abs() < 1e-12 || !w.is_finite() {
            return None;
        }
        Some([
            (h[0][0] * p[0] + h[0][1] * p[1] + h[0][2]) / w,
            (h[1][0] * p[0] + h[1][1] * p[1] + h[1][2]) / w,
        ])
    }

    /// Matrix product self · other (apply `other` first).
    pub fn compose(&self, other: &Homography) -> Homography {
        let mut m = [[0.0; 3]; 3];
        for (r, row) in m.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = (0..3).map(|k| self.0[r][k] * other.0[k][c]).sum();
            }
        }
        Homography(m)
    }

    /// The inverse, `None` if singular.
    pub fn inverse(&self) -> Option<Homography> {
        let m = &self.0;
        let cof = |r0: usize, r1: usize, c0: usize, c1: usize| {
            m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]
        };
        let adj = [
            [cof(1, 2, 1, 2), -cof(0, 2, 1, 2), cof(0, 1, 1, 2)],
            [-cof(1, 2, 0, 2), cof(0, 2, 0, 2), -cof(0, 1, 0, 2)],
            [cof(1, 2, 0, 1), -cof(0, 2, 0, 1), cof(0, 1, 0, 1)],
        ];
        let det = m[0][0] * adj[0][0] + m[0][1] * adj[1][0] + m[0][2] * adj[2][0];
        if det.abs() < 1e-300 || !det.is_finite() {
            return None;
        }
        let mut inv = adj;
        inv.iter_mut().flatten().for_each(|v| *v /= det);
        Some(Homography(inv).normalised())
    }

    /// Scaled so that h₃₃ = 1 (unchanged if h₃₃ is about 0).
    pub fn normalised(&self) -> Homography {
        let s = self.0[2][2];
        if s.abs() < 1e-12 {
            return *self;
        }
        let mut m = self.0;
        m.iter_mut().flatten().for_each(|v| *v /= s);
        Homography(m)
    }

    fn transfer_error2(&self, p: [f64; 2], q: [f64; 2]) -> f64 {
        match self.apply(p) {
            Some(r) => (r[0] - q[0]).powi(2) + (r[1] - q[1]).powi(2),
            None => f64::INFINITY,
        }
    }
}

/// x₂ = s R(θ) x₁ + t, written as (a, b) = s (cos θ, sin θ):
/// u = a x - b y + tx, v = b x + a y + ty.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Similarity {
    pub a: f64,
    pub b: f64,
    pub tx: f64,
    pub ty: f64,
}

impl Similarity {
    pub fn apply(&self, p: [f64; 2]) -> [f64; 2] {
        [
            self.a * p[0] - self.b * p[1] + self.tx,
            self.b * p[0] + self.a * p[1] + self.ty,
        ]
    }
    /// Uniform scale factor s.
    pub fn scale(&self) -> f64 {
        self.a.hypot(self.b)
    }
    /// Rotation θ in radians (image axes: from +x towards +y).
    pub fn angle_rad(&self) -> f64 {
        self.b.atan2(self.a)
    }
    /// The same map as a homography.
    pub fn to_homography(&self) -> Homography {
        Homography([
            [self.a, -self.b, self.tx],
            [self.b, self.a, self.ty],
            [0.0, 0.0, 1.0],
        ])
    }
    fn error2(&self, p: [f64; 2], q: [f64; 2]) -> f64 {
        let r = self.apply(p);
        (r[0] - q[0]).powi(2) + (r[1] - q[1]).powi(2)
    }
}

/// Where image 1 lies in image 2 (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MatchedRegion {
    /// Image 1's outer corners (top-left, top-right, bottom-right,
    /// bottom-left: (-0.5, -0.5) … (w - 0.5, h - 0.5)) in image 2 pixels.
    pub quad: [[f64; 2]; 4],
    /// Mean quad side over the matching image-1 side: < 1 when image 1
    /// appears smaller in image 2.
    pub shrinkage: f64,
    /// Image 1's centre in image 2 minus image 2's centre, pixels (x right, y down).
    pub shift: [f64; 2],
    /// Left side over right side of the quad: 1 for a pure shift or zoom,
    /// away from 1 when the camera turned about its vertical axis.
    pub left_right_ratio: f64,
}

impl MatchedRegion {
    /// The region of an image of `size1` (width, height) mapped by `h` into
    /// an image of `size2`; `None` if a corner maps to infinity.
    pub fn new(h: &Homography, size1: (usize, usize), size2: (usize, usize)) -> Option<Self> {
        let (w1, h1) = (size1.0 as f64, size1.1 as f64);
        let corners = [
            [-0.5, -0.5],
            [w1 - 0.5, -0.5],
            [w1 - 0.5, h1 - 0.5],
            [-0.5, h1 - 0.5],
        ];
        let mut quad = [[0.0; 2]; 4];
        for (q, c) in quad.iter_mut().zip(corners) {
            *q = h.apply(c)?;
        }
        let len = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
        let (top, right, bottom, left) = (
            len(quad[0], quad[1]),
            len(quad[1], quad[2]),
            len(quad[2], quad[3]),
            len(quad[3], quad[0]),
        );
        let shrinkage = ((top + bottom) / (2.0 * w1) + (left + right) / (2.0 * h1)) / 2.0;
        let centre = h.apply([(w1 - 1.0) / 2.0, (h1 - 1.0) / 2.0])?;
        let c2 = [(size2.0 as f64 - 1.0) / 2.0, (size2.1 as f64 - 1.0) / 2.0];
        Some(MatchedRegion {
            quad,
            shrinkage,
            shift: [centre[0] - c2[0], centre[1] - c2[1]],
            left_right_ratio: if right > 0.0 {
                left / right
            } else {
                f64::INFINITY
            },
        })
    }
}

/// Hartley normalisation: translate the centroid to 0, scale to mean
/// distance √2. Returns the matrix and the normalised points.
fn normalise(points: &[[f64; 2]]) -> (Homography, Vec<[f64; 2]>) {
    let n = points.len().max(1) as f64;
    let cx = points.iter().map(|p| p[0]).sum::<f64>() / n;
    let cy = points.iter().map(|p| p[1]).sum::<f64>() / n;
    let mean = points
        .iter()
        .map(|p| (p[0] - cx).hypot(p[1] - cy))
        .sum::<f64>()
        / n;
    let s = if mean > 1e-12 {
        std::f64::consts::SQRT_2 / mean
    } else {
        1.0
    };
    let t = Homography([[s, 0.0, -s * cx], [0.0, s, -s * cy], [0.0, 0.0, 1.0]]);
    let pts = points
        .iter()
        .map(|p| [s * (p[0] - cx), s * (p[1] - cy)])
        .collect();
    (t, pts)
}

fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// Rejects samples with (nearly) collinear triples, or whose triangles turn
/// the other way in image 2 (a mirror image is never a camera motion).
fn good_sample(p: &[[f64; 2]; 4], q: &[[f64; 2]; 4]) -> bool {
    const TRIPLES: [[usize; 3]; 4] = [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]];
    TRIPLES.iter().all(|t| {
        let a = cross(p[t[0]], p[t[1]], p[t[2]]);
        let b = cross(q[t[0]], q[t[1]], q[t[2]]);
        a.abs() > 1e-4 && b.abs() > 1e-4 && (a > 0.0) == (b > 0.0)
    })
}

/// The homography through four correspondences (h₃₃ = 1), by Gaussian
/// elimination with partial pivoting on the 8 × 8 DLT system; `None` when
/// degenerate (three points on a line).
pub fn homography_from_4(p: &[[f64; 2]; 4], q: &[[f64; 2]; 4]) -> Option<Homography> {
    let mut a = [[0.0f64; 9]; 8];
    for k in 0..4 {
        let ([x, y], [u, v]) = (p[k], q[k]);
        a[2 * k] = [x, y, 1.0, 0.0, 0.0, 0.0, -u * x, -u * y, u];
        a[2 * k + 1] = [0.0, 0.0, 0.0, x, y, 1.0, -v * x, -v * y, v];
    }
    for col in 0..8 {
        let pivot = (col..8).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() < 1e-10 {
            return None;
        }
        a.swap(col, pivot);
        for row in 0..8 {
            if row != col {
                let f = a[row][col] / a[col][col];
                if f != 0.0 {
                    for c in col..9 {
                        a[row][c] -= f * a[col][c];
                    }
                }
            }
        }
    }
    let h: Vec<f64> = (0..8).map(|i| a[i][8] / a[i][i]).collect();
    Some(Homography([
        [h[0], h[1], h[2]],
        [h[3], h[4], h[5]],
        [h[6], h[7], 1.0],
    ]))
}

/// Least-squares homography by the DLT on already normalised points: the
/// eigenvector of AᵀA with the smallest eigenvalue.
fn homography_dlt(p: &[[f64; 2]], q: &[[f64; 2]]) -> Option<Homography> {
    if p.len() < 4 {
        return None;
    }
    let mut m = [[0.0f64; 9]; 9];
    for (&[x, y], &[u, v]) in p.iter().zip(q) {
        let r1 = [x, y, 1.0, 0.0, 0.0, 0.0, -u * x, -u * y, -u];
        let r2 = [0.0, 0.0, 0.0, x, y, 1.0, -v * x, -v * y, -v];
        for i in 0..9 {
            for j in i..9 {
                m[i][j] += r1[i] * r1[j] + r2[i] * r2[j];
            }
        }
    }
    for i in 0..9 {
        for j in 0..i {
            m[i][j] = m[j][i];
        }
    }
    let h = smallest_eigenvector(m);
    if h.iter().any(|v| !v.is_finite()) {
        return None;
    }
    Some(Homography([
        [h[0], h[1], h[2]],
        [h[3], h[4], h[5]],
        [h[6], h[7], h[8]],
    ]))
}

/// Cyclic Jacobi eigen-decomposition of a symmetric 9 × 9 matrix; returns
/// the unit eigenvector of the smallest eigenvalue.
fn smallest_eigenvector(mut a: [[f64; 9]; 9]) -> [f64; 9] {
    let mut v = [[0.0f64; 9]; 9];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for _sweep in 0..60 {
        let off: f64 = (0..9)
            .flat_map(|i| (0..9).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i][j] * a[i][j])
            .sum();
        let diag: f64 = (0..9).map(|i| a[i][i] * a[i][i]).sum();
        if off <= 1e-30 * diag.max(1e-300) {
            break;
        }
        for p in 0..8 {
            for q in p + 1..9 {
                if a[p][q].abs() < 1e-300 {
                    continue;
                }
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..9 {
                    let (akp, akq) = (a[k][p], a[k][q]);
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for k in 0..9 {
                    let (apk, aqk) = (a[p][k], a[q][k]);
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for row in v.iter_mut() {
                    let (vp, vq) = (row[p], row[q]);
                    row[p] = c * vp - s * vq;
                    row[q] = s * vp + c * vq;
                }
            }
        }
    }
    let k = (0..9)
        .min_by(|&i, &j| a[i][i].total_cmp(&a[j][j]))
        .unwrap_or(8);
    let mut out = [0.0; 9];
    for (i, o) in out.iter_mut().enumerate() {
        *o = v[i][k];
    }
    out
}

/// Iterations needed for `confidence` with inlier ratio `w` and samples of `k`.
fn needed_iterations(w: f64, k: i32, confidence: f64, max: usize) -> usize {
    let good = w.powi(k);
    if good >= 1.0 {
        return 1;
    }
    if good <= 0.0 {
        return max;
    }
    let n = (1.0 - confidence).ln() / (1.0 - good).ln();
    if n.is_finite() {
        (n.ceil() as usize).min(max)
    } else {
        max
    }
}

fn score(errors: impl Iterator<Item = f64>, t2: f64) -> (f64, usize) {
    let mut cost = 0.0;
    let mut inliers = 0;
    for e in errors {
        if e < t2 {
            cost += e;
            inliers += 1;
        } else {
            cost += t2;
        }
    }
    (cost, inliers)
}

/// Robust homography mapping `p1[i]` to `p2[i]` (pixels). `None` with fewer
/// than 4 pairs, when no sample gives a model, or when fewer than
/// `min_inliers` agree.
pub fn fit_homography(
    p1: &[[f64; 2]],
    p2: &[[f64; 2]],
    config: &MsacConfig,
) -> Option<MsacFit<Homography>> {
    let n = p1.len().min(p2.len());
    if n < 4 {
        return None;
    }
    let (p1, p2) = (&p1[..n], &p2[..n]);
    let (t1, n1) = normalise(p1);
    let (t2, n2) = normalise(p2);
    let t2_inv = t2.inverse()?;
    let denorm = |hn: &Homography| t2_inv.compose(hn).compose(&t1).normalised();
    let thr2 = config.threshold_px * config.threshold_px;
    let mut rng = SplitMix64::new(config.seed);
    let mut best: Option<(f64, usize, Homography)> = None;
    let mut needed = config.max_iterations;
    let mut it = 0;
    while it < needed.max(1) && it < config.max_iterations {
        it += 1;
        let idx = rng.distinct::<4>(n);
        let ps = idx.map(|i| n1[i]);
        let qs = idx.map(|i| n2[i]);
        if !good_sample(&ps, &qs) {
            continue;
        }
        let Some(hn) = homography_from_4(&ps, &qs) else {
            continue;
        };
        let h = denorm(&hn);
        let (cost, inl) = score(
            p1.iter().zip(p2).map(|(&a, &b)| h.transfer_error2(a, b)),
            thr2,
        );
        if best.as_ref().is_none_or(|b| cost < b.0) {
            needed = needed_iterations(
                inl as f64 / n as f64,
                4,
                config.confidence,
                config.max_iterations,
            );
            best = Some((cost, inl, h));
        }
    }
    let (mut cost, _, mut h) = best?;
    // Refit on the inliers, twice.
    for _ in 0..2 {
        let inl: Vec<usize> = (0..n)
            .filter(|&i| h.transfer_error2(p1[i], p2[i]) < thr2)
            .collect();
        if inl.len() < 4 {
            break;
        }
        let a: Vec<[f64; 2]> = inl.iter().map(|&i| n1[i]).collect();
        let b: Vec<[f64; 2]> = inl.iter().map(|&i| n2[i]).collect();
        let Some(hn) = homography_dlt(&a, &b) else {
            break;
        };
        let refit = denorm(&hn);
        let (c, _) = score(
            p1.iter()
                .zip(p2)
                .map(|(&a, &b)| refit.transfer_error2(a, b)),
            thr2,
        );
        if c > cost {
            break;
        }
        (cost, h) = (c, refit);
    }
    // Polish: minimise the geometric transfer error over the inliers
    // (Levenberg-Marquardt); the DLT minimises an algebraic error instead.
    let t1_inv = t1.inverse()?;
    for _ in 0..2 {
        let inl: Vec<usize> = (0..n)
            .filter(|&i| h.transfer_error2(p1[i], p2[i]) < thr2)
            .collect();
        if inl.len() < 5 {
            break;
        }
        let hn = t2.compose(&h).compose(&t1_inv).normalised();
        let a: Vec<[f64; 2]> = inl.iter().map(|&i| n1[i]).collect();
        let b: Vec<[f64; 2]> = inl.iter().map(|&i| n2[i]).collect();
        let refit = denorm(&refine_homography(hn, &a, &b));
        let (c, _) = score(
            p1.iter()
                .zip(p2)
                .map(|(&a, &b)| refit.transfer_error2(a, b)),
            thr2,
        );
        if c > cost {
            break;
        }
        (cost, h) = (c, refit);
    }
    let inliers: Vec<usize> = (0..n)
        .filter(|&i| h.transfer_error2(p1[i], p2[i]) < thr2)
        .collect();
    (inliers.len() >= config.min_inliers.max(4)).then_some(MsacFit {
        model: h,
        inliers,
        cost,
    })
}

/// Levenberg-Marquardt on the 8 entries of `h` (h₃₃ = 1) minimising
/// Σ ‖H p - q‖² over the pairs.
fn refine_homography(mut h: Homography, p: &[[f64; 2]], q: &[[f64; 2]]) -> Homography {
    let cost = |h: &Homography| {
        p.iter()
            .zip(q)
            .map(|(&a, &b)| h.transfer_error2(a, b))
            .sum::<f64>()
    };
    let mut current = cost(&h);
    let mut lambda = 1e-3;
    for _ in 0..20 {
        let m = &h.0;
        let mut jtj = [[0.0f64; 8]; 8];
        let mut jtr = [0.0f64; 8];
        for (&[x, y], &[u, v]) in p.iter().zip(q) {
            let w = m[2][0] * x + m[2][1] * y + m[2][2];
            if w.abs() < 1e-12 {
                continue;
            }
            let uu = (m[0][0] * x + m[0][1] * y + m[0][2]) / w;
            let vv = (m[1][0] * x + m[1][1] * y + m[1][2]) / w;
            let ju = [
                x / w,
                y / w,
                1.0 / w,
                0.0,
                0.0,
                0.0,
                -uu * x / w,
                -uu * y / w,
            ];
            let jv = [
                0.0,
                0.0,
                0.0,
                x / w,
                y / w,
                1.0 / w,
                -vv * x / w,
                -vv * y / w,
            ];
            let (ru, rv) = (uu - u, vv - v);
            for i in 0..8 {
                jtr[i] += ju[i] * ru + jv[i] * rv;
                for j in 0..8 {
                    jtj[i][j] += ju[i] * ju[j] + jv[i] * jv[j];
                }
            }
        }
        let mut improved = false;
        for _ in 0..6 {
            let mut a = jtj;
            for (i, row) in a.iter_mut().enumerate() {
                row[i] *= 1.0 + lambda;
            }
            let Some(delta) = solve8(a, jtr.map(|v| -v)) else {
                break;
            };
            let mut next = h;
            for (k, d) in delta.iter().enumerate() {
                next.0[k / 3][k % 3] += d;
            }
            let c = cost(&next);
            if c < current {
                (h, current) = (next, c);
                lambda = (lambda * 0.3).max(1e-9);
                improved = true;
                break;
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
    }
    h
}

/// Solves an 8 × 8 system by Gaussian elimination with partial pivoting.
fn solve8(mut a: [[f64; 8]; 8], mut b: [f64; 8]) -> Option<[f64; 8]> {
    for col in 0..8 {
        let pivot = (col..8).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..8 {
            let f = a[row][col] / a[col][col];
            for c in col..8 {
                a[row][c] -= f * a[col][c];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 8];
    for row in (0..8).rev() {
        let s: f64 = (row + 1..8).map(|c| a[row][c] * x[c]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Least-squares similarity through the pairs (closed form, centred).
fn similarity_ls(p: &[[f64; 2]], q: &[[f64; 2]]) -> Option<Similarity> {
    let n = p.len() as f64;
    if p.len() < 2 {
        return None;
    }
    let (pcx, pcy) = (
        p.iter().map(|v| v[0]).sum::<f64>() / n,
        p.iter().map(|v| v[1]).sum::<f64>() / n,
    );
    let (qcx, qcy) = (
        q.iter().map(|v| v[0]).sum::<f64>() / n,
        q.iter().map(|v| v[1]).sum::<f64>() / n,
    );
    let (mut sxx, mut sa, mut sb) = (0.0, 0.0, 0.0);
    for (a, b) in p.iter().zip(q) {
        let (x, y) = (a[0] - pcx, a[1] - pcy);
        let (u, v) = (b[0] - qcx, b[1] - qcy);
        sxx += x * x + y * y;
        sa += x * u + y * v;
        sb += x * v - y * u;
    }
    if sxx < 1e-12 {
        return None;
    }
    let (a, b) = (sa / sxx, sb / sxx);
    Some(Similarity {
        a,
        b,
        tx: qcx - (a * pcx - b * pcy),
        ty: qcy - (b * pcx + a * pcy),
    })
}

/// Robust similarity mapping `p1[i]` to `p2[i]`, as [`fit_homography`] with
/// 2-point samples.
pub fn fit_similarity(
    p1: &[[f64; 2]],
    p2: &[[f64; 2]],
    config: &MsacConfig,
) -> Option<MsacFit<Similarity>> {
    let n = p1.len().min(p2.len());
    if n < 2 {
        return None;
    }
    let (p1, p2) = (&p1[..n], &p2[..n]);
    let thr2 = config.threshold_px * config.threshold_px;
    let mut rng = SplitMix64::new(config.seed);
    let mut best: Option<(f64, Similarity)> = None;
    let mut needed = config.max_iterations;
    let mut it = 0;
    while it < needed.max(1) && it < config.max_iterations {
        it += 1;
        let [i, j] = rng.distinct::<2>(n);
        let Some(s) = similarity_ls(&[p1[i], p1[j]], &[p2[i], p2[j]]) else {
            continue;
        };
        let (cost, inl) = score(p1.iter().zip(p2).map(|(&a, &b)| s.error2(a, b)), thr2);
        if best.as_ref().is_none_or(|b| cost < b.0) {
            needed = needed_iterations(
                inl as f64 / n as f64,
                2,
                config.confidence,
                config.max_iterations,
            );
            best = Some((cost, s));
        }
    }
    let (mut cost, mut s) = best?;
    for _ in 0..2 {
        let inl: Vec<usize> = (0..n).filter(|&i| s.error2(p1[i], p2[i]) < thr2).collect();
        let a: Vec<[f64; 2]> = inl.iter().map(|&i| p1[i]).collect();
        let b: Vec<[f64; 2]> = inl.iter().map(|&i| p2[i]).collect();
        let Some(refit) = similarity_ls(&a, &b) else {
            break;
        };
        let (c, _) = score(p1.iter().zip(p2).map(|(&a, &b)| refit.error2(a, b)), thr2);
        if c > cost {
            break;
        }
        (cost, s) = (c, refit);
    }
    let inliers: Vec<usize> = (0..n).filter(|&i| s.error2(p1[i], p2[i]) < thr2).collect();
    (inliers.len() >= config.min_inliers.max(2)).then_some(MsacFit {
        model: s,
        inliers,
        cost,
    })
}
