//! # Wheel odometry: what the robot believes about its own motion
//!
//! A P2DX knows how far it has gone only from its wheel encoders (thesis
//! §4.2, §6.1.1.1). Each control step the true wheel travels `d_l`, `d_r` are
//! read back with two kinds of error:
//!
//! * **systematic** — a wheel whose effective radius is off reads
//!   `(1 + e_l)·d_l`; and the robot computes turns with a wheelbase
//!   `(1 + e_b)·b` that differs from the true `b`. These make the map bend the
//!   same way every time (Borenstein & Feng's "UMBmark" errors).
//! * **random slip** — a Gaussian with standard deviation `σ·|d|` on each
//!   wheel, independent per step, so position error grows like a random walk.
//!
//! The measured travels are integrated on the same exact arc as the truth
//! ([`crate::kinematics::integrate_wheels`]), starting from the identity:
//! a robot's odometry frame has its origin at its start pose.

use crate::geom::Pose2;
use crate::kinematics::{integrate_wheels, P2dx};
use crate::rng::Rng;
use crate::scenario::NoiseSpec;

/// An odometry integrator with its own noise stream.
#[derive(Clone, Debug)]
pub struct Odometry {
    pose: Pose2,
    rng: Rng,
    slip: f64,
    scale_error: [f64; 2],
    believed_wheel_base: f64,
    distance_m: f64,
}

impl Odometry {
    pub fn new(noise: &NoiseSpec, rng: Rng) -> Self {
        Odometry {
            pose: Pose2::IDENTITY,
            rng,
            slip: noise.wheel_slip,
            scale_error: noise.wheel_scale_error,
            believed_wheel_base: P2dx::WHEEL_BASE_M * (1.0 + noise.wheelbase_error),
            distance_m: 0.0,
        }
    }

    /// The pose in the odometry frame.
    pub fn pose(&self) -> Pose2 {
        self.pose
    }

    /// Total distance the robot believes it has driven.
    pub fn distance_m(&self) -> f64 {
        self.distance_m
    }

    /// Reads the encoders after the wheels truly rolled `d_left`, `d_right`
    /// and integrates the (noisy) readings. Returns the measured travels.
    pub fn update(&mut self, d_left: f64, d_right: f64) -> (f64, f64) {
        let ml = d_left * (1.0 + self.scale_error[0]) + self.rng.normal(self.slip * d_left.abs());
        let mr = d_right * (1.0 + self.scale_error[1]) + self.rng.normal(self.slip * d_right.abs());
        self.pose = integrate_wheels(&self.pose, ml, mr, self.believed_wheel_base);
        self.distance_m += 0.5 * (ml.abs() + mr.abs());
        (ml, mr)
    }
}
