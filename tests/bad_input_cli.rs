//! `hdi` on bad scene files: every subcommand that reads a scene exits non-zero with exactly one
//! line on stderr that names the offending field.
#![cfg(feature = "cli")]

use std::path::PathBuf;
use std::process::Command;

use hdi_tribology::scene::Scene;

/// The shipped paper scene (inline footprints, one value per line).
fn paper_toml() -> String {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/paper.toml");
    std::fs::read_to_string(path).unwrap()
}

/// Replaces the first line starting with `key = ` after the line `[section]` (or anywhere when
/// `section` is empty).
fn edit(text: &str, section: &str, key: &str, value: &str) -> String {
    let mut in_section = section.is_empty();
    let mut done = false;
    let mut out = Vec::new();
    for line in text.lines() {
        if line.starts_with('[') {
            let header = line.split('#').next().unwrap_or("").trim();
            in_section = section.is_empty() || header == format!("[{section}]");
        }
        if in_section && !done && line.starts_with(&format!("{key} = ")) {
            out.push(format!("{key} = {value}"));
            done = true;
        } else {
            out.push(line.to_string());
        }
    }
    assert!(done, "no {key} in [{section}]");
    out.join("\n")
}

/// (label, scene text, text the one-line message must contain).
fn bad_scenes() -> Vec<(&'static str, String, &'static str)> {
    let p = paper_toml();
    vec![
        (
            "negative roughness",
            edit(&p, "surface", "height_sigma_m", "-7e-10"),
            "surface.height_sigma_m",
        ),
        (
            "NaN modulus",
            edit(&p, "contact", "composite_modulus_pa", "nan"),
            "contact.composite_modulus_pa",
        ),
        (
            "infinite mass",
            edit(&p, "slider", "mass_kg", "inf"),
            "slider.mass_kg",
        ),
        (
            "zero peak sigma",
            edit(&p, "surface.peaks", "sigma_m", "0.0"),
            "surface.peaks.sigma_m",
        ),
        (
            "epsilon above one",
            edit(&p, "surface.peaks", "epsilon", "1.5"),
            "surface.peaks.epsilon",
        ),
        (
            "zero max radius",
            edit(
                &p,
                "contact",
                "footprint",
                "{ shape = \"paraboloid\", radius_of_curvature_m = 0.02, max_radius_m = 0.0 }",
            ),
            "contact.footprint.max_radius_m",
        ),
        (
            "empty programme",
            edit(&p, "heater", "programme", "[]"),
            "heater.programme",
        ),
        (
            "knots out of order",
            edit(
                &p,
                "heater",
                "programme",
                "[[0.0, 0.06], [2e-3, 0.07], [1e-3, 0.06]]",
            ),
            "heater.programme[2].t_s",
        ),
        (
            "negative power",
            edit(&p, "heater", "programme", "[[0.0, 0.06], [1e-3, -0.07]]"),
            "heater.programme[1].power_w",
        ),
        (
            "zero tolerance",
            edit(&p, "solver", "rtol", "0.0"),
            "solver.rtol",
        ),
        (
            "zero table tolerance",
            edit(&p, "table", "rel_tol", "0.0"),
            "table.rel_tol",
        ),
        (
            "negative window",
            edit(&p, "detector", "window_s", "-1e-5"),
            "detector.window_s",
        ),
        (
            "zero threshold",
            edit(&p, "detector", "contact_threshold_n", "0.0"),
            "detector.contact_threshold_n",
        ),
        (
            "NaN voltage",
            edit(&p, "voltage", "dc_v", "nan"),
            "voltage.dc_v",
        ),
        (
            "zero frequency",
            edit(&p, "voltage", "ac_frequency_hz", "0.0"),
            "voltage.ac_frequency_hz",
        ),
        (
            "negative lag",
            edit(&p, "slider", "interface_lag_s", "-1e-9"),
            "slider.interface_lag_s",
        ),
        (
            "negative sweep amplitude",
            edit(&p, "sweep", "ac_amplitudes_v", "[0.0, -0.5]"),
            "sweep.ac_amplitudes_v[1]",
        ),
        (
            "table range upside down",
            edit(
                &p,
                "table",
                "rel_tol",
                "1e-9\nd_min_m = 1e-8\nd_max_m = 1e-9",
            ),
            "table",
        ),
        (
            "oversized ensemble",
            edit(
                &edit(
                    &edit(&p, "surface.peaks", "family", "\"discrete_sampled\""),
                    "surface.peaks",
                    "sigma_m",
                    "1e-9\nn = 1000000000000000000",
                ),
                "surface.peaks",
                "epsilon",
                "0.7\nseed = 1\nfrom = { family = \"gaussian\", mean_m = 0.0, std_m = 1e-9 }",
            )
            .replace("sigma_m = 1e-9\n", "")
            .replace("epsilon = 0.7\nseed", "seed"),
            "surface.peaks.n",
        ),
        (
            "table below the flying gap",
            edit(&p, "table", "rel_tol", "1e-9\nd_max_m = 5e-9"),
            "table.d_max_m",
        ),
        (
            "table above the asperity peaks",
            edit(&p, "table", "rel_tol", "1e-9\nd_min_m = 2e-9"),
            "table.d_min_m",
        ),
        (
            "overflowing roughness",
            edit(&p, "surface", "height_sigma_m", "1e308"),
            "surface.height_sigma_m",
        ),
        (
            "roughness of 1e300 m, named without a 300-digit decimal",
            edit(
                &edit(&p, "surface", "height_sigma_m", "1e300"),
                "surface.peaks",
                "sigma_m",
                "1e300",
            ),
            "surface.height_sigma_m: must not exceed 10 x nominal_clearance_m = 1e-7 m, got 1e300 m",
        ),
        (
            "sigma set in one place only",
            edit(&p, "surface", "height_sigma_m", "5e-10"),
            "surface.peaks.sigma_m: is 7e-10 m but surface.height_sigma_m is 5e-10 m",
        ),
        (
            "huge DC voltage",
            edit(&p, "voltage", "dc_v", "1e200"),
            "voltage.dc_v: must be at most 1000 V, got 1e200 V",
        ),
        (
            "terahertz AC",
            edit(&p, "voltage", "ac_frequency_hz", "1e12"),
            "voltage.ac_frequency_hz",
        ),
        (
            "unbounded step budget",
            edit(&p, "solver", "max_steps", "1000000000000"),
            "solver.max_steps",
        ),
        (
            "wrong type inside a tagged section",
            edit(&p, "air_bearing", "stiffness_n_per_m", "\"stiff\""),
            "air_bearing.stiffness_n_per_m",
        ),
        (
            "wrong type",
            edit(&p, "slider", "mass_kg", "\"heavy\""),
            "slider.mass_kg",
        ),
        (
            "unknown field",
            p.replacen("[slider]\n", "[slider]\nmass_g = 1.0\n", 1),
            "mass_g",
        ),
        (
            "misspelt section",
            p.replacen("[detector]", "[detectors]", 1),
            "detectors",
        ),
    ]
}

fn write(dir: &std::path::Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn every_subcommand_rejects_bad_scene_files_on_one_line_naming_the_field() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    for (i, (label, text, field)) in bad_scenes().into_iter().enumerate() {
        // The edit itself must have produced a scene the library rejects.
        assert!(Scene::from_toml_str(&text).is_err(), "{label}: accepted");
        let path = write(dir, &format!("bad{i}"), &text);
        let file = path.to_string_lossy().into_owned();
        for args in [
            vec!["scene", file.as_str()],
            vec!["static", file.as_str()],
            vec!["cycle", file.as_str()],
            vec!["forces", file.as_str(), "--gaps", "1e-9"],
        ] {
            let out = Command::new(env!("CARGO_BIN_EXE_hdi"))
                .args(&args)
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(1), "{label} {args:?}: {err}");
            assert!(out.stdout.is_empty(), "{label} {args:?}: printed a result");
            assert_eq!(err.trim_end().lines().count(), 1, "{label} {args:?}: {err}");
            assert!(
                err.contains(field),
                "{label} {args:?}: {err} should name {field}"
            );
        }
    }
}

/// A scene file larger than any scene (64 MiB) is refused before it is read.
#[test]
fn an_oversized_scene_file_is_refused_before_it_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("big.toml");
    let f = std::fs::File::create(&path).unwrap();
    f.set_len(65 << 20).unwrap(); // sparse: no data written
    let err = Scene::from_path(&path).unwrap_err().to_string();
    assert!(err.contains("bytes"), "{err}");
    let out = Command::new(env!("CARGO_BIN_EXE_hdi"))
        .args(["scene", path.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr)
            .trim_end()
            .lines()
            .count(),
        1
    );
}
