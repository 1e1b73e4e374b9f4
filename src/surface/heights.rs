//! Gaussian surface heights for the non-contact (intermolecular, electrostatic) terms.

use super::special::{norm_pdf, norm_sf};
use crate::error::check_non_negative;
use crate::Result;

/// Surface heights `z` (m) about the mean plane, normal with standard deviation
/// `sigma` (combined rms roughness of both surfaces). `sigma = 0` is a smooth
/// surface: the law is a Dirac mass at 0, [`GaussianHeights::pdf`] returns 0.0
/// everywhere and callers use the smooth-surface formula (see
/// [`GaussianHeights::is_smooth`]).
///
/// ```
/// use hdi_tribology::surface::GaussianHeights;
/// let h = GaussianHeights::new(0.5e-9).unwrap();
/// assert!((h.pdf(0.0) * 0.5e-9 - 0.398_942_280_401_432_7).abs() < 1e-15);
/// assert!(GaussianHeights::new(0.0).unwrap().is_smooth());
/// assert!(GaussianHeights::new(-1.0).is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaussianHeights {
    sigma: f64,
}

impl GaussianHeights {
    /// Heights with standard deviation `sigma` ≥ 0 (error names `surface.sigma`).
    pub fn new(sigma: f64) -> Result<Self> {
        check_non_negative("surface.sigma", sigma)?;
        Ok(GaussianHeights { sigma })
    }

    /// Standard deviation (m).
    pub fn sigma(&self) -> f64 {
        self.sigma
    }

    /// True for `sigma = 0` (no density; use the smooth-surface law).
    pub fn is_smooth(&self) -> bool {
        self.sigma == 0.0
    }

    /// Density (1/m) at height `z`; 0.0 for a smooth surface.
    pub fn pdf(&self, z: f64) -> f64 {
        if self.sigma == 0.0 {
            0.0
        } else {
            norm_pdf(z / self.sigma) / self.sigma
        }
    }

    /// Fraction of the surface higher than `z` (a step at 0 for a smooth surface).
    pub fn survival(&self, z: f64) -> f64 {
        if self.sigma == 0.0 {
            if z < 0.0 {
                1.0
            } else {
                0.0
            }
        } else {
            norm_sf(z / self.sigma)
        }
    }

    /// Interval outside which the mass is below 1e-18 (±9σ).
    pub fn support(&self) -> (f64, f64) {
        (-9.0 * self.sigma, 9.0 * self.sigma)
    }
}

impl GaussianHeights {
    /// [`GaussianHeights::new`] with the standard deviation in nanometres.
    ///
    /// ```
    /// use hdi_tribology::surface::GaussianHeights;
    /// assert_eq!(GaussianHeights::from_nm(0.5)?, GaussianHeights::new(0.5e-9)?);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn from_nm(sigma_nm: f64) -> Result<Self> {
        GaussianHeights::new(crate::units::nm(sigma_nm))
    }
}
