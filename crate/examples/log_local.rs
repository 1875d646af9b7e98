//! Whose consecutive-scan relations are noisier, ours or the reference's?
//!
//! `cargo run --release -p slamlab --example log_local [LOG ...]`
//!
//! For every pair of consecutive scans `(i, i + 1)` of a corrected log (replayed
//! with the drifting odometry of `log_relations`), three relative poses of
//! scan `i + 1` in scan `i`'s frame are compared: the reference's
//! (GMapping's), ours after the final optimisation, and ours from the front
//! end alone (the key edge's measurement, where both scans are keys). Each is
//! judged by how well it lays the later scan's points on the earlier scan's
//! surfaces — the robust point-to-line distance (Chen–Medioni) of every
//! point to the nearest point of the other scan along that point's normal —
//! and by how far a pairwise point-to-line ICP started there moves it. The
//! pose the ICP moves less is the one the two scans themselves agree with.
//! Both ICPs should end at the same pose (reported), which serves as a
//! third, independent opinion; pairs whose ICP is poorly constrained (a
//! corridor: the smaller eigenvalue of the translational information below
//! `MIN_WEAK`) are left out of the comparison.
//!
//! All beams within the matching range take part (no thinning), in the
//! robot frame through the laser's offset. `SLAMLAB_LOG_SLAM` as in
//! `log_relations`.

use glam::DVec2;
use slamlab::carmen::{CarmenLog, LogScan};
use slamlab::geom::{wrap_angle, Pose2};
use slamlab::slam::degeneracy::{scan_normals, symmetric_eigen2};
use slamlab::slam::gauss_newton::solve3;
use slamlab::slam::logslam::{scan_points, LogSlamConfig};
use slamlab::slam::relations::{drift_odometry, DriftModel};
use std::collections::HashMap;

#[path = "../../tests/real_support/mod.rs"]
mod support;

/// Association radius of the point-to-line residuals (m).
const RADIUS_M: f64 = 0.3;
/// Huber threshold of the ICP (m).
const HUBER_M: f64 = 0.02;
/// A residual counts at most this much in the alignment score (m).
const CLAMP_M: f64 = 0.05;
/// Least weak eigenvalue of `Σ n nᵀ` for a pair to be compared.
const MIN_WEAK: f64 = 20.0;

/// The earlier scan of a pair: its points, normals and a bucket grid.
struct Target {
    points: Vec<DVec2>,
    normals: Vec<Option<DVec2>>,
    buckets: HashMap<(i64, i64), Vec<usize>>,
}

fn bucket(p: DVec2) -> (i64, i64) {
    (
        (p.x / RADIUS_M).floor() as i64,
        (p.y / RADIUS_M).floor() as i64,
    )
}

impl Target {
    fn new(points: Vec<DVec2>) -> Target {
        let normals = scan_normals(&points);
        let mut buckets: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
        for (i, &p) in points.iter().enumerate() {
            if normals[i].is_some() {
                buckets.entry(bucket(p)).or_default().push(i);
            }
        }
        Target {
            points,
            normals,
            buckets,
        }
    }

    /// The nearest point with a normal within `RADIUS_M` of `q`.
    fn nearest(&self, q: DVec2) -> Option<(DVec2, DVec2)> {
        let (bx, by) = bucket(q);
        let mut best: Option<(f64, usize)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for &i in self.buckets.get(&(bx + dx, by + dy)).into_iter().flatten() {
                    let d = self.points[i].distance_squared(q);
                    if d < RADIUS_M * RADIUS_M && best.is_none_or(|b| d < b.0) {
                        best = Some((d, i));
                    }
                }
            }
        }
        best.map(|(_, i)| (self.points[i], self.normals[i].unwrap()))
    }

    /// Point-to-line residuals of `points` placed at `pose` in the target's
    /// frame, with the Jacobian of each (None: no surface near).
    fn residuals(&self, points: &[DVec2], pose: &Pose2) -> Vec<Option<(f64, [f64; 3])>> {
        let (s, c) = pose.theta.sin_cos();
        let f = pose.frame();
        points
            .iter()
            .map(|&p| {
                let q = f.to_parent(p);
                let (a, n) = self.nearest(q)?;
                let dq = DVec2::new(-s * p.x - c * p.y, c * p.x - s * p.y);
                Some((n.dot(q - a), [n.x, n.y, n.dot(dq)]))
            })
            .collect()
    }

    /// Mean clamped |residual| (points off every surface count as
    /// `CLAMP_M`): how well `points` at `pose` lie on the target.
    fn misfit(&self, points: &[DVec2], pose: &Pose2) -> f64 {
        let r = self.residuals(points, pose);
        r.iter()
            .map(|x| x.map_or(CLAMP_M, |(v, _)| v.abs().min(CLAMP_M)))
            .sum::<f64>()
            / r.len().max(1) as f64
    }

    /// Point-to-line ICP from `start`; the refined pose and the smaller
    /// eigenvalue of its translational information.
    fn icp(&self, points: &[DVec2], start: &Pose2) -> (Pose2, f64) {
        let mut pose = *start;
        let mut weak = 0.0;
        for _ in 0..30 {
            let mut h = [[0.0; 3]; 3];
            let mut g = [0.0; 3];
            for (r, j) in self.residuals(points, &pose).into_iter().flatten() {
                let w = if r.abs() <= HUBER_M {
                    1.0
                } else {
                    HUBER_M / r.abs()
                };
                for a in 0..3 {
                    g[a] += w * j[a] * r;
                    for b in 0..3 {
                        h[a][b] += w * j[a] * j[b];
                    }
                }
            }
            weak = symmetric_eigen2(h[0][0], h[0][1], h[1][1]).1;
            for (a, row) in h.iter_mut().enumerate() {
                row[a] += 1e-6;
            }
            let Some(d) = solve3(h, [-g[0], -g[1], -g[2]]) else {
                break;
            };
            pose = Pose2::new(pose.x + d[0], pose.y + d[1], wrap_angle(pose.theta + d[2]));
            if DVec2::new(d[0], d[1]).length() < 1e-6 && d[2].abs() < 1e-7 {
                break;
            }
        }
        (pose, weak)
    }
}

/// (m, deg) between two relative poses.
fn apart(a: &Pose2, b: &Pose2) -> (f64, f64) {
    let e = a.between(b);
    (e.position().length(), e.theta.to_degrees().abs())
}

/// Running means of (m, deg) pairs and of scalars.
#[derive(Default)]
struct Mean {
    n: usize,
    sums: Vec<f64>,
}

impl Mean {
    fn add(&mut self, v: &[f64]) {
        if self.sums.is_empty() {
            self.sums = vec![0.0; v.len()];
        }
        self.n += 1;
        for (s, x) in self.sums.iter_mut().zip(v) {
            *s += x;
        }
    }

    fn get(&self, k: usize) -> f64 {
        self.sums.get(k).copied().unwrap_or(0.0) / self.n.max(1) as f64
    }
}

/// One pair's comparison: for each candidate relative pose, its misfit,
/// how far the ICP started there moved it, and its distance from the
/// reference-started ICP's answer.
fn compare(target: &Target, points: &[DVec2], candidates: &[Pose2], out: &mut [Mean]) -> bool {
    let (anchor, weak) = target.icp(points, &candidates[0]);
    if weak < MIN_WEAK {
        return false;
    }
    for (c, m) in candidates.iter().zip(out.iter_mut()) {
        let (refined, _) = target.icp(points, c);
        let (mt, mr) = apart(c, &refined);
        let (at, ar) = apart(c, &anchor);
        let (ct, cr) = apart(&refined, &anchor);
        m.add(&[
            target.misfit(points, c),
            mt,
            mr,
            at,
            ar,
            ct,
            cr,
            target.misfit(points, &refined),
        ]);
    }
    true
}

fn report(name: &str, log_all: &CarmenLog, reference: &[Pose2], cfg: &LogSlamConfig) {
    let odom = drift_odometry(reference, &DriftModel::default(), support::DRIFT_SEED);
    let (est, slam, _) = support::replay(log_all, Some(&odom), cfg);
    let log: &[LogScan] = &log_all.scans;
    // Front-end relative pose of consecutive scans that are both keys.
    let mut key_of_scan = HashMap::new();
    for s in &slam.scans {
        if s.relative == Pose2::IDENTITY {
            key_of_scan.insert(s.index, s.key);
        }
    }
    let mut front: HashMap<usize, Pose2> = HashMap::new();
    for e in slam.graph.edges.iter().filter(|e| !e.loop_closure) {
        front.insert(e.from * 1_000_000 + e.to, e.measurement);
    }
    let dense = LogSlamConfig {
        point_spacing_m: 0.0,
        ..cfg.clone()
    };
    let names = ["reference", "ours (final)", "ours (front end)"];
    let mut all = vec![Mean::default(), Mean::default()];
    let mut keyed = vec![Mean::default(), Mean::default(), Mean::default()];
    let mut skipped = 0;
    for i in 0..log.len() - 1 {
        let target = Target::new(scan_points(&log[i], &dense));
        let points = scan_points(&log[i + 1], &dense);
        let r = reference[i].between(&reference[i + 1]);
        let o = est[i].between(&est[i + 1]);
        let f = match (key_of_scan.get(&i), key_of_scan.get(&(i + 1))) {
            (Some(&a), Some(&b)) => front.get(&(a * 1_000_000 + b)).copied(),
            _ => None,
        };
        if !compare(&target, &points, &[r, o], &mut all) {
            skipped += 1;
            continue;
        }
        if let Some(f) = f {
            compare(&target, &points, &[r, o, f], &mut keyed);
        }
    }
    println!(
        "{name}: {} consecutive pairs compared, {skipped} poorly constrained left out",
        all[0].n
    );
    for (title, means) in [("all pairs", &all), ("pairs of keys", &keyed)] {
        println!(
            "  {title} ({}): misfit mm | ICP moves it m / deg | off ICP(ref) m / deg | ICP end vs ICP(ref) m / deg | misfit after ICP mm",
            means[0].n
        );
        for (k, m) in means.iter().enumerate() {
            println!(
                "    {:17} {:6.2} | {:6.4} / {:5.3} | {:6.4} / {:5.3} | {:6.4} / {:5.3} | {:6.2}",
                names[k],
                1000.0 * m.get(0),
                m.get(1),
                m.get(2),
                m.get(3),
                m.get(4),
                m.get(5),
                m.get(6),
                1000.0 * m.get(7)
            );
        }
    }
}

fn main() {
    let cfg = support::config_from_env();
    for name in support::logs_from_args() {
        if name == "mit-csail.clf.gz" {
            println!("{name}: skipped (the reference covers only some scans)");
            continue;
        }
        let log = support::load(&name);
        let reference: Vec<Pose2> = log
            .scans
            .iter()
            .map(|s| s.logged_pose.expect("FLASER pose"))
            .collect();
        report(&name, &log, &reference, &cfg);
    }
}
