//! Footprints: the nominal contact geometry over which a pressure law is integrated.

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
}
