//! # The SLAM benchmark's relations: scoring a trajectory as the field does
//!
//! R. Kümmerle, B. Steder, C. Dornhege, M. Ruhnke, G. Grisetti,
//! C. Stachniss, A. Kleiner, "On measuring the accuracy of SLAM
//! algorithms", Autonomous Robots 27(4), 2009. For the raw Freiburg logs
//! (ACES, Intel, MIT CSAIL, FR079) the authors matched pairs of scans and
//! had a person check every match; the relations they kept are the
//! benchmark. A relation file has one per line,
//!
//! ```text
//! t1 t2 x y z roll pitch yaw
//! ```
//!
//! the pose `r` of the scan stamped `t2` in the frame of the scan stamped
//! `t1` (metres, radians; z, roll and pitch are 0 for these 2-D logs). A
//! scan's pose is the laser's when it took the scan (the robot's pose
//! composed with the laser's offset on it): on FR079, whose laser sits
//! 4 cm ahead of the robot's base, scoring the base instead of the laser
//! adds up to 8 cm to every relation between scans taken facing opposite
//! ways. A trajectory `p` of scans is scored by each relation's error
//!
//! ```text
//! δ = (p_t1⁻¹ ⊕ p_t2)⁻¹ ⊕ r,    translational |δ.xy|,  rotational |δ.θ|
//! ```
//!
//! and a method reports the mean and standard deviation of both over all
//! relations (here also the largest, and the worst relations, to show
//! where a map went wrong). The stamps are the scans' own: a relation's
//! scan is the scan whose time is nearest its stamp, within a millisecond
//! (the Intel log has scans 1.2 ms apart, so the nearest, not the first
//! within a tolerance). A relation whose scan is not in the replay (a
//! stretch of a log) is counted as unmatched, not scored.
//!
//! This is a scoring tool, read only where results are scored: the SLAM
//! never sees it.

use crate::geom::{wrap_angle, Pose2};
use serde::Serialize;

/// One relation of a benchmark file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Relation {
    pub t1: f64,
    pub t2: f64,
    /// The pose of scan `t2` in the frame of scan `t1`.
    pub pose: Pose2,
}

/// How far a relation's stamp may lie from its scan's time (s).
pub const STAMP_TOLERANCE_S: f64 = 1e-3;

/// How many of the worst relations a score lists.
pub const WORST: usize = 10;

/// Reads a relation file: `t1 t2 x y z roll pitch yaw` per line; empty
/// lines and `#` comments are skipped. A malformed line is an error naming
/// it.
pub fn parse_relations(text: &str) -> Result<Vec<Relation>, String> {
    let mut out = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let v: Vec<f64> = line
            .split_whitespace()
            .map(|f| f.parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|e| format!("line {}: {e}", k + 1))?;
        if v.len() != 8 || v.iter().any(|x| !x.is_finite()) {
            return Err(format!(
                "line {}: expected 8 numbers (t1 t2 x y z roll pitch yaw), found {}",
                k + 1,
                v.len()
            ));
        }
        out.push(Relation {
            t1: v[0],
            t2: v[1],
            pose: Pose2::new(v[2], v[3], v[7]),
        });
    }
    if out.is_empty() {
        return Err("no relations in the file".into());
    }
    Ok(out)
}

/// Mean, standard deviation and largest of a set of errors.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Spread {
    pub mean: f64,
    pub sd: f64,
    pub max: f64,
}

impl Spread {
    pub(crate) fn of(values: &[f64]) -> Spread {
        if values.is_empty() {
            return Spread::default();
        }
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
        Spread {
            mean,
            sd: var.sqrt(),
            max: values.iter().copied().fold(0.0, f64::max),
        }
    }
}

/// One relation's error, with the scans it joins.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RelationError {
    pub t1: f64,
    pub t2: f64,
    /// Positions of the two scans among those scored.
    pub scan1: usize,
    pub scan2: usize,
    pub trans_m: f64,
    pub rot_deg: f64,
}

/// A trajectory's score against a relation file.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RelationScore {
    /// Relations in the file, and those whose two scans were found.
    pub count: usize,
    pub matched: usize,
    pub trans_m: Spread,
    pub rot_deg: Spread,
    /// The largest translational errors, worst first.
    pub worst: Vec<RelationError>,
    /// Every matched relation's error, in the file's order.
    pub errors: Vec<RelationError>,
}

/// The scan whose time is nearest `t` (times in replay order, maybe not
/// sorted), if within [`STAMP_TOLERANCE_S`].
fn nearest(order: &[(f64, usize)], t: f64) -> Option<usize> {
    let k = order.partition_point(|(s, _)| *s < t);
    [k.checked_sub(1), Some(k)]
        .into_iter()
        .flatten()
        .filter_map(|i| order.get(i))
        .filter(|(s, _)| (s - t).abs() <= STAMP_TOLERANCE_S)
        .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
        .map(|(_, i)| *i)
}

/// The errors of `poses` (scan `i` at time `times[i]`) against the
/// relations.
pub fn score_relations(times: &[f64], poses: &[Pose2], relations: &[Relation]) -> RelationScore {
    let mut order: Vec<(f64, usize)> = times.iter().copied().zip(0..).collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut errors = Vec::new();
    for r in relations {
        let (Some(i), Some(j)) = (nearest(&order, r.t1), nearest(&order, r.t2)) else {
            continue;
        };
        let (Some(a), Some(b)) = (poses.get(i), poses.get(j)) else {
            continue;
        };
        let d = a.between(b).between(&r.pose);
        errors.push(RelationError {
            t1: r.t1,
            t2: r.t2,
            scan1: i,
            scan2: j,
            trans_m: d.position().length(),
            rot_deg: wrap_angle(d.theta).abs().to_degrees(),
        });
    }
    let trans: Vec<f64> = errors.iter().map(|e| e.trans_m).collect();
    let rot: Vec<f64> = errors.iter().map(|e| e.rot_deg).collect();
    let mut worst = errors.clone();
    worst.sort_by(|a, b| b.trans_m.total_cmp(&a.trans_m));
    worst.truncate(WORST);
    RelationScore {
        count: relations.len(),
        matched: errors.len(),
        trans_m: Spread::of(&trans),
        rot_deg: Spread::of(&rot),
        worst,
        errors,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_relation_file_scores_a_trajectory_by_hand_computed_errors() {
        let text = "# t1 t2 x y z roll pitch yaw\n\
                    10.0 11.0 1.0 0.0 0 0 0 0.0\n\
                    11.0 12.0005 1.0 0.0 0 0 0 1.5707963267948966\n\
                    12.0 99.0 1 0 0 0 0 0\n";
        let rel = parse_relations(text).expect("parses");
        assert_eq!(rel.len(), 3);
        // Scans at 10, 11, 12 s (the last found 0.5 ms from its stamp);
        // the trajectory drove 1.1 m instead of 1 m, then 1 m more, and
        // turned 80° instead of 90°.
        let times = [10.0, 11.0, 12.0];
        let poses = [
            Pose2::new(0.0, 0.0, 0.0),
            Pose2::new(1.1, 0.0, 0.0),
            Pose2::new(2.1, 0.0, 80f64.to_radians()),
        ];
        let s = score_relations(&times, &poses, &rel);
        assert_eq!((s.count, s.matched), (3, 2));
        // δ of the first: (1.1 m ahead)⁻¹ ⊕ (1 m ahead) = 0.1 m back.
        assert!((s.errors[0].trans_m - 0.1).abs() < 1e-12);
        assert!(s.errors[0].rot_deg.abs() < 1e-12);
        // The second: both drove 1 m; the heading is 10° short.
        assert!(s.errors[1].trans_m < 1e-12);
        assert!((s.errors[1].rot_deg - 10.0).abs() < 1e-9);
        assert!((s.trans_m.mean - 0.05).abs() < 1e-12 && (s.trans_m.sd - 0.05).abs() < 1e-12);
        assert!((s.rot_deg.max - 10.0).abs() < 1e-9);
        assert_eq!(s.worst[0].t1, 10.0);
    }

    #[test]
    fn the_nearest_scan_is_taken_and_far_stamps_are_not_matched() {
        // Scans 1.2 ms apart: each stamp takes its own scan.
        let times = [5.0, 5.0012, 7.0];
        let poses = [
            Pose2::new(0.0, 0.0, 0.0),
            Pose2::new(0.5, 0.0, 0.0),
            Pose2::new(2.0, 0.0, 0.0),
        ];
        let rel = parse_relations("5.0012 7.0 1.5 0 0 0 0 0\n5.0 7.002 2 0 0 0 0 0\n").unwrap();
        let s = score_relations(&times, &poses, &rel);
        assert_eq!(s.matched, 1);
        assert_eq!((s.errors[0].scan1, s.errors[0].scan2), (1, 2));
        assert!(s.errors[0].trans_m < 1e-12);
    }

    #[test]
    fn a_malformed_file_names_its_line() {
        assert!(parse_relations("1 2 3\n").unwrap_err().contains("line 1"));
        assert!(parse_relations("1 2 3 4 5 6 7 x\n")
            .unwrap_err()
            .contains("line 1"));
        assert!(parse_relations("\n# nothing\n")
            .unwrap_err()
            .contains("no relations"));
    }
}
