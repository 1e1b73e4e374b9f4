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
    assert!(
        worst < 1e-12,
        "stored table differs from the solver by {worst:e}"
    );
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
        assert!(
            e_standard < 1e-10,
            "D = {d}: standard vs refined {e_standard:e}"
        );
        assert!(e_coarse < 1e-8, "D = {d}: coarse vs refined {e_coarse:e}");
        assert!(
            e_standard < 0.1 * e_coarse.max(1e-13),
            "D = {d}: no convergence, coarse {e_coarse:e}, standard {e_standard:e}"
        );
    }
    eprintln!("(D, coarse, standard) relative errors against refined: {rows:?}");
    // Order family at fixed panels: the error falls geometrically with the nodes per panel
    // (spectral convergence); the observed rate per two extra nodes is at least 5x.
    for &d in &[0.1, 1.0, 10.0] {
        let fine = poiseuille_flow_rate(d, &Resolution::REFINED).unwrap();
        let errors: Vec<f64> = [4, 6, 8]
            .iter()
            .map(|&order| {
                let r = Resolution {
                    order,
                    ..Resolution::REFINED
                };
                (poiseuille_flow_rate(d, &r).unwrap() / fine - 1.0).abs()
            })
            .collect();
        let rates: Vec<f64> = errors.windows(2).map(|e| e[0] / e[1]).collect();
        eprintln!("D = {d}: errors at orders 4, 6, 8: {errors:?}, ratios {rates:?}");
        assert!(rates.iter().all(|&r| r > 5.0), "D = {d}: ratios {rates:?}");
    }
}

/// Error of the database against the solver at the geometric midpoints of the table's
/// intervals, where a cubic spline is least accurate.
#[test]
fn database_interpolation_error_is_bounded() {
    let db = FlowFactor::get();
    let nodes = table_nodes();
    let mut worst: f64 = 0.0;
    for w in nodes.windows(2) {
        let d = (w[0] * w[1]).sqrt();
        worst = worst.max((db.flow_rate(d) / solve(d) - 1.0).abs());
    }
    eprintln!("interpolation: max relative error {worst:.2e}");
    assert!(worst < 1e-8, "interpolation error {worst:e}");
    // At the nodes the spline is the table.
    for (d, q) in nodes.iter().zip(db.table()) {
        assert!((db.flow_rate(*d) / q - 1.0).abs() < 1e-14);
    }
}

#[test]
fn database_tails_follow_the_solver() {
    let db = FlowFactor::get();
    for &d in &[400.0, 800.0] {
        let e = (db.flow_rate(d) / solve(d) - 1.0).abs();
        assert!(e < 1e-8, "continuum tail at D = {d}: {e:e}");
    }
    for &d in &[5e-4, 1e-4, 1e-5] {
        let e = (db.flow_rate(d) / solve(d) - 1.0).abs();
        assert!(e < 3e-6, "free-molecular tail at D = {d}: {e:e}");
    }
    // Continuous across the table's ends.
    for &d in &[TABLE_D_MIN, TABLE_D_MAX] {
        let below = db.flow_rate_and_derivative(d * (1.0 - 1e-12));
        let above = db.flow_rate_and_derivative(d * (1.0 + 1e-12));
        assert!((below.0 - above.0).abs() < 1e-10 * below.0);
        assert!((below.1 - above.1).abs() < 1e-8 * below.1.abs().max(1.0));
    }
}

/// Continuum limit: `Q_P − D/6 → σ_P = 1.016191` (BGK, diffuse walls; Cercignani;
/// Loyalka et al.), and the flow factor's slope at `Kn → 0` is the BGK slip length
/// `2σ_P/√π = 1.1466` mean free paths against 1 for first-order slip.
#[test]
fn continuum_limit_gives_the_bgk_slip_coefficient() {
    // Fit Q_P − D/6 = σ + c₁/D + c₂/D² through three solver values.
    let ds = [100.0, 200.0, 316.0];
    let g: Vec<f64> = ds.iter().map(|&d| solve(d) - d / 6.0).collect();
    let m = nalgebra::Matrix3::from_fn(|i, j| ds[i].powi(-(j as i32)));
    let c = m
        .lu()
        .solve(&nalgebra::Vector3::from_column_slice(&g))
        .unwrap();
    eprintln!("sigma_P = {:.7}, c1 = {:.4}, c2 = {:.4}", c[0], c[1], c[2]);
    assert!((c[0] - SLIP_COEFFICIENT).abs() < 2e-5, "sigma_P {}", c[0]);
    // Fukui & Kaneko's continuum fit has c₁ = 1.0653, c₂ = −2.1354.
    assert!((c[1] - 1.0653).abs() < 0.01, "c1 {}", c[1]);
    assert!((c[2] + 2.1354).abs() < 0.1, "c2 {}", c[2]);
    // Flow factor: Q → 1 with dQ/dKn → 12σ_P/√π.
    for &kn in &[1e-4, 1e-3] {
        let q = FlowModel::FukuiKaneko.factor(kn);
        let slip = (q - 1.0) / (6.0 * kn);
        assert!(
            (slip - 2.0 * SLIP_COEFFICIENT / SQRT_PI).abs() < 0.02,
            "Kn {kn}: {slip}"
        );
    }
    assert_eq!(FlowModel::FukuiKaneko.factor(0.0), 1.0);
}

/// Free-molecular limit: `Q_P = π^{−1/2}(−ln D + c₀) + (D/π) ln²D + O(D ln D)` with
/// `c₀ = 3(1 − γ)/2`: logarithmic growth as `D → 0`.
#[test]
fn free_molecular_limit_is_logarithmic() {
    for &d in &[1e-3, 1e-4, 1e-5] {
        let q = solve(d);
        let l = d.ln();
        let lead = (-l + FREE_MOLECULAR_CONSTANT) / SQRT_PI;
        let second = d / std::f64::consts::PI * l * l;
        let rest = q - lead - second;
        assert!(
            rest.abs() < 2.0 * d * l.abs(),
            "D = {d}: remainder {rest:e} beyond O(D ln D)"
        );
    }
    // Slope in ln D → −1/√π.
    let slope = (solve(1e-5) - solve(1e-4)) / (1e-5f64 / 1e-4).ln();
    assert!((slope * SQRT_PI + 1.0).abs() < 5e-3, "slope {slope}");
}

/// Knudsen's minimum: the flow rate has a single minimum near `D ≈ 1`.
#[test]
fn knudsen_minimum() {
    // Golden-section search on the solver.
    let (mut a, mut b) = (0.3f64.ln(), 3.0f64.ln());
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let f = |x: f64| solve(x.exp());
    let (mut x1, mut x2) = (b - r * (b - a), a + r * (b - a));
    let (mut f1, mut f2) = (f(x1), f(x2));
    while b - a > 1e-5 {
        if f1 < f2 {
            b = x2;
            x2 = x1;
            f2 = f1;
            x1 = b - r * (b - a);
            f1 = f(x1);
        } else {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + r * (b - a);
            f2 = f(x2);
        }
    }
    let d_min = (0.5 * (a + b)).exp();
    let q_min = solve(d_min);
    eprintln!("Knudsen minimum: D = {d_min:.4}, Q_P = {q_min:.6}");
    assert!((d_min - 1.0716).abs() < 2e-3, "minimum at D = {d_min}");
    assert!((q_min - 1.53808).abs() < 1e-5, "minimum value {q_min}");
    // The database has its minimum at the same place.
    let db = FlowFactor::get();
    let (_, slope) = db.flow_rate_and_derivative(d_min);
    assert!(slope.abs() < 1e-4, "database slope at the minimum {slope}");
    // Decreasing below, increasing above.
    for &d in &[1e-3, 0.01, 0.1, 0.5] {
        assert!(db.flow_rate_and_derivative(d).1 < 0.0);
    }
    for &d in &[2.0, 10.0, 100.0, 1e4] {
        assert!(db.flow_rate_and_derivative(d).1 > 0.0);
    }
}

/// Against Fukui & Kaneko's (1988) fitted formulas, to their fits' precision (1 %).
#[test]
fn agrees_with_fukui_kaneko_fits() {
    let mut worst: f64 = 0.0;
    for k in 0..=40 {
        let d = 0.01 * 10f64.powf(k as f64 / 10.0); // 0.01 .. 100
        let e = (fukui_kaneko_fit(d) / solve(d) - 1.0).abs();
        worst = worst.max(e);
    }
    eprintln!("Fukui-Kaneko fits: max relative deviation {worst:.2e}");
    assert!(worst < 1e-2, "deviation {worst:e}");
    // In the slip range their continuum formula is a close expansion.
    for &d in &[30.0, 100.0] {
        assert!((fukui_kaneko_fit(d) / solve(d) - 1.0).abs() < 1e-5);
    }
}

#[test]
fn derivatives_match_finite_differences() {
    let db = FlowFactor::get();
    for k in 0..=70 {
        let d = 1e-4 * 10f64.powf(k as f64 / 10.0); // 1e-4 .. 1e3
        let (_, dq) = db.flow_rate_and_derivative(d);
        let e = 1e-6 * d;
        let fd = (db.flow_rate(d + e) - db.flow_rate(d - e)) / (2.0 * e);
        assert!(
            (dq - fd).abs() < 1e-6 * dq.abs().max(1.0),
            "D = {d}: {dq} vs {fd}"
        );
    }
    for model in [
        FlowModel::Continuum,
        FlowModel::FirstOrderSlip,
        FlowModel::SecondOrderSlip,
        FlowModel::FukuiKaneko,
    ] {
        for &kn in &[1e-3, 0.01, 0.1, 0.5, 1.0, 5.0, 50.0, 500.0, 5000.0] {
            let (_, dq) = model.factor_and_derivative(kn);
            let e = 1e-6 * kn;
            let fd = (model.factor(kn + e) - model.factor(kn - e)) / (2.0 * e);
            assert!(
                (dq - fd).abs() < 1e-6 * dq.abs().max(1.0),
                "{model:?} Kn = {kn}: {dq} vs {fd}"
            );
        }
    }
    // Against the solver's own difference quotient (the spline's derivative error).
    for &d in &[0.02, 0.5, 2.0, 20.0] {
        let (_, dq) = db.flow_rate_and_derivative(d);
        let e = 1e-3 * d;
        let fd = (solve(d + e) - solve(d - e)) / (2.0 * e);
        assert!(
            (dq - fd).abs() < 1e-5 * dq.abs().max(0.1),
            "D = {d}: {dq} vs {fd}"
        );
    }
}

/// At moderate rarefaction the kinetic flow factor lies above first-order slip (its slip
/// length is 1.1466 λ, not λ) and above continuum; second-order slip overshoots it once
/// `Kn` reaches order one.
#[test]
fn models_are_ordered_as_the_physics_says() {
    for &kn in &[0.01, 0.05, 0.1, 0.3, 1.0, 3.0, 10.0] {
        let c = FlowModel::Continuum.factor(kn);
        let f1 = FlowModel::FirstOrderSlip.factor(kn);
        let fk = FlowModel::FukuiKaneko.factor(kn);
        assert!(c < f1 && f1 < fk, "Kn = {kn}: {c} {f1} {fk}");
    }
    for &kn in &[1.0, 3.0, 10.0] {
        assert!(FlowModel::SecondOrderSlip.factor(kn) > FlowModel::FukuiKaneko.factor(kn));
    }
    // Free-molecular: the kinetic factor grows like Kn ln Kn, between first-order slip
    // (linear) and second-order slip (quadratic).
    let r = |kn: f64| FlowModel::FukuiKaneko.factor(kn) / FlowModel::FirstOrderSlip.factor(kn);
    assert!(r(100.0) > r(10.0) && r(1000.0) > r(100.0));
}

#[test]
fn flow_model_serde_and_errors() {
    for (m, name) in [
        (FlowModel::Continuum, "continuum"),
        (FlowModel::FirstOrderSlip, "first_order_slip"),
        (FlowModel::SecondOrderSlip, "second_order_slip"),
        (FlowModel::FukuiKaneko, "fukui_kaneko"),
    ] {
        assert_eq!(serde_json::to_string(&m).unwrap(), format!("\"{name}\""));
        assert_eq!(
            serde_json::from_str::<FlowModel>(&format!("\"{name}\"")).unwrap(),
            m
        );
    }
    let err = FlowModel::FukuiKaneko
        .checked_factor_and_derivative(f64::NAN)
        .unwrap_err();
    assert!(err.to_string().contains("knudsen"), "{err}");
    let err = poiseuille_flow_rate(0.0, &Resolution::STANDARD).unwrap_err();
    assert!(err.to_string().contains("inverse_knudsen"), "{err}");
    let bad = Resolution {
        grading: 0.9,
        ..Resolution::STANDARD
    };
    let err = poiseuille_flow_rate(1.0, &bad).unwrap_err();
    assert!(err.to_string().contains("resolution.grading"), "{err}");
    assert!(FlowFactor::get().factor(-1.0).is_nan());
}
