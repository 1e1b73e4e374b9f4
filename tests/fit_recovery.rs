//! Recovery of known parameters from synthetic data with seeded noise, the coverage of the ±1σ
//! intervals over 50 seeds, and a parameter the data cannot determine.

use hdi_tribology::fit::{fit, model_curves, DataSet, FitOptions, FreeParameter};
use hdi_tribology::scene::Scene;
use hdi_tribology::surface::Xoshiro256;

fn gauss(rng: &mut Xoshiro256) -> f64 {
    let (u, v) = (rng.next_open01(), rng.next_open01());
    (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}

/// The truth: the paper scene with φ = 0.15 V. Touchdown power at 8 DC voltages.
fn truth_and_curve() -> (Scene, DataSet) {
    let mut truth = Scene::paper();
    truth.electrostatic.as_mut().unwrap().contact_potential_v = 0.15;
    let mut grid = String::from("dc_voltage_v,touchdown_power_mw\n");
    for i in 0..8 {
        grid.push_str(&format!("{},0\n", -0.45 + 0.15 * i as f64));
    }
    let template = DataSet::from_csv_str(&grid, "touchdown_vs_vdc.csv").unwrap();
    let clean = model_curves(&truth, &[template]).unwrap().remove(0);
    (truth, clean)
}

fn noisy(clean: &DataSet, seed: u64, sd_w: f64) -> DataSet {
    let mut d = clean.clone();
    let mut rng = Xoshiro256::new(seed);
    for v in &mut d.observed[0].values {
        *v += sd_w * gauss(&mut rng);
    }
    d
}

fn start_scene(truth: &Scene) -> Scene {
    let mut s = truth.clone();
    s.electrostatic.as_mut().unwrap().contact_potential_v = 0.0;
    s.heater.efficiency_m_per_w = 1.15e-7;
    s
}

fn free() -> Vec<FreeParameter> {
    vec![
        FreeParameter::new("contact_potential_v").bounded(-1.0, 1.0),
        FreeParameter::new("efficiency_nm_per_mw").bounded(0.05, 0.2),
    ]
}

#[test]
fn recovers_the_truth_within_the_error_bars_and_covers_about_68_percent() {
    let (truth, clean) = truth_and_curve();
    let start = start_scene(&truth);
    let true_values = [0.15, 0.1];
    let (mut inside, mut total) = (0, 0);
    let mut worst: f64 = 0.0;
    for seed in 0..50 {
        let data = noisy(&clean, 1000 + seed, 0.05e-3);
        let r = fit(&start, &[data], &free(), &FitOptions::default()).unwrap();
        assert!(r.converged && r.trusted, "seed {seed}: {:?}", r.warnings);
        for (p, t) in r.parameters.iter().zip(true_values) {
            let se = p
                .standard_error
                .unwrap_or_else(|| panic!("seed {seed}: {} undetermined", p.name));
            let z = (p.value - t).abs() / se;
            worst = worst.max(z);
            total += 1;
            if z <= 1.0 {
                inside += 1;
            }
        }
        // The fitted scene carries the values, in SI.
        let phi = r.scene.electrostatic.as_ref().unwrap().contact_potential_v;
        assert_eq!(phi, r.parameters[0].value);
        assert!((r.scene.heater.efficiency_m_per_w - r.parameters[1].value * 1e-6).abs() < 1e-20);
    }
    let coverage = inside as f64 / total as f64;
    println!(
        "coverage of ±1σ over 50 seeds: {inside}/{total} = {coverage:.2}; largest |Δ|/σ {worst:.2}"
    );
    // 100 intervals at 68 %: the binomial standard deviation is 4.7 %; 4σ either side.
    assert!((0.49..=0.87).contains(&coverage), "coverage {coverage}");
    assert!(worst < 5.0, "largest deviation {worst} σ");
}

#[test]
fn a_field_the_data_do_not_touch_gets_no_error_bar() {
    let (truth, clean) = truth_and_curve();
    let data = noisy(&clean, 7, 0.05e-3);
    let free = [
        FreeParameter::new("efficiency_nm_per_mw").bounded(0.05, 0.2),
        // Static equilibria do not depend on the mass.
        FreeParameter::new("mass_kg").bounded(1e-7, 1e-5),
    ];
    let r = fit(&start_scene(&truth), &[data], &free, &FitOptions::default()).unwrap();
    let mass = &r.parameters[1];
    assert!(
        !mass.determined && mass.standard_error.is_none(),
        "{mass:?}"
    );
    let words = r.identifiability.statements.join(" ");
    assert!(words.contains("mass_kg is not determined"), "{words}");
    assert!(
        words.contains("no error bar is given for mass_kg"),
        "{words}"
    );
    assert!(
        r.identifiability.condition > 1e8,
        "{}",
        r.identifiability.condition
    );
    assert!(r.identifiability.directions.iter().any(|d| !d.determined));
}

#[test]
fn bounds_hold_and_names_resolve_in_engineering_units() {
    let (truth, clean) = truth_and_curve();
    let data = noisy(&clean, 3, 0.05e-3);
    // The truth (0.15 V) lies outside these bounds: the fit ends on the bound and says so.
    let free = [
        FreeParameter::new("contact_potential_v").bounded(-0.5, 0.1),
        FreeParameter::new("efficiency_nm_per_mw").bounded(0.05, 0.2),
    ];
    let r = fit(&start_scene(&truth), &[data], &free, &FitOptions::default()).unwrap();
    let phi = &r.parameters[0];
    assert!(phi.value <= 0.1 && phi.value > 0.099, "{phi:?}");
    assert!(phi.at_bound, "{phi:?}");
    assert!(r
        .warnings
        .iter()
        .any(|w| w.contains("contact_potential_v ended on a bound")));
    assert_eq!(r.parameters[1].unit, "nm_per_mw");
    assert_eq!(r.parameters[1].field, "heater.efficiency_m_per_w");
}
