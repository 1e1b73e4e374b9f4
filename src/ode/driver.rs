//! [`solve`](super::solve) and [`solve_observed`]: the [`Integrator`] run to the end, with the
//! output the options ask for (saved states, dense output, located events).

use super::dense::DenseOutput;
use super::error::OdeError;
use super::event::Event;
use super::integrator::{Integrator, StepStatus};
use super::options::{Method, Options, SaveAt};
use super::solution::{Solution, Stats};
use super::system::OdeSystem;
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OVector};

/// [`solve`](super::solve), calling `observe(t, y)` at the start and after every accepted step
/// (after an acting event's change, for a step it cut): results streamed without saving every
/// step (`SaveAt::Final`), as a per-step callback of DifferentialEquations.jl does.
///
/// ```
/// use hdi_tribology::ode::{solve_observed, FnSystem, Method, Options, SaveAt};
/// use nalgebra::Vector2;
///
/// // A harmonic oscillator: keep only the largest |x| seen and the number of steps.
/// let osc = FnSystem::new(|_t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>| {
///     dy[0] = y[1];
///     dy[1] = -y[0];
/// });
/// let (mut peak, mut calls) = (0.0f64, 0);
/// let opts = Options::default().rtol(1e-9).save(SaveAt::Final);
/// let sol = solve_observed(&osc, 0.0, Vector2::new(1.0, 0.0), 10.0, Method::Dop853, &opts, &mut [],
///     |_t, y| {
///         peak = peak.max(y[0].abs());
///         calls += 1;
///     })?;
/// assert_eq!(calls, sol.stats.accepted + 1);
/// assert_eq!(sol.t.len(), 1); // nothing saved but the end
/// assert!((peak - 1.0).abs() < 1e-6);
/// # Ok::<(), hdi_tribology::ode::OdeError>(())
/// ```
///
/// # Errors
/// As [`solve`](super::solve).
#[allow(clippy::too_many_arguments)]
pub fn solve_observed<D: Dim, S: OdeSystem<D> + ?Sized>(
    sys: &S,
    t0: f64,
    y0: OVector<f64, D>,
    tf: f64,
    method: Method,
    opts: &Options,
    events: &mut [Event<'_, D>],
    mut observe: impl FnMut(f64, &OVector<f64, D>),
) -> Result<Solution<D>, OdeError>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    opts.validate(y0.len())?;
    let save_times: &[f64] = match &opts.save {
        SaveAt::Times(ts) => {
            if let Some(bad) = ts.iter().find(|&&s| s < t0 || s > tf) {
                return Err(OdeError::invalid(
                    "options.save",
                    format!("time {bad} is outside [t0, tf] = [{t0}, {tf}]"),
                ));
            }
            ts
        }
        _ => &[],
    };
    let need_poly = opts.dense || !events.is_empty() || matches!(opts.save, SaveAt::Times(_));
    let n = y0.len();
    let mut sol = Solution {
        t: Vec::new(),
        y: Vec::new(),
        events: Vec::new(),
        stats: Stats::default(),
        terminated_by_event: None,
        method,
        t_end: t0,
        y_end: y0.clone(),
        dense: opts.dense.then(|| DenseOutput::new(n)),
    };
    let mut save_idx = 0;
    match &opts.save {
        SaveAt::Steps => {
            sol.t.push(t0);
            sol.y.push(y0.clone());
        }
        SaveAt::Times(_) => {
            while save_idx < save_times.len() && save_times[save_idx] <= t0 {
                sol.t.push(save_times[save_idx]);
                sol.y.push(y0.clone());
                save_idx += 1;
            }
        }
        SaveAt::Final => {}
    }

    let mut it = Integrator::new(sys, t0, y0, tf, method, opts)?;
    // Step interpolants for the events and the output times too, not only for dense output.
    it.ctx.need_poly = need_poly;
    it.init_events(events);
    observe(t0, it.state());
    let mut work = sol.y_end.clone();
    loop {
        it.hits.clear();
        let status = it.step_with(events)?;
        let cut = it.last_cut;
        let t = it.t();
        if let Some(d) = sol.dense.as_mut() {
            d.push(&it.poly);
            if cut {
                d.truncate_last(t);
            }
        }
        match &opts.save {
            SaveAt::Steps => {
                if let StepStatus::Acted(i) = status {
                    // The state before the action, then after it.
                    if let Some(hit) = it.hits.iter().rev().find(|e| e.index == i) {
                        sol.t.push(t);
                        sol.y.push(hit.y.clone());
                    }
                }
                sol.t.push(t);
                sol.y.push(it.state().clone());
            }
            SaveAt::Times(_) => {
                while save_idx < save_times.len() && save_times[save_idx] <= t {
                    let ts = save_times[save_idx];
                    if ts == t && !matches!(status, StepStatus::Acted(_)) {
                        work.copy_from(it.state());
                    } else {
                        it.poly.eval_into(ts, &mut work);
                    }
                    sol.t.push(ts);
                    sol.y.push(work.clone());
                    save_idx += 1;
                }
            }
            SaveAt::Final => {}
        }
        observe(t, it.state());
        sol.events.append(&mut it.hits);
        match status {
            StepStatus::Terminated(i) => {
                sol.terminated_by_event = Some(i);
                break;
            }
            StepStatus::ReachedEnd => break,
            StepStatus::Accepted | StepStatus::Acted(_) => {}
        }
    }
    let (t, y, stats) = it.finish();
    if matches!(opts.save, SaveAt::Final) {
        sol.t.push(t);
        sol.y.push(y.clone());
    }
    sol.t_end = t;
    sol.y_end = y;
    sol.stats = stats;
    Ok(sol)
}
