//! Controllers: what firmware does with the sensors, as a trait, and the ones that come with the
//! crate (the touchdown staircase with three detectors, and a closed-loop clearance hold).

use super::plant::{Command, Drive};
use super::sensors::{Readback, Sensors};
use crate::error::{check_non_negative, check_positive, Error, Result};
use serde::Serialize;

/// What a controller decides after reading the sensors of one period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    /// Hold this command over the next period.
    Continue(Command),
    /// The controller has finished.
    Stop,
}

/// Firmware's half of the loop: given the sensors of the period just ended, the command for the
/// next one.
///
/// ```
/// use hdi_tribology::drive::{Action, Command, Controller, Sensors};
/// /// Raise the heater by 0.1 mW per period until the acoustic emission exceeds 20 mV.
/// struct Creep { mw: f64 }
/// impl Controller for Creep {
///     fn start(&mut self) -> Command { Command::heater_mw(self.mw) }
///     fn update(&mut self, s: &Sensors) -> Action {
///         if s.acoustic_v > 0.02 { return Action::Stop; }
///         self.mw += 0.1;
///         Action::Continue(Command::heater_mw(self.mw))
///     }
/// }
/// let mut c = Creep { mw: 60.0 };
/// assert_eq!(c.start(), Command::heater_mw(60.0));
/// ```
pub trait Controller {
    /// The command for the first period.
    fn start(&mut self) -> Command;
    /// Reads the sensors at the end of a period and decides the next command.
    fn update(&mut self, sensors: &Sensors) -> Action;
}

/// Runs `controller` on `drive` at period `dt` until it stops or `max_periods` have passed;
/// returns the number of periods run.
///
/// # Errors
/// Those of [`Drive::step`]; an [`Error::Analysis`] ([`DriveError::NotFinished`](super::DriveError::NotFinished)) when the controller has not stopped after
/// `max_periods`.
pub fn run(
    drive: &mut Drive,
    controller: &mut dyn Controller,
    dt: f64,
    max_periods: usize,
) -> Result<usize> {
    let mut command = controller.start();
    for n in 1..=max_periods {
        let s = drive.step(&command, dt)?;
        match controller.update(&s) {
            Action::Continue(c) => command = c,
            Action::Stop => return Ok(n),
        }
    }
    Err(super::DriveError::NotFinished { max_periods }.into())
}

/// Mean and standard error of one channel over a measurement window.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Channel {
    /// Mean.
    pub mean: f64,
    /// Standard error of the mean (sample standard deviation / √n).
    pub sem: f64,
}

/// The running mean and standard error of a stream of samples: what the level detectors use,
/// for firmware that judges its own windows.
///
/// The sums are taken about the first sample (shifted), so a channel with a large offset and a
/// small scatter (a resistance of 100 Ω that moves by mΩ) keeps its precision. The standard error
/// is the sample standard deviation over `√n` (0 below two samples).
///
/// ```
/// use hdi_tribology::drive::RunningMean;
/// let mut m = RunningMean::new();
/// for x in [100.001, 100.003, 99.998, 100.002] {
///     m.add(x);
/// }
/// assert_eq!(m.count(), 4);
/// assert!((m.mean() - 100.001).abs() < 1e-12);
/// // Sample standard deviation √(1.4e-5 / 3) over √4.
/// let sd: f64 = (1.4e-5f64 / 3.0).sqrt();
/// assert!((m.standard_error() - sd / 2.0).abs() < 1e-12);
/// assert_eq!(m.channel().mean, m.mean());
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RunningMean {
    n: usize,
    s: f64,
    s2: f64,
    shift: f64,
}

impl RunningMean {
    /// No samples yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one sample.
    pub fn add(&mut self, x: f64) {
        if self.n == 0 {
            self.shift = x;
        }
        let d = x - self.shift;
        self.n += 1;
        self.s += d;
        self.s2 += d * d;
    }

    /// Samples so far.
    pub fn count(&self) -> usize {
        self.n
    }

    /// Mean of the samples (0 without any).
    pub fn mean(&self) -> f64 {
        self.channel().mean
    }

    /// Standard error of the mean: sample standard deviation over `√n` (0 below two samples).
    pub fn standard_error(&self) -> f64 {
        self.channel().sem
    }

    /// Mean and standard error together.
    pub fn channel(&self) -> Channel {
        if self.n == 0 {
            return Channel::default();
        }
        let n = self.n as f64;
        let m = self.s / n;
        let var = if self.n > 1 {
            ((self.s2 - n * m * m) / (n - 1.0)).max(0.0)
        } else {
            0.0
        };
        Channel {
            mean: self.shift + m,
            sem: (var / n).sqrt(),
        }
    }
}

/// The sensors over the measurement window of one heater level.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct LevelStats {
    /// Heater power of the level (mW).
    pub heater_power_mw: f64,
    /// `true` on the way down (take-off search).
    pub descending: bool,
    /// Contact-sensor resistance (Ω).
    pub contact_resistance_ohm: Channel,
    /// Acoustic emission (V).
    pub acoustic_v: Channel,
    /// Read-back `ln(A_1/A_3)`.
    pub log_ratio: Channel,
    /// True contact force, period means (µN): the oracle.
    pub true_contact_force_un: Channel,
    /// True bulge gap (nm): the oracle.
    pub true_gap_nm: Channel,
    /// Whether the detector saw contact.
    pub contact: bool,
}

#[derive(Clone, Copy, Debug, Default)]
struct Meter {
    r: RunningMean,
    ae: RunningMean,
    hr: RunningMean,
    fc: RunningMean,
    gap: RunningMean,
}

impl Meter {
    fn add(&mut self, s: &Sensors) {
        self.r.add(s.contact_resistance_ohm);
        self.ae.add(s.acoustic_v);
        self.hr.add(s.readback.log_ratio());
        self.fc.add(s.truth.mean_contact_force_un);
        self.gap.add(s.truth.gap_nm);
    }

    fn stats(&self, power_mw: f64, descending: bool) -> LevelStats {
        LevelStats {
            heater_power_mw: power_mw,
            descending,
            contact_resistance_ohm: self.r.channel(),
            acoustic_v: self.ae.channel(),
            log_ratio: self.hr.channel(),
            true_contact_force_un: self.fc.channel(),
            true_gap_nm: self.gap.channel(),
            contact: false,
        }
    }
}

/// A touchdown detector that judges one heater level from its measurement-window statistics.
pub trait LevelDetector {
    /// A short name for reports.
    fn name(&self) -> &str;
    /// Forgets everything (a new calibration).
    fn reset(&mut self);
    /// Whether the level is in contact. Levels come in the order run: up the staircase, then
    /// (`level.descending`) down it.
    fn judge(&mut self, level: &LevelStats) -> bool;
    /// Sees the sensors of every period of a level before it is judged; `measuring` is true in
    /// its measurement window. The default ignores them (a detector that judges the window's
    /// statistics); a detector that follows the signal period by period (a filter, a running
    /// mean) uses it.
    fn observe(&mut self, sensors: &Sensors, measuring: bool) {
        let _ = (sensors, measuring);
    }
}

/// The oracle: the true contact force, averaged over the window, against a threshold `F_th` (the
/// criterion of the static analyses, `analysis::touchdown_power`).
///
/// ```
/// use hdi_tribology::drive::{LevelDetector, TrueContact};
/// let d = TrueContact::new(50.0)?; // µN
/// assert_eq!(d.threshold_un(), 50.0);
/// assert_eq!(d.name(), "true contact force");
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct TrueContact {
    threshold_un: f64,
}

impl TrueContact {
    /// Threshold `F_th` (µN, > 0).
    pub fn new(threshold_un: f64) -> Result<Self> {
        check_positive("threshold_un", threshold_un)?;
        Ok(TrueContact { threshold_un })
    }

    /// The threshold (µN).
    pub fn threshold_un(&self) -> f64 {
        self.threshold_un
    }
}

impl LevelDetector for TrueContact {
    fn name(&self) -> &str {
        "true contact force"
    }
    fn reset(&mut self) {}
    fn judge(&mut self, level: &LevelStats) -> bool {
        level.true_contact_force_un.mean >= self.threshold_un
    }
}

/// Touchdown from the change of slope of the contact sensor's resistance against heater power.
///
/// On the way up, a straight line is fitted to the last `fit_levels` levels judged flying; a
/// level is in contact when its mean resistance exceeds the line's prediction by more than
/// `n_sigma` standard errors. The standard error has two parts. The noise of a level mean
/// comes from the scatter measured on the flying levels (a level whose own scatter is large,
/// because the head jumped into contact inside its window, must not widen its own band). The
/// model error of the line is taken as the amount by which the last flying level exceeded its
/// own prediction. Just below the fold the asperity tail already carries a few µN, and its
/// frictional heat lifts the resistance above the line smoothly, level after level. A level
/// must stand out from that trend as well as from the noise; the jump into contact stands out
/// by orders of magnitude. Before contact the gap cooling bends the curve down, below the line.
/// On the way down the line of the flying levels is kept.
///
/// ```
/// use hdi_tribology::drive::ContactSensorSlope;
/// assert!(ContactSensorSlope::new(4.0, 4).is_ok());
/// assert!(ContactSensorSlope::new(4.0, 1).is_err()); // a line needs two levels
/// ```
#[derive(Clone, Debug)]
pub struct ContactSensorSlope {
    n_sigma: f64,
    fit_levels: usize,
    flying: Vec<(f64, Channel)>,
    /// How far the last flying level rose above its own prediction (Ω, ≥ 0).
    trend: f64,
}

impl ContactSensorSlope {
    /// Threshold `n_sigma` (> 0) and the number of flying levels the line is fitted to (≥ 2).
    pub fn new(n_sigma: f64, fit_levels: usize) -> Result<Self> {
        check_positive("n_sigma", n_sigma)?;
        if fit_levels < 2 {
            return Err(Error::invalid(
                "fit_levels",
                format!("a line needs at least 2 levels, got {fit_levels}"),
            ));
        }
        Ok(ContactSensorSlope {
            n_sigma,
            fit_levels,
            flying: Vec::with_capacity(64),
            trend: 0.0,
        })
    }

    /// Excess of `level` over the line of the flying levels, and its standard error (Ω): the
    /// noise of a level mean plus the line's model error (see the type's documentation); `None`
    /// until `fit_levels` flying levels are known.
    pub fn excess(&self, level: &LevelStats) -> Option<(f64, f64)> {
        let (e, noise2) = self.prediction_error(level)?;
        let pts = &self.flying[self.flying.len() - self.fit_levels..];
        let n = pts.len() as f64;
        let pm = pts.iter().map(|p| p.0).sum::<f64>() / n;
        let sxx: f64 = pts.iter().map(|p| (p.0 - pm).powi(2)).sum();
        let v = noise2 + self.trend * self.trend;
        let var_pred =
            v * (1.0 / n + (level.heater_power_mw - pm).powi(2) / sxx.max(f64::MIN_POSITIVE));
        Some((e, (v + var_pred).sqrt()))
    }

    /// Excess of `level` over the line, and the noise variance of a flying level mean.
    fn prediction_error(&self, level: &LevelStats) -> Option<(f64, f64)> {
        if self.flying.len() < self.fit_levels {
            return None;
        }
        let pts = &self.flying[self.flying.len() - self.fit_levels..];
        let n = pts.len() as f64;
        let pm = pts.iter().map(|p| p.0).sum::<f64>() / n;
        let rm = pts.iter().map(|p| p.1.mean).sum::<f64>() / n;
        let sxx: f64 = pts.iter().map(|p| (p.0 - pm).powi(2)).sum();
        let sxy: f64 = pts.iter().map(|p| (p.0 - pm) * (p.1.mean - rm)).sum();
        let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
        let pred = rm + slope * (level.heater_power_mw - pm);
        let s2 = pts.iter().map(|p| p.1.sem * p.1.sem).sum::<f64>() / n;
        Some((level.contact_resistance_ohm.mean - pred, s2))
    }
}

impl LevelDetector for ContactSensorSlope {
    fn name(&self) -> &str {
        "contact-sensor slope"
    }
    fn reset(&mut self) {
        self.flying.clear();
        self.trend = 0.0;
    }
    fn judge(&mut self, level: &LevelStats) -> bool {
        let contact = self
            .excess(level)
            .is_some_and(|(e, se)| e > self.n_sigma * se);
        if !contact && !level.descending {
            self.trend = self
                .prediction_error(level)
                .map_or(0.0, |(e, _)| e.max(0.0));
            self.flying
                .push((level.heater_power_mw, level.contact_resistance_ohm));
        }
        contact
    }
}

/// Touchdown from the acoustic emission: a level is in contact when its mean exceeds the mean of
/// the first `baseline_levels` levels by more than `n_sigma` standard errors (of a level mean and
/// of the baseline, from the scatter measured on the baseline levels).
///
/// ```
/// use hdi_tribology::drive::AcousticLevel;
/// assert!(AcousticLevel::new(5.0, 3).is_ok());
/// ```
#[derive(Clone, Debug)]
pub struct AcousticLevel {
    n_sigma: f64,
    baseline_levels: usize,
    seen: usize,
    base: RunningMean,
    base_sem2: f64,
}

impl AcousticLevel {
    /// Threshold `n_sigma` (> 0) and the number of levels that make the baseline (≥ 1).
    pub fn new(n_sigma: f64, baseline_levels: usize) -> Result<Self> {
        check_positive("n_sigma", n_sigma)?;
        if baseline_levels == 0 {
            return Err(Error::invalid("baseline_levels", "must be at least 1"));
        }
        Ok(AcousticLevel {
            n_sigma,
            baseline_levels,
            seen: 0,
            base: RunningMean::default(),
            base_sem2: 0.0,
        })
    }
}

impl LevelDetector for AcousticLevel {
    fn name(&self) -> &str {
        "acoustic emission"
    }
    fn reset(&mut self) {
        self.seen = 0;
        self.base = RunningMean::default();
        self.base_sem2 = 0.0;
    }
    fn judge(&mut self, level: &LevelStats) -> bool {
        if self.seen < self.baseline_levels && !level.descending {
            self.seen += 1;
            self.base.add(level.acoustic_v.mean);
            self.base_sem2 += level.acoustic_v.sem.powi(2);
            return false;
        }
        let n = self.base.count().max(1) as f64;
        let base = self.base.channel().mean;
        // The noise of a level mean is that of the baseline levels (see ContactSensorSlope).
        let s2 = self.base_sem2 / n;
        let se = (s2 + s2 / n).sqrt();
        level.acoustic_v.mean - base > self.n_sigma * se
    }
}

/// The heater staircase of a touchdown calibration, run through [`Drive`] at the controller's
/// period: each level is held for `settle_time_s + measure_time_s`, judged on the sensors of its
/// last `measure_time_s`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct StaircaseSettings {
    /// First level (mW).
    pub start_power_mw: f64,
    /// Power increment (mW, > 0).
    pub step_mw: f64,
    /// Highest level (mW).
    pub max_power_mw: f64,
    /// Time from the start of a level until its measurement begins (s).
    pub settle_time_s: f64,
    /// Measurement window at the end of each level (s).
    pub measure_time_s: f64,
    /// After touchdown, step down until contact is no longer seen.
    pub find_takeoff: bool,
    /// Back-off from the touchdown power to the operating power (mW).
    pub margin_mw: f64,
    /// AC dither amplitude during the calibration (V; 0: none).
    pub dither_amplitude_v: f64,
    /// AC dither frequency (kHz).
    pub dither_frequency_khz: f64,
    /// DC head–disk voltage during the calibration (V).
    pub dc_voltage_v: f64,
    /// Time of the linear heater ramp from one level to the next (s, ≤ `settle_time_s`; 0: a
    /// step). Each period of the ramp holds the ramp's mean over that period.
    pub rise_time_s: f64,
}

impl StaircaseSettings {
    /// A staircase in milliwatts, as firmware tables hold it: start, step, maximum and margin;
    /// 0.5 ms settle (five heater time constants of the default drive, fourteen decay times of
    /// the paper scene's air-bearing mode), 0.5 ms measurement, take-off search on, no dither.
    ///
    /// ```
    /// use hdi_tribology::drive::StaircaseSettings;
    /// let s = StaircaseSettings::from_mw(70.0, 0.25, 80.0, 10.0);
    /// assert_eq!(s.step_mw, 0.25);
    /// assert_eq!(s.settle_time_s, 5e-4);
    /// ```
    pub fn from_mw(start_mw: f64, step_mw: f64, max_mw: f64, margin_mw: f64) -> Self {
        StaircaseSettings {
            start_power_mw: start_mw,
            step_mw,
            max_power_mw: max_mw,
            settle_time_s: 5e-4,
            measure_time_s: 5e-4,
            find_takeoff: true,
            margin_mw,
            dither_amplitude_v: 0.0,
            dither_frequency_khz: 0.0,
            dc_voltage_v: 0.0,
            rise_time_s: 0.0,
        }
    }

    /// The power of level `k` (mW): `start_power_mw + k·step_mw`.
    pub fn level_mw(&self, k: i64) -> f64 {
        self.start_power_mw + k as f64 * self.step_mw
    }

    fn validate(&self, dt: f64) -> Result<(usize, usize, usize)> {
        check_non_negative("staircase.start_power_mw", self.start_power_mw)?;
        check_positive("staircase.step_mw", self.step_mw)?;
        crate::error::check_not_below(
            "staircase.max_power_mw",
            self.max_power_mw,
            "start_power_mw",
            self.start_power_mw,
            "mW",
            1.0,
        )?;
        if (self.max_power_mw - self.start_power_mw) / self.step_mw > 100_000.0 {
            return Err(Error::invalid(
                "staircase.step_mw",
                "more than 100000 levels between start_power_mw and max_power_mw",
            ));
        }
        check_non_negative("staircase.settle_time_s", self.settle_time_s)?;
        check_positive("staircase.measure_time_s", self.measure_time_s)?;
        check_non_negative("staircase.margin_mw", self.margin_mw)?;
        crate::error::check_finite("staircase.dc_voltage_v", self.dc_voltage_v)?;
        crate::error::check_finite("staircase.dither_amplitude_v", self.dither_amplitude_v)?;
        check_non_negative("staircase.dither_frequency_khz", self.dither_frequency_khz)?;
        check_non_negative("staircase.rise_time_s", self.rise_time_s)?;
        if self.rise_time_s > self.settle_time_s {
            return Err(Error::invalid(
                "staircase.rise_time_s",
                format!(
                    "must not exceed settle_time_s = {} µs, got {} µs",
                    self.settle_time_s * 1e6,
                    self.rise_time_s * 1e6
                ),
            ));
        }
        check_positive("dt", dt)?;
        let settle = (self.settle_time_s / dt).round() as usize;
        let rise = (self.rise_time_s / dt).round() as usize;
        let measure = (self.measure_time_s / dt).round() as usize;
        if measure < 2 {
            return Err(Error::invalid(
                "staircase.measure_time_s",
                format!(
                    "needs at least two controller periods of {} µs, got {} µs",
                    dt * 1e6,
                    self.measure_time_s * 1e6
                ),
            ));
        }
        Ok((settle, measure, rise))
    }
}

/// Where the staircase is.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
    Up,
    Down,
    Done,
}

/// The result of a staircase calibration.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StaircaseOutcome {
    /// Detector name.
    pub detector: String,
    /// First level judged in contact (mW); `None` if none up to the maximum.
    pub touchdown_power_mw: Option<f64>,
    /// On the way down, the first level judged flying again (mW).
    pub takeoff_power_mw: Option<f64>,
    /// `touchdown_power_mw − margin_mw` (mW).
    pub set_power_mw: Option<f64>,
    /// Every level, in the order run.
    pub levels: Vec<LevelStats>,
}

/// The firmware touchdown calibration as a [`Controller`]: the staircase of
/// `calibration::calibrate`, driven through [`Drive`], judged by any [`LevelDetector`].
///
/// ```no_run
/// use hdi_tribology::drive::{run, scene_zone, ContactSensorSlope, DriveOptions, Plant, Staircase, StaircaseSettings};
/// use hdi_tribology::scene::Scene;
/// let scene = Scene::paper();
/// let plant = Plant::new(&scene, &scene_zone(&scene, 0.025)?, 1, DriveOptions::default())?;
/// let mut drive = plant.drive()?;
/// let dt = 50e-6;
/// let mut cal = Staircase::new(StaircaseSettings::from_mw(70.0, 0.25, 80.0, 10.0), ContactSensorSlope::new(5.0, 4)?, dt)?;
/// run(&mut drive, &mut cal, dt, 1_000_000)?;
/// println!("touchdown {:?} mW", cal.outcome().touchdown_power_mw);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct Staircase<D: LevelDetector> {
    settings: StaircaseSettings,
    detector: D,
    settle: usize,
    measure: usize,
    rise: usize,
    phase: Phase,
    /// The level: `start_power_mw + level·step_mw`.
    level: i64,
    /// The power of the level before (the ramp's start, mW).
    previous: f64,
    /// The power of the level (mW).
    power: f64,
    k: usize,
    meter: Meter,
    outcome: StaircaseOutcome,
}

impl<D: LevelDetector> Staircase<D> {
    /// A staircase judged by `detector`, for a controller period `dt` (s).
    ///
    /// # Errors
    /// Invalid settings (named field).
    pub fn new(settings: StaircaseSettings, mut detector: D, dt: f64) -> Result<Self> {
        let (settle, measure, rise) = settings.validate(dt)?;
        detector.reset();
        Ok(Staircase {
            settings,
            settle,
            measure,
            rise,
            phase: Phase::Up,
            level: 0,
            previous: settings.start_power_mw,
            power: settings.start_power_mw,
            k: 0,
            meter: Meter::default(),
            outcome: StaircaseOutcome {
                detector: detector.name().to_string(),
                touchdown_power_mw: None,
                takeoff_power_mw: None,
                set_power_mw: None,
                levels: Vec::new(),
            },
            detector,
        })
    }

    /// What was found so far.
    pub fn outcome(&self) -> &StaircaseOutcome {
        &self.outcome
    }

    /// The detector.
    pub fn detector(&self) -> &D {
        &self.detector
    }

    /// Whether the calibration has finished.
    pub fn is_done(&self) -> bool {
        self.phase == Phase::Done
    }

    /// The detector, to change.
    pub fn detector_mut(&mut self) -> &mut D {
        &mut self.detector
    }

    /// The command of the next period (period `k + 1` of the level): on the ramp, its mean
    /// over that period.
    fn command(&self) -> Command {
        let j = self.k + 1;
        let heater_power_mw = if j <= self.rise {
            let f = (j as f64 - 0.5) / self.rise as f64;
            self.previous + (self.power - self.previous) * f
        } else {
            self.power
        };
        Command {
            heater_power_mw,
            dc_voltage_v: self.settings.dc_voltage_v,
            ..Command::default()
        }
        .with_dither(
            self.settings.dither_amplitude_v,
            self.settings.dither_frequency_khz,
        )
    }

    fn finish(&mut self) -> Action {
        self.phase = Phase::Done;
        self.outcome.set_power_mw = self
            .outcome
            .touchdown_power_mw
            .map(|p| (p - self.settings.margin_mw).max(0.0));
        Action::Stop
    }
}

impl<D: LevelDetector> Controller for Staircase<D> {
    fn start(&mut self) -> Command {
        self.command()
    }

    fn update(&mut self, s: &Sensors) -> Action {
        if self.phase == Phase::Done {
            return Action::Stop;
        }
        self.k += 1;
        let measuring = self.k > self.settle;
        self.detector.observe(s, measuring);
        if measuring {
            self.meter.add(s);
        }
        if self.k < self.settle + self.measure {
            return Action::Continue(self.command());
        }
        // The level is over: judge it.
        let sc = self.settings;
        let descending = self.phase == Phase::Down;
        let mut stats = self.meter.stats(self.power, descending);
        stats.contact = self.detector.judge(&stats);
        self.outcome.levels.push(stats);
        self.meter = Meter::default();
        self.k = 0;
        let below_start = |level: i64| level < 0;
        let next = match (self.phase, stats.contact) {
            (Phase::Up, true) => {
                self.outcome.touchdown_power_mw = Some(self.power);
                if !sc.find_takeoff {
                    return self.finish();
                }
                self.phase = Phase::Down;
                self.level - 1
            }
            (Phase::Up, false) => self.level + 1,
            (Phase::Down, false) => {
                self.outcome.takeoff_power_mw = Some(self.power);
                return self.finish();
            }
            (Phase::Down, true) => self.level - 1,
            (Phase::Done, _) => return Action::Stop,
        };
        let p = sc.level_mw(next);
        if below_start(next) || p > sc.max_power_mw + 1e-9 * sc.step_mw {
            return self.finish();
        }
        self.previous = self.power;
        self.level = next;
        self.power = p;
        Action::Continue(self.command())
    }
}

/// Where a [`ClearanceHold`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum HoldPhase {
    /// Running the touchdown staircase.
    Calibrating,
    /// Letting the heater settle at the new operating power (and, holding the set power's
    /// clearance, averaging the read-back there to take its reference).
    Referencing,
    /// Holding the clearance from the read-back.
    Holding,
}

/// The clearance a [`ClearanceHold`] holds.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub enum HoldTarget {
    /// The clearance at the calibrated operating power (touchdown − margin), whatever it is: the
    /// read-back reference is taken there after the heater has settled, and the loop holds the
    /// clearance change from it at zero.
    SetPower,
    /// A clearance above touchdown (nm, > 0): the read-back reference is the mean log ratio of
    /// the touchdown level (clearance zero), the heater starts from the feed-forward
    /// `P_TD − target/η`, and the loop holds the harmonic-ratio clearance at the target.
    AboveTouchdownNm(f64),
}

/// Settings of a [`ClearanceHold`].
///
/// The loop is a PI controller in velocity form, run once per `average` periods on the mean
/// read-back log ratio of those periods: with `e_k` the clearance estimate less the target (nm;
/// positive: too far from the disk),
/// `P_k = P_{k−1} + (proportional_gain·(e_k − e_{k−1}) + integral_gain·e_k) / η`.
/// `proportional_gain = 0` is a pure integral correction.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct HoldSettings {
    /// The touchdown calibration (its margin sets the operating power of
    /// [`HoldTarget::SetPower`]).
    pub staircase: StaircaseSettings,
    /// What clearance to hold.
    pub target: HoldTarget,
    /// Read-back wavelength of the drive (nm), for `Δd = λ/(4π) Δln(A_1/A_3)`.
    pub wavelength_nm: f64,
    /// Heater efficiency the firmware assumes (nm/mW), to turn a clearance error into power.
    pub efficiency_nm_per_mw: f64,
    /// Periods averaged per update.
    pub average: usize,
    /// Integral gain: the fraction of the clearance error corrected per update, (0, 1].
    pub integral_gain: f64,
    /// Proportional gain on the change of the error (≥ 0).
    pub proportional_gain: f64,
    /// Re-calibrate once the heater has moved this far from the operating power (mW): the
    /// read-back reference is then too old to trust.
    pub recalibrate_after_mw: f64,
}

/// A closed-loop clearance controller: calibrates touchdown with a staircase, goes to its
/// operating power, and holds the clearance the read-back harmonic ratio measures at its
/// [`HoldTarget`] with a PI correction of the heater ([`HoldSettings`]), while the disk's
/// waviness and the ambient temperature move it. It re-calibrates when the correction has grown
/// beyond `recalibrate_after_mw`.
pub struct ClearanceHold<D: LevelDetector + Clone> {
    settings: HoldSettings,
    dt: f64,
    prototype: D,
    staircase: Staircase<D>,
    phase: HoldPhase,
    /// The operating power of the last calibration (mW).
    set_power: f64,
    /// The heater power commanded (mW).
    power: f64,
    reference: f64,
    window: RunningMean,
    calibrations: usize,
    /// The last clearance estimate (nm).
    estimate: f64,
    /// The last error (nm; `None` before the first update of a hold).
    error: Option<f64>,
}

impl<D: LevelDetector + Clone> ClearanceHold<D> {
    /// A hold using `detector` for its calibrations, at controller period `dt` (s).
    ///
    /// ```
    /// use hdi_tribology::drive::{
    ///     ClearanceHold, ContactSensorSlope, HoldSettings, HoldTarget, StaircaseSettings,
    /// };
    /// let settings = HoldSettings {
    ///     staircase: StaircaseSettings::from_mw(70.0, 0.25, 80.0, 10.0),
    ///     target: HoldTarget::AboveTouchdownNm(1.0),
    ///     wavelength_nm: 100.0,
    ///     efficiency_nm_per_mw: 0.1,
    ///     average: 20,
    ///     integral_gain: 0.3,
    ///     proportional_gain: 0.5,
    ///     recalibrate_after_mw: 20.0,
    /// };
    /// let hold = ClearanceHold::new(settings, ContactSensorSlope::new(5.0, 4)?, 50e-6)?;
    /// assert_eq!(hold.target_nm(), Some(1.0));
    /// let bad = HoldSettings { target: HoldTarget::AboveTouchdownNm(-1.0), ..settings };
    /// let e = ClearanceHold::new(bad, ContactSensorSlope::new(5.0, 4)?, 50e-6).err().unwrap();
    /// assert!(e.to_string().contains("hold.target"), "{e}");
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    ///
    /// # Errors
    /// Invalid settings (named field).
    pub fn new(settings: HoldSettings, detector: D, dt: f64) -> Result<Self> {
        check_positive("hold.wavelength_nm", settings.wavelength_nm)?;
        check_positive("hold.efficiency_nm_per_mw", settings.efficiency_nm_per_mw)?;
        check_positive("hold.recalibrate_after_mw", settings.recalibrate_after_mw)?;
        check_non_negative("hold.proportional_gain", settings.proportional_gain)?;
        if let HoldTarget::AboveTouchdownNm(t) = settings.target {
            check_positive("hold.target.above_touchdown_nm", t)?;
        }
        if settings.average == 0 {
            return Err(Error::invalid("hold.average", "must be at least 1 period"));
        }
        if !(settings.integral_gain > 0.0 && settings.integral_gain <= 1.0) {
            return Err(Error::invalid(
                "hold.integral_gain",
                format!("must be in (0, 1], got {}", settings.integral_gain),
            ));
        }
        let staircase = Staircase::new(settings.staircase, detector.clone(), dt)?;
        Ok(ClearanceHold {
            settings,
            dt,
            prototype: detector,
            staircase,
            phase: HoldPhase::Calibrating,
            set_power: 0.0,
            power: settings.staircase.start_power_mw,
            reference: 0.0,
            window: RunningMean::default(),
            calibrations: 0,
            estimate: 0.0,
            error: None,
        })
    }

    /// The current phase.
    pub fn phase(&self) -> HoldPhase {
        self.phase
    }

    /// Calibrations completed.
    pub fn calibrations(&self) -> usize {
        self.calibrations
    }

    /// The operating power of the last calibration (mW): touchdown − margin, or the feed-forward
    /// power of a clearance target.
    pub fn set_power_mw(&self) -> f64 {
        self.set_power
    }

    /// The heater power now commanded (mW).
    pub fn power_mw(&self) -> f64 {
        self.power
    }

    /// The last clearance estimated from the read-back (nm): above touchdown for
    /// [`HoldTarget::AboveTouchdownNm`], the change from the reference for
    /// [`HoldTarget::SetPower`].
    pub fn estimate_nm(&self) -> f64 {
        self.estimate
    }

    /// The last calibration (the one running, while [`HoldPhase::Calibrating`]).
    pub fn calibration(&self) -> &StaircaseOutcome {
        self.staircase.outcome()
    }

    /// The heater efficiency the loop assumes (nm/mW).
    pub fn efficiency_nm_per_mw(&self) -> f64 {
        self.settings.efficiency_nm_per_mw
    }

    /// The clearance above touchdown held (nm), if the target is one.
    pub fn target_nm(&self) -> Option<f64> {
        match self.settings.target {
            HoldTarget::SetPower => None,
            HoldTarget::AboveTouchdownNm(t) => Some(t),
        }
    }

    /// The calibration that has just finished: the operating power and, for a clearance target,
    /// the read-back reference of the touchdown level. `false`: nothing safe to hold.
    fn calibrated(&mut self) -> bool {
        let out = self.staircase.outcome();
        let (Some(td), Some(set)) = (out.touchdown_power_mw, out.set_power_mw) else {
            return false;
        };
        match self.settings.target {
            HoldTarget::SetPower => self.set_power = set,
            HoldTarget::AboveTouchdownNm(t) => {
                let Some(level) = out
                    .levels
                    .iter()
                    .find(|l| !l.descending && l.heater_power_mw == td)
                else {
                    return false;
                };
                self.reference = level.log_ratio.mean;
                self.set_power = (td - t / self.settings.efficiency_nm_per_mw).max(0.0);
            }
        }
        self.power = self.set_power;
        self.error = None;
        true
    }

    fn hold_command(&self) -> Command {
        Command::heater_mw(self.power)
    }
}

impl<D: LevelDetector + Clone> Controller for ClearanceHold<D> {
    fn start(&mut self) -> Command {
        self.staircase.start()
    }

    fn update(&mut self, s: &Sensors) -> Action {
        let st = &self.settings;
        match self.phase {
            HoldPhase::Calibrating => {
                if let Action::Continue(c) = self.staircase.update(s) {
                    return Action::Continue(c);
                }
                self.calibrations += 1;
                if !self.calibrated() {
                    // No touchdown found: nothing safe to hold.
                    return Action::Stop;
                }
                self.phase = HoldPhase::Referencing;
                self.window = RunningMean::default();
            }
            HoldPhase::Referencing => {
                // Let the first periods settle before the reference (or the loop) counts.
                self.window.add(s.readback.log_ratio());
                if self.window.count() >= 2 * st.average {
                    if st.target == HoldTarget::SetPower {
                        self.reference = self.window.mean();
                    }
                    self.window = RunningMean::default();
                    self.phase = HoldPhase::Holding;
                }
            }
            HoldPhase::Holding => {
                self.window.add(s.readback.log_ratio());
                if self.window.count() >= st.average {
                    let lr = self.window.mean();
                    self.window = RunningMean::default();
                    self.estimate =
                        Readback::clearance_change_nm(self.reference, lr, st.wavelength_nm);
                    // Too much clearance: more heater.
                    let e = self.estimate - self.target_nm().unwrap_or(0.0);
                    let de = e - self.error.unwrap_or(0.0);
                    self.error = Some(e);
                    self.power += (st.proportional_gain * de + st.integral_gain * e)
                        / st.efficiency_nm_per_mw;
                    self.power = self.power.max(0.0);
                    if (self.power - self.set_power).abs() > st.recalibrate_after_mw {
                        let mut sc = st.staircase;
                        // Restart the staircase a few steps below the expected touchdown.
                        let td_now = self.power + (self.set_power_offset());
                        sc.start_power_mw = (td_now - 8.0 * sc.step_mw).max(0.0);
                        sc.max_power_mw = sc.max_power_mw.max(td_now + 8.0 * sc.step_mw);
                        match Staircase::new(sc, self.prototype.clone(), self.dt) {
                            Ok(stair) => {
                                self.staircase = stair;
                                self.phase = HoldPhase::Calibrating;
                                return Action::Continue(self.staircase.start());
                            }
                            Err(_) => return Action::Stop,
                        }
                    }
                }
            }
        }
        Action::Continue(self.hold_command())
    }
}

impl<D: LevelDetector + Clone> ClearanceHold<D> {
    /// How far below touchdown the operating power sits (mW).
    fn set_power_offset(&self) -> f64 {
        match self.settings.target {
            HoldTarget::SetPower => self.settings.staircase.margin_mw,
            HoldTarget::AboveTouchdownNm(t) => t / self.settings.efficiency_nm_per_mw,
        }
    }
}
