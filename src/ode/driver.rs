//! [`solve`](super::solve): the [`Integrator`] run to the end, with the output the options
//! ask for (saved states, dense output, located events).

use super::dense::DenseOutput;
use super::error::OdeError;
use super::event::Event;
use super::integrator::{Integrator, StepStatus};
use super::options::{Method, Options, SaveAt};
use super::solution::{Solution, Stats};
use super::system::OdeSystem;
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OVector};

/// Integrates from `t0` to `tf` (or a terminal event) and collects the output; `observe` sees
/// the start and every accepted step.
#[allow(clippy::too_many_arguments)]
pub(crate) fn run<D: Dim, S: OdeSystem<D> + ?Sized>(
    sys: &S,
    t0: f64,
    y0: OVector<f64, D>,
    tf: f64,
    method: Method,
    opts: &Options,
    events: &mut [Event<'_, D>],
    observe: &mut dyn FnMut(f64, &OVector<f64, D>),
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
        let cut = matches!(status, StepStatus::Acted(_) | StepStatus::Terminated(_));
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
