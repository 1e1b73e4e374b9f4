//! A calibration as it is printed and returned: the record `hdi calibrate` prints as JSON and
//! the Python package returns, with the keys of [`analysis::record`](crate::analysis::record).

use serde::Serialize;

use super::Calibration;
use crate::analysis::record::Status;
use crate::analysis::sweep::Flag;

/// A touchdown calibration with the scene and a status: `hdi calibrate`'s JSON and Python's
/// `Calibration`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CalibrationRecord {
    /// The scene's name.
    pub scene: String,
    /// The detector as the caller named it (`mean`, `ae`, `vibration`).
    pub detector: String,
    /// The calibration (its `detector_name` the detector's own description).
    #[serde(flatten)]
    pub calibration: Calibration,
    /// Touchdown minus take-off level (W), when the take-off was found.
    pub hysteresis_w: Option<f64>,
    /// Heater levels run.
    pub levels: usize,
    /// Wall time (s).
    pub wall_seconds: f64,
    /// `complete`, or `incomplete` when a take-off was searched for and not found.
    pub status: Status,
    /// `no_takeoff` when a take-off was searched for and not found.
    pub flags: Vec<Flag>,
}

impl CalibrationRecord {
    /// The record of `c`, run with the detector named `detector`, for the scene `scene`;
    /// `searched_takeoff` says whether a take-off was looked for.
    pub fn new(
        scene: &str,
        detector: &str,
        calibration: Calibration,
        searched_takeoff: bool,
        wall_seconds: f64,
    ) -> Self {
        let flags = if searched_takeoff && calibration.takeoff_power.is_none() {
            vec![Flag::NoTakeoff]
        } else {
            Vec::new()
        };
        CalibrationRecord {
            scene: scene.to_string(),
            detector: detector.to_string(),
            hysteresis_w: calibration.hysteresis(),
            levels: calibration.steps.len(),
            wall_seconds,
            status: if flags.is_empty() {
                Status::Complete
            } else {
                Status::Incomplete
            },
            flags,
            calibration,
        }
    }

    /// The record with `flag` added; any flag makes it incomplete.
    ///
    /// ```no_run
    /// # use hdi_tribology::{analysis::sweep::Flag, calibration::CalibrationRecord};
    /// # fn f(r: CalibrationRecord) {
    /// let r = r.flagged(Flag::TakeoffWithoutDither);
    /// assert!(r.flags.contains(&Flag::TakeoffWithoutDither));
    /// # }
    /// ```
    pub fn flagged(mut self, flag: Flag) -> Self {
        self.flags.push(flag);
        self.status = Status::Incomplete;
        self
    }
}
