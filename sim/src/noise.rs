//! Seedable random numbers: the same seed gives the same noise, and the same dataset, on every
//! run.

/// SplitMix64: small, seedable random numbers, rover's own so that its sequence is fixed
/// forever (sensor noise, and the layouts of `rover dataset`'s images, must not change with a
/// random-number crate's next version). The tuple's value is the state; seed it directly.
#[derive(Debug, Clone)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in (0, 1): never 0, for logarithms.
    pub(crate) fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// A pair of independent standard normal samples (Box-Muller).
    pub(crate) fn normal_pair(&mut self) -> (f64, f64) {
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let t = std::f64::consts::TAU * u2;
        (r * t.cos(), r * t.sin())
    }
}

/// Standard normal samples from one seeded stream, both halves of each Box-Muller pair used:
/// the noise of the IMU, p3d and GPS, each sensor its own stream.
#[derive(Debug, Clone)]
pub(crate) struct Normals {
    rng: SplitMix64,
    spare: Option<f64>,
}

impl Normals {
    /// The stream seeded with `seed`.
    pub fn new(seed: u64) -> Self {
        Self {
            rng: SplitMix64(seed),
            spare: None,
        }
    }

    /// The next standard normal sample.
    pub fn next(&mut self) -> f64 {
        match self.spare.take() {
            Some(z) => z,
            None => {
                let (a, b) = self.rng.normal_pair();
                self.spare = Some(b);
                a
            }
        }
    }

    /// Zero-mean white noise of `stddev`; no draw at 0, so a noise-free sensor reads exactly.
    pub fn scaled(&mut self, stddev: f64) -> f64 {
        if stddev == 0.0 {
            0.0
        } else {
            stddev * self.next()
        }
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        self.rng.unit()
    }
}
