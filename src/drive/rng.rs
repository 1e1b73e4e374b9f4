//! The drive's seeded random source: one independent stream per noise source, normal deviates.
//!
//! The drive's noise is the same bit for bit for a seed, run after run and with every version of
//! the dependencies: the bits come from the crate's own SplitMix64 ([`crate::numerics::rng`]),
//! the same on every platform, and the normal deviates from the Box–Muller transform. Its
//! logarithm, sine and cosine are the platform's math library's (its square root is exact
//! everywhere), so across platforms the deviates are the same where those functions round the
//! same, and may otherwise differ in their last bits; the tests pin them on one platform only.

use crate::numerics::rng::SplitMix64;

/// SplitMix64 with a cached second normal deviate.
#[derive(Clone, Debug)]
pub(crate) struct Rng {
    bits: SplitMix64,
    spare: Option<f64>,
}

impl Rng {
    /// A generator for `seed`, split into an independent `stream` (one per noise source, so
    /// turning one source on or off does not change the others).
    pub(crate) fn new(seed: u64, stream: u64) -> Self {
        let mut r = Rng {
            bits: SplitMix64::new(seed ^ stream.wrapping_mul(0xD1B5_4A32_D192_ED03)),
            spare: None,
        };
        // Decorrelate nearby seeds.
        r.next_u64();
        r.next_u64();
        r
    }

    pub(crate) fn next_u64(&mut self) -> u64 {
        self.bits.next_u64()
    }

    /// Uniform on (0, 1]: 53 random bits, never 0 ([`open01`](crate::numerics::rng::open01)).
    pub(crate) fn uniform(&mut self) -> f64 {
        self.bits.next_open01()
    }

    /// Standard normal deviate (Box–Muller).
    pub(crate) fn normal(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let a = 2.0 * std::f64::consts::PI * u2;
        self.spare = Some(r * a.sin());
        r * a.cos()
    }
}

#[cfg(test)]
mod tests {
    use super::Rng;

    #[test]
    fn normal_moments() {
        let mut r = Rng::new(7, 1);
        let n = 200_000;
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let z = r.normal();
            s += z;
            s2 += z * z;
        }
        let mean = s / n as f64;
        let var = s2 / n as f64 - mean * mean;
        // 5 standard errors.
        assert!(mean.abs() < 5.0 / (n as f64).sqrt(), "mean {mean}");
        assert!(
            (var - 1.0).abs() < 5.0 * (2.0 / n as f64).sqrt(),
            "var {var}"
        );
    }

    #[test]
    fn streams_differ_and_repeat() {
        let a: Vec<u64> = (0..4)
            .map({
                let mut r = Rng::new(1, 0);
                move |_| r.next_u64()
            })
            .collect();
        let b: Vec<u64> = (0..4)
            .map({
                let mut r = Rng::new(1, 0);
                move |_| r.next_u64()
            })
            .collect();
        let c: Vec<u64> = (0..4)
            .map({
                let mut r = Rng::new(1, 1);
                move |_| r.next_u64()
            })
            .collect();
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    /// First values recorded before the generator shared its bits with the surface's: the
    /// drive's replay files depend on them.
    #[test]
    fn streams_keep_their_recorded_first_values() {
        let mut r = Rng::new(1, 0);
        let words: Vec<u64> = (0..4).map(|_| r.next_u64()).collect();
        assert_eq!(
            words,
            [
                0xF893_A2EE_FB32_555E,
                0x71C1_8690_EE42_C90B,
                0x71BB_54D8_D101_B5B9,
                0xC34D_0BFF_9015_0280
            ]
        );
        let mut r = Rng::new(2024, 0xEC5);
        let mut bits: Vec<u64> = (0..2).map(|_| r.uniform().to_bits()).collect();
        bits.extend((0..3).map(|_| r.normal().to_bits()));
        assert_eq!(
            bits,
            [
                0x3FE1_8CC6_400D_473E,
                0x3FE2_4CA0_923C_DDC6,
                0xBFF5_6FD7_F5B0_144A,
                0xBFF9_9E60_B0C9_4856,
                0xBFDD_3989_4181_933D
            ]
        );
    }
}
