//! A small, seedable generator (SplitMix64): the same numbers on every machine and thread count.
//! Every random choice in penumbra (visibility samples, Monte Carlo references, test inputs)
//! comes from it, keyed by what it is for, so results never depend on scheduling.

/// SplitMix64 (Steele, Lea & Flood 2014): fast, statistically sound for sampling, and seedable
/// from any 64-bit value, so each (shooter, receiver) pair gets its own reproducible stream.
#[derive(Clone, Debug)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// The stream that starts from `seed`.
    pub fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }

    /// A stream keyed by several integers.
    pub fn keyed(seed: u64, keys: &[u64]) -> Self {
        let mut s = SplitMix64(seed);
        for &k in keys {
            s.0 ^= k.wrapping_mul(0x9E37_79B9_7F4A_7C15);
            s.next_u64();
        }
        s
    }

    /// The next 64 uniformly distributed bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}
