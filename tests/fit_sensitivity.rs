//! The static transitions' sensitivities (`analysis::transition_shift`, which the fit's Jacobian
//! uses) against finite differences of transitions found again from scratch on fully tabulated
//! models, for every kind of parameter: forces (σ, A), voltage (φ), heater (η), geometry (h0),
//! structure (k); at folds and at threshold crossings.

use hdi_tribology::analysis::{static_hysteresis, transition_shift, StaticOptions, Transition};
use hdi_tribology::force::AirBearingModel;
use hdi_tribology::model::{SliderModel, Voltage};
use hdi_tribology::scene::Scene;
use hdi_tribology::surface::PeakModel;

type Setter = fn(&mut Scene, f64);
type Getter = fn(&Scene) -> f64;

fn set_sigma(s: &mut Scene, v: f64) {
    s.surface.height_sigma_m = v;
    if let PeakModel::RiceMaxima { sigma_m, .. } = &mut s.surface.peaks {
        *sigma_m = v;
    }
}

fn params() -> Vec<(&'static str, Setter, Getter)> {
    vec![
        ("height_sigma", set_sigma, |s| s.surface.height_sigma_m),
        (
            "hamaker_attractive",
            |s, v| s.intermolecular.as_mut().unwrap().hamaker_attractive_j = v,
            |s| s.intermolecular.as_ref().unwrap().hamaker_attractive_j,
        ),
        (
            "contact_potential",
            |s, v| s.electrostatic.as_mut().unwrap().contact_potential_v = v,
            |s| s.electrostatic.as_ref().unwrap().contact_potential_v,
        ),
        (
            "efficiency",
            |s, v| s.heater.efficiency_m_per_w = v,
            |s| s.heater.efficiency_m_per_w,
        ),
        (
            "nominal_clearance",
            |s, v| s.nominal_clearance_m = v,
            |s| s.nominal_clearance_m,
        ),
        (
            "stiffness",
            |s, v| {
                if let AirBearingModel::Linear {
                    stiffness_n_per_m, ..
                } = &mut s.air_bearing
                {
                    *stiffness_n_per_m = v;
                }
            },
            |s| match s.air_bearing {
                AirBearingModel::Linear {
                    stiffness_n_per_m, ..
                } => stiffness_n_per_m,
                _ => panic!("linear bearing expected"),
            },
        ),
    ]
}

fn at_dc(m: &SliderModel, dc: f64) -> SliderModel {
    m.with_voltage(Voltage {
        dc,
        ac_amplitude: 0.0,
        ..m.voltage()
    })
}

/// Both transitions of the scene at `dc`.
fn transitions(scene: &Scene, dc: f64) -> (SliderModel, [Transition; 2]) {
    let m = at_dc(&SliderModel::from_scene(scene).unwrap(), dc);
    let h = static_hysteresis(&m, &StaticOptions::new(scene.detector.contact_threshold_n)).unwrap();
    (m, [h.touchdown, h.takeoff])
}

/// Checks every parameter at every voltage; returns the causes met.
fn check(scene: &Scene, voltages: &[f64]) -> Vec<String> {
    let mut causes = Vec::new();
    for &dc in voltages {
        let (m0, t0) = transitions(scene, dc);
        for (name, set, get) in params() {
            let v = get(scene);
            let h = if v == 0.0 { 1e-3 } else { 1e-3 * v.abs() };
            let moved = |sign: f64| {
                let mut s = scene.clone();
                set(&mut s, v + sign * h);
                s
            };
            let (plus, minus) = (moved(1.0), moved(-1.0));
            let (mp, tp) = transitions(&plus, dc);
            let (mm, tm) = transitions(&minus, dc);
            for k in 0..2 {
                let t = &t0[k];
                // From scratch: the whole static analysis on each side.
                let fd = (tp[k].power - tm[k].power) / (2.0 * h);
                // From the transition alone.
                let sens = (transition_shift(&m0, &mp, t).unwrap()
                    - transition_shift(&m0, &mm, t).unwrap())
                    / (2.0 * h);
                let scale = fd.abs().max(1e-6 * t.power / v.abs().max(1e-3));
                let what = if k == 0 { "touchdown" } else { "take-off" };
                println!(
                    "V_dc {dc:+.2} {what:<9} {:?} ∂P/∂{name}: re-solved {fd:+.6e}, sensitivity {sens:+.6e}",
                    t.cause
                );
                assert!(
                    (fd - sens).abs() <= 1e-4 * scale,
                    "V_dc {dc}, {what} ({:?}), {name}: re-solved {fd:e}, sensitivity {sens:e}",
                    t.cause
                );
                causes.push(format!("{:?}", t.cause));
            }
        }
    }
    causes
}

#[test]
fn fold_sensitivities_match_transitions_found_again() {
    let mut scene = Scene::paper();
    scene.electrostatic.as_mut().unwrap().contact_potential_v = 0.2;
    let causes = check(&scene, &[-0.4, 0.8]);
    assert!(causes.iter().any(|c| c == "Fold"), "{causes:?}");
}

#[test]
fn threshold_sensitivities_match_transitions_found_again() {
    // A stiff air bearing leaves no fold: touchdown and take-off are threshold crossings.
    let mut scene = Scene::paper();
    scene.electrostatic.as_mut().unwrap().contact_potential_v = 0.2;
    scene.air_bearing = AirBearingModel::Linear {
        stiffness_n_per_m: 3e7,
        damping_n_s_per_m: 0.0548,
    };
    let causes = check(&scene, &[0.3]);
    assert!(causes.iter().any(|c| c == "Threshold"), "{causes:?}");
}
