//! # Seeded random numbers
//!
//! Every run is a function of its scenario and seed, so all noise comes from
//! this small, explicitly seeded generator: xoshiro256** (Blackman and Vigna,
//! "Scrambled linear pseudorandom number generators", 2018), seeded through
//! SplitMix64 as its authors recommend. Gaussian samples use the Box–Muller
//! transform.
//!
//! Independent *streams* are derived from `(seed, stream id)`, one per robot
//! and per noise source, so that adding a sensor or a robot does not change
//! the noise every other one sees.

/// SplitMix64: a tiny generator used to expand a seed into a full state.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    pub fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
}

/// Named noise streams; each robot gets one of each.
#[derive(Clone, Copy, Debug)]
pub enum Stream {
    Odometry = 1,
    Sonar = 2,
    Laser = 3,
    Camera = 4,
    Texture = 5,
}

/// xoshiro256**, with a cached second Box–Muller sample.
#[derive(Clone, Debug)]
pub struct Rng {
    s: [u64; 4],
    spare_gaussian: Option<f64>,
}

impl Rng {
    pub fn new(seed: u64) -> Self {
        let mut sm = SplitMix64::new(seed);
        let s = [sm.next_u64(), sm.next_u64(), sm.next_u64(), sm.next_u64()];
        Rng {
            s,
            spare_gaussian: None,
        }
    }

    /// The stream for one noise source of one robot.
    pub fn stream(seed: u64, robot_index: usize, stream: Stream) -> Self {
        let mut sm = SplitMix64::new(seed ^ 0xA076_1D64_78BD_642F);
        let a = sm.next_u64();
        let mixed = a
            ^ ((robot_index as u64 + 1).wrapping_mul(0xE703_7ED1_A0B4_28DB))
            ^ ((stream as u64).wrapping_mul(0x8EBC_6AF0_9C88_C6E3));
        Rng::new(SplitMix64::new(mixed).next_u64())
    }

    pub fn next_u64(&mut self) -> u64 {
        let result = self.s[1].wrapping_mul(5).rotate_left(7).wrapping_mul(9);
        let t = self.s[1] << 17;
        self.s[2] ^= self.s[0];
        self.s[3] ^= self.s[1];
        self.s[1] ^= self.s[2];
        self.s[0] ^= self.s[3];
        self.s[2] ^= t;
        self.s[3] = self.s[3].rotate_left(45);
        result
    }

    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// Standard normal sample (Box–Muller).
    pub fn gaussian(&mut self) -> f64 {
        if let Some(g) = self.spare_gaussian.take() {
            return g;
        }
        let u1 = 1.0 - self.uniform(); // (0, 1]: ln is finite
        let u2 = self.uniform();
        let r = (-2.0 * u1.ln()).sqrt();
        let (s, c) = (2.0 * std::f64::consts::PI * u2).sin_cos();
        self.spare_gaussian = Some(r * s);
        r * c
    }

    /// A cheap approximately normal sample (mean 0, variance 1): the sum of
    /// four 16-bit uniforms, centred and scaled (Irwin–Hall). Used for
    /// per-pixel camera noise, where Box–Muller's logarithm and sine per
    /// pixel would cost more than the rest of the rendering; its tails stop
    /// at ±3.46σ, which a pixel's noise never needs to exceed.
    pub fn approx_gaussian(&mut self) -> f64 {
        let r = self.next_u64();
        let sum = (r & 0xFFFF) + ((r >> 16) & 0xFFFF) + ((r >> 32) & 0xFFFF) + (r >> 48);
        (sum as f64 / 65536.0 - 2.0) * 3f64.sqrt()
    }

    /// Normal sample with the given standard deviation (0 gives exactly 0).
    pub fn normal(&mut self, std_dev: f64) -> f64 {
        if std_dev == 0.0 {
            0.0
        } else {
            std_dev * self.gaussian()
        }
    }
}
