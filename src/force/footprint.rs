//! Footprints: the nominal contact geometry over which a pressure law is integrated, and the one
//! place where a mean pressure is reduced to a force over it (Derjaguin's approximation).

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use crate::error::check_positive;
use crate::Result;

/// The nominal shape of the region where head and disk interact.
///
/// Serde form: tagged by `shape`, e.g. `{ shape = "paraboloid", radius_of_curvature_m = 0.02 }`.
///
/// ```
/// use hdi_tribology::force::Footprint;
/// let f = Footprint::Paraboloid { radius_of_curvature_m: 0.02, max_radius_m: Some(1e-4) };
/// assert!(f.validate("footprint").is_ok());
/// assert!((f.derjaguin_depth() - 2.5e-7).abs() < 1e-20);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "snake_case", deny_unknown_fields)]
pub enum Footprint {
    /// A flat area (m²) at uniform gap: `F = area · p̄(d)`.
    Flat {
        /// Nominal area, m².
        area_m2: f64,
    },
    /// A paraboloid of revolution with radius of curvature `Rc`, optionally truncated at radius
    /// `r_max`: Derjaguin integral `F = 2π Rc ∫_d^{d+Δ} p̄(s) ds`, `Δ = r_max²/(2 Rc)`.
    Paraboloid {
        /// Radius of curvature Rc, m.
        radius_of_curvature_m: f64,
        /// Footprint radius r_max, m; `None` integrates to infinity.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        max_radius_m: Option<f64>,
    },
}

impl Footprint {
    /// Checks every field; `field` is the dotted path used in errors.
    pub fn validate(&self, field: &str) -> Result<()> {
        match *self {
            Footprint::Flat { area_m2 } => {
                check_positive(&format!("{field}.area_m2"), area_m2)?;
            }
            Footprint::Paraboloid {
                radius_of_curvature_m,
                max_radius_m,
            } => {
                check_positive(
                    &format!("{field}.radius_of_curvature_m"),
                    radius_of_curvature_m,
                )?;
                if let Some(r) = max_radius_m {
                    check_positive(&format!("{field}.max_radius_m"), r)?;
                }
            }
        }
        Ok(())
    }

    /// Depth of the paraboloid over its radius, `Δ = r_max²/(2 Rc)` (∞ when untruncated; 0 for a
    /// flat footprint).
    pub fn derjaguin_depth(&self) -> f64 {
        match *self {
            Footprint::Flat { .. } => 0.0,
            Footprint::Paraboloid {
                radius_of_curvature_m,
                max_radius_m,
            } => match max_radius_m {
                Some(r) => r * r / (2.0 * radius_of_curvature_m),
                None => f64::INFINITY,
            },
        }
    }

    /// The force on this footprint of a mean pressure `p̄(d) = k·q(d)`, and its slope `dF/dd`:
    /// Derjaguin's reduction.
    ///
    /// - Flat, area `A`: `F = A k q(d)`, `F' = A k q'(d)`. `flat()` gives `(q(d), q'(d))`.
    /// - Paraboloid, radius of curvature `Rc`: `F = 2π Rc k ∫_d^{d+Δ} q(s) ds` and
    ///   `F' = −2π Rc k (q(d) − q(d + Δ))`, with `Δ` the [depth](Footprint::derjaguin_depth)
    ///   (∞ when untruncated). `paraboloid(Δ)` gives `(∫_d^{d+Δ} q, q(d) − q(d + Δ))`.
    ///
    /// Each result is formed in one order, `(factor · coefficient) · value`, with the factor
    /// `A·k` or `2π·Rc·k` and the [`Scaled`] parts the closures return, so that a term's numbers
    /// do not depend on how it splits its constants.
    ///
    /// ```
    /// use hdi_tribology::force::{Footprint, Scaled};
    /// // q(s) = e^(−s/λ): ∫_d^∞ q = λ q(d), q' = −q/λ.
    /// let (lam, d, k) = (1e-9, 2e-9, 3.0);
    /// let q = |s: f64| (-s / lam).exp();
    /// let plate = Footprint::Flat { area_m2: 1e-8 };
    /// let (f, df) = plate.reduce(
    ///     k,
    ///     || Ok::<_, ()>((q(d).into(), Scaled::new(-1.0 / lam, q(d)))),
    ///     |_| unreachable!(),
    /// )?;
    /// assert_eq!((f, df), (1e-8 * k * q(d), 1e-8 * k * (-1.0 / lam) * q(d)));
    /// let sphere = Footprint::Paraboloid { radius_of_curvature_m: 0.02, max_radius_m: None };
    /// let (f, df) = sphere.reduce(
    ///     k,
    ///     || unreachable!(),
    ///     |delta| {
    ///         assert!(delta.is_infinite());
    ///         Ok::<_, ()>((Scaled::new(lam, q(d)), q(d).into()))
    ///     },
    /// )?;
    /// let c = 2.0 * std::f64::consts::PI * 0.02 * k;
    /// assert_eq!((f, df), (c * lam * q(d), -c * q(d)));
    /// # Ok::<(), ()>(())
    /// ```
    pub fn reduce<E>(
        &self,
        k: f64,
        flat: impl FnOnce() -> Result<(Scaled, Scaled), E>,
        paraboloid: impl FnOnce(f64) -> Result<(Scaled, Scaled), E>,
    ) -> Result<(f64, f64), E> {
        match *self {
            Footprint::Flat { area_m2 } => {
                let a = area_m2 * k;
                let (q, slope) = flat()?;
                Ok((
                    a * q.coefficient * q.value,
                    a * slope.coefficient * slope.value,
                ))
            }
            Footprint::Paraboloid {
                radius_of_curvature_m,
                ..
            } => {
                let c = 2.0 * PI * radius_of_curvature_m * k;
                let (band, drop) = paraboloid(self.derjaguin_depth())?;
                Ok((
                    c * band.coefficient * band.value,
                    -(c * drop.coefficient * drop.value),
                ))
            }
        }
    }
}

/// A part of a mean pressure handed to [`Footprint::reduce`]: `coefficient × value`, kept apart
/// so that the footprint multiplies its own factor by the coefficient first.
///
/// ```
/// use hdi_tribology::force::Scaled;
/// let m = 2.0;
/// assert_eq!(Scaled::new(0.4, m), Scaled { coefficient: 0.4, value: m }); // M_{5/2}/2.5
/// assert_eq!(Scaled::from(m), Scaled::new(1.0, m));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scaled {
    /// A constant of the law (`0.4` for `M_{5/2}/2.5`), 1 when there is none.
    pub coefficient: f64,
    /// The computed quantity.
    pub value: f64,
}

impl Scaled {
    /// `coefficient × value`.
    pub fn new(coefficient: f64, value: f64) -> Self {
        Scaled { coefficient, value }
    }
}

#[cfg(test)]
impl Footprint {
    /// One footprint of each kind the reduction tells apart: flat, untruncated, a band thinner
    /// than a σ of 0.7 nm (Δ = 25 pm), a band far wider (Δ = 250 nm).
    pub(crate) fn samples() -> [Footprint; 4] {
        let paraboloid = |max_radius_m| Footprint::Paraboloid {
            radius_of_curvature_m: 0.02,
            max_radius_m,
        };
        [
            Footprint::Flat { area_m2: 3e-9 },
            paraboloid(None),
            paraboloid(Some(1e-6)),
            paraboloid(Some(1e-4)),
        ]
    }
}

impl From<f64> for Scaled {
    /// The value alone (coefficient 1, which multiplies exactly).
    fn from(value: f64) -> Self {
        Scaled::new(1.0, value)
    }
}
