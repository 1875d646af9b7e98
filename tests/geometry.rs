//! Geometry and ray casting against hand-computed values.

use glam::DVec2;
use slamlab::geom::{wrap_angle, ConvexPolygon, Pose2, Segment};
use slamlab::rng::Rng;
use slamlab::world::World;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
use wasm_bindgen_test::wasm_bindgen_test;

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

fn seg(ax: f64, ay: f64, bx: f64, by: f64) -> Segment {
    Segment::new(DVec2::new(ax, ay), DVec2::new(bx, by))
}

#[wasm_bindgen_test(unsupported = test)]
fn ray_hits_wall_square_on_at_its_distance() {
    // Wall x = 3 from y = -1 to 1; ray from the origin along +x.
    let w = seg(3.0, -1.0, 3.0, 1.0);
    assert_eq!(w.ray_hit(DVec2::ZERO, DVec2::X), Some(3.0));
    // Along -x it misses (the wall is behind).
    assert_eq!(w.ray_hit(DVec2::ZERO, -DVec2::X), None);
}

#[wasm_bindgen_test(unsupported = test)]
fn oblique_ray_distance_is_d_over_cos() {
    // Wall y = 2; ray at 60 degrees from +x travels 2 / sin(60°).
    let w = seg(-10.0, 2.0, 10.0, 2.0);
    let a = 60f64.to_radians();
    let t = w
        .ray_hit(DVec2::ZERO, DVec2::new(a.cos(), a.sin()))
        .unwrap();
    assert!(close(t, 2.0 / a.sin(), 1e-12), "{t}");
}

#[wasm_bindgen_test(unsupported = test)]
fn ray_into_a_corner_hits_the_corner() {
    // Corner at (2, 2) formed by two walls; the 45° ray meets it at 2√2.
    let world = World::new(vec![seg(2.0, 2.0, 2.0, -5.0), seg(2.0, 2.0, -5.0, 2.0)]);
    let d = DVec2::new(FRAC_PI_4.cos(), FRAC_PI_4.sin());
    let hit = world.cast(DVec2::ZERO, d, 10.0).unwrap();
    assert!(
        close(hit.range_m, 2.0 * 2f64.sqrt(), 1e-9),
        "{}",
        hit.range_m
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn grazing_ray_past_a_wall_end_misses() {
    // Wall from (1, 0.5) to (1, 2): a ray along +x at y = 0.4999 passes under it.
    let w = seg(1.0, 0.5, 1.0, 2.0);
    assert_eq!(w.ray_hit(DVec2::new(0.0, 0.4999), DVec2::X), None);
    assert_eq!(w.ray_hit(DVec2::new(0.0, 0.5001), DVec2::X), Some(1.0));
    // Parallel to the wall: no return.
    assert_eq!(w.ray_hit(DVec2::new(1.0, 0.0), DVec2::Y), None);
}

#[wasm_bindgen_test(unsupported = test)]
fn nearest_of_two_walls_wins_and_max_range_limits() {
    let world = World::new(vec![seg(5.0, -1.0, 5.0, 1.0), seg(2.0, -1.0, 2.0, 1.0)]);
    let hit = world.cast(DVec2::ZERO, DVec2::X, 4.0).unwrap();
    assert_eq!(hit.range_m, 2.0);
    assert_eq!(hit.wall, Some(1));
    assert!(world.cast(DVec2::ZERO, DVec2::X, 1.5).is_none());
}

#[wasm_bindgen_test(unsupported = test)]
fn grid_index_agrees_with_brute_force_on_many_walls() {
    // 400 random walls force the grid; compare with testing every wall.
    let mut rng = Rng::new(42);
    let walls: Vec<Segment> = (0..400)
        .map(|_| {
            let a = DVec2::new(rng.range(0.0, 40.0), rng.range(0.0, 30.0));
            let ang = rng.range(0.0, 2.0 * PI);
            let len = rng.range(0.2, 5.0);
            Segment::new(a, a + DVec2::new(ang.cos(), ang.sin()) * len)
        })
        .collect();
    let world = World::new(walls.clone());
    let mut hits = 0;
    for _ in 0..3000 {
        let o = DVec2::new(rng.range(-5.0, 45.0), rng.range(-5.0, 35.0));
        let ang = rng.range(0.0, 2.0 * PI);
        let d = DVec2::new(ang.cos(), ang.sin());
        let max = rng.range(0.5, 30.0);
        let brute = walls
            .iter()
            .filter_map(|w| w.ray_hit(o, d))
            .fold(f64::INFINITY, f64::min);
        let got = world.cast(o, d, max).map(|h| h.range_m);
        if brute <= max {
            hits += 1;
            assert!(close(got.unwrap(), brute, 1e-9), "{o} {d} {got:?} {brute}");
        } else {
            assert!(got.is_none(), "{o} {d} {got:?} {brute}");
        }
    }
    assert!(hits > 1000, "the test should hit walls often: {hits}");
}

#[wasm_bindgen_test(unsupported = test)]
fn pose_composition_and_inverse() {
    let a = Pose2::new(1.0, 2.0, FRAC_PI_2);
    let b = Pose2::new(3.0, 0.0, FRAC_PI_2);
    // b in a's frame: 3 m ahead of a (which faces +y) is (1, 5), facing -x.
    let c = a.compose(&b);
    assert!(close(c.x, 1.0, 1e-12) && close(c.y, 5.0, 1e-12) && close(c.theta, PI, 1e-12));
    let id = a.compose(&a.inverse());
    assert!(id.x.abs() < 1e-12 && id.y.abs() < 1e-12 && id.theta.abs() < 1e-12);
    let back = a.between(&c);
    assert!(close(back.x, 3.0, 1e-12) && close(back.y, 0.0, 1e-12));
    let p = DVec2::new(-0.5, 7.0);
    let q = a.inverse_transform_point(a.transform_point(p));
    assert!((q - p).length() < 1e-12);
}

#[wasm_bindgen_test(unsupported = test)]
fn angles_wrap_into_half_open_pi_interval() {
    assert!(close(wrap_angle(3.0 * PI), PI, 1e-12));
    assert!(close(wrap_angle(-PI), PI, 1e-12));
    assert!(close(wrap_angle(-3.5 * PI), 0.5 * PI, 1e-12));
    assert_eq!(wrap_angle(0.25), 0.25);
}

#[wasm_bindgen_test(unsupported = test)]
fn body_rectangle_touches_only_walls_it_reaches() {
    // A 0.455 x 0.381 body at the origin facing +x: front at x = 0.2275.
    let body = ConvexPolygon::rectangle(&Pose2::IDENTITY, 0.455, 0.381);
    assert!(close(
        body.distance_to_segment(&seg(0.3, -1.0, 0.3, 1.0)),
        0.3 - 0.2275,
        1e-12
    ));
    assert_eq!(
        body.distance_to_segment(&seg(0.2275, -1.0, 0.2275, 1.0)),
        0.0
    );
    // A short wall entirely inside the body counts as touching.
    assert_eq!(body.distance_to_segment(&seg(-0.05, 0.0, 0.05, 0.0)), 0.0);
    let world = World::new(vec![seg(0.2, -0.5, 0.2, 0.5)]);
    assert!(world.body_hits_wall(&body));
}

#[wasm_bindgen_test(unsupported = test)]
fn casting_among_the_walls_within_range_answers_as_casting_among_all() {
    // Hand case: a wall square on at exactly the range is kept and hit at
    // the range; one 1 cm further is left out.
    let world = World::new(vec![seg(4.0, -1.0, 4.0, 1.0), seg(-4.01, -1.0, -4.01, 1.0)]);
    let near = world.walls_within(DVec2::ZERO, 4.0).expect("brute force");
    assert_eq!(near, vec![0]);
    let hit = world
        .cast_among(&near, DVec2::ZERO, DVec2::X, 4.0)
        .expect("hit at the range");
    assert_eq!((hit.range_m, hit.wall), (4.0, Some(0)));

    // Random walls, random scan origins, 181 rays each out to 4 m.
    let mut rng = Rng::new(11);
    let walls: Vec<Segment> = (0..40)
        .map(|_| {
            let a = DVec2::new(rng.range(0.0, 20.0), rng.range(0.0, 15.0));
            let b = a + DVec2::from_angle(rng.range(0.0, 2.0 * PI)) * rng.range(0.2, 5.0);
            Segment::new(a, b)
        })
        .collect();
    let world = World::new(walls);
    let (mut culled, mut hits) = (0, 0);
    for _ in 0..200 {
        let o = DVec2::new(rng.range(0.0, 20.0), rng.range(0.0, 15.0));
        let near = world.walls_within(o, 4.0).expect("brute force");
        culled += 40 - near.len();
        for k in 0..181 {
            let dir = DVec2::from_angle(k as f64 * PI / 180.0);
            let all = world.cast(o, dir, 4.0);
            assert_eq!(
                world.cast_among(&near, o, dir, 4.0),
                all,
                "from {o} at {k} deg"
            );
            hits += all.is_some() as usize;
        }
    }
    assert!(
        culled > 200 * 20,
        "most walls are out of range: {culled} left out"
    );
    assert!(hits > 200 * 181 / 4, "rays hit something: {hits}");
}

/// A pose's frame maps many points as the one-point methods do, exactly,
/// and rotates directions without translating them: hand values for a
/// robot at (2, 1) facing 90°.
#[wasm_bindgen_test(unsupported = test)]
fn pose_frame_maps_points_as_the_pose_does() {
    let pose = Pose2::new(2.0, 1.0, FRAC_PI_2);
    let frame = pose.frame();
    let close = |a: DVec2, b: DVec2| (a - b).length() < 1e-12;
    assert!(close(
        frame.to_parent(DVec2::new(1.0, 0.0)),
        DVec2::new(2.0, 2.0)
    ));
    assert!(close(
        frame.to_local(DVec2::new(2.0, 2.0)),
        DVec2::new(1.0, 0.0)
    ));
    assert!(close(
        frame.rotate(DVec2::new(1.0, 0.0)),
        DVec2::new(0.0, 1.0)
    ));
    assert!(close(
        frame.rotate(DVec2::new(0.0, 3.0)),
        DVec2::new(-3.0, 0.0)
    ));
    let mut rng = Rng::new(5);
    for _ in 0..1000 {
        let pose = Pose2::new(
            rng.range(-50.0, 50.0),
            rng.range(-50.0, 50.0),
            rng.range(-PI, PI),
        );
        let p = DVec2::new(rng.range(-10.0, 10.0), rng.range(-10.0, 10.0));
        let frame = pose.frame();
        assert_eq!(frame.to_parent(p), pose.transform_point(p));
        assert_eq!(frame.to_local(p), pose.inverse_transform_point(p));
        assert!(close(frame.to_local(frame.to_parent(p)), p));
    }
}

/// The sensors' finer grid ([`World::cast_range`]) finds the same range as
/// the world's own grid, bit for bit, in a world of long walls (a maze's
/// runs, where the own grid's cells are several metres wide), including
/// rays through the points where walls meet.
#[wasm_bindgen_test(unsupported = test)]
fn the_sensors_grid_finds_the_same_ranges_as_the_worlds() {
    let mut walls = Vec::new();
    for k in 0..=20 {
        let v = 3.0 * k as f64;
        walls.push(seg(0.0, v, 60.0, v));
        walls.push(seg(v, 0.0, v, 60.0));
    }
    let mut rng = Rng::new(5);
    for _ in 0..40 {
        let a = DVec2::new(rng.range(0.0, 60.0), rng.range(0.0, 60.0));
        walls.push(Segment::new(
            a,
            a + DVec2::from_angle(rng.range(0.0, 2.0 * PI)) * 4.0,
        ));
    }
    let world = World::new(walls);
    let (mut hits, mut corners) = (0, 0);
    for i in 0..400 {
        // Every fourth ray from a lattice point: through wall junctions.
        let o = if i % 4 == 0 {
            DVec2::new(3.0 * (i % 19) as f64 + 1.5, 3.0 * (i % 17) as f64 + 1.5)
        } else {
            DVec2::new(rng.range(0.0, 60.0), rng.range(0.0, 60.0))
        };
        for k in 0..181 {
            let dir = DVec2::from_angle(k as f64 * PI / 90.0);
            let range = |h: Option<slamlab::world::RayHit>| h.map(|h| h.range_m.to_bits());
            let own = world.cast(o, dir, 4.0);
            assert_eq!(range(world.cast_range(o, dir, 4.0)), range(own), "{o} {k}");
            hits += own.is_some() as usize;
            corners += (i % 4 == 0 && k % 45 == 0 && own.is_some()) as usize;
        }
    }
    assert!(hits > 400 * 181 / 2, "rays hit walls: {hits}");
    assert!(corners > 100, "rays through junctions: {corners}");
}

#[wasm_bindgen_test(unsupported = test)]
fn the_aligned_ate_forgives_a_turned_map_the_start_aligned_does_not() {
    use slamlab::slam::eval::scoring::{ate_aligned_m, ate_m};
    // The truth: 11 poses along y = 0 from x = 0 to 10, start at (2, 3).
    // The estimate (odometry frame, origin at the start) turned by 1°
    // about the start, as a heading error before the first wall would.
    let start = Pose2::new(2.0, 3.0, 0.0);
    let turn = 1f64.to_radians();
    let truth: Vec<Pose2> = (0..=10)
        .map(|k| Pose2::new(2.0 + k as f64, 3.0, 0.0))
        .collect();
    let turned: Vec<Pose2> = (0..=10)
        .map(|k| Pose2::new(k as f64 * turn.cos(), k as f64 * turn.sin(), turn))
        .collect();
    // Start-aligned: point k is off by 2 k sin(0.5°); RMSE over k = 0..10
    // is 2 sin(0.5°) √(Σk² / 11) = 2 sin(0.5°) √35.
    let expected = 2.0 * (0.5f64.to_radians()).sin() * 35f64.sqrt();
    assert!(close(ate_m(&start, &turned, &truth), expected, 1e-12));
    // Aligned: the rotation is undone exactly.
    assert!(ate_aligned_m(&start, &turned, &truth) < 1e-12);
    // A bend is not a rigid motion: the last five points 0.1 m off sideways.
    // The best fit leaves a residual, less than the start-aligned error.
    let bent: Vec<Pose2> = (0..=10)
        .map(|k| Pose2::new(k as f64, if k > 5 { 0.1 } else { 0.0 }, 0.0))
        .collect();
    let (aligned, anchored) = (
        ate_aligned_m(&start, &bent, &truth),
        ate_m(&start, &bent, &truth),
    );
    assert!(close(anchored, 0.1 * (5.0f64 / 11.0).sqrt(), 1e-12));
    assert!(
        aligned > 0.01 && aligned < anchored,
        "{aligned} vs {anchored}"
    );
    assert_eq!(ate_aligned_m(&start, &[], &truth), 0.0);
}
