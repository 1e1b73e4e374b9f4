//! Why an interface force could not be evaluated or tabulated.

use std::sync::Arc;

use crate::error::{num, FailureKind, Stage};
use crate::Error;

impl Stage {
    /// Evaluating or tabulating the interface forces.
    pub const INTERFACE_FORCE: Stage = Stage::named("interface force");
}

/// Why an interface force could not be evaluated or tabulated. Gaps are in nm, as the field
/// names say; a wrapped `source` is the error of the quadrature or table build underneath.
///
/// ```
/// use hdi_tribology::force::ForceError;
/// let e: hdi_tribology::Error = ForceError::Meniscus { e_nm: 0.5, force_n: f64::NAN, slope_n_per_m: 1.0 }.into();
/// assert_eq!(
///     e.to_string(),
///     "interface force did not converge: the meniscus force at e = 0.5000 nm is NaN N (slope 1 N/m)"
/// );
/// ```
#[derive(Clone, Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ForceError {
    /// A term's quadrature at one gap failed.
    #[error("{term} at d = {} nm: {source}", num(*.d_nm))]
    Quadrature {
        /// The term's name.
        term: String,
        /// The gap (nm).
        d_nm: f64,
        /// The quadrature's error.
        source: Arc<Error>,
    },
    /// Building a table of the interface forces failed.
    #[error(
        "the {} table of [{}]: {source}",
        if *.area { "contact-area" } else { "force" },
        .terms.join(", ")
    )]
    Table {
        /// `true` for the real contact area's table, `false` for the forces'.
        area: bool,
        /// The names of the terms it holds.
        terms: Vec<String>,
        /// The table build's error.
        source: Arc<Error>,
    },
    /// A partial moment of the peak-height distribution is not finite.
    #[error("the partial moment M_{order}(d = {} nm) is {value}", num(*.d_nm))]
    PartialMoment {
        /// The moment's order.
        order: f64,
        /// The gap (nm).
        d_nm: f64,
        /// Its value.
        value: f64,
    },
    /// The meniscus force or its slope is not finite.
    #[error("the meniscus force at e = {} nm is {force_n} N (slope {slope_n_per_m} N/m)", num(*.e_nm))]
    Meniscus {
        /// The bridge gap (nm).
        e_nm: f64,
        /// The force (N).
        force_n: f64,
        /// Its slope (N/m).
        slope_n_per_m: f64,
    },
}

impl FailureKind for ForceError {
    fn stage(&self) -> Stage {
        Stage::INTERFACE_FORCE
    }

    fn name(&self) -> &'static str {
        match self {
            ForceError::Quadrature { .. } => "Quadrature",
            ForceError::Table { .. } => "Table",
            ForceError::PartialMoment { .. } => "PartialMoment",
            ForceError::Meniscus { .. } => "Meniscus",
        }
    }

    fn is_convergence(&self) -> bool {
        match self {
            ForceError::Quadrature { source, .. } | ForceError::Table { source, .. } => {
                matches!(**source, Error::NoConvergence(_))
            }
            _ => true,
        }
    }
}
