//! Synthetic spin-stand measurements from the paper scene, with seeded noise, fitted back.
//!
//! Two fits: a static one (touchdown and take-off power at ten DC voltages, 20 points, four free
//! parameters) and one that adds a six-amplitude AC hysteresis curve (one dynamic cycle per
//! amplitude). Each prints the true values against the fitted ones with their standard errors,
//! the identifiability report, and the wall time against the time of one model evaluation
//! measured in the same run.
//!
//!     cargo run --release --example fit_synthetic [-- static|static-fd|dynamic|dynamic-direct|dynamic-starts|dynamic-tight|dynamic-from-truth]
//!
//! `static-fd` runs the four-parameter static fit twice, with the Jacobian from the transitions'
//! sensitivities (the default) and by finite differences of the whole model, for the ratio.

use std::time::Instant;

use hdi_tribology::fit::{fit, model_curves, DataSet, FitOptions, FitResult, FreeParameter};
use hdi_tribology::scene::Scene;
use hdi_tribology::surface::Xoshiro256;

#[path = "common/doc_numbers.rs"]
#[allow(dead_code)]
pub mod doc_numbers;

/// Seeded Gaussian noise of standard deviation `sd` (Box–Muller).
fn gauss(rng: &mut Xoshiro256, sd: f64) -> f64 {
    let (u, v) = (rng.next_open01(), rng.next_open01());
    sd * (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}

/// The model's curves on `grid` with noise of `sd_mw` added, as a data file would give them.
fn measure(truth: &Scene, grid: &str, origin: &str, sd_mw: f64, seed: u64) -> DataSet {
    let template = DataSet::from_csv_str(grid, origin).expect("grid");
    let mut d = model_curves(truth, &[template])
        .expect("model curves")
        .remove(0);
    let mut rng = Xoshiro256::new(seed);
    for o in &mut d.observed {
        for v in &mut o.values {
            *v += gauss(&mut rng, sd_mw * 1e-3);
        }
        // The noise is the measurement's stated uncertainty, as a data file's `_err_` column
        // gives it: the fit then tests its χ² against it.
        o.errors = Some(vec![sd_mw * 1e-3; o.values.len()]);
    }
    d
}

fn grid(x_col: &str, xs: &[f64]) -> String {
    let mut s = format!("{x_col},touchdown_power_mw,takeoff_power_mw\n");
    for x in xs {
        s.push_str(&format!("{x},0,0\n"));
    }
    s
}

/// CPU time of the whole process so far (s, every thread, user and system), from
/// `/proc/self/stat` (Linux; clock ticks of 10 ms); NaN elsewhere. Unlike the wall clock it does
/// not count time spent waiting for a core on a loaded machine.
fn process_cpu_seconds() -> f64 {
    let Ok(s) = std::fs::read_to_string("/proc/self/stat") else {
        return f64::NAN;
    };
    // Fields after the command name (which is in parentheses and may hold spaces).
    let rest = s.rsplit_once(')').map_or("", |r| r.1);
    let f: Vec<&str> = rest.split_whitespace().collect();
    let tick = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok());
    match (tick(11), tick(12)) {
        (Some(u), Some(s)) => (u + s) / 100.0,
        _ => f64::NAN,
    }
}

/// Wall and process CPU time of `f` (s).
fn timed<T>(f: impl FnOnce() -> T) -> (T, f64, f64) {
    let (t, c) = (Instant::now(), process_cpu_seconds());
    let out = f();
    (out, t.elapsed().as_secs_f64(), process_cpu_seconds() - c)
}

fn report(title: &str, r: &FitResult, truth: &[f64], secs: f64, one_eval: f64) {
    println!("\n== {title}");
    println!(
        "{:<24} {:>12} {:>12} {:>12} {:>8}",
        "parameter", "true", "fitted", "1σ error", "|Δ|/σ"
    );
    for (p, t) in r.parameters.iter().zip(truth) {
        match p.standard_error {
            Some(se) => println!(
                "{:<24} {:>12.4e} {:>12.4e} {:>12.3e} {:>8.2}",
                p.name,
                t,
                p.value,
                se,
                (p.value - t).abs() / se
            ),
            None => println!(
                "{:<24} {:>12.4e} {:>12.4e} {:>12} {:>8}",
                p.name, t, p.value, "not determined", "-"
            ),
        }
    }
    for s in &r.identifiability.statements {
        println!("  · {s}");
    }
    for w in &r.warnings {
        println!("  ! {w}");
    }
    if let Some(i) = &r.integration {
        println!(
            "  integration check: rtol {:e}, largest weighted change under 10× tighter tolerances {:.2e} ({:.3} of the scatter)",
            i.rtol, i.max_weighted_change, i.ratio_to_scatter
        );
    }
    println!(
        "  {} points, χ² {:.3}, s {:.3}, converged {}, trusted {}, {} model evaluations",
        r.points, r.chi2, r.residual_scale, r.converged, r.trusted, r.evaluations
    );
    let lin: Vec<String> = r
        .parameters
        .iter()
        .filter_map(|p| p.linearity.map(|l| format!("{} {l:.2}", p.name)))
        .collect();
    if !lin.is_empty() {
        println!(
            "  χ² rise over one error bar / the linearisation's: {}",
            lin.join(", ")
        );
    }
    if let Some(g) = &r.goodness.chi2 {
        println!(
            "  χ² against the stated uncertainties {:.1} for {} degrees of freedom, p = {:.2e}",
            g.chi2, g.dof, g.p_value
        );
    }
    if secs.is_finite() {
        println!(
            "  wall time {secs:.3} s; one model evaluation {one_eval:.4} s; ratio {:.1}",
            secs / one_eval
        );
    }
}

/// Times one model evaluation of `baseline` and the fit from `start` (with `opts`), then
/// reports both, wall and CPU time; returns the fit and, when made in two stages, the first
/// stage's evaluations.
///
/// With `static_first`, the fit is made in two stages, both timed: the first `static_first` data
/// sets alone (static curves: cheap), then every set from that fit's result.
#[allow(clippy::too_many_arguments)]
fn timed_fit(
    title: &str,
    baseline: &Scene,
    start: &Scene,
    data: &[DataSet],
    free: &[FreeParameter],
    truth: &[f64],
    opts: &FitOptions,
    static_first: Option<usize>,
) -> Result<(FitResult, Option<usize>), hdi_tribology::Error> {
    let (one, one_wall, one_cpu) = timed(|| model_curves(baseline, data));
    one?;
    let (r, wall, cpu) = timed(|| match static_first {
        Some(k) => {
            let first = fit(start, &data[..k], free, opts)?;
            println!(
                "  (stage 1, the static curve alone: {} evaluations, trusted {})",
                first.evaluations, first.trusted
            );
            fit(&first.scene, data, free, opts).map(|r| (r, Some(first.evaluations)))
        }
        None => fit(start, data, free, opts).map(|r| (r, None)),
    });
    let r = r?;
    report(title, &r.0, truth, wall, one_wall);
    println!(
        "  CPU time (all threads) {cpu:.2} s; one model evaluation {one_cpu:.3} s; ratio {:.1}",
        cpu / one_cpu
    );
    Ok(r)
}

/// The synthetic experiment: the true scene, the starting scene (every free parameter off by
/// 10–30 %), the free parameters, their true values and the DC voltages of the static curve.
pub struct Setup {
    truth: Scene,
    start: Scene,
    free: Vec<FreeParameter>,
    true_values: [f64; 4],
    dc: Vec<f64>,
}

impl Default for Setup {
    fn default() -> Self {
        Self::new()
    }
}

impl Setup {
    /// The experiment of this example.
    pub fn new() -> Self {
        // The truth: the paper scene with a contact potential of 0.2 V.
        let mut truth = Scene::paper();
        if let Some(e) = truth.electrostatic.as_mut() {
            e.contact_potential_v = 0.2;
        }
        // The starting scene: every free parameter off by 10–30 %.
        let mut start = truth.clone();
        start.surface.height_sigma_m = 0.6e-9;
        if let hdi_tribology::surface::PeakModel::RiceMaxima { sigma_m, .. } =
            &mut start.surface.peaks
        {
            *sigma_m = 0.6e-9;
        }
        if let Some(m) = start.intermolecular.as_mut() {
            m.hamaker_attractive_j = 1.3e-19;
        }
        if let Some(e) = start.electrostatic.as_mut() {
            e.contact_potential_v = 0.0;
        }
        start.heater.efficiency_m_per_w = 1.1e-7;
        let free = vec![
            FreeParameter::new("height_sigma_nm").bounded(0.3, 1.5),
            FreeParameter::new("hamaker_attractive_j").bounded(2e-20, 5e-19),
            FreeParameter::new("contact_potential_v").bounded(-1.0, 1.0),
            FreeParameter::new("efficiency_nm_per_mw").bounded(0.05, 0.2),
        ];
        Setup {
            truth,
            start,
            free,
            true_values: [0.7, 1e-19, 0.2, 0.1],
            dc: (0..10).map(|i| -0.4 + 1.2 * i as f64 / 9.0).collect(),
        }
    }

    /// The static curve plus a six-amplitude AC curve, σ, A and η free, from the paper scene as
    /// it is (φ = 0): `dynamic` fits in two stages (the static curve first), `dynamic-direct`
    /// both curves at once, `dynamic-from-truth` from the truth, `dynamic-starts` with three
    /// seeded starts per stage, `dynamic-tight` at rtol 1e-8. Returns the fit, the first
    /// stage's evaluations and the true values.
    #[allow(clippy::type_complexity)]
    pub fn dynamic(
        &self,
        which: &str,
        opts: &FitOptions,
    ) -> Result<(FitResult, Option<usize>, [f64; 3]), hdi_tribology::Error> {
        let mut truth = self.truth.clone();
        if let Some(e) = truth.electrostatic.as_mut() {
            e.contact_potential_v = 0.0;
        }
        let mut start = self.start.clone();
        if let Some(e) = start.electrostatic.as_mut() {
            e.contact_potential_v = 0.0;
        }
        // `dynamic-from-truth`: the same fit started at the truth (is a misfit the optimiser's
        // or the model's?).
        if which == "dynamic-from-truth" {
            start = truth.clone();
        }
        // `dynamic-tight`: cycles at rtol 1e-8 (the scene's is 1e-6).
        if which == "dynamic-tight" {
            for s in [&mut truth, &mut start] {
                s.solver.rtol = 1e-8;
                s.solver.atol_m = 1e-16;
            }
        }
        let free = [
            self.free[0].clone(),
            self.free[1].clone(),
            self.free[3].clone(),
        ];
        let true_values = [0.7, 1e-19, 0.1];
        let ac = [0.0, 0.2, 0.4, 0.6, 0.8, 1.0];
        let ac_grid = grid("ac_amplitude_v", &ac);
        let ac_data = measure(&truth, &ac_grid, "cycle_vs_vac.csv", 0.05, 11);
        let dc_grid = grid("dc_voltage_v", &self.dc);
        let static_data = measure(&truth, &dc_grid, "static_vs_vdc.csv", 0.05, 7);
        let data = [static_data, ac_data];
        // The static curve first, then both from there (`dynamic-direct`: both at once from the
        // start, which ends in a false minimum the goodness-of-fit tests reject).
        let staged = (which != "dynamic-direct").then_some(1);
        // `dynamic-starts`: three seeded starts in each stage (other minima as good as the best
        // mark the parameters that differ between them as not determined).
        let opts = if which == "dynamic-starts" {
            FitOptions { starts: 3, ..*opts }
        } else {
            *opts
        };
        let (r, stage1) = timed_fit(
            "static curve plus a 6-amplitude AC hysteresis curve (32 points), σ, A, η",
            // At the start the cycle detects no take-off at zero amplitude (clipped, fitted
            // against the programme's end): the baseline evaluation is timed at the truth.
            &truth,
            &start,
            &data,
            &free,
            &true_values,
            &opts,
            staged,
        )?;
        Ok((r, stage1, true_values))
    }
}

// Used by examples/docs_numbers.rs, which includes this file.
#[allow(dead_code)]
/// The numbers of the dynamic fits that docs/fit.md quotes, keyed `fit.<run>.…` (`run`:
/// `dynamic`, `direct`, `from_truth`): χ² and its p value against the stated uncertainties, the
/// smallest and largest distance of a fitted value from the truth in error bars, the largest
/// deviation from the truth in per cent, the first stage's evaluations, and each parameter's
/// linearity figure.
pub fn doc_numbers(
    run: &str,
    r: &FitResult,
    stage1: Option<usize>,
    truth: &[f64],
) -> Vec<doc_numbers::Quoted> {
    use doc_numbers::Quoted;
    let at = |what: &str| format!("fit.{run}.{what}");
    let mut q = vec![Quoted::new(&at("chi2"), r.chi2)];
    if let Some(g) = &r.goodness.chi2 {
        q.push(Quoted::count(&at("dof"), g.dof as usize));
        q.push(Quoted::power_of_ten(&at("p"), g.p_value).within(0.5 * g.p_value));
        q.push(Quoted::new(&at("p_decimal"), g.p_value));
    }
    if let Some(n) = stage1 {
        q.push(Quoted::count(&at("stage1_evaluations"), n));
    }
    let distances: Vec<f64> = r
        .parameters
        .iter()
        .zip(truth)
        .filter_map(|(p, t)| p.standard_error.map(|se| (p.value - t).abs() / se))
        .collect();
    if !distances.is_empty() {
        let lo = distances.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = distances.iter().copied().fold(0.0, f64::max);
        q.push(Quoted::new(&at("se_distance_min"), lo));
        q.push(Quoted::new(&at("se_distance_max"), hi));
    }
    // The largest deviation of a fitted value from the truth, relative to the truth (%).
    let rel = r
        .parameters
        .iter()
        .zip(truth)
        .map(|(p, t)| 100.0 * ((p.value - t) / t).abs())
        .fold(0.0, f64::max);
    q.push(Quoted::new(&at("max_rel_dev_pct"), rel));
    for p in &r.parameters {
        if let Some(l) = p.linearity {
            q.push(Quoted::new(&at(&format!("linearity.{}", p.name)), l));
        }
    }
    q
}

fn main() -> Result<(), hdi_tribology::Error> {
    let which = std::env::args().nth(1).unwrap_or_else(|| "both".into());
    let setup = Setup::new();
    let Setup {
        truth,
        start,
        free,
        true_values,
        dc,
    } = &setup;
    let static_data = measure(
        truth,
        &grid("dc_voltage_v", dc),
        "static_vs_vdc.csv",
        0.05,
        7,
    );
    let opts = FitOptions::default();

    if which == "static" || which == "both" || which == "static-fd" {
        timed_fit(
            "static: touchdown and take-off at 10 DC voltages (20 points), 4 parameters",
            start,
            start,
            std::slice::from_ref(&static_data),
            free,
            true_values,
            &opts,
            None,
        )?;
    }
    if which == "static-fd" {
        // The same fit with the whole Jacobian by finite differences: the baseline of the
        // transitions' sensitivities, in the same run.
        timed_fit(
            "the same, Jacobian by finite differences of the whole model",
            start,
            start,
            std::slice::from_ref(&static_data),
            free,
            true_values,
            &FitOptions {
                finite_difference_jacobian: true,
                ..opts
            },
            None,
        )?;
    }
    if which == "static" || which == "both" {
        // The same data, touchdown only, for σ and A alone: the combination the issue asks about.
        let td_only = {
            let mut d = static_data.clone();
            d.observed
                .retain(|o| o.quantity == hdi_tribology::fit::Quantity::TouchdownPower);
            d
        };
        let pair = &free[..2];
        let mut near = truth.clone();
        near.surface = start.surface.clone();
        near.intermolecular = start.intermolecular.clone();
        let multi = FitOptions { starts: 6, ..opts };
        let r = fit(&near, &[td_only], pair, &multi)?;
        report(
            "touchdown alone, σ and A free, 6 starts",
            &r,
            &true_values[..2],
            f64::NAN,
            f64::NAN,
        );
    }
    if which == "static" || which == "both" {
        // Four parameters that leave the force tables as they are: one table for the whole fit.
        let free4 = vec![
            FreeParameter::new("contact_potential_v").bounded(-1.0, 1.0),
            FreeParameter::new("efficiency_nm_per_mw").bounded(0.05, 0.2),
            FreeParameter::new("nominal_clearance_nm").bounded(7.0, 13.0),
            FreeParameter::new("stiffness_n_per_m").bounded(1e5, 1e6),
        ];
        let mut s4 = truth.clone();
        if let Some(e) = s4.electrostatic.as_mut() {
            e.contact_potential_v = 0.0;
        }
        s4.heater.efficiency_m_per_w = 1.1e-7;
        s4.nominal_clearance_m = 1.05e-8;
        s4.air_bearing = hdi_tribology::force::AirBearingModel::Linear {
            stiffness_n_per_m: 3.3e5,
            damping_n_s_per_m: 0.0548,
        };
        timed_fit(
            "static, 20 points, φ, η, h0 and k free (the force tables are built once)",
            &s4,
            &s4,
            std::slice::from_ref(&static_data),
            &free4,
            &[0.2, 0.1, 10.0, 3e5],
            &opts,
            None,
        )?;
    }
    if which.starts_with("dynamic") || which == "both" {
        setup.dynamic(&which, &opts)?;
    }
    Ok(())
}
