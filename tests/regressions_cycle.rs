//! Dynamic-cycle cases that once failed, kept as regression tests.

use hdi_tribology::analysis::cycle::CycleError;
use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, HeaterProgramme};
use hdi_tribology::error::{Failure, Stage};

/// The cycle's failure and its kind, or a panic naming what came instead.
fn cycle_failure<T: std::fmt::Debug>(r: Result<T, Error>) -> (Failure, CycleError) {
    match r {
        Err(Error::Analysis(f)) => {
            let kind = f.downcast_ref::<CycleError>().cloned();
            (
                f.clone(),
                kind.unwrap_or_else(|| panic!("not a cycle error: {f}")),
            )
        }
        other => panic!("expected a cycle error, got {other:?}"),
    }
}
use hdi_tribology::model::SliderModel;
use hdi_tribology::scene::Scene;
use hdi_tribology::Error;

#[path = "common/scenes.rs"]
mod scenes;

/// A 100 ns interface lag on the paper scene (c/K_contact ≈ 27 ns) makes the contact branch
/// self-excited: the head bounced ever higher and harder and the integration ended with
/// `Ode(NonFinite)` at t ≈ 3.67 ms, 26 nm deep in the disk. It now stops where the pad reaches
/// the disk, with an error that says why.
#[test]
fn self_excited_contact_stops_with_a_reason_instead_of_nan() {
    let mut scene = Scene::paper();
    scene.slider.interface_lag_s = 1e-7;
    let model = SliderModel::from_scene(&scene).unwrap();
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    match cycle_failure(simulate_cycle(
        &model,
        &programme,
        &CycleOptions::from_scene(&scene).unwrap(),
    )) {
        (
            e,
            CycleError::LeftTheModel {
                self_excited: Some(x),
                ..
            },
        ) => {
            assert_eq!(e.stage(), Stage::CYCLE);
            assert!((x.interface_lag_ns - 100.0).abs() < 1e-9, "{e}");
            assert!(x.limit_ns < x.interface_lag_ns, "{e}");
            let text = e.to_string();
            assert!(text.contains("pad gap h0 + y fell to zero"), "{text}");
            assert!(!text.contains('\n'));
        }
        other => panic!("expected the self-excitation error, got {other:?}"),
    }
}

/// A lag below c/K_contact keeps the contact branch stable: the same programme runs through.
#[test]
fn a_short_interface_lag_runs_through() {
    let mut scene = Scene::paper();
    scene.slider.interface_lag_s = 1e-11;
    let model = SliderModel::from_scene(&scene).unwrap();
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    let r = simulate_cycle(
        &model,
        &programme,
        &CycleOptions::from_scene(&scene).unwrap(),
    )
    .unwrap();
    let h = r.hysteresis.unwrap();
    assert!(h > 0.0 && h.is_finite(), "{r:?}");
}

/// A bulge ringing at 142 MHz beside a 0.1 ns interface lag at 1 V AC: the few-peak contact
/// bounces without bound. The cycle used its whole 3e5-step budget (7 s) on the first 73 µs of
/// a 10 ms programme; it now stops once it spends steps at more than twice the even pace.
#[test]
fn a_cycle_spending_steps_too_fast_stops_early() {
    let scene = scenes::paper_bulge();
    let model = SliderModel::from_scene(&scene)
        .unwrap()
        .with_ac_amplitude(1.0)
        .with_interface_lag(1e-10);
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    let mut opts = CycleOptions::from_scene(&scene).unwrap();
    opts.solver.max_steps = 300_000;
    match cycle_failure(simulate_cycle(&model, &programme, &opts)).1 {
        CycleError::StepPace {
            steps, max_steps, ..
        } => {
            assert_eq!(max_steps, 300_000);
            // The steps spent are named: far fewer than the budget.
            assert!(steps < 100_000, "{steps}");
        }
        other => panic!("expected the step-pace error, got {other:?}"),
    }
}

/// `auto` on a bulge at hundreds of MHz starts with its stiff method (its explicit steps would
/// be limited to about a nanosecond), and gives the same hysteresis as Rodas5P asked for
/// directly, bit for bit.
#[test]
fn auto_on_a_stiff_structure_starts_stiff() {
    use hdi_tribology::model::Structure;
    use hdi_tribology::ode::Method;
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene)
        .unwrap()
        .with_structure(Structure::bulge(scene.slider.mass_kg, 1e-13, 8e5, 0.05).unwrap());
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    let mut opts = CycleOptions::from_scene(&scene).unwrap();
    assert_eq!((opts.solver.method, opts.solver.rtol), (Method::Auto, 1e-6));
    let auto = simulate_cycle(&model, &programme, &opts).unwrap();
    assert_eq!(auto.stats.stiffness_switches, 0, "{:?}", auto.stats);
    assert_eq!(auto.stats.stiff_steps, auto.stats.accepted);
    opts.solver.method = Method::Rodas5P;
    let rodas = simulate_cycle(&model, &programme, &opts).unwrap();
    assert_eq!(auto.hysteresis, rodas.hysteresis);
    assert!(auto.hysteresis.is_some_and(|h| h > 0.0));
    // The rigid paper scene keeps Auto's switching (it starts explicit).
    let rigid = SliderModel::from_scene(&scene).unwrap();
    opts.solver.method = Method::Auto;
    let r = simulate_cycle(&rigid, &programme, &opts).unwrap();
    assert!(r.stats.stiff_steps < r.stats.accepted, "{:?}", r.stats);
}

/// The cycle of `a_cycle_spending_steps_too_fast_stops_early` with the stop below the force
/// tables asked for: at 1 V its contact bounces below the tables' low end (−3.5 nm) at 20 times
/// the even step pace 25 µs into the programme, and the cycle stops at that first step below the
/// tables (1.7e4 steps, 0.05 s), where the step pace alone let it run on to 3.2e4 steps (1.1 s:
/// out there every force is an exact quadrature). At 0.8 V it first goes below the tables at
/// 1.07 ms, within the even pace, and then spends 3e4 steps in 2 µs: it now stops once it has
/// spent the allowance of 1 % of the budget since then at more than twice the even pace.
#[test]
fn a_bounce_below_the_tables_stops_when_asked() {
    let scene = scenes::paper_bulge();
    let mut model = SliderModel::from_scene(&scene)
        .unwrap()
        .with_interface_lag(1e-10);
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    let mut opts = CycleOptions::from_scene(&scene).unwrap();
    assert!(!opts.stop_outside_tables);
    opts.solver.max_steps = 300_000;
    opts.stop_outside_tables = true;
    let low_nm = model.forces().table_range().0 * 1e9;
    for v_ac in [1.0, 0.8] {
        model = model.with_ac_amplitude(v_ac);
        match cycle_failure(simulate_cycle(&model, &programme, &opts)) {
            (
                e,
                CycleError::LeftTheTables {
                    t_ms,
                    bulge_gap_nm,
                    table_low_nm,
                    steps,
                    first_below_ms,
                    steps_below,
                    span_ms,
                    max_steps,
                },
            ) => {
                assert_eq!(e.stage(), Stage::CYCLE);
                assert_eq!(e.kind(), "LeftTheTables");
                assert!((table_low_nm - low_nm).abs() <= 1e-12 * low_nm.abs(), "{e}");
                assert!(bulge_gap_nm < table_low_nm, "{e}");
                assert_eq!((max_steps, span_ms), (300_000, 10.0));
                assert!(first_below_ms <= t_ms && steps_below <= steps, "{e}");
                let pace = |n: usize, ms: f64| n as f64 > 2.0 * 300_000.0 * ms / span_ms;
                if v_ac == 1.0 {
                    // Past twice the even pace from the start, at the first step below.
                    assert!(pace(steps, t_ms) && steps_below == 0, "{e}");
                    assert!(steps < 30_000, "{e}");
                } else {
                    // Within the even pace from the start; past it since the first step below,
                    // after the allowance of 3 000 steps.
                    assert!(!pace(steps, t_ms), "{e}");
                    assert!(pace(steps_below - 3_000, t_ms - first_below_ms), "{e}");
                    assert!(steps_below < 10_000, "{e}");
                }
                assert!(!e.to_string().contains('\n'));
            }
            other => panic!("{v_ac} V: expected the stop below the tables, got {other:?}"),
        }
    }
}

/// The stop below the tables leaves cycles alone that do not bounce without bound: the bulge
/// scene's own cycle, and a rigid slider with a 10 µs lag at 1 V AC whose hard contact dips
/// below the tables (to −4.8 nm, for about 0.2 ms) at a steady pace. Both come out bit for bit
/// as without it.
#[test]
fn the_stop_below_the_tables_leaves_finished_cycles_alone() {
    use hdi_tribology::model::Structure;
    let scene = scenes::paper_bulge();
    let bulge = SliderModel::from_scene(&scene).unwrap();
    let rigid = bulge
        .with_structure(Structure::rigid(scene.slider.mass_kg).unwrap())
        .with_interface_lag(1e-5)
        .with_ac_amplitude(1.0);
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    let mut opts = CycleOptions::from_scene(&scene).unwrap();
    opts.solver.max_steps = 300_000;
    opts.keep_series = true;
    let low = bulge.forces().table_range().0;
    for (model, dips) in [(&bulge, false), (&rigid, true)] {
        let off = simulate_cycle(model, &programme, &opts).unwrap();
        let mut on_opts = opts;
        on_opts.stop_outside_tables = true;
        let on = simulate_cycle(model, &programme, &on_opts).unwrap();
        let deepest = off
            .series
            .as_ref()
            .unwrap()
            .d
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        assert_eq!(
            deepest < low,
            dips,
            "deepest {deepest:e} m, tables from {low:e} m"
        );
        assert!(off.hysteresis.is_some());
        assert_eq!(
            (off.touchdown, off.takeoff, off.hysteresis, off.stats),
            (on.touchdown, on.takeoff, on.hysteresis, on.stats)
        );
        assert_eq!(
            off.mean_temperature_rise.to_bits(),
            on.mean_temperature_rise.to_bits()
        );
        let bits = |r: &hdi_tribology::analysis::CycleResult| {
            let s = r.series.as_ref().unwrap();
            [&s.t, &s.d, &s.contact, &s.indicator]
                .map(|v| v.iter().map(|x| x.to_bits()).collect::<Vec<u64>>())
        };
        assert_eq!(bits(&off), bits(&on));
    }
}
