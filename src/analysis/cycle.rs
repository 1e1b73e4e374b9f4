//! Dynamic touchdown/take-off cycles under a heater programme (MODEL.md section 6).
//!
//! The slider is integrated from its flying equilibrium at `P(0)`, `V(0)²` with two running
//! integrals in the state: `Q = ∫F_c dt`, so the contact indicator — the running mean of `F_c` over
//! the trailing window `T_w` — is exactly `(Q(t) − Q(t − T_w))/T_w` on the dense output, and
//! `Θ = ∫ΔT dt` for the mean flash temperature. Touchdown is the first time the indicator reaches
//! `F_th` (from `t = T_w` on); take-off the first time at or after the end of the hold that it falls
//! below `F_th`. Both are located by root finding on the dense output. The trailing window delays
//! detection by up to `T_w`: the dynamic hysteresis is biased upward by about ramp rate × `T_w`.

use super::equilibrium::{flying_equilibrium, ScanGrid};
use super::roots::brent;
use crate::error::{check_positive, Error, Result};
use crate::heater::Programme;
use crate::model::{SliderModel, SliderSystem, StateLayout};
use crate::ode::{self, Method, Options, SaveAt, Solution, Stats};
use nalgebra::{
    allocator::Allocator, DefaultAllocator, DimName, OVector, U10, U4, U5, U6, U7, U8, U9,
};
use serde::Serialize;
use std::time::Instant;

/// Largest number of segments of the touchdown-triggered search (each `overshoot / ramp_rate`
/// long; the paper scene needs 200).
const MAX_TRIGGERED_SEGMENTS: f64 = 1e5;

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
    /// Step limit.
    pub max_steps: usize,
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
        Ok(())
    }
}

/// A detected touchdown or take-off.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Detection {
    /// Time (s).
    pub time: f64,
    /// Programme power at that time (W).
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

/// Time series of one cycle, at every accepted step.
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
    /// Running mean of the contact force over the detector window (N); NaN before `T_w`.
    pub indicator: Vec<f64>,
}

impl TimeSeries {
    /// Writes the series as CSV, one row per step, SI units in the column names.
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
    pub v_ac: f64,
    /// Touchdown, if detected.
    pub touchdown: Option<Detection>,
    /// Take-off, if detected.
    pub takeoff: Option<Detection>,
    /// `P(t_TD) − P(t_TO)` (W), when both were detected.
    pub hysteresis: Option<f64>,
    /// Time mean of the flash temperature over the whole programme (K).
    pub mean_temperature_rise: f64,
    /// Length of the programme (s).
    pub duration: f64,
    /// The programme actually run (for the triggered protocol: as fixed by the detection).
    #[serde(skip)]
    pub programme: Programme,
    /// Solver statistics, summed over the segments.
    pub stats: Stats,
    /// Wall-clock time of the simulation (s).
    pub wall_seconds: f64,
    /// Time series, when asked for.
    pub series: Option<TimeSeries>,
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
    // Dispatch on the state size to stack vectors: a step allocates nothing, and a scene pays
    // only for the coordinates and lags it uses.
    let layout = StateLayout::new(
        model.structure.dofs(),
        model.thermal_lag > 0.0,
        model.interface_lag > 0.0,
        true,
    );
    match layout.len() {
        4 => run::<U4>(model, programme, opts),
        5 => run::<U5>(model, programme, opts),
        6 => run::<U6>(model, programme, opts),
        7 => run::<U7>(model, programme, opts),
        8 => run::<U8>(model, programme, opts),
        9 => run::<U9>(model, programme, opts),
        10 => run::<U10>(model, programme, opts),
        n => Err(crate::error::AnalysisError::Internal {
            stage: crate::error::Stage::Cycle,
            detail: format!("unexpected state size {n}"),
        }
        .into()),
    }
}

/// Solutions of consecutive segments, sampled as one trajectory.
struct Trajectory<D: DimName>
where
    DefaultAllocator: Allocator<D>,
{
    segments: Vec<Solution<D>>,
}

impl<D: DimName> Trajectory<D>
where
    DefaultAllocator: Allocator<D>,
{
    fn sample(&self, t: f64) -> Option<OVector<f64, D>> {
        // The last segment that starts at or before t.
        let i = self
            .segments
            .partition_point(|s| s.t.first().is_some_and(|&t0| t0 <= t));
        let seg = self.segments.get(i.checked_sub(1)?)?;
        seg.sample(t.min(seg.t_final()))
    }

    fn step_times(&self) -> impl Iterator<Item = f64> + '_ {
        self.segments.iter().flat_map(|s| s.t.iter().copied())
    }
}

struct Detecting<'a, D: DimName>
where
    DefaultAllocator: Allocator<D>,
{
    traj: &'a Trajectory<D>,
    q: usize,
    detector: Detector,
}

impl<D: DimName> Detecting<'_, D>
where
    DefaultAllocator: Allocator<D>,
{
    /// Running mean of the contact force at `t ≥ T_w`.
    fn indicator(&self, t: f64) -> f64 {
        let w = self.detector.window;
        match (self.traj.sample(t), self.traj.sample(t - w)) {
            (Some(a), Some(b)) => (a[self.q] - b[self.q]) / w,
            _ => f64::NAN,
        }
    }

    /// First time in `[a, b]` where the indicator crosses `F_th` upward (`rising`) or downward.
    ///
    /// The indicator is smooth between step times and step times shifted by `T_w`; it is sampled
    /// there and the crossing is refined by root finding on the dense output.
    fn first_crossing(&self, a: f64, b: f64, rising: bool) -> Result<Option<f64>> {
        let w = self.detector.window;
        let th = self.detector.contact_threshold;
        let a = a.max(w);
        if a > b {
            return Ok(None);
        }
        let mut samples: Vec<f64> = self
            .traj
            .step_times()
            .flat_map(|t| [t, t + w])
            .filter(|&t| t > a && t < b)
            .collect();
        samples.push(a);
        samples.push(b);
        samples.sort_by(f64::total_cmp);
        samples.dedup();
        let hit = |x: f64| {
            let v = self.indicator(x);
            if rising {
                v >= th
            } else {
                v < th
            }
        };
        if hit(samples[0]) {
            return Ok(Some(samples[0]));
        }
        for pair in samples.windows(2) {
            if hit(pair[1]) {
                let t = brent(|x| self.indicator(x) - th, pair[0], pair[1], 1e-12 * w)?;
                return Ok(Some(t));
            }
        }
        Ok(None)
    }
}

fn run<D: DimName>(
    model: &SliderModel,
    programme: &HeaterProgramme,
    opts: &CycleOptions,
) -> Result<CycleResult>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let clock = Instant::now();
    let det = opts.detector;
    // The ramp that the triggered protocol follows until touchdown fixes its turning point.
    let (initial_programme, triggered) = match programme {
        HeaterProgramme::Fixed(p) => (p.clone(), None),
        &HeaterProgramme::Triggered {
            start_power,
            ramp_rate,
            overshoot,
        } => {
            check_positive("programme.ramp_rate", ramp_rate)?;
            check_positive("programme.overshoot", overshoot)?;
            crate::error::check_non_negative("programme.start_power", start_power)?;
            // Search up to the power whose protrusion is twice the nominal clearance.
            let span = 2.0 * model.nominal_clearance / model.efficiency;
            // The search runs in segments of `overshoot`; bound their number so that a heater
            // too weak to ever reach touchdown fails at once instead of running for ever.
            let segments = span / overshoot;
            if segments.is_nan() || segments > MAX_TRIGGERED_SEGMENTS {
                return Err(crate::error::AnalysisError::TooManySegments {
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
            (ramp, Some((start_power, ramp_rate, overshoot)))
        }
    };

    let t0 = initial_programme.start_time();
    let volt2_0 = model.voltage.squared(t0);
    let eq = flying_equilibrium(
        model,
        initial_programme.power(t0),
        volt2_0,
        &ScanGrid::default(),
    )?;
    let mut sys = SliderSystem::new(model, initial_programme.clone(), true);
    let layout = sys.layout();
    let q = layout
        .contact_impulse
        .ok_or_else(|| internal("no impulse state"))?;
    let heat = layout.heat.ok_or_else(|| internal("no heat state"))?;
    let y0: OVector<f64, D> = sys.initial_state(D::name(), &eq.rest());

    let ode_opts = ode_options(&sys, opts, &initial_programme)?;
    let mut traj = Trajectory::<D> {
        segments: Vec::new(),
    };
    let mut stats = Stats::default();
    let mut solve = |sys: &SliderSystem,
                     a: f64,
                     y: OVector<f64, D>,
                     b: f64,
                     o: &Options|
     -> Result<Solution<D>> {
        // Stop where the lumped model ends: the pad gap h0 + y reaching zero puts the slider body
        // into the disk (no pad contact is modelled; a power-law bearing is singular there).
        let h0 = model.nominal_clearance;
        let mut guard = [ode::Event::new(move |_t, s: &OVector<f64, D>| h0 + s[0])
            .direction(ode::Direction::Falling)
            .terminal(true)];
        let sol = ode::solve(sys, a, y, b, opts.solver.method, o, &mut guard)
            .map_err(|e| explain_ode_error(model, opts, e))?;
        stats += &sol.stats;
        if sol.terminated_by_event.is_some() {
            return Err(left_the_model(model, sys, &sol));
        }
        Ok(sol)
    };

    let final_programme;
    let search_from;
    match triggered {
        None => {
            let end = initial_programme.end_time();
            let sol = solve(&sys, t0, y0, end, &ode_opts)?;
            traj.segments.push(sol);
            final_programme = initial_programme.clone();
            search_from = final_programme.end_of_hold();
        }
        Some((start_power, rate, overshoot)) => {
            let chunk = overshoot / rate;
            let end = initial_programme.end_time();
            let (mut t, mut y) = (t0, y0);
            let t_td = loop {
                let t1 = (t + chunk).min(end);
                let sol = solve(&sys, t, y, t1, &ode_opts)?;
                y = sol.y_final().clone();
                traj.segments.push(sol);
                let found = Detecting {
                    traj: &traj,
                    q,
                    detector: det,
                }
                .first_crossing(t, t1, true)?;
                if let Some(t_td) = found {
                    break t_td;
                }
                if t1 >= end {
                    return Err(crate::error::AnalysisError::NoTouchdown {
                        stage: crate::error::Stage::TriggeredCycle,
                        max_power_mw: crate::units::to_mw(initial_programme.power(end)),
                        detector: None,
                    }
                    .into());
                }
                t = t1;
            };
            let t_peak = t_td + chunk;
            let p_peak = start_power + rate * (t_peak - t0);
            let t_end = t_peak + (p_peak - start_power) / rate;
            final_programme = Programme::new(vec![
                (t0, start_power),
                (t_peak, p_peak),
                (t_end, start_power),
            ])?;
            sys = SliderSystem::new(model, final_programme.clone(), true);
            let o = ode_options(&sys, opts, &final_programme)?;
            let t_now = traj.segments.last().map_or(t0, |s| s.t_final());
            let sol = solve(&sys, t_now, y, t_end, &o)?;
            traj.segments.push(sol);
            search_from = t_peak;
        }
    }

    let detecting = Detecting {
        traj: &traj,
        q,
        detector: det,
    };
    let end = final_programme.end_time();
    let td = detecting.first_crossing(t0, end, true)?;
    let to = match td {
        Some(t) => detecting.first_crossing(search_from.max(t), end, false)?,
        None => None,
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
    let last = traj
        .segments
        .last()
        .ok_or_else(|| internal("nothing was integrated"))?;
    let duration = end - t0;
    let mean_temperature_rise = last.y_final()[heat] / duration;
    let series = opts.keep_series.then(|| series_of(&sys, &traj, &detecting));
    Ok(CycleResult {
        v_ac: model.voltage.ac_amplitude,
        touchdown,
        takeoff,
        hysteresis,
        mean_temperature_rise,
        duration,
        programme: final_programme,
        stats,
        wall_seconds: clock.elapsed().as_secs_f64(),
        series,
    })
}

fn ode_options(sys: &SliderSystem, opts: &CycleOptions, programme: &Programme) -> Result<Options> {
    let s = opts.solver;
    // The integrals only need the accuracy the detector and the mean temperature use.
    let atol = sys.tolerances(
        s.atol_displacement,
        s.rtol * opts.detector.contact_threshold * opts.detector.window,
        s.rtol * opts.detector.window,
    );
    let n = atol.len();
    let o = Options::default()
        .rtol(s.rtol)
        .atol_per_component(atol)
        .h_max(sys.model().max_step(s.max_step))
        .max_steps(s.max_steps)
        .t_stops(programme.knots().iter().map(|k| k.0).collect())
        .save(SaveAt::Steps)
        .dense(true);
    o.validate(n)
        .map_err(|e| Error::invalid("solver", e.to_string()))?;
    Ok(o)
}

/// The error for a trajectory that left the lumped model (the pad gap reached zero), with the
/// likely cause when an interface lag makes the contact branch self-excited.
fn left_the_model<D: DimName>(model: &SliderModel, sys: &SliderSystem, sol: &Solution<D>) -> Error
where
    DefaultAllocator: Allocator<D>,
{
    let (t, s) = (sol.t_final(), sol.y_final());
    let g = sys.gaps(t, s);
    let mut self_excited = None;
    if model.interface_lag > 0.0 {
        let k_contact = -model.forces().contact(g).d_bulge;
        let c = model.bearing().damping(s[0]);
        if k_contact > 0.0 && model.interface_lag > c / k_contact {
            self_excited = Some(crate::error::SelfExcitation {
                interface_lag_ns: model.interface_lag * 1e9,
                limit_ns: c / k_contact * 1e9,
            });
        }
    }
    crate::error::AnalysisError::LeftTheModel {
        t_ms: t * 1e3,
        bulge_gap_nm: crate::units::to_nm(g.bulge),
        velocity_m_per_s: s[sys.layout().velocity(0)],
        self_excited,
    }
    .into()
}

/// An error of the cycle that no scene should cause.
fn internal(detail: &str) -> Error {
    crate::error::AnalysisError::Internal {
        stage: crate::error::Stage::Cycle,
        detail: detail.into(),
    }
    .into()
}

/// ODE errors of an explicit method on a stiff cycle get the advice to use a stiff method.
fn explain_ode_error(model: &SliderModel, opts: &CycleOptions, e: ode::OdeError) -> Error {
    let explicit = matches!(opts.solver.method, Method::Tsit5 | Method::Dop853);
    match e {
        ode::OdeError::TooManySteps { t, max_steps } if explicit => {
            crate::error::AnalysisError::StepLimit {
                method: opts.solver.method.name(),
                max_steps,
                t_ms: t * 1e3,
                fastest_rate_per_s: model.fastest_rate(),
            }
            .into()
        }
        other => Error::Ode(other),
    }
}

fn series_of<D: DimName>(sys: &SliderSystem, traj: &Trajectory<D>, det: &Detecting<D>) -> TimeSeries
where
    DefaultAllocator: Allocator<D>,
{
    let model = sys.model();
    let mut out = TimeSeries::default();
    let mut last_t = f64::NEG_INFINITY;
    for seg in &traj.segments {
        for (t, s) in seg.t.iter().zip(&seg.y) {
            if *t <= last_t {
                continue; // segment boundaries repeat a time
            }
            last_t = *t;
            let g = sys.gaps(*t, s);
            let volt2 = model.voltage.squared(*t);
            let b = model.breakdown(g, volt2);
            let f_ab = sys.bearing_force(s);
            out.t.push(*t);
            out.power.push(sys.programme().power(*t));
            out.d.push(g.bulge);
            out.air_bearing.push(f_ab);
            out.intermolecular.push(b.intermolecular);
            out.electrostatic.push(b.electrostatic);
            out.contact.push(b.contact);
            out.total.push(f_ab + b.total);
            out.temperature_rise.push(model.flash_temperature(g));
            out.indicator.push(if *t >= det.detector.window {
                det.indicator(*t)
            } else {
                f64::NAN
            });
        }
    }
    out
}
