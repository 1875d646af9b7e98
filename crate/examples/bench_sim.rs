//! Native benchmark of the simulation and the renderer (BENCHMARKS.md).
//!
//! `cargo run --release -p slamlab --example bench_sim`
//!
//! Simulation: every preset run for its full duration, reported as
//! robot-steps per second (one robot's sense + decide + move + log), in
//! three configurations: range sensors only (sonar and laser); plus camera
//! capture (a frame per simulated second); plus both mappers (odometry-only
//! and SLAM). Rendering: ms per 960 x 720 frame of the thesis preset mid-run
//! with laser rays, paths and grid. Medians of 3 and 200 repetitions.
//!
//! `cargo run --release -p slamlab --example bench_sim -- --late S.json 10,600,1800`:
//! the world view of scenario `S.json` (1366 × 560) late in a run, drawn
//! every 2 simulated seconds as the page draws it while running; at each
//! listed time, the median time of a redraw after 2 s more of the run with
//! the robots' paths kept on their layer (`render/trails.rs`), and of the
//! same picture with the paths drawn from nothing (every path stroked
//! whole; the walls from their kept layer in both).

use slamlab::lab::Lab;
use slamlab::render::{render_world_cached, TrailLayer, ViewLayers};
use std::time::Instant;

const PRESETS: [(&str, &str); 4] = [
    ("thesis", include_str!("../../scenarios/thesis.json")),
    ("office", include_str!("../../scenarios/office.json")),
    ("loop", include_str!("../../scenarios/loop.json")),
    ("maze", include_str!("../../scenarios/maze.json")),
];

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--late") {
        let usage = "usage: bench_sim --late SCENARIO.json T1,T2,...";
        let (path, marks) = (args.get(i + 1).ok_or(usage)?, args.get(i + 2).ok_or(usage)?);
        return late(path, marks);
    }
    for (name, text) in PRESETS {
        let mut line = format!("native simulate {name:7}");
        for (label, capture, mapping) in [
            ("sensors", false, false),
            ("+camera", true, false),
            ("+SLAM", true, true),
        ] {
            let mut rates = Vec::new();
            for _ in 0..3 {
                let mut lab = Lab::new(text)?;
                let sim = lab.start()?;
                sim.set_capture(capture);
                sim.set_mapping(mapping);
                let t0 = Instant::now();
                sim.run_to_end();
                let dt = t0.elapsed().as_secs_f64();
                rates.push((sim.steps() * sim.robots.len()) as f64 / dt);
            }
            line += &format!("  {label} {:>7.0}", median(rates));
        }
        println!("{line}  robot-steps/s");
    }
    let mut lab = Lab::new(PRESETS[0].1)?;
    lab.fit_view(960, 720)?;
    lab.step(1500)?;
    let mut times = Vec::new();
    for _ in 0..200 {
        let t0 = Instant::now();
        lab.render()?;
        times.push(t0.elapsed().as_secs_f64() * 1000.0);
    }
    println!("native render 960x720 {:.2} ms/frame", median(times));
    for (w, h) in [(320, 240), (640, 480)] {
        let mut s: serde_json::Value = serde_json::from_str(PRESETS[0].1)?;
        s["camera"] = serde_json::json!({"width": w, "height": h});
        let mut lab = Lab::new(&s.to_string())?;
        lab.step(1500)?;
        lab.camera_view(0, false)?;
        let mut times = Vec::new();
        for _ in 0..100 {
            let t0 = Instant::now();
            lab.camera_view(0, false)?;
            times.push(t0.elapsed().as_secs_f64() * 1000.0);
        }
        println!("native camera {w}x{h} {:.2} ms/frame", median(times));
    }
    Ok(())
}

/// The world view late in a run (see the module doc).
fn late(path: &str, marks: &str) -> Result<(), Box<dyn std::error::Error>> {
    const CHUNK: usize = 20; // steps between two redraws: 2 simulated seconds
    let mut lab = Lab::new(&std::fs::read_to_string(path)?)?;
    let view = lab.fit_view(1366, 560)?.clone();
    let mut pm = tiny_skia::Pixmap::new(view.width, view.height).ok_or("no image")?;
    let mut layers = ViewLayers::default();
    let mut steps = 0;
    for mark in marks.split(',') {
        let mark_s: usize = mark.trim().parse()?;
        while steps + CHUNK <= mark_s * 10 {
            steps += lab.step(CHUNK)?;
            lab.render()?;
        }
        let (mut kept, mut whole) = (Vec::new(), Vec::new());
        for _ in 0..5 {
            steps += lab.step(CHUNK)?;
            let t0 = Instant::now();
            lab.render()?;
            kept.push(t0.elapsed().as_secs_f64() * 1000.0);
            // The walls from their kept layer, the paths from nothing.
            layers.trails = TrailLayer::default();
            let t0 = Instant::now();
            let sim = lab.simulation();
            render_world_cached(&mut pm, lab.scenario(), sim, &view, &mut layers);
            whole.push(t0.elapsed().as_secs_f64() * 1000.0);
        }
        println!(
            "t = {:.0} s: redraw {:.2} ms with the paths kept, {:.2} ms drawn whole",
            steps as f64 / 10.0,
            median(kept),
            median(whole)
        );
    }
    Ok(())
}
