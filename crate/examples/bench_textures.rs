//! Native benchmark of painting wall textures (BENCHMARKS.md, "Simulation,
//! camera and drawing").
//!
//! `cargo run --release -p slamlab --example bench_textures [-- CHUNKS]`
//!
//! Paints the first CHUNKS (default 40) 1-m chunks of each named texture
//! style into a fresh bank (seed 7, walls 2 m tall, as the thesis preset),
//! so every chunk is painted once: its shapes, the neighbours' shapes that
//! reach into it, and its two mip levels. Prints ms per chunk and a hash of
//! all grey texels, so a change meant to be faster but identical can be
//! checked to be identical.

use slamlab::camera::texture::{TextureBank, TextureKey};
use std::time::Instant;

const NAMES: [&str; 12] = [
    "brick",
    "stone",
    "posters",
    "maps",
    "bookshelf",
    "signs",
    "crates",
    "graffiti",
    "mosaic",
    "tiles",
    "wood",
    "marble",
];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let chunks: i64 = match std::env::args().nth(1) {
        Some(s) => s.parse()?,
        None => 40,
    };
    let mut bank = TextureBank::new(7, 2.0);
    let mut hash = 0xcbf2_9ce4_8422_2325u64;
    let t = Instant::now();
    for name in NAMES {
        for k in 0..chunks {
            let chunk = bank.chunk(&TextureKey::new(name, false), k);
            for level in &chunk.gray {
                for &b in level {
                    hash ^= b as u64;
                    hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
                }
            }
        }
    }
    let ms = t.elapsed().as_secs_f64() * 1e3;
    let n = NAMES.len() as f64 * chunks as f64;
    println!(
        "{n} chunks painted: {:.3} ms per chunk ({ms:.0} ms in all); texels {hash:016x}",
        ms / n
    );
    Ok(())
}
