//! Surface roughness statistics: surface-height laws for the non-contact terms and
//! asperity peak-height laws (one file per family) for the contact term.
//!
//! Every peak law implements [`PeakDistribution`], whose partial moments
//! `M_p(d) = ∫_d^∞ (z − d)^p f_p(z) dz` feed the Greenwood–Williamson contact force.
//! Gaussian moments use closed forms for p = 0, 1 (and integer p below the
//! mean); the other continuous laws use adaptive Gauss–Kronrod quadrature of
//! their density (relative target 1e-13) with break points spanning the bulk,
//! in the variable `z = d + v²` when d is inside the bulk and in z itself when
//! it is below; histograms and discrete ensembles are summed in closed form.
//!
//! ```
//! use hdi_tribology::surface::{Gaussian, PeakDistribution, RiceMaxima};
//! let g = Gaussian::new(0.0, 1e-9).unwrap();
//! // Half of the peaks are above the mean plane.
//! assert!((g.partial_moment(0.0, 0.0) - 0.5).abs() < 1e-15);
//! // The maxima of a Gaussian process with ε = 1 are Gaussian.
//! let r = RiceMaxima::new(1e-9, 1.0).unwrap();
//! assert!((r.partial_moment(0.5e-9, 1.5) / g.partial_moment(0.5e-9, 1.5) - 1.0).abs() < 1e-12);
//! ```

mod discrete;
mod empirical;
mod gaussian;
mod heights;
mod moments;
mod peak_model;
mod rice_maxima;
mod rician;
pub mod special;

pub use crate::numerics::rng::Xoshiro256;
pub use discrete::Discrete;
pub use empirical::Empirical;
pub use gaussian::Gaussian;
pub use heights::GaussianHeights;
pub use peak_model::PeakModel;
pub use rice_maxima::RiceMaxima;
pub use rician::Rician;

/// Asperity peak-height distribution, heights z (m) from the surface mean plane.
pub trait PeakDistribution: std::fmt::Debug + Send + Sync {
    /// Probability density (1/m) at height z. Discrete ensembles return 0.0 (no density).
    fn pdf(&self, z: f64) -> f64;
    /// Partial moment M_p(d) = ∫_d^∞ (z − d)^p f_p(z) dz for p ≥ 0 (p = 0: survival function).
    /// Accurate to ≲1e-12 relative (or 1e-300 absolute). Must be fast (called while building tables:
    /// think tens of µs at most), finite for any finite d, and smooth in d.
    fn partial_moment(&self, d: f64, p: f64) -> f64;
    /// Interval outside which the mass is negligible (< 1e-18 of the total).
    fn support(&self) -> (f64, f64);
    /// Mean peak height (m).
    fn mean(&self) -> f64;
    /// Standard deviation of peak heights (m).
    fn std_dev(&self) -> f64;
    /// The height below which a fraction `1 − q` of the peaks lies, i.e. the
    /// inverse of the survival function, when the family knows it cheaply
    /// (used for sampling). `None` means "not available"; callers then invert
    /// `partial_moment(·, 0)` numerically.
    fn inverse_survival(&self, _q: f64) -> Option<f64> {
        None
    }
    /// The peak heights of a discrete ensemble, sorted ascending; `None` for
    /// continuous laws.
    fn atoms(&self) -> Option<&[f64]> {
        None
    }
}
