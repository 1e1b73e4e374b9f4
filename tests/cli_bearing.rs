//! `hdi bearing`: the attitude as JSON with units in its keys, the pressure map, and a typed
//! error for bad geometry.
#![cfg(feature = "cli")]

use std::process::Command;

fn scene(name: &str) -> String {
    format!("{}/scenes/bearing/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn hdi(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_hdi"))
        .args(args)
        .output()
        .expect("the hdi binary runs")
}

#[test]
fn prints_the_attitude_and_writes_the_map() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("map.svg");
    let out = hdi(&[
        "bearing",
        &scene("two_rail_taper_flat.toml"),
        "--cells",
        "65",
        "--svg",
        svg.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let fh = v["fly_height_nm"].as_f64().unwrap();
    assert!(fh > 100.0 && fh < 1000.0, "{fh}");
    assert!(v["pitch_urad"].as_f64().unwrap() > 0.0);
    assert!((v["load_mn"].as_f64().unwrap() - 49.0).abs() < 1e-6);
    assert!(v["stiffness_si"]["force_per_fly_height"].as_f64().unwrap() > 0.0);
    assert!(v["damping_si"]["force_per_fly_height"].as_f64().unwrap() > 0.0);
    let curve = v["force_spacing"].as_array().unwrap();
    let loads: Vec<f64> = curve
        .iter()
        .map(|p| p["load_mn"].as_f64().unwrap())
        .collect();
    assert!(loads.windows(2).all(|w| w[1] < w[0]), "{loads:?}");
    let map = std::fs::read_to_string(&svg).unwrap();
    assert!(map.starts_with("<svg") && map.contains("pressure / ambient"));
    // The text format gives the same attitude.
    let out = hdi(&[
        "bearing",
        &scene("two_rail_taper_flat.abs"),
        "--cells",
        "65",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let w: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(w["fly_height_nm"], v["fly_height_nm"]);
}

#[test]
fn bad_geometry_names_the_polygon() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(scene("two_rail_taper_flat.toml"))
        .unwrap()
        .replace(
            "depth_nm = 0\npolygon_um = [[0, 1200]",
            "depth_nm = -3\npolygon_um = [[0, 1200]",
        );
    let path = dir.path().join("bad.toml");
    std::fs::write(&path, text).unwrap();
    let out = hdi(&["bearing", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("\"right rail\".depth_nm") && err.contains("-3 nm"),
        "{err}"
    );
}
