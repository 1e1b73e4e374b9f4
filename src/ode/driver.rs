//! The integration loop: step size control, stops, output, events and method switching.

use super::dense::{DenseOutput, StepPoly};
use super::error::OdeError;
use super::event::{crossing, locate, Event, EventHit};
use super::jacobian::{eval_jacobian, spectral_radius};
use super::options::{Options, SaveAt};
use super::solution::{Solution, Stats};
use super::stepper::{all_finite, Ctx, FailKind, Stepper, Trial};
use super::system::OdeSystem;
use super::tsit5::STABILITY_BOUNDARY;
use super::Method;
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OMatrix, OVector};

/// Controller constants: PI control `fac = SAFETY · err^(−α) · err_prev^β` with
/// `α = 0.7/k`, `β = 0.4/k` (Gustafsson/Söderlind), clamped to `[FAC_MIN, FAC_MAX]`.
const SAFETY: f64 = 0.9;
const FAC_MIN: f64 = 0.2;
const FAC_MAX_EXPLICIT: f64 = 10.0;
const FAC_MAX_STIFF: f64 = 6.0;

/// Consecutive failed attempts of one kind before giving up with a typed error.
const MAX_CONSECUTIVE_FAILURES: usize = 12;

/// Stiffness switching (`Auto`), in the spirit of LSODA. Every `CHECK_INTERVAL` explicit
/// steps (or when the explicit method's own indicator fires) the spectral radius ρ of the
/// Jacobian is estimated; an explicit step with `h·ρ` above `STIFF_FRACTION` of the stability
/// boundary is limited by stability, not accuracy. Two such checks in a row switch to the
/// stiff method; it switches back after `STEPS_TO_RETURN` steps with `h·ρ` below
/// `RETURN_FRACTION` of the boundary (accuracy would limit an explicit step more than
/// stability). The gap between the fractions prevents ping-pong.
const CHECK_INTERVAL: usize = 25;
const STIFF_FRACTION: f64 = 0.6;
const STIFF_CHECKS_TO_SWITCH: usize = 2;
const RETURN_FRACTION: f64 = 0.3;
const STEPS_TO_RETURN: usize = 5;

pub(crate) struct Problem<'s, 'e, 'ev, D: Dim, S: OdeSystem<D> + ?Sized>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    pub sys: &'s S,
    pub t0: f64,
    pub y0: OVector<f64, D>,
    pub tf: f64,
    pub method: Method,
    pub opts: &'s Options,
    pub events: &'e mut [Event<'ev, D>],
}

/// Runs the loop with `steppers[0]` first; a second stepper enables switching (`Auto`).
pub(crate) fn integrate<D: Dim, S: OdeSystem<D> + ?Sized>(
    p: Problem<'_, '_, '_, D, S>,
    steppers: &mut [&mut dyn Stepper<D, S>],
) -> Result<Solution<D>, OdeError>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let Problem {
        sys,
        t0,
        y0,
        tf,
        method,
        opts,
        events,
    } = p;
    let n = y0.len();
    let (rows, cols) = y0.shape_generic();
    let atol = OVector::from_fn_generic(rows, cols, |i, _| opts.atol.get(i));
    let mut ctx = Ctx {
        atol,
        rtol: opts.rtol,
        stats: Stats::default(),
        want_stiffness: steppers.len() > 1,
        need_poly: opts.dense || !events.is_empty() || matches!(opts.save, SaveAt::Times(_)),
    };

    // Kinks strictly inside (t0, tf), then tf itself.
    let mut stops: Vec<f64> = opts
        .t_stops
        .iter()
        .copied()
        .filter(|&s| s > t0 && s < tf)
        .collect();
    stops.sort_by(f64::total_cmp);
    stops.dedup();
    stops.push(tf);
    let mut stop_idx = 0;

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
    let mut save_idx = 0;

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

    let mut active = 0usize;
    let mut t = t0;
    let mut y = y0;
    let mut y_new = y.clone();
    let mut work = y.clone();
    let mut poly = StepPoly::new(n);

    steppers[active].restart(sys, t, &y, &mut ctx);
    if !all_finite(steppers[active].f0()) {
        return Err(OdeError::NonFinite {
            t,
            what: "right-hand side at the initial point".into(),
        });
    }

    let mut g_old: Vec<f64> = Vec::with_capacity(events.len());
    for ev in events.iter_mut() {
        g_old.push(ev.eval(t, &y));
    }
    ctx.stats.event_evals += events.len();

    let h_max = opts.h_max.min(tf - t0);
    let mut h = match opts.h_init {
        Some(h) => h,
        None => initial_step(
            sys,
            t,
            &y,
            steppers[active].f0(),
            steppers[active].error_order() - 1.0,
            h_max,
            &mut work,
            &mut ctx,
        ),
    }
    .min(h_max);

    let mut err_prev = 1.0f64;
    let mut last_rejected = false;
    let mut fails = (0usize, FailKind::NonFinite);
    // Non-finite trial steps seen recently (forgotten after a run of accepted steps): a step
    // size collapse after them is reported as what it is.
    let mut recent_nonfinite = 0usize;
    let mut accepted_run = 0usize;
    let mut stiff_count = 0usize;
    let mut since_check = 0usize;
    let mut return_count = 0usize;
    let mut jac_work = (steppers.len() > 1).then(|| OMatrix::zeros_generic(rows, rows));
    let mut hits: Vec<(usize, f64, bool)> = Vec::new();

    loop {
        let attempts = ctx.stats.accepted + ctx.stats.rejected;
        if attempts >= opts.max_steps {
            return Err(OdeError::TooManySteps {
                t,
                max_steps: opts.max_steps,
            });
        }
        // A step must change t in floating point by more than a few ulps.
        let floor = opts.h_min.max(16.0 * f64::EPSILON * t.abs()).max(1e-300);
        let stop = stops[stop_idx];
        let remaining = stop - t;
        let mut hit_stop = false;
        if h >= remaining || remaining - h < floor.max(1e-3 * h) {
            h = remaining;
            hit_stop = true;
        } else if h.is_nan() || h < floor {
            if recent_nonfinite > 0 {
                return Err(OdeError::NonFinite {
                    t,
                    what: format!(
                        "state or right-hand side: trial steps failed down to h = {h:e} (floor {floor:e})"
                    ),
                });
            }
            return Err(OdeError::StepTooSmall { t, h, h_min: floor });
        }
        let stepper = &mut *steppers[active];
        let k = stepper.error_order();
        let stiff = stepper.is_stiff();

        let trial = stepper.attempt(sys, t, &y, h, &mut y_new, &mut ctx);
        let h_acc = h;
        let err = match trial {
            Trial::Done { err } if err.is_finite() => err,
            Trial::Done { .. } => {
                recent_nonfinite += 1;
                accepted_run = 0;
                register_failure(&mut fails, FailKind::NonFinite, t, h)?;
                ctx.stats.rejected += 1;
                h *= 0.25;
                last_rejected = true;
                continue;
            }
            Trial::Failed { factor, kind } => {
                if kind == FailKind::NonFinite {
                    recent_nonfinite += 1;
                }
                accepted_run = 0;
                register_failure(&mut fails, kind, t, h)?;
                ctx.stats.rejected += 1;
                h *= factor;
                last_rejected = true;
                continue;
            }
        };
        if err > 1.0 && opts.adaptive {
            fails.0 = 0;
            ctx.stats.rejected += 1;
            let fac = (SAFETY * err.powf(-1.0 / k)).max(FAC_MIN);
            h *= fac;
            last_rejected = true;
            continue;
        }

        // Accepted.
        fails.0 = 0;
        accepted_run += 1;
        if accepted_run >= 50 {
            recent_nonfinite = 0;
        }
        ctx.stats.accepted += 1;
        if stiff {
            ctx.stats.stiff_steps += 1;
        }
        stepper.accept(sys, t, &y, h, &y_new, &mut poly, &mut ctx);
        let t_new = if hit_stop { stop } else { t + h };

        // Events: sign changes between the ends of the step, located on the interpolant.
        hits.clear();
        for (i, ev) in events.iter_mut().enumerate() {
            let g_new = ev.eval(t_new, &y_new);
            ctx.stats.event_evals += 1;
            if let Some(rising) = crossing(ev.get_direction(), g_old[i], g_new) {
                let (te, evals) = locate(
                    ev,
                    &poly,
                    t,
                    g_old[i],
                    t_new,
                    g_new,
                    opts.event_tol,
                    &mut work,
                );
                ctx.stats.event_evals += evals;
                hits.push((i, te, rising));
            }
            g_old[i] = g_new;
        }
        hits.sort_by(|a, b| a.1.total_cmp(&b.1));
        let mut t_cut = None;
        for &(i, te, rising) in &hits {
            if let Some(tc) = t_cut {
                if te > tc {
                    break;
                }
            }
            poly.eval_into(te, &mut work);
            sol.events.push(EventHit {
                index: i,
                t: te,
                y: work.clone(),
                rising,
            });
            if events[i].is_terminal() && t_cut.is_none() {
                t_cut = Some(te);
                sol.terminated_by_event = Some(i);
            }
        }

        if let Some(d) = sol.dense.as_mut() {
            d.push(&poly);
        }
        let t_reach = t_cut.unwrap_or(t_new);
        if let Some(tc) = t_cut {
            poly.eval_into(tc, &mut y_new);
            if let Some(d) = sol.dense.as_mut() {
                d.truncate_last(tc);
            }
        }
        match &opts.save {
            SaveAt::Steps => {
                sol.t.push(t_reach);
                sol.y.push(y_new.clone());
            }
            SaveAt::Times(_) => {
                while save_idx < save_times.len() && save_times[save_idx] <= t_reach {
                    let ts = save_times[save_idx];
                    if ts == t_reach {
                        work.copy_from(&y_new);
                    } else {
                        poly.eval_into(ts, &mut work);
                    }
                    sol.t.push(ts);
                    sol.y.push(work.clone());
                    save_idx += 1;
                }
            }
            SaveAt::Final => {}
        }
        t = t_reach;
        std::mem::swap(&mut y, &mut y_new);
        if t_cut.is_some() {
            break;
        }

        // Next step size.
        let (alpha, beta) = (0.7 / k, 0.4 / k);
        let e = err.max(1e-10);
        let mut fac = SAFETY * e.powf(-alpha) * err_prev.powf(beta);
        let fac_max = if stiff {
            FAC_MAX_STIFF
        } else {
            FAC_MAX_EXPLICIT
        };
        if last_rejected {
            fac = fac.min(1.0);
        }
        if let Some(hint) = stepper.step_hint() {
            fac = fac.min(hint);
        }
        if opts.adaptive {
            h = stepper
                .propose(h, h * fac.clamp(FAC_MIN, fac_max))
                .min(h_max);
        } else if let Some(h0) = opts.h_init {
            h = h0.min(h_max);
        }
        err_prev = e;
        last_rejected = false;

        if hit_stop {
            if stop_idx + 1 == stops.len() {
                break;
            }
            stop_idx += 1;
            // The right-hand side may have a kink here: no derivative carries over.
            stepper.restart(sys, t, &y, &mut ctx);
        }

        // Stiffness switching.
        if steppers.len() > 1 {
            let switch = if !stiff {
                since_check += 1;
                // The cheap indicator of the explicit method flags growing stiff components;
                // a periodic Jacobian check catches a step size pinned at the stability limit
                // while those components are still damped.
                let flagged = steppers[active]
                    .stiffness()
                    .is_some_and(|h_rho| h_rho > STABILITY_BOUNDARY);
                if flagged || since_check >= CHECK_INTERVAL {
                    since_check = 0;
                    let rho = estimate_radius(
                        sys,
                        t,
                        &y,
                        steppers[active].f0(),
                        &mut jac_work,
                        &mut work,
                        &mut ctx,
                    );
                    if h_acc * rho > STIFF_FRACTION * STABILITY_BOUNDARY {
                        stiff_count += 1;
                    } else {
                        stiff_count = 0;
                    }
                }
                stiff_count >= STIFF_CHECKS_TO_SWITCH
            } else {
                match steppers[active].stiffness() {
                    Some(rho) if h_acc * rho < RETURN_FRACTION * STABILITY_BOUNDARY => {
                        return_count += 1;
                    }
                    _ => return_count = 0,
                }
                return_count >= STEPS_TO_RETURN
            };
            if switch {
                active = (active + 1) % steppers.len();
                ctx.stats.stiffness_switches += 1;
                stiff_count = 0;
                since_check = 0;
                return_count = 0;
                err_prev = 1.0;
                steppers[active].restart(sys, t, &y, &mut ctx);
            }
        }
    }

    if matches!(opts.save, SaveAt::Final) {
        sol.t.push(t);
        sol.y.push(y.clone());
    }
    sol.t_end = t;
    sol.y_end = y;
    sol.stats = ctx.stats;
    Ok(sol)
}

fn register_failure(
    fails: &mut (usize, FailKind),
    kind: FailKind,
    t: f64,
    h: f64,
) -> Result<(), OdeError> {
    if fails.1 == kind {
        fails.0 += 1;
    } else {
        *fails = (1, kind);
    }
    if fails.0 < MAX_CONSECUTIVE_FAILURES {
        return Ok(());
    }
    Err(match kind {
        FailKind::NonFinite => OdeError::NonFinite {
            t,
            what: format!("state or right-hand side in every trial step down to h = {h:e}"),
        },
        FailKind::Newton => OdeError::NewtonDivergence {
            t,
            h,
            reason: format!("{MAX_CONSECUTIVE_FAILURES} consecutive failures while halving h"),
        },
        FailKind::Singular => OdeError::SingularMatrix { t, h },
    })
}

/// Initial step size after Hairer, Nørsett & Wanner (1993), II.4: a step whose explicit
/// Euler error estimate matches the tolerance for a method of order `p`.
#[allow(clippy::too_many_arguments)]
fn initial_step<D: Dim, S: OdeSystem<D> + ?Sized>(
    sys: &S,
    t: f64,
    y: &OVector<f64, D>,
    f0: &OVector<f64, D>,
    p: f64,
    h_max: f64,
    work: &mut OVector<f64, D>,
    ctx: &mut Ctx<D>,
) -> f64
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let d0 = ctx.norm_at(y, y);
    let d1 = ctx.norm_at(f0, y);
    let mut h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    };
    h0 = h0.min(h_max);
    let mut y1 = y.clone();
    y1.axpy(h0, f0, 1.0);
    sys.rhs(t + h0, &y1, work);
    ctx.stats.rhs_evals += 1;
    let mut diff = work.clone();
    diff -= f0;
    let d2 = ctx.norm_at(&diff, y) / h0;
    let h1 = if d1.max(d2) <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / d1.max(d2)).powf(1.0 / (p + 1.0))
    };
    let h = (100.0 * h0).min(h1).min(h_max);
    if h.is_finite() && h > 0.0 {
        h
    } else {
        h0
    }
}

/// Spectral radius of the Jacobian at `(t, y)` for the stiffness check (∞ when the Jacobian is
/// not finite, which sends the integration to the stiff method).
fn estimate_radius<D: Dim, S: OdeSystem<D> + ?Sized>(
    sys: &S,
    t: f64,
    y: &OVector<f64, D>,
    f0: &OVector<f64, D>,
    jac: &mut Option<OMatrix<f64, D, D>>,
    work: &mut OVector<f64, D>,
    ctx: &mut Ctx<D>,
) -> f64
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let Some(jac) = jac.as_mut() else {
        return 0.0;
    };
    if eval_jacobian(sys, t, y, f0, jac, work, ctx) {
        spectral_radius(jac, y)
    } else {
        f64::INFINITY
    }
}
