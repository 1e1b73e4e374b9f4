//! Dynamic-cycle cases that once failed, kept as regression tests.

use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, HeaterProgramme};
use hdi_tribology::error::{AnalysisError, Stage};
use hdi_tribology::model::SliderModel;
use hdi_tribology::scene::Scene;
use hdi_tribology::Error;

/// A 100 ns interface lag on the paper scene (c/K_contact ≈ 0.1 ns) makes the contact branch
/// self-excited: the head bounced ever higher and harder and the integration ended with
/// `Ode(NonFinite)` at t ≈ 3.67 ms, 26 nm deep in the disk. It now stops where the pad reaches
/// the disk, with an error that says why.
#[test]
fn self_excited_contact_stops_with_a_reason_instead_of_nan() {
    let mut scene = Scene::paper();
    scene.slider.interface_lag_s = 1e-7;
    let model = SliderModel::from_scene(&scene).unwrap();
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    match simulate_cycle(
        &model,
        &programme,
        &CycleOptions::from_scene(&scene).unwrap(),
    ) {
        Err(Error::Analysis(
            e @ AnalysisError::LeftTheModel {
                self_excited: Some(x),
                ..
            },
        )) => {
            assert_eq!(e.stage(), Stage::Cycle);
            assert!((x.interface_lag_ns - 100.0).abs() < 1e-9, "{e}");
            assert!(x.limit_ns < x.interface_lag_ns, "{e}");
            let text = e.to_string();
            assert!(text.contains("pad gap h0 + y fell to zero"), "{text}");
            assert!(!text.contains('\n'));
        }
        other => panic!("expected the self-excitation error, got {other:?}"),
    }
}

/// A lag below c/K_contact keeps the contact branch stable: the same programme runs through.
#[test]
fn a_short_interface_lag_runs_through() {
    let mut scene = Scene::paper();
    scene.slider.interface_lag_s = 1e-11;
    let model = SliderModel::from_scene(&scene).unwrap();
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    let r = simulate_cycle(
        &model,
        &programme,
        &CycleOptions::from_scene(&scene).unwrap(),
    )
    .unwrap();
    let h = r.hysteresis.unwrap();
    assert!(h > 0.0 && h.is_finite(), "{r:?}");
}

/// A bulge ringing at 142 MHz beside a 0.1 ns interface lag at 1 V AC: the few-peak contact
/// bounces without bound. The cycle used its whole 3e5-step budget (7 s) on the first 73 µs of
/// a 10 ms programme; it now stops once it spends steps at more than twice the even pace.
#[test]
fn a_cycle_spending_steps_too_fast_stops_early() {
    let scene = Scene::from_path(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/paper_bulge.toml"
    ))
    .unwrap();
    let mut model = SliderModel::from_scene(&scene).unwrap();
    model.voltage.ac_amplitude = 1.0;
    model.interface_lag = 1e-10;
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    let mut opts = CycleOptions::from_scene(&scene).unwrap();
    opts.solver.max_steps = 300_000;
    match simulate_cycle(&model, &programme, &opts) {
        Err(Error::Analysis(AnalysisError::StepPace {
            steps, max_steps, ..
        })) => {
            assert_eq!(max_steps, 300_000);
            // The steps spent are named: far fewer than the budget.
            assert!(steps < 100_000, "{steps}");
        }
        other => panic!("expected the step-pace error, got {other:?}"),
    }
}

/// `auto` on a bulge at hundreds of MHz starts with its stiff method (its explicit steps would
/// be limited to about a nanosecond), and gives the same hysteresis as Rodas5P asked for
/// directly, bit for bit.
#[test]
fn auto_on_a_stiff_structure_starts_stiff() {
    use hdi_tribology::model::Structure;
    use hdi_tribology::ode::Method;
    let scene = Scene::paper();
    let mut model = SliderModel::from_scene(&scene).unwrap();
    model.structure = Structure::bulge(scene.slider.mass_kg, 1e-13, 8e5, 0.05).unwrap();
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    let mut opts = CycleOptions::from_scene(&scene).unwrap();
    assert_eq!((opts.solver.method, opts.solver.rtol), (Method::Auto, 1e-6));
    let auto = simulate_cycle(&model, &programme, &opts).unwrap();
    assert_eq!(auto.stats.stiffness_switches, 0, "{:?}", auto.stats);
    assert_eq!(auto.stats.stiff_steps, auto.stats.accepted);
    opts.solver.method = Method::Rodas5P;
    let rodas = simulate_cycle(&model, &programme, &opts).unwrap();
    assert_eq!(auto.hysteresis, rodas.hysteresis);
    assert!(auto.hysteresis.is_some_and(|h| h > 0.0));
    // The rigid paper scene keeps Auto's switching (it starts explicit).
    let rigid = SliderModel::from_scene(&scene).unwrap();
    opts.solver.method = Method::Auto;
    let r = simulate_cycle(&rigid, &programme, &opts).unwrap();
    assert!(r.stats.stiff_steps < r.stats.accepted, "{:?}", r.stats);
}
