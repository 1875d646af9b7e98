//! Edge cases of the SLAM mapper: a robot that never moves, open space,
//! a featureless corridor, and a long run with bounded memory.

mod slam_support;

use slamlab::follower::Command;
use slamlab::scenario::Scenario;
use slamlab::sim::Simulation;
use wasm_bindgen_test::wasm_bindgen_test;

fn sim(json: &str) -> Simulation {
    Simulation::new(&Scenario::parse(json).expect("parses")).expect("runs")
}

#[wasm_bindgen_test(unsupported = test)]
fn a_robot_that_never_moves_keeps_its_pose() {
    let mut s = sim(slam_support::PRESETS[0].1);
    let stop = [Some(Command::default()), Some(Command::default())];
    for _ in 0..300 {
        s.step_with(&stop);
    }
    for r in &s.robots {
        let e = r.mapping.estimate();
        assert!(
            e.position().length() < 0.03,
            "{}: drifted to {e:?}",
            r.spec.name
        );
        assert!(
            e.theta.abs() < 1f64.to_radians(),
            "{}: turned to {}",
            r.spec.name,
            e.theta
        );
        assert_eq!(r.mapping.estimates().len(), 301);
        assert!(
            r.mapping.counts.matched + r.mapping.counts.degenerate > 250,
            "the scans were matched"
        );
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn open_space_maps_nothing_and_keeps_odometry() {
    // No walls at all: every beam is max-range.
    let mut s = sim(
        r#"{"walls": [], "duration_s": 30, "robots": [{"name": "a", "start": [0, 0, 0], "follow": "left"}]}"#,
    );
    s.run_to_end();
    let r = &s.robots[0];
    assert_eq!(r.mapping.slam_map.occupied_count(), 0);
    assert_eq!(r.mapping.odometry_map.occupied_count(), 0);
    assert_eq!(r.mapping.counts.matched + r.mapping.counts.degenerate, 0);
    assert_eq!(r.mapping.estimates().len(), r.log.odometry.len());
    for (e, o) in r.mapping.estimates().iter().zip(&r.log.odometry) {
        assert!((e.position() - o.position()).length() < 1e-9 && (e.theta - o.theta).abs() < 1e-9);
    }
    assert!(r.log.path_length_m() > 5.0, "the robot drove");
}

#[wasm_bindgen_test(unsupported = test)]
fn a_featureless_corridor_does_not_make_the_matcher_slide() {
    // A 60 m × 2 m corridor of plain walls; the robot drives along it for 90 s.
    let json = r#"{"walls": [
        {"from": [0, 0], "to": [60, 0], "texture": "plain"},
        {"from": [0, 2], "to": [60, 2], "texture": "plain"},
        {"from": [0, 0], "to": [0, 2], "texture": "plain"}],
      "duration_s": 90,
      "noise": {"wheel_scale_error": [0.01, 0.01]},
      "robots": [{"name": "a", "start": [1.0, 1.4, 0], "follow": "left"}]}"#;
    let mut s = sim(json);
    s.run_to_end();
    let r = &s.robots[0];
    let start = r.spec.start_pose();
    let last = r.log.truth.len() - 1;
    let slam = start.compose(&r.mapping.estimates()[last]);
    let odo = start.compose(&r.log.odometry[last]);
    let truth = r.log.truth[last];
    let (along_slam, along_odo) = ((slam.x - truth.x).abs(), (odo.x - truth.x).abs());
    println!("along-corridor error: SLAM {along_slam:.3} m, odometry {along_odo:.3} m, degenerate steps {}", r.mapping.counts.degenerate);
    assert!(truth.x > 20.0, "the robot drove down the corridor");
    assert!(
        r.mapping.counts.degenerate > 300,
        "the corridor was detected as degenerate"
    );
    assert!(
        along_slam <= along_odo + 0.05,
        "SLAM slid: {along_slam} vs odometry {along_odo}"
    );
    // Across the corridor, the match still corrects.
    assert!(
        (slam.y - truth.y).abs() < 0.05,
        "across: {}",
        (slam.y - truth.y).abs()
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn a_long_run_keeps_memory_bounded() {
    let mut scenario = Scenario::parse(slam_support::PRESETS[2].1).unwrap();
    scenario.duration_s = 1500.0;
    scenario.robots.truncate(1);
    let mut s = Simulation::new(&scenario).unwrap();
    for _ in 0..5000 {
        s.step();
    }
    let early = (
        s.robots[0].mapping.slam_map.memory_bytes(),
        s.robots[0].mapping.odometry_map.memory_bytes(),
    );
    s.run_to_end();
    let r = &s.robots[0];
    let late = (
        r.mapping.slam_map.memory_bytes(),
        r.mapping.odometry_map.memory_bytes(),
    );
    println!("grid bytes after 500 s {early:?}, after 1500 s {late:?}");
    // The SLAM map covers the same ring: it does not grow with time.
    assert_eq!(early.0, late.0);
    assert!(late.0 <= r.mapping.config.grid.max_cells && late.1 <= r.mapping.config.grid.max_cells);
}
