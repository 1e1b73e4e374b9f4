//! The quasi-static bulge (`model::QuasiStaticBulge`) against the full structure: a cycle of the
//! few-peak deformable slider on the reduced model gives touchdown, take-off and hysteresis
//! within the stated accuracy of the full model's where the check passes; the check refuses a
//! soft bulge (one that folds on its own under the adhesion), a lightly damped one and a lag that
//! is not slow against the bulge; the reduced model's rest is the full model's.

use hdi_tribology::analysis::{simulate_cycle, CycleOptions, CycleResult, HeaterProgramme};
use hdi_tribology::model::{SliderModel, SliderSystem, Structure};
use hdi_tribology::ode::OdeSystem;
use hdi_tribology::scene::Scene;
use nalgebra::{DVector, Dyn};

#[path = "common/scenes.rs"]
mod scenes;

/// The stated accuracy of the reduced model's touchdown and take-off where its check passes (W):
/// a tenth of the maps' convergence tolerance of 0.05 mW.
const ACCURACY: f64 = 5e-6;

fn scene() -> Scene {
    scenes::paper_bulge()
}

fn cycle(model: &SliderModel, scene: &Scene, rtol: f64) -> CycleResult {
    let programme =
        HeaterProgramme::Fixed(SliderModel::programme_from_knots(&scene.heater.programme).unwrap());
    let mut opts = CycleOptions::from_scene(scene).unwrap();
    opts.solver = opts.solver.with_rtol(rtol);
    simulate_cycle(model, &programme, &opts).unwrap()
}

/// Touchdown and take-off of one cycle (W).
fn powers(r: &CycleResult) -> (f64, f64) {
    (
        r.touchdown.expect("touchdown").power,
        r.takeoff.expect("take-off").power,
    )
}

/// Where the check passes, the reduced cycle's touchdown and take-off are the full one's within
/// the stated accuracy: the scene's bulge and a bulge five times stiffer at 0 V; on the stiffer
/// one at 0.6 V AC (where the scene's bulge is refused) touchdown to the same accuracy and
/// take-off only to about a period of V² at the ramp rate (0.24 mW; measured 0.254 mW: with AC a
/// take-off lands on a period of V² that a small change moves, on either model, see
/// docs/analyses.md, "Why a method check"; the bound is one and a half periods).
#[test]
fn reduced_cycle_is_the_full_one_within_its_accuracy() {
    let scene = scene();
    let base = SliderModel::from_scene(&scene).unwrap();
    let stiff =
        base.with_structure(Structure::bulge(scene.slider.mass_kg, 5e-13, 2e6, 0.05).unwrap());
    let period = 5.0 * scene.detector.window_s;
    for (full, rtol, takeoff) in [
        (base.clone(), 1e-6, ACCURACY),
        (stiff.clone(), 1e-6, ACCURACY),
        (stiff.with_ac_amplitude(0.6), 1e-8, 1.5 * period),
    ] {
        let check = full.quasi_static_check().unwrap();
        assert!(check.passes(), "{check:?}");
        let reduced = full.with_quasi_static_bulge().unwrap();
        let ((td, to), (td_r, to_r)) = (
            powers(&cycle(&full, &scene, rtol)),
            powers(&cycle(&reduced, &scene, rtol)),
        );
        assert!(
            (td - td_r).abs() <= ACCURACY && (to - to_r).abs() <= takeoff,
            "full TD {td} TO {to}, reduced TD {td_r} TO {to_r}"
        );
    }
    // The scene's own bulge at 0.4 V: the electrostatic slope at the peak of V² exceeds the
    // bulge spring, the bulge folds on its own, and the check refuses it.
    let refused = base.with_ac_amplitude(0.4).quasi_static_check().unwrap();
    assert!(
        !refused.passes() && refused.fast_stiffness < 0.0,
        "{refused:?}"
    );
}

#[test]
fn the_check_refuses_a_bulge_that_is_not_fast() {
    let scene = scene();
    let base = SliderModel::from_scene(&scene).unwrap();
    let (body, mass) = (scene.slider.mass_kg, 5e-13);
    let refused = |s: Structure, lag: f64| {
        let c = base
            .with_structure(s)
            .with_interface_lag(lag)
            .quasi_static_check()
            .unwrap();
        assert!(!c.passes(), "{c:?}");
        assert!(c.require().is_err());
        c.refused.join("; ")
    };
    // A soft bulge: the tip's adhesion is steeper than its spring, it folds on its own.
    let soft = refused(Structure::bulge(body, mass, 2e4, 0.05).unwrap(), 0.0);
    assert!(soft.contains("folds"), "{soft}");
    // A lightly damped one: its ringing outlasts the slow system's time scale.
    let ringing = refused(Structure::bulge(body, mass, 4e5, 1e-3).unwrap(), 0.0);
    assert!(ringing.contains("decays"), "{ringing}");
    // A nanosecond lag: as fast as the bulge, it drives it.
    let lagged = refused(Structure::bulge(body, mass, 4e5, 0.05).unwrap(), 1e-9);
    assert!(
        lagged.contains("slow rate") || lagged.contains("lag"),
        "{lagged}"
    );
    // A stiff, well-damped bulge passes.
    let stiff = base
        .with_structure(Structure::bulge(body, mass, 4e7, 0.05).unwrap())
        .quasi_static_check()
        .unwrap();
    assert!(stiff.passes(), "{stiff:?}");
    // Structures without a bulge of their own are no candidates.
    assert!(base
        .with_structure(Structure::rigid(body).unwrap())
        .with_quasi_static_bulge()
        .is_err());
}

/// At the full model's static equilibrium the reduced model is at rest too, and its settled
/// bulge gap is the full model's.
#[test]
fn the_reduced_rest_is_the_full_rest() {
    use hdi_tribology::analysis::{flying_equilibrium, ScanGrid};
    let full = SliderModel::from_scene(&scene()).unwrap();
    let reduced = full.with_quasi_static_bulge().unwrap();
    for p in [0.06, 0.075] {
        let eq = flying_equilibrium(&full, p, 0.0, &ScanGrid::default()).unwrap();
        let d_full = full.gaps(&eq.q, eq.protrusion).bulge;
        let sys = SliderSystem::new(
            &reduced,
            reduced.inputs(hdi_tribology::model::Heater::Power(p)),
            false,
        );
        let s: DVector<f64> = sys.initial_state(Dyn(sys.layout().len()), &eq.rest());
        assert_eq!(sys.layout().len(), 2);
        let d = sys.gaps(0.0, &s).bulge;
        assert!((d - d_full).abs() < 1e-16, "{d} vs {d_full}");
        let mut ds = DVector::zeros(2);
        OdeSystem::<Dyn>::rhs(&sys, 0.0, &s, &mut ds);
        // The body's acceleration against that of a 1 pm displacement on the bearing.
        let scale = 3e5 * 1e-12 / scene().slider.mass_kg;
        assert!(ds[1].abs() < 1e-6 * scale, "{ds}");
    }
}
