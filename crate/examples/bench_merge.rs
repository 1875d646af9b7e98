//! The merge benchmark of issue 6: seeded random mazes with random starts
//! and headings, plus cases with no common region (two separate mazes) and
//! with one texture repeated on every wall. Every method runs on the same
//! simulated runs; the truth is used only to score.
//!
//! ```text
//! cargo run --release -p slamlab --example bench_merge -- [--runs 20] [--others 5] [--duration 300] [--methods auto,thesis,map-only] [--verbose]
//! ```
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

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs: u64 = arg(&args, "--runs")
        .and_then(|s| s.parse().ok())
        .unwrap_or(20);
    let others: u64 = arg(&args, "--others")
        .and_then(|s| s.parse().ok())
        .unwrap_or(5);
    let duration: f64 = arg(&args, "--duration")
        .and_then(|s| s.parse().ok())
        .unwrap_or(300.0);
    let methods: Vec<MergeMethod> = arg(&args, "--methods")
        .unwrap_or_else(|| "auto,thesis,map-only".into())
        .split(',')
        .map(|m| MergeMethod::parse(m).expect("method"))
        .collect();
    let verbose = args.iter().any(|a| a == "--verbose");
    let mut cases: Vec<(String, String)> = Vec::new();
    for seed in 1..=runs {
        let spec = MazeSpec {
            seed,
            duration_s: duration,
            ..bench_maze()
        };
        cases.push((format!("maze-{seed}"), random_maze(&spec)));
    }
    for seed in 1..=others {
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
    let mut tallies: Vec<(String, Tally)> = methods
        .iter()
        .flat_map(|m| {
            ["maze", "disjoint", "repeated"]
                .into_iter()
                .map(move |k| (format!("{}/{k}", m.name()), Tally::default()))
        })
        .collect();
    println!("case            method    common  status    error_m  error_deg  ms     reason");
    for (name, json) in &cases {
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
        for &method in &methods {
            let t0 = Instant::now();
            let mut job =
                MergeJob::new(&sim, MergeConfig::new(method, scenario.seed)).expect("job");
            let mut stage_ms: Vec<(&'static str, f64)> = Vec::new();
            while !job.is_done() {
                let stage = job.stage().name();
                let t = Instant::now();
                job.advance(&sim, usize::MAX).expect("merge runs");
                let dt = t.elapsed().as_secs_f64() * 1e3;
                match stage_ms.iter_mut().find(|(s, _)| *s == stage) {
                    Some(e) => e.1 += dt,
                    None => stage_ms.push((stage, dt)),
                }
            }
            let ms = t0.elapsed().as_secs_f64() * 1e3;
            if verbose {
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
            let outcome = job.outcome().expect("outcome");
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
            let reason: String = outcome.reason.chars().take(90).collect();
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
    }
    println!();
    println!("method/cases        runs  common  merged(common)  correct  imprecise  wrong  merged(no common)  median ms");
    for (key, t) in &tallies {
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
}
