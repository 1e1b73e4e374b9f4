//! Hysteresis against AC amplitude (paper Fig. 3d): one cycle per amplitude, in parallel.
//!
//! Each cycle is independent and deterministic, and results are returned in the order of the
//! amplitudes, so the sweep gives the same numbers whatever the thread count.
//!
//! Where the AC drive makes contact intermittent, the running mean of the contact force hovers
//! near its threshold and the detected touchdown and take-off become sensitive to the solver
//! tolerance. [`ac_sweep_refined`] tightens the tolerance at each amplitude until the detected
//! powers and the mean flash temperature stop moving, and says where they did not.
//!
//! Every cycle can say whether it is to be trusted: [`flags`] lists what is wrong with a cycle
//! (a touchdown or take-off not detected, a negative hysteresis), and
//! [`RefinedCycle::flags`] adds a refinement that did not converge.

use serde::Serialize;

use super::cycle::{simulate_cycle, CycleOptions, CycleResult, HeaterProgramme};
use crate::error::{check_finite, check_positive, Result};
use crate::model::{SliderModel, Voltage};
use crate::ode::Stats;
use crate::{units, Error};

/// Runs `programme` once per AC amplitude (V), at the model's frequency and DC voltage.
///
/// With the `parallel` feature the cycles run on rayon's thread pool.
///
/// ```no_run
/// use hdi_tribology::analysis::{ac_sweep, CycleOptions, HeaterProgramme};
/// use hdi_tribology::{model::SliderModel, scene::Scene};
/// let scene = Scene::paper();
/// let model = SliderModel::from_scene(&scene)?;
/// let programme = HeaterProgramme::fixed_from_scene(&scene)?;
/// let opts = CycleOptions::from_scene(&scene)?;
/// for r in ac_sweep(&model, &programme, &opts, &[0.0, 0.5, 1.0])? {
///     println!("{} V: {:?}", r.v_ac, r.hysteresis);
/// }
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn ac_sweep(
    model: &SliderModel,
    programme: &HeaterProgramme,
    opts: &CycleOptions,
    amplitudes: &[f64],
) -> Result<Vec<CycleResult>> {
    per_amplitude(model, amplitudes, |m| simulate_cycle(m, programme, opts))
}

/// `run` on the model at each AC amplitude, in parallel with the `parallel` feature, results in
/// the order of the amplitudes.
fn per_amplitude<T: Send>(
    model: &SliderModel,
    amplitudes: &[f64],
    run: impl Fn(&SliderModel) -> Result<T> + Sync,
) -> Result<Vec<T>> {
    for (i, &a) in amplitudes.iter().enumerate() {
        check_finite(&format!("amplitudes[{i}]"), a)?;
    }
    let one = |&v_ac: &f64| {
        run(&model.with_voltage(Voltage {
            ac_amplitude: v_ac,
            ..model.voltage()
        }))
    };
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        // The workers watch the caller's cancellation flag.
        let cancel = crate::ode::Cancel::current();
        amplitudes
            .par_iter()
            .map(|a| crate::ode::Cancel::carry(&cancel, || one(a)))
            .collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        amplitudes.iter().map(one).collect()
    }
}

/// How [`ac_sweep_refined`] tightens the solver tolerance.
///
/// ```
/// use hdi_tribology::analysis::sweep::Refinement;
/// let r = Refinement::new(6e-5);
/// assert_eq!((r.factor, r.max_runs, r.temperature_tol), (0.1, 4, 0.05));
/// assert_eq!(r.agreeing_runs, 2);
/// // Stricter: three successive tolerances must agree (at most five runs). With AC the detected
/// // take-off can land a whole period of V² early in two successive runs alike.
/// let strict = Refinement { agreeing_runs: 3, max_runs: 5, ..r };
/// # let _ = strict;
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Refinement {
    /// Largest change of the detected touchdown and take-off powers between two successive
    /// tolerances that counts as converged (W).
    pub power_tol: f64,
    /// Largest change of the mean flash-temperature rise between two successive tolerances that
    /// counts as converged (K).
    pub temperature_tol: f64,
    /// Factor applied to the relative and absolute tolerances at each round, in (0, 1).
    pub factor: f64,
    /// Most cycles run per amplitude, the first included, 2 to 12.
    pub max_runs: usize,
    /// How many successive runs must agree: converged when each of the last `agreeing_runs − 1`
    /// tightenings moved the powers and the temperature by at most their tolerances; 2 to
    /// `max_runs`. With 2 (the default) one agreeing pair suffices. Under AC the detected
    /// take-off (or touchdown) can be a whole period of `V²` off in two successive runs alike
    /// (one more burst of contact before leaving, a trajectory effect that no single tolerance
    /// resolves); 3 catches that at the cost of one more, tighter run per amplitude.
    pub agreeing_runs: usize,
}

impl Refinement {
    /// Converged when the powers move by at most `power_tol` (W), and the mean flash-temperature
    /// rise by at most 0.05 K, under a tenfold tighter tolerance; at most four runs (the
    /// tolerance tightened down to a thousandth).
    pub fn new(power_tol: f64) -> Self {
        Refinement {
            power_tol,
            temperature_tol: 0.05,
            factor: 0.1,
            max_runs: 4,
            agreeing_runs: 2,
        }
    }

    /// The tolerance of run `run` (0 for the first) that starts from `first`: `first ·
    /// factor^run`, taken on the decimals they are written as ([`units::geometric_point`]), so
    /// the tolerances reported read as typed (`1e-10`, not `1.0000000000000002e-10`).
    ///
    /// ```
    /// use hdi_tribology::analysis::sweep::Refinement;
    /// let r = Refinement::new(6e-5);
    /// assert_eq!(r.tolerance(1e-8, 0), 1e-8);
    /// assert_eq!(r.tolerance(1e-8, 2), 1e-10);
    /// assert_eq!(r.tolerance(3e-16, 4), 3e-20);
    /// ```
    pub fn tolerance(&self, first: f64, run: usize) -> f64 {
        units::geometric_point(first, self.factor, u32::try_from(run).unwrap_or(u32::MAX))
    }

    fn validate(&self) -> Result<()> {
        check_positive("refinement.power_tol", self.power_tol)?;
        check_positive("refinement.temperature_tol", self.temperature_tol)?;
        if !(self.factor > 0.0 && self.factor < 1.0) {
            return Err(Error::invalid(
                "refinement.factor",
                format!("must lie in (0, 1), got {}", self.factor),
            ));
        }
        if !(2..=12).contains(&self.max_runs) {
            return Err(Error::invalid(
                "refinement.max_runs",
                format!("must lie in 2..=12, got {}", self.max_runs),
            ));
        }
        if !(2..=self.max_runs.max(2)).contains(&self.agreeing_runs) {
            return Err(Error::invalid(
                "refinement.agreeing_runs",
                format!(
                    "must lie in 2..=max_runs ({}), got {}",
                    self.max_runs, self.agreeing_runs
                ),
            ));
        }
        Ok(())
    }
}

/// One amplitude of [`ac_sweep_refined`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RefinedCycle {
    /// The cycle at the tightest tolerance run.
    pub cycle: CycleResult,
    /// The relative tolerance of that cycle.
    pub rtol: f64,
    /// The absolute displacement tolerance of that cycle (m), tightened with `rtol`.
    #[serde(rename = "atol_m")]
    pub atol: f64,
    /// Largest change of the touchdown and take-off powers between the last two runs (W); ∞
    /// when one of them was detected in one run and not in the other.
    #[serde(rename = "power_change_w")]
    pub change: f64,
    /// Change of the mean flash-temperature rise between the last two runs (K); NaN, and not
    /// compared, where [`CycleOptions::mean_temperature`] left the temperature out.
    #[serde(rename = "temperature_change_k")]
    pub temperature_change: f64,
    /// Whether `change ≤ power_tol` and `temperature_change ≤ temperature_tol` held for each of
    /// the last `agreeing_runs − 1` tightenings.
    pub converged: bool,
    /// Cycles run.
    pub runs: usize,
    /// Solver work over all the runs.
    pub stats: Stats,
    /// Wall time over all the runs (s).
    pub wall_seconds: f64,
}

/// Largest change of the detected powers between two cycles (∞ if a detection comes or goes).
fn power_change(a: &CycleResult, b: &CycleResult) -> f64 {
    let one = |x: Option<f64>, y: Option<f64>| match (x, y) {
        (Some(x), Some(y)) => (x - y).abs(),
        (None, None) => 0.0,
        _ => f64::INFINITY,
    };
    let p = |d: Option<super::cycle::Detection>| d.map(|d| d.power);
    one(p(a.touchdown), p(b.touchdown)).max(one(p(a.takeoff), p(b.takeoff)))
}

/// [`ac_sweep`], with the relative and absolute tolerances at each amplitude tightened by
/// `refine.factor` until the detected touchdown and take-off powers move by at most
/// `refine.power_tol` and the mean flash-temperature rise by at most `refine.temperature_tol`
/// over `refine.agreeing_runs` successive runs, or `refine.max_runs` cycles have run. The cycle
/// kept is the last (most accurate) one; the change from the one before is its error estimate,
/// conservative.
///
/// ```no_run
/// use hdi_tribology::analysis::sweep::{ac_sweep_refined, Refinement};
/// use hdi_tribology::analysis::{CycleOptions, HeaterProgramme};
/// use hdi_tribology::{model::SliderModel, scene::Scene};
/// let scene = Scene::paper();
/// let model = SliderModel::from_scene(&scene)?;
/// let programme = HeaterProgramme::fixed_from_scene(&scene)?;
/// let opts = CycleOptions::from_scene(&scene)?;
/// for r in ac_sweep_refined(&model, &programme, &opts, &[0.0, 0.7], &Refinement::new(6e-5))? {
///     let mark = if r.converged { "" } else { " (not converged)" };
///     println!("{} V: {:?} mW at rtol {:e}{mark}", r.cycle.v_ac, r.cycle.hysteresis_mw(), r.rtol);
/// }
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn ac_sweep_refined(
    model: &SliderModel,
    programme: &HeaterProgramme,
    opts: &CycleOptions,
    amplitudes: &[f64],
    refine: &Refinement,
) -> Result<Vec<RefinedCycle>> {
    refine.validate()?;
    per_amplitude(model, amplitudes, |m| {
        let mut o = *opts;
        let mut last = simulate_cycle(m, programme, &o)?;
        let (mut stats, mut wall) = (last.stats, last.wall_seconds);
        let mut runs = 1;
        // Successive runs that agree, the last one included.
        let mut agreeing = 1;
        loop {
            // Run k's tolerances from the first's and the integer k, as the decimals they are:
            // 1e-8 tightened twice by 0.1 is 1e-10 (not 1.0000000000000002e-10).
            o.solver.rtol = refine.tolerance(opts.solver.rtol, runs);
            o.solver.atol_displacement = refine.tolerance(opts.solver.atol_displacement, runs);
            let next = simulate_cycle(m, programme, &o)?;
            runs += 1;
            stats += &next.stats;
            wall += next.wall_seconds;
            let change = power_change(&last, &next);
            let temperature_change =
                (next.mean_temperature_rise - last.mean_temperature_rise).abs();
            last = next;
            // Without the mean temperature (NaN in both runs) the powers alone decide.
            let temperature_agrees =
                !opts.mean_temperature || temperature_change <= refine.temperature_tol;
            agreeing = if change <= refine.power_tol && temperature_agrees {
                agreeing + 1
            } else {
                1
            };
            let converged = agreeing >= refine.agreeing_runs;
            if converged || runs >= refine.max_runs {
                return Ok(RefinedCycle {
                    cycle: last,
                    rtol: o.solver.rtol,
                    atol: o.solver.atol_displacement,
                    change,
                    temperature_change,
                    converged,
                    runs,
                    stats,
                    wall_seconds: wall,
                });
            }
        }
    })
}

/// What makes a cycle's result untrustworthy, or not a result at all.
///
/// ```
/// use hdi_tribology::analysis::sweep::Flag;
/// assert_eq!(Flag::NegativeHysteresis.to_string(), "negative hysteresis");
/// assert_eq!(serde_json::to_string(&Flag::NotConverged).unwrap(), "\"not_converged\"");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Flag {
    /// No touchdown was detected: there is no touchdown power and no hysteresis.
    NoTouchdown,
    /// No take-off was detected after touchdown: there is no hysteresis.
    NoTakeoff,
    /// The take-off power lies above the touchdown power: not a physical hysteresis but a
    /// detection artefact (typically the contact indicator hovering at its threshold).
    NegativeHysteresis,
    /// The refined tolerances did not bring the powers and the mean temperature within their
    /// tolerances.
    NotConverged,
    /// A calibration's take-off heard by a high-pass detector without a dither: the detector
    /// hears only changes, so it stops firing at the first step down, which is then no take-off
    /// (docs/clearance.md).
    TakeoffWithoutDither,
}

impl std::fmt::Display for Flag {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Flag::NoTouchdown => "no touchdown detected",
            Flag::NoTakeoff => "no take-off detected",
            Flag::NegativeHysteresis => "negative hysteresis",
            Flag::NotConverged => "not converged",
            Flag::TakeoffWithoutDither => "take-off heard without a dither",
        })
    }
}

/// What is wrong with one cycle; empty when its touchdown, take-off and hysteresis are all there
/// and the hysteresis is not negative. (Whether the tolerance was fine enough takes a refined
/// run: see [`RefinedCycle::flags`].)
///
/// ```no_run
/// use hdi_tribology::analysis::sweep::flags;
/// use hdi_tribology::analysis::{simulate_cycle, CycleOptions, HeaterProgramme};
/// use hdi_tribology::{model::SliderModel, scene::Scene};
/// let scene = Scene::paper();
/// let model = SliderModel::from_scene(&scene)?;
/// let programme = HeaterProgramme::Fixed(SliderModel::programme_from_knots(&scene.heater.programme)?);
/// let r = simulate_cycle(&model, &programme, &CycleOptions::from_scene(&scene)?)?;
/// assert!(flags(&r).is_empty());
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn flags(cycle: &CycleResult) -> Vec<Flag> {
    let mut f = Vec::new();
    if cycle.touchdown.is_none() {
        f.push(Flag::NoTouchdown);
    } else if cycle.takeoff.is_none() {
        f.push(Flag::NoTakeoff);
    }
    if cycle.hysteresis.is_some_and(|h| h < 0.0) {
        f.push(Flag::NegativeHysteresis);
    }
    f
}

impl RefinedCycle {
    /// [`flags`] of the cycle kept, and [`Flag::NotConverged`] when the refinement did not
    /// converge.
    pub fn flags(&self) -> Vec<Flag> {
        let mut f = flags(&self.cycle);
        if !self.converged {
            f.push(Flag::NotConverged);
        }
        f
    }
}
