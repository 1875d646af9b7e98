//! # Reading CARMEN laser logs
//!
//! The classic real 2-D SLAM datasets (the Intel lab, ACES, MIT CSAIL,
//! Freiburg 079 of the Radish repository) are CARMEN logs: plain text, one
//! record per line, fields separated by white space, the record's name first
//! (Montemerlo, Roy and Thrun, "Perspectives on standardization in mobile
//! robot programming: the Carnegie Mellon Navigation (CARMEN) toolkit",
//! IROS 2003). This module reads `.log` / `.clf` files, gzip-compressed or
//! not (recognised by the gzip magic bytes, whatever the file is called).
//!
//! ## The records read
//!
//! * `FLASER n r1 … rn x y θ odom_x odom_y odom_θ ipc_time [host logger_time]`:
//!   a front laser scan of `n` ranges sweeping 180° from −90° (right) to
//!   +90° (left), with the robot's pose (`x y θ`, in corrected logs the
//!   corrected pose) and its odometry. An odd `n` (181, 361) has a beam at
//!   both ends (step 180° / (n − 1)); an even `n` (180, 360) steps 180° / n
//!   from −90°, the convention of the CARMEN logs on Radish.
//! * `ROBOTLASER1 type start_angle fov resolution max_range accuracy
//!   remission_mode n r1 … rn m e1 … em laser_x laser_y laser_θ robot_x
//!   robot_y robot_θ tv rv fwd_safety side_safety turn_axis ipc_time [host
//!   logger_time]`: a scan that says its own geometry; the laser's offset on
//!   the robot is `robot⁻¹ ⊕ laser`.
//! * `RAWLASER1 type start_angle fov resolution max_range accuracy
//!   remission_mode n r1 … rn m e1 … em ipc_time [host logger_time]`: a scan
//!   without any pose; its odometry comes from the `ODOM` records around it.
//! * `ODOM x y θ tv rv accel ipc_time [host logger_time]`: wheel odometry.
//!   A laser record without a pose gets the odometry interpolated between
//!   the `ODOM` records before and after it in the file (linearly in time
//!   when their timestamps bracket the scan's, else the one before it).
//! * `PARAM name value …`: kept as name/value pairs.
//!
//! `RLASER` (the rear laser) is counted and not used: the lab maps with the
//! front laser. Comments (`#`), empty lines and every other record (`NEFF`,
//! `TRUEPOS`, `SYNC`, …) are skipped and counted in [`CarmenLog::skipped`]:
//! nothing is dropped silently. A malformed or truncated laser, odometry or
//! parameter record is an error naming its line.
//!
//! ## "No return" and time
//!
//! A laser reports "nothing within range" as its largest value (81.91 m,
//! 81.83 m, 50 m or 32.77 m, depending on the unit and logger). A
//! `ROBOTLASER1` says its maximum range; for `FLASER` logs the maximum is
//! the largest range in the whole log (the sentinel, repeated thousands of
//! times in every log of the dataset). A beam at or beyond the maximum, or
//! at zero or below, is [`LaserScan::no_return`]: a mapper may clear space
//! along it up to a sensible distance but must not mark a wall there.
//!
//! Timestamps are broken in several logs (all zero, repeated, printed with
//! six digits so a whole log shares one value): scans are kept in file
//! order, and the time is only reported, never used to order anything.
//!
//! Every scan leaves the reader in the canonical form of
//! [`crate::slam::logs::LogScan::canonical`] (ranges as `float32`, the beam
//! step snapped to the laser's `2π / N`, poses to the micrometre), the form
//! a ROS bag's scans take too: a log written as `FLASER` lines, as
//! `ROBOTLASER1` lines or as a bag replays the same.

use crate::geom::Pose2;
use crate::slam::logs::LogScan;
use std::io::Read;

/// A parsed log.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CarmenLog {
    pub scans: Vec<LogScan>,
    /// `PARAM` records: name and value.
    pub params: Vec<(String, String)>,
    /// Lines not used, by reason: `("comment", n)`, `("RLASER", n)`,
    /// `("NEFF", n)`, … in order of first appearance.
    pub skipped: Vec<(String, usize)>,
    /// Number of `ODOM` records read.
    pub odometry_records: usize,
}

/// A log that could not be read: the line (1-based, 0 for the whole file)
/// and what is wrong with it.
#[derive(Clone, Debug, PartialEq)]
pub struct LogError {
    pub line: usize,
    pub message: String,
}

impl std::fmt::Display for LogError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.line == 0 {
            write!(f, "{}", self.message)
        } else {
            write!(f, "line {}: {}", self.line, self.message)
        }
    }
}

impl std::error::Error for LogError {}

fn fail<T>(line: usize, message: impl Into<String>) -> Result<T, LogError> {
    Err(LogError {
        line,
        message: message.into(),
    })
}

/// Reads a log from its bytes: gzip-compressed (recognised by its magic
/// bytes) or plain text.
pub fn parse_bytes(bytes: &[u8]) -> Result<CarmenLog, LogError> {
    if bytes.starts_with(&[0x1f, 0x8b]) {
        let mut text = String::new();
        flate2::read::MultiGzDecoder::new(bytes)
            .read_to_string(&mut text)
            .map_err(|e| LogError {
                line: 0,
                message: format!("not a readable gzip-compressed text log: {e}"),
            })?;
        parse_str(&text)
    } else {
        let text = std::str::from_utf8(bytes).map_err(|e| {
            let line = 1 + bytes[..e.valid_up_to()]
                .iter()
                .filter(|&&b| b == b'\n')
                .count();
            LogError {
                line,
                message: "not text (invalid UTF-8): is this a CARMEN log?".into(),
            }
        })?;
        parse_str(text)
    }
}

/// An `ODOM` record: where it was in the file and what it said.
struct Odom {
    laser_records_before: usize,
    time: f64,
    pose: Pose2,
}

/// Reads a log from its text.
pub fn parse_str(text: &str) -> Result<CarmenLog, LogError> {
    let mut log = CarmenLog::default();
    let mut odoms: Vec<Odom> = Vec::new();
    // Laser records without a pose: (scan index, odometry records before it).
    let mut needs_odometry: Vec<(usize, usize)> = Vec::new();
    let mut flaser_max = f64::NEG_INFINITY;
    for (k, raw) in text.lines().enumerate() {
        let line = k + 1;
        let mut fields = raw.split_whitespace();
        let Some(name) = fields.next() else {
            skip(&mut log, "empty line");
            continue;
        };
        if name.starts_with('#') {
            skip(&mut log, "comment");
            continue;
        }
        let f = Fields::new(fields.collect(), line, name);
        let index = log.scans.len();
        match name {
            "FLASER" => {
                let scan = flaser(&f, index)?;
                flaser_max = scan.ranges.iter().fold(flaser_max, |m, &r| m.max(r as f64));
                log.scans.push(scan);
            }
            "ROBOTLASER1" => log.scans.push(robotlaser(&f, index, true)?),
            "RAWLASER1" => {
                needs_odometry.push((index, odoms.len()));
                log.scans.push(robotlaser(&f, index, false)?);
            }
            "ODOM" => {
                odoms.push(Odom {
                    laser_records_before: index,
                    time: f.num(6)?,
                    pose: Pose2::new(f.num(0)?, f.num(1)?, f.num(2)?),
                });
                log.odometry_records += 1;
            }
            "PARAM" => log
                .params
                .push((f.text(0)?.to_string(), f.text(1)?.to_string())),
            other => skip(&mut log, other),
        }
    }
    for s in log.scans.iter_mut() {
        if s.max_range.is_nan() {
            s.max_range = flaser_max;
        }
    }
    for (index, before) in needs_odometry {
        let scan = &mut log.scans[index];
        scan.odometry = odometry_at(&odoms, before, scan.time).ok_or_else(|| LogError {
            line: scan.line,
            message: "a RAWLASER1 record carries no pose and the log has no ODOM record".into(),
        })?;
    }
    if log.scans.is_empty() {
        return fail(
            0,
            "no laser records (FLASER, ROBOTLASER1 or RAWLASER1) in the log",
        );
    }
    // The one form every reader hands the SLAM (LogScan::canonical): the
    // same scans give the same answer whichever way they were written.
    log.scans = std::mem::take(&mut log.scans)
        .into_iter()
        .map(|s| {
            let line = s.line;
            s.canonical().map_err(|message| LogError { line, message })
        })
        .collect::<Result<_, _>>()?;
    Ok(log)
}

fn skip(log: &mut CarmenLog, reason: &str) {
    match log.skipped.iter_mut().find(|(r, _)| r == reason) {
        Some((_, n)) => *n += 1,
        None => log.skipped.push((reason.to_string(), 1)),
    }
}

/// The odometry at a laser record that has `before` ODOM records ahead of
/// it in the file: interpolated in time between that one and the next when
/// their timestamps bracket `time`, else the one before (or, at the start
/// of the log, the first one after).
fn odometry_at(odoms: &[Odom], before: usize, time: f64) -> Option<Pose2> {
    let prev = before.checked_sub(1).and_then(|i| odoms.get(i));
    let next = odoms.get(before);
    match (prev, next) {
        (Some(a), Some(b)) if a.time < b.time && a.time <= time && time <= b.time => {
            debug_assert!(a.laser_records_before <= b.laser_records_before);
            let u = (time - a.time) / (b.time - a.time);
            let dtheta = crate::geom::wrap_angle(b.pose.theta - a.pose.theta);
            Some(Pose2::new(
                a.pose.x + u * (b.pose.x - a.pose.x),
                a.pose.y + u * (b.pose.y - a.pose.y),
                crate::geom::wrap_angle(a.pose.theta + u * dtheta),
            ))
        }
        (Some(a), _) => Some(a.pose),
        (None, Some(b)) => Some(b.pose),
        (None, None) => None,
    }
}

/// The fields of one record after its name, with errors that name the line.
struct Fields<'a> {
    items: Vec<&'a str>,
    line: usize,
    name: &'a str,
}

impl<'a> Fields<'a> {
    fn new(items: Vec<&'a str>, line: usize, name: &'a str) -> Self {
        Fields { items, line, name }
    }

    fn text(&self, i: usize) -> Result<&'a str, LogError> {
        match self.items.get(i) {
            Some(s) => Ok(s),
            None => fail(
                self.line,
                format!(
                    "{} record is truncated: it has {} fields, field {} is missing",
                    self.name,
                    self.items.len(),
                    i + 1
                ),
            ),
        }
    }

    fn num(&self, i: usize) -> Result<f64, LogError> {
        let s = self.text(i)?;
        match s.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => fail(
                self.line,
                format!(
                    "{} record: field {} is '{s}', not a number",
                    self.name,
                    i + 1
                ),
            ),
        }
    }

    fn count(&self, i: usize) -> Result<usize, LogError> {
        let s = self.text(i)?;
        match s.parse::<usize>() {
            Ok(n) if n <= 100_000 => Ok(n),
            _ => fail(
                self.line,
                format!(
                    "{} record: field {} is '{s}', not a beam count",
                    self.name,
                    i + 1
                ),
            ),
        }
    }

    fn ranges(&self, from: usize, n: usize) -> Result<Vec<f64>, LogError> {
        if self.items.len() < from + n {
            return fail(
                self.line,
                format!(
                    "{} record is truncated: {} ranges announced, {} fields follow",
                    self.name,
                    n,
                    self.items.len().saturating_sub(from)
                ),
            );
        }
        (from..from + n).map(|i| self.num(i)).collect()
    }

    fn pose(&self, at: usize) -> Result<Pose2, LogError> {
        Ok(Pose2::new(
            self.num(at)?,
            self.num(at + 1)?,
            self.num(at + 2)?,
        ))
    }
}

fn flaser(f: &Fields, index: usize) -> Result<LogScan, LogError> {
    let n = f.count(0)?;
    if n < 2 {
        return fail(f.line, format!("FLASER record with {n} beams"));
    }
    let ranges = f.ranges(1, n)?;
    let logged = f.pose(1 + n)?;
    let odometry = f.pose(4 + n)?;
    let time = f.num(7 + n)?;
    let half_pi = std::f64::consts::FRAC_PI_2;
    let step = if n % 2 == 1 {
        std::f64::consts::PI / (n - 1) as f64
    } else {
        std::f64::consts::PI / n as f64
    };
    Ok(LogScan {
        index,
        line: f.line,
        time,
        start_angle: -half_pi,
        angle_step: step,
        max_range: f64::NAN, // the log's largest range, set at the end
        ranges: ranges.iter().map(|&r| r as f32).collect(),
        odometry,
        logged_pose: Some(logged),
        laser_offset: Pose2::IDENTITY,
    })
}

/// `ROBOTLASER1` (with poses) or `RAWLASER1` (without).
fn robotlaser(f: &Fields, index: usize, with_poses: bool) -> Result<LogScan, LogError> {
    let start_angle = f.num(1)?;
    let fov = f.num(2)?;
    let step = f.num(3)?;
    let max_range = f.num(4)?;
    let n = f.count(7)?;
    if n < 2 || step <= 0.0 || max_range <= 0.0 {
        return fail(
            f.line,
            format!(
                "{}: {n} beams, angular resolution {step}, maximum range {max_range}",
                f.name
            ),
        );
    }
    if (fov - step * (n - 1) as f64).abs() > step * 1.5 && (fov - step * n as f64).abs() > step {
        return fail(
            f.line,
            format!(
                "{}: field of view {fov} rad does not fit {n} beams {step} rad apart",
                f.name
            ),
        );
    }
    let ranges = f.ranges(8, n)?;
    let m = f.count(8 + n)?;
    let after = 9 + n + m;
    if f.items.len() < after {
        return fail(
            f.line,
            format!(
                "{} record is truncated: {m} remission values announced",
                f.name
            ),
        );
    }
    let (odometry, logged_pose, offset, time) = if with_poses {
        let laser = f.pose(after)?;
        let robot = f.pose(after + 3)?;
        let time = f.num(after + 11)?;
        (robot, Some(robot), robot.between(&laser), time)
    } else {
        (Pose2::IDENTITY, None, Pose2::IDENTITY, f.num(after)?)
    };
    Ok(LogScan {
        index,
        line: f.line,
        time,
        start_angle,
        angle_step: step,
        max_range,
        ranges: ranges.iter().map(|&r| r as f32).collect(),
        odometry,
        logged_pose,
        laser_offset: offset,
    })
}
