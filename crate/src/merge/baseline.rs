//! # The map-only baseline: merging grids as images, as existing tools do
//!
//! Before asking what the cameras add, ask what the maps alone can do.
//! The widely used ROS package `multirobot_map_merge` (J. Hörner, *Map-merging
//! for multi-robot system*, Charles University 2016) treats each occupancy
//! grid as a grey image and stitches the images the way panorama software
//! does (Brown and Lowe, *Automatic panoramic image stitching using
//! invariant features*, IJCV 74 (2007) 59-73):
//!
//! 1. **Render** each grid as an image: occupied cells dark (0), free cells
//!    light (255), unknown mid-grey (128), one pixel per cell. Image rows go
//!    *down* while the map's y goes *up*, so row `r` of an image `H` rows
//!    tall holds cell row `H − 1 − r`. The image is cropped to the cells
//!    that are known, plus a margin, which changes no feature and saves
//!    work.
//! 2. **Features** on both images: SURF *with* orientation, since one map
//!    may be turned by any angle relative to the other (the ROS tool offers
//!    ORB, AKAZE and SURF; we have SURF).
//! 3. **Matching** by nearest neighbours and Lowe's ratio test (0.7, the
//!    `match_conf = 0.3` of OpenCV's best-of-two-nearest matcher the tool
//!    uses).
//! 4. **A robust similarity** (rotation, uniform scale, shift: OpenCV's
//!    "affine partial" model) by MSAC with a 3-pixel threshold.
//! 5. **Acceptance** by Brown and Lowe's verification, as OpenCV computes
//!    it and the ROS tool thresholds it: with `n_f` matches and `n_i`
//!    inliers, `confidence = n_i / (8 + 0.3 · n_f)`, and the pair is merged
//!    when the confidence reaches `estimation_confidence` (default 1.0).
//!    OpenCV also zeroes a confidence above 3 ("the same image twice");
//!    that rule exists for stitching photographs and would reject two
//!    robots' maps of the same rooms for agreeing too well, so it is left
//!    out.
//!
//! We then need a rigid pose in metres, not a similarity in pixels. The
//! similarity's scale must be about 1 (both grids have the same cell size;
//! a scale far from 1 means the fit locked onto something else, and we say
//! so), and the pose is the least-squares rigid transform through the
//! inlier correspondences, converted to metres: with `F = diag(1, −1)` the
//! row flip, a pixel `p` of a crop whose bottom-left cell is `(i₀, j₀)` is
//! the map point `origin + r · ((i₀, j₀ + H) + ½·(1, −1) + F p)`.
//!
//! This is a baseline: it is implemented as those tools do it, neither
//! tuned to win nor hobbled to lose. Its weakness is plain: walls look
//! alike, and a grid image has few distinctive places (corners, door
//! jambs), so two maps of rooms that differ only in their texture — which
//! is what the cameras see — are easily confused.
//!
//! Conventions: metres and radians; map frames x right, y up; pixels as in
//! [`crate::surf`] (x right, y down, (0, 0) the centre of the top-left pixel).

use super::MergeStatus;
use crate::geom::{wrap_angle, Pose2};
use crate::slam::{CellState, OccupancyGrid};
use crate::surf::{
    extract, fit_similarity, match_features, GrayImage, MatchConfig, MsacConfig, SurfConfig,
};
use glam::DVec2;

/// Grey level of an occupied cell.
pub const OCCUPIED_GREY: u8 = 0;
/// Grey level of a free cell.
pub const FREE_GREY: u8 = 255;
/// Grey level of a cell never seen (or undecided).
pub const UNKNOWN_GREY: u8 = 128;

/// Settings of the map-only baseline.
#[derive(Clone, Debug, PartialEq)]
pub struct BaselineConfig {
    /// SURF on the grid images: with orientation (maps turn), sampling
    /// every pixel in the first octave as OpenCV does (`initial_step` 1:
    /// walls are one or two cells thick), threshold 10 as everywhere in the
    /// lab.
    pub surf: SurfConfig,
    /// Ratio 0.7 (OpenCV's `match_conf` 0.3), Laplacian gating on.
    pub matching: MatchConfig,
    /// MSAC inlier threshold, pixels (cells). Default 3.0, OpenCV's.
    pub msac_threshold_px: f64,
    /// Merge when `inliers / (8 + 0.3 · matches)` reaches this. Default
    /// 1.0, the ROS tool's `estimation_confidence`.
    pub min_confidence: f64,
    /// The similarity's scale may differ from 1 by at most this. Default 0.1.
    pub max_scale_error: f64,
    /// Unknown cells kept around the known ones when cropping. Default 16.
    pub crop_margin_cells: usize,
}

impl Default for BaselineConfig {
    fn default() -> Self {
        BaselineConfig {
            surf: SurfConfig {
                initial_step: 1,
                ..SurfConfig::default()
            },
            matching: MatchConfig {
                ratio: 0.7,
                ..MatchConfig::default()
            },
            msac_threshold_px: 3.0,
            min_confidence: 1.0,
            max_scale_error: 0.1,
            crop_margin_cells: 16,
        }
    }
}

/// The outcome of the baseline on one pair of maps.
#[derive(Clone, Debug, PartialEq)]
pub struct BaselineOutcome {
    pub status: MergeStatus,
    pub reason: String,
    /// Pose of map B's frame in map A's frame (a point `p` of B is at
    /// `pose.transform_point(p)` in A), when merged.
    pub pose: Option<Pose2>,
    /// Ratio-test matches between the two grid images.
    pub matches: usize,
    /// MSAC similarity inliers.
    pub inliers: usize,
    /// Brown and Lowe's `inliers / (8 + 0.3 · matches)`.
    pub confidence: f64,
}

/// A grid drawn as an image (see the module doc), and where it lies.
#[derive(Clone, Debug, PartialEq)]
pub struct GridPicture {
    pub image: GrayImage,
    /// Local cell of the grid at the picture's bottom-left pixel.
    pub first_cell: (usize, usize),
    /// Map-frame position of the bottom-left corner of cell (0, 0) of the
    /// grid, and the cell size (m).
    pub origin_m: DVec2,
    pub resolution_m: f64,
}

impl GridPicture {
    /// The map point (metres, the grid's frame) at pixel `(u, v)`.
    pub fn pixel_to_map(&self, u: f64, v: f64) -> DVec2 {
        let rows = self.image.height() as f64;
        let (i0, j0) = (self.first_cell.0 as f64, self.first_cell.1 as f64);
        self.origin_m + DVec2::new(i0 + u + 0.5, j0 + rows - 0.5 - v) * self.resolution_m
    }
}

/// Draws a grid as a grey image: occupied 0, free 255, unknown 128, cropped
/// to the known cells plus `margin` cells. `None` when no cell is known.
pub fn grid_picture(grid: &OccupancyGrid, margin: usize) -> Option<GridPicture> {
    let (w, h) = (grid.width(), grid.height());
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0usize, 0usize);
    for iy in 0..h {
        for ix in 0..w {
            if grid.state(ix, iy) != CellState::Unknown {
                x0 = x0.min(ix);
                y0 = y0.min(iy);
                x1 = x1.max(ix);
                y1 = y1.max(iy);
            }
        }
    }
    if x0 == usize::MAX {
        return None;
    }
    let (x0, y0) = (x0.saturating_sub(margin), y0.saturating_sub(margin));
    let (x1, y1) = ((x1 + margin).min(w - 1), (y1 + margin).min(h - 1));
    let (cw, ch) = (x1 - x0 + 1, y1 - y0 + 1);
    let mut pixels = vec![UNKNOWN_GREY; cw * ch];
    for row in 0..ch {
        let iy = y1 - row;
        for col in 0..cw {
            pixels[row * cw + col] = match grid.state(x0 + col, iy) {
                CellState::Occupied => OCCUPIED_GREY,
                CellState::Free => FREE_GREY,
                CellState::Unknown => UNKNOWN_GREY,
            };
        }
    }
    let image = GrayImage::new(cw, ch, pixels).ok()?;
    Some(GridPicture {
        image,
        first_cell: (x0, y0),
        origin_m: grid.origin_m(),
        resolution_m: grid.resolution_m(),
    })
}

/// Least-squares rotation and translation taking `from[i]` to `to[i]`
/// (2-D Kabsch/Umeyama without scale). `None` for fewer than 2 points.
fn rigid_fit(from: &[DVec2], to: &[DVec2]) -> Option<Pose2> {
    if from.len() < 2 || from.len() != to.len() {
        return None;
    }
    let n = from.len() as f64;
    let cf = from.iter().copied().sum::<DVec2>() / n;
    let ct = to.iter().copied().sum::<DVec2>() / n;
    let (mut sc, mut ss) = (0.0, 0.0);
    for (a, b) in from.iter().zip(to) {
        let (a, b) = (*a - cf, *b - ct);
        sc += a.dot(b);
        ss += a.perp_dot(b);
    }
    if sc == 0.0 && ss == 0.0 {
        return None;
    }
    let theta = ss.atan2(sc);
    let t = ct - DVec2::from_angle(theta).rotate(cf);
    let pose = Pose2::new(t.x, t.y, wrap_angle(theta));
    pose.is_finite().then_some(pose)
}

fn no_merge(reason: String, matches: usize, inliers: usize, confidence: f64) -> BaselineOutcome {
    BaselineOutcome {
        status: MergeStatus::NoMerge,
        reason,
        pose: None,
        matches,
        inliers,
        confidence,
    }
}

/// Merges map B into map A from the grids alone (see the module doc).
/// `seed` drives MSAC's samples. Never panics: empty grids, maps without
/// features or without agreement give `no_merge` with the reason.
pub fn map_only_merge(
    a: &OccupancyGrid,
    b: &OccupancyGrid,
    cfg: &BaselineConfig,
    seed: u64,
) -> BaselineOutcome {
    let (Some(pa), Some(pb)) = (
        grid_picture(a, cfg.crop_margin_cells),
        grid_picture(b, cfg.crop_margin_cells),
    ) else {
        return no_merge("a map is empty".into(), 0, 0, 0.0);
    };
    let fa = extract(&pa.image, &cfg.surf);
    let fb = extract(&pb.image, &cfg.surf);
    if fa.is_empty() || fb.is_empty() {
        return no_merge(
            format!(
                "too few features on the grid images ({} and {} keypoints)",
                fa.len(),
                fb.len()
            ),
            0,
            0,
            0.0,
        );
    }
    // B's pixels to A's pixels: the fit then reads as B's frame in A's.
    let matches = match_features(&fb, &fa, &cfg.matching);
    let n_f = matches.len();
    // OpenCV's matcher gives up below 6 matches.
    if n_f < 6 {
        return no_merge(
            format!("only {n_f} feature matches between the grid images"),
            n_f,
            0,
            0.0,
        );
    }
    let key = |k: &crate::surf::Keypoint| [k.x as f64, k.y as f64];
    let p_b: Vec<[f64; 2]> = matches
        .iter()
        .map(|m| key(&fb.keypoints[m.query]))
        .collect();
    let p_a: Vec<[f64; 2]> = matches
        .iter()
        .map(|m| key(&fa.keypoints[m.train]))
        .collect();
    let msac = MsacConfig {
        threshold_px: cfg.msac_threshold_px,
        min_inliers: 2,
        seed,
        ..MsacConfig::default()
    };
    let Some(fit) = fit_similarity(&p_b, &p_a, &msac) else {
        return no_merge(format!("no similarity fits the {n_f} matches"), n_f, 0, 0.0);
    };
    let n_i = fit.inliers.len();
    let confidence = n_i as f64 / (8.0 + 0.3 * n_f as f64);
    if confidence < cfg.min_confidence {
        return no_merge(
            format!(
                "{n_i} of {n_f} matches agree: confidence {confidence:.2} is below {:.2}",
                cfg.min_confidence
            ),
            n_f,
            n_i,
            confidence,
        );
    }
    let scale = fit.model.scale() * pa.resolution_m / pb.resolution_m.max(1e-12);
    if (scale - 1.0).abs() > cfg.max_scale_error {
        return no_merge(
            format!(
                "the fit scales one map by {scale:.2}: the maps share no structure it could lock onto"
            ),
            n_f,
            n_i,
            confidence,
        );
    }
    let from: Vec<DVec2> = fit
        .inliers
        .iter()
        .map(|&i| pb.pixel_to_map(p_b[i][0], p_b[i][1]))
        .collect();
    let to: Vec<DVec2> = fit
        .inliers
        .iter()
        .map(|&i| pa.pixel_to_map(p_a[i][0], p_a[i][1]))
        .collect();
    let Some(pose) = rigid_fit(&from, &to) else {
        return no_merge(
            "the inliers do not fix a rigid transform".into(),
            n_f,
            n_i,
            confidence,
        );
    };
    BaselineOutcome {
        status: MergeStatus::Merged,
        reason: format!(
            "{n_i} of {n_f} grid-image matches agree (confidence {confidence:.2}, scale {scale:.3})"
        ),
        pose: Some(pose),
        matches: n_f,
        inliers: n_i,
        confidence,
    }
}
