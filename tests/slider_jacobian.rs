//! The slider's analytic Jacobian and `∂f/∂t` against central differences of its right-hand side,
//! in contact (with the contact-impulse and flash-temperature states), for the rigid slider with
//! and without lags, and for the few-peak deformable slider: every row, the flash temperature's
//! included, is the derivative of what the right-hand side reads; the two from one force
//! evaluation (`jacobian_and_time_derivative`) equal the two alone; the right-hand side with the
//! inputs' values of a time kept (`rhs_memo`, what the methods call) is `rhs`'s, to the bit.

use hdi_tribology::heater::Programme;
use hdi_tribology::model::{Dofs, SliderModel, SliderSystem};
use hdi_tribology::ode::{OdeSystem, TimeMemo};
use hdi_tribology::scene::Scene;
use nalgebra::{DMatrix, DVector, Dyn};

#[path = "common/scenes.rs"]
mod scenes;

/// Displacement increment of the differences (m): small against the 0.1 nm scale of the contact
/// forces and above rounding (the differences agree with the derivative to about 1e-6).
const H_DISPLACEMENT: f64 = 1e-14;

/// A state of `sys` with the body displaced so that the bulge gap is `gap` (m), the bulge (if
/// any) at rest on the body, moving towards the disk at `speed` (m/s); lag states set to their
/// targets plus an offset, so that their rows are exercised off equilibrium.
fn contact_state(sys: &SliderSystem, t: f64, gap: f64, speed: f64) -> DVector<f64> {
    let m = sys.model();
    let lay = sys.layout();
    let delta = m.protrusion(sys.inputs().heater.power(t));
    // With a quasi-static bulge, the gap of the undeformed bulge spring (the settled gap is
    // within F/k_b of it).
    let reduced = m.quasi_static_bulge().is_some();
    let gaps_at = |x: f64| {
        let mut q = Dofs::zeros();
        for i in 0..lay.dofs {
            q[i] = x;
        }
        if reduced {
            m.undeformed_gaps(x, delta, 0.0)
        } else {
            m.gaps(&q, delta)
        }
    };
    let at = |x: f64| gaps_at(x).bulge;
    // The bulge gap is affine in a common displacement of every coordinate.
    let (g0, g1) = (at(0.0), at(1e-9));
    let x = (gap - g0) / (g1 - g0) * 1e-9;
    let mut s = DVector::zeros(lay.len());
    for i in 0..lay.dofs {
        s[i] = x;
        s[lay.velocity(i)] = -speed;
    }
    if let Some(i) = lay.delta {
        s[i] = delta * 0.999;
    }
    if let Some(i) = lay.lagged_force {
        s[i] = 0.9 * m.interface_force(gaps_at(x), m.voltage().squared(t)).value;
    }
    s
}

/// Central differences of the right-hand side along each state and along time.
fn differences(sys: &SliderSystem, t: f64, s: &DVector<f64>) -> (DMatrix<f64>, DVector<f64>) {
    let n = s.len();
    let lay = sys.layout();
    let w = sys.model().angular_frequencies();
    // Increments in each state's own scale: displacements, velocities (× ω), forces (× the
    // bearing stiffness), anything else relative to its value.
    let step = |i: usize| -> f64 {
        if i < lay.dofs {
            H_DISPLACEMENT
        } else if i < 2 * lay.dofs {
            H_DISPLACEMENT * w[i - lay.dofs]
        } else if Some(i) == lay.lagged_force {
            H_DISPLACEMENT * 3e5
        } else {
            1e-6 * s[i].abs().max(1e-12)
        }
    };
    let rhs = |t: f64, y: &DVector<f64>| {
        let mut f = DVector::zeros(n);
        OdeSystem::<Dyn>::rhs(sys, t, y, &mut f);
        f
    };
    let mut j = DMatrix::zeros(n, n);
    for c in 0..n {
        let h = step(c);
        let (mut up, mut down) = (s.clone(), s.clone());
        up[c] += h;
        down[c] -= h;
        j.set_column(c, &((rhs(t, &up) - rhs(t, &down)) / (2.0 * h)));
    }
    let ht = 1e-12;
    let dt = (rhs(t + ht, s) - rhs(t - ht, s)) / (2.0 * ht);
    (j, dt)
}

/// Every entry of the analytic Jacobian and `∂f/∂t` agrees with the differences to `1e-5` of its
/// row's largest entry (a row's scale: accelerations, rates of lag states, the heat rate).
fn check(model: &SliderModel, programme: Programme, t: f64, gap: f64, speed: f64) {
    let sys = SliderSystem::new(model, model.inputs(programme), true);
    let lay = sys.layout();
    let s = contact_state(&sys, t, gap, speed);
    let n = s.len();
    let (mut j, mut dt) = (DMatrix::zeros(n, n), DVector::zeros(n));
    assert!(OdeSystem::<Dyn>::jacobian(&sys, t, &s, &mut j));
    assert!(OdeSystem::<Dyn>::time_derivative(&sys, t, &s, &mut dt));
    // The two from one force evaluation (what Rodas5P asks for) are the same numbers, to the bit.
    let (mut j2, mut dt2) = (DMatrix::from_element(n, n, f64::NAN), DVector::zeros(n));
    assert_eq!(
        OdeSystem::<Dyn>::jacobian_and_time_derivative(&sys, t, &s, &mut j2, &mut dt2),
        (true, true)
    );
    assert_eq!((&j2, &dt2), (&j, &dt));
    // The inputs' values kept per time: filled at `t`, read again, replaced at another time
    // (the ramp and the AC move every input), and back.
    let mut memo = TimeMemo::default();
    for tm in [t, t, t + 3.7e-6, t] {
        let (mut want, mut got) = (DVector::zeros(n), DVector::from_element(n, f64::NAN));
        OdeSystem::<Dyn>::rhs(&sys, tm, &s, &mut want);
        OdeSystem::<Dyn>::rhs_memo(&sys, tm, &s, &mut got, &mut memo);
        let bits = |v: &DVector<f64>| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&got), bits(&want), "rhs_memo at t = {tm:e}");
    }
    let (jd, dtd) = differences(&sys, t, &s);
    let heat = lay.heat.expect("integrals on: a heat state");
    assert!(
        j.row(heat).amax() > 0.0,
        "no flash-temperature slope in contact: {j}"
    );
    for r in 0..n {
        let scale = jd.row(r).amax().max(1e-300);
        for c in 0..n {
            let (a, d) = (j[(r, c)], jd[(r, c)]);
            assert!(
                (a - d).abs() <= 1e-5 * scale,
                "J[{r},{c}] = {a:e}, differences {d:e} (row scale {scale:e})"
            );
        }
        let tscale = dtd[r].abs().max(1e-5 * dtd.amax());
        assert!(
            (dt[r] - dtd[r]).abs() <= 1e-5 * tscale.max(1e-300),
            "df/dt[{r}] = {:e}, differences {:e}",
            dt[r],
            dtd[r]
        );
    }
}

/// A heater ramp through `p` (W) at 5 mW/ms, and an AC voltage: both enter `∂f/∂t`.
fn ramp(p: f64) -> Programme {
    Programme::new(vec![(0.0, p - 0.005), (2e-3, p + 0.005)]).unwrap()
}

#[test]
fn rigid_slider_in_contact() {
    let model = SliderModel::from_scene(&Scene::paper())
        .unwrap()
        .with_ac_amplitude(0.5);
    for gap in [0.2e-9, 0.6e-9, 1.0e-9] {
        check(&model, ramp(0.080), 1.1e-3, gap, 1e-4);
    }
}

#[test]
fn rigid_slider_with_interface_and_thermal_lags() {
    let mut scene = Scene::paper();
    scene.slider.interface_lag_s = 1e-9;
    scene.heater.thermal_lag_s = 1e-5;
    let model = SliderModel::from_scene(&scene)
        .unwrap()
        .with_ac_amplitude(0.5);
    check(&model, ramp(0.080), 1.1e-3, 0.5e-9, 1e-4);
}

#[test]
fn few_peak_bulge_in_contact() {
    let scene = scenes::paper_bulge();
    let model = SliderModel::from_scene(&scene)
        .unwrap()
        .with_ac_amplitude(0.5);
    // Between the peaks (1.0 … 2.0 nm high): two, three and all five in contact.
    for gap in [1.6e-9, 1.4e-9, 0.6e-9] {
        check(&model, ramp(0.080), 1.1e-3, gap, 1e-4);
    }
}

/// A stateful term's force on the accelerations and its rate's row (`τ ẋ = a d − x`, `F = k x`).
#[test]
fn rigid_slider_with_a_stateful_term() {
    use hdi_tribology::force::RelaxingState;
    let model = SliderModel::from_scene(&Scene::paper())
        .unwrap()
        .with_ac_amplitude(0.5)
        .with_stateful_term(RelaxingState::new(1e-6, 1e9, -2e-5, None).unwrap())
        .unwrap();
    check(&model, ramp(0.080), 1.1e-3, 0.5e-9, 1e-4);
}

/// The quasi-static bulge: the chain rule through the settled bulge gap, without and with an
/// interface lag (a bulge stiff enough for the check to pass at 0.5 V).
#[test]
fn quasi_static_bulge_in_contact() {
    use hdi_tribology::model::Structure;
    let scene = scenes::paper_bulge();
    let full = SliderModel::from_scene(&scene)
        .unwrap()
        .with_structure(Structure::bulge(scene.slider.mass_kg, 5e-13, 2e6, 0.05).unwrap())
        .with_ac_amplitude(0.5);
    for lag in [0.0, 1e-6] {
        let model = full
            .with_interface_lag(lag)
            .with_quasi_static_bulge()
            .unwrap();
        for gap in [1.6e-9, 1.4e-9, 0.6e-9] {
            check(&model, ramp(0.080), 1.1e-3, gap, 1e-4);
        }
    }
}
