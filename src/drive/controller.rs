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
///         if s.acoustic > 0.02 { return Action::Stop; }
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

/// Running sums of one channel.
#[derive(Clone, Copy, Debug, Default)]
struct Acc {
    n: usize,
    s: f64,
    s2: f64,
    shift: f64,
}

impl Acc {
    fn add(&mut self, x: f64) {
        if self.n == 0 {
            self.shift = x;
        }
        let d = x - self.shift;
        self.n += 1;
        self.s += d;
        self.s2 += d * d;
    }

    fn channel(&self) -> Channel {
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
    /// Heater power of the level (W).
    pub power: f64,
    /// `true` on the way down (take-off search).
    pub descending: bool,
    /// Contact-sensor resistance (Ω).
    pub contact_resistance: Channel,
    /// Acoustic emission (V).
    pub acoustic: Channel,
    /// Read-back `ln(A_1/A_3)`.
    pub log_ratio: Channel,
    /// True contact force, period means (N): the oracle.
    pub true_contact_force: Channel,
    /// True bulge gap (m): the oracle.
    pub true_gap: Channel,
    /// Whether the detector saw contact.
    pub contact: bool,
}

#[derive(Clone, Copy, Debug, Default)]
struct Meter {
    r: Acc,
    ae: Acc,
    hr: Acc,
    fc: Acc,
    gap: Acc,
}

impl Meter {
    fn add(&mut self, s: &Sensors) {
        self.r.add(s.contact_resistance);
        self.ae.add(s.acoustic);
        self.hr.add(s.readback.log_ratio());
        self.fc.add(s.truth.mean_contact_force);
        self.gap.add(s.truth.gap);
    }

    fn stats(&self, power: f64, descending: bool) -> LevelStats {
        LevelStats {
            power,
            descending,
            contact_resistance: self.r.channel(),
            acoustic: self.ae.channel(),
            log_ratio: self.hr.channel(),
            true_contact_force: self.fc.channel(),
            true_gap: self.gap.channel(),
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
/// let d = TrueContact::new(5e-5)?;
/// assert_eq!(d.name(), "true contact force");
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct TrueContact {
    threshold: f64,
}

impl TrueContact {
    /// Threshold `F_th` (N, > 0).
    pub fn new(threshold: f64) -> Result<Self> {
        check_positive("threshold", threshold)?;
        Ok(TrueContact { threshold })
    }
}

impl LevelDetector for TrueContact {
    fn name(&self) -> &str {
        "true contact force"
    }
    fn reset(&mut self) {}
    fn judge(&mut self, level: &LevelStats) -> bool {
        level.true_contact_force.mean >= self.threshold
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
        let var_pred = v * (1.0 / n + (level.power - pm).powi(2) / sxx.max(f64::MIN_POSITIVE));
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
        let pred = rm + slope * (level.power - pm);
        let s2 = pts.iter().map(|p| p.1.sem * p.1.sem).sum::<f64>() / n;
        Some((level.contact_resistance.mean - pred, s2))
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
            self.flying.push((level.power, level.contact_resistance));
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
    base: Acc,
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
            base: Acc::default(),
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
        self.base = Acc::default();
        self.base_sem2 = 0.0;
    }
    fn judge(&mut self, level: &LevelStats) -> bool {
        if self.seen < self.baseline_levels && !level.descending {
            self.seen += 1;
            self.base.add(level.acoustic.mean);
            self.base_sem2 += level.acoustic.sem.powi(2);
            return false;
        }
        let n = self.base.n.max(1) as f64;
        let base = self.base.channel().mean;
        // The noise of a level mean is that of the baseline levels (see ContactSensorSlope).
        let s2 = self.base_sem2 / n;
        let se = (s2 + s2 / n).sqrt();
        level.acoustic.mean - base > self.n_sigma * se
    }
}

/// The heater staircase of a touchdown calibration, run through [`Drive`] at the controller's
/// period: each level is held for `settle_time + measure_time`, judged on the sensors of its last
/// `measure_time`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct StaircaseSettings {
    /// First level (W).
    pub start_power: f64,
    /// Power increment (W, > 0).
    pub step: f64,
    /// Highest level (W).
    pub max_power: f64,
    /// Time from the start of a level until its measurement begins (s).
    pub settle_time: f64,
    /// Measurement window at the end of each level (s).
    pub measure_time: f64,
    /// After touchdown, step down until contact is no longer seen.
    pub find_takeoff: bool,
    /// Back-off from the touchdown power to the operating power (W).
    pub margin: f64,
    /// AC dither `(amplitude V, frequency Hz)` during the calibration.
    pub dither: Option<(f64, f64)>,
    /// DC head–disk voltage during the calibration (V).
    pub dc_voltage: f64,
    /// Time of the linear heater ramp from one level to the next (s, ≤ `settle_time`; 0: a
    /// step). Each period of the ramp holds the ramp's mean over that period.
    pub rise_time: f64,
}

impl StaircaseSettings {
    /// A staircase in milliwatts, as firmware tables hold it: start, step, maximum and margin;
    /// 0.5 ms settle (five heater time constants of the default drive, fourteen decay times of
    /// the paper scene's air-bearing mode), 0.5 ms measurement, take-off search on, no dither.
    ///
    /// ```
    /// use hdi_tribology::drive::StaircaseSettings;
    /// let s = StaircaseSettings::from_mw(70.0, 0.25, 80.0, 10.0);
    /// assert_eq!(s.step, 0.00025);
    /// ```
    pub fn from_mw(start_mw: f64, step_mw: f64, max_mw: f64, margin_mw: f64) -> Self {
        use crate::units::mw;
        StaircaseSettings {
            start_power: mw(start_mw),
            step: mw(step_mw),
            max_power: mw(max_mw),
            settle_time: 5e-4,
            measure_time: 5e-4,
            find_takeoff: true,
            margin: mw(margin_mw),
            dither: None,
            dc_voltage: 0.0,
            rise_time: 0.0,
        }
    }

    fn validate(&self, dt: f64) -> Result<(usize, usize, usize)> {
        check_non_negative("staircase.start_power", self.start_power)?;
        check_positive("staircase.step", self.step)?;
        crate::error::check_not_below(
            "staircase.max_power",
            self.max_power,
            "start_power",
            self.start_power,
            "mW",
            1e-3,
        )?;
        if (self.max_power - self.start_power) / self.step > 100_000.0 {
            return Err(Error::invalid(
                "staircase.step",
                "more than 100000 levels between start_power and max_power",
            ));
        }
        check_non_negative("staircase.settle_time", self.settle_time)?;
        check_positive("staircase.measure_time", self.measure_time)?;
        check_non_negative("staircase.margin", self.margin)?;
        crate::error::check_finite("staircase.dc_voltage", self.dc_voltage)?;
        check_non_negative("staircase.rise_time", self.rise_time)?;
        if self.rise_time > self.settle_time {
            return Err(Error::invalid(
                "staircase.rise_time",
                format!(
                    "must not exceed settle_time = {} µs, got {} µs",
                    self.settle_time * 1e6,
                    self.rise_time * 1e6
                ),
            ));
        }
        check_positive("dt", dt)?;
        let settle = (self.settle_time / dt).round() as usize;
        let rise = (self.rise_time / dt).round() as usize;
        let measure = (self.measure_time / dt).round() as usize;
        if measure < 2 {
            return Err(Error::invalid(
                "staircase.measure_time",
                format!(
                    "needs at least two controller periods of {} µs, got {} µs",
                    dt * 1e6,
                    self.measure_time * 1e6
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
    /// First level judged in contact (W); `None` if none up to the maximum.
    pub touchdown_power: Option<f64>,
    /// On the way down, the first level judged flying again (W).
    pub takeoff_power: Option<f64>,
    /// `touchdown_power − margin` (W).
    pub set_power: Option<f64>,
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
/// println!("touchdown {:?} W", cal.outcome().touchdown_power);
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
    /// The level: `start_power + level·step`.
    level: i64,
    /// The power of the level before (the ramp's start).
    previous: f64,
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
            previous: settings.start_power,
            power: settings.start_power,
            k: 0,
            meter: Meter::default(),
            outcome: StaircaseOutcome {
                detector: detector.name().to_string(),
                touchdown_power: None,
                takeoff_power: None,
                set_power: None,
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
        let heater_power = if j <= self.rise {
            let f = (j as f64 - 0.5) / self.rise as f64;
            self.previous + (self.power - self.previous) * f
        } else {
            self.power
        };
        let c = Command {
            heater_power,
            dc_voltage: self.settings.dc_voltage,
            ..Command::default()
        };
        match self.settings.dither {
            Some((a, f)) => c.with_dither(a, f),
            None => c,
        }
    }

    fn finish(&mut self) -> Action {
        self.phase = Phase::Done;
        self.outcome.set_power = self
            .outcome
            .touchdown_power
            .map(|p| (p - self.settings.margin).max(0.0));
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
                self.outcome.touchdown_power = Some(self.power);
                if !sc.find_takeoff {
                    return self.finish();
                }
                self.phase = Phase::Down;
                self.level - 1
            }
            (Phase::Up, false) => self.level + 1,
            (Phase::Down, false) => {
                self.outcome.takeoff_power = Some(self.power);
                return self.finish();
            }
            (Phase::Down, true) => self.level - 1,
            (Phase::Done, _) => return Action::Stop,
        };
        let p = sc.start_power + next as f64 * sc.step;
        if below_start(next) || p > sc.max_power + 1e-9 * sc.step {
            return self.finish();
        }
        self.previous = self.power;
        self.level = next;
        self.power = p;
        Action::Continue(self.command())
    }
}

/// Average read-back log ratio over a window (a helper of [`ClearanceHold`]).
#[derive(Clone, Copy, Debug, Default)]
struct Window {
    acc: Acc,
}

/// Where a [`ClearanceHold`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum HoldPhase {
    /// Running the touchdown staircase.
    Calibrating,
    /// Averaging the read-back at the new operating power to take its reference.
    Referencing,
    /// Holding the clearance from the read-back.
    Holding,
}

/// Settings of a [`ClearanceHold`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct HoldSettings {
    /// The touchdown calibration (its margin sets the clearance held).
    pub staircase: StaircaseSettings,
    /// Read-back wavelength of the drive (m), for `Δd = λ/(4π) Δln(A_1/A_3)`.
    pub wavelength: f64,
    /// Heater efficiency the firmware assumes (m/W), to turn a clearance error into power.
    pub efficiency: f64,
    /// Periods averaged per correction.
    pub average: usize,
    /// Fraction of the estimated clearance error corrected per update (0, 1].
    pub gain: f64,
    /// Re-calibrate once the heater has moved this far from the calibrated operating power (W):
    /// the read-back reference is then too old to trust.
    pub recalibrate_after: f64,
}

/// A closed-loop clearance controller: calibrates touchdown with a staircase, backs off by the
/// margin, takes the read-back harmonic ratio there as its reference, then holds the clearance
/// with an integral correction of the heater from the harmonic-ratio clearance change, while
/// the disk's waviness and the ambient temperature move it. It re-calibrates when the
/// correction has grown beyond `recalibrate_after`.
pub struct ClearanceHold<D: LevelDetector + Clone> {
    settings: HoldSettings,
    dt: f64,
    prototype: D,
    staircase: Staircase<D>,
    phase: HoldPhase,
    set_power: f64,
    power: f64,
    reference: f64,
    window: Window,
    calibrations: usize,
    estimate: f64,
}

impl<D: LevelDetector + Clone> ClearanceHold<D> {
    /// A hold using `detector` for its calibrations, at controller period `dt` (s).
    ///
    /// # Errors
    /// Invalid settings (named field).
    pub fn new(settings: HoldSettings, detector: D, dt: f64) -> Result<Self> {
        check_positive("hold.wavelength", settings.wavelength)?;
        check_positive("hold.efficiency", settings.efficiency)?;
        check_positive("hold.recalibrate_after", settings.recalibrate_after)?;
        if settings.average == 0 {
            return Err(Error::invalid("hold.average", "must be at least 1 period"));
        }
        if !(settings.gain > 0.0 && settings.gain <= 1.0) {
            return Err(Error::invalid(
                "hold.gain",
                format!("must be in (0, 1], got {}", settings.gain),
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
            power: settings.staircase.start_power,
            reference: 0.0,
            window: Window::default(),
            calibrations: 0,
            estimate: 0.0,
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

    /// The operating power of the last calibration (W).
    pub fn set_power(&self) -> f64 {
        self.set_power
    }

    /// The heater power now commanded (W).
    pub fn power(&self) -> f64 {
        self.power
    }

    /// The last clearance change estimated from the read-back (m), relative to the reference.
    pub fn estimate(&self) -> f64 {
        self.estimate
    }

    fn hold_command(&self) -> Command {
        Command {
            heater_power: self.power,
            ..Command::default()
        }
    }
}

impl<D: LevelDetector + Clone> Controller for ClearanceHold<D> {
    fn start(&mut self) -> Command {
        self.staircase.start()
    }

    fn update(&mut self, s: &Sensors) -> Action {
        match self.phase {
            HoldPhase::Calibrating => {
                if let Action::Continue(c) = self.staircase.update(s) {
                    return Action::Continue(c);
                }
                self.calibrations += 1;
                match self.staircase.outcome().set_power {
                    Some(p) => {
                        self.set_power = p;
                        self.power = p;
                        self.phase = HoldPhase::Referencing;
                        self.window = Window::default();
                    }
                    // No touchdown found: nothing safe to hold.
                    None => return Action::Stop,
                }
            }
            HoldPhase::Referencing => {
                // Let the first periods settle before the reference counts.
                self.window.acc.add(s.readback.log_ratio());
                if self.window.acc.n >= 2 * self.settings.average {
                    self.reference = self.window.acc.channel().mean;
                    self.window = Window::default();
                    self.phase = HoldPhase::Holding;
                }
            }
            HoldPhase::Holding => {
                self.window.acc.add(s.readback.log_ratio());
                if self.window.acc.n >= self.settings.average {
                    let lr = self.window.acc.channel().mean;
                    self.window = Window::default();
                    self.estimate =
                        Readback::clearance_change(self.reference, lr, self.settings.wavelength);
                    // Too much clearance: more heater.
                    self.power += self.settings.gain * self.estimate / self.settings.efficiency;
                    self.power = self.power.max(0.0);
                    if (self.power - self.set_power).abs() > self.settings.recalibrate_after {
                        let mut st = self.settings.staircase;
                        // Restart the staircase a few steps below the expected touchdown.
                        let td_now = self.power + st.margin;
                        st.start_power = (td_now - 8.0 * st.step).max(0.0);
                        st.max_power = st.max_power.max(td_now + 8.0 * st.step);
                        match Staircase::new(st, self.prototype.clone(), self.dt) {
                            Ok(sc) => {
                                self.staircase = sc;
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
