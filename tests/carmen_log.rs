//! The CARMEN log reader on hand-written logs: FLASER geometry and the
//! no-return value, ROBOTLASER1's own geometry and laser offset, RAWLASER1
//! odometry interpolated from ODOM records, gzip, skipped records counted,
//! and malformed lines refused with their line number; the log SLAM's map
//! resolution and its weak matches.

use slamlab::formats::carmen::{parse_bytes, parse_str};
use std::f64::consts::{FRAC_PI_2, PI};
use std::io::Write;
use wasm_bindgen_test::wasm_bindgen_test;

fn flaser(ranges: &[f64], pose: [f64; 3], odom: [f64; 3], t: f64) -> String {
    let r: Vec<String> = ranges.iter().map(|v| v.to_string()).collect();
    format!(
        "FLASER {} {} {} {} {} {} {} {} {t} host {t}",
        ranges.len(),
        r.join(" "),
        pose[0],
        pose[1],
        pose[2],
        odom[0],
        odom[1],
        odom[2]
    )
}

#[wasm_bindgen_test(unsupported = test)]
fn flaser_geometry_poses_and_no_return() {
    let text = [
        "# a comment".to_string(),
        "PARAM robot_frontlaser_offset 0.0 nohost 0".into(),
        flaser(&[1.0, 2.0, 81.91], [1.0, 2.0, 0.5], [1.5, 2.5, 0.25], 10.0),
        "NEFF 30".into(),
        flaser(&[3.0, 81.91, 0.0, 4.0], [0.0; 3], [0.0; 3], 11.0),
        "RLASER 2 1 1 0 0 0 0 0 0 12 host 12".into(),
    ]
    .join("\n");
    let log = parse_str(&text).unwrap();
    assert_eq!(log.scans.len(), 2);
    let a = &log.scans[0];
    assert_eq!((a.index, a.line, a.time), (0, 3, 10.0));
    // Ranges as float32, as a ROS LaserScan stores them (the canonical
    // form every reader hands the SLAM).
    assert_eq!(&a.ranges[..], &[1.0, 2.0, 81.91f32]);
    // Odd count: beams at both ends, 90° apart for 3 beams.
    assert!((a.bearing(0) + FRAC_PI_2).abs() < 1e-12);
    assert!((a.bearing(2) - FRAC_PI_2).abs() < 1e-12);
    assert_eq!(a.logged_pose.unwrap().x, 1.0);
    assert_eq!(
        (a.odometry.x, a.odometry.y, a.odometry.theta),
        (1.5, 2.5, 0.25)
    );
    // The log's largest range is the no-return value; zero is no return too.
    assert_eq!(a.max_range, 81.91f32 as f64);
    assert_eq!(
        (0..3).map(|i| a.no_return(i)).collect::<Vec<_>>(),
        vec![false, false, true]
    );
    let b = &log.scans[1];
    // Even count: 180° / n steps from −90°.
    assert!((b.angle_step - PI / 4.0).abs() < 1e-12);
    assert_eq!(
        (0..4).map(|i| b.no_return(i)).collect::<Vec<_>>(),
        vec![false, true, true, false]
    );
    assert_eq!(
        log.params,
        vec![("robot_frontlaser_offset".into(), "0.0".into())]
    );
    assert_eq!(
        log.skipped,
        vec![
            ("comment".into(), 1),
            ("NEFF".into(), 1),
            ("RLASER".into(), 1)
        ]
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn robotlaser1_geometry_and_laser_offset() {
    // type start fov res maxrange accuracy remission n r.. m e.. laser pose, robot pose,
    // tv rv fwd side turn ts host ts
    let line = "ROBOTLASER1 0 -1.0 2.0 0.5 30.0 0.01 0 5 1 2 3 30 5 2 7 7 \
                1.2 3.0 0.6 1.0 3.0 0.5 0 0 0 0 0 99.5 host 99.5";
    let log = parse_str(line).unwrap();
    let s = &log.scans[0];
    assert_eq!(&s.ranges[..], &[1.0, 2.0, 3.0, 30.0, 5.0]);
    assert_eq!(
        (s.start_angle, s.angle_step, s.max_range),
        (-1.0, 0.5, 30.0)
    );
    assert!((s.bearing(4) - 1.0).abs() < 1e-12);
    assert!(s.no_return(3) && !s.no_return(4));
    assert_eq!(
        (s.odometry.x, s.odometry.y, s.odometry.theta),
        (1.0, 3.0, 0.5)
    );
    assert_eq!(s.time, 99.5);
    // Laser at (1.2, 3.0, 0.6) seen from the robot at (1, 3, 0.5), facing 0.5 rad:
    // 0.2 m along x of the world is (0.2 cos 0.5, −0.2 sin 0.5) in the robot frame.
    // (Poses leave the reader rounded to the micrometre and microradian.)
    let o = s.laser_offset;
    assert!((o.x - 0.2 * 0.5f64.cos()).abs() <= 5e-7);
    assert!((o.y + 0.2 * 0.5f64.sin()).abs() <= 5e-7);
    assert!((o.theta - 0.1).abs() <= 5e-7);
}

#[wasm_bindgen_test(unsupported = test)]
fn rawlaser1_odometry_interpolated_between_odom_records() {
    let text = "ODOM 0 0 0 0 0 0 10.0 host 10.0\n\
                RAWLASER1 0 -1.5708 3.1416 1.5708 20 0.01 0 3 1 2 3 0 12.5 host 12.5\n\
                ODOM 2 4 1.0 0 0 0 20.0 host 20.0\n\
                RAWLASER1 0 -1.5708 3.1416 1.5708 20 0.01 0 3 1 2 3 0 25.0 host 25.0\n";
    let log = parse_str(text).unwrap();
    assert_eq!(log.odometry_records, 2);
    let a = log.scans[0].odometry;
    // A quarter of the way from 10 s to 20 s.
    assert!((a.x - 0.5).abs() < 1e-12 && (a.y - 1.0).abs() < 1e-12);
    assert!((a.theta - 0.25).abs() < 1e-12);
    // After the last ODOM: that one.
    let b = log.scans[1].odometry;
    assert_eq!((b.x, b.y, b.theta), (2.0, 4.0, 1.0));
    assert!(log.scans[0].logged_pose.is_none());
}

#[wasm_bindgen_test(unsupported = test)]
fn gzip_compressed_logs_read_like_plain_ones() {
    let text = format!(
        "{}\n{}\n",
        flaser(&[1.0, 2.0, 3.0], [0.0; 3], [0.0; 3], 1.0),
        flaser(&[1.5, 2.5, 3.5], [0.1, 0.0, 0.0], [0.1, 0.0, 0.0], 2.0)
    );
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    gz.write_all(text.as_bytes()).unwrap();
    let bytes = gz.finish().unwrap();
    assert_eq!(&bytes[..2], &[0x1f, 0x8b]);
    assert_eq!(parse_bytes(&bytes).unwrap(), parse_str(&text).unwrap());
    // A cut-off gzip stream is an error, not a shorter log.
    let e = parse_bytes(&bytes[..bytes.len() - 12]).unwrap_err();
    assert!(e.to_string().contains("gzip"), "{e}");
}

#[wasm_bindgen_test(unsupported = test)]
fn bad_and_truncated_lines_name_their_line() {
    let good = flaser(&[1.0, 2.0, 3.0], [0.0; 3], [0.0; 3], 1.0);
    let cases = [
        // Fewer ranges than announced (cut off mid-line).
        (format!("{good}\nFLASER 3 1.0 2.0"), 2, "truncated"),
        // A range that is not a number.
        (
            format!("# c\n{good}\n{}", good.replace("2 3", "2 x")),
            3,
            "not a number",
        ),
        // The beam count is not a count.
        (format!("{good}\nFLASER three 1 2 3"), 2, "not a beam count"),
        // The odometry pose is missing.
        ("FLASER 3 1 2 3 0 0 0".to_string(), 1, "truncated"),
        // ODOM without its timestamp.
        (format!("{good}\n\nODOM 1 2 3"), 3, "truncated"),
        // ROBOTLASER1 whose field of view does not fit its beams.
        (
            "ROBOTLASER1 0 -1.0 2.0 0.1 30.0 0.01 0 3 1 2 3 0 0 0 0 0 0 0 0 0 0 0 0 1 h 1"
                .to_string(),
            1,
            "field of view",
        ),
        // A laser-free log.
        ("ODOM 0 0 0 0 0 0 1 h 1".to_string(), 0, "no laser records"),
    ];
    for (text, line, words) in cases {
        let e = parse_str(&text).unwrap_err();
        assert_eq!(e.line, line, "{text:?}: {e}");
        assert!(e.to_string().contains(words), "{e}");
        if line > 0 {
            assert!(e.to_string().starts_with(&format!("line {line}:")), "{e}");
        }
    }
    let e = parse_bytes(b"FLASER 1 \xff\xfe").unwrap_err();
    assert_eq!(e.line, 1);
}

/// A log whose robot is seen at two places 300 m apart (a campus toured
/// outdoors): at 5 cm its map would need 6,200 × 6,200 cells, past the
/// 16 Mi a log's map may hold, so it is drawn at 10 cm, whole: nothing is
/// dropped, and the corridor walls at both places are in it.
#[wasm_bindgen_test(unsupported = test)]
fn a_tour_too_big_for_5_cm_is_mapped_whole_at_10_cm() {
    use slamlab::lab::log_replay::LogReplay;
    use slamlab::slam::CellState;
    // 181 beams over 180°: walls 1.5 m either side, nothing ahead.
    let ranges: Vec<f64> = (0..181)
        .map(|i| {
            let s = ((i as f64 - 90.0).to_radians()).sin().abs();
            if s > 0.1 {
                1.5 / s
            } else {
                81.91
            }
        })
        .collect();
    let mut lines = Vec::new();
    for (k, x) in [0.0, 0.5, 1.0, 300.0, 300.5, 301.0].iter().enumerate() {
        let y = if *x > 100.0 { 300.0 } else { 0.0 };
        lines.push(flaser(&ranges, [*x, y, 0.0], [*x, y, 0.0], k as f64));
    }
    let mut replay = LogReplay::new(lines.join("\n").as_bytes()).unwrap();
    replay.finish().unwrap();
    let map = replay.map().unwrap();
    assert_eq!(map.resolution_m(), 0.1);
    assert_eq!(map.dropped_updates(), 0);
    assert!(map.width() * map.height() <= slamlab::slam::logs::logslam::MAP_MAX_CELLS);
    // Beside each place (the first scan's pose, then the fourth's), 1.5 m
    // to its left, the wall: on a cell boundary, so in the cell above it or
    // the one below.
    for p in [[0.5, 1.5], [300.5, 301.5]] {
        let occupied = [0.02, -0.02].iter().any(|dy| {
            let [gx, gy] = map.global_cell(glam::DVec2::new(p[0], p[1] + dy));
            let (x, y) = map.local([gx, gy]).expect("inside the map");
            map.state(x, y) == CellState::Occupied
        });
        assert!(occupied, "wall at {p:?}");
    }
}

/// The map's resolution is the finest power-of-two multiple of 5 cm that
/// fits the tour: a 100 m tour stays at 5 cm; 300 m goes to 10 cm; 2 km
/// to 80 cm (all with 20 m of reach around the poses).
#[wasm_bindgen_test(unsupported = test)]
fn the_log_map_resolution_grows_with_the_tour() {
    use glam::DVec2;
    use slamlab::slam::logs::logslam::{map_resolution, MAP_MAX_CELLS};
    let tour = |side: f64| [DVec2::ZERO, DVec2::splat(side)].into_iter();
    assert_eq!(map_resolution(0.05, tour(100.0), 20.0, MAP_MAX_CELLS), 0.05);
    assert_eq!(map_resolution(0.05, tour(300.0), 20.0, MAP_MAX_CELLS), 0.1);
    assert_eq!(map_resolution(0.05, tour(2000.0), 20.0, MAP_MAX_CELLS), 0.8);
    assert_eq!(
        map_resolution(0.05, std::iter::empty(), 20.0, MAP_MAX_CELLS),
        0.05
    );
}

/// A scan of the box room `x ∈ [−3, 5]`, `y ∈ [−2, 3]` from `pose`, 181
/// beams over 180°; beams with `cluttered(i)` instead hit something 0.6–0.9 m
/// away that no earlier scan saw (people around the robot).
fn room_scan(
    index: usize,
    pose: slamlab::geom::Pose2,
    odometry: slamlab::geom::Pose2,
    cluttered: impl Fn(usize) -> bool,
) -> slamlab::slam::logs::LogScan {
    let ranges = (0..181)
        .map(|i| {
            if cluttered(i) {
                return 0.6 + 0.3 * (i as f64 * 0.7).sin().abs();
            }
            let a = pose.theta + (i as f64 - 90.0).to_radians();
            let (c, s) = (a.cos(), a.sin());
            // The nearest of the four walls along the beam.
            let mut r = f64::INFINITY;
            for (d, p, wall) in [
                (c, pose.x, 5.0),
                (c, pose.x, -3.0),
                (s, pose.y, 3.0),
                (s, pose.y, -2.0),
            ] {
                let t = (wall - p) / d;
                if t > 0.0 {
                    r = r.min(t);
                }
            }
            r
        })
        .map(|r: f64| r as f32)
        .collect();
    slamlab::slam::logs::LogScan {
        index,
        line: index + 1,
        time: index as f64,
        start_angle: -FRAC_PI_2,
        angle_step: PI / 180.0,
        max_range: 81.91,
        ranges,
        odometry,
        logged_pose: None,
        laser_offset: slamlab::geom::Pose2::IDENTITY,
    }
}

/// A scan that fits the map only poorly (most of its beams on clutter no
/// earlier scan saw, its match scoring under `min_match_score`) but near
/// where the odometry put it is placed by its match, not left on the
/// odometry's error; with `weak_match_score` 0 it keeps the odometry's pose.
#[wasm_bindgen_test(unsupported = test)]
fn a_weak_match_near_the_prediction_beats_the_odometry() {
    use slamlab::geom::Pose2;
    use slamlab::slam::logs::logslam::{LogSlam, LogSlamConfig};
    let truth = |k: usize| Pose2::new(0.4 * k as f64, 0.0, 0.0);
    // The odometry is right but at the last scan, 0.12 m and 2° off.
    let odometry = |k: usize| {
        if k == 4 {
            Pose2::new(1.7, -0.05, 2f64.to_radians())
        } else {
            truth(k)
        }
    };
    let place = |weak: f64| {
        let mut slam = LogSlam::new(LogSlamConfig {
            weak_match_score: weak,
            // The step as the replay placed it: the smoothing after the
            // replay would align the well-matched scan 3 again but leave
            // the weak scan 4 alone.
            smooth_keys: 0,
            ..LogSlamConfig::default()
        });
        let mut scans: Vec<_> = (0..4)
            .map(|k| room_scan(k, truth(k), odometry(k), |_| false))
            .collect();
        // Seven beams in ten on clutter.
        scans.push(room_scan(4, truth(4), odometry(4), |i| i % 10 < 7));
        for scan in &scans {
            slam.add_scan(scan);
        }
        slam.finish(&scans).unwrap();
        // The last step as the SLAM has it.
        let p = slam.poses();
        p[3].between(&p[4])
    };
    // The true step is 0.4 m straight ahead; the odometry's 0.5 m, 0.05 m
    // aside and 2° turned.
    let matched = place(LogSlamConfig::default().weak_match_score);
    assert!(
        (matched.x - 0.4).abs() < 0.01
            && matched.y.abs() < 0.01
            && matched.theta.abs() < 0.3f64.to_radians(),
        "weak match: {matched:?}"
    );
    let kept = place(0.0);
    let step = odometry(3).between(&odometry(4));
    assert!(
        (kept.x - step.x).abs() < 1e-9
            && (kept.y - step.y).abs() < 1e-9
            && (kept.theta - step.theta).abs() < 1e-9,
        "without weak matches the odometry's step is kept: {kept:?}, odometry {step:?}"
    );
}

/// The smoothing after the replay (the log SLAM's step 7) makes the scans
/// agree with one another: in the box room, scanned every 0.12 m along a
/// gentle curve with exact odometry, the relative pose of every two scans
/// three apart errs less after it than as the replay left it.
#[wasm_bindgen_test(unsupported = test)]
fn smoothing_makes_nearby_scans_agree() {
    use slamlab::geom::Pose2;
    use slamlab::slam::logs::logslam::{LogSlam, LogSlamConfig};
    let truth = |k: usize| {
        let k = k as f64;
        Pose2::new(
            -2.0 + 0.12 * k,
            0.3 * (0.15 * k).sin(),
            0.1 * (0.15 * k).cos(),
        )
    };
    let scans: Vec<_> = (0..50)
        .map(|k| room_scan(k, truth(k), truth(k), |_| false))
        .collect();
    // Mean error (m, rad) of the relative poses of scans k and k + 3.
    let errors = |smooth_keys: usize| {
        let mut slam = LogSlam::new(LogSlamConfig {
            smooth_keys,
            ..LogSlamConfig::default()
        });
        for scan in &scans {
            slam.add_scan(scan);
        }
        slam.finish(&scans).unwrap();
        let p = slam.poses();
        let n = p.len() - 3;
        let (mut m, mut r) = (0.0, 0.0);
        for k in 0..n {
            let e = truth(k)
                .between(&truth(k + 3))
                .between(&p[k].between(&p[k + 3]));
            m += e.position().length() / n as f64;
            r += e.theta.abs() / n as f64;
        }
        (m, r)
    };
    let (before, after) = (errors(0), errors(10));
    // Measured: 6.1 mm and 0.085° before, 3.3 mm and 0.060° after.
    assert!(
        after.0 < 0.75 * before.0 && after.0 < 0.005 && after.1 <= before.1,
        "before {before:?}, after {after:?} (m, rad)"
    );
}

/// A key edge's information (`key_edge_information`, the log SLAM's key
/// edges without odometry): from a corridor's scan, whose surface normals
/// all point across it, the variance along the corridor is
/// `key_loosen_ratio` times that across, in the frame of the key however
/// it is turned; a box room's scan pins both directions alike.
#[wasm_bindgen_test(unsupported = test)]
fn a_corridor_key_edge_is_loose_along_the_corridor() {
    use glam::DVec2;
    use slamlab::geom::Pose2;
    use slamlab::slam::logs::logslam::{key_edge_information, LogSlamConfig};
    let cfg = LogSlamConfig::default();
    let (sm, sr, ratio) = (cfg.key_sigma_m, cfg.key_sigma_rad, cfg.key_loosen_ratio);
    // Walls at y = −1.2 and y = 1 (robot frame), a point every 0.1 m, in
    // the order a laser sweeps them.
    let corridor: Vec<DVec2> = (-60..=60)
        .map(|k| DVec2::new(0.1 * k as f64, -1.2))
        .chain((-60..=60).rev().map(|k| DVec2::new(0.1 * k as f64, 1.0)))
        .collect();
    for theta in [0.0, 0.7, -2.0] {
        let pose = Pose2::new(3.0, -1.0, theta);
        let info = key_edge_information(&corridor, &pose, sm, sr, ratio).expect("loosened");
        // Along the key's x (the corridor) and across it (y).
        assert!(
            (info[0][0] * ratio * sm * sm - 1.0).abs() < 1e-3,
            "{theta}: {info:?}"
        );
        assert!(
            (info[1][1] * sm * sm - 1.0).abs() < 1e-6,
            "{theta}: {info:?}"
        );
        assert!(info[0][1].abs() < 1e-6 && (info[2][2] * sr * sr - 1.0).abs() < 1e-6);
    }
    // The box room x ∈ [−3, 5], y ∈ [−2, 3] seen from the origin.
    let scan = room_scan(0, Pose2::IDENTITY, Pose2::IDENTITY, |_| false);
    let room: Vec<DVec2> = scan
        .ranges
        .iter()
        .enumerate()
        .map(|(i, &r)| {
            let a = scan.start_angle + i as f64 * scan.angle_step;
            DVec2::new(a.cos(), a.sin()) * r as f64
        })
        .collect();
    let info = key_edge_information(&room, &Pose2::IDENTITY, sm, sr, ratio);
    let (along, across) = info.map_or((1.0, 1.0), |m| (m[0][0].min(m[1][1]), m[0][0].max(m[1][1])));
    assert!(along * 4.0 >= across, "{info:?}");
    // One σ for all when the ratio is off.
    assert!(key_edge_information(&corridor, &Pose2::IDENTITY, sm, sr, 1.0).is_none());
}
