//! Radau IIA of order 5 (3 stages, L-stable) after Hairer & Wanner, "Solving ODEs II", IV.8:
//! simplified Newton iterations on the eigen-decoupled stage system (one real and one complex
//! LU), Jacobians and factorisations reused while the iteration converges well, the
//! embedded error estimate filtered through (I − hγ₀J)⁻¹, and the collocation polynomial as
//! dense output (order 3).

use super::dense::StepPoly;
use super::jacobian::{eval_jacobian, Radius};
use super::lu::Lu;
use super::stepper::{all_finite, zeros_like, Ctx, FailKind, Step, Stepper, Trial};
use super::system::OdeSystem;
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, Matrix3, OMatrix, OVector, Vector3};
use num_complex::Complex64;
use std::sync::OnceLock;

/// Constants of the method, derived once from the Butcher matrix.
pub(crate) struct RadauConsts {
    pub c: [f64; 3],
    #[cfg_attr(not(test), allow(dead_code))]
    pub a: Matrix3<f64>,
    /// Real eigenvalue γ and complex pair α ± iβ of A⁻¹.
    pub gamma: f64,
    pub alpha: f64,
    pub beta: f64,
    /// A⁻¹ = T Λ T⁻¹ with Λ = [[γ,0,0],[0,α,−β],[0,β,α]].
    pub t: Matrix3<f64>,
    pub t_inv: Matrix3<f64>,
    /// Error estimate weights (Hairer & Wanner IV.8, (8.20)), divided by γ₀ = 1/γ.
    pub dd: [f64; 3],
    /// Collocation polynomial: L_i(θ) = Σ_m lag[i][m−1] θ^m through (0,0), (c_j, δ_ij).
    pub lag: [[f64; 3]; 3],
}

pub(crate) fn consts() -> &'static RadauConsts {
    static C: OnceLock<RadauConsts> = OnceLock::new();
    C.get_or_init(build_consts)
}

fn build_consts() -> RadauConsts {
    let s6 = 6f64.sqrt();
    let c = [(4.0 - s6) / 10.0, (4.0 + s6) / 10.0, 1.0];
    let a = Matrix3::new(
        (88.0 - 7.0 * s6) / 360.0,
        (296.0 - 169.0 * s6) / 1800.0,
        (-2.0 + 3.0 * s6) / 225.0,
        (296.0 + 169.0 * s6) / 1800.0,
        (88.0 + 7.0 * s6) / 360.0,
        (-2.0 - 3.0 * s6) / 225.0,
        (16.0 - s6) / 36.0,
        (16.0 + s6) / 36.0,
        1.0 / 9.0,
    );
    // Eigenvalues of A in closed form (the roots of the stability denominator), inverted.
    let c81 = 81f64.cbrt();
    let c9 = 9f64.cbrt();
    let gamma = 30.0 / (6.0 + c81 - c9);
    let alpha_a = (12.0 - c81 + c9) / 60.0;
    let beta_a = (c81 + c9) * 3f64.sqrt() / 60.0;
    let cno = alpha_a * alpha_a + beta_a * beta_a;
    let alpha = alpha_a / cno;
    let beta = beta_a / cno;
    // A is invertible (its eigenvalues are above); the fallback is never taken.
    let a_inv = a.try_inverse().unwrap_or_else(Matrix3::identity);
    // Eigenvectors as null vectors of A⁻¹ − λI: cross product of two rows.
    let real_vec = {
        let m = a_inv - Matrix3::identity() * gamma;
        let r0 = Vector3::new(m[(0, 0)], m[(0, 1)], m[(0, 2)]);
        let r1 = Vector3::new(m[(1, 0)], m[(1, 1)], m[(1, 2)]);
        r0.cross(&r1)
    };
    let lam = Complex64::new(alpha, beta);
    let mc = a_inv.map(|v| Complex64::new(v, 0.0))
        - Matrix3::identity().map(|v| Complex64::new(v, 0.0)) * lam;
    let r0 = [mc[(0, 0)], mc[(0, 1)], mc[(0, 2)]];
    let r1 = [mc[(1, 0)], mc[(1, 1)], mc[(1, 2)]];
    let w = [
        r0[1] * r1[2] - r0[2] * r1[1],
        r0[2] * r1[0] - r0[0] * r1[2],
        r0[0] * r1[1] - r0[1] * r1[0],
    ];
    // w = t2 − i t3 is the eigenvector of α + iβ for the real block [[α, −β], [β, α]].
    let t = Matrix3::new(
        real_vec[0],
        w[0].re,
        -w[0].im,
        real_vec[1],
        w[1].re,
        -w[1].im,
        real_vec[2],
        w[2].re,
        -w[2].im,
    );
    let t_inv = t.try_inverse().unwrap_or_else(Matrix3::identity);
    let dd = [
        -(13.0 + 7.0 * s6) / 3.0,
        (-13.0 + 7.0 * s6) / 3.0,
        -1.0 / 3.0,
    ];
    // Lagrange basis on (0, c1, c2, 1) vanishing at 0: solve V p = e_i with V_jm = c_j^m.
    let v = Matrix3::from_fn(|j, m| c[j].powi(m as i32 + 1));
    let v_inv = v.try_inverse().unwrap_or_else(Matrix3::identity);
    let mut lag = [[0.0; 3]; 3];
    for (i, li) in lag.iter_mut().enumerate() {
        for (m, l) in li.iter_mut().enumerate() {
            *l = v_inv[(m, i)];
        }
    }
    RadauConsts {
        c,
        a,
        gamma,
        alpha,
        beta,
        t,
        t_inv,
        dd,
        lag,
    }
}

/// Newton iterations per attempt before giving up and halving the step.
const MAX_NEWTON: usize = 7;
/// Convergence rate above which the Jacobian is recomputed at the next step.
const THETA_REUSE_JAC: f64 = 1e-3;
/// Keep the step size (and the LU factors) when the controller asks for a ratio in this range.
const KEEP_H_LOW: f64 = 1.0;
const KEEP_H_HIGH: f64 = 1.2;

pub(crate) struct Radau5<D: Dim>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    f0: OVector<f64, D>,
    f0_valid: bool,
    jac: OMatrix<f64, D, D>,
    /// J was evaluated at the current point.
    jac_fresh: bool,
    /// J must be re-evaluated before the next attempt.
    jac_stale: bool,
    lu_re: Lu<f64, D>,
    lu_cx: Lu<Complex64, D>,
    lu_h: f64,
    z: [OVector<f64, D>; 3],
    w: [OVector<f64, D>; 3],
    f: [OVector<f64, D>; 3],
    cx: OVector<Complex64, D>,
    tmp: OVector<f64, D>,
    cont: OVector<f64, D>,
    f2: OVector<f64, D>,
    /// Inverse weights of the Newton increment's norm, fixed over one attempt.
    newton_weights: OVector<f64, D>,
    /// Stage increments and step of the last accepted step, for the starting guess.
    z_prev: [OVector<f64, D>; 3],
    h_prev: Option<f64>,
    theta: f64,
    /// Newton convergence factor θ/(1 − θ), carried over between steps.
    eta: f64,
    first: bool,
    last_rejected: bool,
    /// Factor applied to the user's tolerances inside the method (1: the error estimate is
    /// compared with the tolerances as given, which keeps the global error proportional to
    /// the tolerance; Hairer's code uses 0.1 rtol^(2/3) instead).
    tol_scale: f64,
    newton_tol: f64,
    /// Spectral radius of the last Jacobian, when stiffness switching asks for it.
    rho: Radius,
}

impl<D: Dim> Radau5<D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    pub fn new(y: &OVector<f64, D>, rtol: f64) -> Self {
        let z = zeros_like(y);
        let (r, _) = y.shape_generic();
        let rtol_inner = rtol;
        Radau5 {
            f0: z.clone(),
            f0_valid: false,
            jac: OMatrix::zeros_generic(r, r),
            jac_fresh: false,
            jac_stale: true,
            lu_re: Lu::new(r),
            lu_cx: Lu::new(r),
            lu_h: f64::NAN,
            z: std::array::from_fn(|_| z.clone()),
            w: std::array::from_fn(|_| z.clone()),
            f: std::array::from_fn(|_| z.clone()),
            cx: y.map(|_| Complex64::new(0.0, 0.0)),
            tmp: z.clone(),
            cont: z.clone(),
            f2: z.clone(),
            newton_weights: z.clone(),
            z_prev: std::array::from_fn(|_| z.clone()),
            h_prev: None,
            theta: 1.0,
            eta: 1.0,
            first: true,
            last_rejected: false,
            tol_scale: rtol_inner / rtol,
            newton_tol: (10.0 * f64::EPSILON / rtol_inner).max(0.03f64.min(rtol_inner.sqrt())),
            rho: Radius::default(),
        }
    }

    /// Follows a change of the relative tolerance between steps.
    pub fn set_rtol(&mut self, rtol: f64) {
        self.tol_scale = 1.0;
        self.newton_tol = (10.0 * f64::EPSILON / rtol).max(0.03f64.min(rtol.sqrt()));
    }

    fn norm(
        &self,
        v: &OVector<f64, D>,
        y0: &OVector<f64, D>,
        y1: &OVector<f64, D>,
        ctx: &Ctx<D>,
    ) -> f64 {
        ctx.err_norm(v, y0, y1) / self.tol_scale
    }

    /// Factors γ/h − J (real) and (α + iβ)/h − J (complex); `false` if either is singular.
    fn factor(&mut self, h: f64, ctx: &mut Ctx<D>) -> bool {
        let k = consts();
        let n = self.jac.nrows();
        let g = k.gamma / h;
        let lam = Complex64::new(k.alpha / h, k.beta / h);
        let jac = self.jac.as_slice();
        let re = self.lu_re.m.as_mut_slice();
        for (r, j) in re.iter_mut().zip(jac) {
            *r = -j;
        }
        let cx = self.lu_cx.m.as_mut_slice();
        for (c, j) in cx.iter_mut().zip(jac) {
            *c = Complex64::new(-j, 0.0);
        }
        for i in 0..n {
            re[i * n + i] += g;
            cx[i * n + i] += lam;
        }
        ctx.stats.lu_decomps += 2;
        let ok = self.lu_re.factor() && self.lu_cx.factor();
        self.lu_h = if ok { h } else { f64::NAN };
        ok
    }

    /// The start of a step: `f(t, y)`, a fresh Jacobian when the last is stale, and the
    /// factored iteration matrices for `h`; the failed trial otherwise.
    fn prepare<S: OdeSystem<D> + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        y: &OVector<f64, D>,
        h: f64,
        ctx: &mut Ctx<D>,
    ) -> Result<(), Trial> {
        if !self.f0_valid {
            ctx.rhs(sys, t, y, &mut self.f0);
            self.f0_valid = true;
        }
        if !all_finite(&self.f0) {
            return Err(Trial::Failed {
                factor: 0.5,
                kind: FailKind::NonFinite,
            });
        }
        if self.jac_stale {
            if !eval_jacobian(sys, t, y, &self.f0, &mut self.jac, &mut self.tmp, ctx) {
                return Err(Trial::Failed {
                    factor: 0.5,
                    kind: FailKind::NonFinite,
                });
            }
            self.jac_stale = false;
            self.jac_fresh = true;
            self.lu_h = f64::NAN;
            if ctx.want_stiffness {
                self.rho.at_new_jacobian(&self.jac);
            }
        }
        if self.lu_h != h && !self.factor(h, ctx) {
            return Err(Trial::Failed {
                factor: 0.5,
                kind: FailKind::Singular,
            });
        }
        Ok(())
    }

    /// The Newton iteration's starting guess for the stage increments `Z` (and `W = T⁻¹Z`).
    fn starting_guess(&mut self, h: f64) {
        let k = consts();
        // Starting guess: the previous collocation polynomial extrapolated, else zero.
        match self.h_prev {
            Some(hp) => {
                for i in 0..3 {
                    let theta = 1.0 + k.c[i] * h / hp;
                    self.z[i].fill(0.0);
                    for j in 0..3 {
                        let l = &k.lag[j];
                        let lj = theta * (l[0] + theta * (l[1] + theta * l[2]));
                        self.z[i].axpy(lj, &self.z_prev[j], 1.0);
                    }
                    self.z[i] -= &self.z_prev[2];
                }
            }
            None => {
                for z in self.z.iter_mut() {
                    z.fill(0.0);
                }
            }
        }
        for i in 0..3 {
            self.w[i].fill(0.0);
            for j in 0..3 {
                self.w[i].axpy(k.t_inv[(i, j)], &self.z[j], 1.0);
            }
        }
    }

    /// The simplified Newton iteration on the collocation equations, in the variables `W`
    /// that decouple the real and complex blocks; the failed trial when it does not converge.
    fn newton<S: OdeSystem<D> + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        y: &OVector<f64, D>,
        h: f64,
        ctx: &mut Ctx<D>,
    ) -> Result<(), Trial> {
        let k = consts();
        let n = y.len();
        // Inverse weights of the increment's norm, fixed over the iteration (no division in it).
        for r in 0..n {
            self.newton_weights[r] = 1.0 / ((ctx.atol[r] + ctx.rtol * y[r].abs()) * self.tol_scale);
        }
        let mut converged = false;
        let mut dnorm_old = 0.0f64;
        self.theta = 1.0;
        for it in 0..MAX_NEWTON {
            for i in 0..3 {
                self.tmp.copy_from(y);
                self.tmp += &self.z[i];
                sys.rhs_memo(
                    t + k.c[i] * h,
                    &self.tmp,
                    &mut self.f[i],
                    &mut ctx.stage_memos[i],
                );
            }
            ctx.stats.rhs_evals += 3;
            ctx.stats.newton_iters += 1;
            if !self.f.iter().all(all_finite) {
                ctx.stats.newton_failures += 1;
                return Err(Trial::Failed {
                    factor: 0.5,
                    kind: FailKind::NonFinite,
                });
            }
            // Right-hand sides in transformed variables: T⁻¹F − (Λ/h) W.
            let (g, al, be) = (k.gamma / h, k.alpha / h, k.beta / h);
            let mut dnorm_sq = 0.0;
            for r in 0..n {
                let fr = [self.f[0][r], self.f[1][r], self.f[2][r]];
                let tf = |i: usize| {
                    k.t_inv[(i, 0)] * fr[0] + k.t_inv[(i, 1)] * fr[1] + k.t_inv[(i, 2)] * fr[2]
                };
                let (w1, w2, w3) = (self.w[0][r], self.w[1][r], self.w[2][r]);
                self.tmp[r] = tf(0) - g * w1;
                self.cx[r] =
                    Complex64::new(tf(1) - (al * w2 - be * w3), tf(2) - (be * w2 + al * w3));
            }
            self.lu_re.solve_mut(&mut self.tmp);
            self.lu_cx.solve_mut(&mut self.cx);
            ctx.stats.lin_solves += 2;
            // Update W and Z; measure the increment in Z (independent of T's scaling).
            for r in 0..n {
                let dw = [self.tmp[r], self.cx[r].re, self.cx[r].im];
                for (wi, dwi) in self.w.iter_mut().zip(dw) {
                    wi[r] += dwi;
                }
                let wr = self.newton_weights[r];
                for i in 0..3 {
                    let dz = k.t[(i, 0)] * dw[0] + k.t[(i, 1)] * dw[1] + k.t[(i, 2)] * dw[2];
                    self.z[i][r] += dz;
                    dnorm_sq += (dz * wr) * (dz * wr);
                }
            }
            let dnorm = (dnorm_sq / (3 * n) as f64).sqrt();
            if !dnorm.is_finite() {
                break;
            }
            if it >= 1 {
                let theta = dnorm / dnorm_old.max(f64::MIN_POSITIVE);
                self.theta = theta;
                if theta >= 0.99 {
                    break;
                }
                // Would the remaining iterations reach the tolerance at this rate?
                let left = (MAX_NEWTON - 1 - it) as i32;
                if theta.powi(left) / (1.0 - theta) * dnorm > self.newton_tol {
                    break;
                }
                self.eta = theta / (1.0 - theta);
            } else {
                // No rate yet: the previous step's, relaxed towards 1.
                self.eta = self.eta.max(f64::EPSILON).powf(0.8);
            }
            dnorm_old = dnorm;
            if self.eta * dnorm <= self.newton_tol || dnorm == 0.0 {
                converged = true;
                break;
            }
        }
        if !converged {
            ctx.stats.newton_failures += 1;
            // A Jacobian from an earlier point may be the cause: refresh it.
            if !self.jac_fresh {
                self.jac_stale = true;
            }
            return Err(Trial::Failed {
                factor: 0.5,
                kind: FailKind::Newton,
            });
        }
        Ok(())
    }

    /// The scaled error of the step from `y` to `y_new`; marks the Jacobian stale after a
    /// rejection.
    fn error_estimate<S: OdeSystem<D> + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        y: &OVector<f64, D>,
        y_new: &OVector<f64, D>,
        h: f64,
        ctx: &mut Ctx<D>,
    ) -> f64 {
        let k = consts();
        // Error estimate: (γ/h − J)⁻¹ (f0 + Σ dd_i Z_i / h), a second filtered pass when the
        // first is large after a rejection (it can be unreliable for very stiff components).
        self.f2.fill(0.0);
        for i in 0..3 {
            self.f2.axpy(k.dd[i] / h, &self.z[i], 1.0);
        }
        self.cont.copy_from(&self.f2);
        self.cont += &self.f0;
        self.lu_re.solve_mut(&mut self.cont);
        ctx.stats.lin_solves += 1;
        let mut err = self.norm(&self.cont, y, y_new, ctx);
        if err >= 1.0 && (self.first || self.last_rejected) {
            self.tmp.copy_from(y);
            self.tmp += &self.cont;
            ctx.rhs(sys, t, &self.tmp, &mut self.cont);
            self.cont += &self.f2;
            self.lu_re.solve_mut(&mut self.cont);
            ctx.stats.lin_solves += 1;
            err = self.norm(&self.cont, y, y_new, ctx);
        }
        self.last_rejected = err > 1.0;
        // Recompute J after a rejection unless it is already current.
        if err > 1.0 && !self.jac_fresh {
            self.jac_stale = true;
        }
        err
    }
}

impl<D: Dim, S: OdeSystem<D> + ?Sized> Stepper<D, S> for Radau5<D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn error_order(&self) -> f64 {
        4.0
    }

    fn restart(&mut self, sys: &S, t: f64, y: &OVector<f64, D>, ctx: &mut Ctx<D>) {
        ctx.rhs(sys, t, y, &mut self.f0);
        self.f0_valid = true;
        self.jac_stale = true;
        self.h_prev = None;
        self.first = true;
    }

    fn f0(&self) -> &OVector<f64, D> {
        &self.f0
    }

    fn attempt(&mut self, sys: &S, step: Step<'_, D>, ctx: &mut Ctx<D>) -> Trial {
        let Step { t, h, y, y_new } = step;
        if let Err(failed) = self.prepare(sys, t, y, h, ctx) {
            return failed;
        }
        self.starting_guess(h);
        if let Err(failed) = self.newton(sys, t, y, h, ctx) {
            return failed;
        }
        y_new.copy_from(y);
        *y_new += &self.z[2];
        if !all_finite(y_new) {
            return Trial::Failed {
                factor: 0.5,
                kind: FailKind::NonFinite,
            };
        }
        let err = self.error_estimate(sys, t, y, y_new, h, ctx);
        Trial::Done { err }
    }

    fn accept(&mut self, _sys: &S, step: &Step<'_, D>, poly: &mut StepPoly, ctx: &mut Ctx<D>) {
        let Step { t, h, y, .. } = *step;
        let k = consts();
        if ctx.need_poly {
            poly.begin(t, h, 3);
            for i in 0..y.len() {
                *poly.at(0, i) = y[i];
                for m in 1..=3 {
                    let mut a = 0.0;
                    for j in 0..3 {
                        a += k.lag[j][m - 1] * self.z[j][i];
                    }
                    *poly.at(m, i) = a;
                }
            }
        }
        // f at the new point is evaluated at the next attempt (the last Newton evaluation
        // preceded the final update of Z).
        self.f0_valid = false;
        for i in 0..3 {
            std::mem::swap(&mut self.z_prev[i], &mut self.z[i]);
        }
        self.h_prev = Some(h);
        self.first = false;
        self.last_rejected = false;
        self.jac_fresh = false;
        if self.theta > THETA_REUSE_JAC {
            self.jac_stale = true;
        }
    }

    fn stiffness(&self) -> Option<f64> {
        self.rho.get()
    }

    fn stiffness_exact(&mut self) -> Option<f64> {
        self.rho.exact(&self.jac, &self.f0)
    }

    fn propose(&self, h_acc: f64, h_new: f64) -> f64 {
        let q = h_new / h_acc;
        if !self.jac_stale && (KEEP_H_LOW..=KEEP_H_HIGH).contains(&q) {
            h_acc
        } else {
            h_new
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tableau_satisfies_order_conditions() {
        let k = consts();
        // B(5): Σ b_j c_j^(q−1) = 1/q, q = 1..5 (b = last row of A).
        for q in 1..=5 {
            let s: f64 = (0..3).map(|j| k.a[(2, j)] * k.c[j].powi(q - 1)).sum();
            assert!((s - 1.0 / q as f64).abs() < 1e-14, "B({q}): {s}");
        }
        // C(3): Σ_j a_ij c_j^(q−1) = c_i^q / q.
        for i in 0..3 {
            for q in 1..=3 {
                let s: f64 = (0..3).map(|j| k.a[(i, j)] * k.c[j].powi(q - 1)).sum();
                assert!((s - k.c[i].powi(q) / q as f64).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn transformation_diagonalises_a_inverse() {
        let k = consts();
        let a_inv = k.a.try_inverse().unwrap();
        let lam = k.t_inv * a_inv * k.t;
        let expect = Matrix3::new(
            k.gamma, 0.0, 0.0, 0.0, k.alpha, -k.beta, 0.0, k.beta, k.alpha,
        );
        assert!((lam - expect).amax() < 1e-12, "{lam}");
    }

    #[test]
    fn error_weights_annihilate_constant_derivative() {
        // For y' = 1 (Z_i = c_i h), f0 + Σ dd_i Z_i / h must vanish.
        let k = consts();
        let s: f64 = 1.0 + (0..3).map(|i| k.dd[i] * k.c[i]).sum::<f64>();
        assert!(s.abs() < 1e-14);
    }

    #[test]
    fn lagrange_basis_interpolates_nodes() {
        let k = consts();
        for i in 0..3 {
            for j in 0..3 {
                let th = k.c[j];
                let l = &k.lag[i];
                let v = th * (l[0] + th * (l[1] + th * l[2]));
                assert!((v - if i == j { 1.0 } else { 0.0 }).abs() < 1e-13);
            }
        }
    }
}
