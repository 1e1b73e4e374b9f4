//! Air-bearing models behind the [`AirBearing`] trait, and their serde description.

use serde::{Deserialize, Serialize};
use std::fmt::Debug;

use crate::error::{check_finite, check_non_negative, check_positive};
use crate::Result;

/// Air bearing: force (N, positive = away from the disk) at displacement `y` (m, positive = away
/// from the disk) and velocity `v` (m/s).
///
/// ```
/// use hdi_tribology::force::{AirBearing, LinearBearing};
/// let ab = LinearBearing::new(3e5, 0.05).unwrap();
/// assert!((ab.force(1e-9, 0.0) + 3e-4).abs() < 1e-18);
/// assert_eq!(ab.stiffness(0.0), 3e5);
/// ```
pub trait AirBearing: Debug + Send + Sync {
    /// Force, N.
    fn force(&self, y: f64, v: f64) -> f64;
    /// Stiffness `−∂F/∂y`, N/m.
    fn stiffness(&self, y: f64) -> f64;
    /// Damping `−∂F/∂v`, N s/m.
    fn damping(&self, y: f64) -> f64;
}

/// Linear spring–damper: `F = −k y − c v`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearBearing {
    k: f64,
    c: f64,
}

impl LinearBearing {
    /// Stiffness `k > 0` (N/m) and damping `c ≥ 0` (N s/m).
    pub fn new(k: f64, c: f64) -> Result<Self> {
        check_positive("air_bearing.stiffness_n_per_m", k)?;
        check_non_negative("air_bearing.damping_n_s_per_m", c)?;
        Ok(LinearBearing { k, c })
    }
}

impl AirBearing for LinearBearing {
    fn force(&self, y: f64, v: f64) -> f64 {
        -self.k * y - self.c * v
    }
    fn stiffness(&self, _y: f64) -> f64 {
        self.k
    }
    fn damping(&self, _y: f64) -> f64 {
        self.c
    }
}

/// Cubic spring with damper: `F = −k y − k₃ y³ − c v` (k₃ < 0 softens).
///
/// ```
/// use hdi_tribology::force::{AirBearing, CubicBearing};
/// let ab = CubicBearing::new(3e5, 1e20, 0.05).unwrap();
/// assert!((ab.stiffness(1e-8) - (3e5 + 3.0 * 1e20 * 1e-16)).abs() < 1e-6);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CubicBearing {
    k: f64,
    k3: f64,
    c: f64,
}

impl CubicBearing {
    /// Linear stiffness `k > 0` (N/m), cubic stiffness `k₃` (N/m³), damping `c ≥ 0` (N s/m).
    pub fn new(k: f64, k3: f64, c: f64) -> Result<Self> {
        check_positive("air_bearing.stiffness_n_per_m", k)?;
        check_finite("air_bearing.cubic_stiffness_n_per_m3", k3)?;
        check_non_negative("air_bearing.damping_n_s_per_m", c)?;
        Ok(CubicBearing { k, k3, c })
    }
}

impl AirBearing for CubicBearing {
    fn force(&self, y: f64, v: f64) -> f64 {
        -self.k * y - self.k3 * y * y * y - self.c * v
    }
    fn stiffness(&self, y: f64) -> f64 {
        self.k + 3.0 * self.k3 * y * y
    }
    fn damping(&self, _y: f64) -> f64 {
        self.c
    }
}

/// Power law on the pad gap `g = h0 + y`: `F = F0 [(h0/g)^n − 1] − c v`; stiffness `n F0/h0` at
/// `y = 0`. For `g ≤ 0` (the pad through the disk) the law has no meaning and force and stiffness
/// are NaN.
///
/// ```
/// use hdi_tribology::force::{AirBearing, PowerLawBearing};
/// let ab = PowerLawBearing::new(1e-2, 3.0, 1e-8, 0.05).unwrap();
/// assert_eq!(ab.force(0.0, 0.0), 0.0);
/// assert!((ab.stiffness(0.0) - 3.0 * 1e-2 / 1e-8).abs() < 1e-6);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PowerLawBearing {
    f0: f64,
    n: f64,
    h0: f64,
    c: f64,
}

impl PowerLawBearing {
    /// Preload `F0 > 0` (N), exponent `n > 0`, reference gap `h0 > 0` (m), damping `c ≥ 0`.
    pub fn new(f0: f64, n: f64, h0: f64, c: f64) -> Result<Self> {
        check_positive("air_bearing.preload_n", f0)?;
        check_positive("air_bearing.exponent", n)?;
        check_positive("air_bearing.reference_gap_m", h0)?;
        check_non_negative("air_bearing.damping_n_s_per_m", c)?;
        Ok(PowerLawBearing { f0, n, h0, c })
    }
}

impl AirBearing for PowerLawBearing {
    fn force(&self, y: f64, v: f64) -> f64 {
        let g = self.h0 + y;
        if g <= 0.0 {
            return f64::NAN;
        }
        self.f0 * ((self.h0 / g).powf(self.n) - 1.0) - self.c * v
    }
    fn stiffness(&self, y: f64) -> f64 {
        let g = self.h0 + y;
        if g <= 0.0 {
            return f64::NAN;
        }
        self.n * self.f0 / g * (self.h0 / g).powf(self.n)
    }
    fn damping(&self, _y: f64) -> f64 {
        self.c
    }
}

/// Serde description of an air bearing, tagged by `model`.
///
/// ```
/// use hdi_tribology::force::AirBearingModel;
/// let m: AirBearingModel = toml::from_str(
///     "model = \"linear\"\nstiffness_n_per_m = 3e5\ndamping_n_s_per_m = 0.05").unwrap();
/// assert_eq!(m.build().unwrap().stiffness(0.0), 3e5);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum AirBearingModel {
    /// [`LinearBearing`].
    Linear {
        /// k, N/m.
        stiffness_n_per_m: f64,
        /// c, N s/m.
        damping_n_s_per_m: f64,
    },
    /// [`CubicBearing`].
    Cubic {
        /// k, N/m.
        stiffness_n_per_m: f64,
        /// k₃, N/m³.
        cubic_stiffness_n_per_m3: f64,
        /// c, N s/m.
        damping_n_s_per_m: f64,
    },
    /// [`PowerLawBearing`].
    PowerLaw {
        /// F0, N.
        preload_n: f64,
        /// n.
        exponent: f64,
        /// h0, m (normally the nominal clearance).
        reference_gap_m: f64,
        /// c, N s/m.
        damping_n_s_per_m: f64,
    },
}

impl AirBearingModel {
    /// Validates and builds the model.
    pub fn build(&self) -> Result<Box<dyn AirBearing>> {
        Ok(match *self {
            AirBearingModel::Linear {
                stiffness_n_per_m,
                damping_n_s_per_m,
            } => Box::new(LinearBearing::new(stiffness_n_per_m, damping_n_s_per_m)?),
            AirBearingModel::Cubic {
                stiffness_n_per_m,
                cubic_stiffness_n_per_m3,
                damping_n_s_per_m,
            } => Box::new(CubicBearing::new(
                stiffness_n_per_m,
                cubic_stiffness_n_per_m3,
                damping_n_s_per_m,
            )?),
            AirBearingModel::PowerLaw {
                preload_n,
                exponent,
                reference_gap_m,
                damping_n_s_per_m,
            } => Box::new(PowerLawBearing::new(
                preload_n,
                exponent,
                reference_gap_m,
                damping_n_s_per_m,
            )?),
        })
    }
}
