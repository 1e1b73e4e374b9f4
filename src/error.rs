//! The crate's error type: every variant says what went wrong and where.

use thiserror::Error;

/// Result alias used throughout the crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong in `hdi-tribology`.
///
/// ```
/// use hdi_tribology::Error;
/// let e = Error::invalid("surface.sigma", "must be finite and > 0, got -1");
/// assert_eq!(e.to_string(), "invalid surface.sigma: must be finite and > 0, got -1");
/// ```
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum Error {
    /// A user-supplied value is out of its valid range or inconsistent.
    #[error("invalid {field}: {reason}")]
    InvalidInput {
        /// Dotted path of the offending field, e.g. `surface.peaks.sigma`.
        field: String,
        /// Why it was rejected, including the value seen.
        reason: String,
    },
    /// A scene file could not be read or parsed.
    #[error("scene {origin}: {reason}")]
    Scene {
        /// File name or `<string>`.
        origin: String,
        /// Parser message (names the field where the parser can).
        reason: String,
    },
    /// A numerical procedure did not reach its tolerance.
    #[error("{what} did not converge: {reason}")]
    NoConvergence {
        /// What was being computed.
        what: String,
        /// Why it stopped.
        reason: String,
    },
    /// An analysis could not produce its result for this scene.
    #[error("{what}: {reason}")]
    Analysis {
        /// Which analysis.
        what: String,
        /// Why not.
        reason: String,
    },
    /// The ODE stepper failed (says at which time and why).
    #[error(transparent)]
    Ode(#[from] crate::ode::OdeError),
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
}

impl Error {
    /// Shorthand for [`Error::InvalidInput`].
    pub fn invalid(field: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::InvalidInput {
            field: field.into(),
            reason: reason.into(),
        }
    }

    /// Shorthand for [`Error::NoConvergence`].
    pub fn no_convergence(what: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::NoConvergence {
            what: what.into(),
            reason: reason.into(),
        }
    }

    /// Shorthand for [`Error::Analysis`].
    pub fn analysis(what: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::Analysis {
            what: what.into(),
            reason: reason.into(),
        }
    }
}

/// Checks that `value` is finite; names `field` otherwise.
///
/// ```
/// use hdi_tribology::error::check_finite;
/// assert!(check_finite("h0", 1e-8).is_ok());
/// assert!(check_finite("h0", f64::NAN).is_err());
/// ```
pub fn check_finite(field: &str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::invalid(
            field,
            format!("must be finite, got {value:?}"),
        ))
    }
}

/// Checks that `value` is finite and strictly positive.
///
/// ```
/// use hdi_tribology::error::check_positive;
/// assert!(check_positive("k", 3e5).is_ok());
/// assert!(check_positive("k", 0.0).is_err());
/// ```
pub fn check_positive(field: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::invalid(
            field,
            format!("must be finite and > 0, got {value:?}"),
        ))
    }
}

/// Checks that `value` is finite and non-negative.
///
/// ```
/// use hdi_tribology::error::check_non_negative;
/// assert!(check_non_negative("t_d", 0.0).is_ok());
/// assert!(check_non_negative("t_d", -1e-9).is_err());
/// ```
pub fn check_non_negative(field: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(Error::invalid(
            field,
            format!("must be finite and >= 0, got {value:?}"),
        ))
    }
}
