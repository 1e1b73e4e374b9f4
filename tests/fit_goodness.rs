//! The goodness-of-fit tests behind `FitResult::trusted`: each fires on the misfit it is made
//! for and stays quiet on residuals that are noise; a fit with a parameter held at a wrong value
//! is not trusted, the same fit with it free is.

use hdi_tribology::fit::goodness::{assess, ALPHA};
use hdi_tribology::fit::{
    fit, model_curves, DataSet, FitOptions, FreeParameter, ResidualRow, ResidualTable,
};
use hdi_tribology::scene::Scene;
use hdi_tribology::surface::Xoshiro256;

fn gauss(rng: &mut Xoshiro256) -> f64 {
    let (u, v) = (rng.next_open01(), rng.next_open01());
    (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}

/// A residual table of weighted residuals `w` at x = 0, 1, 2, ….
fn table(column: &str, w: &[f64]) -> ResidualTable {
    ResidualTable {
        file: "data.csv".into(),
        x_column: "dc_voltage_v".into(),
        column: column.into(),
        rows: w
            .iter()
            .enumerate()
            .map(|(i, &w)| ResidualRow {
                line: i as u64 + 2,
                x: i as f64,
                measured: 0.0,
                fitted: w,
                residual: w,
                weighted: w,
                clipped: false,
                excluded: false,
            })
            .collect(),
    }
}

/// Two columns of 20 values, `scale[k]` times unit normal noise plus `shape(x)`.
fn two_columns(seed: u64, scale: [f64; 2], shape: impl Fn(f64) -> f64) -> Vec<ResidualTable> {
    let mut rng = Xoshiro256::new(seed);
    ["touchdown_power_mw", "takeoff_power_mw"]
        .iter()
        .zip(scale)
        .map(|(c, s)| {
            let w: Vec<f64> = (0..20)
                .map(|i| s * gauss(&mut rng) + shape(i as f64))
                .collect();
            table(c, &w)
        })
        .collect()
}

#[test]
fn noise_passes_at_about_the_stated_rate() {
    // 400 fits' worth of residuals that are exactly the stated noise: each of the five tests
    // (χ², two column scales, two runs tests) fails with probability ≤ ALPHA.
    let failed = (0..400)
        .filter(|&seed| !assess(&two_columns(seed, [1.0, 1.0], |_| 0.0), &[true, true], 4).passed())
        .count();
    assert!(
        failed <= 6,
        "{failed} of 400 noise-only fits failed (expected about {})",
        400.0 * 5.0 * ALPHA
    );
    // Without stated uncertainties the column scales are compared with each other (F-test).
    let failed = (0..400)
        .filter(|&seed| {
            !assess(&two_columns(seed, [1.0, 1.0], |_| 0.0), &[false, false], 4).passed()
        })
        .count();
    assert!(
        failed <= 6,
        "{failed} of 400 failed without stated uncertainties"
    );
}

#[test]
fn residuals_larger_than_the_stated_uncertainties_fail_the_chi2_test() {
    let g = assess(&two_columns(1, [1.8, 1.8], |_| 0.0), &[true, true], 4);
    let chi2 = g
        .chi2
        .as_ref()
        .expect("every value has a stated uncertainty");
    assert_eq!(chi2.dof, 36.0);
    assert!(chi2.p_value < ALPHA, "{chi2:?}");
    assert!(
        g.failures.iter().any(|f| f.starts_with("χ² = ")),
        "{:?}",
        g.failures
    );
    // Without stated uncertainties there is no χ² test, and both columns scale alike: passed.
    let g = assess(&two_columns(1, [1.8, 1.8], |_| 0.0), &[false, false], 4);
    assert!(g.chi2.is_none());
    assert!(g.passed(), "{:?}", g.failures);
}

#[test]
fn a_curve_the_model_does_not_follow_is_named() {
    let g = assess(&two_columns(2, [1.0, 4.0], |_| 0.0), &[false, false], 4);
    assert!(!g.passed());
    assert_eq!(g.failures.len(), 1, "{:?}", g.failures);
    assert!(
        g.failures[0].contains("takeoff_power_mw"),
        "{}",
        g.failures[0]
    );
    assert!(g.columns[1].scale_p_value.unwrap() < ALPHA);
    assert!(g.columns[0].scale_p_value.unwrap() > 0.5);
}

#[test]
fn a_systematic_misfit_inside_the_scatter_fails_the_runs_test() {
    // A slow wave of twice the noise along x: χ² is only about 3× its expectation per value, but
    // the signs come in long runs.
    let wave = |x: f64| 2.0 * (x * std::f64::consts::PI / 10.0).sin();
    let g = assess(&two_columns(3, [0.3, 0.3], wave), &[false, false], 4);
    assert!(
        g.failures
            .iter()
            .any(|f| f.contains("runs of residual signs")),
        "{:?}",
        g.failures
    );
    assert!(
        g.columns.iter().all(|c| c.runs.unwrap() <= 5),
        "{:?}",
        g.columns
    );
}

/// Touchdown and take-off at 10 DC voltages from the paper scene with φ = 0.2 V, noise of
/// 0.05 mW stated as the uncertainty.
fn data() -> (Scene, DataSet) {
    let mut truth = Scene::paper();
    truth.electrostatic.as_mut().unwrap().contact_potential_v = 0.2;
    let mut grid = String::from("dc_voltage_v,touchdown_power_mw,takeoff_power_mw\n");
    for i in 0..10 {
        grid.push_str(&format!("{},0,0\n", -0.4 + 1.2 * i as f64 / 9.0));
    }
    let template = DataSet::from_csv_str(&grid, "static_vs_vdc.csv").unwrap();
    let mut d = model_curves(&truth, &[template]).unwrap().remove(0);
    let mut rng = Xoshiro256::new(17);
    for o in &mut d.observed {
        for v in &mut o.values {
            *v += 0.05e-3 * gauss(&mut rng);
        }
        o.errors = Some(vec![0.05e-3; o.values.len()]);
    }
    (truth, d)
}

#[test]
fn a_parameter_held_at_a_wrong_value_makes_the_fit_untrusted() {
    let (truth, d) = data();
    let mut start = truth.clone();
    start.heater.efficiency_m_per_w = 1.1e-7;
    // φ free: the model can follow the data; the χ² matches the stated noise.
    let both = [
        FreeParameter::new("contact_potential_v").bounded(-1.0, 1.0),
        FreeParameter::new("efficiency_nm_per_mw").bounded(0.05, 0.2),
    ];
    let r = fit(
        &start,
        std::slice::from_ref(&d),
        &both,
        &FitOptions::default(),
    )
    .unwrap();
    assert!(r.converged && r.trusted, "{:?}", r.warnings);
    let chi2 = r.goodness.chi2.as_ref().unwrap();
    assert!(chi2.p_value > ALPHA, "{chi2:?}");
    // φ held at 0 V (the truth is 0.2 V): the parabola cannot shift, η alone cannot follow it.
    start.electrostatic.as_mut().unwrap().contact_potential_v = 0.0;
    let r = fit(
        &start,
        std::slice::from_ref(&d),
        &both[1..],
        &FitOptions::default(),
    )
    .unwrap();
    assert!(r.converged, "{:?}", r.warnings);
    assert!(!r.trusted, "a wrong φ must not give a trusted fit");
    assert!(r.goodness.chi2.as_ref().unwrap().p_value < ALPHA);
    assert!(
        r.warnings.iter().any(|w| w.starts_with("χ² = ")),
        "{:?}",
        r.warnings
    );
}
