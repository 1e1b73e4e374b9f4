//! Heights of the maxima of a Gaussian process (Rice 1944; Cartwright &
//! Longuet-Higgins 1956), the model's reading of the paper's "Rice distribution".

use super::moments::{self, Shape};
use super::special::{norm_cdf, norm_pdf, one_minus_x_mills, INV_SQRT_2PI};
use super::PeakDistribution;
use crate::error::check_positive;
use crate::{Error, Result};

/// Law of the maxima of a Gaussian process of rms height `sigma` (m) and
/// spectral width parameter `epsilon` ∈ (0, 1]. With ξ = z/σ:
///
/// `σ f(z) = ε/√(2π) · exp(−ξ²/(2ε²)) + √(1−ε²) · ξ · exp(−ξ²/2) · Φ(ξ√(1−ε²)/ε)`.
///
/// ε = 1 is the Gaussian law N(0, σ²); ε → 0 tends to the Rayleigh law.
///
/// ```
/// use hdi_tribology::surface::{PeakDistribution, RiceMaxima};
/// let r = RiceMaxima::new(1e-9, 0.5).unwrap();
/// // mean = σ √(1−ε²) √(π/2)
/// let m = 1e-9 * (0.75f64).sqrt() * (std::f64::consts::PI / 2.0).sqrt();
/// assert!((r.mean() / m - 1.0).abs() < 1e-15);
/// assert!((r.partial_moment(-20e-9, 0.0) - 1.0).abs() < 1e-12);
/// assert!(RiceMaxima::new(1e-9, 1.5).is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RiceMaxima {
    sigma: f64,
    epsilon: f64,
    /// √(1 − ε²).
    c: f64,
    /// √(1 − ε²)/ε.
    k: f64,
}

impl RiceMaxima {
    /// A law of maxima; `sigma` > 0 and `epsilon` ∈ (0, 1]
    /// (errors name `peaks.sigma` / `peaks.epsilon`).
    pub fn new(sigma: f64, epsilon: f64) -> Result<Self> {
        check_positive("peaks.sigma", sigma)?;
        if !(epsilon > 0.0 && epsilon <= 1.0) {
            return Err(Error::invalid(
                "peaks.epsilon",
                format!("must be in (0, 1], got {epsilon}"),
            ));
        }
        let c = ((1.0 - epsilon) * (1.0 + epsilon)).sqrt();
        Ok(RiceMaxima {
            sigma,
            epsilon,
            c,
            k: c / epsilon,
        })
    }

    /// rms height of the underlying process (m).
    pub fn sigma(&self) -> f64 {
        self.sigma
    }

    /// Spectral width parameter ε.
    pub fn epsilon(&self) -> f64 {
        self.epsilon
    }

    /// σ·f(σξ) as a function of ξ.
    fn standard_pdf(&self, xi: f64) -> f64 {
        let eps = self.epsilon;
        if self.c == 0.0 {
            return norm_pdf(xi);
        }
        let x = self.k * xi;
        if xi >= 0.0 {
            let r = xi / eps;
            eps * INV_SQRT_2PI * (-0.5 * r * r).exp()
                + self.c * xi * (-0.5 * xi * xi).exp() * norm_cdf(x)
        } else {
            // Both terms carry exp(−ξ²/(2ε²)); their near-cancellation is the
            // factor 1 − |x|·R(|x|), evaluated without loss.
            let r = xi / eps;
            eps * INV_SQRT_2PI * (-0.5 * r * r).exp() * one_minus_x_mills(-x)
        }
    }
}

impl PeakDistribution for RiceMaxima {
    fn pdf(&self, z: f64) -> f64 {
        self.standard_pdf(z / self.sigma) / self.sigma
    }

    fn partial_moment(&self, d: f64, p: f64) -> f64 {
        if let Some(m) = moments::far_below(self.mean(), self.std_dev(), d, p) {
            return m;
        }
        let e = self.epsilon;
        let pdf = |xi: f64| self.standard_pdf(xi);
        // Lower tail on the scale ε, upper tail on the scale 1, out to the
        // support ends so that no initial interval hides a sliver of mass.
        let landmarks = [
            -9.5 * e,
            -6.0 * e,
            -4.0 * e,
            -2.0 * e,
            -e,
            0.0,
            e,
            0.5,
            1.0,
            2.0,
            3.0,
            4.5,
            6.0,
            9.5,
        ];
        let shape = Shape {
            pdf: &pdf,
            lower: f64::NEG_INFINITY,
            negligible_below: -9.5 * e,
            centre: 0.0,
            scale: 1.0,
            landmarks: &landmarks,
        };
        self.sigma.powf(p) * moments::partial_moment(&shape, d / self.sigma, p)
    }

    fn support(&self) -> (f64, f64) {
        // Below: f ≤ ε²·N(0, ε²) so the mass under −9.5εσ is < 1e-20; above: the
        // tail is bounded by ξ·exp(−ξ²/2) + Gaussian, negligible beyond 9.5σ.
        (-9.5 * self.epsilon * self.sigma, 9.5 * self.sigma)
    }

    fn mean(&self) -> f64 {
        self.sigma * self.c * (std::f64::consts::PI / 2.0).sqrt()
    }

    fn std_dev(&self) -> f64 {
        // E[ξ²] = 2 − ε², E[ξ] = √(1−ε²)·√(π/2).
        let e2 = self.epsilon * self.epsilon;
        let var = 2.0 - e2 - self.c * self.c * std::f64::consts::FRAC_PI_2;
        self.sigma * var.max(0.0).sqrt()
    }
}

impl RiceMaxima {
    /// [`RiceMaxima::new`] with the surface's standard deviation in nanometres.
    ///
    /// ```
    /// use hdi_tribology::surface::RiceMaxima;
    /// assert_eq!(RiceMaxima::from_nm(0.7, 0.7)?, RiceMaxima::new(0.7e-9, 0.7)?);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn from_nm(sigma_nm: f64, epsilon: f64) -> Result<Self> {
        RiceMaxima::new(crate::units::nm(sigma_nm), epsilon)
    }
}
