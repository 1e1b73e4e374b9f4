//! Pressure laws p(h) on the local gap h, with their slopes and interaction energies per area.

use std::f64::consts::PI;
use std::fmt::Debug;

use crate::error::{check_non_negative, check_positive};
use crate::units::EPSILON_0;
use crate::Result;

/// A pressure law between two half-spaces at local gap `h` (positive = repulsive).
///
/// [`crate::force::AveragedTerm`] averages any law over Gaussian surface heights and integrates
/// it over a footprint, so a new non-contact term only needs its law.
pub trait PressureLaw: Debug + Send + Sync {
    /// Pressure p(h), Pa (Pa/V² for voltage-driven laws).
    fn pressure(&self, h: f64) -> f64;
    /// dp/dh, Pa/m.
    fn pressure_slope(&self, h: f64) -> f64;
    /// Interaction energy per area `W(h) = ∫_h^∞ p(u) du`, J/m².
    fn energy(&self, h: f64) -> f64;
    /// Size of the largest contribution to `[p, dp/dh, W]` at `h`. A law that is a difference of
    /// large parts (the 3–9 law near its zero) returns the parts' size: double rounding limits
    /// its accuracy to about 1e-16 of it, and the quadrature tolerances follow. Default: the
    /// absolute values themselves.
    fn magnitudes(&self, h: f64) -> [f64; 3] {
        [
            self.pressure(h).abs(),
            self.pressure_slope(h).abs(),
            self.energy(h).abs(),
        ]
    }
}

/// Lennard-Jones 3–9 law between half-spaces: `p(h) = −A/(6π h³) + B/(45π h⁹)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LennardJones39 {
    a: f64,
    b: f64,
}

impl LennardJones39 {
    /// Attractive Hamaker constant `A` (J) and repulsive constant `B` (J m⁶), both > 0.
    pub fn new(hamaker_a: f64, hamaker_b: f64) -> Result<Self> {
        check_positive("hamaker_attractive_j", hamaker_a)?;
        check_positive("hamaker_repulsive_j_m6", hamaker_b)?;
        Ok(LennardJones39 {
            a: hamaker_a,
            b: hamaker_b,
        })
    }
}

impl PressureLaw for LennardJones39 {
    fn pressure(&self, h: f64) -> f64 {
        let h3 = h * h * h;
        -self.a / (6.0 * PI * h3) + self.b / (45.0 * PI * h3 * h3 * h3)
    }
    fn pressure_slope(&self, h: f64) -> f64 {
        let h4 = h * h * h * h;
        self.a / (2.0 * PI * h4) - self.b / (5.0 * PI * h4 * h4 * h * h)
    }
    fn energy(&self, h: f64) -> f64 {
        let h2 = h * h;
        let h8 = h2 * h2 * h2 * h2;
        -self.a / (12.0 * PI * h2) + self.b / (360.0 * PI * h8)
    }
    fn magnitudes(&self, h: f64) -> [f64; 3] {
        let (h2, h3) = (h * h, h * h * h);
        let (h8, h9) = (h3 * h3 * h2, h3 * h3 * h3);
        [
            self.a / (6.0 * PI * h3) + self.b / (45.0 * PI * h9),
            self.a / (2.0 * PI * h3 * h) + self.b / (5.0 * PI * h9 * h),
            self.a / (12.0 * PI * h2) + self.b / (360.0 * PI * h8),
        ]
    }
}

/// The zero of the 3–9 law, `h_e = (2B/(15A))^{1/6}` (m).
///
/// ```
/// let h = hdi_tribology::force::lj_zero(1e-19, 1e-76);
/// assert!((h - 2.2602e-10).abs() < 1e-14);
/// ```
pub fn lj_zero(hamaker_a: f64, hamaker_b: f64) -> f64 {
    (2.0 * hamaker_b / (15.0 * hamaker_a)).powf(1.0 / 6.0)
}

/// Electrostatic pressure per V² across a gap with a dielectric-equivalent thickness `t_d`:
/// `p(h) = −ε₀ / (2 (h + t_d)²)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Coulomb {
    t_d: f64,
}

impl Coulomb {
    /// Dielectric-equivalent thickness `t_d ≥ 0` (m).
    pub fn new(dielectric_thickness: f64) -> Result<Self> {
        check_non_negative("dielectric_thickness_m", dielectric_thickness)?;
        Ok(Coulomb {
            t_d: dielectric_thickness,
        })
    }

    /// The dielectric-equivalent thickness, m.
    pub fn dielectric_thickness(&self) -> f64 {
        self.t_d
    }
}

impl PressureLaw for Coulomb {
    fn pressure(&self, h: f64) -> f64 {
        let g = h + self.t_d;
        -EPSILON_0 / (2.0 * g * g)
    }
    fn pressure_slope(&self, h: f64) -> f64 {
        let g = h + self.t_d;
        EPSILON_0 / (g * g * g)
    }
    fn energy(&self, h: f64) -> f64 {
        -EPSILON_0 / (2.0 * (h + self.t_d))
    }
}
