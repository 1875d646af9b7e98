//! # The decision stage, a pair at a time
//!
//! Stage 5 of the job decides every pair of robots. With many robots on a
//! long run that is most of the merge (the sixteen-robot hour: 38 map
//! searches on 60 m maps, about 30 s in wasm), and done in one call it
//! held the page's main thread for all of it. [`Deciding`] keeps the
//! stage's state between calls, so [`MergeJob::advance`] can do it a unit
//! at a time, like the features and matching before it:
//!
//! 1. **Verdicts.** A pair of robots at a time: the method's decision on
//!    its frames a step a unit ([`VerdictSteps`]: the rival transforms its
//!    frames propose, then each judged against the maps; without a pair
//!    budget the map search follows in the last step); under a budget
//!    ([`crate::merge::pairbudget`]), pairs left unmatched get their "not
//!    checked" outcome in one unit.
//! 2. **Searches** (budget only). The pairs that are not merged, not torn
//!    between two transforms and ranked for it by coarse map overlap are
//!    searched by the maps alone, likeliest first; a pair whose robots
//!    merged pairs have already joined is skipped. One unit per step of a
//!    search ([`MapSearchSteps`]: each map's wall spectrum, the start, each
//!    rotation's translation search in pieces, each hypothesis refined,
//!    then judged), so
//!    that no call holds a whole search. A map's spectrum is computed
//!    once and kept for its later searches.
//!
//! Units are taken in the order one call would take them, and each reads
//! only what the units before it wrote, so the outcome is the same however
//! the stage is cut into calls (the golden reports check this: the command
//! line advances 64 units at a time, the page 2).

use super::{MergeJob, MergeStatus, PairOutcome};
use crate::merge::frames::MergeInput;
use crate::merge::mapsearch::{MapSearchSteps, WallSpectrum};
use crate::merge::pairbudget::{BudgetSummary, Components, PairPlan};
use crate::merge::verdict::VerdictSteps;

/// The decision stage between two calls.
pub(super) struct Deciding {
    /// One outcome per pair decided so far (in pair order).
    outcomes: Vec<PairOutcome>,
    /// The next pair's decision under way, between its steps.
    judging: Option<VerdictSteps>,
    /// Budget only: the pairs to search by their maps, likeliest first
    /// (`None` until every pair has its verdict), and how many are done.
    searches: Option<Vec<usize>>,
    searched: usize,
    /// Budget only: the search under way, between its steps.
    searching: Option<MapSearchSteps>,
    /// Budget only: each robot's map's wall spectrum, once a search has
    /// computed it (a map is searched against several others).
    spectra: Vec<Option<WallSpectrum>>,
    /// Budget only: the groups the merged pairs make so far.
    joined: Components,
    summary: BudgetSummary,
}

impl Deciding {
    pub(super) fn new(robots: usize, pairs: usize) -> Deciding {
        Deciding {
            outcomes: Vec::with_capacity(pairs),
            judging: None,
            searches: None,
            searched: 0,
            searching: None,
            spectra: vec![None; robots],
            joined: Components::new(robots),
            summary: BudgetSummary {
                pairs,
                ..Default::default()
            },
        }
    }

    /// Units done and in all (the searches count once they are known).
    pub(super) fn progress(&self, pairs: usize) -> (usize, usize) {
        let searches = self.searches.as_ref().map_or(0, Vec::len);
        (self.outcomes.len() + self.searched, pairs + searches)
    }
}

impl MergeJob {
    /// Whether this run's pairs are under a pair budget.
    fn budgeted(&self) -> bool {
        self.pairs.iter().any(|p| p.budget.is_some())
    }

    /// Up to `units` units of the decision stage; returns how many were
    /// done. The stage is over when [`MergeJob::decision_finished`].
    pub(super) fn advance_decision(&mut self, input: &impl MergeInput, units: usize) -> usize {
        let mut d = self
            .deciding
            .take()
            .unwrap_or_else(|| Deciding::new(self.robots.len(), self.pairs.len()));
        let budgeted = self.budgeted();
        let mut done = 0;
        while done < units && d.outcomes.len() < self.pairs.len() {
            if let Some(o) = self.verdict_step(input, budgeted, &mut d) {
                d.outcomes.push(o);
            }
            done += 1;
        }
        if budgeted && d.outcomes.len() == self.pairs.len() {
            if d.searches.is_none() {
                d.searches = Some(self.search_order(&mut d));
            }
            while done < units && d.searched < d.searches.as_ref().map_or(0, Vec::len) {
                let k = d.searches.as_ref().map_or(0, |s| s[d.searched]);
                if self.search_pair(input, k, &mut d) {
                    d.searched += 1;
                }
                done += 1;
            }
        }
        self.deciding = Some(d);
        done
    }

    /// Whether every unit of the decision stage is done.
    pub(super) fn decision_finished(&self) -> bool {
        self.deciding.as_ref().is_some_and(|d| {
            d.outcomes.len() == self.pairs.len()
                && (!self.budgeted() || d.searches.as_ref().is_some_and(|s| d.searched == s.len()))
        })
    }

    /// Ends the stage: each pair's outcome, then the join.
    pub(super) fn finish_decision(&mut self) {
        let Some(mut d) = self.deciding.take() else {
            return;
        };
        let budget = self.budgeted().then(|| {
            d.summary.not_checked = d
                .outcomes
                .iter()
                .filter(|o| o.check == Some("none"))
                .count();
            d.summary.clone()
        });
        for (p, o) in self.pairs.iter_mut().zip(&d.outcomes) {
            p.outcome = Some(o.clone());
        }
        let mut outcome = self.join(d.outcomes);
        outcome.budget = budget;
        self.outcome = Some(outcome);
    }

    /// One unit of step 1 for the next pair: `None` until its outcome.
    fn verdict_step(
        &self,
        input: &impl MergeInput,
        budgeted: bool,
        d: &mut Deciding,
    ) -> Option<PairOutcome> {
        let p = &self.pairs[d.outcomes.len()];
        let b = p.budget.unwrap_or_default();
        if budgeted {
            d.summary.partners_per_robot = b.partners;
            if b.plan != PairPlan::Full {
                return Some(self.unmatched(p, &b));
            }
        }
        let steps = d.judging.get_or_insert_with(VerdictSteps::default);
        let mut o = self
            .method
            .decide_step(&self.pair_input(input, p, !budgeted), steps)?;
        d.judging = None;
        if budgeted {
            d.summary.matched += 1;
            o.check = Some("full");
        }
        Some(o)
    }

    /// Between steps 1 and 2: the groups the verdicts joined, and the
    /// pairs to search in rank order (the others' reasons say why not).
    fn search_order(&self, d: &mut Deciding) -> Vec<usize> {
        for (p, o) in self.pairs.iter().zip(&d.outcomes) {
            if o.status == MergeStatus::Merged {
                d.joined.join(p.a, p.b);
            }
        }
        let mut order: Vec<usize> = Vec::new();
        for (k, o) in d.outcomes.iter_mut().enumerate() {
            let b = self.pairs[k].budget.unwrap_or_default();
            let ambiguous = o.verdict.as_ref().is_some_and(|v| v.ambiguous);
            if o.status == MergeStatus::Merged || b.plan == PairPlan::NotChecked || ambiguous {
                continue;
            }
            if b.search {
                order.push(k);
            } else {
                o.reason = format!(
                    "{}; maps not searched: neither robot ranks the other among its {} likeliest partners by coarse map overlap ({:.2})",
                    o.reason, b.partners, b.overlap
                );
                o.check = Some("frames");
            }
        }
        order.sort_by_key(|&k| (self.pairs[k].budget.map_or(usize::MAX, |b| b.rank), k));
        order
    }

    /// One step of step 2 for pair `k`: skipped when its robots are
    /// already joined, else the next step of its map search. Returns
    /// whether the pair is done.
    fn search_pair(&self, input: &impl MergeInput, k: usize, d: &mut Deciding) -> bool {
        let p = &self.pairs[k];
        let o = &mut d.outcomes[k];
        if d.searching.is_none() && d.joined.same(p.a, p.b) {
            d.summary.searches_skipped += 1;
            o.reason = format!(
                "{}; maps not searched: {} and {} are already joined through merged pairs",
                o.reason, o.a, o.b
            );
            o.check = Some(if o.check == Some("full") {
                "frames"
            } else {
                "none"
            });
            return true;
        }
        if d.searching.is_none() {
            d.summary.maps_searched += 1;
        }
        let steps = d.searching.get_or_insert_with(|| {
            MapSearchSteps::with_spectra(d.spectra[p.a].clone(), d.spectra[p.b].clone())
        });
        let searched = self
            .method
            .search_step(&self.pair_input(input, p, true), o, steps);
        for (robot, spectrum) in [p.a, p.b].into_iter().zip(steps.spectra()) {
            if d.spectra[robot].is_none() {
                d.spectra[robot] = spectrum.cloned();
            }
        }
        let Some(searched) = searched else {
            return false;
        };
        *o = searched;
        d.searching = None;
        if o.status == MergeStatus::Merged {
            d.joined.join(p.a, p.b);
        }
        true
    }
}
