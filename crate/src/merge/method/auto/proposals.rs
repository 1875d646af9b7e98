//! # The automatic method's proposals, a step at a time
//!
//! Before any frame pair is matched, the automatic method decides which
//! pairs to match (stage 3 of [`crate::merge::job`]):
//!
//! 1. **The vocabulary.** A vocabulary tree of visual words is trained on
//!    the described frames of every robot, each frame's descriptors become
//!    words (and count into each word's document frequency), then each
//!    frame becomes a bag of weighted words ([`crate::merge::vocabulary`],
//!    after Sivic and Zisserman 2003 and Nistér and Stewénius 2006).
//! 2. **The pair budget** (many robots only): the visual votes, each
//!    robot's coarse map and each pair's coarse map overlap, then the plan
//!    of which pairs are matched, searched by their maps only, or left
//!    ([`crate::merge::pairbudget`], [`BudgetSteps`]).
//! 3. **The to-do lists.** Each pair checked in full has its frames
//!    nominate their likeliest partners in the other robot
//!    ([`propose_pairs`]); the pair's list of frame pairs to match.
//!
//! Done in one call, this is seconds on a crowded hour (sixteen robots: 120
//! coarse overlaps of 60 m maps), time in which a page could not draw. So
//! it is cut into steps: step 1 is one for the tree, one per robot's words
//! and one for the weights; step 2 one for the votes' inverted file, one
//! per robot's votes, two per coarse map (its spectrum, its raster) and one
//! per quarter turn of each pair's overlap; step 3 one per pair of robots. [`ProposalSteps`] keeps what is done between calls.
//! The steps are taken in the order one call takes them, so the proposals
//! do not depend on how the steps are spread over calls
//! (`tests/merge_groups.rs` checks it).

use crate::merge::config::MergeConfig;
use crate::merge::pairbudget::{partners_per_robot, BudgetSteps, PairBudget, PairPlan};
use crate::merge::vocabulary::{propose_pairs, Bag, VocabularyTraining};
use crate::merge::work::{PairWork, RobotFrames};
use crate::slam::OccupancyGrid;
use crate::surf::Features;

/// The proposal stage between calls; fresh for each merge.
#[derive(Default)]
pub struct ProposalSteps {
    /// The vocabulary under training (step 1): its tree, then the words of
    /// `worded` robots' frames.
    training: Option<VocabularyTraining>,
    worded: usize,
    /// The robots' frames as bags of words, once the training is done.
    bags: Option<Vec<Vec<Bag>>>,
    /// The pair budget under way (step 2; `None` when every pair is
    /// checked in full).
    budget: Option<BudgetSteps>,
    /// The budget's plan of every pair, once made.
    plan: Option<Vec<PairBudget>>,
    /// Pairs whose to-do list is filled (step 3).
    filled: usize,
}

impl ProposalSteps {
    /// Steps (done, total) for `robots` robots under `config`.
    pub fn progress(&self, robots: usize, config: &MergeConfig) -> (usize, usize) {
        let pairs = robots * robots.saturating_sub(1) / 2;
        let budget = if budget_applies(robots, config) {
            BudgetSteps::total(robots)
        } else {
            0
        };
        let done = usize::from(self.training.is_some() || self.bags.is_some())
            + self.worded
            + usize::from(self.bags.is_some())
            + self.budget.as_ref().map_or(0, |b| b.done())
            + self.filled;
        (done, 1 + robots + 1 + budget + pairs)
    }
}

/// Whether the pair budget applies: more robots than are checked in full.
fn budget_applies(robots: usize, config: &MergeConfig) -> bool {
    robots > config.pair_budget.all_pairs_up_to
}

/// One step of the proposals; true once every pair's to-do list is
/// filled (and, with many robots, its budget set). `robots`, `maps` and
/// `config` are the same on every call; `pairs` are the job's, `(a, b)`
/// with `a < b` in that order.
pub fn step(
    steps: &mut ProposalSteps,
    robots: &[RobotFrames],
    pairs: &mut [PairWork],
    maps: &[&OccupancyGrid],
    config: &MergeConfig,
) -> bool {
    let Some(bags) = &steps.bags else {
        train(steps, robots, maps, config);
        return false;
    };
    if let Some(budget) = steps.budget.as_mut() {
        if steps.plan.is_none() {
            // The step that computes the last overlap makes the plan.
            steps.plan = budget.step(bags, maps, &config.pair_budget);
            return false;
        }
    }
    let Some(p) = pairs.get_mut(steps.filled) else {
        return true;
    };
    fill(p, bags, steps.plan.as_deref(), config);
    steps.filled += 1;
    steps.filled == pairs.len()
}

/// One step of step 1: the tree, then one robot's words, then the bags.
fn train(
    steps: &mut ProposalSteps,
    robots: &[RobotFrames],
    maps: &[&OccupancyGrid],
    config: &MergeConfig,
) {
    let Some(training) = steps.training.as_mut() else {
        let sets: Vec<&Features> = robots.iter().flat_map(|r| r.features.iter()).collect();
        let seed = config.seed ^ 0x766f_6361;
        steps.training = Some(VocabularyTraining::new(&sets, &config.vocabulary, seed));
        steps.budget = budget_steps(robots, maps, config);
        return;
    };
    if let Some(r) = robots.get(steps.worded) {
        let sets: Vec<&Features> = r.features.iter().collect();
        training.add(&sets);
        steps.worded += 1;
        return;
    }
    let Some(training) = steps.training.take() else {
        return;
    };
    let mut bags = training.finish().1.into_iter();
    steps.bags = Some(
        robots
            .iter()
            .map(|r| bags.by_ref().take(r.features.len()).collect())
            .collect(),
    );
}

/// Step 2's state for a run with many robots: `k` partners a robot from
/// the robots and their mean frames; `None` (every pair in full) up to
/// `all_pairs_up_to` robots.
fn budget_steps(
    robots: &[RobotFrames],
    maps: &[&OccupancyGrid],
    config: &MergeConfig,
) -> Option<BudgetSteps> {
    let n = robots.len();
    if !budget_applies(n, config) || maps.len() != n {
        return None;
    }
    let frames: usize = robots.iter().map(|r| r.selected.len()).sum();
    Some(BudgetSteps::new(
        n,
        partners_per_robot(n, frames as f64 / n as f64),
    ))
}

/// Step 3 for one pair: its budget from the plan, and, if it is checked
/// in full, its to-do list.
fn fill(p: &mut PairWork, bags: &[Vec<Bag>], plan: Option<&[PairBudget]>, config: &MergeConfig) {
    // The plan lists pairs (a, b), a < b, in order: the index of (a, b).
    let n = bags.len();
    let index = p.a * n - p.a * (p.a + 1) / 2 + p.b - p.a - 1;
    p.budget = plan.and_then(|b| b.get(index)).copied();
    if p.budget.is_some_and(|b| b.plan != PairPlan::Full) {
        p.todo.clear();
        return;
    }
    let proposals = propose_pairs(
        &bags[p.a],
        &bags[p.b],
        config.proposals_per_frame,
        config.max_pairs,
    );
    p.todo = proposals.into_iter().map(|(i, j, _)| (i, j)).collect();
}
