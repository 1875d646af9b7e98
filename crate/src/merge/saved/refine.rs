//! # Refine: aligning two saved maps from a person's rough guess
//!
//! The automatic saved-maps merge ([`super`]) searches the whole of
//! map A for map B and answers `no_merge` when it cannot tell which overlay
//! is the right one: a building that looks the same turned by 180°, a row
//! of identical rooms. A person looking at the two maps often can: the
//! stairwell is *there*, not at the other end. In the page they drag and
//! turn B roughly onto A and press **Refine**; this stage takes that rough
//! overlay (B's map frame in A's map frame, the convention of the report's
//! transforms) and does three things:
//!
//! 1. **A local coarse search around the guess.** A drag is rough, so the
//!    search looks in a window of ±`window_cells` cells (50 cells: 2.5 m at
//!    the common 0.05 m, never less than 2.5 m) and ±`window_deg` (20°)
//!    around the guess. B is turned about its walls' centre (so a turn
//!    does not also swing it away), in `step_deg` (1°) steps, and moved in steps
//!    of `step_cells` cells (4: 0.2 m at 0.05 m); each overlay is scored
//!    by the wide likelihood field of the automatic search,
//!    `Σ max(0, 1 − d/τ)` over a thinned set of B's wall points with
//!    `τ = 0.5 m` (Thrun, Burgard and Fox, *Probabilistic Robotics* §6.4).
//!    This is E. Olson's brute-force correlative matching (*Real-time
//!    correlative scan matching*, ICRA 2009) restricted to a prior window,
//!    which is exactly what Olson uses it for: the window comes from the
//!    person instead of from odometry. The best few overlays that differ
//!    from each other (by the verdict's own `distinct_m` / `distinct_rad`)
//!    go on.
//! 2. **The automatic merge's refinement**: each goes through the same
//!    pattern search on the wide, then narrow field
//!    ([`super::search::refine`]), so a refined overlay is as
//!    precise as an automatic one.
//! 3. **The same verdict** ([`super::evidence`]): enough common wall,
//!    agreement dominating the contradiction (the acceptance index), and a
//!    clear winner. The one thing the guess legitimately replaces is the
//!    *global* ambiguity: the rival whose support the winner must exceed
//!    1.5 times is taken among the overlays found in the guess's window,
//!    not in the whole map. So a symmetric building the automatic merge
//!    declined as ambiguous merges when the person points at the right
//!    end; but a guess onto the wrong place (the walls do not agree there)
//!    or onto another building is still refused, with the numbers, and a
//!    window holding two overlays that fit as well (a row of equal rooms
//!    one step apart) is still ambiguous. And the guess settles only a near
//!    tie: when the automatic search of the pair found a different overlay
//!    with 1.5 times the refined one's support, the refined one is refused
//!    ([`refuse_if_beaten`]), so a person cannot talk the lab out of a
//!    clear winner.
//!
//! Every reason starts "refined from your guess", so a reader of the report
//! knows a person chose the neighbourhood.

use super::evidence::{distinct, evidence, Evidence};
pub use super::search::RefineConfig;
use super::search::{field_score, refine, thinned};
use super::wallmap::WallMap;
use super::{judge_overlays, PairResult, SavedMergeConfig};
use crate::formats::rosmap::RosMap;
use crate::geom::{wrap_angle, Pose2};
use crate::merge::MergeStatus;
use glam::DVec2;

/// The best distinct coarse overlays (B's image frame in A's) in the window
/// around `start` (step 1 of the module doc), best first.
fn window_peaks(a: &WallMap, b: &WallMap, start: Pose2, cfg: &SavedMergeConfig) -> Vec<Pose2> {
    let r = &cfg.refine;
    let (half_m, step_m) = r.window_m(a.resolution, b.resolution);
    let n = (half_m / step_m).round() as i64;
    let m = (r.window_deg / r.step_deg).round() as i64;
    let centre = b.walls.iter().copied().sum::<DVec2>() / b.walls.len().max(1) as f64;
    let points = thinned(&b.walls, r.points);
    let at = start.transform_point(centre);
    let mut scored: Vec<(f64, Pose2)> = Vec::new();
    for k in -m..=m {
        let theta = start.theta + (k as f64 * r.step_deg).to_radians();
        let (s, c) = theta.sin_cos();
        let turned = DVec2::new(c * centre.x - s * centre.y, s * centre.x + c * centre.y);
        for iy in -n..=n {
            for ix in -n..=n {
                let t = at + DVec2::new(ix as f64, iy as f64) * step_m - turned;
                let pose = Pose2::new(t.x, t.y, theta);
                let score = field_score(a, &points, &pose, cfg.search.tau_wide_m);
                if score > 0.0 {
                    scored.push((score, pose));
                }
            }
        }
    }
    // Best first; ties in a fixed order so the result is deterministic.
    scored.sort_by(|p, q| {
        q.0.total_cmp(&p.0)
            .then(p.1.theta.total_cmp(&q.1.theta))
            .then(p.1.x.total_cmp(&q.1.x))
            .then(p.1.y.total_cmp(&q.1.y))
    });
    let mut kept: Vec<Pose2> = Vec::new();
    for (_, pose) in scored {
        if kept.len() >= r.peaks.max(1) {
            break;
        }
        if kept
            .iter()
            .all(|k| distinct(k, &pose, centre, &cfg.evidence))
        {
            kept.push(pose);
        }
    }
    kept
}

/// How every reason of a refined pair begins.
fn guess_prefix(a: &RosMap, b: &RosMap, cfg: &SavedMergeConfig) -> String {
    let (half_m, _) = cfg.refine.window_m(a.resolution, b.resolution);
    format!(
        "refined from your guess (within {:.1} m and {:.0}° of it)",
        half_m, cfg.refine.window_deg
    )
}

/// Aligns B on A from `guess` (B's map frame in A's map frame) and judges
/// the result (see the module doc). `Err` only for a guess that is not
/// finite numbers; a refused overlay is an `Ok` with status `NoMerge` and
/// the reason.
pub fn refine_pair(
    (ia, a, wa): (usize, &RosMap, &WallMap),
    (ib, b, wb): (usize, &RosMap, &WallMap),
    guess: Pose2,
    cfg: &SavedMergeConfig,
) -> Result<PairResult, String> {
    if !guess.is_finite() {
        return Err(format!(
            "the guess must be finite numbers, got x = {}, y = {}, theta = {}",
            guess.x, guess.y, guess.theta
        ));
    }
    let mut out = PairResult::unjudged(ia, ib);
    out.guess = Some(guess);
    let prefix = guess_prefix(a, b, cfg);
    if wa.walls.len() < 10 || wb.walls.len() < 10 {
        out.reason = format!("{prefix}: a map has (almost) no walls to align");
        return Ok(out);
    }
    // The guess between image frames, P = origin_A⁻¹ ⊕ guess ⊕ origin_B
    // (the report's pose is origin_A ⊕ P ⊕ origin_B⁻¹).
    let start = a.origin.inverse().compose(&guess).compose(&b.origin);
    let (_, step_m) = cfg.refine.window_m(a.resolution, b.resolution);
    let judged: Vec<(Pose2, Evidence)> = window_peaks(wa, wb, start, cfg)
        .into_iter()
        .map(|p| {
            let (pose, _) = refine(wa, wb, p, step_m, &cfg.search);
            (pose, evidence(wa, wb, &pose, &cfg.evidence))
        })
        .collect();
    out.overlays = judged.len();
    if !judge_overlays(&mut out, (a, b, wb), &judged, cfg, "near your guess") {
        out.reason = format!("{prefix}: no wall of one map comes near the other's there");
        return Ok(out);
    }
    out.pose = out.pose.map(|p| Pose2::new(p.x, p.y, wrap_angle(p.theta)));
    out.reason = format!("{prefix}: {}", out.reason);
    Ok(out)
}

/// The guess settles a near tie, never a clear winner: a refined pair
/// (`refined`, of maps `a` and `b`) is refused when the automatic search of
/// the same pair (`automatic`, same order) found a different overlay with
/// at least `min_margin` times its net support. Returns whether it was.
pub fn refuse_if_beaten(
    refined: &mut PairResult,
    automatic: &PairResult,
    (a, b): (&RosMap, &RosMap),
    cfg: &SavedMergeConfig,
) -> bool {
    let (Some(mine), Some(theirs)) = (refined.evidence, automatic.evidence) else {
        return false;
    };
    let (Some(p), Some(q)) = (refined.pose, automatic.pose) else {
        return false;
    };
    let at = b
        .origin
        .transform_point(DVec2::new(b.width as f64, b.height as f64) * 0.5 * b.resolution);
    let beaten = (refined.a, refined.b) == (automatic.a, automatic.b)
        && refined.status == MergeStatus::Merged
        && distinct(&p, &q, at, &cfg.evidence)
        && theirs.support_m >= cfg.evidence.min_margin * mine.support_m.max(0.0);
    if beaten {
        refined.status = MergeStatus::NoMerge;
        refined.confidence = 0.0;
        refined.reason = format!(
            "{}: the walls agree there ({:.1} m of net support), but the automatic search found another overlay with {:.1} m, {:.1} times as much ({:.1} times makes it the clear winner): the maps fit best elsewhere",
            guess_prefix(a, b, cfg),
            mine.support_m,
            theirs.support_m,
            theirs.support_m / mine.support_m.max(1e-9),
            cfg.evidence.min_margin
        );
    }
    beaten
}
