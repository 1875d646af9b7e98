//! Runs a scenario natively and writes a picture of the tours.
//!
//! `cargo run --release -p slamlab --example tour -- scenarios/thesis.json out.png`
//!
//! Prints, per robot, the bumps, the true path length and the odometry's
//! final error; the PNG shows walls, true (solid) and odometry (dashed) paths.

use slamlab::lab::Lab;
use slamlab::render::Layers;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = args
        .get(1)
        .ok_or("usage: tour SCENARIO.json [OUT.png] [DURATION_S]")?;
    let text = std::fs::read_to_string(path)?;
    let mut lab = Lab::new(&text)?;
    if let Some(d) = args.get(3) {
        lab.set_duration(d.parse()?)?;
    }
    let t0 = std::time::Instant::now();
    lab.run_to_end()?;
    let dt = t0.elapsed().as_secs_f64();
    let report = lab.report(Default::default())?;
    println!(
        "{}: {} steps in {:.3} s ({:.0} steps/s)",
        report.scenario,
        report.steps,
        dt,
        report.steps as f64 / dt
    );
    for r in &report.robots {
        println!(
            "  {:8} follow {:5} bumps {:2} path {:6.1} m  odometry error {:.2} m / {:.1} deg",
            r.name,
            r.follow,
            r.bumps,
            r.path_length_m,
            r.odometry_final_error.position_m,
            r.odometry_final_error.heading_deg
        );
    }
    if let Some(out) = args.get(2) {
        let mut view = lab.view().clone();
        view.layers = Layers {
            laser: false,
            ..Layers::default()
        };
        lab.set_view(view)?;
        lab.fit_view(960, 720)?;
        let pm = lab.render()?;
        image::save_buffer(
            out,
            pm.data(),
            pm.width(),
            pm.height(),
            image::ColorType::Rgba8,
        )?;
    }
    Ok(())
}
