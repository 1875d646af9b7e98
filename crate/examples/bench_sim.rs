//! Native benchmark of the simulation and the renderer (BENCHMARKS.md).
//!
//! `cargo run --release -p slamlab --example bench_sim`
//!
//! Simulation: every preset run for its full duration, all sensors on;
//! reported as robot-steps per second (one robot's sense + decide + move +
//! log). Rendering: ms per 960 x 720 frame of the thesis preset mid-run with
//! laser rays, paths and grid. Medians of 5 and 200 repetitions.

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
        let mut rates = Vec::new();
        for _ in 0..5 {
            let mut lab = Lab::new(text)?;
            let t0 = Instant::now();
            lab.run_to_end()?;
            let dt = t0.elapsed().as_secs_f64();
            let st = lab.state();
            rates.push((st.steps * st.robots.len()) as f64 / dt);
        }
        println!(
            "native simulate {name:7} {:>9.0} robot-steps/s",
            median(rates)
        );
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
    Ok(())
}
