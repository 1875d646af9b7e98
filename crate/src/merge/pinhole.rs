//! # The thesis's merge: distance between the robots from three pictures (§6.2.3–6.2.5)
//!
//! After selection ([`super::selection`]) every kept frame of robot 1 is
//! matched against every kept frame of robot 2 with SURF, the ratio test
//! and an MSAC homography (§6.2.3; the caller builds that table and hands
//! it over as [`PairMatch`] rows, the thesis's Table 1). This module does
//! the rest, as §6.2.4 and §6.2.5 describe.
//!
//! ## Figure 18 in our terms
//! Robot 1 stands at A' and robot 2 at D and, later, at E, all facing the
//! same wall squarely. A is the point on robot 2's line of approach level
//! with A' (as far from the wall as A'), so AD is how much nearer the wall
//! D is than A', and AA' is the sideways offset between the two robots.
//! The thesis measures "the length of a robot's vision" in pixels:
//!
//! * **B'C'** is robot 1's whole view: the image width `W`.
//! * **FJ** is robot 2's view at D *in the same pixels*: the size robot 2's
//!   image has when it is laid over robot 1's. The MSAC homography `H` maps
//!   robot 1's pixels to robot 2's (the matched region of §5.3.4 is robot
//!   1's image inside robot 2's, [`crate::surf::MatchedRegion`]); its
//!   inverse lays robot 2's image over robot 1's. As §5.3.4 says, "by
//!   comparing the quadrangle's side length with the image's side length,
//!   the image's shrinkage value can be calculated": FJ is `W` times the
//!   mean of the laid-over quad's four sides, each over the matching image
//!   side. For a camera that only moved along its axis and sideways that
//!   is `W · Z_D / Z_A` (all four sides agree); averaging them damps the
//!   noise of a homography fitted on part of the image.
//! * **GH** is the same for robot 2's frame at E.
//! * **DE** is how far robot 2 advanced towards the wall between D and E,
//!   from its own pose estimates: the displacement projected on its
//!   heading at D ("calculated from Robot2's odometry data").
//!
//! A pixel of robot 1's image covers `K = Z_A / f` metres of the wall, so
//! the two equations of §6.2.4 (Figure 12's "half the shrinkage over the
//! distance moved", twice)
//!
//! ```text
//! tan(θ/2) = (B'C'/2 − FJ/2) · K / AD
//! tan(θ/2) = (B'C'/2 − GH/2) · K / (AD + DE)
//! ```
//!
//! are linear in `K` and `AD`. Subtracting the first from the second gives
//! `tan(θ/2) · DE = (FJ − GH)/2 · K`, so
//!
//! ```text
//! K  = 2 · DE · tan(θ/2) / (FJ − GH)
//! AD = DE · (B'C' − FJ) / (FJ − GH)
//! ```
//!
//! ([`solve_distance`]). With signed lengths the same formulas hold
//! whichever of A', D and E is nearest the wall. They fail only when FJ =
//! GH (D and E equally far from the wall: the scale change that measures
//! `K` is zero), which [`solve_distance`] reports.
//!
//! ## What the thesis leaves to the reader
//! * **The sideways offset AA'.** The thesis names it and says no more; its
//!   §5.5.1 says a sideways move shifts the view by the same distance. On
//!   the wall, robot 2's view centre lands `shift` pixels right of robot
//!   1's image centre, and one of robot 1's pixels is `K` metres there, so
//!   robot 2 stood `shift · K` metres to robot 1's right (`shift = f·dx/Z`
//!   read backwards).
//! * **The rotation** (§6.2.5, "the rotation angle is θ₂ − θ₁"): both robots
//!   face the same wall squarely, so they face the same way in the world,
//!   and the heading each believes it has tells how its map is turned. The
//!   pose of robot 2 at D seen from robot 1 at A' is therefore
//!   `rel = (AD, −shift·K, 0)` (x forward, y left; but see the fill-in
//!   below), and robot 2's map
//!   frame sits in robot 1's at `T = P_A' ⊕ rel ⊕ P_D⁻¹` (P: the SLAM pose
//!   each robot had at its frame) — "rotate, then translate by the
//!   difference of the reference positions plus the distance between the
//!   robots".
//! * **Which pairs.** The thesis takes the pair with the most inliers, (3,
//!   10) in its Table 1, and a second with the same robot-1 frame, (3, 11).
//!   We take the best pair D, then the best other frame E of robot 2
//!   matched with the same robot-1 frame that lies on the same line of
//!   approach (heading within [`ThesisConfig::max_heading_change_rad`],
//!   sideways offset within [`ThesisConfig::max_sideways_m`]) and far
//!   enough along it ([`ThesisConfig::min_de_m`]) for the scale to change.
//!   If no such E exists for the best pair, the next best pair is tried,
//!   and then the roles are swapped (one frame of robot 2, two of robot
//!   1), since the thesis's choice of which robot gives two frames is
//!   arbitrary.
//! * **Sanity.** "After the image selection process, the shape of the
//!   matched region should be a rectangle" (§6.2.3): a pair whose region
//!   is keystoned or stretched by more than [`ThesisConfig::max_keystone`]
//!   is not used. And since `K · f` is robot 1's distance from the wall,
//!   which its laser also measures, we compare the two: a solution whose
//!   depth disagrees by more than [`ThesisConfig::max_depth_error`] is
//!   discarded (this is what stops a false match between look-alike walls
//!   from merging), and the agreement sets the confidence.
//! * **Confidence** (the thesis has none): `(1 − e^(−n/2m)) · e^(−½(δ/σ)²)`
//!   with `n` the second pair's inliers, `m` [`ThesisConfig::min_inliers`],
//!   `δ` the relative disagreement of the two depths and `σ` half of
//!   [`ThesisConfig::max_depth_error`]; the second factor is ½ when the
//!   laser saw no straight wall.
//!
//! ## Square is never exactly square (a fill-in)
//! The sonar test ([`super::selection`]) cannot tell a robot facing the
//! wall squarely from one turned 5°, and a wall follower wobbles by about
//! that much. The thesis's rotation `θ₂ − θ₁` then errs by the difference
//! of the two robots' turns, and a degree at the meeting point is 0.25 m
//! fifteen metres away, at the other robot's map origin. Both robots'
//! lasers see the wall, so we measure each robot's skew `φ` (the wall's
//! normal from its heading, [`super::selection::front_wall`], about 0.2°
//! median error) and redo the geometry with it: robot 2's view centre lies
//! on the wall where robot 1's column `shift` looks, robot 2 stands
//! `d_D = K·f − AD` from the wall behind that point along its own axis,
//! and `rel = (AD·n + s·t, φ_A − φ_D)` with `n`, `t` the wall's normal and
//! direction in robot 1's frame and `s` the sideways offset along the wall
//! ([`ThesisConfig::correct_skew`], on by default; with `φ = 0` it is the
//! thesis's arithmetic exactly). The distances K and AD remain the
//! thesis's; the laser contributes only the two angles.
//!
//! ## The assumption
//! Everything above assumes both robots face *the same wall squarely*, with
//! views that overlap, and that the wall is flat. The thesis's robots did.
//! Two wall followers, one keeping the wall on its left and one on its
//! right, face a wall squarely only when they reach an inside corner, and
//! they reach every corner along *different* walls: when one faces the
//! wall ahead, the other, arriving from the far side, faces the wall the
//! first was following. They face the same wall only at the closed end of
//! a corridor or alcove narrow enough for their views to overlap (the
//! situation of Figure 18). Where a layout has none, the method finds no
//! pair it can use and answers `no_merge` with the reason.
//!
//! Conventions: pixels as in [`crate::surf`] (x right, y down, (0, 0) the
//! centre of the top-left pixel); metres and radians; robot frame x
//! forward, y left; poses are SLAM estimates in each robot's map frame.

use super::selection::front_wall;
use super::{FrameInfo, MergeStatus};
use crate::camera::PinholeCamera;
use crate::geom::{wrap_angle, Pose2};
use crate::surf::msac::homography_from_4;
use crate::surf::Homography;
use glam::DVec2;
use serde::Serialize;

/// One cell of the matched-pair table (the thesis's Table 1).
#[derive(Clone, Debug, PartialEq)]
pub struct PairMatch {
    /// Position in robot A's selected frames.
    pub a: usize,
    /// Position in robot B's selected frames.
    pub b: usize,
    /// MSAC homography inliers.
    pub inliers: usize,
    /// The homography mapping A's pixels to B's pixels.
    pub homography: Option<Homography>,
    /// A's image corners (top-left, top-right, bottom-right, bottom-left)
    /// in B's pixels: the matched region ([`crate::surf::MatchedRegion`]).
    pub quad: Option<[[f64; 2]; 4]>,
}

/// Every number of §6.2.4, as the page shows them. "Robot 1" and "robot 2"
/// are the thesis's roles: the robot that gives one frame (A') and the one
/// that gives two (D and E) — robots A and B, or B and A when
/// [`ThesisOutcome::swapped`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DistanceSolution {
    /// The camera's horizontal field of view θ (rad).
    pub hfov_rad: f64,
    /// tan(θ/2).
    pub tan_half_fov: f64,
    /// B'C': robot 1's view, pixels (its image width).
    pub bc_px: f64,
    /// FJ: robot 2's view at D, in robot 1's pixels.
    pub fj_px: f64,
    /// GH: robot 2's view at E, in robot 1's pixels.
    pub gh_px: f64,
    /// DE: robot 2's advance towards the wall from D to E (m).
    pub de_m: f64,
    /// K: metres of wall per pixel of robot 1's image.
    pub k_m_per_px: f64,
    /// AD: how much nearer the wall D is than robot 1 (m).
    pub ad_m: f64,
    /// Robot 1's distance from the wall the equations imply,
    /// `K · f = K · B'C' / (2 tan(θ/2))` (m).
    pub depth_a_m: f64,
    /// Where robot 2's view centre at D lands in robot 1's image, right of
    /// the image centre (pixels). Filled by [`thesis_merge`]; 0 from
    /// [`solve_distance`].
    pub shift_px: f64,
    /// AA': robot 2 at D stood this far to robot 1's *left*, along the wall
    /// (m): `−shift · K` in the thesis's arithmetic. Filled by
    /// [`thesis_merge`].
    pub aa_m: f64,
    /// Robot 1's distance from the wall as its laser measured it (m), for
    /// comparison; `None` when the laser saw no straight wall ahead.
    pub laser_depth_a_m: Option<f64>,
    /// How far robot 1 at A' and robot 2 at D were turned from facing the
    /// wall squarely, as their lasers saw it (rad, the wall's normal
    /// counter-clockwise from the heading, [`super::selection::FrontWall`]);
    /// `None` when not measured or not used.
    pub skew_a_rad: Option<f64>,
    pub skew_d_rad: Option<f64>,
    /// Robot 2's heading at D relative to robot 1's at A' (rad): 0 in the
    /// thesis (both square), `skew_a − skew_d` with the laser correction.
    pub relative_heading_rad: f64,
}

/// Solves the two equations of §6.2.4 for K and AD (see the module doc).
///
/// `hfov_rad` is the horizontal field of view θ, `bc_px`, `fj_px` and
/// `gh_px` the views B'C', FJ and GH in robot 1's pixels, `de_m` the signed
/// advance from D to E towards the wall.
///
/// Fails, saying why, on non-finite or non-positive lengths, a field of
/// view outside (0, π), DE = 0, FJ = GH (no scale change to measure K
/// with), or a negative K (the views shrink the wrong way for DE).
pub fn solve_distance(
    hfov_rad: f64,
    bc_px: f64,
    fj_px: f64,
    gh_px: f64,
    de_m: f64,
) -> Result<DistanceSolution, String> {
    let all = [hfov_rad, bc_px, fj_px, gh_px, de_m];
    if all.iter().any(|v| !v.is_finite()) {
        return Err("a length or the field of view is not a finite number".into());
    }
    if !(hfov_rad > 0.0 && hfov_rad < std::f64::consts::PI) {
        return Err(format!(
            "field of view {:.1}° is not between 0° and 180°",
            hfov_rad.to_degrees()
        ));
    }
    if bc_px <= 0.0 || fj_px <= 0.0 || gh_px <= 0.0 {
        return Err(format!(
            "the views must have positive widths (B'C' {bc_px:.1}, FJ {fj_px:.1}, GH {gh_px:.1} px)"
        ));
    }
    if de_m.abs() < 1e-9 {
        return Err("DE is zero: robot 2 did not move between D and E".into());
    }
    let scale_change = fj_px - gh_px;
    if scale_change.abs() < 1e-9 * bc_px {
        return Err(format!(
            "FJ = GH ({fj_px:.1} px): the view did not change size between D and E, so K is undetermined"
        ));
    }
    let tan_half = (0.5 * hfov_rad).tan();
    let k = 2.0 * de_m * tan_half / scale_change;
    if k <= 0.0 || !k.is_finite() {
        return Err(format!(
            "K = {k:.5} m/px is not positive: with DE = {de_m:.3} m the view at E should be {} than at D, but FJ = {fj_px:.1} px and GH = {gh_px:.1} px",
            if de_m > 0.0 { "narrower" } else { "wider" }
        ));
    }
    let ad = de_m * (bc_px - fj_px) / scale_change;
    Ok(DistanceSolution {
        hfov_rad,
        tan_half_fov: tan_half,
        bc_px,
        fj_px,
        gh_px,
        de_m,
        k_m_per_px: k,
        ad_m: ad,
        depth_a_m: k * bc_px / (2.0 * tan_half),
        shift_px: 0.0,
        aa_m: 0.0,
        laser_depth_a_m: None,
        skew_a_rad: None,
        skew_d_rad: None,
        relative_heading_rad: 0.0,
    })
}

/// Settings of [`thesis_merge_with`].
#[derive(Clone, Debug, PartialEq)]
pub struct ThesisConfig {
    /// A pair takes part only with at least this many inliers. Default 20.
    pub min_inliers: usize,
    /// D and E must be at least this far apart along the line of approach
    /// (m): the scale change between them measures K. Default 0.25.
    pub min_de_m: f64,
    /// D and E lie on one line of approach: headings within this (rad)...
    /// Default 0.1 (≈ 6°).
    pub max_heading_change_rad: f64,
    /// ...and sideways of each other by at most this (m). Default 0.2.
    pub max_sideways_m: f64,
    /// The matched region must be a rectangle (§6.2.3): its left and right
    /// sides may differ by this fraction, and its aspect ratio from the
    /// image's by this fraction. Default 0.15.
    pub max_keystone: f64,
    /// A solution is discarded when robot 1's depth `K · f` and its laser's
    /// distance to the wall differ by more than this fraction. Default 0.3.
    pub max_depth_error: f64,
    /// Pairs tried as the best pair, in order of inliers. Default 8.
    pub max_best_tried: usize,
    /// Correct for the robots not facing the wall exactly squarely, with
    /// the skew each robot's laser measured (a fill-in, see the module
    /// doc). Default true; false is the thesis's arithmetic as written.
    pub correct_skew: bool,
}

impl Default for ThesisConfig {
    fn default() -> Self {
        ThesisConfig {
            min_inliers: 20,
            min_de_m: 0.25,
            max_heading_change_rad: 0.1,
            max_sideways_m: 0.2,
            max_keystone: 0.15,
            max_depth_error: 0.3,
            max_best_tried: 8,
            correct_skew: true,
        }
    }
}

/// The outcome of the thesis's method on one pair of robots.
#[derive(Clone, Debug, PartialEq)]
pub struct ThesisOutcome {
    pub status: MergeStatus,
    /// What was done, or why nothing could be. Pairs in it are (row,
    /// column) of the matched-pair table counted from 1, as the thesis's
    /// Table 1 and the page count them.
    pub reason: String,
    /// The pair that gave the distance (positions in the selected frames,
    /// `(a, b)`), and the second pair: it shares robot 1's frame with the
    /// best (or robot 2's, when the roles were swapped).
    pub best: Option<(usize, usize)>,
    pub second: Option<(usize, usize)>,
    pub distance: Option<DistanceSolution>,
    /// Pose of robot B's map frame in robot A's map frame.
    pub pose: Option<Pose2>,
    /// 0..1: how many inliers backed the two pairs and how well the
    /// equations' depth agreed with the laser.
    pub confidence: f64,
    /// True when one frame of robot B and two of robot A were used.
    pub swapped: bool,
}

impl ThesisOutcome {
    fn no_merge(reason: String) -> ThesisOutcome {
        ThesisOutcome {
            status: MergeStatus::NoMerge,
            reason,
            best: None,
            second: None,
            distance: None,
            pose: None,
            confidence: 0.0,
            swapped: false,
        }
    }
}

/// How the other robot's image lies over the one robot's image.
#[derive(Clone, Copy, Debug, PartialEq)]
struct ViewInOne {
    /// The other's view in one's pixels: `W ×` the mean of the laid-over
    /// quad's sides, each over the matching image side (§5.3.4's
    /// "comparing the quadrangle's side length with the image's").
    width_px: f64,
    /// Where the other's image centre lands, right of one's centre (px).
    shift_px: f64,
    /// |left side / right side − 1| of the laid-over quad.
    keystone: f64,
    /// |(mean width / W) / (mean height / H) − 1|.
    aspect_error: f64,
}

/// Lays the other image over the one, through `h` (other's pixels to
/// one's). `None` if a corner maps to infinity or the quad is degenerate.
fn view_in_one(h: &Homography, cam: &PinholeCamera) -> Option<ViewInOne> {
    let (w, hh) = (cam.width as f64, cam.height as f64);
    let (cx, cy) = ((w - 1.0) / 2.0, (hh - 1.0) / 2.0);
    let centre = h.apply([cx, cy])?;
    let q = [
        h.apply([-0.5, -0.5])?,
        h.apply([w - 0.5, -0.5])?,
        h.apply([w - 0.5, hh - 0.5])?,
        h.apply([-0.5, hh - 0.5])?,
    ];
    let len = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    let (top, right, bottom, left) = (
        len(q[0], q[1]),
        len(q[1], q[2]),
        len(q[2], q[3]),
        len(q[3], q[0]),
    );
    // A mirrored quad (its corners turning the other way) is no view.
    let turn =
        (q[1][0] - q[0][0]) * (q[3][1] - q[0][1]) - (q[1][1] - q[0][1]) * (q[3][0] - q[0][0]);
    if !(turn > 0.0 && right > 0.0 && left > 0.0) {
        return None;
    }
    let across = 0.5 * (top + bottom) / w;
    let down = 0.5 * (left + right) / hh;
    let view = ViewInOne {
        width_px: w * 0.5 * (across + down),
        shift_px: centre[0] - cx,
        keystone: (left / right - 1.0).abs(),
        aspect_error: (across / down - 1.0).abs(),
    };
    [
        view.width_px,
        view.shift_px,
        view.keystone,
        view.aspect_error,
    ]
    .iter()
    .all(|v| v.is_finite())
    .then_some(view)
}

/// A's pixels to B's pixels for one table row: the homography, or the one
/// through the matched region's corners.
fn a_to_b(pm: &PairMatch, cam: &PinholeCamera) -> Option<Homography> {
    if let Some(h) = pm.homography {
        return Some(h);
    }
    let quad = pm.quad?;
    let (w, h) = (cam.width as f64, cam.height as f64);
    let corners = [
        [-0.5, -0.5],
        [w - 0.5, -0.5],
        [w - 0.5, h - 0.5],
        [-0.5, h - 0.5],
    ];
    homography_from_4(&corners, &quad)
}

/// One usable table row seen from the robot that gives one frame ("one")
/// and the robot that gives two ("two").
#[derive(Clone, Copy, Debug)]
struct Row {
    one: usize,
    two: usize,
    inliers: usize,
    /// The two-robot's image laid over the one-robot's.
    view: ViewInOne,
}

/// A computed merge for one choice of roles.
struct Solution {
    best: (usize, usize),
    second: (usize, usize),
    distance: DistanceSolution,
    /// Pose of the two-robot's map frame in the one-robot's map frame.
    pose: Pose2,
    confidence: f64,
}

/// Robot 2's pose at D in robot 1's frame at A' from the solved distances
/// (fills `aa_m` and `relative_heading_rad`). The wall is at robot 1's
/// depth `d_A = K·f` along its normal; robot 2's view centre lands on it
/// where robot 1's column `shift` looks; robot 2 stands `d_D = d_A − AD`
/// from the wall, behind that point along its own axis. With both skews 0
/// this is the thesis's `(AD, −shift·K, 0)`.
fn relative_pose(sol: &mut DistanceSolution, f_px: f64) -> Pose2 {
    let (skew_a, skew_d) = (sol.skew_a_rad.unwrap_or(0.0), sol.skew_d_rad.unwrap_or(0.0));
    let depth_a = sol.depth_a_m;
    let depth_d = depth_a - sol.ad_m;
    // Bearing (x forward, y left) of robot 2's view centre from robot 1.
    let bearing = -(sol.shift_px / f_px).atan();
    let normal = DVec2::from_angle(skew_a);
    let along = normal.perp();
    // Sideways offset along the wall from robot 1's foot to robot 2's.
    let sideways = depth_a * (bearing - skew_a).tan() + depth_d * skew_d.tan();
    let p = normal * sol.ad_m + along * sideways;
    sol.aa_m = sideways;
    sol.relative_heading_rad = wrap_angle(skew_a - skew_d);
    Pose2::new(p.x, p.y, sol.relative_heading_rad)
}

/// The method for one choice of roles: `ones` give one frame (robot 1 of
/// the thesis), `twos` two frames (robot 2). Returns the solution or the
/// reason none was found.
fn solve_roles(
    camera: &PinholeCamera,
    ones: &[FrameInfo],
    twos: &[FrameInfo],
    rows: &[Row],
    cfg: &ThesisConfig,
) -> Result<Solution, String> {
    let rectangular =
        |r: &Row| r.view.keystone <= cfg.max_keystone && r.view.aspect_error <= cfg.max_keystone;
    let mut order: Vec<&Row> = rows.iter().filter(|r| rectangular(r)).collect();
    if order.is_empty() {
        return Err(format!(
            "no matched region with at least {} inliers is a rectangle (§6.2.3): the views were not taken squarely",
            cfg.min_inliers
        ));
    }
    order.sort_by(|x, y| {
        y.inliers
            .cmp(&x.inliers)
            .then(x.one.cmp(&y.one))
            .then(x.two.cmp(&y.two))
    });
    let mut first_failure: Option<String> = None;
    for best in order.iter().take(cfg.max_best_tried.max(1)) {
        let a = &ones[best.one];
        let d = &twos[best.two];
        let heading_d = d.pose.heading();
        // Candidates for E: same frame of the one-robot, on D's line of
        // approach, far enough along it.
        let mut seconds: Vec<(&Row, f64)> = order
            .iter()
            .filter(|r| r.one == best.one && r.two != best.two)
            .filter_map(|r| {
                let e = &twos[r.two];
                let step = e.pose.position() - d.pose.position();
                let de = step.dot(heading_d);
                let sideways = (step - heading_d * de).length();
                let turned = wrap_angle(e.pose.theta - d.pose.theta).abs();
                (de.abs() >= cfg.min_de_m
                    && sideways <= cfg.max_sideways_m
                    && turned <= cfg.max_heading_change_rad)
                    .then_some((*r, de))
            })
            .collect();
        seconds.sort_by(|x, y| y.0.inliers.cmp(&x.0.inliers).then(x.0.two.cmp(&y.0.two)));
        if seconds.is_empty() {
            first_failure.get_or_insert(format!(
                "best pair ({}, {}) with {} inliers: no other frame on the same line of approach matched frame {}",
                best.one + 1, best.two + 1, best.inliers, best.one + 1
            ));
            continue;
        }
        let laser_depth = front_wall(a).map(|w| w.distance_m);
        for (second, de) in seconds {
            let mut sol = match solve_distance(
                camera.hfov_rad,
                camera.width as f64,
                best.view.width_px,
                second.view.width_px,
                de,
            ) {
                Ok(s) => s,
                Err(why) => {
                    first_failure.get_or_insert(format!(
                        "pairs ({}, {}) and ({}, {}): {why}",
                        best.one + 1,
                        best.two + 1,
                        second.one + 1,
                        second.two + 1
                    ));
                    continue;
                }
            };
            sol.shift_px = best.view.shift_px;
            sol.laser_depth_a_m = laser_depth;
            // The depth the equations imply must be a plausible one.
            let agreement = match laser_depth {
                Some(l) => {
                    let err = (sol.depth_a_m - l).abs() / l.max(1e-6);
                    if err > cfg.max_depth_error {
                        first_failure.get_or_insert(format!(
                            "pairs ({}, {}) and ({}, {}): the equations put robot 1 {:.2} m from the wall, its laser {:.2} m",
                            best.one + 1, best.two + 1, second.one + 1, second.two + 1, sol.depth_a_m, l
                        ));
                        continue;
                    }
                    (-0.5f64 * (err / (0.5 * cfg.max_depth_error)).powi(2)).exp()
                }
                None => 0.5,
            };
            if cfg.correct_skew {
                if let (Some(wa), Some(wd)) = (front_wall(a), front_wall(d)) {
                    sol.skew_a_rad = Some(wa.skew_rad);
                    sol.skew_d_rad = Some(wd.skew_rad);
                }
            }
            let rel = relative_pose(&mut sol, camera.f_px);
            let pose = a.pose.compose(&rel).compose(&d.pose.inverse());
            if !pose.is_finite() {
                continue;
            }
            let support =
                1.0 - (-(second.inliers as f64) / (2.0 * cfg.min_inliers.max(1) as f64)).exp();
            return Ok(Solution {
                best: (best.one, best.two),
                second: (second.one, second.two),
                distance: sol,
                pose,
                confidence: (support * agreement).clamp(0.0, 1.0),
            });
        }
    }
    Err(first_failure.unwrap_or_else(|| "no pair of frame pairs gave a distance".into()))
}

/// The thesis's merge (§6.2.4–6.2.5) with the default settings. `a_frames`
/// and `b_frames` are the *selected* frames of robots A and B, and `table`
/// indexes into them. See [`thesis_merge_with`].
pub fn thesis_merge(
    camera: &PinholeCamera,
    a_frames: &[FrameInfo],
    b_frames: &[FrameInfo],
    table: &[PairMatch],
) -> ThesisOutcome {
    thesis_merge_with(camera, a_frames, b_frames, table, &ThesisConfig::default())
}

/// The thesis's merge: the best matched pair and a second one sharing its
/// robot-A frame give K and AD (§6.2.4), the best pair's shift gives the
/// sideways offset, and the headings give the rotation (§6.2.5); see the
/// module doc. If robot A's frames offer no such triple, the roles are
/// swapped (one frame of B, two of A). Never panics; rows that index
/// outside the frame slices or lack geometry are ignored.
pub fn thesis_merge_with(
    camera: &PinholeCamera,
    a_frames: &[FrameInfo],
    b_frames: &[FrameInfo],
    table: &[PairMatch],
    cfg: &ThesisConfig,
) -> ThesisOutcome {
    if a_frames.is_empty() || b_frames.is_empty() {
        return ThesisOutcome::no_merge(format!(
            "image selection kept {} and {} frames: nothing to match (no frame was taken facing a wall squarely)",
            a_frames.len(),
            b_frames.len()
        ));
    }
    if !(camera.width > 0 && camera.height > 0 && camera.hfov_rad.is_finite()) {
        return ThesisOutcome::no_merge("the camera has no valid size or field of view".into());
    }
    // Usable rows, both ways round.
    let mut rows_a_one = Vec::new();
    let mut rows_b_one = Vec::new();
    for pm in table {
        if pm.a >= a_frames.len() || pm.b >= b_frames.len() || pm.inliers < cfg.min_inliers {
            continue;
        }
        let Some(h) = a_to_b(pm, camera) else {
            continue;
        };
        if let Some(view) = h.inverse().and_then(|hi| view_in_one(&hi, camera)) {
            rows_a_one.push(Row {
                one: pm.a,
                two: pm.b,
                inliers: pm.inliers,
                view,
            });
        }
        if let Some(view) = view_in_one(&h, camera) {
            rows_b_one.push(Row {
                one: pm.b,
                two: pm.a,
                inliers: pm.inliers,
                view,
            });
        }
    }
    if rows_a_one.is_empty() && rows_b_one.is_empty() {
        let strong = table
            .iter()
            .filter(|p| p.inliers >= cfg.min_inliers)
            .count();
        let top = table.iter().map(|p| p.inliers).max().unwrap_or(0);
        return ThesisOutcome::no_merge(if strong == 0 {
            format!(
                "no frame pair has {} or more inliers (the best has {top}): the robots never saw the same wall squarely",
                cfg.min_inliers
            )
        } else {
            format!(
                "{strong} frame pairs have {} or more inliers, but none has a usable matched region",
                cfg.min_inliers
            )
        });
    }
    let thesis_roles = solve_roles(camera, a_frames, b_frames, &rows_a_one, cfg);
    let (solution, swapped) = match thesis_roles {
        Ok(s) => (s, false),
        Err(why) => match solve_roles(camera, b_frames, a_frames, &rows_b_one, cfg) {
            Ok(s) => (s, true),
            Err(_) => return ThesisOutcome::no_merge(why),
        },
    };
    let Solution {
        best,
        second,
        distance,
        pose,
        confidence,
    } = solution;
    let (pose, best, second) = if swapped {
        (pose.inverse(), (best.1, best.0), (second.1, second.0))
    } else {
        (pose, best, second)
    };
    let (one, two) = if swapped { ("B", "A") } else { ("A", "B") };
    let reason = format!(
        "pairs ({}, {}) and ({}, {}): K = {:.4} m/px, AD = {:.2} m, AA' = {:.2} m (robot {one}'s frame, robot {two}'s two frames)",
        best.0 + 1, best.1 + 1, second.0 + 1, second.1 + 1, distance.k_m_per_px, distance.ad_m, distance.aa_m
    );
    ThesisOutcome {
        status: MergeStatus::Merged,
        reason,
        best: Some(best),
        second: Some(second),
        distance: Some(distance),
        pose: Some(pose),
        confidence,
        swapped,
    }
}
