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
//! 1. each map's wall directions (its Hough spectrum, [`WallSpectrum`]:
//!    tens of milliseconds on a 60 m map, so each is a step, and a caller
//!    that searches one map many times passes it in,
//!    [`MapSearchSteps::with_spectra`]), then the rotation between them and
//!    map A drawn unturned;
//! 2. each of the four rotations: map B turned and its translation search
//!    begun, then that search ([`PeakSearch`]) in pieces of
//!    [`WORK_PER_STEP`] pyramid lookups (a whole rotation on 60 m maps is
//!    up to half a second in the page);
//! 3. each hypothesis refined (a step), then judged (a step), strongest
//!    first;
//! 4. the decision (with the last judgement).
//!
//! [`super::search_maps`] is this, stepped to the end in one call, so the
//! answer cannot depend on how the steps are spread over calls.

use super::{
    coarse_ranked, coarse_start, correlate, decide, judge_refined, refine, translation_origin,
    wall_centroid, MapHypothesis, MapSearch, MapSearchConfig, Raster, TranslationSearch,
    WallSpectrum,
};
use crate::geom::{wrap_angle, Pose2};
use crate::merge::peaksearch::{pyramid_of, MaxPyramid, PeakSearch};
use crate::merge::verdict::VerdictConfig;
use crate::slam::OccupancyGrid;
use std::f64::consts::FRAC_PI_2;

/// Pyramid lookups of one step of a rotation's translation search: about
/// 10–20 ms natively, 15–30 ms in the page.
pub const WORK_PER_STEP: u64 = 1 << 24;

/// A map search between two steps; [`MapSearchSteps::step`] takes the
/// next one. Made fresh for each pair of maps.
#[derive(Default)]
pub struct MapSearchSteps {
    phase: Phase,
    /// Map A's and map B's spectra, given or computed in step 1.
    spectra: [Option<WallSpectrum>; 2],
}

#[derive(Default)]
enum Phase {
    #[default]
    Start,
    /// Rotation `k` is under way (`rotation`) or next; `coarse` holds the
    /// earlier rotations' peaks.
    Peaks {
        delta: f64,
        ra: Box<Raster>,
        a_max: Option<Option<MaxPyramid>>,
        k: usize,
        rotation: Option<RotationSearch>,
        coarse: Vec<(Pose2, i64)>,
    },
    /// The ranked peaks, the hypotheses judged so far, and the next one's
    /// refined pose once refined.
    Judge {
        delta: f64,
        coarse: Vec<(Pose2, i64)>,
        hypotheses: Vec<MapHypothesis>,
        refined: Option<Option<Pose2>>,
    },
    Finished,
}

impl MapSearchSteps {
    /// A search given the maps' spectra where they are known (computed
    /// for an earlier search of the same map: [`MapSearchSteps::spectra`]).
    pub fn with_spectra(a: Option<WallSpectrum>, b: Option<WallSpectrum>) -> MapSearchSteps {
        MapSearchSteps {
            phase: Phase::Start,
            spectra: [a, b],
        }
    }

    /// Map A's and map B's spectra, once the search has them.
    pub fn spectra(&self) -> [Option<&WallSpectrum>; 2] {
        [self.spectra[0].as_ref(), self.spectra[1].as_ref()]
    }

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
            Phase::Start => {
                // Step 1: a spectrum a step, then the rotation and A's raster.
                for (i, map) in [a, b].into_iter().enumerate() {
                    if self.spectra[i].is_none() {
                        self.spectra[i] = Some(WallSpectrum::of(map));
                        return None;
                    }
                }
                self.start(a, cfg)
            }
            Phase::Peaks {
                delta,
                ra,
                mut a_max,
                k,
                rotation,
                mut coarse,
            } => {
                let mut rotation = match rotation {
                    Some(r) => r,
                    None => {
                        let how = TranslationSearch::BranchAndBound;
                        match RotationSearch::start(a, &ra, &mut a_max, b, delta, k, cfg, how) {
                            Err(reason) => return self.finish(MapSearch::refuse(reason)),
                            Ok(r) => {
                                self.phase = Phase::Peaks {
                                    delta,
                                    ra,
                                    a_max,
                                    k,
                                    rotation: Some(r),
                                    coarse,
                                };
                                return None;
                            }
                        }
                    }
                };
                let Some(found) = rotation.run(&mut a_max, WORK_PER_STEP) else {
                    self.phase = Phase::Peaks {
                        delta,
                        ra,
                        a_max,
                        k,
                        rotation: Some(rotation),
                        coarse,
                    };
                    return None;
                };
                coarse.extend(found);
                self.phase = if k + 1 < 4 {
                    Phase::Peaks {
                        delta,
                        ra,
                        a_max,
                        k: k + 1,
                        rotation: None,
                        coarse,
                    }
                } else {
                    Phase::Judge {
                        delta,
                        coarse: coarse_ranked(coarse, cfg),
                        hypotheses: Vec::new(),
                        refined: None,
                    }
                };
                None
            }
            Phase::Judge {
                delta,
                coarse,
                mut hypotheses,
                refined,
            } => {
                // Each hypothesis in two steps: refined, then judged.
                if let Some(&peak) = coarse.get(hypotheses.len()) {
                    let refined = match refined {
                        None => Some(refine(a, b, peak.0, verdict)),
                        Some(pose) => {
                            hypotheses.push(judge_refined(a, b, peak, pose, cfg, verdict));
                            None
                        }
                    };
                    if refined.is_some() || hypotheses.len() < coarse.len() {
                        self.phase = Phase::Judge {
                            delta,
                            coarse,
                            hypotheses,
                            refined,
                        };
                        return None;
                    }
                }
                self.finish(decide(hypotheses, wall_centroid(b), delta, cfg))
            }
            Phase::Finished => self.finish(MapSearch::refuse(
                "maps alone: this search has already answered".into(),
            )),
        }
    }

    /// The end of step 1: the rotation from the two spectra, and A's raster.
    fn start(&mut self, a: &OccupancyGrid, cfg: &MapSearchConfig) -> Option<MapSearch> {
        let [Some(sa), Some(sb)] = &self.spectra else {
            // Both are computed before this is called.
            return self.finish(MapSearch::refuse("maps alone: no wall directions".into()));
        };
        match coarse_start(a, sa, sb, cfg) {
            Err(reason) => self.finish(MapSearch::refuse(reason)),
            Ok((delta, ra)) => {
                self.phase = Phase::Peaks {
                    delta,
                    ra: Box::new(ra),
                    a_max: None,
                    k: 0,
                    rotation: None,
                    coarse: Vec::new(),
                };
                None
            }
        }
    }

    fn finish(&mut self, found: MapSearch) -> Option<MapSearch> {
        self.phase = Phase::Finished;
        Some(found)
    }
}

/// Step 2 of the search for one rotation, resumable: map B turned and its
/// best translations over A's raster being found ([`PeakSearch`], which
/// holds A's pyramid while it runs), or found.
pub(super) enum RotationSearch {
    Searching {
        search: Box<PeakSearch>,
        a_max: MaxPyramid,
        t0: [i64; 2],
        theta: f64,
        cell: f64,
    },
    Found(Vec<(Pose2, i64)>),
}

impl RotationSearch {
    /// B turned by `delta + k·90°` (rotation `k` of four) and its search
    /// over A's raster `ra` begun. `a_max` is A's pyramid, built at the
    /// first rotation and kept (`Some(None)` when A's scores do not fit a
    /// byte): a running search holds it and gives it back when done. The
    /// exhaustive correlation is the search when asked for, and when a
    /// map's scores do not fit the pyramids' bytes.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn start(
        a: &OccupancyGrid,
        ra: &Raster,
        a_max: &mut Option<Option<MaxPyramid>>,
        b: &OccupancyGrid,
        delta: f64,
        k: usize,
        cfg: &MapSearchConfig,
        how: TranslationSearch,
    ) -> Result<RotationSearch, String> {
        let cell = cfg.cell_m.max(a.resolution_m());
        let apart = cfg.distinct_m / cell;
        let theta = wrap_angle(delta + k as f64 * FRAC_PI_2);
        let Some(rb) = Raster::draw(b, theta, cell, cfg.free_penalty) else {
            return Err("maps alone: a map is empty".into());
        };
        if how == TranslationSearch::BranchAndBound {
            let slot = a_max.get_or_insert_with(|| pyramid_of(&ra.image()));
            if let Some(mut m) = slot.take() {
                let count = cfg.peaks_per_rotation;
                match PeakSearch::new(ra.image(), &mut m, rb.image(), count, apart) {
                    Some(search) => {
                        return Ok(RotationSearch::Searching {
                            search: Box::new(search),
                            a_max: m,
                            t0: translation_origin(ra, &rb),
                            theta,
                            cell,
                        })
                    }
                    None => *slot = Some(m),
                }
            }
        }
        let peaks = correlate(ra, &rb).peaks(cfg.peaks_per_rotation, apart);
        Ok(RotationSearch::Found(poses(peaks, [0, 0], theta, cell)))
    }

    /// About `work` more pyramid lookups of the search; its peaks (B's
    /// frame in A's, to a coarse cell, with its score) once found, when A's
    /// pyramid is back in `a_max`.
    pub(super) fn run(
        &mut self,
        a_max: &mut Option<Option<MaxPyramid>>,
        work: u64,
    ) -> Option<Vec<(Pose2, i64)>> {
        match self {
            RotationSearch::Found(found) => Some(std::mem::take(found)),
            RotationSearch::Searching {
                search,
                a_max: m,
                t0,
                theta,
                cell,
            } => {
                let found = poses(search.run(m, work)?, *t0, *theta, *cell);
                // A's pyramid goes back to the caller for the next rotation.
                *a_max = Some(Some(std::mem::take(m)));
                *self = RotationSearch::Found(Vec::new());
                Some(found)
            }
        }
    }

    /// [`RotationSearch::run`] to the end.
    pub(super) fn run_to_end(
        &mut self,
        a_max: &mut Option<Option<MaxPyramid>>,
    ) -> Vec<(Pose2, i64)> {
        self.run(a_max, u64::MAX).unwrap_or_default()
    }
}

/// Translation indices (plus `t0`, the correlation's offset) as poses of
/// B's frame in A's.
fn poses(peaks: Vec<([i64; 2], i32)>, t0: [i64; 2], theta: f64, cell: f64) -> Vec<(Pose2, i64)> {
    peaks
        .into_iter()
        .map(|(t, score)| {
            let (x, y) = ((t[0] + t0[0]) as f64, (t[1] + t0[1]) as f64);
            (Pose2::new(x * cell, y * cell, theta), score as i64)
        })
        .collect()
}
