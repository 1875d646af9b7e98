//! The scan matcher: recovers known offsets, and does not slide in a
//! featureless corridor.

use glam::DVec2;
use slamlab::geom::{Pose2, Segment};
use slamlab::rng::{Rng, Stream};
use slamlab::sensors::{Laser, RangeScene};
use slamlab::slam::grid::{GridConfig, OccupancyGrid};
use slamlab::slam::mapper::{match_scan, MatchStatus, SlamConfig};
use slamlab::world::World;
use wasm_bindgen_test::wasm_bindgen_test;

fn room() -> World {
    // A 6 × 4 m room with a pillar and an alcove: constrains every direction.
    let s = |a: [f64; 2], b: [f64; 2]| Segment::new(DVec2::from(a), DVec2::from(b));
    World::new(vec![
        s([0.0, 0.0], [6.0, 0.0]),
        s([6.0, 0.0], [6.0, 4.0]),
        s([6.0, 4.0], [3.5, 4.0]),
        s([3.5, 4.0], [3.5, 3.3]),
        s([3.5, 3.3], [2.5, 3.3]),
        s([2.5, 3.3], [2.5, 4.0]),
        s([2.5, 4.0], [0.0, 4.0]),
        s([0.0, 4.0], [0.0, 0.0]),
        s([4.0, 1.0], [4.3, 1.0]),
        s([4.3, 1.0], [4.3, 1.3]),
        s([4.3, 1.3], [4.0, 1.3]),
        s([4.0, 1.3], [4.0, 1.0]),
    ])
}

fn scan_at(world: &World, pose: &Pose2, seed: u64, noise_m: f64) -> slamlab::sensors::LaserScan {
    let scene = RangeScene {
        world,
        obstacles: &[],
    };
    Laser::new(4.0, noise_m, Rng::stream(seed, 0, Stream::Laser)).scan(&scene, pose)
}

/// Maps the room from a few poses (the map frame = the world here).
fn mapped_room(world: &World) -> OccupancyGrid {
    let mut g = OccupancyGrid::new(GridConfig::default());
    for (k, p) in [
        Pose2::new(1.5, 2.0, 0.0),
        Pose2::new(1.5, 2.0, 1.6),
        Pose2::new(1.5, 2.0, -1.6),
        Pose2::new(1.5, 2.0, 3.1),
        Pose2::new(4.5, 2.5, 0.0),
        Pose2::new(4.5, 2.5, 3.1),
    ]
    .iter()
    .enumerate()
    {
        for s in 0..5 {
            g.integrate_scan(p, &scan_at(world, p, 100 + 10 * k as u64 + s, 0.01));
        }
    }
    g
}

#[wasm_bindgen_test(unsupported = test)]
fn matcher_recovers_known_offsets() {
    let world = room();
    let map = mapped_room(&world);
    let truth = Pose2::new(2.2, 1.8, 0.3);
    let scan = scan_at(&world, &truth, 7, 0.01);
    for (dx, dy, dth) in [
        (0.0, 0.0, 0.0),
        (0.12, -0.07, 0.02),
        (-0.2, 0.15, -0.04),
        (0.05, 0.22, 0.045),
    ] {
        let prior = Pose2::new(truth.x + dx, truth.y + dy, truth.theta + dth);
        let cfg = SlamConfig::default();
        let out = match_scan(&map, &scan, &prior, &cfg);
        let e = (out.pose.position() - truth.position()).length();
        let eth = (out.pose.theta - truth.theta).abs();
        println!(
            "offset ({dx}, {dy}, {dth}): error {e:.4} m, {:.3} deg, {:?}",
            eth.to_degrees(),
            out.status
        );
        assert_eq!(out.status, MatchStatus::Matched);
        assert!(
            e < 0.025,
            "offset ({dx}, {dy}, {dth}): position error {e:.4} m"
        );
        assert!(
            eth < 0.3f64.to_radians(),
            "offset ({dx}, {dy}, {dth}): heading error {eth}"
        );
    }
}
