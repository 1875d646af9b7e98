//! # Three or more robots: joining along the most confident spanning tree
//!
//! With `n` robots every pair is judged on its own ([`super::verdict`]);
//! each merged pair is an *edge* of a graph whose nodes are the robots,
//! carrying the relative pose and a confidence. Robot 0's frame is the
//! merged frame, and every other robot needs one chain of edges back to it.
//! Different chains may disagree slightly (each edge has its own small
//! error), so we pick one: the **maximum spanning tree**, which of all trees
//! has the largest total confidence and, by the cut property, never uses a
//! weaker edge where a stronger one would connect the same parts. It is
//! grown by Prim's algorithm from robot 0 (R. C. Prim, *Shortest connection
//! networks*, 1957): repeatedly add the most confident edge from a joined
//! robot to an unjoined one.
//!
//! Poses compose along the tree: an edge `(a, b, T)` holds the pose of b's
//! frame in a's, so with a's frame at `P_a` in robot 0's, b's is
//! `P_a ⊕ T`; walked the other way, `P_a = P_b ⊕ T⁻¹`. Robots that no edge
//! reaches stay unjoined, and are listed.
//!
//! With many robots, several groups may each share a map among themselves
//! and none with robot 0's group ([`groups`]): each is grown the same way,
//! from its lowest-numbered robot, whose frame is that group's frame. The
//! first group is always robot 0's, exactly as [`spanning_tree`] joins it.

use crate::geom::Pose2;

/// A merged robot pair: `pose` is robot b's frame in robot a's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairEdge {
    pub a: usize,
    pub b: usize,
    pub pose: Pose2,
    /// Larger is surer; edges at or below 0 (or not finite) are ignored.
    pub confidence: f64,
}

/// The joined robots.
#[derive(Clone, Debug, PartialEq)]
pub struct Joined {
    /// Each robot's frame in robot 0's frame; `None` for robots not joined.
    pub poses: Vec<Option<Pose2>>,
    /// Indices of the edges in the tree, in the order they were added.
    pub edges_used: Vec<usize>,
}

impl Joined {
    /// Robots that could not be joined to robot 0.
    pub fn unjoined(&self) -> Vec<usize> {
        self.poses
            .iter()
            .enumerate()
            .filter(|(_, p)| p.is_none())
            .map(|(i, _)| i)
            .collect()
    }
}

/// The maximum-confidence spanning tree from robot 0 (see the module doc).
/// Ties go to the lower edge index. Edges naming robots out of range, loops
/// (`a == b`) and non-finite poses are ignored.
pub fn spanning_tree(robots: usize, edges: &[PairEdge]) -> Joined {
    spanning_tree_from(robots, edges, 0)
}

/// Every connected group of robots, each joined along its own
/// maximum-confidence spanning tree from its lowest-numbered robot (poses
/// in that robot's frame; robots of other groups `None`), in the order of
/// their first robots: robot 0's group first. A robot no edge reaches is a
/// group of its own.
pub fn groups(robots: usize, edges: &[PairEdge]) -> Vec<Joined> {
    let mut placed = vec![false; robots];
    let mut out = Vec::new();
    for root in 0..robots {
        if placed[root] {
            continue;
        }
        let joined = spanning_tree_from(robots, edges, root);
        for (i, p) in joined.poses.iter().enumerate() {
            placed[i] |= p.is_some();
        }
        out.push(joined);
    }
    out
}

/// [`spanning_tree`] grown from robot `root` (whose frame is the group's).
pub fn spanning_tree_from(robots: usize, edges: &[PairEdge], root: usize) -> Joined {
    let mut poses: Vec<Option<Pose2>> = vec![None; robots];
    let mut edges_used = Vec::new();
    if root >= robots {
        return Joined { poses, edges_used };
    }
    poses[root] = Some(Pose2::IDENTITY);
    let usable = |e: &PairEdge| {
        e.a < robots
            && e.b < robots
            && e.a != e.b
            && e.confidence.is_finite()
            && e.confidence > 0.0
            && e.pose.is_finite()
    };
    loop {
        // The most confident edge with exactly one end joined.
        let mut best: Option<(usize, f64)> = None;
        for (k, e) in edges.iter().enumerate() {
            if !usable(e) || poses[e.a].is_some() == poses[e.b].is_some() {
                continue;
            }
            if best.is_none_or(|(_, c)| e.confidence > c) {
                best = Some((k, e.confidence));
            }
        }
        let Some((k, _)) = best else { break };
        let e = &edges[k];
        match (poses[e.a], poses[e.b]) {
            (Some(pa), None) => poses[e.b] = Some(pa.compose(&e.pose)),
            (None, Some(pb)) => poses[e.a] = Some(pb.compose(&e.pose.inverse())),
            _ => break,
        }
        edges_used.push(k);
    }
    Joined { poses, edges_used }
}
