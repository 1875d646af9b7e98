//! # A small seeded generator for MSAC
//!
//! MSAC draws random minimal samples. So that a fit is a function of its
//! inputs and a seed alone (the same on every machine, natively and in
//! wasm), we use Vigna's SplitMix64 rather than a system source: one
//! 64-bit state, an additive step and a 64-bit mix. It is not
//! cryptographic, and need not be.

/// SplitMix64 (S. Vigna, public domain algorithm).
#[derive(Clone, Debug)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    pub fn new(seed: u64) -> Self {
        SplitMix64 { state: seed }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`n > 0`), by Lemire's multiply-shift (bias below 2⁻³²
    /// for the small n used here).
    pub fn below(&mut self, n: usize) -> usize {
        (((self.next_u64() >> 32) * n as u64) >> 32) as usize
    }

    /// `K` distinct indices in `0..n` (`n >= K`).
    pub fn distinct<const K: usize>(&mut self, n: usize) -> [usize; K] {
        let mut out = [0usize; K];
        let mut k = 0;
        while k < K {
            let c = self.below(n);
            if !out[..k].contains(&c) {
                out[k] = c;
                k += 1;
            }
        }
        out
    }
}
