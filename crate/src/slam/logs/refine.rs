//! # Every revisit linked: the log SLAM's closing refinement
//!
//! While a log is replayed, [`super::logslam`] closes a loop only where two
//! closures agree, every `loop_every` keys, against the nearest earlier
//! pass: enough to bring a tour back together, not enough to make its
//! passes through a place agree to the centimetre. Between closures the
//! key chain bends a little, and each pass keeps its own small offset.
//!
//! Karto / slam_toolbox (Konolige et al., "Efficient sparse pose adjustment
//! for 2D mapping", IROS 2010) links every scan to every *near chain* — the
//! earlier scans close to it in space, not in time — so the graph is held
//! at each place by all of its passes. This pass does that once the log is
//! replayed and the graph optimised, when every estimate is already within
//! a few decimetres of where it belongs:
//!
//! 1. for every key, each earlier visit to its place (runs of keys within
//!    `radius_m`, [`crate::slam::loop_closure::find_closure_among`]'s visits, not
//!    only the nearest) is a candidate;
//! 2. the key's scan is matched against that visit's keys in a *narrow*
//!    window around its current estimate (`window`): the graph is already
//!    right to within it, so no far, wrong place is in reach, and a match
//!    pressed against the window's edge is refused;
//! 3. every match that scores `min_score` becomes a loop-closure edge;
//! 4. the graph is optimised with Dynamic Covariance Scaling (Agarwal et
//!    al., ICRA 2013), which weighs down an edge that the rest disagree
//!    with instead of letting it bend the map.
//!
//! Repeated `rounds` times: each round starts from the graph the last one
//! left, so a place whose passes were too far apart for the narrow window
//! may come within it.

use crate::slam::degeneracy::scan_normals_within;
use crate::slam::icp::IcpTarget;
use crate::slam::loop_closure::{
    match_visit, on_window_edge, visit_centres, visit_keys, LoopConfig,
};
use crate::slam::multires::Window;
use crate::slam::posegraph::PoseGraph;
use glam::DVec2;
use std::collections::BTreeSet;

/// Settings of the closing refinement.
#[derive(Clone, Debug, PartialEq)]
pub struct RefineConfig {
    /// Rounds of linking and optimising (0: off).
    pub rounds: usize,
    /// Earlier keys within this distance are candidates.
    pub radius_m: f64,
    /// The narrow search window around a key's estimate.
    pub window: Window,
    /// Least score of a link.
    pub min_score: f64,
    /// Only every this many keys is linked.
    pub every: usize,
    /// Φ of Dynamic Covariance Scaling in the optimisation.
    pub dcs_phi: f64,
    /// Refine each link by point-to-line ICP on the visit's points
    /// ([`crate::slam::icp`]), off the matcher's raster grain.
    pub icp: bool,
    /// A link whose ICP answer is pinned less than this in its weakest
    /// direction (points' worth) is dropped.
    pub icp_min_weak: f64,
}

impl Default for RefineConfig {
    fn default() -> Self {
        RefineConfig {
            rounds: 0,
            radius_m: 2.0,
            window: Window {
                linear_m: 0.3,
                angular_rad: 3f64.to_radians(),
            },
            min_score: 0.6,
            every: 1,
            dcs_phi: 1.0,
            icp: true,
            icp_min_weak: 10.0,
        }
    }
}

/// Links every key of `graph` (scan points `key_points`, robot frame) to
/// the earlier visits to its place and optimises, `cfg.rounds` times.
/// `loops` gives the submap size and the closure edges' σ, `resolution_m`
/// the matching tables'. Returns the number of links added.
pub fn refine(
    graph: &mut PoseGraph,
    key_points: &[Vec<DVec2>],
    resolution_m: f64,
    loops: &LoopConfig,
    cfg: &RefineConfig,
) -> Result<usize, String> {
    let search = LoopConfig {
        search_radius_m: cfg.radius_m,
        window: cfg.window.clone(),
        window_per_m: 0.0,
        min_score: cfg.min_score,
        ..loops.clone()
    };
    let mut linked: BTreeSet<(usize, usize)> = graph
        .edges
        .iter()
        .filter(|e| e.loop_closure)
        .map(|e| (e.from, e.to))
        .collect();
    let mut added = 0;
    // Normals of the thinned key scans (robot frame), for the ICP.
    let normals: Vec<Vec<Option<DVec2>>> = if cfg.icp {
        key_points
            .iter()
            .map(|p| scan_normals_within(p, ICP_NORMAL_RADIUS_M))
            .collect()
    } else {
        Vec::new()
    };
    for _ in 0..cfg.rounds {
        let nodes = graph.nodes.clone();
        for i in (0..nodes.len()).step_by(cfg.every.max(1)) {
            for centre in visit_centres(&nodes, i, &search, &[]) {
                if linked.contains(&(centre, i)) {
                    continue;
                }
                let Some(c) =
                    match_visit(&nodes, key_points, i, centre, 0.0, resolution_m, &search)
                else {
                    continue;
                };
                let edge_m = 2.0 * resolution_m;
                if on_window_edge(&nodes, &c, &cfg.window, edge_m, 0.25f64.to_radians()) {
                    continue;
                }
                let found = nodes[c.edge.from].compose(&c.edge.measurement);
                let mut edge = c.edge;
                if cfg.icp {
                    let Some(pose) = icp_link(
                        &nodes, key_points, &normals, i, centre, &search, &found, cfg,
                    ) else {
                        continue;
                    };
                    edge.measurement = nodes[centre].between(&pose);
                }
                linked.insert((centre, i));
                graph.edges.push(edge);
                added += 1;
            }
        }
        graph.optimise_robust(20, Some(cfg.dcs_phi).filter(|&p| p > 0.0))?;
    }
    Ok(added)
}

/// Neighbourhood of a thinned key scan's point for its normal (m).
const ICP_NORMAL_RADIUS_M: f64 = 0.35;
/// Association radius and Huber threshold of a link's ICP (m).
const ICP_RADIUS_M: f64 = 0.2;
const ICP_HUBER_M: f64 = 0.02;

/// Key `i`'s pose refined by point-to-line ICP against the keys of the
/// visit around `centre` (the submap the correlative match used), from its
/// matched pose `found`; `None` when the answer is not pinned in every
/// direction, leaves most points off the visit's surfaces, or wanders
/// further than a cell and half a degree from the match (then the two
/// disagree about which surfaces are which).
#[allow(clippy::too_many_arguments)]
fn icp_link(
    nodes: &[crate::geom::Pose2],
    key_points: &[Vec<DVec2>],
    normals: &[Vec<Option<DVec2>>],
    i: usize,
    centre: usize,
    search: &LoopConfig,
    found: &crate::geom::Pose2,
    cfg: &RefineConfig,
) -> Option<crate::geom::Pose2> {
    let (mut points, mut dirs) = (Vec::new(), Vec::new());
    for j in visit_keys(i, centre, search) {
        let f = nodes[j].frame();
        points.extend(key_points[j].iter().map(|&p| f.to_parent(p)));
        dirs.extend(normals[j].iter().map(|n| n.map(|n| f.rotate(n))));
    }
    let target = IcpTarget::new(&points, &dirs, ICP_RADIUS_M);
    let fit = target.align(&key_points[i], found, ICP_HUBER_M, 30);
    let moved = found.between(&fit.pose);
    let near = moved.position().length() <= 0.05 && moved.theta.abs() <= 0.5f64.to_radians();
    (near && fit.weak >= cfg.icp_min_weak && 2 * fit.associated >= key_points[i].len())
        .then_some(fit.pose)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::Pose2;
    use crate::slam::posegraph::Edge;
    use crate::slam::scenes;

    /// Three passes along the room, each internally right; the third one
    /// was joined to the second by a wrong edge that left it 5–15 cm and 0.5°
    /// off. The refinement links it to the first pass and brings it back.
    #[test]
    fn a_pass_left_off_by_a_wrong_edge_is_brought_back() {
        let walls = scenes::room();
        let mut truth = Vec::new();
        for k in 0..30 {
            truth.push(Pose2::new(1.5 + 0.3 * k as f64, 2.5, 0.0));
        }
        for k in 0..30 {
            truth.push(Pose2::new(10.2 - 0.3 * k as f64, 3.0, std::f64::consts::PI));
        }
        for k in 0..30 {
            truth.push(Pose2::new(1.5 + 0.3 * k as f64, 2.2, 0.02));
        }
        let key_points: Vec<Vec<DVec2>> = truth
            .iter()
            .map(|p| scenes::scan(p, &walls, f64::INFINITY))
            .collect();
        let slip = Pose2::new(0.05, -0.04, 0.5f64.to_radians());
        let mut graph = PoseGraph::default();
        for (k, p) in truth.iter().enumerate() {
            graph.nodes.push(if k >= 60 { slip.compose(p) } else { *p });
        }
        for k in 1..truth.len() {
            let z = if k == 60 {
                graph.nodes[59].between(&graph.nodes[60])
            } else {
                truth[k - 1].between(&truth[k])
            };
            graph
                .edges
                .push(Edge::new(k - 1, k, z, 0.1, 0.5f64.to_radians()));
        }
        graph.optimise(10).unwrap();
        let off = |g: &PoseGraph| {
            (60..90)
                .map(|k| {
                    let e = truth[k - 60]
                        .between(&truth[k])
                        .between(&g.nodes[k - 60].between(&g.nodes[k]));
                    (e.position().length(), e.theta.abs())
                })
                .fold((0f64, 0f64), |a, b| (a.0.max(b.0), a.1.max(b.1)))
        };
        let before = off(&graph);
        assert!(before.0 > 0.05, "the third pass starts off: {before:?}");
        let cfg = RefineConfig {
            rounds: 1,
            ..RefineConfig::default()
        };
        let links = refine(&mut graph, &key_points, 0.05, &LoopConfig::default(), &cfg).unwrap();
        let after = off(&graph);
        // Each link is the truth to the millimetre: ICP on the points,
        // not the raster's grain (which left them 1.4 cm off here).
        for e in graph.edges.iter().filter(|e| e.loop_closure) {
            let t = truth[e.from].between(&truth[e.to]).between(&e.measurement);
            assert!(
                t.position().length() < 0.003 && t.theta.abs() < 0.05f64.to_radians(),
                "link {} → {} off by {:.4} m, {:.3}°",
                e.from,
                e.to,
                t.position().length(),
                t.theta.to_degrees()
            );
        }
        // Keys 60..90 see keys 0..30 (and 30..60) within 2 m.
        assert!(links >= 30, "{links} links");
        assert!(
            after.0 < 0.01 && after.1 < 0.25f64.to_radians(),
            "off by {:.3} m, {:.2}° after (before {:.3} m, {:.2}°)",
            after.0,
            after.1.to_degrees(),
            before.0,
            before.1.to_degrees()
        );
    }
}
