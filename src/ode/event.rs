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

/// Boxed event function `g(t, y)`.
type EventFn<'a, D> = Box<dyn FnMut(f64, &OVector<f64, D>) -> f64 + 'a>;

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
    direction: Direction,
    terminal: bool,
}

impl<'a, D: Dim> Event<'a, D>
where
    DefaultAllocator: Allocator<D>,
{
    /// A non-terminal event on both directions.
    pub fn new(f: impl FnMut(f64, &OVector<f64, D>) -> f64 + 'a) -> Self {
        Event {
            f: Box::new(f),
            direction: Direction::Both,
            terminal: false,
        }
    }

    /// Sets the direction.
    pub fn direction(mut self, d: Direction) -> Self {
        self.direction = d;
        self
    }

    /// Makes the event stop the integration (`true`) or only be recorded (`false`).
    pub fn terminal(mut self, terminal: bool) -> Self {
        self.terminal = terminal;
        self
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
    /// Index of the event in the slice passed to `solve`.
    pub index: usize,
    /// Time of the root.
    pub t: f64,
    /// State at that time (dense output).
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
    ev: &mut Event<'_, D>,
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
        let gm = ev.eval(tm, work);
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
