//! # One laser scan of a recorded log
//!
//! The log SLAM's input, whatever file it came from: a CARMEN log
//! ([`crate::formats::carmen`]) or a ROS bag. Each scan carries its own
//! beam geometry, the odometry pose at the scan and the laser's pose on the
//! robot; a reader fills it in file order.
//!
//! ## One canonical form
//!
//! The same scans reach the lab written in different ways: a CARMEN
//! `FLASER` line implies a 0.5° step (`π / 360`), a `ROBOTLASER1` line
//! prints it to six decimals (`0.008727`), a ROS `LaserScan` stores it as
//! a `float32`; ranges are decimal text or `float32`; a heading is a
//! decimal or a quaternion; times are decimal seconds or nanoseconds.
//! Those differences are far below any laser's accuracy, but a SLAM's loop
//! closures are yes/no decisions, and a last-bit difference in the input
//! can flip one and with it the map (the raw MIT CSAIL log kept 36
//! closures from its `FLASER` lines and 14 from the same scans written as
//! `ROBOTLASER1`). So every reader hands the SLAM its scans through
//! [`LogScan::canonical`], which rounds each number to a precision the
//! sensors never reach, the same way whatever it was written as:
//!
//! * ranges as `float32` (the type of [`LogScan::ranges`]: what ROS stores;
//!   a laser's own resolution is a millimetre or coarser), the maximum
//!   range rounded to the nearest `float32` too;
//! * the beam step to `2π / N` for the nearest whole `N` when it lies
//!   within 10⁻⁴ of it (a scanning laser's encoder divides the turn into
//!   `N` steps: 720 for a SICK at 0.5°, 1024 for a Hokuyo URG), else to the
//!   nearest `float32`; the first beam's bearing then to the nearest
//!   half-step when it lies within a thousandth of a step of one (a sweep
//!   from −90° in 0.5° steps starts at −180 half-steps), else to the
//!   nearest `float32`;
//! * poses (odometry, the logged pose, the laser's offset) to the
//!   micrometre and the microradian, the heading first wrapped into
//!   (−π, π];
//! * the time to the microsecond.

use crate::geom::{wrap_angle, Pose2};
use std::f64::consts::TAU;
use std::sync::Arc;

/// One laser scan of the log, in file order.
#[derive(Clone, Debug, PartialEq)]
pub struct LogScan {
    /// Position among the log's laser records (`FLASER`, `ROBOTLASER1`,
    /// `RAWLASER1`), 0-based.
    pub index: usize,
    /// Line of the file it came from (1-based).
    pub line: usize,
    /// The record's IPC timestamp (s), as written.
    pub time: f64,
    /// Bearing of the first beam in the laser frame (rad, 0 = ahead).
    pub start_angle: f64,
    /// Angle between neighbouring beams (rad).
    pub angle_step: f64,
    /// The laser's maximum range: a range at or beyond it is no return.
    pub max_range: f64,
    /// Ranges (m), beam 0 first, as `float32` (what ROS stores; far finer
    /// than any laser resolves): +∞ where the laser saw nothing within
    /// range, NaN where it gave no reading (a ROS range below `range_min`,
    /// or NaN). Shared, not copied, between a bag's contents and the scans
    /// replayed from it.
    pub ranges: Arc<[f32]>,
    /// The robot's odometry pose at the scan.
    pub odometry: Pose2,
    /// The pose the log gives for the robot (corrected logs: the corrected
    /// pose); `None` when the record carries none.
    pub logged_pose: Option<Pose2>,
    /// The laser's pose on the robot.
    pub laser_offset: Pose2,
}

impl LogScan {
    /// Bearing of beam `i` in the laser frame.
    pub fn bearing(&self, i: usize) -> f64 {
        self.start_angle + self.angle_step * i as f64
    }

    /// True when beam `i` saw nothing within range.
    pub fn no_return(&self, i: usize) -> bool {
        let r = self.ranges[i] as f64;
        !(r > 0.0 && r < self.max_range - 1e-3)
    }

    /// The scan in the one form every reader hands the SLAM (see the
    /// module's doc). Refuses a scan the SLAM cannot use: no beams, a step
    /// of zero or not a number, beams spanning more than a full turn, a
    /// maximum range that is not a positive number.
    pub fn canonical(mut self) -> Result<LogScan, String> {
        let n = self.ranges.len();
        if n == 0 {
            return Err("a scan with no beams".into());
        }
        if !(self.angle_step.is_finite() && self.angle_step != 0.0) {
            return Err(format!(
                "the angle between beams is {}, not a non-zero number",
                self.angle_step
            ));
        }
        if !self.start_angle.is_finite() {
            return Err(format!(
                "the first beam's angle is {}, not a number",
                self.start_angle
            ));
        }
        let span = self.angle_step.abs() * (n - 1) as f64;
        if span > TAU * (1.0 + 1e-3) {
            return Err(format!(
                "{n} beams {:.4}° apart span {:.1}°, more than a full turn",
                self.angle_step.to_degrees(),
                span.to_degrees()
            ));
        }
        if !(self.max_range.is_finite() && self.max_range > 0.0) {
            return Err(format!(
                "the maximum range is {}, not a positive number",
                self.max_range
            ));
        }
        let (start, step) = canonical_beams(self.start_angle, self.angle_step);
        self.start_angle = start;
        self.angle_step = step;
        self.max_range = self.max_range as f32 as f64;
        self.odometry = micro(self.odometry);
        self.logged_pose = self.logged_pose.map(micro);
        self.laser_offset = micro(self.laser_offset);
        self.time = (self.time * 1e6).round() / 1e6;
        Ok(self)
    }
}

/// A pose rounded to the micrometre and the microradian (the heading
/// wrapped first).
fn micro(p: Pose2) -> Pose2 {
    let r = |v: f64| (v * 1e6).round() / 1e6;
    Pose2::new(r(p.x), r(p.y), r(wrap_angle(p.theta)))
}

/// A beam geometry `(start, step)` in canonical form: the step snapped to
/// `±2π / N` when within 10⁻⁴ of it, and then the start to a whole number
/// of half-steps when within a thousandth of a step; what does not snap is
/// rounded to the nearest `float32`.
pub fn canonical_beams(start: f64, step: f64) -> (f64, f64) {
    let f32ish = |v: f64| v as f32 as f64;
    let steps_per_turn = (TAU / step.abs()).round();
    if !(1.0..=1e6).contains(&steps_per_turn) {
        return (f32ish(start), f32ish(step));
    }
    let snapped = TAU / steps_per_turn;
    if (snapped - step.abs()).abs() > 1e-4 * step.abs() {
        return (f32ish(start), f32ish(step));
    }
    let half = TAU / (2.0 * steps_per_turn);
    let k = (start / half).round();
    let start = if (start - k * half).abs() <= 1e-3 * snapped {
        k * TAU / (2.0 * steps_per_turn)
    } else {
        f32ish(start)
    };
    (start, snapped.copysign(step))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn scan(start: f64, step: f64, ranges: Vec<f64>) -> LogScan {
        let ranges: Arc<[f32]> = ranges.iter().map(|&r| r as f32).collect();
        LogScan {
            index: 0,
            line: 1,
            time: 1134864629.895182,
            start_angle: start,
            angle_step: step,
            max_range: 81.91,
            ranges,
            odometry: Pose2::new(576.536523, 0.106594, -2.254938),
            logged_pose: None,
            laser_offset: Pose2::IDENTITY,
        }
    }

    #[test]
    #[allow(clippy::approx_constant)] // the six decimals a log prints
    fn one_geometry_written_three_ways_is_one_geometry() {
        // FLASER's implied −90° + 0.5° steps, ROBOTLASER1's six decimals,
        // and a LaserScan's float32s.
        let exact = canonical_beams(-PI / 2.0, PI / 360.0);
        let printed = canonical_beams(-1.570796, 0.008727);
        let float32 = canonical_beams((-PI / 2.0) as f32 as f64, (PI / 360.0) as f32 as f64);
        assert_eq!(exact, printed);
        assert_eq!(exact, float32);
        assert!((exact.0 + PI / 2.0).abs() < 1e-15 && (exact.1 - PI / 360.0).abs() < 1e-17);
        // A Hokuyo URG's 1024 steps a turn, the first beam 340 steps right.
        let (start, step) = canonical_beams(-2.0862138271331787, 0.006135923322290182);
        assert_eq!(step, TAU / 1024.0);
        assert!((start + 680.0 * TAU / 2048.0).abs() < 1e-15);
        // A step that is no 2π / N (Stage's 270° over 90 beams) only loses
        // its last float32 bit, and a sweep the other way keeps its sign.
        let (s, d) = canonical_beams(-2.356194496154785, 0.05294819176197052);
        assert_eq!((s, d), (-2.356194496154785, 0.05294819176197052));
        assert_eq!(canonical_beams(PI / 2.0, -PI / 360.0).1, -PI / 360.0);
    }

    #[test]
    #[allow(clippy::approx_constant)] // a heading printed past π
    fn numbers_are_rounded_past_what_any_sensor_resolves() {
        let a = scan(-PI / 2.0, PI / 360.0, vec![1.23, 81.91, 0.0])
            .canonical()
            .expect("valid");
        let mut b = scan(
            -PI / 2.0,
            PI / 360.0,
            vec![1.23f32 as f64, 81.91f32 as f64, 0.0],
        );
        // The same pose as a heading from a quaternion and a time from
        // nanoseconds.
        let th = -2.254938f64;
        b.odometry.theta = 2.0 * (th / 2.0).sin().atan2((th / 2.0).cos());
        b.time = 1134864629895181894i64 as f64 * 1e-9;
        let b = b.canonical().expect("valid");
        assert_eq!(a, b);
        assert_eq!(a.ranges[0], 1.23f32);
        assert_eq!(a.time, 1134864629.895182);
        // A heading past π comes back wrapped.
        let mut c = scan(0.0, PI / 180.0, vec![1.0]);
        c.odometry.theta = 3.141593;
        assert!(c.canonical().expect("valid").odometry.theta < 0.0);
    }

    #[test]
    fn a_scan_the_slam_cannot_use_is_refused() {
        let no_beams = scan(0.0, 0.01, vec![]).canonical();
        assert!(no_beams.unwrap_err().contains("no beams"));
        let flat = scan(0.0, 0.0, vec![1.0, 2.0]).canonical();
        assert!(flat.unwrap_err().contains("not a non-zero number"));
        let too_wide = scan(0.0, 0.1, vec![1.0; 100]).canonical();
        assert!(too_wide.unwrap_err().contains("more than a full turn"));
        let mut no_max = scan(0.0, 0.01, vec![1.0]);
        no_max.max_range = f64::NAN;
        assert!(no_max.canonical().unwrap_err().contains("maximum range"));
        // A full turn of 360 beams is fine.
        assert!(scan(0.0, TAU / 360.0, vec![1.0; 360]).canonical().is_ok());
    }
}
