//! A scene whose pitching slider takes its matrices from the air bearing solved from its
//! geometry (`[structure] preset = "pitch"`, `from_bearing = true`, with
//! `[air_bearing] model = "reynolds"`): the model's structure is `Structure::pitch_on_bearing`
//! on the bearing's `heave_pitch` stiffness and damping, to the bit, against a bearing solved
//! here independently; its modes are the roots of `det(λ²M + λC + K) = 0` with the bearing's
//! full heave–pitch matrices; the scene reads back from its TOML and JSON; `hdi static`,
//! `hdi cycle` and `hdi drive` run on it; and a structure that asks for the bearing's matrices
//! without a reynolds bearing, or gives them besides, is a typed error naming the field.

use std::path::{Path, PathBuf};

use hdi_tribology::bearing::{solve_attitude, AttitudeOptions, BearingSpec};
use hdi_tribology::force::ReynoldsBearing;
use hdi_tribology::model::{SliderModel, Structure};
use hdi_tribology::scene::{Scene, StructureSpec};
use hdi_tribology::Error;
use num_complex::Complex64;

/// The shipped scene.
fn scene_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bearing_pitch.toml")
}

fn scene() -> Scene {
    Scene::from_path(scene_path()).unwrap()
}

/// `ReynoldsBearing::heave_pitch`: stiffness, damping, pivot to trailing edge.
type HeavePitch = ([[f64; 2]; 2], [[f64; 2]; 2], f64);

/// The shipped scene's bearing, solved here from the geometry file on the scene's grid, not
/// through the scene: its `heave_pitch`, and the bulge's lever.
fn independent_bearing(cells: usize) -> (HeavePitch, f64) {
    let mut spec = BearingSpec::from_path(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bearing/two_rail_taper_flat.toml"),
    )
    .unwrap();
    spec.grid.nx = cells;
    spec.grid.ny = cells;
    let eq = solve_attitude(&spec.build().unwrap(), &AttitudeOptions::default()).unwrap();
    let b = ReynoldsBearing::from_equilibrium(&eq).unwrap();
    (b.heave_pitch(), b.bulge_lever())
}

fn cells(scene: &Scene) -> usize {
    match &scene.air_bearing {
        hdi_tribology::force::AirBearingModel::Reynolds { cells, .. } => cells.unwrap(),
        other => panic!("the shipped scene's bearing is reynolds, not {other:?}"),
    }
}

fn inertia(scene: &Scene) -> f64 {
    match scene.structure {
        StructureSpec::Pitch { inertia_kg_m2, .. } => inertia_kg_m2,
        ref other => panic!("the shipped scene pitches, not {other:?}"),
    }
}

#[test]
fn the_models_matrices_are_the_bearings_heave_pitch_to_the_bit() {
    let scene = scene();
    assert!(scene.structure.from_bearing());
    let model = SliderModel::from_scene(&scene).unwrap();
    let ((k, c, to_trailing_edge), lever) = independent_bearing(cells(&scene));
    let s = model.structure();
    println!("bearing_pitch heave-pitch K {k:?}, C {c:?}, lever {lever} m");
    // Heave on coordinate 0 is the bearing's heave law; the rest is the structure's.
    assert_eq!(model.bearing().stiffness(0.0), k[0][0]);
    assert_eq!(model.bearing().damping(0.0), c[0][0]);
    let (ks, cs) = (s.stiffness_matrix(), s.damping_matrix());
    assert_eq!((ks.nrows(), ks.ncols()), (2, 2));
    for (i, j) in [(0, 1), (1, 0), (1, 1)] {
        assert_eq!(ks[(i, j)], k[i][j], "K[{i}][{j}]");
        assert_eq!(cs[(i, j)], c[i][j], "C[{i}][{j}]");
    }
    assert_eq!((ks[(0, 0)], cs[(0, 0)]), (0.0, 0.0));
    // The bulge sits on the trailing edge, the pivot at the centre: 1 mm.
    assert_eq!(lever, to_trailing_edge);
    assert!((lever - 1e-3).abs() < 1e-15, "{lever}");
    assert_eq!(s.bulge_influence(), &[1.0, lever][..]);
    let m = s.mass_matrix();
    assert_eq!(
        (m[(0, 0)], m[(1, 1)], m[(0, 1)], m[(1, 0)]),
        (scene.slider.mass_kg, inertia(&scene), 0.0, 0.0)
    );
    // The whole structure is pitch_on_bearing's: nothing recomputed on the way.
    let want =
        Structure::pitch_on_bearing(scene.slider.mass_kg, inertia(&scene), k, c, lever).unwrap();
    assert_eq!(*s, want);
    assert_eq!(Structure::from_scene(&scene).unwrap(), want);
    // What makes them the film's: not symmetric, negative pitch damping. This could fail if
    // the structure held symmetrised or hand-typed matrices.
    assert_ne!(ks[(0, 1)], ks[(1, 0)]);
    assert!(cs[(1, 1)] < 0.0, "{cs}");
}

#[test]
fn the_modes_are_those_of_pitch_on_bearing() {
    let scene = scene();
    let model = SliderModel::from_scene(&scene).unwrap();
    let ((k, c, _), lever) = independent_bearing(cells(&scene));
    let (mass, i) = (scene.slider.mass_kg, inertia(&scene));
    let want = Structure::pitch_on_bearing(mass, i, k, c, lever)
        .unwrap()
        .modes(k[0][0], c[0][0]);
    let ab = model.bearing();
    let got = model.structure().modes(ab.stiffness(0.0), ab.damping(0.0));
    assert_eq!(got, want);
    assert_eq!(got.len(), 4);
    // Each a root of det(λ² diag(m, I) + λ C + K) with the bearing's full 2 × 2 matrices,
    // computed here: the model's heave law and structure together are the bearing's K and C.
    let big = got.iter().map(|x| x.norm()).fold(0.0, f64::max);
    for x in &got {
        let det = (x * x * mass + x * c[0][0] + k[0][0]) * (x * x * i + x * c[1][1] + k[1][1])
            - (x * c[0][1] + k[0][1]) * (x * c[1][0] + k[1][0]);
        let size = (x.norm().powi(2) * mass + x.norm() * c[0][0].abs() + k[0][0].abs())
            * (x.norm().powi(2) * i + x.norm() * c[1][1].abs() + k[1][1].abs());
        assert!(
            det.norm() <= 1e-9 * size,
            "λ = {x}: det {det} against {size}"
        );
        // Both modes decay, and come as conjugate pairs.
        assert!(x.re < 0.0, "{got:?}");
        assert!(
            got.iter().any(|y| (y - x.conj()).norm() <= 1e-9 * big),
            "{x} without its conjugate in {got:?}"
        );
    }
    let freq: Vec<f64> = got
        .iter()
        .filter(|x| x.im > 0.0)
        .map(|x: &Complex64| x.norm() / (2.0 * std::f64::consts::PI))
        .collect();
    println!("bearing_pitch modes (1/s): {got:?}; |λ|/2π (Hz): {freq:?}");
}

#[test]
fn the_scene_reads_back_from_its_toml_and_json() {
    let scene = scene();
    let toml = scene.to_toml_string().unwrap();
    assert!(toml.contains("from_bearing = true"), "{toml}");
    assert!(!toml.contains("stiffness_n_m_per_rad"), "{toml}");
    assert_eq!(Scene::from_toml_str(&toml).unwrap(), scene);
    let json = scene.to_json_string().unwrap();
    assert_eq!(Scene::from_json_str(&json).unwrap(), scene);
}

/// `base` with its `[structure]` section replaced by `structure` (TOML), read back.
fn with_structure(base: &Scene, structure: &str) -> hdi_tribology::Result<Scene> {
    let mut s = base.clone();
    s.structure = StructureSpec::Rigid;
    Scene::from_toml_str(&(s.to_toml_string().unwrap() + structure))
}

const FROM_BEARING: &str = "\n[structure]\npreset = \"pitch\"\ninertia_kg_m2 = 1.36e-12\n\
                            from_bearing = true\n";

fn invalid(r: hdi_tribology::Result<Scene>) -> (String, String) {
    match r {
        Err(Error::InvalidInput { field, reason }) => (field, reason),
        other => panic!("expected a typed error, got {other:?}"),
    }
}

#[test]
fn asking_for_the_bearings_matrices_without_a_reynolds_bearing_is_refused() {
    let (field, reason) = invalid(with_structure(&Scene::paper(), FROM_BEARING));
    assert_eq!(field, "structure.from_bearing");
    assert!(
        reason.contains("\"reynolds\"") && reason.contains("\"linear\""),
        "{reason}"
    );
    // In code, as in a file.
    let mut s = scene();
    s.air_bearing = Scene::paper().air_bearing;
    match s.validate() {
        Err(Error::InvalidInput { field, .. }) => assert_eq!(field, "structure.from_bearing"),
        other => panic!("expected a typed error, got {other:?}"),
    }
    match Structure::from_scene(&s) {
        Err(Error::InvalidInput { field, .. }) => assert_eq!(field, "structure.from_bearing"),
        other => panic!("expected a typed error, got {other:?}"),
    }
    // The structure alone cannot be built: it needs the scene's bearing.
    match Structure::from_spec(&scene().structure, 4.08e-6) {
        Err(Error::InvalidInput { field, reason }) => {
            assert_eq!(field, "structure.from_bearing");
            assert!(reason.contains("Structure::from_scene"), "{reason}");
        }
        other => panic!("expected a typed error, got {other:?}"),
    }
}

#[test]
fn the_numbers_and_the_bearing_together_are_refused_and_neither_is_required() {
    let base = scene();
    for (line, field) in [
        (
            "stiffness_n_m_per_rad = 0.1",
            "structure.stiffness_n_m_per_rad",
        ),
        (
            "coupling_stiffness_n_per_rad = 40",
            "structure.coupling_stiffness_n_per_rad",
        ),
        (
            "damping_n_m_s_per_rad = 1e-7",
            "structure.damping_n_m_s_per_rad",
        ),
        (
            "coupling_damping_n_s_per_rad = 0",
            "structure.coupling_damping_n_s_per_rad",
        ),
        ("trailing_edge_m = 1e-3", "structure.trailing_edge_m"),
        // Named as the file gave it.
        ("trailing_edge_mm = 1", "structure.trailing_edge_mm"),
    ] {
        let (f, reason) = invalid(with_structure(&base, &format!("{FROM_BEARING}{line}\n")));
        assert_eq!(f, field, "{line}");
        assert!(reason.contains("from_bearing = true"), "{line}: {reason}");
    }
    // Without the bearing, the pitch preset needs its numbers, each named.
    let (f, reason) = invalid(with_structure(
        &Scene::paper(),
        "\n[structure]\npreset = \"pitch\"\ninertia_kg_m2 = 1.36e-12\n",
    ));
    assert_eq!(f, "structure.stiffness_n_m_per_rad");
    assert!(
        reason.contains("required") && reason.contains("from_bearing"),
        "{reason}"
    );
    let (f, _) = invalid(with_structure(
        &Scene::paper(),
        "\n[structure]\npreset = \"pitch\"\ninertia_kg_m2 = 1.36e-12\n\
         stiffness_n_m_per_rad = 0.1\ncoupling_stiffness_n_per_rad = 40\n\
         damping_n_m_s_per_rad = 1e-7\ncoupling_damping_n_s_per_rad = 0\n",
    ));
    assert_eq!(f, "structure.trailing_edge_m");
    // The inertia stays required and checked.
    let (f, _) = invalid(with_structure(
        &base,
        "\n[structure]\npreset = \"pitch\"\ninertia_kg_m2 = -1\nfrom_bearing = true\n",
    ));
    assert_eq!(f, "structure.inertia_kg_m2");
}

#[cfg(feature = "cli")]
fn hdi(args: &[&str]) -> std::process::Output {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_hdi"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "hdi {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

#[cfg(feature = "cli")]
fn json(out: &std::process::Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout).unwrap()
}

#[cfg(feature = "cli")]
#[test]
fn hdi_scene_writes_it_back_in_toml_and_json() {
    let path = scene_path();
    let path = path.to_str().unwrap();
    let scene = scene();
    let toml = String::from_utf8(hdi(&["scene", path]).stdout).unwrap();
    assert_eq!(Scene::from_toml_str(&toml).unwrap(), scene);
    let json = String::from_utf8(hdi(&["scene", path, "--json"]).stdout).unwrap();
    assert_eq!(Scene::from_json_str(&json).unwrap(), scene);
}

#[cfg(feature = "cli")]
#[test]
fn hdi_static_cycle_and_drive_run_on_it() {
    let path = scene_path();
    let path = path.to_str().unwrap();
    let s = json(&hdi(&["static", path]));
    let (td, to) = (
        s["touchdown"]["power_w"].as_f64().unwrap(),
        s["takeoff"]["power_w"].as_f64().unwrap(),
    );
    eprintln!("static on the pitching slider: touchdown {td:.6e} W, take-off {to:.6e} W");
    assert!(td > 0.0 && to > 0.0 && td >= to, "{s}");
    let c = json(&hdi(&["cycle", path]));
    let ctd = c["touchdown"]["power_w"].as_f64().unwrap();
    eprintln!("cycle on the pitching slider: touchdown {ctd:.6e} W");
    assert!(ctd > 0.0, "{c}");
    assert!(c["hysteresis_w"].as_f64().is_some(), "{c}");

    let dir = tempfile::tempdir().unwrap();
    let cmds = dir.path().join("commands.csv");
    std::fs::write(
        &cmds,
        "time_s,heater_mw,voltage_dc_v\n0,60,0\n0.0005,65,0\n",
    )
    .unwrap();
    let d = json(&hdi(&[
        "drive",
        path,
        "--commands",
        cmds.to_str().unwrap(),
        "--out",
        dir.path().join("sensors.csv").to_str().unwrap(),
    ]));
    assert_eq!(d["periods"], 10, "{d}");
}
