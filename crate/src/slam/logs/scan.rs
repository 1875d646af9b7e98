//! # One laser scan of a recorded log
//!
//! The log SLAM's input, whatever file it came from: a CARMEN log
//! ([`crate::formats::carmen`]) or a ROS bag. Each scan carries its own
//! beam geometry, the odometry pose at the scan and the laser's pose on the
//! robot; a reader fills it in file order.

use crate::geom::Pose2;

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
    /// Ranges (m), beam 0 first.
    pub ranges: Vec<f64>,
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
        let r = self.ranges[i];
        !(r > 0.0 && r < self.max_range - 1e-3)
    }
}
