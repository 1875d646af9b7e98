//! Kinematics, odometry and the range sensors.

use glam::DVec2;
use slamlab::geom::{Pose2, Segment};
use slamlab::kinematics::{integrate_wheels, wheel_speeds, P2dx, WheelState};
use slamlab::odometry::Odometry;
use slamlab::rng::Rng;
use slamlab::scenario::NoiseSpec;
use slamlab::sensors::laser::beam_bearing;
use slamlab::sensors::{Laser, RangeScene, Sonar, LASER_BEAMS};
use slamlab::world::World;
use std::f64::consts::{FRAC_PI_2, PI};
use wasm_bindgen_test::wasm_bindgen_test;

const B: f64 = P2dx::WHEEL_BASE_M;

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

#[wasm_bindgen_test(unsupported = test)]
fn equal_wheel_travel_drives_straight() {
    let p = integrate_wheels(&Pose2::new(1.0, 1.0, FRAC_PI_2), 0.5, 0.5, B);
    assert!(close(p.x, 1.0, 1e-12) && close(p.y, 1.5, 1e-12) && close(p.theta, FRAC_PI_2, 1e-12));
}

#[wasm_bindgen_test(unsupported = test)]
fn opposite_wheel_travel_spins_in_place() {
    // Each wheel rolls a quarter of the circle of diameter b: a 90° turn.
    let quarter = PI * B / 4.0;
    let p = integrate_wheels(&Pose2::IDENTITY, -quarter, quarter, B);
    assert!(p.x.abs() < 1e-12 && p.y.abs() < 1e-12);
    assert!(close(p.theta, FRAC_PI_2, 1e-12), "{}", p.theta);
}

#[wasm_bindgen_test(unsupported = test)]
fn unequal_wheel_travel_follows_an_arc_of_the_right_radius() {
    // Radius R = b/2 * (dr + dl)/(dr - dl). A half circle ends 2R to the left.
    let r = 1.0;
    let dtheta = PI;
    let (dl, dr) = ((r - B / 2.0) * dtheta, (r + B / 2.0) * dtheta);
    let p = integrate_wheels(&Pose2::IDENTITY, dl, dr, B);
    assert!(p.x.abs() < 1e-9 && close(p.y, 2.0 * r, 1e-9), "{p:?}");
    assert!(close(p.theta.abs(), PI, 1e-9));
    // Integrating in 100 small pieces lands at the same place (exact arcs).
    let mut q = Pose2::IDENTITY;
    for _ in 0..100 {
        q = integrate_wheels(&q, dl / 100.0, dr / 100.0, B);
    }
    assert!((q.position() - p.position()).length() < 1e-9);
}

#[wasm_bindgen_test(unsupported = test)]
fn wheel_speeds_respect_acceleration_limit() {
    let (l, r) = wheel_speeds(0.3, 0.0, B);
    assert_eq!((l, r), (0.3, 0.3));
    let mut w = WheelState::default();
    let (dl, _) = w.advance(0.5, 0.5, 0.1);
    // 1.5 m/s² for 0.1 s: speed 0.15, travel (0 + 0.15)/2 * 0.1.
    assert!(close(w.left_mps, 0.15, 1e-12));
    assert!(close(dl, 0.0075, 1e-12));
}

#[wasm_bindgen_test(unsupported = test)]
fn zero_noise_odometry_equals_the_truth() {
    let mut odo = Odometry::new(&NoiseSpec::zero(), Rng::new(1));
    let mut truth = Pose2::IDENTITY;
    let mut rng = Rng::new(2);
    for _ in 0..500 {
        let (dl, dr) = (rng.range(-0.02, 0.05), rng.range(-0.02, 0.05));
        truth = integrate_wheels(&truth, dl, dr, B);
        odo.update(dl, dr);
    }
    let o = odo.pose();
    assert!(
        (o.position() - truth.position()).length() < 1e-9 && (o.theta - truth.theta).abs() < 1e-9
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn odometry_slip_noise_has_the_configured_statistics() {
    // Straight 10 m in 1 cm steps; only random slip. Heading error after N
    // steps has std sqrt(N) * sqrt(2) * slip * d / b.
    let noise = NoiseSpec {
        wheel_slip: 0.02,
        ..NoiseSpec::zero()
    };
    let (n, d) = (1000usize, 0.01);
    let trials = 400;
    let mut sum = 0.0;
    let mut sum2 = 0.0;
    for k in 0..trials {
        let mut odo = Odometry::new(&noise, Rng::new(1000 + k));
        for _ in 0..n {
            odo.update(d, d);
        }
        let e = odo.pose().theta;
        sum += e;
        sum2 += e * e;
    }
    let mean = sum / trials as f64;
    let std = (sum2 / trials as f64 - mean * mean).sqrt();
    let expected = (n as f64).sqrt() * 2f64.sqrt() * 0.02 * d / B;
    assert!(
        mean.abs() < 3.0 * expected / (trials as f64).sqrt(),
        "mean {mean}"
    );
    assert!(
        close(std, expected, 0.12 * expected),
        "std {std} expected {expected}"
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn systematic_scale_error_curves_a_straight_drive() {
    // Left reads 1% more than the truth: odometry believes it turned right
    // by 0.01 * d / b radians.
    let noise = NoiseSpec {
        wheel_scale_error: [0.01, 0.0],
        ..NoiseSpec::zero()
    };
    let mut odo = Odometry::new(&noise, Rng::new(1));
    for _ in 0..100 {
        odo.update(0.01, 0.01);
    }
    assert!(
        close(odo.pose().theta, -0.01 * 1.0 / B, 1e-9),
        "{}",
        odo.pose().theta
    );
}

fn square_room() -> World {
    // 4 x 4 m room centred on the origin.
    let c = [(-2.0, -2.0), (2.0, -2.0), (2.0, 2.0), (-2.0, 2.0)];
    World::new(
        (0..4)
            .map(|i| Segment::new(DVec2::from(c[i]), DVec2::from(c[(i + 1) % 4])))
            .collect(),
    )
}

#[wasm_bindgen_test(unsupported = test)]
fn laser_ranges_in_a_square_room_match_geometry() {
    let world = square_room();
    let scene = RangeScene {
        world: &world,
        obstacles: &[],
    };
    let mut laser = Laser::new(4.0, 0.0, Rng::new(1));
    let scan = laser.scan(&scene, &Pose2::IDENTITY);
    assert_eq!(scan.ranges_m.len(), LASER_BEAMS);
    // Beam 90 straight ahead: 2 m; beams 0 and 180 to the sides: 2 m;
    // beam 45 (-45°) reaches the corner at 2√2.
    assert!(close(scan.ranges_m[90], 2.0, 1e-12));
    assert!(close(scan.ranges_m[0], 2.0, 1e-12));
    assert!(close(scan.ranges_m[180], 2.0, 1e-12));
    assert!(close(scan.ranges_m[45], 2.0 * 2f64.sqrt(), 1e-9));
    for i in 0..LASER_BEAMS {
        let a = beam_bearing(i);
        let expect = 2.0 / a.cos().abs().max(a.sin().abs());
        assert!(close(scan.ranges_m[i], expect, 1e-9), "beam {i}");
        assert!(!scan.max_range[i]);
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn laser_flags_max_range_when_nothing_is_in_reach() {
    let world = World::new(vec![Segment::new(
        DVec2::new(3.0, -10.0),
        DVec2::new(3.0, 10.0),
    )]);
    let scene = RangeScene {
        world: &world,
        obstacles: &[],
    };
    let mut laser = Laser::new(4.0, 0.05, Rng::new(3));
    let scan = laser.scan(&scene, &Pose2::IDENTITY);
    // The wall at x = 3 is within 4 m for |bearing| < acos(3/4) = 41.4°.
    for i in 0..LASER_BEAMS {
        let within = beam_bearing(i).cos() > 0.75;
        assert_eq!(scan.max_range[i], !within, "beam {i}");
        if !within {
            assert_eq!(scan.ranges_m[i], 4.0);
        }
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn laser_noise_has_the_configured_standard_deviation() {
    let world = square_room();
    let scene = RangeScene {
        world: &world,
        obstacles: &[],
    };
    let mut laser = Laser::new(4.0, 0.03, Rng::new(9));
    let mut errs = Vec::new();
    for _ in 0..200 {
        let scan = laser.scan(&scene, &Pose2::IDENTITY);
        errs.push(scan.ranges_m[90] - 2.0);
    }
    let mean = errs.iter().sum::<f64>() / errs.len() as f64;
    let std = (errs.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / errs.len() as f64).sqrt();
    assert!(mean.abs() < 0.01, "{mean}");
    assert!(close(std, 0.03, 0.006), "{std}");
}

#[wasm_bindgen_test(unsupported = test)]
fn facing_a_wall_squarely_sonars_4_and_5_read_alike() {
    let world = World::new(vec![Segment::new(
        DVec2::new(1.5, -3.0),
        DVec2::new(1.5, 3.0),
    )]);
    let scene = RangeScene {
        world: &world,
        obstacles: &[],
    };
    let mut sonar = Sonar::new(2.0, 15.0, 0.0, Rng::new(1));
    let r = sonar.read(&scene, &Pose2::IDENTITY);
    assert!(close(r.ranges_m[3], r.ranges_m[4], 1e-12));
    // Sonar 4's cone spans 2.5°..17.5°: its nearest return is the cone's
    // edge at 2.5°, (1.5 - 0.166) / cos 2.5°.
    let expect = (1.5 - 0.166) / 2.5f64.to_radians().cos();
    assert!(close(r.ranges_m[3], expect, 1e-9), "{}", r.ranges_m[3]);
    // Side sonars (1 and 8) see nothing: max range, flagged.
    assert!(r.no_echo[0] && r.no_echo[7] && r.ranges_m[0] == 2.0);
    // Turned 20°, sonars 4 and 5 differ.
    let r2 = sonar.read(&scene, &Pose2::new(0.0, 0.0, 20f64.to_radians()));
    assert!((r2.ranges_m[3] - r2.ranges_m[4]).abs() > 0.05);
}

#[wasm_bindgen_test(unsupported = test)]
fn side_sonar_reads_lateral_clearance() {
    // Wall y = 0.8 on the left: sonar 1 at y = 0.136 reads 0.664.
    let world = World::new(vec![Segment::new(
        DVec2::new(-5.0, 0.8),
        DVec2::new(5.0, 0.8),
    )]);
    let scene = RangeScene {
        world: &world,
        obstacles: &[],
    };
    let mut sonar = Sonar::new(2.0, 15.0, 0.0, Rng::new(1));
    let r = sonar.read(&scene, &Pose2::IDENTITY);
    assert!(close(r.ranges_m[0], 0.8 - 0.136, 1e-9), "{}", r.ranges_m[0]);
    assert!(r.no_echo[7]);
}

#[wasm_bindgen_test(unsupported = test)]
fn other_robots_block_rays_and_return_bright() {
    let world = square_room();
    let other = slamlab::kinematics::P2dx::body(&Pose2::new(1.0, 0.0, 0.0));
    let edges: Vec<Segment> = other.edges().collect();
    let scene = RangeScene {
        world: &world,
        obstacles: &edges,
    };
    let mut laser = Laser::new(4.0, 0.0, Rng::new(1));
    let scan = laser.scan(&scene, &Pose2::IDENTITY);
    assert!(close(scan.ranges_m[90], 1.0 - 0.2275, 1e-9));
    assert!(scan.reflective[90]);
    assert!(!scan.reflective[0]);
}
