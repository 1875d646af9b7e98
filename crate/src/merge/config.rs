//! # The settings of a merge
//!
//! One [`MergeConfig`] holds every setting of every stage of every method
//! (SURF, the thesis's selection, verification, the vocabulary, the
//! verdict, the map search, the baseline). [`MergeConfig::new`] gives the
//! defaults the page and the command line use.

use super::baseline::BaselineConfig;
use super::mapsearch::MapSearchConfig;
use super::pairbudget::PairBudgetConfig;
use super::selection::SelectionConfig;
use super::verdict::VerdictConfig;
use super::verify::VerifyConfig;
use super::vocabulary::VocabularyConfig;
use super::MergeMethod;
use crate::slam::MapperKind;
use crate::surf::SurfConfig;

/// Every setting of a merge. `MergeConfig::new(method)` gives the defaults.
#[derive(Clone, Debug)]
pub struct MergeConfig {
    pub method: MergeMethod,
    /// SURF on the robots' frames (upright by default).
    pub surf: SurfConfig,
    pub selection: SelectionConfig,
    pub verify: VerifyConfig,
    pub vocabulary: VocabularyConfig,
    /// At most this many keypoints per frame, the strongest (det H) kept:
    /// description and matching cost grow with the count, and the weakest
    /// blobs are the least repeatable.
    pub max_keypoints: usize,
    /// Automatic method: a frame takes part only if no earlier frame that
    /// does was taken within `min_motion_m` of it facing within
    /// `min_turn_rad` (consecutive views 0.3 m apart show nearly the same,
    /// and so do two passes of one corridor).
    pub min_motion_m: f64,
    pub min_turn_rad: f64,
    /// Automatic method: frames of the other robot proposed per frame.
    pub proposals_per_frame: usize,
    /// Automatic method: at most this many pairs verified per robot pair.
    pub max_pairs: usize,
    /// Automatic method with many robots: which robot pairs are checked
    /// ([`super::pairbudget`]).
    pub pair_budget: PairBudgetConfig,
    pub verdict: VerdictConfig,
    /// Automatic method: when vision finds no transform the maps confirm,
    /// search the maps alone ([`super::mapsearch`]); `None` turns that off.
    pub map_search: Option<MapSearchConfig>,
    pub baseline: BaselineConfig,
    /// Which map each robot contributes (SLAM by default).
    pub mapper: MapperKind,
    /// Seed of every random choice (MSAC samples, k-means seeding).
    pub seed: u64,
}

impl MergeConfig {
    pub fn new(method: MergeMethod, seed: u64) -> MergeConfig {
        MergeConfig {
            method,
            // Three octaves: the fourth's filters (up to 195 px) hardly fit
            // a 240-pixel-high frame.
            surf: SurfConfig {
                upright: true,
                octaves: 3,
                ..SurfConfig::default()
            },
            selection: SelectionConfig::default(),
            max_keypoints: 160,
            min_motion_m: 0.5,
            min_turn_rad: 15f64.to_radians(),
            verify: VerifyConfig::default(),
            vocabulary: VocabularyConfig::default(),
            proposals_per_frame: 3,
            max_pairs: 600,
            pair_budget: PairBudgetConfig::default(),
            verdict: VerdictConfig::default(),
            map_search: Some(MapSearchConfig::default()),
            baseline: BaselineConfig::default(),
            mapper: MapperKind::Slam,
            seed,
        }
    }
}
