//! The step floor's own step ([`super::Integrator::set_floor_retries`]): where the method's
//! trial at the floor fails (its Newton iteration diverges, or its stages leave the right-hand
//! side's finite values) and no retry is left, the step is taken by backward Euler instead of
//! being tried again shorter.
//!
//! Backward Euler, `y₁ = y₀ + h f(t + h, y₁)`, is L-stable, and its equation has one unknown
//! state instead of a collocation method's three stages. It is solved by Newton's method with
//! the Jacobian taken afresh at each iterate (the first iterate from `y₀` is the linearly
//! implicit Euler step), each update halved while it does not lower the residual's weighted
//! norm. The work is bounded: at most [`FLOOR_NEWTON`] iterations, each one Jacobian, one LU
//! factorisation and at most `1 + HALVINGS` right-hand sides, and one more right-hand side at
//! the end. Where the iteration does not converge within that, the step fails and the caller
//! shortens the trial as without a floor. The estimate of one backward Euler step is
//! `(I − hJ)⁻¹ (h/2) (f(t + h, y₁) − f(t, y₀))`: its local error filtered through its own
//! iteration matrix, as Hairer and Wanner filter Radau IIA's (*Solving Ordinary Differential
//! Equations II*, §IV.8), weighted like every other method's.
//!
//! The floor's step is backward Euler over the whole step and over its two halves, extrapolated
//! (Richardson; second order and L-stable, [`FloorStep::take`]), accepted whatever its
//! estimate: it buys a bound on the work at the price of accuracy, which the estimate reports.

use super::jacobian::eval_jacobian;
use super::lu::Lu;
use super::stepper::Ctx;
use super::system::{OdeSystem, TimeMemo};
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OMatrix, OVector};

/// Most Newton iterations of one floor step.
pub(crate) const FLOOR_NEWTON: usize = 8;

/// Most halvings of one Newton update.
const HALVINGS: usize = 3;

/// The iteration has converged when a full update's weighted norm is at most this (the
/// weights are the error tolerances').
const CONVERGED: f64 = 1e-2;

/// The work vectors of the floor's backward Euler step.
pub(crate) struct FloorStep<D: Dim>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    jac: OMatrix<f64, D, D>,
    lu: Lu<f64, D>,
    f0: OVector<f64, D>,
    f1: OVector<f64, D>,
    y1: OVector<f64, D>,
    res: OVector<f64, D>,
    dy: OVector<f64, D>,
    trial: OVector<f64, D>,
    f_trial: OVector<f64, D>,
    res_trial: OVector<f64, D>,
    work: OVector<f64, D>,
    /// The values of the system's inputs at the step's end.
    memo: TimeMemo,
}

impl<D: Dim> FloorStep<D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// Work vectors for states shaped like `y`.
    pub(crate) fn new(y: &OVector<f64, D>) -> Self {
        let (rows, _) = y.shape_generic();
        FloorStep {
            jac: OMatrix::zeros_generic(rows, rows),
            lu: Lu::new(rows),
            f0: y.clone(),
            f1: y.clone(),
            y1: y.clone(),
            res: y.clone(),
            dy: y.clone(),
            trial: y.clone(),
            f_trial: y.clone(),
            res_trial: y.clone(),
            work: y.clone(),
            memo: TimeMemo::default(),
        }
    }

    /// `f(t, y)` at the step's end into `out`, counted; whether it is finite.
    fn end_rhs<S: OdeSystem<D> + ?Sized>(
        memo: &mut TimeMemo,
        sys: &S,
        t: f64,
        y: &OVector<f64, D>,
        out: &mut OVector<f64, D>,
        ctx: &mut Ctx<D>,
    ) -> bool {
        sys.rhs_memo(t, y, out, memo);
        ctx.stats.rhs_evals += 1;
        out.iter().all(|v| v.is_finite())
    }

    /// The residual `y₁ − y₀ − h f₁` into `out`, and its norm weighted at `y₀` (the same
    /// weights for every iterate, so that the norms compare).
    fn residual(
        y0: &OVector<f64, D>,
        y1: &OVector<f64, D>,
        f1: &OVector<f64, D>,
        h: f64,
        out: &mut OVector<f64, D>,
        ctx: &Ctx<D>,
    ) -> f64 {
        for i in 0..y0.len() {
            out[i] = (y1[i] - y0[i]) - h * f1[i];
        }
        ctx.norm_at(out, y0)
    }

    /// Backward Euler from `(t, y0)` over `h` into `self.y1` (and `f(t + h, y1)` into
    /// `self.f1`); false when the iteration did not converge within [`FLOOR_NEWTON`]
    /// iterations, or met values that are not finite, or a singular matrix.
    fn solve<S: OdeSystem<D> + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        h: f64,
        y0: &OVector<f64, D>,
        ctx: &mut Ctx<D>,
    ) -> bool {
        self.memo.clear();
        let t1 = t + h;
        self.y1.copy_from(y0);
        if !Self::end_rhs(&mut self.memo, sys, t1, &self.y1, &mut self.f1, ctx) {
            return false;
        }
        let mut norm = Self::residual(y0, &self.y1, &self.f1, h, &mut self.res, ctx);
        let n = y0.len();
        for _ in 0..FLOOR_NEWTON {
            if !eval_jacobian(
                sys,
                t1,
                &self.y1,
                &self.f1,
                &mut self.jac,
                &mut self.work,
                ctx,
            ) {
                return false;
            }
            for r in 0..n {
                for c in 0..n {
                    self.lu.m[(r, c)] = -h * self.jac[(r, c)];
                }
                self.lu.m[(r, r)] += 1.0;
            }
            ctx.stats.lu_decomps += 1;
            if !self.lu.factor() {
                return false;
            }
            self.dy.copy_from(&self.res);
            self.lu.solve_mut(&mut self.dy);
            ctx.stats.lin_solves += 1;
            if ctx.err_norm(&self.dy, y0, &self.y1) <= CONVERGED {
                // Converged: the last update is taken whole (the residual is at its rounding
                // here, where a comparison of residuals means nothing).
                self.y1 -= &self.dy;
                return Self::end_rhs(&mut self.memo, sys, t1, &self.y1, &mut self.f1, ctx);
            }
            let mut lambda = 1.0;
            let mut lowered = false;
            for _ in 0..=HALVINGS {
                for i in 0..n {
                    self.trial[i] = self.y1[i] - lambda * self.dy[i];
                }
                if Self::end_rhs(&mut self.memo, sys, t1, &self.trial, &mut self.f_trial, ctx) {
                    let tn =
                        Self::residual(y0, &self.trial, &self.f_trial, h, &mut self.res_trial, ctx);
                    if tn < norm {
                        norm = tn;
                        lowered = true;
                        break;
                    }
                }
                lambda *= 0.5;
            }
            if !lowered {
                return false;
            }
            std::mem::swap(&mut self.y1, &mut self.trial);
            std::mem::swap(&mut self.f1, &mut self.f_trial);
            std::mem::swap(&mut self.res, &mut self.res_trial);
        }
        false
    }

    /// The floor's step from `(t, y)` over `h` into `y_new`, and its weighted error estimate;
    /// `None` when backward Euler over the whole step failed ([`FloorStep::solve`]).
    ///
    /// Backward Euler over `h` and over two halves, extrapolated: `2 y_{h/2} − y_h`, second
    /// order and still L-stable (its stability function `2/(1 − z/2)² − 1/(1 − z)` vanishes as
    /// `z → −∞`), with the weighted `y_{h/2} − y_h` as the estimate. Where the halves fail, or
    /// the extrapolated state's right-hand side is not finite, the state of the whole step
    /// (or of the halves) stands, the whole step with its own estimate,
    /// `(I − hJ)⁻¹ (h/2)(f(t + h, y_h) − f(t, y))`.
    pub(crate) fn take<S: OdeSystem<D> + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        h: f64,
        y: &OVector<f64, D>,
        y_new: &mut OVector<f64, D>,
        ctx: &mut Ctx<D>,
    ) -> Option<f64> {
        ctx.rhs(sys, t, y, &mut self.f0);
        if !self.f0.iter().all(|v| v.is_finite()) || !self.solve(sys, t, h, y, ctx) {
            return None;
        }
        y_new.copy_from(&self.y1);
        // The whole step's own estimate, through the iteration matrix of its last iterate.
        for i in 0..y.len() {
            self.work[i] = 0.5 * h * (self.f1[i] - self.f0[i]);
        }
        self.lu.solve_mut(&mut self.work);
        ctx.stats.lin_solves += 1;
        let whole = ctx.err_norm(&self.work, y, y_new);
        let halves = self.solve(sys, t, 0.5 * h, y, ctx) && {
            let mid = self.y1.clone();
            self.solve(sys, t + 0.5 * h, 0.5 * h, &mid, ctx)
        };
        if !halves {
            return whole.is_finite().then_some(whole);
        }
        // y_{h/2} − y_h, and the extrapolated state.
        self.work.copy_from(&self.y1);
        self.work -= &*y_new;
        let err = ctx.err_norm(&self.work, y, &self.y1);
        for i in 0..y.len() {
            self.trial[i] = 2.0 * self.y1[i] - y_new[i];
        }
        self.memo.clear();
        if Self::end_rhs(
            &mut self.memo,
            sys,
            t + h,
            &self.trial,
            &mut self.f_trial,
            ctx,
        ) {
            y_new.copy_from(&self.trial);
        } else {
            y_new.copy_from(&self.y1);
        }
        err.is_finite().then_some(err)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ode::solution::Stats;
    use nalgebra::{Vector1, Vector2, U1, U2};

    fn ctx<D: Dim>(atol: OVector<f64, D>, rtol: f64) -> Ctx<D>
    where
        DefaultAllocator: Allocator<D>,
    {
        Ctx {
            atol,
            rtol,
            stats: Stats::default(),
            want_stiffness: false,
            need_poly: false,
            memo: TimeMemo::default(),
            stage_memos: [TimeMemo::default(); 3],
        }
    }

    /// `y' = -k y` (linear): the step is the extrapolation's closed form,
    /// `2 y₀/(1 + kh/2)² − y₀/(1 + kh)` (slightly below zero for a step this stiff).
    struct Decay(f64);
    impl OdeSystem<U1> for Decay {
        fn rhs(&self, _t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>) {
            dy[0] = -self.0 * y[0];
        }
    }

    #[test]
    fn a_linear_decay_is_the_extrapolations_closed_form() {
        let mut c = ctx(Vector1::new(1e-12), 1e-9);
        let y = Vector1::new(2.0);
        let mut y1 = y;
        let mut fs = FloorStep::new(&y);
        let (k, h) = (1e6, 1e-3);
        let err = fs.take(&Decay(k), 0.0, h, &y, &mut y1, &mut c).unwrap();
        let z = k * h;
        let exact = 2.0 * 2.0 / (1.0 + z / 2.0).powi(2) - 2.0 / (1.0 + z);
        assert!(
            (y1[0] - exact).abs() <= 1e-14 * exact.abs(),
            "{} {exact}",
            y1[0]
        );
        // A step a thousand times the decay's time: the estimate says it missed.
        assert!(err > 1.0, "{err}");
        // Three solves, each in at most three updates (the Jacobian is a finite difference's,
        // not exact).
        assert!(c.stats.lu_decomps <= 9, "{:?}", c.stats);
    }

    /// On `y' = -y`, where nothing is stiff, the step is second order (its local error falls
    /// eightfold when the step is halved), and the estimate, that of the halves, is first
    /// order: larger than the error, by a ratio that doubles when the step is halved.
    #[test]
    fn the_step_is_second_order_and_its_estimate_bounds_the_error() {
        let (atol, rtol) = (1e-14, 1e-12);
        let mut c = ctx(Vector1::new(atol), rtol);
        let y = Vector1::new(1.0);
        let mut fs = FloorStep::new(&y);
        let mut error = |h: f64| {
            let mut y1 = y;
            let est = fs.take(&Decay(1.0), 0.0, h, &y, &mut y1, &mut c).unwrap();
            let e = (y1[0] - (-h).exp()).abs();
            (e, est * (atol + rtol * y1[0].abs().max(1.0)))
        };
        let ((e1, est1), (e2, est2)) = (error(0.02), error(0.01));
        // 7.80 at these steps (the next term, h⁴, still shows): order 1 would give 4, order 3
        // 16.
        assert!(
            (e1 / e2 - 8.0).abs() < 0.5,
            "{e1:e} {e2:e} ratio {}",
            e1 / e2
        );
        assert!(est1 > e1 && est2 > e2, "{est1:e} {e1:e} {est2:e} {e2:e}");
        let growth = (est2 / e2) / (est1 / e1);
        assert!((growth - 2.0).abs() < 0.2, "{growth}");
    }

    /// A stiff pull onto a cubic wall, `y' = -k (y³ + y - 1)`, from twice its root's height:
    /// each solve meets the implicit equation within its bounded work.
    struct Wall(f64);
    impl OdeSystem<U2> for Wall {
        fn rhs(&self, _t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
            dy[0] = -self.0 * (y[0] * y[0] * y[0] + y[0] - 1.0);
            dy[1] = y[0];
        }
    }

    #[test]
    fn a_stiff_cubic_meets_the_implicit_equation_in_a_bounded_work() {
        let mut c = ctx(Vector2::new(1e-12, 1e-12), 1e-9);
        let y = Vector2::new(2.0, 0.0);
        let mut fs = FloorStep::new(&y);
        let (k, h) = (1e6, 1e-2);
        assert!(fs.solve(&Wall(k), 0.0, h, &y, &mut c));
        // The residual of the implicit equation, in each component.
        let mut f = Vector2::zeros();
        Wall(k).rhs(h, &fs.y1, &mut f);
        let r = fs.y1 - y - h * f;
        assert!(r[0].abs() < 1e-9 && r[1].abs() < 1e-9, "{r}");
        assert!(c.stats.lu_decomps <= FLOOR_NEWTON, "{:?}", c.stats);
        // The Jacobians by finite differences: two more right-hand sides each.
        assert!(
            c.stats.rhs_evals <= 2 + FLOOR_NEWTON * (1 + HALVINGS + 2),
            "{:?}",
            c.stats
        );
        // The whole step: k h = 1e4 lands it within 0.1 % of the wall's root, 0.682328.
        let mut y1 = y;
        fs.take(&Wall(k), 0.0, h, &y, &mut y1, &mut c).unwrap();
        assert!((y1[0] - 0.682_328).abs() < 1e-3 * 0.682_328, "{}", y1[0]);
    }

    /// A pull towards `y = -2` on a right-hand side that is not finite below `y = -1`:
    /// backward Euler's answer lies where nothing is finite, so the step gives up (`None`)
    /// after its bounded work instead of returning an iterate.
    struct Cliff;
    impl OdeSystem<U1> for Cliff {
        fn rhs(&self, _t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>) {
            dy[0] = if y[0] < -1.0 {
                f64::NAN
            } else {
                -1e3 * (y[0] + 2.0)
            };
        }
    }

    #[test]
    fn a_step_whose_answer_is_not_finite_gives_up_in_bounded_work() {
        let mut c = ctx(Vector1::new(1e-9), 1e-6);
        let y = Vector1::new(0.5);
        let mut y1 = y;
        let mut fs = FloorStep::new(&y);
        assert!(fs.take(&Cliff, 0.0, 1.0, &y, &mut y1, &mut c).is_none());
        assert!(c.stats.lu_decomps <= FLOOR_NEWTON, "{:?}", c.stats);
        // The Jacobians by finite differences: one more right-hand side each.
        assert!(
            c.stats.rhs_evals <= 2 + FLOOR_NEWTON * (1 + HALVINGS + 1),
            "{:?}",
            c.stats
        );
    }
}

#[cfg(test)]
mod in_the_integrator {
    use crate::ode::{Integrator, Method, OdeSystem, Options};
    use nalgebra::{Vector1, U1};

    /// `y' = -k y³` from 1: Radau5's simplified Newton iteration, its Jacobian frozen at the
    /// start (`-3k`), fails over a step much longer than `1/k`, where `y` falls by orders.
    struct Cubic(f64);
    impl OdeSystem<U1> for Cubic {
        fn rhs(&self, _t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>) {
            dy[0] = -self.0 * y[0].powi(3);
        }
    }

    /// With a floor of an eighth of the span and no retries, trials Radau5 fails are taken by the floor's
    /// step, which is counted; the state falls, ends within 3 % of the exact `1/√(1 + 2kt)`
    /// (1.7–1.9 %), and the estimate reports the miss. At `k = 100` the floor step takes every
    /// failed trial and the span ends in eight steps; at `k = 1000` and `10 000` one trial
    /// fails it too and is shortened (nine steps).
    #[test]
    fn trials_failed_at_the_floor_are_taken_by_backward_euler() {
        for k in [1e2, 1e3, 1e4] {
            let opts = Options::default().rtol(1e-8).atol(1e-12);
            let y0 = Vector1::new(1.0);
            let mut it = Integrator::new(Cubic(k), 0.0, y0, 1.0, Method::Radau5, &opts).unwrap();
            it.set_step_floor(Some(0.125)).unwrap();
            it.set_floor_retries(Some(0));
            let mut last = 1.0;
            let mut missed = false;
            while it.t() < 1.0 {
                it.step().unwrap();
                let y = it.state()[0];
                assert!(y > 0.0 && y < last, "k {k:e}: {y} after {last}");
                last = y;
                missed |= it.last_error() > 1.0;
            }
            let s = it.stats();
            let exact = 1.0 / (1.0 + 2.0 * k).sqrt();
            assert!(s.floor_steps >= 1, "k {k:e}: {s:?}");
            if k == 1e2 {
                assert_eq!(s.accepted, 8, "{s:?}");
            }
            assert!(
                (last / exact - 1.0).abs() < 0.03,
                "k {k:e}: {last} against {exact}"
            );
            assert!(missed, "k {k:e}");
        }
    }
}
