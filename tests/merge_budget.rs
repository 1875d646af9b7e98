//! The pair budget of a merge with many robots (`merge::pairbudget`): the
//! visual votes, the partners kept per robot, each pair's plan and the
//! union-find of the early exit, on hand-made figures whose answers are
//! worked out in the comments.

use slamlab::merge::pairbudget::{
    partners_per_robot, plan_pairs, visual_votes, Components, PairPlan,
};
use slamlab::merge::vocabulary::Bag;
use wasm_bindgen_test::wasm_bindgen_test;

fn bag(words: &[(u32, f32)]) -> Bag {
    Bag {
        words: words.to_vec(),
    }
}

#[wasm_bindgen_test(unsupported = test)]
fn each_frame_votes_for_the_robots_holding_its_most_similar_frames() {
    // Robot 0: frames A0 = {1}, A1 = {2}; robot 1: B0 = {1}, B1 = {2: 0.6,
    // 3: 0.8}; robot 2: C0 = {3}, C1 = {4}.
    let bags = vec![
        vec![bag(&[(1, 1.0)]), bag(&[(2, 1.0)])],
        vec![bag(&[(1, 1.0)]), bag(&[(2, 0.6), (3, 0.8)])],
        vec![bag(&[(3, 1.0)]), bag(&[(4, 1.0)])],
    ];
    // One vote a frame: A0 → B0 (1.0), A1 → B1 (0.6), B0 → A0 (1.0),
    // B1 → C0 (0.8 beats A1's 0.6), C0 → B1 (0.8), C1 shares no word.
    // A pair's figure: the share of each robot's two frames that voted for
    // the other, added: 0–1: 2/2 + 1/2; 1–2: 1/2 + 1/2; 0–2: nothing.
    let v = visual_votes(&bags, 1);
    let want = [[0.0, 1.5, 0.0], [1.5, 0.0, 1.0], [0.0, 1.0, 0.0]];
    for a in 0..3 {
        for b in 0..3 {
            assert!(
                (v[a][b] - want[a][b]).abs() < 1e-12,
                "{a}-{b}: {} (want {})",
                v[a][b],
                want[a][b]
            );
        }
    }
    // Two votes a frame: B1 also votes for A1, so 0–1 gets 2/2 + 2/2.
    let v = visual_votes(&bags, 2);
    assert!((v[0][1] - 2.0).abs() < 1e-12, "{}", v[0][1]);
    assert!((v[1][2] - 1.0).abs() < 1e-12, "{}", v[1][2]);
    assert_eq!(v[0][2], 0.0);
    // A frame never votes for its own robot, whatever it shares with it.
    let alone = vec![
        vec![bag(&[(1, 1.0)]), bag(&[(1, 1.0)])],
        vec![bag(&[(9, 1.0)])],
    ];
    assert_eq!(
        visual_votes(&alone, 3),
        vec![vec![0.0, 0.0], vec![0.0, 0.0]]
    );
}

#[wasm_bindgen_test(unsupported = test)]
fn partners_kept_grow_with_the_log_of_robots_and_of_run_length() {
    // k = ⌈log₂ n + ½ log₂(1 + F / 100)⌉, at least 1, at most n − 1.
    assert_eq!(partners_per_robot(16, 150.0), 5); // 4 + 0.66
    assert_eq!(partners_per_robot(8, 150.0), 4); // 3 + 0.66
    assert_eq!(partners_per_robot(16, 1800.0), 7); // 4 + 2.12
    assert_eq!(partners_per_robot(5, 0.0), 3); // 2.32
    assert_eq!(partners_per_robot(2, 1e6), 1); // only one other robot
    assert_eq!(partners_per_robot(1, 100.0), 1);
}

#[wasm_bindgen_test(unsupported = test)]
fn a_pair_is_matched_by_its_votes_searched_by_its_maps_or_not_checked() {
    // Five robots, symmetric figures.
    let mut votes = vec![vec![0.0; 5]; 5];
    let mut maps = vec![vec![0.0; 5]; 5];
    for (a, b, v) in [(0, 1, 0.9), (2, 3, 0.8), (1, 2, 0.1)] {
        votes[a][b] = v;
        votes[b][a] = v;
    }
    for (a, b, m) in [(3, 4, 0.7), (0, 4, 0.2), (1, 4, 0.3)] {
        maps[a][b] = m;
        maps[b][a] = m;
    }
    // By votes: 0: [1]; 1: [0, 2]; 2: [3, 1]; 3: [2]; 4: []. By maps:
    // 0: [4]; 1: [4]; 3: [4]; 4: [3, 1, 0]. With one partner each:
    let plans = plan_pairs(&votes, &maps, 1);
    let order = [
        (0, 1),
        (0, 2),
        (0, 3),
        (0, 4),
        (1, 2),
        (1, 3),
        (1, 4),
        (2, 3),
        (2, 4),
        (3, 4),
    ];
    assert_eq!(plans.len(), order.len());
    let want = [
        (PairPlan::Full, 0),                // 0-1: each other's first by votes
        (PairPlan::NotChecked, usize::MAX), // 0-2: no evidence
        (PairPlan::NotChecked, usize::MAX),
        (PairPlan::MapsOnly, 0),   // 0-4: 4 is 0's first by maps
        (PairPlan::NotChecked, 1), // 1-2: second in both vote lists
        (PairPlan::NotChecked, usize::MAX),
        (PairPlan::MapsOnly, 0), // 1-4: 4 is 1's first by maps
        (PairPlan::Full, 0),     // 2-3
        (PairPlan::NotChecked, usize::MAX),
        (PairPlan::MapsOnly, 0), // 3-4
    ];
    for ((p, w), (a, b)) in plans.iter().zip(want).zip(order) {
        assert_eq!((p.plan, p.rank), w, "pair {a}-{b}");
        assert_eq!(p.partners, 1);
        // The maps are searched where they rank the pair.
        assert_eq!(p.search, p.plan == PairPlan::MapsOnly, "pair {a}-{b}");
        assert_eq!((p.votes, p.overlap), (votes[a][b], maps[a][b]));
    }
    // With two partners each, 1-2 is matched (second in both lists) and
    // 1-4 stays a map search (1 is 4's second by maps, 4 is 1's first).
    let plans = plan_pairs(&votes, &maps, 2);
    assert_eq!(plans[4].plan, PairPlan::Full);
    assert_eq!(plans[6].plan, PairPlan::MapsOnly);
    assert_eq!(plans[1].plan, PairPlan::NotChecked);
    // 0-1 is matched and, 4 being 0's only partner by maps, not searched.
    assert_eq!((plans[0].plan, plans[0].search), (PairPlan::Full, false));
    assert!(plans[3].search && plans[6].search && plans[9].search);
}

#[wasm_bindgen_test(unsupported = test)]
fn components_join_transitively() {
    let mut c = Components::new(6);
    assert!(!c.same(0, 1));
    c.join(3, 1);
    c.join(4, 5);
    assert!(c.same(1, 3));
    assert!(!c.same(1, 4));
    c.join(5, 3);
    assert!(c.same(1, 4), "1-3, 3-5, 5-4: one group");
    assert!(!c.same(0, 2));
    assert!(c.same(2, 2));
}
