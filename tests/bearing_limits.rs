//! The Reynolds solver against one-dimensional limits with closed-form or independently
//! integrated answers: the infinitely wide inclined plane (closed sides, no skew).
//!
//! Every case uses the two-dimensional solver in its own orientation: the disk moves in `+x`,
//! from the leading edge (`x = 0`) to the trailing edge (`x = L`), and a positive pitch raises
//! the leading edge, so the gap converges towards the trailing edge.

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

/// The exact gauge pressure (Pa) of the incompressible infinitely wide inclined plane at `x`:
/// with `h(x) = h1 + (h2 − h1) x / L` and `m = (h1 − h2) / L`,
/// `p = (6 μ U / m) [(1/h − 1/h1) − (h*/2)(1/h² − 1/h1²)]`, `h* = 2 h1 h2 / (h1 + h2)`.
fn inclined_plane_pressure(mu: f64, u: f64, h1: f64, h2: f64, x: f64) -> f64 {
    let m = (h1 - h2) / L;
    let h = h1 - m * x;
    let hs = 2.0 * h1 * h2 / (h1 + h2);
    6.0 * mu * u / m * ((1.0 / h - 1.0 / h1) - 0.5 * hs * (1.0 / (h * h) - 1.0 / (h1 * h1)))
}

/// The pressure of a converging wedge builds from the leading edge to a peak at `h = h*`, two
/// thirds of the way to the trailing edge for `h1 = 2 h2`, and falls to ambient at the trailing
/// edge: pointwise against the closed form, in the solver's orientation (disk in `+x`, positive
/// pitch).
#[test]
fn the_converging_wedge_builds_pressure_towards_the_trailing_edge() {
    let (u, h1, h2) = (1e-3, 4e-6, 2e-6);
    let (r, att) = wide_plane(u, h1, h2, 0.0, FlowModel::Continuum, 400);
    assert!(att.pitch > 0.0);
    let mu = r.bearing.viscosity;
    let pa = r.bearing.ambient_pressure;
    let mut p = r.ambient();
    r.solve(&att, &mut p).unwrap();
    let nx = r.grid.nx();
    let exact: Vec<f64> = r
        .grid
        .xc
        .iter()
        .map(|&x| inclined_plane_pressure(mu, u, h1, h2, x))
        .collect();
    let peak = exact.iter().cloned().fold(0.0, f64::max);
    let mut worst: f64 = 0.0;
    for i in 0..nx {
        worst = worst.max(((p[i] - 1.0) * pa - exact[i]).abs() / peak);
    }
    eprintln!("inclined plane: pressure profile error {worst:.2e} of the peak");
    assert!(worst < 1e-3, "{worst:e}");
    // The peak: at h = h* = 4/3 h2, x = 2L/3, within one control volume.
    let imax = (0..nx).max_by(|&a, &b| p[a].total_cmp(&p[b])).unwrap();
    let xmax = r.grid.xc[imax];
    let dx = r.grid.xf[imax + 1] - r.grid.xf[imax];
    assert!((xmax - 2.0 * L / 3.0).abs() <= dx, "peak at {xmax} m");
    // Rising all the way from the leading edge to the peak.
    assert!((1..=imax).all(|i| p[i] > p[i - 1]));
}

/// The low-frequency damping of the wide wedge at a very large bearing number against its
/// closed form. There `σ ∂(PH)/∂t + Λ ∂(PH)/∂X = 0` away from the trailing edge's boundary
/// layer: `p h` is carried from the leading edge at `U/2`, so `p(x, t) = p_a h(0, t − 2x/U) /
/// h(x, t)` and a slow motion `q̇` leaves the pressure lagging by `δp = −p_a (2x/U) q̇ ∂h(0)/∂q /
/// h(x)`. Per unit width, with the pivot at `x_p`:
/// heave `C = (2 p_a/U) ∫ x/h dx > 0`, pitch (about the trailing edge, `∂h(0)/∂α = L`)
/// `C = (2 p_a L/U) ∫ x (x_p − x)/h dx`, negative for a pivot at the centre: the pressure's lag
/// is largest where the gap is smallest, behind the pivot. The negative pitch damping is the
/// physics of a compressible bearing at a high bearing number, not a sign error.
#[test]
fn damping_at_a_large_bearing_number_matches_the_transport_lag() {
    let (u, h1, h2) = (20.0, 20e-9, 10e-9);
    let (r, att) = wide_plane(u, h1, h2, 0.0, FlowModel::Continuum, 400);
    let h = r.spacing(&att);
    let mut p = r.ambient();
    let (_, f) = r.solve_spacing(&h, &mut p).unwrap();
    let (_, dps, _) = r.sensitivities(&p, &h, &f, 1e-10).unwrap();
    let c = r.damping(&p, &h, &f, &dps).unwrap();
    let pa = r.bearing.ambient_pressure;
    let xp = r.bearing.pivot[0];
    let gap = |x: f64| att.spacing_at(x, 0.0, L, WIDTH);
    let u = r.bearing.speed;
    let heave = 2.0 * pa / u * simpson(|x| x / gap(x), 0.0, L, 20_000);
    let pitch = 2.0 * pa * L / u * simpson(|x| x * (xp - x) / gap(x), 0.0, L, 20_000);
    let (ch, cp) = (c[0][0] / WIDTH, c[1][1] / WIDTH);
    let (eh, ep) = ((ch / heave - 1.0).abs(), (cp / pitch - 1.0).abs());
    eprintln!(
        "transport lag: heave damping {ch:.6e} against {heave:.6e} N s/m² ({eh:.2e}), \
         pitch {cp:.6e} against {pitch:.6e} N s/rad ({ep:.2e})"
    );
    assert!(pitch < 0.0 && cp < 0.0 && ch > 0.0);
    assert!(eh < 1e-2 && ep < 1e-2, "{eh:e} {ep:e}");
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
    // So the pressure climbs towards the trailing edge, to nearly p_a h1 / h2, and falls to
    // ambient only in the trailing edge's boundary layer.
    let imax = (0..p.len().min(r.grid.nx()))
        .max_by(|&a, &b| p[a].total_cmp(&p[b]))
        .unwrap();
    assert!(r.grid.xc[imax] > 0.95 * L, "peak at {} m", r.grid.xc[imax]);
    assert!(p[imax] > 0.95 * h1 / h2, "peak {}", p[imax]);
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
