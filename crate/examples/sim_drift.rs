//! Where a simulated robot's SLAM goes wrong on a long run: its error
//! against the truth over time, with what the matcher said.
//!
//! ```sh
//! cargo run --release -p slamlab --example sim_drift -- SCENARIO.json robot5 [robot15 …] [--every 60] [--until 3600] [--graph|--no-graph] [--probe]
//! ```
//!
//! The simulation runs with its own mappers off and the named robots' mappers
//! fed here (odometry pose and scan, never the truth), exactly as the
//! simulation would. Every `--every` simulated seconds, and at every step
//! whose position error changes by more than 5 cm at once (a jump rather
//! than drift), it prints the error of the estimate and of odometry, the
//! match outcome counts in that stretch, the calibrated odometry bias, the
//! loop closures accepted so far, and whether the map grid refused to grow.
//! `--graph` / `--no-graph` run the filter with or without the loop-closing back end
//! ([`slamlab::slam::robot_graph`]); without either, as `SlamConfig::back_end` says.
//!
//! `--probe` (with `--graph`, and `GRAPH_NO_LOOPS=1` to keep the key poses
//! the front end's own) measures, at the end, how good a key edge could be:
//! the front end's relative pose between keys 1 to 600 apart against the
//! truth's (signed mean and rms: does it drift, or jitter?), and for keys
//! 1 to 10 apart that still overlap, a direct scan-to-scan match of the
//! two key scans ([`slamlab::slam::robot_graph::RobotGraph::match_keys`])
//! beside the front end's answer.

#[path = "support/back_end.rs"]
mod back_end_support;

use slamlab::geom::{wrap_angle, Pose2};
use slamlab::scenario::Scenario;
use slamlab::sim::Simulation;
use slamlab::slam::eval::scoring::{ate_aligned_m, ate_m, position_errors_m};
use slamlab::slam::mapper::{MatchCounts, RobotMapping, SlamConfig};

struct Traced {
    index: usize,
    mapping: RobotMapping,
    last_err: f64,
    last_counts: MatchCounts,
    /// The slowest SLAM steps: (ms, step, closures accepted by then).
    slowest: Vec<(f64, usize, usize)>,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args.first().ok_or(
        "usage: sim_drift SCENARIO.json ROBOT… [--every S] [--until S] [--graph|--no-graph] [--probe]",
    )?;
    let mut scenario =
        Scenario::parse(&std::fs::read_to_string(path)?).map_err(|e| format!("{e:?}"))?;
    let (mut every_s, mut names, mut back_end): (f64, Vec<String>, bool) =
        (60.0, Vec::new(), SlamConfig::default().back_end);
    let mut probe = false;
    let mut it = args[1..].iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--every" => every_s = it.next().ok_or("--every S")?.parse()?,
            "--graph" => back_end = true,
            "--no-graph" => back_end = false,
            "--probe" => probe = true,
            "--until" => scenario.duration_s = it.next().ok_or("--until S")?.parse()?,
            name => names.push(name.to_string()),
        }
    }
    let mut sim = Simulation::new(&scenario).map_err(|e| format!("{e:?}"))?;
    sim.set_capture(false);
    sim.set_mapping(false);
    let mut traced: Vec<Traced> = names
        .iter()
        .map(|n| {
            let index = sim
                .robots
                .iter()
                .position(|r| &r.spec.name == n)
                .ok_or(format!("no robot '{n}'"))?;
            // Experiments: a few settings from the environment.
            let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<f64>().ok());
            let mut config = SlamConfig {
                back_end,
                ..SlamConfig::default()
            };
            config.match_noise_m = env("SLAM_MATCH_NOISE_M").unwrap_or(config.match_noise_m);
            let o = &mut config.odometry_noise;
            o.radians_per_metre = env("SLAM_ODO_RAD_PER_M").unwrap_or(o.radians_per_metre);
            o.metres_per_metre = env("SLAM_ODO_M_PER_M").unwrap_or(o.metres_per_metre);
            // The motion filter: distance (m), angle (degrees), interval (s).
            let m = &mut config.motion;
            m.min_distance_m = env("SLAM_MOTION_M").unwrap_or(m.min_distance_m);
            m.min_angle_rad = env("SLAM_MOTION_DEG").map_or(m.min_angle_rad, f64::to_radians);
            m.max_interval_s = env("SLAM_MOTION_S").unwrap_or(m.max_interval_s);
            m.every_scan_first_s = env("SLAM_MOTION_FIRST_S").unwrap_or(m.every_scan_first_s);
            back_end_support::config_from_env(&mut config.graph);
            let mapping = RobotMapping::new(config);
            Ok(Traced {
                index,
                mapping,
                last_err: 0.0,
                last_counts: MatchCounts::default(),
                slowest: Vec::new(),
            })
        })
        .collect::<Result<_, String>>()?;
    let every = (every_s / 0.1).round().max(1.0) as usize;
    while !sim.finished() {
        sim.step();
        let step = sim.steps();
        for t in &mut traced {
            let r = &sim.robots[t.index];
            let odometry = r.odometry.pose();
            let seen = t.mapping.graph.as_ref().map_or(0, |g| g.closures.len());
            let t0 = std::time::Instant::now();
            t.mapping.observe(&odometry, &r.last_scan);
            let ms = t0.elapsed().as_secs_f64() * 1e3;
            let accepted = t.mapping.graph.as_ref().map_or(0, |g| g.closures.len());
            t.slowest.push((ms, step, accepted));
            if t.slowest.len() > 64 {
                t.slowest.sort_by(|a, b| b.0.total_cmp(&a.0));
                t.slowest.truncate(5);
            }
            let start = r.spec.start_pose();
            back_end_support::print_accepted(r, &t.mapping, seen);
            let truth = start.inverse().compose(&r.truth);
            let est = t.mapping.estimate();
            let err = est.position().distance(truth.position());
            if step % every == 0 || (err - t.last_err).abs() > 0.05 {
                print_row(&sim, t, &truth, &odometry, err);
            }
            t.last_err = err;
        }
    }
    for t in &mut traced {
        let r = &sim.robots[t.index];
        let start = r.spec.start_pose();
        let errors = position_errors_m(&start, t.mapping.estimates(), &r.log.truth);
        let profile: Vec<String> = errors
            .iter()
            .step_by(every)
            .map(|e| format!("{e:.2}"))
            .collect();
        println!(
            "{} final error every {every_s} s: {}",
            r.spec.name,
            profile.join(" ")
        );
        let headings: Vec<String> = t
            .mapping
            .estimates()
            .iter()
            .zip(&r.log.truth)
            .step_by(every)
            .map(|(e, tr)| {
                let d = slamlab::geom::wrap_angle(start.compose(e).theta - tr.theta);
                format!("{:+.2}", d.to_degrees())
            })
            .collect();
        println!(
            "{} final heading error (°) every {every_s} s: {}",
            r.spec.name,
            headings.join(" ")
        );
        t.slowest.sort_by(|a, b| b.0.total_cmp(&a.0));
        let slow: Vec<String> = t
            .slowest
            .iter()
            .take(5)
            .map(|(ms, step, c)| format!("{ms:.1} ms at step {step} ({c} closures)"))
            .collect();
        println!("{} slowest SLAM steps: {}", r.spec.name, slow.join(", "));
        print_edge_errors(r, &t.mapping);
        if std::env::var("GRAPH_TRIALS").is_ok() {
            back_end_support::print_trials(r, &t.mapping);
        }
        if probe {
            print_front_spans(r, &t.mapping);
            print_key_matches(r, &t.mapping);
        }
        println!(
            "{}: ATE slam {:.3} m (rigidly aligned {:.3} m), odometry {:.3} m, path {:.0} m, counts {:?}, back end {:?}",
            r.spec.name,
            ate_m(&start, t.mapping.estimates(), &r.log.truth),
            ate_aligned_m(&start, t.mapping.estimates(), &r.log.truth),
            ate_m(&start, &r.log.odometry, &r.log.truth),
            r.log.path_length_m(),
            t.mapping.counts,
            t.mapping.graph.as_ref().map(|g| g.stats)
        );
    }
    Ok(())
}

/// RMS error of the front end's relative pose between consecutive keys
/// against the truth's: along, across and in heading (what the key edges'
/// standard deviations should be).
fn print_edge_errors(r: &slamlab::sim::RobotSim, mapping: &RobotMapping) {
    let Some(g) = &mapping.graph else {
        return;
    };
    let (est, truth) = (mapping.estimates(), &r.log.truth);
    let mut sums = [0.0; 3];
    let steps = g.key_steps();
    for w in steps.windows(2) {
        let z = est[w[0]].between(&est[w[1]]);
        let e = truth[w[0]].between(&truth[w[1]]).between(&z);
        sums[0] += e.x * e.x;
        sums[1] += e.y * e.y;
        sums[2] += wrap_angle(e.theta).powi(2);
    }
    let n = steps.len().saturating_sub(1).max(1) as f64;
    println!(
        "{} key edges: rms along {:.4} m, across {:.4} m, heading {:.3}°",
        r.spec.name,
        (sums[0] / n).sqrt(),
        (sums[1] / n).sqrt(),
        (sums[2] / n).sqrt().to_degrees()
    );
}

/// For keys `m` apart: the rms heading and position error against the
/// truth of the front end's relative pose and of a scan-to-scan match of
/// the two keys ([`slamlab::slam::robot_graph::RobotGraph::match_keys`]),
/// over the pairs that overlap.
fn print_key_matches(r: &slamlab::sim::RobotSim, mapping: &RobotMapping) {
    let Some(g) = &mapping.graph else {
        return;
    };
    let (est, truth, steps) = (mapping.estimates(), &r.log.truth, g.key_steps());
    let res = mapping.slam_map.resolution_m();
    for (m, half) in [
        (1, 0),
        (2, 0),
        (3, 0),
        (5, 0),
        (10, 0),
        (3, 2),
        (5, 2),
        (10, 3),
    ] {
        let (mut n, mut front, mut scan, mut front_m, mut scan_m) = (0usize, 0.0, 0.0, 0.0, 0.0);
        let mut tried = 0usize;
        let mut mean_s = [0.0f64; 3];
        for i in m..steps.len() {
            tried += 1;
            let Some(k) = g.match_keys(i - m, half, i, res) else {
                continue;
            };
            let t = truth[steps[i - m]].between(&truth[steps[i]]);
            let z = est[steps[i - m]].between(&est[steps[i]]);
            let (ef, es) = (t.between(&z), t.between(&k.relative));
            front += wrap_angle(ef.theta).powi(2);
            scan += wrap_angle(es.theta).powi(2);
            front_m += ef.position().length_squared();
            scan_m += es.position().length_squared();
            mean_s[0] += es.x;
            mean_s[1] += es.y;
            mean_s[2] += wrap_angle(es.theta).to_degrees();
            n += 1;
        }
        let d = n.max(1) as f64;
        println!(
            "{} keys {m} apart (onto {} keys): {n}/{tried} overlap; heading rms front end {:.4}°, scan-to-scan {:.4}°; position rms {:.4} m, {:.4} m",
            r.spec.name,
            2 * half + 1,
            (front / d).sqrt().to_degrees(),
            (scan / d).sqrt().to_degrees(),
            (front_m / d).sqrt(),
            (scan_m / d).sqrt()
        );
        println!(
            "   scan-to-scan mean error {:+.4} {:+.4} m {:+.4}°",
            mean_s[0] / d,
            mean_s[1] / d,
            mean_s[2] / d
        );
    }
}

/// The front end's relative pose error against the truth between keys
/// `m` apart, for spans up to a lap: signed mean and rms, in the older
/// key's frame (along, across, heading).
fn print_front_spans(r: &slamlab::sim::RobotSim, mapping: &RobotMapping) {
    let Some(g) = &mapping.graph else {
        return;
    };
    let (est, truth, steps) = (mapping.estimates(), &r.log.truth, g.key_steps());
    for m in [1, 10, 50, 150, 300, 600] {
        let (mut mean, mut sq, mut n) = ([0.0; 3], [0.0; 3], 0f64);
        for i in m..steps.len() {
            let t = truth[steps[i - m]].between(&truth[steps[i]]);
            let z = est[steps[i - m]].between(&est[steps[i]]);
            let e = t.between(&z);
            for (k, v) in [e.x, e.y, wrap_angle(e.theta).to_degrees()]
                .into_iter()
                .enumerate()
            {
                mean[k] += v;
                sq[k] += v * v;
            }
            n += 1.0;
        }
        let rms = sq.map(|v| (v / n.max(1.0)).sqrt());
        let mean = mean.map(|v| v / n.max(1.0));
        println!(
            "{} front end {m} keys: mean x {:+.4} y {:+.4} m θ {:+.4}°; rms {:.4} {:.4} m {:.4}°",
            r.spec.name, mean[0], mean[1], mean[2], rms[0], rms[1], rms[2]
        );
    }
}

fn print_row(sim: &Simulation, t: &mut Traced, truth: &Pose2, odometry: &Pose2, err: f64) {
    let r = &sim.robots[t.index];
    let est = t.mapping.estimate();
    let c = t.mapping.counts;
    let d = MatchCounts {
        matched: c.matched - t.last_counts.matched,
        degenerate: c.degenerate - t.last_counts.degenerate,
        odometry_only: c.odometry_only - t.last_counts.odometry_only,
        predicted: c.predicted - t.last_counts.predicted,
    };
    t.last_counts = c;
    let out = t.mapping.last_outcome;
    let bias = t.mapping.odometry_bias();
    let closures = t
        .mapping
        .graph
        .as_ref()
        .map_or(0, |g| g.stats.closures_accepted);
    println!(
        "{:>8} t {:7.1} truth ({:6.2},{:6.2}) err {err:.3} ({:+.3},{:+.3}) {:+6.2}°  odo {:.3}  {:?} score {:.2} weak {:.1}  stretch m/d/o {}/{}/{}  bias ({:+.4}, {:+.4})  dropped {}  bumps {}  closures {closures}",
        r.spec.name,
        sim.time_s(),
        r.truth.x,
        r.truth.y,
        est.x - truth.x,
        est.y - truth.y,
        wrap_angle(est.theta - truth.theta).to_degrees(),
        odometry.position().distance(truth.position()),
        out.map(|o| o.status),
        out.map_or(0.0, |o| o.score),
        out.map_or(0.0, |o| o.constraint.weak),
        d.matched,
        d.degenerate,
        d.odometry_only,
        bias[0],
        bias[1],
        t.mapping.slam_map.dropped_updates(),
        r.bumps,
    );
}
