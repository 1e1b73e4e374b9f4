//! The touchdown and take-off scans that pass over proven stretches of the grid
//! (`ScanGrid::skip_proven`, the default) give the results of the full scan of every grid point,
//! to the bit: on the benchmark scenes, the extreme scenes, at several voltages, and on random
//! structures, thresholds and start powers.

use hdi_tribology::analysis::*;
use hdi_tribology::model::{SliderModel, Structure, Voltage};
use hdi_tribology::scene::Scene;
use proptest::prelude::*;

#[path = "common/scenes.rs"]
mod scenes;
use scenes::bench_structures;

/// The options with and without skipping.
fn both(threshold: f64) -> (StaticOptions, StaticOptions) {
    let skip = StaticOptions::new(threshold);
    let mut full = skip;
    full.grid.skip_proven = false;
    assert!(skip.grid.skip_proven);
    (skip, full)
}

/// The same transition to the bit, or the same error message.
fn same(a: &hdi_tribology::Result<Transition>, b: &hdi_tribology::Result<Transition>) -> bool {
    match (a, b) {
        (Ok(x), Ok(y)) => x == y,
        (Err(x), Err(y)) => x.to_string() == y.to_string(),
        _ => false,
    }
}

/// Touchdown, take-off from `excess` above it (or from a fixed power if there is no
/// touchdown), with and without skipping; the pull-in voltage too where the scene has a voltage
/// term.
fn check(name: &str, model: &SliderModel, threshold: f64, excess: f64) {
    let (skip, full) = both(threshold);
    let td = touchdown_power(model, &skip);
    assert!(
        same(&td, &touchdown_power(model, &full)),
        "{name}: touchdown {td:?}"
    );
    let start = td.as_ref().map_or(0.1, |t| t.power + excess);
    let to = takeoff_power(model, start, &skip);
    let to_full = takeoff_power(model, start, &full);
    assert!(
        same(&to, &to_full),
        "{name}: take-off {to:?} vs {to_full:?}"
    );
    if model.forces().has_voltage_terms() {
        let a = pull_in_voltage(model, 0.0, &skip);
        let b = pull_in_voltage(model, 0.0, &full);
        match (&a, &b) {
            (Ok(x), Ok(y)) => assert_eq!(x.voltage.to_bits(), y.voltage.to_bits(), "{name}"),
            (Err(x), Err(y)) => assert_eq!(x.to_string(), y.to_string(), "{name}"),
            _ => panic!("{name}: pull-in {a:?} vs {b:?}"),
        }
    }
}

#[test]
fn skipping_gives_the_full_scan_on_the_benchmark_and_extreme_scenes() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut scenes = Vec::new();
    for (name, structure) in bench_structures() {
        let mut s = Scene::paper();
        s.structure = structure;
        scenes.push((name.to_string(), s));
    }
    let mut files: Vec<_> = std::fs::read_dir(root.join("scenes/extreme"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.push(root.join("scenes/paper_bulge.toml"));
    files.sort();
    for f in files {
        scenes.push((f.display().to_string(), Scene::from_path(&f).unwrap()));
    }
    for (name, scene) in scenes {
        let model = SliderModel::from_scene(&scene).unwrap();
        check(&name, &model, scene.detector.contact_threshold_n, 0.03);
    }
}

#[test]
fn skipping_gives_the_full_scan_at_other_voltages_and_thresholds() {
    for (name, structure) in bench_structures() {
        let mut scene = Scene::paper();
        scene.structure = structure;
        let model = SliderModel::from_scene(&scene).unwrap();
        for dc in [0.5, 1.5, 2.5] {
            let v = Voltage {
                dc,
                ..model.voltage()
            };
            let m = model.with_voltage(v);
            for threshold in [1e-7, 5e-5, 1e-3] {
                for excess in [0.001, 0.03] {
                    check(
                        &format!("{name} at {dc} V, F_th {threshold:e}"),
                        &m,
                        threshold,
                        excess,
                    );
                }
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Random bulge and pitch structures, thresholds, start powers and voltages.
    #[test]
    fn skipping_gives_the_full_scan_on_random_structures(
        log_mb in -14.0f64..-8.0,
        log_kb in 4.0f64..8.0,
        pitch in any::<bool>(),
        kc in -50.0f64..50.0,
        log_th in -8.0f64..-2.0,
        excess in 0.0005f64..0.06,
        dc in 0.0f64..3.0,
    ) {
        let rigid = SliderModel::from_scene(&Scene::paper()).unwrap();
        let (m, l, k_ab) = (1e-6, 0.5e-3, 3e5);
        let structure = if pitch {
            Structure::pitch(m, m * l * l / 3.0, [k_ab * l * l / 3.0, kc], [1e-9, 0.0], l)
        } else {
            Structure::bulge(m, 10f64.powf(log_mb), 10f64.powf(log_kb), 0.05)
        }
        .unwrap();
        let model = rigid.with_structure(structure);
        let model = model.with_voltage(Voltage { dc, ..model.voltage() });
        check("random", &model, 10f64.powf(log_th), excess);
    }
}
