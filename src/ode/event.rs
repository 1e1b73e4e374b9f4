//! Events: user functions `g(t, y)` whose sign changes are located on the dense output.

use super::dense::StepPoly;
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OVector};
use serde::{Deserialize, Serialize};

/// Which sign changes of an event function count.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Direction {
    /// From negative to non-negative.
    Rising,
    /// From positive to non-positive.
    Falling,
    /// Either.
    Both,
}

/// Interior sign checks per step of an acting event (see [`Event::check_inside`]).
const ACTING_INSIDE_CHECKS: usize = 4;

/// Boxed event function `g(t, y)`.
type EventFn<'a, D> = Box<dyn FnMut(f64, &OVector<f64, D>) -> f64 + 'a>;

/// Boxed action `affect(t, y)` run at a located event; it may change the state in place.
type AffectFn<'a, D> = Box<dyn FnMut(f64, &mut OVector<f64, D>) + 'a>;

/// An event function `g(t, y)`; a root of `g` in the chosen direction is an event.
///
/// ```
/// use hdi_tribology::ode::{Direction, Event};
/// use nalgebra::Vector2;
/// // Ball hits the floor: height y[0] falls through zero; stop there.
/// let ev = Event::new(|_t, y: &Vector2<f64>| y[0]).direction(Direction::Falling).terminal(true);
/// assert!(ev.is_terminal());
/// ```
pub struct Event<'a, D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    f: EventFn<'a, D>,
    affect: Option<AffectFn<'a, D>>,
    direction: Direction,
    terminal: bool,
    inside: usize,
}

impl<'a, D: Dim> Event<'a, D>
where
    DefaultAllocator: Allocator<D>,
{
    /// A non-terminal event on both directions.
    pub fn new(f: impl FnMut(f64, &OVector<f64, D>) -> f64 + 'a) -> Self {
        Event {
            f: Box::new(f),
            affect: None,
            direction: Direction::Both,
            terminal: false,
            inside: 0,
        }
    }

    /// Makes the event act: at the located time `te` the integration stops inside the step,
    /// `affect(te, y)` may change the state `y` in place (a velocity reversed, a counter reset),
    /// and the integration goes on from `(te, y)` with the method restarted there — as after
    /// [`Integrator::reinit`](super::Integrator::reinit). Parameters of the system can be
    /// changed too when the system reads them from a shared cell (`Cell`, `RefCell`) that the
    /// action writes.
    ///
    /// The state right after the action should not sit on the wrong side of the event's
    /// direction, or the event fires again at once: choose [`Direction::Falling`] or
    /// [`Direction::Rising`] for a reset. Steps are sized by the solution's accuracy, not by
    /// the events: where the solution is smooth enough for steps longer than the time between
    /// two events, limit them with `Options::h_max`.
    ///
    /// A ball bouncing with restitution 0.8 (the velocity is reversed and scaled at each
    /// impact):
    ///
    /// ```
    /// use hdi_tribology::ode::{solve, Direction, Event, FnSystem, Method, Options};
    /// use nalgebra::Vector2;
    /// let ball = FnSystem::new(|_t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>| {
    ///     dy[0] = y[1];
    ///     dy[1] = -9.81;
    /// });
    /// let mut events = [Event::new(|_t, y: &Vector2<f64>| y[0])
    ///     .direction(Direction::Falling)
    ///     .affect(|_t, y| y[1] = -0.8 * y[1])];
    /// let opts = Options::default().rtol(1e-10).atol(1e-12);
    /// let sol = solve(&ball, 0.0, Vector2::new(1.0, 0.0), 1.5, Method::Tsit5, &opts, &mut events)?;
    /// // First impact at √(2/g); the second 2·0.8·√(2/g) later.
    /// let t1 = (2.0 / 9.81f64).sqrt();
    /// assert!((sol.events[0].t - t1).abs() < 1e-9);
    /// assert!((sol.events[1].t - t1 * (1.0 + 1.6)).abs() < 1e-9);
    /// # Ok::<(), hdi_tribology::ode::OdeError>(())
    /// ```
    pub fn affect(mut self, affect: impl FnMut(f64, &mut OVector<f64, D>) + 'a) -> Self {
        self.affect = Some(Box::new(affect));
        if self.inside == 0 {
            self.inside = ACTING_INSIDE_CHECKS;
        }
        self
    }

    pub(crate) fn inside_checks(&self) -> usize {
        self.inside
    }

    /// Whether the event acts on the state (see [`Event::affect`]).
    pub fn acts(&self) -> bool {
        self.affect.is_some()
    }

    pub(crate) fn apply(&mut self, t: f64, y: &mut OVector<f64, D>) {
        if let Some(a) = self.affect.as_mut() {
            a(t, y);
        }
    }

    setters! {
        /// Also checks the sign of `g` at `n` evenly spaced points inside each step (on the
        /// interpolant), so that a pair of roots within one step is not missed. 0 (only the step
        /// ends) by default; [`affect`](Event::affect) sets 4 when none was set, because right
        /// after an action `g` starts at zero and a long step could carry it out and back.
        check_inside(n: usize) => inside = n;
        /// Sets the direction.
        direction(d: Direction) => direction = d;
        /// Makes the event stop the integration (`true`) or only be recorded (`false`).
        terminal(terminal: bool) => terminal = terminal;
    }

    /// Whether the event stops the integration.
    pub fn is_terminal(&self) -> bool {
        self.terminal
    }

    /// The direction that counts.
    pub fn get_direction(&self) -> Direction {
        self.direction
    }

    pub(crate) fn eval(&mut self, t: f64, y: &OVector<f64, D>) -> f64 {
        (self.f)(t, y)
    }
}

/// A located event.
#[derive(Debug, Clone, PartialEq)]
pub struct EventHit<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    /// Index of the event in the slice passed to `solve` (or to the integrator).
    pub index: usize,
    /// Time of the root.
    pub t: f64,
    /// State at that time (dense output), before any action of the event.
    pub y: OVector<f64, D>,
    /// Whether `g` was rising (`true`) or falling through zero.
    pub rising: bool,
}

/// Does `g_old -> g_new` cross zero in direction `d`? Returns the sense (rising) if so.
pub(crate) fn crossing(d: Direction, g_old: f64, g_new: f64) -> Option<bool> {
    let rising = g_old < 0.0 && g_new >= 0.0;
    let falling = g_old > 0.0 && g_new <= 0.0;
    match d {
        Direction::Rising if rising => Some(true),
        Direction::Falling if falling => Some(false),
        Direction::Both if rising || falling => Some(rising),
        _ => None,
    }
}

/// Locates the root of `g` on the step interpolant between `ta` (value `ga`) and `tb` (value
/// `gb`, opposite sign or zero) to `tol` in time, by the Illinois variant of regula falsi with
/// bisection safeguards. Returns the right end of the final bracket (the first time at which
/// the sign has changed), so stopping there never leaves the event undone.
#[allow(clippy::too_many_arguments)]
pub(crate) fn locate<D: Dim>(
    mut g: impl FnMut(f64, &OVector<f64, D>) -> f64,
    poly: &StepPoly,
    mut ta: f64,
    mut ga: f64,
    mut tb: f64,
    mut gb: f64,
    tol: f64,
    work: &mut OVector<f64, D>,
) -> (f64, usize)
where
    DefaultAllocator: Allocator<D>,
{
    let mut evals = 0;
    let mut side = 0i32;
    // Iteration limit: bisection alone needs log2(h / tol) < 200 steps for any f64 interval.
    for it in 0..300 {
        if gb == 0.0 || (tb - ta).abs() <= tol {
            break;
        }
        let mut tm = if it % 4 == 3 || ga == gb {
            0.5 * (ta + tb)
        } else {
            tb - gb * (tb - ta) / (gb - ga)
        };
        if !(tm > ta && tm < tb) {
            tm = 0.5 * (ta + tb);
        }
        // Keep the bracket shrinking by at least tol/2 on each side.
        tm = tm.clamp(
            ta + 0.5 * tol.min(0.25 * (tb - ta)),
            tb - 0.5 * tol.min(0.25 * (tb - ta)),
        );
        poly.eval_into(tm, work);
        let gm = g(tm, work);
        evals += 1;
        if (gm < 0.0) == (ga < 0.0) && gm != 0.0 {
            ta = tm;
            ga = gm;
            if side == -1 {
                gb *= 0.5;
            }
            side = -1;
        } else {
            tb = tm;
            gb = gm;
            if side == 1 {
                ga *= 0.5;
            }
            side = 1;
        }
    }
    (tb, evals)
}
