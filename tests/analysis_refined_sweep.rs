//! The refined AC sweep: where it says converged, its hysteresis agrees with a reference run at
//! a far tighter tolerance with another method; the refinement options are checked by field.

use hdi_tribology::analysis::sweep::{ac_sweep_refined, Refinement};
use hdi_tribology::analysis::{simulate_cycle, CycleOptions, HeaterProgramme};
use hdi_tribology::model::{SliderModel, Voltage};
use hdi_tribology::ode::Method;
use hdi_tribology::scene::Scene;
use hdi_tribology::Error;

fn paper() -> (SliderModel, HeaterProgramme, CycleOptions) {
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene).unwrap();
    let knots = SliderModel::programme_from_knots(&scene.heater.programme).unwrap();
    (
        model,
        HeaterProgramme::Fixed(knots),
        CycleOptions::from_scene(&scene).unwrap(),
    )
}

/// Touchdown and take-off powers of one cycle with Radau5 at rtol 1e-10.
fn reference(
    model: &SliderModel,
    programme: &HeaterProgramme,
    opts: &CycleOptions,
    v_ac: f64,
) -> (f64, f64) {
    let m = model.with_voltage(Voltage {
        ac_amplitude: v_ac,
        ..model.voltage()
    });
    let mut o = *opts;
    o.solver.method = Method::Radau5;
    o.solver = o.solver.with_rtol(1e-10);
    let r = simulate_cycle(&m, programme, &o).unwrap();
    (r.touchdown.unwrap().power, r.takeoff.unwrap().power)
}

#[test]
fn converged_amplitudes_agree_with_a_tight_reference() {
    let (model, programme, opts) = paper();
    let refine = Refinement::new(2e-5);
    let amplitudes = [0.0, 0.4, 0.7];
    let sweep = ac_sweep_refined(&model, &programme, &opts, &amplitudes, &refine).unwrap();
    let mut converged = 0;
    for r in &sweep {
        let (td, to) = reference(&model, &programme, &opts, r.cycle.v_ac);
        let (rtd, rto) = (
            r.cycle.touchdown.unwrap().power,
            r.cycle.takeoff.unwrap().power,
        );
        println!(
            "{} V: runs {} rtol {:e} change {:e} | TD {:e} (ref {:e}) TO {:e} (ref {:e})",
            r.cycle.v_ac, r.runs, r.rtol, r.change, rtd, td, rto, to
        );
        assert!(r.runs >= 2 && r.runs <= refine.max_runs);
        assert_eq!(
            r.converged,
            r.change <= refine.power_tol && r.temperature_change <= refine.temperature_tol
        );
        if r.converged {
            converged += 1;
            // The change between the last two runs bounds the error of the earlier one; the
            // last one is the more accurate, so twice the tolerance is a safe bound.
            assert!(
                (rtd - td).abs() <= 2.0 * refine.power_tol,
                "{} V: TD {rtd} vs {td}",
                r.cycle.v_ac
            );
            assert!(
                (rto - to).abs() <= 2.0 * refine.power_tol,
                "{} V: TO {rto} vs {to}",
                r.cycle.v_ac
            );
        }
    }
    // 0 V and 0.4 V converge at the first tightening (measured: change < 1e-6 W).
    assert!(converged >= 2, "{converged} of {} converged", sweep.len());
}

#[test]
fn refinement_options_are_checked_by_field() {
    let (model, programme, opts) = paper();
    let field = |r: Refinement| match ac_sweep_refined(&model, &programme, &opts, &[0.0], &r) {
        Err(Error::InvalidInput { field, .. }) => field,
        other => panic!("expected an input error, got {other:?}"),
    };
    let ok = Refinement::new(1e-5);
    for tol in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert_eq!(
            field(Refinement {
                power_tol: tol,
                ..ok
            }),
            "refinement.power_tol"
        );
    }
    for factor in [0.0, 1.0, 2.0, f64::NAN] {
        assert_eq!(field(Refinement { factor, ..ok }), "refinement.factor");
    }
    for max_runs in [0, 1, 13] {
        assert_eq!(field(Refinement { max_runs, ..ok }), "refinement.max_runs");
    }
    for agreeing_runs in [0, 1, ok.max_runs + 1] {
        assert_eq!(
            field(Refinement {
                agreeing_runs,
                ..ok
            }),
            "refinement.agreeing_runs"
        );
    }
}

/// With `agreeing_runs = 3` a converged amplitude is one whose last three runs agree pairwise
/// within the tolerances, and the cycle kept is the last run itself: each run is redone here
/// with `simulate_cycle` at its tolerance.
#[test]
fn three_agreeing_runs_mean_three_agreeing_runs() {
    let (model, programme, opts) = paper();
    let refine = Refinement {
        agreeing_runs: 3,
        max_runs: 5,
        ..Refinement::new(6e-5)
    };
    for v_ac in [0.0, 0.3] {
        let r = &ac_sweep_refined(&model, &programme, &opts, &[v_ac], &refine).unwrap()[0];
        assert!(r.converged, "{v_ac} V: {r:?}");
        assert!(r.runs >= 3, "{v_ac} V: converged after {} runs", r.runs);
        let m = model.with_voltage(Voltage {
            ac_amplitude: v_ac,
            ..model.voltage()
        });
        // Run k at the paper scene's tolerances (rtol 1e-6, atol 1e-14 m) tightened k times by
        // 0.1, as the decimals they are: rtol 1e-(6+k), atol 1e-(14+k) m.
        assert_eq!(
            (opts.solver.rtol, opts.solver.atol_displacement),
            (1e-6, 1e-14)
        );
        let decimal = |e: usize| format!("1e-{e}").parse::<f64>().unwrap();
        assert_eq!(r.rtol, decimal(6 + r.runs - 1), "{v_ac} V");
        assert_eq!(r.atol, decimal(14 + r.runs - 1), "{v_ac} V");
        let run = |k: usize| {
            let mut o = opts;
            o.solver.rtol = decimal(6 + k);
            o.solver.atol_displacement = decimal(14 + k);
            simulate_cycle(&m, &programme, &o).unwrap()
        };
        let cycles: Vec<_> = (r.runs - 3..r.runs).map(run).collect();
        let last = &cycles[2];
        assert_eq!(last.touchdown, r.cycle.touchdown);
        assert_eq!(last.takeoff, r.cycle.takeoff);
        for w in cycles.windows(2) {
            for (a, b) in [
                (w[0].touchdown, w[1].touchdown),
                (w[0].takeoff, w[1].takeoff),
            ] {
                let moved = (a.unwrap().power - b.unwrap().power).abs();
                assert!(moved <= refine.power_tol, "{v_ac} V: moved {moved:e} W");
            }
            let dt = (w[0].mean_temperature_rise - w[1].mean_temperature_rise).abs();
            assert!(dt <= refine.temperature_tol, "{v_ac} V: ΔT moved {dt} K");
        }
        // With two agreeing runs the same amplitude stops earlier, on a run of this sequence.
        let two = &ac_sweep_refined(&model, &programme, &opts, &[v_ac], &Refinement::new(6e-5))
            .unwrap()[0];
        assert!(
            two.converged && two.runs < r.runs,
            "{v_ac} V: {} runs",
            two.runs
        );
    }
}

/// The refinement watches the mean temperature rise too: at 0.8 V the powers settle at rtol
/// 1e-7 while the mean ΔT is still 0.3 K off; refined, it agrees with a tight reference.
#[test]
fn the_mean_temperature_is_refined_too() {
    let (model, programme, opts) = paper();
    let refine = Refinement::new(6e-5);
    let r = &ac_sweep_refined(&model, &programme, &opts, &[0.8], &refine).unwrap()[0];
    let m = model.with_voltage(Voltage {
        ac_amplitude: 0.8,
        ..model.voltage()
    });
    let mut o = opts;
    o.solver.method = Method::Radau5;
    o.solver = o.solver.with_rtol(1e-10);
    let reference = simulate_cycle(&m, &programme, &o)
        .unwrap()
        .mean_temperature_rise;
    println!(
        "0.8 V: runs {} rtol {:e} ΔT {} (ref {reference}), change {}",
        r.runs, r.rtol, r.cycle.mean_temperature_rise, r.temperature_change
    );
    assert!(r.converged, "{r:?}");
    assert!(
        (r.cycle.mean_temperature_rise - reference).abs() <= 2.0 * refine.temperature_tol,
        "{} vs {reference}",
        r.cycle.mean_temperature_rise
    );
    // The tolerance alone at which the powers settle is not enough for the temperature.
    let mut o = opts;
    o.solver = o.solver.with_rtol(o.solver.rtol / 10.0);
    let loose = simulate_cycle(&m, &programme, &o)
        .unwrap()
        .mean_temperature_rise;
    assert!((loose - reference).abs() > 0.1, "{loose} vs {reference}");
}
