//! Shared helpers of the SLAM tests: running scenarios, scoring, and a
//! seeded random-maze generator.
#![allow(dead_code)]

use slamlab::scenario::Scenario;
use slamlab::sim::Simulation;
use slamlab::slam::eval::scoring::{ate_m, map_accuracy, MapAccuracy};
use slamlab::slam::mapper::MapperKind;

pub const PRESETS: [(&str, &str); 4] = [
    ("thesis", include_str!("../../scenarios/thesis.json")),
    ("office", include_str!("../../scenarios/office.json")),
    ("loop", include_str!("../../scenarios/loop.json")),
    ("maze", include_str!("../../scenarios/maze.json")),
];

/// Figures of one robot after a run.
#[derive(Debug, Clone)]
pub struct RobotFigures {
    pub name: String,
    pub slam_ate_m: f64,
    pub odometry_ate_m: f64,
    pub slam_map: MapAccuracy,
    pub odometry_map: MapAccuracy,
    pub path_m: f64,
}

/// Runs a scenario to its end (or for `duration_s`) and scores every
/// robot. The camera is off: nothing here looks at frames, and capture
/// draws none of the robots' random numbers, so the run is the same.
pub fn run(json: &str, duration_s: Option<f64>) -> (Simulation, Vec<RobotFigures>) {
    let mut scenario = Scenario::parse(json).expect("scenario parses");
    if let Some(d) = duration_s {
        scenario.duration_s = d;
    }
    let mut sim = Simulation::new(&scenario).expect("scenario runs");
    sim.set_capture(false);
    sim.run_to_end();
    let figures = figures(&sim);
    (sim, figures)
}

pub fn figures(sim: &Simulation) -> Vec<RobotFigures> {
    sim.robots
        .iter()
        .map(|r| {
            let start = r.spec.start_pose();
            RobotFigures {
                name: r.spec.name.clone(),
                slam_ate_m: ate_m(&start, r.mapping.estimates(), &r.log.truth),
                odometry_ate_m: ate_m(&start, &r.log.odometry, &r.log.truth),
                slam_map: map_accuracy(r.mapping.map(MapperKind::Slam), &start, &sim.world),
                odometry_map: map_accuracy(r.mapping.map(MapperKind::Odometry), &start, &sim.world),
                path_m: r.log.path_length_m(),
            }
        })
        .collect()
}

/// A small deterministic generator (SplitMix64) for the maze layout.
struct SplitMix(u64);
impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// A perfect maze of `nx × ny` square cells of `cell_m` (depth-first
/// carving), as a scenario with two wall-following robots in opposite
/// corners. Same `seed`, same maze.
pub fn random_maze(seed: u64, nx: usize, ny: usize, cell_m: f64, duration_s: f64) -> String {
    let mut rng = SplitMix(seed);
    // east[x][y]: wall between (x,y) and (x+1,y); north likewise.
    let mut east = vec![vec![true; ny]; nx];
    let mut north = vec![vec![true; ny]; nx];
    let mut seen = vec![vec![false; ny]; nx];
    let mut stack = vec![(0usize, 0usize)];
    seen[0][0] = true;
    while let Some(&(x, y)) = stack.last() {
        let mut next = Vec::new();
        if x + 1 < nx && !seen[x + 1][y] {
            next.push((x + 1, y));
        }
        if x > 0 && !seen[x - 1][y] {
            next.push((x - 1, y));
        }
        if y + 1 < ny && !seen[x][y + 1] {
            next.push((x, y + 1));
        }
        if y > 0 && !seen[x][y - 1] {
            next.push((x, y - 1));
        }
        if next.is_empty() {
            stack.pop();
            continue;
        }
        let (a, b) = next[rng.below(next.len())];
        if a > x {
            east[x][y] = false;
        } else if a < x {
            east[a][y] = false;
        } else if b > y {
            north[x][y] = false;
        } else {
            north[x][b] = false;
        }
        seen[a][b] = true;
        stack.push((a, b));
    }
    let mut walls = Vec::new();
    let (w, h) = (nx as f64 * cell_m, ny as f64 * cell_m);
    for (f, t) in [
        ([0.0, 0.0], [w, 0.0]),
        ([w, 0.0], [w, h]),
        ([w, h], [0.0, h]),
        ([0.0, h], [0.0, 0.0]),
    ] {
        walls.push(format!(
            r#"{{"from":[{},{}],"to":[{},{}]}}"#,
            f[0], f[1], t[0], t[1]
        ));
    }
    for x in 0..nx {
        for y in 0..ny {
            let (x0, y0) = (x as f64 * cell_m, y as f64 * cell_m);
            if x + 1 < nx && east[x][y] {
                walls.push(format!(
                    r#"{{"from":[{},{}],"to":[{},{}]}}"#,
                    x0 + cell_m,
                    y0,
                    x0 + cell_m,
                    y0 + cell_m
                ));
            }
            if y + 1 < ny && north[x][y] {
                walls.push(format!(
                    r#"{{"from":[{},{}],"to":[{},{}]}}"#,
                    x0,
                    y0 + cell_m,
                    x0 + cell_m,
                    y0 + cell_m
                ));
            }
        }
    }
    let c = cell_m / 2.0;
    format!(
        r#"{{"name":"maze-{seed}","seed":{seed},"duration_s":{duration_s},"walls":[{}],
        "robots":[{{"name":"robot1","start":[{c},{c},0.0],"follow":"left"}},
                  {{"name":"robot2","start":[{},{},3.14159],"follow":"right"}}]}}"#,
        walls.join(","),
        w - c,
        h - c
    )
}
