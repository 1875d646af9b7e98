//! # The map-only baseline as a merge method
//!
//! Reads the two maps and nothing else: SURF on the grid images and a
//! robust similarity fit ([`crate::merge::baseline`]), as existing
//! map-merging tools do. No frame takes part, so the job goes straight to
//! the decision.

use super::{pose3, MethodStages, PairInput};
use crate::merge::baseline::map_only_merge;
use crate::merge::config::MergeConfig;
use crate::merge::verify::PairCheck;
use crate::merge::work::PairOutcome;
use crate::merge::FrameInfo;

/// The `map-only` method.
pub struct MapOnly;

impl MethodStages for MapOnly {
    fn uses_frames(&self) -> bool {
        false
    }

    fn select(&self, _infos: &[FrameInfo], _config: &MergeConfig) -> Vec<usize> {
        Vec::new()
    }

    fn table_figure(&self, check: &PairCheck) -> usize {
        check.candidate.as_ref().map_or(0, |c| c.inliers)
    }

    fn decide(&self, pair: &PairInput) -> PairOutcome {
        let p = pair.work;
        let seed = pair.config.seed ^ ((p.a * 16 + p.b) as u64);
        let o = map_only_merge(pair.map_a, pair.map_b, &pair.config.baseline, seed);
        PairOutcome {
            a: pair.robot_a.name.clone(),
            b: pair.robot_b.name.clone(),
            status: o.status,
            reason: o.reason,
            confidence: o.confidence,
            pose: o.pose.as_ref().map(pose3),
            candidates: o.matches,
            support: o.inliers,
            best: None,
            second: None,
            distance: None,
            check: None,
            verdict: None,
        }
    }
}
