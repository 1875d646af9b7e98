//! The map search's translation peaks ([`slamlab::merge::peaksearch`]) on a
//! synthetic raster, without a simulation first: a maze-like lattice of
//! walls two cells thick (3 m cells at 0.1 m, a third of the segments
//! left out, by seed) in a `size × size` raster, searched against a window
//! of itself turned by a quarter turn, as the map search meets two robots'
//! maps whose frames differ by 90°. Prints each round's time, the pyramid
//! lookups and a hash of the peaks (the same before and after a change
//! that keeps the search exact).
//!
//! ```text
//! cargo run --release -p slamlab --example bench_peaks -- [--size 700] [--rounds 3] [--turn DEG]
//! ```
//!
//! `--turn` turns the lattice by whole degrees in the raster (the hour's
//! maps: robots start at random headings, so their walls are staircases).
//! It also builds for `wasm32-wasip1` and runs in node's WASI, to measure
//! the wasm build (BENCHMARKS.md, "Many robots").

use slamlab::merge::peaksearch::{pyramid_of, PeakSearch, ScoreImage};
use std::time::Instant;

/// Score and wall cells of a lattice maze `size` cells a side, its walls
/// turned by `turn` (radians) about the raster's centre: a map whose frame
/// is not along its walls draws them as staircases.
fn lattice(size: usize, period: usize, seed: u64, turn: f64) -> (Vec<i32>, Vec<[usize; 2]>) {
    let mut rng = slamlab::rng::Rng::new(seed);
    // Which lattice segments stand, for lattice cells over a margin wide
    // enough for any turn: keep[cell][0] along x, [1] along y.
    let cells = 3 * (size / period + 2);
    let keep: Vec<[bool; 2]> = (0..cells * cells)
        .map(|_| {
            [
                !rng.next_u64().is_multiple_of(3),
                !rng.next_u64().is_multiple_of(3),
            ]
        })
        .collect();
    let (s, c) = turn.sin_cos();
    let centre = size as f64 / 2.0;
    let offset = (cells / 3 * period) as f64;
    let on_wall = |x: usize, y: usize| {
        let (dx, dy) = (x as f64 + 0.5 - centre, y as f64 + 0.5 - centre);
        let u = c * dx + s * dy + centre + offset;
        let v = -s * dx + c * dy + centre + offset;
        let (cu, cv) = ((u / period as f64) as usize, (v / period as f64) as usize);
        let (fu, fv) = (u % period as f64, v % period as f64);
        let cell = |cu: usize, cv: usize| keep.get(cv * cells + cu).copied().unwrap_or([false; 2]);
        (fv < 2.0 && cell(cu, cv)[0]) || (fu < 2.0 && cell(cu, cv)[1])
    };
    let mut wall = vec![false; size * size];
    for y in 0..size {
        for x in 0..size {
            wall[y * size + x] = on_wall(x, y);
        }
    }
    let mut score = vec![0; size * size];
    let mut walls = Vec::new();
    for y in 0..size {
        for x in 0..size {
            let near = (y.saturating_sub(1)..(y + 2).min(size))
                .any(|v| (x.saturating_sub(1)..(x + 2).min(size)).any(|u| wall[v * size + u]));
            score[y * size + x] = if near { 1 } else { -1 };
            if wall[y * size + x] {
                walls.push([x, y]);
            }
        }
    }
    (score, walls)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let opt = |name: &str, default: usize| -> Result<usize, Box<dyn std::error::Error>> {
        Ok(match args.iter().position(|a| a == name) {
            Some(i) => args.get(i + 1).ok_or("a value")?.parse()?,
            None => default,
        })
    };
    let (size, rounds) = (opt("--size", 700)?, opt("--rounds", 3)?);
    let turn = (opt("--turn", 0)? as f64).to_radians();
    let (sa, wa) = lattice(size, 30, 7, turn);
    // B: the middle half of A, turned by a quarter turn.
    let (lo, n) = (size / 4, size / 2);
    let mut sb = vec![0; n * n];
    let mut wb = Vec::new();
    for y in 0..n {
        for x in 0..n {
            // B(x, y) = A(lo + y, lo + n − 1 − x).
            let (ax, ay) = (lo + y, lo + n - 1 - x);
            sb[y * n + x] = sa[ay * size + ax];
        }
    }
    for &[ax, ay] in &wa {
        if (lo..lo + n).contains(&ax) && (lo..lo + n).contains(&ay) {
            wb.push([lo + n - 1 - ay, ax - lo]);
        }
    }
    wb.sort_by_key(|p| (p[1], p[0]));
    let a = ScoreImage {
        width: size,
        height: size,
        score: &sa,
        walls: &wa,
    };
    // B turned back by the search's rotation: the quarter turn undone.
    let mut sb_back = vec![0; n * n];
    let mut wb_back = Vec::new();
    for y in 0..n {
        for x in 0..n {
            sb_back[y * n + x] = sb[x * n + (n - 1 - y)];
        }
    }
    for &[bx, by] in &wb {
        wb_back.push([n - 1 - by, bx]);
    }
    let b = ScoreImage {
        width: n,
        height: n,
        score: &sb_back,
        walls: &wb_back,
    };
    println!(
        "A {size}x{size}, {} wall cells; B {n}x{n}, {} wall cells",
        wa.len(),
        wb_back.len()
    );
    for round in 0..rounds {
        let t = Instant::now();
        let mut a_max = pyramid_of(&a).ok_or("fits a byte")?;
        let built = t.elapsed().as_secs_f64() * 1e3;
        let mut search = PeakSearch::new(a, &mut a_max, b, 12, 20.0).ok_or("fits a byte")?;
        let peaks = search.run(&a_max, u64::MAX).unwrap_or_default();
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let hash = peaks.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, (i, v)| {
            let h = (h ^ i[0] as u64).wrapping_mul(0x100_0000_01b3);
            let h = (h ^ i[1] as u64).wrapping_mul(0x100_0000_01b3);
            (h ^ *v as u64).wrapping_mul(0x100_0000_01b3)
        });
        println!(
            "round {round}: {ms:.0} ms (pyramid {built:.0} ms), {} lookups, {} peaks, best {:?}, hash {hash:016x}",
            search.lookups(),
            peaks.len(),
            peaks.first()
        );
    }
    Ok(())
}
