//! Where the log SLAM goes wrong, per log: every accepted loop closure's
//! measured relative pose compared with the reference's, and the key-to-key
//! edges of the front end (successive scan matching) that disagree with the
//! reference by more than 0.1 m or 1°, each with the odometry's error on
//! the same pair and how well the new key's own scan pins it along its
//! weakest direction ([`slamlab::slam::degeneracy`]: the points' worth of
//! wall normals across that direction, and how much of the edge's error
//! lies along it). The front end's mean error is also given apart for the
//! keys pinned by fewer than [`CORRIDOR_POINTS`] points along it (a
//! corridor whose ends are out of sight), where the matcher's response is
//! flat and it slides.
//!
//! `cargo run --release -p slamlab --example log_closures [LOG ...]`
//!
//! The reference is the corrected logs' own poses (replayed with the same
//! drifting odometry as `log_relations`), and GMapping's poses for the raw
//! MIT CSAIL log, where a key scan without a GMapping pose takes the nearest
//! scan's that has one, moved by our own estimate between the two (a few
//! scans apart: locally accurate). `SLAMLAB_LOG_SLAM` as in `log_relations`.
//!
//! Then, for the corrected logs, the closures the search could have found:
//! every key the driver tried to close whose place (by the reference) lies
//! within [`REVISIT_M`] of an older key outside the local map is an
//! *opportunity*. Each is counted as found or missed, and a missed one by
//! why the search could not reach it at that moment: the old key's estimate
//! beyond the candidate radius, or the correction the match had to make
//! (where the reference puts the new key, given the old key's estimate)
//! beyond the search window.

use slamlab::geom::Pose2;
use slamlab::slam::degeneracy::{constraint_of, scan_normals_within};
use slamlab::slam::eval::relations::{drift_odometry, relation_errors};
use slamlab::slam::logs::logslam::LogSlam;
use slamlab::slam::posegraph::PoseGraph;

#[path = "../../tests/real_support/mod.rs"]
mod support;

/// A key scan pinned by fewer points than this along its weakest direction
/// counts as a corridor's.
const CORRIDOR_POINTS: f64 = 4.0;

/// One front-end key edge: its error (m, deg), its scans, its
/// information, the odometry's error on the pair (m), the new key's points
/// along its weakest direction and the part of the error along it (m).
struct FrontEdge {
    t: f64,
    r: f64,
    a: usize,
    b: usize,
    info: f64,
    odometry_m: f64,
    weak_points: f64,
    along_m: f64,
}

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
        } else if e.information[0][0] > 0.0 {
            // (Heading-only edges are the square walls' priors, not the
            // front end's.)
            seq.push(front_edge(slam, reference, e, (a, b), (t, r)));
        }
    }
    println!("  closures: {total}, wrong (> 0.2 m or > 2 deg): {wrong}");
    optimum(slam, reference, &key_scan);
    square_spread(slam, reference, &key_scan);
    calibration(slam, reference, &key_scan);
    let n = seq.len().max(1) as f64;
    let (mt, mr) = seq
        .iter()
        .fold((0.0, 0.0), |(x, y), s| (x + s.t / n, y + s.r / n));
    println!(
        "  front end: {} key edges, mean error {mt:.4} m {mr:.3} deg",
        seq.len()
    );
    for corridor in [true, false] {
        let part: Vec<&FrontEdge> = seq
            .iter()
            .filter(|s| (s.weak_points < CORRIDOR_POINTS) == corridor)
            .collect();
        let k = part.len().max(1) as f64;
        println!(
            "    keys pinned by {} {CORRIDOR_POINTS} points along their weakest direction: {} edges, mean error {:.4} m ({:.4} m of it along that direction), the odometry's {:.4} m",
            if corridor { "under" } else { "at least" },
            part.len(),
            part.iter().map(|s| s.t).sum::<f64>() / k,
            part.iter().map(|s| s.along_m).sum::<f64>() / k,
            part.iter().map(|s| s.odometry_m).sum::<f64>() / k,
        );
    }
    for s in seq.iter().filter(|s| s.t > 0.1 || s.r > 1.0) {
        // An odometry key edge has σ 0.3 m (information 11), a matched
        // one `key_sigma_m` (0.1 m: 100, or a little under in floating
        // point, which a test against 100 took for odometry).
        let kind = if s.info < 50.0 { " (odometry)" } else { "" };
        println!(
            "    key edge scans {:5} -> {:5} error {:6.3} m {:6.2} deg{kind}; odometry {:.3} m; weakest direction {:.1} points, {:.3} m of the error along it",
            s.a, s.b, s.t, s.r, s.odometry_m, s.weak_points, s.along_m
        );
    }
}

/// The measures of one front-end key edge `e` between scans `(a, b)`,
/// whose error against the reference is `(t, r)`.
fn front_edge(
    slam: &LogSlam,
    reference: &[Pose2],
    e: &slamlab::slam::posegraph::Edge,
    (a, b): (usize, usize),
    (t, r): (f64, f64),
) -> FrontEdge {
    let odometry = |i: usize| {
        slam.scans
            .iter()
            .find(|s| s.index == i)
            .expect("a key's scan")
            .odometry
    };
    let (odometry_m, _) = error(&odometry(a).between(&odometry(b)), reference, a, b);
    // The new key's points are thinned to one per 10 cm: 0.3 m holds a
    // few neighbours on each side.
    let points = slam.key_points(e.to);
    let normals = scan_normals_within(points, 0.3);
    let c = constraint_of(&normals, &vec![true; normals.len()]);
    // The error in the new key's frame, where the weak direction lies.
    let wrong = reference[a]
        .between(&reference[b])
        .between(&e.measurement)
        .position();
    FrontEdge {
        t,
        r,
        a,
        b,
        info: e.information[0][0],
        odometry_m,
        weak_points: c.weak,
        along_m: wrong.dot(c.weak_direction).abs(),
    }
}

/// How far each square key's wall direction ([`slamlab::slam::manhattan`])
/// lies from the building's, at the reference's headings and at ours: the
/// noise of the square walls' prior, and how much wander it sees. Twice:
/// each key's direction from its normals, and refined by its straight
/// walls (runs of at least 1 m fitted by lines; sharper on clean walls,
/// wider on these logs: docs/history/issue-21-real-laser-logs.md, round 16).
fn square_spread(slam: &LogSlam, reference: &[Pose2], key_scan: &[usize]) {
    use slamlab::slam::manhattan::{building_direction, fold, scan_direction};
    let normals = slam.config.manhattan.clone().unwrap_or_default();
    let lines = slamlab::slam::manhattan::ManhattanConfig {
        line_min_m: 1.0,
        ..normals.clone()
    };
    for (how, m) in [("normals", normals), ("wall lines", lines)] {
        let dirs: Vec<(usize, f64)> = (0..slam.graph.nodes.len())
            .filter_map(|i| scan_direction(slam.key_points(i), &m).map(|(d, _)| (i, d)))
            .collect();
        let headings = [
            (
                "reference",
                key_scan
                    .iter()
                    .map(|&s| reference[s].theta)
                    .collect::<Vec<f64>>(),
            ),
            ("our", slam.graph.nodes.iter().map(|p| p.theta).collect()),
        ];
        for (label, heading) in headings {
            let world: Vec<f64> = dirs.iter().map(|&(i, d)| fold(heading[i] + d)).collect();
            let Some(b) = building_direction(&world, m.gate_rad) else {
                continue;
            };
            let mut off: Vec<f64> = world
                .iter()
                .map(|&a| fold(a - b).abs().to_degrees())
                .filter(|&a| a <= m.gate_rad.to_degrees())
                .collect();
            off.sort_by(f64::total_cmp);
            let rms = (off.iter().map(|a| a * a).sum::<f64>() / off.len().max(1) as f64).sqrt();
            println!(
                "  square keys ({how}) at {label} headings: {} of {} within the gate, offset median {:.2} deg, rms {rms:.2} deg",
                off.len(),
                dirs.len(),
                off.get(off.len() / 2).copied().unwrap_or(0.0)
            );
        }
    }
}

/// Whether the graph's own optimum is the estimate: the final graph's edges
/// optimised again from the reference's key poses, and the relation errors
/// of the keys (all pairs) from there and from the estimate. Equal: the
/// edges themselves put the keys where they are; the restart better: the
/// replay's optimisation ended in another minimum.
fn optimum(slam: &LogSlam, reference: &[Pose2], key_scan: &[usize]) {
    let truth: Vec<Pose2> = key_scan.iter().map(|&s| reference[s]).collect();
    let mut restart = slam.graph.clone();
    restart.nodes = truth.clone();
    let anchor = restart.nodes[0].between(&slam.graph.nodes[0]);
    restart.nodes = restart.nodes.iter().map(|p| p.compose(&anchor)).collect();
    let restart_result = restart.optimise(50);
    let all = |est: &[Pose2]| {
        let e = relation_errors(est, &truth, 1000, 1);
        let a = e.last().expect("all");
        (a.trans_m, a.rot_deg)
    };
    let (t0, r0) = all(&slam.graph.nodes);
    let (t1, r1) = all(&restart.nodes);
    println!(
        "  keys' relation errors (all pairs): estimate {t0:.3} m {r0:.2} deg (chi2 {:.1}); optimised from the reference {t1:.3} m {r1:.2} deg (chi2 {:.1}, {restart_result:?})",
        slam.graph.total_chi2(),
        restart.total_chi2()
    );
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

/// A key within this distance of an older one (by the reference) revisits
/// its place: their scans overlap well.
const REVISIT_M: f64 = 1.0;

/// Replays the log scan by scan and scores every closure try against the
/// reference (see the module doc).
fn opportunities(
    log: &slamlab::formats::carmen::CarmenLog,
    odom: &[Pose2],
    reference: &[Pose2],
    cfg: &slamlab::slam::logs::logslam::LogSlamConfig,
) {
    let loops = &cfg.loops;
    let mut slam = LogSlam::new(cfg.clone());
    let mut key_scan: Vec<usize> = Vec::new();
    let (mut chances, mut found, mut beyond_radius, mut beyond_window, mut in_reach) =
        (0, 0, 0, 0, 0);
    let mut needed: Vec<(f64, f64)> = Vec::new();
    for (k, scan) in log.scans.iter().enumerate() {
        let mut s = scan.clone();
        s.odometry = odom[k];
        let (keys, tried, got) = (
            slam.graph.nodes.len(),
            slam.stats.closures_tried,
            slam.stats.closures_found,
        );
        slam.add_scan(&s);
        if slam.graph.nodes.len() == keys {
            continue;
        }
        key_scan.push(k);
        if slam.stats.closures_tried == tried {
            continue;
        }
        let id = keys;
        let here = reference[k].position();
        let Some(j) = (0..=id.saturating_sub(loops.min_key_gap))
            .filter(|_| id >= loops.min_key_gap)
            .min_by(|&a, &b| {
                let da = reference[key_scan[a]].position().distance(here);
                let db = reference[key_scan[b]].position().distance(here);
                da.total_cmp(&db)
            })
            .filter(|&j| reference[key_scan[j]].position().distance(here) <= REVISIT_M)
        else {
            continue;
        };
        chances += 1;
        let nodes = &slam.graph.nodes;
        let should = nodes[j].compose(&reference[key_scan[j]].between(&reference[k]));
        let d = nodes[id].between(&should);
        needed.push((d.position().length(), d.theta.to_degrees().abs()));
        if slam.stats.closures_found > got {
            found += 1;
        } else if nodes[j].position().distance(nodes[id].position()) > loops.search_radius_m {
            beyond_radius += 1;
        } else if d.x.abs() > loops.window.linear_m
            || d.y.abs() > loops.window.linear_m
            || d.theta.abs() > loops.window.angular_rad
        {
            beyond_window += 1;
        } else {
            in_reach += 1;
        }
    }
    needed.sort_by(|a, b| a.0.total_cmp(&b.0));
    let q = |f: f64| {
        needed
            .get(((needed.len() as f64 - 1.0) * f) as usize)
            .map_or(0.0, |x| x.0)
    };
    println!(
        "  opportunities (a try within {REVISIT_M} m of an older key): {chances}; found {found}; missed: old key beyond the radius {beyond_radius}, correction beyond the window {beyond_window}, within reach {in_reach}; correction needed median {:.2} m, 90 % {:.2} m, max {:.2} m",
        q(0.5),
        q(0.9),
        q(1.0)
    );
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
            let reference = support::logged_poses(&log);
            let odom = drift_odometry(&reference, &support::drift_model(), support::drift_seed());
            let (_, slam, _) = support::replay(&log, Some(&odom), &cfg);
            report(name, &slam, &reference);
            opportunities(&log, &odom, &reference, &cfg);
        }
    }
}
