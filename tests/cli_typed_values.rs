//! A value the user typed comes back as typed: the `hdi` commands echo amplitudes, tolerances,
//! heater levels and gaps as the decimals given (`0.3`, not `0.30000000000000004`), and build
//! their grids and tolerance ladders from integer counts on those decimals. Each expected value
//! is the decimal written out as text and parsed, never the program's own arithmetic.
#![cfg(feature = "cli")]

use std::process::Command;

use serde_json::Value;

fn hdi(args: &[&str]) -> Vec<u8> {
    let out = Command::new(env!("CARGO_BIN_EXE_hdi"))
        .args(args)
        .arg("--no-cache")
        .output()
        .expect("the hdi binary runs");
    assert!(
        out.status.success(),
        "hdi {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

fn json(args: &[&str]) -> Value {
    serde_json::from_slice(&hdi(args)).expect("valid JSON")
}

/// The `f64` a user means by the decimal text `s`.
fn typed(s: &str) -> f64 {
    s.parse().unwrap()
}

/// `key` of `v` as a number, and as the text the JSON holds.
fn number(v: &Value, key: &str) -> (f64, String) {
    let x = &v[key];
    (
        x.as_f64().unwrap_or_else(|| panic!("{key}: {x}")),
        x.to_string(),
    )
}

#[test]
fn sweep_echoes_the_amplitudes_as_typed() {
    let given = ["0", "0.1", "0.3", "0.6", "0.7", "1.1"];
    let rows = json(&[
        "sweep",
        "--paper",
        "--v-ac",
        &given.join(","),
        "--no-refine",
    ]);
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), given.len());
    for (row, g) in rows.iter().zip(given) {
        let (v, text) = number(row, "v_ac_v");
        assert_eq!(v, typed(g), "{g}");
        // as the JSON writes it: 0.3, not 0.30000000000000004 (an integer prints as 0.0)
        assert_eq!(text.trim_end_matches(".0"), g);
    }
}

#[test]
fn the_refined_tolerances_are_the_decimals_of_their_ladder() {
    // rtol 1e-8 (atol scaled with it from the scene's 1e-14 m at 1e-6: 1e-16 m), three runs
    // that must all agree: the last at 1e-10 and 1e-18 m, where repeated multiplication by 0.1
    // gives 1.0000000000000002e-10.
    let c = json(&[
        "cycle",
        "--paper",
        "--rtol",
        "1e-8",
        "--max-runs",
        "3",
        "--agree",
        "3",
    ]);
    assert_eq!(c["runs"], 3);
    assert_eq!(number(&c, "rtol"), (typed("1e-10"), "1e-10".into()));
    assert_eq!(number(&c, "atol_m"), (typed("1e-18"), "1e-18".into()));

    // The same ladder on every amplitude of a sweep, from an rtol and atol of other digits.
    let rows = json(&[
        "sweep",
        "--paper",
        "--v-ac",
        "0,0.3",
        "--rtol",
        "3e-7",
        "--atol-nm",
        "0.07",
        "--max-runs",
        "3",
        "--agree",
        "3",
    ]);
    for row in rows.as_array().unwrap() {
        assert_eq!(row["runs"], 3);
        assert_eq!(number(row, "rtol"), (typed("3e-9"), "3e-9".into()));
        assert_eq!(number(row, "atol_m"), (typed("7e-13"), "7e-13".into()));
    }
}

#[test]
fn a_new_rtol_scales_the_absolute_tolerance_to_its_decimal() {
    // The scene's atol 1e-14 m at rtol 1e-6; 1e-14 · (7e-7 / 1e-6) is 6.999999999999999e-15.
    for (rtol, atol) in [("7e-7", "7e-15"), ("3e-8", "3e-16"), ("2.5e-6", "2.5e-14")] {
        let c = json(&["cycle", "--paper", "--rtol", rtol, "--no-refine"]);
        assert_eq!(number(&c, "rtol"), (typed(rtol), rtol.to_string()));
        assert_eq!(
            number(&c, "atol_m"),
            (typed(atol), atol.to_string()),
            "{rtol}"
        );
    }
    // --atol-nm 0.01 is 1e-11 m (0.01 · 1e-9 is 1.0000000000000001e-11).
    let c = json(&["cycle", "--paper", "--atol-nm", "0.01", "--no-refine"]);
    assert_eq!(number(&c, "atol_m"), (typed("1e-11"), "1e-11".into()));
}

#[test]
fn calibration_levels_are_the_typed_start_plus_whole_steps() {
    // 60.1 mW in steps of 0.1 mW: level k is (601 + k) tenths of a milliwatt, in W.
    let c = json(&[
        "calibrate",
        "--paper",
        "--start-mw",
        "60.1",
        "--step-mw",
        "0.1",
        "--max-mw",
        "90",
        "--margin-mw",
        "0.3",
    ]);
    let tenths = |p: f64| {
        let t = (p * 1e4).round();
        assert_eq!(p, typed(&format!("{t}e-4")), "{p} W is not a level");
        t as i64
    };
    let steps = c["steps"].as_array().unwrap();
    assert!(steps.len() > 20, "{} levels", steps.len());
    let mut up = 601;
    for s in steps.iter().take_while(|s| s["descending"] == false) {
        assert_eq!(tenths(s["power_w"].as_f64().unwrap()), up);
        up += 1;
    }
    let td = tenths(c["touchdown_power_w"].as_f64().unwrap());
    assert_eq!(td, up - 1, "touchdown at the last level up");
    tenths(c["takeoff_power_w"].as_f64().unwrap());
    // The set power is the touchdown level less the margin, as decimals: 0.3 mW is 3 tenths.
    assert_eq!(tenths(c["set_power_w"].as_f64().unwrap()), td - 3);
}

#[test]
fn forces_echo_gaps_in_nm_as_the_metres_typed() {
    let given = ["1.1", "0.3", "2.7", "100"];
    let rows = json(&["forces", "--paper", "--gaps-nm", &given.join(",")]);
    for (row, g) in rows.as_array().unwrap().iter().zip(given) {
        // 1.1 nm is 1.1e-9 m (1.1 · 1e-9 is 1.1000000000000001e-9)
        assert_eq!(row["d_m"].as_f64(), Some(typed(&format!("{g}e-9"))), "{g}");
    }
}

#[test]
fn a_scene_in_engineering_units_reads_as_its_si_decimals() {
    // paper_engineering.toml writes the paper scene in nm, µN, ms, mW, GPa, ...: read, it is
    // the paper scene to the bit, and `hdi scene` prints the same file for both.
    let root = env!("CARGO_MANIFEST_DIR");
    let eng = hdi(&["scene", &format!("{root}/scenes/paper_engineering.toml")]);
    let si = hdi(&["scene", "--paper"]);
    assert_eq!(String::from_utf8_lossy(&eng), String::from_utf8_lossy(&si));
}
