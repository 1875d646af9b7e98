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
    let simulate_only = method_arg == "simulate";
    let method = MergeMethod::parse(if simulate_only { "auto" } else { method_arg })?;
    let mut lab = Lab::new(&std::fs::read_to_string(path)?)?;
    let start = Instant::now();
    lab.set_clock(|| {
        static EPOCH: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
        EPOCH.get_or_init(Instant::now).elapsed().as_secs_f64() * 1e3
    });
    lab.run_to_end()?;
    let simulate = start.elapsed().as_secs_f64() * 1e3;
    if simulate_only {
        for (i, spec) in lab.scenario().robots.iter().enumerate() {
            let f = lab.slam_figures(i)?;
            println!(
                "  {}: SLAM ATE {:.4} m (odometry {:.4} m)",
                spec.name, f.ate_m, f.odometry_ate_m
            );
        }
        if let Some(sim) = lab.simulation() {
            let config =
                slamlab::merge::config::MergeConfig::new(MergeMethod::Auto, sim.scenario.seed);
            let described = slamlab::merge::described::frames_to_describe(sim, &config);
            let stored: usize = sim.robots.iter().map(|r| r.frames.frames.len()).sum();
            println!(
                "frames: {} stored, {} taking part in the automatic merge",
                stored,
                described.len()
            );
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
