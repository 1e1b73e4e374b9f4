//! Small seeded pseudo-random generators whose streams are fixed by this file alone, the same bit
//! for bit on every platform and with every version of the dependencies: SplitMix64 (Steele, Lea
//! and Flood, "Fast splittable pseudorandom number generators", OOPSLA 2014) and xoshiro256**
//! (Blackman and Vigna), seeded through SplitMix64.
//!
//! ```
//! use hdi_tribology::numerics::rng::{open01, SplitMix64};
//! let mut a = SplitMix64::new(7);
//! let mut b = a.clone();
//! assert_eq!(open01(a.next_u64()), b.next_open01());
//! ```

/// Uniform on (0, 1] from 64 random bits: their top 53, centred in their cell, so that 0 never
/// comes out. Above 1/2 the centre rounds to an end of its cell, and the last cell's to exactly 1
/// (one draw in 2^53); the generators' streams are fixed by this formula and stay as they are.
///
/// ```
/// use hdi_tribology::numerics::rng::open01;
/// assert_eq!(open01(0), 0.5 / (1u64 << 53) as f64);
/// assert!(open01(u64::MAX - (1 << 11)) < 1.0);
/// assert_eq!(open01(u64::MAX), 1.0);
/// ```
pub fn open01(bits: u64) -> f64 {
    ((bits >> 11) as f64 + 0.5) * (1.0 / (1u64 << 53) as f64)
}

/// The SplitMix64 generator: a 64-bit counter advanced by the golden-ratio increment and mixed.
///
/// ```
/// use hdi_tribology::numerics::rng::SplitMix64;
/// let mut r = SplitMix64::new(0);
/// // the reference stream for seed 0
/// assert_eq!(r.next_u64(), 0xE220_A839_7B1D_CDAF);
/// assert_eq!(r.next_u64(), 0x6E78_9E6A_A1B9_65F4);
/// ```
#[derive(Clone, Debug)]
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator whose whole stream is determined by `state`.
    pub fn new(state: u64) -> Self {
        SplitMix64 { state }
    }

    /// Next 64 random bits: advances the state and returns a well-mixed word.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform on (0, 1], 53-bit resolution ([`open01`]: 1 comes out once in 2^53 draws).
    pub fn next_open01(&mut self) -> f64 {
        open01(self.next_u64())
    }
}

/// xoshiro256** generator (Blackman & Vigna), seeded through [`SplitMix64`].
///
/// ```
/// use hdi_tribology::numerics::rng::Xoshiro256;
/// let mut a = Xoshiro256::new(42);
/// let mut b = Xoshiro256::new(42);
/// assert_eq!(a.next_u64(), b.next_u64());
/// let u = a.next_open01();
/// assert!(u > 0.0 && u < 1.0);
/// assert!(a.next_below(10) < 10);
/// ```
#[derive(Clone, Debug)]
pub struct Xoshiro256 {
    s: [u64; 4],
}

impl Xoshiro256 {
    /// A generator whose whole stream is determined by `seed`.
    pub fn new(seed: u64) -> Self {
        let mut seeder = SplitMix64::new(seed);
        let s = [
            seeder.next_u64(),
            seeder.next_u64(),
            seeder.next_u64(),
            seeder.next_u64(),
        ];
        Xoshiro256 { s }
    }

    /// Next 64 random bits.
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

    /// Uniform on (0, 1], 53-bit resolution ([`open01`]: 1 comes out once in 2^53 draws).
    pub fn next_open01(&mut self) -> f64 {
        open01(self.next_u64())
    }

    /// Uniform integer in `0..n` (n ≥ 1), without modulo bias worth noting for n ≪ 2^64.
    pub fn next_below(&mut self, n: usize) -> usize {
        ((u128::from(self.next_u64()) * n as u128) >> 64) as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// First values recorded from the generators before they shared this file: sampled surfaces
    /// and fit starts depend on them.
    #[test]
    fn streams_keep_their_recorded_first_values() {
        let mut got = Vec::new();
        let mut r = SplitMix64::new(0);
        got.extend((0..4).map(|_| r.next_u64()));
        let mut x = Xoshiro256::new(42);
        got.extend((0..4).map(|_| x.next_u64()));
        let mut x = Xoshiro256::new(7);
        got.extend((0..3).map(|_| x.next_open01().to_bits()));
        got.extend((0..4).map(|_| x.next_below(1000) as u64));
        let recorded: [u64; 15] = [
            // SplitMix64, seed 0 (the published reference stream)
            0xE220_A839_7B1D_CDAF,
            0x6E78_9E6A_A1B9_65F4,
            0x06C4_5D18_8009_454F,
            0xF88B_B8A8_724C_81EC,
            // xoshiro256**, seed 42
            0x1578_0B2E_0C2E_C716,
            0x6104_D986_6D11_3A7E,
            0xAE17_5332_39E4_99A1,
            0xECB8_AD47_03B3_60A1,
            // xoshiro256**, seed 7: three draws in (0, 1) (their bits), four below 1000
            0x3FE6_6B1F_5EE9_DF2E,
            0x3FD1_D70F_6593_D20B,
            0x3FEA_DE3A_6932_A590,
            981,
            990,
            872,
            60,
        ];
        assert_eq!(got, recorded);
    }
}
