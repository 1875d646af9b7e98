//! The wall follower and the simulation loop, on corridors, presets,
//! open space, random user-drawn mazes, and robots meeting head-on.

use glam::DVec2;
use slamlab::follower::Command;
use slamlab::geom::{Pose2, Segment};
use slamlab::kinematics::P2dx;
use slamlab::rng::Rng;
use slamlab::scenario::{FollowSide, Scenario};
use slamlab::sensors::{RangeScene, Sonar};
use slamlab::sim::Simulation;

/// A simulation without camera capture or mapping: these tests are about
/// motion, which neither changes.
fn sim_of(s: &Scenario) -> Simulation {
    let mut sim = Simulation::new(s).unwrap();
    sim.set_capture(false);
    sim.set_mapping(false);
    sim
}
use wasm_bindgen_test::wasm_bindgen_test;

const PRESETS: [(&str, &str); 4] = [
    ("thesis", include_str!("../scenarios/thesis.json")),
    ("office", include_str!("../scenarios/office.json")),
    ("loop", include_str!("../scenarios/loop.json")),
    ("maze", include_str!("../scenarios/maze.json")),
];

fn wall(a: [f64; 2], b: [f64; 2]) -> String {
    format!(
        r#"{{"from": [{}, {}], "to": [{}, {}]}}"#,
        a[0], a[1], b[0], b[1]
    )
}

fn scenario(walls: &[String], robots: &[String], duration: f64, seed: u64) -> Scenario {
    let json = format!(
        r#"{{"seed": {seed}, "duration_s": {duration}, "walls": [{}], "robots": [{}]}}"#,
        walls.join(","),
        robots.join(",")
    );
    Scenario::from_json(&json).unwrap_or_else(|e| panic!("{e}\n{json}"))
}

/// The noise-free range of sonar `i` at the robot's true pose.
fn true_sonar(sim: &Simulation, robot: usize, i: usize) -> Option<f64> {
    let sonar = Sonar::new(2.0, 15.0, 0.0, Rng::new(0));
    let scene = RangeScene {
        world: &sim.world,
        obstacles: &[],
    };
    sonar.exact_range(&scene, &sim.robots[robot].truth, i)
}

fn corridor_holds_distance(side: FollowSide) {
    // A 40 m corridor, 2.4 m wide; start 1 m from the followed wall.
    let (y_wall, y_start, follow, sonar) = match side {
        FollowSide::Left => (2.4, 1.4, "left", 0),
        FollowSide::Right => (0.0, 1.0, "right", 7),
    };
    let walls = [
        wall([-1.0, 0.0], [40.0, 0.0]),
        wall([-1.0, 2.4], [40.0, 2.4]),
    ];
    let robot = format!(r#"{{"name": "r", "start": [1, {y_start}, 0], "follow": "{follow}"}}"#);
    let mut sim = sim_of(&scenario(&walls, &[robot], 90.0, 3));
    let mut readings = Vec::new();
    while !sim.finished() {
        sim.step();
        let r = &sim.robots[0];
        if sim.time_s() > 15.0 && r.truth.x < 38.0 {
            readings.push(true_sonar(&sim, 0, sonar).expect("the side sonar sees the wall"));
        }
    }
    assert!(
        readings.len() > 300,
        "the robot should drive along: {}",
        readings.len()
    );
    let worst = readings.iter().map(|r| (r - 0.6).abs()).fold(0.0, f64::max);
    let mean = readings.iter().sum::<f64>() / readings.len() as f64;
    assert!(
        worst <= 0.1,
        "{side:?}: side sonar strayed {worst:.3} m from 0.6 (mean {mean:.3})"
    );
    assert_eq!(sim.robots[0].bumps, 0);
    let _ = y_wall;
}

#[wasm_bindgen_test(unsupported = test)]
fn wall_follower_keeps_0_6_m_in_corridor_left() {
    corridor_holds_distance(FollowSide::Left);
}

#[wasm_bindgen_test(unsupported = test)]
fn wall_follower_keeps_0_6_m_in_corridor_right() {
    corridor_holds_distance(FollowSide::Right);
}

#[wasm_bindgen_test(unsupported = test)]
fn every_preset_is_toured_without_a_bump() {
    for (name, text) in PRESETS {
        let s = Scenario::from_json(text).unwrap();
        let mut sim = sim_of(&s);
        sim.run_to_end();
        for r in &sim.robots {
            assert_eq!(r.bumps, 0, "{name}/{} bumped", r.spec.name);
            let path = r.log.path_length_m();
            // Cruise 0.35 m/s: a real tour covers most of the possible distance.
            let possible = 0.35 * s.duration_s;
            assert!(
                path > 0.6 * possible,
                "{name}/{} drove only {path:.1} m",
                r.spec.name
            );
            // It explored: it visited many distinct 1 m cells.
            let mut cells: Vec<(i64, i64)> = r
                .log
                .truth
                .iter()
                .map(|p| (p.x.floor() as i64, p.y.floor() as i64))
                .collect();
            cells.sort();
            cells.dedup();
            assert!(
                cells.len() > 25,
                "{name}/{} stayed in {} cells",
                r.spec.name,
                cells.len()
            );
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn robot_started_in_open_space_finds_a_wall_and_follows_it() {
    let walls = [
        wall([0.0, 0.0], [20.0, 0.0]),
        wall([20.0, 0.0], [20.0, 20.0]),
        wall([20.0, 20.0], [0.0, 20.0]),
        wall([0.0, 20.0], [0.0, 0.0]),
    ];
    for (k, heading) in [0.3f64, 2.0, -2.5].iter().enumerate() {
        let robot = format!(r#"{{"name": "r", "start": [10, 10, {heading}], "follow": "right"}}"#);
        let mut sim = sim_of(&scenario(&walls, &[robot], 120.0, k as u64));
        sim.run_to_end();
        let r = &sim.robots[0];
        assert_eq!(r.bumps, 0);
        // Over the last minute it stays close to the walls (~0.74 m from the centre).
        let n = r.log.truth.len();
        for p in &r.log.truth[n - 600..] {
            let d = p.x.min(p.y).min(20.0 - p.x).min(20.0 - p.y);
            assert!(
                (0.5..1.2).contains(&d),
                "heading {heading}: {d:.2} m from the nearest wall at {p:?}"
            );
        }
    }
}

/// A random maze of the kind a user draws: a closed room, axis-aligned and
/// slanted walls attached to it or free-standing, robots at random free spots.
fn random_maze(seed: u64) -> Scenario {
    let mut rng = Rng::new(seed);
    let (w, h) = (rng.range(12.0, 22.0), rng.range(10.0, 16.0));
    let mut walls = vec![
        wall([0.0, 0.0], [w, 0.0]),
        wall([w, 0.0], [w, h]),
        wall([w, h], [0.0, h]),
        wall([0.0, h], [0.0, 0.0]),
    ];
    let mut segs: Vec<Segment> = Vec::new();
    for _ in 0..rng.range(4.0, 9.0) as usize {
        let side = (rng.uniform() * 4.0) as usize;
        let len = rng.range(2.0, 6.0);
        let (a, dir) = match side {
            0 => ([rng.range(2.5, w - 2.5), 0.0], [0.0, 1.0]),
            1 => ([w, rng.range(2.5, h - 2.5)], [-1.0, 0.0]),
            2 => ([rng.range(2.5, w - 2.5), h], [0.0, -1.0]),
            _ => ([0.0, rng.range(2.5, h - 2.5)], [1.0, 0.0]),
        };
        let tilt = if rng.uniform() < 0.3 {
            rng.range(-0.6, 0.6)
        } else {
            0.0
        };
        let d = DVec2::from(dir).rotate(DVec2::from_angle(tilt));
        let b = DVec2::from(a) + d * len;
        let s = Segment::new(DVec2::from(a), b);
        // Keep corridors at least 2.2 m wide.
        if segs.iter().any(|o| o.distance_to_segment(&s) < 2.2) {
            continue;
        }
        segs.push(s);
        walls.push(wall(a, [b.x, b.y]));
    }
    let mut robots = Vec::new();
    let all: Vec<Segment> = segs
        .iter()
        .copied()
        .chain([
            Segment::new(DVec2::ZERO, DVec2::new(w, 0.0)),
            Segment::new(DVec2::new(w, 0.0), DVec2::new(w, h)),
            Segment::new(DVec2::new(w, h), DVec2::new(0.0, h)),
            Segment::new(DVec2::new(0.0, h), DVec2::ZERO),
        ])
        .collect();
    let mut placed: Vec<DVec2> = Vec::new();
    while robots.len() < 2 {
        let p = DVec2::new(rng.range(1.0, w - 1.0), rng.range(1.0, h - 1.0));
        if all.iter().any(|s| s.distance_to_point(p) < 0.8)
            || placed.iter().any(|q| q.distance(p) < 3.0)
        {
            continue;
        }
        let side = if robots.is_empty() { "left" } else { "right" };
        robots.push(format!(
            r#"{{"name": "r{}", "start": [{}, {}, {}], "follow": "{side}"}}"#,
            robots.len(),
            p.x,
            p.y,
            rng.range(-3.1, 3.1)
        ));
        placed.push(p);
    }
    scenario(&walls, &robots, 240.0, seed)
}

#[wasm_bindgen_test(unsupported = test)]
fn random_user_drawn_mazes_are_toured_without_a_bump() {
    for seed in 1..=8 {
        let s = random_maze(seed);
        let mut sim = sim_of(&s);
        sim.run_to_end();
        for r in &sim.robots {
            assert_eq!(
                r.bumps,
                0,
                "maze seed {seed}: {} bumped\n{}",
                r.spec.name,
                s.to_json_pretty()
            );
            let path = r.log.path_length_m();
            assert!(
                path > 40.0,
                "maze seed {seed}: {} drove only {path:.1} m",
                r.spec.name
            );
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn robots_meeting_head_on_pass_each_other() {
    // A left-follower and a right-follower on the same wall of a 3 m corridor,
    // driving at each other.
    let walls = [
        wall([-5.0, 0.0], [35.0, 0.0]),
        wall([-5.0, 3.0], [35.0, 3.0]),
    ];
    let robots = [
        r#"{"name": "east", "start": [2, 2.26, 0], "follow": "left"}"#.to_string(),
        r#"{"name": "west", "start": [26, 2.26, 3.14159], "follow": "right"}"#.to_string(),
    ];
    let mut sim = sim_of(&scenario(&walls, &robots, 120.0, 5));
    sim.run_to_end();
    let (e, w) = (&sim.robots[0], &sim.robots[1]);
    assert_eq!((e.bumps, w.bumps), (0, 0));
    // Each got past the other's start region.
    let max_x = e.log.truth.iter().map(|p| p.x).fold(f64::MIN, f64::max);
    let min_x = w.log.truth.iter().map(|p| p.x).fold(f64::MAX, f64::min);
    assert!(max_x > 24.0, "east reached only x = {max_x:.1}");
    assert!(min_x < 4.0, "west reached only x = {min_x:.1}");
}

#[wasm_bindgen_test(unsupported = test)]
fn a_bump_stops_the_robot_and_is_counted_once_per_contact() {
    let walls = [wall([2.0, -3.0], [2.0, 3.0])];
    let robots = [r#"{"name": "r", "start": [0, 0, 0], "follow": "left"}"#.to_string()];
    let mut sim = sim_of(&scenario(&walls, &robots, 60.0, 1));
    let drive = Command {
        v_mps: 0.4,
        omega_radps: 0.0,
    };
    for _ in 0..100 {
        sim.step_with(&[Some(drive)]);
        let front = sim.robots[0].truth.x + P2dx::BODY_LENGTH_M / 2.0;
        assert!(
            front < 2.0,
            "the body passed through the wall: front at {front}"
        );
    }
    let r = &sim.robots[0];
    assert_eq!(r.bumps, 1, "one contact, one bump");
    // Stalled against the wall: odometry stopped growing too.
    let o = r.odometry.pose();
    assert!(
        o.x < 1.8 && (o.x - r.truth.x).abs() < 0.05,
        "{o:?} vs {:?}",
        r.truth
    );
    // Back off, then drive in again: a second bump.
    for _ in 0..20 {
        sim.step_with(&[Some(Command {
            v_mps: -0.3,
            omega_radps: 0.0,
        })]);
    }
    for _ in 0..40 {
        sim.step_with(&[Some(drive)]);
    }
    assert_eq!(sim.robots[0].bumps, 2);
}

#[wasm_bindgen_test(unsupported = test)]
fn runs_are_a_function_of_scenario_and_seed() {
    let text = PRESETS[0].1;
    let run = |seed: u64| {
        let mut s = Scenario::from_json(text).unwrap();
        s.seed = seed;
        s.duration_s = 60.0;
        let mut sim = sim_of(&s);
        sim.run_to_end();
        sim
    };
    let (a, b, c) = (run(7), run(7), run(8));
    for i in 0..2 {
        assert_eq!(a.robots[i].log.odometry, b.robots[i].log.odometry);
        assert_eq!(a.robots[i].log.truth, b.robots[i].log.truth);
        assert_eq!(a.robots[i].log.sensors, b.robots[i].log.sensors);
        assert_ne!(a.robots[i].log.odometry, c.robots[i].log.odometry);
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn zero_noise_odometry_tracks_truth_exactly_over_a_tour() {
    let mut s = Scenario::from_json(PRESETS[0].1).unwrap();
    s.noise = slamlab::scenario::NoiseSpec::zero();
    s.duration_s = 120.0;
    let mut sim = sim_of(&s);
    sim.run_to_end();
    for r in &sim.robots {
        let start = r.spec.start_pose();
        for (o, t) in r.log.odometry.iter().zip(&r.log.truth) {
            let w = start.compose(o);
            assert!((w.position() - t.position()).length() < 1e-6);
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn default_noise_makes_odometry_visibly_drift_over_a_thesis_length_run() {
    let s = Scenario::from_json(PRESETS[0].1).unwrap();
    let mut sim = sim_of(&s);
    sim.run_to_end();
    for r in &sim.robots {
        let n = r.log.truth.len() - 1;
        let w = r.spec.start_pose().compose(&r.log.odometry[n]);
        let err = (w.position() - r.log.truth[n].position()).length();
        // Visible on a 20 m map (more than a robot length), but not absurd.
        assert!(
            err > 0.5 && err < 8.0,
            "{}: odometry off by {err:.2} m",
            r.spec.name
        );
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn logs_have_one_row_per_step_in_the_thesis_layout() {
    let mut s = Scenario::from_json(PRESETS[0].1).unwrap();
    s.duration_s = 10.0;
    let mut sim = sim_of(&s);
    sim.run_to_end();
    for r in &sim.robots {
        assert_eq!(r.log.times_s.len(), 101);
        assert_eq!(r.log.odometry.len(), 101);
        assert_eq!(r.log.truth.len(), 101);
        assert_eq!(r.log.sensors.len(), 101);
        assert_eq!(r.log.sensors[100].laser_mm.len(), 181);
        assert_eq!(r.log.sensors[100].sonar_m.len(), 8);
        assert!((r.log.times_s[100] - 10.0).abs() < 1e-9);
        assert_eq!(r.log.odometry[0], Pose2::IDENTITY);
        assert_eq!(r.log.truth[0], r.spec.start_pose());
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn a_robot_that_never_moves_keeps_a_bounded_log() {
    // Memory stays bounded on long runs: sensor rows are capped.
    let walls = [wall([0.0, 0.0], [1.0, 0.0])];
    let robots = [r#"{"name": "r", "start": [0.5, 1, 0], "follow": "left"}"#.to_string()];
    let mut sim = sim_of(&scenario(&walls, &robots, 1300.0, 1));
    let stop = Command::default();
    while !sim.finished() {
        sim.step_with(&[Some(stop)]);
    }
    let r = &sim.robots[0];
    assert_eq!(r.log.truth.len(), 13_001);
    assert_eq!(r.log.sensors.len(), slamlab::sim::LOG_SENSOR_CAP);
    assert_eq!(r.log.sensors_dropped, 13_001 - slamlab::sim::LOG_SENSOR_CAP);
    assert_eq!(r.log.sensors.back().unwrap().step, 13_000);
    assert_eq!(r.truth, r.spec.start_pose());
}

#[wasm_bindgen_test(unsupported = test)]
fn camera_capture_and_mapping_do_not_change_the_run() {
    // The switches the tests above use must not change what they test.
    let mut s = Scenario::from_json(PRESETS[0].1).unwrap();
    s.duration_s = 30.0;
    let mut full = Simulation::new(&s).unwrap();
    full.run_to_end();
    let mut bare = sim_of(&s);
    bare.run_to_end();
    for (a, b) in full.robots.iter().zip(&bare.robots) {
        assert_eq!(a.log.truth, b.log.truth);
        assert_eq!(a.log.odometry, b.log.odometry);
        assert_eq!(a.log.sensors, b.log.sensors);
        assert_eq!(a.frames.frames.len(), 31);
        // Only the frame taken at t = 0, when the simulation was built.
        assert_eq!(b.frames.frames.len(), 1);
    }
}

/// The follower's scan-cover test answers exactly as the arctangent it
/// replaces, on random points at every scale, on points a hair either side
/// of the 88° edge, on the axes and at the origin.
#[wasm_bindgen_test(unsupported = test)]
fn scan_cover_test_answers_as_the_arctangent() {
    use slamlab::follower::{outside_scan_cover, SCAN_COVER_RAD};
    let t = SCAN_COVER_RAD.tan();
    let atan = |q: DVec2| q.y.atan2(q.x).abs() > SCAN_COVER_RAD;
    let mut rng = Rng::new(88);
    let mut points = Vec::new();
    for _ in 0..100_000 {
        let scale = 10f64.powf(rng.range(-6.0, 2.0));
        points.push(DVec2::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)) * scale);
        // Near the edge: bearing 88° ± up to 1e-6 rad (decided from the
        // tangent) or ± 1e-12 rad (within the band left to the arctangent).
        let near = if rng.uniform() < 0.5 { 1e-6 } else { 1e-12 };
        let a = SCAN_COVER_RAD + rng.range(-near, near);
        let side = if rng.uniform() < 0.5 { 1.0 } else { -1.0 };
        points.push(DVec2::new(a.cos(), side * a.sin()) * rng.range(0.01, 3.0));
    }
    for (x, y) in [
        (0.0, 0.0),
        (-0.0, 0.0),
        (0.0, -0.0),
        (0.0, 1.0),
        (-1.0, 0.0),
        (1.0, 0.0),
        (1e-300, 1.0),
        (1.0, t),
        (1.0, -t),
    ] {
        points.push(DVec2::new(x, y));
    }
    let mut outside = 0;
    for q in points {
        assert_eq!(outside_scan_cover(q, t), atan(q), "{q:?}");
        outside += usize::from(atan(q));
    }
    // Both answers were exercised, and near the edge both ways.
    assert!(outside > 20_000 && outside < 180_000, "{outside}");
}

/// Beam unit vectors come from a table made once: the very numbers of the
/// cosine and sine of each beam's bearing.
#[wasm_bindgen_test(unsupported = test)]
fn beam_units_are_the_cosine_and_sine_of_the_bearings() {
    use slamlab::sensors::laser::{beam_bearing, beam_unit};
    use slamlab::sensors::LASER_BEAMS;
    for i in 0..LASER_BEAMS + 2 {
        let a = beam_bearing(i);
        assert_eq!(beam_unit(i), DVec2::new(a.cos(), a.sin()), "beam {i}");
    }
    assert_eq!(beam_unit(90), DVec2::new(1.0, 0.0));
}
