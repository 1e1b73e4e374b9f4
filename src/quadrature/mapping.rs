//! Rational substitutions that turn infinite integration ranges into finite ones.

use super::QuadratureError;
use crate::error::Stage;
use crate::{Error, Result};
use std::cmp::Ordering;

/// The limits `a`, `b` of an integral in increasing order, and the sign that turns the integral
/// over them into the one from `a` to `b` (−1 when `b < a`); `None` when `a = b`, where the
/// integral is zero.
pub(crate) fn ordered_limits(a: f64, b: f64) -> Result<Option<(f64, f64, f64)>> {
    Ok(match a.partial_cmp(&b) {
        None => {
            return Err(Error::invalid(
                "quad.limits",
                format!("integration limits must not be NaN, got [{a}, {b}]"),
            ))
        }
        Some(Ordering::Equal) => None,
        Some(Ordering::Less) => Some((a, b, 1.0)),
        Some(Ordering::Greater) => Some((b, a, -1.0)),
    })
}

/// How the original variable `x` is obtained from the integration variable `t`.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Mapping {
    /// `x = t` on a finite interval.
    Identity,
    /// `[a, ∞)`: `x = a + t/(1−t)`, `t ∈ [0, 1)`.
    UpperInfinite(f64),
    /// `(−∞, b]`: `x = b − (1−t)/t`, `t ∈ (0, 1]`.
    LowerInfinite(f64),
    /// `(−∞, ∞)`: `x = t/(1−t²)`, `t ∈ (−1, 1)`.
    Both,
}

impl Mapping {
    /// The mapping for `a < b` (either may be infinite) and the finite `t` range.
    pub(crate) fn new(a: f64, b: f64) -> Result<(Mapping, f64, f64)> {
        if a.is_nan() || b.is_nan() {
            return Err(Error::invalid(
                "quad.limits",
                format!("integration limits must not be NaN, got [{a}, {b}]"),
            ));
        }
        Ok(match (a.is_finite(), b.is_finite()) {
            (true, true) => (Mapping::Identity, a, b),
            (true, false) => (Mapping::UpperInfinite(a), 0.0, 1.0),
            (false, true) => (Mapping::LowerInfinite(b), 0.0, 1.0),
            (false, false) => (Mapping::Both, -1.0, 1.0),
        })
    }

    /// `(x, dx/dt)` at `t`.
    #[inline]
    pub(crate) fn apply(&self, t: f64) -> (f64, f64) {
        match *self {
            Mapping::Identity => (t, 1.0),
            Mapping::UpperInfinite(a) => {
                let s = 1.0 - t;
                (a + t / s, 1.0 / (s * s))
            }
            Mapping::LowerInfinite(b) => (b - (1.0 - t) / t, 1.0 / (t * t)),
            Mapping::Both => {
                let s = 1.0 - t * t;
                (t / s, (1.0 + t * t) / (s * s))
            }
        }
    }

    /// The `t` corresponding to a finite `x` (for break points).
    pub(crate) fn inverse(&self, x: f64) -> f64 {
        match *self {
            Mapping::Identity => x,
            Mapping::UpperInfinite(a) => {
                let y = x - a;
                y / (1.0 + y)
            }
            Mapping::LowerInfinite(b) => 1.0 / (1.0 + (b - x)),
            Mapping::Both => 2.0 * x / (1.0 + (1.0 + 4.0 * x * x).sqrt()),
        }
    }
}

/// Evaluates `f(x(t))·dx/dt`, rejecting non-finite integrand values.
#[inline]
pub(crate) fn mapped_eval<F: FnMut(f64) -> f64>(
    f: &mut F,
    map: &Mapping,
    t: f64,
    what: Stage,
) -> Result<f64> {
    let (x, jac) = map.apply(t);
    let y = f(x);
    if !y.is_finite() {
        return Err(QuadratureError::NotFinite { stage: what, x, y }.into());
    }
    // A zero integrand far out in an infinite range must not meet an infinite Jacobian.
    Ok(if y == 0.0 { 0.0 } else { y * jac })
}
