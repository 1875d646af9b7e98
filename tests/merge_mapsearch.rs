//! The map search's branch-and-bound translation search
//! (`crate/src/merge/peaksearch.rs`) against the exhaustive correlation it
//! replaces, on the SLAM maps of simulated mazes of three sizes: the peaks
//! of all four rotations must be identical (same translations, same
//! scores, same order, bit-identical poses), and so the whole search's
//! answer.

use slamlab::maze::{random_maze, MazeSpec};
use slamlab::merge::mapsearch::{coarse_peaks, search_maps, MapSearchConfig, TranslationSearch};
use slamlab::merge::verdict::VerdictConfig;
use slamlab::scenario::Scenario;
use slamlab::sim::Simulation;
use slamlab::slam::{MapperKind, OccupancyGrid};
use wasm_bindgen_test::wasm_bindgen_test;

fn maze_maps(
    nx: usize,
    ny: usize,
    robots: usize,
    seed: u64,
    duration_s: f64,
) -> Vec<OccupancyGrid> {
    let spec = MazeSpec {
        nx,
        ny,
        seed,
        robots,
        duration_s,
        ..MazeSpec::default()
    };
    let scenario = Scenario::from_json(&random_maze(&spec)).expect("a maze scenario");
    let mut sim = Simulation::new(&scenario).expect("scenario runs");
    sim.run_to_end();
    sim.robots
        .iter()
        .map(|r| r.mapping.map(MapperKind::Slam).clone())
        .collect()
}

/// The large maze's maps, simulated once for both tests.
fn large_maze() -> &'static [OccupancyGrid] {
    static MAPS: std::sync::OnceLock<Vec<OccupancyGrid>> = std::sync::OnceLock::new();
    MAPS.get_or_init(|| maze_maps(14, 12, 2, 11, 600.0))
}

/// Both searches on every ordered pair of `maps`; returns how many peaks
/// were compared.
fn assert_same_peaks(maps: &[OccupancyGrid], cfg: &MapSearchConfig) -> usize {
    let mut compared = 0;
    for (i, a) in maps.iter().enumerate() {
        for (j, b) in maps.iter().enumerate() {
            if i == j {
                continue;
            }
            let full = coarse_peaks(a, b, cfg, TranslationSearch::Exhaustive);
            let fast = coarse_peaks(a, b, cfg, TranslationSearch::BranchAndBound);
            assert_eq!(full, fast, "maps {i} and {j}");
            let (_, peaks) = full.expect("the maps have walls");
            // Bit-identical poses, not merely equal within rounding.
            let bits = |p: &[(slamlab::geom::Pose2, i64)]| {
                p.iter()
                    .map(|(q, s)| (q.x.to_bits(), q.y.to_bits(), q.theta.to_bits(), *s))
                    .collect::<Vec<_>>()
            };
            let (_, again) = fast.expect("same");
            assert_eq!(bits(&peaks), bits(&again));
            compared += peaks.len();
        }
    }
    compared
}

#[wasm_bindgen_test(unsupported = test)]
fn branch_and_bound_finds_the_exhaustive_peaks_on_maze_maps_of_three_sizes() {
    let cfg = MapSearchConfig::default();
    // 12.5 × 10 m, 20 × 15 m and 35 × 30 m mazes (2.5 m cells).
    let small = maze_maps(5, 4, 2, 3, 120.0);
    let middle = maze_maps(8, 6, 3, 7, 300.0);
    let mut compared = 0;
    for maps in [&small[..], &middle[..], large_maze()] {
        compared += assert_same_peaks(maps, &cfg);
    }
    // 2 + 6 + 2 ordered pairs, up to 12 peaks each: most pairs fill them.
    assert!(compared >= 60, "only {compared} peaks compared");
    // Other settings: more peaks further apart, and a harsher free-space
    // penalty (more negative cells under the bounds).
    let other = MapSearchConfig {
        peaks_per_rotation: 9,
        max_hypotheses: 30,
        distinct_m: 2.3,
        free_penalty: 7,
        ..cfg
    };
    assert!(assert_same_peaks(&middle, &other) > 60);
    // A penalty beyond a byte falls back to the exhaustive search: still
    // the same answer.
    let huge = MapSearchConfig {
        free_penalty: 1000,
        ..cfg
    };
    assert_same_peaks(&small, &huge);
}

#[wasm_bindgen_test(unsupported = test)]
fn the_whole_search_is_unchanged_on_a_large_maze() {
    // search_maps uses the branch and bound; its hypotheses come from the
    // peaks above, so the same peaks give the same answer. Here the answer
    // itself: every hypothesis judged from the exhaustive peaks.
    let maps = large_maze();
    let (cfg, verdict) = (MapSearchConfig::default(), VerdictConfig::default());
    let found = search_maps(&maps[0], &maps[1], &cfg, &verdict);
    let (_, full) = coarse_peaks(&maps[0], &maps[1], &cfg, TranslationSearch::Exhaustive)
        .expect("the maps have walls");
    let coarse: Vec<_> = found
        .hypotheses
        .iter()
        .map(|h| (h.coarse, h.coarse_score))
        .collect();
    assert_eq!(coarse, full);
    assert!(!coarse.is_empty());
}
