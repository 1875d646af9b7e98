//! # SLAM for real laser logs: scan-to-map matching, a pose graph, loop closures
//!
//! The driver that replays a CARMEN log ([`crate::formats::carmen`]) in file order,
//! in the manner of Karto / slam_toolbox (Konolige et al., "Efficient sparse
//! pose adjustment for 2D mapping", IROS 2010) and Cartographer (Hess et al.,
//! "Real-time loop closure in 2D LIDAR SLAM", ICRA 2016):
//!
//! 1. **Predict** each scan's pose from the previous one and the odometry
//!    increment between them (`x̂_t = x_{t−1} ⊕ (u_{t−1}⁻¹ ⊕ u_t)`).
//! 2. **Match** the scan against the local map — the points of the last
//!    `local_keys` key scans at their current estimates — with Olson's
//!    multi-resolution correlative search and a Gauss–Newton refinement
//!    ([`crate::slam::multires`]). A narrow window first; if its best pose
//!    lies on the window's edge or scores poorly, a wide window: real wheel
//!    odometry slips, and the raw MIT CSAIL log's heading jumps by 10–30°.
//!    The wide window turns far (35°) but reaches only 0.6 m. In a corridor
//!    the response is nearly flat along it, and a window that reaches a
//!    metre lets a stretch further along that happens to score a little
//!    better win, so key edges slide along corridors.
//!
//!    A scan whose best match still scores poorly keeps the prediction,
//!    unless the narrow window's match lies inside that window and scores
//!    at least `weak_match_score` (0.2, against `min_match_score`'s 0.35).
//!    A poor fit close to where the odometry put the scan (a hall whose
//!    far walls lie beyond the 20 m match range, a turn that shows new
//!    ground) is still a better pose than the odometry alone, whose error
//!    the scans after it would otherwise inherit. Such a scan fits poorly
//!    for a reason (people around the robot, ground no key has seen), so it
//!    gives the local map nothing to match the next scans against: once
//!    the next key follows it, it leaves the local map. It stays a node of
//!    the graph, with its points for loop closures. Kept in the local map,
//!    weak matches make the keys after them slide along corridors.
//!
//!    Wheel odometry can also arrive late: the raw MIT CSAIL log's odometry
//!    stands still for a few scans of a fast turn, then jumps by the whole
//!    turn (85° in one step), which the matcher had already followed. So
//!    after a scan whose odometry did not change, when the motion the
//!    matcher saw last (a constant-velocity prediction, as Cartographer's
//!    pose extrapolator makes) disagrees with the odometry's by more than
//!    the narrow window, the scan is also matched around that prediction,
//!    and the better-scoring match is kept (`velocity_prior`).
//! 3. **Key scans** (every `key_distance_m` or `key_angle_rad` of motion)
//!    become nodes of the pose graph ([`crate::slam::posegraph`]), linked to
//!    the previous key by the matched relative pose with one σ for all
//!    (`key_sigma_m`, `key_sigma_rad`), or, where no match held, by odometry
//!    with a looser covariance. Other scans are stored relative to their
//!    key, so they follow it when the graph moves. The spread of the
//!    matcher's response ([`crate::slam::match_covariance`]) could weigh
//!    each edge by its own match instead, but on these logs which closures
//!    are found decides the result, not the key edges' weights
//!    (BENCHMARKS.md).
//!
//!    Without odometry it is otherwise: in a corridor whose ends are out
//!    of range the match along it is a guess, and nothing else in the log
//!    says how far the robot went. A key edge there is made as loose along
//!    the new key's scan's weakest direction as the scan's surface normals
//!    pin it less there than across (`Σ n nᵀ`, [`crate::slam::degeneracy`];
//!    the ratio of its eigenvalues, up to `key_loosen_ratio`), so a loop's
//!    closure puts the error where the corridor lost it instead of bending
//!    the whole loop. On the Stage bag (a 5 m, 90-beam laser) a stretch
//!    whose normals give a weak/strong ratio of 0.0003 lost 0.87 m; with
//!    one σ for all edges the closure spread it over the loop (ATE 0.253
//!    m), loosened 0.114 m. With odometry the edges keep one σ: loosened,
//!    a wrong closure bends the raw ACES log by metres (the chain along a
//!    corridor is then held by nothing but the closures).
//! 4. **Loop closures** ([`crate::slam::loop_closure`]): every `loop_every`
//!    keys the new key is matched against the older keys of the nearest
//!    earlier pass near its estimate.
//!    - A closure whose match lies on the edge of its search window is
//!      refused (`loop_edge_reject`), as the local match widens its window
//!      in that case: the best pose inside a window is only a peak of the
//!      response if it lies inside, and a match pressed against the
//!      window's border is often a wrong place that merely fits better than
//!      the right one within reach (on the raw MIT CSAIL log, closures that
//!      slid nearly two metres along a corridor).
//!    - An accepted closure's edge is as loose along the match's weakest
//!      direction as the point-to-line information there is weaker than
//!      across it ([`crate::slam::loop_closure::closure_fit`]), up to
//!      `loop_loosen_ratio` (10) times the variance: a corridor whose ends
//!      are out of sight pins a closure only across itself, so its closure
//!      holds the corridor's two walls without pinning where along it the
//!      key lies. Refusing such closures outright would throw away the
//!      right half of what they say, and the corridor-rich logs need them.
//!    - The search window reaches ±1.5 m, and on one try in `grown_every`
//!      (4) further, by 0.03 m for every metre of the shortest path from the
//!      old key through the chain and the closures accepted so far, up to
//!      16 m ([`crate::slam::loop_closure::closure_window`]): in a
//!      convention hall or around a campus the drift a revisit must undo
//!      reaches metres, and 16 m covers all but a few revisits of a 250 m
//!      campus tour. A match found only in the grown reach must score
//!      `far_min_score` and have no rival near as good; after one, every
//!      try searches the grown window for `confirm_keys` keys so that a
//!      second can confirm it. Growing the window on one try in four keeps
//!      the long revisits in reach without paying the wide search on every
//!      key.
//! 5. **Consistency**: a single match can be wrong (two alike corridors).
//!    Following Olson's pairwise consistency idea ("Recognizing places using
//!    spectrally clustered local matches", RAS 2009), a closure is only
//!    accepted once a second closure found within `confirm_keys` keys
//!    agrees with it: the cycle *old₁ → new₁ → new₂ → old₂ → old₁*, made of
//!    the two closures and the graph's current relative poses along the two
//!    stretches (each locally accurate), must compose to nearly the
//!    identity. Accepted closures go into the graph, which is optimised by
//!    plain least squares; an optimisation that leaves a closure badly
//!    unsatisfied (χ² over `max_closure_chi2`) is undone. Once accepted, a
//!    closure stays: with key edges of σ 0.1 m the graph absorbs each one
//!    to χ² < 1, so a later χ² test cannot tell a wrong one, and a robust
//!    kernel (Dynamic Covariance Scaling) has no outlier to weigh down.
//! 6. **Square walls** ([`crate::slam::manhattan`]), once the log is
//!    replayed and the graph optimised: between closures the chain's
//!    heading wanders by tenths of a degree, and most buildings are built
//!    square. Each key whose scan's walls run in two directions at right
//!    angles gets a loose heading prior towards the building's direction,
//!    measured from the keys themselves, in rounds that let a stretch
//!    hanging on odometry turn back in; a building that is not square gets
//!    none.
//! 7. **Smoothing** ([`LogSlam::finish`]): each scan was matched while the
//!    robot went, against the keys *behind* it, rasterised. Once the graph
//!    is settled, every scan is aligned again by point-to-line ICP
//!    ([`crate::slam::icp`]) on the points of the `smooth_keys` keys on
//!    *both* sides of its own along the chain, at their final poses:
//!    a filter's estimate becomes a smoother's. The points themselves,
//!    not a raster, take away the grain of the 5 cm cells, and keys ahead
//!    of the scan balance the pull of those behind it towards where they
//!    were taken (a key's marks lie densest near its own position). The
//!    scan aligned keeps a point every `smooth_spacing_m` (5 cm, twice as
//!    many as it was matched with); the scans of a key are aligned without
//!    that key's own scan, which a key scan would otherwise find itself in.
//!    A scan that few target points meet or that would move more than
//!    `smooth_max_move_m` or `smooth_max_turn_rad` keeps its pose, and the
//!    graph's nodes and closures are not changed: only where each scan
//!    sits relative to its key. On the benchmark's raw logs it lowers
//!    every log's relation error, whole and by halves (BENCHMARKS.md).
//! 8. **Fusion with the odometry** ([`super::fusion`]): each smoothed scan
//!    is a measurement of where it was; the wheel odometry between two
//!    neighbouring scans is another of how far apart they were. A
//!    smoother over the chain of scans weighs the two by their noises,
//!    measured from the log itself (how their disagreement grows with the
//!    number of scans between), so good wheels steady the scans where a
//!    match is unsure (along a corridor) and poor wheels are ignored.
//!    Only positions are fused, not the odometry's heading. A fused pose
//!    may lie up to `fusion_max_move_m` from where the replay left it.
//!
//! Karto's scan-to-scan chain of recent keys, closures against several
//! earlier passes, each edge weighted by its match's response, and a
//! closing pass that links every revisit after the replay were all tried
//! and are not part of the driver: none improved the logs as a whole
//! (BENCHMARKS.md).
//!
//! The poses are in the log's odometry frame: the first scan's pose is its
//! odometry pose, and the graph's first node stays fixed there.

use super::fusion::{fuse, measure_noise, FusionNoise, Placement};
use super::scan::LogScan;
use crate::geom::{wrap_angle, Pose2};
use crate::slam::degeneracy::{constraint_of, scan_normals_within};
use crate::slam::grid::{GridConfig, OccupancyGrid, GROW_STEP_CELLS};
use crate::slam::icp::IcpTarget;
use crate::slam::likelihood::LikelihoodField;
use crate::slam::loop_closure::{
    closure_fit, closures_agree, find_closure_among, loose_along, loosened_along_weak,
    on_window_edge, Closure, LoopConfig,
};
use crate::slam::manhattan::{scan_direction, settle_priors, ManhattanConfig};
use crate::slam::multires::{field_from_points, match_scan, ScanMatch, Window};
use crate::slam::posegraph::{Edge, PoseGraph};
use glam::DVec2;

/// Settings of the log SLAM.
#[derive(Clone, Debug, PartialEq)]
pub struct LogSlamConfig {
    pub resolution_m: f64,
    /// Beams longer than this are not matched (nor drawn as walls).
    pub match_range_m: f64,
    /// A beam without a return clears free space this far.
    pub free_range_m: f64,
    /// Scan points closer than this to the previous kept one are dropped.
    pub point_spacing_m: f64,
    pub key_distance_m: f64,
    pub key_angle_rad: f64,
    pub local_keys: usize,
    pub narrow: Window,
    /// The window searched when the narrow one's match is poor or on its
    /// edge (see the module doc on why it reaches only 0.6 m).
    pub wide: Window,
    /// Below this mean field value a match is not trusted.
    pub min_match_score: f64,
    /// When no window found a match scoring `min_match_score`, the narrow
    /// window's match is still taken down to this score if it lies inside
    /// the window (not on its edge): a poor fit near the prediction beats
    /// the prediction alone (0: off).
    pub weak_match_score: f64,
    pub close_loops: bool,
    pub loops: LoopConfig,
    pub loop_every: usize,
    pub confirm_keys: usize,
    /// Largest disagreement of two closures' cycle (m, rad).
    pub confirm_m: f64,
    pub confirm_rad: f64,
    pub max_closure_chi2: f64,
    /// Standard deviations of a matched key-to-key edge (m, rad). The
    /// matcher pins a heading better than a position (a 20 m beam moves a
    /// cell for a quarter of a degree): its key edges measured against the
    /// reference poses (example `log_closures`) err by a few centimetres
    /// and about half a degree. A tighter position with a looser heading
    /// would make a turn the cheaper way to absorb a loop's error, and the
    /// graph would bend headings.
    pub key_sigma_m: f64,
    pub key_sigma_rad: f64,
    /// Also match around the constant-velocity prediction when it
    /// disagrees with the odometry's (see the module doc).
    pub velocity_prior: bool,
    /// Refuse a closure whose match lies on the edge of the closure search
    /// window (the best pose inside the window is then not a peak of the
    /// response: the true one may lie outside, as for the local match).
    pub loop_edge_reject: bool,
    /// With a closure window that grows with the path
    /// (`loops.window_per_m` > 0): the grown window is searched on one try
    /// in this many (tries are `loop_every` keys apart), and on every try
    /// for `confirm_keys` keys after a try found a match in it, so that a
    /// second can confirm the first. A revisit lasts many keys, so a hall's
    /// loop still closes; an outdoor tour that rarely closes one stops
    /// paying the wide search on every key. 1: every try.
    pub grown_every: usize,
    /// The score a closure must reach when it moves its key beyond the
    /// fixed window (`loops.window`): a search grown with the path sees
    /// more of a building, and a corridor's doors repeat.
    pub far_min_score: f64,
    /// A closure's edge is loose along its weakest direction: its variance
    /// there is `loops.sigma_m²` times the ratio of the strong to the weak
    /// eigenvalue of the match's point-to-line information, at most this
    /// ([`crate::slam::loop_closure::loosened_along_weak`]; 0 or 1: one σ for
    /// all). A corridor's closure is right across it and unsure along it.
    pub loop_loosen_ratio: f64,
    /// Without odometry (`odometry` false), a key edge is as loose along
    /// the new key's scan's weakest direction as that scan's surface
    /// normals pin it less there than across ([`crate::slam::degeneracy`]),
    /// up to this many times the variance (module doc, step 3; 0 or 1:
    /// one σ for all). With odometry the edges keep one σ.
    pub key_loosen_ratio: f64,
    /// Square walls' heading prior after the replay ([`crate::slam::manhattan`];
    /// `None`: off). On: a building whose walls are not square gets no
    /// prior.
    pub manhattan: Option<ManhattanConfig>,
    /// Keys on each side of a scan's own whose points it is aligned to
    /// after the replay (module doc, step 7; 0: no smoothing).
    pub smooth_keys: usize,
    /// ICP iterations of that alignment, the Huber threshold of its
    /// residuals, and how far a target point may lie from a scan point.
    pub smooth_iterations: usize,
    pub smooth_huber_m: f64,
    pub smooth_radius_m: f64,
    /// A scan the alignment would move further than this keeps its pose.
    pub smooth_max_move_m: f64,
    pub smooth_max_turn_rad: f64,
    /// The scan aligned keeps a point every this far along it (the keys'
    /// points stay as matched, `point_spacing_m`): more points average
    /// more of the range noise.
    pub smooth_spacing_m: f64,
    /// Whether the smoothed scans are fused with the odometry between
    /// them, each weighed by its noise measured from the log
    /// ([`super::fusion`]); only where the scans carry odometry.
    pub smooth_odometry: bool,
    /// A scan the fusion would move further than this from where the
    /// replay left it keeps that pose. Further than ICP alone may move it
    /// (`smooth_max_move_m`): along a corridor, where ICP has no hold, the
    /// odometry does, and the replay's matches slide there by decimetres.
    pub fusion_max_move_m: f64,
    /// Whether the scans carry odometry. Without it (a hand-carried laser,
    /// a simulator's bag of scans alone) each scan is predicted from the
    /// last one by the motion the estimate made between the two before
    /// (a constant velocity, scaled by the scans' time apart), and
    /// `LogScan::odometry` is not read.
    pub odometry: bool,
}

impl Default for LogSlamConfig {
    fn default() -> Self {
        LogSlamConfig {
            resolution_m: 0.05,
            match_range_m: 20.0,
            free_range_m: 10.0,
            point_spacing_m: 0.1,
            key_distance_m: 0.3,
            key_angle_rad: 10f64.to_radians(),
            local_keys: 20,
            narrow: Window {
                linear_m: 0.3,
                angular_rad: 6f64.to_radians(),
            },
            wide: Window {
                linear_m: 0.6,
                angular_rad: 35f64.to_radians(),
            },
            min_match_score: 0.35,
            weak_match_score: 0.2,
            close_loops: true,
            // The closure window grows with the path (on one try in
            // `grown_every`): a hall's loop needs a correction of metres,
            // a campus's up to 20 m (see the module doc).
            loops: LoopConfig {
                window_per_m: 0.03,
                max_window_m: 16.0,
                ..LoopConfig::default()
            },
            loop_every: 2,
            confirm_keys: 12,
            confirm_m: 0.3,
            confirm_rad: 3f64.to_radians(),
            max_closure_chi2: 50.0,
            key_sigma_m: 0.1,
            key_sigma_rad: 0.5f64.to_radians(),
            velocity_prior: true,
            loop_edge_reject: true,
            grown_every: 4,
            far_min_score: 0.7,
            loop_loosen_ratio: 10.0,
            key_loosen_ratio: 10_000.0,
            manhattan: Some(ManhattanConfig::for_logs()),
            odometry: true,
            smooth_keys: 10,
            smooth_iterations: 3,
            smooth_huber_m: 0.02,
            smooth_radius_m: 0.2,
            smooth_max_move_m: 0.1,
            smooth_max_turn_rad: 2f64.to_radians(),
            smooth_spacing_m: 0.05,
            smooth_odometry: true,
            fusion_max_move_m: 0.5,
        }
    }
}

/// Where one scan ended up: its key node and its pose relative to it.
#[derive(Clone, Debug, PartialEq)]
pub struct ScanEntry {
    pub index: usize,
    pub time: f64,
    pub odometry: Pose2,
    pub key: usize,
    pub relative: Pose2,
}

/// An accepted loop closure (key and scan indices, match score).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ClosureInfo {
    pub from_key: usize,
    pub to_key: usize,
    pub from_scan: usize,
    pub to_scan: usize,
    pub score: f64,
}

/// Counts of what the matcher did.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct LogSlamStats {
    pub scans: usize,
    pub keys: usize,
    pub matched: usize,
    pub wide_searches: usize,
    pub unmatched: usize,
    /// Scans also matched around the constant-velocity prediction, and how
    /// many of them it won.
    pub velocity_searches: usize,
    pub velocity_wins: usize,
    pub closures_tried: usize,
    pub closures_found: usize,
    pub closures_rejected: usize,
    /// Closures refused for lying on the search window's edge.
    pub closures_on_edge: usize,
    /// Closures refused for moving their key beyond the fixed window with
    /// a score under `far_min_score`.
    pub closures_far_weak: usize,
    /// Keys given a square walls' heading prior ([`crate::slam::manhattan`]).
    pub square_keys: usize,
    /// The odometry's and the smoothed scans' noise as measured for their
    /// fusion ([`super::fusion`]), where they were fused.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fusion_noise: Option<FusionNoise>,
}

/// The SLAM state of one log replay.
#[derive(Clone, Debug)]
pub struct LogSlam {
    pub config: LogSlamConfig,
    pub graph: PoseGraph,
    key_points: Vec<Vec<DVec2>>,
    key_scan: Vec<usize>,
    pub scans: Vec<ScanEntry>,
    local: Option<LikelihoodField>,
    last: Option<(Pose2, Pose2)>,
    /// The last scan-to-scan motion of the estimate (robot frame).
    last_step: Pose2,
    /// The time of the last scan, and how long the last step took (s).
    last_time: f64,
    last_dt: f64,
    /// Whether the odometry did not change between the last two scans.
    odometry_stale: bool,
    unmatched_since_key: bool,
    /// Whether each key's scan matched only weakly (`weak_match_score`).
    weak_keys: Vec<bool>,
    pending: Vec<Closure>,
    /// The grown closure window is searched on every try up to this key:
    /// a try there found a match beyond the fixed window (`grown_every`).
    grow_until: usize,
    pub closures: Vec<ClosureInfo>,
    pub stats: LogSlamStats,
}

/// The local match of [`LogSlam::match_local`]: the best pose and whether
/// the wide window was searched.
fn local_match(
    field: &LikelihoodField,
    cfg: &LogSlamConfig,
    points: &[DVec2],
    predicted: &Pose2,
) -> (Option<ScanMatch>, bool) {
    let on_edge = |m: &ScanMatch, w: &Window| {
        let d = predicted.between(&m.pose);
        d.x.abs() > w.linear_m - 2.0 * cfg.resolution_m
            || d.y.abs() > w.linear_m - 2.0 * cfg.resolution_m
            || d.theta.abs() > w.angular_rad - 0.5f64.to_radians()
    };
    let good = |m: &ScanMatch| m.score >= cfg.min_match_score;
    let narrow = match_scan(field, points, predicted, &cfg.narrow);
    if let Some(m) = &narrow {
        if good(m) && !on_edge(m, &cfg.narrow) {
            return (narrow, false);
        }
    }
    let wide = match_scan(field, points, predicted, &cfg.wide);
    let weak = narrow.clone().filter(|m| {
        cfg.weak_match_score > 0.0 && m.score >= cfg.weak_match_score && !on_edge(m, &cfg.narrow)
    });
    let best = match (narrow, wide) {
        (Some(a), Some(b)) => Some(if b.score > a.score { b } else { a }),
        (a, b) => a.or(b),
    };
    (best.filter(good).or(weak), true)
}

/// The points of a scan worth matching, in the robot frame: returns within
/// `match_range_m`, through the laser's offset, thinned to one per
/// `point_spacing_m` along the scan.
pub fn scan_points(scan: &LogScan, cfg: &LogSlamConfig) -> Vec<DVec2> {
    points_every(scan, cfg.match_range_m, cfg.point_spacing_m)
}

/// Every return of `scan` within `range_m`, in the laser's own frame (not
/// through its offset on the robot), unthinned.
pub fn laser_points(scan: &LogScan, range_m: f64) -> Vec<DVec2> {
    points_from(scan, &Pose2::IDENTITY, range_m, 0.0)
}

/// The returns of `scan` within `range_m`, in the robot frame, one per
/// `spacing_m` along the scan.
fn points_every(scan: &LogScan, range_m: f64, spacing_m: f64) -> Vec<DVec2> {
    points_from(scan, &scan.laser_offset, range_m, spacing_m)
}

/// The returns of `scan` within `range_m` through the laser's pose
/// `offset`, one per `spacing_m` along the scan.
fn points_from(scan: &LogScan, offset: &Pose2, range_m: f64, spacing_m: f64) -> Vec<DVec2> {
    let mut out: Vec<DVec2> = Vec::with_capacity(scan.ranges.len());
    let offset = offset.frame();
    for (i, &r) in scan.ranges.iter().enumerate() {
        let r = r as f64;
        if scan.no_return(i) || r > range_m {
            continue;
        }
        let b = scan.bearing(i);
        let p = offset.to_parent(DVec2::new(b.cos(), b.sin()) * r);
        if out.last().is_none_or(|q| q.distance(p) >= spacing_m) {
            out.push(p);
        }
    }
    out
}

/// The information of a key edge ending at `pose` whose scan's `points`
/// (robot frame) pin its position less along one direction than across:
/// the variance `sigma_m²` across, `sigma_m²` times the ratio of the
/// strong to the weak eigenvalue of the points' surface normals' `Σ n nᵀ`
/// ([`crate::slam::degeneracy`]) along, at most `max_ratio` times;
/// heading `sigma_rad²`. `None` where that ratio is 1 (or `max_ratio` is
/// at most 1): the edge keeps one σ.
pub fn key_edge_information(
    points: &[DVec2],
    pose: &Pose2,
    sigma_m: f64,
    sigma_rad: f64,
    max_ratio: f64,
) -> Option<[[f64; 3]; 3]> {
    if max_ratio <= 1.0 {
        return None;
    }
    let normals = scan_normals_within(points, NORMAL_RADIUS_M);
    let c = constraint_of(&normals, &vec![true; normals.len()]);
    let ratio = (c.strong / c.weak.max(1e-9)).clamp(1.0, max_ratio);
    let along = pose.frame().rotate(c.weak_direction);
    (ratio > 1.0)
        .then(|| loose_along(along, ratio, sigma_m, sigma_rad, pose.theta))
        .flatten()
}

impl LogSlam {
    pub fn new(config: LogSlamConfig) -> LogSlam {
        LogSlam {
            config,
            graph: PoseGraph::default(),
            key_points: Vec::new(),
            key_scan: Vec::new(),
            scans: Vec::new(),
            local: None,
            last: None,
            last_step: Pose2::IDENTITY,
            last_time: 0.0,
            last_dt: 0.0,
            odometry_stale: false,
            unmatched_since_key: false,
            weak_keys: Vec::new(),
            pending: Vec::new(),
            grow_until: 0,
            closures: Vec::new(),
            stats: LogSlamStats::default(),
        }
    }

    /// Adds the next scan of the log (file order).
    pub fn add_scan(&mut self, scan: &LogScan) {
        let points = scan_points(scan, &self.config);
        self.stats.scans += 1;
        let Some((last_pose, last_odom)) = self.last else {
            self.add_key(scan, scan.odometry, points, None, false);
            self.last = Some((scan.odometry, scan.odometry));
            self.last_time = scan.time;
            return;
        };
        // With odometry, the constant-velocity guess is a second opinion
        // after a stale odometry reading (the last step as it was).
        // Without, it is the prediction, and standing still the second
        // opinion: a constant velocity carries a wrong match's turn into
        // the next scan, and a robot that stops must be found where it
        // stopped.
        let (predicted, steady) = if self.config.odometry {
            (
                last_pose.compose(&last_odom.between(&scan.odometry)),
                last_pose.compose(&self.last_step),
            )
        } else {
            (last_pose.compose(&self.steady_step(scan.time)), last_pose)
        };
        if !self.config.odometry {
            self.odometry_stale = true;
        }
        let found = self.match_local(&points, &predicted, &steady);
        let pose = match &found {
            Some(m) => {
                self.stats.matched += 1;
                m.pose
            }
            None => {
                self.stats.unmatched += 1;
                self.unmatched_since_key = true;
                predicted
            }
        };
        let step = last_pose.between(&pose);
        self.odometry_stale = !self.config.odometry || last_odom == scan.odometry;
        let key = self.graph.nodes.len() - 1;
        let rel = self.graph.nodes[key].between(&pose);
        let is_key = rel.position().length() >= self.config.key_distance_m
            || rel.theta.abs() >= self.config.key_angle_rad;
        if is_key {
            let weak = found
                .as_ref()
                .is_some_and(|m| m.score < self.config.min_match_score);
            self.add_key(scan, pose, points, Some(key), weak);
        } else {
            self.scans.push(ScanEntry {
                index: scan.index,
                time: scan.time,
                odometry: scan.odometry,
                key,
                relative: rel,
            });
        }
        let now = self.scan_pose(self.scans.len() - 1);
        self.last_step = step;
        self.last_dt = scan.time - self.last_time;
        self.last_time = scan.time;
        self.last = Some((now, scan.odometry));
    }

    /// The constant-velocity step to a scan at `time`: the last step, scaled
    /// by the time since the last scan over the time the last step took
    /// (when both are positive and within a factor of five of each other;
    /// otherwise the last step as it is — logs with broken timestamps).
    fn steady_step(&self, time: f64) -> Pose2 {
        let s = self.last_step;
        let (dt, before) = (time - self.last_time, self.last_dt);
        if !(dt > 0.0 && before > 0.0) {
            return s;
        }
        let ratio = dt / before;
        if !(0.2..=5.0).contains(&ratio) {
            return s;
        }
        Pose2::new(s.x * ratio, s.y * ratio, s.theta * ratio)
    }

    /// The local match: narrow window, then wide if needed; after a scan
    /// whose odometry did not change, also around the constant-velocity
    /// prediction `steady` if it is off the odometry's by more than the
    /// narrow window.
    fn match_local(
        &mut self,
        points: &[DVec2],
        predicted: &Pose2,
        steady: &Pose2,
    ) -> Option<ScanMatch> {
        let field = self.local.as_ref()?;
        let cfg = &self.config;
        let (found, wide) = local_match(field, cfg, points, predicted);
        self.stats.wide_searches += wide as usize;
        let d = predicted.between(steady);
        let apart =
            d.position().length() > cfg.narrow.linear_m || d.theta.abs() > cfg.narrow.angular_rad;
        if !cfg.velocity_prior || !self.odometry_stale || !apart {
            return found;
        }
        self.stats.velocity_searches += 1;
        let (other, wide) = local_match(field, cfg, points, steady);
        self.stats.wide_searches += wide as usize;
        match (found, other) {
            (Some(a), Some(b)) if b.score > a.score => {
                self.stats.velocity_wins += 1;
                Some(b)
            }
            (None, Some(b)) => {
                self.stats.velocity_wins += 1;
                Some(b)
            }
            (a, _) => a,
        }
    }

    /// Adds key `scan` at `pose`, linked to key `prev`; `weak`: its match
    /// scored under `min_match_score`.
    fn add_key(
        &mut self,
        scan: &LogScan,
        pose: Pose2,
        points: Vec<DVec2>,
        prev: Option<usize>,
        weak: bool,
    ) {
        let id = self.graph.nodes.len();
        self.graph.nodes.push(pose);
        if let Some(p) = prev {
            let z = self.graph.nodes[p].between(&pose);
            let (sm, sr) = if self.unmatched_since_key {
                (0.3, 5f64.to_radians())
            } else {
                (self.config.key_sigma_m, self.config.key_sigma_rad)
            };
            let mut edge = Edge::new(p, id, z, sm, sr);
            if !self.unmatched_since_key {
                if let Some(info) = self.key_edge_along_corridor(&pose, &points, sm, sr) {
                    edge.information = info;
                }
            }
            self.graph.edges.push(edge);
        }
        self.unmatched_since_key = false;
        self.key_points.push(points);
        self.weak_keys.push(weak);
        self.key_scan.push(scan.index);
        self.scans.push(ScanEntry {
            index: scan.index,
            time: scan.time,
            odometry: scan.odometry,
            key: id,
            relative: Pose2::IDENTITY,
        });
        self.stats.keys += 1;
        if self.config.close_loops && id.is_multiple_of(self.config.loop_every.max(1)) {
            self.try_close(id);
        }
        self.rebuild_local();
    }

    /// Without odometry, the information of a matched key edge ending at
    /// `pose` made loose along the weakest direction of the new key's
    /// `points` ([`key_edge_information`]); `None` with odometry.
    fn key_edge_along_corridor(
        &self,
        pose: &Pose2,
        points: &[DVec2],
        sigma_m: f64,
        sigma_rad: f64,
    ) -> Option<[[f64; 3]; 3]> {
        if self.config.odometry {
            return None;
        }
        key_edge_information(
            points,
            pose,
            sigma_m,
            sigma_rad,
            self.config.key_loosen_ratio,
        )
    }

    /// Rasterises the last `local_keys` key scans into the local map, but
    /// the weakly matched ones.
    fn rebuild_local(&mut self) {
        let n = self.graph.nodes.len();
        let from = n.saturating_sub(self.config.local_keys);
        let mut world = Vec::new();
        for k in from..n {
            // A weakly matched key, once another key follows it (see the
            // module doc).
            if self.weak_keys[k] && k + 1 < n {
                continue;
            }
            let f = self.graph.nodes[k].frame();
            world.extend(self.key_points[k].iter().map(|&p| f.to_parent(p)));
        }
        self.local = Some(field_from_points(
            &world,
            self.config.resolution_m,
            4,
            self.config.wide.linear_m + 1.0,
        ));
    }

    /// Looks for a closure of key `id`; accepts it (and a pending one) when
    /// two agree.
    fn try_close(&mut self, id: usize) {
        self.stats.closures_tried += 1;
        let links = self.grow_window(id).then(|| self.links());
        let Some(mut found) = find_closure_among(
            &self.graph.nodes,
            &self.key_points,
            id,
            self.config.resolution_m,
            &self.config.loops,
            links.as_deref(),
        ) else {
            return;
        };
        self.stats.closures_found += 1;
        if found.window.linear_m > self.config.loops.window.linear_m {
            self.grow_until = id + self.config.confirm_keys;
        }
        if found.score < self.config.far_min_score && self.beyond_base_window(&found) {
            self.stats.closures_far_weak += 1;
            return;
        }
        if self.config.loop_edge_reject && self.on_window_edge(&found) {
            self.stats.closures_on_edge += 1;
            return;
        }
        // Loose along the direction the match pins least (a corridor's).
        if self.config.loop_loosen_ratio > 1.0 {
            let loops = &self.config.loops;
            let fit = closure_fit(&self.graph.nodes, &self.key_points, &found, loops);
            if let Some(info) = loosened_along_weak(
                &self.graph.nodes,
                &found,
                &fit,
                loops.sigma_m,
                loops.sigma_rad,
                self.config.loop_loosen_ratio,
            ) {
                found.edge.information = info;
            }
        }
        let cfg = &self.config;
        self.pending
            .retain(|c| c.edge.to + cfg.confirm_keys >= id && c.edge.to != id);
        let agreeing = self.pending.iter().position(|c| {
            closures_agree(
                &self.graph.nodes,
                c,
                &found,
                self.config.confirm_m,
                self.config.confirm_rad,
            )
        });
        match agreeing {
            Some(k) => {
                let other = self.pending.remove(k);
                self.accept(vec![other, found]);
            }
            None => self.pending.push(found),
        }
    }

    /// Whether the try at key `id` searches the grown closure window
    /// (`grown_every`).
    fn grow_window(&self, id: usize) -> bool {
        let cfg = &self.config;
        cfg.loops.window_per_m > 0.0
            && ((id / cfg.loop_every.max(1)).is_multiple_of(cfg.grown_every.max(1))
                || id <= self.grow_until)
    }

    /// The accepted closures' keys, `(older, newer)`.
    fn links(&self) -> Vec<(usize, usize)> {
        self.closures
            .iter()
            .map(|c| (c.from_key, c.to_key))
            .collect()
    }

    /// Whether closure `c` moves its new key further than the fixed window
    /// (`loops.window`) would have reached: found only thanks to the reach
    /// grown with the path ([`closure_window`]).
    fn beyond_base_window(&self, c: &Closure) -> bool {
        let window = &self.config.loops.window;
        on_window_edge(&self.graph.nodes, c, window, 0.0, 0.0)
    }

    /// Whether closure `c`'s match lies on the edge of the window it was
    /// searched in (within two cells of a side, half a degree of the
    /// heading range).
    fn on_window_edge(&self, c: &Closure) -> bool {
        let res = self.config.resolution_m;
        on_window_edge(
            &self.graph.nodes,
            c,
            &c.window,
            2.0 * res,
            0.5f64.to_radians(),
        )
    }

    /// Adds confirmed closures, optimises, and undoes it all if a closure
    /// stays badly unsatisfied.
    fn accept(&mut self, closures: Vec<Closure>) {
        let edges: Vec<Edge> = closures.iter().map(|c| c.edge.clone()).collect();
        if !self
            .graph
            .try_closures(&edges, 10, None, self.config.max_closure_chi2)
        {
            self.stats.closures_rejected += closures.len();
            return;
        }
        for c in closures {
            self.closures.push(ClosureInfo {
                from_key: c.edge.from,
                to_key: c.edge.to,
                from_scan: self.key_scan[c.edge.from],
                to_scan: self.key_scan[c.edge.to],
                score: c.score,
            });
        }
        // The last scan's pose moved with its key.
        if let Some((_, odom)) = self.last {
            let now = self.scan_pose(self.scans.len() - 1);
            self.last = Some((now, odom));
        }
    }

    /// Final optimisation (the graph is already optimised after each
    /// accepted closure; this settles it), square walls, and the smoothing
    /// of every scan's pose (module doc, step 7). `scans`: the scans added,
    /// in the order added (others: no smoothing).
    pub fn finish(&mut self, scans: &[LogScan]) -> Result<(), String> {
        if !self.closures.is_empty() {
            self.graph.optimise(20)?;
        }
        if let Some(m) = &self.config.manhattan {
            let directions: Vec<Option<f64>> = self
                .key_points
                .iter()
                .map(|p| scan_direction(p, m).map(|(d, _)| d))
                .collect();
            self.stats.square_keys = settle_priors(&mut self.graph, &directions, m, |g| {
                g.optimise(20).map(|_| ())
            })?;
        }
        let before = self.poses();
        let placements = self.smooth(scans);
        self.fuse_odometry(&placements, &before);
        Ok(())
    }

    /// Step 7 of the module doc: each scan aligned by ICP on the keys
    /// around its own, its pose relative to its key replaced where the
    /// alignment holds. Returns each scan's placement (`None`: kept its
    /// pose; all `None` without smoothing).
    fn smooth(&mut self, scans: &[LogScan]) -> Vec<Option<Placement>> {
        let mut placements: Vec<Option<Placement>> = vec![None; self.scans.len()];
        let half = self.config.smooth_keys;
        if half == 0 || scans.len() != self.scans.len() {
            return placements;
        }
        let cfg = &self.config;
        let n = self.graph.nodes.len();
        // Each key's surface normals (robot frame), once.
        let key_normals: Vec<Vec<Option<DVec2>>> = self
            .key_points
            .iter()
            .map(|p| scan_normals_within(p, NORMAL_RADIUS_M))
            .collect();
        // The scans of one key follow one another.
        let mut start = 0;
        while start < self.scans.len() {
            let key = self.scans[start].key;
            let end = start
                + self.scans[start..]
                    .iter()
                    .take_while(|e| e.key == key)
                    .count();
            let (mut points, mut normals) = (Vec::new(), Vec::new());
            let (lo, hi) = (key.saturating_sub(half), (key + half + 1).min(n));
            for (k, own_normals) in key_normals.iter().enumerate().take(hi).skip(lo) {
                // Its own key's scan, and weakly matched keys (as for the
                // local map), take no part.
                if k == key || self.weak_keys[k] {
                    continue;
                }
                let f = self.graph.nodes[k].frame();
                points.extend(self.key_points[k].iter().map(|&p| f.to_parent(p)));
                normals.extend(own_normals.iter().map(|n| n.map(|n| f.rotate(n))));
            }
            let target = IcpTarget::new(&points, &normals, cfg.smooth_radius_m);
            let node = self.graph.nodes[key];
            for (k, (entry, scan)) in self.scans[start..end]
                .iter_mut()
                .zip(&scans[start..end])
                .enumerate()
            {
                let points = points_every(scan, cfg.match_range_m, cfg.smooth_spacing_m);
                let now = node.compose(&entry.relative);
                let fit = target.align(&points, &now, cfg.smooth_huber_m, cfg.smooth_iterations);
                if fit.associated * 2 >= points.len()
                    && within(&now, &fit.pose, cfg.smooth_max_move_m, cfg)
                {
                    entry.relative = node.between(&fit.pose);
                    placements[start + k] = Some(Placement {
                        pose: fit.pose,
                        information: fit.information,
                    });
                }
            }
            start = end;
        }
        placements
    }

    /// Step 8 of the module doc: the placements fused with the odometry,
    /// each scan's pose relative to its key replaced where the fused pose
    /// lies within `fusion_max_move_m` of where the replay left it
    /// (`before`).
    fn fuse_odometry(&mut self, placements: &[Option<Placement>], before: &[Pose2]) {
        let cfg = &self.config;
        if !(cfg.smooth_odometry && cfg.odometry) || placements.iter().all(Option::is_none) {
            return;
        }
        let odometry: Vec<Pose2> = self.scans.iter().map(|e| e.odometry).collect();
        let Some(noise) = measure_noise(placements, &odometry) else {
            return;
        };
        self.stats.fusion_noise = Some(noise);
        let fused = fuse(&self.poses(), placements, &odometry, &noise);
        for ((entry, pose), was) in self.scans.iter_mut().zip(fused).zip(before) {
            if within(was, &pose, cfg.fusion_max_move_m, cfg) {
                entry.relative = self.graph.nodes[entry.key].between(&pose);
            }
        }
    }

    /// The current estimate of scan `k` (position in [`LogSlam::scans`]).
    pub fn scan_pose(&self, k: usize) -> Pose2 {
        let s = &self.scans[k];
        self.graph.nodes[s.key].compose(&s.relative)
    }

    /// Key `i`'s scan points (robot frame, thinned as matched).
    pub fn key_points(&self, i: usize) -> &[DVec2] {
        &self.key_points[i]
    }

    /// Every scan's current estimate, in the order added.
    pub fn poses(&self) -> Vec<Pose2> {
        (0..self.scans.len()).map(|k| self.scan_pose(k)).collect()
    }

    /// Draws the occupancy grid of `scans` (the same scans, in the same
    /// order, as were added) at the current estimates, at the finest of
    /// `resolution_m`, twice it, four times it, … at which the whole tour
    /// fits in [`MAP_MAX_CELLS`] ([`map_resolution`]): a campus toured
    /// outdoors is mapped whole at 10 cm rather than cut off at 5 cm.
    pub fn build_map(&self, scans: &[LogScan]) -> OccupancyGrid {
        self.build_map_at(scans, &self.poses())
    }

    /// Draws the occupancy grid of `scans` as [`LogSlam::build_map`] does,
    /// but at `poses` (one per scan, in the same order): the trajectory as
    /// the SLAM had it at an earlier moment of the replay. Draws as many
    /// scans as both lists hold.
    pub fn build_map_at(&self, scans: &[LogScan], poses: &[Pose2]) -> OccupancyGrid {
        let reach = self.config.match_range_m.max(self.config.free_range_m);
        let count = poses.len().min(scans.len());
        let positions = poses[..count].iter().map(|p| p.position());
        let config = GridConfig {
            resolution_m: map_resolution(self.config.resolution_m, positions, reach, MAP_MAX_CELLS),
            max_cells: MAP_MAX_CELLS,
            ..GridConfig::default()
        };
        OccupancyGrid::drawn_at(config, poses[..count].iter().copied(), |grid, k, pose| {
            let scan = &scans[k];
            let c = pose.position();
            grid.ensure_contains(c - reach, c + reach);
            let laser = pose.compose(&scan.laser_offset);
            let from = laser.position();
            for (i, &r) in scan.ranges.iter().enumerate() {
                let r = r as f64;
                if r.is_nan() {
                    // No reading at all (a ROS range below range_min, or
                    // NaN): neither a wall nor free space.
                    continue;
                }
                let dir = DVec2::from_angle(wrap_angle(laser.theta + scan.bearing(i)));
                if scan.no_return(i) || r > self.config.match_range_m {
                    grid.integrate_beam(from, from + dir * self.config.free_range_m, false);
                } else {
                    grid.integrate_beam(from, from + dir * r, true);
                }
            }
        })
    }
}

/// Whether `to` lies within `max_move_m` and the smoothing's turn of `from`.
fn within(from: &Pose2, to: &Pose2, max_move_m: f64, cfg: &LogSlamConfig) -> bool {
    let d = from.between(to);
    d.position().length() <= max_move_m && d.theta.abs() <= cfg.smooth_max_turn_rad
}

/// The neighbourhood of a key's point its surface normal is fitted over
/// (m): a scan thinned to a point every 10 cm needs more than a full one.
const NORMAL_RADIUS_M: f64 = 0.35;

/// Cells a log's map may hold: 16 Mi, a 205 m square at 5 cm (16 MB).
pub const MAP_MAX_CELLS: usize = 1 << 24;

/// The finest of `base`, 2·`base`, 4·`base`, … (at most 64·`base`) at which
/// a grid covering every one of `positions` plus `reach` around it, with
/// the grid's growth steps on every side, holds at most `max_cells` cells.
pub fn map_resolution(
    base: f64,
    positions: impl Iterator<Item = DVec2>,
    reach: f64,
    max_cells: usize,
) -> f64 {
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for p in positions {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    if !(lo.x <= hi.x && lo.y <= hi.y) {
        return base;
    }
    let size = hi - lo + 2.0 * reach;
    let margin = 2.0 * GROW_STEP_CELLS as f64;
    let mut resolution = base;
    for _ in 0..6 {
        let cells = (size.x / resolution + margin) * (size.y / resolution + margin);
        if cells <= max_cells as f64 {
            break;
        }
        resolution *= 2.0;
    }
    resolution
}
