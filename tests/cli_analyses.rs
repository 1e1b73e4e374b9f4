//! `hdi static`, `hdi cycle`, `hdi sweep` and `hdi calibrate`: their JSON agrees with the
//! library, and bad input gives one line and a non-zero exit.
#![cfg(feature = "cli")]

use std::process::Command;

use hdi_tribology::analysis::{static_hysteresis, StaticOptions};
use hdi_tribology::model::SliderModel;
use hdi_tribology::scene::Scene;
use serde_json::Value;

fn hdi(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_hdi"))
        .args(args)
        .output()
        .expect("the hdi binary runs")
}

fn json(args: &[&str]) -> Value {
    let out = hdi(args);
    assert!(
        out.status.success(),
        "hdi {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("valid JSON")
}

#[test]
fn static_reports_the_library_values() {
    let v = json(&["static", "--paper"]);
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene).unwrap();
    let h = static_hysteresis(
        &model,
        &StaticOptions::new(scene.detector.contact_threshold_n),
    )
    .unwrap();
    // the library's result, serialized: every key with its unit
    assert_eq!(
        v["touchdown"]["power_w"].as_f64().unwrap(),
        h.touchdown.power
    );
    assert_eq!(
        v["touchdown"]["at"]["d_m"].as_f64().unwrap(),
        h.touchdown.at.d
    );
    assert_eq!(v["takeoff"]["power_w"].as_f64().unwrap(), h.takeoff.power);
    assert_eq!(v["hysteresis_w"].as_f64().unwrap(), h.hysteresis);
    assert_eq!(v["scene"].as_str(), Some(scene.name.as_str()));
    assert_eq!(v["status"].as_str(), Some("converged"));
    let vpi = v["pull_in"]["voltage_v"].as_f64().unwrap();
    assert!((2.0..10.0).contains(&vpi));
    let folds = v["folds"].as_array().unwrap();
    assert_eq!(folds.len(), 2);
    assert!(folds
        .iter()
        .all(|f| f["power_w"].is_f64() && f["d_m"].is_f64()));
}

#[test]
fn static_answers_for_a_scene_file() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/paper.toml");
    let from_file = json(&["static", path]);
    let built_in = json(&["static", "--paper"]);
    assert_eq!(from_file, built_in);
}

#[test]
fn cycle_and_sweep_report_every_key_and_the_csv() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("series.csv");
    let v = json(&[
        "cycle",
        "--paper",
        "--v-ac",
        "0.6",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    for key in [
        "scene",
        "programme",
        "v_ac_v",
        "touchdown",
        "takeoff",
        "hysteresis_w",
        "mean_temperature_rise_k",
        "duration_s",
        "method",
        "stats",
        "wall_seconds",
        "total_stats",
        "status",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert_eq!(v["programme"].as_str(), Some("fixed"));
    assert_eq!(v["v_ac_v"].as_f64(), Some(0.6));
    assert_eq!(v["method"].as_str(), Some("auto"));
    let h = v["hysteresis_w"].as_f64().unwrap();
    let (td, to) = (&v["touchdown"]["power_w"], &v["takeoff"]["power_w"]);
    assert_eq!(h, td.as_f64().unwrap() - to.as_f64().unwrap());
    assert!(h > 0.0 && h < 6e-3, "hysteresis {h}");
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.starts_with("t_s,power_w,d_m,"));
    assert!(text.lines().count() > 1000);

    let rows = json(&["sweep", "--paper", "--v-ac", "0,0.6", "--triggered"]);
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0]["v_ac_v"].as_f64(), Some(0.0));
    assert_eq!(rows[1]["v_ac_v"].as_f64(), Some(0.6));
    assert_eq!(rows[1]["programme"].as_str(), Some("triggered"));
    let h = |r: &serde_json::Value| r["hysteresis_w"].as_f64().unwrap();
    assert!(h(&rows[0]) > h(&rows[1]));

    // Refined by default: the 0.7 V amplitude needs a tighter tolerance than the scene's to
    // settle; the status says whether both the powers and the mean temperature did.
    let rows = json(&["sweep", "--paper", "--v-ac", "0,0.7", "--refine-mw", "0.06"]);
    let rows = rows.as_array().unwrap();
    for r in rows {
        let change = r["power_change_w"].as_f64().unwrap();
        let dt = r["temperature_change_k"].as_f64().unwrap();
        let converged = change <= 6e-5 && dt <= 0.05;
        let status = if converged {
            "converged"
        } else {
            "not_converged"
        };
        assert_eq!(r["status"].as_str(), Some(status), "{r}");
        assert!((2..=5).contains(&r["runs"].as_u64().unwrap()), "{r}");
        // atol is tightened with rtol
        let (rtol, atol) = (r["rtol"].as_f64().unwrap(), r["atol_m"].as_f64().unwrap());
        assert!((atol / rtol / 1e-8 - 1.0).abs() < 1e-9, "{r}");
    }
    assert_eq!(rows[0]["rtol"].as_f64(), Some(1e-7));
    assert!(rows[1]["rtol"].as_f64().unwrap() < 1e-7, "{}", rows[1]);
}

#[test]
fn calibrate_finds_the_static_touchdown_within_one_step() {
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene).unwrap();
    let th = scene.detector.contact_threshold_n;
    let stat = static_hysteresis(&model, &StaticOptions::new(th)).unwrap();
    let v = json(&[
        "calibrate",
        "--paper",
        "--start-mw",
        "65",
        "--step-mw",
        "0.5",
        "--margin-mw",
        "10",
    ]);
    let td = v["touchdown_power_w"].as_f64().unwrap();
    // The staircase fires at the first level at or above the static touchdown (the mean-force
    // detector with the scene's threshold is the static model's criterion).
    assert!(
        td >= stat.touchdown.power - 1e-12 && td <= stat.touchdown.power + 0.5e-3,
        "{v}"
    );
    let set = v["set_power_w"].as_f64().unwrap();
    assert!((set - (td - 10e-3)).abs() < 1e-12, "{v}");
    let to = v["takeoff_power_w"].as_f64().unwrap();
    assert!((to - stat.takeoff.power).abs() <= 0.5e-3 + 1e-12, "{v}");
    let clearance = v["clearance_m"].as_f64().unwrap();
    assert!(
        clearance > 0.0 && clearance < scene.nominal_clearance_m,
        "{v}"
    );
    assert_eq!(v["detector"].as_str(), Some("mean"));
    assert_eq!(v["detector_name"].as_str(), Some("mean contact force"));
    assert_eq!(v["status"].as_str(), Some("complete"));
    assert_eq!(
        v["levels"].as_u64(),
        Some(v["steps"].as_array().unwrap().len() as u64)
    );
}

#[test]
fn bad_arguments_are_usage_errors_naming_the_option_as_typed() {
    for (args, named) in [
        (vec!["cycle", "--paper", "--method", "euler"], "--method"),
        (vec!["sweep", "--paper", "--v-ac", "0,x"], "--v-ac"),
        (vec!["static"], "--paper"),
        (vec!["cycle", "--paper", "--rtol", "nan"], "--rtol"),
        (
            vec!["sweep", "--paper", "--v-ac", "0", "--refine-mw", "0"],
            "--refine-mw",
        ),
        (
            vec!["calibrate", "--paper", "--detector", "microphone"],
            "--detector",
        ),
        (vec!["calibrate", "--paper", "--step-mw", "-1"], "--step-mw"),
        (vec!["calibrate", "--paper", "--max-mw", "1e9"], "--max-mw"),
        (
            vec!["calibrate", "--paper", "--start-mw", "70", "--max-mw", "60"],
            "--max-mw",
        ),
    ] {
        let out = hdi(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(out.stdout.is_empty(), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.starts_with("error: "), "{args:?}: {err}");
        assert!(err.contains(named), "{args:?}: {err} should name {named}");
        assert!(
            !err.contains("panicked") && !err.contains("staircase"),
            "{err}"
        );
    }
    let out = hdi(&["calibrate", "--paper", "--step-mw", "-1"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("'-1'") && err.contains("> 0"), "{err}");
    let out = hdi(&["calibrate", "--paper", "--max-mw", "1e9"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--max-mw 1e9"), "{err}");
    // a missing file is not a usage error
    let out = hdi(&["static", "no-such-scene.toml"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.starts_with("hdi: ") && err.contains("no-such-scene.toml"),
        "{err}"
    );
}

/// A dither strong enough to bring the slider into contact at the start power leaves no
/// touchdown to find: an error, not the start power reported as touchdown.
#[test]
fn calibrate_refuses_contact_at_the_start_power() {
    let out = hdi(&["calibrate", "--paper", "--dither-v", "5"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(out.stdout.is_empty());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("start power") && err.contains("--dither-v 5"),
        "{err}"
    );
}

#[test]
fn printed_paper_scene_reads_back_as_the_paper_scene() {
    let dir = tempfile::tempdir().unwrap();
    for (flag, ext) in [(None, "toml"), (Some("--json"), "json")] {
        let mut args = vec!["scene", "--paper"];
        args.extend(flag);
        let out = hdi(&args);
        assert!(out.status.success());
        let path = dir.path().join(format!("paper.{ext}"));
        std::fs::write(&path, &out.stdout).unwrap();
        assert_eq!(Scene::from_path(&path).unwrap(), Scene::paper());
    }
}
