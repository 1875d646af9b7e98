//! # The map search, a step at a time
//!
//! On two 80 m maps one search takes about a second natively (the
//! sixteen-robot hour: 0.8–1.5 s), most of it the translation search of
//! the four rotations. The merge job advances in small units so that the
//! page can draw between them ([`crate::merge::job`]); a whole search in
//! one unit held the page's thread for up to 3 s. [`MapSearchSteps`] is
//! the search of [`super::search_maps`] cut at its natural seams, keeping
//! what it found between calls:
//!
//! 1. the rotation from the wall directions, and map A drawn unturned;
//! 2. each of the four rotations: map B turned, its best translations;
//! 3. each hypothesis refined and judged, strongest first;
//! 4. the decision (with the last judgement).
//!
//! [`super::search_maps`] is this, stepped to the end in one call, so the
//! answer cannot depend on how the steps are spread over calls.

use super::{
    coarse_ranked, coarse_rotation, coarse_start, decide, judge, wall_centroid, MapHypothesis,
    MapSearch, MapSearchConfig, Raster, TranslationSearch,
};
use crate::geom::Pose2;
use crate::merge::peaksearch::MaxPyramid;
use crate::merge::verdict::VerdictConfig;
use crate::slam::OccupancyGrid;

/// A map search between two steps; [`MapSearchSteps::step`] takes the
/// next one. Made fresh for each pair of maps.
#[derive(Default)]
pub struct MapSearchSteps {
    phase: Phase,
}

#[derive(Default)]
enum Phase {
    #[default]
    Start,
    /// Rotation `k` is next; `coarse` holds the earlier rotations' peaks.
    Peaks {
        delta: f64,
        ra: Raster,
        a_max: Option<Option<MaxPyramid>>,
        k: usize,
        coarse: Vec<(Pose2, i64)>,
    },
    /// The ranked peaks, and the hypotheses judged so far.
    Judge {
        delta: f64,
        coarse: Vec<(Pose2, i64)>,
        hypotheses: Vec<MapHypothesis>,
    },
    Finished,
}

impl MapSearchSteps {
    /// Takes the next step of searching map A (`a`) for map B (`b`);
    /// returns the search's answer after its last step, `None` before.
    /// Every call of one search must pass the same maps and settings.
    /// After the answer, further calls answer that it is over.
    pub fn step(
        &mut self,
        a: &OccupancyGrid,
        b: &OccupancyGrid,
        cfg: &MapSearchConfig,
        verdict: &VerdictConfig,
    ) -> Option<MapSearch> {
        match std::mem::take(&mut self.phase) {
            Phase::Start => match coarse_start(a, b, cfg) {
                Err(reason) => self.finish(MapSearch::refuse(reason)),
                Ok((delta, ra)) => {
                    self.phase = Phase::Peaks {
                        delta,
                        ra,
                        a_max: None,
                        k: 0,
                        coarse: Vec::new(),
                    };
                    None
                }
            },
            Phase::Peaks {
                delta,
                ra,
                mut a_max,
                k,
                mut coarse,
            } => {
                let how = TranslationSearch::BranchAndBound;
                match coarse_rotation(a, &ra, &mut a_max, b, delta, k, cfg, how) {
                    Err(reason) => self.finish(MapSearch::refuse(reason)),
                    Ok(found) => {
                        coarse.extend(found);
                        self.phase = if k + 1 < 4 {
                            Phase::Peaks {
                                delta,
                                ra,
                                a_max,
                                k: k + 1,
                                coarse,
                            }
                        } else {
                            Phase::Judge {
                                delta,
                                coarse: coarse_ranked(coarse, cfg),
                                hypotheses: Vec::new(),
                            }
                        };
                        None
                    }
                }
            }
            Phase::Judge {
                delta,
                coarse,
                mut hypotheses,
            } => {
                if let Some(&(pose, score)) = coarse.get(hypotheses.len()) {
                    hypotheses.push(judge(a, b, pose, score, cfg, verdict));
                }
                if hypotheses.len() < coarse.len() {
                    self.phase = Phase::Judge {
                        delta,
                        coarse,
                        hypotheses,
                    };
                    return None;
                }
                self.finish(decide(hypotheses, wall_centroid(b), delta, cfg))
            }
            Phase::Finished => self.finish(MapSearch::refuse(
                "maps alone: this search has already answered".into(),
            )),
        }
    }

    fn finish(&mut self, found: MapSearch) -> Option<MapSearch> {
        self.phase = Phase::Finished;
        Some(found)
    }
}
