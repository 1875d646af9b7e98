//! The automatic map merge, part by part: lifting keypoints with the laser,
//! the rigid MSAC, place recognition, the pairwise-consistency test, grid
//! alignment, the verdict, fusion and the spanning tree; then the product's
//! whole automatic merge (`MergeJob`) on simulated runs, scored against the
//! truth (which only this test reads).

use glam::DVec2;
use slamlab::camera::texture::TextureBank;
use slamlab::camera::{render, PinholeCamera};
use slamlab::geom::{wrap_angle, Pose2, Segment};
use slamlab::merge::align::{refine_alignment, AlignConfig};
use slamlab::merge::consistency::{
    independent_places, max_consistent_places, max_consistent_set, pairwise_consistent,
    ConsistencyConfig,
};
use slamlab::merge::frames::MergeInput;
use slamlab::merge::fuse::{fuse, FuseSteps};
use slamlab::merge::graph::{groups, spanning_tree, PairEdge};
use slamlab::merge::job::{MergeConfig, MergeJob, Stage};
use slamlab::merge::lift::{column_bearing_rad, laser_range_at, lift_keypoint_3d};
use slamlab::merge::mapsearch::{dominant_rotation, search_maps, MapSearchConfig};
use slamlab::merge::rigid::{fit_rigid_least_squares, fit_rigid_msac, RigidConfig};
use slamlab::merge::verdict::{
    decide_pair, map_agreement, PairDecision, SearchSummary, VerdictConfig, VerdictSteps,
};
use slamlab::merge::vocabulary::{propose_pairs, similarity, Vocabulary, VocabularyConfig};
use slamlab::merge::{Candidate, FrameInfo, MergeMethod, MergeStatus};
use slamlab::rng::Rng;
use slamlab::scenario::{CameraSpec, Scenario, WallSpec};
use slamlab::sensors::laser::{beam_bearing, LASER_BEAMS};
use slamlab::sensors::sonar::SONAR_COUNT;
use slamlab::sim::Simulation;
use slamlab::slam::grid::{CellState, GridConfig, OccupancyGrid};
use slamlab::slam::MapperKind;
use slamlab::surf::{extract, Features, GrayImage, SurfConfig};
use slamlab::world::World;
use std::f64::consts::PI;
use wasm_bindgen_test::wasm_bindgen_test;

fn camera() -> PinholeCamera {
    PinholeCamera::new(&CameraSpec::default())
}

/// A frame taken at `pose` with the given laser ranges (m; `None`: no
/// return).
fn frame_with_ranges(pose: Pose2, range: impl Fn(f64) -> Option<f64>) -> FrameInfo {
    let mut laser_mm = [u16::MAX; LASER_BEAMS];
    for (k, mm) in laser_mm.iter_mut().enumerate() {
        if let Some(r) = range(beam_bearing(k)) {
            *mm = (r * 1000.0).round() as u16;
        }
    }
    FrameInfo {
        index: 0,
        step: 0,
        pose,
        odometry: pose,
        turn_rad: 0.0,
        sonar_m: [0.0; SONAR_COUNT],
        laser_mm,
    }
}

/// A flat wall `d` metres ahead of the robot, across its heading.
fn facing_wall(pose: Pose2, d: f64) -> FrameInfo {
    frame_with_ranges(pose, |b| {
        let r = d / b.cos();
        (b.cos() > 0.05 && r < 4.0).then_some(r)
    })
}

// ----- lift -----------------------------------------------------------------

#[wasm_bindgen_test(unsupported = test)]
fn column_bearing_follows_the_pinhole_and_opencv_pixel_centres() {
    let cam = camera();
    // 320 px over 60°: f = 160 / tan 30° = 277.13 px; the optical axis is
    // at u = 160, i.e. between SURF columns 159 and 160 (x = 159.5).
    assert!((cam.f_px - 277.128).abs() < 1e-3);
    assert!(column_bearing_rad(&cam, 159.5).abs() < 1e-12);
    // The left edge of the image (u = 0, x = -0.5) is 30° to the left.
    assert!((column_bearing_rad(&cam, -0.5) - 30f64.to_radians()).abs() < 1e-12);
    assert!((column_bearing_rad(&cam, 319.5) + 30f64.to_radians()).abs() < 1e-12);
    // x = 239.5: u = 240, 80 px right of centre: atan(80 / 277.13) = 16.10° right.
    let b = column_bearing_rad(&cam, 239.5);
    assert!((b.to_degrees() + 16.102).abs() < 1e-3, "{}", b.to_degrees());
}

#[wasm_bindgen_test(unsupported = test)]
fn laser_range_interpolates_between_beams_and_refuses_gaps_and_edges() {
    let mut mm = [2000u16; LASER_BEAMS];
    mm[91] = 2100; // +1°
    mm[92] = 2100;
    // Halfway between beam 90 (0°) and beam 91 (1°).
    let r = laser_range_at(&mm, 0.5f64.to_radians()).expect("range");
    assert!((r - 2.05).abs() < 1e-9, "{r}");
    // Exactly on a beam.
    assert!((laser_range_at(&mm, 0.0).expect("range") - 2.0).abs() < 1e-9);
    // No return on either side of the bearing.
    mm[100] = u16::MAX;
    assert_eq!(laser_range_at(&mm, 9.5f64.to_radians()), None);
    assert_eq!(laser_range_at(&mm, 10.5f64.to_radians()), None);
    // A wall's end in front of a far wall: 2.0 m then 3.5 m.
    for m in mm.iter_mut().skip(121) {
        *m = 3500;
    }
    assert_eq!(laser_range_at(&mm, 30.5f64.to_radians()), None);
    // One beam further from the jump the neighbours are still too close to it.
    assert_eq!(laser_range_at(&mm, 29.5f64.to_radians()), None);
    assert!(laser_range_at(&mm, 27.5f64.to_radians()).is_some());
    // Outside the half-plane the laser sweeps.
    assert_eq!(
        laser_range_at(&[2000; LASER_BEAMS], 91f64.to_radians()),
        None
    );
    assert_eq!(laser_range_at(&[2000; LASER_BEAMS], f64::NAN), None);
}

#[wasm_bindgen_test(unsupported = test)]
fn lifted_keypoints_land_on_the_wall_in_the_map_frame() {
    let cam = camera();
    // Robot at (1, 2) facing +y (90°), a flat wall 2 m ahead: the wall is
    // the line y = 4 of the map frame.
    let pose = Pose2::new(1.0, 2.0, PI / 2.0);
    let frame = facing_wall(pose, 2.0);
    let lift =
        |frame: &FrameInfo, x: f64| lift_keypoint_3d(&cam, frame, x, 119.5).map(|p| p.truncate());
    let centre = lift(&frame, 159.5).expect("lifts");
    assert!((centre - DVec2::new(1.0, 4.0)).length() < 1e-9, "{centre}");
    // 80 px right of centre: X/Z = 80/f, so the point is 2·80/f = 0.577 m to
    // the robot's right, which is +x in the map. Interpolating 1/cos between
    // beams costs well under a millimetre.
    let right = lift(&frame, 239.5).expect("lifts");
    assert!((right.y - 4.0).abs() < 1e-3, "{right}");
    assert!(
        (right.x - (1.0 + 2.0 * 80.0 / cam.f_px)).abs() < 1e-3,
        "{right}"
    );
    // Height on the wall from the row: the horizon row (v = 120, y = 119.5)
    // is the camera's height, 0.4 m; 50 px higher is 0.4 + 50·Z/f.
    let p = lift_keypoint_3d(&cam, &frame, 159.5, 119.5).expect("lifts");
    assert!((p.z - 0.4).abs() < 1e-9);
    let p = lift_keypoint_3d(&cam, &frame, 159.5, 69.5).expect("lifts");
    assert!(
        (p.z - (0.4 + 50.0 * 2.0 / cam.f_px)).abs() < 1e-9,
        "{}",
        p.z
    );
    // Where the laser saw nothing, nothing lifts.
    let empty = frame_with_ranges(pose, |_| None);
    assert_eq!(lift(&empty, 159.5), None);
}

// ----- rigid ----------------------------------------------------------------

#[wasm_bindgen_test(unsupported = test)]
fn rigid_least_squares_is_exact_on_noise_free_points() {
    let truth = Pose2::new(3.0, -1.5, 0.7);
    let b = [
        DVec2::new(0.0, 0.0),
        DVec2::new(2.0, 0.5),
        DVec2::new(-1.0, 3.0),
    ];
    let a: Vec<DVec2> = b.iter().map(|&p| truth.transform_point(p)).collect();
    let fit = fit_rigid_least_squares(&a, &b).expect("fits");
    assert!((fit.x - 3.0).abs() < 1e-12 && (fit.y + 1.5).abs() < 1e-12);
    assert!((fit.theta - 0.7).abs() < 1e-12);
    // Coincident points fix no angle.
    let same = [DVec2::new(1.0, 1.0); 3];
    assert_eq!(fit_rigid_least_squares(&same, &same), None);
    assert_eq!(fit_rigid_least_squares(&[], &[]), None);
}

#[wasm_bindgen_test(unsupported = test)]
fn rigid_msac_recovers_a_known_transform_with_40_percent_outliers() {
    let truth = Pose2::new(-4.2, 7.5, 2.4);
    let mut rng = Rng::new(11);
    let n = 50;
    let b: Vec<DVec2> = (0..n)
        .map(|_| DVec2::new(rng.range(-3.0, 3.0), rng.range(-2.0, 2.0)))
        .collect();
    let mut a: Vec<DVec2> = b
        .iter()
        .map(|&p| truth.transform_point(p) + DVec2::new(rng.normal(0.01), rng.normal(0.01)))
        .collect();
    // 20 of 50 (40 %) are wrong matches: anywhere within 5 m.
    for p in a.iter_mut().take(20) {
        *p = DVec2::new(rng.range(-9.0, 1.0), rng.range(2.5, 12.5));
    }
    let fit = fit_rigid_msac(&a, &b, &RigidConfig::default(), 7).expect("fits");
    assert!((fit.pose.x - truth.x).abs() < 0.01, "{:?}", fit.pose);
    assert!((fit.pose.y - truth.y).abs() < 0.01, "{:?}", fit.pose);
    assert!(wrap_angle(fit.pose.theta - truth.theta).abs() < 0.3f64.to_radians());
    // Every true match is an inlier, and an outlier only by bad luck (a
    // random point within 8 cm of its partner's true place).
    assert!((20..50).all(|i| fit.inliers.contains(&i)));
    assert!(fit.inliers.iter().filter(|&&i| i < 20).count() <= 1);
    assert!(fit.rms_m < 0.025, "rms {}", fit.rms_m);
    // The same seed gives the same fit.
    assert_eq!(
        fit_rigid_msac(&a, &b, &RigidConfig::default(), 7),
        Some(fit)
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn rigid_msac_refuses_degenerate_and_too_small_sets() {
    let cfg = RigidConfig::default();
    // All points within a few centimetres: no angle can be read.
    let b: Vec<DVec2> = (0..20)
        .map(|i| DVec2::new(0.01 * (i % 4) as f64, 0.01 * (i / 4) as f64))
        .collect();
    assert_eq!(fit_rigid_msac(&b, &b, &cfg, 1), None);
    // Too few pairs, mismatched lengths, non-finite input.
    assert_eq!(fit_rigid_msac(&b[..3], &b[..3], &cfg, 1), None);
    assert_eq!(fit_rigid_msac(&[], &[], &cfg, 1), None);
    let mut bad: Vec<DVec2> = (0..10).map(|i| DVec2::new(i as f64, 0.0)).collect();
    bad[3] = DVec2::new(f64::NAN, 0.0);
    assert_eq!(fit_rigid_msac(&bad, &bad, &cfg, 1), None);
}

// ----- vocabulary -----------------------------------------------------------

fn wall(a: [f64; 2], b: [f64; 2], texture: &str) -> WallSpec {
    WallSpec {
        from: a,
        to: b,
        texture: Some(texture.into()),
    }
}

fn upright() -> SurfConfig {
    SurfConfig {
        upright: true,
        ..SurfConfig::default()
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn vocabulary_ranks_the_true_pair_first_among_frames_of_different_textures() {
    // A 12 m × 12 m room, each wall its own style; robot A looks at each
    // wall from 3 m, robot B from 3.6 m, 0.5 m aside and turned 8°.
    let walls = vec![
        wall([0.0, 0.0], [12.0, 0.0], "posters"),
        wall([12.0, 0.0], [12.0, 12.0], "signs"),
        wall([12.0, 12.0], [0.0, 12.0], "graffiti"),
        wall([0.0, 12.0], [0.0, 0.0], "wood"),
    ];
    let world = World::new(walls.iter().map(|w| w.segment()).collect());
    let mut bank = TextureBank::new(3, 2.5);
    let cam = camera();
    let centre = DVec2::new(6.0, 6.0);
    let shot = |bank: &mut TextureBank, pose: Pose2| {
        let img = render(&cam, &pose, &world, &walls, &[], bank, false, None);
        let gray =
            GrayImage::new(img.width as usize, img.height as usize, img.gray).expect("image");
        extract(&gray, &upright())
    };
    let mut fa = Vec::new();
    let mut fb = Vec::new();
    for k in 0..4 {
        // Facing wall k: headings -90°, 0°, 90°, 180°.
        let heading = -PI / 2.0 + k as f64 * PI / 2.0;
        let dir = DVec2::from_angle(heading);
        let a = centre + dir * 3.0;
        let b = centre + dir * 2.4 + dir.perp() * 0.5;
        fa.push(shot(&mut bank, Pose2::new(a.x, a.y, heading)));
        fb.push(shot(
            &mut bank,
            Pose2::new(b.x, b.y, heading + 8f64.to_radians()),
        ));
    }
    for f in fa.iter().chain(&fb) {
        assert!(f.len() > 50, "textured walls give keypoints: {}", f.len());
    }
    let sets: Vec<&Features> = fa.iter().chain(&fb).collect();
    let (vocab, bags) = Vocabulary::train_with_bags(&sets, &VocabularyConfig::default(), 5);
    assert!(vocab.len() > 100, "{} words", vocab.len());
    // The bags from training are the bags `bag` gives.
    assert_eq!(bags[1], vocab.bag(&fa[1]));
    let (ba, bb) = (&bags[..4], &bags[4..]);
    for (i, bag) in ba.iter().enumerate() {
        let scores: Vec<f64> = bb.iter().map(|b| similarity(bag, b)).collect();
        let best = (0..4)
            .max_by(|&x, &y| scores[x].total_cmp(&scores[y]))
            .unwrap_or(9);
        assert_eq!(best, i, "frame {i}: {scores:?}");
    }
    // Proposals, best first: the four true pairs lead.
    let props = propose_pairs(ba, bb, 1, 10);
    let mut first: Vec<(usize, usize)> = props.iter().take(4).map(|p| (p.0, p.1)).collect();
    first.sort_unstable();
    assert_eq!(first, vec![(0, 0), (1, 1), (2, 2), (3, 3)], "{props:?}");
    assert!(props.windows(2).all(|w| w[0].2 >= w[1].2));
    // Nothing in common, nothing proposed.
    let empty = vocab.bag(&Features::default());
    assert!(empty.is_empty());
    assert!(propose_pairs(std::slice::from_ref(&empty), bb, 3, 10).is_empty());
    assert_eq!(similarity(&empty, &bb[0]), 0.0);
}

// ----- consistency ----------------------------------------------------------

fn candidate(truth: &Pose2, place_b: DVec2, frame: usize) -> Candidate {
    Candidate {
        a_frame: frame,
        b_frame: frame,
        pose: *truth,
        inliers: 30,
        rms_m: 0.02,
        place_a: truth.transform_point(place_b),
        place_b,
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn pairwise_consistency_tolerates_more_between_distant_places() {
    let cfg = ConsistencyConfig::default();
    let truth = Pose2::new(5.0, 2.0, 0.5);
    let c1 = candidate(&truth, DVec2::new(0.0, 0.0), 1);
    // The same place, transform shifted 0.35 m: more than the 0.25 m allowed.
    let mut c2 = candidate(&truth, DVec2::new(0.5, 0.0), 2);
    c2.pose.x += 0.35;
    assert!(!pairwise_consistent(&c1, &c2, &cfg));
    // 10 m apart, the same shift is within 0.25 + 0.04·10 = 0.65 m.
    let mut c3 = candidate(&truth, DVec2::new(10.0, 0.0), 3);
    c3.pose.x += 0.35;
    assert!(pairwise_consistent(&c1, &c3, &cfg));
    // An angle 4° off at one place: beyond 3°.
    let mut c4 = candidate(&truth, DVec2::new(0.5, 0.0), 4);
    c4.pose.theta += 4f64.to_radians();
    assert!(!pairwise_consistent(&c1, &c4, &cfg));
    assert!(pairwise_consistent(&c1, &c1, &cfg));
}

#[wasm_bindgen_test(unsupported = test)]
fn pcm_rejects_an_inconsistent_candidate_and_counts_places_not_frames() {
    let cfg = ConsistencyConfig::default();
    let truth = Pose2::new(-3.0, 8.0, 2.0);
    let mut cands: Vec<Candidate> = [
        DVec2::new(0.0, 0.0),
        DVec2::new(4.0, 1.0),
        DVec2::new(8.0, -2.0),
        DVec2::new(3.0, 6.0),
    ]
    .iter()
    .enumerate()
    .map(|(k, &p)| candidate(&truth, p, k))
    .collect();
    // A fifth, 1 m off (a repeated texture elsewhere), with the most inliers.
    let mut wrong = candidate(&Pose2::new(-2.0, 8.0, 2.0), DVec2::new(6.0, 3.0), 9);
    wrong.inliers = 90;
    cands.push(wrong);
    assert_eq!(max_consistent_set(&cands, &cfg), vec![0, 1, 2, 3]);
    assert_eq!(max_consistent_places(&cands, &cfg).places, 4);
    // Ten frames a second apart at one place are one place, whatever their
    // number: they would all be fooled together.
    let one_place: Vec<Candidate> = (0..10)
        .map(|k| candidate(&truth, DVec2::new(0.1 * k as f64, 0.0), k))
        .collect();
    let set = max_consistent_places(&one_place, &cfg);
    assert_eq!(set.members.len(), 10);
    assert_eq!(set.places, 1);
    assert_eq!(independent_places(&one_place, &set.members, &cfg), 1);
    assert!(max_consistent_set(&[], &cfg).is_empty());
}

// ----- runs on simulated robots ---------------------------------------------

/// A loop corridor 2 m wide around a 4 m × 2 m block, with a stub on the
/// right to break the symmetry; each wall its own texture. The robots start
/// on opposite sides, facing opposite ways, both following the outer wall.
const CORRIDOR: &str = r#"{
  "name": "corridor-loop", "seed": 3, "duration_s": 70,
  "walls": [
    {"from": [0, 0], "to": [9, 0], "texture": "posters"},
    {"from": [9, 0], "to": [9, 6], "texture": "signs"},
    {"from": [9, 6], "to": [0, 6], "texture": "graffiti"},
    {"from": [0, 6], "to": [0, 0], "texture": "bookshelf"},
    {"from": [2.5, 2], "to": [6.5, 2], "texture": "brick"},
    {"from": [6.5, 2], "to": [6.5, 4], "texture": "maps"},
    {"from": [6.5, 4], "to": [2.5, 4], "texture": "crates"},
    {"from": [2.5, 4], "to": [2.5, 2], "texture": "tiles"},
    {"from": [9, 3], "to": [8.3, 3], "texture": "mosaic"}
  ],
  "robots": [
    {"name": "robot1", "start": [1.5, 0.9, 0.0], "follow": "right"},
    {"name": "robot2", "start": [7.5, 5.1, 3.1416], "follow": "right"}
  ]
}"#;

/// Two rooms 10 m apart, one robot in each.
const TWO_ROOMS: &str = r#"{
  "name": "two-rooms", "seed": 4, "duration_s": 50,
  "walls": [
    {"from": [0, 0], "to": [6, 0], "texture": "posters"},
    {"from": [6, 0], "to": [6, 5], "texture": "signs"},
    {"from": [6, 5], "to": [0, 5], "texture": "graffiti"},
    {"from": [0, 5], "to": [0, 0], "texture": "wood"},
    {"from": [16, 0], "to": [22, 0], "texture": "maps"},
    {"from": [22, 0], "to": [22, 5], "texture": "crates"},
    {"from": [22, 5], "to": [16, 5], "texture": "bookshelf"},
    {"from": [16, 5], "to": [16, 0], "texture": "tiles"}
  ],
  "robots": [
    {"name": "robot1", "start": [1.5, 1.0, 0.0], "follow": "right"},
    {"name": "robot2", "start": [20.5, 4.0, 3.1416], "follow": "right"}
  ]
}"#;

fn run(json: &str) -> Simulation {
    let scenario = Scenario::parse(json).expect("scenario parses");
    let mut sim = Simulation::new(&scenario).expect("scenario runs");
    sim.run_to_end();
    sim
}

/// Pose of robot 1's map frame in robot 0's, from the true starts (tests
/// only).
fn truth_b_in_a(sim: &Simulation) -> Pose2 {
    let (a, b) = (
        sim.robots[0].spec.start_pose(),
        sim.robots[1].spec.start_pose(),
    );
    a.inverse().compose(&b)
}

/// The product's automatic merge ([`MergeJob`] with the default settings)
/// on a finished run: the first robot pair's candidates, in table order,
/// and the verdict on them.
fn merge_auto(sim: &Simulation) -> (Vec<Candidate>, PairDecision) {
    let config = MergeConfig::new(MergeMethod::Auto, sim.scenario.seed);
    let mut job = MergeJob::new(sim, config).expect("a merge job");
    job.run(sim).expect("the merge runs");
    let feats: Vec<usize> = job
        .robots
        .iter()
        .flat_map(|r| r.features.iter().map(|f| f.len()))
        .collect();
    let mean_kp = feats.iter().sum::<usize>() as f64 / feats.len().max(1) as f64;
    assert!(
        (80.0..500.0).contains(&mean_kp),
        "keypoints per 320 × 240 frame: {mean_kp}"
    );
    let pair = &job.pairs[0];
    let cands: Vec<Candidate> = pair
        .cells
        .iter()
        .filter_map(|c| c.candidate.clone())
        .collect();
    let d = pair
        .outcome
        .as_ref()
        .and_then(|o| o.verdict.clone())
        .expect("the automatic method's verdict");
    (cands, d)
}

fn pose_error(p: &Pose2, truth: &Pose2) -> (f64, f64) {
    (
        (p.position() - truth.position()).length(),
        wrap_angle(p.theta - truth.theta).abs().to_degrees(),
    )
}

#[wasm_bindgen_test(unsupported = test)]
fn two_robots_touring_one_corridor_from_different_starts_are_merged_within_0_1_m_and_1_degree() {
    let sim = run(CORRIDOR);
    let truth = truth_b_in_a(&sim);
    let (cands, d) = merge_auto(&sim);
    assert!(cands.len() >= 4, "{} candidates", cands.len());
    assert_eq!(d.status, MergeStatus::Merged, "{}", d.reason);
    assert!(d.reason.starts_with("merged:"), "{}", d.reason);
    let (m, deg) = pose_error(&d.pose.expect("pose"), &truth);
    println!("{} (error {m:.3} m, {deg:.2}°)", d.reason);
    assert!(
        m < 0.1 && deg < 1.0,
        "error {m:.3} m {deg:.2}° ({})",
        d.reason
    );
    assert!(d.places >= 2 && d.confidence > 0.5, "{d:?}");
    // Every supporting candidate is right where its frames are.
    for &i in &d.support {
        let c = &cands[i];
        let e = (c.pose.transform_point(c.place_b) - truth.transform_point(c.place_b)).length();
        assert!(e < 0.15, "candidate {i} off by {e:.3} m");
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn robots_in_two_separate_rooms_are_not_merged() {
    let sim = run(TWO_ROOMS);
    let (_, d) = merge_auto(&sim);
    println!("{}", d.reason);
    assert_eq!(d.status, MergeStatus::NoMerge, "{}", d.reason);
    assert!(d.confidence == 0.0);
}

#[wasm_bindgen_test(unsupported = test)]
fn grid_alignment_recovers_a_perturbed_transform_and_the_verdict_refuses_wrong_ones() {
    let sim = run(CORRIDOR);
    let truth = truth_b_in_a(&sim);
    let map_a = sim.robots[0].mapping.map(MapperKind::Slam);
    let map_b = sim.robots[1].mapping.map(MapperKind::Slam);
    // Alignment: 0.25 m and 2° off, back to within 3 cm and 0.3°.
    let guess = truth.compose(&Pose2::new(0.2, -0.15, 2f64.to_radians()));
    let aligned = refine_alignment(map_a, map_b, &guess, &AlignConfig::default()).expect("aligns");
    let (m, deg) = pose_error(&aligned.pose, &truth);
    assert!(m < 0.03 && deg < 0.3, "aligned {m:.3} m {deg:.2}°");
    assert!(aligned.matched_cells > 200, "{}", aligned.matched_cells);
    // The maps agree at the truth, with no wall in the other's free space.
    let at_truth = map_agreement(map_a, map_b, &truth);
    assert!(at_truth.min_direction_agree > 200, "{at_truth:?}");
    assert!(at_truth.contradiction() < 0.01, "{at_truth:?}");
    // Candidates from two places that agree on the truth: merged.
    let cand = |p: DVec2, pose: Pose2, k: usize| Candidate {
        a_frame: k,
        b_frame: k,
        pose,
        inliers: 20,
        rms_m: 0.02,
        place_a: pose.transform_point(p),
        place_b: p,
    };
    let b_places = [
        truth.inverse().transform_point(DVec2::new(4.5, 0.6)),
        truth.inverse().transform_point(DVec2::new(4.5, 5.4)),
    ];
    let cfg = VerdictConfig::default();
    let right: Vec<Candidate> = b_places
        .iter()
        .enumerate()
        .map(|(k, &p)| cand(p, truth, k))
        .collect();
    let d = decide_pair(&right, map_a, map_b, &cfg);
    assert_eq!(d.status, MergeStatus::Merged, "{}", d.reason);
    let (m, deg) = pose_error(&d.pose.expect("pose"), &truth);
    assert!(m < 0.05 && deg < 0.5, "{m:.3} m {deg:.2}°");
    // The same two places agreeing on a transform 1 m off, or turned 30°
    // about the corridor's centre: the overlaid maps contradict.
    let shifted = Pose2::new(1.0, 0.0, 0.0).compose(&truth);
    let centre = Pose2::new(4.5, 3.0, 0.0);
    let turned = centre
        .compose(&Pose2::new(0.0, 0.0, 30f64.to_radians()))
        .compose(&centre.inverse())
        .compose(&truth);
    for wrong in [shifted, turned] {
        let cands: Vec<Candidate> = b_places
            .iter()
            .enumerate()
            .map(|(k, &p)| cand(p, wrong, k))
            .collect();
        let d = decide_pair(&cands, map_a, map_b, &cfg);
        assert_eq!(d.status, MergeStatus::NoMerge);
        assert!(d.reason.starts_with("maps contradict"), "{}", d.reason);
        let a = d.agreement.expect("judged on the maps");
        assert!(a.occupied_contradict > 50, "{a:?}");
    }
    // Both transforms proposed at once: each is refined, then judged, in
    // steps of their own (after the step that finds them, before the one
    // that compares them), and the decision is the one call's: the right
    // one, merged.
    let mut both = right.clone();
    // (seen from other places: two candidates of one place are one place)
    let elsewhere = [DVec2::new(1.5, 0.6), DVec2::new(1.5, 5.4)];
    both.extend(
        elsewhere
            .iter()
            .enumerate()
            .map(|(k, &p)| cand(truth.inverse().transform_point(p), turned, k + 2)),
    );
    let whole = decide_pair(&both, map_a, map_b, &cfg);
    assert_eq!(whole.status, MergeStatus::Merged, "{}", whole.reason);
    let mut steps = VerdictSteps::default();
    let mut calls = 1;
    let stepped = loop {
        match steps.step(&both, &SearchSummary::default(), map_a, map_b, &cfg) {
            Some(d) => break d,
            None => calls += 1,
        }
    };
    assert_eq!(calls, 6, "rivals, two refined and judged, the comparison");
    assert_eq!(stepped, whole);
    // One place alone is not enough, however good.
    let d = decide_pair(&right[..1], map_a, map_b, &cfg);
    assert_eq!(d.status, MergeStatus::NoMerge);
    assert!(d.reason.starts_with("too little evidence"), "{}", d.reason);
    let d = decide_pair(&[], map_a, map_b, &cfg);
    assert!(d.reason.starts_with("no common place seen"), "{}", d.reason);
}

// ----- the map search -------------------------------------------------------

/// A building of axis-aligned walls (metres): an outline `w` × `h` and the
/// interior walls given, as segments.
fn building(w: f64, h: f64, inner: &[[f64; 4]]) -> Vec<Segment> {
    let c = |x: f64, y: f64| DVec2::new(x, y);
    let mut walls = vec![
        Segment::new(c(0.0, 0.0), c(w, 0.0)),
        Segment::new(c(w, 0.0), c(w, h)),
        Segment::new(c(w, h), c(0.0, h)),
        Segment::new(c(0.0, h), c(0.0, 0.0)),
    ];
    walls.extend(
        inner
            .iter()
            .map(|s| Segment::new(c(s[0], s[1]), c(s[2], s[3]))),
    );
    walls
}

/// The map a robot whose map frame sits at `frame` (in the building's
/// coordinates) makes from 360-beam scans (8 m range) at `stops`, three
/// scans each, every beam ray-cast against `walls`.
fn scanned_map(walls: &[Segment], frame: &Pose2, stops: &[DVec2]) -> OccupancyGrid {
    let mut g = OccupancyGrid::new(GridConfig::default());
    let local: Vec<DVec2> = stops
        .iter()
        .map(|&p| frame.inverse_transform_point(p))
        .collect();
    let lo = local
        .iter()
        .fold(DVec2::splat(f64::INFINITY), |m, &p| m.min(p));
    let hi = local
        .iter()
        .fold(DVec2::splat(f64::NEG_INFINITY), |m, &p| m.max(p));
    assert!(g.ensure_contains(lo - 9.0, hi + 9.0));
    for &stop in stops {
        for k in 0..360 {
            let dir = DVec2::from_angle((k as f64).to_radians());
            let hit = walls
                .iter()
                .filter_map(|s| s.ray_hit(stop, dir))
                .fold(f64::INFINITY, f64::min);
            let (range, is_hit) = if hit <= 8.0 {
                (hit, true)
            } else {
                (8.0, false)
            };
            let from = frame.inverse_transform_point(stop);
            let to = frame.inverse_transform_point(stop + dir * range);
            for _ in 0..3 {
                g.integrate_beam(from, to, is_hit);
            }
        }
    }
    g
}

/// Points every metre in `x0..x1` × `y0..y1` (half-metre offsets, so none
/// lies on a wall of the buildings below).
fn stops(x0: f64, x1: f64, y0: f64, y1: f64) -> Vec<DVec2> {
    let mut out = Vec::new();
    let mut y = y0 + 0.5;
    while y < y1 {
        let mut x = x0 + 0.5;
        while x < x1 {
            out.push(DVec2::new(x, y));
            x += 1.0;
        }
        y += 1.0;
    }
    out
}

const HOUSE: [[f64; 4]; 6] = [
    [4.0, 0.0, 4.0, 7.0],
    [8.0, 4.0, 8.0, 12.0],
    [12.0, 0.0, 12.0, 5.0],
    [10.0, 5.0, 14.0, 5.0],
    [12.0, 8.0, 16.0, 8.0],
    [4.0, 9.0, 8.0, 9.0],
];

#[wasm_bindgen_test(unsupported = test)]
fn map_search_finds_a_turned_and_shifted_map_within_0_1_m_and_1_degree() {
    let walls = building(16.0, 12.0, &HOUSE);
    // A's frame is turned 17° in the building, B's 110° the other way and
    // shifted; each robot tours two thirds of the floor.
    let frame_a = Pose2::new(1.3, 0.7, 17f64.to_radians());
    let frame_b = Pose2::new(9.2, 4.1, -110f64.to_radians());
    let a = scanned_map(&walls, &frame_a, &stops(0.0, 11.0, 0.0, 12.0));
    let b = scanned_map(&walls, &frame_b, &stops(5.0, 16.0, 0.0, 12.0));
    let truth = frame_a.inverse().compose(&frame_b);
    // The wall directions give the rotation modulo 90°.
    let delta = dominant_rotation(&a, &b).expect("walls have directions");
    let off = wrap_angle(4.0 * (delta - truth.theta)) / 4.0;
    assert!(off.abs() < 0.5f64.to_radians(), "rotation off by {off}");
    let found = search_maps(
        &a,
        &b,
        &MapSearchConfig::default(),
        &VerdictConfig::default(),
    );
    assert_eq!(found.status, MergeStatus::Merged, "{}", found.reason);
    assert!(
        found.reason.starts_with("maps alone agree"),
        "{}",
        found.reason
    );
    let pose = found.pose.expect("pose");
    let (m, deg) = pose_error(&pose, &truth);
    assert!(m < 0.1 && deg < 1.0, "off by {m:.3} m, {deg:.2}°");
}

/// Maps and no frames, as real robots' map files give them.
struct MapsOnly(Vec<OccupancyGrid>);

impl MergeInput for MapsOnly {
    fn robot_names(&self) -> Vec<String> {
        (0..self.0.len()).map(|i| format!("map{i}")).collect()
    }
    fn map(&self, robot: usize, _mapper: MapperKind) -> &OccupancyGrid {
        &self.0[robot]
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn the_merge_job_merges_maps_that_come_without_frames() {
    // The building of the map search test, through the product's driver.
    let walls = building(16.0, 12.0, &HOUSE);
    let frame_a = Pose2::new(1.3, 0.7, 17f64.to_radians());
    let frame_b = Pose2::new(9.2, 4.1, -110f64.to_radians());
    let a = scanned_map(&walls, &frame_a, &stops(0.0, 11.0, 0.0, 12.0));
    let b = scanned_map(&walls, &frame_b, &stops(5.0, 16.0, 0.0, 12.0));
    let truth = frame_a.inverse().compose(&frame_b);
    let input = MapsOnly(vec![a, b]);
    // The automatic method finds no frame to describe or match; vision
    // has nothing to say, so the maps alone decide.
    let mut job = MergeJob::new(&input, MergeConfig::new(MergeMethod::Auto, 1)).expect("a job");
    assert_eq!(job.stage(), Stage::Features);
    job.run(&input).expect("runs");
    assert!(job.robots.iter().all(|r| r.infos.is_empty()));
    assert_eq!(job.pairs[0].cells.len(), 0);
    let outcome = job.outcome().expect("decided");
    assert_eq!(outcome.status, MergeStatus::Merged, "{}", outcome.reason);
    assert!(
        outcome.reason.contains("maps alone agree"),
        "{}",
        outcome.reason
    );
    let t = &outcome.transforms[1];
    assert_eq!(t.robot, "map1");
    let (m, deg) = pose_error(&Pose2::new(t.pose[0], t.pose[1], t.pose[2]), &truth);
    assert!(m < 0.1 && deg < 1.0, "off by {m:.3} m, {deg:.2}°");
    assert!(job.merged_map().is_some_and(|g| g.occupied_count() > 0));
    // A method that reads the maps only goes straight to the decision.
    let config = MergeConfig::new(MergeMethod::MapOnly, 1);
    let job = MergeJob::new(&input, config).expect("a job");
    assert_eq!(job.stage(), Stage::Decision);
}

#[wasm_bindgen_test(unsupported = test)]
fn map_search_refuses_two_different_buildings_and_a_symmetric_one() {
    let house = building(16.0, 12.0, &HOUSE);
    let other = building(
        14.0,
        10.0,
        &[
            [3.0, 3.0, 3.0, 10.0],
            [6.0, 0.0, 6.0, 6.0],
            [6.0, 6.0, 10.0, 6.0],
            [10.0, 3.0, 14.0, 3.0],
        ],
    );
    let frame = Pose2::new(0.0, 0.0, 0.0);
    let a = scanned_map(&house, &frame, &stops(0.0, 16.0, 0.0, 12.0));
    let b = scanned_map(&other, &frame, &stops(0.0, 14.0, 0.0, 10.0));
    let cfg = MapSearchConfig::default();
    let found = search_maps(&a, &b, &cfg, &VerdictConfig::default());
    assert_eq!(found.status, MergeStatus::NoMerge, "{}", found.reason);
    assert!(found.pose.is_none());
    // An empty hall is symmetric: turned by 180° it lies on itself as
    // well as it does unturned, so the maps alone cannot choose.
    let hall = building(12.0, 8.0, &[]);
    let a = scanned_map(&hall, &frame, &stops(0.0, 12.0, 0.0, 8.0));
    let b = scanned_map(
        &hall,
        &Pose2::new(2.0, 1.0, 0.3),
        &stops(0.0, 12.0, 0.0, 8.0),
    );
    let found = search_maps(&a, &b, &cfg, &VerdictConfig::default());
    assert_eq!(found.status, MergeStatus::NoMerge, "{}", found.reason);
    assert!(found.reason.contains("ambiguous"), "{}", found.reason);
}

// ----- fusion and the spanning tree -----------------------------------------

/// A grid with one straight wall seen from `from`: beams to the points of
/// the segment `a`–`b`.
fn wall_grid(from: DVec2, a: DVec2, b: DVec2, scans: usize) -> OccupancyGrid {
    let mut g = OccupancyGrid::new(GridConfig::default());
    assert!(g.ensure_contains(a.min(b).min(from) - 1.0, a.max(b).max(from) + 1.0));
    for _ in 0..scans {
        for k in 0..=100 {
            g.integrate_beam(from, a + (b - a) * (k as f64 / 100.0), true);
        }
    }
    g
}

#[wasm_bindgen_test(unsupported = test)]
fn fusion_adds_log_odds_and_resamples_rotated_maps_without_holes() {
    let cfg = GridConfig::default();
    // A: a wall along y = 2 for x in [-1, 1], seen from the origin 3 times.
    let a = wall_grid(DVec2::ZERO, DVec2::new(-1.0, 2.0), DVec2::new(1.0, 2.0), 3);
    // The same wall in a frame turned 90° and shifted: B's frame at
    // (0.5, 0, 90°) in A's, so A's (x, y) is B's (y, 0.5 − x).
    let pose_b = Pose2::new(0.5, 0.0, PI / 2.0);
    let to_b = |p: DVec2| pose_b.inverse_transform_point(p);
    let b = wall_grid(
        to_b(DVec2::ZERO),
        to_b(DVec2::new(-1.0, 2.0)),
        to_b(DVec2::new(1.0, 2.0)),
        3,
    );
    let merged = fuse(&[(&a, Pose2::IDENTITY), (&b, pose_b)], cfg.clone());
    let units = |g: &OccupancyGrid, p: DVec2| {
        g.local(g.global_cell(p))
            .map_or(0, |(x, y)| g.units(x, y) as i32)
    };
    // On the wall both maps say "occupied", in front of it both say "free":
    // the merge holds the sum of the two, clamped to [−40, 70].
    let b_units = |p: DVec2| units(&b, to_b(p));
    for p in [
        DVec2::new(0.025, 2.025),
        DVec2::new(-0.725, 2.025),
        DVec2::new(0.025, 1.025),
        DVec2::new(0.475, 1.525),
    ] {
        let expected = (units(&a, p) + b_units(p)).clamp(-40, 70);
        assert_eq!(units(&merged, p), expected, "at {p}");
    }
    let on_wall = DVec2::new(0.025, 2.025);
    assert!(units(&a, on_wall) > 13 && b_units(on_wall) > 13);
    assert_eq!(units(&merged, on_wall), 70);
    let free = DVec2::new(0.025, 1.025);
    assert!(units(&a, free) < -16 && b_units(free) < -16);
    // Every cell of the triangle both maps cleared is free in the merge: no
    // holes from the rotated lattice.
    let mut holes = 0;
    for iy in 0..merged.height() {
        for ix in 0..merged.width() {
            let c = merged.cell_centre(ix, iy);
            if c.y > 0.3
                && c.y < 1.7
                && c.x.abs() < 0.3 * c.y
                && merged.state(ix, iy) != CellState::Free
            {
                holes += 1;
            }
        }
    }
    assert_eq!(holes, 0);
    // A band of 7 rows at a time (as the page's merge calls fuse) gives the
    // same grid, cell for cell.
    let maps = [(&a, Pose2::IDENTITY), (&b, pose_b)];
    let mut steps = FuseSteps::new(&maps, cfg.clone());
    let (_, rows) = steps.progress();
    assert_eq!(rows, merged.height());
    let mut calls = 1;
    while !steps.step(&maps, 7) {
        calls += 1;
    }
    assert_eq!(
        calls,
        rows.div_ceil(7),
        "one call per band of 7 of {rows} rows"
    );
    let banded = steps.into_grid();
    assert_eq!(
        (banded.width(), banded.height(), banded.raw_units()),
        (merged.width(), merged.height(), merged.raw_units())
    );
    // Fusing one map alone reproduces it; nothing to fuse gives an empty grid.
    let alone = fuse(&[(&a, Pose2::IDENTITY)], cfg.clone());
    assert_eq!(units(&alone, on_wall), units(&a, on_wall));
    assert_eq!(alone.occupied_count(), a.occupied_count());
    // The merge covers what the map knows, not the margin it grew by: a map
    // whose only known cells sit in a 1 m box far from its origin fuses into
    // one grow step (64 cells) or two across, not the whole span from 0.
    let mut far = OccupancyGrid::new(cfg.clone());
    far.ensure_contains(DVec2::ZERO, DVec2::new(20.0, 20.0));
    far.integrate_beam(DVec2::new(18.0, 18.0), DVec2::new(19.0, 18.5), true);
    let fused = fuse(&[(&far, Pose2::IDENTITY)], cfg.clone());
    assert!(far.width() >= 400, "{}", far.width());
    assert!(
        fused.width() <= 128 && fused.height() <= 128,
        "{} x {}",
        fused.width(),
        fused.height()
    );
    assert_eq!(fused.occupied_count(), far.occupied_count());
    assert_eq!(fuse(&[], cfg.clone()).width(), 0);
    let empty = OccupancyGrid::new(cfg.clone());
    assert_eq!(fuse(&[(&empty, Pose2::IDENTITY)], cfg).width(), 0);
}

#[wasm_bindgen_test(unsupported = test)]
fn spanning_tree_joins_three_robots_by_the_surest_edges_and_lists_the_fourth() {
    let e01 = Pose2::new(2.0, 0.0, PI / 2.0);
    let e12 = Pose2::new(1.0, 1.0, 0.0);
    let edges = [
        PairEdge {
            a: 0,
            b: 1,
            pose: e01,
            confidence: 0.9,
        },
        // Stored from 2 to 1: robot 1's frame in robot 2's.
        PairEdge {
            a: 2,
            b: 1,
            pose: e12.inverse(),
            confidence: 0.8,
        },
        // A weaker, slightly different direct edge: not used.
        PairEdge {
            a: 0,
            b: 2,
            pose: Pose2::new(1.1, 1.0, PI / 2.0),
            confidence: 0.5,
        },
        // Robot 3 has only a worthless edge.
        PairEdge {
            a: 3,
            b: 1,
            pose: Pose2::IDENTITY,
            confidence: 0.0,
        },
    ];
    let joined = spanning_tree(4, &edges);
    assert_eq!(joined.edges_used, vec![0, 1]);
    assert_eq!(joined.poses[0], Some(Pose2::IDENTITY));
    assert_eq!(joined.poses[1], Some(e01));
    // Robot 2's frame = e01 ⊕ e12: (2, 0) + R(90°)·(1, 1) = (1, 1), heading 90°.
    let p2 = joined.poses[2].expect("joined");
    assert!((p2.x - 1.0).abs() < 1e-12 && (p2.y - 1.0).abs() < 1e-12);
    assert!((p2.theta - PI / 2.0).abs() < 1e-12);
    assert_eq!(joined.poses[3], None);
    assert_eq!(joined.unjoined(), vec![3]);
    // No edges: only robot 0; no robots: nothing.
    assert_eq!(spanning_tree(2, &[]).unjoined(), vec![1]);
    assert!(spanning_tree(0, &edges).poses.is_empty());
}

/// Issue 22: with robots 0–1 joined, 2–3–4 joined among themselves and 5
/// joined to no one, every group comes out, each in its first robot's frame.
#[wasm_bindgen_test(unsupported = test)]
fn groups_are_every_connected_group_each_in_its_first_robots_frame() {
    let edge = |a, b, pose, confidence| PairEdge {
        a,
        b,
        pose,
        confidence,
    };
    let e01 = Pose2::new(2.0, 0.0, PI / 2.0);
    let e34 = Pose2::new(0.0, 3.0, -PI / 2.0);
    let e23 = Pose2::new(1.0, 0.0, PI);
    let edges = [
        edge(0, 1, e01, 0.9),
        // Stored from 4 to 3: robot 3's frame in robot 4's.
        edge(4, 3, e34.inverse(), 0.7),
        edge(2, 3, e23, 0.6),
        edge(5, 0, Pose2::IDENTITY, 0.0),
    ];
    let g = groups(6, &edges);
    let members =
        |k: usize| -> Vec<usize> { (0..6).filter(|&i| g[k].poses[i].is_some()).collect() };
    assert_eq!(g.len(), 3);
    assert_eq!(members(0), vec![0, 1]);
    assert_eq!(members(1), vec![2, 3, 4]);
    assert_eq!(members(2), vec![5]);
    // Robot 0's group is the spanning tree from robot 0.
    assert_eq!(g[0], spanning_tree(6, &edges));
    assert_eq!(g[1].poses[2], Some(Pose2::IDENTITY));
    assert_eq!(g[1].poses[3], Some(e23));
    // Robot 4 in robot 2's frame: e23 ⊕ e34 = (1, 0) + R(180°)·(0, 3) =
    // (1, -3), heading 180° - 90° = 90°.
    let p4 = g[1].poses[4].expect("joined");
    assert!(
        (p4.x - 1.0).abs() < 1e-12 && (p4.y + 3.0).abs() < 1e-12,
        "{p4:?}"
    );
    assert!((p4.theta - PI / 2.0).abs() < 1e-12, "{p4:?}");
    assert_eq!(g[2].poses[5], Some(Pose2::IDENTITY));
    assert!(groups(0, &edges).is_empty());
}

// ----- timing ---------------------------------------------------------------

/// Milliseconds from an arbitrary origin (the wall clock of the host: the
/// core itself reads no clock).
fn now_ms() -> f64 {
    #[cfg(target_arch = "wasm32")]
    {
        js_sys::Date::now()
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        use std::time::{SystemTime, UNIX_EPOCH};
        SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map_or(0.0, |d| d.as_secs_f64() * 1e3)
    }
}

/// Stage times of the automatic merge on a 300 s random maze (about 300
/// frames per robot). Natively:
/// `cargo test --release -p slamlab --test merge_parts -- --ignored --nocapture`;
/// in node, the same with `--target wasm32-unknown-unknown`.
#[wasm_bindgen_test(unsupported = test)]
#[ignore = "benchmark"]
fn bench_automatic_merge_stages() {
    let spec = slamlab::maze::MazeSpec {
        seed: 2,
        ..slamlab::maze::MazeSpec::default()
    };
    let sim = run(&slamlab::maze::random_maze(&spec));
    let config = MergeConfig::new(MergeMethod::Auto, sim.scenario.seed);
    let mut job = MergeJob::new(&sim, config).expect("a merge job");
    // The product's own stages, one at a time: `advance` never crosses a
    // stage boundary.
    let mut times: Vec<(&str, f64)> = Vec::new();
    while !job.is_done() {
        let stage = job.stage();
        let t = now_ms();
        job.advance(&sim, usize::MAX).expect("advances");
        times.push((stage.name(), now_ms() - t));
    }
    assert_eq!(job.stage(), Stage::Done);
    let pair = &job.pairs[0];
    let outcome = pair.outcome.as_ref().expect("decided");
    let checked = pair.todo.len().max(1) as f64;
    let ms: Vec<String> = times
        .iter()
        .map(|&(s, t)| match s {
            "matching" => format!("{s} {t:.1} ({:.2}/pair)", t / checked),
            _ => format!("{s} {t:.1}"),
        })
        .collect();
    let report = format!(
        "frames {}+{} (of {}+{}), {} proposals, {} candidates: {}\n\
         ms: {}; merged map {} cells",
        job.robots[0].selected.len(),
        job.robots[1].selected.len(),
        job.robots[0].infos.len(),
        job.robots[1].infos.len(),
        pair.todo.len(),
        outcome.candidates,
        outcome.reason,
        ms.join(", "),
        job.merged_map().map_or(0, |m| m.width() * m.height())
    );
    #[cfg(target_arch = "wasm32")]
    wasm_bindgen_test::console_log!("{report}");
    #[cfg(not(target_arch = "wasm32"))]
    println!("{report}");
    assert_eq!(outcome.status, MergeStatus::Merged, "{}", outcome.reason);
}

// ----- the pair budget with many robots -------------------------------------

#[wasm_bindgen_test(unsupported = test)]
fn a_budgeted_merge_of_five_maps_searches_in_rank_order_and_skips_joined_robots() {
    // Four robots toured the house from frames turned every which way; a
    // fifth mapped another building. Five robots: over the budget's
    // all-pairs limit (four), so the pairs are ranked and bounded.
    let house = building(16.0, 12.0, &HOUSE);
    let other = building(14.0, 10.0, &[[3.0, 3.0, 3.0, 10.0], [6.0, 0.0, 6.0, 6.0]]);
    let frames = [
        Pose2::new(1.3, 0.7, 17f64.to_radians()),
        Pose2::new(9.2, 4.1, -110f64.to_radians()),
        Pose2::new(3.0, 8.0, 75f64.to_radians()),
        Pose2::new(-2.0, 5.0, 200f64.to_radians()),
    ];
    let tours = [
        stops(0.0, 11.0, 0.0, 12.0),
        stops(5.0, 16.0, 0.0, 12.0),
        stops(0.0, 16.0, 0.0, 8.0),
        stops(2.0, 16.0, 4.0, 12.0),
    ];
    let mut maps: Vec<OccupancyGrid> = frames
        .iter()
        .zip(&tours)
        .map(|(f, t)| scanned_map(&house, f, t))
        .collect();
    maps.push(scanned_map(
        &other,
        &Pose2::new(0.0, 0.0, 0.0),
        &stops(0.0, 14.0, 0.0, 10.0),
    ));
    let input = MapsOnly(maps);
    let mut job = MergeJob::new(&input, MergeConfig::new(MergeMethod::Auto, 1)).expect("a job");
    job.run(&input).expect("runs");
    let outcome = job.outcome().expect("decided");
    let budget = outcome.budget.clone().expect("five robots: a budget");
    // No frames, so no visual votes: nothing is matched, and each robot
    // keeps k = ⌈log₂ 5⌉ = 3 partners by coarse map overlap.
    assert_eq!(budget.pairs, 10);
    assert_eq!(budget.partners_per_robot, 3);
    assert_eq!(budget.matched, 0);
    // Each pair was searched, or not checked at all (left out of the
    // budget, or left out because its robots were joined already).
    assert_eq!(budget.maps_searched + budget.not_checked, 10, "{budget:?}");
    // Four maps of one house need three merged pairs; the other three
    // pairs among them come after in rank order and are not searched.
    assert!(budget.searches_skipped >= 1, "{budget:?}");
    for p in &outcome.pairs {
        match p.check {
            Some("none") => {
                assert!(p.reason.contains("budget"), "{}", p.reason);
                assert_eq!(p.status, MergeStatus::NoMerge);
            }
            Some("maps") => {}
            other => panic!("{} + {}: check {other:?}", p.a, p.b),
        }
    }
    // The groups: the house's four maps, each right, and the other alone.
    assert_eq!(outcome.groups.len(), 2, "{:?}", outcome.groups);
    let house_group = &outcome.groups[0];
    assert_eq!(house_group.robots, ["map0", "map1", "map2", "map3"]);
    for (t, frame) in house_group.transforms.iter().zip(&frames) {
        let truth = frames[0].inverse().compose(frame);
        let (m, deg) = pose_error(&Pose2::new(t.pose[0], t.pose[1], t.pose[2]), &truth);
        assert!(
            m < 0.15 && deg < 1.0,
            "{}: off by {m:.3} m, {deg:.2}°",
            t.robot
        );
    }
    assert_eq!(outcome.groups[1].robots, ["map4"]);
    let reason = outcome.groups[1].reason.clone().unwrap_or_default();
    assert!(reason.contains("joined no other robot"), "{reason}");
}

// ----- frames taking part: thinned by place ---------------------------------

#[wasm_bindgen_test(unsupported = test)]
fn frames_are_thinned_by_place_not_only_against_the_last_one() {
    use slamlab::merge::method::auto::thin_by_place;
    let at =
        |x: f64, y: f64, deg: f64| frame_with_ranges(Pose2::new(x, y, deg.to_radians()), |_| None);
    // A first pass along a corridor, a frame every 0.35 m heading east;
    // then a second pass over the same stretch, again heading east but
    // 0.1 m to the side; then the corridor driven back, heading west.
    let mut frames: Vec<FrameInfo> = (0..6).map(|k| at(0.35 * k as f64, 0.0, 0.0)).collect();
    frames.extend((0..6).map(|k| at(0.35 * k as f64 + 0.05, 0.1, 3.0)));
    frames.extend((0..6).map(|k| at(1.75 - 0.35 * k as f64, 0.0, 180.0)));
    let kept = thin_by_place(&frames, 0.5, 15f64.to_radians());
    // First pass: 0, 0.7, 1.4 m (0.35 m from a kept frame is too close),
    // i.e. frames 0, 2, 4. The second pass is within 0.5 m and 3° of them
    // everywhere: none kept. Driving back faces the other way: its own
    // thinning, 1.75, 1.05, 0.35 m, i.e. frames 12, 14, 16.
    assert_eq!(kept, vec![0, 2, 4, 12, 14, 16]);
    // A turn of 15° or more at the same spot is a new view.
    let turned = vec![at(0.0, 0.0, 0.0), at(0.0, 0.0, 10.0), at(0.0, 0.0, 16.0)];
    assert_eq!(thin_by_place(&turned, 0.5, 15f64.to_radians()), vec![0, 2]);
    // Frames across a cell border are still compared (the hash grid's
    // neighbours): 0.49 m apart over x = 0.5 is too close.
    let border = vec![at(0.26, 0.0, 0.0), at(0.75, 0.0, 0.0), at(1.2, 0.0, 0.0)];
    assert_eq!(thin_by_place(&border, 0.5, 15f64.to_radians()), vec![0, 2]);
}
