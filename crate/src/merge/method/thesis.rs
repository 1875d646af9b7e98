//! # The thesis's method as a merge method
//!
//! Thesis §6.2: only frames taken facing a wall squarely take part
//! ([`crate::merge::selection`]); every kept frame of one robot is compared
//! with every kept frame of the other (§6.2.3), the table showing MSAC
//! homography inliers (its Table 1); the best pair gives the distance
//! between the robots and the transform (§6.2.4, [`crate::merge::pinhole`]).

use super::{pose3, MethodStages, PairInput};
use crate::merge::config::MergeConfig;
use crate::merge::pinhole::{thesis_merge, PairMatch};
use crate::merge::selection::select_frames;
use crate::merge::verify::PairCheck;
use crate::merge::work::{PairOutcome, PairWork, RobotFrames};
use crate::merge::FrameInfo;
use crate::slam::OccupancyGrid;

/// The `thesis` method.
pub struct Thesis;

impl MethodStages for Thesis {
    fn select(&self, infos: &[FrameInfo], config: &MergeConfig) -> Vec<usize> {
        select_frames(infos, &config.selection)
    }

    /// Every kept frame of one robot against every kept frame of the other.
    fn propose(
        &self,
        robots: &[RobotFrames],
        pairs: &mut [PairWork],
        _maps: &[&OccupancyGrid],
        _config: &MergeConfig,
    ) {
        for p in pairs {
            let (na, nb) = (robots[p.a].selected.len(), robots[p.b].selected.len());
            p.todo = (0..na).flat_map(|i| (0..nb).map(move |j| (i, j))).collect();
        }
    }

    fn table_figure(&self, check: &PairCheck) -> usize {
        check.homography_inliers
    }

    fn decide(&self, pair: &PairInput) -> PairOutcome {
        let (ra, rb) = (pair.robot_a, pair.robot_b);
        let a_frames: Vec<FrameInfo> = ra.selected.iter().map(|&k| ra.infos[k].clone()).collect();
        let b_frames: Vec<FrameInfo> = rb.selected.iter().map(|&k| rb.infos[k].clone()).collect();
        let table: Vec<PairMatch> = pair
            .work
            .cells
            .iter()
            .map(|c| PairMatch {
                a: c.row,
                b: c.col,
                inliers: c.inliers as usize,
                homography: c.homography,
                quad: c.quad,
            })
            .collect();
        let t = thesis_merge(pair.camera, &a_frames, &b_frames, &table);
        PairOutcome {
            a: ra.name.clone(),
            b: rb.name.clone(),
            status: t.status,
            reason: t.reason,
            confidence: t.confidence,
            pose: t.pose.as_ref().map(pose3),
            candidates: table.len(),
            support: usize::from(t.best.is_some()),
            best: t.best.map(|(i, j)| [i, j]),
            second: t.second.map(|(i, j)| [i, j]),
            distance: t.distance,
            check: None,
            verdict: None,
        }
    }
}
