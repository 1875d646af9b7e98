//! # Relations the scans themselves fix
//!
//! Kümmerle et al. ("On measuring the accuracy of SLAM algorithms",
//! Autonomous Robots 27(4), 2009) score a SLAM by the relative poses of
//! pairs of scans whose true relation is known ([`super::relations`]). For
//! the classic real logs they made those relations by matching pairs of
//! scans that overlap and having a person accept or reject each match; the
//! published figures for these buildings (GMapping 0.05–0.07 m, graph
//! mapping 0.004–0.056 m) are errors against such relations. A corrected
//! log's own poses are another SLAM's estimate, with noise of their own,
//! and score even the truth at several centimetres over far pairs.
//!
//! This module makes relations in Kümmerle's manner, with the person
//! replaced by checks, between two estimates `a` and `b` of the same scans
//! (say, a reference and ours):
//!
//! 1. **Candidates**: every pair of scans `i < j` within `near_m` and
//!    `near_rad` of each other by `a` *or* by `b` (either may have put two
//!    overlapping scans apart).
//! 2. **The scans' own relation**: scan `j`'s points aligned to scan `i`'s
//!    by point-to-line ICP ([`crate::slam::icp`]), once from `a`'s relative pose
//!    and once from `b`'s.
//! 3. **Accepted** when both starts end at the same pose (within `same_m`
//!    and `same_rad`: the answer is the scans', not the start's), at least
//!    `min_share` of scan `j`'s points lie on scan `i`'s surfaces, and the
//!    fit pins the pose in every direction (`min_weak` points' worth of
//!    wall normals in its weakest direction: a corridor whose ends are out
//!    of sight fixes nothing along it). A candidate whose two starts end
//!    apart is counted, with which start's end the scans fit better.
//!
//! [`errors_by_gap`] then averages an estimate's error against the
//! accepted relations by how far apart the two scans lie in the sequence
//! (consecutive, 2–9, 10–99, 100 or more: revisits, where loops close).
//! The relations test what the scans can see — the map's consistency where
//! it overlaps — not the bend of a corridor seen once. As with Kümmerle's
//! relations, a scan matcher aligns scans by construction, so the measure
//! favours one; a scoring tool, which no SLAM reads.

use crate::geom::Pose2;
use crate::slam::degeneracy::scan_normals;
use crate::slam::icp::{IcpFit, IcpTarget};
use glam::DVec2;

/// Settings of [`verified_relations`].
#[derive(Clone, Debug, PartialEq)]
pub struct VerifyConfig {
    /// Candidate pairs lie this close by one estimate or the other.
    pub near_m: f64,
    pub near_rad: f64,
    /// The ICP's association radius and Huber threshold (m), its steps.
    pub radius_m: f64,
    pub huber_m: f64,
    pub iterations: usize,
    /// The two starts' answers must agree within this.
    pub same_m: f64,
    pub same_rad: f64,
    /// Least share of scan `j`'s points on scan `i`'s surfaces.
    pub min_share: f64,
    /// Least points' worth of constraint in the weakest direction.
    pub min_weak: f64,
    /// At most this many candidates per gap class, spread evenly over them.
    pub max_pairs: usize,
}

impl Default for VerifyConfig {
    fn default() -> Self {
        VerifyConfig {
            near_m: 2.0,
            near_rad: 30f64.to_radians(),
            radius_m: 0.3,
            huber_m: 0.02,
            iterations: 40,
            same_m: 0.01,
            same_rad: 0.2f64.to_radians(),
            min_share: 0.5,
            min_weak: 20.0,
            max_pairs: 4000,
        }
    }
}

/// The gap classes: `j − i` in `[lo, hi)`, and their names.
pub const GAPS: [(usize, usize, &str); 4] = [
    (1, 2, "1"),
    (2, 10, "2-9"),
    (10, 100, "10-99"),
    (100, usize::MAX, ">=100"),
];

/// Which gap class `j − i` falls in.
fn gap_class(gap: usize) -> usize {
    GAPS.iter()
        .position(|&(lo, hi, _)| gap >= lo && gap < hi)
        .unwrap_or(0)
}

/// One accepted relation: scan `j`'s pose in scan `i`'s frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Verified {
    pub i: usize,
    pub j: usize,
    pub relation: Pose2,
}

/// A candidate whose two starts ended apart, and which end the scans fit
/// better (by 2 mm of mean misfit): `Some(true)` the second estimate's.
#[derive(Clone, Debug, PartialEq)]
pub struct Disputed {
    pub i: usize,
    pub j: usize,
    pub second_fits_better: Option<bool>,
}

/// The outcome of [`verified_relations`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Verification {
    pub relations: Vec<Verified>,
    pub disputed: Vec<Disputed>,
}

/// Whether two poses lie within the candidate distance.
fn near(a: &Pose2, b: &Pose2, cfg: &VerifyConfig) -> bool {
    let d = a.between(b);
    d.position().length() <= cfg.near_m && d.theta.abs() <= cfg.near_rad
}

/// The candidate pairs, at most `max_pairs` per gap class.
fn candidates(a: &[Pose2], b: &[Pose2], cfg: &VerifyConfig) -> Vec<(usize, usize)> {
    let mut classes = vec![Vec::new(); GAPS.len()];
    for j in 1..a.len() {
        for i in 0..j {
            if near(&a[i], &a[j], cfg) || near(&b[i], &b[j], cfg) {
                classes[gap_class(j - i)].push((i, j));
            }
        }
    }
    let mut out = Vec::new();
    for c in classes {
        if c.len() > cfg.max_pairs {
            let step = c.len() as f64 / cfg.max_pairs as f64;
            out.extend((0..cfg.max_pairs).map(|k| c[(k as f64 * step) as usize]));
        } else {
            out.extend(c);
        }
    }
    // By the older scan first, so that each one's ICP target is built once.
    out.sort_unstable();
    out
}

/// Mean point-to-line misfit of `points` at `pose`, each clamped to 5 cm
/// (a point on no surface counts 5 cm).
fn misfit(target: &IcpTarget, points: &[DVec2], pose: &Pose2) -> f64 {
    let r = target.residuals(points, pose);
    r.iter()
        .map(|x| x.map_or(0.05, |(v, _)| v.abs().min(0.05)))
        .sum::<f64>()
        / r.len().max(1) as f64
}

/// Relations between the scans whose points (robot frame, one list per
/// scan) are `points`, checked as the module doc says, with `a` and `b`
/// two estimates of the scans' poses (the same length as `points`).
pub fn verified_relations(
    points: &[Vec<DVec2>],
    a: &[Pose2],
    b: &[Pose2],
    cfg: &VerifyConfig,
) -> Verification {
    let mut out = Verification::default();
    let n = points.len().min(a.len()).min(b.len());
    let mut target: Option<(usize, IcpTarget)> = None;
    for (i, j) in candidates(&a[..n], &b[..n], cfg) {
        if target.as_ref().is_none_or(|(k, _)| *k != i) {
            let t = IcpTarget::new(&points[i], &scan_normals(&points[i]), cfg.radius_m);
            target = Some((i, t));
        }
        let Some((_, t)) = &target else { continue };
        let q = &points[j];
        let from_a = t.align(q, &a[i].between(&a[j]), cfg.huber_m, cfg.iterations);
        let from_b = t.align(q, &b[i].between(&b[j]), cfg.huber_m, cfg.iterations);
        let pinned = |f: &IcpFit| {
            f.weak >= cfg.min_weak && f.associated as f64 >= cfg.min_share * q.len() as f64
        };
        let d = from_a.pose.between(&from_b.pose);
        if d.position().length() > cfg.same_m || d.theta.abs() > cfg.same_rad {
            if pinned(&from_a) || pinned(&from_b) {
                let (ma, mb) = (misfit(t, q, &from_a.pose), misfit(t, q, &from_b.pose));
                out.disputed.push(Disputed {
                    i,
                    j,
                    second_fits_better: (mb + 0.002 < ma)
                        .then_some(true)
                        .or((ma + 0.002 < mb).then_some(false)),
                });
            }
        } else if pinned(&from_a) {
            out.relations.push(Verified {
                i,
                j,
                relation: from_a.pose,
            });
        }
    }
    out
}

/// What two scans say of a relation given between them (a benchmark's
/// relation file, [`super::benchmark_relations`]).
#[derive(Clone, Debug, PartialEq)]
pub struct PairCheck {
    /// The pose that ICP reaches both from the given relation and from
    /// `other` (within `same_m` and `same_rad`), where that fit pins every
    /// direction and meets `min_share` of scan `j`'s points: the scans'
    /// own relation. `None`: the scans do not settle one.
    pub settled: Option<Pose2>,
    /// Mean point-to-line misfit (m, each point clamped to 5 cm) of scan
    /// `j`'s points at the given relation and at the settled pose.
    pub misfit_given: f64,
    pub misfit_settled: f64,
}

/// Checks the relation `given` (scan `j`'s pose in scan `i`'s frame; points
/// in each scan's own frame) against the scans, as [`verified_relations`]
/// checks a candidate: point-to-line ICP of scan `j` onto scan `i` from
/// `given` and from `other` (another estimate of the same relation).
pub fn check_pair(
    points_i: &[DVec2],
    points_j: &[DVec2],
    given: &Pose2,
    other: &Pose2,
    cfg: &VerifyConfig,
) -> PairCheck {
    let t = IcpTarget::new(points_i, &scan_normals(points_i), cfg.radius_m);
    let from_given = t.align(points_j, given, cfg.huber_m, cfg.iterations);
    let from_other = t.align(points_j, other, cfg.huber_m, cfg.iterations);
    let d = from_given.pose.between(&from_other.pose);
    let settled = (d.position().length() <= cfg.same_m
        && d.theta.abs() <= cfg.same_rad
        && from_given.weak >= cfg.min_weak
        && from_given.associated as f64 >= cfg.min_share * points_j.len() as f64)
        .then_some(from_given.pose);
    PairCheck {
        settled,
        misfit_given: misfit(&t, points_j, given),
        misfit_settled: settled.map_or(f64::NAN, |p| misfit(&t, points_j, &p)),
    }
}

/// Scans apart within which the wheel odometry can witness a relation
/// ([`odometry_contradicts`]): over more, its drift is no longer a few
/// steps' random walk.
pub const ODOMETRY_WITNESS_SCANS: usize = 16;

/// Whether the wheel odometry contradicts the translation of a relation
/// `given` between two scans `steps` apart, where the scans settle no pose
/// ([`check_pair`]; a corridor whose ends are out of sight fixes nothing
/// along it, and there the relation says what no scan can). `odometry` is
/// the odometry's relative pose of the same two scans, `step_variance` its
/// measured variance per step along each axis (m², as the fusion of
/// [`crate::slam::logs::fusion`] measures it from the log).
///
/// Contradicted when the two lie more than 0.1 m apart and more than five
/// standard deviations of `steps` steps' random walk: a relation of 0.75 m
/// over two scans of half a second, where the wheels say 0.34 m, is a
/// robot moving 1.5 m/s in a log that never goes faster than 1 m/s. Only
/// the translation is tested: a wheel's heading error comes in the turns,
/// not as a random walk. The odometry is not the SLAM's estimate, so this
/// is a second witness independent of the one being scored.
pub fn odometry_contradicts(
    given: &Pose2,
    odometry: &Pose2,
    steps: usize,
    step_variance: [f64; 2],
) -> bool {
    if steps == 0 || steps > ODOMETRY_WITNESS_SCANS {
        return false;
    }
    let sigma = (steps as f64 * (step_variance[0] + step_variance[1])).sqrt();
    let apart = given.position().distance(odometry.position());
    apart > 0.1 && apart > 5.0 * sigma
}

/// An estimate's errors against the accepted relations of one gap class
/// (or all of them).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct GapErrors {
    pub gap: &'static str,
    pub pairs: usize,
    pub trans_m: f64,
    pub rot_deg: f64,
    /// Relations it misses by over 0.1 m or 1°.
    pub over: usize,
}

/// The mean error of `estimate`'s relative poses against `relations` per
/// gap class of [`GAPS`], then over all of them.
pub fn errors_by_gap(relations: &[Verified], estimate: &[Pose2]) -> Vec<GapErrors> {
    let names = GAPS.iter().map(|g| g.2).chain(std::iter::once("all"));
    let mut out: Vec<GapErrors> = names
        .map(|gap| GapErrors {
            gap,
            pairs: 0,
            trans_m: 0.0,
            rot_deg: 0.0,
            over: 0,
        })
        .collect();
    let all = GAPS.len();
    for r in relations {
        let e = estimate[r.i].between(&estimate[r.j]).between(&r.relation);
        let (t, d) = (e.position().length(), e.theta.to_degrees().abs());
        for k in [gap_class(r.j - r.i), all] {
            out[k].pairs += 1;
            out[k].trans_m += t;
            out[k].rot_deg += d;
            out[k].over += (t > 0.1 || d > 1.0) as usize;
        }
    }
    for g in &mut out {
        let n = g.pairs.max(1) as f64;
        g.trans_m /= n;
        g.rot_deg /= n;
    }
    out
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    #[test]
    fn odometry_witnesses_only_a_short_relation_it_is_sure_of() {
        let given = Pose2::new(0.755, -0.036, 0.039);
        let wheels = Pose2::new(0.342, 0.0, 0.04);
        // σ 6 mm per step (ACES's wheels): 0.41 m over 2 steps is 48σ.
        let ok = [3.6e-5 / 2.0, 3.6e-5 / 2.0];
        assert!(odometry_contradicts(&given, &wheels, 2, ok));
        // Under 0.1 m apart: not contradicted, however sure the wheels.
        let near = Pose2::new(0.43, 0.0, 0.04);
        assert!(!odometry_contradicts(&near, &wheels, 2, ok));
        // Wheels of σ 0.1 m per step: 0.41 m over 2 steps is 2.9σ.
        assert!(!odometry_contradicts(&given, &wheels, 2, [0.005, 0.005]));
        // Too many steps apart for a random walk to speak.
        assert!(!odometry_contradicts(
            &given,
            &wheels,
            ODOMETRY_WITNESS_SCANS + 1,
            ok
        ));
        assert!(!odometry_contradicts(&given, &wheels, 0, ok));
    }

    /// A 6 × 4 m room's walls, a point every 2 cm, seen from `pose`: robot
    /// frame, in bearing order as a laser returns them.
    pub(crate) fn room_seen_from(pose: &Pose2) -> Vec<DVec2> {
        let mut world = Vec::new();
        for k in 0..300 {
            let x = -3.0 + 0.02 * k as f64;
            world.push(DVec2::new(x, -2.0));
            world.push(DVec2::new(x, 2.0));
        }
        for k in 0..200 {
            let y = -2.0 + 0.02 * k as f64;
            world.push(DVec2::new(-3.0, y));
            world.push(DVec2::new(3.0, y));
        }
        let f = pose.frame();
        let mut local: Vec<DVec2> = world.iter().map(|&p| f.to_local(p)).collect();
        local.sort_by(|a, b| a.y.atan2(a.x).total_cmp(&b.y.atan2(b.x)));
        local
    }

    #[test]
    fn relations_are_the_scans_and_errors_are_measured_against_them() {
        let truth = [
            Pose2::new(0.0, 0.0, 0.0),
            Pose2::new(0.4, 0.1, 0.05),
            Pose2::new(0.8, -0.2, 0.12),
        ];
        let points: Vec<Vec<DVec2>> = truth.iter().map(room_seen_from).collect();
        // `b` is off by 5 cm along x and 0.8° at the last scan; `a` is right.
        let mut b = truth;
        b[2] = Pose2::new(0.85, -0.2, 0.12 + 0.8f64.to_radians());
        let v = verified_relations(&points, &truth, &b, &VerifyConfig::default());
        assert_eq!(v.relations.len(), 3, "{v:?}");
        assert!(v.disputed.is_empty());
        for r in &v.relations {
            let d = truth[r.i].between(&truth[r.j]).between(&r.relation);
            assert!(
                d.position().length() < 0.002 && d.theta.abs() < 0.001,
                "{r:?}"
            );
        }
        let ea = errors_by_gap(&v.relations, &truth);
        assert!(ea[4].trans_m < 0.002, "{ea:?}");
        let eb = errors_by_gap(&v.relations, &b);
        // Pair (0, 1) is right; (1, 2) and (0, 2) are off by the last scan's error.
        assert_eq!((eb[0].pairs, eb[1].pairs, eb[4].pairs), (2, 1, 3));
        assert!((eb[4].rot_deg - 1.6 / 3.0).abs() < 0.01, "{eb:?}");
        assert!(eb[4].trans_m > 0.03 && eb[4].trans_m < 0.06, "{eb:?}");
        assert_eq!(eb[4].over, 0);
    }

    #[test]
    fn a_relation_its_scans_contradict_is_found_and_a_right_one_is_not() {
        let (p, q) = (Pose2::new(0.0, 0.0, 0.0), Pose2::new(0.5, 0.2, 0.3));
        let (a, b) = (room_seen_from(&p), room_seen_from(&q));
        let truth = p.between(&q);
        let cfg = VerifyConfig::default();
        // A relation 2° and 4 cm off, checked with an estimate near the truth.
        let wrong = truth.compose(&Pose2::new(0.04, 0.0, 2f64.to_radians()));
        let near = truth.compose(&Pose2::new(0.005, -0.005, 0.1f64.to_radians()));
        let c = check_pair(&a, &b, &wrong, &near, &cfg);
        let settled = c.settled.expect("a room pins every direction");
        let off = settled.between(&truth);
        assert!(
            off.position().length() < 0.002 && off.theta.abs() < 0.001,
            "{c:?}"
        );
        assert!(c.misfit_settled + 0.002 < c.misfit_given, "{c:?}");
        // The right relation settles where it is, with the same misfit.
        let c = check_pair(&a, &b, &truth, &near, &cfg);
        let off = c.settled.expect("settles").between(&truth);
        assert!(off.position().length() < 0.002, "{c:?}");
        assert!((c.misfit_given - c.misfit_settled).abs() < 0.001, "{c:?}");
        // A corridor, seen from two places along it, settles nothing.
        let corridor = |x: f64| -> Vec<DVec2> {
            let wall = |y: f64| (0..400).map(move |k| DVec2::new(-4.0 + 0.02 * k as f64 - x, y));
            wall(-1.0).chain(wall(1.0)).collect()
        };
        let step = Pose2::new(0.3, 0.0, 0.0);
        let c = check_pair(
            &corridor(0.0),
            &corridor(0.3),
            &step,
            &Pose2::new(0.5, 0.0, 0.0),
            &cfg,
        );
        assert_eq!(c.settled, None, "{c:?}");
    }
}
