//! Scene errors name the field as the file gave it: dotted JSON paths, fields inside tagged
//! sections, one σ for one surface, and bounded fields.

use hdi_tribology::scene::Scene;

fn paper_toml() -> String {
    Scene::paper().to_toml_string().unwrap()
}

fn paper_json() -> serde_json::Value {
    serde_json::from_str(&Scene::paper().to_json_string().unwrap()).unwrap()
}

fn json_err(v: &serde_json::Value) -> String {
    Scene::from_json_str(&v.to_string())
        .unwrap_err()
        .to_string()
}

#[test]
fn json_errors_give_the_dotted_path() {
    let mut v = paper_json();
    v["slider"]["mass_kg"] = "heavy".into();
    let err = json_err(&v);
    assert!(err.contains("slider.mass_kg: invalid type"), "{err}");
    let mut v = paper_json();
    v["heater"]["programme"][1][0] = true.into();
    let err = json_err(&v);
    assert!(err.contains("heater.programme[1][0]"), "{err}");
    // in engineering units the path names the field as given
    let mut v = paper_json();
    let slider = v["slider"].as_object_mut().unwrap();
    slider.remove("interface_lag_s");
    slider.insert("interface_lag_us".into(), 1.0.into());
    v["detector"]["window_s"] = "long".into();
    let err = json_err(&v);
    assert!(err.contains("detector.window_s: invalid type"), "{err}");
}

#[test]
fn a_wrong_type_inside_a_tagged_section_keeps_the_field() {
    let mut v = paper_json();
    v["air_bearing"]["damping_n_s_per_m"] = "x".into();
    let err = json_err(&v);
    assert!(err.contains("air_bearing.damping_n_s_per_m"), "{err}");
    let text = paper_toml().replacen("damping_n_s_per_m = ", "damping_n_s_per_m = \"x\" #", 1);
    let err = Scene::from_toml_str(&text).unwrap_err().to_string();
    assert!(err.contains("air_bearing.damping_n_s_per_m"), "{err}");
}

#[test]
fn sigma_has_one_source_of_truth() {
    let text = paper_toml();
    // set in one place only: refused, naming both fields
    let one = text.replace("height_sigma_m = 7e-10", "height_sigma_m = 5e-10");
    let err = Scene::from_toml_str(&one).unwrap_err().to_string();
    assert!(
        err.contains("surface.peaks.sigma_m") && err.contains("surface.height_sigma_m"),
        "{err}"
    );
    // both in place, in different units: accepted
    let both = text
        .replace("height_sigma_m = 7e-10", "height_sigma_nm = 0.5")
        .replace("sigma_m = 7e-10", "sigma_m = 5e-10");
    let s = Scene::from_toml_str(&both).unwrap();
    assert!((s.surface.height_sigma_m - 5e-10).abs() < 1e-24);
    // different on purpose: said so, accepted, and written back out
    let on_purpose = one.replace("[surface]\n", "[surface]\nindependent_peak_sigma = true\n");
    assert_ne!(on_purpose, one);
    let s = Scene::from_toml_str(&on_purpose).unwrap();
    assert!(s.surface.independent_peak_sigma);
    assert_eq!(
        Scene::from_toml_str(&s.to_toml_string().unwrap()).unwrap(),
        s
    );
    // the paper scene keeps one σ, and does not write the statement
    assert!(!text.contains("independent_peak_sigma"));
    // the same rule for a scene built in code
    let mut s = Scene::paper();
    s.surface.height_sigma_m = 1e-9;
    assert!(s.validate().is_err());
    s.surface.independent_peak_sigma = true;
    s.validate().unwrap();
}

#[test]
fn fields_that_set_the_work_of_a_run_are_bounded() {
    let text = paper_toml();
    for (from, to, field) in [
        (
            "ac_frequency_hz = 10500.0",
            "ac_frequency_hz = 1e12",
            "voltage.ac_frequency_hz",
        ),
        (
            "max_steps = 10000000",
            "max_steps = 1000000000000",
            "solver.max_steps",
        ),
        ("dc_v = 0.0", "dc_v = 1e200", "voltage.dc_v"),
    ] {
        assert!(text.contains(from), "{from} not in the paper scene");
        let err = Scene::from_toml_str(&text.replace(from, to))
            .unwrap_err()
            .to_string();
        assert!(err.contains(field), "{err}");
        assert!(err.len() < 200, "{err}");
    }
    // the bounds leave room: the shipped 3 MHz scene still reads
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/extreme/ac_3mhz.toml");
    Scene::from_path(path).unwrap();
}
