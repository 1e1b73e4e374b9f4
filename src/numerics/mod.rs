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

/// [`cubic_hermite`]'s interpolant of an interval of length `h` in power form, for a look-up by
/// Horner's rule: from the values `f0`, `f1` at its ends and the slopes `s0`, `s1` there (per
/// unit `x`), `[a0, a1, a2, a3, b0, b1, b2]` with the value `a0 + t(a1 + t(a2 + t a3))` and
/// the slope in `x` `b0 + t(b1 + t b2)` at `t = (x − x0)/h` in [0, 1]. The same polynomial as
/// [`cubic_hermite`]'s with `m = h s`, its coefficients rounded once.
pub(crate) fn cubic_hermite_power(h: f64, f0: f64, s0: f64, f1: f64, s1: f64) -> [f64; 7] {
    let (m0, m1) = (h * s0, h * s1);
    let d = f1 - f0;
    let (a2, a3) = (3.0 * d - 2.0 * m0 - m1, m0 + m1 - 2.0 * d);
    [f0, m0, a2, a3, m0 / h, 2.0 * a2 / h, 3.0 * a3 / h]
}

#[cfg(test)]
mod tests {
    use super::{cubic_hermite, cubic_hermite_power};

    /// The power form against the basis form at points of an interval: the same polynomial.
    #[test]
    fn the_power_form_is_the_hermite_interpolant() {
        let (h, f0, s0, f1, s1) = (2.5e-6, 0.3, -4.0e4, -0.2, 7.0e4);
        let q = cubic_hermite_power(h, f0, s0, f1, s1);
        // Rounding of a few operations on the data's scale, in value and in slope.
        let scale = f0.abs() + f1.abs() + h * (s0.abs() + s1.abs());
        for k in 0..=10 {
            let t = k as f64 / 10.0;
            let (v, d) = cubic_hermite(t, f0, h * s0, f1, h * s1);
            let value = q[0] + t * (q[1] + t * (q[2] + t * q[3]));
            let slope = q[4] + t * (q[5] + t * q[6]);
            assert!(
                (value - v).abs() < 1e-15 * scale,
                "{t}: {value} against {v}"
            );
            assert!(
                (slope - d / h).abs() < 1e-15 * scale / h,
                "{t}: {slope} against {}",
                d / h
            );
        }
    }

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
