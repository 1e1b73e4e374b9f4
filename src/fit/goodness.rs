//! Whether the fitted model follows the data: the tests behind [`super::FitResult::trusted`]
//! beyond the optimiser's convergence.
//!
//! A converged fit can still be wrong: a model that cannot follow the data (a missing physical
//! effect, a parameter held at a wrong value) converges to the least bad compromise and reports
//! error bars scaled by its own misfit. Four tests look for that, each at the significance level
//! [`ALPHA`]:
//!
//! - **χ² against the stated uncertainties**, when the data files give an uncertainty for every
//!   fitted value: `P(χ²_ν ≥ χ²)` with `ν = m − n` degrees of freedom.
//! - **The scale of each measured column against the others**: a column whose weighted residuals
//!   are much larger than the rest is one the model does not follow. With stated uncertainties the
//!   column's own χ² is tested (`ν_k = m_k ν / m` degrees of freedom); without, an F-test of its
//!   mean square against the other columns'.
//! - **Runs of residual signs** along x in each column (Wald–Wolfowitz, normal approximation,
//!   from 8 values on): too few runs mean a systematic misfit that the scatter hides.
//! - **The mean of each column's residuals** against zero, from [`MIN_MEAN_POINTS`] values on:
//!   residuals that sit on one side of the data (a curve the model cannot reach, a parameter held
//!   on a bound) are a misfit whatever the weights. With stated uncertainties `z = w̄·√m_k`
//!   (normal); without, Student's `t = w̄/(s_k/√m_k)` with the column's scatter about its mean
//!   on `m_k − 1 − n m_k/m` degrees of freedom (the fit's `n` parameters take their share).
//!   At an exact least-squares optimum the residuals' mean varies less than free noise's, so
//!   the test errs on the side of passing.

use std::f64::consts::SQRT_2;

use serde::Serialize;
use statrs::function::{beta::beta_reg, erf::erfc, gamma::gamma_ur};

use super::ResidualTable;

/// Significance level of each test: a fit whose residuals are as the noise makes them fails one
/// with a probability of about this per test.
pub const ALPHA: f64 = 1e-3;

/// Fewest values in a column for the runs test (below it the test cannot reject anything at
/// [`ALPHA`]).
pub const MIN_RUNS_POINTS: usize = 8;

/// Fewest values in a column for the test of its mean.
pub const MIN_MEAN_POINTS: usize = 4;

/// The χ² test of the whole fit against the stated uncertainties.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Chi2Test {
    /// Sum of the squared residuals over their stated uncertainties.
    pub chi2: f64,
    /// Degrees of freedom, fitted values minus free parameters.
    pub dof: f64,
    /// `P(χ²_dof ≥ chi2)`.
    pub p_value: f64,
}

/// The tests of one measured column.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ColumnCheck {
    /// Data file.
    pub file: String,
    /// Measured column as written.
    pub column: String,
    /// Fitted values in it (left-out values not counted).
    pub points: usize,
    /// Mean square of its weighted residuals.
    pub mean_square: f64,
    /// Whether its values have stated uncertainties.
    pub stated: bool,
    /// `p` of a residual scale this large: its own χ² (stated uncertainties) or the F-test
    /// against the other columns; `None` where neither applies (a single column without
    /// uncertainties, too few degrees of freedom).
    pub scale_p_value: Option<f64>,
    /// Runs of residual signs along x; `None` below [`MIN_RUNS_POINTS`] values.
    pub runs: Option<usize>,
    /// `p` of so few runs.
    pub runs_p_value: Option<f64>,
    /// Mean of its weighted residuals.
    pub mean: f64,
    /// Two-sided `p` of a mean this far from zero; `None` below [`MIN_MEAN_POINTS`] values or
    /// without degrees of freedom left.
    pub mean_p_value: Option<f64>,
}

/// The goodness-of-fit tests of a fit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Goodness {
    /// Significance level of each test.
    pub alpha: f64,
    /// The χ² test against the stated uncertainties, when every fitted value has one.
    pub chi2: Option<Chi2Test>,
    /// The tests of each measured column.
    pub columns: Vec<ColumnCheck>,
    /// Each failed test in words (empty: the residuals look like noise).
    pub failures: Vec<String>,
}

impl ColumnCheck {
    /// Whether every residual of the column has the same sign (its mean test says how unlikely).
    pub fn residuals_one_signed(&self) -> bool {
        self.runs == Some(1)
    }
}

impl Goodness {
    /// Whether every test passed.
    pub fn passed(&self) -> bool {
        self.failures.is_empty()
    }
}

/// `P(χ²_ν ≥ x)`.
fn chi2_sf(x: f64, nu: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    gamma_ur(0.5 * nu, 0.5 * x)
}

/// `P(F_{ν1,ν2} ≥ f)`.
fn f_sf(f: f64, nu1: f64, nu2: f64) -> f64 {
    if f <= 0.0 {
        return 1.0;
    }
    beta_reg(0.5 * nu2, 0.5 * nu1, nu2 / (nu2 + nu1 * f))
}

/// `P(|T_ν| ≥ t)` of Student's t.
fn t_two_sided(t: f64, nu: f64) -> f64 {
    beta_reg(0.5 * nu, 0.5, nu / (nu + t * t))
}

/// Mean of `w` and the two-sided `p` of a mean this far from zero (see the module's words);
/// `free_share` is the fit's parameters' share of this column.
pub fn mean_test(w: &[f64], stated: bool, free_share: f64) -> (f64, Option<f64>) {
    let m = w.len();
    if m == 0 {
        return (0.0, None);
    }
    let mean = w.iter().sum::<f64>() / m as f64;
    if m < MIN_MEAN_POINTS {
        return (mean, None);
    }
    if stated {
        return (mean, Some(erfc(mean.abs() * (m as f64).sqrt() / SQRT_2)));
    }
    let nu = m as f64 - 1.0 - free_share;
    if nu < 1.0 {
        return (mean, None);
    }
    let ss: f64 = w.iter().map(|v| (v - mean).powi(2)).sum();
    if ss <= 0.0 {
        // Every residual the same: no scatter to measure the mean against.
        return (mean, Some(if mean == 0.0 { 1.0 } else { 0.0 }));
    }
    let t = mean / (ss / nu / m as f64).sqrt();
    (mean, Some(t_two_sided(t, nu)))
}

/// `P(Z ≤ z)` of the standard normal.
fn normal_cdf(z: f64) -> f64 {
    0.5 * erfc(-z / SQRT_2)
}

/// Runs of signs of `residuals` ordered by `x`, and the probability of so few under random
/// signs; `None` below [`MIN_RUNS_POINTS`] non-zero residuals.
pub fn runs_test(x: &[f64], residuals: &[f64]) -> Option<(usize, f64)> {
    let mut order: Vec<usize> = (0..x.len()).filter(|&i| residuals[i] != 0.0).collect();
    order.sort_by(|&a, &b| x[a].total_cmp(&x[b]));
    let n = order.len();
    if n < MIN_RUNS_POINTS {
        return None;
    }
    let pos = order.iter().filter(|&&i| residuals[i] > 0.0).count();
    let neg = n - pos;
    let runs = 1 + order
        .windows(2)
        .filter(|w| (residuals[w[0]] > 0.0) != (residuals[w[1]] > 0.0))
        .count();
    if pos == 0 || neg == 0 {
        // Every residual on one side: probability 2·2⁻ⁿ under random signs.
        return Some((1, 0.5_f64.powi(n as i32 - 1)));
    }
    let (p, q, n) = (pos as f64, neg as f64, n as f64);
    let mean = 2.0 * p * q / n + 1.0;
    let var = (mean - 1.0) * (mean - 2.0) / (n - 1.0);
    if var <= 0.0 {
        return Some((runs, 1.0));
    }
    // Continuity correction of half a run.
    Some((runs, normal_cdf((runs as f64 + 0.5 - mean) / var.sqrt())))
}

/// The tests on the residual `tables` of a fit with `free` parameters; `stated[k]` says whether
/// the values of table `k` carry stated uncertainties (its `weighted` residuals are then over
/// them). Left-out rows are not counted.
pub fn assess(tables: &[ResidualTable], stated: &[bool], free: usize) -> Goodness {
    struct Col {
        x: Vec<f64>,
        w: Vec<f64>,
        chi2: f64,
    }
    let cols: Vec<Col> = tables
        .iter()
        .map(|t| {
            let rows: Vec<_> = t.rows.iter().filter(|r| !r.excluded).collect();
            let w: Vec<f64> = rows.iter().map(|r| r.weighted).collect();
            Col {
                x: rows.iter().map(|r| r.x).collect(),
                chi2: w.iter().map(|v| v * v).sum(),
                w,
            }
        })
        .collect();
    let m: usize = cols.iter().map(|c| c.w.len()).sum();
    let chi2: f64 = cols.iter().map(|c| c.chi2).sum();
    let dof = m as f64 - free as f64;
    let all_stated = !stated.is_empty() && stated.iter().all(|&s| s);
    let mut failures = Vec::new();
    let chi2_test = (all_stated && dof > 0.0).then(|| {
        let p = chi2_sf(chi2, dof);
        if p < ALPHA {
            failures.push(format!(
                "χ² = {chi2:.1} for {dof} degrees of freedom against the stated uncertainties \
                 (p = {p:.1e}): the model does not fit the data within their uncertainties"
            ));
        }
        Chi2Test {
            chi2,
            dof,
            p_value: p,
        }
    });
    let mut columns = Vec::new();
    for (k, (t, c)) in tables.iter().zip(&cols).enumerate() {
        let mk = c.w.len();
        let nu_k = if m > 0 {
            mk as f64 * dof / m as f64
        } else {
            0.0
        };
        let is_stated = stated.get(k).copied().unwrap_or(false);
        let scale_p = if mk == 0 || nu_k <= 0.0 {
            None
        } else if is_stated {
            Some(chi2_sf(c.chi2, nu_k))
        } else {
            let nu_rest = dof - nu_k;
            let rest = chi2 - c.chi2;
            (tables.len() > 1 && nu_rest > 0.0 && rest > 0.0)
                .then(|| f_sf((c.chi2 / nu_k) / (rest / nu_rest), nu_k, nu_rest))
        };
        if let Some(p) = scale_p.filter(|&p| p < ALPHA) {
            failures.push(if is_stated {
                format!(
                    "{} ({}): its residuals are {:.1} times its stated uncertainties (rms, \
                     p = {p:.1e}): the model does not follow this curve",
                    t.file,
                    t.column,
                    (c.chi2 / nu_k).sqrt()
                )
            } else {
                format!(
                    "{} ({}): its weighted residuals are {:.1} times those of the other curves \
                     (rms, F-test p = {p:.1e}): the model does not follow this curve as it follows \
                     the others",
                    t.file,
                    t.column,
                    ((c.chi2 / nu_k) / ((chi2 - c.chi2) / (dof - nu_k))).sqrt()
                )
            });
        }
        let runs = runs_test(&c.x, &c.w);
        if let Some((r, p)) = runs.filter(|&(_, p)| p < ALPHA) {
            failures.push(format!(
                "{} ({}): {r} runs of residual signs in {mk} values along x (p = {p:.1e}): a \
                 systematic misfit",
                t.file, t.column
            ));
        }
        let share = if m > 0 {
            free as f64 * mk as f64 / m as f64
        } else {
            0.0
        };
        let (mean, mean_p) = mean_test(&c.w, is_stated, share);
        if let Some(p) = mean_p.filter(|&p| p < ALPHA) {
            let below = c.w.iter().filter(|v| **v < 0.0).count();
            failures.push(format!(
                "{} ({}): its residuals average {mean:+.3} (weighted; {below} of {mk} negative, \
                 p = {p:.1e}): the model curve sits {} the data",
                t.file,
                t.column,
                if mean < 0.0 { "below" } else { "above" }
            ));
        }
        columns.push(ColumnCheck {
            file: t.file.clone(),
            column: t.column.clone(),
            points: mk,
            mean_square: if mk > 0 { c.chi2 / mk as f64 } else { 0.0 },
            stated: is_stated,
            scale_p_value: scale_p,
            runs: runs.map(|r| r.0),
            runs_p_value: runs.map(|r| r.1),
            mean,
            mean_p_value: mean_p,
        });
    }
    Goodness {
        alpha: ALPHA,
        chi2: chi2_test,
        columns,
        failures,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distribution_tails_match_closed_forms() {
        // χ²₂: P(X ≥ x) = e^{−x/2}
        for x in [0.5, 2.0, 9.0] {
            assert!((chi2_sf(x, 2.0) - (-0.5 * x).exp()).abs() < 1e-14);
        }
        // F_{2,2}: P(F ≥ f) = 1/(1 + f)
        for f in [0.5, 1.0, 7.0] {
            assert!((f_sf(f, 2.0, 2.0) - 1.0 / (1.0 + f)).abs() < 1e-14);
        }
        assert!((normal_cdf(0.0) - 0.5).abs() < 1e-16);
        assert!((normal_cdf(-3.090_232_306_167_813) - 1e-3).abs() < 1e-12);
    }

    #[test]
    fn student_t_tails_match_closed_forms() {
        // ν = 1 is Cauchy: P(|T| ≥ t) = 1 − 2 atan(t)/π; ν = 2: 1 − t/√(2 + t²).
        for t in [0.3, 1.0, 12.0] {
            let cauchy = 1.0 - 2.0 * f64::atan(t) / std::f64::consts::PI;
            assert!((t_two_sided(t, 1.0) - cauchy).abs() < 1e-14);
            assert!((t_two_sided(t, 2.0) - (1.0 - t / (2.0 + t * t).sqrt())).abs() < 1e-14);
        }
        // One-signed residuals far from zero fail; symmetric ones pass.
        let off = [-58.0, -61.0, -65.0, -59.0, -62.0, -60.0, -64.0, -63.0];
        assert!(mean_test(&off, false, 2.0).1.unwrap() < 1e-6);
        let sym = [-1.0, 1.0, -0.5, 0.5, -2.0, 2.0];
        assert!((mean_test(&sym, false, 1.0).1.unwrap() - 1.0).abs() < 1e-12);
        assert!(mean_test(&sym[..3], false, 0.0).1.is_none());
    }

    #[test]
    fn runs_of_signs() {
        let x: Vec<f64> = (0..10).map(f64::from).collect();
        // alternating: 10 runs, as many as there can be
        let alt: Vec<f64> = (0..10)
            .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let (r, p) = runs_test(&x, &alt).unwrap();
        assert_eq!(r, 10);
        assert!(p > 0.99);
        // five up then five down: 2 runs
        let two: Vec<f64> = (0..10).map(|i| if i < 5 { 1.0 } else { -1.0 }).collect();
        let (r, p) = runs_test(&x, &two).unwrap();
        assert_eq!(r, 2);
        assert!(p < 0.01);
        // the order is x's, not the slice's
        let mut xs = x.clone();
        xs.reverse();
        assert_eq!(runs_test(&xs, &two).unwrap().0, 2);
        assert!(runs_test(&x[..5], &two[..5]).is_none());
    }
}
