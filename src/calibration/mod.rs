//! Firmware clearance calibration on the simulated drive: step the heater up to touchdown, detect
//! it with a pluggable [`TouchdownDetector`], back off by a margin and report the clearance set.
//!
//! [`calibrate`] runs the staircase on a [`crate::model::SliderModel`] (dither included when the
//! model's voltage has an AC part) and returns a [`Calibration`]; [`Zone`] moves a scene to another
//! radius and disk speed. Three detectors come with the module: [`MeanContactForce`] (the static
//! model's own criterion), [`ContactForceRms`] (an acoustic-emission proxy) and [`VibrationRms`].
//!
//! ```
//! use hdi_tribology::calibration::{calibrate, CalibrationOptions, ContactForceRms};
//! use hdi_tribology::model::{SliderModel, Voltage};
//! use hdi_tribology::scene::Scene;
//! let model = SliderModel::from_scene(&Scene::paper())?;
//! // A 0.5 V dither at 10.5 kHz while calibrating.
//! let dithered = model.with_voltage(Voltage { ac_amplitude: 0.5, frequency: 10.5e3, ..model.voltage() });
//! let mut ae = ContactForceRms::new(1e-5, 5e3, 5e-5)?;
//! let cal = calibrate(&dithered, &mut ae, &CalibrationOptions::new(0.060, 0.0005, 0.120, 0.010))?;
//! // Take-off (stepping down) comes below touchdown: the hysteresis of the interface.
//! assert!(cal.takeoff_power.is_some_and(|to| to < cal.touchdown_power));
//! println!("touchdown {:.2} mW, set {:.2} mW, clearance {:.3} nm",
//!     cal.touchdown_power * 1e3, cal.set_power * 1e3, cal.clearance * 1e9);
//! # Ok::<(), hdi_tribology::Error>(())
//! ```

mod calibrate;
mod detector;
mod error;
mod filters;
mod record;

/// The zone lives with the drive it configures; it is named here too, where calibrations use it.
pub use crate::drive::Zone;
pub use calibrate::{
    calibrate, Calibration, CalibrationOptions, Staircase, StepRecord, MAX_LEVELS,
};
pub use detector::{
    ContactForceRms, MeanContactForce, Relative, Sample, TouchdownDetector, VibrationRms,
};
pub use error::CalibrationError;
pub use filters::{HighPass, MeanSquare};
pub use record::CalibrationRecord;
