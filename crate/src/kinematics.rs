//! # Differential-drive kinematics of a Pioneer P2DX
//!
//! The P2DX (thesis §6.1.1.1, Figure 14) has two driven wheels on one axle
//! and a castor. If the left and right wheels roll `d_l` and `d_r` metres in
//! one control step, the robot's centre moves `d = (d_l + d_r)/2` along an arc
//! and turns by `Δθ = (d_r − d_l)/b`, where `b` is the wheelbase (the distance
//! between the wheels). The arc is integrated exactly:
//!
//! ```text
//! Δθ ≈ 0:  x' = x + d·cos θ,                      y' = y + d·sin θ
//! else:    x' = x + (d/Δθ)·(sin(θ+Δθ) − sin θ),   y' = y − (d/Δθ)·(cos(θ+Δθ) − cos θ)
//! ```
//!
//! The same function moves the true robot (with the true wheelbase) and
//! integrates odometry (with the wheelbase the robot *believes*), so that the
//! only difference between truth and odometry is the noise in
//! [`crate::odometry`].

use crate::geom::{wrap_angle, ConvexPolygon, Pose2};

/// The fixed control step: sensors are read and wheel speeds commanded
/// ten times per simulated second.
pub const CONTROL_DT_S: f64 = 0.1;

/// Dimensions and limits of the simulated Pioneer P2DX.
pub struct P2dx;

impl P2dx {
    /// Body length along the heading (m).
    pub const BODY_LENGTH_M: f64 = 0.455;
    /// Body width across the heading (m).
    pub const BODY_WIDTH_M: f64 = 0.381;
    /// Distance between the two driven wheels (m).
    pub const WHEEL_BASE_M: f64 = 0.33;
    /// Fastest a wheel may turn (m/s of rim speed).
    pub const MAX_WHEEL_SPEED_MPS: f64 = 0.5;
    /// Largest change of wheel speed per second (m/s²).
    pub const MAX_WHEEL_ACCEL_MPS2: f64 = 1.5;

    /// The body rectangle at `pose` (the pose is the body's centre, which is
    /// also the midpoint of the axle and the laser's position).
    pub fn body(pose: &Pose2) -> ConvexPolygon {
        ConvexPolygon::rectangle(pose, Self::BODY_LENGTH_M, Self::BODY_WIDTH_M)
    }
}

/// Moves `pose` by the wheel travels `d_left`, `d_right` (m) on an exact arc,
/// for a wheelbase `wheel_base` (m).
pub fn integrate_wheels(pose: &Pose2, d_left: f64, d_right: f64, wheel_base: f64) -> Pose2 {
    let d = 0.5 * (d_left + d_right);
    let dtheta = (d_right - d_left) / wheel_base;
    let (x, y, th) = (pose.x, pose.y, pose.theta);
    if dtheta.abs() < 1e-9 {
        let (s, c) = th.sin_cos();
        Pose2::new(x + d * c, y + d * s, th)
    } else {
        let r = d / dtheta;
        let th2 = th + dtheta;
        Pose2::new(
            x + r * (th2.sin() - th.sin()),
            y - r * (th2.cos() - th.cos()),
            wrap_angle(th2),
        )
    }
}

/// Wheel rim speeds `(left, right)` for a body speed `v` (m/s) and turn rate
/// `omega` (rad/s).
pub fn wheel_speeds(v: f64, omega: f64, wheel_base: f64) -> (f64, f64) {
    (v - 0.5 * omega * wheel_base, v + 0.5 * omega * wheel_base)
}

/// The wheels' actual speeds: they follow the commanded ones within the
/// speed and acceleration limits.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WheelState {
    pub left_mps: f64,
    pub right_mps: f64,
}

impl WheelState {
    /// Moves the wheel speeds toward the command for one step of `dt`,
    /// respecting [`P2dx::MAX_WHEEL_ACCEL_MPS2`] and
    /// [`P2dx::MAX_WHEEL_SPEED_MPS`]. Returns the wheel travels `(d_l, d_r)`
    /// over the step (trapezoidal rule on the speed ramp).
    pub fn advance(&mut self, cmd_left: f64, cmd_right: f64, dt: f64) -> (f64, f64) {
        let max = P2dx::MAX_WHEEL_SPEED_MPS;
        let dv = P2dx::MAX_WHEEL_ACCEL_MPS2 * dt;
        let step = |cur: f64, cmd: f64| {
            let cmd = cmd.clamp(-max, max);
            cur + (cmd - cur).clamp(-dv, dv)
        };
        let (l0, r0) = (self.left_mps, self.right_mps);
        self.left_mps = step(l0, cmd_left);
        self.right_mps = step(r0, cmd_right);
        (
            0.5 * (l0 + self.left_mps) * dt,
            0.5 * (r0 + self.right_mps) * dt,
        )
    }

    pub fn stop(&mut self) {
        *self = WheelState::default();
    }
}
