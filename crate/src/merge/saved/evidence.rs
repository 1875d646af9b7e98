//! # Evidence that two real maps show one place, and the saved-maps verdict
//!
//! The lab's verdict ([`crate::merge::verdict`]) refuses an overlay as soon as a
//! short piece of wall stands in the other map's free space. On maps the
//! lab makes itself that is right. On real maps it vetoes the truth: maps
//! of one building from different runs put 0.3–6 % of their common wall,
//! and maps from different sensors 17–70 %, into each other's free space
//! (bends, furniture moved, doors open in one run and shut in the other).
//! What still separates a true overlay from a wrong one is *how much* wall
//! lies on wall, against how much lies where the other map saw through,
//! measured with tolerance. This is Birk and Carpin's acceptance index
//! (A. Birk and S. Carpin, *Merging occupancy grid maps from multiple
//! robots*, Proc. IEEE 94(7), 2006: agreement / (agreement + disagreement)),
//! counted on wall-surface points with a tolerance band:
//!
//! * a wall point of one map **agrees** when the other map has a wall
//!   within `agree_m` (0.15 m: three 5 cm cells);
//! * it is **in the band** when the nearest wall is within `band_m`
//!   (0.5 m): bent or thick walls, neither for nor against;
//! * it **disagrees** when there is no wall within `band_m` and it stands
//!   in the other map's *free* space;
//! * anywhere else (the other map's unknown) it says nothing.
//!
//! Both directions are counted (B's walls on A, and A's on B), and the
//! overlay is accepted only when all of these hold:
//!
//! 1. **enough common wall**: at least `min_agree_m` metres of each map's
//!    wall agree (a point is a cell of wall face, so points × resolution);
//! 2. **agreement dominates**: the acceptance index of the two directions
//!    pooled is at least `min_index`;
//! 3. **a clear winner**: overlays are ranked by their *net support*,
//!    agreeing wall minus disagreeing wall (metres), and every
//!    *different* overlay the search found (its transform moves B's walls
//!    by `distinct_m` or turns them by `distinct_rad`) has at most
//!    `1 / min_margin` of the winner's net support. A symmetric building turned by 180° lies on itself in part,
//!    never as well as the truth, so the margin is a ratio of agreement
//!    measured this tightly, not the lab's 2.5.
//!
//! Two different buildings can put a few metres of wall on each other by
//! chance, but not tens of metres with most of the overlap agreeing: the
//! thresholds come from the measurements that `tests/real_maps.rs` records
//! (laser maps of four buildings, each pair and every cross-building pair).

use super::wallmap::WallMap;
use crate::geom::{wrap_angle, Pose2};
use crate::slam::grid::CellState;
use glam::DVec2;
use serde::Serialize;

/// Settings of the saved-maps verdict.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EvidenceConfig {
    pub agree_m: f64,
    pub band_m: f64,
    pub min_agree_m: f64,
    pub min_index: f64,
    pub min_margin: f64,
    /// What a disagreeing wall point costs in the net support, in
    /// agreeing points. Default 1 (the figures in BENCHMARKS.md).
    pub disagree_weight: f64,
    pub distinct_m: f64,
    pub distinct_rad: f64,
}

impl Default for EvidenceConfig {
    fn default() -> Self {
        EvidenceConfig {
            agree_m: 0.15,
            band_m: 0.5,
            min_agree_m: 20.0,
            min_index: 0.7,
            min_margin: 1.5,
            disagree_weight: 1.0,
            distinct_m: 1.0,
            distinct_rad: 3f64.to_radians(),
        }
    }
}

/// What one overlay shows, in both directions (`[B on A, A on B]`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Evidence {
    pub agree: [usize; 2],
    pub band: [usize; 2],
    pub disagree: [usize; 2],
    /// Metres of agreeing wall, the smaller direction.
    pub agree_m: f64,
    /// Pooled acceptance index `agree / (agree + disagree)` (0 with none).
    pub index: f64,
    /// Net support, metres of wall: agreeing wall minus `disagree_weight`
    /// times disagreeing wall, the mean of the two directions. What
    /// overlays are ranked by, and what the margin compares.
    pub support_m: f64,
}

fn one_way(target: &WallMap, points: &[DVec2], pose: &Pose2, cfg: &EvidenceConfig) -> [usize; 3] {
    let f = pose.frame();
    let mut n = [0usize; 3];
    for p in points {
        let q = f.to_parent(*p);
        match target.wall_distance(q) {
            Some(d) if d <= cfg.agree_m => n[0] += 1,
            Some(d) if d <= cfg.band_m => n[1] += 1,
            _ => {
                if target.state_at(q) == CellState::Free {
                    n[2] += 1;
                }
            }
        }
    }
    n
}

/// The evidence of B laid on A at `pose` (B's image frame in A's).
pub fn evidence(a: &WallMap, b: &WallMap, pose: &Pose2, cfg: &EvidenceConfig) -> Evidence {
    let ba = one_way(a, &b.walls, pose, cfg);
    let ab = one_way(b, &a.walls, &pose.inverse(), cfg);
    let agree = [ba[0], ab[0]];
    let disagree = [ba[2], ab[2]];
    let total_agree = (agree[0] + agree[1]) as f64;
    let total = total_agree + (disagree[0] + disagree[1]) as f64;
    Evidence {
        agree,
        band: [ba[1], ab[1]],
        disagree,
        agree_m: (agree[0] as f64 * b.resolution).min(agree[1] as f64 * a.resolution),
        index: if total > 0.0 {
            total_agree / total
        } else {
            0.0
        },
        support_m: 0.5
            * ((ba[0] as f64 - cfg.disagree_weight * ba[2] as f64) * b.resolution
                + (ab[0] as f64 - cfg.disagree_weight * ab[2] as f64) * a.resolution),
    }
}

/// Whether two overlays of B differ (at B's wall centre `at`).
pub fn distinct(p: &Pose2, q: &Pose2, at: DVec2, cfg: &EvidenceConfig) -> bool {
    (p.transform_point(at) - q.transform_point(at)).length() >= cfg.distinct_m
        || wrap_angle(p.theta - q.theta).abs() >= cfg.distinct_rad
}

/// The verdict on the best overlay given its evidence and the best
/// rival's net support (m): `Ok(confidence)` or `Err(reason)`.
pub fn judge(e: &Evidence, rival_support_m: f64, cfg: &EvidenceConfig) -> Result<f64, String> {
    let rival = rival_support_m.max(0.0);
    if e.agree_m < cfg.min_agree_m {
        return Err(format!(
            "too little common wall: {:.1} m of wall agree within {:.2} m ({:.0} m needed)",
            e.agree_m, cfg.agree_m, cfg.min_agree_m
        ));
    }
    if e.index < cfg.min_index {
        return Err(format!(
            "the maps disagree: at the best overlay only {:.0} % of the overlapping wall lies on the other map's wall ({} points agree, {} stand in free space; {:.0} % needed)",
            100.0 * e.index,
            e.agree[0] + e.agree[1],
            e.disagree[0] + e.disagree[1],
            100.0 * cfg.min_index
        ));
    }
    if e.support_m < cfg.min_margin * rival {
        return Err(format!(
            "ambiguous: another overlay fits almost as well ({:.1} m and {:.1} m of net supporting wall; {:.1} times needed)",
            e.support_m, rival, cfg.min_margin
        ));
    }
    let margin = if rival > 0.0 {
        1.0 - rival / e.support_m
    } else {
        1.0
    };
    let amount = 1.0 - (-e.agree_m / 50.0).exp();
    Ok((e.index * margin * amount).clamp(0.0, 1.0))
}
