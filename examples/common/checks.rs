//! The convergence checks of a map point (`mechanism_maps`, `meniscus_map`). A point whose cycle
//! shows touchdown and take-off counts as converged when two more cycles agree with it, each to
//! [`POWER_TOL`] in touchdown and take-off:
//! - the method check: the other stiff method at the same tolerance. With AC the detected
//!   take-off can land a whole period of `V²` early or late (0.24 mW at 5 mW/ms and 10.5 kHz)
//!   in both runs of a tolerance check alike; another method's error rarely picks the same
//!   period (docs/analyses.md, "Why a method check");
//! - the tolerance check: the same settings at a tolerance ten times tighter.
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

/// The method check of the values `shown`, which a cycle with `opts` gave: whether the other
/// stiff method at the same tolerance agrees. A run that fails does not agree. Its accepted
/// steps are added to `steps`.
pub fn method_check(
    model: &SliderModel,
    programme: &HeaterProgramme,
    opts: &CycleOptions,
    shown: (Option<f64>, Option<f64>),
    steps: &mut usize,
) -> bool {
    let mut o = *opts;
    o.keep_series = false;
    // A check compares the two powers alone: the run ends at its take-off.
    o.stop_at_takeoff = true;
    o.solver.method = other_stiff_method(o.solver.method);
    match simulate_cycle(model, programme, &o) {
        Ok(other) => {
            *steps += other.stats.accepted;
            agree(shown, powers(&other))
        }
        Err(_) => false,
    }
}

/// The tolerance check of the values `shown`: whether a cycle at ten times tighter tolerances
/// than `opts` agrees. A run that fails is the point's error. Its accepted steps are added to
/// `steps`.
pub fn tolerance_check(
    model: &SliderModel,
    programme: &HeaterProgramme,
    opts: &CycleOptions,
    shown: (Option<f64>, Option<f64>),
    steps: &mut usize,
) -> hdi_tribology::Result<bool> {
    let mut o = *opts;
    o.keep_series = false;
    // A check compares the two powers alone: the run ends at its take-off.
    o.stop_at_takeoff = true;
    o.solver.rtol *= 0.1;
    o.solver.atol_displacement *= 0.1;
    let tighter = simulate_cycle(model, programme, &o)?;
    *steps += tighter.stats.accepted;
    Ok(agree(shown, powers(&tighter)))
}

/// Both checks of the values `shown` (the method check only where `method`), the method check
/// first: whether the point converged. Each run started is counted in `runs`, its accepted
/// steps in `steps`; the tighter run's failure is the point's error.
pub fn both_checks(
    model: &SliderModel,
    programme: &HeaterProgramme,
    opts: &CycleOptions,
    shown: (Option<f64>, Option<f64>),
    method: bool,
    runs: &mut usize,
    steps: &mut usize,
) -> hdi_tribology::Result<bool> {
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
            &model, &programme, &opts, shown, true, &mut runs, &mut steps
        )?);
        assert_eq!(runs, 3);
        let off = (shown.0.map(|p| p + 1e-3), shown.1);
        let (mut runs, mut steps) = (1, 0);
        assert!(!both_checks(
            &model, &programme, &opts, off, true, &mut runs, &mut steps
        )?);
        assert_eq!(runs, 2);
        // Without the method check the tighter run alone decides, and disagrees too.
        let (mut runs, mut steps) = (1, 0);
        assert!(!both_checks(
            &model, &programme, &opts, off, false, &mut runs, &mut steps
        )?);
        assert_eq!(runs, 2);
        assert!(!agree((shown.0, None), shown));
        assert_eq!(other_stiff_method(Method::Auto), Method::Radau5);
        assert_eq!(other_stiff_method(Method::Radau5), Method::Rodas5P);
        Ok(())
    }
}
