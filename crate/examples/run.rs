//! The whole experiment natively, as `node web/cli.mjs run` does it in
//! wasm: simulate, then merge with the default (automatic) method, and
//! print the stage timings. A profiling target:
//!
//! `cargo run --release -p slamlab --example run -- scenarios/thesis.json [auto|thesis|map-only]`
//!
//! `perf record -g target/release/examples/run scenarios/thesis.json` shows
//! where the time goes; `… run SCENARIO.json simulate` stops after the
//! simulation (the robots' runs, their SLAM and frames) and prints its time.

use slamlab::lab::Lab;
use slamlab::merge::MergeMethod;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = args
        .get(1)
        .ok_or("usage: run SCENARIO.json [auto|thesis|map-only|simulate]")?;
    let method_arg = args.get(2).map_or("auto", |s| s.as_str());
    let simulate_only = method_arg == "simulate" || method_arg == "steps";
    let method = MergeMethod::parse(if simulate_only { "auto" } else { method_arg })?;
    let mut lab = Lab::new(&std::fs::read_to_string(path)?)?;
    let start = Instant::now();
    lab.set_clock(|| {
        static EPOCH: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
        EPOCH.get_or_init(Instant::now).elapsed().as_secs_f64() * 1e3
    });
    if method_arg == "steps" {
        slowest_steps(&mut lab)?;
    } else {
        lab.run_to_end()?;
    }
    let simulate = start.elapsed().as_secs_f64() * 1e3;
    if simulate_only {
        for (i, spec) in lab.scenario().robots.iter().enumerate() {
            let f = lab.slam_figures(i)?;
            println!(
                "  {}: SLAM ATE {:.4} m (odometry {:.4} m; SLAM aligned {:.4} m)",
                spec.name, f.ate_m, f.odometry_ate_m, f.ate_aligned_m
            );
        }
        if let Some(sim) = lab.simulation() {
            let config =
                slamlab::merge::config::MergeConfig::new(MergeMethod::Auto, sim.scenario.seed);
            let described = slamlab::merge::described_ahead::frames_to_describe(sim, &config);
            let stored: usize = sim.robots.iter().map(|r| r.frames.frames.len()).sum();
            println!(
                "frames: {} stored, {} taking part in the automatic merge",
                stored,
                described.len()
            );
            println!("fingerprint: {:016x}", fingerprint(sim));
        }
        println!("simulate (ms): {simulate:.0}");
        return Ok(());
    }
    lab.merge_start(method)?;
    lab.merge_finish()?;
    let total = start.elapsed().as_secs_f64() * 1e3;
    let report = lab.report(slamlab::lab::report::Timings {
        simulate,
        total,
        ..Default::default()
    })?;
    let merge = report.merge.as_ref().ok_or("no merge report")?;
    println!("{}: {:?} ({})", report.scenario, merge.status, merge.reason);
    for e in &merge.errors {
        println!(
            "  {}: {:.3} m, {:.2} deg off",
            e.robot, e.error_m, e.error_deg
        );
    }
    println!("timings (ms): {:?}", report.timings_ms);
    Ok(())
}

/// Runs `lab` one step at a time, as the page does, and prints the ten
/// slowest steps with their SLAM and camera shares.
fn slowest_steps(lab: &mut Lab) -> Result<(), Box<dyn std::error::Error>> {
    let mut steps: Vec<(f64, f64, f64, usize)> = Vec::new();
    let stages = |lab: &Lab| {
        lab.simulation().map_or((0.0, 0.0), |s| {
            (s.stage_times.slam_ms, s.stage_times.camera_ms)
        })
    };
    loop {
        let (slam0, camera0) = stages(lab);
        let t = Instant::now();
        if lab.step(1)? == 0 {
            break;
        }
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let (slam1, camera1) = stages(lab);
        let n = lab.simulation().map_or(0, |s| s.steps());
        steps.push((ms, slam1 - slam0, camera1 - camera0, n));
    }
    steps.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (ms, slam, camera, n) in steps.iter().take(10) {
        println!("step {n}: {ms:.1} ms (SLAM {slam:.1}, camera {camera:.1})");
    }
    Ok(())
}

/// A hash (FNV-1a) of every robot's true and SLAM poses, step by step, and
/// of both its maps' cells: two builds that print the same fingerprint ran
/// the same simulation and SLAM bit for bit (a check for changes meant to
/// be faster only).
fn fingerprint(sim: &slamlab::sim::Simulation) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            h = (h ^ b as u64).wrapping_mul(0x0100_0000_01b3);
        }
    };
    for r in &sim.robots {
        for p in r.log.truth.iter().chain(r.mapping.estimates()) {
            for v in [p.x, p.y, p.theta] {
                eat(&v.to_bits().to_le_bytes());
            }
        }
        for map in [&r.mapping.slam_map, &r.mapping.odometry_map] {
            let [ox, oy] = map.origin_cell();
            eat(&[ox, oy, map.width() as i64, map.height() as i64].map(|v| v as u8));
            eat(&map.raw_units().iter().map(|&u| u as u8).collect::<Vec<_>>());
        }
    }
    h
}
