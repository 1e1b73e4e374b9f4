//! Static analyses: pull-in against closed forms, the paper scene's qualitative targets, and
//! properties of the equilibria (force balance, folds, symmetry about the contact potential).

use hdi_tribology::analysis::*;
use hdi_tribology::force::{Footprint, Gaps};
use hdi_tribology::model::{SliderModel, Voltage};
use hdi_tribology::scene::Scene;
use hdi_tribology::units::EPSILON_0;

#[path = "common/scenes.rs"]
mod scenes;
use scenes::electrostatic_only;

#[test]
fn pull_in_flat_plate_on_linear_spring_matches_closed_form() {
    let area = 1e-11;
    let scene = electrostatic_only(Footprint::Flat { area_m2: area });
    let model = SliderModel::from_scene(&scene).unwrap();
    let opts = StaticOptions::new(scene.detector.contact_threshold_n);
    let pi = pull_in_voltage(&model, 0.0, &opts).unwrap();
    let k = 3e5;
    let g = scene.nominal_clearance_m;
    let exact = (8.0 * k * g.powi(3) / (27.0 * EPSILON_0 * area)).sqrt();
    // The fold is refined to 1e-12 in d on exact forces; V² is stationary there, so V is
    // accurate to far better than 1e-8.
    assert!(
        (pi.voltage / exact - 1.0).abs() < 1e-8,
        "{} vs {exact}",
        pi.voltage
    );
    assert!(
        (pi.d / (2.0 * g / 3.0) - 1.0).abs() < 1e-6,
        "fold at {}",
        pi.d
    );
    assert_eq!(pi.cause, Cause::Fold);
}

#[test]
fn pull_in_smooth_sphere_on_linear_spring_matches_closed_form() {
    let rc = 0.02;
    let scene = electrostatic_only(Footprint::Paraboloid {
        radius_of_curvature_m: rc,
        max_radius_m: None,
    });
    let model = SliderModel::from_scene(&scene).unwrap();
    let opts = StaticOptions::new(scene.detector.contact_threshold_n);
    let g = scene.nominal_clearance_m;
    let exact = 0.5 * g * (3e5 / (std::f64::consts::PI * rc * EPSILON_0)).sqrt();
    let pi = pull_in_voltage(&model, 0.0, &opts).unwrap();
    assert!(
        (pi.voltage / exact - 1.0).abs() < 1e-8,
        "{} vs {exact}",
        pi.voltage
    );
    assert!((pi.d / (0.5 * g) - 1.0).abs() < 1e-6);
    // With protrusion the effective gap shrinks: V_pi(P) uses g = h0 − ηP.
    let p = 0.03;
    let gp = g - 1e-7 * p;
    let exact_p = 0.5 * gp * (3e5 / (std::f64::consts::PI * rc * EPSILON_0)).sqrt();
    let pi_p = pull_in_voltage(&model, p, &opts).unwrap();
    assert!((pi_p.voltage / exact_p - 1.0).abs() < 1e-8);
}

#[test]
fn paper_scene_meets_the_static_targets() {
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene).unwrap();
    let opts = StaticOptions::new(scene.detector.contact_threshold_n);
    let h = static_hysteresis(&model, &opts).unwrap();
    let td = h.touchdown.power * 1e3;
    let to = h.takeoff.power * 1e3;
    // PAPER_SCENE.md: touchdown of tens of mW (50–120), static hysteresis of a few mW (2–10).
    assert!((50.0..120.0).contains(&td), "P_TD = {td} mW");
    assert!((2.0..10.0).contains(&(td - to)), "ΔP = {} mW", td - to);
    assert!(to < td);
    // The flying branch ends at a fold below the threshold; the contact branch likewise.
    assert_eq!(h.touchdown.cause, Cause::Fold);
    assert!(h.touchdown.at.contact_force < opts.contact_threshold);
    let curve = s_curve(&model, None, &ScanGrid::default()).unwrap();
    assert_eq!(curve.folds.len(), 2);
    assert!(curve.folds[0].jump_in && !curve.folds[1].jump_in);
    assert!((curve.folds[0].power - h.touchdown.power).abs() < 1e-12);
    // Pull-in voltage at zero power: several volts (2–10).
    let pi = pull_in_voltage(&model, 0.0, &opts).unwrap();
    assert!((2.0..10.0).contains(&pi.voltage), "V_pi = {}", pi.voltage);
}

#[test]
fn clearance_loss_is_parabolic_and_symmetric_about_the_contact_potential() {
    let mut scene = Scene::paper();
    let phi = 0.3;
    scene.electrostatic.as_mut().unwrap().contact_potential_v = phi;
    let model = SliderModel::from_scene(&scene).unwrap();
    let opts = StaticOptions::new(scene.detector.contact_threshold_n);
    let v = [phi - 1.0, phi - 0.5, phi, phi + 0.5, phi + 1.0];
    let c = clearance_change(&model, &v, &opts).unwrap();
    // Symmetric about φ to the fold tolerance (1e-12 relative in d).
    assert!((c[0].clearance_change - c[4].clearance_change).abs() < 1e-15);
    assert!((c[1].clearance_change - c[3].clearance_change).abs() < 1e-15);
    assert!(c[2].clearance_change.abs() < 1e-15);
    // A loss of clearance, of order 0.1–2 nm at 1 V.
    let at1 = -c[4].clearance_change * 1e9;
    assert!((0.1..2.0).contains(&at1), "ΔFH(1 V) = {at1} nm");
    assert!(c[3].clearance_change < 0.0);
    // Parabolic to leading order: quadrupling from 0.5 V to 1 V, within the curvature of the
    // pull-in nonlinearity (the ratio tends to 4 as V → 0).
    let ratio = c[4].clearance_change / c[3].clearance_change;
    assert!((3.3..4.0).contains(&ratio), "ratio {ratio}");
}

#[test]
fn equilibria_satisfy_the_force_balance() {
    let mut scene = Scene::paper();
    scene.voltage.dc_v = 1.0;
    let model = SliderModel::from_scene(&scene).unwrap();
    let curve = s_curve(&model, None, &ScanGrid::default()).unwrap();
    let volt2 = 1.0;
    for e in curve.points.iter().step_by(97) {
        let g = Gaps {
            bulge: e.d,
            pad: model.nominal_clearance() + e.y,
        };
        let f = model.interface_force_exact(g, volt2).unwrap().value;
        let fab = model.bearing().force(e.y, 0.0);
        // Tables agree with direct quadrature to 1e-8 relative: so does the balance.
        let scale = fab.abs().max(f.abs()).max(1e-12);
        assert!((fab + f).abs() < 2e-8 * scale, "d = {}: {fab} + {f}", e.d);
    }
}

#[test]
fn fold_is_a_power_maximum_of_the_flying_branch() {
    let model = SliderModel::from_scene(&Scene::paper()).unwrap();
    let opts = StaticOptions::new(5e-5);
    let td = touchdown_power(&model, &opts).unwrap();
    let solver = equilibrium::EquilibriumSolver::new(&model, 0.0);
    for delta in [1e-12, 1e-11] {
        let above = solver.at_gap_exact(td.at.d + delta).unwrap();
        let below = solver.at_gap_exact(td.at.d - delta).unwrap();
        assert!(above.power < td.power && below.power < td.power);
        assert!(above.is_stable() && !below.is_stable());
    }
    // The same fold without voltage terms' help: a DC voltage lowers touchdown.
    let m1 = model.with_voltage(Voltage {
        dc: 1.0,
        ..model.voltage()
    });
    assert!(touchdown_power(&m1, &opts).unwrap().power < td.power);
}

#[test]
fn static_options_reject_bad_thresholds() {
    let model = SliderModel::from_scene(&Scene::paper()).unwrap();
    let e = touchdown_power(&model, &StaticOptions::new(-1.0)).unwrap_err();
    assert!(e.to_string().contains("contact_threshold"));
    let e = takeoff_power(&model, f64::NAN, &StaticOptions::new(5e-5)).unwrap_err();
    assert!(e.to_string().contains("start_power"));
}

#[test]
fn a_rougher_disk_has_no_folds_and_no_static_hysteresis() {
    // The letter: "for high roughness the contact force dominates". With σ = 1 nm the contact
    // stiffness grows before the adhesion can fold the branch: touchdown and take-off both come
    // at the threshold, at the same gap.
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/rough_disk.toml");
    let scene = Scene::from_path(path).unwrap();
    let model = SliderModel::from_scene(&scene).unwrap();
    let curve = s_curve(&model, None, &ScanGrid::default()).unwrap();
    assert!(curve.folds.is_empty());
    let h = static_hysteresis(
        &model,
        &StaticOptions::new(scene.detector.contact_threshold_n),
    )
    .unwrap();
    assert_eq!(h.touchdown.cause, Cause::Threshold);
    assert_eq!(h.takeoff.cause, Cause::Threshold);
    assert!(h.hysteresis.abs() < 1e-12, "{}", h.hysteresis);
}

/// The same kind of analysis error (its numbers may differ by rounding: a fold at 0 W lies at
/// ±1e-14 mW), or the same message for any other error.
fn same_error(a: &hdi_tribology::Error, b: &hdi_tribology::Error) -> bool {
    use hdi_tribology::Error::Analysis;
    match (a, b) {
        (Analysis(x), Analysis(y)) => x.kind() == y.kind(),
        _ => a.to_string() == b.to_string(),
    }
}

/// Refining on the tables and polishing with direct forces finds the same folds and threshold
/// crossings as Brent's method on the direct forces alone (both to 1e-12 relative in the gap),
/// on the paper scene and on every extreme scene, or fails with the same error.
#[test]
fn polishing_from_the_tables_finds_the_direct_roots() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/extreme");
    let mut scenes = vec![Scene::paper()];
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    for f in files {
        scenes.push(Scene::from_path(&f).unwrap());
    }
    for scene in scenes {
        let model = SliderModel::from_scene(&scene).unwrap();
        let mut direct = StaticOptions::new(scene.detector.contact_threshold_n);
        direct.grid.polish_from_tables = false;
        let polished = StaticOptions::new(scene.detector.contact_threshold_n);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-10 * a.abs().max(1e-6);
        match (
            static_hysteresis(&model, &direct),
            static_hysteresis(&model, &polished),
        ) {
            (Ok(a), Ok(b)) => {
                assert!(
                    close(a.touchdown.power, b.touchdown.power),
                    "{}",
                    scene.name
                );
                assert!(close(a.takeoff.power, b.takeoff.power), "{}", scene.name);
                assert!(close(a.touchdown.at.d, b.touchdown.at.d), "{}", scene.name);
                assert_eq!(a.touchdown.cause, b.touchdown.cause);
            }
            (Err(a), Err(b)) => assert!(same_error(&a, &b), "{}: {a} vs {b}", scene.name),
            (a, b) => panic!("{}: {a:?} vs {b:?}", scene.name),
        }
        if model.forces().has_voltage_terms() {
            match (
                pull_in_voltage(&model, 0.0, &direct),
                pull_in_voltage(&model, 0.0, &polished),
            ) {
                (Ok(a), Ok(b)) => assert!(close(a.voltage, b.voltage), "{}", scene.name),
                (Err(a), Err(b)) => assert!(same_error(&a, &b), "{}: {a} vs {b}", scene.name),
                (a, b) => panic!("{}: {a:?} vs {b:?}", scene.name),
            }
        }
    }
}
