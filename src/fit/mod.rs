//! Fitting a scene to measurements: which interface parameters explain a spin stand's curves.
//!
//! Measured curves ([`DataSet`], read from CSV in engineering units) are touchdown and take-off
//! power against DC voltage (static equilibria) or against AC amplitude (one dynamic cycle of the
//! scene's heater programme per amplitude). The parameters to free are named as a scene file
//! names them, in the unit of that name (`height_sigma_nm`, `contact_potential_v`,
//! `hamaker_attractive_j`, `efficiency_nm_per_mw`, `nominal_clearance_nm`,
//! `stiffness_n_per_m`), with optional bounds. [`fit`] minimises the weighted residuals with
//! Levenberg–Marquardt (bounds by transformation, optional seeded multi-start) and returns the
//! fitted scene, standard errors from the Jacobian at the optimum scaled by the residuals, the
//! correlation matrix, the residuals, and an identifiability report from the singular values.
//! The method, the data format and the limits are in `docs/fit.md`.
//!
//! ```no_run
//! use hdi_tribology::fit::{fit, DataSet, FitOptions, FreeParameter};
//! use hdi_tribology::scene::Scene;
//! let data = [DataSet::from_path("touchdown_vs_vdc.csv")?];
//! let free: Vec<FreeParameter> = vec!["contact_potential_v".parse()?, "efficiency_nm_per_mw=0.05:0.2".parse()?];
//! let r = fit(&Scene::paper(), &data, &free, &FitOptions::default())?;
//! println!("{}", serde_json::to_string_pretty(&r.identifiability.statements).unwrap());
//! # Ok::<(), hdi_tribology::Error>(())
//! ```

use crate::error::{failure_kind, num, Stage};

mod data;
mod forward;
pub mod goodness;
mod params;
mod solve;

pub use crate::error::DataError;
pub use data::{CurveKind, DataSet, Observed, Quantity, Unit};
pub use params::FreeParameter;
pub use solve::{
    fit, model_curves, Direction, FitOptions, FitResult, FittedParameter, Identifiability,
    IntegrationCheck, ResidualRow, ResidualTable, StartOutcome, MIN_LINEARITY, STRONG_CORRELATION,
};

impl Stage {
    /// A fit of scene parameters to measurements.
    pub const FIT: Stage = Stage::named("fit");
    /// The model curves at the measured points.
    pub const MODEL_CURVES: Stage = Stage::named("model curves");
}

/// Why a fit, or the model curves at the measured points, could not be given. Numbers are in
/// engineering units, as the field names say.
///
/// ```
/// use hdi_tribology::fit::FitFailure;
/// let e: hdi_tribology::Error = FitFailure::BeyondEquilibria {
///     origin: "td.csv".into(),
///     heater_power_mw: 95.0,
///     last_power_mw: 80.0,
/// }
/// .into();
/// assert!(e.to_string().starts_with("model curves: td.csv: the heater power 95.0000 mW"), "{e}");
/// ```
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FitFailure {
    /// Too few values settle for the free parameters once the unsettled dynamic ones are left
    /// out.
    #[error(
        "only {included} of {points} values remain once the dynamic points whose detected powers \
         do not settle within {tol_mw} mW under tighter tolerances are left out: too few for \
         {free} free parameters (raise dynamic_power_tol_mw or tighten solver.rtol)"
    )]
    TooFewSettled {
        /// Values left in the fit.
        included: usize,
        /// Values in the data.
        points: usize,
        /// The power tolerance they had to settle within (mW).
        tol_mw: f64,
        /// Free parameters.
        free: usize,
    },
    /// The model could not be evaluated at any start.
    #[error("the model could not be evaluated at any start: {first_error}")]
    NoModelStart {
        /// How the first start ended, as its outcome records it.
        first_error: String,
    },
    /// A measured heater power lies beyond the equilibria the model tabulates.
    #[error(
        "{origin}: the heater power {} mW lies beyond the equilibria of the table range (up to {} \
         mW)",
        num(*.heater_power_mw),
        num(*.last_power_mw)
    )]
    BeyondEquilibria {
        /// The data set.
        origin: String,
        /// The measured heater power (mW).
        heater_power_mw: f64,
        /// The largest heater power with a tabulated equilibrium (mW).
        last_power_mw: f64,
    },
    /// The model detects no transition at a measured point inside the heater programme.
    #[error(
        "{origin}: the model detects no {} at x = {x} inside the heater programme",
        .quantity.stem()
    )]
    NotDetected {
        /// The data set.
        origin: String,
        /// The quantity.
        quantity: Quantity,
        /// The measured point's abscissa, as in the data.
        x: f64,
    },
}

failure_kind!(FitFailure, convergence = |_| false, {
        TooFewSettled => Stage::FIT,
        NoModelStart => Stage::FIT,
        BeyondEquilibria => Stage::MODEL_CURVES,
        NotDetected => Stage::MODEL_CURVES,
});
