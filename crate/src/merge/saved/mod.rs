//! # Merging saved maps: two to sixteen ROS maps, no robots
//!
//! Everything else in [`crate::merge`] merges the maps of robots the lab
//! simulated, with their camera frames and laser scans at hand. Here only
//! the maps are: ROS `map_server` files from GMapping, slam_toolbox,
//! Cartographer or Hector, made on different runs ([`crate::formats::rosmap`]
//! reads them). The stages, one file each:
//!
//! | stage | file | what |
//! |---|---|---|
//! | prepare | [`wallmap`] | wall-surface points and a distance field per map |
//! | search | [`search`] | rotations from Hough spectra, coarse correlation, refinement |
//! | judge | [`evidence`] | agreement within a tolerance band, acceptance index, margin |
//! | join | [`crate::merge::graph`] | with three or more maps, the most confident spanning tree |
//! | refine | [`refine`] | a pair again, from a person's rough overlay (the page's Refine) |
//! | write | [`crate::formats::rosmap::write`] | the merged map as PGM + PNG + YAML |
//!
//! Each pair of maps is searched and judged on its own; a pair is an edge
//! when its verdict is "merged", weighted by its confidence, and the maps
//! are joined along the maximum spanning tree from the first map, as the
//! lab joins three or more robots. The first map's frame is the merged
//! frame.
//!
//! A person may also keep a placement of their own that the tests refused
//! ([`SavedMerge::keep_placement`]): the pair then joins at exactly that
//! pose, marked *not verified* (`verified: false` on the pair, on every
//! group it joins and on the merge), with the refusal kept in its reason,
//! and with the least confidence, so the spanning tree takes any verified
//! chain first.
//!
//! Maps of two buildings opened together join into several *groups*
//! ([`crate::merge::graph::groups`]): each group is a connected part of the
//! graph of merged pairs, joined along its own spanning tree from its
//! lowest-numbered map, whose frame is that group's frame. The first group
//! is always the first map's, exactly as the merged frame above; a map no
//! merged pair reaches is a group of its own, with the reason of its
//! best-supported pair. A transform is reported as the pose of a map's own frame (the
//! frame its YAML `origin` is written in) in the first map's frame:
//! the search works in image frames (the image's lower-left corner), so a
//! pair's image-frame overlay `P` becomes `origin_A ⊕ P ⊕ origin_B⁻¹`.
//!
//! Nothing here changes the lab's own pipeline: the simulated robots'
//! merge keeps its own search ([`crate::merge::mapsearch`]) and verdict.

pub mod evidence;
pub mod refine;
pub mod search;
pub mod wallmap;

use self::evidence::{distinct, evidence, judge, Evidence, EvidenceConfig};
use self::search::{propose, RefineConfig, SearchConfig};
use self::wallmap::WallMap;
use crate::formats::rosmap::RosMap;
use crate::geom::Pose2;
use crate::merge::graph::{groups, spanning_tree, Joined, PairEdge};
use crate::merge::MergeStatus;
use glam::DVec2;
use serde_json::json;

/// Settings of the saved-maps merge.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SavedMergeConfig {
    pub search: SearchConfig,
    pub evidence: EvidenceConfig,
    /// The search around a person's guess ([`refine`]).
    pub refine: RefineConfig,
}

/// The verdict on one pair of maps.
#[derive(Clone, Debug, PartialEq)]
pub struct PairResult {
    pub a: usize,
    pub b: usize,
    pub status: MergeStatus,
    pub reason: String,
    pub confidence: f64,
    /// B's map frame in A's map frame: the merge when merged, else the
    /// best overlay found (for display; not to be trusted).
    pub pose: Option<Pose2>,
    pub evidence: Option<Evidence>,
    /// Net support (m) of the best different overlay.
    pub rival_support_m: f64,
    /// Overlays refined and judged.
    pub overlays: usize,
    /// The person's guess this pair was refined from (B's map frame in
    /// A's), `None` for the automatic merge.
    pub guess: Option<Pose2>,
    /// `false` for a placement a person kept although the tests refused
    /// it ([`SavedMerge::keep_placement`]).
    pub verified: bool,
}

impl PairResult {
    /// A pair not judged yet: `no_merge`, no reason, nothing found.
    pub fn unjudged(a: usize, b: usize) -> PairResult {
        PairResult {
            a,
            b,
            status: MergeStatus::NoMerge,
            reason: String::new(),
            confidence: 0.0,
            pose: None,
            evidence: None,
            rival_support_m: 0.0,
            overlays: 0,
            guess: None,
            verified: true,
        }
    }
}

/// The reason of an accepted overlay in words with numbers; `others` says
/// which overlays the rival was taken among ("any other overlay …").
pub fn agreement_reason(
    e: &Evidence,
    rival_support_m: f64,
    cfg: &SavedMergeConfig,
    others: &str,
) -> String {
    let others = if others.is_empty() {
        String::new()
    } else {
        format!(" {others}")
    };
    // With no rival at all the ratio would be infinite: say so in words.
    let rival = if rival_support_m > 0.0 {
        format!(
            "{:.1} times that of any other overlay{others}",
            e.support_m / rival_support_m
        )
    } else {
        format!("and no other overlay{others} has any")
    };
    format!(
        "the maps agree: {:.1} m of wall of each on the other's within {:.2} m, acceptance index {:.2} ({} points agree, {} in the band, {} in free space), {:.1} m of net support, {rival}",
        e.agree_m,
        cfg.evidence.agree_m,
        e.index,
        e.agree[0] + e.agree[1],
        e.band[0] + e.band[1],
        e.disagree[0] + e.disagree[1],
        e.support_m,
    )
}

/// The merge of all maps.
#[derive(Clone, Debug, PartialEq)]
pub struct SavedMerge {
    pub status: MergeStatus,
    pub reason: String,
    pub confidence: f64,
    /// Each map's frame in the first map's; `None` where not joined.
    pub poses: Vec<Option<Pose2>>,
    pub unjoined: Vec<usize>,
    pub pairs: Vec<PairResult>,
    /// Every connected group of maps (the first map's first).
    pub groups: Vec<MapGroup>,
    /// `false` when a pair joining the first map's group is a placement
    /// kept by hand, not verified.
    pub verified: bool,
}

/// The confidence of a kept placement: above 0 (so it joins), below any
/// verified pair's.
pub const KEPT_CONFIDENCE: f64 = 1e-6;

/// One group of maps joined to each other and to no map outside it.
#[derive(Clone, Debug, PartialEq)]
pub struct MapGroup {
    /// Its maps, in the order they were opened.
    pub maps: Vec<usize>,
    /// Each map's frame in the frame of the group's first map (`None` for
    /// maps of other groups).
    pub poses: Vec<Option<Pose2>>,
    /// The weakest confidence of the pairs that join it (0 for one map).
    pub confidence: f64,
    /// Why a map stands alone (groups of one map only): the reason of the
    /// pair with the most net support among its pairs.
    pub reason: Option<String>,
    /// `false` when a pair joining it is a placement kept by hand.
    pub verified: bool,
}

impl MapGroup {
    fn new(tree: Joined, edges: &[(PairEdge, bool)], pairs: &[PairResult]) -> MapGroup {
        let verified = tree
            .edges_used
            .iter()
            .all(|&k| edges.get(k).is_none_or(|e| e.1));
        let maps: Vec<usize> = (0..tree.poses.len())
            .filter(|&i| tree.poses[i].is_some())
            .collect();
        let confidence = tree
            .edges_used
            .iter()
            .filter_map(|&k| edges.get(k).map(|e| e.0.confidence))
            .reduce(f64::min)
            .unwrap_or(0.0);
        let reason = match maps.as_slice() {
            [only] => pairs
                .iter()
                .filter(|p| p.a == *only || p.b == *only)
                .max_by(|p, q| {
                    let s = |r: &PairResult| r.evidence.map_or(f64::MIN, |e| e.support_m);
                    s(p).total_cmp(&s(q))
                })
                .map(|p| p.reason.clone()),
            _ => None,
        };
        MapGroup {
            maps,
            poses: tree.poses,
            confidence,
            reason,
            verified,
        }
    }
}

/// Searches and judges one pair (maps A and B, prepared as `wa`, `wb`).
pub fn merge_pair(
    (ia, a, wa): (usize, &RosMap, &WallMap),
    (ib, b, wb): (usize, &RosMap, &WallMap),
    cfg: &SavedMergeConfig,
) -> PairResult {
    let mut out = PairResult::unjudged(ia, ib);
    if wa.walls.len() < 10 || wb.walls.len() < 10 {
        out.reason = "a map has (almost) no walls to align".into();
        return out;
    }
    let proposals = propose(wa, wb, &cfg.search);
    out.overlays = proposals.len();
    let judged: Vec<(Pose2, Evidence)> = proposals
        .iter()
        .map(|p| (p.pose, evidence(wa, wb, &p.pose, &cfg.evidence)))
        .collect();
    if !judge_overlays(&mut out, (a, b, wb), &judged, cfg, "") {
        out.reason = "no overlay of the walls scores above zero".into();
    }
    out
}

/// Judges the overlay of `judged` (B's image frame in A's, with its
/// evidence) with the most net support (ties: the earlier) against the best
/// different one of them, and writes the verdict, the pose (B's map frame in
/// A's), the evidence and the rival into `out`; `others` says where the
/// rivals were found, for the reason. `false` when `judged` is empty.
pub fn judge_overlays(
    out: &mut PairResult,
    (a, b, wb): (&RosMap, &RosMap, &WallMap),
    judged: &[(Pose2, Evidence)],
    cfg: &SavedMergeConfig,
    others: &str,
) -> bool {
    let Some(w) = (0..judged.len()).reduce(|best, i| {
        if judged[i].1.support_m > judged[best].1.support_m {
            i
        } else {
            best
        }
    }) else {
        return false;
    };
    let (wpose, e) = judged[w];
    let centre = wb.walls.iter().copied().sum::<DVec2>() / wb.walls.len() as f64;
    out.rival_support_m = judged
        .iter()
        .filter(|(p, _)| distinct(p, &wpose, centre, &cfg.evidence))
        .map(|(_, r)| r.support_m)
        .fold(0.0, f64::max);
    out.evidence = Some(e);
    out.pose = Some(a.origin.compose(&wpose).compose(&b.origin.inverse()));
    match judge(&e, out.rival_support_m, &cfg.evidence) {
        Ok(confidence) => {
            out.status = MergeStatus::Merged;
            out.confidence = confidence;
            out.reason = agreement_reason(&e, out.rival_support_m, cfg, others);
        }
        Err(reason) => out.reason = reason,
    }
    true
}

/// Merges all `maps` (see the module doc). `progress` hears a line per
/// pair.
pub fn merge_all(
    maps: &[RosMap],
    cfg: &SavedMergeConfig,
    progress: &mut dyn FnMut(&str),
) -> SavedMerge {
    let prepared: Vec<WallMap> = maps.iter().map(WallMap::new).collect();
    let mut pairs = Vec::new();
    for i in 0..maps.len() {
        for j in i + 1..maps.len() {
            let r = merge_pair(
                (i, &maps[i], &prepared[i]),
                (j, &maps[j], &prepared[j]),
                cfg,
            );
            progress(&format!(
                "{} + {}: {} ({})",
                maps[i].name,
                maps[j].name,
                if r.status == MergeStatus::Merged {
                    "merged"
                } else {
                    "no merge"
                },
                r.reason
            ));
            pairs.push(r);
        }
    }
    join(maps, pairs)
}

/// Joins `maps` along the most confident spanning tree of the merged
/// `pairs` (see the module doc) and words the verdict.
pub fn join(maps: &[RosMap], pairs: Vec<PairResult>) -> SavedMerge {
    let marked: Vec<(PairEdge, bool)> = pairs
        .iter()
        .filter(|p| p.status == MergeStatus::Merged)
        .filter_map(|p| {
            p.pose.map(|pose| {
                let edge = PairEdge {
                    a: p.a,
                    b: p.b,
                    pose,
                    confidence: p.confidence,
                };
                (edge, p.verified)
            })
        })
        .collect();
    let edges: Vec<PairEdge> = marked.iter().map(|e| e.0).collect();
    let joined = spanning_tree(maps.len(), &edges);
    let verified = joined.edges_used.iter().all(|&k| marked[k].1);
    let map_groups = groups(maps.len(), &edges)
        .into_iter()
        .map(|tree| MapGroup::new(tree, &marked, &pairs))
        .collect();
    let unjoined = joined.unjoined();
    let used: Vec<&PairEdge> = joined.edges_used.iter().map(|&k| &edges[k]).collect();
    let confidence = used
        .iter()
        .map(|e| e.confidence)
        .reduce(f64::min)
        .unwrap_or(0.0);
    let (status, reason) = if maps.len() < 2 {
        (
            MergeStatus::NoMerge,
            "one map: nothing to merge".to_string(),
        )
    } else if unjoined.is_empty() {
        let reason = if pairs.len() == 1 {
            pairs[0].reason.clone()
        } else {
            format!(
                "all {} maps joined along the most confident of {} merged pairs (weakest edge confidence {:.2})",
                maps.len(),
                edges.len(),
                confidence
            )
        };
        (MergeStatus::Merged, reason)
    } else if pairs.len() == 1 {
        (MergeStatus::NoMerge, pairs[0].reason.clone())
    } else {
        let names: Vec<&str> = unjoined.iter().map(|&i| maps[i].name.as_str()).collect();
        (
            MergeStatus::NoMerge,
            format!(
                "{} of {} maps joined ({} of {} pairs merged); not joined: {}",
                maps.len() - unjoined.len(),
                maps.len(),
                edges.len(),
                pairs.len(),
                names.join(", ")
            ),
        )
    };
    SavedMerge {
        status,
        reason,
        confidence: if status == MergeStatus::Merged {
            confidence
        } else {
            0.0
        },
        poses: joined.poses,
        unjoined,
        pairs,
        groups: map_groups,
        verified,
    }
}

impl SavedMerge {
    /// Puts `pair` in place of the result on the same two maps (either
    /// order) and joins the maps again; returns its index in `pairs`,
    /// `None` when no such pair was judged.
    pub fn replace_pair(&mut self, maps: &[RosMap], pair: PairResult) -> Option<usize> {
        let same =
            |p: &PairResult| (p.a, p.b) == (pair.a, pair.b) || (p.a, p.b) == (pair.b, pair.a);
        let k = self.pairs.iter().position(same)?;
        let mut pairs = std::mem::take(&mut self.pairs);
        pairs[k] = pair;
        *self = join(maps, pairs);
        Some(k)
    }

    /// Keeps a person's placement of the pair `a`, `b` (in the order the
    /// merge judged it): map `b`'s frame at `pose` in map `a`'s, joined as
    /// it is, not verified. `refused` is why the tests refused it (the
    /// refine's reason). Returns the pair's index, `None` when no such pair
    /// was judged.
    pub fn keep_placement(
        &mut self,
        maps: &[RosMap],
        (a, b): (usize, usize),
        pose: Pose2,
        refused: &str,
    ) -> Option<usize> {
        let mut pair = PairResult::unjudged(a, b);
        pair.status = MergeStatus::Merged;
        pair.confidence = KEPT_CONFIDENCE;
        pair.pose = Some(pose);
        pair.guess = Some(pose);
        pair.verified = false;
        pair.reason = if refused.is_empty() {
            "placed by hand and kept as placed, not verified".to_string()
        } else {
            format!(
                "placed by hand and kept as placed, not verified (the tests refused it: {refused})"
            )
        };
        self.replace_pair(maps, pair)
    }
}

fn pose_json(p: &Pose2) -> serde_json::Value {
    json!([p.x, p.y, p.theta])
}

/// One group as the report gives it: its maps, each one's frame in the
/// group's first map's frame, the weakest confidence joining it and, for a
/// map alone, why.
fn group_json<'a>(g: &MapGroup, name: &dyn Fn(usize) -> &'a str) -> serde_json::Value {
    let transforms: Vec<_> = g
        .poses
        .iter()
        .enumerate()
        .filter_map(|(i, p)| p.map(|p| json!({ "map": name(i), "pose": pose_json(&p) })))
        .collect();
    let mut out = json!({
        "maps": g.maps.iter().map(|&i| name(i)).collect::<Vec<_>>(),
        "transforms": transforms,
        "confidence": g.confidence,
        "verified": g.verified,
    });
    if let Some(r) = &g.reason {
        out["reason"] = json!(r);
    }
    out
}

fn status_name(s: MergeStatus) -> &'static str {
    match s {
        MergeStatus::Merged => "merged",
        MergeStatus::NoMerge => "no_merge",
    }
}

impl SavedMerge {
    /// The report's `maps` and `merge` (docs/interfaces.md, "Real maps:
    /// merge-maps"); the caller adds `timings_ms`.
    pub fn report(&self, maps: &[RosMap]) -> serde_json::Value {
        let name = |i: usize| maps.get(i).map_or("", |m| m.name.as_str());
        let transforms: Vec<_> = self
            .poses
            .iter()
            .enumerate()
            .filter_map(|(i, p)| p.map(|p| json!({ "map": name(i), "pose": pose_json(&p) })))
            .collect();
        let pairs: Vec<_> = self
            .pairs
            .iter()
            .map(|p| {
                let mut pair = json!({
                    "a": name(p.a),
                    "b": name(p.b),
                    "status": status_name(p.status),
                    "reason": p.reason,
                    "confidence": p.confidence,
                    "pose": p.pose.map(|q| pose_json(&q)),
                    "evidence": p.evidence,
                    "rival_support_m": p.rival_support_m,
                    "overlays": p.overlays,
                });
                if let Some(g) = p.guess {
                    pair["guess"] = pose_json(&g);
                }
                if !p.verified {
                    pair["verified"] = json!(false);
                }
                pair
            })
            .collect();
        json!({
            "maps": maps.iter().map(|m| json!({
                "name": m.name, "width": m.width, "height": m.height, "resolution": m.resolution,
            })).collect::<Vec<_>>(),
            "merge": {
                "status": status_name(self.status),
                "verified": self.verified,
                "reason": self.reason,
                "confidence": self.confidence,
                "transforms": transforms,
                "unjoined": self.unjoined.iter().map(|&i| name(i)).collect::<Vec<_>>(),
                "pairs": pairs,
                "groups": self.groups.iter().map(|g| group_json(g, &name)).collect::<Vec<_>>(),
            },
        })
    }
}
