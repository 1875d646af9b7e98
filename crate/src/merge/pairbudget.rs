//! # Many robots: which pairs to check, within a budget
//!
//! `n` robots make `n (n − 1) / 2` pairs: 120 for sixteen robots. Judging
//! every pair in full — matching hundreds of frame pairs, then, where the
//! frames find nothing, searching one map for the other
//! ([`super::mapsearch`]) — makes the merge grow with the square of the
//! robots, and almost all of it is spent proving that robots which never
//! met did not meet (on a 16-robot run, 99 % of the decision time went to
//! map searches of pairs that were then refused). Most pairs of a crowd
//! never saw a common place, and a group of robots needs only a spanning
//! tree of merged pairs to share one map. So the automatic method ranks the
//! pairs first, by evidence that needs no transform and costs little, and
//! checks only a bounded number of them:
//!
//! 1. **Visual votes** (place recognition as a vote, after Sivic and
//!    Zisserman's *Video Google*, 2003, and Nistér and Stewénius 2006):
//!    every frame's bag of visual words ([`super::vocabulary`]) is scored
//!    against every frame of every *other* robot through one inverted file,
//!    and the frame votes for the robots that hold its `votes_per_frame`
//!    most similar frames. Two robots that saw the same walls collect many
//!    votes from each other; a frame of a place nobody else saw spreads its
//!    few votes thinly over everyone. A pair's figure is the share of each
//!    robot's frames that voted for the other, added.
//! 2. **Coarse map overlap** (Carpin 2008, steps 1 and 2 of
//!    [`super::mapsearch`] at a coarse cell): the rotation from the maps'
//!    Hough spectra, computed once per map, then the best translation of
//!    the four rotations, scored as walls on walls and walls in free space
//!    at 0.4 m cells — a few hundred times cheaper than the full search at
//!    0.1 m with its refinement and verdict. The figure is the best score
//!    over the smaller map's wall cells. Two robots can map the same
//!    corridors without ever facing the same stretch of wall from nearby;
//!    this is the evidence that finds them.
//! 3. **The budget.** Each robot keeps its `k` best partners by each
//!    figure, with `k = ⌈log₂ n + ½ log₂(1 + F / 100)⌉` growing gently with
//!    the robots `n` and the mean number of frames `F` a robot brings (a
//!    longer run covers more of the building and meets more robots). A pair
//!    among either robot's `k` best by the votes has its frames matched and
//!    judged; a pair among either robot's `k` best by map overlap has its
//!    maps searched where the frames did not merge it (or were not
//!    matched); any other pair is not checked, and the report says so. So
//!    at most `n k` pairs are matched and `n k` maps searched. Up to
//!    `all_pairs_up_to` robots (four: six pairs) every pair is checked in
//!    full, exactly as before.
//! 4. **Early exit** (the spanning tree needs only enough edges,
//!    [`super::graph`]): the frame-based verdicts come first; then the map
//!    searches run in the order of the pairs' ranks, and a pair whose two
//!    robots are already joined through merged pairs ([`Components`], a
//!    union-find) is not searched. Skipping a search only ever leaves an
//!    edge out: it can cost a redundant confirmation, never add a wrong
//!    merge.
//!
//! Nothing here reads the truth; everything is deterministic (ties go to
//! the lower robot index).

use super::mapsearch::{CoarseMap, CoarseOverlap, WallSpectrum};
use super::vocabulary::{inverted_file, word_count, Bag};
use crate::slam::OccupancyGrid;
use serde::Serialize;

/// Settings of the pair budget.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairBudgetConfig {
    /// Every pair is checked in full up to this many robots. Default 4.
    pub all_pairs_up_to: usize,
    /// Frames of other robots each frame votes for. Default 3.
    pub votes_per_frame: usize,
    /// Cell of the coarse map overlap, metres. Default 0.4.
    pub coarse_cell_m: f64,
    /// What a wall in the other map's free space costs in the coarse
    /// overlap, in agreeing wall cells. Default 3 (as the map search).
    pub free_penalty: i32,
}

impl Default for PairBudgetConfig {
    fn default() -> Self {
        PairBudgetConfig {
            all_pairs_up_to: 4,
            votes_per_frame: 3,
            coarse_cell_m: 0.4,
            free_penalty: 3,
        }
    }
}

/// How much of a pair of robots is checked.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PairPlan {
    /// Frames matched, then the verdict and, if needed, the map search.
    #[default]
    Full,
    /// The maps searched alone; no frame matched.
    MapsOnly,
    /// Not checked within the budget.
    NotChecked,
}

/// The budget's view of one pair of robots.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairBudget {
    pub plan: PairPlan,
    /// Position of the pair in its robots' partner lists, best of the four
    /// (0 is a robot's likeliest partner); the map searches go in this order.
    pub rank: usize,
    /// Partners each robot keeps (`k` of the module doc).
    pub partners: usize,
    /// Whether the maps may be searched: one robot ranks the other among
    /// its `k` likeliest partners by coarse map overlap.
    pub search: bool,
    /// The visual-vote figure and the coarse map overlap.
    pub votes: f64,
    pub overlap: f64,
}

/// `k` of the module doc: partners kept per robot, for `robots` robots
/// bringing `mean_frames` frames each; at least 1, at most `robots − 1`.
pub fn partners_per_robot(robots: usize, mean_frames: f64) -> usize {
    let k = (robots.max(1) as f64).log2() + 0.5 * (1.0 + mean_frames.max(0.0) / 100.0).log2();
    (k.ceil() as usize).clamp(1, robots.saturating_sub(1).max(1))
}

/// The visual-vote figure of every pair of robots (step 1 of the module
/// doc): `out[a][b]`, symmetric, 0 on the diagonal. `bags[r]` holds robot
/// `r`'s frames' bags. [`VoteTally`] run to the end.
pub fn visual_votes(bags: &[Vec<Bag>], votes_per_frame: usize) -> Vec<Vec<f64>> {
    let mut tally = VoteTally::new(bags);
    for r in 0..bags.len() {
        tally.vote(bags, r, votes_per_frame);
    }
    tally.shares(bags)
}

/// The visual votes a robot at a time: one inverted file over every frame
/// of every robot, then each robot's frames cast their votes.
struct VoteTally {
    postings: Vec<Vec<(u32, f32)>>,
    /// The robot of each frame, frames numbered robot after robot.
    owner: Vec<usize>,
    /// `votes[a][b]`: frames of `a` that voted for `b`.
    votes: Vec<Vec<usize>>,
    /// Robots whose frames have voted.
    voted: usize,
}

impl VoteTally {
    fn new(bags: &[Vec<Bag>]) -> VoteTally {
        let n = bags.len();
        let all: Vec<&Bag> = bags.iter().flatten().collect();
        VoteTally {
            postings: inverted_file(all.iter().copied(), word_count(all.iter().copied())),
            owner: (0..n).flat_map(|r| vec![r; bags[r].len()]).collect(),
            votes: vec![vec![0; n]; n],
            voted: 0,
        }
    }

    /// Robot `r`'s frames vote, each for the robots holding its
    /// `votes_per_frame` most similar frames of other robots.
    fn vote(&mut self, bags: &[Vec<Bag>], r: usize, votes_per_frame: usize) {
        let mut scores = vec![0f64; self.owner.len()];
        for bag in &bags[r] {
            scores.iter_mut().for_each(|s| *s = 0.0);
            for &(w, va) in &bag.words {
                for &(j, vb) in &self.postings[w as usize] {
                    scores[j as usize] += va as f64 * vb as f64;
                }
            }
            for j in best_of_others(&scores, &self.owner, r, votes_per_frame) {
                self.votes[r][self.owner[j]] += 1;
            }
        }
        self.voted += 1;
    }

    /// A pair's figure: the share of each robot's frames that voted for
    /// the other, added.
    fn shares(&self, bags: &[Vec<Bag>]) -> Vec<Vec<f64>> {
        let n = bags.len();
        let share = |a: usize, b: usize| self.votes[a][b] as f64 / bags[a].len().max(1) as f64;
        (0..n)
            .map(|a| {
                (0..n)
                    .map(|b| {
                        if a == b {
                            0.0
                        } else {
                            share(a, b) + share(b, a)
                        }
                    })
                    .collect()
            })
            .collect()
    }
}

/// The `k` frames with the best positive scores that belong to a robot
/// other than `me` (ties: the lower index).
fn best_of_others(scores: &[f64], owner: &[usize], me: usize, k: usize) -> Vec<usize> {
    // A short sorted list, kept by insertion: k is a handful.
    let mut best: Vec<usize> = Vec::with_capacity(k + 1);
    for j in (0..scores.len()).filter(|&j| owner[j] != me && scores[j] > 0.0) {
        let at = best.partition_point(|&x| scores[x] >= scores[j]);
        if at < k {
            best.insert(at, j);
            best.truncate(k);
        }
    }
    best
}

/// The whole budget (steps 1 to 3 of the module doc) a step at a time, so
/// that a caller with a page to draw never waits for all of it: the
/// inverted file of the visual votes, each robot's votes, then each
/// robot's coarse map (its spectrum and raster,
/// [`CoarseMap`]), then each pair's coarse overlap (step 2; 120 pairs for
/// sixteen robots, tens of milliseconds each on 60 m maps), then the plan.
/// Run to the end it is the same budget however the steps are spread over
/// calls.
pub struct BudgetSteps {
    /// Partners kept per robot (`k`).
    k: usize,
    tally: Option<VoteTally>,
    votes: Option<Vec<Vec<f64>>>,
    coarse: Vec<CoarseMap>,
    /// The next robot's wall spectrum, once computed (its coarse map is
    /// two steps: the spectrum, then the raster).
    spectrum: Option<WallSpectrum>,
    /// `overlaps[a][b]`, symmetric, filled pair by pair.
    overlaps: Vec<Vec<f64>>,
    /// The next pair whose overlap is computed, `a < b`, and its
    /// comparison under way (a quarter turn a step).
    next: (usize, usize),
    overlap: Option<CoarseOverlap>,
    pairs_done: usize,
}

impl BudgetSteps {
    /// The budget of `robots` robots keeping `k` partners each.
    pub fn new(robots: usize, k: usize) -> BudgetSteps {
        BudgetSteps {
            k,
            tally: None,
            votes: None,
            coarse: Vec::with_capacity(robots),
            spectrum: None,
            overlaps: vec![vec![0.0; robots]; robots],
            next: (0, 1),
            overlap: None,
            pairs_done: 0,
        }
    }

    /// Steps in all for `robots` robots: the inverted file, a robot's votes
    /// each, two per coarse map (its spectrum, its raster), four quarter
    /// turns per pair's overlap (a pair whose maps show too few walls takes
    /// one).
    pub fn total(robots: usize) -> usize {
        1 + 3 * robots + 4 * (robots * robots.saturating_sub(1) / 2)
    }

    /// Steps taken so far.
    pub fn done(&self) -> usize {
        let (file, voted) = match (&self.tally, &self.votes) {
            (Some(t), _) => (1, t.voted),
            (None, Some(v)) => (1, v.len()),
            (None, None) => (0, 0),
        };
        let turns = self.overlap.as_ref().map_or(0, CoarseOverlap::turns);
        let spectra = self.coarse.len() + usize::from(self.spectrum.is_some());
        file + voted + self.coarse.len() + spectra + 4 * self.pairs_done + turns
    }

    /// One step; the plan of every pair `(a, b)`, `a < b`, in that order,
    /// once the last overlap is in. `bags[r]` holds robot `r`'s frames'
    /// bags and `maps[r]` its map, the same on every call.
    pub fn step(
        &mut self,
        bags: &[Vec<Bag>],
        maps: &[&OccupancyGrid],
        cfg: &PairBudgetConfig,
    ) -> Option<Vec<PairBudget>> {
        let n = maps.len();
        let Some(votes) = &self.votes else {
            match self.tally.as_mut() {
                None => self.tally = Some(VoteTally::new(bags)),
                Some(tally) => {
                    if tally.voted < bags.len() {
                        tally.vote(bags, tally.voted, cfg.votes_per_frame);
                    }
                    if tally.voted >= bags.len() {
                        self.votes = Some(tally.shares(bags));
                        self.tally = None;
                    }
                }
            }
            return None;
        };
        if self.coarse.len() < n {
            let map = maps[self.coarse.len()];
            match self.spectrum.take() {
                None => self.spectrum = Some(WallSpectrum::of(map)),
                Some(spectrum) => self.coarse.push(CoarseMap::with_spectrum(
                    map,
                    spectrum,
                    cfg.coarse_cell_m,
                    cfg.free_penalty,
                )),
            }
            return None;
        }
        let (a, b) = self.next;
        if b < n {
            let overlap = self
                .overlap
                .get_or_insert_with(|| CoarseOverlap::new(&self.coarse[a], &self.coarse[b]));
            let s = overlap.step(&self.coarse[a], maps[b], cfg.free_penalty)?;
            self.overlap = None;
            self.overlaps[a][b] = s;
            self.overlaps[b][a] = s;
            self.pairs_done += 1;
            self.next = if b + 1 < n {
                (a, b + 1)
            } else {
                (a + 1, a + 2)
            };
            if self.next.1 < n {
                return None;
            }
        }
        Some(plan_pairs(votes, &self.overlaps, self.k))
    }
}

/// Robot `a`'s partners by `figure[a]`, best first (positive figures only;
/// ties: the lower index).
fn ranked_partners(figure: &[Vec<f64>], a: usize) -> Vec<usize> {
    let mut v: Vec<usize> = (0..figure.len())
        .filter(|&b| b != a && figure[a][b] > 0.0)
        .collect();
    v.sort_by(|&x, &y| figure[a][y].total_cmp(&figure[a][x]).then(x.cmp(&y)));
    v
}

/// The plan of every pair `(a, b)`, `a < b`, in that order (step 3 of the
/// module doc), from the two figures and `k` partners per robot.
pub fn plan_pairs(votes: &[Vec<f64>], overlaps: &[Vec<f64>], k: usize) -> Vec<PairBudget> {
    let n = votes.len();
    let by_votes: Vec<Vec<usize>> = (0..n).map(|a| ranked_partners(votes, a)).collect();
    let by_maps: Vec<Vec<usize>> = (0..n).map(|a| ranked_partners(overlaps, a)).collect();
    // Where b stands in a's list (usize::MAX when absent).
    let place = |lists: &[Vec<usize>], a: usize, b: usize| {
        lists[a].iter().position(|&x| x == b).unwrap_or(usize::MAX)
    };
    let mut out = Vec::new();
    for a in 0..n {
        for b in a + 1..n {
            let rank_votes = place(&by_votes, a, b).min(place(&by_votes, b, a));
            let rank_maps = place(&by_maps, a, b).min(place(&by_maps, b, a));
            let plan = if rank_votes < k {
                PairPlan::Full
            } else if rank_maps < k {
                PairPlan::MapsOnly
            } else {
                PairPlan::NotChecked
            };
            out.push(PairBudget {
                plan,
                rank: rank_votes.min(rank_maps),
                partners: k,
                search: rank_maps < k,
                votes: votes[a][b],
                overlap: overlaps[a][b],
            });
        }
    }
    out
}

/// The connected groups of robots the merged pairs so far make: a
/// union-find (Tarjan 1975) with path halving.
#[derive(Clone, Debug)]
pub struct Components {
    parent: Vec<usize>,
}

impl Components {
    pub fn new(robots: usize) -> Components {
        Components {
            parent: (0..robots).collect(),
        }
    }

    fn root(&mut self, mut i: usize) -> usize {
        while self.parent[i] != i {
            self.parent[i] = self.parent[self.parent[i]];
            i = self.parent[i];
        }
        i
    }

    /// Joins the groups of `a` and `b` (the lower root stays the root).
    pub fn join(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.root(a), self.root(b));
        self.parent[ra.max(rb)] = ra.min(rb);
    }

    /// Whether `a` and `b` are already in one group.
    pub fn same(&mut self, a: usize, b: usize) -> bool {
        self.root(a) == self.root(b)
    }
}

/// What the budget did, for the report (only when it applied).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct BudgetSummary {
    /// Partners each robot keeps by each figure (`k`).
    pub partners_per_robot: usize,
    /// Pairs of robots in all.
    pub pairs: usize,
    /// Pairs whose frames were matched (checked in full).
    pub matched: usize,
    /// Map searches run (of matched pairs vision did not merge, and of
    /// pairs searched by their maps only).
    pub maps_searched: usize,
    /// Map searches not run because the two robots were already joined
    /// (of matched pairs, and of pairs left to their maps).
    pub searches_skipped: usize,
    /// Pairs of which nothing was checked: not within the budget, or left
    /// to their maps and skipped as joined already (`check: "none"`).
    pub not_checked: usize,
}
