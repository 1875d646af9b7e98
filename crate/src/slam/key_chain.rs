//! # How sure is the chain between two key scans? A compounded covariance
//!
//! The back end ([`super::robot_graph`]) links consecutive key scans by the
//! front end's relative motion. How much the pose graph may bend that edge
//! when a loop closes is its information (inverse covariance), and one
//! fixed σ for every edge is wrong in the way that matters most on a long
//! run: the front end's filter ([`super::mapper`]) keeps odometry's word
//! along a corridor (the direction its scans do not pin,
//! [`super::degeneracy`]) and the match's across it. A chain of corridor
//! edges is loose along the corridor and stiff across it; a closure around
//! a loop of such corridors should stretch them, not bend the headings or
//! slide the walls sideways. With equal edges least squares spreads the
//! loop's error evenly, and the middle of the loop keeps most of it.
//!
//! So the edge carries the uncertainty the front end actually had, built up
//! step by step between the two keys, as an extended Kalman filter of the
//! pose *relative to the last key* would (the compounding of R. Smith,
//! M. Self, P. Cheeseman, "Estimating uncertain spatial relationships in
//! robotics", 1990; an edge's covariance from the chain of scan matches as
//! in K. Konolige et al., "Efficient sparse pose adjustment for 2D
//! mapping", IROS 2010, and E. Olson, "Real-time correlative scan
//! matching", ICRA 2009, §IV-C). With `r = x_key⁻¹ ⊕ x` the current pose in
//! the key's frame and `Σ` its covariance (zero at the key):
//!
//! 1. **Motion.** The step `d = x_{t−1}⁻¹ ⊕ x_t` moves `r` to `r ⊕ d`. Its
//!    noise is odometry's as the filter models it ([`OdometryNoise`]:
//!    `σ_m = a·|d| + floor`, `σ_θ = b·|d| + c·|dθ| + floor`, in the frame of
//!    the step), and
//!
//!    ```text
//!    Σ ← J_r Σ J_rᵀ + J_d Q J_dᵀ
//!    J_r = [1 0 −(y' − y); 0 1 (x' − x); 0 0 1]      J_d = [R(θ_r) 0; 0 1]
//!    ```
//!
//!    (`(x, y)` and `(x', y')` the position of `r` before and after).
//! 2. **Match.** A scan matched against the map measures the pose with the
//!    matcher's information `Λ = JᵀJ / σ²` (world frame; the map near the
//!    key was drawn at the key's pose, so it stands for the key's frame).
//!    Where the match was degenerate the mapper kept odometry's word along
//!    the weak direction `w`, so that direction's information goes:
//!    `Λ' = P Λ P` with `P = diag(I − w wᵀ, 1)`. Heading keeps the match's
//!    information when the scan pinned it (a wall seen over a long lever
//!    arm), and has little where it did not. Rotated into the key's frame,
//!    `Λ_k = Tᵀ Λ' T` with `T = diag(R(θ_key), 1)`, it is fused as a
//!    measurement, `Σ ← (Σ⁻¹ + Λ_k)⁻¹ = Σ (I + Λ_k Σ)⁻¹` (a form that never
//!    inverts the zero covariance at the key).
//! 3. **Edge.** At the next key, the edge's information is
//!    `(Rᵀ (Σ + F) R)⁻¹` with `R` the rotation of the measured relative pose
//!    (the graph measures the error in the frame of the node it ends at,
//!    [`super::posegraph`]) and `F` a floor (the key's own match is not
//!    exact), [`super::match_covariance::edge_information`].
//!
//! A stretch the scans pinned in every direction gives a stiff edge (a few
//! millimetres); a corridor edge is as loose along the corridor as odometry
//! over the distance between the keys and stiff across it; a stretch on
//! odometry alone is loose in every direction.

use super::filter::{inverse3, mul, symmetric, transpose, OdometryNoise};
use super::match_covariance::edge_information;
use crate::geom::{wrap_angle, Pose2};
use glam::DVec2;

type Mat3 = [[f64; 3]; 3];

/// What one matched scan told the front end: the match's information
/// (world frame, over x, y, θ) and, when the match was degenerate, the weak
/// direction (world frame, unit) along which odometry's word was kept.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StepMatch {
    pub information: Mat3,
    pub weak_direction: Option<DVec2>,
}

/// The pose relative to the last key and its covariance (key frame).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct KeyChain {
    key: Pose2,
    last: Pose2,
    covariance: Mat3,
}

impl KeyChain {
    /// A chain starting at a key: the relative pose known exactly.
    pub fn start(key: Pose2) -> KeyChain {
        KeyChain {
            key,
            last: key,
            covariance: [[0.0; 3]; 3],
        }
    }

    /// The covariance of the current pose relative to the key (key frame).
    pub fn covariance(&self) -> Mat3 {
        self.covariance
    }

    /// Moves the chain with the whole trajectory (a correction moved the
    /// key and the steps after it rigidly): the relative pose and its
    /// covariance stay.
    pub fn moved(&mut self, key: Pose2, last: Pose2) {
        self.key = key;
        self.last = last;
    }

    /// Step 1: the motion from the last pose to `to`, with odometry's noise.
    pub fn step(&mut self, to: &Pose2, noise: &OdometryNoise) {
        let before = self.key.between(&self.last);
        let after = self.key.between(to);
        let d = self.last.between(to);
        let s = d.position().length();
        let dtheta = wrap_angle(d.theta);
        let sd_m = noise.metres_per_metre * s + noise.floor_m;
        let sd_rad =
            noise.radians_per_metre * s + noise.radians_per_radian * dtheta.abs() + noise.floor_rad;
        let jr = [
            [1.0, 0.0, -(after.y - before.y)],
            [0.0, 1.0, after.x - before.x],
            [0.0, 0.0, 1.0],
        ];
        let (sn, cs) = before.theta.sin_cos();
        let jd = [[cs, -sn, 0.0], [sn, cs, 0.0], [0.0, 0.0, 1.0]];
        let q = diagonal(sd_m * sd_m, sd_rad * sd_rad);
        self.covariance = symmetric(&add(&sandwich(&jr, &self.covariance), &sandwich(&jd, &q)));
        self.last = *to;
    }

    /// Step 2: fuses a match of the current pose (see the module doc).
    pub fn observe(&mut self, m: &StepMatch) {
        let mut lambda = m.information;
        if let Some(w) = m.weak_direction {
            let p = [
                [1.0 - w.x * w.x, -w.x * w.y, 0.0],
                [-w.x * w.y, 1.0 - w.y * w.y, 0.0],
                [0.0, 0.0, 1.0],
            ];
            lambda = sandwich(&p, &lambda);
        }
        // δ_world = T δ_key: Λ_k = Tᵀ Λ T.
        let (sn, cs) = self.key.theta.sin_cos();
        let t_inv = [[cs, sn, 0.0], [-sn, cs, 0.0], [0.0, 0.0, 1.0]];
        let lambda_k = sandwich(&t_inv, &lambda);
        let mut i_plus = mul(&lambda_k, &self.covariance);
        for (r, row) in i_plus.iter_mut().enumerate() {
            row[r] += 1.0;
        }
        let Some(inv) = inverse3(&i_plus) else {
            return;
        };
        let next = symmetric(&mul(&self.covariance, &inv));
        if next.iter().flatten().all(|v| v.is_finite()) {
            self.covariance = next;
        }
    }

    /// Step 3: the information of the edge from the key to the current pose
    /// (measured as `z`), with the floor's standard deviations added.
    pub fn edge_information(&self, z: &Pose2, floor_m: f64, floor_rad: f64) -> Option<Mat3> {
        let f = diagonal(floor_m * floor_m, floor_rad * floor_rad);
        edge_information(&add(&self.covariance, &f), z.theta)
    }
}

fn diagonal(m2: f64, rad2: f64) -> Mat3 {
    [[m2, 0.0, 0.0], [0.0, m2, 0.0], [0.0, 0.0, rad2]]
}

fn add(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut m = *a;
    for (r, row) in m.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v += b[r][c];
        }
    }
    m
}

/// `J M Jᵀ`.
fn sandwich(j: &Mat3, m: &Mat3) -> Mat3 {
    mul(&mul(j, m), &transpose(j))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quiet() -> OdometryNoise {
        OdometryNoise {
            metres_per_metre: 0.1,
            radians_per_metre: 0.0,
            radians_per_radian: 0.0,
            floor_m: 0.0,
            floor_rad: 0.0,
            ..OdometryNoise::default()
        }
    }

    #[test]
    fn straight_steps_add_odometry_variance_in_the_key_frame() {
        // Key facing +y; two 1 m steps ahead: σ = 0.1 m per step, both axes.
        let key = Pose2::new(5.0, 5.0, std::f64::consts::FRAC_PI_2);
        let mut c = KeyChain::start(key);
        c.step(&Pose2::new(5.0, 6.0, key.theta), &quiet());
        c.step(&Pose2::new(5.0, 7.0, key.theta), &quiet());
        let s = c.covariance();
        assert!((s[0][0] - 0.02).abs() < 1e-12, "{s:?}");
        assert!((s[1][1] - 0.02).abs() < 1e-12);
        assert!(s[0][1].abs() < 1e-12 && s[2][2] == 0.0);
    }

    #[test]
    fn heading_noise_swings_the_lateral_variance_with_the_lever_arm() {
        // One 1 m step ahead with a pure heading variance, then another 1 m:
        // the first step's heading error σ_θ² moves the second step's end
        // sideways by 1 m · δθ: var(y) = σ_θ² · 1², cov(y, θ) = σ_θ².
        let noise = OdometryNoise {
            metres_per_metre: 0.0,
            radians_per_metre: 0.1,
            radians_per_radian: 0.0,
            floor_m: 0.0,
            floor_rad: 0.0,
            ..OdometryNoise::default()
        };
        let mut c = KeyChain::start(Pose2::IDENTITY);
        c.step(&Pose2::new(1.0, 0.0, 0.0), &noise);
        c.step(&Pose2::new(2.0, 0.0, 0.0), &noise);
        let s = c.covariance();
        assert!((s[1][1] - 0.01).abs() < 1e-12, "{s:?}");
        assert!((s[1][2] - 0.01).abs() < 1e-12);
        assert!((s[2][2] - 0.02).abs() < 1e-12);
        assert!(s[0][0].abs() < 1e-12);
    }

    #[test]
    fn a_degenerate_match_tightens_across_the_corridor_only() {
        // Key facing +y (world): the corridor runs along world y, which is
        // the key frame's x. Odometry variance 0.01 m² both ways; a match of
        // information 1e4 per axis (σ = 1 cm) with the weak direction world y.
        let key = Pose2::new(0.0, 0.0, std::f64::consts::FRAC_PI_2);
        let mut c = KeyChain::start(key);
        c.step(&Pose2::new(0.0, 1.0, key.theta), &quiet());
        let m = StepMatch {
            information: [[1e4, 0.0, 0.0], [0.0, 1e4, 0.0], [0.0, 0.0, 1e4]],
            weak_direction: Some(DVec2::Y),
        };
        c.observe(&m);
        let s = c.covariance();
        // Along (key x): unchanged 0.01. Across (key y = world −x):
        // 1 / (1 / 0.01 + 1e4) = 1 / 10100.
        assert!((s[0][0] - 0.01).abs() < 1e-12, "{s:?}");
        assert!((s[1][1] - 1.0 / 10_100.0).abs() < 1e-12);
        // The edge's information then, measured straight ahead (z.θ = 0),
        // is its inverse: 100 along, 10,100 across (heading: the floor's).
        let info = c
            .edge_information(&Pose2::new(1.0, 0.0, 0.0), 0.0, 0.01)
            .unwrap();
        assert!((info[0][0] - 100.0).abs() < 1e-6, "{info:?}");
        assert!((info[1][1] - 10_100.0).abs() < 1e-6);
    }
}
