//! SLAM against odometry on every preset and on seeded random mazes (full
//! runs, default noise), held to the issue's targets on every robot: SLAM
//! ATE ≤ 0.10 m and ≤ 1/5 of odometry's, and ≥ 95 % of occupied cells
//! within 0.15 m of a true wall.
//!
//! The default tests run the four presets and six random mazes; the
//! ignored `issue_targets_on_thirty_more_random_mazes` runs mazes 1–30 (a
//! few minutes natively in release: `cargo test --release -p slamlab --test
//! slam_accuracy -- --include-ignored`). Figures per run are in the printed
//! lines; `crate/examples/slam_trace.rs` traces a run step by step.

mod slam_support;

use slam_support::*;
use wasm_bindgen_test::wasm_bindgen_test;

/// The issue's targets.
const MAX_ATE_M: f64 = 0.10;
const MAX_SHARE_OF_ODOMETRY: f64 = 0.2;
const MIN_PRECISION: f64 = 0.95;

fn check(label: &str, json: &str) {
    let (_, figs) = run(json, None);
    for f in figs {
        println!(
            "{label:>10} {:>7}: path {:6.1} m  ATE slam {:.3} m  odometry {:.3} m  ({:.1}x)  precision slam {:.3} odometry {:.3}  coverage {:.2}",
            f.name,
            f.path_m,
            f.slam_ate_m,
            f.odometry_ate_m,
            f.odometry_ate_m / f.slam_ate_m.max(1e-9),
            f.slam_map.occupied_precision,
            f.odometry_map.occupied_precision,
            f.slam_map.wall_coverage
        );
        assert!(
            f.slam_ate_m <= MAX_ATE_M,
            "{label}/{}: SLAM ATE {:.3} m > {MAX_ATE_M} m",
            f.name,
            f.slam_ate_m,
        );
        assert!(
            f.slam_ate_m <= MAX_SHARE_OF_ODOMETRY * f.odometry_ate_m,
            "{label}/{}: SLAM ATE {:.3} m is more than a fifth of odometry's {:.3} m",
            f.name,
            f.slam_ate_m,
            f.odometry_ate_m
        );
        assert!(
            f.slam_map.occupied_precision >= MIN_PRECISION,
            "{label}/{}: only {:.3} of occupied cells within 0.15 m of a wall",
            f.name,
            f.slam_map.occupied_precision
        );
    }
}

fn check_maze(seed: u64) {
    check(
        &format!("maze-{seed}"),
        &random_maze(seed, 6, 5, 2.5, 300.0),
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn issue_targets_on_the_thesis_preset() {
    check("thesis", PRESETS[0].1);
}

#[wasm_bindgen_test(unsupported = test)]
fn issue_targets_on_the_office_preset() {
    check("office", PRESETS[1].1);
}

#[wasm_bindgen_test(unsupported = test)]
fn issue_targets_on_the_loop_preset() {
    check("loop", PRESETS[2].1);
}

#[wasm_bindgen_test(unsupported = test)]
fn issue_targets_on_the_maze_preset() {
    check("maze", PRESETS[3].1);
}

#[wasm_bindgen_test(unsupported = test)]
fn issue_targets_on_random_mazes() {
    // 37 used to diverge (0.47 m) and 11 to miss (0.12 m); 101 and 202
    // were added after the fixes, unseen by them.
    for seed in [11, 23, 37, 101, 202] {
        check_maze(seed);
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn issue_targets_on_a_finer_maze() {
    // 8 × 6 cells of 2 m: narrower corridors, more corners per metre.
    check("maze-7/2m", &random_maze(7, 8, 6, 2.0, 300.0));
}

#[test]
#[ignore = "thirty more full runs: a few minutes natively in release"]
fn issue_targets_on_thirty_more_random_mazes() {
    for seed in 1..=30 {
        check_maze(seed);
    }
}
