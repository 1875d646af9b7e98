//! The thesis's merging method (selection §6.2.2, distance §6.2.4, merge
//! §6.2.5) and the map-only baseline: the equations on hand-built
//! geometry, selection on synthetic frames, the whole method on camera
//! images rendered from a known layout, and full simulated runs.
//!
//! Ground truth appears here only to score.

mod slam_support;

use glam::DVec2;
use slamlab::camera::PinholeCamera;
use slamlab::geom::{wrap_angle, Pose2};
use slamlab::merge::baseline::{grid_picture, map_only_merge, BaselineConfig};
use slamlab::merge::pinhole::{
    solve_distance, thesis_merge, thesis_merge_with, PairMatch, ThesisConfig, ThesisOutcome,
};
use slamlab::merge::selection::{front_wall, is_square, select_frames, SelectionConfig};
use slamlab::merge::{FrameInfo, MergeStatus};
use slamlab::scenario::{CameraSpec, Scenario};
use slamlab::sensors::laser::beam_bearing;
use slamlab::sensors::{LaserScan, LASER_BEAMS, SONAR_COUNT};
use slamlab::sim::Simulation;
use slamlab::slam::{GridConfig, OccupancyGrid};
use slamlab::surf::{
    extract, fit_homography, match_features, GrayImage, MatchConfig, MatchedRegion, MsacConfig,
    SurfConfig,
};
use std::sync::OnceLock;
use wasm_bindgen_test::wasm_bindgen_test;

const TAN_30: f64 = 0.577_350_269_189_625_8;

// ---------------------------------------------------------------------
// §6.2.4: the two equations
// ---------------------------------------------------------------------

#[wasm_bindgen_test(unsupported = test)]
fn solve_distance_recovers_k_and_ad_from_a_constructed_geometry() {
    // 60° camera, 320 px: f = 160 / tan 30° = 277.128 px. Robot 1 stands
    // 2.0 m from the wall; robot 2 at D is 1.6 m away (AD = 0.4) and at E
    // 1.1 m (DE = 0.5). In robot 1's pixels robot 2's views are
    // FJ = 320 · 1.6 / 2.0 = 256 and GH = 320 · 1.1 / 2.0 = 176, and one
    // pixel is K = 2.0 / 277.128 = 0.0072169 m of wall.
    let s = solve_distance(60f64.to_radians(), 320.0, 256.0, 176.0, 0.5).expect("solvable");
    // K = 2 · 0.5 · tan 30° / (256 − 176) = 0.57735 / 80.
    assert!(
        (s.k_m_per_px - TAN_30 / 80.0).abs() < 1e-12,
        "K {}",
        s.k_m_per_px
    );
    assert!((s.k_m_per_px - 2.0 / (160.0 / TAN_30)).abs() < 1e-12);
    // AD = 0.5 · (320 − 256) / 80 = 0.4.
    assert!((s.ad_m - 0.4).abs() < 1e-12, "AD {}", s.ad_m);
    assert!((s.depth_a_m - 2.0).abs() < 1e-12, "K·f {}", s.depth_a_m);
    assert!((s.tan_half_fov - TAN_30).abs() < 1e-12);
    // Both equations hold.
    assert!((TAN_30 * s.ad_m - (160.0 - 128.0) * s.k_m_per_px).abs() < 1e-12);
    assert!((TAN_30 * (s.ad_m + 0.5) - (160.0 - 88.0) * s.k_m_per_px).abs() < 1e-12);
}

#[wasm_bindgen_test(unsupported = test)]
fn solve_distance_handles_robot_2_farther_from_the_wall_and_backing_away() {
    // Robot 1 at 1.2 m; D at 1.5 m (AD = −0.3), E at 1.9 m (DE = −0.4):
    // FJ = 320 · 1.5 / 1.2 = 400, GH = 320 · 1.9 / 1.2 = 506.667.
    let gh = 320.0 * 1.9 / 1.2;
    let s = solve_distance(60f64.to_radians(), 320.0, 400.0, gh, -0.4).expect("solvable");
    assert!((s.ad_m + 0.3).abs() < 1e-9, "AD {}", s.ad_m);
    assert!((s.depth_a_m - 1.2).abs() < 1e-9, "K·f {}", s.depth_a_m);
}

#[wasm_bindgen_test(unsupported = test)]
fn solve_distance_refuses_degenerate_inputs() {
    let fov = 60f64.to_radians();
    let bad = [
        (fov, 320.0, 256.0, 176.0, 0.0, "DE"),
        (fov, 320.0, 200.0, 200.0, 0.5, "FJ = GH"),
        (0.0, 320.0, 256.0, 176.0, 0.5, "field of view"),
        (
            std::f64::consts::PI,
            320.0,
            256.0,
            176.0,
            0.5,
            "field of view",
        ),
        (fov, 320.0, f64::NAN, 176.0, 0.5, "finite"),
        (fov, 320.0, 256.0, f64::INFINITY, 0.5, "finite"),
        (fov, 320.0, -256.0, 176.0, 0.5, "positive"),
        (fov, 0.0, 256.0, 176.0, 0.5, "positive"),
        // E nearer the wall (DE > 0) yet its view is wider: K < 0.
        (fov, 320.0, 176.0, 256.0, 0.5, "not positive"),
    ];
    for (f, bc, fj, gh, de, why) in bad {
        let r = solve_distance(f, bc, fj, gh, de);
        match r {
            Err(e) => assert!(e.contains(why), "{why}: got '{e}'"),
            Ok(s) => panic!("{why}: expected an error, got {s:?}"),
        }
    }
}

// ---------------------------------------------------------------------
// §6.2.2: selection
// ---------------------------------------------------------------------

/// A frame with both forward sonars reading `s4`, `s5`, at `(x, y)`
/// heading north, and the laser seeing nothing.
fn frame(index: usize, x: f64, y: f64, s4: f32, s5: f32, turn_rad: f64) -> FrameInfo {
    let mut sonar_m = [2.0f32; SONAR_COUNT];
    sonar_m[3] = s4;
    sonar_m[4] = s5;
    FrameInfo {
        index,
        step: index * 10,
        pose: Pose2::new(x, y, std::f64::consts::FRAC_PI_2),
        odometry: Pose2::new(x, y, std::f64::consts::FRAC_PI_2),
        turn_rad,
        sonar_m,
        laser_mm: [u16::MAX; LASER_BEAMS],
    }
}

/// Laser ranges (mm) of a straight wall at perpendicular distance `d`
/// whose normal lies at `skew` (rad, counter-clockwise) from the heading.
fn wall_scan(d: f64, skew: f64) -> [u16; LASER_BEAMS] {
    let mut out = [u16::MAX; LASER_BEAMS];
    for (k, o) in out.iter_mut().enumerate() {
        let c = (beam_bearing(k) - skew).cos();
        if c > 0.2 && d / c <= 4.0 {
            *o = (d / c * 1000.0).round() as u16;
        }
    }
    out
}

#[wasm_bindgen_test(unsupported = test)]
fn a_frame_is_square_when_sonars_4_and_5_agree_on_a_wall_and_the_robot_is_not_turning() {
    let cfg = SelectionConfig::default();
    assert!(is_square(&frame(0, 0.0, 0.0, 1.20, 1.22, 0.0), &cfg));
    assert!(is_square(&frame(0, 0.0, 0.0, 1.20, 1.25, -0.02), &cfg));
    // Sonars disagree by 10 cm: the wall ahead is oblique.
    assert!(!is_square(&frame(0, 0.0, 0.0, 1.20, 1.30, 0.0), &cfg));
    // Both read their 2 m maximum: they agree on seeing nothing.
    assert!(!is_square(&frame(0, 0.0, 0.0, 2.0, 2.0, 0.0), &cfg));
    // Turning at 0.12 rad a step, as around a corner.
    assert!(!is_square(&frame(0, 0.0, 0.0, 1.20, 1.20, 0.12), &cfg));
    // Nose to the wall.
    assert!(!is_square(&frame(0, 0.0, 0.0, 0.2, 0.2, 0.0), &cfg));
    // Garbage never counts.
    assert!(!is_square(
        &frame(0, 0.0, 0.0, f32::NAN, f32::NAN, 0.0),
        &cfg
    ));
    assert!(!is_square(&frame(0, 0.0, 0.0, 1.2, 1.2, f64::NAN), &cfg));
}

#[wasm_bindgen_test(unsupported = test)]
fn the_laser_fit_measures_the_skew_the_sonars_cannot_see() {
    // A wall 1.5 m away turned 8°: the sonars (10° either side, 15° cones)
    // differ by under 3 cm, within their tolerance, but the laser line fit
    // sees 8°.
    let mut f = frame(0, 0.0, 0.0, 1.33, 1.35, 0.0);
    f.laser_mm = wall_scan(1.5, 8f64.to_radians());
    let w = front_wall(&f).expect("a wall ahead");
    assert!(
        (w.distance_m - 1.5).abs() < 0.002,
        "distance {}",
        w.distance_m
    );
    assert!(
        (w.skew_rad.to_degrees() - 8.0).abs() < 0.1,
        "skew {}",
        w.skew_rad.to_degrees()
    );
    assert!(is_square(&f, &SelectionConfig::default()));
    let strict = SelectionConfig {
        max_wall_skew_rad: Some(3f64.to_radians()),
        ..SelectionConfig::default()
    };
    assert!(!is_square(&f, &strict));
    f.laser_mm = wall_scan(1.5, -1f64.to_radians());
    assert!(is_square(&f, &strict));
    // Something in front of the wall at the edge of the fan is trimmed,
    // not averaged in: beams 12° to 20° left end 0.9 m away.
    let mut scan = wall_scan(1.5, 0.0);
    for r in scan.iter_mut().take(111).skip(102) {
        *r = 900;
    }
    f.laser_mm = scan;
    let w = front_wall(&f).expect("a wall ahead");
    assert!(
        w.skew_rad.abs() < 0.1f64.to_radians(),
        "skew {}",
        w.skew_rad.to_degrees()
    );
    assert_eq!(w.points, 41 - 9);
    // No returns: no wall.
    f.laser_mm = [u16::MAX; LASER_BEAMS];
    assert!(front_wall(&f).is_none());
}

#[wasm_bindgen_test(unsupported = test)]
fn selection_keeps_the_squarest_of_each_close_group() {
    // Along one line: (x, |s4 − s5|). Visited squarest first: #3 (0.00)
    // kept; #1 (0.01) is 0.25 m from #3: dropped; #4 (0.02) 0.15 m from #3:
    // dropped; #0 (0.03) 0.35 m from #3: kept; #5 (0.04) kept; #2 (0.05)
    // 0.15 m from #3: dropped. #6 is not square.
    let spots = [
        (0.0, 0.03),
        (0.1, 0.01),
        (0.2, 0.05),
        (0.35, 0.0),
        (0.5, 0.02),
        (1.0, 0.04),
    ];
    let mut frames: Vec<FrameInfo> = spots
        .iter()
        .enumerate()
        .map(|(i, &(x, d))| frame(i, x, 3.0, 1.0, 1.0 + d as f32, 0.0))
        .collect();
    frames.push(frame(6, 2.0, 3.0, 1.0, 1.5, 0.0));
    let cfg = SelectionConfig {
        min_separation_m: 0.3,
        ..SelectionConfig::default()
    };
    assert_eq!(select_frames(&frames, &cfg), vec![0, 3, 5]);
    // With no thinning every square frame is kept, in order.
    let all = SelectionConfig {
        min_separation_m: 0.0,
        ..cfg.clone()
    };
    assert_eq!(select_frames(&frames, &all), vec![0, 1, 2, 3, 4, 5]);
    assert!(select_frames(&[], &cfg).is_empty());
}

// ---------------------------------------------------------------------
// §6.2.4–6.2.5 on exact pictures of a known layout
// ---------------------------------------------------------------------

fn camera() -> PinholeCamera {
    PinholeCamera::new(&CameraSpec::default())
}

/// Where a point (x, y, z) of the world lands in the image of a camera
/// at `pose` (keypoint pixels: (0, 0) the centre of the top-left pixel).
fn project(cam: &PinholeCamera, pose: &Pose2, p: [f64; 3]) -> Option<[f64; 2]> {
    let local = pose.inverse_transform_point(DVec2::new(p[0], p[1]));
    if local.x <= 0.05 {
        return None;
    }
    let u = cam.width as f64 / 2.0 - cam.f_px * local.y / local.x - 0.5;
    let v = cam.height as f64 / 2.0 - cam.f_px * (p[2] - cam.mount_height_m) / local.x - 0.5;
    let inside =
        (-0.5..cam.width as f64 - 0.5).contains(&u) && (-0.5..cam.height as f64 - 0.5).contains(&v);
    inside.then_some([u, v])
}

/// The table row two cameras looking at the wall y = `wall_y` give: the
/// homography from exact correspondences on the wall, as MSAC finds it.
fn exact_row(
    cam: &PinholeCamera,
    a: (usize, &Pose2),
    b: (usize, &Pose2),
    wall_y: f64,
    inliers: usize,
) -> PairMatch {
    let (mut p1, mut p2) = (Vec::new(), Vec::new());
    for i in 0..60 {
        for j in 0..12 {
            let w = [-2.0 + 0.1 * i as f64, wall_y, 0.1 + 0.2 * j as f64];
            if let (Some(x1), Some(x2)) = (project(cam, a.1, w), project(cam, b.1, w)) {
                p1.push(x1);
                p2.push(x2);
            }
        }
    }
    let fit = fit_homography(&p1, &p2, &MsacConfig::default()).expect("views overlap");
    let size = (cam.width as usize, cam.height as usize);
    PairMatch {
        a: a.0,
        b: b.0,
        inliers,
        homography: Some(fit.model),
        quad: MatchedRegion::new(&fit.model, size, size).map(|r| r.quad),
    }
}

/// What a robot whose map frame starts at `start` knows at world pose
/// `world` facing the wall y = `wall_y`: its pose in its map frame and a
/// laser scan of the wall.
fn known_frame(index: usize, start: &Pose2, world: &Pose2, wall_y: f64) -> FrameInfo {
    let depth = wall_y - world.y;
    let skew = wrap_angle(std::f64::consts::FRAC_PI_2 - world.theta);
    let mut f = frame(index, 0.0, 0.0, 1.0, 1.0, 0.0);
    f.pose = start.between(world);
    f.odometry = f.pose;
    f.laser_mm = wall_scan(depth, skew);
    f
}

fn pose_error(got: &Pose2, want: &Pose2) -> (f64, f64) {
    (
        (got.position() - want.position()).length(),
        wrap_angle(got.theta - want.theta).to_degrees().abs(),
    )
}

struct Layout {
    start_a: Pose2,
    start_b: Pose2,
    a: Pose2,
    d: Pose2,
    e: Pose2,
}

fn layout(skew_a_deg: f64) -> Layout {
    let north = std::f64::consts::FRAC_PI_2;
    Layout {
        start_a: Pose2::new(-3.0, -6.0, 0.3),
        start_b: Pose2::new(8.0, 2.0, -2.5),
        // Robot 1 2.0 m from the wall y = 5; robot 2 0.5 m to its right,
        // at 1.6 m (D) and 1.1 m (E).
        a: Pose2::new(1.0, 3.0, north + skew_a_deg.to_radians()),
        d: Pose2::new(1.5, 3.4, north),
        e: Pose2::new(1.5, 3.9, north),
    }
}

fn merge_layout(l: &Layout, cfg: &ThesisConfig) -> ThesisOutcome {
    let cam = camera();
    let a = [known_frame(3, &l.start_a, &l.a, 5.0)];
    let b = [
        known_frame(0, &l.start_b, &Pose2::new(-4.0, 0.0, 0.0), 5.0),
        known_frame(10, &l.start_b, &l.d, 5.0),
        known_frame(11, &l.start_b, &l.e, 5.0),
    ];
    let table = vec![
        exact_row(&cam, (0, &l.a), (1, &l.d), 5.0, 120),
        exact_row(&cam, (0, &l.a), (2, &l.e), 5.0, 90),
        // A weak row that must not be used.
        PairMatch {
            a: 0,
            b: 0,
            inliers: 9,
            homography: None,
            quad: None,
        },
    ];
    thesis_merge_with(&cam, &a, &b, &table, cfg)
}

#[wasm_bindgen_test(unsupported = test)]
fn thesis_merge_recovers_the_relative_transform_from_exact_pictures() {
    let l = layout(0.0);
    let out = merge_layout(&l, &ThesisConfig::default());
    assert_eq!(out.status, MergeStatus::Merged, "{}", out.reason);
    assert_eq!((out.best, out.second), (Some((0, 1)), Some((0, 2))));
    assert!(!out.swapped);
    let d = out.distance.as_ref().expect("the numbers of §6.2.4");
    // FJ = 320 · 1.6 / 2.0 = 256, GH = 320 · 1.1 / 2.0 = 176, DE = 0.5.
    assert!((d.fj_px - 256.0).abs() < 0.5, "FJ {}", d.fj_px);
    assert!((d.gh_px - 176.0).abs() < 0.5, "GH {}", d.gh_px);
    assert!((d.de_m - 0.5).abs() < 1e-9, "DE {}", d.de_m);
    assert!((d.ad_m - 0.4).abs() < 0.01, "AD {}", d.ad_m);
    assert!((d.depth_a_m - 2.0).abs() < 0.01, "K·f {}", d.depth_a_m);
    // Robot 2 stood 0.5 m to robot 1's right: its view centre lands
    // f · 0.5 / 2.0 = 69.3 px right of robot 1's.
    assert!(
        (d.shift_px - camera().f_px * 0.25).abs() < 0.5,
        "shift {}",
        d.shift_px
    );
    assert!((d.aa_m + 0.5).abs() < 0.01, "AA' {}", d.aa_m);
    let truth = l.start_a.inverse().compose(&l.start_b);
    let (dm, ddeg) = pose_error(&out.pose.expect("a pose"), &truth);
    assert!(dm < 0.02 && ddeg < 0.1, "error {dm:.4} m {ddeg:.3}°");
    assert!(out.confidence > 0.8, "confidence {}", out.confidence);
}

#[wasm_bindgen_test(unsupported = test)]
fn the_laser_skew_correction_removes_the_rotation_the_thesis_assumes_away() {
    // Robot 1 is 3° off square. The thesis's arithmetic (both square, so
    // the maps differ by the difference of the headings) is then 3° off;
    // with the skews its laser and robot 2's measured, the pose is exact.
    let l = layout(3.0);
    let truth = l.start_a.inverse().compose(&l.start_b);
    let corrected = merge_layout(&l, &ThesisConfig::default());
    let (dm, ddeg) = pose_error(&corrected.pose.expect("a pose"), &truth);
    assert!(dm < 0.05 && ddeg < 0.2, "corrected: {dm:.3} m {ddeg:.2}°");
    let d = corrected.distance.expect("numbers");
    assert!((d.skew_a_rad.expect("measured").to_degrees() + 3.0).abs() < 0.2);
    let as_written = merge_layout(
        &l,
        &ThesisConfig {
            correct_skew: false,
            ..ThesisConfig::default()
        },
    );
    let (_, ddeg) = pose_error(&as_written.pose.expect("a pose"), &truth);
    assert!((ddeg - 3.0).abs() < 0.2, "as written: {ddeg:.2}°");
}

#[wasm_bindgen_test(unsupported = test)]
fn the_roles_swap_when_robot_a_gives_the_two_frames() {
    // Robot A at D and E, robot B once at A': the table is transposed.
    let l = layout(0.0);
    let cam = camera();
    let a = [
        known_frame(0, &l.start_a, &l.d, 5.0),
        known_frame(1, &l.start_a, &l.e, 5.0),
    ];
    let b = [known_frame(0, &l.start_b, &l.a, 5.0)];
    let table = vec![
        exact_row(&cam, (0, &l.d), (0, &l.a), 5.0, 120),
        exact_row(&cam, (1, &l.e), (0, &l.a), 5.0, 90),
    ];
    let out = thesis_merge(&cam, &a, &b, &table);
    assert_eq!(out.status, MergeStatus::Merged, "{}", out.reason);
    assert!(out.swapped);
    assert_eq!((out.best, out.second), (Some((0, 0)), Some((1, 0))));
    let truth = l.start_a.inverse().compose(&l.start_b);
    let (dm, ddeg) = pose_error(&out.pose.expect("a pose"), &truth);
    assert!(dm < 0.02 && ddeg < 0.1, "error {dm:.4} m {ddeg:.3}°");
}

#[wasm_bindgen_test(unsupported = test)]
fn thesis_merge_says_why_when_it_cannot_merge() {
    let l = layout(0.0);
    let cam = camera();
    let a = [known_frame(3, &l.start_a, &l.a, 5.0)];
    let b = [known_frame(10, &l.start_b, &l.d, 5.0)];
    // Nothing selected.
    let out = thesis_merge(&cam, &[], &b, &[]);
    assert_eq!(out.status, MergeStatus::NoMerge);
    assert!(out.reason.contains("selection kept 0"), "{}", out.reason);
    // Only weak pairs.
    let weak = PairMatch {
        a: 0,
        b: 0,
        inliers: 7,
        homography: None,
        quad: None,
    };
    let out = thesis_merge(&cam, &a, &b, std::slice::from_ref(&weak));
    assert_eq!(out.status, MergeStatus::NoMerge);
    assert!(out.reason.contains("the best has 7"), "{}", out.reason);
    // One good pair but no second frame of either robot.
    let one = exact_row(&cam, (0, &l.a), (0, &l.d), 5.0, 100);
    let out = thesis_merge(&cam, &a, &b, std::slice::from_ref(&one));
    assert_eq!(out.status, MergeStatus::NoMerge);
    assert!(
        out.reason.contains("same line of approach"),
        "{}",
        out.reason
    );
    assert!(out.pose.is_none() && out.confidence == 0.0);
    // Garbage geometry and indices outside the frames never panic.
    let junk = [
        PairMatch {
            a: 0,
            b: 0,
            inliers: 500,
            homography: Some(slamlab::surf::Homography([[0.0; 3]; 3])),
            quad: None,
        },
        PairMatch {
            a: 0,
            b: 0,
            inliers: 400,
            homography: None,
            quad: Some([[f64::NAN, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]),
        },
        PairMatch {
            a: 0,
            b: 0,
            inliers: 300,
            homography: None,
            quad: Some([[0.0, 0.0]; 4]),
        },
        PairMatch {
            a: 0,
            b: 0,
            inliers: 200,
            // A mirror image.
            homography: Some(slamlab::surf::Homography([
                [-1.0, 0.0, 319.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ])),
            quad: None,
        },
        PairMatch {
            a: 5,
            b: 9,
            inliers: 900,
            homography: one.homography,
            quad: one.quad,
        },
    ];
    let out = thesis_merge(&cam, &a, &b, &junk);
    assert_eq!(out.status, MergeStatus::NoMerge, "{}", out.reason);
    assert!(!out.reason.is_empty());
}

// ---------------------------------------------------------------------
// The whole method on simulated runs
// ---------------------------------------------------------------------

/// A finished run and the thesis's method on it.
struct ThesisRun {
    sim: Simulation,
    selected: [usize; 2],
    pairs: usize,
    outcome: ThesisOutcome,
}

/// Runs a scenario and the thesis's method on it, end to end: selection,
/// upright SURF on every selected frame, every pair matched (ratio test,
/// MSAC homography: the thesis's Table 1), then §6.2.4–6.2.5.
fn run_thesis(json: &str) -> ThesisRun {
    let scenario = Scenario::parse(json).expect("scenario parses");
    let mut sim = Simulation::new(&scenario).expect("scenario runs");
    sim.run_to_end();
    let surf = SurfConfig {
        upright: true,
        ..SurfConfig::default()
    };
    let cfg = SelectionConfig::default();
    let mut infos = Vec::new();
    let mut features = Vec::new();
    for i in 0..2 {
        let all = slamlab::merge::frames::frame_infos(&sim, i);
        let keep = select_frames(&all, &cfg);
        let frames = &sim.robots[i].frames.frames;
        features.push(
            keep.iter()
                .map(|&k| {
                    let f = sim.frame_image(&frames[k]);
                    let img = GrayImage::new(f.width as usize, f.height as usize, f.gray)
                        .expect("frame size");
                    extract(&img, &surf)
                })
                .collect::<Vec<_>>(),
        );
        infos.push(keep.iter().map(|&k| all[k].clone()).collect::<Vec<_>>());
    }
    let cam = &sim.camera;
    let size = (cam.width as usize, cam.height as usize);
    let mut table = Vec::new();
    for (a, fa) in features[0].iter().enumerate() {
        for (b, fb) in features[1].iter().enumerate() {
            let m = match_features(fa, fb, &MatchConfig::default());
            let key = |k: &slamlab::surf::Keypoint| [k.x as f64, k.y as f64];
            let p1: Vec<[f64; 2]> = m.iter().map(|m| key(&fa.keypoints[m.query])).collect();
            let p2: Vec<[f64; 2]> = m.iter().map(|m| key(&fb.keypoints[m.train])).collect();
            let fit = fit_homography(&p1, &p2, &MsacConfig::default());
            let homography = fit.as_ref().map(|f| f.model);
            table.push(PairMatch {
                a,
                b,
                inliers: fit.map_or(0, |f| f.inliers.len()),
                homography,
                quad: homography
                    .and_then(|h| MatchedRegion::new(&h, size, size))
                    .map(|r| r.quad),
            });
        }
    }
    let outcome = thesis_merge(cam, &infos[0], &infos[1], &table);
    ThesisRun {
        selected: [infos[0].len(), infos[1].len()],
        pairs: table.len(),
        sim,
        outcome,
    }
}

fn truth_transform(sim: &Simulation) -> Pose2 {
    let (a, b) = (
        sim.robots[0].spec.start_pose(),
        sim.robots[1].spec.start_pose(),
    );
    a.inverse().compose(&b)
}

/// The thesis preset with its "maps" wall moved back from x = 8 to x = 13
/// (the layout of earlier versions): the 2 m alcove at the posters wall is
/// gone, and with it the one wall both robots face squarely.
fn no_alcove_variant() -> String {
    let json = slam_support::PRESETS[0].1;
    let mut v: serde_json::Value = serde_json::from_str(json).expect("preset is JSON");
    let walls = v["walls"].as_array_mut().expect("walls");
    let maps = walls
        .iter_mut()
        .find(|w| w["texture"] == "maps")
        .expect("the maps wall");
    assert_eq!(maps["from"], serde_json::json!([8, 15]), "the preset moved");
    maps["from"] = serde_json::json!([13, 15]);
    maps["to"] = serde_json::json!([13, 11]);
    v.to_string()
}

fn thesis_preset_run() -> &'static ThesisRun {
    static RUN: OnceLock<ThesisRun> = OnceLock::new();
    RUN.get_or_init(|| run_thesis(slam_support::PRESETS[0].1))
}

#[wasm_bindgen_test(unsupported = test)]
fn thesis_method_merges_when_both_robots_face_one_wall_squarely() {
    // On the preset the marble and maps walls close a 2 m alcove onto the
    // posters wall, which the left follower enters along the marble wall
    // and the right follower along the maps wall, both facing the posters
    // squarely about 0.55 m apart: the situation of the thesis's Figure 18.
    let run = thesis_preset_run();
    let o = &run.outcome;
    println!(
        "thesis: selected {:?}, {} pairs, {:?}: {}",
        run.selected, run.pairs, o.status, o.reason
    );
    assert_eq!(o.status, MergeStatus::Merged, "{}", o.reason);
    let truth = truth_transform(&run.sim);
    let (dm, ddeg) = pose_error(&o.pose.expect("a pose"), &truth);
    println!(
        "thesis: error {dm:.3} m {ddeg:.2}°, confidence {:.2}",
        o.confidence
    );
    // Wasm's maths library differs from the native one in the last bit,
    // which changes the robots' paths after a minute or so; the native run
    // is held to the target, the wasm one to a looser bound.
    let limit_m = if cfg!(target_arch = "wasm32") {
        0.6
    } else {
        0.3
    };
    assert!(dm <= limit_m && ddeg <= 3.0, "error {dm:.3} m {ddeg:.2}°");
    let d = o.distance.as_ref().expect("numbers");
    if let Some(l) = d.laser_depth_a_m {
        assert!(
            (d.depth_a_m - l).abs() < 0.3 * l,
            "K·f {} laser {l}",
            d.depth_a_m
        );
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn thesis_method_declines_a_layout_where_no_wall_is_faced_by_both() {
    // Without the alcove a left and a right wall follower meet every inside
    // corner along different walls, so whenever one faces a wall squarely
    // the other faces the neighbouring one; where both face the posters
    // wall, the marble and maps walls stand between them. The method's
    // assumption never holds, and it must say so rather than merge.
    let run = run_thesis(&no_alcove_variant());
    let o = &run.outcome;
    println!(
        "no alcove: selected {:?}, {} pairs, {:?}: {}",
        run.selected, run.pairs, o.status, o.reason
    );
    assert!(
        run.selected[0] >= 10 && run.selected[1] >= 10,
        "{:?}",
        run.selected
    );
    assert_eq!(o.status, MergeStatus::NoMerge, "{}", o.reason);
    assert!(o.pose.is_none() && !o.reason.is_empty());
}

// ---------------------------------------------------------------------
// The map-only baseline
// ---------------------------------------------------------------------

/// Robot `i`'s scans from the log, integrated at `transform ⊕ estimate`
/// into a fresh grid: the robot's SLAM map, moved by `transform`.
fn rebuilt_map(sim: &Simulation, i: usize, transform: &Pose2) -> OccupancyGrid {
    let r = &sim.robots[i];
    let range_max = sim.scenario.sensors.laser_range_m;
    let mut grid = OccupancyGrid::new(GridConfig::default());
    for row in &r.log.sensors {
        let Some(pose) = r.mapping.estimates().get(row.step) else {
            continue;
        };
        let scan = LaserScan {
            ranges_m: row
                .laser_mm
                .iter()
                .map(|&mm| {
                    if mm == u16::MAX {
                        range_max
                    } else {
                        mm as f64 / 1000.0
                    }
                })
                .collect(),
            max_range: row.laser_mm.iter().map(|&mm| mm == u16::MAX).collect(),
            reflective: vec![false; LASER_BEAMS],
            range_max_m: range_max,
        };
        grid.integrate_scan(&transform.compose(pose), &scan);
    }
    grid
}

#[wasm_bindgen_test(unsupported = test)]
fn baseline_recovers_a_copy_of_a_map_turned_by_right_angles() {
    // The presets start their robots at right angles to each other, and so
    // do the copies asserted here, shifted by whole cells. Off the cell
    // grid, or at other angles, the walls are drawn differently in the two
    // pictures and the baseline's matches thin out: those copies are only
    // printed.
    let sim = &thesis_preset_run().sim;
    let a = rebuilt_map(sim, 0, &Pose2::IDENTITY);
    let copies = [
        Pose2::new(3.0, -2.0, std::f64::consts::FRAC_PI_2),
        Pose2::new(-6.5, 4.0, std::f64::consts::PI),
        Pose2::new(-6.53, 4.01, -std::f64::consts::FRAC_PI_2),
        Pose2::new(1.5, 0.5, 0.3),
    ];
    for (i, truth) in copies.iter().enumerate() {
        // Map B is map A seen from a frame whose pose in A is `truth`.
        let b = rebuilt_map(sim, 0, &truth.inverse());
        let out = map_only_merge(&a, &b, &BaselineConfig::default(), 11 + i as u64);
        let error = out.pose.map(|p| pose_error(&p, truth));
        println!(
            "copy turned {:.2} rad: {:?} {} error {error:?}",
            truth.theta, out.status, out.reason
        );
        if i >= 2 {
            continue;
        }
        assert_eq!(out.status, MergeStatus::Merged, "{}", out.reason);
        let (dm, ddeg) = error.expect("a pose");
        assert!(
            dm < 0.1 && ddeg < 0.5,
            "copy {i}: error {dm:.3} m {ddeg:.2}°"
        );
        assert!(out.confidence >= 1.0 && out.inliers <= out.matches);
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn baseline_on_the_two_robots_maps_reports_what_it_finds() {
    // Whatever it concludes on the preset, it is a complete answer: a pose
    // with a confidence at or above the threshold, or a reason.
    let sim = &thesis_preset_run().sim;
    let (a, b) = (
        &sim.robots[0].mapping.slam_map,
        &sim.robots[1].mapping.slam_map,
    );
    let out = map_only_merge(a, b, &BaselineConfig::default(), 7);
    let truth = truth_transform(sim);
    match out.pose {
        Some(p) => {
            let (dm, ddeg) = pose_error(&p, &truth);
            println!(
                "baseline on the thesis preset: {:?}, error {dm:.2} m {ddeg:.1}°: {}",
                out.status, out.reason
            );
            assert_eq!(out.status, MergeStatus::Merged);
            assert!(out.confidence >= 1.0 && p.is_finite());
        }
        None => {
            println!("baseline on the thesis preset: no merge: {}", out.reason);
            assert_eq!(out.status, MergeStatus::NoMerge);
            assert!(!out.reason.is_empty());
        }
    }
    assert!(out.inliers <= out.matches);
}

#[wasm_bindgen_test(unsupported = test)]
fn baseline_never_panics_on_empty_or_featureless_maps() {
    let empty = OccupancyGrid::new(GridConfig::default());
    let out = map_only_merge(&empty, &empty, &BaselineConfig::default(), 1);
    assert_eq!(out.status, MergeStatus::NoMerge);
    assert!(out.reason.contains("empty"), "{}", out.reason);
    // A single straight wall: no corners, nothing to lock onto.
    let mut wall = OccupancyGrid::new(GridConfig::default());
    let scan = LaserScan {
        ranges_m: (0..LASER_BEAMS)
            .map(|k| (1.0 / beam_bearing(k).cos().max(0.25)).min(4.0))
            .collect(),
        max_range: (0..LASER_BEAMS)
            .map(|k| beam_bearing(k).cos() < 0.25)
            .collect(),
        reflective: vec![false; LASER_BEAMS],
        range_max_m: 4.0,
    };
    for _ in 0..5 {
        wall.integrate_scan(&Pose2::IDENTITY, &scan);
    }
    let pic = grid_picture(&wall, 16).expect("known cells");
    assert!(pic.image.width() > 32 && pic.image.height() > 16);
    let out = map_only_merge(&wall, &empty, &BaselineConfig::default(), 1);
    assert_eq!(out.status, MergeStatus::NoMerge);
    let out = map_only_merge(&wall, &wall, &BaselineConfig::default(), 1);
    assert!(out.pose.is_none_or(|p| p.is_finite()), "{}", out.reason);
}

#[wasm_bindgen_test(unsupported = test)]
fn grid_pictures_put_map_y_up_and_image_rows_down() {
    // One occupied cell at map (0.31, 0.81), cell (6, 16): after cropping, it must come
    // back from its pixel as the same point.
    let mut g = OccupancyGrid::new(GridConfig::default());
    assert!(g.ensure_contains(DVec2::new(-1.0, -1.0), DVec2::new(1.0, 1.0)));
    for _ in 0..4 {
        g.integrate_beam(DVec2::new(0.31, 0.01), DVec2::new(0.31, 0.81), true);
    }
    let pic = grid_picture(&g, 2).expect("known cells");
    let px = pic.image.pixels();
    let w = pic.image.width();
    let dark: Vec<(usize, usize)> = (0..px.len())
        .filter(|&i| px[i] == 0)
        .map(|i| (i % w, i / w))
        .collect();
    assert_eq!(dark.len(), 1, "one occupied cell");
    let (u, v) = dark[0];
    // The wall cell is the top of the picture's known part (y grows up).
    assert_eq!(v, 2, "margin rows above the top cell");
    let p = pic.pixel_to_map(u as f64, v as f64);
    assert!((p - DVec2::new(0.325, 0.825)).length() < 1e-9, "{p}");
    // The free cells of the beam lie below it in the picture.
    assert_eq!(px[(v + 3) * w + u], 255);
}
