//! # Verifying a proposed frame pair: homography for the table, rigid fit for the pose
//!
//! Place recognition ([`super::vocabulary`]) only says two frames *look*
//! alike. This step checks that they show the same place, and measures how
//! the two robots' maps sit relative to each other there.
//!
//! 1. **Match** the two frames' SURF descriptors (nearest neighbour with
//!    Lowe's ratio and the sign of the Laplacian, [`crate::surf::matching`];
//!    thesis §5.3.4).
//! 2. **Homography, for the table.** The thesis fits a homography to the
//!    matches with MSAC and counts its inliers (§6.2.3, Table 1), and draws
//!    where one image lies in the other (the matched region). We do the same,
//!    so the matched-pair table can be read beside the thesis's. A homography
//!    only holds for one plane, though, and frames taken from different
//!    viewpoints of a corner are not related by one, so it does not decide
//!    anything below.
//! 3. **Lift** both keypoints of every match to the wall point they show,
//!    in each robot's own map frame ([`super::lift`]: bearing from the
//!    column, range from the laser, through the SLAM pose), with the height
//!    of the point on the wall. A match whose two heights differ by more than
//!    `height_tolerance_m` cannot be one physical point and is dropped: a
//!    repeated texture (bricks one above another) fools the descriptor, not
//!    the geometry.
//! 4. **Rigid MSAC** ([`super::rigid`]) on the lifted pairs gives the pose of
//!    B's map frame in A's: the [`Candidate`]. There is none when too few
//!    matches lift, too few agree, or the agreeing points bunch within a few
//!    centimetres (no angle can be read from them).
//!
//! A candidate is one frame pair's opinion. Whether the maps are merged is
//! decided later, from all candidates together ([`super::consistency`],
//! [`super::verdict`]).

use super::lift::lift_keypoint_3d;
use super::rigid::{fit_rigid_msac, RigidConfig};
use super::{Candidate, FrameInfo};
use crate::camera::PinholeCamera;
use crate::surf::{
    fit_homography, match_features, Features, Homography, Match, MatchConfig, MatchedRegion,
    MsacConfig,
};
use glam::DVec2;

/// Settings of [`verify_pair`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VerifyConfig {
    /// Descriptor matching. Default: ratio 0.8, Laplacian gating, not mutual.
    pub matching: MatchConfig,
    /// The homography MSAC (its seed is replaced by the pair's seed).
    pub msac: MsacConfig,
    /// Whether to fit the homography at all (the table's numbers). Default
    /// true; the rigid candidate does not depend on it.
    pub homography: bool,
    /// The rigid MSAC on lifted points.
    pub rigid: RigidConfig,
    /// Two views of one point must put it at heights on the wall within this
    /// (m). Default 0.12.
    pub height_tolerance_m: f64,
    /// A candidate needs at least this many rigid inliers. Default 8.
    pub min_inliers: usize,
}

impl Default for VerifyConfig {
    fn default() -> Self {
        VerifyConfig {
            matching: MatchConfig::default(),
            msac: MsacConfig::default(),
            homography: true,
            rigid: RigidConfig::default(),
            height_tolerance_m: 0.12,
            min_inliers: 8,
        }
    }
}

/// Everything one frame pair's check found.
#[derive(Clone, Debug, PartialEq)]
pub struct PairCheck {
    /// Descriptor matches, `query` in A's frame, `train` in B's.
    pub matches: Vec<Match>,
    /// Homography mapping A's pixels to B's (thesis §6.2.3).
    pub homography: Option<Homography>,
    pub homography_inliers: usize,
    /// One flag per match.
    pub homography_inlier_mask: Vec<bool>,
    /// Where A's image lies in B's (the thesis's green quadrangle).
    pub quad: Option<[[f64; 2]; 4]>,
    /// The relative pose from the lifted matches, if they agree.
    pub candidate: Option<Candidate>,
    /// One flag per match: supports the candidate.
    pub rigid_inlier_mask: Vec<bool>,
    /// Matches whose both keypoints lifted to consistent wall points.
    pub lifted: usize,
    /// Rigid-fit inliers, also when too few for a candidate (0 without a
    /// fit): "too few inliers" reports quote the best.
    pub rigid_inliers: usize,
}

/// Pixel position of a keypoint.
fn pixel(f: &Features, i: usize) -> Option<[f64; 2]> {
    f.keypoints
        .get(i)
        .map(|k| [k.x as f64, k.y as f64])
        .filter(|p| p[0].is_finite() && p[1].is_finite())
}

/// Checks one frame pair (see the module doc). Never panics: frames without
/// features, matches that do not lift, or degenerate geometry give a
/// [`PairCheck`] without a candidate.
pub fn verify_pair(
    camera: &PinholeCamera,
    a: &FrameInfo,
    fa: &Features,
    b: &FrameInfo,
    fb: &Features,
    cfg: &VerifyConfig,
    seed: u64,
) -> PairCheck {
    let matches = match_features(fa, fb, &cfg.matching);
    let mut check = PairCheck {
        homography_inlier_mask: vec![false; matches.len()],
        rigid_inlier_mask: vec![false; matches.len()],
        matches,
        homography: None,
        homography_inliers: 0,
        quad: None,
        candidate: None,
        lifted: 0,
        rigid_inliers: 0,
    };
    // The pixel pairs of the matches (both keypoints exist by construction).
    let pairs: Vec<(usize, [f64; 2], [f64; 2])> = check
        .matches
        .iter()
        .enumerate()
        .filter_map(|(m, mt)| Some((m, pixel(fa, mt.query)?, pixel(fb, mt.train)?)))
        .collect();

    if cfg.homography {
        let p1: Vec<[f64; 2]> = pairs.iter().map(|p| p.1).collect();
        let p2: Vec<[f64; 2]> = pairs.iter().map(|p| p.2).collect();
        let msac = MsacConfig { seed, ..cfg.msac };
        if let Some(fit) = fit_homography(&p1, &p2, &msac) {
            for &i in &fit.inliers {
                check.homography_inlier_mask[pairs[i].0] = true;
            }
            check.homography_inliers = fit.inliers.len();
            let size = (camera.width as usize, camera.height as usize);
            check.quad = MatchedRegion::new(&fit.model, size, size).map(|r| r.quad);
            check.homography = Some(fit.model);
        }
    }

    // Lift both ends of every match; keep pairs at the same height.
    let mut index = Vec::new();
    let mut pa = Vec::new();
    let mut pb = Vec::new();
    for &(m, qa, qb) in &pairs {
        let (Some(la), Some(lb)) = (
            lift_keypoint_3d(camera, a, qa[0], qa[1]),
            lift_keypoint_3d(camera, b, qb[0], qb[1]),
        ) else {
            continue;
        };
        if (la.z - lb.z).abs() > cfg.height_tolerance_m {
            continue;
        }
        index.push(m);
        pa.push(DVec2::new(la.x, la.y));
        pb.push(DVec2::new(lb.x, lb.y));
    }
    check.lifted = index.len();
    let rigid_seed = seed ^ 0x9E37_79B9_7F4A_7C15;
    let Some(fit) = fit_rigid_msac(&pa, &pb, &cfg.rigid, rigid_seed) else {
        return check;
    };
    check.rigid_inliers = fit.inliers.len();
    if fit.inliers.len() < cfg.min_inliers {
        return check;
    }
    for &i in &fit.inliers {
        check.rigid_inlier_mask[index[i]] = true;
    }
    let k = fit.inliers.len() as f64;
    let place_a = fit.inliers.iter().map(|&i| pa[i]).sum::<DVec2>() / k;
    let place_b = fit.inliers.iter().map(|&i| pb[i]).sum::<DVec2>() / k;
    check.candidate = Some(Candidate {
        a_frame: a.index,
        b_frame: b.index,
        pose: fit.pose,
        inliers: fit.inliers.len(),
        rms_m: fit.rms_m,
        place_a,
        place_b,
    });
    check
}
