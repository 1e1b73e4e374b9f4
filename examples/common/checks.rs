//! The convergence checks of a map point (`mechanism_maps`, `meniscus_map`). A point whose cycle
//! shows touchdown and take-off counts as converged when two more cycles agree with it, each to
//! [`POWER_TOL`] in touchdown and take-off:
//! - the method check: the other stiff method at the same tolerance. With AC the detected
//!   take-off can land a whole period of `V²` early or late (0.24 mW at 5 mW/ms and 10.5 kHz)
//!   in both runs of a tolerance check alike; another method's error rarely picks the same
//!   period (docs/analyses.md, "Why a method check");
//! - the tolerance check: the same method at a tolerance ten times tighter. The method is the
//!   one the shown run took ([`CycleResult::method`]): where `Auto` ran Rodas5P from the start
//!   (a stiff slider), the tighter run is Rodas5P too, not the Radau5 that `Auto` takes below
//!   rtol 1e-6, so that the check varies the tolerance alone and the method check the method
//!   alone (docs/benchmarks.md, "The tolerance check holds the method").
//!
//! Both must pass, so [`both_checks`] runs the method check first and the tighter run only where
//! it agrees: a point the method check stops saves the tighter run.

use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, CycleResult, HeaterProgramme};
use hdi_tribology::model::SliderModel;
use hdi_tribology::ode::Method;

/// Largest move of `P_TD` and `P_TO` for a check to agree (W).
pub const POWER_TOL: f64 = 5e-5;

/// Touchdown and take-off power of a cycle (W).
pub fn powers(r: &CycleResult) -> (Option<f64>, Option<f64>) {
    (r.touchdown.map(|d| d.power), r.takeoff.map(|d| d.power))
}

/// Whether touchdown and take-off are both present in `a` and `b` and move by at most
/// [`POWER_TOL`] between them.
pub fn agree(a: (Option<f64>, Option<f64>), b: (Option<f64>, Option<f64>)) -> bool {
    let close = |x: Option<f64>, y: Option<f64>| match (x, y) {
        (Some(x), Some(y)) => (x - y).abs() <= POWER_TOL,
        _ => false,
    };
    close(a.0, b.0) && close(a.1, b.1)
}

/// The stiff method that checks a run of `m`: Radau5, or Rodas5P for a run of Radau5.
pub fn other_stiff_method(m: Method) -> Method {
    match m {
        Method::Radau5 => Method::Rodas5P,
        _ => Method::Radau5,
    }
}

/// The options of a check run by `method`: those of `opts`, without the series, ending at the
/// take-off (a check compares the two powers alone).
fn check_options(opts: &CycleOptions, method: Method) -> CycleOptions {
    let mut o = *opts;
    o.keep_series = false;
    o.stop_at_takeoff = true;
    o.solver.method = method;
    o
}

/// The options of the tolerance check's run by `method`: [`check_options`] at ten times tighter
/// tolerances, by the library's one rule for a new rtol (`SolverSettings::with_rtol`, which
/// scales the displacement tolerance alike).
fn tighter_options(opts: &CycleOptions, method: Method) -> CycleOptions {
    let mut o = check_options(opts, method);
    o.solver = o.solver.with_rtol(o.solver.rtol / 10.0);
    o
}

/// The method check of the values `shown`, which a cycle with `opts` gave by `method`
/// ([`CycleResult::method`]): whether the other stiff method at the same tolerance agrees. A run
/// that fails does not agree. Its accepted steps are added to `steps`.
pub fn method_check(
    model: &SliderModel,
    programme: &HeaterProgramme,
    opts: &CycleOptions,
    (shown, method): ((Option<f64>, Option<f64>), Method),
    steps: &mut usize,
) -> bool {
    let o = check_options(opts, other_stiff_method(method));
    match simulate_cycle(model, programme, &o) {
        Ok(other) => {
            *steps += other.stats.accepted;
            agree(shown, powers(&other))
        }
        Err(_) => false,
    }
}

/// The tolerance check of the values `shown`, which a cycle with `opts` gave by `method`
/// ([`CycleResult::method`]): whether a cycle by the same method at ten times tighter
/// tolerances agrees. A run that fails is the point's error. Its accepted steps are added to
/// `steps`.
pub fn tolerance_check(
    model: &SliderModel,
    programme: &HeaterProgramme,
    opts: &CycleOptions,
    (shown, method): ((Option<f64>, Option<f64>), Method),
    steps: &mut usize,
) -> hdi_tribology::Result<bool> {
    let tighter = simulate_cycle(model, programme, &tighter_options(opts, method))?;
    *steps += tighter.stats.accepted;
    Ok(agree(shown, powers(&tighter)))
}

/// Both checks of the values that the cycle `first` (run with `opts`) shows (the method check
/// only where `method`), the method check first: whether the point converged. Each run started
/// is counted in `runs`, its accepted steps in `steps`; the tighter run's failure is the point's
/// error.
pub fn both_checks(
    model: &SliderModel,
    programme: &HeaterProgramme,
    opts: &CycleOptions,
    first: &CycleResult,
    method: bool,
    runs: &mut usize,
    steps: &mut usize,
) -> hdi_tribology::Result<bool> {
    let shown = (powers(first), first.method);
    if method {
        *runs += 1;
        if !method_check(model, programme, opts, shown, steps) {
            return Ok(false);
        }
    }
    *runs += 1;
    tolerance_check(model, programme, opts, shown, steps)
}

#[cfg(test)]
mod tests {
    use super::*;
    use hdi_tribology::scene::Scene;

    /// The paper cycle at 0 V passes both checks in three runs; values a milliwatt off fail the
    /// method check, and the tighter run is then not run.
    #[test]
    fn the_method_check_runs_first_and_a_disagreement_skips_the_tighter_run(
    ) -> hdi_tribology::Result<()> {
        let scene = Scene::paper();
        let model = SliderModel::from_scene(&scene)?;
        let programme = HeaterProgramme::fixed_from_scene(&scene)?;
        let opts = CycleOptions::from_scene(&scene)?;
        let first = simulate_cycle(&model, &programme, &opts)?;
        let shown = powers(&first);
        assert!(shown.0.is_some() && shown.1.is_some());
        let (mut runs, mut steps) = (1, first.stats.accepted);
        assert!(both_checks(
            &model, &programme, &opts, &first, true, &mut runs, &mut steps
        )?);
        assert_eq!(runs, 3);
        let mut off = first.clone();
        off.touchdown = first.touchdown.map(|mut d| {
            d.power += 1e-3;
            d
        });
        let (mut runs, mut steps) = (1, 0);
        assert!(!both_checks(
            &model, &programme, &opts, &off, true, &mut runs, &mut steps
        )?);
        assert_eq!(runs, 2);
        // Without the method check the tighter run alone decides, and disagrees too.
        let (mut runs, mut steps) = (1, 0);
        assert!(!both_checks(
            &model, &programme, &opts, &off, false, &mut runs, &mut steps
        )?);
        assert_eq!(runs, 2);
        assert!(!agree((shown.0, None), shown));
        assert_eq!(other_stiff_method(Method::Auto), Method::Radau5);
        assert_eq!(other_stiff_method(Method::Radau5), Method::Rodas5P);
        Ok(())
    }

    /// Where `Auto` ran Rodas5P from the start (a 10 ns interface lag), the tolerance check runs
    /// Rodas5P at the tighter tolerance: its steps are those of that run, not those of `Auto`
    /// there, which would take Radau5.
    #[test]
    fn the_tolerance_check_holds_the_method_the_first_run_took() -> hdi_tribology::Result<()> {
        let scene = Scene::paper();
        let model = SliderModel::from_scene(&scene)?.with_interface_lag(1e-8);
        let programme = HeaterProgramme::fixed_from_scene(&scene)?;
        let mut opts = CycleOptions::from_scene(&scene)?;
        opts.solver.method = Method::Auto;
        let first = simulate_cycle(&model, &programme, &opts)?;
        assert_eq!(first.method, Method::Rodas5P);
        let mut steps = 0;
        assert!(tolerance_check(
            &model,
            &programme,
            &opts,
            (powers(&first), first.method),
            &mut steps
        )?);
        let tighter = |method| simulate_cycle(&model, &programme, &tighter_options(&opts, method));
        let (held, auto) = (tighter(Method::Rodas5P)?, tighter(Method::Auto)?);
        assert_eq!(auto.method, Method::Radau5);
        assert_eq!(steps, held.stats.accepted);
        assert_ne!(steps, auto.stats.accepted);
        Ok(())
    }
}
