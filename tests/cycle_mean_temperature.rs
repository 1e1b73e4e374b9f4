//! `CycleOptions::mean_temperature`: a cycle that leaves the heat integral out of its state
//! reports no mean temperature (NaN), runs on one state fewer, and finds touchdown and take-off
//! as accurately as the cycle that keeps it: both against a reference run 10⁴ times tighter, within
//! the heater power that moves the clearance by the displacement tolerance.

use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, HeaterProgramme};
use hdi_tribology::heater::Programme;
use hdi_tribology::model::{SliderModel, Structure};
use hdi_tribology::ode::Method;
use hdi_tribology::scene::Scene;
use hdi_tribology::sim::Problem;

#[path = "common/scenes.rs"]
mod scenes;

/// The paper scene at 0 and 0.6 V, and the few-peak rigid slider with a 10 ns interface lag at
/// 0.55 V (intermittent contact on five Hertz peaks).
fn cases() -> Vec<(
    &'static str,
    SliderModel,
    HeaterProgramme,
    CycleOptions,
    f64,
)> {
    let paper = Scene::paper();
    let few = scenes::paper_bulge();
    let mut out = Vec::new();
    for (name, scene, v_ac) in [
        ("paper, 0 V", &paper, 0.0),
        ("paper, 0.6 V", &paper, 0.6),
        ("few-peak rigid, 10 ns lag, 0.55 V", &few, 0.55),
    ] {
        let mut model = SliderModel::from_scene(scene)
            .unwrap()
            .with_ac_amplitude(v_ac);
        if scene.name != paper.name {
            model = model
                .with_interface_lag(1e-8)
                .with_structure(Structure::rigid(scene.slider.mass_kg).unwrap());
        }
        let programme = HeaterProgramme::fixed_from_scene(scene).unwrap();
        let mut opts = CycleOptions::from_scene(scene).unwrap();
        opts.stop_at_takeoff = true;
        let bound = opts.solver.atol_displacement / scene.heater.efficiency_m_per_w;
        out.push((name, model, programme, opts, bound));
    }
    out
}

#[test]
fn a_cycle_without_the_mean_temperature_runs_one_state_fewer() {
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene).unwrap();
    let inputs = model.inputs(Programme::constant(0.06, 1e-3).unwrap());
    let with = Problem::builder(&model, inputs.clone(), true);
    let without = Problem::builder(&model, inputs, true).without_heat();
    assert_eq!(with.system().layout().len(), 4);
    assert_eq!(without.system().layout().len(), 3);
    assert_eq!(without.system().layout().heat, None);
    assert_eq!(without.system().layout().contact_impulse, Some(2));
    // The paper scene's cycle then runs on a state of three components.
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    let mut opts = CycleOptions::from_scene(&scene).unwrap();
    opts.mean_temperature = false;
    let r = simulate_cycle(&model, &programme, &opts).unwrap();
    assert!(r.mean_temperature_rise.is_nan());
    assert!(r.touchdown.is_some() && r.takeoff.is_some());
}

#[test]
fn leaving_the_mean_temperature_out_keeps_the_accuracy_of_the_powers() {
    for (name, model, programme, opts, bound) in cases() {
        let mut tight = opts;
        tight.solver.method = Method::Radau5;
        tight.solver = tight.solver.with_rtol(tight.solver.rtol * 1e-4);
        let reference = simulate_cycle(&model, &programme, &tight).unwrap();
        let with = simulate_cycle(&model, &programme, &opts).unwrap();
        let mut o = opts;
        o.mean_temperature = false;
        let without = simulate_cycle(&model, &programme, &o).unwrap();
        assert!(with.mean_temperature_rise > 0.0 && without.mean_temperature_rise.is_nan());
        for r in [&with, &without] {
            for (what, a, b) in [
                ("touchdown", r.touchdown, reference.touchdown),
                ("take-off", r.takeoff, reference.takeoff),
            ] {
                let (a, b) = (a.unwrap().power, b.unwrap().power);
                assert!(
                    (a - b).abs() <= bound,
                    "{name}: {what} {a} W against {b} W (bound {bound:e} W)"
                );
            }
        }
    }
}

/// A refined sweep without the mean temperature compares the powers alone: the temperature
/// change it reports is NaN, and it converges where the sweep with the temperature does.
#[test]
fn a_refined_sweep_without_the_mean_temperature_compares_the_powers() {
    use hdi_tribology::analysis::sweep::{ac_sweep_refined, Refinement};
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene).unwrap();
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    let mut opts = CycleOptions::from_scene(&scene).unwrap();
    let refine = Refinement::new(6e-5);
    let with = ac_sweep_refined(&model, &programme, &opts, &[0.0], &refine).unwrap();
    opts.mean_temperature = false;
    let without = ac_sweep_refined(&model, &programme, &opts, &[0.0], &refine).unwrap();
    assert!(with[0].converged && without[0].converged);
    assert!(with[0].temperature_change <= refine.temperature_tol);
    assert!(without[0].temperature_change.is_nan());
    assert!(without[0].change <= refine.power_tol);
}
