//! The simulated robot's loop-closing back end (`slam/robot_graph.rs`) on a
//! run known to drift: one robot following the 240 m outer wall of a 60 × 60 m
//! maze for 1,800 s (`tests/data/outer_wall_maze.json`, see its README).
//! More than half its scans pin only the direction across the wall, and the
//! filter alone drifts by more than a metre before the robot is back where
//! it started; the back end closes the loop there and moves the whole lap.
//! Both sides are asserted: without the back end the run drifts (ATE over
//! 0.5 m, measured 0.898 m), with it the ATE is under the 0.1 m
//! (measured 0.040 m, session 23). Slow in a debug build: `cargo test --release -p
//! slamlab --test slam_back_end`.

use slamlab::scenario::Scenario;
use slamlab::sim::Simulation;
use slamlab::slam::mapper::{RobotMapping, SlamConfig};
use slamlab::slam::scoring::ate_m;

/// The run's ATE (m) and loop closures accepted, with or without the back end.
fn run(back_end: bool) -> (f64, usize) {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/data/outer_wall_maze.json"
    );
    let text = std::fs::read_to_string(path).expect("tests/data/outer_wall_maze.json");
    let scenario = Scenario::parse(&text).expect("the scenario parses");
    let mut sim = Simulation::new(&scenario).expect("the scenario simulates");
    sim.set_capture(false);
    sim.set_mapping(false);
    let mut mapping = RobotMapping::new(SlamConfig {
        back_end,
        ..SlamConfig::default()
    });
    while !sim.finished() {
        sim.step();
        let robot = &sim.robots[0];
        mapping.observe(&robot.odometry.pose(), &robot.last_scan);
    }
    let robot = &sim.robots[0];
    let ate = ate_m(
        &robot.spec.start_pose(),
        mapping.estimates(),
        &robot.log.truth,
    );
    let closures = mapping
        .graph
        .as_ref()
        .map_or(0, |g| g.stats.closures_accepted);
    (ate, closures)
}

#[test]
#[cfg_attr(debug_assertions, ignore = "slow in a debug build: run with --release")]
fn the_back_end_undoes_an_outer_wall_drift() {
    let (without, none) = run(false);
    let (with, closures) = run(true);
    println!("ATE without the back end {without:.3} m, with it {with:.3} m ({closures} closures)");
    assert_eq!(none, 0);
    assert!(
        without > 0.5,
        "the filter alone should drift here: {without:.3} m"
    );
    assert!(closures >= 2, "the lap should close: {closures} closures");
    assert!(with < 0.1, "with the back end: ATE {with:.3} m");
}
