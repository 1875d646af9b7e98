//! Native benchmark of the merge's per-frame work (BENCHMARKS.md): rendering
//! the stored camera frames and describing them with SURF.
//!
//! `cargo run --release -p slamlab --example bench_frames [-- SCENARIO.json]`
//!
//! Runs the scenario (thesis preset by default), then renders every frame the
//! automatic merge would describe twice: the first pass paints the wall
//! texture chunks it meets, the second finds them cached, so the difference
//! is the painting. Then SURF on each frame as the merge runs it. Prints ms
//! per frame and a hash of all pixels and of all features, so a change meant
//! to be faster but identical can be checked to be identical.

use slamlab::lab::Lab;
use slamlab::merge::config::MergeConfig;
use slamlab::merge::frames::strongest_features;
use slamlab::merge::MergeMethod;
use slamlab::surf::GrayImage;
use std::time::Instant;

fn fnv(h: &mut u64, bytes: &[u8]) {
    for &b in bytes {
        *h ^= b as u64;
        *h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let text = match std::env::args().nth(1) {
        Some(path) => std::fs::read_to_string(path)?,
        None => include_str!("../../scenarios/thesis.json").to_string(),
    };
    let mut lab = Lab::new(&text)?;
    lab.run_to_end()?;
    let config = MergeConfig::new(MergeMethod::Auto, lab.scenario().seed);
    let sim = lab.simulation().ok_or("no simulation")?;
    let frames: Vec<_> = sim
        .robots
        .iter()
        .flat_map(|r| r.frames.frames.iter())
        .collect();
    let n = frames.len() as f64;
    let mut pixel_hash = 0xcbf2_9ce4_8422_2325u64;
    let mut images = Vec::new();
    let t = Instant::now();
    for f in &frames {
        let img = sim.frame_image(f);
        fnv(&mut pixel_hash, &img.gray);
        images.push(img);
    }
    let first = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    for f in &frames {
        std::hint::black_box(sim.frame_image(f));
    }
    let second = t.elapsed().as_secs_f64() * 1e3;
    let mut feature_hash = 0xcbf2_9ce4_8422_2325u64;
    let t = Instant::now();
    for img in images {
        let img = GrayImage::new(img.width as usize, img.height as usize, img.gray)?;
        let f = strongest_features(&img, &config.surf, config.max_keypoints);
        for (k, d) in f.keypoints.iter().zip(&f.descriptors) {
            for v in [k.x, k.y, k.scale, k.orientation, k.response] {
                fnv(&mut feature_hash, &v.to_le_bytes());
            }
            for v in d.0.iter() {
                fnv(&mut feature_hash, &v.to_le_bytes());
            }
        }
    }
    let surf = t.elapsed().as_secs_f64() * 1e3;
    println!(
        "{} frames: render {:.2} ms/frame with texture painting, {:.2} cached \
         (painting {:.0} ms in all); SURF {:.2} ms/frame",
        frames.len(),
        first / n,
        second / n,
        first - second,
        surf / n
    );
    println!("pixels {pixel_hash:016x}  features {feature_hash:016x}");
    Ok(())
}
