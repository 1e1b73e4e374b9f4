//! A moving disk under any structure: the base excitation `−M r ẅ` of `Structure::base_influence`,
//! checked on the rigid, `bulge` and `pitch` structures against the linearised transmissibility
//! of the model at one disk harmonic: the steady response of `ẋ = J x + G sin(Ωt + φ)`, with `J`
//! the Jacobian of the model's own `SliderSystem` at the flying equilibrium (central differences)
//! and `G = r Ω² A` on the accelerations, is `Im[z e^{i(Ωt+φ)}]`, `(iΩ − J) z = G`; the bulge gap
//! moves by `∇d · x`.

use hdi_tribology::analysis::{flying_equilibrium, ScanGrid};
use hdi_tribology::drive::{scene_zone, Command, DiskSpec, DriveOptions, Harmonic, Plant};
use hdi_tribology::heater::Programme;
use hdi_tribology::model::SliderSystem;
use hdi_tribology::ode::{Method, OdeSystem};
use hdi_tribology::scene::{Scene, StructureSpec};
use nalgebra::{DMatrix, DVector, Dyn};
use std::f64::consts::PI;

const POWER: f64 = 0.060;

/// Complex amplitude `c` of the bulge gap's response, `δd = Im[c e^{i(Ωt+φ)}]`, from the model
/// linearised at its flying equilibrium, for a disk `A sin(Ωt + φ)`.
fn linear_response(plant: &Plant, omega: f64, amplitude: f64) -> (f64, f64) {
    let model = plant.model();
    let sys = SliderSystem::new(
        model,
        model.inputs(Programme::constant(POWER, 1.0).unwrap()),
        false,
    );
    let lay = sys.layout();
    let n = lay.len();
    let eq = flying_equilibrium(model, POWER, 0.0, &ScanGrid::default()).unwrap();
    let y0 = sys.initial_state(Dyn(n), &eq.rest());
    let f = |y: &DVector<f64>| {
        let mut dy = DVector::zeros(n);
        sys.rhs(0.0, y, &mut dy);
        dy
    };
    let scale = |i: usize| {
        if i < 2 * lay.dofs {
            1e-12 * (1.0 + y0[i].abs() * 1e9)
        } else {
            1e-12
        }
    };
    let mut j = DMatrix::zeros(n, n);
    let mut grad = DVector::zeros(n);
    for c in 0..n {
        let h = scale(c);
        let (mut yp, mut ym) = (y0.clone(), y0.clone());
        yp[c] += h;
        ym[c] -= h;
        let col = (f(&yp) - f(&ym)) / (2.0 * h);
        j.set_column(c, &col);
        grad[c] = (sys.gaps(0.0, &yp).bulge - sys.gaps(0.0, &ym).bulge) / (2.0 * h);
    }
    // (iΩ − J)(a + ib) = G as a real system of twice the size.
    let mut big = DMatrix::zeros(2 * n, 2 * n);
    let mut rhs = DVector::zeros(2 * n);
    for r in 0..n {
        for c in 0..n {
            big[(r, c)] = -j[(r, c)];
            big[(n + r, n + c)] = -j[(r, c)];
        }
        big[(r, n + r)] = -omega;
        big[(n + r, r)] = omega;
    }
    for (i, &r) in model.structure().base_influence().iter().enumerate() {
        rhs[lay.velocity(i)] = r * omega * omega * amplitude;
    }
    let z = big.lu().solve(&rhs).expect("regular");
    let (mut re, mut im) = (0.0, 0.0);
    for i in 0..n {
        re += grad[i] * z[i];
        im += grad[i] * z[n + i];
    }
    (re, im)
}

/// The same amplitude measured on the drive: least squares of the true bulge gap on
/// `sin(Ωt+φ)`, `cos(Ωt+φ)` and a constant over whole periods after the transient.
fn drive_response(plant: &Plant, omega: f64, phase: f64) -> (f64, f64) {
    let mut d = plant.drive().unwrap();
    let period = 2.0 * PI / omega;
    let dt = period / 24.0;
    let cmd = Command::heater_mw(POWER * 1e3);
    let settle = (4e-3 / period).ceil() as usize * 24;
    for _ in 0..settle {
        d.step(&cmd, dt).unwrap();
    }
    let n = 40 * 24;
    let mut a = DMatrix::zeros(n, 3);
    let mut b = DVector::zeros(n);
    for k in 0..n {
        let s = d.step(&cmd, dt).unwrap();
        let th = omega * s.time_s + phase;
        a[(k, 0)] = th.sin();
        a[(k, 1)] = th.cos();
        a[(k, 2)] = 1.0;
        b[k] = s.truth.gap_nm * 1e-9;
    }
    let x = (a.transpose() * &a)
        .lu()
        .solve(&(a.transpose() * b))
        .unwrap();
    (x[0], x[1])
}

/// The response to a disk harmonic of `amplitude` (m, small enough for the response to stay
/// linear: tens of picometres) at `order` per revolution.
fn check(structure: StructureSpec, order: u32, amplitude: f64, what: &str) -> f64 {
    let mut scene = Scene::paper();
    scene.structure = structure;
    let zone = scene_zone(&scene, 0.025).unwrap();
    let phase = 0.7;
    let opts = DriveOptions {
        initial_power: POWER,
        disk: DiskSpec {
            harmonics: vec![Harmonic {
                order,
                amplitude,
                phase,
            }],
            random_rms: 0.0,
            ..DiskSpec::default()
        },
        method: Method::Rodas5P,
        rtol: 1e-10,
        atol_displacement: 1e-17,
        atol_displacement_flight: 1e-17,
        ..DriveOptions::default()
    };
    let plant = Plant::new(&scene, &zone, 1, opts).unwrap();
    let rpm = zone.disk_speed * 60.0 / (2.0 * PI * zone.radius);
    let omega = 2.0 * PI * order as f64 * rpm / 60.0;
    let (re, im) = linear_response(&plant, omega, amplitude);
    let (mre, mim) = drive_response(&plant, omega, phase);
    let mag = re.hypot(im);
    let err = (mre - re).hypot(mim - im);
    println!(
        "{what}: {:.1} kHz, linear {:.4} pm ∠{:.4}, drive {:.4} pm ∠{:.4}, error {:.2e} of it",
        omega / (2e3 * PI),
        mag * 1e12,
        im.atan2(re),
        mre.hypot(mim) * 1e12,
        mim.atan2(mre),
        err / mag
    );
    assert!(mag > 1e-13, "{what}: response too small to test: {mag}");
    assert!(
        err < 5e-3 * mag,
        "{what}: drive ({mre}, {mim}) vs linear ({re}, {im})"
    );
    mag
}

#[test]
fn rigid_slider_follows_the_linear_transmissibility() {
    check(StructureSpec::Rigid, 300, 0.2e-9, "rigid");
}

#[test]
fn bulge_follows_the_linear_transmissibility() {
    // A soft, heavy bulge (32 kHz on its spring) under a 19 kHz disk harmonic: its own mode
    // changes the response far from the rigid slider's.
    let spec = StructureSpec::Bulge {
        mass_kg: 5e-6,
        stiffness_n_per_m: 2e5,
        damping_ratio: 0.05,
    };
    let bulge = check(spec, 300, 0.01e-9, "bulge");
    let rigid = check(StructureSpec::Rigid, 300, 0.01e-9, "rigid");
    assert!(
        bulge > 10.0 * rigid,
        "the bulge's own mode should change the response: {bulge} vs {rigid}"
    );
}

#[test]
fn pitch_follows_the_linear_transmissibility() {
    let (m, k_ab, l) = (1e-6, 3e5, 0.5e-3);
    let (inertia, kp) = (m * l * l / 3.0, k_ab * l * l / 3.0);
    let spec = StructureSpec::Pitch {
        inertia_kg_m2: inertia,
        stiffness_n_m_per_rad: Some(kp),
        coupling_stiffness_n_per_rad: Some(12.0),
        damping_n_m_s_per_rad: Some(2.0 * 0.05 * (kp * inertia).sqrt()),
        coupling_damping_n_s_per_rad: Some(0.0),
        trailing_edge_m: Some(l),
        from_bearing: false,
    };
    check(spec, 500, 0.2e-9, "pitch");
}
