//! `hdi fit` end to end: JSON out, plots written, a bad data file refused with its line.
#![cfg(feature = "cli")]

use std::process::Command;

fn data(name: &str) -> String {
    format!("{}/tests/data/fit/{name}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn fits_the_paper_curve_and_writes_plots() {
    let tmp = tempfile::tempdir().unwrap();
    // The plot directory does not exist yet: `--plot` makes it.
    let dir = tmp.path().join("plots");
    let out = Command::new(env!("CARGO_BIN_EXE_hdi"))
        .args(["fit", "--paper", "--data"])
        .arg(data("paper_touchdown_vs_vdc.csv"))
        .args([
            "--free",
            "contact_potential_v=-1:1,efficiency_nm_per_mw=0.05:0.2",
            "--plot",
        ])
        .arg(&dir)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let p = &v["parameters"];
    let (phi, phi_se) = (
        p[0]["value"].as_f64().unwrap(),
        p[0]["standard_error"].as_f64().unwrap(),
    );
    let (eta, eta_se) = (
        p[1]["value"].as_f64().unwrap(),
        p[1]["standard_error"].as_f64().unwrap(),
    );
    // The curve was made with φ = 0 and η = 0.1 nm/mW (plus 0.03 mW of scatter).
    assert!(
        phi.abs() < 4.0 * phi_se && phi_se < 0.01,
        "φ = {phi} ± {phi_se}"
    );
    assert!(
        (eta - 0.1).abs() < 4.0 * eta_se && eta_se < 0.005,
        "η = {eta} ± {eta_se}"
    );
    assert_eq!(v["trusted"], serde_json::Value::Bool(true));
    assert_eq!(v["residuals"][0]["rows"].as_array().unwrap().len(), 10);
    assert!(v["identifiability"]["statements"][0]
        .as_str()
        .unwrap()
        .contains("determined"));
    assert_eq!(v["correlation"].as_array().unwrap().len(), 2);
    for f in [
        "paper_touchdown_vs_vdc_touchdown_power_mw.svg",
        "paper_touchdown_vs_vdc_touchdown_power_mw_residuals.svg",
    ] {
        let svg = std::fs::read_to_string(dir.join(f)).unwrap();
        assert!(svg.contains("<svg"), "{f}");
    }
}

#[test]
fn a_bad_data_file_is_one_line_on_stderr() {
    let out = Command::new(env!("CARGO_BIN_EXE_hdi"))
        .args(["fit", "--paper", "--data"])
        .arg(data("nan_value.csv"))
        .args(["--free", "contact_potential_v"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("nan_value.csv, line 3, column 2 (`touchdown_power_mw`)"),
        "{stderr}"
    );
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(out.stdout.is_empty());
}
