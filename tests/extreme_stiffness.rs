//! Stiffness: in contact the stiff methods take steps far beyond the explicit stability limit,
//! the automatic switch picks the stiff method there, an explicit method on a stiff scene stops
//! with a clear "stiff" error, and the stiffness ratio of every extreme scene is measured
//! (printed with `--nocapture`; the numbers are in `docs/validity.md`).

use hdi_tribology::analysis::cycle::CycleError;
use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, HeaterProgramme};
use hdi_tribology::analysis::equilibrium::{
    flying_equilibrium, Equilibrium, EquilibriumSolver, ScanGrid,
};
use hdi_tribology::heater::Programme;
use hdi_tribology::model::{SliderModel, SliderSystem};
use hdi_tribology::ode::{self, Method, OdeSystem, Options, SaveAt};
use hdi_tribology::scene::Scene;
use hdi_tribology::Error;
use nalgebra::{DMatrix, DVector, Dyn};
use std::path::Path;

/// Explicit Runge–Kutta methods of order 5 are stable only for `|hλ|` below about 3.5 (Tsit5:
/// about 3.5 on the negative real axis, 3.4 on the imaginary one); 5 bounds every direction.
const EXPLICIT_LIMIT: f64 = 5.0;

/// The stable equilibrium on the contact side at `power`: scanning up from the bottom of the
/// table, the first stable one whose protrusion does not exceed `η P`.
fn contact_equilibrium(model: &SliderModel, power: f64) -> Option<Equilibrium> {
    let solver = EquilibriumSolver::new(model, model.voltage().effective_dc().powi(2));
    let (lo, hi) = model.forces().table_range();
    let target = model.protrusion(power);
    let mut grid = ScanGrid::default().descending(lo, hi).ok()?;
    grid.reverse();
    let mut prev: Option<Equilibrium> = None;
    for d in grid {
        let e = solver.at_gap(d).ok()?;
        if e.protrusion <= target && e.is_stable() {
            // Interpolate the gap of the equilibrium at exactly this power.
            let p = prev?;
            let f = (p.protrusion - target) / (p.protrusion - e.protrusion);
            return solver.at_gap(p.d + f * (e.d - p.d)).ok();
        }
        prev = Some(e);
    }
    None
}

/// Magnitudes of the eigenvalues of the slider's Jacobian (dynamic states only) at rest at `e`.
fn eigen_magnitudes(model: &SliderModel, power: f64, e: &Equilibrium) -> Vec<f64> {
    let sys = SliderSystem::new(
        model,
        model.inputs(Programme::constant(power, 1.0).unwrap()),
        false,
    );
    let n = sys.layout().len();
    let s: DVector<f64> = sys.initial_state(Dyn(n), &e.rest());
    let mut j = DMatrix::zeros(n, n);
    assert!(OdeSystem::<Dyn>::jacobian(&sys, 0.0, &s, &mut j));
    j.complex_eigenvalues().iter().map(|z| z.norm()).collect()
}

/// The paper scene with a 1 ns interface lag: in contact its Jacobian has a real eigenvalue near
/// −1e9 1/s next to the contact mode (about 2e6 1/s), a stiff pair.
fn lagged_paper() -> SliderModel {
    let mut scene = Scene::paper();
    scene.slider.interface_lag_s = 1e-9;
    SliderModel::from_scene(&scene).unwrap()
}

/// A 1 ms ramp of 5 mW on the contact branch, from rest at its equilibrium at 90 mW: returns the
/// step sizes of `method`, the largest eigenvalue magnitude at the start, and the statistics.
fn contact_ramp_steps(method: Method) -> (Vec<f64>, f64, ode::Stats) {
    let model = lagged_paper();
    let p0 = 0.090;
    let e = contact_equilibrium(&model, p0).expect("contact equilibrium at 90 mW");
    assert!(e.contact_force > 1e-3, "not in contact: {e:?}");
    let lambda = eigen_magnitudes(&model, p0, &e)
        .into_iter()
        .fold(0.0, f64::max);
    let programme = Programme::new(vec![(0.0, p0), (1e-3, p0 + 0.005)]).unwrap();
    let sys = SliderSystem::new(&model, model.inputs(programme), false);
    assert_eq!(sys.layout().len(), 3);
    let y0: DVector<f64> = sys.initial_state(Dyn(3), &e.rest());
    let (k, m) = (3e5f64, 1e-6f64);
    let opts = Options::default()
        .rtol(1e-6)
        .atol_per_component(vec![1e-14, 1e-14 * (k / m).sqrt(), 1e-14 * k])
        .save(SaveAt::Steps)
        .max_steps(2_000_000);
    let sol = ode::solve(&sys, 0.0, y0, 1e-3, method, &opts, &mut []).unwrap();
    let steps: Vec<f64> = sol.t.windows(2).map(|w| w[1] - w[0]).collect();
    (steps, lambda, sol.stats)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

#[test]
fn stiff_methods_step_far_beyond_the_explicit_limit_in_contact() {
    for method in [Method::Rodas5P, Method::Radau5] {
        let (steps, lambda, _) = contact_ramp_steps(method);
        let m = median(steps.clone()) * lambda;
        println!(
            "{method}: {} steps, median h|λ| = {m:.1}, |λ| = {lambda:.3e} 1/s",
            steps.len()
        );
        // "Far larger": ten times the explicit stability bound.
        assert!(m > 10.0 * EXPLICIT_LIMIT, "{method}: median h|λ| = {m}");
    }
    let (steps, lambda, _) = contact_ramp_steps(Method::Tsit5);
    let m = median(steps.clone()) * lambda;
    println!("tsit5: {} steps, median h|λ| = {m:.2}", steps.len());
    // The explicit method is held at its stability limit: every step, and so the number of
    // steps, is set by |λ| and not by the smooth slow solution.
    assert!(m <= EXPLICIT_LIMIT, "tsit5: median h|λ| = {m}");
    assert!(steps.len() as f64 >= 1e-3 * lambda / EXPLICIT_LIMIT);
}

#[test]
fn auto_switches_to_the_stiff_method_in_contact() {
    let (steps, _, stats) = contact_ramp_steps(Method::Auto);
    println!(
        "auto: {} steps, {} stiff, {} switches",
        steps.len(),
        stats.stiff_steps,
        stats.stiffness_switches
    );
    assert!(stats.stiffness_switches >= 1, "{stats:?}");
    // After the switch, nearly every step is a stiff one.
    assert!(
        stats.stiff_steps as f64 >= 0.8 * stats.accepted as f64,
        "{stats:?}"
    );
}

/// With a 0.6 V AC voltage the steps in contact are held by the dither's accuracy, not by
/// stability: a stiff step there is no longer than an explicit one and costs about twice as
/// much. Auto tries its stiff method, finds that its steps do not pay, and hands back; it used
/// to keep the stiff method for 2 450 of its 5 535 steps and took 1.7× Tsit5's time. Its
/// powers agree with Tsit5's within the tolerance's reach, and at 0 V it still goes stiff in
/// contact, where the stiff steps grow far beyond the explicit ones.
#[test]
fn auto_hands_back_a_stiff_method_that_gains_nothing() {
    let scene = Scene::paper();
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    let mut opts = CycleOptions::from_scene(&scene).unwrap();
    assert_eq!(opts.solver.method, Method::Auto);
    let model = SliderModel::from_scene(&scene).unwrap();
    let dithered = model.with_ac_amplitude(0.6);
    let auto = simulate_cycle(&dithered, &programme, &opts).unwrap();
    opts.solver.method = Method::Tsit5;
    let tsit5 = simulate_cycle(&dithered, &programme, &opts).unwrap();
    let (a, t) = (auto.stats, tsit5.stats);
    println!("0.6 V auto: {a:?}\n0.6 V tsit5: {t:?}");
    assert!(a.stiffness_switches >= 2, "{a:?}");
    assert!(20 * a.stiff_steps < a.accepted, "{a:?}");
    assert!(
        (a.accepted as f64 - t.accepted as f64).abs() < 0.05 * t.accepted as f64,
        "{a:?} against {t:?}"
    );
    for (x, y) in [
        (auto.touchdown, tsit5.touchdown),
        (auto.takeoff, tsit5.takeoff),
    ] {
        let (x, y) = (x.unwrap().power, y.unwrap().power);
        assert!((x - y).abs() < 1e-8, "{x} W against {y} W");
    }
    // At 0 V a quarter of the steps or more are stiff (the contact), and Auto takes fewer than
    // half of Tsit5's steps.
    let explicit = simulate_cycle(&model, &programme, &opts).unwrap().stats;
    opts.solver.method = Method::Auto;
    let plain = simulate_cycle(&model, &programme, &opts).unwrap().stats;
    println!("0 V auto: {plain:?}\n0 V tsit5: {explicit:?}");
    assert!(4 * plain.stiff_steps > plain.accepted, "{plain:?}");
    assert!(2 * plain.accepted < explicit.accepted, "{plain:?}");
}

/// A 1 ns interface lag adds an eigenvalue near −1e9 1/s: the explicit method runs out of its
/// step budget with an error that names the stiffness; the automatic method finishes.
#[test]
fn explicit_method_on_a_stiff_scene_fails_with_a_clear_error() {
    let mut scene = Scene::paper();
    scene.slider.interface_lag_s = 1e-9;
    scene.solver.max_steps = 20_000;
    let model = SliderModel::from_scene(&scene).unwrap();
    let programme = HeaterProgramme::Fixed(
        Programme::new(vec![
            (0.0, 0.066),
            (6e-4, 0.078),
            (7e-4, 0.078),
            (1.3e-3, 0.066),
        ])
        .unwrap(),
    );
    let mut opts = CycleOptions::from_scene(&scene).unwrap();
    opts.solver.method = Method::Tsit5;
    match simulate_cycle(&model, &programme, &opts) {
        // The cycle stops on the step budget itself, or earlier on the pace of its steps;
        // either way it names the stiffness.
        Err(Error::Analysis(e)) => {
            let (t_ms, rate) = match e.downcast_ref::<CycleError>().expect("a cycle error") {
                CycleError::StepLimit {
                    method: "tsit5",
                    max_steps: 20_000,
                    t_ms,
                    fastest_rate_per_s,
                } => (*t_ms, *fastest_rate_per_s),
                CycleError::StepPace {
                    method: "tsit5",
                    max_steps: 20_000,
                    t_ms,
                    stiff_rate_per_s: Some(rate),
                    ..
                } => (*t_ms, *rate),
                other => panic!("expected a stiffness error, got {other:?}"),
            };
            assert!(t_ms > 0.0 && t_ms < 1.3, "{e}");
            assert!(rate > 1e6, "{e}");
            let text = e.to_string();
            assert!(
                text.contains("stiff") && text.contains("20000 steps"),
                "{text}"
            );
            assert!(!text.contains('\n'));
        }
        other => panic!("expected a stiffness error, got {other:?}"),
    }
    opts.solver.method = Method::Auto;
    let r = simulate_cycle(&model, &programme, &opts).unwrap();
    assert!(r.hysteresis.is_some_and(|h| h > 0.0), "{r:?}");
    assert!(r.stats.accepted + r.stats.rejected < 20_000);
}

/// The stiffness ratio of each extreme scene: the largest over the smallest eigenvalue magnitude
/// of the dynamic states, over the flying equilibrium at the programme's start and the contact
/// equilibrium at its highest power.
#[test]
fn stiffness_ratios_of_the_extreme_scenes() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/extreme");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    println!("| scene | flying |λ| (1/s) | contact |λ| (1/s) | ratio | |λ|max × duration |");
    for f in files {
        let scene = Scene::from_path(&f).unwrap();
        let model = SliderModel::from_scene(&scene).unwrap();
        let prog = SliderModel::programme_from_knots(&scene.heater.programme).unwrap();
        let p0 = prog.power(prog.start_time());
        let volt2 = model.voltage().effective_dc().powi(2);
        let mut all = Vec::new();
        let flying = flying_equilibrium(&model, p0, volt2, &ScanGrid::default())
            .ok()
            .map(|e| eigen_magnitudes(&model, p0, &e));
        let contact = contact_equilibrium(&model, prog.max_power())
            .map(|e| eigen_magnitudes(&model, prog.max_power(), &e));
        for v in flying.iter().chain(contact.iter()) {
            all.extend(v.iter().copied());
        }
        if all.is_empty() {
            println!("| {} | – | – | – | – |", scene.name);
            continue;
        }
        let max = all.iter().copied().fold(0.0, f64::max);
        let min = all.iter().copied().fold(f64::INFINITY, f64::min);
        assert!(max.is_finite() && min > 0.0, "{}: {all:?}", scene.name);
        let fmt = |v: &Option<Vec<f64>>| {
            v.as_ref().map_or("–".to_string(), |v| {
                let m = v.iter().copied().fold(0.0, f64::max);
                format!("{m:.2e}")
            })
        };
        println!(
            "| {} | {} | {} | {:.3e} | {:.2e} |",
            scene.name,
            fmt(&flying),
            fmt(&contact),
            max / min,
            max * (prog.end_time() - prog.start_time())
        );
        // Independent check of the Jacobian on two-state scenes: the product of the
        // eigenvalues is K/m with K the total stiffness of the static analysis.
        if model.thermal_lag() == 0.0 && model.interface_lag() == 0.0 {
            if let (Some(v), Ok(e)) = (
                &flying,
                flying_equilibrium(&model, p0, volt2, &ScanGrid::default()),
            ) {
                let prod = v[0] * v[1];
                let want = e.stiffness / model.structure().body_mass();
                assert!(
                    (prod - want).abs() <= 1e-9 * want,
                    "{}: {prod:e} vs {want:e}",
                    scene.name
                );
            }
        }
    }
}
