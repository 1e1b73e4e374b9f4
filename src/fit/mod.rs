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
//! # Ok::<(), hdi_tribology::fit::FitError>(())
//! ```

mod data;
mod forward;
pub mod goodness;
mod params;
mod solve;

pub use data::{CurveKind, DataError, DataSet, Observed, Quantity, Unit};
pub use params::FreeParameter;
pub use solve::{
    fit, model_curves, Direction, FitOptions, FitResult, FittedParameter, Identifiability,
    IntegrationCheck, ResidualRow, ResidualTable, StartOutcome, MIN_LINEARITY, STRONG_CORRELATION,
};

/// Why a fit could not be made.
///
/// ```
/// use hdi_tribology::fit::{DataSet, FitError};
/// let e: FitError = DataSet::from_csv_str("dc_voltage_kv,touchdown_power_mw\n", "a.csv").unwrap_err().into();
/// assert!(e.to_string().starts_with("a.csv, line 1, column 1 (`dc_voltage_kv`): unknown unit `kv`"), "{e}");
/// ```
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FitError {
    /// A data file is bad (names the file, line and column).
    #[error(transparent)]
    Data(#[from] DataError),
    /// Anything else: a parameter name, an option, the scene or the model.
    #[error(transparent)]
    Other(#[from] crate::Error),
}
