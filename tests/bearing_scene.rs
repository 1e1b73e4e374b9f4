//! A scene whose air bearing is solved from the slider's geometry (`model = "reynolds"`): the
//! geometry named relative to the scene file, the lumped stiffness the model uses equal to the
//! bearing's own at the attitude, typed errors for a missing or bad geometry, and `hdi static`
//! and `hdi cycle` running on it.

use std::path::{Path, PathBuf};

use hdi_tribology::bearing::{solve_attitude, AttitudeOptions, BearingSpec};
use hdi_tribology::force::AirBearingModel;
use hdi_tribology::model::SliderModel;
use hdi_tribology::scene::Scene;
use hdi_tribology::Error;

const CELLS: usize = 65;

fn example() -> &'static str {
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/bearing/two_rail_taper_flat.toml"
    )
}

/// The paper's scene with its air bearing solved from `geometry` (as written in the scene),
/// written with a copy of the example slider as `bearing.toml` in `dir`.
fn scene_file(dir: &Path, geometry: &str) -> PathBuf {
    std::fs::copy(example(), dir.join("bearing.toml")).unwrap();
    let mut scene = Scene::paper();
    scene.air_bearing = AirBearingModel::Reynolds {
        geometry: geometry.into(),
        cells: Some(CELLS),
        radius_mm: None,
        rpm: None,
        skew_deg: None,
        preload_mn: None,
    };
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene.to_toml_string().unwrap()).unwrap();
    path
}

#[test]
fn the_model_uses_the_bearings_own_stiffness_and_damping() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Scene::from_path(scene_file(dir.path(), "bearing.toml")).unwrap();
    let model = SliderModel::from_scene(&scene).unwrap();
    let mut spec = BearingSpec::from_path(example()).unwrap();
    spec.grid.nx = CELLS;
    spec.grid.ny = CELLS;
    let eq = solve_attitude(&spec.build().unwrap(), &AttitudeOptions::default()).unwrap();
    let (k, c) = (eq.stiffness()[0][0], eq.damping().unwrap()[0][0]);
    let ab = model.bearing();
    eprintln!("reynolds air bearing: k = {k:.6e} N/m, c = {c:.6e} N s/m");
    assert_eq!(ab.stiffness(0.0), k);
    assert_eq!(ab.damping(0.0), c);
    assert_eq!(ab.force(0.0, 0.0), 0.0);
    // Away from the equilibrium the force is the bearing's own, re-solved there.
    let d = 20e-9;
    let curve = eq.force_spacing(&[d]).unwrap();
    let want = curve[0].1 - eq.loads[0];
    let got = ab.force(d, 0.0);
    assert!((got / want - 1.0).abs() < 1e-3, "{got} against {want}");
    // Stiffer when closer.
    assert!(ab.stiffness(-50e-9) > k && ab.stiffness(50e-9) < k);
}

#[test]
fn a_missing_or_bad_geometry_is_a_typed_error() {
    let dir = tempfile::tempdir().unwrap();
    match Scene::from_path(scene_file(dir.path(), "no_such_bearing.toml")) {
        Err(Error::InvalidInput { field, reason }) => {
            assert_eq!(field, "air_bearing.geometry");
            assert!(reason.contains("no_such_bearing.toml"), "{reason}");
        }
        other => panic!("expected a typed error, got {other:?}"),
    }
    let text =
        std::fs::read_to_string(example())
            .unwrap()
            .replacen("depth_nm = 0", "depth_nm = -5", 1);
    let path = scene_file(dir.path(), "bearing.toml");
    std::fs::write(dir.path().join("bearing.toml"), text).unwrap();
    match Scene::from_path(&path) {
        Err(Error::InvalidInput { field, reason }) => {
            assert_eq!(field, "air_bearing.geometry");
            assert!(reason.contains("left rail"), "{reason}");
        }
        other => panic!("expected a typed error, got {other:?}"),
    }
    let mut scene = Scene::paper();
    scene.air_bearing = AirBearingModel::Reynolds {
        geometry: example().into(),
        cells: Some(CELLS),
        radius_mm: None,
        rpm: Some(0.0),
        skew_deg: None,
        preload_mn: None,
    };
    match scene.validate() {
        Err(Error::InvalidInput { field, .. }) => assert_eq!(field, "air_bearing.rpm"),
        other => panic!("expected a typed error, got {other:?}"),
    }
}

#[cfg(feature = "cli")]
#[test]
fn hdi_static_and_cycle_run_on_the_solved_bearing() {
    let dir = tempfile::tempdir().unwrap();
    let path = scene_file(dir.path(), "bearing.toml");
    let path = path.to_str().unwrap();
    let run = |args: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_hdi"))
            .args(args)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "hdi {args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let s = run(&["static", path]);
    let (td, to) = (
        s["touchdown"]["power_w"].as_f64().unwrap(),
        s["takeoff"]["power_w"].as_f64().unwrap(),
    );
    eprintln!("static on the solved bearing: touchdown {td:.6e} W, take-off {to:.6e} W");
    assert!(td > 0.0 && to > 0.0 && td >= to, "{s}");
    let c = run(&["cycle", path]);
    assert!(c["touchdown"]["power_w"].as_f64().unwrap() > 0.0, "{c}");
    assert!(c["hysteresis_w"].as_f64().is_some(), "{c}");
}
