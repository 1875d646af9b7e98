//! # Do the candidates agree? Pairwise consistency and the largest agreeing set
//!
//! Each verified frame pair gives a candidate transform (B's map frame in
//! A's). Most candidates from a common place are right; some are wrong, and
//! a wrong one can look perfect on its own: two walls with the same texture
//! in different places match as well as one wall seen twice, and the lifted
//! points fit a rigid motion exactly. What a wrong candidate cannot do is
//! agree with right candidates from *other* places, because the robots'
//! maps are (nearly) rigid. That is the idea of Pairwise Consistency
//! Maximisation (J. Mangelson, D. Dominic, R. Eustice, R. Vasudevan,
//! *Pairwise Consistent Measurement Set Maximization for Robust Multi-robot
//! Map Merging*, ICRA 2018): build a graph with one node per measurement
//! and an edge between every two measurements that are consistent with each
//! other, and keep the *maximum clique*, the largest set in which every two
//! agree.
//!
//! ## The pairwise test
//! Two candidates `T₁`, `T₂` are consistent when they carry B's points to
//! nearly the same places in A and have nearly the same angle. Each
//! candidate is accurate at its own place (where its points are) and less so
//! far from it (an angle error `δθ` moves a point `d` away by `d·δθ`), and
//! the two maps themselves drift a little between two places `d` apart.
//! So the tolerance grows with the distance `d` between the two places:
//!
//! ```text
//! |T₁(p) − T₂(p)| ≤ t₀ + k_t·d   for p = each candidate's place in B
//! |θ₁ − θ₂|       ≤ a₀ + k_a·d
//! ```
//!
//! (Mangelson et al. use a Mahalanobis distance with covariances; we have
//! no calibrated covariances, and this linear growth is the same idea in
//! metres.)
//!
//! ## Independent evidence
//! A clique counts *measurements*, but ten frames taken a second apart of
//! one corridor are not ten independent witnesses: if the corridor's texture
//! repeats elsewhere, all ten are fooled together. Candidates are therefore
//! grouped into *places*: a candidate joins a group when both its place in
//! A and its place in B lie within `same_place_m` of the group's first
//! (strongest) member. Each group is represented by the member that agrees
//! with most of its group, and the maximum clique is taken over the
//! representatives: its size is the number of independent places that
//! agree. The answer lists every member of those groups that agrees with
//! all chosen representatives.
//!
//! ## Rival hypotheses
//! With a texture repeated on every wall, wrong candidates can agree among
//! themselves too (a maze shifted by a whole cell lays walls on walls), and
//! their clique may even be the largest. [`consistent_hypotheses`] therefore
//! lists the runners-up as well: the maximum clique, then the maximum clique
//! among the places that do not support it, and so on. The verdict
//! ([`super::verdict`]) judges each against the maps.
//!
//! ## The maximum clique
//! Bron–Kerbosch with pivoting (Tomita et al. 2006) on bit sets, which is
//! exact and fast on these sparse graphs. Maximum clique is NP-hard, so the
//! search has a budget of recursive calls; past it, the best clique found
//! so far is kept, which is deterministic too (and starts from a greedy
//! clique, so it is never empty when there are nodes).

use super::Candidate;
use crate::geom::wrap_angle;

/// Settings of the consistency test and of place grouping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConsistencyConfig {
    /// Translation tolerance at zero distance, metres. Default 0.25.
    pub translation_m: f64,
    /// Added per metre between the two places. Default 0.04.
    pub translation_per_m: f64,
    /// Angle tolerance at zero distance, radians. Default 3°.
    pub angle_rad: f64,
    /// Added per metre between the two places. Default 0.1°.
    pub angle_per_m_rad: f64,
    /// Candidates whose places lie this close in both maps are one piece of
    /// evidence, metres. Default 1.5.
    pub same_place_m: f64,
    /// Recursive calls the clique search may make. Default 50,000.
    pub clique_budget: usize,
}

impl Default for ConsistencyConfig {
    fn default() -> Self {
        ConsistencyConfig {
            translation_m: 0.25,
            translation_per_m: 0.04,
            angle_rad: 3f64.to_radians(),
            angle_per_m_rad: 0.1f64.to_radians(),
            same_place_m: 1.5,
            clique_budget: 50_000,
        }
    }
}

/// Distance between the two candidates' places (the larger of the distances
/// in A's map and in B's).
fn place_distance_m(c1: &Candidate, c2: &Candidate) -> f64 {
    (c1.place_a - c2.place_a)
        .length()
        .max((c1.place_b - c2.place_b).length())
}

/// Whether two candidates agree (see the module doc).
pub fn pairwise_consistent(c1: &Candidate, c2: &Candidate, cfg: &ConsistencyConfig) -> bool {
    if !c1.pose.is_finite() || !c2.pose.is_finite() {
        return false;
    }
    let d = place_distance_m(c1, c2);
    if !d.is_finite() {
        return false;
    }
    let tol_m = cfg.translation_m + cfg.translation_per_m * d;
    let tol_rad = cfg.angle_rad + cfg.angle_per_m_rad * d;
    if wrap_angle(c1.pose.theta - c2.pose.theta).abs() > tol_rad {
        return false;
    }
    [c1.place_b, c2.place_b]
        .iter()
        .all(|&p| (c1.pose.transform_point(p) - c2.pose.transform_point(p)).length() <= tol_m)
}

/// Groups candidates into independent places: `group[i]` for each
/// candidate, groups numbered from 0 in order of their strongest member
/// (most inliers first, then lowest index).
pub fn place_groups(cands: &[Candidate], cfg: &ConsistencyConfig) -> Vec<usize> {
    let mut order: Vec<usize> = (0..cands.len()).collect();
    order.sort_by(|&i, &j| cands[j].inliers.cmp(&cands[i].inliers).then(i.cmp(&j)));
    let mut seeds: Vec<usize> = Vec::new();
    let mut group = vec![0usize; cands.len()];
    for &i in &order {
        let c = &cands[i];
        let found = seeds.iter().position(|&s| {
            (cands[s].place_a - c.place_a).length() < cfg.same_place_m
                && (cands[s].place_b - c.place_b).length() < cfg.same_place_m
        });
        group[i] = match found {
            Some(g) => g,
            None => {
                seeds.push(i);
                seeds.len() - 1
            }
        };
    }
    group
}

/// Number of independent places among `members` (indices into `cands`).
pub fn independent_places(
    cands: &[Candidate],
    members: &[usize],
    cfg: &ConsistencyConfig,
) -> usize {
    let sub: Vec<Candidate> = members
        .iter()
        .filter_map(|&i| cands.get(i).cloned())
        .collect();
    let groups = place_groups(&sub, cfg);
    groups.iter().map(|g| g + 1).max().unwrap_or(0)
}

/// The largest agreeing set, as indices into the candidates.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ConsistentSet {
    /// Candidates in the set, ascending.
    pub members: Vec<usize>,
    /// Independent places among them (the clique's size).
    pub places: usize,
}

/// Bit set over up to `n` nodes.
#[derive(Clone, Debug, PartialEq)]
struct Bits(Vec<u64>);

impl Bits {
    fn new(n: usize) -> Bits {
        Bits(vec![0; n.div_ceil(64)])
    }
    fn set(&mut self, i: usize) {
        self.0[i / 64] |= 1 << (i % 64);
    }
    fn get(&self, i: usize) -> bool {
        self.0[i / 64] >> (i % 64) & 1 == 1
    }
    fn and(&self, o: &Bits) -> Bits {
        Bits(self.0.iter().zip(&o.0).map(|(a, b)| a & b).collect())
    }
    fn count(&self) -> usize {
        self.0.iter().map(|w| w.count_ones() as usize).sum()
    }
    fn is_empty(&self) -> bool {
        self.0.iter().all(|&w| w == 0)
    }
    fn iter(&self) -> impl Iterator<Item = usize> + '_ {
        self.0.iter().enumerate().flat_map(|(k, &w)| {
            (0..64)
                .filter(move |b| w >> b & 1 == 1)
                .map(move |b| k * 64 + b)
        })
    }
}

/// The search for the largest clique (ties: the larger total weight).
struct CliqueSearch<'a> {
    adjacency: &'a [Bits],
    weight: &'a [usize],
    best: Vec<usize>,
    best_key: (usize, usize),
    calls: usize,
    budget: usize,
}

impl CliqueSearch<'_> {
    fn key(&self, clique: &[usize]) -> (usize, usize) {
        (clique.len(), clique.iter().map(|&v| self.weight[v]).sum())
    }

    /// Bron–Kerbosch with pivoting: `r` the clique so far, `p` the nodes
    /// that could extend it, `x` those already tried.
    fn expand(&mut self, r: &mut Vec<usize>, p: Bits, mut x: Bits) {
        self.calls += 1;
        if p.is_empty() {
            if x.is_empty() {
                let key = self.key(r);
                if key > self.best_key {
                    self.best_key = key;
                    self.best = r.clone();
                }
            }
            return;
        }
        if self.calls > self.budget || r.len() + p.count() < self.best_key.0 {
            return;
        }
        // Pivot: the node of P ∪ X with most neighbours in P.
        let pivot = p
            .iter()
            .chain(x.iter())
            .max_by_key(|&u| (self.adjacency[u].and(&p).count(), usize::MAX - u))
            .unwrap_or(0);
        let candidates: Vec<usize> = p
            .iter()
            .filter(|&v| !self.adjacency[pivot].get(v))
            .collect();
        let mut p = p;
        for v in candidates {
            r.push(v);
            self.expand(r, p.and(&self.adjacency[v]), x.and(&self.adjacency[v]));
            r.pop();
            p.0[v / 64] &= !(1 << (v % 64));
            x.set(v);
            if self.calls > self.budget {
                return;
            }
        }
    }
}

/// The maximum clique of the graph, ties broken by total weight; exact
/// within the call budget.
fn maximum_clique(adjacency: &[Bits], weight: &[usize], budget: usize) -> Vec<usize> {
    let n = adjacency.len();
    if n == 0 {
        return Vec::new();
    }
    // Greedy start: repeatedly add the heaviest node adjacent to all so far.
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| {
        adjacency[b]
            .count()
            .cmp(&adjacency[a].count())
            .then(weight[b].cmp(&weight[a]))
            .then(a.cmp(&b))
    });
    let mut greedy: Vec<usize> = Vec::new();
    for v in order {
        if greedy.iter().all(|&u| adjacency[u].get(v)) {
            greedy.push(v);
        }
    }
    let mut search = CliqueSearch {
        adjacency,
        weight,
        best_key: (0, 0),
        best: Vec::new(),
        calls: 0,
        budget,
    };
    search.best_key = search.key(&greedy);
    search.best = greedy;
    let mut all = Bits::new(n);
    (0..n).for_each(|i| all.set(i));
    search.expand(&mut Vec::new(), all, Bits::new(n));
    let mut best = search.best;
    best.sort_unstable();
    best
}

/// The place groups, each group's representative (the member that agrees
/// with most of its group), and the consistency graph over the
/// representatives.
struct PlaceGraph {
    group: Vec<usize>,
    reps: Vec<usize>,
    adjacency: Vec<Bits>,
}

impl PlaceGraph {
    fn new(cands: &[Candidate], cfg: &ConsistencyConfig) -> PlaceGraph {
        let group = place_groups(cands, cfg);
        let groups = group.iter().max().map_or(0, |g| g + 1);
        let mut reps = Vec::with_capacity(groups);
        for g in 0..groups {
            let members: Vec<usize> = (0..cands.len()).filter(|&i| group[i] == g).collect();
            let rep = members
                .iter()
                .copied()
                .max_by_key(|&i| {
                    let agree = members
                        .iter()
                        .filter(|&&j| pairwise_consistent(&cands[i], &cands[j], cfg))
                        .count();
                    (agree, cands[i].inliers, usize::MAX - i)
                })
                .unwrap_or(g);
            reps.push(rep);
        }
        let mut adjacency = vec![Bits::new(groups); groups];
        for u in 0..groups {
            for v in u + 1..groups {
                if pairwise_consistent(&cands[reps[u]], &cands[reps[v]], cfg) {
                    adjacency[u].set(v);
                    adjacency[v].set(u);
                }
            }
        }
        PlaceGraph {
            group,
            reps,
            adjacency,
        }
    }

    /// The candidates of the clique's groups that agree with all of the
    /// clique's representatives.
    fn members(
        &self,
        cands: &[Candidate],
        clique: &[usize],
        cfg: &ConsistencyConfig,
    ) -> ConsistentSet {
        let chosen: Vec<usize> = clique.iter().map(|&g| self.reps[g]).collect();
        let members = (0..cands.len())
            .filter(|&i| clique.contains(&self.group[i]))
            .filter(|&i| {
                chosen
                    .iter()
                    .all(|&r| r == i || pairwise_consistent(&cands[i], &cands[r], cfg))
            })
            .collect();
        ConsistentSet {
            members,
            places: clique.len(),
        }
    }
}

/// The largest set of candidates from independent places that all agree
/// (see the module doc), with the number of places.
pub fn max_consistent_places(cands: &[Candidate], cfg: &ConsistencyConfig) -> ConsistentSet {
    consistent_hypotheses(cands, cfg, 1)
        .into_iter()
        .next()
        .unwrap_or_default()
}

/// Up to `max` rival hypotheses, largest first: the maximum clique, then
/// the maximum clique among the places that do not support it (a place
/// supports a clique when it agrees with at least half of its places), and
/// so on. Each is a different transform the evidence could stand for; the
/// verdict checks them against the maps. Empty without candidates.
pub fn consistent_hypotheses(
    cands: &[Candidate],
    cfg: &ConsistencyConfig,
    max: usize,
) -> Vec<ConsistentSet> {
    let graph = PlaceGraph::new(cands, cfg);
    let n = graph.reps.len();
    let mut alive: Vec<usize> = (0..n).collect();
    let mut out = Vec::new();
    while !alive.is_empty() && out.len() < max {
        // The subgraph of the places still in play, renumbered.
        let sub: Vec<Bits> = alive
            .iter()
            .map(|&u| {
                let mut b = Bits::new(alive.len());
                for (k, &v) in alive.iter().enumerate() {
                    if graph.adjacency[u].get(v) {
                        b.set(k);
                    }
                }
                b
            })
            .collect();
        let weight: Vec<usize> = alive
            .iter()
            .map(|&g| cands[graph.reps[g]].inliers)
            .collect();
        let clique: Vec<usize> = maximum_clique(&sub, &weight, cfg.clique_budget)
            .into_iter()
            .map(|k| alive[k])
            .collect();
        if clique.is_empty() {
            break;
        }
        out.push(graph.members(cands, &clique, cfg));
        alive.retain(|&g| {
            let support = clique
                .iter()
                .filter(|&&c| c == g || graph.adjacency[g].get(c))
                .count();
            2 * support < clique.len()
        });
    }
    out
}

/// The largest agreeing set of candidates (indices, ascending); see
/// [`max_consistent_places`] for how places are counted.
pub fn max_consistent_set(cands: &[Candidate], cfg: &ConsistencyConfig) -> Vec<usize> {
    max_consistent_places(cands, cfg).members
}
