//! # Random mazes for experiments
//!
//! Seeded generators of scenarios the merge is benchmarked on (and that a
//! class can use for fresh exercises): perfect mazes carved by a randomised
//! depth-first search, with robots started in random cells at random
//! headings; and, for the cases where a merge must be refused, two separate
//! mazes side by side with one robot in each, so the robots can never see a
//! common place.
//!
//! A perfect maze has exactly one path between any two cells, so its walls
//! form one connected tree plus the outer boundary, and a robot following
//! either wall tours all of it given time: what two robots have in common
//! depends only on where they start and for how long they run.

use crate::rng::Rng;
use serde_json::{json, Value};
use std::f64::consts::PI;

/// What to generate.
#[derive(Clone, Debug)]
pub struct MazeSpec {
    /// Cells across and up.
    pub nx: usize,
    pub ny: usize,
    /// Cell size (m): corridors are this wide.
    pub cell_m: f64,
    pub seed: u64,
    /// Number of robots (they alternate left / right wall following).
    pub robots: usize,
    pub duration_s: f64,
    /// One texture name on every wall (a repeated texture), or each wall
    /// its own (None).
    pub texture: Option<String>,
}

impl Default for MazeSpec {
    fn default() -> Self {
        MazeSpec {
            nx: 5,
            ny: 4,
            cell_m: 2.5,
            seed: 1,
            robots: 2,
            duration_s: 300.0,
            texture: None,
        }
    }
}

/// The walls of a perfect maze of `nx × ny` cells of `cell_m`, offset by
/// `origin`, as `[x0, y0, x1, y1]` segments (outer boundary first).
pub fn maze_walls(
    rng: &mut Rng,
    nx: usize,
    ny: usize,
    cell_m: f64,
    origin: [f64; 2],
) -> Vec<[f64; 4]> {
    let (nx, ny) = (nx.max(1), ny.max(1));
    // east[x][y]: a wall between (x, y) and (x + 1, y); north likewise.
    let mut east = vec![vec![true; ny]; nx];
    let mut north = vec![vec![true; ny]; nx];
    let mut seen = vec![vec![false; ny]; nx];
    let mut stack = vec![(0usize, 0usize)];
    seen[0][0] = true;
    while let Some(&(x, y)) = stack.last() {
        let mut next = Vec::with_capacity(4);
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
        let (a, b) = next[(rng.next_u64() % next.len() as u64) as usize];
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
    let [ox, oy] = origin;
    let (w, h) = (nx as f64 * cell_m, ny as f64 * cell_m);
    let mut walls = vec![
        [ox, oy, ox + w, oy],
        [ox + w, oy, ox + w, oy + h],
        [ox + w, oy + h, ox, oy + h],
        [ox, oy + h, ox, oy],
    ];
    for x in 0..nx {
        for y in 0..ny {
            let (x0, y0) = (ox + x as f64 * cell_m, oy + y as f64 * cell_m);
            if x + 1 < nx && east[x][y] {
                walls.push([x0 + cell_m, y0, x0 + cell_m, y0 + cell_m]);
            }
            if y + 1 < ny && north[x][y] {
                walls.push([x0, y0 + cell_m, x0 + cell_m, y0 + cell_m]);
            }
        }
    }
    walls
}

fn wall_json(w: &[f64; 4], texture: &Option<String>) -> Value {
    let r = |v: f64| (v * 1000.0).round() / 1000.0;
    let mut o = json!({ "from": [r(w[0]), r(w[1])], "to": [r(w[2]), r(w[3])] });
    if let Some(t) = texture {
        o["texture"] = json!(t);
    }
    o
}

fn robot_json(i: usize, x: f64, y: f64, theta: f64) -> Value {
    let r = |v: f64| (v * 10_000.0).round() / 10_000.0;
    json!({
        "name": format!("robot{}", i + 1),
        "start": [r(x), r(y), r(theta)],
        "follow": if i.is_multiple_of(2) { "left" } else { "right" },
    })
}

/// A random perfect maze with `spec.robots` robots in distinct random cells
/// (cell centres) at random headings, as scenario JSON.
pub fn random_maze(spec: &MazeSpec) -> String {
    let mut rng = Rng::new(spec.seed ^ 0x6d61_7a65);
    let walls = maze_walls(&mut rng, spec.nx, spec.ny, spec.cell_m, [0.0, 0.0]);
    let cells = spec.nx.max(1) * spec.ny.max(1);
    let mut taken: Vec<usize> = Vec::new();
    let mut robots = Vec::new();
    for i in 0..spec.robots.min(cells) {
        let mut c = (rng.next_u64() % cells as u64) as usize;
        while taken.contains(&c) {
            c = (c + 1) % cells;
        }
        taken.push(c);
        let (cx, cy) = (c % spec.nx.max(1), c / spec.nx.max(1));
        let theta = rng.range(-PI, PI);
        robots.push(robot_json(
            i,
            (cx as f64 + 0.5) * spec.cell_m,
            (cy as f64 + 0.5) * spec.cell_m,
            theta,
        ));
    }
    json!({
        "name": format!("maze-{}", spec.seed),
        "seed": spec.seed,
        "duration_s": spec.duration_s,
        "walls": walls.iter().map(|w| wall_json(w, &spec.texture)).collect::<Vec<_>>(),
        "robots": robots,
    })
    .to_string()
}

/// Two separate random mazes 6 m apart with one robot in each: the robots
/// can never see a common place, so any merge would be wrong.
pub fn disjoint_mazes(spec: &MazeSpec) -> String {
    let mut rng = Rng::new(spec.seed ^ 0x6469_736a);
    let w = spec.nx as f64 * spec.cell_m;
    let mut walls = maze_walls(&mut rng, spec.nx, spec.ny, spec.cell_m, [0.0, 0.0]);
    walls.extend(maze_walls(
        &mut rng,
        spec.nx,
        spec.ny,
        spec.cell_m,
        [w + 6.0, 0.0],
    ));
    let mut robots = Vec::new();
    for (i, ox) in [0.0, w + 6.0].into_iter().enumerate() {
        let cx = (rng.next_u64() % spec.nx.max(1) as u64) as f64;
        let cy = (rng.next_u64() % spec.ny.max(1) as u64) as f64;
        let theta = rng.range(-PI, PI);
        robots.push(robot_json(
            i,
            ox + (cx + 0.5) * spec.cell_m,
            (cy + 0.5) * spec.cell_m,
            theta,
        ));
    }
    json!({
        "name": format!("disjoint-{}", spec.seed),
        "seed": spec.seed,
        "duration_s": spec.duration_s,
        "walls": walls.iter().map(|w| wall_json(w, &spec.texture)).collect::<Vec<_>>(),
        "robots": robots,
    })
    .to_string()
}
