//! # The log replay session: what the CLI's `run-log` and "Your log…" drive
//!
//! Holds a parsed CARMEN log ([`crate::formats::carmen`]), the stretch of its laser
//! records to replay (`from..=to`, positions among the log's laser records),
//! and the [`LogSlam`] fed with them in file order, a few at a time (so a
//! page can animate it and a CLI can time it). While it runs, the page
//! reads its view ([`LogReplay::view`]: the paths and loop closures so far)
//! and the live map ([`LogReplay::draw_live`]); at the end it draws the map
//! at the final poses and writes the report of `docs/interfaces.md`
//! ("Real laser logs: run-log").

use crate::formats::carmen::{parse_bytes, CarmenLog, LogError};
use crate::geom::Pose2;
use crate::slam::export::{self, MapInfo};
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
    /// The map of the scans replayed so far at their current poses, drawn
    /// by [`LogReplay::draw_live`].
    live: Option<OccupancyGrid>,
}

/// The replay so far, for a page that animates it.
#[derive(Serialize)]
pub struct ReplayView {
    /// Scans replayed, of `total`.
    pub done: usize,
    pub total: usize,
    /// Each replayed scan's odometry, flat `[x, y, theta, ...]` (the first
    /// scan at its odometry pose).
    pub odometry: Vec<f64>,
    /// Each replayed scan's current SLAM pose, flat, same frame.
    pub poses: Vec<f64>,
    /// Each loop closure found so far.
    pub closures: Vec<ClosureView>,
}

/// A loop closure as the page draws it: the segment between its two key
/// scans' current poses.
#[derive(Serialize)]
pub struct ClosureView {
    /// `[x1, y1, x2, y2]`.
    pub segment: [f64; 4],
    pub from_scan: usize,
    pub to_scan: usize,
    pub score: f64,
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
            live: None,
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

    /// The map as a binary PGM (ROS map_server).
    pub fn map_pgm(&self) -> Result<Vec<u8>, String> {
        Ok(export::to_pgm(self.map()?))
    }

    /// The map as a PNG.
    pub fn map_png(&self) -> Result<Vec<u8>, String> {
        export::to_png(self.map()?).map_err(|e| e.to_string())
    }

    /// The map_server YAML naming `image` (the PGM's file name).
    pub fn map_yaml(&self, image: &str) -> Result<String, String> {
        Ok(export::to_yaml(self.map()?, image))
    }

    /// The replay so far: paths and loop closures.
    pub fn view(&self) -> ReplayView {
        let slam = &self.slam;
        let flat = |poses: &mut dyn Iterator<Item = Pose2>| -> Vec<f64> {
            poses.flat_map(|p| [p.x, p.y, p.theta]).collect()
        };
        let node = |k: usize| slam.graph.nodes.get(k).copied().unwrap_or_default();
        let closures = slam
            .closures
            .iter()
            .map(|c| {
                let (a, b) = (node(c.from_key), node(c.to_key));
                ClosureView {
                    segment: [a.x, a.y, b.x, b.y],
                    from_scan: c.from_scan,
                    to_scan: c.to_scan,
                    score: c.score,
                }
            })
            .collect();
        ReplayView {
            done: self.replayed().len(),
            total: self.replayed().len() + self.remaining(),
            odometry: flat(&mut slam.scans.iter().map(|s| s.odometry)),
            poses: flat(&mut slam.poses().into_iter()),
            closures,
        }
    }

    /// Draws the map of the scans replayed so far at their current poses
    /// (kept for [`LogReplay::live_info`] and [`LogReplay::live_pixels`]);
    /// returns false before the first scan.
    pub fn draw_live(&mut self) -> bool {
        let scans = self.replayed();
        if scans.is_empty() {
            return false;
        }
        self.live = Some(self.slam.build_map(scans));
        true
    }

    fn live(&self) -> Result<&OccupancyGrid, String> {
        self.live
            .as_ref()
            .ok_or_else(|| "drawLive first".to_string())
    }

    /// Size, resolution and origin of the live map.
    pub fn live_info(&self) -> Result<MapInfo, String> {
        Ok(MapInfo::of(self.live()?))
    }

    /// The live map's grey pixels (PGM shades), top row first.
    pub fn live_pixels(&self) -> Result<Vec<u8>, String> {
        Ok(export::grey_rows_top_first(self.live()?))
    }
}
