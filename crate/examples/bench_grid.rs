//! Native benchmark of the occupancy grid's scan integration (BENCHMARKS.md).
//!
//! `cargo run --release -p slamlab --example bench_grid`
//!
//! Records robot 1's scans and odometry poses over the thesis preset
//! (mappers off), then replays them into a fresh grid: the beam clearing
//! and hit marking both mappers do every step, isolated from matching.
//! Median of 5 replays, in µs per scan, and the cell visits a beam-by-beam
//! walk would make (what the fan fill of `OccupancyGrid::integrate_scan`
//! replaced).

use slamlab::geom::Pose2;
use slamlab::lab::Lab;
use slamlab::sensors::LaserScan;
use slamlab::slam::grid::{GridConfig, OccupancyGrid};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut lab = Lab::new(include_str!("../../scenarios/thesis.json"))?;
    let sim = lab.start()?;
    sim.set_capture(false);
    sim.set_mapping(false);
    let mut scans: Vec<(Pose2, LaserScan)> = Vec::new();
    while !sim.finished() {
        sim.step();
        let r = &sim.robots[0];
        scans.push((r.odometry.pose(), r.last_scan.clone()));
    }
    let mut cells = 0usize;
    for (pose, scan) in &scans {
        let c = pose.position() / 0.05;
        for (i, d) in
            slamlab::slam::grid::beam_directions(pose.theta, scan.ranges_m.len()).enumerate()
        {
            slamlab::slam::grid::traverse(c, c + d * scan.ranges_m[i] / 0.05, |_| cells += 1);
        }
    }
    println!("beam-walk cell visits per scan: {}", cells / scans.len());
    for surface_points in [false, true] {
        let mut times = Vec::new();
        let mut checksum = 0i64;
        for _ in 0..5 {
            let mut grid = OccupancyGrid::new(GridConfig {
                surface_points,
                ..GridConfig::default()
            });
            let t0 = Instant::now();
            for (pose, scan) in &scans {
                grid.integrate_scan(pose, scan);
            }
            times.push(t0.elapsed().as_secs_f64() * 1e6 / scans.len() as f64);
            checksum = grid.raw_units().iter().map(|&c| c as i64).sum();
        }
        times.sort_by(f64::total_cmp);
        println!(
            "native integrate_scan (surface layer {surface_points:5}): {:.1} µs/scan over {} scans, cell sum {checksum}",
            times[2],
            scans.len()
        );
    }
    Ok(())
}
