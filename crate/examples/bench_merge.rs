//! The merge benchmark of issue 6: seeded random mazes with random starts
//! and headings, plus cases with no common region (two separate mazes) and
//! with one texture repeated on every wall. Every method runs on the same
//! simulated runs; the truth is used only to score.
//!
//! ```text
//! cargo run --release -p slamlab --example bench_merge -- [--runs 20] [--first-seed 1] [--others 5] [--multi 5] [--duration 300] [--methods auto,thesis,map-only] [--verbose] [--only maze-10] [--scenario-out DIR]
//! cargo run --release -p slamlab --example bench_merge -- --dump-search   # the map search alone, every hypothesis against the truth
//! ```
//!
//! `--multi N` adds N mazes with three robots each, scored robot by robot:
//! each robot's map frame in the merged frame against the truth.
//!
//! A run "has a common region" when, placed with the true transform, the
//! two SLAM maps share at least `COMMON_CELLS` wall cells. A merge is
//! *correct* within 0.1 m and 1°, *wrong* beyond 0.3 m or 3° (between the
//! two it is counted as imprecise).

use slamlab::geom::{wrap_angle, Pose2};
use slamlab::maze::{disjoint_mazes, random_maze, MazeSpec};
use slamlab::merge::job::{MergeConfig, MergeJob};
use slamlab::merge::{MergeMethod, MergeStatus};
use slamlab::scenario::Scenario;
use slamlab::sim::Simulation;
use slamlab::slam::{CellState, MapperKind, OccupancyGrid};
use std::time::Instant;

const COMMON_CELLS: usize = 40;

fn arg(args: &[String], name: &str) -> Option<String> {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}

/// Wall cells of `b` (moved by the true transform) that fall within one
/// cell of a wall cell of `a`.
fn common_wall_cells(a: &OccupancyGrid, b: &OccupancyGrid, b_in_a: &Pose2) -> usize {
    let mut n = 0;
    for iy in 0..b.height() {
        for ix in 0..b.width() {
            if b.state(ix, iy) != CellState::Occupied {
                continue;
            }
            let p = b_in_a.transform_point(b.cell_centre(ix, iy));
            let g = a.global_cell(p);
            let hit = (-1..=1).any(|dy| {
                (-1..=1).any(|dx| {
                    a.local([g[0] + dx, g[1] + dy])
                        .is_some_and(|(x, y)| a.state(x, y) == CellState::Occupied)
                })
            });
            if hit {
                n += 1;
            }
        }
    }
    n
}

/// 8 × 6 cells of 2.5 m (20 × 15 m): in 300 s a robot tours about half of
/// it, so how much two robots share varies from run to run.
fn bench_maze() -> MazeSpec {
    MazeSpec {
        nx: 8,
        ny: 6,
        ..MazeSpec::default()
    }
}

#[derive(Default)]
struct Tally {
    runs: usize,
    common: usize,
    merged_common: usize,
    correct: usize,
    imprecise: usize,
    wrong: usize,
    no_common_merged: usize,
    ms: Vec<f64>,
    errors: Vec<(f64, f64)>,
}

/// The command line (see the module docs); the experiments' knobs are
/// `None` unless given.
struct Options {
    runs: u64,
    others: u64,
    duration: f64,
    methods: Vec<MergeMethod>,
    multi: u64,
    verbose: bool,
    /// `--only maze-14`: just that case, with the whole reason.
    only: Option<String>,
    /// `--scenario-out DIR`: write the cases' scenario files instead of running them.
    scenario_out: Option<String>,
    /// `--min-places N`: the verdict's independent places (an experiment).
    min_places: Option<usize>,
    /// `--min-inliers N`: rigid inliers a frame pair needs (an experiment).
    min_inliers: Option<usize>,
    /// `--max-keypoints N`, `--min-motion M`: frame features and thinning (experiments).
    max_keypoints: Option<usize>,
    min_motion: Option<f64>,
    proposals: Option<usize>,
    max_pairs: Option<usize>,
    /// `--first-seed S`: mazes S..S+runs (default 1), e.g. for a held-out set.
    first_seed: u64,
    /// `--first-other S`: the no-overlap and repeated-texture cases use seeds
    /// S..S+others (default 1: disjoint-101…, repeated-201…).
    first_other: u64,
    dump_search: bool,
    /// `--no-map-search`: the automatic method on vision alone (as before
    /// the map search existed).
    no_map_search: bool,
}

impl Options {
    fn parse(args: &[String]) -> Options {
        let number = |name: &str| arg(args, name).and_then(|s| s.parse().ok());
        Options {
            runs: number("--runs").unwrap_or(20),
            others: number("--others").unwrap_or(5),
            duration: arg(args, "--duration")
                .and_then(|s| s.parse().ok())
                .unwrap_or(300.0),
            methods: arg(args, "--methods")
                .unwrap_or_else(|| "auto,thesis,map-only".into())
                .split(',')
                .map(|m| MergeMethod::parse(m).expect("method"))
                .collect(),
            multi: number("--multi").unwrap_or(0),
            verbose: args.iter().any(|a| a == "--verbose"),
            only: arg(args, "--only"),
            scenario_out: arg(args, "--scenario-out"),
            min_places: arg(args, "--min-places").and_then(|s| s.parse().ok()),
            min_inliers: arg(args, "--min-inliers").and_then(|s| s.parse().ok()),
            max_keypoints: arg(args, "--max-keypoints").and_then(|s| s.parse().ok()),
            min_motion: arg(args, "--min-motion").and_then(|s| s.parse().ok()),
            proposals: arg(args, "--proposals").and_then(|s| s.parse().ok()),
            max_pairs: arg(args, "--max-pairs").and_then(|s| s.parse().ok()),
            first_seed: number("--first-seed").unwrap_or(1),
            first_other: number("--first-other").unwrap_or(1),
            dump_search: args.iter().any(|a| a == "--dump-search"),
            no_map_search: args.iter().any(|a| a == "--no-map-search"),
        }
    }

    /// The merge's configuration for `method`, with the experiments' knobs.
    fn merge_config(&self, method: MergeMethod, seed: u64) -> MergeConfig {
        let mut cfg = MergeConfig::new(method, seed);
        if let Some(n) = self.min_places {
            cfg.verdict.min_places = n;
        }
        if let Some(n) = self.min_inliers {
            cfg.verify.min_inliers = n;
        }
        if let Some(n) = self.max_keypoints {
            cfg.max_keypoints = n;
        }
        if let Some(m) = self.min_motion {
            cfg.min_motion_m = m;
        }
        if let Some(n) = self.proposals {
            cfg.proposals_per_frame = n;
        }
        if let Some(n) = self.max_pairs {
            cfg.max_pairs = n;
        }
        if self.no_map_search {
            cfg.map_search = None;
        }
        cfg
    }
}

/// The benchmark's cases, (name, scenario JSON): random mazes, then
/// disjoint pairs and repeated-texture mazes, then three-robot mazes.
fn bench_cases(o: &Options) -> Vec<(String, String)> {
    let duration = o.duration;
    let mut cases: Vec<(String, String)> = Vec::new();
    for seed in o.first_seed..o.first_seed + o.runs {
        let spec = MazeSpec {
            seed,
            duration_s: duration,
            ..bench_maze()
        };
        cases.push((format!("maze-{seed}"), random_maze(&spec)));
    }
    for seed in o.first_other..o.first_other + o.others {
        let spec = MazeSpec {
            seed: 100 + seed,
            duration_s: duration,
            ..bench_maze()
        };
        cases.push((format!("disjoint-{}", 100 + seed), disjoint_mazes(&spec)));
        let spec = MazeSpec {
            seed: 200 + seed,
            duration_s: duration,
            texture: Some("brick".into()),
            ..bench_maze()
        };
        cases.push((format!("repeated-{}", 200 + seed), random_maze(&spec)));
    }
    for seed in 1..=o.multi {
        let spec = MazeSpec {
            seed: 300 + seed,
            robots: 3,
            duration_s: duration,
            ..bench_maze()
        };
        cases.push((format!("three-{}", 300 + seed), random_maze(&spec)));
    }
    cases
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let o = Options::parse(&args);
    let cases = bench_cases(&o);
    let mut tallies: Vec<(String, Tally)> = o
        .methods
        .iter()
        .flat_map(|m| {
            ["maze", "disjoint", "repeated", "three"]
                .into_iter()
                .map(move |k| (format!("{}/{k}", m.name()), Tally::default()))
        })
        .collect();
    let mut multi_tally: Vec<(&'static str, MultiTally)> = Vec::new();
    println!("case            method    common  status    error_m  error_deg  ms     reason");
    for (name, json) in &cases {
        if o.only.as_ref().is_some_and(|only| only != name) {
            continue;
        }
        if let Some(dir) = &o.scenario_out {
            // `--scenario-out DIR`: each case as a scenario file, to open in
            // the page or run with `node web/cli.mjs run`.
            let path = std::path::Path::new(dir).join(format!("{name}.json"));
            std::fs::write(&path, json).expect("write the scenario");
            println!("wrote {}", path.display());
            continue;
        }
        let scenario = Scenario::parse(json).expect("scenario parses");
        let mut sim = Simulation::new(&scenario).expect("scenario runs");
        sim.run_to_end();
        let starts: Vec<Pose2> = sim.robots.iter().map(|r| r.spec.start_pose()).collect();
        let truth = starts[0].inverse().compose(&starts[1]);
        let common = common_wall_cells(
            sim.robots[0].mapping.map(MapperKind::Slam),
            sim.robots[1].mapping.map(MapperKind::Slam),
            &truth,
        );
        let kind = name.split('-').next().unwrap_or("maze");
        let has_common = kind != "disjoint" && common >= COMMON_CELLS;
        if o.dump_search {
            // `--dump-search`: the map-only search on robots 1 and 2 alone,
            // every hypothesis scored against the truth (an experiment).
            dump_map_search(name, common, &sim, &truth);
            continue;
        }
        for &method in &o.methods {
            let t0 = Instant::now();
            let (job, stage_ms) = run_merge(&sim, o.merge_config(method, scenario.seed));
            let ms = t0.elapsed().as_secs_f64() * 1e3;
            if o.verbose {
                print_merge_work(&job, &stage_ms);
            }
            let outcome = job.outcome().expect("outcome");
            if kind == "three" {
                score_robots(&sim, &starts, outcome, &mut multi_tally, method, name, ms);
                continue;
            }
            let case = Case {
                name,
                kind,
                common,
                has_common,
                truth: &truth,
            };
            score_pair(
                &case,
                &sim,
                outcome,
                &mut tallies,
                method,
                ms,
                o.only.is_some(),
            );
        }
    }
    print_summary(&tallies, &multi_tally);
}

/// Runs the merge stage by stage, timing each stage (ms).
fn run_merge(sim: &Simulation, cfg: MergeConfig) -> (MergeJob, Vec<(&'static str, f64)>) {
    let mut job = MergeJob::new(sim, cfg).expect("job");
    let mut stage_ms: Vec<(&'static str, f64)> = Vec::new();
    while !job.is_done() {
        let stage = job.stage().name();
        let t = Instant::now();
        job.advance(sim, usize::MAX).expect("merge runs");
        let dt = t.elapsed().as_secs_f64() * 1e3;
        match stage_ms.iter_mut().find(|(s, _)| *s == stage) {
            Some(e) => e.1 += dt,
            None => stage_ms.push((stage, dt)),
        }
    }
    (job, stage_ms)
}

/// What the merge looked at, and each stage's milliseconds (`--verbose`).
fn print_merge_work(job: &MergeJob, stage_ms: &[(&'static str, f64)]) {
    let frames: usize = job.robots.iter().map(|r| r.selected.len()).sum();
    let pairs: usize = job.pairs.iter().map(|p| p.cells.len()).sum();
    let parts: Vec<String> = stage_ms
        .iter()
        .map(|(s, t)| format!("{s} {t:.0}"))
        .collect();
    let kps: usize = job
        .robots
        .iter()
        .flat_map(|r| r.features.iter())
        .map(|f| f.len())
        .sum();
    println!(
        "    {frames} frames ({:.0} keypoints each), {pairs} pairs checked; ms: {}",
        kps as f64 / frames.max(1) as f64,
        parts.join(", ")
    );
}

/// A two-robot case as the scoring sees it.
struct Case<'a> {
    name: &'a str,
    kind: &'a str,
    /// Wall cells the two SLAM maps share under the true transform.
    common: usize,
    has_common: bool,
    /// Robot 2's start in robot 1's start frame.
    truth: &'a Pose2,
}

/// Scores robot 2's transform against the truth, counts it in its
/// method's tally for the case's kind, and prints the case's line.
fn score_pair(
    case: &Case,
    sim: &Simulation,
    outcome: &slamlab::merge::job::MergeOutcome,
    tallies: &mut [(String, Tally)],
    method: MergeMethod,
    ms: f64,
    whole_reason: bool,
) {
    let (name, kind, common, has_common, truth) = (
        case.name,
        case.kind,
        case.common,
        case.has_common,
        case.truth,
    );
    let merged = outcome.status == MergeStatus::Merged;
    let err = outcome
        .transforms
        .iter()
        .find(|t| t.robot == sim.robots[1].spec.name)
        .map(|t| {
            let p = Pose2::new(t.pose[0], t.pose[1], t.pose[2]);
            (
                (p.position() - truth.position()).length(),
                wrap_angle(p.theta - truth.theta).to_degrees().abs(),
            )
        });
    let key = format!("{}/{kind}", method.name());
    let tally = &mut tallies
        .iter_mut()
        .find(|(k, _)| *k == key)
        .expect("tally")
        .1;
    tally.runs += 1;
    tally.ms.push(ms);
    if has_common {
        tally.common += 1;
    }
    if merged {
        let (m, d) = err.unwrap_or((f64::INFINITY, f64::INFINITY));
        tally.errors.push((m, d));
        if has_common {
            tally.merged_common += 1;
        } else {
            tally.no_common_merged += 1;
        }
        if m <= 0.1 && d <= 1.0 {
            tally.correct += 1;
        } else if m > 0.3 || d > 3.0 {
            tally.wrong += 1;
        } else {
            tally.imprecise += 1;
        }
    }
    let reason: String = if whole_reason {
        outcome.reason.clone()
    } else {
        outcome.reason.chars().take(90).collect()
    };
    println!(
        "{name:<15} {:<9} {common:>6}  {:<8} {:>8} {:>9} {ms:>6.0}  {reason}",
        method.name(),
        if merged { "merged" } else { "no_merge" },
        err.filter(|_| merged)
            .map_or("-".into(), |e| format!("{:.3}", e.0)),
        err.filter(|_| merged)
            .map_or("-".into(), |e| format!("{:.2}", e.1)),
    );
}

/// The tables at the end: each method's two-robot tallies by kind of case,
/// then its three-robot joins.
fn print_summary(tallies: &[(String, Tally)], multi_tally: &[(&'static str, MultiTally)]) {
    println!();
    println!("method/cases        runs  common  merged(common)  correct  imprecise  wrong  merged(no common)  median ms");
    for (key, t) in tallies {
        if t.runs == 0 {
            continue;
        }
        let mut ms = t.ms.clone();
        ms.sort_by(|a, b| a.total_cmp(b));
        println!(
            "{key:<19} {:>4}  {:>6}  {:>14}  {:>7}  {:>9}  {:>5}  {:>17}  {:>9.0}",
            t.runs,
            t.common,
            t.merged_common,
            t.correct,
            t.imprecise,
            t.wrong,
            t.no_common_merged,
            ms[ms.len() / 2]
        );
    }
    for (method, t) in multi_tally {
        println!(
            "{method}/three: {} robots to join in {} runs, {} joined ({} correct, {} imprecise, {} wrong)",
            t.robots, t.runs, t.joined, t.correct, t.imprecise, t.wrong
        );
    }
}

/// Three-robot runs, scored robot by robot.
#[derive(Default)]
struct MultiTally {
    runs: usize,
    /// Robots other than the first (each needs joining).
    robots: usize,
    joined: usize,
    correct: usize,
    imprecise: usize,
    wrong: usize,
}

fn score_robots(
    sim: &Simulation,
    starts: &[Pose2],
    outcome: &slamlab::merge::job::MergeOutcome,
    tallies: &mut Vec<(&'static str, MultiTally)>,
    method: MergeMethod,
    name: &str,
    ms: f64,
) {
    if !tallies.iter().any(|(m, _)| *m == method.name()) {
        tallies.push((method.name(), MultiTally::default()));
    }
    let t = &mut tallies
        .iter_mut()
        .find(|(m, _)| *m == method.name())
        .expect("tally")
        .1;
    t.runs += 1;
    let mut parts = Vec::new();
    for (i, r) in sim.robots.iter().enumerate().skip(1) {
        t.robots += 1;
        let truth = starts[0].inverse().compose(&starts[i]);
        let Some(tf) = outcome.transforms.iter().find(|x| x.robot == r.spec.name) else {
            parts.push(format!("{} unjoined", r.spec.name));
            continue;
        };
        t.joined += 1;
        let p = Pose2::new(tf.pose[0], tf.pose[1], tf.pose[2]);
        let (m, d) = (
            (p.position() - truth.position()).length(),
            wrap_angle(p.theta - truth.theta).to_degrees().abs(),
        );
        if m <= 0.1 && d <= 1.0 {
            t.correct += 1;
        } else if m > 0.3 || d > 3.0 {
            t.wrong += 1;
        } else {
            t.imprecise += 1;
        }
        parts.push(format!("{} {m:.3} m {d:.2}°", r.spec.name));
    }
    println!(
        "{name:<15} {:<9} {ms:>6.0}  {}",
        method.name(),
        parts.join(", ")
    );
}

fn dump_map_search(name: &str, common: usize, sim: &Simulation, truth: &Pose2) {
    use slamlab::merge::mapsearch::{search_maps, MapSearchConfig};
    use slamlab::merge::verdict::VerdictConfig;
    let a = sim.robots[0].mapping.map(MapperKind::Slam);
    let b = sim.robots[1].mapping.map(MapperKind::Slam);
    let t = Instant::now();
    let s = search_maps(a, b, &MapSearchConfig::default(), &VerdictConfig::default());
    let ms = t.elapsed().as_secs_f64() * 1e3;
    let err = |p: &Pose2| {
        (
            (p.position() - truth.position()).length(),
            wrap_angle(p.theta - truth.theta).to_degrees().abs(),
        )
    };
    let verdict_err = s.pose.as_ref().map(err);
    println!(
        "{name:<15} common {common:>5} {:?} {ms:.0} ms rot {:.2}° (truth {:.2}°) err {:?} :: {}",
        s.status,
        s.rotation_rad.unwrap_or(f64::NAN).to_degrees(),
        truth.theta.to_degrees(),
        verdict_err,
        s.reason
    );
    for (i, h) in s.hypotheses.iter().enumerate() {
        let p = h.pose.unwrap_or(h.coarse);
        let (m, d) = err(&p);
        let (cm, cd) = err(&h.coarse);
        let ag = h.agreement.unwrap_or_default();
        println!(
            "   {}{} #{i:<2} coarse {:>6} ({cm:.2} m {cd:.1}°) -> {m:.2} m {d:.1}°  agree {:>5} min {:>5} contra {:>4} run {:>4} weak {:>6.0} free {:>6} net {:>7.0}  {}",
            if Some(i) == s.winner { "W" } else { " " },
            if Some(i) == s.runner_up { "R" } else { " " },
            h.coarse_score,
            ag.occupied_agree,
            ag.min_direction_agree,
            ag.occupied_contradict,
            ag.largest_contradiction,
            ag.weak_constraint,
            ag.free_agree,
            h.net,
            h.failure.clone().unwrap_or_else(|| "PASS".into())
        );
    }
}
