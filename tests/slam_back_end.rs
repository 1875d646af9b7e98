//! The simulated robot's loop-closing back end (`slam/robot_graph.rs`) on a
//! run known to drift: one robot following the 240 m outer wall of a 60 × 60 m
//! maze for 1,800 s (`tests/data/outer_wall_maze.json`, see its README).
//! More than half its scans pin only the direction across the wall, and the
//! filter alone drifts by more than a metre before the robot is back where
//! it started; the back end closes the loop there and moves the whole lap.
//! Both sides are asserted: without the back end the run drifts (ATE over
//! 0.2 m; measured 0.325 m), with it the ATE is under the 0.1 m and
//! under a third of the drift (measured 0.053 m; the history is in
//! docs/history/issue-22-many-robots.md, rounds 11 and 14). Slow in a debug
//! build: `cargo test --release -p slamlab --test slam_back_end`.

use slamlab::scenario::Scenario;
use slamlab::sim::Simulation;
use slamlab::slam::eval::scoring::ate_m;
use slamlab::slam::mapper::{RobotMapping, SlamConfig};

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
        without > 0.2,
        "the filter alone should drift here: {without:.3} m"
    );
    assert!(closures >= 2, "the lap should close: {closures} closures");
    assert!(with < 0.1, "with the back end: ATE {with:.3} m");
    assert!(
        with < without / 3.0,
        "the back end should undo most of the drift: {with:.3} m of {without:.3} m"
    );
}

/// A robot's mapping handed to "another thread" (here, a value beside the
/// simulation: `slam/handoff.rs`) for the middle of a run and brought home
/// ends as the one that stayed, bit for bit; the simulation refuses a
/// mapping that missed steps, estimates it never made, a second hand-off.
#[test]
fn a_mapping_sent_away_and_brought_home_is_the_one_that_stayed() {
    use slamlab::slam::handoff::{mapping_from_bytes, mapping_to_bytes, observe_packed};
    let scenario = Scenario::parse(include_str!("../scenarios/thesis.json")).expect("thesis");
    let mut stayed = Simulation::new(&scenario).expect("simulates");
    let mut went = Simulation::new(&scenario).expect("simulates");
    for sim in [&mut stayed, &mut went] {
        sim.set_capture(false);
    }
    for _ in 0..200 {
        stayed.step();
        went.step();
    }
    let mut away = mapping_from_bytes(&went.send_mapping_away(1).expect("away")).expect("bytes");
    assert!(went.send_mapping_away(1).is_err(), "away already");
    assert_eq!(
        went.robots[1].slam_estimates().len(),
        201,
        "the estimates so far stay"
    );
    for slice in 0..30 {
        for _ in 0..(17 + slice % 5) {
            stayed.step();
            went.step();
        }
        let from = away.estimates().len();
        observe_packed(&mut away, &went.take_mapping_steps(1)).expect("a batch");
        let reported: Vec<f64> = away.estimates()[from..]
            .iter()
            .flat_map(|p| [p.x, p.y, p.theta])
            .collect();
        went.note_away_estimates(1, &reported).expect("estimates");
    }
    assert_eq!(went.robots[1].slam_estimates().len(), went.steps() + 1);
    assert!(
        went.note_away_estimates(1, &[0.0; 3]).is_err(),
        "a step not made"
    );
    went.step();
    stayed.step();
    let bytes = mapping_to_bytes(&away).expect("bytes");
    let refused = went.bring_mapping_home(1, &bytes).unwrap_err();
    assert!(refused.contains("steps it was not sent"), "{refused}");
    observe_packed(&mut away, &went.take_mapping_steps(1)).expect("the last step");
    went.bring_mapping_home(1, &mapping_to_bytes(&away).expect("bytes"))
        .expect("home");
    let (a, b) = (&stayed.robots[1].mapping, &went.robots[1].mapping);
    assert_eq!(a.estimates(), b.estimates());
    assert_eq!(mapping_to_bytes(a).unwrap(), mapping_to_bytes(b).unwrap());
    assert_eq!(a.slam_map.memory_bytes(), b.slam_map.memory_bytes());
    assert!(went.note_away_estimates(1, &[]).is_err(), "home again");
}
