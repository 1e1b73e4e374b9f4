//! Gaussian peak heights (classic Greenwood–Williamson).

use super::moments::{self, Shape};
use super::special::{norm_partial_first, norm_pdf, norm_sf};
use super::PeakDistribution;
use crate::error::{check_finite, check_positive};
use crate::Result;

/// Break points (in standard deviations) for the partial-moment quadrature.
/// They reach ±9 so that no initial interval is long enough to hide a
/// Gaussian-tail sliver of mass from the 21 Kronrod nodes.
const LANDMARKS: [f64; 13] = [
    -9.0, -6.0, -4.5, -3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0, 4.5, 6.0, 9.0,
];

/// Support half-width in standard deviations: 2·Q(9) ≈ 2.3e-19 < 1e-18.
const SUPPORT_SIGMAS: f64 = 9.0;

/// Normal law of peak heights with mean `mean` (m) and standard deviation `std` (m).
///
/// ```
/// use hdi_tribology::surface::{Gaussian, PeakDistribution};
/// let g = Gaussian::new(1e-9, 2e-9).unwrap();
/// assert_eq!(g.mean(), 1e-9);
/// // M_1(d) at the mean is σ/√(2π)
/// let m1 = g.partial_moment(1e-9, 1.0);
/// assert!((m1 / (2e-9 / (2.0 * std::f64::consts::PI).sqrt()) - 1.0).abs() < 1e-14);
/// assert!(Gaussian::new(0.0, -1.0).is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gaussian {
    mean: f64,
    std: f64,
}

impl Gaussian {
    /// A normal law; `mean` finite, `std` finite and > 0
    /// (errors name `peaks.mean` / `peaks.std`).
    pub fn new(mean: f64, std: f64) -> Result<Self> {
        check_finite("peaks.mean", mean)?;
        check_positive("peaks.std", std)?;
        Ok(Gaussian { mean, std })
    }

    /// `J_p(t) = ∫_t^∞ (x − t)^p φ(x) dx` for the standard normal law.
    fn standard_partial(t: f64, p: f64) -> f64 {
        if p == 0.0 {
            return norm_sf(t);
        }
        if p == 1.0 {
            return norm_partial_first(t);
        }
        if t <= 0.0 && p.fract() == 0.0 && p <= 64.0 {
            // J_{k+1} = k J_{k−1} − t J_k: every term is positive for t ≤ 0.
            let (mut prev, mut cur) = (norm_sf(t), norm_partial_first(t));
            let mut k = 1.0;
            while k < p {
                let next = k * prev - t * cur;
                prev = cur;
                cur = next;
                k += 1.0;
            }
            return cur;
        }
        let pdf = |x: f64| norm_pdf(x);
        let shape = Shape {
            pdf: &pdf,
            lower: f64::NEG_INFINITY,
            negligible_below: -SUPPORT_SIGMAS,
            centre: 0.0,
            scale: 1.0,
            landmarks: &LANDMARKS,
        };
        moments::partial_moment(&shape, t, p)
    }
}

impl PeakDistribution for Gaussian {
    fn pdf(&self, z: f64) -> f64 {
        norm_pdf((z - self.mean) / self.std) / self.std
    }

    fn partial_moment(&self, d: f64, p: f64) -> f64 {
        if let Some(m) = moments::far_below(self.mean, self.std, d, p) {
            return m;
        }
        let t = (d - self.mean) / self.std;
        self.std.powf(p) * Self::standard_partial(t, p)
    }

    fn support(&self) -> (f64, f64) {
        (
            self.mean - SUPPORT_SIGMAS * self.std,
            self.mean + SUPPORT_SIGMAS * self.std,
        )
    }

    fn mean(&self) -> f64 {
        self.mean
    }

    fn std_dev(&self) -> f64 {
        self.std
    }

    fn inverse_survival(&self, q: f64) -> Option<f64> {
        if !(q > 0.0 && q < 1.0) {
            return None;
        }
        // Q(x) = q  ⇔  erfc(x/√2) = 2q
        let x = std::f64::consts::SQRT_2 * statrs::function::erf::erfc_inv(2.0 * q);
        Some(self.mean + self.std * x)
    }
}

impl Gaussian {
    /// [`Gaussian::new`] with the mean and standard deviation in nanometres.
    ///
    /// ```
    /// use hdi_tribology::surface::{Gaussian, PeakDistribution};
    /// let g = Gaussian::from_nm(0.5, 1.2)?;
    /// assert_eq!(g, Gaussian::new(0.5e-9, 1.2e-9)?);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn from_nm(mean_nm: f64, std_nm: f64) -> Result<Self> {
        Gaussian::new(crate::units::nm(mean_nm), crate::units::nm(std_nm))
    }
}
