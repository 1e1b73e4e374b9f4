//! The energy audit of the interface lag (docs/validity.md, "The lag's energy audit"): the work
//! a cycle reports is checked against an independent integration of the same powers at a tighter
//! tolerance with adaptive quadrature, against the first-order law `F_eff − F ≈ −τ dF/dt`, and
//! against the damping's closed form `c v²` of the paper scene's linear bearing.

use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, HeaterProgramme};
use hdi_tribology::analysis::{flying_equilibrium, ScanGrid};
use hdi_tribology::model::SliderModel;
use hdi_tribology::quadrature::{integrate, QuadOptions};
use hdi_tribology::scene::Scene;
use hdi_tribology::sim::{self, Flow, Observer, Problem, StepView};

/// Work integrals along a run, each step's interpolant integrated by adaptive Gauss–Kronrod from
/// the public state and forces alone (not through the crate's audit).
#[derive(Default)]
struct Reference {
    model: Option<SliderModel>,
    tau: f64,
    /// `∫ (F_eff − F(d)) v dt` from the lagged-force state.
    lag: f64,
    /// `−τ ∫ (dF/dt) v dt`, `dF/dt` by central differences along the interpolant (when asked
    /// for: under AC the differences of `V²` make the quadrature's work large).
    first_order: f64,
    with_first_order: bool,
    /// `∫ c v² dt`.
    damping: f64,
}

impl Observer for Reference {
    fn accepted(&mut self, step: &StepView<'_>) -> hdi_tribology::Result<Flow> {
        let model = self.model.as_ref().unwrap();
        let p = step.last_step;
        let sys = step.system;
        let lag_index = sys.layout().lagged_force.unwrap();
        let v_index = sys.layout().velocity(0);
        let mut y = vec![0.0; p.n];
        let force_at = |t: f64, y: &mut Vec<f64>| {
            p.state_at(t, y);
            let g = sys.gaps(t, y.as_slice());
            model.hot_values(g, model.voltage().squared(t)).interface
        };
        let (a, b) = (p.t0, step.t);
        let e = 1e-4 * p.h;
        let q = QuadOptions {
            // Totals of 1e-15 J and more, over at most some 1e5 steps.
            abs_tol: 1e-25,
            rel_tol: 1e-8,
            max_intervals: 2000,
        };
        let value = |f: &mut dyn FnMut(f64) -> f64| integrate(f, a, b, &q).unwrap().value;
        let mut yy = y.clone();
        self.lag += value(&mut |t| {
            let f = force_at(t, &mut y);
            (y[lag_index] - f) * y[v_index]
        });
        let tau = self.tau;
        if self.with_first_order {
            self.first_order += value(&mut |t| {
                let rate = (force_at(t + e, &mut yy) - force_at(t - e, &mut yy)) / (2.0 * e);
                p.state_at(t, &mut y);
                -tau * rate * y[v_index]
            });
        }
        self.damping += value(&mut |t| {
            p.state_at(t, &mut y);
            model.bearing().damping(y[0]) * y[v_index] * y[v_index]
        });
        Ok(Flow::Continue)
    }
}

/// The paper scene's cycle (fixed, or triggered: its heater ramp turns after touchdown, and the
/// run goes on under the new programme) with an interface lag `tau` at AC amplitude `v_ac`: the
/// cycle's audit at rtol `rtol`, and the reference along an integration of the programme the
/// cycle ran at a hundredfold tighter one.
fn audit(
    tau: f64,
    v_ac: f64,
    rtol: f64,
    triggered: bool,
) -> (hdi_tribology::analysis::LagEnergy, Reference) {
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene)
        .unwrap()
        .with_interface_lag(tau)
        .with_ac_amplitude(v_ac);
    let programme = if triggered {
        HeaterProgramme::triggered_from_scene(&scene)
    } else {
        HeaterProgramme::fixed_from_scene(&scene).unwrap()
    };
    let mut opts = CycleOptions::from_scene(&scene).unwrap();
    opts.solver = opts.solver.with_rtol(rtol);
    let cycle = simulate_cycle(&model, &programme, &opts).unwrap();
    let energy = cycle.lag_energy.expect("an interface lag is audited");
    let p = cycle.programme;

    let tight = opts.solver.with_rtol(rtol / 100.0);
    let (t0, t1) = (p.start_time(), p.end_time());
    let rest = flying_equilibrium(
        &model,
        p.power(t0),
        model.voltage().squared(t0),
        &ScanGrid::default(),
    )
    .unwrap()
    .rest();
    let problem = Problem::builder(&model, model.inputs(p), false)
        .rtol(tight.rtol)
        .tolerances(tight.atol_displacement, 1.0, 1.0)
        .max_step(None)
        .max_steps(10_000_000)
        .dense()
        .build()
        .unwrap();
    let n = problem.system().layout().len();
    let y0 = problem.initial_state(nalgebra::Dyn(n), &rest);
    let mut it = problem.integrator(t0, y0, t1).unwrap();
    let mut reference = Reference {
        model: Some(model),
        tau,
        with_first_order: v_ac == 0.0,
        ..Default::default()
    };
    sim::run(&mut it, None, &mut reference, Into::into).unwrap();
    (energy, reference)
}

#[test]
fn without_a_lag_there_is_no_audit_and_no_json_key() {
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene).unwrap();
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    let r = simulate_cycle(
        &model,
        &programme,
        &CycleOptions::from_scene(&scene).unwrap(),
    )
    .unwrap();
    assert_eq!(r.lag_energy, None);
    let json = serde_json::to_value(&r).unwrap();
    assert!(json.get("lag_work_j").is_none() && json.get("damping_work_j").is_none());
    // With a lag but the audit turned off, none either.
    let mut off = CycleOptions::from_scene(&scene).unwrap();
    off.energy_audit = false;
    let lagged = model.with_interface_lag(2e-8);
    assert_eq!(
        simulate_cycle(&lagged, &programme, &off)
            .unwrap()
            .lag_energy,
        None
    );
}

#[test]
fn a_triggered_cycle_is_audited_over_the_programme_it_ran() {
    let (e, r) = audit(1e-8, 0.0, 1e-8, true);
    println!(
        "lag {:e} (reference {:e}), damping {:e} (reference {:e})",
        e.lag_work, r.lag, e.damping_work, r.damping
    );
    assert!((e.lag_work - r.lag).abs() <= 1e-4 * r.lag.abs());
    assert!((e.damping_work - r.damping).abs() <= 1e-6 * r.damping);
}

#[test]
fn the_audit_matches_an_independent_integration_and_the_first_order_law() {
    let mut first_order_error = Vec::new();
    for tau in [2e-9, 1e-9] {
        let (e, r) = audit(tau, 0.0, 1e-8, false);
        println!(
            "tau {tau:e}: lag {:e} (reference {:e}, first order {:e}), damping {:e} (reference {:e})",
            e.lag_work, r.lag, r.first_order, e.damping_work, r.damping
        );
        // The same integrals along two integrations a hundredfold apart in tolerance.
        assert!((e.lag_work - r.lag).abs() <= 1e-3 * r.lag.abs(), "lag work");
        assert!(
            (e.damping_work - r.damping).abs() <= 1e-6 * r.damping,
            "damping work"
        );
        // The lag puts energy in: the contact branch's F' < 0 makes −τ F' ḋ² positive.
        assert!(r.lag > 0.0 && r.first_order > 0.0);
        first_order_error.push((r.lag / r.first_order - 1.0).abs());
    }
    // First order in τ: the relative deviation is small and halves with τ.
    let (at2, at1) = (first_order_error[0], first_order_error[1]);
    println!("first-order deviation: {at2:e} at 2 ns, {at1:e} at 1 ns");
    assert!(at1 < 0.02, "{at1}");
    assert!(at1 < 0.7 * at2 && at1 > 0.3 * at2, "{at2} → {at1}");
}

#[test]
fn with_ac_the_audit_matches_the_independent_integration() {
    let (e, r) = audit(2e-8, 0.6, 1e-8, false);
    println!(
        "lag {:e} (reference {:e}), damping {:e} (reference {:e})",
        e.lag_work, r.lag, e.damping_work, r.damping
    );
    // Under AC the contact bounces at every peak of V²: the two integrations' trajectories
    // themselves differ at the 1e-4 level, and both works with them.
    assert!((e.lag_work - r.lag).abs() <= 1e-3 * r.lag.abs());
    assert!((e.damping_work - r.damping).abs() <= 1e-3 * r.damping);
    // Here the lag puts in a sizeable share of what the damping takes out.
    assert!(e.lag_work > 0.1 * e.damping_work && e.lag_work < e.damping_work);
}
