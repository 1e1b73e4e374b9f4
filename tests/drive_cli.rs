//! `hdi drive`: a command file replayed, the sensor CSV written whole or not at all.
#![cfg(feature = "cli")]

use std::process::Command;

fn tmp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("hdi-drive-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn hdi_drive_writes_the_sensor_csv() {
    let cmds = tmp("commands.csv");
    std::fs::write(&cmds, "time_s,heater_mw,voltage_dc_v\n0,60,0\n0.001,65,0\n").unwrap();
    let out = tmp("sensors.csv");
    let o = Command::new(env!("CARGO_BIN_EXE_hdi"))
        .args(["drive", "--paper", "--commands"])
        .arg(&cmds)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let summary: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(summary["periods"], 20);
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(
        text.lines().next().unwrap(),
        hdi_tribology::drive::SENSOR_COLUMNS.join(",")
    );
    assert_eq!(text.lines().count(), 21);
}

#[test]
fn hdi_drive_bad_command_file_writes_nothing() {
    let cmds = tmp("bad.csv");
    std::fs::write(
        &cmds,
        "time_s,heater_mw,voltage_dc_v\n0,60,0\n0.001,-65,0\n",
    )
    .unwrap();
    let out = tmp("never.csv");
    let o = Command::new(env!("CARGO_BIN_EXE_hdi"))
        .args(["drive", "--paper", "--commands"])
        .arg(&cmds)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("line 3, heater_mw"), "{err}");
    assert!(!out.exists());
}

#[test]
fn hdi_drive_tolerance_flags_that_do_not_fit_write_nothing() {
    let cmds = tmp("tol.csv");
    std::fs::write(&cmds, "time_s,heater_mw,voltage_dc_v\n0,60,0\n0.001,65,0\n").unwrap();
    for (flags, named) in [
        (
            vec!["--atol-pm", "0.1", "--atol-flight-pm", "0.05"],
            "--atol-flight-pm",
        ),
        (vec!["--atol-pm", "2"], ""),
        (vec!["--atol-pm", "0"], "--atol-pm"),
    ] {
        let out = tmp("tol-out.csv");
        let _ = std::fs::remove_file(&out);
        let o = Command::new(env!("CARGO_BIN_EXE_hdi"))
            .args(["drive", "--paper", "--commands"])
            .arg(&cmds)
            .arg("--out")
            .arg(&out)
            .args(&flags)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        if named.is_empty() {
            // The flight tolerance follows a larger contact one by default.
            assert!(o.status.success(), "{flags:?}: {err}");
            assert!(out.exists());
        } else {
            assert_eq!(o.status.code(), Some(2), "{flags:?}: {err}");
            assert!(err.contains(named), "{flags:?}: {err}");
            assert!(!out.exists());
        }
    }
}
