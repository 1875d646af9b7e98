//! # Checking a benchmark's relations against their own scans and wheels
//!
//! The relations of Kümmerle et al. ([`super::benchmark_relations`]) were
//! made by matching pairs of scans and having a person accept each match:
//! they are a reference with errors of its own. Scoring a SLAM against
//! them is only as good as they are, so each can be put to two witnesses
//! that do not depend on the SLAM being scored:
//!
//! 1. **Its two scans** ([`super::verified::check_pair`]): the later scan
//!    aligned onto the earlier one by point-to-line ICP, once from the
//!    relation and once from the estimate. Where both starts reach one
//!    pose that pins every direction, that pose is what the scans say
//!    (they *settle* it). A relation more than 0.1 m or 1° from it, at
//!    which the scans fit worse (by 2 mm of mean misfit), is contradicted
//!    by its own scans.
//! 2. **The wheel odometry**, where the scans settle nothing (a corridor
//!    whose ends are out of sight pins nothing along it, and there the
//!    relation says what no scan can): over a few scans the wheels'
//!    random walk is millimetres, so a relation far outside it is
//!    contradicted ([`super::verified::odometry_contradicts`]).
//!
//! Where the scans settle a pose, the check also measures how far the
//! relations themselves lie from it beside how far the estimate does: the
//! reference's own noise, the floor under any method's score. On the raw
//! FR079 log the relations lie 0.41° from what their scans settle, more
//! than the 0.40° an estimate is asked to reach against them.
//!
//! A scan matcher aligns scans by construction, so the scans' witness
//! favours one; the wheels' does not. A scoring tool, read only where
//! results are scored: the SLAM never sees it.

use super::benchmark_relations::{Relation, RelationScore, Spread};
use super::verified::{check_pair, odometry_contradicts, VerifyConfig};
use crate::geom::Pose2;
use glam::DVec2;
use serde::Serialize;

/// A relation more than this from the pose its scans settle (m, rad), at
/// which they fit worse by [`WORSE_FIT_M`], is contradicted by them.
const CONTRADICTED_M: f64 = 0.1;
const CONTRADICTED_RAD: f64 = 0.017_453_292_519_943_295; // 1°
/// How much worse (mean point-to-line misfit, m) the scans must fit at a
/// relation they contradict than at the pose they settle.
const WORSE_FIT_M: f64 = 0.002;
/// An estimate's relation errors over this (m, deg) are listed with what
/// the witnesses say.
const MISS_M: f64 = 0.2;
const MISS_DEG: f64 = 2.0;

/// What a replay knows of the scans a score matched: for the `k`-th scan
/// scored, the estimate's laser pose, and the wheels' (at the laser) when
/// the log has odometry with its measured noise per step (m² along each
/// axis, [`crate::slam::logs::fusion`]).
pub struct Witnesses<'a> {
    pub lasers: &'a [Pose2],
    pub wheels: Option<(&'a [Pose2], [f64; 2])>,
}

/// Mean translational and rotational distance.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct MeanOffset {
    pub trans_m: f64,
    pub rot_deg: f64,
}

/// A relation a witness contradicts.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Contradicted {
    pub t1: f64,
    pub t2: f64,
    /// `"scans"` or `"odometry"`.
    pub by: &'static str,
    /// How far the relation lies from what the witness says.
    pub off_m: f64,
    pub off_deg: f64,
    /// The estimate's error against the relation, and against the witness.
    pub ours_m: f64,
    pub ours_deg: f64,
    pub ours_vs_witness_m: f64,
}

/// A relation the estimate misses by over 0.2 m or 2°, and whether its
/// scans settle a pose (then the estimate's distance from it).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Miss {
    pub t1: f64,
    pub t2: f64,
    pub trans_m: f64,
    pub rot_deg: f64,
    pub settled: Option<MeanOffset>,
}

/// The relations checked against their witnesses.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RelationCheck {
    /// Relations checked (those the score matched), those whose scans
    /// settle a pose, and those contradicted by each witness.
    pub checked: usize,
    pub settled: usize,
    pub by_scans: usize,
    pub by_odometry: usize,
    /// Where the scans settle a pose: how far the relations lie from it,
    /// and how far the estimate does.
    pub relations_vs_scans: MeanOffset,
    pub ours_vs_scans: MeanOffset,
    /// The estimate's errors against the relations no witness contradicts.
    pub uncontradicted: usize,
    pub trans_m: Spread,
    pub rot_deg: Spread,
    pub contradicted: Vec<Contradicted>,
    pub misses: Vec<Miss>,
}

fn offset(a: &Pose2, b: &Pose2) -> (f64, f64) {
    let d = a.between(b);
    (d.position().length(), d.theta.abs().to_degrees())
}

/// Checks the relations `score` matched (`relations` in the file's order,
/// as its errors are) against their scans (`points(k)`: the `k`-th scored
/// scan's returns in its laser's frame) and the wheels.
pub fn check_relations(
    relations: &[Relation],
    score: &RelationScore,
    seen: &Witnesses,
    mut points: impl FnMut(usize) -> Vec<DVec2>,
    cfg: &VerifyConfig,
) -> RelationCheck {
    let mut out = RelationCheck::default();
    let (mut kept_t, mut kept_r) = (Vec::new(), Vec::new());
    let (mut file, mut ours_s) = (Vec::new(), Vec::new());
    // Each scan's points, made once however many relations it is in.
    let mut made: Vec<Option<Vec<DVec2>>> = vec![None; seen.lasers.len()];
    // The score's errors are the matched relations', in the file's order.
    let mut errors = score.errors.iter().peekable();
    for r in relations {
        let Some(e) = errors.next_if(|e| e.t1 == r.t1 && e.t2 == r.t2) else {
            continue;
        };
        out.checked += 1;
        let ours = seen.lasers[e.scan1].between(&seen.lasers[e.scan2]);
        for k in [e.scan1, e.scan2] {
            if made[k].is_none() {
                made[k] = Some(points(k));
            }
        }
        let scan = |k: usize| made[k].as_deref().unwrap_or(&[]);
        let c = check_pair(scan(e.scan1), scan(e.scan2), &r.pose, &ours, cfg);
        let (given_m, given_deg) = offset(&ours, &r.pose);
        if e.trans_m > MISS_M || e.rot_deg > MISS_DEG {
            out.misses.push(Miss {
                t1: r.t1,
                t2: r.t2,
                trans_m: e.trans_m,
                rot_deg: e.rot_deg,
                settled: c.settled.map(|s| {
                    let (trans_m, rot_deg) = offset(&ours, &s);
                    MeanOffset { trans_m, rot_deg }
                }),
            });
        }
        let mut witness = None;
        if let Some(s) = c.settled {
            out.settled += 1;
            file.push(offset(&r.pose, &s));
            ours_s.push(offset(&ours, &s));
            let off = r.pose.between(&s);
            if (off.position().length() > CONTRADICTED_M || off.theta.abs() > CONTRADICTED_RAD)
                && c.misfit_settled + WORSE_FIT_M < c.misfit_given
            {
                out.by_scans += 1;
                witness = Some(("scans", s));
            }
        } else if let Some((wheels, variance)) = seen.wheels {
            let odometry = wheels[e.scan1].between(&wheels[e.scan2]);
            let steps = e.scan2.abs_diff(e.scan1);
            if odometry_contradicts(&r.pose, &odometry, steps, variance) {
                out.by_odometry += 1;
                witness = Some(("odometry", odometry));
            }
        }
        match witness {
            Some((by, w)) => {
                let (off_m, off_deg) = offset(&r.pose, &w);
                out.contradicted.push(Contradicted {
                    t1: r.t1,
                    t2: r.t2,
                    by,
                    off_m,
                    off_deg,
                    ours_m: given_m,
                    ours_deg: given_deg,
                    ours_vs_witness_m: offset(&ours, &w).0,
                });
            }
            None => {
                kept_t.push(given_m);
                kept_r.push(given_deg);
            }
        }
    }
    let mean = |v: &[(f64, f64)]| {
        let n = v.len().max(1) as f64;
        MeanOffset {
            trans_m: v.iter().map(|x| x.0).sum::<f64>() / n,
            rot_deg: v.iter().map(|x| x.1).sum::<f64>() / n,
        }
    };
    out.relations_vs_scans = mean(&file);
    out.ours_vs_scans = mean(&ours_s);
    out.uncontradicted = kept_t.len();
    out.trans_m = Spread::of(&kept_t);
    out.rot_deg = Spread::of(&kept_r);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::slam::eval::benchmark_relations::score_relations;
    use crate::slam::eval::verified::tests::room_seen_from;

    /// The check of `relations` on scans at `times` and `lasers`, each
    /// seeing `scene` from its pose; with wheels at the same poses (σ 3 mm
    /// a step) or without.
    fn run_check(
        relations: &[Relation],
        times: &[f64],
        lasers: &[Pose2],
        with_wheels: bool,
        scene: impl Fn(&Pose2) -> Vec<DVec2>,
    ) -> RelationCheck {
        let score = score_relations(times, lasers, relations);
        let seen = Witnesses {
            lasers,
            wheels: with_wheels.then_some((lasers, [1e-5, 1e-5])),
        };
        let points = |k: usize| scene(&lasers[k]);
        check_relations(relations, &score, &seen, points, &VerifyConfig::default())
    }

    #[test]
    fn a_wrong_relation_is_caught_by_its_scans_and_a_right_one_kept() {
        let truth = [Pose2::new(-1.0, 0.0, 0.1), Pose2::new(-0.4, 0.2, 0.3)];
        let exact = truth[0].between(&truth[1]);
        // One relation true, one 0.3 m and 2° off.
        let off = exact.compose(&Pose2::new(0.3, 0.0, 2f64.to_radians()));
        let relations = [
            Relation {
                t1: 0.0,
                t2: 1.0,
                pose: exact,
            },
            Relation {
                t1: 0.0,
                t2: 1.000_5,
                pose: off,
            },
        ];
        // Three scans: the second and third are one place (stamps 1.0 and 1.0005).
        let lasers = [truth[0], truth[1], truth[1]];
        let times = [0.0, 1.0, 1.000_5];
        let check = run_check(&relations, &times, &lasers, false, room_seen_from);
        assert_eq!((check.checked, check.settled, check.by_scans), (2, 2, 1));
        assert_eq!(check.contradicted[0].t2, 1.000_5);
        assert!(
            (check.contradicted[0].off_m - 0.3).abs() < 0.02,
            "{check:?}"
        );
        // The estimate is exact: against the one relation kept, no error.
        assert_eq!(check.uncontradicted, 1);
        assert!(check.trans_m.mean < 1e-9);
        // The relations lie 0.15 m and 1° from the scans on average; the
        // estimate on them.
        assert!((check.relations_vs_scans.trans_m - 0.15).abs() < 0.01);
        assert!((check.relations_vs_scans.rot_deg - 1.0).abs() < 0.05);
        assert!(check.ours_vs_scans.trans_m < 0.005);
        // The estimate misses the wrong relation by 0.3 m: listed, with
        // the scans' pose near the estimate.
        assert_eq!(check.misses.len(), 1);
        assert!(check.misses[0].settled.unwrap().trans_m < 0.005);
    }

    #[test]
    fn in_a_corridor_the_wheels_witness_what_the_scans_cannot() {
        // Two long walls 2 m apart: nothing pins a pose along them.
        let corridor = |pose: &Pose2| -> Vec<DVec2> {
            let f = pose.frame();
            let mut seen = (0..2000)
                .flat_map(|k| {
                    let x = -20.0 + k as f64 * 0.02;
                    [DVec2::new(x, 0.0), DVec2::new(x, 2.0)]
                })
                .map(|p| f.to_local(p))
                .collect::<Vec<_>>();
            seen.sort_by(|a, b| a.y.atan2(a.x).total_cmp(&b.y.atan2(b.x)));
            seen
        };
        // Wheels and estimate say 0.34 m along the corridor; the relation 0.75.
        let lasers = [Pose2::new(0.0, 1.0, 0.0), Pose2::new(0.34, 1.0, 0.0)];
        let relations = [Relation {
            t1: 0.0,
            t2: 0.5,
            pose: Pose2::new(0.75, 0.0, 0.0),
        }];
        let check = run_check(&relations, &[0.0, 0.5], &lasers, true, corridor);
        assert_eq!(
            (check.settled, check.by_scans, check.by_odometry),
            (0, 0, 1)
        );
        assert_eq!(check.contradicted[0].by, "odometry");
        assert!((check.contradicted[0].off_m - 0.41).abs() < 1e-9);
        assert_eq!(check.uncontradicted, 0);
        // Without wheels nothing contradicts it.
        let check = run_check(&relations, &[0.0, 0.5], &lasers, false, corridor);
        assert_eq!((check.by_odometry, check.uncontradicted), (0, 1));
        assert!((check.trans_m.mean - 0.41).abs() < 1e-9);
    }
}
