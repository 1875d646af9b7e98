//! Relations the scans themselves fix: ours and the reference's, each
//! judged against them.
//!
//! `cargo run --release -p slamlab --example log_verified [LOG ...]`
//!
//! Kümmerle et al. ("On measuring the accuracy of SLAM algorithms",
//! Autonomous Robots 2009) score a SLAM by relative poses between pairs of
//! scans whose true relation is known. For the classic logs they made those
//! relations by matching pairs of scans that overlap and having a person
//! accept or reject each match; the published figures for these buildings
//! (GMapping 0.05–0.07 m, graph mapping 0.004–0.056 m) are errors against
//! such relations. The lab's own figure (`log_relations`) scores against the
//! corrected logs' poses instead, which carry their own noise (BENCHMARKS.md,
//! "Log replay": the truth itself would score about 0.08 m against them on
//! ACES and CSAIL corrected).
//!
//! This example makes relations in Kümmerle's manner with the person
//! replaced by checks ([`slamlab::slam::eval::verified`]): candidate pairs near
//! by the reference's poses or by ours, each aligned by point-to-line ICP
//! from both estimates' relative poses, accepted when both starts end at
//! one pose that every direction pins.
//!
//! Each estimate's relative pose (ours, the reference's, the drifting
//! odometry's) is then compared with the accepted relation, and the errors
//! are averaged by how far apart the two scans lie in the log: consecutive,
//! 2–9, 10–99, and 100 or more scans (revisits, where loops close). The
//! relations test what the scans can see: the map's consistency where it
//! overlaps, not the bend of a corridor seen once.
//!
//! Caveat, as for Kümmerle's relations: a scan matcher aligns scans by
//! construction, so this measure favours one; the reference (GMapping's
//! poses) comes from one too.
//!
//! The raw MIT CSAIL log is scored on the 406 scans GMapping's poses cover
//! (its gaps count among those scans).
//! `SLAMLAB_DRIFT_SEED` and `SLAMLAB_LOG_SLAM` as in `log_relations`.

use slamlab::slam::eval::verified::VerifyConfig;

#[path = "../../tests/real_support/mod.rs"]
mod support;

fn main() {
    let cfg = support::config_from_env();
    for name in support::logs_from_args() {
        let o = support::verified(&name, &cfg, &VerifyConfig::default());
        let v = &o.verification;
        let favour = |second: bool| {
            v.disputed
                .iter()
                .filter(|d| d.second_fits_better == Some(second))
                .count()
        };
        println!(
            "{name}: {} scans, {} relations verified; {} candidates whose two starts ended apart (the scans fit ours better on {}, the reference's on {})",
            o.scans,
            v.relations.len(),
            v.disputed.len(),
            favour(true),
            favour(false)
        );
        println!(
            "  gap      pairs | ours m / deg     over | reference m / deg over | odometry m / deg"
        );
        for ((us, r), d) in o.ours.iter().zip(&o.reference).zip(&o.odometry) {
            println!(
                "  {:>6} {:6} | {:.4} / {:.3} {:4} | {:.4} / {:.3} {:4} | {:.3} / {:.2}",
                us.gap,
                us.pairs,
                us.trans_m,
                us.rot_deg,
                us.over,
                r.trans_m,
                r.rot_deg,
                r.over,
                d.trans_m,
                d.rot_deg
            );
        }
    }
}
