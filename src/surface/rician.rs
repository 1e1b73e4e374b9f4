//! Rician (Rice–Nakagami) peak heights: the length of a 2-D Gaussian vector with offset.

use super::moments::{self, Shape};
use super::special::{bessel_i0e, bessel_i1e};
use super::PeakDistribution;
use crate::error::{check_non_negative, check_positive};
use crate::Result;

/// Rician law with location `nu` ≥ 0 (m) and scale `s` > 0 (m):
/// `f(z) = z/s² · exp(−(z² + ν²)/(2s²)) · I₀(zν/s²)` for z ≥ 0.
/// ν = 0 is the Rayleigh law.
///
/// ```
/// use hdi_tribology::surface::{PeakDistribution, Rician};
/// let r = Rician::new(2e-9, 1e-9).unwrap();
/// // E[z²] = 2s² + ν²
/// let m2 = r.std_dev().powi(2) + r.mean().powi(2);
/// assert!((m2 / 6e-18 - 1.0).abs() < 1e-13);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rician {
    nu: f64,
    s: f64,
}

impl Rician {
    /// A Rician law; errors name `peaks.nu` / `peaks.s`.
    pub fn new(nu: f64, s: f64) -> Result<Self> {
        check_non_negative("peaks.nu", nu)?;
        check_positive("peaks.s", s)?;
        Ok(Rician { nu, s })
    }

    /// Location parameter ν (m).
    pub fn nu(&self) -> f64 {
        self.nu
    }

    /// Scale parameter s (m).
    pub fn s(&self) -> f64 {
        self.s
    }

    /// Density in units of s: `x·exp(−(x−a)²/2)·e^{−xa}I₀(xa)` with a = ν/s.
    fn standard_pdf(x: f64, a: f64) -> f64 {
        if x <= 0.0 {
            return 0.0;
        }
        let dx = x - a;
        x * (-0.5 * dx * dx).exp() * bessel_i0e(x * a)
    }
}

impl PeakDistribution for Rician {
    fn pdf(&self, z: f64) -> f64 {
        Self::standard_pdf(z / self.s, self.nu / self.s) / self.s
    }

    fn partial_moment(&self, d: f64, p: f64) -> f64 {
        if let Some(m) = moments::far_below(self.mean(), self.std_dev(), d, p) {
            return m;
        }
        let a = self.nu / self.s;
        let pdf = |x: f64| Self::standard_pdf(x, a);
        // Around the Gaussian-like bulk at ν, out to ±9 scales, plus the
        // Rayleigh peak near 1 for small ν.
        let landmarks = [
            a - 9.0,
            a - 6.0,
            a - 4.5,
            a - 3.0,
            a - 2.0,
            a - 1.0,
            a,
            a + 1.0,
            a + 2.0,
            a + 3.0,
            a + 4.5,
            a + 6.0,
            a + 9.0,
            0.5,
            1.0,
        ];
        let shape = Shape {
            pdf: &pdf,
            lower: 0.0,
            // Below ν − 9.5s the Gaussian-like bulk holds < 1e-20 of the mass.
            negligible_below: a - 9.5,
            centre: a,
            scale: 1.0,
            landmarks: &landmarks,
        };
        self.s.powf(p) * moments::partial_moment(&shape, d / self.s, p)
    }

    fn support(&self) -> (f64, f64) {
        // The upper tail is Gaussian about ν with the slowly growing factor √(z/ν).
        (0.0, self.nu + 10.0 * self.s)
    }

    fn mean(&self) -> f64 {
        // s·√(π/2)·L_{1/2}(−ν²/(2s²)), L_{1/2}(x) = e^{x/2}[(1−x)I₀(−x/2) − x I₁(−x/2)];
        // with y = ν²/(4s²): e^{−y}[(1+2y)I₀(y) + 2y I₁(y)] = (1+2y)I0e(y) + 2y I1e(y).
        let y = 0.25 * (self.nu / self.s).powi(2);
        let l = (1.0 + 2.0 * y) * bessel_i0e(y) + 2.0 * y * bessel_i1e(y);
        self.s * (std::f64::consts::FRAC_PI_2).sqrt() * l
    }

    fn std_dev(&self) -> f64 {
        let m = self.mean();
        let second = 2.0 * self.s * self.s + self.nu * self.nu;
        (second - m * m).max(0.0).sqrt()
    }
}

impl Rician {
    /// [`Rician::new`] with `ν` and `s` in nanometres.
    ///
    /// ```
    /// use hdi_tribology::surface::Rician;
    /// assert_eq!(Rician::from_nm(2.0, 1.0)?, Rician::new(2e-9, 1e-9)?);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn from_nm(nu_nm: f64, s_nm: f64) -> Result<Self> {
        Rician::new(crate::units::nm(nu_nm), crate::units::nm(s_nm))
    }
}
