//! The merge of saved maps (crate/src/merge/saved/) on maps cut
//! from generated buildings with known transforms: a pair merges to the
//! truth, three maps join along the spanning tree, two different buildings
//! are refused, maps of two buildings form two groups, and the merged map
//! is written as ROS map_server files.

use glam::DVec2;
use slamlab::formats::rosmap::{self, RosMap};
use slamlab::geom::{wrap_angle, Pose2, Segment};
use slamlab::merge::saved::{merge_all, SavedMergeConfig};
use slamlab::merge::MergeStatus;
use slamlab::rng::Rng;

/// A floor plan: an outer `w × h` rectangle, rooms along two sides of a
/// corridor, doors, a slanted wall and pillars, placed by `seed`.
fn building(seed: u64, w: f64, h: f64) -> Vec<Segment> {
    let mut rng = Rng::new(seed);
    let s = |a: (f64, f64), b: (f64, f64)| Segment::new(DVec2::new(a.0, a.1), DVec2::new(b.0, b.1));
    let mut walls = vec![
        s((0.0, 0.0), (w, 0.0)),
        s((w, 0.0), (w, h)),
        s((w, h), (0.0, h)),
        s((0.0, h), (0.0, 0.0)),
    ];
    let (c0, c1) = (h * 0.42, h * 0.42 + 2.4);
    // Corridor walls with a door into each room.
    let mut x = 0.0;
    while x < w - 3.0 {
        let room = rng.range(3.5, 7.0).min(w - x);
        let (d0, d1) = (rng.range(0.5, room - 1.5), rng.range(0.5, room - 1.5));
        walls.push(s((x, c0), (x + d0, c0)));
        walls.push(s((x + d0 + 1.0, c0), (x + room, c0)));
        walls.push(s((x, c1), (x + d1, c1)));
        walls.push(s((x + d1 + 1.0, c1), (x + room, c1)));
        if x + room < w - 0.5 {
            walls.push(s((x + room, 0.0), (x + room, c0)));
            let up = rng.range(0.0, 1.0) < 0.7;
            if up {
                walls.push(s((x + room, c1), (x + room, h)));
            }
        }
        x += room;
    }
    // A slanted wall and a few pillars (0.4 m squares) break symmetries.
    let (px, py) = (rng.range(2.0, w - 6.0), rng.range(c1 + 1.0, h - 3.0));
    walls.push(s((px, py), (px + 3.0, py + 1.5)));
    for _ in 0..4 {
        let (qx, qy) = (rng.range(1.0, w - 1.0), rng.range(1.0, c0 - 1.0));
        walls.push(s((qx, qy), (qx + 0.4, qy)));
        walls.push(s((qx + 0.4, qy), (qx + 0.4, qy + 0.4)));
        walls.push(s((qx + 0.4, qy + 0.4), (qx, qy + 0.4)));
        walls.push(s((qx, qy + 0.4), (qx, qy)));
    }
    walls
}

/// A building's plan: its walls inside a `size` = (w, h) metre rectangle.
struct Plan<'a> {
    walls: &'a [Segment],
    size: (f64, f64),
}

impl<'a> Plan<'a> {
    fn new(walls: &'a [Segment], size: (f64, f64)) -> Plan<'a> {
        Plan { walls, size }
    }

    /// A map of the plan whose image's lower-left corner is at `frame`
    /// (world), `size` metres, showing only the part of the building with
    /// `seen(x, y)`, and written with YAML origin `origin`.
    fn cut(
        &self,
        name: &str,
        frame: Pose2,
        size: DVec2,
        seen: impl Fn(DVec2) -> bool,
        origin: Pose2,
    ) -> RosMap {
        let (r, (w, h)) = (0.05, self.size);
        let (nx, ny) = ((size.x / r) as usize, (size.y / r) as usize);
        let mut data = vec![-1i8; nx * ny];
        for iy in 0..ny {
            for ix in 0..nx {
                let p = frame.transform_point(DVec2::new(ix as f64 + 0.5, iy as f64 + 0.5) * r);
                let inside = p.x > -0.1 && p.y > -0.1 && p.x < w + 0.1 && p.y < h + 0.1;
                if !inside || !seen(p) {
                    continue;
                }
                let near = self.walls.iter().any(|s| s.distance_to_point(p) <= 0.04);
                data[iy * nx + ix] = if near { 100 } else { 0 };
            }
        }
        RosMap::from_values(name, nx, ny, r, origin, data).unwrap()
    }
}

/// The map frame of a map whose image frame is `frame` (world) and whose
/// YAML origin is `origin`: `frame ⊕ origin⁻¹`.
fn map_frame(frame: &Pose2, origin: &Pose2) -> Pose2 {
    frame.compose(&origin.inverse())
}

fn error(est: &Pose2, truth: &Pose2) -> (f64, f64) {
    (
        (est.position() - truth.position()).length(),
        wrap_angle(est.theta - truth.theta).abs().to_degrees(),
    )
}

/// B's image frame turned by `theta` about the middle of the window x0..x1.
fn turned_frame(x0: f64, x1: f64, h: f64, theta: f64, size: f64) -> Pose2 {
    let centre = DVec2::new(0.5 * (x0 + x1), 0.5 * h);
    let (s, c) = theta.sin_cos();
    let half = DVec2::splat(0.5 * size);
    let corner = centre - DVec2::new(c * half.x - s * half.y, s * half.x + c * half.y);
    Pose2::new(corner.x, corner.y, theta)
}

#[test]
fn a_pair_cut_from_one_building_merges_to_the_known_transform() {
    let (a, b, truth) = east_west_pair();
    let r = merge_all(&[a, b], &SavedMergeConfig::default(), &mut |_| {});
    assert_eq!(r.status, MergeStatus::Merged, "{}", r.reason);
    let est = r.poses[1].unwrap();
    let (dm, dd) = error(&est, &truth);
    println!(
        "synthetic pair: off by {dm:.4} m, {dd:.3} deg; {}",
        r.reason
    );
    assert!(dm < 0.05 && dd < 0.2, "off by {dm} m {dd} deg");
    assert!(r.confidence > 0.0 && r.confidence <= 1.0);
    assert_eq!(r.poses[0], Some(Pose2::IDENTITY));
}

#[test]
fn three_maps_join_along_the_spanning_tree() {
    let (w, h) = (36.0, 24.0);
    let walls = building(5, w, h);
    let plan = Plan::new(&walls, (w, h));
    let fa = Pose2::new(-1.0, -1.0, 0.0);
    let oa = Pose2::IDENTITY;
    let a = plan.cut("a.yaml", fa, DVec2::new(22.0, 26.0), |p| p.x <= 20.0, oa);
    let fb = turned_frame(8.0, 30.0, h, -1.2, 34.0);
    let b = plan.cut(
        "b.yaml",
        fb,
        DVec2::new(34.0, 34.0),
        |p| (8.0..=30.0).contains(&p.x),
        oa,
    );
    let fc = turned_frame(10.0, 37.0, h, 2.5, 38.0);
    let c = plan.cut("c.yaml", fc, DVec2::new(38.0, 38.0), |p| p.x >= 10.0, oa);
    let r = merge_all(&[a, b, c], &SavedMergeConfig::default(), &mut |line| {
        println!("{line}")
    });
    assert_eq!(r.status, MergeStatus::Merged, "{}", r.reason);
    assert!(r.unjoined.is_empty());
    for (k, f) in [(1, fb), (2, fc)] {
        let (dm, dd) = error(&r.poses[k].unwrap(), &fa.between(&f));
        println!("map {k}: off by {dm:.4} m, {dd:.3} deg");
        assert!(dm < 0.08 && dd < 0.3, "map {k} off by {dm} m {dd} deg");
    }
    assert_eq!(r.pairs.len(), 3);
}

/// Maps of two different buildings (seeds 3 and 8), B's image turned by
/// 0.4 rad, and B's frame in A's where their corners sit as cut.
fn two_buildings() -> (RosMap, RosMap, Pose2) {
    let fa = Pose2::new(-1.0, -1.0, 0.0);
    let (sa, sb) = ((36.0, 24.0), (30.0, 20.0));
    let all = |_: DVec2| true;
    let (wa, wb) = (building(3, sa.0, sa.1), building(8, sb.0, sb.1));
    let a = Plan::new(&wa, sa).cut("a.yaml", fa, DVec2::new(38.0, 26.0), all, Pose2::IDENTITY);
    let fb = turned_frame(0.0, 30.0, 20.0, 0.4, 38.0);
    let b = Plan::new(&wb, sb).cut("b.yaml", fb, DVec2::new(38.0, 38.0), all, Pose2::IDENTITY);
    (a, b, fa.between(&fb))
}

#[test]
fn two_different_buildings_are_not_merged() {
    let (a, b, _) = two_buildings();
    let r = merge_all(&[a, b], &SavedMergeConfig::default(), &mut |_| {});
    println!("different buildings: {}", r.reason);
    assert_eq!(r.status, MergeStatus::NoMerge, "{}", r.reason);
    assert_eq!(r.unjoined, vec![1]);
    assert_eq!(r.pairs[0].status, MergeStatus::NoMerge);
}

#[test]
fn the_merged_map_is_written_as_map_server_files() {
    let (a, b, b_in_a) = east_west_pair_with(Pose2::IDENTITY, Pose2::IDENTITY);
    let (fa, h) = (Pose2::new(-1.0, -1.0, 0.0), 24.0);
    let merged = rosmap::write::merge_maps(&[(&a, Pose2::IDENTITY), (&b, b_in_a)]).unwrap();
    // It covers both maps: A's 26 m and B's turned square reach x = 37 m.
    assert!(merged.width as f64 * 0.05 > 38.0, "{}", merged.width);
    let yaml = merged.yaml("m.pgm");
    let back = rosmap::load("m.yaml", &yaml, "m.pgm", &merged.pgm()).unwrap();
    assert_eq!((back.width, back.height), (merged.width, merged.height));
    // World point (33, 5) is only in B: free there (no wall within 0.5 m?).
    let at = |m: &RosMap, world: DVec2| {
        let p = fa.inverse().transform_point(world);
        let q = m.origin.inverse().transform_point(p);
        let (ix, iy) = m.cell_at_image(q).unwrap();
        m.data[iy * m.width + ix]
    };
    let free_spot = DVec2::new(30.0, 0.5 * (h * 0.42 + h * 0.42 + 2.4));
    assert_eq!(
        at(&back, free_spot),
        0,
        "corridor middle at x = 30 (only B saw it) is free"
    );
    assert_eq!(
        at(&back, DVec2::new(36.0, 12.0)),
        100,
        "the east outer wall (only in B) is a wall"
    );
    assert_eq!(
        at(&back, DVec2::new(0.0, 12.0)),
        100,
        "the west outer wall (only in A) is a wall"
    );
    let png = merged.png().unwrap();
    let from_png = rosmap::load("m.yaml", &yaml.replace("m.pgm", "m.png"), "m.png", &png).unwrap();
    assert_eq!(from_png.data, back.data);
}

// Refine (crate/src/merge/saved/refine.rs): a pair aligned again from a person's
// rough overlay, judged by the same verdict.

#[path = "merge_support/guess.rs"]
mod guess;
use guess::{middle, nudged, refined};
use slamlab::merge::saved::refine::refine_pair;
use slamlab::merge::saved::wallmap::WallMap;
use slamlab::merge::saved::{join, PairResult};

/// The first test's pair (A the west part of a building, B the east part
/// turned by 0.7 rad, both with YAML origins) and B's true pose in A.
fn east_west_pair() -> (RosMap, RosMap, Pose2) {
    east_west_pair_with(Pose2::new(-3.0, 2.0, 0.0), Pose2::new(1.0, -2.0, 0.3))
}

/// The same with YAML origins `oa` and `ob`. A's image's lower-left corner
/// is at (-1, -1) of the 36 x 24 m plan.
fn east_west_pair_with(oa: Pose2, ob: Pose2) -> (RosMap, RosMap, Pose2) {
    let (w, h) = (36.0, 24.0);
    let walls = building(11, w, h);
    let plan = Plan::new(&walls, (w, h));
    let fa = Pose2::new(-1.0, -1.0, 0.0);
    let a = plan.cut("a.yaml", fa, DVec2::new(26.0, 26.0), |p| p.x <= 24.0, oa);
    let fb = turned_frame(12.0, 37.0, h, 0.7, 36.0);
    let b = plan.cut("b.yaml", fb, DVec2::new(36.0, 36.0), |p| p.x >= 12.0, ob);
    let truth = map_frame(&fa, &oa).between(&map_frame(&fb, &ob));
    (a, b, truth)
}

#[test]
fn refine_from_a_guess_1_m_and_10_deg_off_converges_and_merges() {
    let (a, b, truth) = east_west_pair();
    for (dtheta, shift) in [
        (10f64, DVec2::new(0.6, -0.8)),
        (-10.0, DVec2::new(-0.8, 0.6)),
    ] {
        let guess = nudged(&truth, middle(&b), dtheta.to_radians(), shift);
        let r = refined(&a, &b, guess);
        let (dm, dd) = error(&r.pose.unwrap(), &truth);
        println!(
            "refine from {dtheta}° / {shift}: off by {dm:.4} m, {dd:.3} deg; {}",
            r.reason
        );
        assert_eq!(r.status, MergeStatus::Merged, "{}", r.reason);
        assert!(dm < 0.1 && dd < 0.5, "off by {dm} m {dd} deg");
        assert!(
            r.reason.starts_with("refined from your guess"),
            "{}",
            r.reason
        );
        assert!(r.reason.contains("near your guess"), "{}", r.reason);
        assert_eq!(r.guess, Some(guess));
        assert!(r.confidence > 0.0 && r.confidence <= 1.0);
    }
}

#[test]
fn refine_onto_a_wrong_place_is_refused() {
    let (a, b, truth) = east_west_pair();
    // B's middle dropped 6 m west and 5 m south of where it belongs, and
    // turned by 90°: the walls do not agree there.
    for (dtheta, shift) in [(0.0f64, DVec2::new(-6.0, -5.0)), (90.0, DVec2::ZERO)] {
        let guess = nudged(&truth, middle(&b), dtheta.to_radians(), shift);
        let r = refined(&a, &b, guess);
        println!("wrong place ({dtheta}°, {shift}): {}", r.reason);
        assert_eq!(r.status, MergeStatus::NoMerge, "{}", r.reason);
        assert!(
            r.reason.starts_with("refined from your guess"),
            "{}",
            r.reason
        );
        assert!(r.reason.chars().any(|c| c.is_ascii_digit()), "{}", r.reason);
        assert_eq!(r.confidence, 0.0);
    }
}

#[test]
fn refine_never_merges_two_different_buildings() {
    let (a, b, placed) = two_buildings();
    // Outer walls laid on each other as a person would try.
    for guess in [
        placed,
        nudged(&placed, middle(&b), 0.1, DVec2::new(2.0, 1.0)),
    ] {
        let r = refined(&a, &b, guess);
        println!("different buildings, refined: {}", r.reason);
        assert_eq!(r.status, MergeStatus::NoMerge, "{}", r.reason);
    }
}

#[test]
fn refine_refuses_a_guess_that_is_not_finite() {
    let (a, b, _) = east_west_pair();
    let (wa, wb) = (WallMap::new(&a), WallMap::new(&b));
    for guess in [
        Pose2::new(f64::NAN, 0.0, 0.0),
        Pose2::new(0.0, f64::INFINITY, 0.0),
        Pose2::new(0.0, 0.0, f64::NEG_INFINITY),
    ] {
        let e = refine_pair(
            (0, &a, &wa),
            (1, &b, &wb),
            guess,
            &SavedMergeConfig::default(),
        )
        .unwrap_err();
        assert!(e.contains("finite"), "{e}");
    }
}

/// A building that is the same turned by 180°: a `w / 2` wide plan and its
/// copy turned about the middle of the `w` x `h` rectangle.
fn symmetric_building(seed: u64, w: f64, h: f64) -> Vec<Segment> {
    let half = building(seed, 0.5 * w, h);
    let turn = |p: DVec2| DVec2::new(w - p.x, h - p.y);
    let mut walls = half.clone();
    walls.extend(half.iter().map(|s| Segment::new(turn(s.a), turn(s.b))));
    walls
}

#[test]
fn refine_merges_a_symmetric_building_the_automatic_merge_declines() {
    let (w, h) = (40.0, 20.0);
    let walls = symmetric_building(21, w, h);
    let plan = Plan::new(&walls, (w, h));
    let all = |_: DVec2| true;
    let fa = Pose2::new(-1.0, -1.0, 0.0);
    let a = plan.cut("a.yaml", fa, DVec2::new(42.0, 22.0), all, Pose2::IDENTITY);
    let fb = turned_frame(-1.0, 41.0, h, 0.9, 44.0);
    let b = plan.cut("b.yaml", fb, DVec2::new(44.0, 44.0), all, Pose2::IDENTITY);
    let truth = fa.between(&fb);
    let maps = [a, b];
    let mut r = merge_all(&maps, &SavedMergeConfig::default(), &mut |_| {});
    println!("symmetric building, automatic: {}", r.reason);
    assert_eq!(r.status, MergeStatus::NoMerge, "{}", r.reason);
    assert!(r.reason.contains("ambiguous"), "{}", r.reason);

    let guess = nudged(
        &truth,
        middle(&maps[1]),
        8f64.to_radians(),
        DVec2::new(0.7, 0.7),
    );
    let pair = refined(&maps[0], &maps[1], guess);
    let (dm, dd) = error(&pair.pose.unwrap(), &truth);
    println!(
        "symmetric building, refined: off by {dm:.4} m, {dd:.3} deg; {}",
        pair.reason
    );
    assert_eq!(pair.status, MergeStatus::Merged, "{}", pair.reason);
    assert!(dm < 0.1 && dd < 0.5, "off by {dm} m {dd} deg");

    // The refined pair replaces the automatic one and the maps are joined.
    assert_eq!(r.replace_pair(&maps, pair.clone()), Some(0));
    assert_eq!(r.status, MergeStatus::Merged, "{}", r.reason);
    assert_eq!(r.poses[1], pair.pose);
    assert!(r.unjoined.is_empty());
    assert_eq!(r, join(&maps, vec![pair]));
}

#[test]
fn refine_is_refused_where_the_automatic_merge_found_a_clear_winner_elsewhere() {
    use slamlab::merge::saved::merge_pair;
    use slamlab::merge::saved::refine::refuse_if_beaten;
    let (a, b, truth) = east_west_pair();
    let (wa, wb) = (WallMap::new(&a), WallMap::new(&b));
    let cfg = SavedMergeConfig::default();
    let automatic = merge_pair((0, &a, &wa), (1, &b, &wb), &cfg);
    let guess = nudged(&truth, middle(&b), 0.1, DVec2::new(0.5, 0.5));
    let mine = refined(&a, &b, guess);
    assert_eq!(mine.status, MergeStatus::Merged, "{}", mine.reason);
    let support = mine.evidence.unwrap().support_m;
    // The same overlay found by both: nothing to refuse.
    let mut same = mine.clone();
    assert!(!refuse_if_beaten(&mut same, &automatic, (&a, &b), &cfg));
    assert_eq!(same, mine);
    // A different overlay (4 m away) with 1.4 times the support: a near
    // tie, which the guess settles; with 1.6 times, a clear winner.
    let elsewhere = |ratio: f64| {
        let mut other = automatic.clone();
        let p = other.pose.unwrap();
        other.pose = Some(Pose2::new(p.x + 4.0, p.y, p.theta));
        let mut e = other.evidence.unwrap();
        e.support_m = ratio * support;
        other.evidence = Some(e);
        other
    };
    let mut near_tie = mine.clone();
    assert!(!refuse_if_beaten(
        &mut near_tie,
        &elsewhere(1.4),
        (&a, &b),
        &cfg
    ));
    assert_eq!(near_tie.status, MergeStatus::Merged);
    let mut beaten = mine.clone();
    assert!(refuse_if_beaten(
        &mut beaten,
        &elsewhere(1.6),
        (&a, &b),
        &cfg
    ));
    assert_eq!(beaten.status, MergeStatus::NoMerge);
    assert_eq!(beaten.confidence, 0.0);
    println!("beaten: {}", beaten.reason);
    assert!(
        beaten.reason.starts_with("refined from your guess"),
        "{}",
        beaten.reason
    );
    assert!(
        beaten.reason.contains("1.6 times as much"),
        "{}",
        beaten.reason
    );
}

/// A judged pair: merged at `pose` with `confidence`, or refused (`None`).
fn judged(a: usize, b: usize, merged: Option<(Pose2, f64)>, reason: &str) -> PairResult {
    let mut p = PairResult::unjudged(a, b);
    p.reason = reason.into();
    if let Some((pose, confidence)) = merged {
        p.status = MergeStatus::Merged;
        p.pose = Some(pose);
        p.confidence = confidence;
    }
    p
}

#[test]
fn maps_of_two_buildings_form_two_groups_each_in_its_first_maps_frame() {
    // Five small maps: 0 and 2 of one building, 1, 3 and 4 of another
    // (4 joined through 3), opened interleaved.
    let blank =
        |name: &str| RosMap::from_values(name, 4, 4, 0.05, Pose2::IDENTITY, vec![0; 16]).unwrap();
    let maps: Vec<RosMap> = ["a0", "b0", "a1", "b1", "b2"]
        .iter()
        .map(|n| blank(n))
        .collect();
    let p02 = Pose2::new(3.0, 1.0, 0.5);
    let (p13, p34) = (Pose2::new(-2.0, 4.0, -1.0), Pose2::new(1.0, 0.0, 0.25));
    let mut pairs = Vec::new();
    for a in 0..5 {
        for b in a + 1..5 {
            let merged = match (a, b) {
                (0, 2) => Some((p02, 0.9)),
                (1, 3) => Some((p13, 0.7)),
                (3, 4) => Some((p34, 0.6)),
                _ => None,
            };
            pairs.push(judged(a, b, merged, &format!("pair {a} {b}")));
        }
    }
    let r = join(&maps, pairs);
    let members: Vec<Vec<usize>> = r.groups.iter().map(|g| g.maps.clone()).collect();
    assert_eq!(members, vec![vec![0, 2], vec![1, 3, 4]], "{}", r.reason);
    // The first map's group is the merge's own: the same poses.
    assert_eq!(r.groups[0].poses, r.poses);
    assert_eq!(r.unjoined, vec![1, 3, 4]);
    let g = &r.groups[1];
    assert_eq!(g.poses[1], Some(Pose2::IDENTITY));
    assert_eq!(g.poses[3], Some(p13));
    let (dm, dd) = error(&g.poses[4].unwrap(), &p13.compose(&p34));
    assert!(dm < 1e-9 && dd < 1e-9, "map 4 off by {dm} m {dd} deg");
    assert_eq!((r.groups[0].confidence, g.confidence), (0.9, 0.6));
    assert!(r.groups.iter().all(|g| g.reason.is_none()));
    let report = r.report(&maps);
    let groups = report["merge"]["groups"].as_array().unwrap();
    assert_eq!(groups[1]["maps"], serde_json::json!(["b0", "b1", "b2"]));
    assert_eq!(groups[1]["transforms"][0]["map"], "b0");
    assert_eq!(
        groups[1]["transforms"][1]["pose"],
        serde_json::json!([-2.0, 4.0, -1.0])
    );
}

#[test]
fn a_map_alone_is_a_group_of_its_own_with_its_reason() {
    let (a, b, _) = two_buildings();
    let r = merge_all(&[a, b], &SavedMergeConfig::default(), &mut |_| {});
    assert_eq!(r.groups.len(), 2);
    for (k, g) in r.groups.iter().enumerate() {
        assert_eq!(g.maps, vec![k]);
        assert_eq!(g.confidence, 0.0);
        assert_eq!(g.reason.as_deref(), Some(r.pairs[0].reason.as_str()));
    }
}

#[test]
fn a_kept_placement_joins_as_placed_and_is_marked_not_verified() {
    let blank =
        |name: &str| RosMap::from_values(name, 4, 4, 0.05, Pose2::IDENTITY, vec![0; 16]).unwrap();
    let maps: Vec<RosMap> = ["m0", "m1", "m2"].iter().map(|n| blank(n)).collect();
    let p01 = Pose2::new(2.0, 0.5, 0.1);
    let pairs = vec![
        judged(0, 1, Some((p01, 0.8)), "agree"),
        judged(0, 2, None, "the walls disagree"),
        judged(1, 2, None, "too little common wall"),
    ];
    let mut r = join(&maps, pairs.clone());
    assert_eq!(r.unjoined, vec![2]);
    assert!(r.verified);
    let mine = Pose2::new(-4.0, 3.0, 2.0);
    let k = r
        .keep_placement(
            &maps,
            (0, 2),
            mine,
            "refined from your guess: the walls disagree",
        )
        .unwrap();
    assert_eq!(k, 1);
    assert_eq!(r.status, MergeStatus::Merged, "{}", r.reason);
    assert_eq!(r.poses[2], Some(mine), "joined exactly where it was placed");
    assert!(!r.verified);
    assert!(!r.pairs[1].verified && r.pairs[0].verified);
    assert!(
        r.pairs[1].reason.contains("not verified"),
        "{}",
        r.pairs[1].reason
    );
    assert!(
        r.pairs[1].reason.contains("the walls disagree"),
        "{}",
        r.pairs[1].reason
    );
    assert!(!r.groups[0].verified);
    let report = r.report(&maps);
    assert_eq!(report["merge"]["verified"], false);
    assert_eq!(report["merge"]["pairs"][1]["verified"], false);
    assert_eq!(report["merge"]["groups"][0]["verified"], false);
    assert!(report["merge"]["pairs"][0].get("verified").is_none());

    // A verified chain to the same map wins over a kept placement.
    let p12 = Pose2::new(1.0, 1.0, -0.3);
    let mut with_chain = pairs;
    with_chain[2] = judged(1, 2, Some((p12, 0.5)), "agree");
    let mut r = join(&maps, with_chain);
    r.keep_placement(&maps, (0, 2), mine, "").unwrap();
    let (dm, dd) = error(&r.poses[2].unwrap(), &p01.compose(&p12));
    assert!(dm < 1e-9 && dd < 1e-9, "off by {dm} m {dd} deg");
    assert!(r.verified);
}

#[test]
fn an_overlay_with_no_rival_is_said_in_words_not_inf() {
    use slamlab::merge::saved::agreement_reason;
    use slamlab::merge::saved::evidence::Evidence;
    let e = Evidence {
        agree_m: 40.0,
        support_m: 38.0,
        index: 0.95,
        ..Evidence::default()
    };
    let cfg = SavedMergeConfig::default();
    let alone = agreement_reason(&e, 0.0, &cfg, "near your guess");
    assert!(!alone.contains("inf"), "{alone}");
    assert!(
        alone.ends_with("38.0 m of net support, and no other overlay near your guess has any"),
        "{alone}"
    );
    let beaten = agreement_reason(&e, 19.0, &cfg, "");
    assert!(
        beaten.ends_with("2.0 times that of any other overlay"),
        "{beaten}"
    );
}

#[test]
fn the_merged_yaml_origin_has_no_float_noise() {
    use slamlab::lab::saved_maps::SavedMaps;
    let blank = |name: &str, origin: Pose2| {
        RosMap::from_values(name, 4, 4, 0.05, origin, vec![0; 16]).unwrap()
    };
    let mut maps = SavedMaps::new();
    maps.add_loaded(blank("a", Pose2::new(1.0, 1.0, 0.0)))
        .unwrap();
    maps.add_loaded(blank("b", Pose2::new(0.2, 0.1, 0.0)))
        .unwrap();
    maps.merge(&mut |_| {}).unwrap();
    // B's corner lands at 0.1 + 0.2 = 0.30000000000000004 in A's frame.
    maps.keep_placement(0, 1, Pose2::new(0.1, 0.2, 0.0))
        .unwrap();
    let yaml = maps.merged_yaml("m.pgm").unwrap();
    assert!(yaml.contains("origin: [0.3, 0.3, 0.0]"), "{yaml}");
}
