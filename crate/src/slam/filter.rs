//! # The pose filter: odometry, scan matches, and odometry's own bias
//!
//! The SLAM mapper estimates the current pose with an extended Kalman
//! filter (Thrun, Burgard, Fox, *Probabilistic Robotics*, §3.3 and §7.4)
//! whose motion model is wheel odometry and whose measurement is a scan
//! match. Its state is
//!
//! ```text
//! s = (x, y, θ, b_d, b_t)
//! ```
//!
//! the pose in the odometry frame plus two *systematic* odometry errors the
//! filter calibrates as it goes (augmented-state calibration, as in
//! A. Martinelli, *Simultaneous Localization and Odometry Self Calibration
//! for Mobile Robot*, Autonomous Robots 2007): `b_d`, the heading error per
//! metre driven (unequal wheel radii make a robot curve when it thinks it
//! goes straight), and `b_t`, the heading error per radian turned (a
//! wheelbase the robot believes wrong scales every turn). These are
//! Borenstein and Feng's two dominant systematic errors (UMBmark, 1996).
//!
//! **Predict.** The odometry increment `u = (dx, dy, dθ)` (robot frame)
//! is corrected, `dθ' = dθ + b_d·dx + b_t·dθ`, and composed onto the pose;
//! `P ← F P Fᵀ + Q` with `F = ∂s'/∂s` (turning the pose swings the step
//! around it; the biases move the heading) and `Q` from the increment's
//! length and turn.
//!
//! **Update.** A match measures the pose with information `Λ` (3×3,
//! possibly singular: a corridor says nothing along itself). With `H` the
//! 3×5 selector of the pose, `S = H P Hᵀ`, the gain is
//! `K = P Hᵀ (S + Λ⁻¹)⁻¹ = P Hᵀ Λ (S Λ + 1)⁻¹`, a form that never inverts
//! `Λ`. The biases are corrected through their correlation with the
//! heading: after a turn, the heading the match reports says by how much
//! odometry's turns are off. Where matching then fails for a while (open
//! space, a room whose walls are out of range), the calibrated odometry
//! drifts far less than the raw one.
//!
//! **The validation gate.** A match that is wrong (a scan fitted onto the
//! wrong one of two parallel walls, a short stub of wall that pins only a
//! mix of position and heading) can sit far from where the filter believes
//! the robot is. Fused anyway, its innovation `ν` (match minus prior) is
//! spread over the state through the covariance's correlations: after a
//! metre driven, a 0.3 m jump sideways reads as a heading error of 19°,
//! and the robot's SLAM is lost for good (seen on the 16-robot hour).
//! So each match must first pass the gate of Y. Bar-Shalom and T. Fortmann
//! (*Tracking and Data Association*, 1988, §2.3): its normalised innovation
//! squared `νᵀ (S + Λ⁻¹)⁻¹ ν`, computed as `νᵀ Λ (S Λ + 1)⁻¹ ν` (no `Λ⁻¹`
//! again), is χ²-distributed with up to 3 degrees of freedom when the match
//! is right. Beyond the gate (30, where χ²₃ has 10⁻⁶ of its mass) the match
//! is not fused and the step is odometry's. A robot that truly slipped is
//! not locked out: its covariance grows with every step on odometry alone
//! until the match fits inside the gate again.

use crate::geom::{wrap_angle, Pose2};

/// Size of the state.
const N: usize = 5;
type Mat = [[f64; N]; N];
type Mat3 = [[f64; 3]; 3];

/// Odometry's noise per step as the filter models it (standard
/// deviations; generous on purpose: over-trusting odometry leaks its drift
/// into the map, over-trusting a good match costs nothing), and the prior
/// on its systematic errors.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OdometryNoise {
    /// Position error per metre driven.
    pub metres_per_metre: f64,
    /// Heading error per metre driven (wheel slip).
    pub radians_per_metre: f64,
    /// Heading error per radian turned.
    pub radians_per_radian: f64,
    /// Added every step, so the covariance never collapses.
    pub floor_m: f64,
    pub floor_rad: f64,
    /// Prior standard deviation of the heading bias per metre (rad/m) and
    /// per radian turned.
    pub bias_per_metre: f64,
    pub bias_per_radian: f64,
    /// How far the biases may wander per step (random walk).
    pub bias_drift: f64,
}

impl Default for OdometryNoise {
    fn default() -> Self {
        OdometryNoise {
            metres_per_metre: 0.05,
            radians_per_metre: 0.05,
            radians_per_radian: 0.05,
            floor_m: 1e-4,
            floor_rad: 1e-4,
            bias_per_metre: 0.006,
            bias_per_radian: 0.015,
            bias_drift: 1e-6,
        }
    }
}

/// The largest biases the filter will believe (rad/m, rad/rad).
const MAX_BIAS: [f64; 2] = [0.1, 0.2];

/// The filter's state and covariance.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PoseFilter {
    pub pose: Pose2,
    /// Heading bias per metre driven and per radian turned.
    pub bias: [f64; 2],
    covariance: Mat,
}

impl PoseFilter {
    /// Starts at `pose`, known exactly, with the biases' prior.
    pub fn new(pose: Pose2, noise: &OdometryNoise) -> PoseFilter {
        let mut covariance = [[0.0; N]; N];
        covariance[3][3] = noise.bias_per_metre * noise.bias_per_metre;
        covariance[4][4] = noise.bias_per_radian * noise.bias_per_radian;
        PoseFilter {
            pose,
            bias: [0.0, 0.0],
            covariance,
        }
    }

    /// Covariance of the pose (x, y in m, θ in rad).
    pub fn pose_covariance(&self) -> Mat3 {
        let mut m = [[0.0; 3]; 3];
        for (r, row) in m.iter_mut().enumerate() {
            row.copy_from_slice(&self.covariance[r][..3]);
        }
        m
    }

    /// The pose after the odometry increment `step` (robot frame), with the
    /// biases corrected; the state is not changed.
    pub fn predicted(&self, step: &Pose2) -> Pose2 {
        self.pose.compose(&self.corrected(step))
    }

    fn corrected(&self, step: &Pose2) -> Pose2 {
        let dtheta = wrap_angle(step.theta);
        Pose2::new(
            step.x,
            step.y,
            dtheta + self.bias[0] * step.x + self.bias[1] * dtheta,
        )
    }

    /// Moves the state by the odometry increment `step` (robot frame).
    pub fn predict(&mut self, step: &Pose2, noise: &OdometryNoise) {
        let corrected = self.corrected(step);
        let next = self.pose.compose(&corrected);
        let moved = next.position() - self.pose.position();
        let dtheta = wrap_angle(step.theta);
        let mut f = identity();
        f[0][2] = -moved.y;
        f[1][2] = moved.x;
        f[2][3] = step.x;
        f[2][4] = dtheta;
        let mut p = mul(&mul(&f, &self.covariance), &transpose(&f));
        let s = step.position().length();
        let sd_m = noise.metres_per_metre * s + noise.floor_m;
        let sd_rad =
            noise.radians_per_metre * s + noise.radians_per_radian * dtheta.abs() + noise.floor_rad;
        p[0][0] += sd_m * sd_m;
        p[1][1] += sd_m * sd_m;
        p[2][2] += sd_rad * sd_rad;
        p[3][3] += noise.bias_drift * noise.bias_drift;
        p[4][4] += noise.bias_drift * noise.bias_drift;
        self.pose = next;
        self.covariance = symmetric(&p);
    }

    /// Fuses a match of the pose carrying `information` (x, y, θ), unless
    /// its normalised innovation squared exceeds `gate` (see the module
    /// doc): then, or if the algebra fails (nothing finite to add), the
    /// state is left unchanged and the answer is `false`.
    pub fn update(&mut self, matched: &Pose2, information: &Mat3, gate: f64) -> bool {
        let p = &self.covariance;
        // S = H P Hᵀ (the pose block), and (S Λ + 1)⁻¹.
        let mut s_lambda = [[0.0; 3]; 3];
        for (r, row) in s_lambda.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = (0..3).map(|k| p[r][k] * information[k][c]).sum::<f64>()
                    + if r == c { 1.0 } else { 0.0 };
            }
        }
        let Some(inv) = inverse3(&s_lambda) else {
            return false;
        };
        // Λ (S Λ + 1)⁻¹, then K = P Hᵀ · that (5 × 3).
        let mut m = [[0.0; 3]; 3];
        for (r, row) in m.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = (0..3).map(|k| information[r][k] * inv[k][c]).sum();
            }
        }
        let mut gain = [[0.0; 3]; N];
        for (r, row) in gain.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = (0..3).map(|k| p[r][k] * m[k][c]).sum();
            }
        }
        let innovation = [
            matched.x - self.pose.x,
            matched.y - self.pose.y,
            wrap_angle(matched.theta - self.pose.theta),
        ];
        // The validation gate: the innovation's squared length measured by
        // its own covariance, νᵀ (S + Λ⁻¹)⁻¹ ν = νᵀ Λ (S Λ + 1)⁻¹ ν.
        let nis: f64 = (0..3)
            .map(|r| {
                (0..3)
                    .map(|c| innovation[r] * m[r][c] * innovation[c])
                    .sum::<f64>()
            })
            .sum();
        if nis.is_nan() || nis > gate {
            return false;
        }
        let delta: Vec<f64> = gain
            .iter()
            .map(|row| (0..3).map(|k| row[k] * innovation[k]).sum())
            .collect();
        // P ← (1 − K H) P.
        let mut next = *p;
        for (r, row) in next.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v -= (0..3).map(|k| gain[r][k] * p[k][c]).sum::<f64>();
            }
        }
        let pose = Pose2::new(
            self.pose.x + delta[0],
            self.pose.y + delta[1],
            wrap_angle(self.pose.theta + delta[2]),
        );
        let bias = [
            (self.bias[0] + delta[3]).clamp(-MAX_BIAS[0], MAX_BIAS[0]),
            (self.bias[1] + delta[4]).clamp(-MAX_BIAS[1], MAX_BIAS[1]),
        ];
        let finite = pose.is_finite()
            && bias.iter().all(|b| b.is_finite())
            && next.iter().flatten().all(|v| v.is_finite());
        if !finite {
            return false;
        }
        self.pose = pose;
        self.bias = bias;
        self.covariance = symmetric(&next);
        true
    }
}

fn identity() -> Mat {
    let mut m = [[0.0; N]; N];
    for (i, row) in m.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    m
}

/// `A B` of two square matrices (the filter's 5 × 5, the back end's 3 × 3).
pub(super) fn mul<const K: usize>(a: &[[f64; K]; K], b: &[[f64; K]; K]) -> [[f64; K]; K] {
    let mut m = [[0.0; K]; K];
    for (r, row) in m.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v = (0..K).map(|k| a[r][k] * b[k][c]).sum();
        }
    }
    m
}

pub(super) fn transpose<const K: usize>(a: &[[f64; K]; K]) -> [[f64; K]; K] {
    let mut m = [[0.0; K]; K];
    for (r, row) in a.iter().enumerate() {
        for (c, v) in row.iter().enumerate() {
            m[c][r] = *v;
        }
    }
    m
}

/// `(A + Aᵀ) / 2`: keeps rounding from making the covariance asymmetric.
pub(super) fn symmetric<const K: usize>(a: &[[f64; K]; K]) -> [[f64; K]; K] {
    let mut m = *a;
    for r in 0..K {
        for c in r + 1..K {
            let v = 0.5 * (a[r][c] + a[c][r]);
            m[r][c] = v;
            m[c][r] = v;
        }
    }
    m
}

/// Inverse of a 3×3 matrix (adjugate over determinant); `None` if it is
/// singular or not finite.
pub fn inverse3(m: &Mat3) -> Option<Mat3> {
    let c =
        |r0: usize, r1: usize, c0: usize, c1: usize| m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0];
    let cof = [
        [c(1, 2, 1, 2), -c(1, 2, 0, 2), c(1, 2, 0, 1)],
        [-c(0, 2, 1, 2), c(0, 2, 0, 2), -c(0, 2, 0, 1)],
        [c(0, 1, 1, 2), -c(0, 1, 0, 2), c(0, 1, 0, 1)],
    ];
    let det = m[0][0] * cof[0][0] + m[0][1] * cof[0][1] + m[0][2] * cof[0][2];
    if !det.is_finite() || det.abs() < 1e-300 {
        return None;
    }
    // The inverse is the adjugate (the cofactors transposed) over det.
    let mut inv = [[0.0; 3]; 3];
    for (r, row) in inv.iter_mut().enumerate() {
        for (k, v) in row.iter_mut().enumerate() {
            *v = cof[k][r] / det;
        }
    }
    inv.iter().flatten().all(|v| v.is_finite()).then_some(inv)
}
