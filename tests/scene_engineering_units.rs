//! Scene files in engineering units (nm, mW, kHz, GPa, …): converted to SI on reading, refused
//! by field when ambiguous or not numbers, and errors still located in the file as written.

use std::path::PathBuf;

use hdi_tribology::force::Gaps;
use hdi_tribology::scene::Scene;
use hdi_tribology::Error;
use serde_json::Value;

fn scene_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

fn as_value(s: &Scene) -> Value {
    serde_json::to_value(s).unwrap()
}

fn paper_in_engineering_units() -> String {
    std::fs::read_to_string(scene_path("paper_engineering.toml")).unwrap()
}

#[test]
fn the_paper_scene_in_engineering_units_is_the_paper_scene() {
    let eng = Scene::from_path(scene_path("paper_engineering.toml")).unwrap();
    // Each value is scaled by a power of ten on the decimal the file writes (100 nm is 1e-7 m,
    // 3.6 ms is 3.6e-3 s, 50 µN is 5e-5 N): the paper scene to the bit.
    assert_eq!(as_value(&eng), as_value(&Scene::paper()));
    // And it behaves the same.
    let (a, b) = (
        eng.build_interface().unwrap(),
        Scene::paper().build_interface().unwrap(),
    );
    for d in [-1e-9, 0.0, 1e-9, 3e-9] {
        let g = Gaps::same(d);
        let (fa, fb) = (a.breakdown(g, 1.0), b.breakdown(g, 1.0));
        assert!(
            (fa.total - fb.total).abs() <= 1e-12 * fb.total.abs(),
            "{fa:?} {fb:?}"
        );
    }
}

#[test]
fn json_takes_engineering_units_too() {
    let mut v = as_value(&Scene::paper());
    let obj = v.as_object_mut().unwrap();
    obj.remove("nominal_clearance_m");
    obj.insert("nominal_clearance_nm".into(), 10.into());
    let heater = obj["heater"].as_object_mut().unwrap();
    heater.remove("programme");
    heater.insert(
        "programme_ms_mw".into(),
        serde_json::json!([[0, 60], [3.6, 78], [4.0, 78], [7.6, 60]]),
    );
    let contact = obj["contact"].as_object_mut().unwrap();
    contact.remove("composite_modulus_pa");
    contact.insert("composite_modulus_gpa".into(), 100.0.into());
    let s = Scene::from_json_str(&v.to_string()).unwrap();
    assert_eq!(as_value(&s), as_value(&Scene::paper()));
}

#[test]
fn lists_of_heights_are_scaled_element_by_element() {
    let text = Scene::paper().to_toml_string().unwrap().replace(
        "family = \"rice_maxima\"\nsigma_m = 7e-10\nepsilon = 0.7",
        "family = \"discrete\"\nheights_nm = [0.5, -0.25, 1]",
    );
    let s = Scene::from_toml_str(&text).unwrap();
    let v = as_value(&s);
    let h: Vec<f64> = v["surface"]["peaks"]["heights_m"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(h, vec![0.5e-9, -0.25e-9, 1e-9]);
}

fn invalid_field(r: hdi_tribology::Result<Scene>) -> (String, String) {
    match r {
        Err(Error::InvalidInput { field, reason }) => (field, reason),
        other => panic!("expected an invalid-input error, got {other:?}"),
    }
}

#[test]
fn a_field_in_two_units_is_refused_by_name() {
    let text = paper_in_engineering_units().replace(
        "height_sigma_nm = 0.7",
        "height_sigma_nm = 0.7\nheight_sigma_m = 7e-10",
    );
    let (field, reason) = invalid_field(Scene::from_toml_str(&text));
    assert_eq!(field, "surface.height_sigma_nm");
    assert!(reason.contains("height_sigma_m"), "{reason}");

    // Two engineering spellings of one field, in TOML and in JSON.
    let text = paper_in_engineering_units().replace(
        "height_sigma_nm = 0.7",
        "height_sigma_nm = 0.7\nheight_sigma_um = 0.0007",
    );
    let (field, reason) = invalid_field(Scene::from_toml_str(&text));
    assert!(field.starts_with("surface.height_sigma_"), "{field}");
    assert!(reason.contains("height_sigma_"), "{reason}");
    let mut v = as_value(&Scene::paper());
    let surface = v["surface"].as_object_mut().unwrap();
    surface.remove("height_sigma_m");
    surface.insert("height_sigma_nm".into(), 0.7.into());
    surface.insert("height_sigma_um".into(), 0.0007.into());
    let (field, _) = invalid_field(Scene::from_json_str(&v.to_string()));
    assert!(field.starts_with("surface.height_sigma_"), "{field}");
}

#[test]
fn an_engineering_field_that_is_not_a_number_is_refused_by_name_and_unit() {
    let text =
        paper_in_engineering_units().replace("start_power_mw = 60.0", "start_power_mw = \"60\"");
    let (field, reason) = invalid_field(Scene::from_toml_str(&text));
    assert_eq!(field, "heater.triggered.start_power_mw");
    assert!(reason.contains("mW"), "{reason}");

    let text = paper_in_engineering_units().replace("[3.6, 78.0]", "[3.6, 78.0, 1.0]");
    let (field, reason) = invalid_field(Scene::from_toml_str(&text));
    assert_eq!(field, "heater.programme_ms_mw[1]");
    assert!(reason.contains("pair"), "{reason}");

    let text = paper_in_engineering_units().replace(
        "composite_modulus_gpa = 100.0",
        "composite_modulus_gpa = 1e308",
    );
    let (field, reason) = invalid_field(Scene::from_toml_str(&text));
    assert_eq!(field, "contact.composite_modulus_gpa");
    assert!(reason.contains("overflow"), "{reason}");
}

#[test]
fn validation_errors_name_the_field_as_given_in_its_unit() {
    let text = paper_in_engineering_units()
        .replace("asperity_radius_nm = 100.0", "asperity_radius_nm = -1");
    let (field, reason) = invalid_field(Scene::from_toml_str(&text));
    assert_eq!(field, "contact.asperity_radius_nm");
    assert!(reason.ends_with("got -1 nm"), "{reason}");
    let text =
        paper_in_engineering_units().replace("ac_frequency_khz = 10.5", "ac_frequency_khz = 1e12");
    let (field, reason) = invalid_field(Scene::from_toml_str(&text));
    assert_eq!(field, "voltage.ac_frequency_khz");
    assert!(reason.ends_with("got 1e12 kHz"), "{reason}");
    // the pairs of the programme have two units: both spellings are named
    // (the reason stays in SI)
    let text = paper_in_engineering_units()
        .replace("[3.6, 78.0], [4.0, 78.0]", "[4.0, 78.0], [3.6, 78.0]");
    let (field, _) = invalid_field(Scene::from_toml_str(&text));
    assert!(
        field.contains("(given as heater.programme_ms_mw["),
        "{field}"
    );
}

#[test]
fn parse_errors_point_into_the_file_as_written() {
    // The edits made for the engineering units change the lengths of earlier lines; a later
    // error must still give its own line and column, and the key as the file spells it.
    let text = paper_in_engineering_units().replace("mass_kg = 1e-6", "mass_kg = \"heavy\"");
    let line = text.lines().position(|l| l.starts_with("mass_kg")).unwrap() + 1;
    let msg = Scene::from_toml_str(&text).unwrap_err().to_string();
    assert!(
        msg.contains(&format!("line {line}, column 11, slider.mass_kg")),
        "{msg}"
    );
    assert!(!msg.contains('\n'));

    let text = paper_in_engineering_units().replace(
        "overshoot_mw = 1.0",
        "overshoot_mw = 1.0\nundershoot_mw = 1.0",
    );
    let line = text
        .lines()
        .position(|l| l.starts_with("undershoot"))
        .unwrap()
        + 1;
    let msg = Scene::from_toml_str(&text).unwrap_err().to_string();
    assert!(
        msg.contains(&format!(
            "line {line}, column 1, heater.triggered.undershoot_mw"
        )),
        "{msg}"
    );
    assert!(msg.contains("unknown field `undershoot_mw`"), "{msg}");
}

#[test]
fn written_scenes_are_si() {
    let eng = Scene::from_path(scene_path("paper_engineering.toml")).unwrap();
    let toml = eng.to_toml_string().unwrap();
    assert!(
        toml.contains("nominal_clearance_m =") && !toml.contains("_nm ="),
        "{toml}"
    );
}
