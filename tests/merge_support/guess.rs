//! A person's rough placing of one saved map on another, for the tests of
//! Refine (crate/src/merge/saved/refine.rs): `tests/saved_merge.rs` and
//! `tests/real_maps.rs` include this file with `#[path]`.

use glam::DVec2;
use slamlab::formats::rosmap::RosMap;
use slamlab::geom::Pose2;
use slamlab::merge::saved::refine::refine_pair;
use slamlab::merge::saved::wallmap::WallMap;
use slamlab::merge::saved::{PairResult, SavedMergeConfig};

/// `pose` (B's map frame in A's) turned by `dtheta` about B's point
/// `pivot` (in B's map frame) and then moved by `shift`: how a person drags
/// and turns a map about its middle.
pub fn nudged(pose: &Pose2, pivot: DVec2, dtheta: f64, shift: DVec2) -> Pose2 {
    let q = pose.transform_point(pivot);
    let (s, c) = dtheta.sin_cos();
    let d = pose.position() - q;
    let t = q + DVec2::new(c * d.x - s * d.y, s * d.x + c * d.y) + shift;
    Pose2::new(t.x, t.y, pose.theta + dtheta)
}

/// The middle of map `m`'s image, in its map frame.
pub fn middle(m: &RosMap) -> DVec2 {
    m.origin
        .transform_point(DVec2::new(m.width as f64, m.height as f64) * 0.5 * m.resolution)
}

/// B refined on A from `guess` with the default settings.
pub fn refined(a: &RosMap, b: &RosMap, guess: Pose2) -> PairResult {
    let (wa, wb) = (WallMap::new(a), WallMap::new(b));
    refine_pair(
        (0, a, &wa),
        (1, b, &wb),
        guess,
        &SavedMergeConfig::default(),
    )
    .unwrap()
}
