//! The least-squares fit, its error bars and its identifiability report.

use std::cell::RefCell;
use std::sync::atomic::Ordering;

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::DMatrix;
use nalgebra_lm::{storage::Owned, DMatrix as LmMatrix, DVector as LmVector, Dyn};
use serde::Serialize;

use super::data::{DataError, DataSet};
use super::model::{weighted, Evaluator, Predicted, DEFAULT_WEIGHT_W};
use super::params::{resolve, FreeParameter, Resolved};
use super::FitError;
use crate::scene::Scene;
use crate::surface::Xoshiro256;
use crate::Error;

/// Settings of a fit.
///
/// ```
/// let o = hdi_tribology::fit::FitOptions::default();
/// assert_eq!((o.starts, o.undetermined_rel_error), (1, 0.5));
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
    /// A parameter, or a combination of parameters, whose 1σ error exceeds this fraction of its
    /// scale (its value, or half its range for one that may change sign) is reported as not
    /// determined, without an error bar.
    pub undetermined_rel_error: f64,
    /// Relative tolerance of the force tables for static curves (touchdown and take-off are
    /// refined on direct quadrature, so tables only guide the scan and a coarse one is as exact).
    pub static_table_rel_tol: f64,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            starts: 1,
            seed: 1,
            max_evaluations: 400,
            rel_step: 1e-3,
            undetermined_rel_error: 0.5,
            static_table_rel_tol: 1e-6,
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
            ("undetermined_rel_error", self.undetermined_rel_error, 1e6),
            ("static_table_rel_tol", self.static_table_rel_tol, 0.01),
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
    /// The residual divided by the uncertainty (1 mW where the file gives none).
    pub weighted: f64,
    /// The model did not detect this transition inside the heater programme (the value is the
    /// programme's end, a bound).
    pub clipped: bool,
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

/// How much the integration error of the cycles moves the residuals.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IntegrationCheck {
    /// Relative tolerance of the fit's cycles.
    pub rtol: f64,
    /// Largest change of a weighted residual when the tolerances are tightened tenfold.
    pub max_weighted_change: f64,
    /// That change over the residual scale `s`; it should be well below 1 (0.1 is the limit used).
    pub ratio_to_scatter: f64,
    /// Whether the integration noise is small enough not to drive the fit.
    pub ok: bool,
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
    /// Converged, no clipped transition, integration noise small.
    pub trusted: bool,
    /// What keeps the fit from being trusted, in words.
    pub warnings: Vec<String>,
}

/// The least-squares problem in the optimiser's unbounded variables.
struct Problem<'e, 'a> {
    ev: &'e Evaluator<'a>,
    u: Vec<f64>,
    rel_step: f64,
    budget: usize,
    /// Residuals at the last point that could be evaluated.
    last: RefCell<Option<(Vec<f64>, Vec<f64>)>>,
    /// The last evaluation error.
    error: RefCell<Option<String>>,
}

impl Problem<'_, '_> {
    fn x(&self, u: &[f64]) -> Vec<f64> {
        self.ev
            .params
            .iter()
            .zip(u)
            .map(|(p, &u)| p.transform.x(u))
            .collect()
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
        let r0 = self.residuals_at(&self.u)?;
        let cols = jacobian_columns(self.ev, &x, &r0, self.rel_step, false);
        let m = r0.len();
        let mut j = LmMatrix::zeros(m, self.u.len());
        for (c, (col, p)) in cols.iter().zip(self.ev.params).enumerate() {
            let col = match col {
                Ok(col) => col,
                Err(e) => {
                    *self.error.borrow_mut() = Some(e.to_string());
                    return None;
                }
            };
            let d = p.transform.dx_du(self.u[c]);
            for (i, v) in col.iter().enumerate() {
                j[(i, c)] = v * d;
            }
        }
        Some(j)
    }
}

/// `∂r/∂x_j` by finite differences (forward from `r0`, or central), each column on its own
/// thread with the `parallel` feature. Steps that would leave the bounds go the other way.
fn jacobian_columns(
    ev: &Evaluator<'_>,
    x: &[f64],
    r0: &[f64],
    rel_step: f64,
    central: bool,
) -> Vec<crate::Result<Vec<f64>>> {
    let column = |j: usize| -> crate::Result<Vec<f64>> {
        let p = &ev.params[j];
        let mut h = rel_step * p.scale;
        if p.upper.is_some_and(|hi| x[j] + h > hi) {
            h = -h;
        }
        let at = |h: f64| {
            let mut xs = x.to_vec();
            xs[j] += h;
            ev.residuals(&xs)
        };
        let plus = at(h)?;
        let (minus, span) = if central && p.lower.is_none_or(|lo| x[j] - h >= lo) {
            (at(-h)?, 2.0 * h)
        } else {
            (r0.to_vec(), h)
        };
        Ok(plus
            .iter()
            .zip(&minus)
            .map(|(a, b)| (a - b) / span)
            .collect())
    };
    let n = x.len();
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        (0..n).into_par_iter().map(column).collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        (0..n).map(column).collect()
    }
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
/// # Ok::<(), hdi_tribology::fit::FitError>(())
/// ```
pub fn fit(
    scene: &Scene,
    data: &[DataSet],
    free: &[FreeParameter],
    opts: &FitOptions,
) -> Result<FitResult, FitError> {
    opts.validate()?;
    scene.validate()?;
    if free.is_empty() {
        return Err(Error::invalid("--free", "name at least one parameter to fit").into());
    }
    let base = serde_json::to_value(scene)
        .map_err(|e| Error::invalid("scene", format!("cannot be represented: {e}")))?;
    let params = free
        .iter()
        .map(|p| resolve(&base, p))
        .collect::<crate::Result<Vec<_>>>()?;
    for (i, p) in params.iter().enumerate() {
        if let Some(q) = params[..i].iter().find(|q| q.path == p.path) {
            return Err(Error::invalid(
                format!("--free {}", p.name),
                format!("sets the same field as `{}`", q.name),
            )
            .into());
        }
    }
    let points: usize = data.iter().map(DataSet::len).sum();
    if points <= params.len() {
        let files: Vec<&str> = data.iter().map(|d| d.origin.as_str()).collect();
        return Err(FitError::Data(DataError {
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
    let ev = Evaluator::new(base, &params, data, opts.static_table_rel_tol);

    let mut outcomes = Vec::new();
    let mut best: Option<(f64, Vec<f64>, bool, String)> = None;
    let mut first_error = None;
    for start in start_points(&params, opts.starts, opts.seed) {
        let budget = ev.evaluations.load(Ordering::Relaxed) + opts.max_evaluations;
        let u0: Vec<f64> = params
            .iter()
            .zip(&start)
            .map(|(p, &x)| p.transform.u(x))
            .collect();
        let problem = Problem {
            ev: &ev,
            u: u0.clone(),
            rel_step: opts.rel_step,
            budget,
            last: RefCell::new(None),
            error: RefCell::new(None),
        };
        if problem.residuals_at(&u0).is_none() {
            let e = problem.error.borrow().clone().unwrap_or_default();
            first_error.get_or_insert_with(|| e.clone());
            outcomes.push(StartOutcome {
                start,
                end: Vec::new(),
                cost: f64::INFINITY,
                termination: format!("start not evaluated: {e}"),
            });
            continue;
        }
        let (solved, report) = LevenbergMarquardt::new()
            .with_patience(opts.max_evaluations)
            .minimize(problem);
        let u = solved.u.clone();
        let x = solved.x(&u);
        let cost = solved
            .residuals_at(&u)
            .map_or(f64::INFINITY, |r| r.iter().map(|v| v * v).sum());
        let mut termination = format!("{:?}", report.termination);
        if let Some(e) = solved.error.borrow().as_ref() {
            termination.push_str(&format!(" (last model error: {e})"));
        }
        let converged = report.termination.was_successful();
        outcomes.push(StartOutcome {
            start,
            end: x.clone(),
            cost,
            termination: termination.clone(),
        });
        if best.as_ref().is_none_or(|b| cost < b.0) {
            best = Some((cost, x, converged, termination));
        }
    }
    let Some((_, x, converged, termination)) = best.filter(|b| b.0.is_finite()) else {
        return Err(Error::from(crate::error::AnalysisError::NoModelStart {
            first_error: first_error.unwrap_or_default(),
        })
        .into());
    };
    let best_start = outcomes
        .iter()
        .find(|o| o.end == x)
        .map(|o| o.start.clone())
        .unwrap_or_else(|| params.iter().map(|p| p.start).collect());
    analyse(&ev, opts, x, best_start, converged, termination, outcomes)
}

/// Errors, correlations, identifiability and residual tables at the optimum `x`.
fn analyse(
    ev: &Evaluator<'_>,
    opts: &FitOptions,
    x: Vec<f64>,
    start: Vec<f64>,
    converged: bool,
    termination: String,
    starts: Vec<StartOutcome>,
) -> Result<FitResult, FitError> {
    let params = ev.params;
    let data = ev.data;
    let pred = ev.predict(&x, 1.0)?;
    let r0 = weighted(data, &pred);
    let (m, n) = (r0.len(), params.len());
    let chi2: f64 = r0.iter().map(|v| v * v).sum();
    let s = (chi2 / (m - n) as f64).sqrt();

    // Central differences, in each parameter's scale: J_s = J · diag(scale).
    let cols = jacobian_columns(ev, &x, &r0, opts.rel_step, true);
    let mut js = DMatrix::<f64>::zeros(m, n);
    for (c, col) in cols.into_iter().enumerate() {
        for (i, v) in col?.into_iter().enumerate() {
            js[(i, c)] = v * params[c].scale;
        }
    }
    let svd = js.clone().svd(false, true);
    let v_t = svd.v_t.ok_or_else(|| {
        Error::from(crate::error::AnalysisError::Internal {
            stage: crate::error::Stage::Fit,
            detail: "singular value decomposition failed".into(),
        })
    })?;
    let sv = svd.singular_values;
    let s_max = sv.iter().copied().fold(0.0, f64::max);
    // Singular values below this are treated as zero (their directions are not determined).
    let floor = s_max * 1e-10;
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| sv[b].total_cmp(&sv[a]));
    let tol = opts.undetermined_rel_error;
    let names: Vec<&str> = params.iter().map(|p| p.name.as_str()).collect();
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
    // Covariance in scaled units, C = s² V Σ⁻² Vᵀ, with vanishing singular values floored so
    // that the correlations of an undetermined pair still show (±1).
    let mut cov = DMatrix::<f64>::zeros(n, n);
    for k in 0..n {
        let w = s * s / sv[k].max(floor).max(f64::MIN_POSITIVE).powi(2);
        for a in 0..n {
            for b in 0..n {
                cov[(a, b)] += w * v_t[(k, a)] * v_t[(k, b)];
            }
        }
    }
    let rank_deficient = |j: usize| (0..n).any(|k| sv[k] <= floor && v_t[(k, j)].abs() > 1e-6);
    let parameters: Vec<FittedParameter> = params
        .iter()
        .enumerate()
        .map(|(j, p)| {
            let rel = if rank_deficient(j) {
                f64::INFINITY
            } else {
                cov[(j, j)].sqrt()
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
                name: p.name.clone(),
                unit: p.unit.clone(),
                field: p.path.join("."),
                value: x[j],
                start: start[j],
                standard_error: determined.then_some(rel * p.scale),
                linear_error: rel * p.scale,
                determined,
                lower: p.lower,
                upper: p.upper,
                at_bound,
            }
        })
        .collect();
    // Other starts that ended as good a fit (χ² within n·s² of the best) but elsewhere: the
    // linearisation at one minimum cannot see them, so the parameters that differ by more than
    // three of their error bars are not determined.
    let mut parameters = parameters;
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
    let correlation: Vec<Vec<f64>> = (0..n)
        .map(|a| {
            (0..n)
                .map(|b| cov[(a, b)] / (cov[(a, a)] * cov[(b, b)]).sqrt())
                .collect()
        })
        .collect();
    let mut statements = Vec::new();
    if !elsewhere.is_empty() {
        statements.push(format!(
            "starts that ended elsewhere fit as well (χ² within {n}·s² of the best): {} differ(s) \
             between them by more than three error bars, so the data do not determine {}",
            elsewhere.join(", "),
            if elsewhere.len() == 1 { "it" } else { "them" }
        ));
    }
    statements.extend(identifiability_words(&parameters, &directions, params, tol));
    let condition = if sv.iter().any(|&v| v <= 0.0) {
        f64::INFINITY
    } else {
        s_max / sv.iter().copied().fold(f64::INFINITY, f64::min)
    };

    let residuals = residual_tables(data, &pred);
    let mut warnings = Vec::new();
    if !converged {
        warnings.push(format!("the optimiser did not converge: {termination}"));
    }
    let clipped = residuals
        .iter()
        .flat_map(|t| t.rows.iter().map(move |r| (t, r)))
        .filter(|(_, r)| r.clipped)
        .count();
    if clipped > 0 {
        warnings.push(format!(
            "{clipped} transition(s) not detected by the model inside the heater programme \
             (their fitted value is the programme's end)"
        ));
    }
    for p in parameters.iter().filter(|p| p.at_bound) {
        warnings.push(format!(
            "{} ended on a bound: its error bar is not meaningful",
            p.name
        ));
    }
    let integration = if data.iter().any(DataSet::is_dynamic) {
        let tight = weighted(data, &ev.predict(&x, 0.1)?);
        let change = tight
            .iter()
            .zip(&r0)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let ratio = change / s.max(f64::MIN_POSITIVE);
        let scene = ev.scene(&x)?;
        let ok = ratio <= 0.1;
        if !ok {
            warnings.push(format!(
                "integration noise {change:.3e} (weighted) is {ratio:.2} of the scatter: tighten \
                 solver.rtol (now {:e})",
                scene.solver.rtol
            ));
        }
        Some(IntegrationCheck {
            rtol: scene.solver.rtol,
            max_weighted_change: change,
            ratio_to_scatter: ratio,
            ok,
        })
    } else {
        None
    };
    let trusted = converged && clipped == 0 && integration.as_ref().is_none_or(|i| i.ok);
    Ok(FitResult {
        scene: ev.scene(&x)?,
        parameters,
        correlation,
        residuals,
        identifiability: Identifiability {
            directions,
            condition,
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
        trusted,
        warnings,
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
) -> Vec<String> {
    let scale_word = |name: &str| {
        let p = params.iter().find(|p| p.name == name);
        match p {
            Some(p) if p.lower.is_some_and(|lo| lo >= 0.0) && p.start > 0.0 => "its value",
            _ => "its scale",
        }
    };
    let mut out = Vec::new();
    for d in directions.iter().filter(|d| !d.determined) {
        match d.components.as_slice() {
            [] => {}
            [(name, _)] => out.push(format!(
                "{name} is not determined by these data: its 1σ range is {} of {}",
                percent(d.rel_error),
                scale_word(name)
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
    if undetermined.is_empty() {
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

fn residual_tables(data: &[DataSet], pred: &[Vec<Vec<Predicted>>]) -> Vec<ResidualTable> {
    let mut out = Vec::new();
    for (ds, p) in data.iter().zip(pred) {
        for (o, pc) in ds.observed.iter().zip(p) {
            let f = o.unit.to_si;
            let rows = (0..ds.x.len())
                .map(|i| {
                    let w = o.errors.as_ref().map_or(DEFAULT_WEIGHT_W, |e| e[i]);
                    ResidualRow {
                        line: ds.lines[i],
                        x: ds.x[i] / ds.x_unit.to_si,
                        measured: o.values[i] / f,
                        fitted: pc[i].value / f,
                        residual: (pc[i].value - o.values[i]) / f,
                        weighted: (pc[i].value - o.values[i]) / w,
                        clipped: pc[i].clipped,
                    }
                })
                .collect();
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
/// # Ok::<(), hdi_tribology::fit::FitError>(())
/// ```
pub fn model_curves(scene: &Scene, data: &[DataSet]) -> Result<Vec<DataSet>, FitError> {
    let base = serde_json::to_value(scene)
        .map_err(|e| Error::invalid("scene", format!("cannot be represented: {e}")))?;
    let ev = Evaluator::new(base, &[], data, FitOptions::default().static_table_rel_tol);
    let pred = ev.predict(&[], 1.0)?;
    let mut out = data.to_vec();
    for (ds, p) in out.iter_mut().zip(&pred) {
        for (o, pc) in ds.observed.iter_mut().zip(p) {
            if let Some(i) = pc.iter().position(|q| q.clipped) {
                return Err(Error::from(crate::error::AnalysisError::NotDetected {
                    origin: ds.origin.clone(),
                    quantity: o.quantity.stem().to_string(),
                    x: ds.x[i],
                })
                .into());
            }
            o.values = pc.iter().map(|q| q.value).collect();
        }
    }
    Ok(out)
}
