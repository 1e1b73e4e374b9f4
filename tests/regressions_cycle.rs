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
