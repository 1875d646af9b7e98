//! Each group of robots gets its own merged map (issue 22), through the lab
//! as the page drives it (`crate/src/lab/groups.rs`).
//!
//! The scenario `tests/data/two-buildings.json` is two buildings 10 m
//! apart and a small room: the thesis preset's building (robots 1 and 2),
//! the loop preset's moved 30 m east with other outer textures (robots 3
//! and 4), and a 6 × 4 m room 7 m north of the first (robot 5). Nothing
//! ties the buildings together, so the merge must find two groups of two
//! and leave robot 5 alone; each group's map is scored against the truth
//! in the frame of its first robot.

use slamlab::lab::Lab;
use slamlab::merge::MergeMethod;
use slamlab::palette::robot_colour;
use wasm_bindgen_test::wasm_bindgen_test;

const SCENARIO: &str = include_str!("data/two-buildings.json");

fn merged_lab() -> Lab {
    let mut lab = Lab::new(SCENARIO).expect("the scenario parses");
    lab.run_to_end().expect("runs");
    lab.merge_start(MergeMethod::Auto).expect("starts");
    lab.merge_finish().expect("finishes");
    lab
}

/// Pixels of `rgba` within 40 (per channel) of robot `i`'s colour.
fn pixels_of(rgba: &[u8], i: usize) -> usize {
    let c = robot_colour(i);
    rgba.chunks_exact(4)
        .filter(|p| (0..3).all(|k| (p[k] as i32 - c[k] as i32).abs() <= 40))
        .count()
}

#[wasm_bindgen_test(unsupported = test)]
fn two_buildings_give_two_groups_each_with_its_own_map_and_a_robot_alone() {
    let lab = merged_lab();
    groups_and_their_errors(&lab);
    each_group_map_is_fused_in_its_first_robots_frame(&lab);
}

fn groups_and_their_errors(lab: &Lab) {
    let groups = lab.merge_groups().expect("groups");
    let robots: Vec<Vec<&str>> = groups
        .iter()
        .map(|g| g.robots.iter().map(String::as_str).collect())
        .collect();
    assert_eq!(
        robots,
        [
            vec!["robot1", "robot2"],
            vec!["robot3", "robot4"],
            vec!["robot5"]
        ]
    );
    let reason = groups[2].reason.as_deref().expect("robot5's reason");
    assert!(
        reason.starts_with("robot5 joined no other robot: none of its 4 pairs merged"),
        "{reason}"
    );
    assert!(groups[0].reason.is_none() && groups[1].reason.is_none());

    // Group 2 is scored in robot3's frame: robot3 starts at (32, 2, 0) and
    // robot4 at (44, 10, 3.1416), so robot4's map frame truly lies at
    // (12, 8, 3.1416) in robot3's.
    let e = &groups[1].errors[1];
    assert_eq!(e.robot, "robot4");
    // 3.1416 is robot4's heading as the scenario file writes it, not π.
    #[allow(clippy::approx_constant)]
    let heading = 3.1416;
    let turn = (e.truth[2] - heading + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU);
    assert!(
        (e.truth[0] - 12.0).abs() < 1e-6
            && (e.truth[1] - 8.0).abs() < 1e-6
            && (turn - std::f64::consts::PI).abs() < 1e-6,
        "robot4's true frame in robot3's: {:?}",
        e.truth
    );
    assert!(
        e.error_m < 0.3 && e.error_deg.abs() < 2.0,
        "robot4 off by {} m, {} deg",
        e.error_m,
        e.error_deg
    );
    assert_eq!(groups[1].transforms[0].pose, [0.0, 0.0, 0.0]);
    // Group 1's errors are the report's (robot 1's group is the report's own).
    let report = lab.merge_report().expect("report");
    assert_eq!(report.errors[1].error_m, groups[0].errors[1].error_m);
    assert_eq!(report.groups.len(), 3);
}

fn each_group_map_is_fused_in_its_first_robots_frame(lab: &Lab) {
    // Robot 1's group fused here is the merge's own merged map.
    assert_eq!(
        lab.group_merged_pgm(0).expect("group 1"),
        lab.merged_pgm().expect("merged")
    );
    // Group 2 is the loop building, 16 × 12 m, in robot3's frame: robot3
    // starts 2 m from its south-west corner facing east, so the walls
    // span x in [-2, 14] and y in [-2, 10] there. The map holds them all,
    // with at most 3.5 m of margin (measured: 1.2 m west, 2.0 m east,
    // 2.8 m north: the fused grid spans what the maps hold past the walls).
    let g = lab.group_merged_map(1).expect("group 2");
    let (o, r) = (g.origin_m(), g.resolution_m());
    let far = [o.x + g.width() as f64 * r, o.y + g.height() as f64 * r];
    for (low, wall) in [(o.x, -2.0), (o.y, -2.0)] {
        assert!(
            low <= wall + 0.2 && low >= wall - 3.5,
            "group 2's map starts at {low} m, the wall at {wall} m"
        );
    }
    for (high, wall) in [(far[0], 14.0), (far[1], 10.0)] {
        assert!(
            high >= wall - 0.2 && high <= wall + 3.5,
            "group 2's map ends at {high} m, the wall at {wall} m"
        );
    }
    // Its picture holds robot3's and robot4's paths, no one else's.
    let rgba = lab.group_merged_rgba(1, 240, 180).expect("picture");
    for i in [2, 3] {
        assert!(pixels_of(&rgba, i) > 60, "robot{}'s path drawn", i + 1);
    }
    for i in [0, 1, 4] {
        // (a few anti-aliased edge pixels of other colours may come near)
        let n = pixels_of(&rgba, i);
        assert!(n <= 3, "robot{} is not in group 2: {n} pixels", i + 1);
    }
    assert!(lab
        .group_merged_yaml(1, "g2.pgm")
        .expect("yaml")
        .starts_with("image: \"g2.pgm\"\nresolution: "));
    assert_eq!(&lab.group_merged_png(1).expect("png")[1..4], b"PNG");
    // A robot alone: its own map, its own path.
    let alone = lab.group_merged_rgba(2, 120, 90).expect("robot5's map");
    assert!(pixels_of(&alone, 4) > 10);
    let err = lab.group_merged_pgm(3).expect_err("no fourth group");
    assert_eq!(err, "there is no group 3: the merge found 3");
}

/// The proposal and decision stages, cut into single units as the page
/// cuts them, come out exactly as in one call (the command line's way),
/// and they are cut: the proposals one step for the vocabulary's tree, one
/// per robot's words, one for the bags, one for the votes' inverted file,
/// one per robot's votes, coarse map, coarse overlap and pair's to-do
/// list; the decision one unit per pair's verdict, then one per map search
/// step; each stage's progress counting them.
#[wasm_bindgen_test(unsupported = test)]
fn the_merge_a_unit_at_a_time_equals_the_merge_at_once() {
    let mut lab = Lab::new(SCENARIO).expect("the scenario parses");
    lab.run_to_end().expect("runs");
    let mut report_of = |units: usize| {
        lab.merge_start(MergeMethod::Auto).expect("starts");
        let (mut decision_calls, mut proposal_calls) = (0, 0);
        let (mut seen_total, mut proposal_total) = (0, 0);
        loop {
            let before = lab.merge_progress().expect("progress");
            if before.finished {
                break;
            }
            let after = lab.merge_advance(units).expect("advances");
            if after.stage == before.stage {
                assert!(after.done <= after.total, "{after:?}");
            }
            match (before.stage, after.stage == before.stage) {
                ("decision", same) => {
                    decision_calls += 1;
                    if same {
                        seen_total = seen_total.max(after.total);
                    }
                }
                ("proposals", same) => {
                    proposal_calls += 1;
                    if same {
                        proposal_total = proposal_total.max(after.total);
                    }
                }
                _ => {}
            }
        }
        let mut report = lab.merge_report().expect("a report");
        report.timings_ms = Default::default();
        let json = serde_json::to_string(&report).expect("serialises");
        (
            json,
            decision_calls,
            seen_total,
            proposal_calls,
            proposal_total,
        )
    };
    let (whole, calls_whole, _, proposals_whole, _) = report_of(usize::MAX);
    let (cut, calls_cut, total, proposals_cut, proposals_total) = report_of(1);
    assert_eq!(proposals_whole, 1, "one call proposes every pair");
    // Five robots, over the budget's four: the vocabulary's tree, five
    // robots' words, the bags, the votes' inverted file, five robots'
    // votes, five coarse maps of two steps each (spectrum, raster), ten
    // overlaps of four quarter turns each, ten to-do lists.
    assert_eq!(proposals_total, 73, "the proposal steps");
    assert_eq!(proposals_cut, 73, "one call per proposal step");
    assert_eq!(calls_whole, 1, "one call decides every pair");
    // Five robots: ten pairs under the budget, then at least one search.
    assert!(total > 10, "the searches count as units: {total}");
    assert!(calls_cut >= 10, "one call per unit: {calls_cut}");
    assert_eq!(
        whole, cut,
        "the outcome does not depend on the units per call"
    );
}
