//! The Reynolds solver against one-dimensional limits with closed-form or independently
//! integrated answers: the infinitely wide inclined plane (closed sides, no skew).

use hdi_tribology::bearing::{
    Attitude, BearingSpec, FlowModel, GridSpec, OperatingConditions, Reynolds, Sides,
    SliderGeometry,
};

const L: f64 = 1e-3;
const WIDTH: f64 = 1e-3;
const RADIUS_MM: f64 = 10.0;

/// An infinitely wide inclined plane of length `L`: outlet spacing `h2`, inlet `h1`, disk speed
/// `u`, mean free path `lambda`, on `nx` control volumes.
fn wide_plane(
    u: f64,
    h1: f64,
    h2: f64,
    lambda: f64,
    model: FlowModel,
    nx: usize,
) -> (Reynolds, Attitude) {
    let mut op = OperatingConditions::new(RADIUS_MM, 1.0, 1.0);
    op.rpm = u * 60.0 / (2.0 * std::f64::consts::PI * RADIUS_MM * 1e-3);
    op.mean_free_path_nm = lambda * 1e9;
    op.flow_model = model;
    let spec = BearingSpec {
        slider: SliderGeometry::flat(L * 1e6, WIDTH * 1e6),
        operating: op,
        grid: GridSpec {
            nx,
            ny: 8,
            refinement: 1.0,
        },
        bulge_um: None,
    };
    let b = spec.build().unwrap();
    let mut r = Reynolds::new(&b, nx, 8);
    r.sides = Sides::Closed;
    let att = Attitude {
        fly_height: h2,
        pitch: (h1 - h2) / L,
        roll: 0.0,
    };
    (r, att)
}

/// Composite Simpson on `[a, b]` with `n` (even) intervals.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let mut s = f(a) + f(b);
    for k in 1..n {
        s += f(a + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * h / 3.0
}

/// Load per unit width and centre of pressure of the incompressible wedge with conductance
/// `c(h) = h³ Q(λ/h)`, integrated independently: `c p' = 6 μ U (h − h*)`, `p(0) = p(L) = 0`.
fn incompressible(mu: f64, u: f64, h1: f64, h2: f64, c: impl Fn(f64) -> f64) -> (f64, f64) {
    let h = |x: f64| h1 + (h2 - h1) * x / L;
    let n = 20_000;
    let i1 = simpson(|x| h(x) / c(h(x)), 0.0, L, n);
    let i0 = simpson(|x| 1.0 / c(h(x)), 0.0, L, n);
    let hstar = i1 / i0;
    // p(x) on a fine mesh by cumulative Simpson of p'.
    let m = 4000;
    let dx = L / m as f64;
    let dp = |x: f64| 6.0 * mu * u * (h(x) - hstar) / c(h(x));
    let mut p = vec![0.0; m + 1];
    for k in 0..m {
        let (a, b) = (k as f64 * dx, (k + 1) as f64 * dx);
        p[k + 1] = p[k] + (b - a) / 6.0 * (dp(a) + 4.0 * dp(0.5 * (a + b)) + dp(b));
    }
    let (mut w, mut mx) = (0.0, 0.0);
    for k in 0..m {
        let x = (k as f64 + 0.5) * dx;
        let pm = 0.5 * (p[k] + p[k + 1]);
        w += pm * dx;
        mx += pm * x * dx;
    }
    (w, mx / w)
}

#[test]
fn incompressible_limit_of_the_wide_inclined_plane() {
    let (u, h1, h2) = (1e-3, 4e-6, 2e-6);
    let (r, att) = wide_plane(u, h1, h2, 0.0, FlowModel::Continuum, 400);
    let mu = r.bearing.viscosity;
    let lambda_phys = 6.0 * mu * u * L / (r.bearing.ambient_pressure * h2 * h2);
    assert!(lambda_phys < 1e-3, "{lambda_phys}");
    let mut p = r.ambient();
    r.solve(&att, &mut p).unwrap();
    let [load, moment, _] = r.loads(&p);
    // Closed form of the load per unit width (a = h1/h2).
    let a = h1 / h2;
    let closed = 6.0 * mu * u * L * L / ((a - 1.0).powi(2) * h2 * h2)
        * (a.ln() - 2.0 * (a - 1.0) / (a + 1.0));
    let (quad, xcp) = incompressible(mu, u, h1, h2, |h| h * h * h);
    assert!((quad / closed - 1.0).abs() < 1e-6, "{quad} {closed}");
    let w = load / WIDTH;
    let err = (w / closed - 1.0).abs();
    eprintln!("inclined plane: load error {err:.2e}");
    assert!(err < 2e-3, "load {w} N/m against {closed} N/m: {err:e}");
    let centre = r.bearing.pivot[0] - moment / load;
    let cerr = (centre - xcp).abs() / L;
    eprintln!("inclined plane: centre of pressure error {cerr:.2e} L");
    assert!(
        cerr < 1e-3,
        "centre of pressure {centre} against {xcp}: {cerr:e}"
    );
}

#[test]
fn large_bearing_number_keeps_p_h_constant() {
    let (u, h1, h2) = (20.0, 20e-9, 10e-9);
    let (r, att) = wide_plane(u, h1, h2, 0.0, FlowModel::Continuum, 400);
    let lambda_phys = 6.0 * r.bearing.viscosity * u * L / (r.bearing.ambient_pressure * h2 * h2);
    assert!(lambda_phys > 1e5, "{lambda_phys}");
    let mut p = r.ambient();
    r.solve(&att, &mut p).unwrap();
    let mut worst: f64 = 0.0;
    for (i, &x) in r.grid.xc.iter().enumerate() {
        if !(0.05 * L..=0.9 * L).contains(&x) {
            continue;
        }
        let h = att.spacing_at(x, 0.0, L, WIDTH);
        worst = worst.max((p[i] * h / h1 - 1.0).abs());
    }
    eprintln!("large bearing number {lambda_phys:.3e}: p h departs by {worst:.2e}");
    assert!(worst < 1e-2, "p h / (p_a h1) departs by {worst:e}");
}

/// The compressible solution at small bearing number with slip, against the incompressible
/// wedge with the same flow factor at `p = p_a`.
fn slip_case(model: FlowModel) -> f64 {
    let (u, h1, h2, lambda) = (1e-4, 400e-9, 200e-9, 63.5e-9);
    let (r, att) = wide_plane(u, h1, h2, lambda, model, 400);
    let mut p = r.ambient();
    r.solve(&att, &mut p).unwrap();
    let w = r.loads(&p)[0] / WIDTH;
    let (want, _) = incompressible(r.bearing.viscosity, u, h1, h2, |h| {
        h * h * h * model.factor(lambda / h)
    });
    let err = (w / want - 1.0).abs();
    eprintln!("{model:?}: load {w:.6e} N/m, error {err:.2e}");
    assert!(
        err < 3e-3,
        "{model:?}: load {w} N/m against {want} N/m: {err:e}"
    );
    w
}

#[test]
fn slip_models_match_the_incompressible_wedge_with_slip() {
    let c = slip_case(FlowModel::Continuum);
    let f = slip_case(FlowModel::FirstOrderSlip);
    let s = slip_case(FlowModel::SecondOrderSlip);
    let k = slip_case(FlowModel::FukuiKaneko);
    // More flow under the same wedge carries less load.
    assert!(c > f && f > s, "{c} {f} {s}");
    assert!(k < c, "{k} {c}");
}
