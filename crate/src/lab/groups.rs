//! # Each group's merged map
//!
//! With many robots the merge may join them into several groups that share
//! no map with one another: robots 1 and 2 drove through one building, 3
//! and 4 through another, and nothing any of them saw ties the two
//! buildings together ([`crate::merge::graph::groups`]). The report's
//! `merge.groups[]` gives each group's transforms in the frame of its first
//! robot; the merged map the merge itself fuses is only robot 1's group.
//! Here the session turns any group into what the page shows of it:
//!
//! * its merged map: the members' occupancy grids placed at their poses in
//!   the group's frame and their log-odds added, exactly as the merge fuses
//!   robot 1's group ([`crate::merge::fuse`]); so group 0 of a merged run
//!   gives the same grid as the report's merged map;
//! * a picture of it with each member's SLAM path in its colour, and the
//!   ROS `map_server` files (PGM, YAML, PNG);
//! * each member's error against the ground truth, in the group's frame.
//!   Both map frames are the robots' odometry frames, whose origins are
//!   their start poses, so the true pose of robot j's map frame in the
//!   frame of the group's first robot f is `start_f⁻¹ ∘ start_j` (the same
//!   scoring as the report's `errors`, which is group 0's). Scoring is the
//!   only use of the truth; the groups themselves never read it.
//!
//! A robot nobody joined is a group of one, with the merge's reason; its
//! "merged map" is its own map.

use super::merge::{picture, pose_of, rounded, transform_error, TransformError};
use super::Lab;
use crate::geom::Pose2;
use crate::merge::frames::MergeInput;
use crate::merge::fuse::fuse;
use crate::merge::job::{RobotGroup, RobotTransform};
use crate::slam::export::{to_pgm, to_png, to_yaml};
use crate::slam::OccupancyGrid;
use serde::Serialize;

/// One group of robots as the page shows it.
#[derive(Clone, Debug, Serialize)]
pub struct GroupView {
    /// Its position in the report's `merge.groups[]` (robot 1's is 0).
    pub group: usize,
    pub robots: Vec<String>,
    /// Each member's map frame in the frame of the group's first robot.
    pub transforms: Vec<RobotTransform>,
    /// Why a robot stands alone (groups of one only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// Each member's transform against the ground truth.
    pub errors: Vec<TransformError>,
}

impl Lab {
    /// Group `group` of the finished merge.
    fn merge_group(&self, group: usize) -> Result<&RobotGroup, String> {
        let job = self.merge.as_ref().ok_or("no merge has been started")?;
        let outcome = job.outcome().ok_or("the merge has not finished yet")?;
        outcome.groups.get(group).ok_or_else(|| {
            format!(
                "there is no group {group}: the merge found {}",
                outcome.groups.len()
            )
        })
    }

    /// Every group of the finished merge with its members' errors against
    /// the ground truth (see the module doc).
    pub fn merge_groups(&self) -> Result<Vec<GroupView>, String> {
        let sim = self.simulation().ok_or("nothing has run yet")?;
        let job = self.merge.as_ref().ok_or("no merge has been started")?;
        let outcome = job.outcome().ok_or("the merge has not finished yet")?;
        let start = |name: &str| {
            sim.robots
                .iter()
                .find(|r| r.spec.name == name)
                .map(|r| r.spec.start_pose())
        };
        let views = outcome.groups.iter().enumerate().map(|(k, g)| {
            let first = g.robots.first().and_then(|n| start(n));
            let errors = g
                .transforms
                .iter()
                .filter_map(|t| {
                    let truth = first?.inverse().compose(&start(&t.robot)?);
                    Some(transform_error(t, &truth))
                })
                .collect();
            GroupView {
                group: k,
                robots: g.robots.clone(),
                transforms: rounded(&g.transforms),
                reason: g.reason.clone(),
                errors,
            }
        });
        Ok(views.collect())
    }

    /// Group `group`'s merged map: its members' maps fused at their poses
    /// in the frame of its first robot.
    pub fn group_merged_map(&self, group: usize) -> Result<OccupancyGrid, String> {
        let sim = self.simulation().ok_or("nothing has run yet")?;
        let job = self.merge.as_ref().ok_or("no merge has been started")?;
        let g = self.merge_group(group)?;
        let mapper = job.config.mapper;
        let maps: Vec<(&OccupancyGrid, Pose2)> = g
            .transforms
            .iter()
            .filter_map(|t| {
                let i = sim.robots.iter().position(|r| r.spec.name == t.robot)?;
                Some((sim.map(i, mapper), pose_of(t.pose)))
            })
            .collect();
        let config = maps
            .first()
            .ok_or_else(|| format!("group {group} has no robot of this run"))?
            .0
            .config
            .clone();
        Ok(fuse(&maps, config))
    }

    /// Group `group`'s merged map fitted to `width × height` as RGBA, with
    /// its members' SLAM paths in their colours.
    pub fn group_merged_rgba(
        &self,
        group: usize,
        width: u32,
        height: u32,
    ) -> Result<Vec<u8>, String> {
        let sim = self.simulation().ok_or("nothing has run yet")?;
        let grid = self.group_merged_map(group)?;
        picture(
            sim,
            &grid,
            &self.merge_group(group)?.transforms,
            width,
            height,
        )
    }

    /// Group `group`'s merged map as a ROS `map_server` PGM ...
    pub fn group_merged_pgm(&self, group: usize) -> Result<Vec<u8>, String> {
        Ok(to_pgm(&self.group_merged_map(group)?))
    }

    /// ... a PNG of the same pixels ...
    pub fn group_merged_png(&self, group: usize) -> Result<Vec<u8>, String> {
        to_png(&self.group_merged_map(group)?)
    }

    /// ... and the YAML naming `image`.
    pub fn group_merged_yaml(&self, group: usize, image: &str) -> Result<String, String> {
        Ok(to_yaml(&self.group_merged_map(group)?, image))
    }
}
