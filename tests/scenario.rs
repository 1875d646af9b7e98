//! The scenario file: defaults, presets, and every refusal naming its field.

use slamlab::scenario::{FollowSide, NoiseSpec, Scenario, SensorSpec};
use wasm_bindgen_test::wasm_bindgen_test;

const PRESETS: [(&str, &str); 4] = [
    ("thesis", include_str!("../scenarios/thesis.json")),
    ("office", include_str!("../scenarios/office.json")),
    ("loop", include_str!("../scenarios/loop.json")),
    ("maze", include_str!("../scenarios/maze.json")),
];

const MINIMAL: &str = r#"{"walls": [{"from": [0, 0], "to": [10, 0]}],
  "robots": [{"name": "r1", "start": [2, 2, 0], "follow": "left"}]}"#;

fn err(json: &str) -> String {
    match Scenario::from_json(json) {
        Ok(_) => panic!("accepted: {json}"),
        Err(e) => e.to_string(),
    }
}

fn with_robot(robot: &str) -> String {
    format!(r#"{{"walls": [{{"from": [0, 0], "to": [10, 0]}}], "robots": [{robot}]}}"#)
}

#[wasm_bindgen_test(unsupported = test)]
fn minimal_scenario_gets_documented_defaults() {
    let s = Scenario::from_json(MINIMAL).unwrap();
    assert_eq!(s.name, "untitled");
    assert_eq!(s.seed, 1);
    assert_eq!(s.duration_s, 300.0);
    assert_eq!(s.walls[0].texture, None);
    assert_eq!(s.robots[0].distance, 0.6);
    assert_eq!(s.robots[0].speed, 0.35);
    assert_eq!(s.robots[0].follow, FollowSide::Left);
    assert_eq!(s.noise, NoiseSpec::default());
    assert_eq!(s.sensors, SensorSpec::default());
    assert_eq!(s.sensors.laser_range_m, 4.0);
    assert_eq!(s.sensors.sonar_range_m, 2.0);
}

#[wasm_bindgen_test(unsupported = test)]
fn presets_parse_and_can_run() {
    for (name, text) in PRESETS {
        let s = Scenario::from_json(text).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(s.name, name);
        assert!(s.robots.len() >= 2, "{name}");
        assert!(s.placement_problems().is_empty(), "{name}");
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn thesis_preset_is_about_20_by_15_m_with_distant_differently_headed_starts() {
    let s = Scenario::from_json(PRESETS[0].1).unwrap();
    let (lo, hi) = s.bounds();
    let size = hi - lo;
    assert!(
        (18.0..=22.0).contains(&size.x) && (13.0..=17.0).contains(&size.y),
        "{size}"
    );
    let (a, b) = (s.robots[0].start_pose(), s.robots[1].start_pose());
    let rel = a.between(&b);
    assert!(rel.position().length() > 5.0, "{rel:?}");
    assert!(rel.theta.abs() > 0.5, "{rel:?}");
    assert_eq!(s.robots[0].follow, FollowSide::Left);
    assert_eq!(s.robots[1].follow, FollowSide::Right);
}

#[wasm_bindgen_test(unsupported = test)]
fn round_trip_through_json_keeps_everything() {
    for (_, text) in PRESETS {
        let s = Scenario::from_json(text).unwrap();
        let again = Scenario::from_json(&s.to_json_pretty()).unwrap();
        assert_eq!(s, again);
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn unknown_keys_are_refused_by_name() {
    let e = err(
        r#"{"walls": [], "robots": [{"name": "a", "start": [0,0,0], "follow": "left"}], "colour": 1}"#,
    );
    assert!(e.starts_with("colour: unknown key"), "{e}");
    let e = err(&with_robot(
        r#"{"name": "a", "start": [2,2,0], "follow": "left", "sped": 1}"#,
    ));
    assert!(e.starts_with("robots[0].sped: unknown key"), "{e}");
    let e = err(r#"{"walls": [{"from": [0,0], "to": [1,0], "colour": "red"}], "robots": []}"#);
    assert!(e.starts_with("walls[0].colour: unknown key"), "{e}");
    let e = err(&format!(r#"{{"noise": {{"slip": 0.1}}, {}"#, &MINIMAL[1..]));
    assert!(e.starts_with("noise.slip: unknown key"), "{e}");
}

#[wasm_bindgen_test(unsupported = test)]
fn non_finite_and_mistyped_numbers_are_refused_by_field() {
    // JSON has no NaN; a page's NaN arrives as null.
    let e = err(&with_robot(
        r#"{"name": "a", "start": [2, null, 0], "follow": "left"}"#,
    ));
    assert_eq!(e, "robots[0].start[1]: expected a number, found null");
    let e = err(&with_robot(
        r#"{"name": "a", "start": [2, 2], "follow": "left"}"#,
    ));
    assert!(
        e.starts_with("robots[0].start: expected [x, y, theta] (3 numbers)"),
        "{e}"
    );
    let e = err(r#"{"walls": [{"from": [0, 1e400], "to": [1, 0]}], "robots": []}"#);
    assert!(e.contains("out of range"), "{e}");
    let e = err(r#"{"walls": [{"from": [0, 0], "to": [1, "x"]}], "robots": []}"#);
    assert_eq!(e, "walls[0].to[1]: expected a number, found a string");
    let e = err(&format!(r#"{{"duration_s": -5, {}"#, &MINIMAL[1..]));
    assert!(e.starts_with("duration_s: -5 is outside"), "{e}");
    let e = err(&format!(r#"{{"seed": 1.5, {}"#, &MINIMAL[1..]));
    assert!(e.starts_with("seed: "), "{e}");
}

#[wasm_bindgen_test(unsupported = test)]
fn zero_length_walls_are_refused() {
    let e = err(
        r#"{"walls": [{"from": [0,0], "to": [5,0]}, {"from": [3,3], "to": [3,3]}],
        "robots": [{"name": "a", "start": [2,2,0], "follow": "left"}]}"#,
    );
    assert_eq!(e, "walls[1]: zero-length wall (from equals to)");
}

#[wasm_bindgen_test(unsupported = test)]
fn robots_inside_or_touching_walls_are_refused() {
    // Body half-width 0.1905: centre 0.15 from the wall overlaps it.
    let e = err(&with_robot(
        r#"{"name": "a", "start": [5, 0.15, 0], "follow": "left"}"#,
    ));
    assert_eq!(
        e,
        "robots[0].start: robot 'a' starts inside or touching walls[0]"
    );
    // Exactly touching: half-width 0.1905 above the wall when turned 0.
    let e = err(&with_robot(
        r#"{"name": "a", "start": [5, 0.1905, 0], "follow": "left"}"#,
    ));
    assert!(e.starts_with("robots[0].start"), "{e}");
    // A wall wholly inside the body.
    let e = err(r#"{"walls": [{"from": [5, 5], "to": [5.1, 5]}],
        "robots": [{"name": "a", "start": [5, 5, 0], "follow": "left"}]}"#);
    assert!(e.starts_with("robots[0].start"), "{e}");
    // Clear by 1 cm is fine; turned 90°, the half-length 0.2275 counts.
    assert!(Scenario::from_json(&with_robot(
        r#"{"name": "a", "start": [5, 0.2005, 0], "follow": "left"}"#
    ))
    .is_ok());
    let turned = with_robot(r#"{"name": "a", "start": [5, 0.2005, 1.5707963], "follow": "left"}"#);
    assert!(Scenario::from_json(&turned).is_err());
}

#[wasm_bindgen_test(unsupported = test)]
fn overlapping_robots_are_refused() {
    let e = err(&with_robot(
        r#"{"name": "a", "start": [5, 2, 0], "follow": "left"}, {"name": "b", "start": [5.3, 2, 0], "follow": "right"}"#,
    ));
    assert_eq!(e, "robots[1].start: robot 'b' overlaps robot 'a'");
}

#[wasm_bindgen_test(unsupported = test)]
fn duplicate_robot_names_are_refused() {
    let e = err(&with_robot(
        r#"{"name": "a", "start": [2, 2, 0], "follow": "left"}, {"name": "a", "start": [6, 2, 0], "follow": "right"}"#,
    ));
    assert_eq!(e, "robots[1].name: duplicate robot name 'a'");
}

#[wasm_bindgen_test(unsupported = test)]
fn more_than_16_robots_are_refused() {
    let robots: Vec<String> = (0..17)
        .map(|i| {
            format!(
                r#"{{"name": "r{i}", "start": [{}, 3, 0], "follow": "left"}}"#,
                1 + i
            )
        })
        .collect();
    let e = err(&with_robot(&robots.join(",")));
    assert_eq!(e, "robots: 17 robots, at most 16 allowed");
    // 16 is fine.
    assert!(Scenario::from_json(&with_robot(&robots[..16].join(","))).is_ok());
}

#[wasm_bindgen_test(unsupported = test)]
fn more_than_10000_walls_are_refused() {
    let walls: Vec<String> = (0..10_001)
        .map(|i| format!(r#"{{"from": [{i}, 20], "to": [{i}, 21]}}"#))
        .collect();
    let json = format!(
        r#"{{"walls": [{}], "robots": [{{"name": "a", "start": [0.5, 2, 0], "follow": "left"}}]}}"#,
        walls.join(",")
    );
    assert_eq!(err(&json), "walls: 10001 walls, at most 10000 allowed");
}

#[wasm_bindgen_test(unsupported = test)]
fn other_shape_errors_name_their_field() {
    assert_eq!(err(r#"{"robots": []}"#), "walls: is required");
    assert_eq!(err(r#"{"walls": []}"#), "robots: is required");
    assert_eq!(
        err(r#"{"walls": [], "robots": []}"#),
        "robots: at least one robot is required"
    );
    let e = err(&with_robot(
        r#"{"name": "a", "start": [2, 2, 0], "follow": "up"}"#,
    ));
    assert_eq!(
        e,
        r#"robots[0].follow: expected "left" or "right", found "up""#
    );
    let e = err(&with_robot(
        r#"{"name": "a", "start": [2, 2, 0], "follow": "left", "distance": 3}"#,
    ));
    assert!(e.starts_with("robots[0].distance: 3 is outside"), "{e}");
    let e = err(&with_robot(r#"{"start": [2, 2, 0], "follow": "left"}"#));
    assert_eq!(e, "robots[0].name: is required");
    assert!(err("[1, 2]").starts_with("scenario: expected an object"));
    assert!(err("{not json").starts_with("not valid JSON"));
}
