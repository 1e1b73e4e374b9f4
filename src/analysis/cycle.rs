//! Dynamic touchdown/take-off cycles under a heater programme (MODEL.md section 6).
//!
//! The slider is integrated from its flying equilibrium at `P(0)`, `V(0)²` with two running
//! integrals in the state: `Q = ∫F_c dt`, so the contact indicator — the running mean of `F_c` over
//! the trailing window `T_w` — is exactly `(Q(t) − Q(t − T_w))/T_w` on the dense output, and
//! `Θ = ∫ΔT dt` for the mean flash temperature. Touchdown is the first time the indicator reaches
//! `F_th` (from `t = T_w` on); take-off the first time at or after the end of the hold that it falls
//! below `F_th`. Both are located by root finding on the dense output. The trailing window delays
//! detection by up to `T_w`: the dynamic hysteresis is biased upward by about ramp rate × `T_w`.

use super::energy::{Audit, LagEnergy};
use super::equilibrium::{flying_equilibrium, ScanGrid};
use super::roots::brent;
use crate::error::{check_positive, failure_kind, num, Error, Result, Stage};
use crate::heater::Programme;
use crate::model::{SliderModel, SliderSystem};
use crate::ode::{self, Method, Stats, StepStatus};
use crate::sim::{self, Flow, Observer, Problem, SizedRun, StepView};
use nalgebra::{allocator::Allocator, DefaultAllocator, DimName, OVector};
use serde::Serialize;
use std::sync::Arc;
use std::time::Instant;

impl Stage {
    /// A dynamic cycle under a fixed heater programme.
    pub const CYCLE: Stage = Stage::named("cycle");
    /// A dynamic cycle whose heater ramp reverses at touchdown.
    pub const TRIGGERED_CYCLE: Stage = Stage::named("triggered cycle");
}

/// A contact that feeds energy into the bounce: the interface lag exceeds the time constant
/// `c/K_contact` of the air-bearing damping against the contact stiffness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SelfExcitation {
    /// The interface lag `τ` (ns).
    pub interface_lag_ns: f64,
    /// `c/K_contact` where the trajectory stopped (ns).
    pub limit_ns: f64,
}

/// Why a cycle could not run to its end. Numbers are in engineering units, as the field names
/// say.
///
/// ```
/// use hdi_tribology::analysis::cycle::CycleError;
/// let e: hdi_tribology::Error = CycleError::NoTriggeredTouchdown { max_power_mw: 80.0 }.into();
/// assert_eq!(e.to_string(), "triggered cycle: no touchdown detected up to 80.0000 mW");
/// ```
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CycleError {
    /// Triggered cycle: the touchdown search would need too many segments of the overshoot.
    #[error(
        "reaching a protrusion of 2 h0 takes {} mW, {segments:.3e} segments of the overshoot {} mW \
         (at most {max_segments:e}): raise the overshoot or the heater efficiency",
        num(*.span_mw),
        num(*.overshoot_mw)
    )]
    TooManySegments {
        /// Heater power span searched, up to a protrusion of twice the clearance (mW).
        span_mw: f64,
        /// The overshoot (mW).
        overshoot_mw: f64,
        /// Segments needed.
        segments: f64,
        /// Segments allowed.
        max_segments: f64,
    },
    /// Triggered cycle: the detector saw no touchdown on the whole ramp.
    #[error("no touchdown detected up to {} mW", num(*.max_power_mw))]
    NoTriggeredTouchdown {
        /// The largest heater power reached (mW).
        max_power_mw: f64,
    },
    /// The pad gap reached zero, so the slider body would enter the disk, outside the lumped
    /// model.
    #[error("{}", left_the_model_reason(*.t_ms, *.bulge_gap_nm, *.velocity_m_per_s, .self_excited))]
    LeftTheModel {
        /// Time (ms).
        t_ms: f64,
        /// Bulge gap there (nm).
        bulge_gap_nm: f64,
        /// Body velocity there (m/s).
        velocity_m_per_s: f64,
        /// Set when an interface lag makes the contact branch self-excited, the likely cause.
        self_excited: Option<SelfExcitation>,
    },
    /// An explicit method used up its steps where the system is stiff.
    #[error(
        "the explicit method {method} used up its {max_steps} steps at t = {} ms: {}",
        num(*.t_ms),
        stiff_advice(*.fastest_rate_per_s)
    )]
    StepLimit {
        /// The method's name, e.g. `tsit5`.
        method: &'static str,
        /// Its step budget.
        max_steps: usize,
        /// Time reached (ms).
        t_ms: f64,
        /// Fastest decay rate of the bearing, contact and lags (1/s).
        fastest_rate_per_s: f64,
    },
    /// The steps are spent more than twice as fast as an even pace over the programme would
    /// spend `solver.max_steps`, so the budget would run out.
    #[error("{}", step_pace(method, *.steps, *.t_ms, *.span_ms, *.max_steps, *.stiff_rate_per_s))]
    StepPace {
        /// The method's name, e.g. `auto`.
        method: &'static str,
        /// Steps taken so far (accepted and rejected).
        steps: usize,
        /// Time reached (ms).
        t_ms: f64,
        /// Length of the heater programme (ms).
        span_ms: f64,
        /// The step budget.
        max_steps: usize,
        /// For an explicit method: the fastest decay rate of the bearing, contact and lags
        /// (1/s), the likely cause.
        stiff_rate_per_s: Option<f64>,
    },
    /// With [`CycleOptions::stop_outside_tables`]: the bulge gap of an accepted step is deeper
    /// than the force tables reach while the steps are spent more than twice as fast as an even
    /// pace over the programme would spend `solver.max_steps` (from the start, or since the
    /// first step below the tables after an allowance of 1 % of the budget): a contact bouncing
    /// deep in the disk, where the contact model is far outside its light-contact validity, at a
    /// pace that would use up the step budget.
    #[error(
        "at t = {} ms the bulge gap d = {} nm is deeper than the force tables reach (down to {} \
         nm), where the contact model is far outside its light-contact validity and every force \
         is an exact quadrature, and the cycle spends its steps at more than twice the pace that \
         uses solver.max_steps = {max_steps} evenly over the {} ms programme ({steps} steps, \
         {steps_below} of them since the gap first went below the tables at {} ms): a contact \
         bouncing below the tables that would use up the step budget",
        num(*.t_ms),
        num(*.bulge_gap_nm),
        num(*.table_low_nm),
        num(*.span_ms),
        num(*.first_below_ms)
    )]
    LeftTheTables {
        /// Time reached (ms).
        t_ms: f64,
        /// Bulge gap `d` there (nm).
        bulge_gap_nm: f64,
        /// The low end of the force tables (nm).
        table_low_nm: f64,
        /// Steps taken so far (accepted and rejected).
        steps: usize,
        /// Time of the first accepted step below the tables (ms).
        first_below_ms: f64,
        /// Steps taken since then.
        steps_below: usize,
        /// Length of the heater programme (ms).
        span_ms: f64,
        /// The step budget.
        max_steps: usize,
    },
}

failure_kind!(CycleError, convergence = |_| false, {
        TooManySegments => Stage::TRIGGERED_CYCLE,
        NoTriggeredTouchdown => Stage::TRIGGERED_CYCLE,
        LeftTheModel => Stage::CYCLE,
        StepLimit => Stage::CYCLE,
        StepPace => Stage::CYCLE,
        LeftTheTables => Stage::CYCLE,
});

/// The reason of [`CycleError::LeftTheModel`].
fn left_the_model_reason(
    t_ms: f64,
    gap_nm: f64,
    v: f64,
    self_excited: &Option<SelfExcitation>,
) -> String {
    let mut s = format!(
        "at t = {} ms the pad gap h0 + y fell to zero (bulge gap d = {} nm, velocity {} m/s): the \
         slider body would enter the disk, outside the lumped model",
        num(t_ms),
        num(gap_nm),
        num(v)
    );
    if let Some(x) = self_excited {
        s.push_str(&format!(
            "; the interface lag {} ns exceeds c/K_contact = {} ns, so each contact feeds energy \
             into the bounce (self-excited contact branch)",
            num(x.interface_lag_ns),
            num(x.limit_ns)
        ));
    }
    s
}

/// Why an explicit method's step is limited on a stiff cycle, and what to use instead.
fn stiff_advice(rate_per_s: f64) -> String {
    format!(
        "the system is stiff there (fastest mode about {rate_per_s:.3e} 1/s from the bearing, \
         contact and lags), so stability, not accuracy, limits its step; use auto, rodas5p or \
         radau5"
    )
}

/// The reason of [`CycleError::StepPace`].
fn step_pace(
    method: &str,
    steps: usize,
    t_ms: f64,
    span_ms: f64,
    max_steps: usize,
    stiff_rate_per_s: Option<f64>,
) -> String {
    let pace = format!(
        "{steps} steps by t = {} ms, more than twice the pace that spends them evenly over the {} \
         ms programme",
        num(t_ms),
        num(span_ms)
    );
    match stiff_rate_per_s {
        Some(rate) => format!(
            "the explicit method {method} would use up its {max_steps} steps ({pace}): {}",
            stiff_advice(rate)
        ),
        None => format!(
            "the cycle would use up solver.max_steps = {max_steps} ({pace}): a contact that \
             bounces without bound, or a tolerance too strict for the method"
        ),
    }
}

/// Largest length of the touchdown-triggered search, in overshoots (`overshoot / ramp_rate` of
/// time each; the paper scene's search spans 200).
const MAX_TRIGGERED_SEGMENTS: f64 = 1e5;

/// The step pace's start allowance, as a fraction of `max_steps` ([`SolverSettings::max_steps`]).
const STEP_PACE_ALLOWANCE: f64 = 0.1;

/// The start allowance of the step pace taken afresh from a cycle's first step below the force
/// tables, as a fraction of `max_steps` ([`CycleOptions::stop_outside_tables`]).
const BELOW_TABLES_ALLOWANCE: f64 = 0.01;

/// The heater programme of a cycle.
#[derive(Clone, Debug, PartialEq)]
pub enum HeaterProgramme {
    /// A fixed piecewise-linear programme; take-off is searched from its end of hold (the last knot
    /// at its highest power).
    Fixed(Programme),
    /// The experiment's protocol: ramp up at `ramp_rate` from `start_power` until touchdown is
    /// detected, go on for `overshoot` more, then ramp down at the same rate to `start_power`.
    Triggered {
        /// Starting (and final) power (W).
        start_power: f64,
        /// Ramp rate (W/s), both ways.
        ramp_rate: f64,
        /// Power added after touchdown is detected (W).
        overshoot: f64,
    },
}

impl HeaterProgramme {
    /// `"fixed"` or `"triggered"`, as results record the programme.
    ///
    /// ```
    /// use hdi_tribology::analysis::HeaterProgramme;
    /// let p = HeaterProgramme::Triggered { start_power: 0.0, ramp_rate: 1.0, overshoot: 0.0 };
    /// assert_eq!(p.name(), "triggered");
    /// ```
    pub fn name(&self) -> &'static str {
        match self {
            HeaterProgramme::Fixed(_) => "fixed",
            HeaterProgramme::Triggered { .. } => "triggered",
        }
    }
}

/// The contact detector standing in for the acoustic-emission sensor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detector {
    /// Threshold `F_th` on the running mean of the contact force (N).
    pub contact_threshold: f64,
    /// Trailing window `T_w` of the running mean (s).
    pub window: f64,
}

/// Integration settings of a cycle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverSettings {
    /// Method.
    pub method: Method,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance on the displacement (m); the other states are scaled from it.
    pub atol_displacement: f64,
    /// Largest step (s); `None`: a twentieth of the period of `V²` with AC, else unlimited.
    pub max_step: Option<f64>,
    /// Step limit of the whole cycle (accepted and rejected steps). A cycle also stops early once
    /// it runs at more than twice the pace that would spend the limit evenly over the programme
    /// (after a tenth of the limit as a start allowance): a contact that bounces without bound
    /// would otherwise use the whole limit on its first microseconds.
    pub max_steps: usize,
}

impl SolverSettings {
    /// The settings at relative tolerance `rtol`, the displacement's absolute tolerance scaled
    /// with it (`atol · rtol / rtol₀`): the one rule by which a new rtol tightens or loosens
    /// the whole error control, as `hdi cycle --rtol` and Python's `rtol=` apply it. The ratio
    /// is taken on the decimals the tolerances are written as where it is one
    /// ([`units::proportional`](crate::units::proportional)): atol `1e-14` at rtol `1e-6` scales
    /// to `7e-15` at `7e-7`, not `6.999999999999999e-15`.
    ///
    /// ```
    /// use hdi_tribology::{analysis::CycleOptions, scene::Scene};
    /// let s = CycleOptions::from_scene(&Scene::paper())?.solver;
    /// assert_eq!((s.rtol, s.atol_displacement), (1e-6, 1e-14));
    /// assert_eq!(s.with_rtol(7e-7).atol_displacement, 7e-15); // 1e-14 * (7e-7 / 1e-6) is 6.999999999999999e-15
    /// let tight = s.with_rtol(s.rtol / 10.0);
    /// assert!((tight.atol_displacement - s.atol_displacement / 10.0).abs() < 1e-30);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn with_rtol(self, rtol: f64) -> Self {
        SolverSettings {
            atol_displacement: crate::units::proportional(self.atol_displacement, rtol, self.rtol),
            rtol,
            ..self
        }
    }
}

/// Options of a cycle simulation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CycleOptions {
    /// Contact detector.
    pub detector: Detector,
    /// Integration settings.
    pub solver: SolverSettings,
    /// Keep the time series of forces and spacing (costs memory and some time).
    pub keep_series: bool,
    /// With [`keep_series`](CycleOptions::keep_series), the series holds only the step times
    /// within `[start, end]` (s, both included); `None` (the default): every step. Each value
    /// is the one the whole series has at that time, to the bit; the times outside cost no
    /// evaluation of the forces, the detector or the heater. For callers that read one stretch,
    /// such as the mechanism maps' bounce flag over the hold (the series of the whole run took
    /// about a sixth of a few-peak cycle's instructions).
    ///
    /// ```
    /// use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, HeaterProgramme};
    /// use hdi_tribology::{model::SliderModel, scene::Scene};
    /// let scene = Scene::paper();
    /// let model = SliderModel::from_scene(&scene)?;
    /// let programme = HeaterProgramme::fixed_from_scene(&scene)?;
    /// let mut opts = CycleOptions::from_scene(&scene)?;
    /// opts.keep_series = true;
    /// let whole = simulate_cycle(&model, &programme, &opts)?.series.unwrap();
    /// opts.series_window = Some((4e-3, 6e-3));
    /// let part = simulate_cycle(&model, &programme, &opts)?.series.unwrap();
    /// let first = whole.t.iter().position(|&t| t >= 4e-3).unwrap();
    /// assert!(part.t.iter().all(|&t| (4e-3..=6e-3).contains(&t)));
    /// assert_eq!(part.contact[..], whole.contact[first..first + part.t.len()]);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub series_window: Option<(f64, f64)>,
    /// Stop a cycle whose contact bounces deep in the disk at a pace that would use up the step
    /// budget. At an accepted step whose bulge gap is below the low end of the force tables
    /// ([`InterfaceForces::table_range`](crate::force::InterfaceForces::table_range)), the cycle
    /// ends with [`CycleError::LeftTheTables`] when it has spent
    /// its steps at more than twice the even pace of [`max_steps`](SolverSettings::max_steps),
    /// either from the start without the step pace's start allowance, or since its first step
    /// below the tables after an allowance of 1 % of `max_steps`. Below the tables the few-peak
    /// or Greenwood–Williamson contact is far outside its light-contact validity, and every force
    /// is an exact quadrature (a step there costs up to ten times one inside).
    /// A cycle that dips below the tables at a steady pace (a hard contact at 1 V AC does) runs
    /// on as before. Off by default ([`CycleOptions::from_scene`]).
    ///
    /// ```
    /// use hdi_tribology::analysis::cycle::{simulate_cycle, CycleError, CycleOptions, HeaterProgramme};
    /// use hdi_tribology::{model::SliderModel, scene::Scene, Error};
    /// let scene = Scene::from_path(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/paper_bulge.toml"))?;
    /// // A 0.1 ns interface lag at 1 V AC: the few-peak contact bounces deep into the disk.
    /// let model = SliderModel::from_scene(&scene)?
    ///     .with_ac_amplitude(1.0)
    ///     .with_interface_lag(1e-10);
    /// let programme = HeaterProgramme::fixed_from_scene(&scene)?;
    /// let mut opts = CycleOptions::from_scene(&scene)?;
    /// opts.solver.max_steps = 300_000;
    /// opts.stop_outside_tables = true;
    /// match simulate_cycle(&model, &programme, &opts) {
    ///     Err(Error::Analysis(e)) => {
    ///         let Some(CycleError::LeftTheTables { bulge_gap_nm, table_low_nm, .. }) = e.downcast_ref() else {
    ///             panic!("{e}")
    ///         };
    ///         assert!(bulge_gap_nm < table_low_nm);
    ///     }
    ///     other => panic!("{other:?}"),
    /// }
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub stop_outside_tables: bool,
    /// With an interface lag, integrate the lag's work and the damping's over the cycle
    /// ([`CycleResult::lag_energy`]); it costs about a tenth of a lagged cycle's time (the
    /// paper scene at 20 ns and 0.6 V: 1.11× the instructions). On by default
    /// ([`CycleOptions::from_scene`]); without a lag it costs nothing either way.
    pub energy_audit: bool,
    /// End the run at the step where the detector sees take-off, instead of at the programme's
    /// end. Touchdown and take-off are those of the whole run to the bit: both are first
    /// crossings, found on the same steps. What the run covers ends there: the statistics, the
    /// series, the energy audit and the mean temperature rise (over the time run,
    /// [`CycleResult::duration`]), and a failure after the take-off (the step pace, the
    /// slider reaching the disk) is not met. For callers that need the two powers alone, such as
    /// the checks of a map (a 12 × 12 `freq` or `lag_rigid` map of docs/analyses.md spends about
    /// a tenth of its steps after the take-off). Off by default ([`CycleOptions::from_scene`]).
    ///
    /// ```
    /// use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, HeaterProgramme};
    /// use hdi_tribology::{model::SliderModel, scene::Scene};
    /// let scene = Scene::paper();
    /// let model = SliderModel::from_scene(&scene)?;
    /// let programme = HeaterProgramme::fixed_from_scene(&scene)?;
    /// let mut opts = CycleOptions::from_scene(&scene)?;
    /// let whole = simulate_cycle(&model, &programme, &opts)?;
    /// opts.stop_at_takeoff = true;
    /// let short = simulate_cycle(&model, &programme, &opts)?;
    /// assert_eq!(short.touchdown, whole.touchdown);
    /// assert_eq!(short.takeoff, whole.takeoff);
    /// assert!(short.stats.accepted < whole.stats.accepted);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub stop_at_takeoff: bool,
    /// Integrate the flash temperature over the run for [`CycleResult::mean_temperature_rise`].
    /// Off, the state leaves out that integral ([`crate::sim::ProblemBuilder::without_heat`]):
    /// one state fewer, and no flash temperature or its slope in the right-hand side and the
    /// Jacobian (about 13 % fewer instructions on the few-peak maps' cycles), and
    /// `mean_temperature_rise` is NaN. The error norm then runs over one state fewer, so
    /// touchdown and take-off move within the tolerance, not to the bit. For callers that need
    /// the powers alone, such as the mechanism maps. On by default
    /// ([`CycleOptions::from_scene`]).
    ///
    /// ```
    /// use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, HeaterProgramme};
    /// use hdi_tribology::{model::SliderModel, scene::Scene};
    /// let scene = Scene::paper();
    /// let model = SliderModel::from_scene(&scene)?;
    /// let programme = HeaterProgramme::fixed_from_scene(&scene)?;
    /// let mut opts = CycleOptions::from_scene(&scene)?;
    /// let with = simulate_cycle(&model, &programme, &opts)?;
    /// opts.mean_temperature = false;
    /// let without = simulate_cycle(&model, &programme, &opts)?;
    /// assert!(without.mean_temperature_rise.is_nan() && with.mean_temperature_rise > 0.0);
    /// let (a, b) = (with.takeoff.unwrap().power, without.takeoff.unwrap().power);
    /// assert!((a - b).abs() < 1e-7, "{a} W against {b} W");
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub mean_temperature: bool,
}

impl CycleOptions {
    fn validate(&self) -> Result<()> {
        check_positive(
            "detector.contact_threshold",
            self.detector.contact_threshold,
        )?;
        check_positive("detector.window", self.detector.window)?;
        check_positive("solver.rtol", self.solver.rtol)?;
        check_positive("solver.atol_displacement", self.solver.atol_displacement)?;
        if let Some(h) = self.solver.max_step {
            check_positive("solver.max_step", h)?;
        }
        if self.solver.max_steps == 0 {
            return Err(Error::invalid("solver.max_steps", "must be at least 1"));
        }
        if let Some((start, end)) = self.series_window {
            if !(start.is_finite() && end.is_finite() && start <= end) {
                return Err(Error::invalid(
                    "series_window",
                    format!(
                        "must be a finite (start, end) with start <= end, got ({start} s, {end} s)"
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// A detected touchdown or take-off.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Detection {
    /// Time (s).
    #[serde(rename = "time_s")]
    pub time: f64,
    /// Programme power at that time (W).
    #[serde(rename = "power_w")]
    pub power: f64,
}

impl Detection {
    /// The programme power in milliwatts.
    ///
    /// ```
    /// let d = hdi_tribology::analysis::Detection { time: 1e-3, power: 0.0743 };
    /// assert!((d.power_mw() - 74.3).abs() < 1e-12);
    /// ```
    pub fn power_mw(&self) -> f64 {
        crate::units::to_mw(self.power)
    }
}

/// Time series of one cycle, at every accepted step (within
/// [`CycleOptions::series_window`] where one is set).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct TimeSeries {
    /// Time (s).
    pub t: Vec<f64>,
    /// Programme heater power (W).
    pub power: Vec<f64>,
    /// Bulge gap `d` (m).
    pub d: Vec<f64>,
    /// Air-bearing force (N).
    pub air_bearing: Vec<f64>,
    /// Intermolecular force (N).
    pub intermolecular: Vec<f64>,
    /// Electrostatic force (N).
    pub electrostatic: Vec<f64>,
    /// Contact force (N).
    pub contact: Vec<f64>,
    /// Interface plus air-bearing force (N).
    pub total: Vec<f64>,
    /// Flash temperature rise (K).
    pub temperature_rise: Vec<f64>,
    /// Running mean of the contact force over the detector window (N); NaN before `T_w` (an
    /// empty field in the CSV).
    pub indicator: Vec<f64>,
    /// The states of the model's stateful terms ([`crate::force::StatefulTerm`]), one series
    /// per state in the order of the terms; empty without such terms (not in the CSV).
    pub term_states: Vec<Vec<f64>>,
}

impl TimeSeries {
    /// Writes the series as CSV, one row per step, SI units in the column names; `indicator_n`
    /// is an empty field (a missing value) before the detector's window has filled.
    ///
    /// ```no_run
    /// # fn f(r: &hdi_tribology::analysis::CycleResult) -> hdi_tribology::Result<()> {
    /// if let Some(s) = &r.series {
    ///     s.write_csv(std::path::Path::new("cycle.csv"))?;
    /// }
    /// # Ok(()) }
    /// ```
    pub fn write_csv(&self, path: &std::path::Path) -> Result<()> {
        crate::report::write_csv(
            path,
            &[
                "t_s",
                "power_w",
                "d_m",
                "air_bearing_n",
                "intermolecular_n",
                "electrostatic_n",
                "contact_n",
                "total_n",
                "temperature_rise_k",
                "indicator_n",
            ],
            &[
                &self.t,
                &self.power,
                &self.d,
                &self.air_bearing,
                &self.intermolecular,
                &self.electrostatic,
                &self.contact,
                &self.total,
                &self.temperature_rise,
                &self.indicator,
            ],
        )
    }
}

/// The outcome of one cycle.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CycleResult {
    /// AC amplitude of the cycle (V).
    #[serde(rename = "v_ac_v")]
    pub v_ac: f64,
    /// Touchdown, if detected.
    pub touchdown: Option<Detection>,
    /// Take-off, if detected.
    pub takeoff: Option<Detection>,
    /// `P(t_TD) − P(t_TO)` (W), when both were detected.
    #[serde(rename = "hysteresis_w")]
    pub hysteresis: Option<f64>,
    /// Time mean of the flash temperature over the whole programme (K); NaN where
    /// [`CycleOptions::mean_temperature`] left it out.
    #[serde(rename = "mean_temperature_rise_k")]
    pub mean_temperature_rise: f64,
    /// Length of the programme (s), or of the run up to the take-off where
    /// [`CycleOptions::stop_at_takeoff`] ended it there.
    #[serde(rename = "duration_s")]
    pub duration: f64,
    /// The programme actually run (for the triggered protocol: as fixed by the detection).
    #[serde(skip)]
    pub programme: Programme,
    /// The method the cycle ran with: as asked, except that `Auto` on a slider whose fastest
    /// rate no explicit step can follow runs its stiff method from the start
    /// ([`Method::for_problem`]): Rodas5P at `rtol` ≥ 1e-6, Radau5 below. A check that holds
    /// the method while it tightens the tolerance reads it here.
    ///
    /// ```
    /// use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, HeaterProgramme};
    /// use hdi_tribology::{model::SliderModel, ode::Method, scene::Scene};
    /// let scene = Scene::paper();
    /// let programme = HeaterProgramme::fixed_from_scene(&scene)?;
    /// let mut opts = CycleOptions::from_scene(&scene)?;
    /// opts.solver.method = Method::Auto;
    /// let rigid = SliderModel::from_scene(&scene)?;
    /// assert_eq!(simulate_cycle(&rigid, &programme, &opts)?.method, Method::Auto);
    /// // A 10 ns interface lag: 1e8 s⁻¹, which no explicit step follows over the programme.
    /// let lagged = rigid.with_interface_lag(1e-8);
    /// assert_eq!(simulate_cycle(&lagged, &programme, &opts)?.method, Method::Rodas5P);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub method: Method,
    /// Solver statistics of the cycle's integration.
    pub stats: Stats,
    /// Wall-clock time of the simulation (s).
    pub wall_seconds: f64,
    /// Time series, when asked for (not serialized: it is the CSV's, [`TimeSeries::write_csv`]).
    #[serde(skip)]
    pub series: Option<TimeSeries>,
    /// The energy audit of the interface lag over the cycle, with one and with
    /// [`CycleOptions::energy_audit`] ([`super::energy::LagEnergy`]); left out of the JSON
    /// otherwise.
    #[serde(flatten)]
    pub lag_energy: Option<LagEnergy>,
}

impl CycleResult {
    /// The hysteresis `P_TD − P_TO` in milliwatts, when both were detected.
    pub fn hysteresis_mw(&self) -> Option<f64> {
        self.hysteresis.map(crate::units::to_mw)
    }

    /// The hysteresis for printing: `6.417` (mW, three decimals) when both transitions were
    /// detected, else which one was not.
    ///
    /// ```
    /// # use hdi_tribology::analysis::CycleResult;
    /// # fn f(r: &CycleResult) { println!("ΔP = {} mW", r.hysteresis_text()); }
    /// ```
    pub fn hysteresis_text(&self) -> String {
        match (self.touchdown, self.takeoff, self.hysteresis_mw()) {
            (_, _, Some(h)) => format!("{h:.3}"),
            (None, _, _) => "n/a (no touchdown detected)".into(),
            (Some(_), _, None) => "n/a (no take-off detected)".into(),
        }
    }
}

/// Simulates one touchdown/take-off cycle.
///
/// ```no_run
/// use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, HeaterProgramme};
/// use hdi_tribology::{model::SliderModel, scene::Scene};
/// let scene = Scene::paper();
/// let model = SliderModel::from_scene(&scene)?;
/// let programme = HeaterProgramme::fixed_from_scene(&scene)?;
/// let r = simulate_cycle(&model, &programme, &CycleOptions::from_scene(&scene)?)?;
/// println!("ΔP = {:?} W, mean ΔT = {} K", r.hysteresis, r.mean_temperature_rise);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn simulate_cycle(
    model: &SliderModel,
    programme: &HeaterProgramme,
    opts: &CycleOptions,
) -> Result<CycleResult> {
    opts.validate()?;
    super::equilibrium::check_heater(model)?;
    let clock = Instant::now();
    let start = Start::of(model, programme)?;
    let t0 = start.programme.start_time();
    let eq = flying_equilibrium(
        model,
        start.programme.power(t0),
        model.voltage().squared(t0),
        &ScanGrid::default(),
    )?;
    // The fixed programme's knots are kinks of the right-hand side; the triggered programme's
    // only interior knot, its turning point, is where the programme is replaced (a restart).
    let kinks = match start.triggered {
        None => start.programme.knots().iter().map(|k| k.0).collect(),
        Some(_) => Vec::new(),
    };
    let s = opts.solver;
    let end = start.programme.end_time();
    // The integrals only need the accuracy the detector and the mean temperature use.
    let mut builder = Problem::builder(model, model.inputs(start.programme.clone()), true);
    if !opts.mean_temperature {
        builder = builder.without_heat();
    }
    let problem = builder
        .rtol(s.rtol)
        .tolerances(
            s.atol_displacement,
            s.rtol * opts.detector.contact_threshold * opts.detector.window,
            s.rtol * opts.detector.window,
        )
        .max_step(s.max_step)
        .max_steps(s.max_steps)
        .stops(kinks)
        .dense()
        .method_for_span(s.method, end - t0)
        .build()?;
    // On a state vector sized at compile time: a step allocates nothing, and a scene pays only
    // for the coordinates, lags and term states it uses.
    problem.dispatch(
        Stage::CYCLE,
        CycleRun {
            model,
            opts,
            start,
            rest: eq.rest(),
            clock,
        },
    )
}

/// The programme a cycle starts on: the fixed one, or the triggered protocol's ramp (whose
/// turning point the detector fixes), with the triggered protocol's settings.
struct Start {
    programme: Programme,
    /// `(start power, ramp rate, overshoot)` of the triggered protocol.
    triggered: Option<(f64, f64, f64)>,
}

impl Start {
    fn of(model: &SliderModel, programme: &HeaterProgramme) -> Result<Self> {
        Ok(match programme {
            HeaterProgramme::Fixed(p) => Start {
                programme: p.clone(),
                triggered: None,
            },
            &HeaterProgramme::Triggered {
                start_power,
                ramp_rate,
                overshoot,
            } => {
                check_positive("programme.ramp_rate", ramp_rate)?;
                check_positive("programme.overshoot", overshoot)?;
                crate::error::check_non_negative("programme.start_power", start_power)?;
                // Search up to the power whose protrusion is twice the nominal clearance.
                let span = model.power_for(2.0 * model.nominal_clearance());
                // Bound the search, in overshoots, so that a heater too weak to ever reach
                // touchdown fails at once instead of running for ever.
                let segments = span / overshoot;
                if segments.is_nan() || segments > MAX_TRIGGERED_SEGMENTS {
                    return Err(CycleError::TooManySegments {
                        span_mw: crate::units::to_mw(span),
                        overshoot_mw: crate::units::to_mw(overshoot),
                        segments,
                        max_segments: MAX_TRIGGERED_SEGMENTS,
                    }
                    .into());
                }
                let ramp = Programme::new(vec![
                    (0.0, start_power),
                    (span / ramp_rate, start_power + span),
                ])?;
                Start {
                    programme: ramp,
                    triggered: Some((start_power, ramp_rate, overshoot)),
                }
            }
        })
    }
}

/// The cycle's integration on a [`Problem`], at the state size of its layout.
struct CycleRun<'m> {
    model: &'m SliderModel,
    opts: &'m CycleOptions,
    start: Start,
    rest: crate::model::Rest,
    clock: Instant,
}

impl SizedRun for CycleRun<'_> {
    type Output = CycleResult;
    fn run<D: DimName>(self, problem: Problem) -> Result<CycleResult>
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        run::<D>(self, problem)
    }
}

/// What the cycle keeps of its one integration: every step time, the interpolant of the contact
/// impulse `Q` over each step (the detector reads `Q` at `t` and `t − T_w`), and the states when a
/// time series is asked for.
struct Record<D: DimName>
where
    DefaultAllocator: Allocator<D>,
{
    times: Vec<f64>,
    /// Index of `Q` in the state.
    q: usize,
    /// Per step: start, length, and the offset of its monomial coefficients of `Q` in `coeffs`.
    steps: Vec<(f64, f64, usize)>,
    coeffs: Vec<f64>,
    /// End of the covered range (the last step may have been cut).
    end: f64,
    /// `Q` there: the state's, as the next step's interpolant would start from it.
    end_value: f64,
    states: Option<Vec<OVector<f64, D>>>,
}

impl<D: DimName> Record<D>
where
    DefaultAllocator: Allocator<D>,
{
    fn new(t0: f64, y0: &OVector<f64, D>, q: usize, keep_states: bool) -> Self {
        Record {
            times: vec![t0],
            q,
            steps: Vec::new(),
            coeffs: Vec::new(),
            end: t0,
            end_value: y0[q],
            states: keep_states.then(|| vec![y0.clone()]),
        }
    }

    /// Keeps the `Q` part of the last step's interpolant, valid up to `t_end`, where `Q` is
    /// `q_end`. (`coeffs[m·n + i]` is component `i` of the coefficient of `θ^m` on
    /// `[t0, t0 + h]`.)
    fn push_step(&mut self, t0: f64, h: f64, n: usize, coeffs: &[f64], t_end: f64, q_end: f64) {
        self.steps.push((t0, h, self.coeffs.len()));
        self.coeffs
            .extend(coeffs.iter().skip(self.q).step_by(n.max(1)));
        self.end = t_end;
        self.end_value = q_end;
    }

    /// `Q(t)` on the interpolants (`None` outside the integrated range), with the search for
    /// the step that holds `t` starting at step `from`, which is then set to it: a cursor for
    /// times read in increasing order (`from` must not be past that step; 0 always works).
    /// A step time is read on the step that starts there, whose interpolant starts from the
    /// state; the end of the range, where no step starts, from the state there too. So a
    /// record cut short at a step reads every time it covers as the whole record does.
    fn impulse_after(&self, t: f64, from: &mut usize) -> Option<f64> {
        let first = self.steps.first()?.0;
        if !(t >= first && t <= self.end) {
            return None;
        }
        // The last step that starts at or before `t`: a few steps on from `from` by a walk,
        // beyond them by bisection.
        let rest = &self.steps[*from..];
        let walked = rest.iter().take(4).skip(1).take_while(|s| s.0 <= t).count();
        let k = *from
            + if walked < 3 {
                walked
            } else {
                rest.partition_point(|s| s.0 <= t).saturating_sub(1)
            };
        *from = k;
        if t == self.end && k + 1 == self.steps.len() {
            return Some(self.end_value);
        }
        let (t0, h, lo) = self.steps[k];
        let hi = self.steps.get(k + 1).map_or(self.coeffs.len(), |s| s.2);
        let theta = if h != 0.0 { (t - t0) / h } else { 0.0 };
        Some(
            self.coeffs[lo..hi]
                .iter()
                .rev()
                .fold(0.0, |acc, &c| acc * theta + c),
        )
    }

    /// Drops every step time after `t` (inside the last step).
    fn truncate(&mut self, t: f64) {
        if let Some(q) = self.impulse_after(t, &mut 0) {
            self.end_value = q;
        }
        self.end = t;
        let keep = self.times.partition_point(|&s| s <= t);
        self.times.truncate(keep);
        if let Some(st) = self.states.as_mut() {
            st.truncate(keep);
        }
    }
}

struct Detecting<'a, D: DimName>
where
    DefaultAllocator: Allocator<D>,
{
    rec: &'a Record<D>,
    detector: Detector,
}

impl<D: DimName> Detecting<'_, D>
where
    DefaultAllocator: Allocator<D>,
{
    /// Running mean of the contact force at `t ≥ T_w`.
    fn indicator(&self, t: f64) -> f64 {
        self.indicator_after(t, &mut [0, 0])
    }

    /// [`Detecting::indicator`] with cursors for `Q(t)` and `Q(t − T_w)` (see
    /// [`Record::impulse_after`]).
    fn indicator_after(&self, t: f64, from: &mut [usize; 2]) -> f64 {
        let w = self.detector.window;
        let [now, before] = from;
        match (
            self.rec.impulse_after(t, now),
            self.rec.impulse_after(t - w, before),
        ) {
            (Some(a), Some(b)) => (a - b) / w,
            _ => f64::NAN,
        }
    }

    /// First time in `[a, b]` where the indicator crosses `F_th` upward (`rising`) or downward.
    ///
    /// The indicator is smooth between step times and step times shifted by `T_w`; it is sampled
    /// there and the crossing is refined by root finding on the dense output.
    fn first_crossing(&self, a: f64, b: f64, rising: bool) -> Result<Option<f64>> {
        self.scan(&mut Scan::new(a, rising), b)
    }

    /// Reads the samples of `scan` up to `b` in increasing order, from where it stopped: the
    /// step times and the step times shifted by `T_w` strictly between its start and `b`,
    /// without repeats, then `b`. The first sample where the indicator is at or above `F_th`
    /// (`rising`), or below it, brackets the crossing with the sample before. Reading up to
    /// `b₁` and then on to `b₂` reads the samples one reading up to `b₂` does when `b₁` is a
    /// step time (a sample itself), so a scan that goes on step after step finds the crossing
    /// a search over the whole record finds.
    fn scan(&self, scan: &mut Scan, b: f64) -> Result<Option<f64>> {
        let w = self.detector.window;
        let th = self.detector.contact_threshold;
        let times = &self.rec.times;
        let rising = scan.rising;
        // The indicator is read at increasing times: its look-ups go on from the last.
        let hit = |x: f64, cursors: &mut [usize; 2]| {
            let v = self.indicator_after(x, cursors);
            if rising {
                v >= th
            } else {
                v < th
            }
        };
        let crossing = |prev: f64, t: f64| brent(|x| self.indicator(x) - th, prev, t, 1e-12 * w);
        if !scan.started {
            let a = scan.last.max(w);
            if a > b {
                return Ok(None);
            }
            scan.started = true;
            scan.last = a;
            scan.own = times.partition_point(|&t| t <= a);
            scan.shifted = times.partition_point(|&t| t <= a - w);
            if hit(a, &mut scan.cursors) {
                return Ok(Some(a));
            }
        }
        loop {
            let own = times.get(scan.own).copied().filter(|&t| t < b);
            let shifted = times.get(scan.shifted).map(|&t| t + w).filter(|&t| t < b);
            let t = match (own, shifted) {
                (Some(x), Some(y)) if x > y => {
                    scan.shifted += 1;
                    y
                }
                (Some(x), _) => {
                    scan.own += 1;
                    x
                }
                (None, Some(y)) => {
                    scan.shifted += 1;
                    y
                }
                (None, None) => break,
            };
            if t <= scan.last {
                continue;
            }
            if hit(t, &mut scan.cursors) {
                return crossing(scan.last, t).map(Some);
            }
            scan.last = t;
        }
        if b > scan.last {
            if hit(b, &mut scan.cursors) {
                return crossing(scan.last, b).map(Some);
            }
            scan.last = b;
        }
        Ok(None)
    }
}

/// Where a search of the detector's indicator stands ([`Detecting::scan`]).
struct Scan {
    /// Upward crossing (touchdown) or downward (take-off).
    rising: bool,
    /// Whether the first sample, the start, has been read.
    started: bool,
    /// The start, then the last sample read.
    last: f64,
    /// The next step time to read, and the next to read shifted by `T_w`.
    own: usize,
    shifted: usize,
    /// The look-ups' cursors (see [`Record::impulse_after`]).
    cursors: [usize; 2],
}

impl Scan {
    /// A search from `a` on.
    fn new(a: f64, rising: bool) -> Self {
        Scan {
            rising,
            started: false,
            last: a,
            own: 0,
            shifted: 0,
            cursors: [0, 0],
        }
    }
}

/// The recorder of a cycle's run: every accepted step goes into the [`Record`]; with a watch,
/// the run stops at the step where the detector first sees what the watch waits for.
struct Recorder<D: DimName>
where
    DefaultAllocator: Allocator<D>,
{
    rec: Record<D>,
    watch: Option<Watch>,
}

/// The detector watched step by step: for touchdown (the triggered programme's ramp up), or for
/// take-off from a time on ([`CycleOptions::stop_at_takeoff`]).
struct Watch {
    detector: Detector,
    /// The search under way.
    scan: Scan,
    /// After the touchdown watched for, watch on for the take-off from this time on (or from
    /// the touchdown, if later), as the cycle's search does.
    then_takeoff_from: Option<f64>,
    /// The crossing's time, once seen.
    found: Option<f64>,
    /// The touchdown, where the watch went on to the take-off after it.
    touchdown: Option<f64>,
}

impl Watch {
    /// A watch for touchdown from `t0` on.
    fn touchdown(detector: Detector, t0: f64) -> Self {
        Watch {
            detector,
            scan: Scan::new(t0, true),
            then_takeoff_from: None,
            found: None,
            touchdown: None,
        }
    }

    /// A watch for take-off from `from` on.
    fn takeoff(detector: Detector, from: f64) -> Self {
        Watch {
            scan: Scan::new(from, false),
            ..Watch::touchdown(detector, from)
        }
    }

    /// A watch for touchdown from `t0` on, then for take-off from `from` or the touchdown,
    /// whichever is later.
    fn cycle(detector: Detector, t0: f64, from: f64) -> Self {
        Watch {
            then_takeoff_from: Some(from),
            ..Watch::touchdown(detector, t0)
        }
    }

    /// Whether the watch has seen the take-off.
    fn saw_takeoff(&self) -> bool {
        !self.scan.rising && self.found.is_some()
    }
}

impl<D: DimName> Observer for Recorder<D>
where
    DefaultAllocator: Allocator<D>,
{
    fn accepted(&mut self, step: &StepView<'_>) -> Result<Flow> {
        let p = step.last_step;
        let t = step.t;
        let q = self.rec.q;
        self.rec
            .push_step(p.t0, p.h, p.n, p.coeffs, t, step.state[q]);
        self.rec.times.push(t);
        if let Some(st) = self.rec.states.as_mut() {
            st.push(OVector::<f64, D>::from_column_slice(step.state));
        }
        let Some(w) = self.watch.as_mut() else {
            return Ok(Flow::Continue);
        };
        let detecting = Detecting {
            rec: &self.rec,
            detector: w.detector,
        };
        let found = loop {
            let found = detecting.scan(&mut w.scan, t)?;
            match (found, w.then_takeoff_from.take()) {
                // Touchdown seen: on to the take-off, in this step too.
                (Some(td), Some(from)) => {
                    w.touchdown = Some(td);
                    w.scan = Scan::new(from.max(td), false);
                }
                (found, then) => {
                    w.then_takeoff_from = then;
                    break found;
                }
            }
        };
        w.found = found;
        Ok(if found.is_some() {
            Flow::Stop
        } else {
            Flow::Continue
        })
    }
}

/// The cycle's guards: the step pace, the pad-contact guard and (when asked for) a bounce below
/// the force tables end the cycle with an error.
struct Guards<'m> {
    model: &'m SliderModel,
    opts: &'m CycleOptions,
    /// Start and length of the programme, for the step pace.
    span: (f64, f64),
    /// Time and steps taken at the first accepted step below the force tables.
    below_since: Option<(f64, usize)>,
}

impl Observer for Guards<'_> {
    fn accepted(&mut self, step: &StepView<'_>) -> Result<Flow> {
        let (model, opts) = (self.model, self.opts);
        let st = step.stats;
        let (t0, span) = self.span;
        let max = opts.solver.max_steps as f64;
        let t = step.t;
        let steps = st.accepted + st.rejected;
        // More than twice the even pace of `max_steps` since `from`, after `allowance` steps.
        let too_fast = |n: usize, from: f64, allowance: f64| {
            n as f64 > max * (allowance + 2.0 * (t - from) / span)
        };
        if too_fast(steps, t0, STEP_PACE_ALLOWANCE) && t < t0 + span {
            return Err(out_of_step_budget(model, opts, t, st, span));
        }
        if let StepStatus::Terminated(_) = step.status {
            return Err(left_the_model(model, step.system, t, step.state));
        }
        if opts.stop_outside_tables {
            let d = step.system.gaps(t, step.state).bulge;
            let low = model.forces().table_range().0;
            if d < low {
                let (t1, n1) = *self.below_since.get_or_insert((t, steps));
                // From the start without the step pace's start allowance, or afresh from the
                // first step below the tables with a small one.
                if too_fast(steps, t0, 0.0) || too_fast(steps - n1, t1, BELOW_TABLES_ALLOWANCE) {
                    return Err(CycleError::LeftTheTables {
                        t_ms: t * 1e3,
                        bulge_gap_nm: crate::units::to_nm(d),
                        table_low_nm: crate::units::to_nm(low),
                        steps,
                        first_below_ms: t1 * 1e3,
                        steps_below: steps - n1,
                        span_ms: span * 1e3,
                        max_steps: opts.solver.max_steps,
                    }
                    .into());
                }
            }
        }
        Ok(Flow::Continue)
    }
}

fn run<D: DimName>(job: CycleRun<'_>, problem: Problem) -> Result<CycleResult>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let CycleRun {
        model,
        opts,
        start,
        rest,
        clock,
    } = job;
    let det = opts.detector;
    let Start {
        programme: initial_programme,
        triggered,
    } = start;
    let t0 = initial_programme.start_time();
    let layout = problem.system().layout();
    let q = layout
        .contact_impulse
        .ok_or_else(|| internal("no impulse state"))?;
    let heat = layout.heat;
    let y0: OVector<f64, D> = problem.initial_state(D::name(), &rest);
    // Stop where the lumped model ends: the pad gap h0 + y reaching zero puts the slider body
    // into the disk (no pad contact is modelled; a power-law bearing is singular there).
    let body = Arc::clone(problem.system().model_arc());
    let guard = ode::Event::new(move |_t, s: &OVector<f64, D>| body.pad_gap(s[0], 0.0))
        .direction(ode::Direction::Falling)
        .terminal(true);
    let end = initial_programme.end_time();
    let method = problem.method();
    let audit = Audit::of(problem.system(), opts.energy_audit);
    let it = problem
        .integrator(t0, y0.clone(), end)
        .map_err(|e| explain_ode_error(model, opts, e))?
        .events([guard]);
    let mut it = it;
    let mut recorder = Recorder {
        rec: Record::new(t0, &y0, q, opts.keep_series),
        watch: None,
    };
    let guards = Guards {
        model,
        opts,
        span: (t0, end - t0),
        below_since: None,
    };
    // The guards and the energy audit see every step after the recorder.
    let mut checks = (guards, audit);
    let ode_err = |e| explain_ode_error(model, opts, e);

    let final_programme;
    let search_from;
    match triggered {
        None => {
            final_programme = initial_programme.clone();
            search_from = final_programme.end_of_hold();
            if opts.stop_at_takeoff {
                recorder.watch = Some(Watch::cycle(det, t0, search_from));
            }
            sim::run(&mut it, None, &mut (&mut recorder, &mut checks), ode_err)?;
        }
        Some((start_power, rate, overshoot)) => {
            // Ramp up, watching the detector step by step.
            let chunk = overshoot / rate;
            recorder.watch = Some(Watch::touchdown(det, t0));
            sim::run(&mut it, None, &mut (&mut recorder, &mut checks), ode_err)?;
            let Some(t_td) = recorder.watch.take().and_then(|w| w.found) else {
                return Err(CycleError::NoTriggeredTouchdown {
                    max_power_mw: crate::units::to_mw(initial_programme.power(end)),
                }
                .into());
            };
            // The programme turns `overshoot` after the detection: go on up the ramp to the
            // turning point (or step back to it from a longer step), then ramp down.
            let t_peak = t_td + chunk;
            let p_peak = start_power + rate * (t_peak - t0);
            let t_end = t_peak + (p_peak - start_power) / rate;
            final_programme = Programme::new(vec![
                (t0, start_power),
                (t_peak, p_peak),
                (t_end, start_power),
            ])?;
            if it.t() < t_peak {
                if t_peak < it.tf() {
                    it.set_tf(t_peak).map_err(ode_err)?;
                }
                sim::run(&mut it, None, &mut (&mut recorder, &mut checks), ode_err)?;
            } else if it.t() > t_peak {
                let y = it.interpolate(t_peak).map_err(ode_err)?;
                checks.1.cut(it.last_step(), it.system(), t_peak);
                let rec = &mut recorder.rec;
                rec.truncate(t_peak);
                if rec.times.last().is_some_and(|&t| t < t_peak) {
                    rec.times.push(t_peak);
                    if let Some(st) = rec.states.as_mut() {
                        st.push(y.clone());
                    }
                }
                it.reinit(t_peak, y).map_err(ode_err)?;
            }
            it.system_mut()
                .set_inputs(model.inputs(final_programme.clone()));
            it.set_tf(t_end).map_err(ode_err)?;
            search_from = t_peak;
            if opts.stop_at_takeoff {
                recorder.watch = Some(Watch::takeoff(det, search_from));
            }
            sim::run(&mut it, None, &mut (&mut recorder, &mut checks), ode_err)?;
        }
    }
    // A take-off watch that saw the take-off ended the run there; what it found of the touchdown
    // and the take-off is what the search below would find.
    let watched = recorder
        .watch
        .as_ref()
        .filter(|w| w.saw_takeoff())
        .map(|w| (w.touchdown, w.found));

    let detecting = Detecting {
        rec: &recorder.rec,
        detector: det,
    };
    let end = if watched.is_some() {
        it.t()
    } else {
        final_programme.end_time()
    };
    let (td, to) = match watched {
        Some((Some(td), to)) => (Some(td), to),
        _ => {
            let td = detecting.first_crossing(t0, end, true)?;
            let to = match td {
                Some(t) => detecting.first_crossing(search_from.max(t), end, false)?,
                None => None,
            };
            (td, to)
        }
    };
    let as_detection = |t: f64| Detection {
        time: t,
        power: final_programme.power(t),
    };
    let touchdown = td.map(as_detection);
    let takeoff = to.map(as_detection);
    let hysteresis = match (touchdown, takeoff) {
        (Some(a), Some(b)) => Some(a.power - b.power),
        _ => None,
    };
    let duration = end - t0;
    let mean_temperature_rise = heat.map_or(f64::NAN, |h| it.state()[h] / duration);
    let series = recorder.rec.states.as_ref().map(|states| {
        series_of(
            it.system(),
            &recorder.rec.times,
            states,
            &detecting,
            opts.series_window,
        )
    });
    Ok(CycleResult {
        v_ac: model.voltage().ac_amplitude,
        touchdown,
        takeoff,
        hysteresis,
        mean_temperature_rise,
        duration,
        programme: final_programme,
        method,
        stats: it.stats(),
        wall_seconds: clock.elapsed().as_secs_f64(),
        series,
        lag_energy: checks.1.energy(),
    })
}

/// The error for a trajectory that left the lumped model (the pad gap reached zero), with the
/// likely cause when an interface lag makes the contact branch self-excited.
fn left_the_model(model: &SliderModel, sys: &SliderSystem, t: f64, s: &[f64]) -> Error {
    let g = sys.gaps(t, s);
    let mut self_excited = None;
    if model.interface_lag() > 0.0 {
        let k_contact = -model.forces().contact(g).d_bulge;
        let c = model.bearing().damping(s[0]);
        if k_contact > 0.0 && model.interface_lag() > c / k_contact {
            self_excited = Some(SelfExcitation {
                interface_lag_ns: model.interface_lag() * 1e9,
                limit_ns: c / k_contact * 1e9,
            });
        }
    }
    CycleError::LeftTheModel {
        t_ms: t * 1e3,
        bulge_gap_nm: crate::units::to_nm(g.bulge),
        velocity_m_per_s: s[sys.layout().velocity(0)],
        self_excited,
    }
    .into()
}

/// An error of the cycle that no scene should cause.
fn internal(what: &'static str) -> Error {
    crate::error::Internal {
        stage: Stage::CYCLE,
        what,
    }
    .into()
}

/// The error for a cycle that spends its steps too fast (see [`SolverSettings::max_steps`]);
/// with an explicit method, the stiffness of the model as the likely cause.
fn out_of_step_budget(
    model: &SliderModel,
    opts: &CycleOptions,
    t: f64,
    st: Stats,
    span: f64,
) -> Error {
    let explicit = matches!(opts.solver.method, Method::Tsit5 | Method::Dop853);
    CycleError::StepPace {
        method: opts.solver.method.name(),
        steps: st.accepted + st.rejected,
        t_ms: t * 1e3,
        span_ms: span * 1e3,
        max_steps: opts.solver.max_steps,
        stiff_rate_per_s: explicit.then(|| model.fastest_rate()),
    }
    .into()
}

/// ODE errors of an explicit method on a stiff cycle get the advice to use a stiff method.
fn explain_ode_error(model: &SliderModel, opts: &CycleOptions, e: ode::OdeError) -> Error {
    let explicit = matches!(opts.solver.method, Method::Tsit5 | Method::Dop853);
    match e {
        ode::OdeError::TooManySteps { t, max_steps } if explicit => CycleError::StepLimit {
            method: opts.solver.method.name(),
            max_steps,
            t_ms: t * 1e3,
            fastest_rate_per_s: model.fastest_rate(),
        }
        .into(),
        other => Error::Ode(other),
    }
}

fn series_of<D: DimName>(
    sys: &SliderSystem,
    times: &[f64],
    states: &[OVector<f64, D>],
    det: &Detecting<D>,
    window: Option<(f64, f64)>,
) -> TimeSeries
where
    DefaultAllocator: Allocator<D>,
{
    let model = sys.model();
    let mut out = TimeSeries::default();
    let (first, n_terms) = sys.layout().term_states;
    out.term_states = vec![Vec::with_capacity(times.len()); n_terms];
    let inside = |t: f64| window.is_none_or(|(a, b)| t >= a && t <= b);
    for (t, s) in times.iter().zip(states).filter(|(t, _)| inside(**t)) {
        let t = *t;
        let g = sys.gaps(t, s);
        let volt2 = sys.inputs().voltage.squared(t);
        let b = model.breakdown(g, volt2);
        let f_ab = sys.bearing_force(s);
        out.t.push(t);
        out.power.push(sys.inputs().heater.power(t));
        out.d.push(g.bulge);
        out.air_bearing.push(f_ab);
        out.intermolecular.push(b.intermolecular);
        out.electrostatic.push(b.electrostatic);
        out.contact.push(b.contact);
        out.total.push(f_ab + b.total);
        out.temperature_rise.push(model.flash_temperature(g));
        out.indicator.push(if t >= det.detector.window {
            det.indicator(t)
        } else {
            f64::NAN
        });
        for (j, series) in out.term_states.iter_mut().enumerate() {
            series.push(s[first + j]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector1, U1};

    /// Reading `Q` at increasing times with one cursor gives the same bits as a fresh search
    /// at every time: inside steps, on their starts and ends, twice at one time, and across
    /// runs of steps longer than the cursor's walk.
    #[test]
    fn the_cursor_reads_the_impulse_a_fresh_search_reads() {
        let mut rec = Record::<U1>::new(0.0, &Vector1::new(0.0), 0, false);
        let mut t = 0.0;
        for k in 0..40 {
            let h = 0.1 + 0.05 * f64::from(k % 7);
            let c = [
                f64::from(k),
                1.0 + 0.1 * f64::from(k),
                -0.3,
                0.02 * f64::from(k),
            ];
            rec.push_step(t, h, 1, &c, t + h, c.iter().sum());
            t += h;
        }
        let end = t;
        let mut times: Vec<f64> = (0..=400).map(|i| end * f64::from(i) / 400.0).collect();
        times.extend(rec.steps.iter().map(|s| s.0));
        times.extend(rec.steps.iter().map(|s| s.0 + s.1));
        times.push(end + 1.0);
        times.sort_by(f64::total_cmp);
        // Steps of the cursor over more than its walk: every eighth time only.
        for stride in [1, 8] {
            let mut from = 0;
            for &t in times.iter().step_by(stride) {
                let fresh = rec.impulse_after(t, &mut 0);
                let cursor = rec.impulse_after(t, &mut from);
                assert_eq!(fresh.map(f64::to_bits), cursor.map(f64::to_bits), "t = {t}");
                assert_eq!(cursor.is_some(), t <= end, "t = {t}");
            }
        }
    }
}
