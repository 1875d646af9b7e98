//! # Square walls: a heading prior for rectilinear buildings
//!
//! A pose graph knows only relative poses. Between loop closures its keys
//! hang on a chain of scan matches, and the chain's heading wanders: each
//! match is good to a tenth of a degree, but a local map of a few metres
//! is drawn with the very heading it is meant to hold, so a few tenths of
//! a degree come and go over tens of metres (on the real logs, about 0.45°
//! by twenty scans; docs/history/issue-21-real-laser-logs.md, round 15). Across a building that is
//! decimetres.
//!
//! Most buildings are built square: their walls run in two directions at
//! right angles. Nguyen, Harati, Martinelli, Siegwart and Tomatis
//! ("Orthogonal SLAM: a step toward lightweight indoor autonomous
//! navigation", IROS 2006) use that to take the heading out of the
//! estimation altogether. Here it is a soft prior, and only where the scans
//! say it holds:
//!
//! 1. **A scan's own direction.** Each key scan's surface normals
//!    ([`super::degeneracy::scan_normals_within`]) are folded modulo 90°,
//!    so a wall and its perpendicular vote alike, and the strongest fold
//!    (a histogram of half-degree bins, each vote spread over ±`window`) is
//!    refined by the mean of the votes within `window` of it, on the circle
//!    of four times the angle. The key is *square* if at least `min_share`
//!    of its normals, and `min_normals` of them, lie within `window` of
//!    that direction.
//! 2. **The building's direction.** Every square key's direction in the
//!    world (its heading plus its scan's direction) is a vote for the
//!    building's, found as a scan's is from its normals, with the same
//!    `window`. It is measured, never assumed to be the map's x axis, and
//!    neither a wing built at an angle nor a stretch of keys turned by
//!    drift pulls it.
//! 3. **The prior.** A square key whose world direction lies within `gate`
//!    of the building's gets a heading-only edge from the anchored first
//!    node, asking its heading to move by the difference, with deviation
//!    `sigma_rad`. A key outside the gate (a wing built at an angle, a
//!    room full of furniture) gets nothing: the prior corrects a wander of
//!    tenths of a degree, never a heading the matches have put elsewhere.
//!
//! Then the graph is optimised again. In a building that is not square no
//! key passes step 1 or the gate of step 3, and nothing changes.
//!
//! ## Wider, in rounds (a replayed log's setting)
//! A log's chain of matches is not one rigid body: where a scan found no
//! match (a turn of 35–77° in place, a step of 3 m) its key hangs on
//! odometry, and everything after it can be turned by degrees at once. A
//! 2° gate leaves such a stretch out altogether (on the Örebro log, 42 of
//! 116 square keys). A log therefore gates at 6° ([`ManhattanConfig::for_logs`])
//! and settles in rounds ([`settle_priors`]): the keys within the gate are
//! pulled in, which turns the stretches they hang on, and the next round
//! gates again at the headings that left, until the keys given a prior no
//! longer change. On the real logs this brings such stretches back and
//! leaves the five shared logs as they were; a 10° gate would bend a part
//! of the raw MIT CSAIL log's building that stands that far off square,
//! which is the limit of the idea (docs/history/issue-21-real-laser-logs.md,
//! round 18). The simulated robots, whose matches never fail that way, keep
//! 2° and one round.
//!
//! ## What the numbers say
//! The wall directions of square keys scatter by 0.4–0.5° rms about the
//! building's on the corrected logs, at the reference's headings and at
//! ours alike (`log_closures`): a single key's direction is no better than
//! its heading, so the prior is loose (σ 2°) and works by numbers — a
//! chain's wander is pulled in by hundreds of keys at once. σ 2° scored
//! better than 0.5° and 1° on the logs it acts on, and leaves the logs whose
//! chains do not wander as they were (docs/history/issue-21-real-laser-logs.md,
//! round 15).
//!
//! ## Straight walls (a setting, off)
//! A normal is fitted to the few returns within `normal_radius_m` of a
//! point, so a key's direction is a mean of many noisy normals. With
//! `line_min_m` above 0 it is refined by the key's straight walls instead
//! ([`wall_lines`]): each run of returns whose normals bundle along one of
//! the two directions is fitted by a line, and the lines vote with their
//! information about their direction. On a synthetic room with 1 cm of
//! range noise this is sharper. On the real logs it is not (long walls are
//! no squarer than short ones) and the relation errors do not improve; for
//! the simulated robots, with the building's direction taken from ten keys
//! instead of fifty, it trades one hour's failures for another's. So it
//! stays off (docs/history/issue-21-real-laser-logs.md, round 16, and
//! issue-22-many-robots.md, round 19).

use super::degeneracy::{covariance2, scan_normals_within, symmetric_eigen2, MAX_GAP_M};
use super::posegraph::{Edge, PoseGraph};
use crate::geom::{wrap_angle, Pose2};
use glam::DVec2;
use std::f64::consts::FRAC_PI_2;

/// Settings of the square-walls prior.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ManhattanConfig {
    /// Neighbourhood of a point for its normal (m).
    pub normal_radius_m: f64,
    /// Half-width of a direction's bundle of normals (rad).
    pub window_rad: f64,
    /// Share of a scan's normals its direction must gather.
    pub min_share: f64,
    /// Normals its direction must gather.
    pub min_normals: usize,
    /// Largest difference from the building's direction that is corrected (rad).
    pub gate_rad: f64,
    /// Standard deviation of the heading prior (rad): loose, as a single
    /// key's wall direction is good to about half a degree.
    pub sigma_rad: f64,
    /// Straight walls (see [`wall_lines`]): the shortest run that counts
    /// (m); 0 takes the normals' direction as it is.
    pub line_min_m: f64,
    /// The largest rms distance of a run's points from its line (m).
    pub line_max_rms_m: f64,
    /// Rounds of steps 2–3 and the optimisation (see [`settle_priors`]):
    /// 1 gates the keys once, at the headings the replay left.
    pub rounds: usize,
}

impl Default for ManhattanConfig {
    fn default() -> Self {
        ManhattanConfig {
            normal_radius_m: 0.35,
            window_rad: 2f64.to_radians(),
            min_share: 0.5,
            min_normals: 20,
            gate_rad: 2f64.to_radians(),
            sigma_rad: 2f64.to_radians(),
            line_min_m: 0.0,
            line_max_rms_m: 0.015,
            rounds: 1,
        }
    }
}

impl ManhattanConfig {
    /// The settings of a replayed log (see "Wider, in rounds" in the module
    /// doc): a gate of 6°, settled in up to four rounds. The simulated
    /// robots keep the defaults (2°, one round).
    pub fn for_logs() -> Self {
        ManhattanConfig {
            gate_rad: 6f64.to_radians(),
            rounds: 4,
            ..ManhattanConfig::default()
        }
    }
}

/// `a` folded into [−45°, 45°).
pub fn fold(a: f64) -> f64 {
    (a + FRAC_PI_2 / 2.0).rem_euclid(FRAC_PI_2) - FRAC_PI_2 / 2.0
}

/// The mean of `angles` modulo 90°, weighted (on the circle of 4θ).
fn folded_mean(angles: impl Iterator<Item = (f64, f64)>) -> Option<f64> {
    let s: DVec2 = angles
        .map(|(a, w)| w * DVec2::from_angle(4.0 * a))
        .sum::<DVec2>();
    (s.length() > 1e-12).then(|| fold(s.y.atan2(s.x) / 4.0))
}

/// The strongest direction modulo 90° of `angles` (folded): the
/// half-degree bin with most votes within `window_rad`, refined by the
/// mean of the votes within twice `window_rad` of it, then within
/// `window_rad` of that. Returns it and how many
/// votes lie within `window_rad` of it.
fn peak(angles: &[f64], window_rad: f64) -> Option<(f64, usize)> {
    let bins = 180;
    let bin = FRAC_PI_2 / bins as f64;
    let reach = (window_rad / bin).round() as i64;
    let mut hist = vec![0u32; bins];
    for &a in angles {
        let b = ((a + FRAC_PI_2 / 2.0) / bin).floor() as i64;
        for d in -reach..=reach {
            hist[(b + d).rem_euclid(bins as i64) as usize] += 1;
        }
    }
    let top = (0..bins).max_by_key(|&b| (hist[b], std::cmp::Reverse(b)))?;
    let centre = -FRAC_PI_2 / 2.0 + (top as f64 + 0.5) * bin;
    let near = |c: f64, w: f64| {
        angles
            .iter()
            .copied()
            .filter(move |&a| fold(a - c).abs() <= w)
    };
    // The top bin may lie anywhere on a plateau as wide as the window: the
    // first mean reaches twice as far.
    let rough = folded_mean(near(centre, 2.0 * window_rad).map(|a| (a, 1.0)))?;
    let direction = folded_mean(near(rough, window_rad).map(|a| (a, 1.0)))?;
    Some((direction, near(direction, window_rad).count()))
}

/// A scan's direction modulo 90° in its own frame and the share of its
/// normals within `cfg.window_rad` of it (step 1 of the module doc), or
/// `None` if it is not square.
pub fn scan_direction(points: &[DVec2], cfg: &ManhattanConfig) -> Option<(f64, f64)> {
    let normals = scan_normals_within(points, cfg.normal_radius_m);
    let angles: Vec<f64> = normals
        .iter()
        .flatten()
        .map(|n| fold(n.y.atan2(n.x)))
        .collect();
    if angles.len() < cfg.min_normals {
        return None;
    }
    let (direction, count) = peak(&angles, cfg.window_rad)?;
    let share = count as f64 / angles.len() as f64;
    if count < cfg.min_normals || share < cfg.min_share {
        return None;
    }
    if cfg.line_min_m <= 0.0 {
        return Some((direction, share));
    }
    wall_lines(points, &normals, direction, cfg).map(|d| (d, share))
}

/// A square scan's direction `rough` refined by its straight walls. A
/// normal is noisy (a few points, a few centimetres apart), but a wall is
/// long: the runs of neighbouring points whose normals lie within
/// `cfg.window_rad` of `rough` (or of its perpendicular) are each fitted
/// by a line (total least squares: the major axis of the points'
/// scatter), and their directions, folded, are averaged with the weight of
/// each line's information about its direction, `Σ (t − t̄)²` over the
/// points' places `t` along it. Runs shorter than `cfg.line_min_m` or
/// further than `cfg.line_max_rms_m` from straight take no part; `None`
/// if none is left.
pub fn wall_lines(
    points: &[DVec2],
    normals: &[Option<DVec2>],
    rough: f64,
    cfg: &ManhattanConfig,
) -> Option<f64> {
    // Which of the two wall directions a point's normal belongs to.
    let side = |i: usize| -> Option<i64> {
        let a = normals[i].map(|n| n.y.atan2(n.x))?;
        (fold(a - rough).abs() <= cfg.window_rad)
            .then(|| ((a - rough) / FRAC_PI_2).round() as i64 & 1)
    };
    let mut votes = Vec::new();
    let mut i = 0;
    while i < points.len() {
        let Some(s) = side(i) else {
            i += 1;
            continue;
        };
        let mut j = i + 1;
        while j < points.len()
            && side(j) == Some(s)
            && (points[j] - points[j - 1]).length() <= MAX_GAP_M
        {
            j += 1;
        }
        votes.extend(line_vote(&points[i..j], cfg));
        i = j;
    }
    folded_mean(
        votes
            .into_iter()
            .filter(|&(a, _)| fold(a - rough).abs() <= cfg.window_rad),
    )
}

/// A run's line as a vote: its normal's direction, folded, and its weight.
fn line_vote(run: &[DVec2], cfg: &ManhattanConfig) -> Option<(f64, f64)> {
    if run.len() < 5 || run[0].distance(run[run.len() - 1]) < cfg.line_min_m {
        return None;
    }
    let [a, b, c] = covariance2(run);
    let (along, across, normal) = symmetric_eigen2(a, b, c);
    (across.sqrt() <= cfg.line_max_rms_m)
        .then(|| (fold(normal.y.atan2(normal.x)), along * run.len() as f64))
}

/// The building's direction modulo 90° from the square keys' world
/// directions (step 2): the strongest bundle within `window_rad`, or `None`
/// without any.
pub fn building_direction(world: &[f64], window_rad: f64) -> Option<f64> {
    peak(world, window_rad).map(|(d, _)| d)
}

/// A heading-only edge from the anchored node 0 (at `anchor`) asking node
/// `to`'s heading to be `wanted`, with deviation `sigma_rad`.
pub fn heading_prior(anchor: &Pose2, to: usize, wanted: f64, sigma_rad: f64) -> Edge {
    let w = 1.0 / (sigma_rad * sigma_rad);
    Edge {
        from: 0,
        to,
        measurement: Pose2::new(0.0, 0.0, wrap_angle(wanted - anchor.theta)),
        information: [[0.0; 3], [0.0; 3], [0.0, 0.0, w]],
        loop_closure: false,
    }
}

/// The heading priors of step 3 towards the building's direction
/// `building` for the square keys `square` (`(node, scan direction)`):
/// one edge per key within `cfg.gate_rad` of it, none for node 0, the
/// anchor.
pub fn priors_towards(
    nodes: &[Pose2],
    square: &[(usize, f64)],
    building: f64,
    cfg: &ManhattanConfig,
) -> Vec<Edge> {
    let anchor = nodes[0];
    square
        .iter()
        .filter_map(|&(i, d)| {
            let off = fold(fold(nodes[i].theta + d) - building);
            (i > 0 && off.abs() <= cfg.gate_rad)
                .then(|| heading_prior(&anchor, i, nodes[i].theta - off, cfg.sigma_rad))
        })
        .collect()
}

/// The heading priors of steps 2 and 3 for the keys at `nodes` whose scan
/// directions are `directions[i]` (`None`: not square). Node 0 is the
/// anchor: it votes for the building's direction but gets no prior.
pub fn priors_for(nodes: &[Pose2], directions: &[Option<f64>], cfg: &ManhattanConfig) -> Vec<Edge> {
    let n = nodes.len().min(directions.len());
    let square: Vec<(usize, f64)> = (0..n)
        .filter_map(|i| directions[i].map(|d| (i, d)))
        .collect();
    let votes: Vec<f64> = square
        .iter()
        .map(|&(i, d)| fold(nodes[i].theta + d))
        .collect();
    match building_direction(&votes, cfg.window_rad) {
        Some(building) => priors_towards(nodes, &square, building, cfg),
        None => Vec::new(),
    }
}

/// Steps 2 and 3 and the optimisation (`optimise`), in up to `cfg.rounds`
/// rounds: each round gates the square keys again at the headings the
/// round before left, replaces that round's priors by its own and
/// optimises; it stops once a round would give the same keys as the one
/// before. Returns how many keys have a prior in the end.
pub fn settle_priors(
    graph: &mut PoseGraph,
    directions: &[Option<f64>],
    cfg: &ManhattanConfig,
    mut optimise: impl FnMut(&mut PoseGraph) -> Result<(), String>,
) -> Result<usize, String> {
    let base = graph.edges.len();
    let mut last: Vec<usize> = Vec::new();
    for _ in 0..cfg.rounds.max(1) {
        let edges = priors_for(&graph.nodes, directions, cfg);
        let keys: Vec<usize> = edges.iter().map(|e| e.to).collect();
        if keys == last {
            // Settled (or, in the first round, nothing to add).
            break;
        }
        graph.edges.truncate(base);
        graph.edges.extend(edges);
        optimise(graph)?;
        last = keys;
    }
    Ok(last.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points along the sides of a rectangle turned by `turn`, one per
    /// 0.1 m, seen from its centre.
    fn room(turn: f64) -> Vec<DVec2> {
        let (w, h) = (6.0, 4.0);
        let mut pts = Vec::new();
        let mut side = |a: DVec2, b: DVec2| {
            let n = ((b - a).length() / 0.1) as usize;
            for k in 0..n {
                pts.push(a + (b - a) * (k as f64 / n as f64));
            }
        };
        let c = [
            DVec2::new(-w / 2.0, -h / 2.0),
            DVec2::new(w / 2.0, -h / 2.0),
            DVec2::new(w / 2.0, h / 2.0),
            DVec2::new(-w / 2.0, h / 2.0),
        ];
        for k in 0..4 {
            side(c[k], c[(k + 1) % 4]);
        }
        let r = DVec2::from_angle(turn);
        pts.into_iter().map(|p| r.rotate(p)).collect()
    }

    #[test]
    fn fold_maps_into_a_quarter_turn() {
        assert!((fold(100f64.to_radians()) - 10f64.to_radians()).abs() < 1e-12);
        assert!((fold(-50f64.to_radians()) - 40f64.to_radians()).abs() < 1e-12);
        assert!((fold(44f64.to_radians()) - 44f64.to_radians()).abs() < 1e-12);
    }

    /// A rectangular room turned by 7.3° is square at 7.3°; a room of walls
    /// in three directions 30° apart is not.
    #[test]
    fn a_square_room_gives_its_turn_and_a_skewed_one_nothing() {
        let cfg = ManhattanConfig::default();
        let (d, share) = scan_direction(&room(7.3f64.to_radians()), &cfg).expect("square");
        assert!(
            (d.to_degrees() - 7.3).abs() < 0.05,
            "direction {}",
            d.to_degrees()
        );
        assert!(share > 0.9, "share {share}");
        // A triangle-ish fan: walls at 0°, 30° and 60°.
        let mut skew = Vec::new();
        for (k, a) in [0.0f64, 30.0, 60.0].iter().enumerate() {
            let dir = DVec2::from_angle(a.to_radians());
            let base = DVec2::new(0.0, 2.0 + 3.0 * k as f64);
            for s in 0..40 {
                skew.push(base + dir * (s as f64 * 0.1));
            }
        }
        assert!(scan_direction(&skew, &cfg).is_none());
    }

    /// With 1 cm of range noise, the straight walls measure a room's turn
    /// better than its normals do, and a run further than
    /// `line_max_rms_m` from straight (a zigzag) is no wall.
    #[test]
    fn straight_walls_measure_the_turn_through_noise() {
        let turn = 7.3f64.to_radians();
        // Range noise from a fixed linear congruential sequence.
        let mut state = 12345u64;
        let mut noise = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
            ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.035
        };
        let noisy: Vec<DVec2> = room(turn)
            .into_iter()
            .map(|p| p * (1.0 + noise() / p.length()))
            .collect();
        let normals = ManhattanConfig::default();
        let lines = ManhattanConfig {
            line_min_m: 1.0,
            ..normals.clone()
        };
        let err = |cfg: &ManhattanConfig| {
            let (d, _) = scan_direction(&noisy, cfg).expect("square");
            (d - turn).to_degrees().abs()
        };
        assert!(err(&lines) < 0.1, "lines off by {}°", err(&lines));
        assert!(
            err(&lines) < err(&normals),
            "{} vs {}",
            err(&lines),
            err(&normals)
        );
        // A run whose points lie 3 cm either side of its line is no wall;
        // the same run straight is one, and votes with its direction.
        let run = |off: f64| -> Vec<DVec2> {
            (0..30)
                .map(|k| DVec2::new(0.1 * k as f64, 2.0 + off * (k % 2) as f64))
                .collect()
        };
        assert_eq!(line_vote(&run(0.06), &lines), None);
        let (a, w) = line_vote(&run(0.0), &lines).expect("a straight wall");
        assert!(
            a.abs() < 1e-9 && (w - 0.01 * 2247.5).abs() < 1e-6,
            "{a} {w}"
        );
    }

    /// Keys whose headings wander by a few tenths of a degree in a square
    /// building are pulled back to a common direction (the building's as
    /// the votes measure it: off the truth by their mean wander, which
    /// turns every key alike); a key whose walls lie 20° off the
    /// building's gets no prior.
    #[test]
    fn priors_take_out_a_heading_wander() {
        let cfg = ManhattanConfig::default();
        let wander: [f64; 6] = [0.0, 0.3, -0.4, 0.5, 0.2, 20.0];
        let mut graph = PoseGraph::default();
        let mut directions = Vec::new();
        for (i, w) in wander.iter().enumerate() {
            // The key's estimate is off by `w`; its scan sees the building
            // (direction 3°) from its true heading.
            let truth = 0.1 * i as f64;
            graph
                .nodes
                .push(Pose2::new(i as f64, 0.0, truth + w.to_radians()));
            directions.push(Some(fold(3f64.to_radians() - truth)));
            if i > 0 {
                let z = Pose2::new(1.0, 0.0, 0.1);
                graph
                    .edges
                    .push(Edge::new(i - 1, i, z, 0.1, 5f64.to_radians()));
            }
        }
        let priors = priors_for(&graph.nodes, &directions, &cfg);
        assert_eq!(priors.len(), 4, "keys 1 to 4; key 5 lies 20° off");
        graph.edges.extend(priors);
        graph.optimise(20).expect("optimise");
        let err = |i: usize| (graph.nodes[i].theta - 0.1 * i as f64).to_degrees();
        // The votes' mean wander: (0 + 0.3 − 0.4 + 0.5 + 0.2) / 5 = 0.12°.
        for i in 1..5 {
            assert!(
                (err(i) - 0.12).abs() < 0.03,
                "key {i}: heading off by {}°",
                err(i)
            );
        }
    }

    /// A stretch of keys matched firmly among themselves but hung on the
    /// rest by one loose odometry edge, turned 5° as a whole, with a last
    /// key whose walls stand 20° off square: `(graph, directions)`.
    fn stretch_turned_by(turn_deg: f64) -> (PoseGraph, Vec<Option<f64>>) {
        let mut graph = PoseGraph::default();
        let mut directions = Vec::new();
        for i in 0..13 {
            // Headings 0 (the building's direction); keys 6 to 12 were
            // estimated turned by `turn_deg` after the loose edge.
            let off = if i >= 6 { turn_deg.to_radians() } else { 0.0 };
            graph.nodes.push(Pose2::new(i as f64, 0.0, off));
            let walls = if i == 12 { 20f64.to_radians() } else { 0.0 };
            directions.push(Some(walls));
            if i > 0 {
                let (z, sigma_deg): (Pose2, f64) = if i == 6 {
                    (Pose2::new(1.0, 0.0, turn_deg.to_radians()), 20.0)
                } else {
                    (Pose2::new(1.0, 0.0, 0.0), 0.1)
                };
                graph
                    .edges
                    .push(Edge::new(i - 1, i, z, 0.05, sigma_deg.to_radians()));
            }
        }
        (graph, directions)
    }

    /// The 2° gate leaves a stretch turned 5° behind a loose edge alone; the
    /// logs' 6° gate, settled in rounds, turns it back square (to within a
    /// tenth of a degree), and still gives the key 20° off square nothing.
    #[test]
    fn rounds_at_a_wider_gate_turn_back_a_stretch_hung_on_a_loose_edge() {
        let optimise = |g: &mut PoseGraph| g.optimise(20).map(|_| ());
        let (mut graph, directions) = stretch_turned_by(5.0);
        let narrow = ManhattanConfig::default();
        let n = settle_priors(&mut graph, &directions, &narrow, optimise).expect("settle");
        assert_eq!(n, 5, "keys 1 to 5 only");
        let err = |g: &PoseGraph, i: usize| g.nodes[i].theta.to_degrees();
        assert!((err(&graph, 9) - 5.0).abs() < 0.1, "{}°", err(&graph, 9));

        let (mut graph, directions) = stretch_turned_by(5.0);
        let mut rounds = 0;
        let n = settle_priors(&mut graph, &directions, &ManhattanConfig::for_logs(), |g| {
            rounds += 1;
            optimise(g)
        })
        .expect("settle");
        assert_eq!(n, 11, "keys 1 to 11; key 12's walls lie 20° off");
        assert_eq!(rounds, 1, "the second round finds the same keys and stops");
        for i in 1..12 {
            assert!(err(&graph, i).abs() < 0.1, "key {i}: {}°", err(&graph, i));
        }
        // Key 12 follows its stretch, priors or not.
        assert!(err(&graph, 12).abs() < 0.1, "key 12: {}°", err(&graph, 12));
    }
}
