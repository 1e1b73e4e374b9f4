//! Numerical integration and precomputed tables for the interface force terms.
//! Adaptive Gauss–Kronrod (with infinite limits and break points), an independent
//! tanh–sinh rule for cross-checks, and O(1) cubic Hermite look-up tables.
//!
//! ```
//! use hdi_tribology::quadrature::{integrate, QuadOptions};
//! // ∫_{-∞}^{∞} exp(-x²) dx = √π
//! let est = integrate(|x: f64| (-x * x).exp(), f64::NEG_INFINITY, f64::INFINITY,
//!                     &QuadOptions::default()).unwrap();
//! assert!((est.value - std::f64::consts::PI.sqrt()).abs() < 1e-12);
//! ```

mod error;
mod gauss_kronrod;
mod mapping;
mod table;
mod tanh_sinh;

pub use error::QuadratureError;
pub use gauss_kronrod::{integrate, integrate_with_breaks};
pub(crate) use gauss_kronrod::{integrate_adaptive, Exhausted};
pub(crate) use table::{hermite_bounds, Span};
pub use table::{Table, TableOptions};
pub use tanh_sinh::integrate_tanh_sinh;

/// Tolerances and limits of the adaptive integrators.
///
/// The integration stops when the estimated error is at most
/// `max(abs_tol, rel_tol·|value|)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuadOptions {
    /// Absolute error target (same unit as the integral).
    pub abs_tol: f64,
    /// Relative error target.
    pub rel_tol: f64,
    /// Largest number of subintervals (Gauss–Kronrod) before giving up; for
    /// tanh–sinh, the evaluation budget is `21·max_intervals`.
    pub max_intervals: usize,
}

impl Default for QuadOptions {
    /// `abs_tol = 0`, `rel_tol = 1e-12`, `max_intervals = 2000`.
    fn default() -> Self {
        QuadOptions {
            abs_tol: 0.0,
            rel_tol: 1e-12,
            max_intervals: 2000,
        }
    }
}

impl QuadOptions {
    /// Checks that the tolerances are finite and non-negative and that at least one
    /// subinterval is allowed.
    pub fn validate(&self) -> crate::Result<()> {
        crate::error::check_non_negative("quad.abs_tol", self.abs_tol)?;
        crate::error::check_non_negative("quad.rel_tol", self.rel_tol)?;
        if self.max_intervals == 0 {
            return Err(crate::Error::invalid(
                "quad.max_intervals",
                "must be >= 1, got 0",
            ));
        }
        Ok(())
    }

    /// The error target for an integral of magnitude `value`.
    pub fn target(&self, value: f64) -> f64 {
        self.abs_tol.max(self.rel_tol * value.abs())
    }
}

/// Result of an integration: value, an (honest, usually pessimistic) error
/// estimate and the number of integrand evaluations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// Approximate value of the integral.
    pub value: f64,
    /// Estimated absolute error of `value`.
    pub error: f64,
    /// Number of integrand evaluations used.
    pub evaluations: usize,
}

impl Estimate {
    /// The integral over an empty range: zero, exactly, from no evaluation.
    pub(crate) const EMPTY: Estimate = Estimate {
        value: 0.0,
        error: 0.0,
        evaluations: 0,
    };
}
