//! `hdi drive`: a command file replayed, the sensor CSV written whole or not at all.
#![cfg(feature = "cli")]

use std::process::Command;

/// One test's directory of files, removed when the test ends, passed or failed.
struct Tmp(tempfile::TempDir);

impl Tmp {
    fn new() -> Self {
        Tmp(tempfile::tempdir().unwrap())
    }

    fn path(&self, name: &str) -> std::path::PathBuf {
        self.0.path().join(name)
    }
}

#[test]
fn hdi_drive_writes_the_sensor_csv() {
    let t = Tmp::new();
    let cmds = t.path("commands.csv");
    std::fs::write(&cmds, "time_s,heater_mw,voltage_dc_v\n0,60,0\n0.001,65,0\n").unwrap();
    let out = t.path("sensors.csv");
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
    let t = Tmp::new();
    let cmds = t.path("bad.csv");
    std::fs::write(
        &cmds,
        "time_s,heater_mw,voltage_dc_v\n0,60,0\n0.001,-65,0\n",
    )
    .unwrap();
    let out = t.path("never.csv");
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
    let t = Tmp::new();
    let cmds = t.path("tol.csv");
    std::fs::write(&cmds, "time_s,heater_mw,voltage_dc_v\n0,60,0\n0.001,65,0\n").unwrap();
    for (flags, named) in [
        (
            vec!["--atol-pm", "0.1", "--atol-flight-pm", "0.05"],
            "--atol-flight-pm",
        ),
        (vec!["--atol-pm", "2"], ""),
        (vec!["--atol-pm", "0"], "--atol-pm"),
    ] {
        let out = t.path("tol-out.csv");
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

fn hdi(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_hdi"))
        .args(args)
        .output()
        .unwrap()
}

/// The drive settings as flags and as a scene's `[drive]` section give the same CSV, byte for
/// byte, and a different one from the default drive.
#[test]
fn hdi_drive_flags_and_the_scene_drive_section_agree() {
    let t = Tmp::new();
    let cmds = t.path("settings_commands.csv");
    std::fs::write(&cmds, "time_s,heater_mw,voltage_dc_v\n0,62,0\n0.001,66,0\n").unwrap();
    let scene = hdi_tribology::scene::Scene::paper()
        .to_toml_string()
        .unwrap();
    let with_drive = t.path("drive_scene.toml");
    std::fs::write(
        &with_drive,
        format!(
            "{scene}\n[drive]\nrpm = 7200\ninitial_heater_power_mw = 62\n\
             [drive.disk]\nrunout_nm = 500\nwaviness_rms_nm = 0.2\n\
             [drive.ambient]\nrate_k_per_s = 50\n\
             [drive.sensors]\nreadback_wavelength_nm = 80\nae_bandwidth_khz = 10\n\
             ae_gain_v_per_sqrt_w = 2\ncontact_noise_ohm = 0.01\n"
        ),
    )
    .unwrap();
    let plain = t.path("plain_scene.toml");
    std::fs::write(&plain, &scene).unwrap();
    let c = cmds.to_str().unwrap();
    let run = |extra: &[&str], out: &str| {
        let out = t.path(out);
        let mut args = vec!["drive", "--commands", c, "--out", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        let o = hdi(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        std::fs::read(out).unwrap()
    };
    let from_scene = run(&[with_drive.to_str().unwrap()], "a.csv");
    let from_flags = run(
        &[
            plain.to_str().unwrap(),
            "--rpm",
            "7200",
            "--initial-heater-power-mw",
            "62",
            "--runout-nm",
            "500",
            "--waviness-rms-nm",
            "0.2",
            "--ambient-rate-k-per-s",
            "50",
            "--readback-wavelength-nm",
            "80",
            "--ae-bandwidth-khz",
            "10",
            "--ae-gain-v-per-sqrt-w",
            "2",
            "--contact-noise-ohm",
            "0.01",
        ],
        "b.csv",
    );
    let default = run(&[plain.to_str().unwrap()], "c.csv");
    assert_eq!(from_scene, from_flags);
    assert_ne!(from_scene, default);
}

/// A bad drive setting names the flag as written, with the value in its unit; a bad one in the
/// scene names the field as written.
#[test]
fn hdi_drive_bad_settings_name_the_flag_in_its_unit() {
    let t = Tmp::new();
    let cmds = t.path("bad_settings_commands.csv");
    std::fs::write(&cmds, "time_s,heater_mw,voltage_dc_v\n0,62,0\n0.001,66,0\n").unwrap();
    let c = cmds.to_str().unwrap();
    for (flag, value, unit) in [
        ("--initial-heater-power-mw", "-5", "mW"),
        ("--initial-heater-power-mw", "2000", "mW"),
        ("--radius-mm", "0", "mm"),
        ("--rpm", "-1", "rpm"),
        ("--heater-time-constant-us", "-1", "µs"),
        ("--runout-nm", "-3", "nm"),
        ("--waviness-rms-nm", "-0.5", "nm"),
        ("--ambient-rate-k-per-s", "inf", "K/s"),
        ("--ambient-period-s", "0", "s"),
        ("--ambient-step-time-s", "-1", "s"),
        ("--ae-gain-v-per-sqrt-w", "-1", "V/√W"),
        ("--ae-bandwidth-khz", "0", "kHz"),
        ("--contact-noise-ohm", "-0.1", "Ω"),
        ("--readback-wavelength-nm", "0", "nm"),
        ("--heads", "0", ""),
        ("--heads", "2.5", ""),
    ] {
        let out = t.path("never.csv");
        let o = hdi(&[
            "drive",
            "--paper",
            "--commands",
            c,
            "--out",
            out.to_str().unwrap(),
            flag,
            value,
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{flag} {value} was taken");
        assert!(err.contains(flag), "{flag} {value}: {err}");
        assert!(
            err.contains(&format!("got {value} {unit}").trim_end().to_string())
                || err.contains(&format!("got {value}")),
            "{flag} {value}: {err}"
        );
        assert!(!out.exists(), "{flag} {value} wrote a file");
    }
    let scene = hdi_tribology::scene::Scene::paper()
        .to_toml_string()
        .unwrap();
    let bad = t.path("bad_drive_scene.toml");
    std::fs::write(
        &bad,
        format!("{scene}\n[drive.sensors]\nreadback_wavelength_nm = -80\n"),
    )
    .unwrap();
    let o = hdi(&["drive", bad.to_str().unwrap(), "--commands", c]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        err.contains("drive.sensors.readback_wavelength_nm") && err.contains("-80 nm"),
        "{err}"
    );
}

/// `--heads 3` (or the scene's `drive.heads`) replays the commands on every head: a leading
/// `head` column, one row per period and head; head 0's rows are the one-head file's, byte for
/// byte, and the other heads' surfaces are their own.
#[test]
fn hdi_drive_heads_replays_every_head() {
    let t = Tmp::new();
    let cmds = t.path("heads_commands.csv");
    std::fs::write(&cmds, "time_s,heater_mw,voltage_dc_v\n0,62,0\n0.001,66,0\n").unwrap();
    let c = cmds.to_str().unwrap();
    let run = |extra: &[&str], name: &str| {
        let out = t.path(name);
        let mut args = vec!["drive", "--commands", c, "--out", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        let o = hdi(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let summary: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        (std::fs::read_to_string(out).unwrap(), summary)
    };
    let (one, s1) = run(&["--paper"], "one_head.csv");
    assert!(s1.get("heads").is_none(), "{s1}");
    let (three, s3) = run(&["--paper", "--heads", "3"], "three_heads.csv");
    assert_eq!(
        (s3["heads"].as_u64(), s3["periods"].as_u64()),
        (Some(3), Some(20))
    );
    let scene = hdi_tribology::scene::Scene::paper()
        .to_toml_string()
        .unwrap();
    let in_scene = t.path("heads_scene.toml");
    std::fs::write(&in_scene, format!("{scene}\n[drive]\nheads = 3\n")).unwrap();
    let (from_scene, _) = run(&[in_scene.to_str().unwrap()], "three_heads_scene.csv");
    assert_eq!(three, from_scene);

    let mut lines = three.lines();
    assert_eq!(
        lines.next().unwrap(),
        format!("head,{}", hdi_tribology::drive::SENSOR_COLUMNS.join(","))
    );
    let rows: Vec<(&str, &str)> = lines.map(|l| l.split_once(',').unwrap()).collect();
    assert_eq!(rows.len(), 60);
    let head = |h: &str| -> Vec<&str> {
        rows.iter()
            .filter(|(k, _)| *k == h)
            .map(|(_, r)| *r)
            .collect()
    };
    assert_eq!(rows[0].0, "0");
    assert_eq!(rows[1].0, "1");
    assert_eq!(rows[2].0, "2");
    let head0: Vec<&str> = one.lines().skip(1).collect();
    assert_eq!(head("0"), head0);
    assert_ne!(head("1"), head0);
    assert_ne!(head("1"), head("2"));
}

/// `--steps-per-period`: the bounded mode's summary counts the periods that missed the
/// tolerances and says so on standard error; a bound out of range is a usage error naming the
/// flag, and nothing is written.
#[test]
fn hdi_drive_bounded_mode_flags_its_misses() {
    let t = Tmp::new();
    let cmds = t.path("dither.csv");
    std::fs::write(
        &cmds,
        "time_s,heater_mw,voltage_dc_v,voltage_ac_v,ac_frequency_khz\n0,68,0,0.5,10.5\n0.002,68,0,0.5,10.5\n",
    )
    .unwrap();
    let out = t.path("bounded.csv");
    let run = |n: &str, out: &std::path::Path| {
        Command::new(env!("CARGO_BIN_EXE_hdi"))
            .args(["drive", "--paper", "--steps-per-period", n, "--commands"])
            .arg(&cmds)
            .arg("--out")
            .arg(out)
            .output()
            .unwrap()
    };
    let o = run("2", &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let summary: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let b = &summary["bounded"];
    assert_eq!(b["steps_per_period"], 2);
    let missed = b["periods_over_tolerance"].as_u64().unwrap();
    assert!(missed > 0 && b["max_error_estimate"].as_f64().unwrap() > 1.0);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains(&format!("{missed} of 40 periods missed")),
        "{err}"
    );
    let never = t.path("never-bounded.csv");
    let o = run("65", &never);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--steps-per-period"));
    assert!(!never.exists());
}

/// `--scheme exponential`: the same periods as the default integrator, every true gap within
/// 0.1 pm of its (the scheme's accuracy against a tight reference is tests/drive_plant.rs's),
/// the same file from run to run; a scheme that does not exist is a usage error naming the
/// flag, and nothing is written.
#[test]
fn hdi_drive_exponential_scheme_replays_close_to_the_integrator() {
    let t = Tmp::new();
    let cmds = t.path("changed.csv");
    let mut text = String::from("time_s,heater_mw,voltage_dc_v\n");
    for k in 0..80 {
        let p = 66.0 + if k % 2 == 1 { 0.001 } else { 0.0 };
        text += &format!("{},{p},0\n", hdi_tribology::units::grid_point(0.0, 5e-5, k));
    }
    std::fs::write(&cmds, text).unwrap();
    let run = |scheme: Option<&str>, out: &std::path::Path| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_hdi"));
        c.args(["drive", "--paper", "--commands"])
            .arg(&cmds)
            .arg("--out")
            .arg(out);
        if let Some(s) = scheme {
            c.args(["--scheme", s]);
        }
        c.output().unwrap()
    };
    let column = |path: &std::path::Path, name: &str| -> Vec<f64> {
        let text = std::fs::read_to_string(path).unwrap();
        let mut lines = text.lines();
        let i = lines
            .next()
            .unwrap()
            .split(',')
            .position(|c| c == name)
            .unwrap();
        lines
            .map(|l| l.split(',').nth(i).unwrap().parse().unwrap())
            .collect()
    };
    let (default, exp, again) = (t.path("int.csv"), t.path("exp.csv"), t.path("exp2.csv"));
    for (scheme, out) in [
        (None, &default),
        (Some("exponential"), &exp),
        (Some("exponential"), &again),
    ] {
        let o = run(scheme, out);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    assert_eq!(std::fs::read(&exp).unwrap(), std::fs::read(&again).unwrap());
    let (a, b) = (column(&default, "true_gap_nm"), column(&exp, "true_gap_nm"));
    assert_eq!(a.len(), b.len());
    let worst = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    // The scheme advanced periods itself (not one bit the same), and stayed close.
    assert!(
        worst > 0.0 && worst < 1e-4,
        "worst gap difference {worst} nm"
    );
    let never = t.path("never-scheme.csv");
    let o = run(Some("implicit"), &never);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--scheme"));
    assert!(!never.exists());
}

/// The sensor file's times come back as typed: the k-th period at 20 kHz ends at k / 20 000 s,
/// the nearest double to the decimal (`0.00015`, not `0.00015000000000000001`), however long
/// the run; at 25 kHz likewise.
#[test]
fn hdi_drive_times_are_the_decimals_of_the_periods() {
    let t = Tmp::new();
    let cmds = t.path("times.csv");
    std::fs::write(&cmds, "time_s,heater_mw,voltage_dc_v\n0,60,0\n0.1,60,0\n").unwrap();
    for (rate, hz) in [("20", 20_000.0), ("25", 25_000.0)] {
        let o = Command::new(env!("CARGO_BIN_EXE_hdi"))
            .args([
                "drive",
                "--paper",
                "--flat-disk",
                "--rate-khz",
                rate,
                "--commands",
            ])
            .arg(&cmds)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = String::from_utf8(o.stdout).unwrap();
        let times: Vec<&str> = text
            .lines()
            .skip(1)
            .map(|l| l.split(',').next().unwrap())
            .collect();
        for (k, t) in times.iter().enumerate() {
            let exact = (k + 1) as f64 / hz;
            assert_eq!(t.parse::<f64>().unwrap(), exact, "period {}", k + 1);
        }
        assert_eq!(*times.last().unwrap(), "0.1");
        assert_eq!(times[2], if hz == 20_000.0 { "0.00015" } else { "0.00012" });
    }
}
