//! Real-data suite (`./build.sh test-real`): the log SLAM on the real CARMEN
//! logs of `../shared/data/carmen` (or `$SLAMLAB_DATA/carmen`), scored by
//! relation errors (Kümmerle et al. 2009). Fails when the data is missing.
//!
//! The raw MIT CSAIL log is scored against GMapping's poses for 406 of its
//! scans; each corrected log (GMapping's poses) is replayed with drifting
//! odometry made from those poses (seeded, `slam::relations::DriftModel`)
//! and scored against them. Bounds are the figures measured on this code
//! (BENCHMARKS.md, "Real laser logs") with a small margin (the replay is
//! deterministic); the targets (0.10 m, 1 deg, a quarter of
//! odometry's) are not met yet on most logs, so the bounds are honest ones;
//! every log must beat its odometry. On the corrected logs the scans must
//! also agree with each other at our poses about as well as at the
//! reference's, by a measure that needs no reference
//! (`support::cells_hit`).

#[path = "real_support/mod.rs"]
mod support;

use support::{pooled, Outcome};

/// Checks the pooled relation errors against `max_m` / `max_deg` and
/// against the odometry's (at most `share` of it).
fn check(name: &str, o: &Outcome, max_m: f64, max_deg: f64, share: f64) {
    println!("{}", support::table(name, o));
    let (ours, odom) = (pooled(&o.ours), pooled(&o.odometry));
    assert!(
        ours.trans_m <= max_m && ours.rot_deg <= max_deg,
        "{name}: {:.3} m / {:.2} deg, bounds {max_m} m / {max_deg} deg",
        ours.trans_m,
        ours.rot_deg
    );
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
/// reference). Measured, session 30: 0.97 (ACES), 0.99 (CSAIL
/// corrected), 0.90 (Intel), 0.84 (Freiburg 079): the scans agree with
/// each other better at our poses than at GMapping's on every log.
const CELLS_MARGIN: f64 = 1.02;

#[test]
fn mit_csail_raw_log_against_gmapping() {
    let (o, recorded) = support::csail_raw();
    // Measured: 0.193 m / 0.95 deg against odometry's 6.628 m / 18.80 deg
    // (0.213 m / 1.03 deg before session 30's square walls' prior)
    // (0.432 m / 1.00 deg before session 17 refused closures on the search
    // window's edge; the 0.10 m / 1 deg is not met on
    // this log: see BENCHMARKS.md).
    check("mit-csail.clf.gz", &o, 0.20, 1.0, 0.25);
    assert!(o.closures > 0, "the CSAIL tour revisits corridors");
    println!("recorded {recorded:.0} s, replayed in {:.1} s", o.seconds);
}

#[test]
fn intel_with_drifting_odometry() {
    let o = support::corrected("intel-corrected.log.gz");
    // Measured: 0.099 m / 0.69 deg against odometry's 3.122 m / 17.79 deg.
    check("intel", &o, 0.105, 0.75, 0.25);
}

#[test]
fn aces_with_drifting_odometry() {
    let o = support::corrected("aces-corrected.log.gz");
    // Measured: 0.155 m / 0.48 deg against odometry's 7.266 m / 18.92 deg
    // (0.161 m / 0.49 deg before session 30's square walls' prior).
    check("aces", &o, 0.16, 0.52, 0.25);
}

#[test]
fn csail_corrected_with_drifting_odometry() {
    let o = support::corrected("csail-corrected.log.gz");
    // Measured: 0.234 m / 1.08 deg against odometry's 10.786 m / 35.14 deg
    // (0.274 m / 1.16 deg before session 18 narrowed the wide window's
    // reach to 0.6 m).
    check("csail", &o, 0.245, 1.15, 0.25);
}

#[test]
fn freiburg_079_with_drifting_odometry() {
    let o = support::corrected("freiburg-079-corrected.log.gz");
    // Measured: 0.053 m / 0.75 deg against odometry's 0.456 m / 3.59 deg:
    // the targets, met.
    check("freiburg-079", &o, 0.10, 1.0, 0.25);
}
