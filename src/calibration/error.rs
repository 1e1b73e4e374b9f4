//! Why a clearance calibration could not give its result.

use crate::error::{failure_kind, num, Stage};

impl Stage {
    /// The firmware clearance calibration.
    pub const CLEARANCE_CALIBRATION: Stage = Stage::named("clearance calibration");
}

/// Why a clearance calibration could not give its result. Numbers are in engineering units, as
/// the field names say.
///
/// ```
/// use hdi_tribology::calibration::CalibrationError;
/// let e: hdi_tribology::Error = CalibrationError::NoTouchdown {
///     detector: "AE".into(),
///     max_power_mw: 90.0,
/// }
/// .into();
/// assert_eq!(e.to_string(), "clearance calibration: AE saw no contact up to 90.0000 mW");
/// ```
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CalibrationError {
    /// The detector saw no contact on the whole staircase.
    #[error("{detector} saw no contact up to {} mW", num(*.max_power_mw))]
    NoTouchdown {
        /// The detector's name.
        detector: String,
        /// The largest heater power reached (mW).
        max_power_mw: f64,
    },
    /// The detector fired at the start power, before the first step.
    #[error(
        "{detector} fired at the start power {} mW already, before the first heater step: contact \
         before the staircase began (start lower, or with less dither)",
        num(*.start_power_mw)
    )]
    ContactAtStart {
        /// The detector's name.
        detector: String,
        /// The start power (mW).
        start_power_mw: f64,
    },
}

failure_kind!(CalibrationError, convergence = |_| false, {
        NoTouchdown => Stage::CLEARANCE_CALIBRATION,
        ContactAtStart => Stage::CLEARANCE_CALIBRATION,
});
