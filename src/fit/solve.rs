//! The least-squares fit, its error bars and its identifiability report.

use std::cell::RefCell;
use std::sync::atomic::Ordering;

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector};
use nalgebra_lm::{storage::Owned, DMatrix as LmMatrix, DVector as LmVector, Dyn};
use serde::Serialize;

use super::data::DataSet;
use super::forward::{weighted, weights, Evaluator, Predicted, Sets};
use super::goodness::{self, Goodness};
use super::params::{resolve, FreeParameter, Resolved};
use crate::analysis::sweep::Refinement;
use crate::error::DataError;
use crate::numerics::rng::Xoshiro256;
use crate::scene::Scene;
use crate::Error;

/// Settings of a fit.
///
/// ```
/// let o = hdi_tribology::fit::FitOptions::default();
/// assert_eq!((o.starts, o.undetermined_rel_error), (1, 0.5));
/// assert!(!o.finite_difference_jacobian);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FitOptions {
    /// Number of starts: the first from the scene's values (or the parameters' own starts),
    /// the others drawn from the bounds with `seed`. The best fit is kept.
    pub starts: usize,
    /// Seed of the extra starts.
    pub seed: u64,
    /// Most model evaluations per start (a Jacobian costs one per parameter).
    pub max_evaluations: usize,
    /// Finite-difference step, relative to each parameter's scale.
    pub rel_step: f64,
    /// The optimiser stops when an iteration reduces χ² by at most this fraction (actual and
    /// predicted), or moves the parameters by at most this fraction. At a χ² of about `m − n`
    /// residual scales that leaves the parameters within `√(tolerance·(m − n))` of their error
    /// bars of the minimum (0.013 error bars for 20 points and 4 parameters at 1e-5).
    pub tolerance: f64,
    /// A parameter, or a combination of parameters, whose 1σ error exceeds this fraction of its
    /// scale (its value, or half its range for one that may change sign) is reported as not
    /// determined, without an error bar.
    pub undetermined_rel_error: f64,
    /// Relative tolerance of the force tables for static curves (touchdown and take-off are
    /// refined on direct quadrature, so tables only guide the scan and a coarse one is as exact).
    pub static_table_rel_tol: f64,
    /// Dynamic curves: the cycle at each amplitude is run with tolerances tightened tenfold
    /// until its detected touchdown and take-off powers move by at most this (mW) between two
    /// tolerances ([`crate::analysis::ac_sweep_refined`], at most four runs). Points that do not
    /// settle at the start are left out of the fit and reported.
    pub dynamic_power_tol_mw: f64,
    /// Finite-difference step of the dynamic curves' Jacobian, relative to each parameter's scale
    /// (larger than `rel_step`, so that the step moves the powers by far more than the
    /// integration noise left after refinement).
    pub dynamic_rel_step: f64,
    /// Compute the whole Jacobian by finite differences of the model (every column a full
    /// evaluation, rebuilding force tables where the parameter changes them) instead of the
    /// static transitions' sensitivities. Slower; kept to check the sensitivities.
    pub finite_difference_jacobian: bool,
    /// Curves with cycles: from the optimum, this many more starts (in pairs, ± along the least
    /// determined directions, [`FitOptions::check_distance`] error bars out). A check start that
    /// ends with a lower χ² shows the first ended in a false minimum: the better one is kept and
    /// the fit says so. 0 turns the check off.
    pub cycle_check_starts: usize,
    /// How far out the check starts begin, in error bars along their direction.
    pub check_distance: f64,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            starts: 1,
            seed: 1,
            max_evaluations: 400,
            rel_step: 1e-3,
            tolerance: 1e-5,
            undetermined_rel_error: 0.5,
            static_table_rel_tol: 1e-6,
            dynamic_power_tol_mw: 1e-3,
            dynamic_rel_step: 1e-2,
            finite_difference_jacobian: false,
            cycle_check_starts: 2,
            check_distance: 4.0,
        }
    }
}

impl FitOptions {
    fn validate(&self) -> crate::Result<()> {
        if !(1..=1000).contains(&self.starts) {
            return Err(Error::invalid(
                "starts",
                format!("must lie in 1..=1000, got {}", self.starts),
            ));
        }
        if self.max_evaluations < 2 {
            return Err(Error::invalid("max_evaluations", "must be at least 2"));
        }
        for (f, v, hi) in [
            ("rel_step", self.rel_step, 0.1),
            ("tolerance", self.tolerance, 0.01),
            ("undetermined_rel_error", self.undetermined_rel_error, 1e6),
            ("static_table_rel_tol", self.static_table_rel_tol, 0.01),
            ("dynamic_power_tol_mw", self.dynamic_power_tol_mw, 10.0),
            ("dynamic_rel_step", self.dynamic_rel_step, 0.1),
            ("check_distance", self.check_distance, 100.0),
        ] {
            if !(v > 0.0 && v <= hi) {
                return Err(Error::invalid(
                    f,
                    format!("must lie in (0, {hi}], got {v:?}"),
                ));
            }
        }
        Ok(())
    }
}

/// One fitted parameter, in the unit of its name.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FittedParameter {
    /// The name as given.
    pub name: String,
    /// Its unit (the suffix of the name).
    pub unit: String,
    /// The scene field it sets (SI), dotted.
    pub field: String,
    /// Fitted value.
    pub value: f64,
    /// Value the best start began from.
    pub start: f64,
    /// Standard error from the Jacobian at the optimum, scaled by the residuals; `None` when the
    /// data do not determine the parameter (see the identifiability report).
    pub standard_error: Option<f64>,
    /// The 1σ error the linearisation gives, determined or not (can be huge or infinite).
    pub linear_error: f64,
    /// Whether the data determine it.
    pub determined: bool,
    /// Bounds.
    pub lower: Option<f64>,
    /// Upper bound.
    pub upper: Option<f64>,
    /// The fit ended on a bound (its error bar then means little).
    pub at_bound: bool,
    /// Curves with cycles only: the rise of χ² when the parameter moves by its error bar (both
    /// ways, mean) over the rise the linearisation predicts. About 1 where the error bar is
    /// right; below 0.25 the error bar is at least twice too small, and the fit is not trusted.
    pub linearity: Option<f64>,
}

/// A direction in parameter space (relative to each parameter's scale) and how well the data fix it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Direction {
    /// Singular value of the scaled Jacobian.
    pub singular_value: f64,
    /// 1σ error along the direction, as a fraction of the parameters' scales.
    pub rel_error: f64,
    /// Whether the data determine it.
    pub determined: bool,
    /// Components (parameter name, weight), the larger first; weights below 0.05 left out.
    pub components: Vec<(String, f64)>,
}

/// What the data determine.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Identifiability {
    /// Directions, best determined first.
    pub directions: Vec<Direction>,
    /// Condition number of the scaled Jacobian.
    pub condition: f64,
    /// The report in words.
    pub statements: Vec<String>,
}

/// One row of a residual table, in the data file's units.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ResidualRow {
    /// Line in the data file.
    pub line: u64,
    /// x (file unit).
    pub x: f64,
    /// Measured value (file unit).
    pub measured: f64,
    /// Model value at the fit (file unit).
    pub fitted: f64,
    /// `fitted − measured` (file unit).
    pub residual: f64,
    /// The residual divided by the uncertainty (1 mW, or 1 µN for the indicator, where the file
    /// gives none).
    pub weighted: f64,
    /// The model did not detect this transition inside the heater programme (the value is the
    /// programme's end, a bound).
    pub clipped: bool,
    /// Left out of the fit: a dynamic value whose detected power did not settle under tighter
    /// tolerances at the start or at an optimum (its residual is shown, not fitted).
    pub excluded: bool,
}

/// Residuals of one measured column.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ResidualTable {
    /// Data file.
    pub file: String,
    /// x column as written.
    pub x_column: String,
    /// Measured column as written (quantity and unit).
    pub column: String,
    /// Rows.
    pub rows: Vec<ResidualRow>,
}

/// How much the integration error of the cycles moves the residuals, at the optimum.
///
/// Every cycle is refined ([`crate::analysis::ac_sweep_refined`]): its tolerances are tightened
/// tenfold until the detected powers move by at most the power tolerance; the last change is the
/// error estimate of the value kept.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IntegrationCheck {
    /// The power tolerance of the refinement (mW).
    pub power_tol_mw: f64,
    /// Tightest relative tolerance any cycle needed.
    pub rtol: f64,
    /// Loosest relative tolerance any cycle needed.
    pub loosest_rtol: f64,
    /// Largest last change of a fitted dynamic value, weighted (over its uncertainty).
    pub max_weighted_change: f64,
    /// That change over the residual scale `s`; it should be well below 1 (0.1 is the limit used).
    pub ratio_to_scatter: f64,
    /// Dynamic values in the fit whose refinement did not converge at the optimum.
    pub unconverged: usize,
    /// Dynamic values left out of the fit (not settled at the start or at an optimum).
    pub excluded: usize,
    /// Whether the integration noise is small enough not to drive the fit: every value in the
    /// fit converged and `ratio_to_scatter ≤ 0.1`.
    pub ok: bool,
}

/// Predictions flattened in the order of the residuals.
fn flatten(pred: &[Vec<Vec<Predicted>>]) -> Vec<Predicted> {
    pred.iter().flatten().flatten().copied().collect()
}

/// The integration check of the dynamic values of `pred` (residual scale `s`).
fn integration_check(
    data: &[DataSet],
    pred: &[Vec<Vec<Predicted>>],
    excluded: &[bool],
    s: f64,
    opts: &FitOptions,
) -> IntegrationCheck {
    let w = weights(data);
    let (mut change, mut tight, mut loose) = (0.0_f64, f64::INFINITY, 0.0_f64);
    let mut unconverged = 0;
    for (i, q) in flatten(pred).iter().enumerate() {
        let Some(r) = q.refined else { continue };
        if excluded.get(i).copied().unwrap_or(false) {
            continue;
        }
        change = change.max(r.change / w[i]);
        tight = tight.min(r.rtol);
        loose = loose.max(r.rtol);
        if !r.converged {
            unconverged += 1;
        }
    }
    let ratio = change / s.max(f64::MIN_POSITIVE);
    IntegrationCheck {
        power_tol_mw: opts.dynamic_power_tol_mw,
        rtol: tight,
        loosest_rtol: loose,
        max_weighted_change: change,
        ratio_to_scatter: ratio,
        unconverged,
        excluded: excluded.iter().filter(|e| **e).count(),
        ok: unconverged == 0 && ratio <= 0.1,
    }
}

/// One start of a multi-start fit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StartOutcome {
    /// Starting values.
    pub start: Vec<f64>,
    /// Final values.
    pub end: Vec<f64>,
    /// Final sum of squared weighted residuals; ∞ when the start could not be evaluated.
    pub cost: f64,
    /// Why the optimiser stopped (or why the start failed).
    pub termination: String,
}

/// The outcome of [`fit`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FitResult {
    /// The fitted scene (SI).
    pub scene: Scene,
    /// The parameters.
    pub parameters: Vec<FittedParameter>,
    /// Correlation matrix, in the order of `parameters`.
    pub correlation: Vec<Vec<f64>>,
    /// Residuals per measured column.
    pub residuals: Vec<ResidualTable>,
    /// What the data determine.
    pub identifiability: Identifiability,
    /// Number of residuals.
    pub points: usize,
    /// Sum of squared weighted residuals.
    pub chi2: f64,
    /// Residual scale `s = √(χ²/(m − n))`: the errors are scaled by it.
    pub residual_scale: f64,
    /// Whether the optimiser met its convergence test.
    pub converged: bool,
    /// Why the optimiser stopped.
    pub termination: String,
    /// Model evaluations over all starts and the error analysis.
    pub evaluations: usize,
    /// Every start.
    pub starts: Vec<StartOutcome>,
    /// Integration-noise check (curves with cycles only).
    pub integration: Option<IntegrationCheck>,
    /// Whether the residuals look like noise: χ² against stated uncertainties, the scale of
    /// each curve against the others, runs of residual signs ([`super::goodness`]).
    pub goodness: Goodness,
    /// Converged; every parameter determined and none on a bound; no pair correlated beyond
    /// [`STRONG_CORRELATION`]; no clipped transition; integration noise small; the error bars
    /// linear (curves with cycles); and every goodness-of-fit test passed. Each failure is a
    /// warning.
    pub trusted: bool,
    /// What keeps the fit from being trusted, in words.
    pub warnings: Vec<String>,
}

/// The least-squares problem in the optimiser's unbounded variables.
struct Problem<'e, 'a> {
    ev: &'e Evaluator<'a>,
    /// The optimiser's variables: those of the parameters in `active`.
    u: Vec<f64>,
    /// Indices of the parameters the optimiser moves; the others are held at `held`.
    active: &'e [usize],
    /// The full parameter vector the held values are taken from.
    held: Vec<f64>,
    opts: &'e FitOptions,
    budget: usize,
    /// Residuals at the last point that could be evaluated.
    last: RefCell<Option<(Vec<f64>, Vec<f64>)>>,
    /// The last evaluation error.
    error: RefCell<Option<String>>,
}

impl Problem<'_, '_> {
    fn x(&self, u: &[f64]) -> Vec<f64> {
        let mut x = self.held.clone();
        for (&j, &u) in self.active.iter().zip(u) {
            x[j] = self.ev.params[j].transform.x(u);
        }
        x
    }

    fn over_budget(&self) -> bool {
        self.ev.evaluations.load(Ordering::Relaxed) >= self.budget
    }

    fn residuals_at(&self, u: &[f64]) -> Option<Vec<f64>> {
        if let Some((lu, r)) = self.last.borrow().as_ref() {
            if lu == u {
                return Some(r.clone());
            }
        }
        match self.ev.residuals(&self.x(u)) {
            Ok(r) if r.iter().all(|v| v.is_finite()) => {
                *self.last.borrow_mut() = Some((u.to_vec(), r.clone()));
                Some(r)
            }
            Ok(_) => {
                *self.error.borrow_mut() = Some("non-finite residuals".into());
                None
            }
            Err(e) => {
                *self.error.borrow_mut() = Some(e.to_string());
                None
            }
        }
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_, '_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, u: &LmVector<f64>) {
        self.u = u.iter().copied().collect();
    }

    fn params(&self) -> LmVector<f64> {
        LmVector::from_vec(self.u.clone())
    }

    fn residuals(&self) -> Option<LmVector<f64>> {
        if self.over_budget() {
            *self.error.borrow_mut() = Some("evaluation budget spent".into());
            return None;
        }
        let good = self.last.borrow().as_ref().map(|(_, r)| r.clone());
        match (self.residuals_at(&self.u), good) {
            (Some(r), _) => Some(LmVector::from_vec(r)),
            // A trial point the model cannot evaluate: far worse than the last good one, so the
            // optimiser shrinks its step instead of stopping.
            (None, Some(g)) => Some(LmVector::from_vec(
                g.iter()
                    .map(|v| 10.0 * v + v.signum() * 1e3 + 1e3)
                    .collect(),
            )),
            (None, None) => None,
        }
    }

    fn jacobian(&self) -> Option<LmMatrix<f64>> {
        if self.over_budget() {
            *self.error.borrow_mut() = Some("evaluation budget spent".into());
            return None;
        }
        let x = self.x(&self.u);
        self.residuals_at(&self.u)?;
        let cols = match jacobian_columns(self.ev, &x, self.opts, false, self.active) {
            Ok(c) => c,
            Err(e) => {
                *self.error.borrow_mut() = Some(e.to_string());
                return None;
            }
        };
        let m = cols.first().map_or(0, Vec::len);
        let mut j = LmMatrix::zeros(m, self.u.len());
        for (c, (col, &p)) in cols.iter().zip(self.active).enumerate() {
            let d = self.ev.params[p].transform.dx_du(self.u[c]);
            for (i, v) in col.iter().enumerate() {
                j[(i, c)] = v * d;
            }
        }
        Some(j)
    }
}

/// `∂r/∂x_j` of the weighted residuals, one column per parameter in `which`.
///
/// Static values come from the transitions' first-order shifts ([`Evaluator::static_sensitivities`]:
/// no rescan and no table build), dynamic values from finite differences of the cycles alone,
/// each column on its own thread with the `parallel` feature; with
/// `finite_difference_jacobian` every value by finite differences of the whole model. Steps that
/// would leave the bounds go the other way; `central` takes central differences where both
/// sides lie inside the bounds.
fn jacobian_columns(
    ev: &Evaluator<'_>,
    x: &[f64],
    opts: &FitOptions,
    central: bool,
    which: &[usize],
) -> crate::Result<Vec<Vec<f64>>> {
    let n = x.len();
    let pred = ev.predict(x)?;
    let r0 = weighted(ev.data, &pred, &ev.excluded);
    let w = weights(ev.data);
    // The step of parameter j and whether it can be taken both ways.
    let step = |j: usize, rel: f64| -> (f64, bool) {
        let p = &ev.params[j];
        let mut h = rel * p.scale;
        if p.upper.is_some_and(|hi| x[j] + h > hi) {
            h = -h;
        }
        let both = central
            && p.lower.is_none_or(|lo| x[j] - h.abs() >= lo)
            && p.upper.is_none_or(|hi| x[j] + h.abs() <= hi);
        (h, both)
    };
    let fd = |j: usize, rel: f64, sets: Sets| -> crate::Result<Vec<f64>> {
        let (h, both) = step(j, rel);
        let at = |h: f64| {
            let mut xs = x.to_vec();
            xs[j] += h;
            ev.predict_sets(&xs, sets)
                .map(|p| weighted(ev.data, &p, &ev.excluded))
        };
        let plus = at(h)?;
        let (minus, span) = if both {
            (at(-h)?, 2.0 * h)
        } else {
            (r0.clone(), h)
        };
        Ok(plus
            .iter()
            .zip(&minus)
            .map(|(a, b)| (a - b) / span)
            .collect())
    };
    let par_map =
        |f: &(dyn Fn(usize) -> crate::Result<Vec<f64>> + Sync)| -> crate::Result<Vec<Vec<f64>>> {
            #[cfg(feature = "parallel")]
            {
                use rayon::prelude::*;
                let cancel = crate::ode::Cancel::current();
                which
                    .par_iter()
                    .map(|&j| crate::ode::Cancel::carry(&cancel, || f(j)))
                    .collect()
            }
            #[cfg(not(feature = "parallel"))]
            {
                which.iter().map(|&j| f(j)).collect()
            }
        };
    if opts.finite_difference_jacobian {
        return par_map(&|j| fd(j, opts.rel_step, Sets::All));
    }
    // Cycles need the larger step (integration noise); the indicator alone takes `rel_step`.
    let rel = if ev.data.iter().any(DataSet::is_dynamic) {
        opts.dynamic_rel_step
    } else {
        opts.rel_step
    };
    let mut cols = if ev.data.iter().any(|d| !d.is_transitions()) {
        par_map(&|j| fd(j, rel, Sets::NoTransitions))?
    } else {
        vec![vec![0.0; r0.len()]; which.len()]
    };
    let steps: Vec<(f64, bool)> = (0..n).map(|j| step(j, opts.rel_step)).collect();
    let sens = ev.static_sensitivities(x, &pred, &steps)?;
    for (col, s) in cols.iter_mut().zip(which.iter().map(|&j| &sens[j])) {
        for (i, v) in s.iter().enumerate() {
            if let Some(v) = v {
                col[i] = if ev.excluded.get(i).copied().unwrap_or(false) {
                    0.0
                } else {
                    v / w[i]
                };
            }
        }
    }
    Ok(cols)
}

/// Starting points: the given one, then `starts − 1` drawn inside the bounds.
fn start_points(params: &[Resolved], starts: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = Xoshiro256::new(seed);
    let mut out = vec![params.iter().map(|p| p.start).collect::<Vec<_>>()];
    for _ in 1..starts {
        out.push(
            params
                .iter()
                .map(|p| {
                    let u = rng.next_open01();
                    match (p.lower, p.upper) {
                        (Some(lo), Some(hi)) if lo > 0.0 && hi / lo >= 10.0 => {
                            lo * (hi / lo).powf(u)
                        }
                        (Some(lo), Some(hi)) => lo + (hi - lo) * u,
                        (Some(lo), None) => lo + (p.start - lo) * 4f64.powf(2.0 * u - 1.0),
                        (None, Some(hi)) => hi - (hi - p.start) * 4f64.powf(2.0 * u - 1.0),
                        (None, None) => p.start + p.scale * (2.0 * u - 1.0),
                    }
                })
                .collect(),
        );
    }
    out
}

/// Fits the free parameters of `scene` to the measured curves.
///
/// Each parameter is named as a scene file names it, in the unit of that name; the fitted
/// scene, the errors, the correlations and the identifiability report come back together.
///
/// ```no_run
/// use hdi_tribology::fit::{fit, DataSet, FitOptions, FreeParameter};
/// use hdi_tribology::scene::Scene;
/// let data = [DataSet::from_path("touchdown_vs_vdc.csv")?];
/// let free = ["contact_potential_v".parse()?, FreeParameter::new("height_sigma_nm").bounded(0.3, 1.5)];
/// let r = fit(&Scene::paper(), &data, &free, &FitOptions::default())?;
/// for p in &r.parameters {
///     println!("{} = {} ± {:?} {}", p.name, p.value, p.standard_error, p.unit);
/// }
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn fit(
    scene: &Scene,
    data: &[DataSet],
    free: &[FreeParameter],
    opts: &FitOptions,
) -> crate::Result<FitResult> {
    opts.validate()?;
    scene.validate()?;
    if free.is_empty() {
        return Err(Error::invalid(
            "--free",
            "name at least one parameter to fit",
        ));
    }
    let base = serde_json::to_value(scene)
        .map_err(|e| Error::invalid("scene", format!("cannot be represented: {e}")))?;
    let params = free
        .iter()
        .map(|p| resolve(&base, p))
        .collect::<crate::Result<Vec<_>>>()?;
    for (i, p) in params.iter().enumerate() {
        if let Some(q) = params[..i]
            .iter()
            .find(|q| q.field.keys() == p.field.keys())
        {
            return Err(Error::invalid(
                format!("--free {}", p.name()),
                format!("sets the same field as `{}`", q.name()),
            ));
        }
    }
    let points: usize = data.iter().map(DataSet::len).sum();
    if points <= params.len() {
        let files: Vec<&str> = data.iter().map(|d| d.origin.as_str()).collect();
        return Err(Error::Data(DataError {
            file: if files.is_empty() {
                "(no data file)".into()
            } else {
                files.join(", ")
            },
            line: None,
            column: None,
            column_name: None,
            reason: format!(
                "too few points: {points} measured values for {} free parameters; at least {} are \
                 needed to fit them and estimate their errors",
                params.len(),
                params.len() + 1
            ),
        }));
    }
    let refinement = Refinement::new(opts.dynamic_power_tol_mw * 1e-3);
    let mut ev = Evaluator::new(base, &params, data, opts.static_table_rel_tol, refinement);
    // Dynamic points whose detected powers do not settle under tighter tolerances at the first
    // start are left out of the fit (their residual would be integration noise), and reported.
    if data.iter().any(DataSet::is_dynamic) {
        let x0: Vec<f64> = params.iter().map(|p| p.start).collect();
        if let Ok(pred) = ev.predict(&x0) {
            ev.excluded = flatten(&pred)
                .iter()
                .map(|q| q.refined.is_some_and(|r| !r.converged))
                .collect();
            let included = ev.excluded.iter().filter(|e| !**e).count();
            if included <= params.len() {
                return Err(super::FitFailure::TooFewSettled {
                    included,
                    points,
                    tol_mw: opts.dynamic_power_tol_mw,
                    free: params.len(),
                }
                .into());
            }
        }
    }

    // Parameters no fitted value depends on at the first start are held there: the optimiser
    // moves the others (a column of zeros would only stall its trust region), and the error
    // analysis at the optimum reports them as not determined.
    let x0: Vec<f64> = params.iter().map(|p| p.start).collect();
    let all: Vec<usize> = (0..params.len()).collect();
    let held = untouched_parameters(&ev, &x0, opts);
    let active: Vec<usize> = all.iter().copied().filter(|j| !held.contains(j)).collect();
    let active = if active.is_empty() { all } else { active };

    let mut outcomes = Vec::new();
    let mut best: Option<(f64, Vec<f64>, bool, String)> = None;
    let mut first_error = None;
    for mut start in start_points(&params, opts.starts, opts.seed) {
        for &j in &held {
            start[j] = x0[j];
        }
        let (outcome, end) = run_start(&ev, opts, start, &active);
        if end.is_none() {
            first_error.get_or_insert_with(|| outcome.termination.clone());
        }
        outcomes.push(outcome);
        if let Some(e) = end {
            if best.as_ref().is_none_or(|b| e.0 < b.0) {
                best = Some(e);
            }
        }
    }
    let Some((_, x, converged, termination)) = best.filter(|b| b.0.is_finite()) else {
        return Err(super::FitFailure::NoModelStart {
            first_error: first_error.unwrap_or_default(),
        }
        .into());
    };
    let best_start = outcomes
        .iter()
        .find(|o| o.end == x)
        .map(|o| o.start.clone())
        .unwrap_or_else(|| params.iter().map(|p| p.start).collect());
    // Dynamic values that settled at the start but not at the optimum are left out too, and
    // the fit is resumed from the optimum without them (at most twice).
    let mut optimum = (x, converged, termination);
    resume_without_unsettled(&mut ev, opts, &active, points, &mut optimum, &mut outcomes);
    // Curves with cycles: the detected powers are not smooth in the parameters, and a single
    // start can end in a false minimum whose residuals pass every test. Starts from the optimum
    // moved out along the least determined directions look for a better one.
    let escaped = if data.iter().any(DataSet::is_dynamic) && opts.cycle_check_starts > 0 {
        escape_false_minimum(&ev, opts, &active, &mut optimum, &mut outcomes)?
    } else {
        None
    };
    let (x, converged, termination) = optimum;
    let held: Vec<&str> = held.iter().map(|&j| params[j].name()).collect();
    analyse(
        &ev,
        opts,
        Optimum {
            x,
            start: best_start,
            converged,
            termination,
            starts: outcomes,
            held: &held,
            escaped,
        },
    )
}

/// The parameters no fitted value depends on at `x0`: their Jacobian column (in their scale) is
/// at most [`UNTOUCHED_COLUMN`] of the largest. The optimiser holds them at their start (a
/// column of zeros would only stall its trust region).
fn untouched_parameters(ev: &Evaluator<'_>, x0: &[f64], opts: &FitOptions) -> Vec<usize> {
    let params = ev.params;
    let all: Vec<usize> = (0..params.len()).collect();
    match jacobian_columns(ev, x0, opts, false, &all) {
        Ok(cols) => {
            let norms: Vec<f64> = cols
                .iter()
                .zip(params)
                .map(|(c, p)| p.scale * c.iter().map(|v| v * v).sum::<f64>().sqrt())
                .collect();
            let top = norms.iter().copied().fold(0.0, f64::max);
            (0..params.len())
                .filter(|&j| top > 0.0 && norms[j] <= UNTOUCHED_COLUMN * top)
                .collect()
        }
        Err(_) => Vec::new(),
    }
}

/// The optimum: the parameters, whether the optimiser converged, and why it stopped.
type Found = (Vec<f64>, bool, String);

/// Leaves out the dynamic values that settled at the start but not at the `optimum`, and
/// resumes the fit from it without them (at most twice, and never below one more value than
/// parameters).
fn resume_without_unsettled(
    ev: &mut Evaluator<'_>,
    opts: &FitOptions,
    active: &[usize],
    points: usize,
    optimum: &mut Found,
    outcomes: &mut Vec<StartOutcome>,
) {
    for _ in 0..2 {
        let Ok(pred) = ev.predict(&optimum.0) else {
            break;
        };
        let newly: Vec<usize> = flatten(&pred)
            .iter()
            .enumerate()
            .filter(|(i, q)| {
                !ev.excluded.get(*i).copied().unwrap_or(false)
                    && q.refined.is_some_and(|r| !r.converged)
            })
            .map(|(i, _)| i)
            .collect();
        let included = ev.excluded.iter().filter(|e| !**e).count();
        if newly.is_empty() || included - newly.len() <= ev.params.len() {
            break;
        }
        if ev.excluded.is_empty() {
            ev.excluded = vec![false; points];
        }
        for i in newly {
            ev.excluded[i] = true;
        }
        let (outcome, end) = run_start(ev, opts, optimum.0.clone(), active);
        outcomes.push(outcome);
        let Some((_, x1, c1, t1)) = end else { break };
        *optimum = (x1, c1, t1);
    }
}

/// Curves with cycles: the detected powers are not smooth in the parameters, and a single start
/// can end in a false minimum whose residuals pass every test. Starts from the `optimum` moved
/// out along the least determined directions look for a better one; the first that is lower by
/// more than the optimiser's tolerance and one unit of χ² replaces it. Returns (χ² of the first,
/// χ² of the better) when one did.
fn escape_false_minimum(
    ev: &Evaluator<'_>,
    opts: &FitOptions,
    active: &[usize],
    optimum: &mut Found,
    outcomes: &mut Vec<StartOutcome>,
) -> crate::Result<Option<(f64, f64)>> {
    let best_cost = outcomes
        .iter()
        .filter(|o| o.end == optimum.0)
        .map(|o| o.cost)
        .fold(f64::INFINITY, f64::min);
    let checks = check_starts(ev, opts, &optimum.0, active, best_cost)?;
    for start in checks {
        let (outcome, end) = run_start(ev, opts, start, active);
        outcomes.push(outcome);
        if let Some((c, x1, c1, t1)) = end {
            if c1 && c < best_cost - 1.0 - opts.tolerance * best_cost {
                *optimum = (x1, c1, t1);
                return Ok(Some((best_cost, c)));
            }
        }
    }
    Ok(None)
}

/// Check starts around the optimum `x` (cost `chi2`): pairs ± along the least determined
/// directions of the scaled Jacobian, `check_distance` error bars out, kept inside the bounds.
fn check_starts(
    ev: &Evaluator<'_>,
    opts: &FitOptions,
    x: &[f64],
    active: &[usize],
    chi2: f64,
) -> crate::Result<Vec<Vec<f64>>> {
    let params = ev.params;
    let cols = jacobian_columns(ev, x, opts, false, active)?;
    let m = cols.first().map_or(0, Vec::len);
    let excluded = ev.excluded.iter().filter(|e| **e).count();
    let dof = (m - excluded).saturating_sub(active.len()).max(1);
    let s = (chi2 / dof as f64).sqrt();
    let mut js = DMatrix::<f64>::zeros(m, active.len());
    for (c, (col, &j)) in cols.iter().zip(active).enumerate() {
        for (i, v) in col.iter().enumerate() {
            js[(i, c)] = v * params[j].scale;
        }
    }
    let svd = js.svd(false, true);
    let Some(v_t) = svd.v_t else {
        return Ok(Vec::new());
    };
    let sv = svd.singular_values;
    let mut order: Vec<usize> = (0..sv.len()).collect();
    order.sort_by(|&a, &b| sv[a].total_cmp(&sv[b]));
    let mut out = Vec::new();
    for &k in order.iter().take(opts.cycle_check_starts.div_ceil(2)) {
        // Out to `check_distance` error bars, but at most half the parameters' scale.
        let reach = (opts.check_distance * s / sv[k].max(f64::MIN_POSITIVE)).min(0.5);
        for sign in [1.0, -1.0] {
            if out.len() == opts.cycle_check_starts {
                break;
            }
            let mut p = x.to_vec();
            for (c, &j) in active.iter().enumerate() {
                let r = &params[j];
                let mut v = x[j] + sign * reach * v_t[(k, c)] * r.scale;
                let room = match (r.lower, r.upper) {
                    (Some(lo), Some(hi)) => 1e-3 * (hi - lo),
                    _ => 1e-3 * r.scale,
                };
                if let Some(lo) = r.lower {
                    v = v.max(lo + room);
                }
                if let Some(hi) = r.upper {
                    v = v.min(hi - room);
                }
                p[j] = v;
            }
            out.push(p);
        }
    }
    Ok(out)
}

/// Where the optimiser ended, and how.
struct Optimum<'h> {
    x: Vec<f64>,
    start: Vec<f64>,
    converged: bool,
    termination: String,
    starts: Vec<StartOutcome>,
    /// Parameters no fitted value depended on at the start, held there.
    held: &'h [&'h str],
    /// A check start found a lower minimum: (χ² of the first, χ² of the better).
    escaped: Option<(f64, f64)>,
}

/// A parameter whose Jacobian column (in its scale) is at most this fraction of the largest at
/// the start is one the data do not touch; it is held at its start.
const UNTOUCHED_COLUMN: f64 = 1e-12;

/// Why the optimiser stopped, in words (the JSON's `termination`).
fn termination_text(t: &levenberg_marquardt::TerminationReason) -> String {
    use levenberg_marquardt::TerminationReason as T;
    match t {
        T::Converged { ftol, xtol } => match (ftol, xtol) {
            (true, true) => "converged: cost and parameters settled".into(),
            (true, false) => "converged: cost settled".into(),
            _ => "converged: parameters settled".into(),
        },
        T::ResidualsZero => "converged: residuals zero".into(),
        T::Orthogonal => "converged: gradient zero (residuals orthogonal to the Jacobian)".into(),
        T::LostPatience => "stopped: the evaluation budget was used up".into(),
        T::NoImprovementPossible(what) => format!("stopped: no improvement possible ({what})"),
        T::User(what) => format!("stopped: the model failed ({what})"),
        T::Numerical(what) => format!("stopped: a non-finite number ({what})"),
        T::NoParameters => "stopped: no parameters".into(),
        T::NoResiduals => "stopped: no residuals".into(),
        T::WrongDimensions(what) => format!("stopped: wrong dimensions ({what})"),
    }
}

/// One start of the optimiser: its outcome, and (cost, end, converged, termination) when the
/// start could be evaluated.
#[allow(clippy::type_complexity)]
fn run_start(
    ev: &Evaluator<'_>,
    opts: &FitOptions,
    start: Vec<f64>,
    active: &[usize],
) -> (StartOutcome, Option<(f64, Vec<f64>, bool, String)>) {
    let params = ev.params;
    let budget = ev.evaluations.load(Ordering::Relaxed) + opts.max_evaluations;
    let u0: Vec<f64> = active
        .iter()
        .map(|&j| params[j].transform.u(start[j]))
        .collect();
    let problem = Problem {
        ev,
        u: u0.clone(),
        active,
        held: start.clone(),
        opts,
        budget,
        last: RefCell::new(None),
        error: RefCell::new(None),
    };
    if problem.residuals_at(&u0).is_none() {
        let e = problem.error.borrow().clone().unwrap_or_default();
        let outcome = StartOutcome {
            start,
            end: Vec::new(),
            cost: f64::INFINITY,
            termination: format!("start not evaluated: {e}"),
        };
        return (outcome, None);
    }
    let (solved, report) = LevenbergMarquardt::new()
        .with_ftol(opts.tolerance)
        .with_xtol(opts.tolerance)
        .with_patience(opts.max_evaluations)
        .minimize(problem);
    let u = solved.u.clone();
    let x = solved.x(&u);
    let cost = solved
        .residuals_at(&u)
        .map_or(f64::INFINITY, |r| r.iter().map(|v| v * v).sum());
    let mut termination = termination_text(&report.termination);
    if let Some(e) = solved.error.borrow().as_ref() {
        termination.push_str(&format!(" (last model error: {e})"));
    }
    let converged = report.termination.was_successful();
    let outcome = StartOutcome {
        start,
        end: x.clone(),
        cost,
        termination: termination.clone(),
    };
    (outcome, Some((cost, x, converged, termination)))
}

/// Errors, correlations, identifiability and residual tables at the optimum `x`.
fn analyse(ev: &Evaluator<'_>, opts: &FitOptions, opt: Optimum<'_>) -> crate::Result<FitResult> {
    let Optimum {
        x,
        start,
        converged,
        termination,
        starts,
        held,
        escaped,
    } = opt;
    let params = ev.params;
    let data = ev.data;
    let pred = ev.predict(&x)?;
    let r0 = weighted(data, &pred, &ev.excluded);
    let n = params.len();
    // Residuals left out (unsettled dynamic points) count neither as points nor in χ².
    let m = r0.len() - ev.excluded.iter().filter(|e| **e).count();
    let chi2: f64 = r0.iter().map(|v| v * v).sum();
    let s = (chi2 / (m - n) as f64).sqrt();

    let js = scaled_jacobian(ev, &x, opts, r0.len())?;
    let tol = opts.undetermined_rel_error;
    let spectrum = Spectrum::of(&js, s, params, tol)?;
    let mut parameters = spectrum.parameters(params, &x, &start, tol);
    let elsewhere = undetermined_by_other_minima(&mut parameters, &starts, &x, chi2, s);
    let correlation = spectrum.correlation();
    let mut statements = Vec::new();
    if !elsewhere.is_empty() {
        statements.push(format!(
            "starts that ended elsewhere fit as well (χ² within {n}·s² of the best): {} differ(s) \
             between them by more than three error bars, so the data do not determine {}",
            elsewhere.join(", "),
            if elsewhere.len() == 1 { "it" } else { "them" }
        ));
    }
    let strong = strongly_correlated(&parameters, &correlation);
    statements.extend(identifiability_words(
        &parameters,
        &spectrum.directions,
        params,
        tol,
        !strong.is_empty(),
    ));

    let residuals = residual_tables(data, &pred, &ev.excluded);
    let clipped = residuals
        .iter()
        .flat_map(|t| t.rows.iter())
        .filter(|r| r.clipped && !r.excluded)
        .count();
    let mut warnings = fit_warnings(
        &parameters,
        held,
        &strong,
        escaped,
        converged.then_some(()).ok_or(termination.as_str()),
        clipped,
    );
    let integration = if data.iter().any(DataSet::is_dynamic) {
        // Detected transitions of cycles are not smooth in the parameters at the scale of the
        // integration tolerance: check that χ² rises over an error bar as the Jacobian says.
        check_linearity(ev, &js, &x, chi2, &mut parameters, &mut warnings)?;
        let check = integration_check(data, &pred, &ev.excluded, s, opts);
        warnings.extend(integration_warnings(&residuals, &check, opts));
        Some(check)
    } else {
        None
    };
    let stated: Vec<bool> = data
        .iter()
        .flat_map(|d| d.observed.iter().map(|o| o.errors.is_some()))
        .collect();
    let goodness = goodness::assess(&residuals, &stated, n);
    warnings.extend(goodness.failures.iter().cloned());
    let linear = parameters
        .iter()
        .all(|p| p.linearity.is_none_or(|r| r >= MIN_LINEARITY));
    let trusted = converged
        && linear
        && strong.is_empty()
        && escaped.is_none()
        && parameters.iter().all(|p| p.determined && !p.at_bound)
        && clipped == 0
        && integration.as_ref().is_none_or(|i| i.ok)
        && goodness.passed();
    Ok(FitResult {
        scene: ev.scene(&x)?,
        parameters,
        correlation,
        residuals,
        identifiability: Identifiability {
            directions: spectrum.directions,
            condition: spectrum.condition,
            statements,
        },
        points: m,
        chi2,
        residual_scale: s,
        converged,
        termination,
        evaluations: ev.evaluations.load(Ordering::Relaxed),
        starts,
        integration,
        goodness,
        trusted,
        warnings,
    })
}

/// The Jacobian of the weighted residuals at `x` by central differences, in each parameter's
/// scale: `J_s = J · diag(scale)`.
fn scaled_jacobian(
    ev: &Evaluator<'_>,
    x: &[f64],
    opts: &FitOptions,
    rows: usize,
) -> crate::Result<DMatrix<f64>> {
    let n = ev.params.len();
    let all: Vec<usize> = (0..n).collect();
    let cols = jacobian_columns(ev, x, opts, true, &all)?;
    let mut js = DMatrix::<f64>::zeros(rows, n);
    for (c, col) in cols.into_iter().enumerate() {
        for (i, v) in col.into_iter().enumerate() {
            js[(i, c)] = v * ev.params[c].scale;
        }
    }
    Ok(js)
}

/// The singular value decomposition of the scaled Jacobian and what follows from it: the
/// directions in parameter space with their relative errors, the covariance and the condition.
struct Spectrum {
    /// Singular values.
    sv: DVector<f64>,
    /// Right singular vectors, one per row.
    v_t: DMatrix<f64>,
    /// Singular values at or below this count as zero (their directions are not determined).
    floor: f64,
    /// Covariance in scaled units.
    cov: DMatrix<f64>,
    /// The directions, largest singular value first.
    directions: Vec<Direction>,
    /// The ratio of the largest to the smallest singular value.
    condition: f64,
}

impl Spectrum {
    /// The spectrum of `js` for residual scale `s`; directions with a relative error above `tol`
    /// are not determined.
    fn of(js: &DMatrix<f64>, s: f64, params: &[Resolved], tol: f64) -> crate::Result<Self> {
        let n = params.len();
        let svd = js.clone().svd(false, true);
        let v_t = svd.v_t.ok_or_else(|| {
            Error::from(crate::error::Internal {
                stage: crate::error::Stage::FIT,
                what: "singular value decomposition failed",
            })
        })?;
        let sv = svd.singular_values;
        let s_max = sv.iter().copied().fold(0.0, f64::max);
        let floor = s_max * 1e-10;
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| sv[b].total_cmp(&sv[a]));
        let names: Vec<&str> = params.iter().map(Resolved::name).collect();
        let directions: Vec<Direction> = order
            .iter()
            .map(|&k| {
                let rel_error = if sv[k] > floor {
                    s / sv[k]
                } else {
                    f64::INFINITY
                };
                let mut components: Vec<(String, f64)> = (0..n)
                    .map(|j| (names[j].to_string(), v_t[(k, j)]))
                    .filter(|(_, w)| w.abs() >= 0.05)
                    .collect();
                components.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
                // Sign convention: the largest component positive.
                if components.first().is_some_and(|c| c.1 < 0.0) {
                    components.iter_mut().for_each(|c| c.1 = -c.1);
                }
                Direction {
                    singular_value: sv[k],
                    rel_error,
                    determined: rel_error <= tol,
                    components,
                }
            })
            .collect();
        // Covariance in scaled units, C = s² V Σ⁻² Vᵀ, with vanishing singular values floored
        // so that the correlations of an undetermined pair still show (±1).
        let mut cov = DMatrix::<f64>::zeros(n, n);
        for k in 0..n {
            let w = s * s / sv[k].max(floor).max(f64::MIN_POSITIVE).powi(2);
            for a in 0..n {
                for b in 0..n {
                    cov[(a, b)] += w * v_t[(k, a)] * v_t[(k, b)];
                }
            }
        }
        let condition = if sv.iter().any(|&v| v <= 0.0) {
            f64::INFINITY
        } else {
            s_max / sv.iter().copied().fold(f64::INFINITY, f64::min)
        };
        Ok(Spectrum {
            sv,
            v_t,
            floor,
            cov,
            directions,
            condition,
        })
    }

    /// `true` when parameter `j` has a part in a direction the data do not determine.
    fn rank_deficient(&self, j: usize) -> bool {
        (0..self.sv.len()).any(|k| self.sv[k] <= self.floor && self.v_t[(k, j)].abs() > 1e-6)
    }

    /// The fitted parameters at `x` with their linear errors (determined when at most `tol`).
    fn parameters(
        &self,
        params: &[Resolved],
        x: &[f64],
        start: &[f64],
        tol: f64,
    ) -> Vec<FittedParameter> {
        params
            .iter()
            .enumerate()
            .map(|(j, p)| {
                let rel = if self.rank_deficient(j) {
                    f64::INFINITY
                } else {
                    self.cov[(j, j)].sqrt()
                };
                let determined = rel <= tol;
                // Within a thousandth of the range (or of the scale, for a one-sided bound).
                let width = match (p.lower, p.upper) {
                    (Some(lo), Some(hi)) => hi - lo,
                    _ => p.scale,
                };
                let at_bound = [p.lower, p.upper]
                    .iter()
                    .flatten()
                    .any(|b| (x[j] - b).abs() <= 1e-3 * width);
                FittedParameter {
                    name: p.name().to_string(),
                    unit: p.field.unit().to_string(),
                    field: p.field.keys().join("."),
                    value: x[j],
                    start: start[j],
                    standard_error: determined.then_some(rel * p.scale),
                    linear_error: rel * p.scale,
                    determined,
                    lower: p.lower,
                    upper: p.upper,
                    at_bound,
                    linearity: None,
                }
            })
            .collect()
    }

    /// The correlation matrix.
    fn correlation(&self) -> Vec<Vec<f64>> {
        let (n, cov) = (self.cov.nrows(), &self.cov);
        (0..n)
            .map(|a| {
                (0..n)
                    .map(|b| cov[(a, b)] / (cov[(a, a)] * cov[(b, b)]).sqrt())
                    .collect()
            })
            .collect()
    }
}

/// Other starts that ended as good a fit (χ² within n·s² of the best) but elsewhere: the
/// linearisation at one minimum cannot see them, so the parameters that differ by more than
/// three of their error bars are not determined. Returns their names.
fn undetermined_by_other_minima(
    parameters: &mut [FittedParameter],
    starts: &[StartOutcome],
    x: &[f64],
    chi2: f64,
    s: f64,
) -> Vec<String> {
    let n = parameters.len();
    let mut elsewhere: Vec<String> = Vec::new();
    for o in starts
        .iter()
        .filter(|o| o.cost <= chi2 + n as f64 * s * s && o.end.len() == n)
    {
        for (j, p) in parameters.iter_mut().enumerate() {
            let far = (o.end[j] - x[j]).abs() > 3.0 * p.linear_error;
            if far && p.determined {
                p.determined = false;
                p.standard_error = None;
            }
            if far && !elsewhere.contains(&p.name) {
                elsewhere.push(p.name.clone());
            }
        }
    }
    elsewhere
}

/// The warnings of the optimum itself: a false minimum escaped, the optimiser's termination
/// (`Err` with its words when it did not converge), transitions the model does not detect,
/// bounds, undetermined parameters (`held` at their start or not) and strong correlations.
fn fit_warnings(
    parameters: &[FittedParameter],
    held: &[&str],
    strong: &[(String, String, f64)],
    escaped: Option<(f64, f64)>,
    converged: std::result::Result<(), &str>,
    clipped: usize,
) -> Vec<String> {
    let mut warnings = Vec::new();
    if let Some((first, better)) = escaped {
        warnings.push(format!(
            "the first start ended in a false minimum (χ² = {first:.1}); a check start from it \
             found χ² = {better:.1}, which is the fit reported: the cycles' detected powers are \
             not smooth in the parameters, so give several starts (--starts) or fit the static \
             curves first"
        ));
    }
    if let Err(termination) = converged {
        warnings.push(format!("the optimiser did not converge: {termination}"));
    }
    if clipped > 0 {
        warnings.push(format!(
            "{clipped} transition(s) not detected by the model inside the heater programme \
             (their fitted value is the programme's end)"
        ));
    }
    for p in parameters.iter().filter(|p| p.at_bound) {
        warnings.push(format!(
            "{} ended on a bound: the best fit lies beyond it, so the other values are those of a \
             constrained fit and the error bars (which assume a free minimum) are not meaningful",
            p.name
        ));
    }
    for p in parameters.iter().filter(|p| !p.determined) {
        warnings.push(if held.contains(&p.name.as_str()) {
            format!(
                "{} is not determined: no fitted value depends on it, so it was held at its start \
                 ({}) while the others were fitted; fix it in the scene or add data that \
                 depend on it",
                p.name, p.start
            )
        } else {
            format!(
                "{} is not determined by these data (no error bar): its value is where the \
                 optimiser stopped, not a measurement; fix it in the scene or add data that \
                 determine it",
                p.name
            )
        });
    }
    for (a, b, rho) in strong {
        warnings.push(format!(
            "{a} and {b} are correlated at ρ = {rho:+.4} (|ρ| > {STRONG_CORRELATION}): the data \
             fix a combination of them, along a valley {:.0} times longer than it is wide; \
             their separate error bars rest on the linearisation along all of it",
            (1.0 - rho * rho)
                .max(f64::MIN_POSITIVE)
                .sqrt()
                .recip()
                .min(1e6)
        ));
    }
    warnings
}

/// Sets each determined parameter's linearity: the rise of χ² over one error bar either side
/// against the rise the Jacobian `js` predicts, with a warning where they disagree.
fn check_linearity(
    ev: &Evaluator<'_>,
    js: &DMatrix<f64>,
    x: &[f64],
    chi2: f64,
    parameters: &mut [FittedParameter],
    warnings: &mut Vec<String>,
) -> crate::Result<()> {
    let params = ev.params;
    for (j, p) in parameters.iter_mut().enumerate() {
        let Some(se) = p.standard_error else { continue };
        let rel = se / params[j].scale;
        let predicted: f64 = (0..js.nrows()).map(|i| (js[(i, j)] * rel).powi(2)).sum();
        let mut rise = 0.0;
        for sign in [1.0, -1.0] {
            let mut xs = x.to_vec();
            xs[j] += sign * se;
            let inside = params[j].lower.is_none_or(|lo| xs[j] >= lo)
                && params[j].upper.is_none_or(|hi| xs[j] <= hi);
            if !inside {
                xs[j] -= 2.0 * sign * se;
            }
            let r = weighted(ev.data, &ev.predict(&xs)?, &ev.excluded);
            rise += 0.5 * (r.iter().map(|v| v * v).sum::<f64>() - chi2);
        }
        let ratio = rise / predicted.max(f64::MIN_POSITIVE);
        p.linearity = Some(ratio);
        if let Some(w) = linearity_warning(&p.name, ratio) {
            warnings.push(w);
        }
    }
    Ok(())
}

/// The warnings of the dynamic values: those left out of the fit, those unsettled at the
/// optimum, and integration noise against the scatter.
fn integration_warnings(
    residuals: &[ResidualTable],
    check: &IntegrationCheck,
    opts: &FitOptions,
) -> Vec<String> {
    let mut warnings = Vec::new();
    let left_out: Vec<String> = residuals
        .iter()
        .flat_map(|t| t.rows.iter().map(move |r| (t, r)))
        .filter(|(_, r)| r.excluded)
        .map(|(t, r)| format!("{} line {} ({})", t.file, r.line, t.column))
        .collect();
    if !left_out.is_empty() {
        warnings.push(format!(
            "{} dynamic value(s) left out of the fit: their detected powers did not settle \
             within {} mW under tenfold tighter tolerances (at the start, or at an optimum \
             the fit was then resumed from): {}",
            left_out.len(),
            opts.dynamic_power_tol_mw,
            left_out.join(", ")
        ));
    }
    if check.unconverged > 0 {
        warnings.push(format!(
            "{} dynamic value(s) in the fit did not settle within {} mW at the optimum: \
             their residuals carry integration noise",
            check.unconverged, opts.dynamic_power_tol_mw
        ));
    }
    if check.ratio_to_scatter > 0.1 {
        warnings.push(format!(
            "integration noise {:.3e} (weighted) is {:.2} of the scatter: lower \
             dynamic_power_tol_mw or tighten solver.rtol",
            check.max_weighted_change, check.ratio_to_scatter
        ));
    }
    warnings
}

/// Correlations beyond this (in magnitude) make a fit untrusted: the pair is then fixed by the
/// data only as a combination, along a valley more than 7 times (`1/√(1 − ρ²)`) longer than it
/// is wide, and the separate error bars depend on the linearisation holding along all of it.
pub const STRONG_CORRELATION: f64 = 0.99;

/// Below this ratio of the χ² rise over one error bar to the linearisation's (curves with
/// cycles), the error bar is at least twice too small and the fit is not trusted.
pub const MIN_LINEARITY: f64 = 0.25;

/// Pairs of parameters (both determined) correlated beyond [`STRONG_CORRELATION`].
fn strongly_correlated(
    parameters: &[FittedParameter],
    correlation: &[Vec<f64>],
) -> Vec<(String, String, f64)> {
    let mut out = Vec::new();
    for (a, pa) in parameters.iter().enumerate() {
        for (b, pb) in parameters.iter().enumerate().skip(a + 1) {
            let rho = correlation[a][b];
            if pa.determined && pb.determined && rho.abs() > STRONG_CORRELATION {
                out.push((pa.name.clone(), pb.name.clone(), rho));
            }
        }
    }
    out
}

/// The warning of a linearity ratio below [`MIN_LINEARITY`], its figures bounded: a χ² that does
/// not rise (or falls) is said in words, not as an astronomically small error bar.
fn linearity_warning(name: &str, ratio: f64) -> Option<String> {
    if ratio >= MIN_LINEARITY {
        return None;
    }
    Some(if ratio <= 0.0 {
        format!(
            "the error bar of {name} is not reliable: moving it by one error bar does not raise \
             χ² at all, so the fit did not end at a minimum along it"
        )
    } else if ratio < 1e-4 {
        format!(
            "the error bar of {name} is not reliable: moving it by one error bar raises χ² by \
             less than 1e-4 of what the linearisation predicts (the error bar is more than 100 \
             times too small)"
        )
    } else {
        format!(
            "the error bar of {name} is not reliable: moving it by one error bar raises χ² by \
             {ratio:.2} of what the linearisation predicts (the error bar is about {:.1} times \
             too small)",
            ratio.sqrt().recip()
        )
    })
}

fn percent(v: f64) -> String {
    if v.is_finite() {
        format!("{:.2} %", 100.0 * v)
    } else {
        "unbounded".into()
    }
}

/// The identifiability report in words.
fn identifiability_words(
    fitted: &[FittedParameter],
    directions: &[Direction],
    params: &[Resolved],
    tol: f64,
    strongly_correlated: bool,
) -> Vec<String> {
    let scale_word = |name: &str| {
        let p = params.iter().find(|p| p.name() == name);
        match p {
            Some(p) if p.lower.is_some_and(|lo| lo >= 0.0) && p.start > 0.0 => "its value",
            _ => "its scale",
        }
    };
    let mut out = Vec::new();
    for d in directions.iter().filter(|d| !d.determined) {
        match d.components.as_slice() {
            [] => {}
            [(name, _)] if d.rel_error.is_finite() => out.push(format!(
                "{name} is not determined by these data: its 1σ range is {} of {}",
                percent(d.rel_error),
                scale_word(name)
            )),
            [(name, _)] => out.push(format!(
                "{name} is not determined by these data: no fitted value depends on it"
            )),
            comps => {
                let list: Vec<&str> = comps.iter().map(|c| c.0.as_str()).collect();
                let combo: Vec<String> =
                    comps.iter().map(|(n, w)| format!("{w:+.2}·Δ{n}")).collect();
                let moves: Vec<String> = comps
                    .iter()
                    .map(|(n, w)| format!("{} {n}", if *w > 0.0 { "raising" } else { "lowering" }))
                    .collect();
                out.push(format!(
                    "{} are not determined separately: along {} (each change relative to the \
                     parameter's scale) the fit is as good within {}; {} together leaves the \
                     residuals within the noise",
                    list.join(" and "),
                    combo.join(" "),
                    percent(d.rel_error),
                    moves.join(" while ")
                ));
            }
        }
    }
    let undetermined: Vec<&str> = fitted
        .iter()
        .filter(|p| !p.determined)
        .map(|p| p.name.as_str())
        .collect();
    if undetermined.is_empty() && strongly_correlated {
        out.push(format!(
            "each parameter's error is within the {} limit, but some are strongly correlated \
             (|ρ| > {STRONG_CORRELATION}, in the warnings): the data determine their \
             combination better than each alone",
            percent(tol)
        ));
    } else if undetermined.is_empty() {
        let worst = fitted
            .iter()
            .zip(params)
            .map(|(f, p)| (f.name.as_str(), f.linear_error / p.scale))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((name, rel)) = worst {
            out.push(format!(
                "all {} parameters are determined (the loosest, {name}, to {} of {}, within the \
                 {} limit)",
                fitted.len(),
                percent(rel),
                scale_word(name),
                percent(tol)
            ));
        }
    } else {
        out.push(format!(
            "no error bar is given for {}: the data do not determine {}",
            undetermined.join(", "),
            if undetermined.len() == 1 {
                "it"
            } else {
                "them"
            }
        ));
    }
    out
}

fn residual_tables(
    data: &[DataSet],
    pred: &[Vec<Vec<Predicted>>],
    excluded: &[bool],
) -> Vec<ResidualTable> {
    let mut out = Vec::new();
    let mut k = 0;
    for (ds, p) in data.iter().zip(pred) {
        for (o, pc) in ds.observed.iter().zip(p) {
            let f = o.unit.to_si;
            let rows = (0..ds.x.len())
                .map(|i| {
                    let w = o
                        .errors
                        .as_ref()
                        .map_or(o.quantity.default_weight(), |e| e[i]);
                    ResidualRow {
                        line: ds.lines[i],
                        x: ds.x[i] / ds.x_unit.to_si,
                        measured: o.values[i] / f,
                        fitted: pc[i].value / f,
                        residual: (pc[i].value - o.values[i]) / f,
                        weighted: (pc[i].value - o.values[i]) / w,
                        clipped: pc[i].clipped,
                        excluded: excluded.get(k + i).copied().unwrap_or(false),
                    }
                })
                .collect();
            k += ds.x.len();
            let stem = o.quantity.stem();
            out.push(ResidualTable {
                file: ds.origin.clone(),
                x_column: ds.x_name.clone(),
                column: format!("{stem}_{}", o.unit.suffix),
                rows,
            });
        }
    }
    out
}

/// The curves the model of `scene` gives at the x values of `data` (uncertainty columns are
/// kept): synthetic measurements, or a scene's prediction to compare with measured ones.
///
/// ```no_run
/// use hdi_tribology::fit::{model_curves, DataSet};
/// let grid = DataSet::from_csv_str("dc_voltage_v,touchdown_power_mw\n-0.5,0\n0,0\n0.5,0\n", "grid")?;
/// let curves = model_curves(&hdi_tribology::scene::Scene::paper(), &[grid])?;
/// println!("{:?} W", curves[0].observed[0].values);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn model_curves(scene: &Scene, data: &[DataSet]) -> crate::Result<Vec<DataSet>> {
    let base = serde_json::to_value(scene)
        .map_err(|e| Error::invalid("scene", format!("cannot be represented: {e}")))?;
    let o = FitOptions::default();
    let ev = Evaluator::new(
        base,
        &[],
        data,
        o.static_table_rel_tol,
        Refinement::new(o.dynamic_power_tol_mw * 1e-3),
    );
    let pred = ev.predict(&[])?;
    let mut out = data.to_vec();
    for (ds, p) in out.iter_mut().zip(&pred) {
        for (o, pc) in ds.observed.iter_mut().zip(p) {
            if let Some(i) = pc.iter().position(|q| q.clipped) {
                return Err(super::FitFailure::NotDetected {
                    origin: ds.origin.clone(),
                    quantity: o.quantity,
                    x: ds.x[i],
                }
                .into());
            }
            o.values = pc.iter().map(|q| q.value).collect();
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_linearity_warning_never_prints_an_absurd_factor() {
        assert_eq!(linearity_warning("a", MIN_LINEARITY), None);
        let w = linearity_warning("a", 0.04).unwrap();
        assert!(w.contains("about 5.0 times too small"), "{w}");
        // A ratio of 2e-307 once printed "about 6.7e153 times too small".
        for ratio in [2e-307, 1e-9, 0.0, -3.0, f64::MIN_POSITIVE] {
            let w = linearity_warning("a", ratio).unwrap();
            assert!(!w.contains('e') || !w.contains("e1"), "{w}");
            assert!(
                w.contains("more than 100 times too small")
                    || w.contains("did not end at a minimum"),
                "{ratio}: {w}"
            );
        }
    }
}
