//! The integration loop as an object: one accepted step per call, step size control, stops,
//! events (recorded, terminal or acting) and method switching. [`solve`](super::solve) is a
//! thin loop over it.

use super::ark436::Ark436;
use super::dense::StepPoly;
use super::dop853::Dop853;
use super::error::OdeError;
use super::event::{crossing, locate, Event, EventHit};
use super::floor_step::FloorStep;
use super::jacobian::{eval_jacobian, spectral_radius};
use super::options::{Method, Options};
use super::radau5::Radau5;
use super::rodas5p::Rodas5P;
use super::solution::Stats;
use super::stepper::{all_finite, Ctx, FailKind, Step, Stepper, Trial};
use super::system::{OdeSystem, TimeMemo};
use super::tsit5::Tsit5;
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
/// boundary `b` may be limited by stability. Two such checks in a row switch to the stiff
/// method.
///
/// A stiff step pays for itself when it is more than `COST_RATIO` times as long as the
/// explicit step before the switch. While it does, the stiff method switches back after
/// `STEPS_TO_RETURN` steps in a row with `h·ρ` below `RETURN_FRACTION` of the boundary (the
/// stiffness has gone). While it does not, the explicit method would cost less as soon as
/// its step could be as long: `h·ρ` below `COST_RETURN_FRACTION` of the boundary, the same
/// number of steps in a row, after a trial of at least `TRIAL_STEPS` steps. A stiff run most
/// of whose steps did not pay gained nothing (the step was held by accuracy, not stability:
/// a forcing such as an AC voltage, resolved by both methods alike); the next `backoff`
/// periodic stiffness checks are then skipped (the explicit method's indicator is not heard
/// meanwhile), a number that doubles with each such run in a row up to `MAX_BACKOFF` and is
/// cleared by a run that gained. Without the backoff the two tests would hand over back and
/// forth, since an explicit step held by accuracy there has `h·ρ` above `STIFF_FRACTION·b`
/// too. Only `Auto`'s pair of Tsit5 and Rodas5P weighs the cost (`Steppers::weighs_cost`).
/// That pair also goes stiff at once at a switch into a branch whose declared rate would hold
/// the explicit step far below the coming one, and hands back at a switch that ends the
/// stiffness it switched for ([`Integrator::enter_stiff_branch`],
/// [`Integrator::leave_stiff_branch`]); where the system declares the branch's stiff rows, it
/// takes its third method for the branch, the additive pair (`IMEX`).
const CHECK_INTERVAL: usize = 25;
/// The index of `Auto`'s third method, the additive pair it steps a branch with when the system
/// declares the branch's stiff diagonal ([`OdeSystem::stiff_diagonal`]).
const IMEX: usize = 2;
const STIFF_FRACTION: f64 = 0.6;
const STIFF_CHECKS_TO_SWITCH: usize = 2;
/// Cost of a stiff step over an explicit one: Rodas5P's step (six stages, a Jacobian and a
/// factorisation) against Tsit5's six stages on the paper cycle, 1.40 µs against 0.75 µs
/// (docs/benchmarks.md, "Auto weighs the cost").
const COST_RATIO: f64 = 2.0;
const RETURN_FRACTION: f64 = 0.3;
/// `STIFF_FRACTION·COST_RATIO` with a margin of 1.5: the explicit step would be as long as the
/// stiff one.
const COST_RETURN_FRACTION: f64 = 0.8;
const STEPS_TO_RETURN: usize = 5;
/// Fewest steps of a stiff run before it may hand back for its cost (see above).
const TRIAL_STEPS: usize = 25;
/// Most stiffness checks skipped after stiff runs that gained nothing (see above).
const MAX_BACKOFF: usize = 64;

/// An accepted trial step: its size, error norm, the method's error order, whether the
/// method is stiff and whether the step ends on the stop time.
struct Accepted {
    h: f64,
    err: f64,
    order: f64,
    stiff: bool,
    hit_stop: bool,
    /// Taken by the step floor's backward Euler step (`floor_step`), not the method.
    by_floor: bool,
}

/// What one call of [`Integrator::step`] (or [`Integrator::advance_to`]) ended with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepStatus {
    /// An ordinary accepted step (or, for `advance_to`, the time asked for was reached).
    Accepted,
    /// The step ended exactly on the end time `tf`; extend it with [`Integrator::set_tf`] to
    /// go on.
    ReachedEnd,
    /// An acting event (index given) cut the step at its root and changed the state; the
    /// integration goes on from there.
    Acted(usize),
    /// A terminal event (index given) cut the step at its root. Stepping again goes on from
    /// there.
    Terminated(usize),
}

/// What cut a step short.
#[derive(Clone, Copy, Debug)]
enum Cut {
    /// An event that acts or stops.
    Event(usize),
    /// A switch of the system's branch.
    Switch(usize),
}

/// The methods of one integration; `Auto` holds an explicit and a stiff one.
enum Steppers<D: Dim>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    Tsit5(Tsit5<D>),
    Dop853(Box<Dop853<D>>),
    Rodas5P(Box<Rodas5P<D>>),
    Radau5(Box<Radau5<D>>),
    /// Tsit5, Rodas5P, and the additive pair for branches with a declared stiff diagonal
    /// ([`OdeSystem::stiff_diagonal`]; `IMEX`).
    Auto(Tsit5<D>, Box<Rodas5P<D>>, Box<Ark436<D>>),
    AutoRadau(Tsit5<D>, Box<Radau5<D>>),
    AutoDop853(Box<Dop853<D>>, Box<Radau5<D>>),
}

/// `Auto` takes Radau5 as its stiff method below this relative tolerance, Rodas5P from it on.
/// Measured (docs/benchmarks.md, "Which method when"): at equal error Radau5 is as fast as
/// Rodas5P or faster on every stiff test problem from about 1e-7 on (up to 2× on Robertson and
/// OREGO), and it alone is right on E5; at rtol ≥ 1e-6 Rodas5P is up to 1.5× faster on Van der
/// Pol, HIRES and the slider without AC.
pub(crate) const AUTO_RADAU_BELOW_RTOL: f64 = 1e-6;

/// `Auto` takes DOP853 as its explicit method below this relative tolerance, Tsit5 from it on.
/// Measured (docs/benchmarks.md, "Auto's explicit method"): at rtol 1e-9 the 8th-order method
/// needs 2.6–3× fewer steps than Tsit5 on the slider cycle and on Pleiades for an error as
/// small or smaller; at rtol ≥ 1e-8 Tsit5's cheaper steps win on the slider without AC.
pub(crate) const AUTO_DOP853_BELOW_RTOL: f64 = 1e-8;

/// Auto's choice where the problem is known to be stiff from the start (here, beside the
/// thresholds Auto itself uses).
impl Method {
    /// The method for a problem whose fastest rate is `fastest_rate` (1/s) over `span` (s), at
    /// relative tolerance `rtol`: as asked, except that `Auto` on a problem that no explicit step
    /// could follow in fewer than `explicit_step_limit` steps is its stiff method from the start
    /// (Radau5 or Rodas5P by the tolerance, as `Auto` itself would switch to): the explicit
    /// phase would only spend steps finding out.
    ///
    /// ```
    /// use hdi_tribology::ode::Method;
    /// assert_eq!(Method::Auto.for_problem(1e-8, 1e9, 1e-3, 1e5), Method::Radau5);
    /// assert_eq!(Method::Auto.for_problem(1e-4, 1e9, 1e-3, 1e5), Method::Rodas5P);
    /// assert_eq!(Method::Auto.for_problem(1e-8, 1e3, 1e-3, 1e5), Method::Auto);
    /// assert_eq!(Method::Tsit5.for_problem(1e-8, 1e9, 1e-3, 1e5), Method::Tsit5);
    /// ```
    pub fn for_problem(
        self,
        rtol: f64,
        fastest_rate: f64,
        span: f64,
        explicit_step_limit: f64,
    ) -> Method {
        let explicit_steps = span * fastest_rate / super::tsit5::STABILITY_BOUNDARY;
        match self {
            Method::Auto if explicit_steps > explicit_step_limit => {
                if rtol < AUTO_RADAU_BELOW_RTOL {
                    Method::Radau5
                } else {
                    Method::Rodas5P
                }
            }
            m => m,
        }
    }
}

impl<D: Dim> Steppers<D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn new(method: Method, y0: &OVector<f64, D>, rtol: f64) -> Self {
        match method {
            Method::Tsit5 => Steppers::Tsit5(Tsit5::new(y0)),
            Method::Dop853 => Steppers::Dop853(Box::new(Dop853::new(y0))),
            Method::Rodas5P => Steppers::Rodas5P(Box::new(Rodas5P::new(y0))),
            Method::Radau5 => Steppers::Radau5(Box::new(Radau5::new(y0, rtol))),
            Method::Auto if rtol < AUTO_DOP853_BELOW_RTOL => {
                Steppers::AutoDop853(Box::new(Dop853::new(y0)), Box::new(Radau5::new(y0, rtol)))
            }
            Method::Auto if rtol < AUTO_RADAU_BELOW_RTOL => {
                Steppers::AutoRadau(Tsit5::new(y0), Box::new(Radau5::new(y0, rtol)))
            }
            Method::Auto => Steppers::Auto(
                Tsit5::new(y0),
                Box::new(Rodas5P::new(y0)),
                Box::new(Ark436::new(y0)),
            ),
        }
    }

    /// Whether `Auto` weighs the cost of its stiff steps: for the pair whose costs were measured
    /// (Tsit5 and Rodas5P, see `COST_RATIO`); with Radau5 or DOP853 it weighs stability alone.
    fn weighs_cost(&self) -> bool {
        matches!(self, Steppers::Auto(..))
    }

    fn count(&self) -> usize {
        match self {
            Steppers::Auto(..) | Steppers::AutoRadau(..) | Steppers::AutoDop853(..) => 2,
            _ => 1,
        }
    }

    fn get<S: OdeSystem<D> + ?Sized>(&mut self, active: usize) -> &mut dyn Stepper<D, S> {
        match self {
            Steppers::Tsit5(m) => m,
            Steppers::Dop853(m) => m.as_mut(),
            Steppers::Rodas5P(m) => m.as_mut(),
            Steppers::Radau5(m) => m.as_mut(),
            Steppers::Auto(e, s, a) => match active {
                0 => e,
                IMEX => a.as_mut(),
                _ => s.as_mut(),
            },
            Steppers::AutoRadau(e, s) => {
                if active == 0 {
                    e
                } else {
                    s.as_mut()
                }
            }
            Steppers::AutoDop853(e, s) => {
                if active == 0 {
                    e.as_mut()
                } else {
                    s.as_mut()
                }
            }
        }
    }

    fn set_rtol(&mut self, rtol: f64) {
        match self {
            Steppers::Radau5(m) | Steppers::AutoRadau(_, m) | Steppers::AutoDop853(_, m) => {
                m.set_rtol(rtol)
            }
            _ => {}
        }
    }
}

/// An integration you can step: `y' = f(t, y)` from `(t0, y0)` towards `tf`, one accepted
/// step at a time.
///
/// [`step`](Integrator::step) takes one accepted step; [`advance_to`](Integrator::advance_to)
/// steps until it lands exactly on a time; [`interpolate`](Integrator::interpolate) evaluates
/// the dense output inside the last step; [`reinit`](Integrator::reinit) restarts from a new
/// state after a discontinuity; [`set_tf`](Integrator::set_tf) and
/// [`set_tolerances`](Integrator::set_tolerances) change the run between steps. Events added
/// with [`events`](Integrator::events) are located on each step; an
/// [acting](Event::affect) event changes the state and the integration goes on. Looping over
/// `step` is also the way to observe every step without saving them all.
///
/// [`solve`](super::solve) is this loop run to the end: stepping by hand gives the same steps,
/// bit for bit.
///
/// ```
/// use hdi_tribology::ode::{FnSystem, Integrator, Method, Options, StepStatus};
/// use nalgebra::Vector2;
///
/// // The harmonic oscillator y'' = −y, stepped to t = 10, observed at every step.
/// let osc = FnSystem::new(|_t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>| {
///     dy[0] = y[1];
///     dy[1] = -y[0];
/// });
/// let opts = Options::default().rtol(1e-10).atol(1e-12);
/// let mut it = Integrator::new(&osc, 0.0, Vector2::new(1.0, 0.0), 10.0, Method::Dop853, &opts)?;
/// let mut energy_drift = 0.0f64;
/// while it.step()? != StepStatus::ReachedEnd {
///     let y = it.state();
///     energy_drift = energy_drift.max((y[0] * y[0] + y[1] * y[1] - 1.0).abs());
///     // Inside the last step the dense output is available.
///     let mid = 0.5 * (it.t_prev() + it.t());
///     assert!((it.interpolate(mid)?[0] - mid.cos()).abs() < 1e-7);
/// }
/// assert_eq!(it.t(), 10.0);
/// assert!((it.state()[0] - 10f64.cos()).abs() < 1e-8 && energy_drift < 1e-8);
/// // Go on: a later end time, and land exactly on t = 12.5.
/// it.set_tf(20.0)?;
/// it.advance_to(12.5)?;
/// assert_eq!(it.t(), 12.5);
/// assert!((it.state()[0] - 12.5f64.cos()).abs() < 1e-8);
/// println!("{} steps", it.stats().accepted);
/// # Ok::<(), hdi_tribology::ode::OdeError>(())
/// ```
pub struct Integrator<'a, D: Dim, S: OdeSystem<D>>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    sys: S,
    method: Method,
    steppers: Steppers<D>,
    active: usize,
    pub(crate) ctx: Ctx<D>,
    events: Vec<Event<'a, D>>,
    g_old: Vec<f64>,
    /// The system's switching functions at the current point ([`OdeSystem::switches`]).
    sw_old: Vec<f64>,
    /// The last step ended on a cut (an acting or terminal event, or a switch of branch)
    /// short of its interpolant's end.
    pub(crate) last_cut: bool,
    /// Events located since the last public `step`/`advance_to` began.
    pub(crate) hits: Vec<EventHit<D>>,
    step_hits: Vec<(usize, f64, bool)>,
    t: f64,
    y: OVector<f64, D>,
    y_new: OVector<f64, D>,
    work: OVector<f64, D>,
    /// The stiff rows the system declared last ([`OdeSystem::stiff_diagonal`]).
    lambda: OVector<f64, D>,
    /// The accepted steps when the additive pair last took over a branch.
    imex_entered_at: usize,
    /// The pair's last branch ended at its first step: the next entry goes to the stiff method.
    imex_refuse_next: bool,
    /// Interpolant of the last accepted step (valid on `[poly.t0, t]` when `have_poly`).
    pub(crate) poly: StepPoly,
    have_poly: bool,
    t_span0: f64,
    tf: f64,
    /// Kinks of the right-hand side (sorted, deduplicated); steps end on them and restart.
    kinks: Vec<f64>,
    kink_idx: usize,
    /// A time the current `advance_to` must land on (no restart there).
    target: Option<f64>,
    h_init: Option<f64>,
    h_max_opt: f64,
    h_min: f64,
    max_steps: usize,
    event_tol: f64,
    adaptive: bool,
    h: f64,
    h_needs_init: bool,
    needs_restart: bool,
    /// The system was changed through `system_mut`: the events' values at the current point
    /// are evaluated again before the next step.
    events_stale: bool,
    err_prev: f64,
    /// Error estimate of the last accepted step (NaN before the first).
    err_last: f64,
    /// Shortest step the error control may ask for (`set_step_floor`); 0: none.
    h_floor: f64,
    last_rejected: bool,
    fails: (usize, FailKind),
    /// Non-finite trial steps seen recently (forgotten after a run of accepted steps): a step
    /// size collapse after them is reported as what it is.
    recent_nonfinite: usize,
    accepted_run: usize,
    stiff_count: usize,
    since_check: usize,
    return_count: usize,
    /// Steps of the current stiff run, and those of them that paid for themselves (see
    /// `COST_RATIO`).
    stiff_run: (usize, usize),
    /// The explicit step before the switch to the stiff method.
    h_explicit: f64,
    /// Stiffness checks to skip, and the number the next run that gains nothing sets.
    skip_checks: usize,
    backoff: usize,
    /// Per switch of the system: the first step accepted after the last entry into a branch
    /// that sent `Auto` to the stiff method at once (NaN before one), where the next such
    /// entry's first step starts ([`Integrator::enter_stiff_branch`]).
    entry_steps: Vec<f64>,
    /// The switch whose entry waits for its first accepted step.
    entry_pending: Option<usize>,
    jac_work: Option<OMatrix<f64, D, D>>,
    /// The step floor's own step, for trials the method fails at the floor
    /// ([`set_step_floor`](Integrator::set_step_floor)).
    floor_step: Option<Box<FloorStep<D>>>,
    /// Trials failed at the floor that may still be tried again shorter
    /// ([`set_floor_retries`](Integrator::set_floor_retries)); `None`: every one.
    floor_retries: Option<usize>,
}

impl<'a, D: Dim, S: OdeSystem<D>> Integrator<'a, D, S>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// Starts an integration of `sys` from `(t0, y0)` towards `tf > t0` with `method`.
    ///
    /// The interpolant of each step is built when `opts.dense` is on (the default) or events
    /// are added; `opts.save` is ignored (the caller sees every step).
    ///
    /// # Errors
    /// [`OdeError::InvalidInput`] for bad arguments or options; [`OdeError::NonFinite`] when
    /// `f(t0, y0)` is not finite.
    pub fn new(
        sys: S,
        t0: f64,
        y0: OVector<f64, D>,
        tf: f64,
        method: Method,
        opts: &Options,
    ) -> Result<Self, OdeError> {
        opts.validate(y0.len())?;
        if y0.is_empty() {
            return Err(OdeError::invalid(
                "y0",
                "the state must have at least one component",
            ));
        }
        if !t0.is_finite() || !tf.is_finite() {
            return Err(OdeError::invalid(
                "t0, tf",
                format!("must be finite, got t0 = {t0}, tf = {tf}"),
            ));
        }
        if tf <= t0 {
            return Err(OdeError::invalid(
                "tf",
                format!(
                    "must be greater than t0 (forward integration only), got t0 = {t0}, tf = {tf}"
                ),
            ));
        }
        check_finite_state(&y0)?;
        let n = y0.len();
        let (rows, cols) = y0.shape_generic();
        let atol = OVector::from_fn_generic(rows, cols, |i, _| opts.atol.get(i));
        let steppers = Steppers::new(method, &y0, opts.rtol);
        let switching = steppers.count() > 1;
        let ctx = Ctx {
            atol,
            rtol: opts.rtol,
            stats: Stats::default(),
            want_stiffness: switching,
            // Switches of branch are located on the interpolant.
            need_poly: opts.dense || sys.switches() > 0,
            memo: TimeMemo::default(),
            stage_memos: [TimeMemo::default(); 3],
        };
        let mut kinks: Vec<f64> = opts.t_stops.clone();
        kinks.sort_by(f64::total_cmp);
        kinks.dedup();
        let mut it = Integrator {
            sys,
            method,
            steppers,
            active: 0,
            ctx,
            events: Vec::new(),
            g_old: Vec::new(),
            sw_old: Vec::new(),
            last_cut: false,
            hits: Vec::new(),
            step_hits: Vec::new(),
            t: t0,
            y_new: y0.clone(),
            work: y0.clone(),
            lambda: y0.clone(),
            imex_entered_at: 0,
            imex_refuse_next: false,
            y: y0,
            poly: StepPoly::new(n),
            have_poly: false,
            t_span0: t0,
            tf,
            kinks,
            kink_idx: 0,
            target: None,
            h_init: opts.h_init,
            h_max_opt: opts.h_max,
            h_min: opts.h_min,
            max_steps: opts.max_steps,
            event_tol: opts.event_tol,
            adaptive: opts.adaptive,
            h: f64::NAN,
            h_needs_init: true,
            needs_restart: true,
            events_stale: false,
            err_prev: 1.0,
            err_last: f64::NAN,
            h_floor: 0.0,
            last_rejected: false,
            fails: (0, FailKind::NonFinite),
            recent_nonfinite: 0,
            accepted_run: 0,
            stiff_count: 0,
            since_check: 0,
            return_count: 0,
            stiff_run: (0, 0),
            h_explicit: 0.0,
            skip_checks: 0,
            backoff: 0,
            entry_steps: Vec::new(),
            entry_pending: None,
            jac_work: switching.then(|| OMatrix::zeros_generic(rows, rows)),
            floor_step: None,
            floor_retries: None,
        };
        it.init_switches();
        it.restart()?;
        Ok(it)
    }

    /// Adds events, located on every step from now on (see [`Event`]); their indices in
    /// [`EventHit`] and [`StepStatus`] count from the first event added.
    pub fn events(mut self, events: impl IntoIterator<Item = Event<'a, D>>) -> Self {
        for mut ev in events {
            self.g_old.push(ev.eval(self.t, &self.y));
            self.ctx.stats.event_evals += 1;
            self.events.push(ev);
        }
        self.ctx.need_poly = true;
        self
    }

    /// Evaluates every event at the current point (after a start, a reset or an action).
    pub(crate) fn init_events(&mut self, events: &mut [Event<'_, D>]) {
        self.g_old.clear();
        for ev in events.iter_mut() {
            self.g_old.push(ev.eval(self.t, &self.y));
        }
        self.ctx.stats.event_evals += events.len();
        self.init_switches();
    }

    /// Evaluates the system's switching functions at the current point, first changing the
    /// branch of any that is negative there (a start, or a system changed through
    /// `system_mut`, on the wrong branch); the method restarts after such a change.
    fn init_switches(&mut self) {
        self.sw_old.clear();
        for i in 0..self.sys.switches() {
            let mut g = self.sys.switching(i, self.t, &self.y);
            if g < 0.0 {
                self.sys.switch(i, self.t, &mut self.y);
                self.ctx.stats.branch_switches += 1;
                self.needs_restart = true;
                g = self.sys.switching(i, self.t, &self.y);
            }
            self.sw_old.push(g);
        }
    }

    /// Restarts the method at the current point (evaluates `f`), and picks an initial step
    /// size when none is pending.
    fn restart(&mut self) -> Result<(), OdeError> {
        // The system may have changed (`system_mut`, an event's action): no kept value of its
        // inputs carries over.
        self.ctx.clear_memos();
        let stepper = self.steppers.get::<S>(self.active);
        stepper.restart(&self.sys, self.t, &self.y, &mut self.ctx);
        if !all_finite(stepper.f0()) {
            return Err(OdeError::NonFinite {
                t: self.t,
                what: if self.ctx.stats.accepted == 0 {
                    "right-hand side at the initial point".into()
                } else {
                    format!("right-hand side at the restart point t = {}", self.t)
                },
            });
        }
        self.needs_restart = false;
        if self.h_needs_init {
            let h_max = self.h_max_opt.min(self.tf - self.t_span0);
            let order = stepper.error_order() - 1.0;
            self.h = match self.h_init {
                Some(h) => h,
                None => initial_step(
                    &self.sys,
                    self.t,
                    &self.y,
                    self.steppers.get::<S>(self.active).f0(),
                    order,
                    h_max,
                    &mut self.work,
                    &mut self.ctx,
                ),
            }
            .max(self.h_floor)
            .min(h_max);
            self.h_needs_init = false;
            // The estimate sees accuracy only: a declared rate bounds an explicit first step.
            if self.h_init.is_none() {
                self.within_branch_rates();
            }
        }
        Ok(())
    }

    /// Current time.
    pub fn t(&self) -> f64 {
        self.t
    }

    /// Start of the last accepted step (equal to [`t`](Integrator::t) before the first step
    /// and after [`reinit`](Integrator::reinit)).
    pub fn t_prev(&self) -> f64 {
        if self.have_poly {
            self.poly.t0
        } else {
            self.t
        }
    }

    /// Current state.
    pub fn state(&self) -> &OVector<f64, D> {
        &self.y
    }

    /// The system being integrated.
    pub fn system(&self) -> &S {
        &self.sys
    }

    /// The system, to change its parameters between steps (a new input held over the next
    /// interval, a switched model). The method restarts at the current point before the next
    /// step: `f` and the events are evaluated again there, and the step size is kept (use
    /// [`reinit`](Integrator::reinit) when the state jumps too). The last step's interpolant
    /// stays as it was computed.
    ///
    /// ```
    /// use hdi_tribology::nalgebra::Vector1;
    /// use hdi_tribology::ode::{Integrator, Method, OdeSystem, Options};
    /// use hdi_tribology::nalgebra::U1;
    /// /// y' = u, with the input u held by the system.
    /// struct Held { u: f64 }
    /// impl OdeSystem<U1> for Held {
    ///     fn rhs(&self, _t: f64, _y: &Vector1<f64>, dy: &mut Vector1<f64>) { dy[0] = self.u; }
    ///     fn is_autonomous(&self) -> bool { true }
    /// }
    /// let opts = Options::default().rtol(1e-10).atol(1e-12);
    /// // The integrator owns the system.
    /// let mut it = Integrator::new(Held { u: 1.0 }, 0.0, Vector1::new(0.0), 2.0, Method::Tsit5, &opts)?;
    /// it.advance_to(1.0)?;
    /// it.system_mut().u = -3.0;
    /// it.advance_to(2.0)?;
    /// assert!((it.state()[0] - (1.0 - 3.0)).abs() < 1e-12);
    /// # Ok::<(), hdi_tribology::ode::OdeError>(())
    /// ```
    pub fn system_mut(&mut self) -> &mut S {
        self.needs_restart = true;
        self.events_stale = true;
        &mut self.sys
    }

    /// End time.
    pub fn tf(&self) -> f64 {
        self.tf
    }

    /// Method asked for.
    pub fn method(&self) -> Method {
        self.method
    }

    /// Step size the next attempt will try.
    pub fn next_step_size(&self) -> f64 {
        self.h
    }

    /// Whether the stiff method of `Auto` is active (always `true` for Rodas5P and Radau5,
    /// `false` for the explicit methods).
    pub fn is_stiff(&self) -> bool {
        match &self.steppers {
            Steppers::Tsit5(_) | Steppers::Dop853(_) => false,
            Steppers::Rodas5P(_) | Steppers::Radau5(_) => true,
            Steppers::Auto(..) | Steppers::AutoRadau(..) | Steppers::AutoDop853(..) => {
                self.active == 1
            }
        }
    }

    /// The weighted RMS error estimate of the last accepted step, against the tolerances in
    /// force when it was taken: at most 1 under adaptive control, any size with fixed steps
    /// ([`set_step_floor`](Integrator::set_step_floor)); NaN before the first step.
    pub fn last_error(&self) -> f64 {
        self.err_last
    }

    /// Bounds the cost of a span from the next step on: the error control never asks for a
    /// step shorter than `floor`, and a step it would shorten below it is taken at `floor` and
    /// accepted whatever its error estimate ([`last_error`](Integrator::last_error) tells how
    /// far it was from the tolerances). A span of length `L` then takes at most `L / floor`
    /// steps, plus the rejected trials on the way down to the floor (at most
    /// `log(h / floor) / log 5` for a step that began at `h`), and a span the error control
    /// can cross in longer steps still does. Steps may still be shortened below the floor to
    /// land on the end time, a kink or an event, and a step whose state or right-hand side is
    /// not finite, or whose Newton iteration fails, is tried again shorter, unless
    /// [`set_floor_retries`](Integrator::set_floor_retries) bounds those retries. `None`
    /// removes the floor.
    ///
    /// ```
    /// use hdi_tribology::nalgebra::{Vector1, U1};
    /// use hdi_tribology::ode::{Integrator, Method, OdeSystem, Options};
    /// /// y' = -y.
    /// struct Decay;
    /// impl OdeSystem<U1> for Decay {
    ///     fn rhs(&self, _t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>) {
    ///         dy[0] = -y[0];
    ///     }
    /// }
    /// let opts = Options::default().rtol(1e-12).atol(1e-14);
    /// let mut it = Integrator::new(Decay, 0.0, Vector1::new(1.0), 1.0, Method::Rodas5P, &opts)?;
    /// it.set_step_floor(Some(0.25))?;
    /// it.advance_to(1.0)?;
    /// // At most four steps, each over this tight tolerance, none of them repeated shorter.
    /// assert!(it.stats().accepted <= 4);
    /// assert!(it.last_error() > 1.0);
    /// assert!((it.state()[0] - (-1.0f64).exp()).abs() < 1e-4);
    /// # Ok::<(), hdi_tribology::ode::OdeError>(())
    /// ```
    ///
    /// # Errors
    /// [`OdeError::InvalidInput`] naming `floor` when it is not positive and finite.
    pub fn set_step_floor(&mut self, floor: Option<f64>) -> Result<(), OdeError> {
        self.h_floor = match floor {
            Some(f) if f.is_finite() && f > 0.0 => f,
            Some(f) => {
                return Err(OdeError::invalid(
                    "floor",
                    format!("a step floor must be positive and finite, got {f}"),
                ))
            }
            None => 0.0,
        };
        // The next step too.
        if self.h < self.h_floor {
            self.h = self.h_floor;
        }
        Ok(())
    }

    /// Bounds the retries below the step floor ([`set_step_floor`](Integrator::set_step_floor))
    /// from now on: at most `retries` trials that failed at the floor for another reason than
    /// their error (a Newton iteration that diverged, a state or right-hand side that is not
    /// finite) are tried again shorter. After those, such a trial is taken at its length by the
    /// floor's own step and accepted whatever its estimate: backward Euler over the step and
    /// over its two halves, extrapolated (second order, L-stable), each solved by at most eight
    /// Newton iterations with a fresh Jacobian, its estimate that of the halves against the
    /// whole ([`Stats::floor_steps`] counts them). Where that iteration fails too, the trial is
    /// tried again shorter. Each call sets the count afresh; `None` (the default) retries
    /// every such trial shorter, as without the bound.
    ///
    /// ```
    /// use hdi_tribology::nalgebra::{Vector1, U1};
    /// use hdi_tribology::ode::{Integrator, Method, OdeSystem, Options};
    /// /// y' = -k y³: over a step much longer than 1/k, Radau5's simplified Newton iteration
    /// /// (its Jacobian frozen at the step's start) fails.
    /// struct Cubic;
    /// impl OdeSystem<U1> for Cubic {
    ///     fn rhs(&self, _t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>) {
    ///         dy[0] = -100.0 * y[0].powi(3);
    ///     }
    /// }
    /// let opts = Options::default().rtol(1e-8).atol(1e-12);
    /// let mut it = Integrator::new(Cubic, 0.0, Vector1::new(1.0), 1.0, Method::Radau5, &opts)?;
    /// it.set_step_floor(Some(0.125))?;
    /// it.set_floor_retries(Some(0));
    /// it.advance_to(1.0)?;
    /// // Eight steps of an eighth, those Radau5 failed taken by the floor's step.
    /// assert_eq!(it.stats().accepted, 8);
    /// assert!(it.stats().floor_steps > 0);
    /// assert!((it.state()[0] * 201f64.sqrt() - 1.0).abs() < 0.03);
    /// # Ok::<(), hdi_tribology::ode::OdeError>(())
    /// ```
    pub fn set_floor_retries(&mut self, retries: Option<usize>) {
        self.floor_retries = retries;
    }

    /// Work counters so far (all steps since [`new`](Integrator::new), across reinits).
    pub fn stats(&self) -> Stats {
        self.ctx.stats
    }

    /// Events located in the last call of [`step`](Integrator::step) or
    /// [`advance_to`](Integrator::advance_to), in time order.
    pub fn events_hit(&self) -> &[EventHit<D>] {
        &self.hits
    }

    /// The interpolant of the last accepted step (its coefficients are kept only with dense
    /// output or events; meaningless before the first step).
    pub fn last_step(&self) -> super::StepPolynomial<'_> {
        self.poly.view()
    }

    /// The state at `t` on the interpolant of the last accepted step, `t` in
    /// `[t_prev(), t()]`.
    ///
    /// # Errors
    /// [`OdeError::InvalidInput`] when no step was taken since the start (or the last reinit),
    /// when `t` is outside the last step, or when interpolants are off (`opts.dense = false`
    /// and no events).
    pub fn interpolate(&self, t: f64) -> Result<OVector<f64, D>, OdeError> {
        if !self.ctx.need_poly {
            return Err(OdeError::invalid(
                "options.dense",
                "interpolation needs dense = true (or an event)",
            ));
        }
        if !self.have_poly {
            return Err(OdeError::invalid(
                "t",
                "no step has been taken since the start or the last reinit",
            ));
        }
        let (a, b) = (self.poly.t0, self.t);
        if !(t >= a && t <= b) {
            return Err(OdeError::invalid(
                "t",
                format!("{t} is outside the last step [{a}, {b}]"),
            ));
        }
        let mut out = self.y.clone();
        if t == b {
            return Ok(out);
        }
        self.poly.eval_into(t, &mut out);
        Ok(out)
    }

    /// Sets a new end time `tf > t()` (shorter or longer).
    ///
    /// # Errors
    /// [`OdeError::InvalidInput`] when `tf` is not finite or not after the current time.
    pub fn set_tf(&mut self, tf: f64) -> Result<(), OdeError> {
        if !(tf.is_finite() && tf > self.t) {
            return Err(OdeError::invalid(
                "tf",
                format!(
                    "must be finite and after the current time {}, got {tf}",
                    self.t
                ),
            ));
        }
        self.tf = tf;
        Ok(())
    }

    /// The tolerances of the following steps: the relative one and the absolute one of each
    /// component (what [`Integrator::set_tolerances`] set last, or the options').
    ///
    /// ```
    /// use hdi_tribology::nalgebra::Vector1;
    /// use hdi_tribology::ode::{FnSystem, Integrator, Method, Options, Tolerance};
    /// let decay = FnSystem::new(|_t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>| dy[0] = -y[0]);
    /// let opts = Options::default().rtol(1e-8).atol(1e-12);
    /// let mut it = Integrator::new(decay, 0.0, Vector1::new(1.0), 1.0, Method::Tsit5, &opts)?;
    /// it.set_tolerances(1e-10, Tolerance::Scalar(1e-14))?;
    /// assert_eq!((it.rtol(), it.atol()), (1e-10, &[1e-14][..]));
    /// # Ok::<(), hdi_tribology::ode::OdeError>(())
    /// ```
    pub fn rtol(&self) -> f64 {
        self.ctx.rtol
    }

    /// The absolute tolerance of each component for the following steps (see
    /// [`Integrator::rtol`]).
    pub fn atol(&self) -> &[f64] {
        self.ctx.atol.as_slice()
    }

    /// Changes the tolerances for the following steps. `Auto` keeps the stiff method chosen
    /// from the tolerance at the start.
    ///
    /// # Errors
    /// [`OdeError::InvalidInput`] naming `options.rtol` or `options.atol` when out of range.
    pub fn set_tolerances(&mut self, rtol: f64, atol: super::Tolerance) -> Result<(), OdeError> {
        let check = Options {
            rtol,
            atol,
            ..Options::default()
        };
        check.validate(self.y.len())?;
        for i in 0..self.y.len() {
            self.ctx.atol[i] = check.atol.get(i);
        }
        self.ctx.rtol = rtol;
        self.steppers.set_rtol(rtol);
        Ok(())
    }

    /// Changes the absolute tolerance of every component for the following steps, without a
    /// restart and without allocating (the relative tolerance and the step size stay).
    ///
    /// ```
    /// use hdi_tribology::nalgebra::{Vector2, U2};
    /// use hdi_tribology::ode::{Integrator, Method, OdeSystem, Options};
    /// /// y'' = -y.
    /// struct Spring;
    /// impl OdeSystem<U2> for Spring {
    ///     fn rhs(&self, _t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
    ///         dy[0] = y[1];
    ///         dy[1] = -y[0];
    ///     }
    ///     fn is_autonomous(&self) -> bool { true }
    /// }
    /// let opts = Options::default().rtol(1e-6).atol(1e-12);
    /// let mut it = Integrator::new(Spring, 0.0, Vector2::new(1.0, 0.0), 10.0, Method::Tsit5, &opts)?;
    /// it.advance_to(5.0)?;
    /// let tight = it.stats().accepted;
    /// it.set_atol(&[1e-3, 1e-3])?; // looser from here on: longer steps
    /// it.advance_to(10.0)?;
    /// assert!(it.stats().accepted - tight < tight);
    /// assert!(it.set_atol(&[1e-3]).is_err()); // one per component
    /// # Ok::<(), hdi_tribology::ode::OdeError>(())
    /// ```
    ///
    /// # Errors
    /// [`OdeError::InvalidInput`] naming `options.atol` (wrong length) or `options.atol[i]` (not
    /// finite, or negative); nothing is changed then.
    pub fn set_atol(&mut self, atol: &[f64]) -> Result<(), OdeError> {
        super::options::check_atol_components(atol, self.y.len())?;
        for (a, &b) in self.ctx.atol.iter_mut().zip(atol) {
            *a = b;
        }
        Ok(())
    }

    /// Restarts from `(t, y)` after a discontinuity (a jump of the state or of the system's
    /// parameters): the method drops what it carried over, a new initial step size is chosen,
    /// and events are evaluated afresh. `t` may be earlier than the current time but must be
    /// before `tf`.
    ///
    /// # Errors
    /// [`OdeError::InvalidInput`] for a non-finite or misplaced `t` or a non-finite or
    /// wrongly sized `y`; [`OdeError::NonFinite`] when `f(t, y)` is not finite.
    pub fn reinit(&mut self, t: f64, y: OVector<f64, D>) -> Result<(), OdeError> {
        if !(t.is_finite() && t < self.tf) {
            return Err(OdeError::invalid(
                "t",
                format!("must be finite and before tf = {}, got {t}", self.tf),
            ));
        }
        if y.len() != self.y.len() {
            return Err(OdeError::invalid(
                "y",
                format!("has {} components, the state has {}", y.len(), self.y.len()),
            ));
        }
        check_finite_state(&y)?;
        self.t = t;
        self.y = y;
        self.t_span0 = t;
        self.have_poly = false;
        self.kink_idx = 0;
        self.h_needs_init = true;
        self.err_prev = 1.0;
        self.last_rejected = false;
        self.fails = (0, FailKind::NonFinite);
        self.restart()?;
        let mut ev = std::mem::take(&mut self.events);
        self.init_events(&mut ev);
        self.events = ev;
        Ok(())
    }

    /// Takes one accepted step (shortened to land on `tf`, a kink in `opts.t_stops`, or an
    /// event that stops or acts).
    ///
    /// # Errors
    /// [`OdeError::InvalidInput`] when `tf` is already reached; otherwise the failures of
    /// [`solve`](super::solve).
    pub fn step(&mut self) -> Result<StepStatus, OdeError> {
        self.hits.clear();
        let mut ev = std::mem::take(&mut self.events);
        let r = self.step_with(&mut ev);
        self.events = ev;
        r
    }

    /// Steps until the current time is exactly `t` (`t()` ≤ `t` ≤ `tf`); the last step is
    /// shortened to end there, with no restart of the method. Stops early at a terminal event
    /// (returns [`StepStatus::Terminated`]); acting events act on the way.
    ///
    /// # Errors
    /// [`OdeError::InvalidInput`] when `t` is outside `[t(), tf]`; otherwise the failures of
    /// [`solve`](super::solve).
    pub fn advance_to(&mut self, t: f64) -> Result<StepStatus, OdeError> {
        if !(t >= self.t && t <= self.tf) {
            return Err(OdeError::invalid(
                "t",
                format!(
                    "must lie in [{}, {}] (current time, tf), got {t}",
                    self.t, self.tf
                ),
            ));
        }
        self.hits.clear();
        let mut ev = std::mem::take(&mut self.events);
        self.target = Some(t);

        let mut status = Ok(StepStatus::Accepted);
        while self.t < t {
            status = self.step_with(&mut ev);
            match status {
                Err(_) | Ok(StepStatus::Terminated(_)) => break,
                _ => {}
            }
        }
        self.target = None;
        self.events = ev;
        match status {
            Ok(StepStatus::Acted(_)) if self.t >= self.tf => Ok(StepStatus::ReachedEnd),
            Ok(StepStatus::Acted(_)) => Ok(StepStatus::Accepted),
            other => other,
        }
    }

    /// The loop body: one accepted step, with `events` located on it. Hits are appended to
    /// `self.hits`.
    pub(crate) fn step_with(
        &mut self,
        events: &mut [Event<'_, D>],
    ) -> Result<StepStatus, OdeError> {
        if self.t >= self.tf {
            return Err(OdeError::invalid(
                "tf",
                format!(
                    "the end time {} is reached; set a later one to go on",
                    self.tf
                ),
            ));
        }
        // The events first: a changed system may start on another branch, and the method
        // restarts after that.
        if self.events_stale {
            self.init_events(events);
            self.events_stale = false;
        }
        if self.needs_restart {
            self.restart()?;
        }
        let (kink, stop) = self.next_stop();
        let h_max = self.h_max_opt.min(self.tf - self.t_span0);
        let t = self.t;
        let Some(Accepted {
            h,
            err,
            order: k,
            stiff,
            hit_stop,
            by_floor,
        }) = self.attempt_until_accepted(stop)?
        else {
            // Rodas5P's rounding floor: the same step again with the method that took over.
            return self.step_with(events);
        };
        self.fails.0 = 0;
        self.err_last = err;
        self.accepted_run += 1;
        if self.accepted_run >= 50 {
            self.recent_nonfinite = 0;
        }
        self.ctx.stats.accepted += 1;
        if stiff {
            self.ctx.stats.stiff_steps += 1;
        }
        if let Some(i) = self.entry_pending.take() {
            self.entry_steps[i] = h;
        }
        if by_floor {
            // Backward Euler's interpolant is the chord; the method starts again at its end.
            if self.ctx.need_poly {
                self.poly.begin(t, h, 1);
                let [a0, a1] = self.poly.rows_mut::<2>();
                for i in 0..self.y.len() {
                    a0[i] = self.y[i];
                    a1[i] = self.y_new[i] - self.y[i];
                }
            }
            self.needs_restart = true;
        } else {
            let stepper = self.steppers.get::<S>(self.active);
            let step = Step {
                t,
                h,
                y: &self.y,
                y_new: &mut self.y_new,
            };
            stepper.accept(&self.sys, &step, &mut self.poly, &mut self.ctx);
        }
        self.have_poly = self.ctx.need_poly;
        let t_new = if hit_stop { stop } else { t + h };

        let (cut_by, terminal) = self.locate_events(events, t, t_new);
        self.set_next_step(h, err, k, stiff, h_max);
        self.last_cut = cut_by.is_some();

        match cut_by {
            Some(Cut::Event(i)) => return self.act_on_cut(events, i, terminal),
            Some(Cut::Switch(i)) => return self.switch_on_cut(events, i),
            None => {}
        }
        if hit_stop && kink == Some(stop) {
            // The right-hand side may have a kink here: no derivative carries over.
            self.kink_idx += 1;
            self.restart()?;
        }
        if self.t >= self.tf {
            return Ok(StepStatus::ReachedEnd);
        }
        // Stiffness switching.
        if self.steppers.count() > 1 {
            self.switch_check(stiff, h);
        }
        Ok(StepStatus::Accepted)
    }

    /// The next kink of the right-hand side before the end time (skipping those passed), and
    /// where the coming step must stop: that kink, the end time or the time asked for.
    #[inline]
    fn next_stop(&mut self) -> (Option<f64>, f64) {
        while self.kink_idx < self.kinks.len() && self.kinks[self.kink_idx] <= self.t {
            self.kink_idx += 1;
        }
        let kink = self
            .kinks
            .get(self.kink_idx)
            .copied()
            .filter(|&k| k < self.tf);
        let mut stop = kink.unwrap_or(self.tf);
        if let Some(tg) = self.target {
            stop = stop.min(tg);
        }
        (kink, stop)
    }

    /// Trial steps from `(t, y)` until one is accepted (its end state in `y_new`); `None` when
    /// Rodas5P refused a step for its rounding floor and another method took over (the step is
    /// to be taken again).
    #[inline]
    fn attempt_until_accepted(&mut self, stop: f64) -> Result<Option<Accepted>, OdeError> {
        let t = self.t;
        let mut h = self.h;
        // The error control has asked for the step floor (`set_step_floor`).
        let mut floored = false;
        loop {
            let attempts = self.ctx.stats.accepted + self.ctx.stats.rejected;
            if super::Cancel::requested() {
                return Err(OdeError::Cancelled { t });
            }
            if attempts >= self.max_steps {
                return Err(OdeError::TooManySteps {
                    t,
                    max_steps: self.max_steps,
                });
            }
            // A step must change t in floating point by more than a few ulps.
            let floor = self.h_min.max(16.0 * f64::EPSILON * t.abs()).max(1e-300);
            let remaining = stop - t;
            let mut hit_stop = false;
            if h >= remaining || remaining - h < floor.max(1e-3 * h) {
                h = remaining;
                hit_stop = true;
            } else if h.is_nan() || h < floor {
                self.h = h;
                if self.recent_nonfinite > 0 {
                    return Err(OdeError::NonFinite {
                        t,
                        what: format!(
                            "state or right-hand side: trial steps failed down to h = {h:e} (floor {floor:e})"
                        ),
                    });
                }
                return Err(OdeError::StepTooSmall { t, h, h_min: floor });
            }
            let stepper = self.steppers.get::<S>(self.active);
            let k = stepper.error_order();
            let stiff = stepper.is_stiff();
            let step = Step {
                t,
                h,
                y: &self.y,
                y_new: &mut self.y_new,
            };
            let trial = stepper.attempt(&self.sys, step, &mut self.ctx);
            let err = match trial {
                Trial::Done { err } if err.is_finite() => err,
                Trial::Done { .. } => {
                    self.recent_nonfinite += 1;
                    self.accepted_run = 0;
                    if let Some(a) = self.at_the_floor(t, h, 0.25, hit_stop) {
                        self.ctx.stats.rejected += 1;
                        return Ok(Some(a));
                    }
                    register_failure(&mut self.fails, FailKind::NonFinite, t, h)?;
                    self.ctx.stats.rejected += 1;
                    h *= 0.25;
                    self.last_rejected = true;
                    continue;
                }
                Trial::Failed {
                    kind: FailKind::RoundingFloor,
                    ..
                } => {
                    self.ctx.stats.rejected += 1;
                    self.rounding_floor_fallback(t, h)?;
                    return Ok(None);
                }
                Trial::Failed { factor, kind } => {
                    if kind == FailKind::NonFinite {
                        self.recent_nonfinite += 1;
                    }
                    self.accepted_run = 0;
                    if let Some(a) = self.at_the_floor(t, h, factor, hit_stop) {
                        self.ctx.stats.rejected += 1;
                        return Ok(Some(a));
                    }
                    register_failure(&mut self.fails, kind, t, h)?;
                    self.ctx.stats.rejected += 1;
                    h *= factor;
                    self.last_rejected = true;
                    continue;
                }
            };
            // A step at the floor (or stretched from it onto the stop) is accepted whatever its
            // error.
            if err > 1.0 && self.adaptive && !floored && h > self.h_floor {
                self.fails.0 = 0;
                self.ctx.stats.rejected += 1;
                let fac = (SAFETY * err.powf(-1.0 / k)).max(FAC_MIN);
                h *= fac;
                if h <= self.h_floor {
                    h = self.h_floor;
                    floored = true;
                }
                self.last_rejected = true;
                continue;
            }
            return Ok(Some(Accepted {
                h,
                err,
                order: k,
                stiff,
                hit_stop,
                by_floor: false,
            }));
        }
    }

    /// A trial of length `h` from `t` failed (not for its error), and the method would try it
    /// again at `h · factor`: below the step floor, once the retries
    /// ([`set_floor_retries`](Integrator::set_floor_retries)) are spent, the step is taken at
    /// `h` by the floor's step instead ([`FloorStep`]), accepted whatever its error estimate.
    /// `None` when there is no floor, the shorter trial would stay above it, a retry is left,
    /// or the floor's step failed too (the trial is then shortened as without a floor).
    #[cold]
    fn at_the_floor(&mut self, t: f64, h: f64, factor: f64, hit_stop: bool) -> Option<Accepted> {
        if !(self.h_floor > 0.0 && h * factor < self.h_floor) {
            return None;
        }
        match self.floor_retries.as_mut() {
            None => return None,
            Some(left) if *left > 0 => {
                *left -= 1;
                return None;
            }
            Some(_) => {}
        }
        let fs = self
            .floor_step
            .get_or_insert_with(|| Box::new(FloorStep::new(&self.y)));
        let err = fs.take(&self.sys, t, h, &self.y, &mut self.y_new, &mut self.ctx)?;
        self.ctx.stats.floor_steps += 1;
        Some(Accepted {
            h,
            err,
            order: self.steppers.get::<S>(self.active).error_order(),
            stiff: true,
            hit_stop,
            by_floor: true,
        })
    }

    /// The events' sign changes between the ends of the accepted step `[t, t_new]`, located
    /// on the interpolant and appended to `self.hits`; the first event that stops or acts, or
    /// the first switch of the system's branch, cuts the step there (later roots are dropped:
    /// those of acting events and switches are found again after the restart). Sets the time
    /// and state to the step's (or the cut's) end, and returns the cut and whether a terminal
    /// event made it.
    #[inline]
    fn locate_events(
        &mut self,
        events: &mut [Event<'_, D>],
        t: f64,
        t_new: f64,
    ) -> (Option<Cut>, bool) {
        let switch = if self.sw_old.is_empty() {
            None
        } else {
            self.locate_switch(t, t_new)
        };
        self.step_hits.clear();
        for (i, ev) in events.iter_mut().enumerate() {
            let g_new = ev.eval(t_new, &self.y_new);
            self.ctx.stats.event_evals += 1;
            // The first sub-interval (between the step ends and any interior checks) on
            // which g changes sign in the event's direction.
            let inside = ev.inside_checks();
            let (mut ta, mut ga) = (t, self.g_old[i]);
            let mut bracket = None;
            for j in 1..=inside + 1 {
                let (tb, gb) = if j == inside + 1 {
                    (t_new, g_new)
                } else {
                    let tb = t + (t_new - t) * j as f64 / (inside + 1) as f64;
                    self.poly.eval_into(tb, &mut self.work);
                    self.ctx.stats.event_evals += 1;
                    (tb, ev.eval(tb, &self.work))
                };
                if let Some(rising) = crossing(ev.get_direction(), ga, gb) {
                    bracket = Some((ta, ga, tb, gb, rising));
                    break;
                }
                (ta, ga) = (tb, gb);
            }
            if let Some((ta, ga, tb, gb, rising)) = bracket {
                let (te, evals) = locate(
                    |t, y| ev.eval(t, y),
                    &self.poly,
                    ta,
                    ga,
                    tb,
                    gb,
                    self.event_tol,
                    &mut self.work,
                );
                self.ctx.stats.event_evals += evals;
                self.step_hits.push((i, te, rising));
            }
            self.g_old[i] = g_new;
        }
        self.step_hits.sort_by(|a, b| a.1.total_cmp(&b.1));
        let mut t_cut = None;
        let mut cut_by = None;
        let mut terminal = false;
        for &(i, te, rising) in &self.step_hits {
            // A switch before an event's root cuts first; the event is found again after it.
            if let Some(tc) = t_cut.or(switch.map(|(_, ts)| ts)) {
                if te > tc {
                    break;
                }
            }
            self.poly.eval_into(te, &mut self.work);
            self.hits.push(EventHit {
                index: i,
                t: te,
                y: self.work.clone(),
                rising,
            });
            if events[i].is_terminal() || events[i].acts() {
                if t_cut.is_none() {
                    t_cut = Some(te);
                    cut_by = Some(Cut::Event(i));
                }
                terminal |= events[i].is_terminal();
            }
        }
        if let (None, Some((j, ts))) = (t_cut, switch) {
            t_cut = Some(ts);
            cut_by = Some(Cut::Switch(j));
        }
        let t_reach = t_cut.unwrap_or(t_new);
        if let Some(tc) = t_cut {
            self.poly.eval_into(tc, &mut self.y_new);
        }
        self.t = t_reach;
        std::mem::swap(&mut self.y, &mut self.y_new);
        (cut_by, terminal)
    }

    /// The size of the next step after an accepted one of size `h` with error `err` (method of
    /// error order `k`): the PI controller, capped by the method's hint and `h_max`.
    #[inline]
    fn set_next_step(&mut self, h: f64, err: f64, k: f64, stiff: bool, h_max: f64) {
        let (alpha, beta) = (0.7 / k, 0.4 / k);
        let e = err.max(1e-10);
        let mut fac = SAFETY * e.powf(-alpha) * self.err_prev.powf(beta);
        let fac_max = if stiff {
            FAC_MAX_STIFF
        } else {
            FAC_MAX_EXPLICIT
        };
        if self.last_rejected {
            fac = fac.min(1.0);
        }
        let stepper = self.steppers.get::<S>(self.active);
        if let Some(hint) = stepper.step_hint() {
            fac = fac.min(hint);
        }
        let mut h_next = h;
        if self.adaptive {
            h_next = stepper
                .propose(h, h * fac.clamp(FAC_MIN, fac_max))
                .max(self.h_floor)
                .min(h_max);
        } else if let Some(h0) = self.h_init {
            h_next = h0.min(h_max);
        }
        self.h = h_next;
        self.err_prev = e;
        self.last_rejected = false;
    }

    /// The first root in `[t, t_new]` of the system's switching functions, where one falls from
    /// non-negative at `t` to negative at `t_new`, located on the interpolant: `(switch, time)`.
    /// Updates the switching functions' values at `t_new`. Only the step's ends are compared:
    /// a function that dips below zero and back within one step (by less than the step
    /// resolves) keeps its branch.
    #[inline(never)]
    fn locate_switch(&mut self, t: f64, t_new: f64) -> Option<(usize, f64)> {
        let mut first: Option<(usize, f64)> = None;
        for i in 0..self.sw_old.len() {
            let (ga, gb) = (self.sw_old[i], self.sys.switching(i, t_new, &self.y_new));
            self.sw_old[i] = gb;
            if ga >= 0.0 && gb < 0.0 {
                let sys = &self.sys;
                let (te, _) = locate(
                    |t, y| sys.switching(i, t, y),
                    &self.poly,
                    t,
                    ga,
                    t_new,
                    gb,
                    self.event_tol,
                    &mut self.work,
                );
                if first.is_none_or(|(_, tf)| te < tf) {
                    first = Some((i, te));
                }
            }
        }
        first
    }

    /// Shortens the coming step of an explicit method to its stability bound for the fastest
    /// rate the system declares of the branches it holds ([`OdeSystem::branch_rate`]).
    fn within_branch_rates(&mut self) {
        let stepper = self.steppers.get::<S>(self.active);
        if stepper.is_stiff() || self.active == IMEX {
            return;
        }
        let boundary = stepper.stability_boundary();
        for i in 0..self.sys.switches() {
            if let Some(rate) = self.sys.branch_rate(i, &self.y).filter(|r| *r > 0.0) {
                self.h = self.h.min(boundary / rate);
            }
        }
    }

    /// After a switch into a branch of the fastest rate `entered`: an explicit method that
    /// weighs its cost hands over to the stiff one at once when the branch's stability bound
    /// `b/rate` is less than `1/COST_RATIO` of the coming step, as the stiffness checks would
    /// after some steps at that bound. The bound is the explicit step the stiff run has to beat
    /// ([`Integrator::leave_stiff_branch`] hands back where the branch ends).
    ///
    /// The stiff run starts with the first step that the last such entry of switch `i`
    /// accepted, where that is shorter than the explicit step carried over: a branch of a fast
    /// rate starts a layer of that rate's time, which the explicit step, long on the branch
    /// left, does not resolve (on the meniscus's formation branch, 1/τ_f = 1e7 s⁻¹, each entry
    /// cost three to five rejected stiff steps before one of a fifth of the step carried over
    /// passed). Only the entries that go stiff at once: where the stiff method already ran,
    /// the same rule cost more steps than the rejections it saved.
    ///
    /// Where the system declares the branch's stiff rows ([`OdeSystem::stiff_diagonal`]), the
    /// branch goes to the additive pair instead, which steps those rows implicitly at an
    /// explicit step's cost, unless the rest of the system is stiff at the first step (`h·ρ`
    /// above `STIFF_FRACTION` of the boundary, ρ of the Jacobian without the declared rows and
    /// columns; the periodic checks go on watching it and hand a run that turns stiff to the
    /// stiff method), or the pair's last branch ended at its first step (a refusal for that one
    /// entry). That happens where the branch's switching function stays within the
    /// integration error of zero (the meniscus's formation branch in slow contact at 0 V): the
    /// pair's branches then end and start again every step or two, each a restart, where the
    /// stiff method's run carries on (at 0 V, 1 416 steps without this exception, 1 315 with
    /// it, against 1 283 with the stiff method on every such branch).
    fn enter_stiff_branch(&mut self, i: usize, entered: Option<f64>) {
        if !self.steppers.weighs_cost() || self.active != 0 {
            return;
        }
        let Some(rate) = entered.filter(|r| *r > 0.0) else {
            return;
        };
        let boundary = self.steppers.get::<S>(0).stability_boundary();
        let bound = boundary / rate;
        if COST_RATIO * bound >= self.h {
            return;
        }
        if self.entry_steps.len() <= i {
            self.entry_steps.resize(i + 1, f64::NAN);
        }
        let first = self.entry_steps[i].min(self.h);
        // The additive pair where the system declares the branch's stiff rows, the rest is not
        // stiff at the first step, and the pair's last branch did not end at once; the stiff
        // method otherwise, where it pays.
        let refused = std::mem::take(&mut self.imex_refuse_next);
        let imex = !refused && self.sys.stiff_diagonal(self.t, &self.y, &mut self.lambda) && {
            first * self.radius_here(true) < STIFF_FRACTION * boundary
        };
        self.h = first;
        self.h_explicit = bound;
        if imex {
            self.imex_entered_at = self.ctx.stats.accepted;
        }
        self.use_method(if imex { IMEX } else { 1 });
        self.entry_pending = Some(i);
    }

    /// After a switch of branch from the fastest rate `left` to `entered`: a stiff method that
    /// weighs its cost hands back to the explicit one when the branch it leaves held the
    /// explicit step at its stability bound (`h·rate` above `STIFF_FRACTION` of the boundary
    /// for the explicit step before the switch to the stiff method), the branch entered is
    /// slower, and on it the stiff step would not count as stiff for the explicit method
    /// (`h·ρ` below `STIFF_FRACTION` of the boundary, ρ estimated there, one Jacobian). The
    /// stiffness that made the stiff steps pay was then that branch's own. (With the looser
    /// `COST_RETURN_FRACTION` the cycle with menisci at 0 V took 5 % longer, handing back
    /// where the contact was still stiff; with `RETURN_FRACTION` it rarely handed back.)
    fn leave_stiff_branch(&mut self, left: Option<f64>, entered: Option<f64>) {
        if self.active == IMEX {
            // The pair steps only the branch it was entered for.
            if !self.branch_holds_explicit_step(entered) {
                self.imex_refuse_next = self.ctx.stats.accepted <= self.imex_entered_at + 1;
                self.use_method(0);
            }
            return;
        }
        if !self.steppers.weighs_cost() || !self.steppers.get::<S>(self.active).is_stiff() {
            return;
        }
        let boundary = self.steppers.get::<S>(0).stability_boundary();
        let held = left.is_some_and(|r| {
            r * self.h_explicit > STIFF_FRACTION * boundary && entered.unwrap_or(0.0) < r
        });
        if !held {
            return;
        }
        if self.h * self.radius_here(false) < STIFF_FRACTION * boundary {
            self.change_method();
        }
    }

    /// The step was cut at the root of switch `i`: the system changes branch there and the
    /// method restarts (the step counts as an ordinary accepted one).
    fn switch_on_cut(
        &mut self,
        events: &mut [Event<'_, D>],
        i: usize,
    ) -> Result<StepStatus, OdeError> {
        let left = self.sys.branch_rate(i, &self.y);
        self.sys.switch(i, self.t, &mut self.y);
        self.ctx.stats.branch_switches += 1;
        let entered = self.sys.branch_rate(i, &self.y);
        self.leave_stiff_branch(left, entered);
        self.enter_stiff_branch(i, entered);
        self.within_branch_rates();
        check_finite_state(&self.y).map_err(|_| OdeError::NonFinite {
            t: self.t,
            what: format!("state set by switch {i} of the system"),
        })?;
        self.needs_restart = true;
        self.init_events(events);
        Ok(if self.t >= self.tf {
            StepStatus::ReachedEnd
        } else {
            StepStatus::Accepted
        })
    }

    /// The step was cut by event `i`: the actions of every event cut at the same time, in
    /// index order, and a restart of the method from the cut.
    fn act_on_cut(
        &mut self,
        events: &mut [Event<'_, D>],
        i: usize,
        terminal: bool,
    ) -> Result<StepStatus, OdeError> {
        let tc = self.t;
        let mut acted = false;
        let mut acting: Vec<usize> = self
            .step_hits
            .iter()
            .filter(|&&(j, te, _)| te == tc && events[j].acts())
            .map(|&(j, _, _)| j)
            .collect();
        acting.sort_unstable();
        for j in acting {
            events[j].apply(tc, &mut self.y);
            acted = true;
        }
        if acted {
            check_finite_state(&self.y).map_err(|_| OdeError::NonFinite {
                t: tc,
                what: format!("state set by the action of event {i}"),
            })?;
        }
        // The method's carried-over data belong to the uncut step end.
        self.needs_restart = true;
        self.init_events(events);
        Ok(if terminal {
            StepStatus::Terminated(i)
        } else {
            StepStatus::Acted(i)
        })
    }

    /// Rodas5P refused a step of size `h` at `t` for its rounding floor (see
    /// [`OdeError::RoundingFloor`]): `Auto` takes Radau5 as its stiff method from here on and
    /// retries the same step; Rodas5P chosen by the user fails.
    fn rounding_floor_fallback(&mut self, t: f64, h: f64) -> Result<(), OdeError> {
        match &self.steppers {
            Steppers::Auto(..) => {
                self.steppers = Steppers::AutoRadau(
                    Tsit5::new(&self.y),
                    Box::new(Radau5::new(&self.y, self.ctx.rtol)),
                );
                self.h = h;
                self.err_prev = 1.0;
                self.needs_restart = true;
                Ok(())
            }
            steppers => {
                // Only Rodas5P reports a rounding floor.
                let (component, floor) = match steppers {
                    Steppers::Rodas5P(m) => m.floor_hit().unwrap_or((0, f64::NAN)),
                    _ => (0, f64::NAN),
                };
                Err(OdeError::RoundingFloor {
                    t,
                    h,
                    component,
                    floor,
                    significant: self.ctx.atol[component] / self.ctx.rtol,
                })
            }
        }
    }

    fn switch_check(&mut self, stiff: bool, h_acc: f64) {
        // The explicit method (the first of the two) sets the stability boundary.
        let boundary = self.steppers.get::<S>(0).stability_boundary();
        let switch = if !stiff {
            self.since_check += 1;
            // The cheap indicator of the explicit method flags growing stiff components;
            // a periodic Jacobian check catches a step size pinned at the stability limit
            // while those components are still damped.
            let flagged = self
                .steppers
                .get::<S>(self.active)
                .stiffness()
                .is_some_and(|h_rho| h_rho > boundary);
            if self.skip_checks > 0 {
                // A backoff counts the periodic checks; the indicator is not heard meanwhile.
                if self.since_check >= CHECK_INTERVAL {
                    self.since_check = 0;
                    self.skip_checks -= 1;
                }
            } else if flagged || self.since_check >= CHECK_INTERVAL {
                self.since_check = 0;
                // While the additive pair runs, its implicit rows are left out: the rest
                // limits its step.
                let imex = self.active == IMEX;
                if imex {
                    self.sys.stiff_diagonal(self.t, &self.y, &mut self.lambda);
                }
                let f0 = self.steppers.get::<S>(self.active).f0().clone();
                let rho = self.radius_at(&f0, imex);
                if h_acc * rho > STIFF_FRACTION * boundary {
                    self.stiff_count += 1;
                } else {
                    self.stiff_count = 0;
                }
            }
            self.stiff_count >= STIFF_CHECKS_TO_SWITCH
        } else {
            // The stiff method may hold only a lower bound of ρ: a bound that already keeps
            // the step stiff settles the test; otherwise the test takes the estimate itself.
            let pays = !self.steppers.weighs_cost() || h_acc > COST_RATIO * self.h_explicit;
            let fraction = if pays {
                RETURN_FRACTION
            } else {
                COST_RETURN_FRACTION
            };
            let below = |rho: f64| h_acc * rho < fraction * boundary;
            let stepper = self.steppers.get::<S>(self.active);
            // A run that does not pay may hand back only after its trial: the estimate is
            // taken from the steps that could end it on.
            let tested = pays || self.stiff_run.0 + STEPS_TO_RETURN >= TRIAL_STEPS;
            match stepper.stiffness() {
                Some(rho)
                    if tested && below(rho) && stepper.stiffness_exact().is_some_and(below) =>
                {
                    self.return_count += 1;
                }
                _ => self.return_count = 0,
            }
            self.stiff_run.0 += 1;
            self.stiff_run.1 += usize::from(pays);
            self.return_count >= STEPS_TO_RETURN && (pays || self.stiff_run.0 >= TRIAL_STEPS)
        };
        if switch && stiff {
            let (steps, gained) = self.stiff_run;
            if 2 * gained > steps {
                self.backoff = 0;
            } else {
                self.backoff = (2 * self.backoff).clamp(1, MAX_BACKOFF);
                self.skip_checks = self.backoff;
            }
        }
        if switch {
            if !stiff {
                self.h_explicit = h_acc;
            }
            self.change_method();
        }
    }

    /// Whether a branch of the fastest rate `entered` would hold the explicit method's step
    /// below `1/COST_RATIO` of the coming one.
    fn branch_holds_explicit_step(&mut self, entered: Option<f64>) -> bool {
        entered.filter(|r| *r > 0.0).is_some_and(|rate| {
            COST_RATIO * self.steppers.get::<S>(0).stability_boundary() / rate < self.h
        })
    }

    /// Hands over to the other method of the pair (from the additive pair, to the stiff one);
    /// it restarts from the current state.
    fn change_method(&mut self) {
        self.use_method(usize::from(self.active != 1));
    }

    /// Spectral radius of the Jacobian at the current point, where `f0` is `f`, for the
    /// stiffness checks (∞ when the Jacobian is not finite, which sends the integration to the
    /// stiff method). With `without_stiff_rows`, the rows and columns the system declares stiff
    /// (`self.lambda`, as [`OdeSystem::stiff_diagonal`] last wrote it) are left out: what limits
    /// the additive pair's explicit part.
    fn radius_at(&mut self, f0: &OVector<f64, D>, without_stiff_rows: bool) -> f64 {
        let Some(jac) = self.jac_work.as_mut() else {
            return 0.0;
        };
        if !eval_jacobian(
            &self.sys,
            self.t,
            &self.y,
            f0,
            jac,
            &mut self.work,
            &mut self.ctx,
        ) {
            return f64::INFINITY;
        }
        if without_stiff_rows {
            for i in 0..self.y.len() {
                if self.lambda[i] != 0.0 {
                    jac.row_mut(i).fill(0.0);
                    jac.column_mut(i).fill(0.0);
                }
            }
        }
        spectral_radius(jac, &self.y)
    }

    /// [`Integrator::radius_at`] with `f` evaluated at the current point (after a switch, where
    /// the method has not restarted yet).
    fn radius_here(&mut self, without_stiff_rows: bool) -> f64 {
        let mut f0 = self.y.clone();
        self.sys.rhs(self.t, &self.y, &mut f0);
        self.ctx.stats.rhs_evals += 1;
        self.radius_at(&f0, without_stiff_rows)
    }

    /// Hands over to method `m` of `Auto`; it restarts from the current state.
    fn use_method(&mut self, m: usize) {
        self.stiff_run = (0, 0);
        self.active = m;
        self.ctx.stats.stiffness_switches += 1;
        self.stiff_count = 0;
        self.since_check = 0;
        self.return_count = 0;
        self.err_prev = 1.0;
        self.needs_restart = true;
    }
}

impl<D: Dim, S: OdeSystem<D>> Integrator<'_, D, S>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// Time, state and work counters at the end, consuming the integrator.
    pub(crate) fn finish(self) -> (f64, OVector<f64, D>, Stats) {
        (self.t, self.y, self.ctx.stats)
    }
}

fn check_finite_state<D: Dim>(y: &OVector<f64, D>) -> Result<(), OdeError>
where
    DefaultAllocator: Allocator<D>,
{
    if let Some(i) = y.iter().position(|v| !v.is_finite()) {
        return Err(OdeError::invalid(
            format!("y0[{i}]"),
            format!("must be finite, got {}", y[i]),
        ));
    }
    Ok(())
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
        // Handled before `register_failure` (the method is changed or the run ends).
        FailKind::RoundingFloor => OdeError::NonFinite {
            t,
            what: "rounding floor of the linear solves".into(),
        },
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
    ctx.rhs(sys, t + h0, &y1, work);
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
