//! # The automatic method as a merge method
//!
//! Every frame takes part, thinned by place (consecutive views a few
//! centimetres apart show nearly the same, as do two passes of one
//! corridor); a bag of visual words trained on
//! this run's descriptors proposes the frame pairs most likely to show the
//! same place ([`crate::merge::vocabulary`]); each is verified by a rigid
//! fit of keypoints lifted with the laser ([`crate::merge::verify`]), the
//! table showing its inliers. The decision combines the candidates that
//! agree with the agreement of the overlaid maps
//! ([`crate::merge::verdict`]); when vision finds no transform the maps
//! confirm, and was not torn between two, the maps alone are searched
//! ([`crate::merge::mapsearch`]) and judged as strictly.

mod proposals;

use super::{pose3, MethodStages, PairInput};
use crate::geom::wrap_angle;
use crate::merge::config::MergeConfig;
use crate::merge::mapsearch::{MapSearch, MapSearchSteps};
use crate::merge::verdict::{SearchSummary, VerdictSteps};
use crate::merge::verify::{PairCheck, VerifyConfig};
use crate::merge::work::{PairOutcome, PairWork, RobotFrames};
use crate::merge::{Candidate, FrameInfo, MergeStatus};
use crate::slam::OccupancyGrid;
pub use proposals::ProposalSteps;
use std::collections::HashMap;

/// The `auto` method.
pub struct Auto;

/// Positions in `infos` of the frames that show a new *place*: a frame
/// takes part unless an earlier frame that takes part was taken within
/// `min_m` of it (SLAM poses) facing within `min_rad` of its heading. The
/// first frame is always kept.
///
/// Consecutive views a few centimetres apart show nearly the same, and so
/// does the view of a place the robot passed an hour ago: a robot touring a
/// maze for an hour passes its corridors many times, and a frame of each
/// pass would make the description and matching grow with the run's
/// duration. Compared with every frame kept so far (not only the last),
/// the frames grow with the places seen, which the world bounds. Frames are
/// visited in capture order, so the choice only ever adds frames as the
/// run goes on (what [`crate::merge::described_ahead`] relies on). The kept
/// frames are found through a hash grid of `min_m` cells: each frame looks
/// at its own cell and the eight around it.
pub fn thin_by_place(infos: &[FrameInfo], min_m: f64, min_rad: f64) -> Vec<usize> {
    let mut kept: Vec<usize> = Vec::new();
    let mut cells: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    let cell_of = |p: glam::DVec2| ((p.x / min_m).floor() as i64, (p.y / min_m).floor() as i64);
    for (k, f) in infos.iter().enumerate() {
        let (cx, cy) = cell_of(f.pose.position());
        let seen = (-1..=1).any(|dx| {
            (-1..=1).any(|dy| {
                cells.get(&(cx + dx, cy + dy)).is_some_and(|list| {
                    list.iter().any(|&j| {
                        let old = &infos[j].pose;
                        (f.pose.position() - old.position()).length() < min_m
                            && wrap_angle(f.pose.theta - old.theta).abs() < min_rad
                    })
                })
            })
        });
        if !seen {
            kept.push(k);
            cells.entry((cx, cy)).or_default().push(k);
        }
    }
    kept
}

impl MethodStages for Auto {
    fn select(&self, infos: &[FrameInfo], config: &MergeConfig) -> Vec<usize> {
        thin_by_place(infos, config.min_motion_m, config.min_turn_rad)
    }

    /// The vocabulary's proposals: trained on every described frame of
    /// every robot, then each robot pair's frames nominate their partners.
    /// With many robots only the pairs the budget keeps are proposed
    /// ([`crate::merge::pairbudget`]). The steps of [`ProposalSteps`] run to
    /// the end.
    fn propose(
        &self,
        robots: &[RobotFrames],
        pairs: &mut [PairWork],
        maps: &[&OccupancyGrid],
        config: &MergeConfig,
    ) {
        let mut steps = ProposalSteps::default();
        while !proposals::step(&mut steps, robots, pairs, maps, config) {}
    }

    fn propose_step(
        &self,
        robots: &[RobotFrames],
        pairs: &mut [PairWork],
        maps: &[&OccupancyGrid],
        config: &MergeConfig,
        steps: &mut ProposalSteps,
    ) -> bool {
        proposals::step(steps, robots, pairs, maps, config)
    }

    /// The decision rests on the rigid fit alone: the homography (the
    /// thesis's table figure) is fitted only for a pair the user opens.
    fn verify_config(&self, config: &MergeConfig) -> VerifyConfig {
        VerifyConfig {
            homography: false,
            ..config.verify
        }
    }

    fn table_figure(&self, check: &PairCheck) -> usize {
        check.candidate.as_ref().map_or(0, |c| c.inliers)
    }

    fn decide(&self, pair: &PairInput) -> PairOutcome {
        let mut steps = VerdictSteps::default();
        loop {
            if let Some(o) = self.decide_step(pair, &mut steps) {
                return o;
            }
        }
    }

    fn decide_step(&self, pair: &PairInput, steps: &mut VerdictSteps) -> Option<PairOutcome> {
        let (p, config) = (pair.work, pair.config);
        let cands: Vec<Candidate> = p.cells.iter().filter_map(|c| c.candidate.clone()).collect();
        let summary = SearchSummary {
            proposed_pairs: p.cells.len(),
            best_rigid_inliers: p
                .cells
                .iter()
                .map(|c| c.rigid_inliers as usize)
                .max()
                .unwrap_or(0),
            min_inliers: config.verify.min_inliers,
        };
        let d = steps.step(&cands, &summary, pair.map_a, pair.map_b, &config.verdict)?;
        let outcome = PairOutcome {
            a: pair.robot_a.name.clone(),
            b: pair.robot_b.name.clone(),
            status: d.status,
            reason: d.reason.clone(),
            confidence: d.confidence,
            pose: d.pose.as_ref().map(pose3),
            candidates: cands.len(),
            support: d.support.len(),
            best: None,
            second: None,
            distance: None,
            check: None,
            verdict: Some(d),
        };
        Some(if pair.search_maps {
            self.search_after(pair, outcome)
        } else {
            outcome
        })
    }

    /// Vision found nothing the maps confirm (and was not torn between two
    /// transforms): ask the maps alone.
    fn search_after(&self, pair: &PairInput, o: PairOutcome) -> PairOutcome {
        let mut steps = MapSearchSteps::default();
        loop {
            if let Some(done) = self.search_step(pair, &o, &mut steps) {
                return done;
            }
        }
    }

    fn search_step(
        &self,
        pair: &PairInput,
        o: &PairOutcome,
        steps: &mut MapSearchSteps,
    ) -> Option<PairOutcome> {
        let config = pair.config;
        let ambiguous = o.verdict.as_ref().is_some_and(|d| d.ambiguous);
        let Some(ms) = config
            .map_search
            .as_ref()
            .filter(|_| o.status != MergeStatus::Merged && !ambiguous)
        else {
            return Some(o.clone());
        };
        let m = steps.step(pair.map_a, pair.map_b, ms, &config.verdict)?;
        Some(with_search(o.clone(), m))
    }
}

/// A pair's outcome after the search of its maps alone found `m`.
fn with_search(mut o: PairOutcome, m: MapSearch) -> PairOutcome {
    if m.status == MergeStatus::Merged {
        o.status = MergeStatus::Merged;
        o.pose = m.pose.as_ref().map(pose3);
        o.confidence = m.confidence;
        o.support = 0;
        o.reason = format!("merged: {} (vision: {})", m.reason, o.reason);
    } else {
        o.reason = format!("{}; {}", o.reason, m.reason);
    }
    if let Some(d) = o.verdict.as_mut() {
        d.status = o.status;
        d.pose = m
            .pose
            .filter(|_| m.status == MergeStatus::Merged)
            .or(d.pose);
        d.confidence = o.confidence;
        if m.status == MergeStatus::Merged {
            d.support.clear();
        }
        d.reason = o.reason.clone();
    }
    o
}
