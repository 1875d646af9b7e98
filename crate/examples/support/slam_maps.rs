//! A scenario's SLAM maps for the map-merging benchmarks (`bench_mapsearch`,
//! `bench_overlaps`): simulated once natively (a minute for sixteen robots
//! over an hour), or read back from a cache file (postcard) that an earlier
//! call with the same `cache` wrote.

use slamlab::lab::Lab;
use slamlab::slam::{MapperKind, OccupancyGrid};
use std::time::Instant;

/// Every robot's SLAM map after running the scenario at `path` to its end,
/// in the scenario's robot order; from `cache` when that file is there
/// (and written there when it is not).
pub fn slam_maps(
    path: &str,
    cache: Option<&String>,
) -> Result<Vec<OccupancyGrid>, Box<dyn std::error::Error>> {
    if let Some(bytes) = cache.and_then(|c| std::fs::read(c).ok()) {
        return Ok(postcard::from_bytes(&bytes)?);
    }
    let mut lab = Lab::new(&std::fs::read_to_string(path)?)?;
    let start = Instant::now();
    lab.run_to_end()?;
    println!("simulate (ms): {:.0}", start.elapsed().as_secs_f64() * 1e3);
    let sim = lab.simulation().ok_or("no simulation")?;
    let maps: Vec<OccupancyGrid> = sim
        .robots
        .iter()
        .map(|r| r.mapping.map(MapperKind::Slam).clone())
        .collect();
    if let Some(c) = cache {
        std::fs::write(c, postcard::to_allocvec(&maps)?)?;
    }
    Ok(maps)
}
