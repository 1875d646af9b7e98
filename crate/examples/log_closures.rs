//! Where the log SLAM goes wrong, per log: every accepted loop closure's
//! measured relative pose compared with the reference's, and the key-to-key
//! edges of the front end (successive scan matching) that disagree with the
//! reference by more than 0.1 m or 1°.
//!
//! `cargo run --release -p slamlab --example log_closures [LOG ...]`
//!
//! The reference is the corrected logs' own poses (replayed with the same
//! drifting odometry as `log_relations`), and GMapping's poses for the raw
//! MIT CSAIL log, where a key scan without a GMapping pose takes the nearest
//! scan's that has one, moved by our own estimate between the two (a few
//! scans apart: locally accurate). `SLAMLAB_LOG_SLAM` as in `log_relations`.

use slamlab::geom::Pose2;
use slamlab::slam::logslam::LogSlam;
use slamlab::slam::posegraph::PoseGraph;
use slamlab::slam::relations::{drift_odometry, DriftModel};

#[path = "../../tests/real_support/mod.rs"]
mod support;

/// The reference pose of every scan (approximated where missing, see above).
fn raw_reference(est: &[Pose2]) -> Vec<Pose2> {
    let known = support::csail_gmapping_reference();
    (0..est.len())
        .map(|s| {
            let &(r, pose) = known
                .iter()
                .min_by_key(|(r, _)| r.abs_diff(s))
                .expect("reference poses");
            pose.compose(&est[r].between(&est[s]))
        })
        .collect()
}

/// The error (m, deg) of a measured relation against the reference's.
fn error(measured: &Pose2, reference: &[Pose2], a: usize, b: usize) -> (f64, f64) {
    let e = reference[a].between(&reference[b]).between(measured);
    (e.position().length(), e.theta.to_degrees().abs())
}

fn report(name: &str, slam: &LogSlam, reference: &[Pose2]) {
    // The log index of each key scan.
    let mut key_scan = vec![0; slam.graph.nodes.len()];
    for s in &slam.scans {
        if s.relative == Pose2::IDENTITY {
            key_scan[s.key] = s.index;
        }
    }
    println!(
        "{name}: {} keys, stats {:?}",
        slam.graph.nodes.len(),
        slam.stats
    );
    let (mut wrong, mut total) = (0, 0);
    let mut seq = Vec::new();
    for e in &slam.graph.edges {
        let (a, b) = (key_scan[e.from], key_scan[e.to]);
        let (t, r) = error(&e.measurement, reference, a, b);
        if e.loop_closure {
            total += 1;
            let bad = t > 0.2 || r > 2.0;
            wrong += bad as usize;
            println!(
                "  closure keys {:5} -> {:5} (scans {:5} -> {:5}) error {:6.3} m {:6.2} deg{}",
                e.from,
                e.to,
                a,
                b,
                t,
                r,
                if bad { "  WRONG" } else { "" }
            );
        } else {
            seq.push((t, r, a, b, e.information[0][0]));
        }
    }
    println!("  closures: {total}, wrong (> 0.2 m or > 2 deg): {wrong}");
    calibration(slam, reference, &key_scan);
    let n = seq.len().max(1) as f64;
    let (mt, mr) = seq
        .iter()
        .fold((0.0, 0.0), |(x, y), s| (x + s.0 / n, y + s.1 / n));
    println!(
        "  front end: {} key edges, mean error {mt:.4} m {mr:.3} deg",
        seq.len()
    );
    for (t, r, a, b, info) in &seq {
        if *t > 0.1 || *r > 1.0 {
            // An odometry key edge has σ 0.3 m (information 11), a matched
            // one `key_sigma_m` (0.1 m: 100, or a little under in floating
            // point, which a test against 100 took for odometry).
            let kind = if *info < 50.0 { " (odometry)" } else { "" };
            println!("    key edge scans {a:5} -> {b:5} error {t:6.3} m {r:6.2} deg{kind}");
        }
    }
}

/// How well the edges' information matches their errors: the mean χ² of
/// each kind of edge at the reference poses (3 if the covariances were
/// right), and its median (2.37 for a χ²₃).
fn calibration(slam: &LogSlam, reference: &[Pose2], key_scan: &[usize]) {
    let graph = PoseGraph {
        nodes: key_scan.iter().map(|&s| reference[s]).collect(),
        edges: Vec::new(),
    };
    for closures in [false, true] {
        let mut chi2: Vec<f64> = slam
            .graph
            .edges
            .iter()
            .filter(|e| e.loop_closure == closures && e.information[0][0] > 20.0)
            .map(|e| graph.chi2(e))
            .collect();
        // The heading's share: χ² of the edge with its heading weight only.
        let heading: f64 = slam
            .graph
            .edges
            .iter()
            .filter(|e| e.loop_closure == closures && e.information[0][0] > 20.0)
            .map(|e| {
                let mut h = e.clone();
                h.information = [[0.0; 3], [0.0; 3], [0.0, 0.0, e.information[2][2]]];
                graph.chi2(&h)
            })
            .sum();
        chi2.sort_by(f64::total_cmp);
        let n = chi2.len().max(1) as f64;
        println!(
            "  {} at the reference: mean chi2 {:.2} (heading {:.2}), median {:.2} ({} edges)",
            if closures {
                "closures"
            } else {
                "matched key edges"
            },
            chi2.iter().sum::<f64>() / n,
            heading / n,
            chi2.get(chi2.len() / 2).copied().unwrap_or(0.0),
            chi2.len()
        );
    }
}

fn main() {
    let cfg = support::config_from_env();
    for name in support::logs_from_args() {
        let name = name.as_str();
        let log = support::load(name);
        if name == "mit-csail.clf.gz" {
            let (est, slam, _) = support::replay(&log, None, &cfg);
            report(name, &slam, &raw_reference(&est));
        } else {
            let reference: Vec<Pose2> = log
                .scans
                .iter()
                .map(|s| s.logged_pose.expect("FLASER pose"))
                .collect();
            let odom = drift_odometry(&reference, &DriftModel::default(), support::drift_seed());
            let (_, slam, _) = support::replay(&log, Some(&odom), &cfg);
            report(name, &slam, &reference);
        }
    }
}
