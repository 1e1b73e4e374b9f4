//! Numerical building blocks that know no physics and are shared by several modules.
//!
//! - [`rng`]: seeded pseudo-random generators whose streams are fixed by the crate alone
//!   (SplitMix64 and xoshiro256**), for the sampled surfaces, the fit's starting points and the
//!   drive's noise;
//! - `cubic_hermite` (crate-internal): the cubic Hermite interpolant of one interval, for the
//!   tabulated flow factor and air-bearing force.
//!
//! ```
//! use hdi_tribology::numerics::rng::{SplitMix64, Xoshiro256};
//! let mut bits = SplitMix64::new(0);
//! assert_eq!(bits.next_u64(), 0xE220_A839_7B1D_CDAF); // the published first word for seed 0
//! let u = Xoshiro256::new(42).next_open01();
//! assert!(u > 0.0 && u < 1.0);
//! ```

pub mod rng;

/// The cubic Hermite interpolant of one interval at `t` in [0, 1] and its derivative in `t`,
/// from the values `f0`, `f1` at the ends and the slopes `m0`, `m1` there (per unit `t`, i.e.
/// the slopes in `x` times the interval's length).
#[inline]
pub(crate) fn cubic_hermite(t: f64, f0: f64, m0: f64, f1: f64, m1: f64) -> (f64, f64) {
    let t2 = t * t;
    let t3 = t2 * t;
    // The four basis functions h₀₀, h₁₀, h₀₁, h₁₁ and their derivatives.
    let (h00, h10, h01, h11) = (
        2.0 * t3 - 3.0 * t2 + 1.0,
        t3 - 2.0 * t2 + t,
        -2.0 * t3 + 3.0 * t2,
        t3 - t2,
    );
    let (d00, d10, d01, d11) = (
        6.0 * t2 - 6.0 * t,
        3.0 * t2 - 4.0 * t + 1.0,
        -6.0 * t2 + 6.0 * t,
        3.0 * t2 - 2.0 * t,
    );
    (
        h00 * f0 + h10 * m0 + h01 * f1 + h11 * m1,
        d00 * f0 + d10 * m0 + d01 * f1 + d11 * m1,
    )
}

#[cfg(test)]
mod tests {
    use super::cubic_hermite;

    #[test]
    fn cubic_hermite_reproduces_a_cubic() {
        // p(t) = 1 − 2t + 3t² − 0.5t³: values and slopes at the ends give p and p' anywhere.
        let p = |t: f64| 1.0 - 2.0 * t + 3.0 * t * t - 0.5 * t * t * t;
        let dp = |t: f64| -2.0 + 6.0 * t - 1.5 * t * t;
        for t in [0.0, 0.1, 0.5, 0.77, 1.0] {
            let (v, d) = cubic_hermite(t, p(0.0), dp(0.0), p(1.0), dp(1.0));
            assert!((v - p(t)).abs() < 1e-14, "{t}: {v} vs {}", p(t));
            assert!((d - dp(t)).abs() < 1e-14, "{t}: {d} vs {}", dp(t));
        }
    }
}
