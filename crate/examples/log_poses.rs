//! Every scan's final pose of a log replay, at full precision: the check
//! that a change to the log SLAM leaves its output bit for bit as it was.
//!
//! `cargo run --release -p slamlab --example log_poses -- LOG.gz… [--drift SEED]`
//!
//! Without `--drift`, each log is replayed as `run-log` does it
//! ([`slamlab::lab::log_replay::LogReplay`]: the log's own odometry, the map
//! drawn at the final poses). With `--drift SEED`, a corrected log's
//! odometry is replaced by odometry drifted from its own poses with that
//! seed (the default drift model), as the real-data suite replays it. Prints
//! each scan's pose (`{:?}` of the f64s), the accepted closures, the
//! matcher's counts and a hash of the map's cells; diff two runs' outputs.

use slamlab::formats::carmen::parse_bytes;
use slamlab::geom::Pose2;
use slamlab::lab::log_replay::LogReplay;
use slamlab::slam::eval::relations::{drift_odometry, DriftModel};
use slamlab::slam::logs::{LogSlam, LogSlamConfig};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let drift = match args.iter().position(|a| a == "--drift") {
        Some(k) => {
            let seed = args.get(k + 1).ok_or("--drift SEED")?.parse::<u64>()?;
            args.drain(k..k + 2);
            Some(seed)
        }
        None => None,
    };
    if args.is_empty() {
        return Err("usage: log_poses LOG.gz… [--drift SEED]".into());
    }
    for path in &args {
        let bytes = std::fs::read(path)?;
        println!("log {path}");
        match drift {
            None => replay(&bytes)?,
            Some(seed) => replay_drifted(&bytes, seed)?,
        }
    }
    Ok(())
}

/// The replay `run-log` makes.
fn replay(bytes: &[u8]) -> Result<(), Box<dyn std::error::Error>> {
    let mut r = LogReplay::new(bytes)?;
    r.finish()?;
    print_poses(&r.slam.poses());
    print_slam(&r.slam)?;
    let grid = r.map()?;
    let report = r.report(serde_json::Value::Null)?;
    println!("map {}", serde_json::to_string(&report.map)?);
    println!("map cells {:016x}", fnv(grid.raw_units()));
    Ok(())
}

/// The replay of a corrected log on odometry drifted from its own poses.
fn replay_drifted(bytes: &[u8], seed: u64) -> Result<(), Box<dyn std::error::Error>> {
    let log = parse_bytes(bytes)?;
    let reference: Vec<Pose2> = log
        .scans
        .iter()
        .map(|s| s.logged_pose.ok_or("a corrected log (FLASER poses)"))
        .collect::<Result<_, _>>()?;
    let odometry = drift_odometry(&reference, &DriftModel::default(), seed);
    let mut slam = LogSlam::new(LogSlamConfig::default());
    for (scan, odom) in log.scans.iter().zip(&odometry) {
        let mut s = scan.clone();
        s.odometry = *odom;
        slam.add_scan(&s);
    }
    slam.finish(&log.scans)?;
    print_poses(&slam.poses());
    print_slam(&slam)
}

fn print_poses(poses: &[Pose2]) {
    for (k, p) in poses.iter().enumerate() {
        println!("{k} {:?} {:?} {:?}", p.x, p.y, p.theta);
    }
}

fn print_slam(slam: &LogSlam) -> Result<(), Box<dyn std::error::Error>> {
    for c in &slam.closures {
        println!("closure {}", serde_json::to_string(c)?);
    }
    println!("stats {}", serde_json::to_string_pretty(&slam.stats)?);
    Ok(())
}

/// FNV-1a over the map's cells.
fn fnv(cells: &[i8]) -> u64 {
    cells.iter().fold(0xcbf2_9ce4_8422_2325, |h, &c| {
        (h ^ c as u8 as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}
