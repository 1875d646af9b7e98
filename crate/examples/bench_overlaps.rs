//! The pair budget's coarse map overlaps ([`slamlab::merge::mapsearch::coarse_overlap`])
//! on a scenario's own SLAM maps: every robot's coarse map, then every
//! pair's overlap, as the automatic merge's proposals compute them for many
//! robots (120 pairs for sixteen). Prints the time of each half and a hash
//! of the overlaps' bits, so that a change meant to be faster only can be
//! checked to give the same figures.
//!
//! ```text
//! cargo run --release -p slamlab --example bench_overlaps -- S.json [--cache MAPS.bin] [--runs 3] [--search N]
//! ```
//!
//! `--search N` times the whole map search ([`search_maps`]) of the first
//! `N` pairs instead, (1, 2), (1, 3), …, with a hash of their answers.
//!
//! The scenario is simulated once natively (a minute for sixteen robots
//! over an hour); with `--cache` its SLAM maps are kept in that file
//! (postcard) and read back on the next call instead (`support/slam_maps.rs`).

use slamlab::merge::mapsearch::{coarse_overlap, search_maps, CoarseMap, MapSearchConfig};
use slamlab::merge::pairbudget::PairBudgetConfig;
use slamlab::merge::verdict::VerdictConfig;
use slamlab::slam::OccupancyGrid;
use std::time::Instant;

#[path = "support/slam_maps.rs"]
mod slam_maps;
use slam_maps::slam_maps;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = args
        .get(1)
        .ok_or("usage: bench_overlaps S.json [--cache MAPS.bin] [--runs N]")?;
    let value = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
    };
    let runs: usize = value("--runs").map_or(Ok(3), |s| s.parse())?;
    let maps = slam_maps(path, value("--cache"))?;
    if let Some(n) = value("--search") {
        return search(&maps, n.parse()?, runs);
    }
    let cfg = PairBudgetConfig::default();
    for run in 0..runs {
        let t = Instant::now();
        let coarse: Vec<CoarseMap> = maps
            .iter()
            .map(|g| CoarseMap::new(g, cfg.coarse_cell_m, cfg.free_penalty))
            .collect();
        let maps_ms = t.elapsed().as_secs_f64() * 1e3;
        let t = Instant::now();
        let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
        let mut sum = 0.0;
        for a in 0..maps.len() {
            for b in a + 1..maps.len() {
                let s = coarse_overlap(&coarse[a], &coarse[b], &maps[b], cfg.free_penalty);
                sum += s;
                for byte in s.to_bits().to_le_bytes() {
                    hash = (hash ^ byte as u64).wrapping_mul(0x0100_0000_01b3);
                }
            }
        }
        let pairs_ms = t.elapsed().as_secs_f64() * 1e3;
        println!(
            "run {run}: coarse maps {maps_ms:.0} ms, overlaps {pairs_ms:.0} ms; mean overlap {:.4}, hash {hash:016x}",
            sum / (maps.len() * maps.len().saturating_sub(1) / 2).max(1) as f64
        );
    }
    Ok(())
}

/// The map search of the first `pairs` pairs, `runs` times.
fn search(
    maps: &[OccupancyGrid],
    pairs: usize,
    runs: usize,
) -> Result<(), Box<dyn std::error::Error>> {
    let list: Vec<(usize, usize)> = (0..maps.len())
        .flat_map(|a| (a + 1..maps.len()).map(move |b| (a, b)))
        .take(pairs)
        .collect();
    let (cfg, verdict) = (MapSearchConfig::default(), VerdictConfig::default());
    for run in 0..runs {
        let t = Instant::now();
        let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
        let mut merged = 0;
        for &(a, b) in &list {
            let s = search_maps(&maps[a], &maps[b], &cfg, &verdict);
            merged += usize::from(s.pose.is_some());
            let text = format!("{:?} {:?} {}", s.pose, s.status, s.hypotheses.len());
            for byte in text.bytes() {
                hash = (hash ^ byte as u64).wrapping_mul(0x0100_0000_01b3);
            }
        }
        println!(
            "run {run}: {} searches in {:.0} ms, {merged} with a transform, hash {hash:016x}",
            list.len(),
            t.elapsed().as_secs_f64() * 1e3
        );
    }
    Ok(())
}
