//! The interface between the integration loop and one method, and the shared error norm.

use super::dense::StepPoly;
use super::solution::Stats;
use super::system::{OdeSystem, TimeMemo};
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OVector};

/// Tolerances and counters shared by the loop and the method.
pub(crate) struct Ctx<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    pub atol: OVector<f64, D>,
    pub rtol: f64,
    pub stats: Stats,
    /// Whether the method should estimate the spectral radius for stiffness switching.
    pub want_stiffness: bool,
    /// Whether the step interpolant is used (dense output, events, output at given times);
    /// methods whose interpolant costs extra function evaluations skip it otherwise.
    pub need_poly: bool,
    /// The system's values of the last time its right-hand side was asked for
    /// ([`OdeSystem::rhs_memo`]).
    pub memo: TimeMemo,
    /// The same for each stage of an implicit method, whose iterations ask again at the
    /// stages' times.
    pub stage_memos: [TimeMemo; 3],
}

impl<D: Dim> Ctx<D>
where
    DefaultAllocator: Allocator<D>,
{
    /// Weighted RMS norm of an error estimate `e` for a step from `y0` to `y1`.
    pub fn err_norm(&self, e: &OVector<f64, D>, y0: &OVector<f64, D>, y1: &OVector<f64, D>) -> f64 {
        let n = e.len();
        let mut s = 0.0;
        for i in 0..n {
            let sc = self.atol[i] + self.rtol * y0[i].abs().max(y1[i].abs());
            let r = e[i] / sc;
            s += r * r;
        }
        (s / n.max(1) as f64).sqrt()
    }

    /// `f(t, y)` into `out`, counted.
    #[inline]
    pub fn rhs<S: OdeSystem<D> + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        y: &OVector<f64, D>,
        out: &mut OVector<f64, D>,
    ) where
        DefaultAllocator: Allocator<D, D>,
    {
        sys.rhs_memo(t, y, out, &mut self.memo);
        self.stats.rhs_evals += 1;
    }

    /// Forgets every kept value of the system's inputs (the system may have changed).
    pub fn clear_memos(&mut self) {
        self.memo.clear();
        for m in &mut self.stage_memos {
            m.clear();
        }
    }

    /// Weighted RMS norm of a vector relative to the scale of `y`.
    pub fn norm_at(&self, v: &OVector<f64, D>, y: &OVector<f64, D>) -> f64 {
        self.err_norm(v, y, y)
    }
}

/// A step of size `h` from `(t, y)`: what the integration loop hands a method to attempt
/// (which writes the new state into `y_new`) and to accept (which reads it there).
pub(crate) struct Step<'a, D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    pub t: f64,
    pub h: f64,
    pub y: &'a OVector<f64, D>,
    pub y_new: &'a mut OVector<f64, D>,
}

/// Outcome of one step attempt.
pub(crate) enum Trial {
    /// The step was computed; `err` is the weighted error norm (accept when ≤ 1).
    Done { err: f64 },
    /// The step could not be computed; retry with `h * factor`.
    Failed { factor: f64, kind: FailKind },
}

/// Why a step attempt failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum FailKind {
    NonFinite,
    Newton,
    Singular,
    /// The rounding of the linear algebra exceeds what the tolerance asks for (Rodas5P).
    RoundingFloor,
}

/// One integration method.
pub(crate) trait Stepper<D: Dim, S: OdeSystem<D> + ?Sized>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// Exponent base of the step size controller: order of the error estimate plus one.
    fn error_order(&self) -> f64;

    /// Whether this is a stiff (implicit or linearly implicit) method: one whose stability
    /// region holds the whole negative real axis.
    fn is_stiff(&self) -> bool {
        self.stability_boundary() == f64::INFINITY
    }

    /// (Re)starts at `(t, y)`: evaluates and keeps `f(t, y)`; drops reusable data that is no
    /// longer valid (after a kink in the right-hand side or a method switch).
    fn restart(&mut self, sys: &S, t: f64, y: &OVector<f64, D>, ctx: &mut Ctx<D>);

    /// `f(t, y)` at the current point.
    fn f0(&self) -> &OVector<f64, D>;

    /// Attempts `step`, writing the new state into `step.y_new`.
    fn attempt(&mut self, sys: &S, step: Step<'_, D>, ctx: &mut Ctx<D>) -> Trial;

    /// Called after the last attempt, `step`, was accepted: writes the step interpolant into
    /// `poly` and moves the method's state to the new point.
    fn accept(&mut self, sys: &S, step: &Step<'_, D>, poly: &mut StepPoly, ctx: &mut Ctx<D>);

    /// Stiffness indicator of the last accepted step: for explicit methods `h·ρ` (ρ estimated
    /// spectral radius), for stiff methods `ρ`, or a lower bound of it (see
    /// [`stiffness_exact`](Stepper::stiffness_exact)); `None` when not available.
    fn stiffness(&self) -> Option<f64>;

    /// [`stiffness`](Stepper::stiffness) with a lower bound replaced by the estimate itself
    /// (the stiff methods keep `|tr J|/n ≤ ρ` and run the power iteration only when asked).
    fn stiffness_exact(&mut self) -> Option<f64> {
        self.stiffness()
    }

    /// Where the method's stability region meets the negative real axis, as `h·ρ`: the limit of
    /// an explicit step on a stiff problem (infinite for the stiff methods).
    fn stability_boundary(&self) -> f64 {
        f64::INFINITY
    }

    /// Step size multiplier suggested after a Newton or linear-algebra difficulty, if any.
    fn step_hint(&self) -> Option<f64> {
        None
    }

    /// Final say on the next step size after an accepted step of size `h_acc` for which the
    /// controller proposes `h_new` (e.g. keep `h_acc` to reuse an LU factorisation).
    fn propose(&self, _h_acc: f64, h_new: f64) -> f64 {
        h_new
    }
}

/// Is every component finite?
pub(crate) fn all_finite<D: Dim>(v: &OVector<f64, D>) -> bool
where
    DefaultAllocator: Allocator<D>,
{
    v.as_slice().iter().all(|x| x.is_finite())
}

/// Spectral radius estimate of an explicit step from two stages at the same time: the
/// derivatives `k_b`, `k_a` at the inputs `y_b`, `y_a` give `ρ ≈ ‖k_b − k_a‖ / ‖y_b − y_a‖`
/// (`None` when the inputs coincide).
#[inline]
pub(crate) fn stage_spectral_radius<D: Dim>(
    k_b: &OVector<f64, D>,
    k_a: &OVector<f64, D>,
    y_b: &OVector<f64, D>,
    y_a: &OVector<f64, D>,
) -> Option<f64>
where
    DefaultAllocator: Allocator<D>,
{
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..y_b.len() {
        let dk = k_b[i] - k_a[i];
        let dy = y_b[i] - y_a[i];
        num += dk * dk;
        den += dy * dy;
    }
    (den > 0.0).then(|| (num / den).sqrt())
}

/// Zero vector shaped like `y`.
pub(crate) fn zeros_like<D: Dim>(y: &OVector<f64, D>) -> OVector<f64, D>
where
    DefaultAllocator: Allocator<D>,
{
    let (r, c) = y.shape_generic();
    OVector::zeros_generic(r, c)
}

/// `y += a·x`, on the contiguous storage (the same result as nalgebra's `y.axpy(a, x, 1.0)`,
/// without its strided indexing).
#[inline]
pub(crate) fn add_scaled<D: Dim>(y: &mut OVector<f64, D>, a: f64, x: &OVector<f64, D>)
where
    DefaultAllocator: Allocator<D>,
{
    for (yi, xi) in y.as_mut_slice().iter_mut().zip(x.as_slice()) {
        *yi += a * xi;
    }
}

/// `out = a + b`, on the contiguous storage.
#[inline]
pub(crate) fn sum_into<D: Dim>(out: &mut OVector<f64, D>, a: &OVector<f64, D>, b: &OVector<f64, D>)
where
    DefaultAllocator: Allocator<D>,
{
    for ((o, ai), bi) in out
        .as_mut_slice()
        .iter_mut()
        .zip(a.as_slice())
        .zip(b.as_slice())
    {
        *o = ai + bi;
    }
}
