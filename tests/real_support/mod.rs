//! Shared by the real-data log tests (`tests/real_logs.rs`) and the
//! benchmark example (`crate/examples/log_relations.rs`): locating the data,
//! replaying a log through the log SLAM, scoring it by relation errors.
#![allow(dead_code)]

use glam::DVec2;
use slamlab::formats::carmen::{parse_bytes, CarmenLog};
use slamlab::geom::Pose2;
use slamlab::slam::eval::relations::{drift_odometry, relation_errors, DriftModel, RelationErrors};
use slamlab::slam::eval::verified::{
    errors_by_gap, verified_relations, GapErrors, Verification, VerifyConfig,
};
use slamlab::slam::logs::logslam::{scan_points, LogSlam, LogSlamConfig};
use slamlab::slam::logs::LogScan;
use slamlab::slam::manhattan::ManhattanConfig;
use std::path::PathBuf;
use std::time::Instant;

/// `$SLAMLAB_DATA`, else `<repo>/../shared/data`; panics when missing.
pub fn data_dir() -> PathBuf {
    let dir = match std::env::var_os("SLAMLAB_DATA") {
        Some(d) => PathBuf::from(d),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/data"),
    };
    assert!(
        dir.join("carmen").is_dir(),
        "real data not found: {} has no carmen/ (set SLAMLAB_DATA to the shared data folder)",
        dir.display()
    );
    dir
}

pub fn load(name: &str) -> CarmenLog {
    let path = data_dir().join("carmen").join(name);
    let bytes =
        std::fs::read(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    parse_bytes(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The cell size of [`cells_hit`] (m).
pub const CRISP_CELL_M: f64 = 0.05;
/// Returns farther than this take no part in [`cells_hit`] (m): the
/// matching range of the log SLAM's defaults.
pub const CRISP_RANGE_M: f64 = 20.0;

/// A measure of a trajectory that needs no reference: the number of
/// distinct `CRISP_CELL_M` cells the scans' returns fall in, every scan at
/// its pose. The same walls seen from poses that agree land in the same
/// cells; a wrong pose draws a wall beside itself, in new cells. It is
/// blind to an error every scan of a place shares (a place seen once).
pub fn cells_hit(scans: &[LogScan], poses: &[Pose2]) -> usize {
    let mut cells = std::collections::HashSet::new();
    for (scan, pose) in scans.iter().zip(poses) {
        let laser = pose.compose(&scan.laser_offset);
        for (i, &r) in scan.ranges.iter().enumerate() {
            let r = r as f64;
            if scan.no_return(i) || r > CRISP_RANGE_M {
                continue;
            }
            let p = laser.position() + DVec2::from_angle(laser.theta + scan.bearing(i)) * r;
            let c = (p / CRISP_CELL_M).floor();
            cells.insert((c.x as i64, c.y as i64));
        }
    }
    cells.len()
}

/// One evaluated replay.
pub struct Outcome {
    pub ours: Vec<RelationErrors>,
    pub odometry: Vec<RelationErrors>,
    pub seconds: f64,
    pub scans: usize,
    pub closures: usize,
    pub slam: LogSlam,
    /// [`cells_hit`] at our poses and at the reference's (corrected logs).
    pub cells_hit: Option<(usize, usize)>,
}

/// Replays `log` (its odometry replaced by `odometry` when given) and
/// returns every scan's final pose and the SLAM.
pub fn replay(
    log: &CarmenLog,
    odometry: Option<&[Pose2]>,
    cfg: &LogSlamConfig,
) -> (Vec<Pose2>, LogSlam, f64) {
    let t0 = Instant::now();
    let mut slam = LogSlam::new(cfg.clone());
    for (k, scan) in log.scans.iter().enumerate() {
        match odometry {
            Some(o) => {
                let mut s = scan.clone();
                s.odometry = o[k];
                slam.add_scan(&s);
            }
            None => slam.add_scan(scan),
        }
    }
    slam.finish(&log.scans).expect("pose graph");
    let seconds = t0.elapsed().as_secs_f64();
    (slam.poses(), slam, seconds)
}

/// The seed of the drifting odometry in every figure.
pub const DRIFT_SEED: u64 = 21;
/// `$SLAMLAB_DRIFT_SEED` if set (to measure how much a figure moves with
/// the odometry's noise), else [`DRIFT_SEED`].
pub fn drift_seed() -> u64 {
    std::env::var("SLAMLAB_DRIFT_SEED")
        .map(|s| s.parse().expect("SLAMLAB_DRIFT_SEED: an integer"))
        .unwrap_or(DRIFT_SEED)
}

/// The drift model of every figure, its noise (not its bias) times
/// `$SLAMLAB_DRIFT_SCALE` if set (to measure a method against odometry
/// worse or better than the default's), and its distance error
/// `$SLAMLAB_DRIFT_DISTANCE_ERROR` if set (-0.02: the odometry reads 2 %
/// short, as the raw MIT CSAIL log's wheels do against GMapping's poses).
/// A method that takes the odometry's word along a corridor gains on the
/// default model, whose distance is unbiased, and should be checked with it
/// (docs/history/issue-21-real-laser-logs.md, round 21).
pub fn drift_model() -> DriftModel {
    let scale: f64 = std::env::var("SLAMLAB_DRIFT_SCALE")
        .map(|s| s.parse().expect("SLAMLAB_DRIFT_SCALE: a number"))
        .unwrap_or(1.0);
    let d = DriftModel::default();
    DriftModel {
        trans_per_m: d.trans_per_m * scale,
        rot_per_rad: d.rot_per_rad * scale,
        heading_per_m: d.heading_per_m * scale,
        distance_error: std::env::var("SLAMLAB_DRIFT_DISTANCE_ERROR")
            .map(|s| s.parse().expect("SLAMLAB_DRIFT_DISTANCE_ERROR: a number"))
            .unwrap_or(d.distance_error),
        ..d
    }
}

/// Random far pairs per evaluation.
pub const RANDOM_PAIRS: usize = 1000;

/// A corrected log's own poses (GMapping's), the reference it is scored
/// against.
pub fn logged_poses(log: &CarmenLog) -> Vec<Pose2> {
    log.scans
        .iter()
        .map(|s| s.logged_pose.expect("FLASER pose"))
        .collect()
}

/// A corrected log: its poses are the reference; odometry drifted from them
/// with drift seed `seed`.
pub fn corrected(name: &str, seed: u64) -> Outcome {
    corrected_seeded(name, &LogSlamConfig::default(), seed)
}

/// [`corrected`] with other SLAM settings, at [`drift_seed`].
pub fn corrected_with(name: &str, cfg: &LogSlamConfig) -> Outcome {
    corrected_seeded(name, cfg, drift_seed())
}

fn corrected_seeded(name: &str, cfg: &LogSlamConfig, seed: u64) -> Outcome {
    let log = load(name);
    let reference = logged_poses(&log);
    let odom = drift_odometry(&reference, &drift_model(), seed);
    let (est, slam, seconds) = replay(&log, Some(&odom), cfg);
    Outcome {
        ours: relation_errors(&est, &reference, RANDOM_PAIRS, 1),
        odometry: relation_errors(&odom, &reference, RANDOM_PAIRS, 1),
        seconds,
        scans: log.scans.len(),
        closures: slam.closures.len(),
        slam,
        cells_hit: Some((
            cells_hit(&log.scans, &est),
            cells_hit(&log.scans, &reference),
        )),
    }
}

/// The raw MIT CSAIL log against GMapping's poses for 406 of its scans.
pub fn csail_raw() -> (Outcome, f64) {
    csail_raw_with(&LogSlamConfig::default())
}

/// [`csail_raw`] with other SLAM settings.
/// The five logs of `../shared/data/carmen`, the raw one first.
pub const LOGS: [&str; 5] = [
    "mit-csail.clf.gz",
    "intel-corrected.log.gz",
    "aces-corrected.log.gz",
    "csail-corrected.log.gz",
    "freiburg-079-corrected.log.gz",
];

/// The logs named on the command line, or all of [`LOGS`].
pub fn logs_from_args() -> Vec<String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.is_empty() {
        LOGS.iter().map(|s| s.to_string()).collect()
    } else {
        args
    }
}

/// GMapping's pose for some of the raw MIT CSAIL log's scans:
/// `(scan index, pose)` from `mit-csail_gmapping_reference.txt`.
pub fn csail_gmapping_reference() -> Vec<(usize, Pose2)> {
    let path = data_dir().join("carmen/mit-csail_gmapping_reference.txt");
    let text = std::fs::read_to_string(&path).expect("reference file");
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|line| {
            let f: Vec<f64> = line
                .split_whitespace()
                .map(|v| v.parse().expect("number"))
                .collect();
            (f[0] as usize, Pose2::new(f[5], f[6], f[7]))
        })
        .collect()
}

pub fn csail_raw_with(cfg: &LogSlamConfig) -> (Outcome, f64) {
    let log = load("mit-csail.clf.gz");
    let (idx, reference): (Vec<usize>, Vec<Pose2>) = csail_gmapping_reference().into_iter().unzip();
    let (est, slam, seconds) = replay(&log, None, cfg);
    let ours: Vec<Pose2> = idx.iter().map(|&i| est[i]).collect();
    let odom: Vec<Pose2> = idx.iter().map(|&i| log.scans[i].odometry).collect();
    let recorded = log.scans.last().unwrap().time - log.scans[0].time;
    (
        Outcome {
            ours: relation_errors(&ours, &reference, RANDOM_PAIRS, 1),
            odometry: relation_errors(&odom, &reference, RANDOM_PAIRS, 1),
            seconds,
            scans: log.scans.len(),
            closures: slam.closures.len(),
            slam,
            cells_hit: None,
        },
        recorded,
    )
}

/// The pooled ("all") errors of a list.
pub fn pooled(e: &[RelationErrors]) -> &RelationErrors {
    e.last().expect("relation errors")
}

pub fn table(name: &str, o: &Outcome) -> String {
    let mut s = format!(
        "{name}: {} scans, {} keys, {} loop closures ({} rejected), {:.2} s\n",
        o.scans, o.slam.stats.keys, o.closures, o.slam.stats.closures_rejected, o.seconds
    );
    s += "  pairs      ours m / deg        odometry m / deg\n";
    for (a, b) in o.ours.iter().zip(&o.odometry) {
        s += &format!(
            "  {:8} {:7.3} / {:6.2}     {:7.3} / {:6.2}   ({} pairs)\n",
            a.pairs_of, a.trans_m, a.rot_deg, b.trans_m, b.rot_deg, a.pairs
        );
    }
    s
}

/// The square walls' settings of `cfg`, switched on with a log's defaults
/// if off.
fn manhattan(cfg: &mut LogSlamConfig) -> &mut ManhattanConfig {
    cfg.manhattan.get_or_insert_with(ManhattanConfig::for_logs)
}

/// The defaults with the overrides of `$SLAMLAB_LOG_SLAM`.
pub fn config_from_env() -> LogSlamConfig {
    let mut cfg = LogSlamConfig::default();
    let Ok(list) = std::env::var("SLAMLAB_LOG_SLAM") else {
        return cfg;
    };
    for item in list.split(',').filter(|s| !s.is_empty()) {
        let (key, value) = item.split_once('=').expect("SLAMLAB_LOG_SLAM: key=value");
        let v: f64 = value.parse().expect("SLAMLAB_LOG_SLAM: a number");
        match key {
            "key_sigma_m" => cfg.key_sigma_m = v,
            "key_sigma_deg" => cfg.key_sigma_rad = v.to_radians(),
            "loop_sigma_m" => cfg.loops.sigma_m = v,
            "loop_sigma_deg" => cfg.loops.sigma_rad = v.to_radians(),
            "loop_every" => cfg.loop_every = v as usize,
            "loop_min_score" => cfg.loops.min_score = v,
            "confirm_m" => cfg.confirm_m = v,
            "confirm_deg" => cfg.confirm_rad = v.to_radians(),
            "max_closure_chi2" => cfg.max_closure_chi2 = v,
            "velocity_prior" => cfg.velocity_prior = v != 0.0,
            "loop_edge_reject" => cfg.loop_edge_reject = v != 0.0,
            "loop_radius_m" => cfg.loops.search_radius_m = v,
            "loop_submap_half" => cfg.loops.submap_half = v as usize,
            "loop_window_m" => cfg.loops.window.linear_m = v,
            "loop_window_per_m" => cfg.loops.window_per_m = v,
            "loop_max_window_m" => cfg.loops.max_window_m = v,
            "grown_every" => cfg.grown_every = v as usize,
            "far_min_score" => cfg.far_min_score = v,
            "unique_ratio" => cfg.loops.unique_ratio = v,
            "loop_window_deg" => cfg.loops.window.angular_rad = v.to_radians(),
            "confirm_keys" => cfg.confirm_keys = v as usize,
            "wide_m" => cfg.wide.linear_m = v,
            "wide_deg" => cfg.wide.angular_rad = v.to_radians(),
            "loop_loosen_ratio" => cfg.loop_loosen_ratio = v,
            "key_loosen_ratio" => cfg.key_loosen_ratio = v,
            "local_keys" => cfg.local_keys = v as usize,
            "key_distance_m" => cfg.key_distance_m = v,
            "key_angle_deg" => cfg.key_angle_rad = v.to_radians(),
            "point_spacing_m" => cfg.point_spacing_m = v,
            "min_match_score" => cfg.min_match_score = v,
            "weak_match_score" => cfg.weak_match_score = v,
            "match_range_m" => cfg.match_range_m = v,
            "smooth_keys" => cfg.smooth_keys = v as usize,
            "smooth_iterations" => cfg.smooth_iterations = v as usize,
            "smooth_huber_m" => cfg.smooth_huber_m = v,
            "smooth_radius_m" => cfg.smooth_radius_m = v,
            "smooth_spacing_m" => cfg.smooth_spacing_m = v,
            "smooth_odometry" => cfg.smooth_odometry = v != 0.0,
            "smooth_max_move_m" => cfg.smooth_max_move_m = v,
            "fusion_max_move_m" => cfg.fusion_max_move_m = v,
            "smooth_max_turn_deg" => cfg.smooth_max_turn_rad = v.to_radians(),
            "close_loops" => cfg.close_loops = v != 0.0,
            "manhattan" => cfg.manhattan = (v != 0.0).then(ManhattanConfig::for_logs),
            "manhattan_sigma_deg" => manhattan(&mut cfg).sigma_rad = v.to_radians(),
            "manhattan_rounds" => manhattan(&mut cfg).rounds = v as usize,
            "manhattan_gate_deg" => manhattan(&mut cfg).gate_rad = v.to_radians(),
            "manhattan_window_deg" => manhattan(&mut cfg).window_rad = v.to_radians(),
            "manhattan_min_share" => manhattan(&mut cfg).min_share = v,
            "manhattan_line_min_m" => manhattan(&mut cfg).line_min_m = v,
            "manhattan_line_max_rms_m" => manhattan(&mut cfg).line_max_rms_m = v,
            _ => panic!("SLAMLAB_LOG_SLAM: unknown setting {key}"),
        }
    }
    println!("settings: {list}");
    cfg
}

/// A log scored against the relations its scans fix
/// ([`slamlab::slam::eval::verified`]).
pub struct VerifiedOutcome {
    pub scans: usize,
    pub verification: Verification,
    /// The errors by gap class of the reference, ours and the odometry.
    pub reference: Vec<GapErrors>,
    pub ours: Vec<GapErrors>,
    pub odometry: Vec<GapErrors>,
}

/// Replays log `name` (a corrected log with drifting odometry at
/// [`drift_seed`], or the raw MIT CSAIL log on the scans GMapping's poses
/// cover) and scores the reference, ours and the odometry against the
/// relations the scans fix between the reference's poses and ours.
pub fn verified(name: &str, cfg: &LogSlamConfig, verify: &VerifyConfig) -> VerifiedOutcome {
    let log = load(name);
    let (idx, reference, odometry, ours) = if name == "mit-csail.clf.gz" {
        let (est, _, _) = replay(&log, None, cfg);
        let (idx, reference): (Vec<usize>, Vec<Pose2>) =
            csail_gmapping_reference().into_iter().unzip();
        let odometry = idx.iter().map(|&i| log.scans[i].odometry).collect();
        let ours = idx.iter().map(|&i| est[i]).collect();
        (idx, reference, odometry, ours)
    } else {
        let reference = logged_poses(&log);
        let odometry = drift_odometry(&reference, &drift_model(), drift_seed());
        let (ours, _, _) = replay(&log, Some(&odometry), cfg);
        ((0..log.scans.len()).collect(), reference, odometry, ours)
    };
    // Every return within the matching range takes part.
    let dense = LogSlamConfig {
        point_spacing_m: 0.0,
        ..cfg.clone()
    };
    let points: Vec<Vec<DVec2>> = idx
        .iter()
        .map(|&i| scan_points(&log.scans[i], &dense))
        .collect();
    let verification = verified_relations(&points, &reference, &ours, verify);
    let by_gap = |p: &[Pose2]| errors_by_gap(&verification.relations, p);
    VerifiedOutcome {
        scans: idx.len(),
        reference: by_gap(&reference),
        ours: by_gap(&ours),
        odometry: by_gap(&odometry),
        verification,
    }
}
