//! The calibration loop: a heater staircase up to touchdown, optionally back down to take-off,
//! then the back-off and the clearance it leaves.

use super::detector::{Sample, TouchdownDetector};
use crate::analysis::equilibrium::{flying_equilibrium, ScanGrid};
use crate::error::{check_finite, check_non_negative, check_positive, Error, Result};
use crate::heater::Programme;
use crate::model::{SliderModel, SliderSystem};
use crate::ode::{self, Method, Options, SaveAt, Stats};
use nalgebra::{DVector, Dyn};
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
        check_finite("staircase.max_power", self.max_power)?;
        if self.max_power < self.start_power {
            return Err(Error::invalid(
                "staircase.max_power",
                format!(
                    "must not be below start_power = {} W, got {} W",
                    self.start_power, self.max_power
                ),
            ));
        }
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
/// assert_eq!(hdi_tribology::clearance::MAX_LEVELS, 100_000);
/// ```
pub const MAX_LEVELS: usize = 100_000;

/// Options of [`calibrate`].
///
/// ```
/// use hdi_tribology::clearance::CalibrationOptions;
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
    /// them.
    ///
    /// ```
    /// use hdi_tribology::clearance::CalibrationOptions;
    /// let o = CalibrationOptions::from_mw(60.0, 0.5, 90.0, 5.0);
    /// use hdi_tribology::units::mw;
    /// assert_eq!(o, CalibrationOptions::new(mw(60.0), mw(0.5), mw(90.0), mw(5.0)));
    /// ```
    pub fn from_mw(start_mw: f64, step_mw: f64, max_mw: f64, margin_mw: f64) -> Self {
        use crate::units::mw;
        CalibrationOptions::new(mw(start_mw), mw(step_mw), mw(max_mw), mw(margin_mw))
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
    pub power: f64,
    /// `true` on the way down (take-off search).
    pub descending: bool,
    /// Largest detector level in the measurement window.
    pub peak_level: f64,
    /// Smallest bulge gap over the whole level (m).
    pub min_gap: f64,
    /// Whether the detector saw contact in the measurement window.
    pub contact: bool,
}

/// The outcome of one calibration.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Calibration {
    /// Name of the detector used.
    pub detector: String,
    /// First heater level where contact was seen (W).
    pub touchdown_power: f64,
    /// On the way down, the first level where contact was no longer seen (W); `None` when the
    /// search was off or contact persisted down to the start power.
    pub takeoff_power: Option<f64>,
    /// Operating power `touchdown_power − margin` (W).
    pub set_power: f64,
    /// Clearance at the operating power: the bulge gap of the static flying equilibrium at
    /// `set_power` with the DC voltage only (the dither is off in operation) (m).
    pub clearance: f64,
    /// Peak detector level at touchdown over that at the level before (∞ if that was 0): how
    /// sharply the detector separates contact from flying.
    pub contrast: f64,
    /// Every level, in the order run.
    pub steps: Vec<StepRecord>,
    /// Simulated time (s).
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
/// climbs the staircase; every level is integrated with the crate's ODE stepper through
/// [`SliderSystem`] (the model's voltage, dither included, acts throughout) and sampled every
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
/// use hdi_tribology::clearance::{calibrate, CalibrationOptions, MeanContactForce};
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
    let grid = ScanGrid::default();
    let eq = flying_equilibrium(model, sc.start_power, model.voltage.squared(0.0), &grid)?;
    let probe = SliderSystem::new(model, Programme::constant(sc.start_power, 1.0)?, false);
    let n = probe.layout().len();
    let mut state = Run {
        model,
        opts,
        t: 0.0,
        y: probe.initial_state(Dyn(n), &eq.rest()),
        power: sc.start_power,
        stats: Stats::default(),
        steps: Vec::new(),
    };
    detector.reset();

    // Up: levels start_power + k·step; the first level is the start power itself (a baseline).
    let levels = ((sc.max_power - sc.start_power) / sc.step * (1.0 + 1e-12)).floor() as usize;
    let mut touchdown = None;
    for k in 0..=levels {
        let p = sc.start_power + k as f64 * sc.step;
        if state.level(p, false, detector)?.contact {
            touchdown = Some(p);
            break;
        }
    }
    let Some(touchdown_power) = touchdown else {
        return Err(crate::error::AnalysisError::NoTouchdown {
            stage: crate::error::Stage::ClearanceCalibration,
            max_power_mw: crate::units::to_mw(sc.max_power),
            detector: Some(detector.name().to_string()),
        }
        .into());
    };
    if state.steps.len() == 1 {
        // Fired at the baseline level: the slider was in contact before the staircase began, so
        // there is no touchdown power to find and no contrast to measure.
        return Err(crate::error::AnalysisError::ContactAtStart {
            detector: detector.name().to_string(),
            start_power_mw: crate::units::to_mw(sc.start_power),
        }
        .into());
    }
    let contrast = match state.steps.len() {
        0 | 1 => f64::INFINITY,
        m => {
            let (a, b) = (state.steps[m - 1].peak_level, state.steps[m - 2].peak_level);
            if b > 0.0 {
                a / b
            } else {
                f64::INFINITY
            }
        }
    };

    let mut takeoff_power = None;
    if opts.find_takeoff {
        let mut k = 1usize;
        loop {
            let p = touchdown_power - k as f64 * sc.step;
            if p < sc.start_power - 1e-12 * sc.step {
                break;
            }
            if !state.level(p, true, detector)?.contact {
                takeoff_power = Some(p);
                break;
            }
            k += 1;
        }
    }

    let set_power = touchdown_power - opts.margin;
    if set_power < 0.0 {
        return Err(Error::invalid(
            "margin",
            format!(
                "{} W exceeds the touchdown power {} W",
                opts.margin, touchdown_power
            ),
        ));
    }
    let dc2 = model.voltage.dc_squared();
    let clearance = flying_equilibrium(model, set_power, dc2, &grid)?.d;
    Ok(Calibration {
        detector: detector.name().to_string(),
        touchdown_power,
        takeoff_power,
        set_power,
        clearance,
        contrast,
        simulated_time: state.t,
        stats: state.stats,
        steps: state.steps,
    })
}

/// The drive being calibrated: time, state and heater level so far.
struct Run<'a> {
    model: &'a SliderModel,
    opts: &'a CalibrationOptions,
    t: f64,
    y: DVector<f64>,
    power: f64,
    stats: Stats,
    steps: Vec<StepRecord>,
}

impl Run<'_> {
    /// Moves the heater to `p` and holds it there for one dwell, feeding the detector.
    fn level(
        &mut self,
        p: f64,
        descending: bool,
        detector: &mut dyn TouchdownDetector,
    ) -> Result<StepRecord> {
        let sc = self.opts.staircase;
        let (t0, t1) = (self.t, self.t + sc.dwell());
        let knots = if p == self.power {
            vec![(t0, p), (t1, p)]
        } else {
            vec![(t0, self.power), (t0 + sc.rise_time, p), (t1, p)]
        };
        let programme = Programme::new(knots)?;
        let sys = SliderSystem::new(self.model, programme.clone(), false);
        let dt = self.opts.sample_interval;
        let count = (sc.dwell() / dt).floor() as usize;
        let times: Vec<f64> = (1..=count)
            .map(|j| t0 + j as f64 * dt)
            .filter(|&t| t <= t1)
            .collect();
        let sol = ode::solve(
            &sys,
            t0,
            self.y.clone(),
            t1,
            self.opts.method,
            &self.ode_options(&programme, times),
            &mut [],
        )?;
        self.stats += &sol.stats;

        let m = self.model;
        let judge_from = t0 + sc.settle_time;
        let mut rec = StepRecord {
            power: p,
            descending,
            peak_level: 0.0,
            min_gap: f64::INFINITY,
            contact: false,
        };
        for (&t, s) in sol.t.iter().zip(&sol.y) {
            let g = sys.gaps(t, s);
            let f = m.interface_force(g, m.voltage.squared(t));
            let sample = Sample {
                t,
                power: programme.power(t),
                displacement: s[0],
                velocity: s[sys.layout().velocity(0)],
                gap: g.bulge,
                contact_force: m.contact_force(g),
                interface_force: f.value,
            };
            let fired = detector.update(&sample);
            rec.min_gap = rec.min_gap.min(g.bulge);
            if t >= judge_from {
                rec.contact |= fired;
                rec.peak_level = rec.peak_level.max(detector.level());
            }
        }
        self.t = t1;
        self.y = sol.y_end;
        self.power = p;
        self.steps.push(rec);
        Ok(rec)
    }

    fn ode_options(&self, programme: &Programme, times: Vec<f64>) -> Options {
        let m = self.model;
        let sys = SliderSystem::new(m, programme.clone(), false);
        let atol = sys.tolerances(self.opts.atol_displacement, 0.0, 0.0);
        let h_max = m.max_step(None);
        Options::default()
            .rtol(self.opts.rtol)
            .atol_per_component(atol)
            .h_max(h_max)
            .max_steps(10_000_000)
            .t_stops(programme.knots().iter().map(|k| k.0).collect())
            .save(SaveAt::Times(times))
            .dense(false)
    }
}
