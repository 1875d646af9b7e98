//! The pose graph against hand-computed solutions, the relation-error
//! scoring and the drifting odometry's model.

use slamlab::geom::Pose2;
use slamlab::slam::eval::relations::{drift_odometry, relation_errors, DriftModel};
use slamlab::slam::posegraph::{Edge, PoseGraph};
use std::f64::consts::FRAC_PI_2;
use wasm_bindgen_test::wasm_bindgen_test;

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

#[wasm_bindgen_test(unsupported = test)]
fn a_corridor_loop_spreads_its_error_evenly() {
    // Three steps of 1 m measured, and a closure saying the end is 2.7 m
    // from the start: all four edges alike, so each takes a quarter of the
    // 0.3 m disagreement. By hand: x1 = 0.925, x2 = 1.85, x3 = 2.775.
    let mut g = PoseGraph {
        nodes: vec![
            Pose2::IDENTITY,
            Pose2::new(1.0, 0.0, 0.0),
            Pose2::new(2.0, 0.0, 0.0),
            Pose2::new(3.0, 0.0, 0.0),
        ],
        edges: vec![],
    };
    for i in 0..3 {
        g.edges
            .push(Edge::new(i, i + 1, Pose2::new(1.0, 0.0, 0.0), 0.1, 0.01));
    }
    g.edges
        .push(Edge::new(0, 3, Pose2::new(2.7, 0.0, 0.0), 0.1, 0.01));
    g.optimise(10).unwrap();
    for (k, x) in [0.0, 0.925, 1.85, 2.775].into_iter().enumerate() {
        let p = g.nodes[k];
        assert!(
            close(p.x, x, 1e-9) && close(p.y, 0.0, 1e-9),
            "node {k}: {p:?}"
        );
        assert!(close(p.theta, 0.0, 1e-9));
    }
    // Each edge is off by 0.075 m at σ = 0.1 m: χ² = 4 · 0.5625.
    assert!(close(g.total_chi2(), 2.25, 1e-9), "{}", g.total_chi2());
}

#[wasm_bindgen_test(unsupported = test)]
fn a_closure_between_two_free_nodes_spreads_over_its_loop_either_way_round() {
    // Steps of 1 m from node 0 to node 3, and a closure saying node 3 is
    // 1.8 m from node 1: the loop 1-2-3 takes the 0.2 m, a third on each of
    // its three edges, and the step from the fixed node 0 none. By hand:
    // x1 = 1, x2 = 1 + 14/15, x3 = 1 + 28/15; χ² = 3 · (0.2/3 / 0.1)² = 4/3.
    // Written 3 → 1 the closure's blocks fall on the other side of H's
    // diagonal; the answer is the same.
    for backwards in [false, true] {
        let mut g = PoseGraph {
            nodes: (0..4).map(|k| Pose2::new(k as f64, 0.0, 0.0)).collect(),
            edges: vec![],
        };
        for i in 0..3 {
            g.edges
                .push(Edge::new(i, i + 1, Pose2::new(1.0, 0.0, 0.0), 0.1, 0.01));
        }
        g.edges.push(if backwards {
            Edge::new(3, 1, Pose2::new(-1.8, 0.0, 0.0), 0.1, 0.01)
        } else {
            Edge::new(1, 3, Pose2::new(1.8, 0.0, 0.0), 0.1, 0.01)
        });
        g.optimise(10).unwrap();
        let want = [0.0, 1.0, 1.0 + 14.0 / 15.0, 1.0 + 28.0 / 15.0];
        for (k, x) in want.into_iter().enumerate() {
            let p = g.nodes[k];
            assert!(
                close(p.x, x, 1e-9) && close(p.y, 0.0, 1e-9) && close(p.theta, 0.0, 1e-9),
                "backwards {backwards}, node {k}: {p:?}"
            );
        }
        assert!(close(g.total_chi2(), 4.0 / 3.0, 1e-9), "{}", g.total_chi2());
    }
}

fn square_truth() -> Vec<Pose2> {
    vec![
        Pose2::new(0.0, 0.0, 0.0),
        Pose2::new(2.0, 0.0, FRAC_PI_2),
        Pose2::new(2.0, 2.0, 2.0 * FRAC_PI_2),
        Pose2::new(0.0, 2.0, -FRAC_PI_2),
    ]
}

#[wasm_bindgen_test(unsupported = test)]
fn a_square_loop_with_a_closure_comes_back_to_the_square() {
    // Exact measurements of a 2 m square (turning left at each corner) and
    // the closure from the last corner back to the first; the start guess is
    // dead reckoning with a heading error of 10° per corner.
    let truth = square_truth();
    let step = Pose2::new(2.0, 0.0, FRAC_PI_2);
    let mut guess = vec![Pose2::IDENTITY];
    for k in 1..4 {
        let bent = Pose2::new(2.0, 0.0, FRAC_PI_2 + 10f64.to_radians());
        guess.push(guess[k - 1].compose(&bent));
    }
    let mut g = PoseGraph {
        nodes: guess,
        edges: vec![],
    };
    for i in 0..3 {
        g.edges.push(Edge::new(i, i + 1, step, 0.05, 0.02));
    }
    g.edges.push(Edge::new(3, 0, step, 0.05, 0.02));
    let steps = g.optimise(20).unwrap();
    assert!(steps < 20, "Gauss–Newton should converge");
    for (p, t) in g.nodes.iter().zip(&truth) {
        assert!(p.position().distance(t.position()) < 1e-7, "{p:?} vs {t:?}");
        assert!(slamlab::geom::wrap_angle(p.theta - t.theta).abs() < 1e-7);
    }
    assert!(g.total_chi2() < 1e-10);
}

#[wasm_bindgen_test(unsupported = test)]
fn a_closure_pulls_drifted_poses_back_and_node_zero_stays() {
    // Odometry edges measured 5 % long around the square, a closure that
    // is exact and much more certain: the optimum honours the closure, the
    // total disagreement drops, and node 0 does not move.
    let truth = square_truth();
    let long = Pose2::new(2.1, 0.0, FRAC_PI_2);
    let mut g = PoseGraph {
        nodes: vec![Pose2::IDENTITY],
        edges: vec![],
    };
    for k in 1..4 {
        let p = g.nodes[k - 1].compose(&long);
        g.nodes.push(p);
        g.edges.push(Edge::new(k - 1, k, long, 0.1, 0.01));
    }
    let mut closure = Edge::new(3, 0, Pose2::new(2.0, 0.0, FRAC_PI_2), 0.001, 0.001);
    closure.loop_closure = true;
    g.edges.push(closure);
    let before = g.total_chi2();
    assert!(close(
        g.nodes[3].position().distance(truth[3].position()),
        0.1,
        1e-9
    ));
    g.optimise(20).unwrap();
    assert_eq!(g.nodes[0], Pose2::IDENTITY);
    assert!(
        g.total_chi2() < before / 10.0,
        "{before} -> {}",
        g.total_chi2()
    );
    // The closure holds: node 0 seen from node 3 is where it said.
    let seen = g.nodes[3].between(&g.nodes[0]);
    assert!(close(seen.x, 2.0, 0.01) && close(seen.y, 0.0, 0.01));
}

#[wasm_bindgen_test(unsupported = test)]
fn relation_errors_by_hand() {
    // Estimate = reference with node 2 shifted 0.1 m sideways: relations
    // (1,2) and (2,3) are off by 0.1 m, (0,1) not at all.
    let reference: Vec<Pose2> = (0..4).map(|i| Pose2::new(i as f64, 0.0, 0.0)).collect();
    let mut est = reference.clone();
    est[2].y = 0.1;
    let e = relation_errors(&est, &reference, 10, 3);
    assert_eq!(e[0].pairs_of, "k=1");
    assert_eq!(e[0].pairs, 3);
    assert!(close(e[0].trans_m, 0.2 / 3.0, 1e-12));
    assert!(close(e[0].rot_deg, 0.0, 1e-12));
    let all = e.last().unwrap();
    assert_eq!(all.pairs_of, "all");
    // A perfect estimate scores zero everywhere.
    for r in relation_errors(&reference, &reference, 10, 3) {
        assert_eq!((r.trans_m, r.rot_deg), (0.0, 0.0));
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn drifting_odometry_follows_its_model() {
    // A straight 100 m drive in 0.5 m steps: with only the bias switched
    // on, the heading turns by exactly bias · distance.
    let reference: Vec<Pose2> = (0..=200)
        .map(|i| Pose2::new(0.5 * i as f64, 0.0, 0.0))
        .collect();
    let bias_only = DriftModel {
        trans_per_m: 0.0,
        rot_per_rad: 0.0,
        heading_per_m: 0.0,
        bias_rad_per_m: 0.001,
        distance_error: 0.0,
    };
    let o = drift_odometry(&reference, &bias_only, 1);
    assert!(close(o[200].theta, 0.1, 1e-9), "{:?}", o[200]);
    // A distance error alone: 100 m driven read as 98 m, straight on.
    let short = DriftModel {
        bias_rad_per_m: 0.0,
        distance_error: -0.02,
        ..bias_only
    };
    let o = drift_odometry(&reference, &short, 1);
    assert!(
        close(o[200].x, 98.0, 1e-9) && close(o[200].y, 0.0, 1e-12),
        "{:?}",
        o[200]
    );
    // Noise is seeded: the same seed, the same odometry; another, another.
    let m = DriftModel::default();
    assert_eq!(
        drift_odometry(&reference, &m, 5),
        drift_odometry(&reference, &m, 5)
    );
    assert_ne!(
        drift_odometry(&reference, &m, 5),
        drift_odometry(&reference, &m, 6)
    );
}

/// The point-by-point tables of `multires::field_from_points` against
/// their definitions, computed by brute force: fine = max over points of
/// `w(dx)·w(dy)` (|dx|, |dy| ≤ 2, `w(d) = exp(−d²/2)`), coarse = maximum of
/// fine over the block `[c, c + k)²`.
#[wasm_bindgen_test(unsupported = test)]
fn point_tables_match_their_definition() {
    use slamlab::slam::multires::field_from_points;
    let w = |d: i64| match d.abs() {
        0 => 1.0f32,
        1 => 0.606_530_66,
        2 => 0.135_335_28,
        _ => 0.0,
    };
    let points: Vec<glam::DVec2> = [(0.01, 0.02), (0.12, 0.02), (0.33, -0.21), (-0.4, 0.5)]
        .iter()
        .map(|&(x, y)| glam::DVec2::new(x, y))
        .collect();
    let cells: Vec<[i64; 2]> = points
        .iter()
        .map(|p| [(p.x / 0.05).floor() as i64, (p.y / 0.05).floor() as i64])
        .collect();
    for k in [1usize, 4, 8] {
        let f = field_from_points(&points, 0.05, k, 0.2);
        let fine = |x: i64, y: i64| {
            cells
                .iter()
                .map(|c| w(x - c[0]) * w(y - c[1]))
                .fold(0f32, f32::max)
        };
        let mut nonzero = 0;
        for y in 0..f.height as i64 {
            for x in 0..f.width as i64 {
                let (gx, gy) = (x + f.x0, y + f.y0);
                assert_eq!(f.fine_at(x, y), fine(gx, gy), "fine ({gx}, {gy})");
                let mut block = 0f32;
                for yy in 0..k as i64 {
                    for xx in 0..k as i64 {
                        block = block.max(fine(gx + xx, gy + yy));
                    }
                }
                assert_eq!(f.coarse_at(x, y), block, "coarse k={k} ({gx}, {gy})");
                nonzero += (block > 0.0) as usize;
            }
        }
        // Four 5 × 5 stamps, two of them overlapping by three columns: 85
        // cells at k = 1, more for larger blocks.
        assert!(nonzero >= 85, "k={k}: {nonzero} coarse cells set");
        // The points' cells are inside, with room for the search margin.
        for c in &cells {
            assert!(c[0] - f.x0 >= 4 && c[1] - f.y0 >= 4);
            assert!(c[0] - f.x0 < f.width as i64 - 4 && c[1] - f.y0 < f.height as i64 - 4);
        }
    }
}

/// Scan points on walls, every 5 cm: `(from, to)` segments in the robot
/// frame, moved by half a 5 cm cell so each lands mid-cell.
/// A wall from one (x, y) to another.
type Wall = ((f64, f64), (f64, f64));

fn wall_points(walls: &[Wall]) -> Vec<glam::DVec2> {
    let mut out = Vec::new();
    for &((x0, y0), (x1, y1)) in walls {
        let (a, b) = (glam::DVec2::new(x0, y0), glam::DVec2::new(x1, y1));
        let n = (a.distance(b) / 0.05).round() as usize;
        let half = glam::DVec2::splat(0.025);
        out.extend((0..=n).map(|i| a.lerp(b, i as f64 / n as f64) + half));
    }
    out
}

fn window() -> slamlab::slam::match_covariance::ResponseWindow {
    slamlab::slam::match_covariance::ResponseWindow {
        half_m: 0.3,
        half_rad: 3f64.to_radians(),
        drop: 0.1,
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn a_corridor_match_is_uncertain_along_the_corridor_only() {
    use slamlab::slam::match_covariance::response_covariance;
    use slamlab::slam::multires::field_from_points;
    // Two walls 2 m apart, 6 m long, along x. Moving the scan along x by up
    // to 0.3 m slides a twentieth of its points off the walls' ends (mean
    // response ≥ 0.95, counted); across by one 5 cm cell drops every point
    // to the blur's 0.61 (not counted). So the x variance is the second
    // moment of the 13 offsets k · 0.05 m, k = −6..6: Σk² / 13 · 0.05² =
    // 0.035 m² with equal weights, a little less as the outer ones weigh
    // 0.95; y keeps the floor of one cell's quantisation, 0.05² / 12.
    let pts = wall_points(&[((-3.0, -1.0), (3.0, -1.0)), ((-3.0, 1.0), (3.0, 1.0))]);
    let field = field_from_points(&pts, 0.05, 4, 1.0);
    let c = response_covariance(&field, &pts, &Pose2::IDENTITY, &window()).unwrap();
    let q = 0.05f64.powi(2) / 12.0;
    assert!(
        c[0][0] > 0.033 && c[0][0] <= 0.035,
        "x variance {}",
        c[0][0]
    );
    assert!(close(c[1][1], q, 1e-12), "y variance {}", c[1][1]);
    assert!(c[0][1].abs() < 1e-9, "xy {}", c[0][1]);
    // In a closed 4 × 4 m room every direction is pinned.
    let room = wall_points(&[
        ((-2.0, -2.0), (2.0, -2.0)),
        ((2.0, -2.0), (2.0, 2.0)),
        ((2.0, 2.0), (-2.0, 2.0)),
        ((-2.0, 2.0), (-2.0, -2.0)),
    ]);
    let field = field_from_points(&room, 0.05, 4, 1.0);
    let c = response_covariance(&field, &room, &Pose2::IDENTITY, &window()).unwrap();
    assert!(c[0][0] < 2.0 * q && c[1][1] < 2.0 * q, "room {c:?}");
    // The corridor's heading: 3 m lever arms, so a tenth of a degree moves
    // the ends by 5 mm; the heading variance is far below a degree's.
    assert!(c[2][2] < 1f64.to_radians().powi(2), "heading {}", c[2][2]);
}

#[wasm_bindgen_test(unsupported = test)]
fn a_world_covariance_becomes_the_edge_frame_information() {
    use slamlab::slam::match_covariance::edge_information;
    // Long axis along world x (σ 0.2 m), short along y (σ 0.05 m), heading
    // σ 0.01 rad; a node facing +y sees world x as its −y axis: information
    // diag(1/0.05², 1/0.2², 1/0.01²) = diag(400, 25, 10000).
    let cov = [[0.04, 0.0, 0.0], [0.0, 0.0025, 0.0], [0.0, 0.0, 0.0001]];
    let w = edge_information(&cov, FRAC_PI_2).unwrap();
    let want = [[400.0, 0.0, 0.0], [0.0, 25.0, 0.0], [0.0, 0.0, 10000.0]];
    for r in 0..3 {
        for c in 0..3 {
            assert!(close(w[r][c], want[r][c], 1e-6), "{w:?}");
        }
    }
    // Unrotated, with a correlation: the inverse of [[a, b], [b, d]] is
    // [[d, −b], [−b, a]] / (ad − b²).
    let cov = [[0.04, 0.01, 0.0], [0.01, 0.01, 0.0], [0.0, 0.0, 0.0001]];
    let w = edge_information(&cov, 0.0).unwrap();
    let det = 0.04 * 0.01 - 0.0001;
    assert!(close(w[0][0], 0.01 / det, 1e-6) && close(w[0][1], -0.01 / det, 1e-6));
    assert!(close(w[1][1], 0.04 / det, 1e-6) && close(w[2][2], 10000.0, 1e-6));
    assert!(edge_information(&[[0.0; 3]; 3], 0.0).is_none());
}

/// The rival of a match (`multires::rival_score`: the best pose more than
/// 0.5 m from it): in a corridor whose door posts repeat every 2 m, a scan
/// of three of them fits as well two metres on, so its rival scores as
/// its match does; in a closed room nothing else fits. The search that
/// finds the rival never returns a pose inside the excluded box.
#[wasm_bindgen_test(unsupported = test)]
fn a_repeating_corridor_has_a_rival_and_a_room_has_none() {
    use glam::DVec2;
    use slamlab::slam::correlative::{search_outside, CorrelativeConfig, Exclusion};
    use slamlab::slam::multires::{field_from_points, match_scan, rival_score, Window};
    let mut walls = vec![((-8.0, -1.0), (8.0, -1.0)), ((-8.0, 1.0), (8.0, 1.0))];
    for k in -3..=3 {
        let x = 2.0 * k as f64;
        walls.push(((x, 1.0), (x, 1.5)));
    }
    let map = wall_points(&walls);
    // The scan: what lies within 2.5 m of the origin along x.
    let scan: Vec<DVec2> = map.iter().copied().filter(|p| p.x.abs() <= 2.5).collect();
    let field = field_from_points(&map, 0.05, 4, 3.5);
    let window = Window {
        linear_m: 3.0,
        angular_rad: 2f64.to_radians(),
    };
    let m = match_scan(&field, &scan, &Pose2::IDENTITY, &window).unwrap();
    assert!(m.pose.position().length() < 0.03, "{:?}", m.pose);
    let rival = rival_score(&field, &scan, &Pose2::IDENTITY, &window, &m.pose, 0.5);
    assert!(
        rival >= 0.95 * m.search_score,
        "corridor: rival {rival}, match {}",
        m.search_score
    );
    let cfg = CorrelativeConfig {
        linear_window_m: 3.0,
        angular_window_rad: 2f64.to_radians(),
        angular_step_rad: 0.2f64.to_radians(),
        coarse_cells: 4,
    };
    let exclusion = Exclusion {
        centre: DVec2::ZERO,
        radius_m: 0.5,
    };
    let other = search_outside(&field, &scan, &Pose2::IDENTITY, &cfg, Some(exclusion)).unwrap();
    assert!(
        other.pose.x.abs() > 0.5 || other.pose.y.abs() > 0.5,
        "outside the box: {:?}",
        other.pose
    );
    assert!(
        (other.pose.x.abs() - 2.0).abs() < 0.06,
        "two metres on: {:?}",
        other.pose
    );
    let room = wall_points(&[
        ((-2.0, -2.0), (2.0, -2.0)),
        ((2.0, -2.0), (2.0, 2.0)),
        ((2.0, 2.0), (-2.0, 2.0)),
        ((-2.0, 2.0), (-2.0, -2.0)),
    ]);
    let field = field_from_points(&room, 0.05, 4, 3.5);
    let m = match_scan(&field, &room, &Pose2::IDENTITY, &window).unwrap();
    let rival = rival_score(&field, &room, &Pose2::IDENTITY, &window, &m.pose, 0.5);
    assert!(
        rival < 0.7 * m.search_score,
        "room: rival {rival}, match {}",
        m.search_score
    );
}
