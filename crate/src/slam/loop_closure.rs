//! # Loop closure: matching a scan against an older part of the map
//!
//! Scan-to-map matching against the last few key scans keeps a trajectory
//! locally straight, but its small errors add up: after a tour of a
//! building the robot comes back to a corridor it mapped long ago with its
//! estimate off by a metre and a few degrees, and mapping on would draw the
//! corridor twice. A *loop closure* notices the return and says how the new
//! scan lies relative to the old ones; the pose graph ([`super::posegraph`])
//! then spreads the accumulated error over the whole loop.
//!
//! This follows Karto / slam_toolbox (Konolige et al., "Efficient sparse pose
//! adjustment for 2D mapping", IROS 2010) and Cartographer (Hess, Kohler,
//! Rapp, Andor, "Real-time loop closure in 2D LIDAR SLAM", ICRA 2016):
//!
//! 1. **Candidates**: key scans older than the local map (at least
//!    `min_key_gap` keys back) whose estimated position lies within
//!    `search_radius_m` of the new key scan's. The nearest one is the centre
//!    of the candidate region, the visit the new scan is matched against
//!    ([`find_closure`]; [`find_closure_among`] with a reach that grows with
//!    the path, [`closure_window`]).
//! 2. **Match**: the key scans around that centre (`submap_half` either side,
//!    consecutive, so they are consistent among themselves) are rasterised
//!    into Olson's tables ([`super::multires`]), and the new scan is searched
//!    in a wide window (`window`) around its current estimate: wide enough
//!    for the drift since, exact thanks to branch and bound.
//! 3. **Accept**: only a match whose mean field value reaches `min_score`
//!    (most points on mapped walls) becomes an edge; the driver
//!    ([`super::logs::logslam`]) then optimises the graph and keeps the edge only if
//!    the result is consistent (see there).

use super::degeneracy::scan_normals_within;
use super::icp::{IcpFit, IcpTarget};
use super::match_covariance::edge_information;
use super::multires::{field_covering, field_from_points, match_scan, rival_score, Window};
use super::posegraph::Edge;
use crate::geom::{wrap_angle, Pose2};
use glam::DVec2;
use std::ops::RangeInclusive;

/// Settings of the loop-closure search.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LoopConfig {
    pub search_radius_m: f64,
    pub min_key_gap: usize,
    pub submap_half: usize,
    pub window: Window,
    /// How much the window's reach (and the candidates' radius with it)
    /// grows per metre the estimate has travelled since the candidate key
    /// ([`closure_window`]): 0 keeps `window` for every candidate.
    pub window_per_m: f64,
    /// The reach it grows to at most (m).
    pub max_window_m: f64,
    /// A closure found in a grown window must beat its strongest rival
    /// (the best pose more than [`RIVAL_EXCLUDE_M`] from it) by this
    /// ratio: the rival's search score at most `unique_ratio` times its
    /// own. A corridor whose doors repeat offers a rival as good a door
    /// further on.
    pub unique_ratio: f64,
    pub min_score: f64,
    /// Standard deviations given to an accepted closure's edge.
    pub sigma_m: f64,
    pub sigma_rad: f64,
}

impl Default for LoopConfig {
    fn default() -> Self {
        LoopConfig {
            search_radius_m: 4.0,
            min_key_gap: 40,
            submap_half: 6,
            window: Window {
                linear_m: 1.5,
                angular_rad: 12f64.to_radians(),
            },
            window_per_m: 0.0,
            max_window_m: 8.0,
            unique_ratio: 0.9,
            min_score: 0.55,
            sigma_m: 0.05,
            sigma_rad: 1f64.to_radians(),
        }
    }
}

/// A loop closure found: the edge, its match score and the window it was
/// found in (the fixed one or one grown with the path, [`closure_window`]).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Closure {
    pub edge: Edge,
    pub score: f64,
    pub window: Window,
}

/// Looks for a closure of key `i` (pose `nodes[i]`, points `key_points[i]`
/// in its robot frame) against the older keys of the nearest earlier pass
/// through its place, in the fixed window ([`find_closure_among`] without
/// links). The edge's σ is `cfg.sigma_m` / `cfg.sigma_rad`.
pub fn find_closure(
    nodes: &[Pose2],
    key_points: &[Vec<DVec2>],
    i: usize,
    resolution_m: f64,
    cfg: &LoopConfig,
) -> Option<Closure> {
    find_closure_among(nodes, key_points, i, resolution_m, cfg, None)
}

/// [`find_closure`] in a window that may grow with the path: `links` are
/// the closures accepted so far (`(older key, newer key)`); with a window
/// that grows with the path ([`closure_window`]), the path is the shortest
/// through them ([`paths_to`]). `None` searches the fixed window only,
/// whatever `cfg.window_per_m` says: the driver grows the window on some
/// tries only.
pub fn find_closure_among(
    nodes: &[Pose2],
    key_points: &[Vec<DVec2>],
    i: usize,
    resolution_m: f64,
    cfg: &LoopConfig,
    links: Option<&[(usize, usize)]>,
) -> Option<Closure> {
    // The path from each key to key i, only when the reach grows with it.
    let paths = match links {
        Some(links) if cfg.window_per_m > 0.0 => paths_to(nodes, links, i),
        _ => Vec::new(),
    };
    let path = |j: usize| paths.get(j).copied().unwrap_or(0.0);
    let centre = nearest_candidate(nodes, i, cfg, &paths)?;
    match_visit(
        nodes,
        key_points,
        i,
        centre,
        path(centre),
        resolution_m,
        cfg,
    )
}

/// The candidate key nearest key `i`'s estimate, the centre of the
/// visit a closure is matched against: at least `min_key_gap` keys back,
/// within `search_radius_m` of it, a radius grown with the path `paths[j]`
/// from key `j` ([`paths_to`]; empty: the radius does not grow). Of keys
/// equally near, the earliest.
fn nearest_candidate(nodes: &[Pose2], i: usize, cfg: &LoopConfig, paths: &[f64]) -> Option<usize> {
    let newest_old = i.checked_sub(cfg.min_key_gap)?;
    let here = nodes[i].position();
    let widening = |j: usize| paths.get(j).map_or(0.0, |&p| widening_m(cfg, p));
    (0..=newest_old)
        .map(|j| (j, nodes[j].position().distance(here)))
        .filter(|&(j, d)| d <= cfg.search_radius_m + widening(j))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(j, _)| j)
}

/// The shortest path (m) from each key `j ≤ i` to key `i` along the chain
/// of keys (the distance the estimate moves from key to key) and across
/// the accepted closures `links` (the distance between their two keys'
/// estimates), by Dijkstra's algorithm. Without links it is the path the
/// estimate travelled since key `j`; with them, a place already tied to
/// the newer part of the tour is near it however long ago it was first
/// seen, as its drift has been taken out.
pub fn paths_to(nodes: &[Pose2], links: &[(usize, usize)], i: usize) -> Vec<f64> {
    let n = i + 1;
    let mut across: Vec<Vec<usize>> = vec![Vec::new(); n];
    for &(a, b) in links {
        if a < n && b < n && a != b {
            across[a].push(b);
            across[b].push(a);
        }
    }
    let mut dist = vec![f64::INFINITY; n];
    let mut done = vec![false; n];
    // (distance, key) ordered by distance, nearest first.
    let mut queue = std::collections::BinaryHeap::new();
    dist[i] = 0.0;
    queue.push(std::cmp::Reverse((Ordered(0.0), i)));
    while let Some(std::cmp::Reverse((Ordered(d), k))) = queue.pop() {
        if done[k] {
            continue;
        }
        done[k] = true;
        let chain = [k.checked_sub(1), (k + 1 < n).then_some(k + 1)];
        let neighbours = chain.into_iter().flatten().chain(across[k].iter().copied());
        for m in neighbours {
            let step = nodes[m].position().distance(nodes[k].position());
            if d + step < dist[m] {
                dist[m] = d + step;
                queue.push(std::cmp::Reverse((Ordered(d + step), m)));
            }
        }
    }
    dist
}

/// An `f64` ordered by `total_cmp`, for the queue of [`paths_to`].
#[derive(Clone, Copy, PartialEq)]
struct Ordered(f64);

impl Eq for Ordered {}

impl PartialOrd for Ordered {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Ordered {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// How much further than `cfg.window` a closure search reaches after the
/// estimate has travelled `path_m` since the candidate key.
fn widening_m(cfg: &LoopConfig, path_m: f64) -> f64 {
    let reach = (cfg.window.linear_m + cfg.window_per_m * path_m).min(cfg.max_window_m);
    (reach - cfg.window.linear_m).max(0.0)
}

/// The window a closure onto a visit `path_m` along the tour from the new
/// key ([`paths_to`]) is searched in: `cfg.window`, its reach grown by
/// `window_per_m` for every metre of that path, up to `max_window_m`.
///
/// The drift a revisit must undo grows with the path since the place was
/// last seen: on the shared logs it stays within a few decimetres, but on
/// a convention centre's hall (the Acapulco log, 812 m of path) it reaches
/// metres, far outside a fixed 1.5 m window. Karto sizes its loop search
/// by the covariance accumulated along the chain; a reach proportional to
/// the path is that bound for drift that grows with distance. The path is
/// the shortest through the closures accepted so far: a place already tied
/// to the newer part of the tour has had its drift taken out, and the
/// search there stays near the fixed window, which keeps the replays' time
/// near that of a fixed reach.
///
/// The search takes the fixed window first and the grown one only where
/// the fixed one finds nothing good enough, and a match found there must
/// have no rival: no pose more than [`RIVAL_EXCLUDE_M`] from it may score
/// `unique_ratio` of its score (a corridor's doors repeat, and a window
/// that reaches several metres along one finds the wrong door as readily
/// as the right one). `LoopConfig::default` keeps the growth off (0 per
/// metre), as the simulated robots' back end does. A replayed log's driver
/// ([`super::logs::logslam`]) turns it on (0.03 per metre, 16 m at most)
/// and grows it on one try in four only (`grown_every`; `links: None` to
/// [`find_closure_among`] on the other tries): grown on every try, the
/// replays are several times slower for little more (BENCHMARKS.md).
pub fn closure_window(cfg: &LoopConfig, path_m: f64) -> Window {
    Window {
        linear_m: cfg.window.linear_m + widening_m(cfg, path_m),
        angular_rad: cfg.window.angular_rad,
    }
}

/// The keys of the visit around `centre` that key `i` is matched against:
/// `submap_half` either side, none of the last `min_key_gap` before `i`.
fn visit_keys(i: usize, centre: usize, cfg: &LoopConfig) -> RangeInclusive<usize> {
    let lo = centre.saturating_sub(cfg.submap_half);
    let hi = (centre + cfg.submap_half).min(i.saturating_sub(cfg.min_key_gap));
    lo..=hi
}

/// Whether closure `c`'s match lies on the edge of the search `window`: a
/// box in the world frame and a heading range around the new key's pose in
/// `nodes`, less `margin_m` and `margin_rad`. A match pressed against the
/// edge is where the search ran out, not where the scan fits.
pub(super) fn on_window_edge(
    nodes: &[Pose2],
    c: &Closure,
    window: &Window,
    margin_m: f64,
    margin_rad: f64,
) -> bool {
    let found = nodes[c.edge.from].compose(&c.edge.measurement);
    let here = &nodes[c.edge.to];
    let d = found.position() - here.position();
    d.x.abs() > window.linear_m - margin_m
        || d.y.abs() > window.linear_m - margin_m
        || wrap_angle(found.theta - here.theta).abs() > window.angular_rad - margin_rad
}

/// Matches key `i` against the key scans around `centre`, `path_m` along
/// the tour from it ([`closure_window`]).
fn match_visit(
    nodes: &[Pose2],
    key_points: &[Vec<DVec2>],
    i: usize,
    centre: usize,
    path_m: f64,
    resolution_m: f64,
    cfg: &LoopConfig,
) -> Option<Closure> {
    let mut world = Vec::new();
    for j in visit_keys(i, centre, cfg) {
        let f = nodes[j].frame();
        world.extend(key_points[j].iter().map(|&p| f.to_parent(p)));
    }
    // The fixed window first; the grown one (if any) only where it finds
    // nothing good enough, and then only a match without a rival: the
    // grown reach adds closures, never replaces one the fixed window finds.
    let points = &key_points[i];
    let field = field_from_points(&world, resolution_m, 8, cfg.window.linear_m + 1.0);
    let found = match_scan(&field, points, &nodes[i], &cfg.window);
    let (m, window) = match found.filter(|m| m.score >= cfg.min_score) {
        Some(m) => (m, cfg.window.clone()),
        None => {
            let window = closure_window(cfg, path_m);
            if window.linear_m <= cfg.window.linear_m {
                return None;
            }
            // Wide enough for the new scan at every pose searched: the
            // search then reads its tables without bounds tests (on the
            // fixed window's smaller field that gains nothing).
            let reach = points.iter().map(|p| p.length()).fold(0.0, f64::max);
            let around = Some((nodes[i].position(), reach));
            let margin = window.linear_m + 1.0;
            let field = field_covering(&world, resolution_m, 8, margin, around);
            let m = match_scan(&field, points, &nodes[i], &window)?;
            if m.score < cfg.min_score {
                return None;
            }
            let rival = rival_score(&field, points, &nodes[i], &window, &m.pose, RIVAL_EXCLUDE_M);
            if rival > cfg.unique_ratio * m.search_score {
                return None;
            }
            (m, window)
        }
    };
    let mut edge = Edge::new(
        centre,
        i,
        nodes[centre].between(&m.pose),
        cfg.sigma_m,
        cfg.sigma_rad,
    );
    edge.loop_closure = true;
    Some(Closure {
        edge,
        score: m.score,
        window,
    })
}

/// How far from a closure's pose its rivals are looked for (m): beyond
/// the width of one peak of the search's response, within a corridor's
/// door spacing.
pub const RIVAL_EXCLUDE_M: f64 = 0.5;

/// Neighbourhood of a thinned key scan's point for its normal, and the
/// association radius and Huber threshold of [`closure_fit`] (m).
const PIN_NORMAL_RADIUS_M: f64 = 0.35;
const PIN_RADIUS_M: f64 = 0.2;
const PIN_HUBER_M: f64 = 0.02;

/// How well closure `c`'s match pins its new key: the point-to-line
/// information `Σ w n nᵀ` of the new key's points laid at the matched pose
/// onto the visit's scans (each point measured along the normal of the
/// nearest visit point within 0.2 m; [`super::icp`]), with its strong and
/// weak directions. `weak` is in points' worth: a room or a corner gives
/// tens; a corridor whose end walls and doors are out of sight gives
/// nearly nothing along it, and a match there may sit anywhere along it.
pub fn closure_fit(
    nodes: &[Pose2],
    key_points: &[Vec<DVec2>],
    c: &Closure,
    cfg: &LoopConfig,
) -> IcpFit {
    let (i, centre) = (c.edge.to, c.edge.from);
    let (mut points, mut normals) = (Vec::new(), Vec::new());
    for j in visit_keys(i, centre, cfg) {
        let f = nodes[j].frame();
        points.extend(key_points[j].iter().map(|&p| f.to_parent(p)));
        normals.extend(
            scan_normals_within(&key_points[j], PIN_NORMAL_RADIUS_M)
                .into_iter()
                .map(|n| n.map(|n| f.rotate(n))),
        );
    }
    let found = nodes[centre].compose(&c.edge.measurement);
    // One pass: the information at the matched pose, not a refined one.
    IcpTarget::new(&points, &normals, PIN_RADIUS_M).align(&key_points[i], &found, PIN_HUBER_M, 1)
}

/// Closure `c`'s edge made loose along its weak direction: the variance
/// `sigma_m²` across it, `sigma_m² · min(strong / weak, max_ratio)` along
/// it, heading `sigma_rad²`, as the edge's information.
pub fn loosened_along_weak(
    nodes: &[Pose2],
    c: &Closure,
    fit: &IcpFit,
    sigma_m: f64,
    sigma_rad: f64,
    max_ratio: f64,
) -> Option<[[f64; 3]; 3]> {
    let ratio = (fit.strong / fit.weak.max(1e-9)).clamp(1.0, max_ratio);
    let found = nodes[c.edge.from].compose(&c.edge.measurement);
    loose_along(fit.weak_direction, ratio, sigma_m, sigma_rad, found.theta)
}

/// The information of an edge ending at a node with heading `theta_rad`
/// whose position is `ratio` times as unsure (in variance) along the
/// world-frame unit vector `v` as across it: the variance `sigma_m²`
/// across, `sigma_m² · ratio` along, heading `sigma_rad²`.
pub fn loose_along(
    v: DVec2,
    ratio: f64,
    sigma_m: f64,
    sigma_rad: f64,
    theta_rad: f64,
) -> Option<[[f64; 3]; 3]> {
    let s2 = sigma_m * sigma_m;
    let k = s2 * (ratio.max(1.0) - 1.0);
    let cov = [
        [s2 + k * v.x * v.x, k * v.x * v.y, 0.0],
        [k * v.x * v.y, s2 + k * v.y * v.y, 0.0],
        [0.0, 0.0, sigma_rad * sigma_rad],
    ];
    edge_information(&cov, theta_rad)
}

/// Pairwise consistency of two closures `a` and `b` (Olson, "Recognizing
/// places using spectrally clustered local matches", RAS 2009): the cycle
/// *old_a → new_a → new_b → old_b → old_a*, made of the two closures and the
/// relative poses of `nodes` along the two stretches between their ends
/// (each locally accurate), must compose to within `max_m` and `max_rad` of
/// the identity.
pub fn closures_agree(nodes: &[Pose2], a: &Closure, b: &Closure, max_m: f64, max_rad: f64) -> bool {
    let cycle = a
        .edge
        .measurement
        .compose(&nodes[a.edge.to].between(&nodes[b.edge.to]))
        .compose(&b.edge.measurement.inverse())
        .compose(&nodes[b.edge.from].between(&nodes[a.edge.from]));
    cycle.position().length() <= max_m && cycle.theta.abs() <= max_rad
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::slam::scenes;

    /// Keys every 0.3 m along a path at heading 0 through `walls`, scanned
    /// to `range_m`, and the closure of the last key onto the first at its
    /// true relative pose.
    fn closure_along(
        walls: &[(DVec2, DVec2)],
        from: DVec2,
        range_m: f64,
    ) -> (Vec<Pose2>, Vec<Vec<DVec2>>, Closure, LoopConfig) {
        let cfg = LoopConfig {
            min_key_gap: 10,
            submap_half: 2,
            ..LoopConfig::default()
        };
        // Out along the path, and back to the start facing the same way.
        let mut nodes: Vec<Pose2> = (0..12)
            .map(|k| Pose2::new(from.x + 0.3 * k as f64, from.y, 0.0))
            .collect();
        nodes.push(Pose2::new(from.x + 0.05, from.y + 0.02, 0.01));
        let key_points = nodes
            .iter()
            .map(|p| scenes::scan(p, walls, range_m))
            .collect();
        let i = nodes.len() - 1;
        let edge = Edge::new(0, i, nodes[0].between(&nodes[i]), 0.05, 0.02);
        let window = cfg.window.clone();
        let closure = Closure {
            edge,
            score: 1.0,
            window,
        };
        (nodes, key_points, closure, cfg)
    }

    /// A room pins a closure in every direction: tens of points' worth
    /// along its weakest one. In a corridor whose ends are out of range
    /// nothing pins it along the corridor.
    #[test]
    fn a_closure_in_a_corridor_is_not_pinned_along_it() {
        let (nodes, points, c, cfg) = closure_along(&scenes::room(), DVec2::new(2.0, 2.5), 20.0);
        let room = closure_fit(&nodes, &points, &c, &cfg).weak;
        let (nodes, points, c, cfg) =
            closure_along(&scenes::corridor(), DVec2::new(-2.0, 1.0), 8.0);
        let corridor = closure_fit(&nodes, &points, &c, &cfg).weak;
        assert!(room > 20.0, "room: {room}");
        assert!(corridor < 1.0, "corridor: {corridor}");
    }

    /// Loosened, a corridor's closure keeps its σ across the corridor and
    /// heading, and takes `max_ratio` times the variance along it (here the
    /// keys' frames are the world's: the corridor runs along x). A room's
    /// keeps nearly the σ it had in every direction.
    #[test]
    fn a_corridor_closure_is_loose_along_the_corridor_only() {
        let (sigma_m, sigma_rad) = (0.05, 1f64.to_radians());
        let info = |walls: &[(DVec2, DVec2)], from: DVec2, range_m: f64| {
            let (nodes, points, c, cfg) = closure_along(walls, from, range_m);
            let fit = closure_fit(&nodes, &points, &c, &cfg);
            loosened_along_weak(&nodes, &c, &fit, sigma_m, sigma_rad, 10.0).unwrap()
        };
        let corridor = info(&scenes::corridor(), DVec2::new(-2.0, 1.0), 8.0);
        let nominal = 1.0 / (sigma_m * sigma_m);
        // The closing key is turned by 0.01 rad: its frame is nearly the world's.
        assert!(
            (corridor[0][0] - nominal / 10.0).abs() < 0.01 * nominal,
            "{corridor:?}"
        );
        assert!(
            (corridor[1][1] - nominal).abs() < 0.01 * nominal,
            "{corridor:?}"
        );
        assert!((corridor[2][2] - 1.0 / (sigma_rad * sigma_rad)).abs() < 1e-6 * corridor[2][2]);
        let room = info(&scenes::room(), DVec2::new(2.0, 2.5), 20.0);
        for a in 0..2 {
            assert!(
                room[a][a] > 0.5 * nominal && room[a][a] <= nominal * 1.001,
                "{room:?}"
            );
        }
    }

    /// The window grows by `window_per_m` for each metre the estimate
    /// travelled from the candidate to the new key, up to `max_window_m`;
    /// off (0 per metre), it is the fixed window.
    #[test]
    fn the_closure_window_grows_with_the_path_since_the_candidate() {
        // Keys 2 m apart along x: 10 keys apart is 20 m of path.
        let nodes: Vec<Pose2> = (0..200)
            .map(|k| Pose2::new(2.0 * k as f64, 0.0, 0.0))
            .collect();
        let cfg = LoopConfig {
            window_per_m: 0.03,
            max_window_m: 8.0,
            ..LoopConfig::default()
        };
        let reach = |centre: usize, i: usize| {
            closure_window(&cfg, paths_to(&nodes, &[], i)[centre]).linear_m
        };
        assert!((reach(0, 10) - (1.5 + 0.03 * 20.0)).abs() < 1e-12);
        assert!((reach(5, 55) - (1.5 + 0.03 * 100.0)).abs() < 1e-12);
        assert_eq!(reach(0, 199), 8.0);
        let fixed = LoopConfig::default();
        assert_eq!(closure_window(&fixed, 398.0).linear_m, 1.5);
        assert_eq!(
            closure_window(&cfg, 398.0).angular_rad,
            fixed.window.angular_rad
        );
    }

    /// The path to a key runs along the chain, or across an accepted
    /// closure where that is shorter: a tour out along a corridor and back
    /// beside it, tied once near its start.
    /// A room left and come back to after about 100 m of path, the
    /// estimate 2.5 m off: the window grown with the path (reach 4 m)
    /// finds the true pose; without the accepted closures' list
    /// (`links: None`, a try the driver does not grow) the search is the
    /// fixed window's, exactly as with the growth switched off.
    #[test]
    fn a_grown_window_reaches_a_revisit_the_fixed_one_cannot() {
        let walls = scenes::room();
        // The first visit along the room, then keys far outside it.
        let mut nodes: Vec<Pose2> = (0..12)
            .map(|k| Pose2::new(2.0 + 0.3 * k as f64, 3.0, 0.0))
            .collect();
        nodes.extend((0..48).map(|k| Pose2::new(30.0 + 0.5 * k as f64, 3.0, 0.0)));
        let truth = Pose2::new(2.6, 3.1, 0.0);
        nodes.push(Pose2::new(truth.x + 2.5, truth.y + 0.4, 0.0));
        let i = nodes.len() - 1;
        let mut key_points: Vec<Vec<DVec2>> = nodes
            .iter()
            .map(|p| scenes::scan(p, &walls, 10.0))
            .collect();
        key_points[i] = scenes::scan(&truth, &walls, 10.0);
        let cfg = LoopConfig {
            min_key_gap: 10,
            submap_half: 2,
            window: Window {
                linear_m: 1.5,
                angular_rad: 3f64.to_radians(),
            },
            window_per_m: 0.03,
            max_window_m: 4.0,
            ..LoopConfig::default()
        };
        let find = |cfg: &LoopConfig, links: Option<&[(usize, usize)]>| {
            find_closure_among(&nodes, &key_points, i, 0.05, cfg, links)
        };
        let grown = find(&cfg, Some(&[])).expect("a closure in the grown window");
        assert_eq!(grown.window.linear_m, 4.0);
        let found = nodes[grown.edge.from].compose(&grown.edge.measurement);
        assert!(
            found.position().distance(truth.position()) < 0.1,
            "{found:?}"
        );
        assert!(wrap_angle(found.theta - truth.theta).abs() < 0.5f64.to_radians());
        let fixed = LoopConfig {
            window_per_m: 0.0,
            ..cfg.clone()
        };
        let not_grown = find(&cfg, None);
        assert_eq!(not_grown, find(&fixed, Some(&[])));
        assert!(not_grown.is_none_or(|c| c.window.linear_m == 1.5));
    }

    #[test]
    fn paths_run_along_the_chain_or_across_a_closure() {
        // Keys 0–5 out along y = 0, 1 m apart; keys 6–10 back along y = 0.5.
        let nodes: Vec<Pose2> = (0..=10)
            .map(|k| {
                if k <= 5 {
                    Pose2::new(k as f64, 0.0, 0.0)
                } else {
                    Pose2::new((10 - k) as f64, 0.5, 0.0)
                }
            })
            .collect();
        let turn = 1.25f64.sqrt();
        let chain = paths_to(&nodes, &[], 10);
        assert!((chain[0] - (9.0 + turn)).abs() < 1e-12, "{}", chain[0]);
        assert!((chain[5] - (4.0 + turn)).abs() < 1e-12, "{}", chain[5]);
        assert_eq!(chain[10], 0.0);
        // Key 1 tied to key 9 (0.5 m apart): key 0 is 1 + 0.5 + 1 m away,
        // key 3 1 + 0.5 + 2 m.
        let tied = paths_to(&nodes, &[(1, 9)], 10);
        assert!((tied[0] - 2.5).abs() < 1e-12, "{}", tied[0]);
        assert!((tied[3] - 3.5).abs() < 1e-12, "{}", tied[3]);
        // Key 5 is still nearer along the chain (5.118 m against 5.5 m).
        assert!((tied[5] - (4.0 + turn)).abs() < 1e-12, "{}", tied[5]);
        // Keys after `i` are not part of its paths.
        assert_eq!(paths_to(&nodes, &[(1, 9)], 6).len(), 7);
    }
}
