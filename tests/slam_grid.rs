//! The occupancy grid: the beam model on hand-computed cases, origin
//! bookkeeping as the grid grows, and the memory cap.

use glam::DVec2;
use slamlab::geom::Pose2;
use slamlab::slam::export::{to_pgm, to_yaml, GridPicture};
use slamlab::slam::grid::{traverse, CellState, GridConfig, OccupancyGrid, LOG_ODDS_UNIT};
use wasm_bindgen_test::wasm_bindgen_test;

fn grid() -> OccupancyGrid {
    let mut g = OccupancyGrid::new(GridConfig::default());
    assert!(g.ensure_contains(DVec2::new(-1.0, -1.0), DVec2::new(1.0, 1.0)));
    g
}

#[wasm_bindgen_test(unsupported = test)]
fn traversal_visits_each_crossed_cell_once_in_order() {
    let mut v = Vec::new();
    traverse(DVec2::new(0.5, 0.5), DVec2::new(3.5, 1.2), |c| v.push(c));
    // Slope 0.7/3 from (0.5, 0.5): crosses x = 1, x = 2, then y = 1 at x ≈ 2.64, then x = 3.
    assert_eq!(v, vec![[0, 0], [1, 0], [2, 0], [2, 1], [3, 1]]);
    v.clear();
    traverse(DVec2::new(0.5, 0.5), DVec2::new(-1.5, 0.5), |c| v.push(c));
    assert_eq!(v, vec![[0, 0], [-1, 0], [-2, 0]]);
}

#[wasm_bindgen_test(unsupported = test)]
fn a_hit_clears_before_the_margin_and_marks_the_end_cell() {
    let mut g = grid();
    let cfg = g.config.clone();
    // From the centre of cell (0, 0) along +x for 0.5 m: the end (0.525) is in cell 10;
    // the last 0.1 m (0.425..0.525) touches cells 8, 9, 10, so cells 0..=7 are cleared.
    g.integrate_beam(DVec2::new(0.025, 0.025), DVec2::new(0.525, 0.025), true);
    for x in 0..=7 {
        assert_eq!(
            g.log_odds_global([x, 0]),
            cfg.miss as f32 * LOG_ODDS_UNIT,
            "cell {x}"
        );
    }
    assert_eq!(g.log_odds_global([8, 0]), 0.0);
    assert_eq!(g.log_odds_global([9, 0]), 0.0);
    assert_eq!(g.log_odds_global([10, 0]), cfg.hit as f32 * LOG_ODDS_UNIT);
    assert_eq!(g.log_odds_global([11, 0]), 0.0);
    assert_eq!(g.log_odds_global([0, 1]), 0.0, "the beam stays in its row");
}

#[wasm_bindgen_test(unsupported = test)]
fn a_max_range_or_reflective_beam_clears_without_marking() {
    let mut g = grid();
    g.integrate_beam(DVec2::new(0.025, 0.025), DVec2::new(0.025, 0.525), false);
    for y in 0..=10 {
        assert!(g.log_odds_global([0, y]) < 0.0, "cell (0, {y}) cleared");
    }
    assert_eq!(g.log_odds_global([0, 11]), 0.0);
    assert_eq!(g.occupied_count(), 0);
}

#[wasm_bindgen_test(unsupported = test)]
fn log_odds_are_clamped_and_saturated_walls_survive_passing_beams() {
    let mut g = grid();
    let (lo, hi) = (
        g.config.min as f32 * LOG_ODDS_UNIT,
        g.config.max as f32 * LOG_ODDS_UNIT,
    );
    for _ in 0..50 {
        g.integrate_beam(DVec2::new(0.025, 0.025), DVec2::new(0.525, 0.025), true);
    }
    assert_eq!(g.log_odds_global([10, 0]), hi);
    assert_eq!(g.log_odds_global([3, 0]), lo);
    assert_eq!(
        g.state(g.local([10, 0]).unwrap().0, g.local([10, 0]).unwrap().1),
        CellState::Occupied
    );
    // A beam passing through the saturated wall cell does not lower it.
    g.integrate_beam(DVec2::new(0.025, 0.025), DVec2::new(0.925, 0.025), true);
    assert_eq!(g.log_odds_global([10, 0]), hi);
}

#[wasm_bindgen_test(unsupported = test)]
fn the_origin_stays_right_as_the_grid_grows_in_every_direction() {
    let mut g = OccupancyGrid::new(GridConfig::default());
    let r = g.resolution_m();
    // Mark a cell, then grow the grid west, south, east and north in turn:
    // the mark stays at the same place of the odometry frame.
    let p = DVec2::new(0.33, -0.12);
    g.ensure_contains(p, p);
    g.integrate_beam(p - DVec2::new(0.2, 0.0), p, true);
    let expected = g.global_cell(p);
    for (lo, hi) in [
        (DVec2::new(-30.0, -0.1), DVec2::new(0.0, 0.0)),
        (DVec2::new(0.0, -25.0), DVec2::new(0.1, 0.0)),
        (DVec2::new(0.0, 0.0), DVec2::new(41.0, 0.1)),
        (DVec2::new(0.0, 0.0), DVec2::new(0.1, 17.0)),
    ] {
        assert!(g.ensure_contains(lo, hi));
        let (ix, iy) = g.local(expected).expect("mark still inside");
        assert_eq!(g.state(ix, iy), CellState::Occupied);
        // The cell's centre, through the origin, is where the mark was made.
        let c = g.cell_centre(ix, iy);
        assert!(
            (c - p).abs().max_element() <= r / 2.0 + 1e-12,
            "{c:?} vs {p:?}"
        );
        assert_eq!(g.occupied_count(), 1);
        // The origin is the lower-left corner of cell (0, 0), and covers the box.
        let o = g.origin_m();
        assert!(o.x <= lo.x && o.y <= lo.y);
        assert!(o.x + g.width() as f64 * r > hi.x && o.y + g.height() as f64 * r > hi.y);
    }
    assert!(g.origin_m().x <= -30.0 && g.origin_m().y <= -25.0);
}

#[wasm_bindgen_test(unsupported = test)]
fn growth_beyond_the_cap_is_refused_and_updates_outside_are_counted() {
    let mut g = OccupancyGrid::new(GridConfig {
        max_cells: 200 * 200,
        ..GridConfig::default()
    });
    assert!(g.ensure_contains(DVec2::ZERO, DVec2::new(5.0, 5.0)));
    let (w, h) = (g.width(), g.height());
    assert!(!g.ensure_contains(DVec2::ZERO, DVec2::new(50.0, 5.0)));
    assert_eq!((g.width(), g.height()), (w, h));
    let before = g.dropped_updates();
    g.integrate_beam(DVec2::new(1.0, 1.0), DVec2::new(30.0, 1.0), true);
    assert!(g.dropped_updates() > before);
    assert!(g.memory_bytes() <= 200 * 200);
}

#[wasm_bindgen_test(unsupported = test)]
fn ros_export_has_the_map_server_layout() {
    let mut g = OccupancyGrid::new(GridConfig::default());
    let pose = Pose2::IDENTITY;
    g.ensure_contains(DVec2::new(-0.5, -0.5), DVec2::new(0.5, 0.5));
    for _ in 0..5 {
        g.integrate_beam(pose.position() + 0.01, DVec2::new(0.301, 0.01), true);
    }
    let pgm = to_pgm(&g);
    let header = format!(
        "P5\n# slamlab occupancy grid, 0.05 m/cell\n{} {}\n255\n",
        g.width(),
        g.height()
    );
    assert!(pgm.starts_with(header.as_bytes()));
    let px = &pgm[header.len()..];
    assert_eq!(px.len(), g.width() * g.height());
    // The wall cell (6, 0): row 0 of the image is the top of the map.
    let (ix, iy) = g.local([6, 0]).unwrap();
    assert_eq!(px[(g.height() - 1 - iy) * g.width() + ix], 0);
    let (fx, fy) = g.local([2, 0]).unwrap();
    assert_eq!(px[(g.height() - 1 - fy) * g.width() + fx], 254);
    assert_eq!(px[0], 205);
    let yaml = to_yaml(&g, "map.pgm");
    let o = g.origin_m();
    assert!(
        yaml.contains(&format!("origin: [{}, {}, 0.0]", o.x, o.y)),
        "{yaml}"
    );
    for line in [
        "image: \"map.pgm\"",
        "resolution: 0.05",
        "negate: 0",
        "occupied_thresh: 0.65",
        "free_thresh: 0.196",
    ] {
        assert!(yaml.contains(line), "{line} in {yaml}");
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn the_surface_layer_keeps_the_mean_of_the_hits_in_each_cell() {
    let mut g = OccupancyGrid::new(GridConfig {
        surface_points: true,
        ..GridConfig::default()
    });
    assert!(g.ensure_contains(DVec2::new(-1.0, -1.0), DVec2::new(1.0, 1.0)));
    // Three hits in cell (10, 4) = [0.50, 0.55) × [0.20, 0.25).
    let from = DVec2::new(0.0, 0.0);
    for p in [
        DVec2::new(0.510, 0.210),
        DVec2::new(0.520, 0.240),
        DVec2::new(0.545, 0.225),
    ] {
        g.integrate_beam(from, p, true);
    }
    let (x, y) = g.local([10, 4]).expect("inside");
    let s = g.surface_point(x, y).expect("a surface");
    assert_eq!(s.hits, 3);
    // Mean (0.525, 0.225), stored to 1/65536 of a cell.
    assert!(
        (s.position - DVec2::new(0.525, 0.225)).length() < 1e-6,
        "{:?}",
        s.position
    );
    // Enough passing beams clear the cell, and its surface goes with it.
    for _ in 0..10 {
        g.integrate_beam(from, DVec2::new(0.9, 0.9 * 0.225 / 0.525), true);
    }
    assert!(g.units(x, y) <= 0);
    assert!(g.surface_point(x, y).is_none());
    // A grid without the layer has no surface anywhere.
    let mut plain = grid();
    plain.integrate_beam(from, DVec2::new(0.52, 0.22), true);
    let (x, y) = plain.local([10, 4]).expect("inside");
    assert!(plain.units(x, y) > 0 && plain.surface_point(x, y).is_none());
}

#[wasm_bindgen_test(unsupported = test)]
fn the_surface_layer_survives_growth() {
    let mut g = OccupancyGrid::new(GridConfig {
        surface_points: true,
        ..GridConfig::default()
    });
    assert!(g.ensure_contains(DVec2::new(-1.0, -1.0), DVec2::new(1.0, 1.0)));
    g.integrate_beam(DVec2::ZERO, DVec2::new(0.512, 0.233), true);
    let before = g.origin_cell();
    assert!(g.ensure_contains(DVec2::new(-20.0, -20.0), DVec2::new(20.0, 20.0)));
    assert_ne!(g.origin_cell(), before, "the grid grew down and left");
    let (x, y) = g
        .local(g.global_cell(DVec2::new(0.512, 0.233)))
        .expect("inside");
    let s = g.surface_point(x, y).expect("kept");
    assert!((s.position - DVec2::new(0.512, 0.233)).length() < 1e-6);
}

#[wasm_bindgen_test(unsupported = test)]
fn grid_picture_fits_the_grid_y_up_and_draws_in_map_coordinates() {
    let mut g = OccupancyGrid::new(GridConfig::default());
    g.ensure_contains(DVec2::new(-0.5, -0.5), DVec2::new(0.5, 0.5));
    for _ in 0..5 {
        g.integrate_beam(DVec2::new(0.01, 0.01), DVec2::new(0.301, 0.01), true);
    }
    let (w, h) = (g.width() as u32, g.height() as u32);
    // Twice the grid's size in both directions: 2 × 2 pixels a cell, no margin.
    let mut pic = GridPicture::new(&g, 2 * w, 2 * h).expect("picture");
    let o = g.origin_m();
    assert_eq!(pic.to_px(o), (0.0, (2 * h) as f32));
    let cell = |gx: i64, gy: i64| {
        let (ix, iy) = g.local([gx, gy]).expect("in the grid");
        // Bottom-left pixel of the cell's 2 × 2 block, image rows down.
        (2 * ix, 2 * (h as usize - 1 - iy) + 1)
    };
    let px = |rgba: &[u8], (x, y): (usize, usize)| rgba[(y * 2 * w as usize + x) * 4];
    let before = {
        let p = GridPicture::new(&g, 2 * w, 2 * h).expect("picture");
        p.into_rgba()
    };
    assert_eq!(px(&before, cell(6, 0)), 30, "the wall cell is dark");
    assert_eq!(px(&before, cell(2, 0)), 250, "free cells are light");
    assert_eq!(px(&before, (0, 0)), 205, "unknown is grey");
    // A red dot drawn at the wall cell's centre lands on its pixels.
    pic.dot(DVec2::new(0.325, 0.025), 2.0, [255, 0, 0, 255]);
    let after = pic.into_rgba();
    let (x, y) = cell(6, 0);
    let i = (y * 2 * w as usize + x) * 4;
    assert_eq!(&after[i..i + 4], &[255, 0, 0, 255]);
    assert!(GridPicture::new(&g, 0, 10).is_err());
}

/// A scan of `LASER_BEAMS` beams, all `range` long, all hits or all
/// max-range.
fn ring_scan(range: f64, hit: bool) -> slamlab::sensors::LaserScan {
    let n = slamlab::sensors::LASER_BEAMS;
    slamlab::sensors::LaserScan {
        ranges_m: vec![range; n],
        max_range: vec![!hit; n],
        reflective: vec![false; n],
        range_max_m: 4.0,
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn a_scan_lowers_each_cell_of_its_fan_once() {
    // From the origin facing +x, 181 max-range beams 1 m long over ±90°:
    // the fan is the right half-disc of radius 1 m. Walked beam by beam,
    // cell (1, 0) would lie under some thirty beams; once per scan, it is
    // lowered by one `miss`, like every cell whose centre is in the fan.
    let mut g = OccupancyGrid::new(GridConfig::default());
    g.integrate_scan(&Pose2::new(0.0, 0.0, 0.0), &ring_scan(1.0, false));
    let miss = g.config.miss as f32 * LOG_ODDS_UNIT;
    for k in 0..=19 {
        assert_eq!(g.log_odds_global([k, 0]), miss, "cell ({k}, 0)");
        assert_eq!(g.log_odds_global([0, k]), miss, "cell (0, {k})");
        assert_eq!(g.log_odds_global([0, -k - 1]), miss, "cell (0, {})", -k - 1);
    }
    // Centres at x = 1.025 m, y = 1.025 m: outside the disc.
    assert_eq!(g.log_odds_global([20, 0]), 0.0);
    assert_eq!(g.log_odds_global([0, 20]), 0.0);
    // (0.725, 0.725) lies 1.025 m out; (0.675, 0.675) 0.955 m.
    assert_eq!(g.log_odds_global([14, 14]), 0.0);
    assert_eq!(g.log_odds_global([13, 13]), miss);
    // Behind the robot (centre x = −0.025 m): not in the fan.
    assert_eq!(g.log_odds_global([-1, 0]), 0.0);
    assert_eq!(g.occupied_count(), 0);
}

#[wasm_bindgen_test(unsupported = test)]
fn a_scan_of_hits_clears_to_the_margin_and_marks_the_ends() {
    // Every beam ends on a surface 1 m out: cells are cleared only to
    // 0.9 m (the hit margin), and the cells the beams end in are marked.
    let mut g = OccupancyGrid::new(GridConfig::default());
    g.integrate_scan(&Pose2::new(0.0, 0.0, 0.0), &ring_scan(1.0, true));
    let (miss, hit) = (
        g.config.miss as f32 * LOG_ODDS_UNIT,
        g.config.hit as f32 * LOG_ODDS_UNIT,
    );
    assert_eq!(g.log_odds_global([17, 0]), miss, "centre 0.875 m");
    assert_eq!(
        g.log_odds_global([18, 0]),
        0.0,
        "centre 0.925 m: in the margin"
    );
    // The 0° beam ends at (1.0, 0) in cell (20, 0); the +1° and +2° beams
    // at (0.99985, 0.01745) and (0.99939, 0.03490), both in cell (19, 0).
    assert_eq!(g.log_odds_global([20, 0]), hit);
    assert_eq!(g.log_odds_global([19, 0]), 2.0 * hit);
    assert_eq!(g.log_odds_global([21, 0]), 0.0);
}

/// The matcher's window walk ([`OccupancyGrid::for_surface_points`]) gives
/// the points `surface_point` gives cell by cell, in the same order, for
/// windows across block borders and the grid's edges.
#[wasm_bindgen_test(unsupported = test)]
fn the_window_walk_gives_the_surface_points_cell_by_cell() {
    let mut g = OccupancyGrid::new(GridConfig {
        surface_points: true,
        ..GridConfig::default()
    });
    for (k, range) in [1.3, 2.1, 0.7, 3.4].into_iter().enumerate() {
        let pose = Pose2::new(0.1 * k as f64, -0.05 * k as f64, 0.4 * k as f64);
        g.integrate_scan(&pose, &ring_scan(range, true));
    }
    let (w, h) = (g.width(), g.height());
    let mut corners = vec![(0, 0), (w - 3, h - 2)];
    let mut surface_cells = 0;
    for y in 0..h {
        for x in 0..w {
            if g.surface_point(x, y).is_some() {
                surface_cells += 1;
                if surface_cells % 97 == 0 {
                    corners.push((x.saturating_sub(2), y.saturating_sub(3)));
                }
            }
        }
    }
    let mut windows = 0;
    for (x0, y0) in corners {
        for (dx, dy) in [(4, 4), (1, 7), (60, 60)] {
            let (x1, y1) = ((x0 + dx).min(w - 1), (y0 + dy).min(h - 1));
            let mut walked = Vec::new();
            g.for_surface_points([x0, x1], [y0, y1], |s| walked.push(s));
            let mut asked = Vec::new();
            for y in y0..=y1 {
                for x in x0..=x1 {
                    asked.extend(g.surface_point(x, y));
                }
            }
            assert_eq!(walked, asked, "window {x0}..={x1} × {y0}..={y1}");
            windows += (!asked.is_empty()) as usize;
        }
    }
    assert!(windows >= 10, "windows with surface points: {windows}");
}

/// The likelihood field of one saturated wall cell is the Gaussian kernel
/// around it (σ = 1 cell, radius 2, unit sum: `w(d) = exp(−d²/2) / Σ`,
/// the value at offset (dx, dy) being `w(dx)·w(dy)`), cut off at the
/// window's edge, and each coarse entry is the largest fine value of its
/// 4 × 4 block forward.
#[wasm_bindgen_test(unsupported = test)]
fn the_likelihood_field_of_one_wall_cell_is_the_kernel() {
    use slamlab::slam::likelihood::LikelihoodField;
    let mut g = grid();
    let p = DVec2::new(0.525, 0.275); // global cell (10, 5)
    for _ in 0..6 {
        g.integrate_beam(p - DVec2::new(0.01, 0.0), p, true);
    }
    let norm = 1.0 + 2.0 * ((-0.5f64).exp() + (-2.0f64).exp());
    let w = |d: i64| {
        if d.abs() > 2 {
            0.0
        } else {
            (-0.5 * (d * d) as f64).exp() / norm
        }
    };
    // A window whose left edge cuts the kernel: cells 9..=20 × 0..=11.
    let f = LikelihoodField::build(&g, [9, 0], [20, 11], 4);
    assert_eq!((f.width, f.height), (12, 12));
    for y in 0..12i64 {
        for x in 0..12i64 {
            let (dx, dy) = (x + 9 - 10, y - 5);
            let want = w(dx) * w(dy);
            let got = f.fine_at(x, y) as f64;
            assert!(
                (got - want).abs() < 1e-6,
                "({x}, {y}): {got} against {want}"
            );
        }
    }
    // Coarse: the block [x, x + 4) × [y, y + 4) holding the wall cell
    // (window x 1, y 5) has its value; a block two cells off, w(2)·w(0).
    let top = w(0) * w(0);
    assert!((f.coarse_at(0, 2) as f64 - top).abs() < 1e-6);
    assert!((f.coarse_at(3, 5) as f64 - w(2) * w(0)).abs() < 1e-6);
    assert_eq!(f.coarse_at(6, 5), 0.0);
    assert_eq!(f.coarse_at(0, 8), 0.0);
}
