//! Synthetic walls and scans for the SLAM modules' unit tests (compiled
//! for tests only): a room off the map raster, a corridor whose ends lie
//! out of range, and a range scan of either from any pose.

use crate::geom::Pose2;
use glam::DVec2;

/// The walls of a 12 × 6 m room with two pillars, as segments.
pub fn room() -> Vec<(DVec2, DVec2)> {
    // Off the 5 cm raster, as real walls are.
    let v = |x: f64, y: f64| DVec2::new(x + 0.013, y + 0.031);
    let mut walls = vec![
        (v(0.0, 0.0), v(12.0, 0.0)),
        (v(12.0, 0.0), v(12.0, 6.0)),
        (v(12.0, 6.0), v(0.0, 6.0)),
        (v(0.0, 6.0), v(0.0, 0.0)),
    ];
    for (cx, cy) in [(4.0, 4.2), (8.5, 1.0)] {
        let (a, b, c, d) = (
            v(cx, cy),
            v(cx + 0.6, cy),
            v(cx + 0.6, cy + 0.4),
            v(cx, cy + 0.4),
        );
        walls.extend([(a, b), (b, c), (c, d), (d, a)]);
    }
    walls
}

/// The two walls of a corridor 2 m wide along x, from x = −50 to 50 m:
/// from its middle, its ends lie far beyond any laser's reach.
pub fn corridor() -> Vec<(DVec2, DVec2)> {
    let v = |x: f64, y: f64| DVec2::new(x, y + 0.031);
    vec![(v(-50.0, 0.0), v(50.0, 0.0)), (v(50.0, 2.0), v(-50.0, 2.0))]
}

/// A 360-beam scan from `pose` in the robot frame, one point per 10 cm
/// or so, as `scan_points` keeps them; beams that meet no wall within
/// `range_m` give no point.
pub fn scan(pose: &Pose2, walls: &[(DVec2, DVec2)], range_m: f64) -> Vec<DVec2> {
    let f = pose.frame();
    let o = pose.position();
    let mut out: Vec<DVec2> = Vec::new();
    for i in 0..360 {
        let dir = DVec2::from_angle(pose.theta + (i as f64).to_radians());
        let hit = walls
            .iter()
            .filter_map(|&(a, b)| {
                let (e, w) = (b - a, a - o);
                let den = dir.perp_dot(e);
                let t = w.perp_dot(e) / den;
                let u = w.perp_dot(dir) / den;
                (den.abs() > 1e-12 && t > 0.0 && (0.0..=1.0).contains(&u)).then_some(t)
            })
            .fold(f64::INFINITY, f64::min);
        if hit > range_m {
            continue;
        }
        let p = f.to_local(o + dir * hit);
        if out.last().is_none_or(|q| q.distance(p) >= 0.1) {
            out.push(p);
        }
    }
    out
}
