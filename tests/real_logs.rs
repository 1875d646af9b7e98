//! Real-data suite (`./build.sh test-real`): the log SLAM on the real CARMEN
//! logs of `../shared/data/carmen` (or `$SLAMLAB_DATA/carmen`), scored by
//! relation errors (Kümmerle et al. 2009). Fails when the data is missing.
//!
//! The raw MIT CSAIL log is scored against GMapping's poses for 406 of its
//! scans; each corrected log (GMapping's poses) is replayed with drifting
//! odometry made from those poses (seeded, `slam::eval::relations::DriftModel`)
//! and scored against them, at four drift seeds. One seed's figure moves by
//! several centimetres with which loop closures a small change lets the
//! replay find (docs/history/issue-21-real-laser-logs.md), so the bounds hold
//! the mean over the seeds; each seed must beat its odometry. Bounds are the
//! figures measured on this code (BENCHMARKS.md, "Log replay") with a small
//! margin (the replay is deterministic); the targets (0.10 m, 1 deg,
//! a quarter of odometry's) are not met yet on most logs, so the bounds are
//! honest ones. On the corrected logs the scans must
//! also agree with each other at our poses about as well as at the
//! reference's, by a measure that needs no reference
//! (`support::cells_hit`).

#[path = "real_support/mod.rs"]
mod support;

use support::{pooled, Outcome};

/// The drift seeds of the corrected logs: the default one and three more.
const SEEDS: [u64; 4] = [support::DRIFT_SEED, 1, 2, 3];

/// Checks the pooled relation errors against `max_m` / `max_deg` and
/// against the odometry's (at most `share` of it).
fn check(name: &str, o: &Outcome, max_m: f64, max_deg: f64, share: f64) {
    let ours = pooled(&o.ours);
    assert!(
        ours.trans_m <= max_m && ours.rot_deg <= max_deg,
        "{name}: {:.3} m / {:.2} deg, bounds {max_m} m / {max_deg} deg",
        ours.trans_m,
        ours.rot_deg
    );
    against_odometry(name, o, share);
}

/// Replays corrected log `file` at every drift seed of [`SEEDS`]: each
/// seed against its odometry (at most `share` of it), the mean over the
/// seeds against `max_m` / `max_deg`.
fn check_seeds(name: &str, file: &str, max_m: f64, max_deg: f64, share: f64) {
    let (mut m, mut deg) = (0.0, 0.0);
    for seed in SEEDS {
        let o = support::corrected(file, seed);
        let name = format!("{name} (drift seed {seed})");
        against_odometry(&name, &o, share);
        let ours = pooled(&o.ours);
        m += ours.trans_m / SEEDS.len() as f64;
        deg += ours.rot_deg / SEEDS.len() as f64;
    }
    println!("{name}: mean over drift seeds {SEEDS:?}: {m:.3} m / {deg:.2} deg");
    assert!(
        m <= max_m && deg <= max_deg,
        "{name}: {m:.3} m / {deg:.2} deg over drift seeds {SEEDS:?}, bounds {max_m} m / {max_deg} deg"
    );
}

/// Beats the odometry (at most `share` of its translational error, less
/// rotational error); the square walls' prior found; the scans agree with
/// each other about as well as at the reference's poses.
fn against_odometry(name: &str, o: &Outcome, share: f64) {
    println!("{}", support::table(name, o));
    let (ours, odom) = (pooled(&o.ours), pooled(&o.odometry));
    assert!(
        ours.trans_m <= share * odom.trans_m,
        "{name}: {:.3} m is more than {share} of odometry's {:.3} m",
        ours.trans_m,
        odom.trans_m
    );
    assert!(
        ours.rot_deg < odom.rot_deg,
        "{name}: rotation {:.2} deg not better than odometry's {:.2} deg",
        ours.rot_deg,
        odom.rot_deg
    );
    // Every one of these buildings is square enough for the heading prior.
    assert!(
        o.slam.stats.square_keys > 0,
        "{name}: no key got the square walls' prior"
    );
    if let Some((ours, reference)) = o.cells_hit {
        println!("{name}: returns in {ours} cells at our poses, {reference} at the reference's");
        assert!(
            ours as f64 <= CELLS_MARGIN * reference as f64,
            "{name}: the scans fall in {ours} cells at our poses, more than {CELLS_MARGIN} x the reference's {reference}"
        );
    }
}

/// Our poses may put the returns in at most this many times the cells the
/// reference's poses do ([`support::cells_hit`], a measure needing no
/// reference). Measured at the four drift seeds with the canonical scan
/// form (`LogScan::canonical`): ACES 0.985–1.031 (seed 2, where a loop
/// closure now lands a few centimetres off), CSAIL corrected 0.95–0.97,
/// Intel 0.87–0.92, Freiburg 079 0.84–0.85 (weakly matched scans taken
/// into the local map made ACES 1.033–1.038).
const CELLS_MARGIN: f64 = 1.035;

#[test]
fn mit_csail_raw_log_against_gmapping() {
    let (o, recorded) = support::csail_raw();
    // Measured: 0.193 m / 0.95 deg against odometry's 6.628 m / 18.80 deg
    // (the 0.10 m / 1 deg is not met on this log: see BENCHMARKS.md,
    // "Log replay", and docs/history/issue-21-real-laser-logs.md).
    check("mit-csail.clf.gz", &o, 0.20, 1.0, 0.25);
    assert!(o.closures > 0, "the CSAIL tour revisits corridors");
    println!("recorded {recorded:.0} s, replayed in {:.1} s", o.seconds);
}

// The corrected logs' bounds hold the mean over the four drift seeds.
// Measured: Intel 0.099 m / 0.72 deg; ACES 0.171 / 0.46; CSAIL corrected
// 0.205 / 1.01; Freiburg 079 0.054 / 0.77.

#[test]
fn intel_with_drifting_odometry() {
    check_seeds("intel", "intel-corrected.log.gz", 0.105, 0.76, 0.25);
}

#[test]
fn aces_with_drifting_odometry() {
    check_seeds("aces", "aces-corrected.log.gz", 0.18, 0.50, 0.25);
}

#[test]
fn csail_corrected_with_drifting_odometry() {
    check_seeds("csail", "csail-corrected.log.gz", 0.215, 1.05, 0.25);
}

#[test]
fn freiburg_079_with_drifting_odometry() {
    // The targets, met: 0.053-0.054 m at each of the four seeds.
    check_seeds(
        "freiburg-079",
        "freiburg-079-corrected.log.gz",
        0.06,
        0.80,
        0.25,
    );
}

/// Against the relations the scans themselves fix (`slam::eval::verified`,
/// Kümmerle et al.'s relations with the person replaced by checks), at the
/// default drift seed: our poses within 0.035 m / 0.40 deg on average, no
/// further off than the reference's own poses, and at most a quarter of
/// the odometry's error. Measured (ours / the reference's,
/// all gaps): raw MIT CSAIL 0.019 m / 0.30 deg (0.029 / 0.69), Intel
/// 0.021 / 0.29 (0.027 / 0.47), ACES 0.027 / 0.34 (0.033 / 0.40), CSAIL
/// corrected 0.017 / 0.26 (0.029 / 0.68), Freiburg 079 0.015 / 0.30
/// (0.031 / 0.63), with up to 4,000 candidates per gap class.
#[test]
fn scan_verified_relations() {
    let verify = slamlab::slam::eval::verified::VerifyConfig {
        max_pairs: 1000,
        ..Default::default()
    };
    for name in support::LOGS {
        let o = support::verified(
            name,
            &slamlab::slam::logs::logslam::LogSlamConfig::default(),
            &verify,
        );
        let (ours, reference, odometry) = (
            o.ours.last().unwrap(),
            o.reference.last().unwrap(),
            o.odometry.last().unwrap(),
        );
        println!(
            "{name}: {} relations verified: ours {:.4} m / {:.3} deg, the reference's {:.4} / {:.3}, odometry's {:.3} / {:.2}",
            ours.pairs, ours.trans_m, ours.rot_deg, reference.trans_m, reference.rot_deg, odometry.trans_m, odometry.rot_deg
        );
        assert!(
            ours.pairs >= 200,
            "{name}: only {} relations verified",
            ours.pairs
        );
        assert!(
            ours.trans_m <= 0.035 && ours.rot_deg <= 0.40,
            "{name}: {:.4} m / {:.3} deg against the scans' relations",
            ours.trans_m,
            ours.rot_deg
        );
        assert!(
            ours.trans_m <= reference.trans_m && ours.rot_deg <= reference.rot_deg,
            "{name}: ours {:.4} m / {:.3} deg, the reference's {:.4} / {:.3}",
            ours.trans_m,
            ours.rot_deg,
            reference.trans_m,
            reference.rot_deg
        );
        assert!(
            ours.trans_m <= 0.25 * odometry.trans_m,
            "{name}: against odometry"
        );
    }
}
