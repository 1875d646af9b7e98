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
//! Then, per log: the reference's glitches (short runs of scans whose
//! reference relations to both neighbours lay the scans worse than ours, by
//! `GLITCH_MM`) and the relation errors without them; the same comparison
//! on revisits (pairs far apart in the log, near in space), which tests the
//! far relations where the scans can; the far relations' translational
//! error split along and across the reference's path; and the floor the
//! reference's own noise puts under the relation errors (what the truth
//! itself would score against a reference that far off it, see
//! `reference_floor`); and, needing no reference, how many cells the
//! scans' returns fall in at the reference's poses, ours and odometry's
//! (`support::cells_hit`).
//!
//! All beams within the matching range take part (no thinning), in the
//! robot frame through the laser's offset. `SLAMLAB_DRIFT_SEED` changes the
//! drifting odometry's seed (all the real-log examples). `SLAMLAB_LOG_SLAM` as in
//! `log_relations`; with `LOG_LOCAL_LIST` set, every pair where ours and the
//! reference differ by over 0.1 m or 1° is listed.

use glam::DVec2;
use slamlab::formats::carmen::CarmenLog;
use slamlab::geom::{wrap_angle, Pose2};
use slamlab::rng::Rng;
use slamlab::slam::degeneracy::scan_normals;
use slamlab::slam::eval::relations::{drift_odometry, relation_errors, RelationErrors};
use slamlab::slam::icp::IcpTarget;
use slamlab::slam::logs::logslam::{scan_points, LogSlamConfig};
use slamlab::slam::logs::LogScan;
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

/// The earlier scan of a pair, as the crate's ICP target
/// (`slamlab::slam::icp`), with the alignment score this example adds.
struct Target(IcpTarget);

impl Target {
    fn new(points: Vec<DVec2>) -> Target {
        Target(IcpTarget::new(&points, &scan_normals(&points), RADIUS_M))
    }

    /// Mean clamped |residual| (points off every surface count as
    /// `CLAMP_M`): how well `points` at `pose` lie on the target.
    fn misfit(&self, points: &[DVec2], pose: &Pose2) -> f64 {
        let r = self.0.residuals(points, pose);
        r.iter()
            .map(|x| x.map_or(CLAMP_M, |(v, _)| v.abs().min(CLAMP_M)))
            .sum::<f64>()
            / r.len().max(1) as f64
    }

    /// Point-to-line ICP from `start`; the refined pose and the smaller
    /// eigenvalue of its translational information.
    fn icp(&self, points: &[DVec2], start: &Pose2) -> (Pose2, f64) {
        let fit = self.0.align(points, start, HUBER_M, 30);
        (fit.pose, fit.weak)
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

    /// One table row: misfit (mm), three pose offsets (m / deg), misfit after ICP (mm).
    fn print_row(&self, name: &str) {
        println!(
            "    {:17} {:6.2} | {:6.4} / {:5.3} | {:6.4} / {:5.3} | {:6.4} / {:5.3} | {:6.2}",
            name,
            1000.0 * self.get(0),
            self.get(1),
            self.get(2),
            self.get(3),
            self.get(4),
            self.get(5),
            self.get(6),
            1000.0 * self.get(7)
        );
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

/// One pair where the reference and ours disagree: each one's misfit and
/// its offset (m, deg) from the pairwise ICP's answer, the ICP's weak
/// eigenvalue, and the difference ours − reference in scan `i`'s frame.
fn print_pair(i: usize, target: &Target, points: &[DVec2], r: &Pose2, o: &Pose2) {
    let (icp, weak) = target.icp(points, r);
    let (rt, rr) = apart(r, &icp);
    let (ot, or) = apart(o, &icp);
    println!(
        "    pair {i:5}: ours-ref ({:+.3}, {:+.3}) m {:+.2} deg; misfit ref {:5.1} ours {:5.1} icp {:5.1} mm; off ICP: ref {rt:.3} m {rr:.2} deg, ours {ot:.3} m {or:.2} deg; weak {weak:.0}",
        o.x - r.x,
        o.y - r.y,
        wrap_angle(o.theta - r.theta).to_degrees(),
        1000.0 * target.misfit(points, r),
        1000.0 * target.misfit(points, o),
        1000.0 * target.misfit(points, &icp),
    );
}

fn report(name: &str, log_all: &CarmenLog, reference: &[Pose2], cfg: &LogSlamConfig) {
    let list = std::env::var_os("LOG_LOCAL_LIST").is_some();
    let odom = drift_odometry(reference, &support::drift_model(), support::drift_seed());
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
    let mut bad_pairs = Vec::new();
    let mut ours_bad = 0;
    // The reference's consecutive relations' offsets from pairwise ICP.
    let mut off_icp: Vec<[f64; 3]> = Vec::new();
    for i in 0..log.len() - 1 {
        let target = Target::new(scan_points(&log[i], &dense));
        let points = scan_points(&log[i + 1], &dense);
        let r = reference[i].between(&reference[i + 1]);
        let o = est[i].between(&est[i + 1]);
        let (dt, dr) = apart(&r, &o);
        if dt > 0.1 || dr > 1.0 {
            let gain = target.misfit(&points, &r) - target.misfit(&points, &o);
            if gain > GLITCH_MM / 1000.0 {
                bad_pairs.push(i);
            } else if gain < -GLITCH_MM / 1000.0 {
                ours_bad += 1;
            }
        }
        let f = match (key_of_scan.get(&i), key_of_scan.get(&(i + 1))) {
            (Some(&a), Some(&b)) => front.get(&(a * 1_000_000 + b)).copied(),
            _ => None,
        };
        if list && (apart(&r, &o).0 > 0.1 || apart(&r, &o).1 > 1.0) {
            print_pair(i, &target, &points, &r, &o);
        }
        if !compare(&target, &points, &[r, o], &mut all) {
            skipped += 1;
            continue;
        }
        let d = r.between(&target.icp(&points, &r).0);
        off_icp.push([d.x, d.y, wrap_angle(d.theta)]);
        if let Some(f) = f {
            compare(&target, &points, &[r, o, f], &mut keyed);
        }
    }
    println!(
        "{name}: {} consecutive pairs compared, {skipped} poorly constrained left out",
        all[0].n
    );
    let glitches = glitch_scans(&bad_pairs);
    println!(
        "  consecutive relations where ours fits the scans {GLITCH_MM} mm better (and differs by > 0.1 m or 1 deg): {}; the reverse: {ours_bad}; reference glitch scans: {glitches:?}",
        bad_pairs.len()
    );
    print_errors(
        "relation errors",
        &relation_errors(&est, reference, support::RANDOM_PAIRS, 1),
    );
    print_errors(
        "without the glitch scans",
        &without(&est, reference, &glitches),
    );
    revisits(log, reference, &est, &dense);
    far_split(&est, reference);
    reference_floor(reference, &off_icp);
    println!(
        "  cells hit at {} m (fewer: the scans agree better): reference {}, ours {}, odometry {}",
        support::CRISP_CELL_M,
        support::cells_hit(log, reference),
        support::cells_hit(log, &est),
        support::cells_hit(log, &odom)
    );
    for (title, means) in [("all pairs", &all), ("pairs of keys", &keyed)] {
        println!(
            "  {title} ({}): misfit mm | ICP moves it m / deg | off ICP(ref) m / deg | ICP end vs ICP(ref) m / deg | misfit after ICP mm",
            means[0].n
        );
        for (k, m) in means.iter().enumerate() {
            m.print_row(names[k]);
        }
    }
}

/// What the reference's own noise costs a perfect estimate. If each
/// reference pose is the truth moved by independent noise of deviation σ
/// (per axis, robot frame), a consecutive relation is off by σ√2, and
/// the pairwise ICP (far more precise on a well-constrained pair) shows it:
/// σ is estimated robustly, as 1.4826 · median |offset| / √2 per axis, so
/// the glitches do not count (a lower bound). The truth would then score
/// what the reference moved by such noise scores against the reference
/// itself, averaged over five noise seeds.
fn reference_floor(reference: &[Pose2], off_icp: &[[f64; 3]]) {
    let sigma: Vec<f64> = (0..3)
        .map(|a| {
            let mut v: Vec<f64> = off_icp.iter().map(|d| d[a].abs()).collect();
            v.sort_by(f64::total_cmp);
            1.4826 * v.get(v.len() / 2).copied().unwrap_or(0.0) / 2f64.sqrt()
        })
        .collect();
    let (mut t, mut r) = (0.0, 0.0);
    let mut per_k: Vec<RelationErrors> = Vec::new();
    for seed in 1..=5u64 {
        let mut rng = Rng::new(seed);
        let noisy: Vec<Pose2> = reference
            .iter()
            .map(|p| {
                let n = Pose2::new(
                    rng.normal(sigma[0]),
                    rng.normal(sigma[1]),
                    rng.normal(sigma[2]),
                );
                p.compose(&n)
            })
            .collect();
        let e = relation_errors(&noisy, reference, support::RANDOM_PAIRS, 1);
        let all = e.last().expect("all pairs");
        t += all.trans_m / 5.0;
        r += all.rot_deg / 5.0;
        if per_k.is_empty() {
            per_k = e
                .iter()
                .map(|x| RelationErrors {
                    trans_m: 0.0,
                    rot_deg: 0.0,
                    ..x.clone()
                })
                .collect();
        }
        for (p, x) in per_k.iter_mut().zip(&e) {
            p.trans_m += x.trans_m / 5.0;
            p.rot_deg += x.rot_deg / 5.0;
        }
    }
    println!(
        "  the reference's own noise, from its consecutive relations against pairwise ICP (robust, {} pairs): sigma x {:.4} m, y {:.4} m, heading {:.3} deg; the truth seen through such noise scores (all pairs) {t:.3} m / {r:.2} deg",
        off_icp.len(),
        sigma[0],
        sigma[1],
        sigma[2].to_degrees()
    );
    print_errors("the floor by pairs", &per_k);
}

/// A consecutive relation is the reference's fault when ours lays the scans
/// this much better (mean clamped misfit, mm) and the two differ by over
/// 0.1 m or 1°.
const GLITCH_MM: f64 = 5.0;
/// Longest run of reference poses between two faulty relations that is
/// taken for a glitch (the poses jumped away and back).
const GLITCH_RUN: usize = 5;

/// The scans inside runs of at most `GLITCH_RUN` between two faulty
/// relations (pair `i` joins scans `i` and `i + 1`).
fn glitch_scans(bad_pairs: &[usize]) -> Vec<usize> {
    let mut out = Vec::new();
    for w in bad_pairs.windows(2) {
        if w[1] - w[0] <= GLITCH_RUN {
            out.extend(w[0] + 1..=w[1]);
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// The relation errors ("all" and random) with the scans in `drop` left
/// out of both trajectories.
fn without(est: &[Pose2], reference: &[Pose2], drop: &[usize]) -> Vec<RelationErrors> {
    let keep = |v: &[Pose2]| -> Vec<Pose2> {
        v.iter()
            .enumerate()
            .filter(|(i, _)| !drop.contains(i))
            .map(|(_, p)| *p)
            .collect()
    };
    relation_errors(&keep(est), &keep(reference), support::RANDOM_PAIRS, 1)
}

fn print_errors(title: &str, e: &[RelationErrors]) {
    let row: Vec<String> = e
        .iter()
        .map(|r| format!("{} {:.3}/{:.2}", r.pairs_of, r.trans_m, r.rot_deg))
        .collect();
    println!("  {title}: {}", row.join("  "));
}

/// Revisits: for each scan, the scan at least `REVISIT_GAP`
/// scans before it whose reference pose lies nearest, if within 0.5 m and
/// 20° (found by the reference, judged by the scans alone). The
/// same comparison as for consecutive scans, on those far pairs.
const REVISIT_GAP: usize = 50;

fn revisits(log: &[LogScan], reference: &[Pose2], est: &[Pose2], dense: &LogSlamConfig) {
    let mut means = vec![Mean::default(), Mean::default()];
    let (mut better, mut worse, mut gaps) = (0, 0, 0usize);
    for j in REVISIT_GAP..log.len() {
        let near = (0..j - REVISIT_GAP)
            .map(|i| (i, reference[i].between(&reference[j])))
            .filter(|(_, d)| d.position().length() < 0.5 && d.theta.abs() < 20f64.to_radians())
            .min_by(|a, b| a.1.position().length().total_cmp(&b.1.position().length()));
        let Some((i, r)) = near else { continue };
        let target = Target::new(scan_points(&log[i], dense));
        let points = scan_points(&log[j], dense);
        let o = est[i].between(&est[j]);
        if !compare(&target, &points, &[r, o], &mut means) {
            continue;
        }
        gaps += j - i;
        let gain = target.misfit(&points, &r) - target.misfit(&points, &o);
        better += (gain > GLITCH_MM / 1000.0) as usize;
        worse += (gain < -GLITCH_MM / 1000.0) as usize;
    }
    println!(
        "  revisits ({} pairs, mean gap {} scans; ours fits {GLITCH_MM} mm better in {better}, worse in {worse}):",
        means[0].n,
        gaps / means[0].n.max(1)
    );
    for (k, m) in means.iter().enumerate() {
        m.print_row(["reference", "ours (final)"][k]);
    }
}

/// How the far relations err: the translational error of pairs `k` apart
/// split along the reference's displacement (a path too long or short:
/// sliding along corridors) and across it (a bend: heading), mean |·| each,
/// and the share of the summed error from each tenth of the log (by the
/// pair's first scan).
fn far_split(est: &[Pose2], reference: &[Pose2]) {
    for k in [50usize, 100] {
        let n = est.len();
        if k >= n {
            continue;
        }
        let (mut along, mut across, mut total) = (0.0, 0.0, 0.0);
        let mut tenth = [0.0; 10];
        for i in 0..n - k {
            let dr = reference[i].between(&reference[i + k]);
            let de = est[i].between(&est[i + k]);
            let e = de.position() - dr.position();
            let dir = dr.position().normalize_or(DVec2::X);
            along += dir.dot(e).abs();
            across += dir.perp_dot(e).abs();
            total += e.length();
            tenth[10 * i / n] += e.length();
        }
        let m = (n - k) as f64;
        let shares: Vec<String> = tenth
            .iter()
            .map(|t| format!("{:.0}", 100.0 * t / total))
            .collect();
        println!(
            "  k={k}: |error| {:.3} m, along the path {:.3}, across {:.3}; % by tenth of the log: {}",
            total / m,
            along / m,
            across / m,
            shares.join(" ")
        );
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
        let reference = support::logged_poses(&log);
        report(&name, &log, &reference, &cfg);
    }
}
