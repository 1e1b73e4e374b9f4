//! The contact indicator against heater power (the letter's Fig. 1): recovery of known
//! parameters from synthetic data with seeded noise, and the reader's errors for the kind.

use hdi_tribology::fit::{fit, model_curves, CurveKind, DataSet, FitOptions, FreeParameter};
use hdi_tribology::scene::Scene;
use hdi_tribology::surface::Xoshiro256;

fn gauss(rng: &mut Xoshiro256) -> f64 {
    let (u, v) = (rng.next_open01(), rng.next_open01());
    (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}

#[test]
fn indicator_curve_gives_back_the_truth_within_its_error_bars() {
    let truth = Scene::paper();
    // 14 powers from 66 to 92 mW: flying, touchdown (about 74 mW), contact.
    let mut grid = String::from("heater_power_mw,contact_indicator_un\n");
    for i in 0..14 {
        grid.push_str(&format!("{},0\n", 66.0 + 2.0 * i as f64));
    }
    let template = DataSet::from_csv_str(&grid, "indicator_vs_power.csv").unwrap();
    assert_eq!(template.kind, CurveKind::IndicatorVsPower);
    let mut data = model_curves(&truth, &[template]).unwrap().remove(0);
    let clean = data.observed[0].values.clone();
    println!(
        "indicator (µN): {:?}",
        clean.iter().map(|v| v * 1e6).collect::<Vec<_>>()
    );
    // Flying (nN) below touchdown, in contact (mN) above it.
    assert!(clean[0] < 1e-8 && clean[13] > 1e-4, "{clean:?}");
    let sd = 2e-6;
    let mut rng = Xoshiro256::new(5);
    for v in &mut data.observed[0].values {
        *v += sd * gauss(&mut rng);
    }
    let mut start = truth.clone();
    start.heater.efficiency_m_per_w = 1.08e-7;
    start.nominal_clearance_m = 1.04e-8;
    let free = [
        FreeParameter::new("efficiency_nm_per_mw").bounded(0.05, 0.2),
        FreeParameter::new("nominal_clearance_nm").bounded(7.0, 13.0),
    ];
    let r = fit(&start, &[data], &free, &FitOptions::default()).unwrap();
    // The residuals look like noise, but η and h0 are correlated at ρ ≈ 0.998: the fit is not
    // trusted for that alone (the indicator's onset fixes h0/η far better than each), and says so.
    assert!(r.converged && r.goodness.passed(), "{:?}", r.warnings);
    assert!(!r.trusted);
    assert_eq!(r.warnings.len(), 1, "{:?}", r.warnings);
    assert!(
        r.warnings[0].starts_with("efficiency_nm_per_mw and nominal_clearance_nm are correlated"),
        "{:?}",
        r.warnings
    );
    for (p, t) in r.parameters.iter().zip([0.1, 10.0]) {
        let se = p.standard_error.expect("determined");
        println!("{} = {} ± {se} (truth {t})", p.name, p.value);
        assert!(
            (p.value - t).abs() <= 4.0 * se,
            "{}: {} ± {se}, truth {t}",
            p.name,
            p.value
        );
        assert!(
            se < 0.05 * t,
            "{}: error bar {se} too wide to be a test",
            p.name
        );
    }
    // The residual scale estimates the noise (in units of the 1 µN default weight).
    assert!(
        r.residual_scale > 1.0 && r.residual_scale < 4.0,
        "{}",
        r.residual_scale
    );
    assert_eq!(r.residuals[0].column, "contact_indicator_un");
}

#[test]
fn indicator_files_give_one_clear_error() {
    let e = DataSet::from_csv_str("dc_voltage_v,contact_indicator_un\n0,1\n", "a.csv").unwrap_err();
    assert_eq!((e.line, e.column), (Some(1), Some(2)));
    assert!(e.to_string().contains("heater_power_mw"), "{e}");
    let e =
        DataSet::from_csv_str("heater_power_mw,touchdown_power_mw\n70,1\n", "b.csv").unwrap_err();
    assert_eq!(e.column, Some(2));
    assert!(e.to_string().contains("contact_indicator_un"), "{e}");
    let e =
        DataSet::from_csv_str("heater_power_mw,contact_indicator_kn\n70,1\n", "c.csv").unwrap_err();
    assert!(e.to_string().contains("unknown unit `kn`"), "{e}");
    let e = DataSet::from_csv_str(
        "heater_power_mw,contact_indicator_un\n70,1\n70,2\n",
        "d.csv",
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .contains("duplicate x value 70 mw (first at line 2)"),
        "{e}"
    );
    let e = DataSet::from_csv_str("heater_power_mw,contact_indicator_un\n70,nan\n", "e.csv")
        .unwrap_err();
    assert_eq!(e.line, Some(2));
    let d = DataSet::from_csv_str(
        "heater_power_w,contact_indicator_nn,contact_indicator_err_nn\n0.07,5,1\n",
        "f.csv",
    )
    .unwrap();
    assert!((d.x[0] - 0.07).abs() < 1e-15 && (d.observed[0].values[0] - 5e-9).abs() < 1e-21);
}
