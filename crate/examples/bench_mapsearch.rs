//! The map search ([`slamlab::merge::mapsearch`]) on a scenario's own SLAM
//! maps: simulates the scenario once natively, then times `search_maps`
//! on robot pairs, and (with `--compare`) checks that the branch and bound
//! translation search finds exactly the exhaustive search's peaks.
//!
//! ```text
//! cargo run --release -p slamlab --example bench_mapsearch -- S.json [--pairs 12] [--robots 5,7,11] [--compare] [--cache MAPS.bin]
//! ```
//!
//! `--cache` keeps the SLAM maps in that file and reads them back on the
//! next call instead of simulating again (`support/slam_maps.rs`, shared
//! with `bench_overlaps`).
//!
//! The pairs are taken in order (1, 2), (1, 3), … (1, n), (2, 3), …; the
//! first `--pairs` of them are searched.

use slamlab::merge::mapsearch::{coarse_peaks, search_maps, MapSearchConfig, TranslationSearch};
use slamlab::merge::verdict::VerdictConfig;
use std::time::Instant;

#[path = "support/slam_maps.rs"]
mod slam_maps;
use slam_maps::slam_maps;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = args
        .get(1)
        .ok_or("usage: bench_mapsearch S.json [--pairs N] [--robots A,B,...] [--compare] [--cache MAPS.bin]")?;
    let pairs: usize = args
        .iter()
        .position(|a| a == "--pairs")
        .and_then(|i| args.get(i + 1))
        .map_or(Ok(12), |s| s.parse())?;
    let compare = args.iter().any(|a| a == "--compare");
    let cache = args
        .iter()
        .position(|a| a == "--cache")
        .and_then(|i| args.get(i + 1));
    let owned = slam_maps(path, cache)?;
    let maps: Vec<_> = owned.iter().collect();
    let n = maps.len();
    // `--robots 5,7,11` restricts the pairs to those robots (1-based).
    let chosen: Vec<usize> = match args.iter().position(|a| a == "--robots") {
        Some(i) => args
            .get(i + 1)
            .ok_or("--robots needs a list")?
            .split(',')
            .map(|s| s.parse::<usize>().map(|r| r - 1))
            .collect::<Result<_, _>>()?,
        None => (0..n).collect(),
    };
    let list: Vec<(usize, usize)> = chosen
        .iter()
        .enumerate()
        .flat_map(|(k, &a)| chosen[k + 1..].iter().map(move |&b| (a, b)))
        .take(pairs)
        .collect();
    let (cfg, verdict) = (MapSearchConfig::default(), VerdictConfig::default());
    let mut total = 0.0;
    let mut peaks_total = [0.0, 0.0];
    for &(a, b) in &list {
        let t = Instant::now();
        let s = search_maps(maps[a], maps[b], &cfg, &verdict);
        let ms = t.elapsed().as_secs_f64() * 1e3;
        total += ms;
        let size = |g: &slamlab::slam::OccupancyGrid| {
            format!(
                "{:.0}x{:.0} m",
                g.width() as f64 * g.resolution_m(),
                g.height() as f64 * g.resolution_m()
            )
        };
        print!(
            "{}-{}: {} on {}, {:.0} ms, {:?}, {} hypotheses",
            a + 1,
            b + 1,
            size(maps[a]),
            size(maps[b]),
            ms,
            s.status,
            s.hypotheses.len()
        );
        if compare {
            let mut found = Vec::new();
            for (k, how) in [
                TranslationSearch::Exhaustive,
                TranslationSearch::BranchAndBound,
            ]
            .into_iter()
            .enumerate()
            {
                let t = Instant::now();
                found.push(coarse_peaks(maps[a], maps[b], &cfg, how));
                let ms = t.elapsed().as_secs_f64() * 1e3;
                peaks_total[k] += ms;
                print!(", {how:?} peaks {ms:.0} ms");
            }
            let same = found[0] == found[1];
            print!(", same: {same}");
            if !same {
                println!();
                return Err(
                    format!("pair {}-{}: {:?} != {:?}", a + 1, b + 1, found[0], found[1]).into(),
                );
            }
        }
        println!();
    }
    println!(
        "{} searches: {:.0} ms ({:.0} ms each)",
        list.len(),
        total,
        total / list.len().max(1) as f64
    );
    if compare {
        println!(
            "peaks only: exhaustive {:.0} ms, branch and bound {:.0} ms ({:.1}x)",
            peaks_total[0],
            peaks_total[1],
            peaks_total[0] / peaks_total[1].max(1e-9)
        );
    }
    Ok(())
}
