//! # Image selection: frames taken facing a wall squarely (thesis §5.6, §6.2.2)
//!
//! The thesis's distance computation (§6.2.4, [`super::pinhole`]) reads only
//! two things off a matched image pair: how much the view *shrank* and how
//! far it *shifted*. That is all a camera that moves along its optical axis
//! and sideways can do to the picture of a flat wall in front of it (§5.5.1,
//! §5.5.2). A camera that also *turns* keystones the picture (§5.5.3) and
//! breaks the arithmetic, so the thesis keeps only the images taken while
//! the robot faced a wall squarely, where "the camera's orientation is
//! fixed" (§5.6):
//!
//! 1. **Squareness** (§6.2.2): sonars 4 and 5, the two that look 10° either
//!    side of straight ahead, read the same range. If the wall in front is
//!    perpendicular to the heading the two cones meet it symmetrically.
//!    We add the two conditions the thesis leaves implicit: both sonars
//!    must actually see a wall (a sonar with no echo reads its maximum
//!    range, and two "nothing" readings agree perfectly), and the robot
//!    must not be turning, since a frame taken mid-turn shows a rotating
//!    view even if the sonars happen to agree (the issue's "the robot not
//!    turning"; the heading change over the last control step, from
//!    odometry).
//! 2. **Thinning** (§6.2.2): "many positions were very close to each
//!    other. The next step was to delete the positions that were close to
//!    each other". The thesis does not say which of a close group survived.
//!    We keep the *squarest* one: the frames are visited in order of
//!    increasing sonar disagreement `|s₄ − s₅|` (ties: the earlier frame)
//!    and a frame is kept only if it lies at least
//!    [`SelectionConfig::min_separation_m`] from every frame kept before it
//!    — greedy non-maximum suppression. The squarest frame is kept because
//!    the whole method rests on squareness; which frame of a cluster is
//!    kept matters less than that the survivors are spread out.
//!
//!    How far is "close"? §6.2.4 needs *two* frames of one robot on one
//!    line of approach to the wall, at different distances from it (D and
//!    E). Our robots cruise at 0.35 m/s and the camera fires once a
//!    second, so the frames of one approach lie about 0.35 m apart, and an
//!    approach from the sonars' 2 m reach to the turn at 0.6 m yields three
//!    to five of them. The default 0.3 m therefore keeps every frame of an
//!    approach and drops only those taken while the robot stood or crept
//!    (a bump, an encounter); the thesis's far harder thinning (21 square
//!    positions to 5) would leave one frame per approach and no E. With
//!    two robots of about 40 kept frames each the matched-pair table has
//!    some 1,700 cells, about a second of matching natively.
//!
//! Distances are measured between the robot's own pose estimates
//! ([`FrameInfo::pose`], its SLAM pose in its map frame), never the truth.
//!
//! ## How good is the sonar test?
//! Not very, and honestly so. With 15° cones, a wall skewed by φ changes
//! the difference of the two nearest echoes by only about
//! `d · tan(2.5°) · 2φ` — under a centimetre at 1.5 m for φ = 5° — while
//! each sonar has 2 cm of noise. The test therefore rejects oblique walls
//! (20° and more), corners and wall ends, but cannot tell 0° from 5°. The
//! optional laser check ([`SelectionConfig::max_wall_skew_rad`]) measures the
//! skew of the wall ahead directly, by a line fit to the laser's central
//! beams ([`front_wall`], within about 0.2° median on the presets); it is
//! off by default, to keep the thesis's rule as the thesis wrote it.
//! [`super::pinhole`] uses the same fit to check its distances and to
//! correct for the few degrees by which "square" robots are in fact turned.
//!
//! Conventions: metres and radians; the sonars are numbered 1 to 8 from
//! left to right as in the thesis (indices 0 to 7); laser beam `k` looks
//! at bearing `(k − 90)°` (x forward, y left).

use super::FrameInfo;
use crate::sensors::laser::{beam_bearing, LASER_BEAMS};
use glam::DVec2;

/// Index of the thesis's sonar 4 (10° left of straight ahead).
pub const SONAR_4: usize = 3;
/// Index of the thesis's sonar 5 (10° right of straight ahead).
pub const SONAR_5: usize = 4;

/// Settings of the image selection.
#[derive(Clone, Debug, PartialEq)]
pub struct SelectionConfig {
    /// Sonars 4 and 5 "read alike" when they differ by at most this much
    /// (m). Default 0.06: about twice the standard deviation of the
    /// difference of two sonars with the default 2 cm noise.
    pub sonar_tolerance_m: f64,
    /// Both forward sonars must see a wall nearer than this (m). Default
    /// 1.9, just inside the sonars' 2 m reach: a sonar without an echo
    /// reads its maximum range, and two such readings agree perfectly
    /// without seeing anything.
    pub max_front_range_m: f64,
    /// And farther than this (m): a robot nose-to-wall sees a few texels
    /// filling the image. Default 0.3.
    pub min_front_range_m: f64,
    /// The robot is "not turning" when its heading changed by at most this
    /// much over the last control step (rad). Default 0.03 (≈ 17°/s at
    /// 10 Hz); a wall follower rounding a corner turns about 0.12 a step.
    pub max_turn_per_step_rad: f64,
    /// Of frames taken closer together than this (m, between pose
    /// estimates), only one is kept. Default 0.3 (see the module doc).
    pub min_separation_m: f64,
    /// Optional laser check of squareness (rad): the wall ahead, fitted to
    /// the laser's central beams, must be perpendicular to the heading
    /// within this angle. `None` (default) keeps the thesis's sonar rule
    /// alone.
    pub max_wall_skew_rad: Option<f64>,
}

impl Default for SelectionConfig {
    fn default() -> Self {
        SelectionConfig {
            sonar_tolerance_m: 0.06,
            max_front_range_m: 1.9,
            min_front_range_m: 0.3,
            max_turn_per_step_rad: 0.03,
            min_separation_m: 0.3,
            max_wall_skew_rad: None,
        }
    }
}

/// The wall straight ahead, as the laser's central beams see it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrontWall {
    /// Perpendicular distance from the robot's centre to the wall line (m).
    pub distance_m: f64,
    /// Angle from the robot's heading to the wall's normal (pointing from
    /// the robot to the wall), rad, counter-clockwise positive: 0 when the
    /// robot faces the wall squarely, positive when the wall's nearest
    /// point lies to the robot's left.
    pub skew_rad: f64,
    /// RMS distance of the fitted points from the line (m).
    pub rms_m: f64,
    /// Laser points that took part.
    pub points: usize,
}

/// Half-width of the fan of laser beams [`front_wall`] fits (degrees).
pub const FRONT_WALL_HALF_FAN_DEG: usize = 20;

/// Residual (m) beyond which a laser point is not on the wall ahead: three
/// times the default laser noise.
const WALL_TOLERANCE_M: f64 = 0.03;

/// Fits a line to the laser returns within ±[`FRONT_WALL_HALF_FAN_DEG`]° of
/// straight ahead and reports the wall's distance and skew. Something in
/// front of the wall, or a side wall at the edge of the fan, must not tilt
/// the line, so the fit is robust and deterministic: every pair of points
/// at least 20 cm apart proposes a line, the line with most points within
/// 3 cm of it wins (an exhaustive RANSAC, cheap on 41 points), and the wall
/// is the total-least-squares line through those points, refitted once on
/// its own inliers. `None` when fewer than 8 points lie on one line.
pub fn front_wall(frame: &FrameInfo) -> Option<FrontWall> {
    let centre = LASER_BEAMS / 2;
    let lo = centre.saturating_sub(FRONT_WALL_HALF_FAN_DEG);
    let hi = (centre + FRONT_WALL_HALF_FAN_DEG).min(LASER_BEAMS - 1);
    let points: Vec<DVec2> = (lo..=hi)
        .filter(|&k| frame.laser_mm[k] != u16::MAX && frame.laser_mm[k] > 0)
        .map(|k| DVec2::from_angle(beam_bearing(k)) * (frame.laser_mm[k] as f64 / 1000.0))
        .collect();
    let near = |normal: DVec2, d: f64| {
        points
            .iter()
            .copied()
            .filter(|p| (normal.dot(*p) - d).abs() <= WALL_TOLERANCE_M)
            .collect::<Vec<DVec2>>()
    };
    let mut best: Option<(usize, DVec2, f64)> = None;
    for (i, &p) in points.iter().enumerate() {
        for &q in &points[i + 1..] {
            if p.distance(q) < 0.2 {
                continue;
            }
            let normal = (q - p).perp().normalize();
            let d = normal.dot(p);
            let count = points
                .iter()
                .filter(|r| (normal.dot(**r) - d).abs() <= WALL_TOLERANCE_M)
                .count();
            if best.is_none_or(|b| count > b.0) {
                best = Some((count, normal, d));
            }
        }
    }
    let (_, normal, d) = best?;
    let (normal, d) = fit_line(&near(normal, d))?;
    let inliers = near(normal, d);
    let (normal, distance_m) = fit_line(&inliers)?;
    let n = inliers.len() as f64;
    let rms_m = (inliers
        .iter()
        .map(|p| (normal.dot(*p) - distance_m).powi(2))
        .sum::<f64>()
        / n)
        .sqrt();
    Some(FrontWall {
        distance_m,
        skew_rad: normal.y.atan2(normal.x),
        rms_m,
        points: inliers.len(),
    })
}

/// Total-least-squares line through at least 8 points: its unit normal
/// (pointing away from the origin, the robot) and its distance from the
/// origin. `None` for too few points or a line through the robot.
fn fit_line(points: &[DVec2]) -> Option<(DVec2, f64)> {
    if points.len() < 8 {
        return None;
    }
    let n = points.len() as f64;
    let c = points.iter().copied().sum::<DVec2>() / n;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for p in points {
        let d = *p - c;
        sxx += d.x * d.x;
        sxy += d.x * d.y;
        syy += d.y * d.y;
    }
    // Direction of the line: the principal axis of the scatter.
    let along = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let normal = DVec2::from_angle(along + std::f64::consts::FRAC_PI_2);
    let normal = if normal.dot(c) < 0.0 { -normal } else { normal };
    let distance = normal.dot(c);
    (distance.is_finite() && distance > 1e-3).then_some((normal, distance))
}

/// Whether a frame was taken facing a wall squarely (see the module doc):
/// sonars 4 and 5 both see a wall within range and read alike, the robot
/// is not turning, and (if asked) the laser agrees.
pub fn is_square(frame: &FrameInfo, cfg: &SelectionConfig) -> bool {
    let (s4, s5) = (frame.sonar_m[SONAR_4] as f64, frame.sonar_m[SONAR_5] as f64);
    let in_range =
        |s: f64| s.is_finite() && s >= cfg.min_front_range_m && s <= cfg.max_front_range_m;
    if !(in_range(s4) && in_range(s5)) {
        return false;
    }
    if (s4 - s5).abs() > cfg.sonar_tolerance_m {
        return false;
    }
    if !frame.turn_rad.is_finite() || frame.turn_rad.abs() > cfg.max_turn_per_step_rad {
        return false;
    }
    match cfg.max_wall_skew_rad {
        None => true,
        Some(max) => front_wall(frame).is_some_and(|w| w.skew_rad.abs() <= max),
    }
}

/// The thesis's selection (§6.2.2): the square frames, thinned so that no
/// two kept frames lie closer than `min_separation_m` (the squarest of a
/// close group survives; see the module doc). Returns indices into
/// `frames`, in increasing order.
pub fn select_frames(frames: &[FrameInfo], cfg: &SelectionConfig) -> Vec<usize> {
    let mut square: Vec<(f64, usize)> = frames
        .iter()
        .enumerate()
        .filter(|(_, f)| is_square(f, cfg) && f.pose.is_finite())
        .map(|(i, f)| {
            let disagreement = (f.sonar_m[SONAR_4] as f64 - f.sonar_m[SONAR_5] as f64).abs();
            (disagreement, i)
        })
        .collect();
    // Squarest first; the earlier frame on a tie (the sort is stable).
    square.sort_by(|a, b| a.0.total_cmp(&b.0));
    let min_sep = cfg.min_separation_m.max(0.0);
    let mut kept: Vec<usize> = Vec::new();
    for (_, i) in square {
        let p = frames[i].pose.position();
        if kept
            .iter()
            .all(|&k| frames[k].pose.position().distance(p) >= min_sep)
        {
            kept.push(i);
        }
    }
    kept.sort_unstable();
    kept
}
