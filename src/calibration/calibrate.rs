//! The calibration loop: a heater staircase up to touchdown, optionally back down to take-off,
//! then the back-off and the clearance it leaves.

use super::detector::{Sample, TouchdownDetector};
use crate::analysis::equilibrium::{flying_equilibrium, ScanGrid};
use crate::drive::{
    run, DiskSpec, DriveOptions, LevelDetector, LevelStats, Plant, Sensors,
    Staircase as DriveStaircase, StaircaseSettings,
};
use crate::error::{check_non_negative, check_not_below, check_positive, Error, Result};
use crate::model::SliderModel;
use crate::ode::{Method, Stats};
use crate::units::{grid_point, shift_decimal};
use serde::Serialize;

/// The heater staircase: levels `start_power + k·step` up to `max_power`, each reached by a linear
/// ramp of `rise_time` and held for `settle_time + measure_time` in all.
///
/// The detector sees every sample; a level counts as "in contact" only when it fires during the
/// last `measure_time` of the level, after the air-bearing transient of the step has had
/// `settle_time` to decay.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Staircase {
    /// First level (W, ≥ 0); the slider starts at rest in its flying equilibrium there.
    pub start_power: f64,
    /// Power increment between levels (W, > 0).
    pub step: f64,
    /// Highest level tried (W); the search fails if no contact is seen up to it.
    pub max_power: f64,
    /// Ramp time from one level to the next (s, > 0, ≤ `settle_time`).
    pub rise_time: f64,
    /// Time from the start of a level until the detector's verdict counts (s).
    pub settle_time: f64,
    /// Length of the measurement window at the end of each level (s, > 0).
    pub measure_time: f64,
}

impl Staircase {
    fn validate(&self) -> Result<()> {
        check_non_negative("staircase.start_power", self.start_power)?;
        check_positive("staircase.step", self.step)?;
        check_not_below(
            "staircase.max_power",
            self.max_power,
            "start_power",
            self.start_power,
            "W",
            1.0,
        )?;
        if (self.max_power - self.start_power) / self.step > MAX_LEVELS as f64 {
            return Err(Error::invalid(
                "staircase.step",
                format!(
                    "more than {MAX_LEVELS} levels of step = {:?} W between start_power = {:?} W \
                     and max_power = {:?} W",
                    self.step, self.start_power, self.max_power
                ),
            ));
        }
        check_positive("staircase.rise_time", self.rise_time)?;
        check_positive("staircase.settle_time", self.settle_time)?;
        check_positive("staircase.measure_time", self.measure_time)?;
        if self.rise_time > self.settle_time {
            return Err(Error::invalid(
                "staircase.rise_time",
                format!(
                    "must not exceed settle_time = {} s, got {} s",
                    self.settle_time, self.rise_time
                ),
            ));
        }
        Ok(())
    }

    /// Time spent at one level, ramp included (s).
    pub fn dwell(&self) -> f64 {
        self.settle_time + self.measure_time
    }
}

/// Upper bound on the number of levels of one search, against runaway loops.
///
/// ```
/// assert_eq!(hdi_tribology::calibration::MAX_LEVELS, 100_000);
/// ```
pub const MAX_LEVELS: usize = 100_000;

/// Options of [`calibrate`].
///
/// ```
/// use hdi_tribology::calibration::CalibrationOptions;
/// let o = CalibrationOptions::new(0.060, 0.0005, 0.120, 0.010);
/// assert_eq!(o.staircase.step, 0.0005);
/// assert!(o.find_takeoff);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CalibrationOptions {
    /// The heater staircase.
    pub staircase: Staircase,
    /// Back-off from the detected touchdown power to the operating power (W, ≥ 0). A clearance
    /// target `Δh` above touchdown corresponds to about `Δh/η`.
    pub margin: f64,
    /// Interval at which the detector samples the drive (s, > 0).
    pub sample_interval: f64,
    /// After touchdown, step the heater back down until contact is no longer seen.
    pub find_takeoff: bool,
    /// ODE method.
    pub method: Method,
    /// Relative tolerance of the integration.
    pub rtol: f64,
    /// Absolute tolerance on the displacement (m); the velocity's is scaled by the air-bearing
    /// modal frequency.
    pub atol_displacement: f64,
}

impl CalibrationOptions {
    /// A staircase from `start_power` to `max_power` in steps of `step`, back-off `margin` (all
    /// W), with defaults that suit the paper scene: 20 µs rise, 200 µs settle (about six decay
    /// times of the lightly damped air-bearing mode), 100 µs measurement, 1 MHz sampling,
    /// take-off search on, the automatic ODE method at `rtol = 1e-7`, `atol = 1e-15 m`.
    pub fn new(start_power: f64, step: f64, max_power: f64, margin: f64) -> Self {
        CalibrationOptions {
            staircase: Staircase {
                start_power,
                step,
                max_power,
                rise_time: 2e-5,
                settle_time: 2e-4,
                measure_time: 1e-4,
            },
            margin,
            sample_interval: 1e-6,
            find_takeoff: true,
            method: Method::Auto,
            rtol: 1e-7,
            atol_displacement: 1e-15,
        }
    }

    /// [`CalibrationOptions::new`] with every power in milliwatts, as firmware tables hold
    /// them, each taken to watts on the decimal it is written as
    /// ([`shift_decimal`](crate::units::shift_decimal)): 60.1 mW is `0.0601` W.
    ///
    /// ```
    /// use hdi_tribology::calibration::CalibrationOptions;
    /// let o = CalibrationOptions::from_mw(60.1, 0.5, 90.0, 5.0);
    /// assert_eq!(o, CalibrationOptions::new(0.0601, 0.0005, 0.09, 0.005));
    /// ```
    pub fn from_mw(start_mw: f64, step_mw: f64, max_mw: f64, margin_mw: f64) -> Self {
        let w = |x| shift_decimal(x, -3);
        CalibrationOptions::new(w(start_mw), w(step_mw), w(max_mw), w(margin_mw))
    }

    fn validate(&self) -> Result<()> {
        self.staircase.validate()?;
        check_non_negative("margin", self.margin)?;
        check_positive("sample_interval", self.sample_interval)?;
        if self.sample_interval > 0.5 * self.staircase.measure_time {
            return Err(Error::invalid(
                "sample_interval",
                "needs at least two samples per measurement window",
            ));
        }
        if self.staircase.dwell() / self.sample_interval > 1e7 {
            return Err(Error::invalid(
                "sample_interval",
                "more than 1e7 samples per heater level",
            ));
        }
        check_positive("rtol", self.rtol)?;
        check_positive("atol_displacement", self.atol_displacement)?;
        Ok(())
    }
}

/// What the detector saw at one heater level.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct StepRecord {
    /// Heater level (W).
    #[serde(rename = "power_w")]
    pub power: f64,
    /// `true` on the way down (take-off search).
    pub descending: bool,
    /// Largest detector level in the measurement window.
    pub peak_level: f64,
    /// Smallest bulge gap over the whole level (m).
    #[serde(rename = "min_gap_m")]
    pub min_gap: f64,
    /// Whether the detector saw contact in the measurement window.
    pub contact: bool,
}

/// The outcome of one calibration.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Calibration {
    /// Name of the detector used (its own description).
    #[serde(rename = "detector_name")]
    pub detector: String,
    /// First heater level where contact was seen (W).
    #[serde(rename = "touchdown_power_w")]
    pub touchdown_power: f64,
    /// On the way down, the first level where contact was no longer seen (W); `None` when the
    /// search was off or contact persisted down to the start power.
    #[serde(rename = "takeoff_power_w")]
    pub takeoff_power: Option<f64>,
    /// Operating power `touchdown_power − margin` (W).
    #[serde(rename = "set_power_w")]
    pub set_power: f64,
    /// Clearance at the operating power: the bulge gap of the static flying equilibrium at
    /// `set_power` with the DC voltage only (the dither is off in operation) (m).
    #[serde(rename = "clearance_m")]
    pub clearance: f64,
    /// Peak detector level at touchdown over that at the level before (∞ if that was 0): how
    /// sharply the detector separates contact from flying.
    pub contrast: f64,
    /// Every level, in the order run.
    pub steps: Vec<StepRecord>,
    /// Simulated time (s).
    #[serde(rename = "simulated_time_s")]
    pub simulated_time: f64,
    /// Solver work, summed over the levels.
    pub stats: Stats,
}

impl Calibration {
    /// The clearance set, in nanometres.
    pub fn clearance_nm(&self) -> f64 {
        crate::units::to_nm(self.clearance)
    }

    /// `touchdown_power − takeoff_power` (W), when the take-off was found.
    pub fn hysteresis(&self) -> Option<f64> {
        self.takeoff_power.map(|p| self.touchdown_power - p)
    }
}

/// Runs the firmware's touchdown calibration on the simulated drive.
///
/// The slider starts at rest in its flying equilibrium at `start_power` (with `V(0)²`). The heater
/// climbs the staircase; every level runs on the simulated drive ([`Drive`](crate::drive::Drive):
/// the model's voltage, dither included, acts throughout) and is sampled every
/// `sample_interval` for the detector. The first level where the detector fires in its
/// measurement window is the touchdown power. With `find_takeoff`, the heater then steps down
/// until a level passes without contact. The operating power is the touchdown power minus the
/// margin, and the clearance there comes from the static model.
///
/// # Errors
/// Invalid options (named field); no contact up to `max_power`; a margin that leaves no power;
/// the flying branch ending before the operating power; integration failures.
///
/// ```
/// use hdi_tribology::analysis::{touchdown_power, StaticOptions};
/// use hdi_tribology::calibration::{calibrate, CalibrationOptions, MeanContactForce};
/// use hdi_tribology::{model::SliderModel, scene::Scene};
/// let scene = Scene::paper();
/// let model = SliderModel::from_scene(&scene)?;
/// let (th, window) = (scene.detector.contact_threshold_n, scene.detector.window_s);
/// let mut det = MeanContactForce::new(th, window)?;
/// let mut opts = CalibrationOptions::new(0.070, 0.001, 0.090, 0.010);
/// opts.find_takeoff = false;
/// let cal = calibrate(&model, &mut det, &opts)?;
/// let p_static = touchdown_power(&model, &StaticOptions::new(th))?.power;
/// assert!((cal.touchdown_power - p_static).abs() <= 0.001); // within one step
/// println!("touchdown {:.1} mW, clearance {:.2} nm", cal.touchdown_power * 1e3, cal.clearance * 1e9);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn calibrate(
    model: &SliderModel,
    detector: &mut dyn TouchdownDetector,
    opts: &CalibrationOptions,
) -> Result<Calibration> {
    opts.validate()?;
    let sc = opts.staircase;
    let dt = opts.sample_interval;
    // The drive of the model as it is: a flat disk, the model's own heater (no added lag), its
    // voltage carried by every command; the detector reads the true values of each sample.
    let h_max = model.voltage().max_step(None);
    let drive_opts = DriveOptions {
        initial_power: sc.start_power,
        heater_time_constant: 0.0,
        disk: DiskSpec::flat(),
        method: opts.method,
        rtol: opts.rtol,
        atol_displacement: opts.atol_displacement,
        // One tolerance throughout: the staircase is compared with the static model.
        atol_displacement_flight: opts.atol_displacement,
        max_step: h_max.is_finite().then_some(h_max),
        ..DriveOptions::default()
    };
    let mut drive = Plant::from_model(model, 0.025, 0, drive_opts)?.into_drive()?;
    let v = model.voltage();
    // The staircase counts in mW: the levels' powers as written, in the other unit.
    let to_mw = |x| shift_decimal(x, 3);
    let settings = StaircaseSettings {
        start_power_mw: to_mw(sc.start_power),
        step_mw: to_mw(sc.step),
        max_power_mw: to_mw(sc.max_power),
        settle_time_s: sc.settle_time,
        measure_time_s: sc.measure_time,
        find_takeoff: opts.find_takeoff,
        margin_mw: to_mw(opts.margin),
        dither_amplitude_v: v.ac_amplitude,
        dither_frequency_khz: if v.ac_amplitude != 0.0 {
            v.frequency * 1e-3
        } else {
            0.0
        },
        dc_voltage_v: v.dc,
        rise_time_s: sc.rise_time,
    };
    detector.reset();
    let mut staircase = DriveStaircase::new(
        settings,
        PerSample {
            inner: detector,
            record: None,
            steps: Vec::new(),
        },
        dt,
    )?;
    // Up and back down at most once over every level, each `dwell / dt` samples.
    let levels = ((sc.max_power - sc.start_power) / sc.step).floor() as usize + 1;
    let per_level = (sc.dwell() / dt).round() as usize + 1;
    run(&mut drive, &mut staircase, dt, 2 * (levels + 1) * per_level)?;
    let outcome = staircase.outcome().clone();
    let mut steps = std::mem::take(&mut staircase.detector_mut().steps);
    // The staircase counts in mW; the powers reported are those of the levels in W, as
    // `Staircase` defines them: level k is `start + k·step` on the decimals typed (0.0745 W,
    // not 0.07450000000000001).
    let level_power = |p_mw: f64| {
        let k = ((p_mw - settings.start_power_mw) / settings.step_mw).round();
        grid_point(sc.start_power, sc.step, k as i64)
    };
    for s in &mut steps {
        s.power = level_power(s.power * 1e3);
    }
    let name = staircase.detector().inner.name().to_string();

    let Some(touchdown_power) = outcome.touchdown_power_mw.map(level_power) else {
        return Err(super::CalibrationError::NoTouchdown {
            detector: name,
            max_power_mw: to_mw(sc.max_power),
        }
        .into());
    };
    let up = steps.iter().take_while(|s| !s.descending).count();
    if up == 1 {
        // Fired at the baseline level: the slider was in contact before the staircase began, so
        // there is no touchdown power to find and no contrast to measure.
        return Err(super::CalibrationError::ContactAtStart {
            detector: name,
            start_power_mw: to_mw(sc.start_power),
        }
        .into());
    }
    let contrast = {
        let (a, b) = (steps[up - 1].peak_level, steps[up - 2].peak_level);
        if b > 0.0 {
            a / b
        } else {
            f64::INFINITY
        }
    };
    let set_power = grid_point(touchdown_power, opts.margin, -1);
    if set_power < 0.0 {
        return Err(Error::invalid(
            "margin",
            format!(
                "{} W exceeds the touchdown power {} W",
                opts.margin, touchdown_power
            ),
        ));
    }
    let dc2 = model.voltage().dc_squared();
    let clearance = flying_equilibrium(model, set_power, dc2, &ScanGrid::default())?.d;
    Ok(Calibration {
        detector: name,
        touchdown_power,
        takeoff_power: outcome.takeoff_power_mw.map(level_power),
        set_power,
        clearance,
        contrast,
        simulated_time: drive.time(),
        stats: drive.stats(),
        steps,
    })
}

/// A [`TouchdownDetector`] fed every sample of the drive's staircase: the level is in contact
/// when it fires in the measurement window.
struct PerSample<'a> {
    inner: &'a mut dyn TouchdownDetector,
    record: Option<StepRecord>,
    steps: Vec<StepRecord>,
}

impl LevelDetector for PerSample<'_> {
    fn name(&self) -> &str {
        self.inner.name()
    }

    fn reset(&mut self) {
        self.inner.reset();
        self.record = None;
        self.steps.clear();
    }

    fn observe(&mut self, s: &Sensors, measuring: bool) {
        let tr = &s.truth;
        // The detectors read SI.
        let fired = self.inner.update(&Sample {
            t: s.time_s,
            power: s.heater_power_mw * 1e-3,
            displacement: tr.displacement_nm * 1e-9,
            velocity: tr.velocity_mm_per_s * 1e-3,
            gap: tr.gap_nm * 1e-9,
            contact_force: tr.contact_force_un * 1e-6,
            interface_force: tr.interface_force_un * 1e-6,
        });
        let rec = self.record.get_or_insert(StepRecord {
            power: 0.0,
            descending: false,
            peak_level: 0.0,
            min_gap: f64::INFINITY,
            contact: false,
        });
        rec.min_gap = rec.min_gap.min(tr.gap_nm * 1e-9);
        if measuring {
            rec.contact |= fired;
            rec.peak_level = rec.peak_level.max(self.inner.level());
        }
    }

    fn judge(&mut self, level: &LevelStats) -> bool {
        let mut rec = self.record.take().unwrap_or(StepRecord {
            power: 0.0,
            descending: false,
            peak_level: 0.0,
            min_gap: f64::INFINITY,
            contact: false,
        });
        rec.power = level.heater_power_mw * 1e-3;
        rec.descending = level.descending;
        self.steps.push(rec);
        rec.contact
    }
}
