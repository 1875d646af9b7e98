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

use slamlab::lab::Lab;
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
