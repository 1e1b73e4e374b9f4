//! Scene files: the shipped paper scene, round trips, and typed errors naming the field.

use std::path::PathBuf;

use hdi_tribology::force::{Footprint, GapReference};
use hdi_tribology::scene::Scene;
use hdi_tribology::Error;

fn scene_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

fn paper_text() -> String {
    std::fs::read_to_string(scene_path("paper.toml")).unwrap()
}

#[test]
fn shipped_paper_toml_equals_the_built_in_scene() {
    assert_eq!(
        Scene::from_path(scene_path("paper.toml")).unwrap(),
        Scene::paper()
    );
}

#[test]
fn every_shipped_scene_loads_and_builds() {
    for entry in
        std::fs::read_dir(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes")).unwrap()
    {
        let path = entry.unwrap().path();
        // Sub-directories (scenes/extreme) hold scenes with their own tests.
        if !path.is_file() {
            continue;
        }
        let scene = Scene::from_path(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let forces = scene.build_interface().unwrap();
        assert_eq!(forces.terms().len(), 3, "{}", path.display());
        scene.build_air_bearing().unwrap();
    }
}

#[test]
fn toml_and_json_round_trip() {
    let s = Scene::paper();
    assert_eq!(
        Scene::from_toml_str(&s.to_toml_string().unwrap()).unwrap(),
        s
    );
    assert_eq!(
        Scene::from_json_str(&s.to_json_string().unwrap()).unwrap(),
        s
    );
    let flat = Scene::from_path(scene_path("flat_gaussian.toml")).unwrap();
    assert_eq!(
        Scene::from_json_str(&flat.to_json_string().unwrap()).unwrap(),
        flat
    );
}

#[test]
fn a_scene_builds_only_what_it_enables() {
    let mut s = Scene::paper();
    s.electrostatic = None;
    s.contact = None;
    let f = s.build_interface().unwrap();
    assert_eq!(f.terms().len(), 1);
    assert!(!f.has_voltage_terms() && !f.has_contact());
    // with the intermolecular term off the electrostatic cutoff must be given
    let mut s = Scene::paper();
    s.intermolecular = None;
    assert!(field_of(s.validate()).as_deref() == Some("electrostatic.cutoff_m"));
    s.electrostatic.as_mut().unwrap().cutoff_m = Some(2e-10);
    s.electrostatic.as_mut().unwrap().gap = GapReference::Pad;
    let f = s.build_interface().unwrap();
    assert!(f.uses_pad_gap());
}

fn field_of(r: hdi_tribology::Result<()>) -> Option<String> {
    match r {
        Err(Error::InvalidInput { field, .. }) => Some(field),
        _ => None,
    }
}

#[test]
fn validation_names_the_field() {
    type Edit = Box<dyn Fn(&mut Scene)>;
    let cases: Vec<(&str, Edit)> = vec![
        (
            "nominal_clearance_m",
            Box::new(|s| s.nominal_clearance_m = 0.0),
        ),
        (
            "surface.height_sigma_m",
            Box::new(|s| s.surface.height_sigma_m = -1e-10),
        ),
        (
            "intermolecular.hamaker_attractive_j",
            Box::new(|s| s.intermolecular.as_mut().unwrap().hamaker_attractive_j = f64::NAN),
        ),
        (
            "electrostatic.dielectric_thickness_m",
            Box::new(|s| s.electrostatic.as_mut().unwrap().dielectric_thickness_m = -1e-9),
        ),
        (
            "contact.footprint.max_radius_m",
            Box::new(|s| {
                s.contact.as_mut().unwrap().footprint = Footprint::Paraboloid {
                    radius_of_curvature_m: 0.02,
                    max_radius_m: Some(0.0),
                }
            }),
        ),
        (
            "slider.mass_kg",
            Box::new(|s| s.slider.mass_kg = f64::INFINITY),
        ),
        (
            "heater.programme",
            Box::new(|s| s.heater.programme.truncate(1)),
        ),
        (
            "heater.programme[2].t_s",
            Box::new(|s| s.heater.programme[2][0] = 1e-3),
        ),
        (
            "heater.programme[1].power_w",
            Box::new(|s| s.heater.programme[1][1] = -0.01),
        ),
        (
            "heater.triggered.ramp_rate_w_per_s",
            Box::new(|s| s.heater.triggered.ramp_rate_w_per_s = 0.0),
        ),
        (
            "voltage.ac_frequency_hz",
            Box::new(|s| s.voltage.ac_frequency_hz = 0.0),
        ),
        ("detector.window_s", Box::new(|s| s.detector.window_s = 0.0)),
        (
            "friction.head_conductivity_w_per_m_k",
            Box::new(|s| s.friction.head_conductivity_w_per_m_k = 0.0),
        ),
        ("solver.rtol", Box::new(|s| s.solver.rtol = 1.0)),
        ("solver.max_steps", Box::new(|s| s.solver.max_steps = 0)),
        ("table", Box::new(|s| s.table.d_min_m = Some(1.0))),
        (
            "sweep.ac_amplitudes_v[1]",
            Box::new(|s| s.sweep.ac_amplitudes_v[1] = -0.1),
        ),
        (
            "air_bearing.stiffness_n_per_m",
            Box::new(|s| {
                s.air_bearing = hdi_tribology::force::AirBearingModel::Linear {
                    stiffness_n_per_m: -1.0,
                    damping_n_s_per_m: 0.0,
                }
            }),
        ),
    ];
    for (field, edit) in cases {
        let mut s = Scene::paper();
        edit(&mut s);
        assert_eq!(field_of(s.validate()).as_deref(), Some(field));
        assert!(s.build_interface().is_err());
    }
}

#[test]
fn parse_errors_name_the_field_and_fit_on_one_line() {
    let paper = paper_text();
    let cases = [
        (
            paper.replace("nominal_clearance_m = 1e-8", ""),
            "nominal_clearance_m",
        ),
        (format!("{paper}\n[magnetic]\nstrength = 1.0\n"), "magnetic"),
        (
            paper.replace("shape = \"paraboloid\"", "shape = \"cube\""),
            "cube",
        ),
        (
            paper.replace("mass_kg = 1e-6", "mass_kg = \"heavy\""),
            "line",
        ),
    ];
    for (text, needle) in cases {
        assert_ne!(text, paper);
        let e = Scene::from_toml_str(&text).unwrap_err();
        assert!(matches!(e, Error::Scene { .. }), "{e:?}");
        let msg = e.to_string();
        assert!(msg.contains(needle) && !msg.contains('\n'), "{msg}");
    }
    let e = Scene::from_toml_str(&paper.replace("mass_kg = 1e-6", "mass_kg = nan")).unwrap_err();
    assert!(e.to_string().contains("slider.mass_kg"), "{e}");
    let e = Scene::from_toml_str(&paper.replace(
        "family = \"rice_maxima\"\nsigma_m = 7e-10\nepsilon = 0.7",
        "family = \"histogram\"\nedges_m = []\ncounts = []",
    ))
    .unwrap_err();
    assert!(e.to_string().contains("surface.peaks"), "{e}");
    let e = Scene::from_json_str("{\"name\": 3}").unwrap_err();
    assert!(matches!(e, Error::Scene { .. }));
}

/// Other peak families go through the same tables: a discrete ensemble (kinked moments at every
/// peak), a histogram and the Rician law all build, and the contact force stays non-negative and
/// non-increasing in d.
#[test]
fn other_peak_families_build_and_behave() {
    use hdi_tribology::force::Gaps;
    use hdi_tribology::surface::PeakModel;
    let families = [
        PeakModel::DiscreteSampled {
            from: Box::new(PeakModel::RiceMaxima {
                sigma_m: 7e-10,
                epsilon: 0.7,
            }),
            n: 200,
            seed: 7,
        },
        PeakModel::Histogram {
            edges_m: vec![-1e-9, 0.0, 1e-9, 2e-9, 3e-9],
            counts: vec![1.0, 4.0, 3.0, 1.0],
        },
        PeakModel::Rician {
            nu_m: 5e-10,
            s_m: 4e-10,
        },
    ];
    for flat in [false, true] {
        for peaks in families.clone() {
            let mut s = Scene::paper();
            s.surface.peaks = peaks.clone();
            if flat {
                s.contact.as_mut().unwrap().footprint = Footprint::Flat { area_m2: 1e-8 };
            }
            let f = s
                .build_interface()
                .unwrap_or_else(|e| panic!("{peaks:?} flat={flat}: {e}"));
            let mut last = f64::INFINITY;
            for i in 0..200 {
                let d = -3e-9 + 8e-9 * i as f64 / 199.0;
                let g = Gaps::same(d);
                let c = f.contact(g).value;
                // the tables' absolute tolerance, 1e-16 N, bounds undershoots where F_c ≈ 0
                assert!(
                    c >= -1e-16 && c <= last * (1.0 + 1e-8) + 2e-16,
                    "{peaks:?}: F_c({d}) = {c} after {last}"
                );
                assert!(f.real_contact_area(g) >= 0.0);
                last = c;
            }
        }
    }
}
