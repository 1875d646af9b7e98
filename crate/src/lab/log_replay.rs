//! # A log replay session: what the CLI's `run-log` and the page drive
//!
//! Holds a parsed CARMEN log ([`crate::formats::carmen`]), the stretch of its laser
//! records to replay (`from..=to`, positions among the log's laser records),
//! and the [`LogSlam`] fed with them in file order, a few at a time (so a
//! page can animate it and a CLI can time it). At the end it draws the map
//! at the final poses and writes the report of `docs/interfaces.md`
//! ("Real laser logs: run-log").

use crate::formats::carmen::{parse_bytes, CarmenLog, LogError};
use crate::slam::export::MapInfo;
use crate::slam::grid::OccupancyGrid;
use crate::slam::logs::logslam::{ClosureInfo, LogSlam, LogSlamConfig, LogSlamStats};
use serde::Serialize;

/// A replay of one log.
pub struct LogReplay {
    pub log: CarmenLog,
    pub slam: LogSlam,
    from: usize,
    to: usize,
    next: usize,
    map: Option<OccupancyGrid>,
}

/// One scan of the report.
#[derive(Serialize)]
pub struct ScanReport {
    pub index: usize,
    pub time: f64,
    pub odometry: [f64; 3],
    pub pose: [f64; 3],
}

/// The `run-log` report.
#[derive(Serialize)]
pub struct LogReport {
    pub frame: &'static str,
    pub laser_records: usize,
    pub from: usize,
    pub to: usize,
    pub scans: Vec<ScanReport>,
    pub map: MapInfo,
    pub loop_closures: Vec<ClosureInfo>,
    pub slam: LogSlamStats,
    pub params: usize,
    pub odometry_records: usize,
    pub skipped: Vec<(String, usize)>,
    pub timings_ms: serde_json::Value,
}

/// What the report's `frame` says.
pub const FRAME: &str =
    "log: the log's own odometry frame (the first scan replayed is placed at its odometry pose)";

impl LogReplay {
    /// Parses a log (plain or gzip-compressed) and prepares to replay all of it.
    pub fn new(bytes: &[u8]) -> Result<LogReplay, LogError> {
        let log = parse_bytes(bytes)?;
        let to = log.scans.len() - 1;
        Ok(LogReplay {
            log,
            slam: LogSlam::new(LogSlamConfig::default()),
            from: 0,
            to,
            next: 0,
            map: None,
        })
    }

    /// Number of laser records in the log.
    pub fn laser_records(&self) -> usize {
        self.log.scans.len()
    }

    /// Replays only laser records `from..=to` (`to` clipped to the last);
    /// before the first step only.
    pub fn set_range(&mut self, from: usize, to: Option<usize>) -> Result<(), String> {
        if self.next > 0 {
            return Err("the replay has started: set the range first".into());
        }
        let last = self.log.scans.len() - 1;
        let to = to.unwrap_or(last).min(last);
        if from > to {
            return Err(format!(
                "--from {from} is past --to {to} (the log has {} laser records, 0 to {last})",
                last + 1
            ));
        }
        self.from = from;
        self.to = to;
        Ok(())
    }

    /// Replays up to `n` more scans; returns how many are left.
    pub fn step(&mut self, n: usize) -> usize {
        let mut done = 0;
        while done < n && self.from + self.next <= self.to {
            let scan = &self.log.scans[self.from + self.next];
            self.slam.add_scan(scan);
            self.next += 1;
            done += 1;
        }
        self.remaining()
    }

    /// The laser records replayed so far (a page draws the map as it grows
    /// from them with [`LogSlam::build_map`]).
    pub fn replayed(&self) -> &[crate::slam::logs::LogScan] {
        &self.log.scans[self.from..self.from + self.next]
    }

    pub fn remaining(&self) -> usize {
        self.to + 1 - self.from - self.next
    }

    /// Settles the pose graph and draws the map at the final poses.
    pub fn finish(&mut self) -> Result<(), String> {
        self.step(usize::MAX);
        self.slam.finish()?;
        let scans = &self.log.scans[self.from..=self.to];
        self.map = Some(self.slam.build_map(scans));
        Ok(())
    }

    /// The map drawn by [`LogReplay::finish`].
    pub fn map(&self) -> Result<&OccupancyGrid, String> {
        self.map
            .as_ref()
            .ok_or_else(|| "the replay has not finished: no map yet".to_string())
    }

    /// The report; `timings_ms` is passed through as given.
    pub fn report(&self, timings_ms: serde_json::Value) -> Result<LogReport, String> {
        let grid = self.map()?;
        let poses = self.slam.poses();
        let scans = self
            .slam
            .scans
            .iter()
            .zip(&poses)
            .map(|(s, p)| ScanReport {
                index: s.index,
                time: s.time,
                odometry: [s.odometry.x, s.odometry.y, s.odometry.theta],
                pose: [p.x, p.y, p.theta],
            })
            .collect();
        Ok(LogReport {
            frame: FRAME,
            laser_records: self.log.scans.len(),
            from: self.from,
            to: self.to,
            scans,
            map: MapInfo::of(grid),
            loop_closures: self.slam.closures.clone(),
            slam: self.slam.stats.clone(),
            params: self.log.params.len(),
            odometry_records: self.log.odometry_records,
            skipped: self.log.skipped.clone(),
            timings_ms,
        })
    }
}
