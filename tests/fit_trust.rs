//! `trusted` means what it says: each fit below is one the fitter once called trusted, and each
//! is now untrusted with a warning that says why.

use hdi_tribology::fit::goodness::ALPHA;
use hdi_tribology::fit::{
    fit, model_curves, DataSet, FitOptions, FreeParameter, STRONG_CORRELATION,
};
use hdi_tribology::scene::Scene;
use hdi_tribology::surface::Xoshiro256;

fn gauss(rng: &mut Xoshiro256) -> f64 {
    let (u, v) = (rng.next_open01(), rng.next_open01());
    (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}

/// Touchdown power at 8 DC voltages from `truth`, with 0.05 mW of seeded noise; `stated` adds
/// that noise as the uncertainty column.
fn touchdown_curve(truth: &Scene, seed: u64, stated: bool) -> DataSet {
    let mut grid = String::from("dc_voltage_v,touchdown_power_mw\n");
    for i in 0..8 {
        grid.push_str(&format!("{},0\n", -0.45 + 0.15 * i as f64));
    }
    let template = DataSet::from_csv_str(&grid, "touchdown_vs_vdc.csv").unwrap();
    let mut d = model_curves(truth, &[template]).unwrap().remove(0);
    let mut rng = Xoshiro256::new(seed);
    for v in &mut d.observed[0].values {
        *v += 0.05e-3 * gauss(&mut rng);
    }
    if stated {
        d.observed[0].errors = Some(vec![0.05e-3; d.x.len()]);
    }
    d
}

fn truth() -> Scene {
    let mut s = Scene::paper();
    s.electrostatic.as_mut().unwrap().contact_potential_v = 0.15;
    s
}

fn free(spec: &[&str]) -> Vec<FreeParameter> {
    spec.iter().map(|f| f.parse().unwrap()).collect()
}

#[test]
fn a_parameter_on_its_bound_with_one_signed_residuals_is_not_trusted() {
    // η is 0.1 nm/mW; bounded to 0.15–0.2 the model's touchdown sits about 24 mW below every
    // measured one. Without stated uncertainties there is no χ² test and 8 values are too few
    // for the runs test to reject all-one-sign at α: the test of the mean catches it.
    let t = truth();
    let mut start = t.clone();
    start.heater.efficiency_m_per_w = 1.6e-7;
    let bounded = free(&["efficiency_nm_per_mw=0.15:0.2", "contact_potential_v=-1:1"]);
    let r = fit(
        &start,
        &[touchdown_curve(&t, 7, false)],
        &bounded,
        &FitOptions::default(),
    )
    .unwrap();
    assert!(r.converged, "{:?}", r.warnings);
    assert!(r.parameters[0].at_bound, "{:?}", r.parameters[0]);
    assert!(!r.trusted, "{:?}", r.warnings);
    assert!(
        r.warnings
            .iter()
            .any(|w| w.starts_with("efficiency_nm_per_mw ended on a bound")),
        "{:?}",
        r.warnings
    );
    let col = &r.goodness.columns[0];
    assert!(col.residuals_one_signed(), "{col:?}");
    assert!(col.mean_p_value.unwrap() < ALPHA, "{col:?}");
    assert!(
        r.warnings
            .iter()
            .any(|w| w.contains("8 of 8 negative") && w.contains("sits below the data")),
        "{:?}",
        r.warnings
    );
    // With the noise stated as the uncertainty, χ² against its distribution fails as well.
    let r = fit(
        &start,
        &[touchdown_curve(&t, 7, true)],
        &bounded,
        &FitOptions::default(),
    )
    .unwrap();
    assert!(!r.trusted);
    let chi2 = r.goodness.chi2.as_ref().unwrap();
    assert!(chi2.p_value < ALPHA && chi2.chi2 > 1e4, "{chi2:?}");
    assert!(
        r.warnings.iter().any(|w| w.starts_with("χ² = ")),
        "{:?}",
        r.warnings
    );
}

#[test]
fn a_parameter_not_determined_is_a_warning_and_not_trusted() {
    let t = truth();
    let mut start = t.clone();
    start.heater.efficiency_m_per_w = 1.15e-7;
    // Static equilibria do not depend on the mass.
    let r = fit(
        &start,
        &[touchdown_curve(&t, 7, false)],
        &free(&["efficiency_nm_per_mw=0.05:0.2", "mass_kg=1e-7:1e-5"]),
        &FitOptions::default(),
    )
    .unwrap();
    assert!(!r.parameters[1].determined);
    assert!(!r.trusted);
    assert!(
        r.warnings
            .iter()
            .any(|w| w.starts_with("mass_kg is not determined")),
        "{:?}",
        r.warnings
    );
}

#[test]
fn an_untouched_parameter_is_held_and_the_others_still_move() {
    // σ starts 14 % off with the mass free and unbounded: σ is fitted, the mass is held at its
    // start and reported.
    let t = truth();
    let mut start = t.clone();
    start.surface.height_sigma_m = 0.6e-9;
    if let hdi_tribology::surface::PeakModel::RiceMaxima { sigma_m, .. } = &mut start.surface.peaks
    {
        *sigma_m = 0.6e-9;
    }
    let r = fit(
        &start,
        &[touchdown_curve(&t, 7, false)],
        &free(&["height_sigma_nm", "mass_kg"]),
        &FitOptions::default(),
    )
    .unwrap();
    let (sigma, mass) = (&r.parameters[0], &r.parameters[1]);
    let se = sigma.standard_error.expect("σ is determined");
    assert!((sigma.value - 0.7).abs() < 4.0 * se, "{sigma:?}");
    assert!(se < 0.01, "{sigma:?}");
    assert_eq!(mass.value, 1e-6);
    assert!(!mass.determined && !r.trusted);
    assert!(
        r.warnings.iter().any(|w| w.starts_with(
            "mass_kg is not determined: no fitted value depends on it, so \
                                   it was held at its start"
        )),
        "{:?}",
        r.warnings
    );
    let words = r.identifiability.statements.join(" ");
    assert!(
        words.contains("mass_kg is not determined by these data: no fitted value depends on it"),
        "{words}"
    );
}

#[test]
fn strongly_correlated_parameters_are_not_all_called_determined() {
    // η and the nominal clearance from touchdown and take-off against DC voltage: both within
    // their error limit, but correlated at ρ ≈ 0.997.
    let t = truth();
    let mut grid = String::from("dc_voltage_v,touchdown_power_mw,takeoff_power_mw\n");
    for i in 0..10 {
        grid.push_str(&format!("{},0,0\n", -0.4 + 1.2 * i as f64 / 9.0));
    }
    let template = DataSet::from_csv_str(&grid, "static_vs_vdc.csv").unwrap();
    let mut d = model_curves(&t, &[template]).unwrap().remove(0);
    let mut rng = Xoshiro256::new(7);
    for o in &mut d.observed {
        for v in &mut o.values {
            *v += 0.05e-3 * gauss(&mut rng);
        }
        o.errors = Some(vec![0.05e-3; o.values.len()]);
    }
    let r = fit(
        &t,
        &[d],
        &free(&["efficiency_nm_per_mw=0.05:0.2", "nominal_clearance_nm=7:13"]),
        &FitOptions::default(),
    )
    .unwrap();
    let rho = r.correlation[0][1];
    assert!(rho.abs() > STRONG_CORRELATION, "ρ = {rho}");
    assert!(r.parameters.iter().all(|p| p.determined));
    assert!(r.goodness.passed(), "{:?}", r.goodness.failures);
    assert!(!r.trusted);
    assert!(
        r.warnings.iter().any(|w| w.starts_with(
            "efficiency_nm_per_mw and nominal_clearance_nm are correlated at ρ = +0.99"
        )),
        "{:?}",
        r.warnings
    );
    let words = r.identifiability.statements.join(" ");
    assert!(
        !words.contains("all 2 parameters are determined"),
        "{words}"
    );
    assert!(words.contains("strongly correlated"), "{words}");
}

fn ac_curve(truth: &Scene, seed: u64, sd_mw: f64) -> DataSet {
    let mut grid = String::from("ac_amplitude_v,touchdown_power_mw,takeoff_power_mw\n");
    for a in [0.0, 0.2, 0.4, 0.6, 0.8] {
        grid.push_str(&format!("{a},0,0\n"));
    }
    let template = DataSet::from_csv_str(&grid, "cycle_vs_vac.csv").unwrap();
    let mut d = model_curves(truth, &[template]).unwrap().remove(0);
    let mut rng = Xoshiro256::new(seed);
    for o in &mut d.observed {
        for v in &mut o.values {
            *v += sd_mw * 1e-3 * gauss(&mut rng);
        }
        o.errors = Some(vec![sd_mw * 1e-3; o.values.len()]);
    }
    d
}

/// The coverage of the AC-only fit's error bars over noise draws: touchdown and take-off at
/// five AC amplitudes (0–0.8 V) from the paper scene with 0.7 mW (1 %) of noise stated as the
/// uncertainty; σ, A and η free, starting 10 % off. Slow (one to three minutes per draw):
/// `cargo test --all-features --test fit -- --ignored --nocapture ac_fit_coverage`
/// (`DRAWS=n` sets the number of draws, 20 by default). The figures are in docs/fit.md.
#[test]
#[ignore]
fn ac_fit_coverage_over_noise_draws() {
    let t = Scene::paper();
    let draws: u64 = std::env::var("DRAWS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20);
    let mut start = t.clone();
    start.surface.height_sigma_m = 0.77e-9;
    if let hdi_tribology::surface::PeakModel::RiceMaxima { sigma_m, .. } = &mut start.surface.peaks
    {
        *sigma_m = 0.77e-9;
    }
    start.intermolecular.as_mut().unwrap().hamaker_attractive_j = 1e-19 / 1.1;
    start.heater.efficiency_m_per_w = 1.1e-7;
    let free = free(&[
        "height_sigma_nm=0.3:1.5",
        "hamaker_attractive_j=2e-20:5e-19",
        "efficiency_nm_per_mw=0.05:0.2",
    ]);
    let truth = [0.7, 1e-19, 0.1];
    let (mut in1, mut in2, mut total, mut trusted, mut escaped) = (0, 0, 0, 0, 0);
    let (mut in1_t, mut in2_t, mut total_t) = (0, 0, 0);
    for seed in 0..draws {
        let t0 = std::time::Instant::now();
        let data = ac_curve(&t, 100 + seed, 0.7);
        let r = fit(&start, &[data], &free, &FitOptions::default()).unwrap();
        escaped += usize::from(r.warnings.iter().any(|w| w.contains("false minimum")));
        trusted += usize::from(r.trusted);
        let z: Vec<Option<f64>> = r
            .parameters
            .iter()
            .zip(truth)
            .map(|(p, v)| p.standard_error.map(|se| (p.value - v).abs() / se))
            .collect();
        for z in z.iter().flatten() {
            total += 1;
            in1 += usize::from(*z <= 1.0);
            in2 += usize::from(*z <= 2.0);
            if r.trusted {
                total_t += 1;
                in1_t += usize::from(*z <= 1.0);
                in2_t += usize::from(*z <= 2.0);
            }
        }
        println!(
            "draw {seed}: {:.0} s, χ² {:.1}, trusted {}, |Δ|/SE {:?}, warnings {:?}",
            t0.elapsed().as_secs_f64(),
            r.chi2,
            r.trusted,
            z,
            r.warnings
        );
    }
    println!(
        "{draws} draws: {trusted} trusted, {escaped} escaped a false minimum; over all \
         determined parameters ({total}): within 1 SE {in1} ({:.0} %), within 2 SE {in2} \
         ({:.0} %); over trusted fits ({total_t}): {in1_t} ({:.0} %), {in2_t} ({:.0} %)",
        100.0 * in1 as f64 / total.max(1) as f64,
        100.0 * in2 as f64 / total.max(1) as f64,
        100.0 * in1_t as f64 / total_t.max(1) as f64,
        100.0 * in2_t as f64 / total_t.max(1) as f64,
    );
}
