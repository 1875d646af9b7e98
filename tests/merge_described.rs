//! Frames described by a second lab of the same scenario, as the command
//! line's worker threads do (`slamlab::merge::described_ahead`): the features come
//! out bit for bit the same, cross the boundary exactly, and a merge that
//! takes them (or pictures rendered there and described here) reports what a
//! merge computing everything itself reports.

use slamlab::lab::Lab;
use slamlab::maze::{random_maze, MazeSpec};
use slamlab::merge::config::MergeConfig;
use slamlab::merge::described_ahead::{decode, encode, PACKED_LEN};
use slamlab::merge::frames::strongest_features;
use slamlab::merge::MergeMethod;
use slamlab::surf::GrayImage;
use wasm_bindgen_test::wasm_bindgen_test;

fn scenario(duration_s: f64) -> String {
    random_maze(&MazeSpec {
        seed: 3,
        duration_s,
        ..MazeSpec::default()
    })
}

fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// A merge's view as JSON without its wall-clock timings.
fn view_without_timings(lab: &Lab) -> serde_json::Value {
    fn strip(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(m) => {
                m.remove("timings_ms");
                m.values_mut().for_each(strip);
            }
            serde_json::Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    let mut v = serde_json::to_value(lab.merge_view().expect("view")).expect("json");
    strip(&mut v);
    v
}

#[wasm_bindgen_test(unsupported = test)]
fn packed_features_round_trip_exactly_and_bad_arrays_are_refused() {
    let mut lab = Lab::new(&scenario(20.0)).expect("lab");
    lab.run_to_end().expect("runs");
    let frame = lab.frames(0).expect("frames")[3].clone();
    let img = lab.frame_image(&frame).expect("renders");
    let img = GrayImage::new(img.width as usize, img.height as usize, img.gray).expect("image");
    let config = MergeConfig::new(MergeMethod::Auto, 3);
    let f = strongest_features(&img, &config.surf, config.max_keypoints);
    assert!(f.len() > 20, "a textured frame has keypoints: {}", f.len());
    let packed = encode(&f);
    assert_eq!(packed.len(), 1 + f.len() * PACKED_LEN);
    let back = decode(&packed).expect("decodes");
    assert_eq!(back.keypoints, f.keypoints);
    assert_eq!(back.descriptors, f.descriptors);
    assert!(decode(&[0.0]).expect("no keypoints").is_empty());

    let refused = |data: &[f32], says: &str| {
        let e = decode(data).expect_err("refused");
        assert!(e.contains(says), "'{e}' should mention '{says}'");
    };
    refused(&[], "empty");
    refused(&packed[..packed.len() - 1], "expected 70 per keypoint");
    refused(&[-1.0], "count of -1");
    refused(&[0.5], "count of 0.5");
    let mut sign = packed.clone();
    sign[1 + 4] = 0.0;
    refused(&sign, "laplacian sign 0");
    let mut nan = packed.clone();
    nan[1 + 10] = f32::NAN;
    refused(&nan, "not a finite number");
}

#[wasm_bindgen_test(unsupported = test)]
fn a_second_lab_describes_the_first_labs_frames_bit_for_bit() {
    let json = scenario(60.0);
    let mut a = Lab::new(&json).expect("lab");
    assert!(a.frames_to_describe(MergeMethod::Auto).is_empty(), "no run");
    a.run_to_end().expect("runs");
    let mut b = Lab::new(&json).expect("second lab");
    let todo = a.frames_to_describe(MergeMethod::Auto);
    assert!(todo.len() >= 10, "{} frames to describe", todo.len());
    assert!(todo.iter().any(|&(r, _)| r == 1), "both robots' frames");
    let config = MergeConfig::new(MergeMethod::Auto, 3);
    for &(robot, index) in todo.iter().step_by(4) {
        let spec = a.frame_spec(robot, index).expect("spec");
        let there = b
            .describe_frame_spec(&spec, MergeMethod::Auto)
            .expect("describes");
        let frame = a.frame(robot, index).expect("frame").clone();
        let img = a.frame_image(&frame).expect("renders");
        // Rendering alone gives the frame's own pixels, byte for byte.
        let rendered = b.render_frame_spec(&spec).expect("renders there");
        assert_eq!(rendered.gray, img.gray, "robot {robot} frame {index}");
        let img = GrayImage::new(img.width as usize, img.height as usize, img.gray).expect("img");
        let here = strongest_features(&img, &config.surf, config.max_keypoints);
        assert_eq!(
            bits(&encode(&there)),
            bits(&encode(&here)),
            "robot {robot} frame {index}"
        );
    }
    // Describing other labs' frames leaves the second lab's own run at 0.
    assert_eq!(b.state().steps, 0);
    assert!(a.frame_spec(0, 1_000_000).is_err());
    assert!(a
        .store_described(7, 0, MergeMethod::Auto, Default::default())
        .is_err());
    // Pixels of the wrong size, or of a frame that does not exist, are
    // refused with a message.
    let (robot, index) = todo[0];
    let e = a
        .describe_rendered(robot, index, MergeMethod::Auto, vec![0; 100])
        .expect_err("wrong size");
    assert!(e.contains("100 grey bytes for a 320 x 240 camera"), "{e}");
    let e = a
        .describe_rendered(robot, 1_000_000, MergeMethod::Auto, vec![0; 320 * 240])
        .expect_err("no such frame");
    assert!(e.contains("has no frame 1000000"), "{e}");
}

#[wasm_bindgen_test(unsupported = test)]
fn a_merge_that_takes_described_frames_reports_the_same() {
    let json = scenario(120.0);
    let mut alone = Lab::new(&json).expect("lab");
    alone.run_to_end().expect("runs");
    alone.merge_start(MergeMethod::Auto).expect("starts");
    alone.merge_finish().expect("merges");

    let mut helped = Lab::new(&json).expect("lab");
    let mut helper = Lab::new(&json).expect("helper");
    // Hand frames over while the run goes on, as the command line does:
    // the helper describes every other one, and only renders the rest for
    // this lab to describe (as after the run).
    let mut handed = 0;
    while !helped.state().finished {
        helped.step(200).expect("steps");
        for (robot, index) in helped.frames_to_describe(MergeMethod::Auto) {
            let spec = helped.frame_spec(robot, index).expect("spec");
            if handed % 2 == 0 {
                let f = helper
                    .describe_frame_spec(&spec, MergeMethod::Auto)
                    .expect("describes");
                helped
                    .store_described(robot, index, MergeMethod::Auto, f)
                    .expect("stores");
            } else {
                let img = helper.render_frame_spec(&spec).expect("renders");
                helped
                    .describe_rendered(robot, index, MergeMethod::Auto, img.gray)
                    .expect("describes here");
            }
            handed += 1;
        }
    }
    assert!(helped.frames_to_describe(MergeMethod::Auto).is_empty());
    let needed: usize = {
        let p = alone.merge_view().expect("view");
        p.robots.iter().map(|r| r.frames.len()).sum()
    };
    assert_eq!(handed, needed, "every frame the merge describes, once");
    helped.merge_start(MergeMethod::Auto).expect("starts");
    helped.merge_finish().expect("merges");
    let (x, y) = (view_without_timings(&alone), view_without_timings(&helped));
    assert!(x["report"].is_object(), "a verdict");
    assert_eq!(x, y);
    // A new run starts with nothing described.
    helped.reset();
    helped.step(300).expect("steps");
    assert!(!helped.frames_to_describe(MergeMethod::Auto).is_empty());
}

/// Issue 22: the frame store thins its frames when its budget is full, also
/// frames listed, handed out and being described elsewhere. What comes back
/// for a thinned frame is dropped cleanly (and said so), and the merge,
/// which asks only for frames the store holds, reports what a merge
/// describing everything itself reports.
#[wasm_bindgen_test(unsupported = test)]
fn frames_thinned_while_out_are_dropped_and_the_merge_reports_the_same() {
    let json = scenario(120.0);
    // Room for 20 frames a robot (two robots): a frame a second thins
    // several times in 120 s.
    let budget = 40 * slamlab::camera::capture::FRAME_BYTES;
    let mut alone = Lab::new(&json).expect("lab");
    alone.set_frame_budget(budget);
    alone.run_to_end().expect("runs");
    alone.merge_start(MergeMethod::Auto).expect("starts");
    alone.merge_finish().expect("merges");
    let held = alone.frames(0).expect("frames").len();
    assert!(held <= 20, "{held} frames kept within the budget");

    let mut helped = Lab::new(&json).expect("lab");
    helped.set_frame_budget(budget);
    let mut helper = Lab::new(&json).expect("helper");
    // Features described as frames are listed and handed back only at the
    // end, as a slow worker might: meanwhile the store thins most of them.
    let mut out = Vec::new();
    let (mut kept, mut refused) = (0, 0);
    loop {
        let finished = helped.state().finished;
        let back = if finished { out.len() } else { 0 };
        for (robot, index, f) in out.drain(..back) {
            let stored = helped
                .store_described(robot, index, MergeMethod::Auto, f)
                .expect("a frame that was captured");
            assert_eq!(stored, helped.has_frame(robot, index));
            if stored {
                kept += 1;
            } else {
                refused += 1;
            }
        }
        if finished {
            break;
        }
        helped.step(150).expect("steps");
        for (robot, index) in helped.frames_to_describe(MergeMethod::Auto) {
            assert!(
                helped.has_frame(robot, index),
                "only held frames are listed"
            );
            let spec = helped.frame_spec(robot, index).expect("spec");
            let f = helper
                .describe_frame_spec(&spec, MergeMethod::Auto)
                .expect("describes");
            out.push((robot, index, f));
        }
    }
    assert!(
        refused > 0,
        "some frames were thinned while out ({kept} kept)"
    );
    assert!(kept > 0, "{refused} refused, none kept");
    // A thinned frame is gone for the pixels path too, and for its spec.
    let r = helped.state().robots.len();
    let gone = (0..r)
        .flat_map(|robot| (0..50).map(move |i| (robot, i)))
        .find(|&(robot, i)| !helped.has_frame(robot, i))
        .expect("a thinned frame");
    assert_eq!(
        helped.describe_rendered(gone.0, gone.1, MergeMethod::Auto, vec![0; 320 * 240]),
        Ok(false)
    );
    assert!(helped.frame_spec(gone.0, gone.1).is_err());
    helped.merge_start(MergeMethod::Auto).expect("starts");
    helped.merge_finish().expect("merges");
    let (x, y) = (view_without_timings(&alone), view_without_timings(&helped));
    assert!(x["report"].is_object(), "a verdict");
    assert_eq!(x, y);
}

/// The frame budget charges each frame the features a merge may keep of it
/// (`camera::capture::FEATURE_BYTES`): as many bytes as the merge's most
/// keypoints take with their descriptors.
#[wasm_bindgen_test(unsupported = test)]
fn the_frame_budget_charges_what_a_merge_keeps_of_a_frame() {
    let config = MergeConfig::new(MergeMethod::Auto, 1);
    let per_keypoint = std::mem::size_of::<slamlab::surf::Keypoint>()
        + std::mem::size_of::<slamlab::surf::Descriptor>();
    assert_eq!(per_keypoint, 280);
    assert_eq!(
        config.max_keypoints * per_keypoint,
        slamlab::camera::capture::FEATURE_BYTES
    );
}
