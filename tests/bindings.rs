//! The wasm-bindgen boundary, exercised in node: errors arrive as
//! exceptions with messages, never as panics, and nothing is lost.
#![cfg(target_arch = "wasm32")]

use slamlab::bindings::{simd_enabled, validate_scenario, Lab};
use wasm_bindgen::JsValue;
use wasm_bindgen_test::wasm_bindgen_test;

const THESIS: &str = include_str!("../scenarios/thesis.json");

fn message(e: wasm_bindgen::JsError) -> String {
    let v: JsValue = e.into();
    js_sys::Error::from(v).message().into()
}

#[wasm_bindgen_test]
fn lab_runs_steps_and_reports_through_the_binding() {
    let mut lab = Lab::new(THESIS).unwrap();
    assert_eq!(lab.step(25).unwrap(), 25);
    assert!((lab.time_s() - 2.5).abs() < 1e-9);
    let state: serde_json::Value = serde_json::from_str(&lab.state_json().unwrap()).unwrap();
    assert_eq!(state["robots"].as_array().unwrap().len(), 2);
    assert_eq!(state["robots"][0]["sonar_m"].as_array().unwrap().len(), 8);
    let report: serde_json::Value = serde_json::from_str(&lab.report_json("{}").unwrap()).unwrap();
    assert_eq!(report["robots"][0]["truth"].as_array().unwrap().len(), 26);
    assert_eq!(
        report["robots"][1]["odometry"][0],
        serde_json::json!([0.0, 0.0, 0.0, 0.0])
    );
    let rgba = lab.render_rgba().unwrap();
    assert_eq!(rgba.len(), 960 * 720 * 4);
    let csv = lab.log_csv(1).unwrap();
    assert_eq!(csv.lines().count(), 27);
    assert_eq!(
        csv.lines().next().unwrap().split(',').count(),
        4 + 8 + 181 + 3
    );
}

#[wasm_bindgen_test]
fn bad_input_throws_a_message_and_keeps_the_scenario() {
    let mut lab = Lab::new(THESIS).unwrap();
    let before = lab.scenario_json();
    let e = lab.set_scenario(
        r#"{"walls": [], "robots": [{"name": "a", "start": [0, 0], "follow": "left"}]}"#,
    );
    assert!(message(e.unwrap_err()).starts_with("robots[0].start: expected [x, y, theta]"));
    assert_eq!(lab.scenario_json(), before, "a failed edit loses nothing");
    assert!(message(lab.set_seed(-1.0).unwrap_err()).starts_with("seed:"));
    assert!(message(lab.set_seed(f64::NAN).unwrap_err()).starts_with("seed:"));
    assert!(message(lab.set_duration(f64::INFINITY).unwrap_err()).starts_with("duration_s:"));
    assert!(message(lab.set_view("{\"width\": -1}").unwrap_err()).starts_with("view:"));
    assert!(message(lab.set_view("{\"zoom\": 2}").unwrap_err()).contains("unknown field"));
    assert!(message(lab.report_json("{}").unwrap_err()).contains("run the scenario first"));
    assert!(message(lab.log_csv(5).unwrap_err()).contains("nothing has run"));
    lab.step(1).unwrap();
    assert!(message(lab.log_csv(5).unwrap_err()).contains("no robot with index 5"));
    assert!(message(Lab::new("nonsense").err().unwrap()).starts_with("not valid JSON"));
}

#[wasm_bindgen_test]
fn badly_placed_robots_are_kept_for_editing_but_refuse_to_run() {
    let json = r#"{"walls": [{"from": [0, 0], "to": [10, 0]}],
        "robots": [{"name": "a", "start": [5, 0.1, 0], "follow": "left"}]}"#;
    let mut lab = Lab::new(json).unwrap();
    let problems: serde_json::Value = serde_json::from_str(&lab.problems_json()).unwrap();
    assert_eq!(problems[0]["field"], "robots[0].start");
    assert!(
        message(lab.step(1).unwrap_err()).starts_with("robots[0].start: robot 'a' starts inside")
    );
    assert!(message(validate_scenario(json).unwrap_err()).starts_with("robots[0].start"));
}

#[wasm_bindgen_test]
fn simd_flag_matches_the_build() {
    assert_eq!(simd_enabled(), cfg!(target_feature = "simd128"));
}

#[wasm_bindgen_test]
fn camera_frames_cross_the_boundary() {
    let mut lab = Lab::new(THESIS).unwrap();
    // Before a run: a live view from the start pose, no frames yet.
    assert_eq!(lab.camera_gray(0).unwrap().len(), 320 * 240);
    assert_eq!(lab.frame_count(0).unwrap(), 0);
    lab.step(20).unwrap();
    assert_eq!(lab.frame_count(1).unwrap(), 3, "t = 0, 1, 2 s");
    let frames: serde_json::Value = serde_json::from_str(&lab.frames_json(1).unwrap()).unwrap();
    assert_eq!(frames[2]["time_s"], 2.0);
    assert_eq!(frames[0]["odometry"], serde_json::json!([0.0, 0.0, 0.0]));
    let png = lab.frame_png(1, 2).unwrap();
    let img = image::load_from_memory(&png).unwrap().to_luma8();
    assert_eq!(img.as_raw(), &lab.frame_gray(1, 2).unwrap());
    assert!(message(lab.frame_png(1, 99).unwrap_err()).contains("has no frame 99"));
    assert!(message(lab.camera_gray(7).unwrap_err()).contains("no robot with index 7"));
    assert!(message(lab.add_image_texture("x", b"junk").unwrap_err()).contains("not a PNG or JPEG"));
    lab.add_image_texture("poster", &png).unwrap();
}
