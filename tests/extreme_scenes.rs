//! Every scene under `scenes/extreme/` is loaded and run: interface forces over the whole table
//! range (down to −5σ), the static touchdown/take-off analysis, and a dynamic cycle under the
//! scene's programme. Each gives a finite answer that holds when the tolerance is tightened
//! tenfold, or the typed error that the table below expects — never NaN, a panic or a hang.

use hdi_tribology::analysis::cycle::CycleError;
use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, CycleResult, HeaterProgramme};
use hdi_tribology::analysis::equilibrium::FlyingError;
use hdi_tribology::analysis::touchdown::TransitionError;
use hdi_tribology::analysis::{static_hysteresis, StaticHysteresis, StaticOptions};
use hdi_tribology::error::Failure;
use hdi_tribology::force::Gaps;
use hdi_tribology::model::SliderModel;
use hdi_tribology::scene::Scene;
use hdi_tribology::{Error, Result};
use std::path::{Path, PathBuf};

/// What an analysis of a scene must give.
#[derive(Clone, Copy, Debug)]
enum Expect {
    /// A finite answer.
    Finite,
    /// An analysis error of the kind this function accepts.
    Fails(fn(&Failure) -> bool),
}

/// Touchdown lies at negative power.
fn in_contact_at_zero_power(e: &Failure) -> bool {
    matches!(e.downcast_ref(), Some(TransitionError::InContactAtZeroPower { power_mw, .. }) if *power_mw < 0.0)
}

/// Take-off would need negative power: adhesion holds the head.
fn held_in_contact(e: &Failure) -> bool {
    matches!(e.downcast_ref(), Some(TransitionError::NoTakeOff { power_mw, .. }) if *power_mw < 0.0)
}

/// At exactly the pull-in voltage the touchdown fold lies at 0 W to rounding: either.
fn either_at_zero_power(e: &Failure) -> bool {
    in_contact_at_zero_power(e) || held_in_contact(e)
}

/// The flying branch ends before the programme's start power.
fn flying_branch_ends(e: &Failure) -> bool {
    matches!(e.downcast_ref(), Some(FlyingError::FlyingBranchEnds { .. }))
}

/// The pad reached the disk, with the lag named as the cause.
fn self_excited(e: &Failure) -> bool {
    matches!(
        e.downcast_ref(),
        Some(CycleError::LeftTheModel {
            self_excited: Some(_),
            ..
        })
    )
}

use Expect::{Fails, Finite};

/// (file, static analysis, dynamic cycle).
const CASES: &[(&str, Expect, Expect)] = &[
    ("roughness_0p01nm.toml", Fails(held_in_contact), Finite),
    (
        "roughness_5nm.toml",
        Fails(in_contact_at_zero_power),
        Finite,
    ),
    ("smooth.toml", Finite, Finite),
    ("hard_contact.toml", Finite, Finite),
    ("adhesion_weak.toml", Finite, Finite),
    ("adhesion_strong.toml", Fails(held_in_contact), Finite),
    (
        "voltage_20v.toml",
        Fails(in_contact_at_zero_power),
        Fails(flying_branch_ends),
    ),
    ("voltage_1mv.toml", Finite, Finite),
    ("ac_1hz.toml", Finite, Finite),
    ("ac_43khz.toml", Finite, Finite),
    ("ac_3mhz.toml", Finite, Finite),
    ("damping_1e-4.toml", Finite, Finite),
    ("damping_10.toml", Finite, Finite),
    ("ramp_1us.toml", Finite, Finite),
    ("ramp_1s.toml", Finite, Finite),
    ("near_fold.toml", Finite, Finite),
    // At exactly the pull-in voltage the touchdown fold lies at 0 W to rounding.
    (
        "pull_in.toml",
        Fails(either_at_zero_power),
        Fails(flying_branch_ends),
    ),
    ("interface_lag_100ns.toml", Finite, Fails(self_excited)),
];

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/extreme")
}

fn load(file: &str) -> Scene {
    Scene::from_path(dir().join(file)).unwrap_or_else(|e| panic!("{file}: {e}"))
}

fn check_expect<T>(file: &str, what: &str, r: &Result<T>, e: Expect) {
    match (r, e) {
        (Ok(_), Finite) => {}
        (Err(Error::Analysis(a)), Fails(accepts)) => {
            assert!(accepts(a), "{file} {what}: {a:?}: {a}")
        }
        (Err(err), _) => panic!("{file} {what}: expected {e:?}, got error {err}"),
        (Ok(_), Fails(_)) => {
            panic!("{file} {what}: expected {e:?}, got a result")
        }
    }
}

fn static_of(scene: &Scene) -> Result<StaticHysteresis> {
    let model = SliderModel::from_scene(scene)?;
    static_hysteresis(
        &model,
        &StaticOptions::new(scene.detector.contact_threshold_n),
    )
}

fn cycle_of(scene: &Scene) -> Result<CycleResult> {
    let model = SliderModel::from_scene(scene)?;
    let programme = HeaterProgramme::fixed_from_scene(scene)?;
    simulate_cycle(&model, &programme, &CycleOptions::from_scene(scene)?)
}

#[test]
fn every_extreme_scene_is_covered_by_the_table() {
    let mut files: Vec<String> = std::fs::read_dir(dir())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|f| f.ends_with(".toml"))
        .collect();
    files.sort();
    let mut listed: Vec<String> = CASES.iter().map(|c| c.0.to_string()).collect();
    listed.sort();
    assert_eq!(files, listed);
}

/// Forces through the tables at every gap of a fine grid over the table range (which reaches
/// −5σ below the lowest of the mean plane and the mean peak height): finite, contact force
/// non-negative to the table's absolute tolerance, and equal to direct evaluation.
#[test]
fn forces_are_finite_down_to_minus_five_sigma() {
    for file in CASES.iter().map(|c| c.0) {
        let scene = load(file);
        let model = SliderModel::from_scene(&scene).unwrap();
        let (lo, hi) = model.forces().table_range();
        let s = scene
            .surface
            .height_sigma_m
            .max(scene.peaks().unwrap().std_dev());
        assert!(
            lo <= -5.0 * s,
            "{file}: table starts at {lo:e}, above -5 sigma"
        );
        let volt2 = scene.dc_volt2().max(1.0);
        for i in 0..=400 {
            let d = lo + (hi - lo) * f64::from(i) / 400.0;
            let g = Gaps::same(d);
            let f = model.interface_force(g, volt2);
            let b = model.breakdown(g, volt2);
            for x in [f.value, f.d_bulge, b.contact, b.real_contact_area, b.total] {
                assert!(
                    x.is_finite(),
                    "{file}: non-finite force at d = {d:e}: {b:?}"
                );
            }
            // Tables interpolate with abs_tol 1e-16 N: a Hermite undershoot below zero stays
            // within it.
            assert!(
                b.contact >= -1e-16,
                "{file}: contact {:e} at {d:e}",
                b.contact
            );
            let exact = model.interface_force_exact(g, volt2).unwrap();
            let scale = b.intermolecular.abs() + b.contact.abs() + b.electrostatic.abs();
            // 1e-9 table tolerance per merged table, a few tables summed.
            assert!(
                (f.value - exact.value).abs() <= 1e-8 * scale + 1e-15,
                "{file}: table {:e} vs direct {:e} at {d:e}",
                f.value,
                exact.value
            );
        }
    }
}

/// Static analysis: the expected outcome, `P_TD ≥ P_TO ≥ 0`, and the same powers (to 1e-9 W)
/// with the table tolerance tightened tenfold. Folds and thresholds are refined on direct
/// evaluation to 1e-12 relative in `d`, so the tables only choose the bracket.
#[test]
fn static_analyses_are_finite_and_converged_or_say_why() {
    for &(file, expect, _) in CASES {
        let scene = load(file);
        let r = static_of(&scene);
        check_expect(file, "static", &r, expect);
        let Ok(h) = r else { continue };
        assert!(
            h.touchdown.power >= 0.0 && h.takeoff.power >= 0.0,
            "{file}: {h:?}"
        );
        assert!(h.hysteresis >= 0.0, "{file}: negative hysteresis {h:?}");
        let mut tight = scene.clone();
        tight.table.rel_tol /= 10.0;
        let t = static_of(&tight).unwrap();
        for (a, b) in [
            (h.touchdown.power, t.touchdown.power),
            (h.takeoff.power, t.takeoff.power),
        ] {
            assert!(
                (a - b).abs() <= 1e-9,
                "{file}: {a} W vs {b} W with a tighter table"
            );
        }
    }
}

/// Dynamic cycle: the expected outcome; finite powers, hysteresis and mean temperature; the same
/// detections with rtol tightened tenfold.
#[test]
fn cycles_are_finite_and_converged_or_say_why() {
    for &(file, _, expect) in CASES {
        let scene = load(file);
        let r = cycle_of(&scene);
        check_expect(file, "cycle", &r, expect);
        let Ok(c) = r else { continue };
        assert!(
            c.mean_temperature_rise.is_finite() && c.mean_temperature_rise >= 0.0,
            "{file}"
        );
        if let Some(h) = c.hysteresis {
            assert!(h.is_finite() && h >= 0.0, "{file}: hysteresis {h}");
        }
        let mut tight = scene.clone();
        tight.solver.rtol /= 10.0;
        tight.solver.atol_m /= 10.0;
        let t = cycle_of(&tight).unwrap_or_else(|e| panic!("{file} at rtol/10: {e}"));
        let report = format!(
            "{file}: {:?} {:?} vs {:?} {:?}",
            c.touchdown, c.takeoff, t.touchdown, t.takeoff
        );
        assert_eq!(c.touchdown.is_some(), t.touchdown.is_some(), "{report}");
        assert_eq!(c.takeoff.is_some(), t.takeoff.is_some(), "{report}");
        // The detection powers move by the programme's power change over the detection-time
        // error; 1 µW is 0.2 % of the smallest hysteresis here and far above an integration
        // error of rtol 1e-6 on the contact impulse.
        for (a, b) in [(c.touchdown, t.touchdown), (c.takeoff, t.takeoff)] {
            if let (Some(a), Some(b)) = (a, b) {
                assert!((a.power - b.power).abs() <= 1e-6, "{report}");
            }
        }
        let (m1, m2) = (c.mean_temperature_rise, t.mean_temperature_rise);
        assert!(
            (m1 - m2).abs() <= 1e-3 * m2.abs() + 1e-9,
            "{file}: mean ΔT {m1} vs {m2}"
        );
    }
}

/// A hair below the fold of the flying branch the equilibrium is still found, stable and above
/// the fold's gap; a hair above, the analysis says that the branch has ended.
#[test]
fn equilibria_next_to_the_fold_are_found_or_refused_cleanly() {
    use hdi_tribology::analysis::{flying_equilibrium, touchdown_power, Cause, ScanGrid};
    let scene = load("near_fold.toml");
    let model = SliderModel::from_scene(&scene).unwrap();
    let td = touchdown_power(
        &model,
        &StaticOptions::new(scene.detector.contact_threshold_n),
    )
    .unwrap();
    assert_eq!(td.cause, Cause::Fold);
    for rel in [1e-3, 1e-6, 1e-9] {
        let e = flying_equilibrium(&model, td.power * (1.0 - rel), 0.0, &ScanGrid::default())
            .unwrap_or_else(|e| panic!("{rel}: {e}"));
        assert!(
            e.is_stable() && e.d > td.at.d,
            "{rel}: {e:?} vs fold {:?}",
            td.at
        );
        assert!((e.power - td.power * (1.0 - rel)).abs() <= 1e-9 * td.power);
    }
    for rel in [1e-9, 1e-6, 1e-3] {
        match flying_equilibrium(&model, td.power * (1.0 + rel), 0.0, &ScanGrid::default()) {
            Err(Error::Analysis(e)) if e.is::<FlyingError>() => {
                let Some(&FlyingError::FlyingBranchEnds {
                    power_mw,
                    fold_gap_nm,
                }) = e.downcast_ref()
                else {
                    panic!("{e}")
                };
                assert!(
                    (fold_gap_nm - td.at.d * 1e9).abs() <= 1e-9 * fold_gap_nm,
                    "{fold_gap_nm} nm vs the fold at {:e} m",
                    td.at.d
                );
                assert!((power_mw - td.power_mw() * (1.0 + rel)).abs() <= 1e-9 * power_mw);
            }
            other => panic!("{rel}: expected the end of the branch, got {other:?}"),
        }
    }
}
