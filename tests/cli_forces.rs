//! `hdi forces` against an independent computation (literal double integrals by tanh–sinh), and
//! its behaviour on bad input.
#![cfg(feature = "cli")]

use std::f64::consts::PI;
use std::path::PathBuf;
use std::process::Command;

use hdi_tribology::force::{lj_zero, Footprint};
use hdi_tribology::quadrature::{integrate_tanh_sinh, QuadOptions};
use hdi_tribology::scene::Scene;
use hdi_tribology::surface::PeakModel;
use hdi_tribology::units::EPSILON_0;
use statrs::function::erf::erfc;

const GAPS: [f64; 3] = [0.5e-9, 1e-9, 2e-9];

fn scene_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name)
}

fn hdi(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_hdi"))
        .args(args)
        .output()
        .expect("the hdi binary runs")
}

/// Tanh–sinh at `rel`; the literal integrals below are nested, so the inner rule is asked for
/// more than the 1e-6 acceptance bound by a wide margin.
fn ts(f: impl FnMut(f64) -> f64, a: f64, b: f64, rel: f64) -> f64 {
    let opts = QuadOptions {
        abs_tol: 0.0,
        rel_tol: rel,
        max_intervals: 4000,
    };
    integrate_tanh_sinh(f, a, b, &opts).unwrap().value
}

fn gauss(z: f64, s: f64) -> f64 {
    (-0.5 * (z / s).powi(2)).exp() / (s * (2.0 * PI).sqrt())
}

/// Peak-height density written out from MODEL.md 3.1 (not the crate's implementation).
fn peak_pdf(model: &PeakModel) -> (Box<dyn Fn(f64) -> f64>, f64) {
    match *model {
        PeakModel::Gaussian { mean_m, std_m } => (
            Box::new(move |z| gauss(z - mean_m, std_m)),
            mean_m + 40.0 * std_m,
        ),
        PeakModel::RiceMaxima { sigma_m, epsilon } => {
            let c = (1.0 - epsilon * epsilon).sqrt();
            let f = move |z: f64| {
                let x = z / sigma_m;
                let big_phi = 0.5 * erfc(-x * c / epsilon / std::f64::consts::SQRT_2);
                (epsilon / (2.0 * PI).sqrt() * (-x * x / (2.0 * epsilon * epsilon)).exp()
                    + c * x * (-x * x / 2.0).exp() * big_phi)
                    / sigma_m
            };
            (Box::new(f), 40.0 * sigma_m)
        }
        _ => panic!("reference covers Gaussian and Rice-maxima peaks"),
    }
}

/// Derjaguin integral of a pressure `p̄(s)` over a footprint, literally.
fn over_footprint(fp: Footprint, d: f64, pbar: &dyn Fn(f64) -> f64) -> f64 {
    match fp {
        Footprint::Flat { area_m2 } => area_m2 * pbar(d),
        Footprint::Paraboloid {
            radius_of_curvature_m: rc,
            max_radius_m,
        } => {
            let c = 2.0 * PI * rc;
            match max_radius_m {
                Some(r) => c * ts(pbar, d, d + r * r / (2.0 * rc), 1e-10),
                // split so that tanh-sinh sees the near part at full resolution
                None => {
                    c * (ts(pbar, d, d + 20e-9, 1e-10) + ts(pbar, d + 20e-9, f64::INFINITY, 1e-10))
                }
            }
        }
    }
}

/// Roughness average of a pressure law over the non-contacting heights, literally:
/// `∫_{−∞}^{s − h_c} p(s − z) φ_σ(z) dz` (σ > 0 in these scenes).
fn averaged(p: &dyn Fn(f64) -> f64, s: f64, hc: f64, sigma: f64) -> f64 {
    let hi = (s - hc).min(40.0 * sigma);
    if hi <= -40.0 * sigma {
        return 0.0;
    }
    ts(|z| p(s - z) * gauss(z, sigma), -40.0 * sigma, hi, 1e-12)
}

struct Reference {
    intermolecular: f64,
    electrostatic_per_volt2: f64,
    contact: f64,
    area: f64,
}

fn reference(scene: &Scene, d: f64) -> Reference {
    let sigma = scene.surface.height_sigma_m;
    let m = scene.intermolecular.as_ref().unwrap();
    let (a, b) = (m.hamaker_attractive_j, m.hamaker_repulsive_j_m6);
    let hc = m.cutoff_m.unwrap_or_else(|| lj_zero(a, b));
    let lj = |h: f64| -a / (6.0 * PI * h.powi(3)) + b / (45.0 * PI * h.powi(9));
    let e = scene.electrostatic.as_ref().unwrap();
    let td = e.dielectric_thickness_m;
    let hce = e.cutoff_m.unwrap_or(hc);
    let el = |h: f64| -EPSILON_0 / (2.0 * (h + td).powi(2));
    let c = scene.contact.as_ref().unwrap();
    let (pdf, top) = peak_pdf(&scene.surface.peaks);
    let k =
        4.0 / 3.0 * c.composite_modulus_pa * c.asperity_radius_m.sqrt() * c.asperity_density_per_m2;
    let ka = PI * c.asperity_radius_m * c.asperity_density_per_m2;
    let pc = |s: f64| k * ts(|z| (z - s).powf(1.5) * pdf(z), s, top.max(s), 1e-12);
    let pa = |s: f64| ka * ts(|z| (z - s) * pdf(z), s, top.max(s), 1e-12);
    Reference {
        intermolecular: over_footprint(m.footprint, d, &|s| averaged(&lj, s, hc, sigma)),
        electrostatic_per_volt2: over_footprint(e.footprint, d, &|s| averaged(&el, s, hce, sigma)),
        contact: over_footprint(c.footprint, d, &pc),
        area: over_footprint(c.footprint, d, &pa),
    }
}

fn close(got: f64, want: f64) -> bool {
    // acceptance bound of the issue: 1e-6 relative
    (got - want).abs() <= 1e-6 * want.abs()
}

fn check_scene(args: &[&str], scene: &Scene) {
    let gaps = GAPS.map(|g| g.to_string()).join(",");
    let mut all: Vec<&str> = args.to_vec();
    all.extend(["--gaps", &gaps]);
    let out = hdi(&all);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), GAPS.len());
    let v = {
        let dv = scene.voltage.dc_v - scene.electrostatic.as_ref().unwrap().contact_potential_v;
        dv * dv
    };
    for (row, &d) in rows.iter().zip(&GAPS) {
        let get = |k: &str| {
            row[k]
                .as_f64()
                .unwrap_or_else(|| panic!("key {k} in {row}"))
        };
        assert_eq!(get("d_m"), d);
        let r = reference(scene, d);
        let name = &scene.name;
        assert!(
            close(get("intermolecular_n"), r.intermolecular),
            "{name} d={d}: LJ {} vs {}",
            get("intermolecular_n"),
            r.intermolecular
        );
        assert!(
            close(
                get("electrostatic_per_volt2_n_per_v2"),
                r.electrostatic_per_volt2
            ),
            "{name} d={d}: G_e"
        );
        assert!(
            close(get("contact_n"), r.contact),
            "{name} d={d}: contact {} vs {}",
            get("contact_n"),
            r.contact
        );
        assert!(
            close(get("real_contact_area_m2"), r.area),
            "{name} d={d}: area"
        );
        let fe = v * r.electrostatic_per_volt2;
        if v > 0.0 {
            assert!(close(get("electrostatic_n"), fe), "{name} d={d}: F_e");
        } else {
            assert_eq!(get("electrostatic_n"), 0.0);
        }
        let total = r.intermolecular + r.contact + fe;
        let scale = r.intermolecular.abs() + r.contact.abs() + fe.abs();
        assert!(
            (get("total_n") - total).abs() <= 1e-6 * scale,
            "{name} d={d}: total"
        );
    }
}

#[test]
fn paper_scene_forces_match_literal_double_integrals() {
    check_scene(&["forces", "--paper"], &Scene::paper());
    // the shipped file gives the same numbers as the built-in scene
    let file = scene_path("paper.toml");
    let a = hdi(&["forces", file.to_str().unwrap(), "--gaps", "1e-9"]);
    let b = hdi(&["forces", "--paper", "--gaps", "1e-9"]);
    assert_eq!(a.stdout, b.stdout);
}

#[test]
fn hand_written_scenes_match_literal_double_integrals() {
    for name in [
        "flat_gaussian.toml",
        "dielectric.toml",
        "finite_radius.toml",
    ] {
        let path = scene_path(name);
        let scene = Scene::from_path(&path).unwrap();
        check_scene(&["forces", path.to_str().unwrap()], &scene);
    }
}

fn one_line_error(out: &std::process::Output, code: i32) -> String {
    assert_eq!(
        out.status.code(),
        Some(code),
        "stdout {}",
        String::from_utf8_lossy(&out.stdout)
    );
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(err.lines().count(), 1, "one line expected: {err:?}");
    assert!(err.starts_with("hdi: "), "{err}");
    assert!(
        !err.contains("panicked") && !err.contains("backtrace"),
        "{err}"
    );
    assert!(out.stdout.is_empty());
    err
}

fn write_scene(name: &str, text: &str) -> PathBuf {
    let p = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn bad_scene_files_give_one_clear_line() {
    let paper = std::fs::read_to_string(scene_path("paper.toml")).unwrap();
    let cases: Vec<(&str, String, &str)> = vec![
        (
            "missing.toml",
            paper.replace("nominal_clearance_m = 1e-8 ", "# "),
            "nominal_clearance_m",
        ),
        (
            "negative.toml",
            paper.replace("height_sigma_m = 7e-10", "height_sigma_m = -7e-10"),
            "surface.height_sigma_m",
        ),
        (
            "nan.toml",
            paper.replace("mass_kg = 1e-6", "mass_kg = nan"),
            "slider.mass_kg",
        ),
        (
            "unknown.toml",
            format!("{paper}\n[magnetic]\nstrength = 1.0\n"),
            "magnetic",
        ),
        (
            "histogram.toml",
            paper.replace(
                "family = \"rice_maxima\"\nsigma_m = 7e-10\nepsilon = 0.7",
                "family = \"histogram\"\nedges_m = []\ncounts = []",
            ),
            "surface.peaks",
        ),
    ];
    for (file, text, needle) in cases {
        assert_ne!(text, paper, "{file}: the edit must apply");
        let p = write_scene(file, &text);
        let out = hdi(&["forces", p.to_str().unwrap(), "--gaps", "1e-9"]);
        let err = one_line_error(&out, 1);
        assert!(err.contains(needle), "{file}: {err}");
    }
    let json = write_scene("bad.json", "{\"name\": \"x\"");
    let err = one_line_error(
        &hdi(&["forces", json.to_str().unwrap(), "--gaps", "1e-9"]),
        1,
    );
    assert!(err.contains("bad.json"), "{err}");
    let err = one_line_error(
        &hdi(&["forces", "/nonexistent/scene.toml", "--gaps", "1e-9"]),
        1,
    );
    assert!(err.contains("scene.toml"), "{err}");
}

#[test]
fn bad_command_lines_are_usage_errors() {
    for args in [
        vec![],
        vec!["frobnicate"],
        vec!["forces", "--paper"],
        vec!["forces", "--paper", "--gaps", "1e-9,abc"],
        vec!["forces", "--paper", "--gaps", ""],
        vec!["forces", "--gaps", "1e-9"],
        vec!["forces", "--paper", "--gaps", "1e-9", "--colour", "red"],
        vec!["forces", "--paper", "x.toml", "--gaps", "1e-9"],
        vec!["forces", "--paper", "--gaps", "1e-9", "--gaps-nm", "1"],
        vec![
            "forces",
            "--paper",
            "--gaps-nm",
            "1",
            "--protrusion-m",
            "0",
            "--protrusion-nm",
            "0",
        ],
    ] {
        let out = hdi(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(out.stdout.is_empty(), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        // no command at all: the overview of the commands, on stderr
        let expected = if args.is_empty() {
            "Usage: hdi"
        } else {
            "error: "
        };
        assert!(err.contains(expected), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    assert!(hdi(&["help"]).status.success());
}

#[test]
fn gaps_in_nanometres_give_the_same_answer() {
    let m = hdi(&[
        "forces",
        "--paper",
        "--gaps",
        "5e-10,1e-9,2.5e-9",
        "--protrusion-m",
        "2e-9",
    ]);
    let nm = hdi(&[
        "forces",
        "--paper",
        "--gaps-nm",
        "0.5,1,2.5",
        "--protrusion-nm",
        "2",
    ]);
    assert!(m.status.success() && nm.status.success());
    assert_eq!(m.stdout, nm.stdout);
}
