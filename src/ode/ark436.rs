//! The additive Runge–Kutta pair ARK4(3)6L\[2\]SA of Kennedy and Carpenter (Appl. Numer. Math.
//! 44 (2003) 139–181, Table 6 of their appendix): an explicit method and an L-stable, stiffly
//! accurate ESDIRK that share their nodes and weights, order 4 with an embedded order 3, six
//! stages.
//!
//! Here the split is by rows: the rows the system declares stiff ([`OdeSystem::stiff_diagonal`],
//! each affine in its own state with the declared slope and free of the other stiff rows) are
//! the implicit part, with their whole rate, and the other rows the explicit part. A stage then
//! forms the explicit rows first, then solves each stiff row `Z = R + hγ f(Z)` by one division
//! (exact for a row affine in its own state), with no Jacobian and no factorisation. A fast
//! relaxation that would hold an explicit step at its stability bound then costs what an
//! explicit step costs (six right-hand sides, the last one handed on to the next step) and five
//! evaluations of the stiff rows alone ([`OdeSystem::stiff_rates`]).
//!
//! The error estimate of a declared row is filtered through that row's stage solve,
//! `(1 − hγλ)⁻¹ h Σ (b_j − b̂_j) f_j`, as Hairer and Wanner filter Radau IIA's estimate with
//! `(I − hγ₀J)⁻¹` (Solving Ordinary Differential Equations II, Sect. IV.8). The embedded weights
//! are not L-stable, so the raw estimate grows with `h|λ|` on a row that follows its moving
//! target. On `ẋ = λ(x − cos ωt)` with `λ = −1e7` and `ω = 1.3e5`, one step from the exact
//! solution at `hλ` from −3 to −100, the raw estimate is 1.4–8.3 times the step's true error
//! and the filtered one 0.32–0.80 times (the test below). The filtered estimate thus errs on the
//! short side, by up to a factor of 3, on a row whose local errors the stiff decay damps rather
//! than accumulates. On the meniscus's formation branch the raw estimate of the closest
//! approach held the steps (8 575 at 0.6 V); filtered, the paper cycle takes 7 622, with
//! touchdown and take-off as close to a hundredfold tighter run as before (docs/benchmarks.md,
//! "The formation branch on an additive pair").
//!
//! (Splitting `f = (f − Λy) + Λy` instead would leave a stiff row's target, `−Λu` for
//! `ẋ = Λ(x − u)`, in the explicit part: the two tables then integrate it differently, an error
//! of order `hΛ·h·u̇` that a step far beyond `1/|Λ|` does not tolerate.)

use super::dense::StepPoly;
use super::stepper::{all_finite, zeros_like, Ctx, FailKind, Step, Stepper, Trial};
use super::system::OdeSystem;
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OVector};

/// Stages.
const S: usize = 6;

/// The ESDIRK's diagonal.
const GAMMA: f64 = 0.25;

/// Nodes.
const C: [f64; S] = [0.0, 0.5, 83.0 / 250.0, 31.0 / 50.0, 17.0 / 20.0, 1.0];

/// The explicit method's coefficients (strictly lower triangular).
const AE: [[f64; S]; S] = [
    [0.0; S],
    [0.5, 0.0, 0.0, 0.0, 0.0, 0.0],
    [13861.0 / 62500.0, 6889.0 / 62500.0, 0.0, 0.0, 0.0, 0.0],
    [
        -116_923_316_275.0 / 2_393_684_061_468.0,
        -2_731_218_467_317.0 / 15_368_042_101_831.0,
        9_408_046_702_089.0 / 11_113_171_139_209.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        -451_086_348_788.0 / 2_902_428_689_909.0,
        -2_682_348_792_572.0 / 7_519_795_681_897.0,
        12_662_868_775_082.0 / 11_960_479_115_383.0,
        3_355_817_975_965.0 / 11_060_851_509_271.0,
        0.0,
        0.0,
    ],
    [
        647_845_179_188.0 / 3_216_320_057_751.0,
        73_281_519_250.0 / 8_382_639_484_533.0,
        552_539_513_391.0 / 3_454_668_386_233.0,
        3_354_512_671_639.0 / 8_306_763_924_573.0,
        4040.0 / 17871.0,
        0.0,
    ],
];

/// The implicit method's coefficients below the diagonal (the diagonal is [`GAMMA`] from the
/// second stage on; the first stage is explicit).
const AI: [[f64; S]; S] = [
    [0.0; S],
    [0.25, 0.0, 0.0, 0.0, 0.0, 0.0],
    [8611.0 / 62500.0, -1743.0 / 31250.0, 0.0, 0.0, 0.0, 0.0],
    [
        5_012_029.0 / 34_652_500.0,
        -654_441.0 / 2_922_500.0,
        174_375.0 / 388_108.0,
        0.0,
        0.0,
        0.0,
    ],
    [
        15_267_082_809.0 / 155_376_265_600.0,
        -71_443_401.0 / 120_774_400.0,
        730_878_875.0 / 902_184_768.0,
        2_285_395.0 / 8_070_912.0,
        0.0,
        0.0,
    ],
    [B[0], B[1], B[2], B[3], B[4], 0.0],
];

/// The weights of both methods (the implicit one is stiffly accurate: its last row).
const B: [f64; S] = [
    82889.0 / 524_892.0,
    0.0,
    15625.0 / 83664.0,
    69875.0 / 102_672.0,
    -2260.0 / 8211.0,
    0.25,
];

/// The embedded third-order weights.
const BHAT: [f64; S] = [
    4_586_570_599.0 / 29_645_900_160.0,
    0.0,
    178_811_875.0 / 945_068_544.0,
    814_220_225.0 / 1_159_782_912.0,
    -3_700_637.0 / 11_593_932.0,
    61727.0 / 225_920.0,
];

/// The ARK4(3)6L\[2\]SA stepper: `F_j` are the full right-hand sides at the stage inputs `Z_j`,
/// the first of which is the step's start (handed on from the last step's end).
pub(crate) struct Ark436<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    f: [OVector<f64, D>; S],
    /// The stage input being built.
    z: OVector<f64, D>,
    /// The stiff rows' rates at it.
    rates: OVector<f64, D>,
    /// `f` at the end of the last attempt (the next step's `F_0` once it is accepted).
    f_end: OVector<f64, D>,
    /// The declared diagonal `Λ`, frozen over an attempt.
    lambda: OVector<f64, D>,
    err: OVector<f64, D>,
}

impl<D: Dim> Ark436<D>
where
    DefaultAllocator: Allocator<D>,
{
    pub fn new(y: &OVector<f64, D>) -> Self {
        let z = zeros_like(y);
        Ark436 {
            f: std::array::from_fn(|_| z.clone()),
            z: z.clone(),
            rates: z.clone(),
            f_end: z.clone(),
            lambda: z.clone(),
            err: z,
        }
    }
}

impl<D: Dim, Sys: OdeSystem<D> + ?Sized> Stepper<D, Sys> for Ark436<D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn error_order(&self) -> f64 {
        4.0
    }

    fn restart(&mut self, sys: &Sys, t: f64, y: &OVector<f64, D>, ctx: &mut Ctx<D>) {
        ctx.rhs(sys, t, y, &mut self.f[0]);
    }

    fn f0(&self) -> &OVector<f64, D> {
        &self.f[0]
    }

    fn attempt(&mut self, sys: &Sys, step: Step<'_, D>, ctx: &mut Ctx<D>) -> Trial {
        let Step { t, h, y, y_new } = step;
        let declared = sys.stiff_diagonal(t, y, &mut self.lambda);
        if !declared {
            self.lambda.fill(0.0);
        }
        let n = y.len();
        for s in 1..S {
            let zs = &mut self.z;
            // The explicit rows from the explicit coefficients, the stiff rows' known part from
            // the implicit ones.
            for i in 0..n {
                let a = if self.lambda[i] == 0.0 {
                    &AE[s]
                } else {
                    &AI[s]
                };
                let mut sum = 0.0;
                for (aj, fj) in a[..s].iter().zip(&self.f) {
                    sum += aj * fj[i];
                }
                zs[i] = y[i] + h * sum;
            }
            // The stiff rows: `Z = R + hγ f(Z)` with `f` affine in the row's own state.
            if declared {
                sys.stiff_rates(t + C[s] * h, zs, &mut self.rates);
                for i in 0..n {
                    let l = self.lambda[i];
                    if l != 0.0 {
                        zs[i] += h * GAMMA * self.rates[i] / (1.0 - h * GAMMA * l);
                    }
                }
            }
            let (_, fr) = self.f.split_at_mut(s);
            sys.rhs_memo(t + C[s] * h, zs, &mut fr[0], &mut ctx.memo);
        }
        for i in 0..n {
            let (mut sum, mut e) = (0.0, 0.0);
            for j in 0..S {
                sum += B[j] * self.f[j][i];
                e += (B[j] - BHAT[j]) * self.f[j][i];
            }
            y_new[i] = y[i] + h * sum;
            // A declared row's estimate filtered through its stage solve (module docs).
            self.err[i] = h * e / (1.0 - h * GAMMA * self.lambda[i]);
        }
        // The last stage and the end share t + h: the system's values of that time are kept.
        sys.rhs_memo(t + h, y_new, &mut self.f_end, &mut ctx.memo);
        ctx.stats.rhs_evals += S;
        if !all_finite(y_new) || !all_finite(&self.f_end) {
            return Trial::Failed {
                factor: 0.25,
                kind: FailKind::NonFinite,
            };
        }
        Trial::Done {
            err: ctx.err_norm(&self.err, y, y_new),
        }
    }

    /// The interpolant is the cubic Hermite polynomial of the step's ends and their slopes.
    fn accept(&mut self, _sys: &Sys, step: &Step<'_, D>, poly: &mut StepPoly, ctx: &mut Ctx<D>) {
        let Step { t, h, y, .. } = *step;
        if ctx.need_poly {
            poly.begin(t, h, 3);
            let y1 = &*step.y_new;
            for i in 0..y.len() {
                let (f0, f1) = (h * self.f[0][i], h * self.f_end[i]);
                let dy = y1[i] - y[i];
                *poly.at(0, i) = y[i];
                *poly.at(1, i) = f0;
                *poly.at(2, i) = 3.0 * dy - 2.0 * f0 - f1;
                *poly.at(3, i) = f0 + f1 - 2.0 * dy;
            }
        }
        std::mem::swap(&mut self.f[0], &mut self.f_end);
    }

    /// No estimate: the explicit part's stiffness is not watched while the declared diagonal
    /// is stepped implicitly.
    fn stiffness(&self) -> Option<f64> {
        None
    }

    /// The explicit part's boundary is not a limit for the declared diagonal; the method is
    /// not stiff for the rest of the system.
    fn stability_boundary(&self) -> f64 {
        super::tsit5::STABILITY_BOUNDARY
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ode::solution::Stats;
    use crate::ode::TimeMemo;
    use nalgebra::{Vector2, U2};

    /// `x′ = λ (x − cos t)`, `t′ = 1`: the first row stiff (declared) or not.
    struct Relax {
        lambda: f64,
        declared: bool,
    }

    impl OdeSystem<U2> for Relax {
        fn rhs(&self, _t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
            dy[0] = self.lambda * (y[0] - y[1].cos());
            dy[1] = 1.0;
        }
        fn stiff_diagonal(&self, _t: f64, _y: &Vector2<f64>, l: &mut Vector2<f64>) -> bool {
            *l = Vector2::new(self.lambda, 0.0);
            self.declared
        }
    }

    /// The solution from `x(0) = 1`: `A cos t + B sin t + (1 − A) e^{λt}`, with
    /// `A = λ²/(1 + λ²)` and `B = −λ/(1 + λ²)`.
    fn exact(lambda: f64, t: f64) -> f64 {
        let (a, b) = (
            lambda * lambda / (1.0 + lambda * lambda),
            -lambda / (1.0 + lambda * lambda),
        );
        a * t.cos() + b * t.sin() + (1.0 - a) * (lambda * t).exp()
    }

    /// `x(1)` in `n` fixed steps, or `None` when a step is not finite.
    fn fixed_steps(sys: &Relax, n: usize) -> Option<f64> {
        let mut y = Vector2::new(1.0, 0.0);
        let mut ctx = Ctx {
            atol: Vector2::new(1.0, 1.0),
            rtol: 1.0,
            stats: Stats::default(),
            want_stiffness: false,
            need_poly: false,
            memo: TimeMemo::default(),
            stage_memos: [TimeMemo::default(); 3],
        };
        let mut m = Ark436::new(&y);
        let mut poly = StepPoly::new(2);
        m.restart(sys, 0.0, &y, &mut ctx);
        let h = 1.0 / n as f64;
        let mut y_new = y;
        for k in 0..n {
            let t = k as f64 * h;
            let step = Step {
                t,
                h,
                y: &y,
                y_new: &mut y_new,
            };
            if let Trial::Failed { .. } = m.attempt(sys, step, &mut ctx) {
                return None;
            }
            let step = Step {
                t,
                h,
                y: &y,
                y_new: &mut y_new,
            };
            m.accept(sys, &step, &mut poly, &mut ctx);
            y = y_new;
        }
        Some(y[0])
    }

    /// Fourth order on a smooth problem, with its row declared stiff or not: halving the step
    /// divides the error by 2⁴ = 16, within ±25 %.
    #[test]
    fn fourth_order_split_or_not() {
        for declared in [false, true] {
            let sys = Relax {
                lambda: -2.0,
                declared,
            };
            let err = |n| (fixed_steps(&sys, n).unwrap() - exact(-2.0, 1.0)).abs();
            let (e1, e2, e3) = (err(10), err(20), err(40));
            for r in [e1 / e2, e2 / e3] {
                assert!(
                    (12.0..20.0).contains(&r),
                    "declared {declared}: {e1:e} {e2:e} {e3:e}"
                );
            }
        }
    }

    /// A relaxation of rate 1e8 stepped at h = 0.01 (hλ = −1e6): declared, the row follows
    /// its moving target to within 1e-10 of the exact solution (1.1e-12 measured); undeclared, the explicit method
    /// blows up.
    #[test]
    fn a_declared_stiff_row_follows_its_target_far_beyond_the_explicit_bound() {
        let lambda = -1e8;
        let x = fixed_steps(
            &Relax {
                lambda,
                declared: true,
            },
            100,
        )
        .unwrap();
        assert!(
            (x - exact(lambda, 1.0)).abs() < 1e-10,
            "{x} against {}",
            exact(lambda, 1.0)
        );
        let blown = fixed_steps(
            &Relax {
                lambda,
                declared: false,
            },
            100,
        );
        assert!(blown.is_none_or(|x| x.abs() > 1e10), "{blown:?}");
    }

    /// One step from the exact solution of `x′ = λ (x − cos ωt)` (λ = −1e7, ω = 1.3e5, the
    /// row declared) at `hλ` from −1 to −100: the filtered estimate stays within a factor of
    /// 4 of the step's true error (0.32–1.7 measured), where the raw one (the filter undone)
    /// exceeds it by up to 8.3 times and grows with `h|λ|`.
    #[test]
    fn the_filtered_estimate_of_a_declared_row_tracks_its_true_error() {
        struct Forced {
            lambda: f64,
            w: f64,
        }
        impl OdeSystem<U2> for Forced {
            fn rhs(&self, _t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
                dy[0] = self.lambda * (y[0] - (self.w * y[1]).cos());
                dy[1] = 1.0;
            }
            fn stiff_diagonal(&self, _t: f64, _y: &Vector2<f64>, l: &mut Vector2<f64>) -> bool {
                *l = Vector2::new(self.lambda, 0.0);
                true
            }
        }
        let (lambda, w) = (-1e7, 1.3e5);
        let sys = Forced { lambda, w };
        // The solution without a transient: A cos ωt + B sin ωt.
        let d = lambda * lambda + w * w;
        let (a, b) = (lambda * lambda / d, -lambda * w / d);
        let exact = |t: f64| a * (w * t).cos() + b * (w * t).sin();
        let mut raw_ratios = vec![];
        for hl in [-1.0, -3.0, -10.0, -30.0, -100.0] {
            let (t0, h) = (1e-5, hl / lambda);
            let y = Vector2::new(exact(t0), t0);
            let mut ctx = Ctx {
                atol: Vector2::new(1.0, 1.0),
                rtol: 0.0,
                stats: Stats::default(),
                want_stiffness: false,
                need_poly: false,
                memo: TimeMemo::default(),
                stage_memos: [TimeMemo::default(); 3],
            };
            let mut m = Ark436::new(&y);
            m.restart(&sys, t0, &y, &mut ctx);
            let mut y_new = y;
            let step = Step {
                t: t0,
                h,
                y: &y,
                y_new: &mut y_new,
            };
            let Trial::Done { err } = m.attempt(&sys, step, &mut ctx) else {
                panic!("the step at hλ = {hl} failed");
            };
            // The norm is the root mean square over the two rows; the second has no error.
            let estimate = err * 2f64.sqrt();
            let truth = (y_new[0] - exact(t0 + h)).abs();
            let ratio = estimate / truth;
            assert!(
                (0.25..4.0).contains(&ratio),
                "hλ = {hl}: {estimate:e} against {truth:e}"
            );
            raw_ratios.push(ratio * (1.0 - h * GAMMA * lambda));
        }
        assert!(
            raw_ratios[4] > 5.0 && raw_ratios[4] > raw_ratios[1],
            "{raw_ratios:?}"
        );
    }

    /// The order conditions of the pair up to order 4 (order 3 for the embedded weights),
    /// including the coupling conditions between the explicit and implicit coefficients: each
    /// holds to rounding, so the coefficients above carry no typing error.
    #[test]
    fn the_coefficients_satisfy_the_order_conditions() {
        let mut ai = AI;
        for (s, row) in ai.iter_mut().enumerate().skip(1) {
            row[s] = GAMMA;
        }
        let rows = |a: &[[f64; S]; S], v: &[f64; S]| -> [f64; S] {
            std::array::from_fn(|i| (0..S).map(|j| a[i][j] * v[j]).sum())
        };
        let dot = |b: &[f64; S], v: &[f64; S]| -> f64 { (0..S).map(|j| b[j] * v[j]).sum() };
        let ones = [1.0; S];
        for a in [&AE, &ai] {
            let rs = rows(a, &ones);
            for i in 0..S {
                assert!((rs[i] - C[i]).abs() < 1e-14, "row sum {i}: {}", rs[i]);
            }
        }
        let c2: [f64; S] = std::array::from_fn(|i| C[i] * C[i]);
        let c3: [f64; S] = std::array::from_fn(|i| C[i] * C[i] * C[i]);
        for (b, order) in [(&B, 4), (&BHAT, 3)] {
            let mut conds = vec![dot(b, &ones) - 1.0, dot(b, &C) - 0.5];
            for a1 in [&AE, &ai] {
                let ac = rows(a1, &C);
                conds.push(dot(b, &c2) - 1.0 / 3.0);
                conds.push(dot(b, &ac) - 1.0 / 6.0);
                if order == 4 {
                    conds.push(dot(b, &c3) - 0.25);
                    let cac: [f64; S] = std::array::from_fn(|i| C[i] * ac[i]);
                    conds.push(dot(b, &cac) - 1.0 / 8.0);
                    conds.push(dot(b, &rows(a1, &c2)) - 1.0 / 12.0);
                    for a2 in [&AE, &ai] {
                        conds.push(dot(b, &rows(a2, &rows(a1, &C))) - 1.0 / 24.0);
                    }
                }
            }
            for (k, c) in conds.iter().enumerate() {
                assert!(
                    c.abs() < 1e-13,
                    "weights of order {order}, condition {k}: {c}"
                );
            }
        }
    }
}
