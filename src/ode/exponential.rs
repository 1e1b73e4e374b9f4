//! Exponential integration with a held matrix: the matrix exponential of a small dense matrix,
//! the φ-functions, and a second-order exponential step with an error estimate
//! ([`ExponentialStepper`]).

use super::OdeError;
use nalgebra::DMatrix;

/// The exponential of a square matrix: Padé's [6/6] approximant of `e^{A/2^s}`, squared `s`
/// times, with `s` the least that brings the 1-norm of `A/2^s` to 1/2 or below (a relative
/// truncation error below 1e-16).
///
/// ```
/// use hdi_tribology::nalgebra::DMatrix;
/// use hdi_tribology::ode::expm;
/// // A rotation by 2 rad.
/// let a = DMatrix::from_row_slice(2, 2, &[0.0, -2.0, 2.0, 0.0]);
/// let e = expm(&a)?;
/// assert!((e[(0, 0)] - 2f64.cos()).abs() < 1e-14 && (e[(1, 0)] - 2f64.sin()).abs() < 1e-14);
/// # Ok::<(), hdi_tribology::ode::OdeError>(())
/// ```
///
/// # Errors
/// [`OdeError::InvalidInput`] naming `a` when it is not square or not finite;
/// [`OdeError::SingularMatrix`] if the Padé denominator cannot be solved (not seen for a finite
/// matrix).
pub fn expm(a: &DMatrix<f64>) -> Result<DMatrix<f64>, OdeError> {
    let n = a.nrows();
    if a.ncols() != n {
        return Err(OdeError::invalid(
            "a",
            format!("must be square, got {} × {}", n, a.ncols()),
        ));
    }
    if a.iter().any(|v| !v.is_finite()) {
        return Err(OdeError::invalid("a", "must be finite"));
    }
    let norm = (0..n)
        .map(|j| a.column(j).iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0f64, f64::max);
    let mut s = 0i32;
    while norm / 2f64.powi(s) > 0.5 {
        s += 1;
    }
    let x = a / 2f64.powi(s);
    // c_j = (2q − j)! q! / ((2q)! j! (q − j)!), q = 6.
    const Q: usize = 6;
    let mut c = [1.0f64; Q + 1];
    for j in 1..=Q {
        c[j] = c[j - 1] * (Q - j + 1) as f64 / (j * (2 * Q - j + 1)) as f64;
    }
    let id = DMatrix::<f64>::identity(n, n);
    let mut num = &id * c[0];
    let mut den = &id * c[0];
    let mut pow = id.clone();
    for (j, cj) in c.iter().enumerate().skip(1) {
        pow = &pow * &x;
        num += &pow * *cj;
        den += &pow * if j % 2 == 0 { *cj } else { -*cj };
    }
    let mut e = den
        .lu()
        .solve(&num)
        .ok_or(OdeError::SingularMatrix { t: 0.0, h: 0.0 })?;
    for _ in 0..s {
        e = &e * &e;
    }
    Ok(e)
}

/// `e^{hA}`, `φ₁(hA)` and `φ₂(hA)`, in this order.
pub type PhiFunctions = (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>);

/// `e^{hA}`, `φ₁(hA)` and `φ₂(hA)` of a square matrix `A` and a step `h`, from one exponential
/// of the augmented matrix `[[hA, I, 0], [0, 0, I], [0, 0, 0]]`.
///
/// ```
/// use hdi_tribology::nalgebra::DMatrix;
/// use hdi_tribology::ode::phi_functions;
/// let z: f64 = -3.0;
/// let (e, p1, p2) = phi_functions(&DMatrix::from_element(1, 1, z), 1.0)?;
/// assert!((e[(0, 0)] - z.exp()).abs() < 1e-15);
/// assert!((p1[(0, 0)] - (z.exp() - 1.0) / z).abs() < 1e-15);
/// assert!((p2[(0, 0)] - (z.exp() - 1.0 - z) / (z * z)).abs() < 1e-15);
/// # Ok::<(), hdi_tribology::ode::OdeError>(())
/// ```
///
/// # Errors
/// As [`expm`]; [`OdeError::InvalidInput`] naming `h` when it is not positive and finite.
pub fn phi_functions(a: &DMatrix<f64>, h: f64) -> Result<PhiFunctions, OdeError> {
    if !(h.is_finite() && h > 0.0) {
        return Err(OdeError::invalid(
            "h",
            format!("must be positive and finite, got {h}"),
        ));
    }
    let n = a.nrows();
    if a.ncols() != n {
        return Err(OdeError::invalid(
            "a",
            format!("must be square, got {} × {}", n, a.ncols()),
        ));
    }
    let mut m = DMatrix::<f64>::zeros(3 * n, 3 * n);
    m.view_mut((0, 0), (n, n)).copy_from(&(a * h));
    for i in 0..n {
        m[(i, n + i)] = 1.0;
        m[(n + i, 2 * n + i)] = 1.0;
    }
    let e = expm(&m)?;
    Ok((
        e.view((0, 0), (n, n)).into_owned(),
        e.view((0, n), (n, n)).into_owned(),
        e.view((0, 2 * n), (n, n)).into_owned(),
    ))
}

/// Steps of one length `h` of a second-order exponential scheme with a held matrix `A`: the
/// φ-functions are computed once, each step then costs one right-hand side besides the one at
/// its start, and three products of an `n × n` matrix with a vector. Nothing is allocated per
/// step. A step that follows another of the same length may take the two-step method instead
/// ([`ExponentialStepper::step_two`]), whose one right-hand side is at its end.
///
/// For `y' = F(t, y)` and a matrix `A` near `∂F/∂y` (held over many steps, refreshed by the
/// caller), one step of length `h` is the exponential time differencing scheme ETD2RK of Cox and
/// Matthews (J. Comput. Phys. 176, 2002) written for the whole right-hand side, with the
/// remainder `g(t, y) = F(t, y) − A y`:
///
/// ```text
/// a  = y₀ + h φ₁(hA) F(t₀, y₀)                                  (exponential Euler)
/// y₁ = a + h φ₂(hA) (F(t₀ + h, a) − F(t₀, y₀) − A (a − y₀))
/// ```
///
/// with `φ₁(z) = (eᶻ − 1)/z` and `φ₂(z) = (eᶻ − 1 − z)/z²`. It is exact for `y' = A y + c` with a
/// constant `c` and of second order otherwise, whatever the stiffness of `A`. The step's error
/// estimate takes, component by component, the larger of two terms: the difference `y₁ − a`,
/// the first-order scheme's error, and, when the previous step of the same length ended where
/// this one starts, `h φ₂(hA) (d − d₋₁)` with `d = F(t₀ + h, a) − F(t₀, y₀) − A (a − y₀)` the
/// remainder's change over the step: the second difference of the remainder, about six times
/// the error of the linear interpolation of the remainder the scheme rests on. The first term
/// misses a remainder whose slope vanishes within the step; the second one sees its curvature.
/// The φ-functions of `hA` come together from one exponential of an augmented matrix (Al-Mohy and Higham, SIAM J. Sci. Comput. 33,
/// 2011, §2): `exp([[hA, I, 0], [0, 0, I], [0, 0, 0]])` has `e^{hA}`, `φ₁(hA)` and `φ₂(hA)` in
/// its first block row. The exponential is Padé's [6/6] approximant with scaling and squaring.
///
/// ```
/// use hdi_tribology::nalgebra::DMatrix;
/// use hdi_tribology::ode::ExponentialStepper;
/// // y' = -1000 y + 1: stiff, and exact in one step of any length.
/// let a = DMatrix::from_element(1, 1, -1000.0);
/// let mut s = ExponentialStepper::new(&a, 0.1)?;
/// let f = |_t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -1000.0 * y[0] + 1.0;
/// let (mut y1, mut f0) = ([0.0], [0.0]);
/// f(0.0, &[0.0], &mut f0);
/// let err = s.step(0.0, &[0.0], &f0, f, (1e-10, &[1e-12]), &mut y1);
/// let exact = (1.0 - (-100.0f64).exp()) / 1000.0;
/// assert!((y1[0] - exact).abs() < 1e-15 && err < 1e-3);
/// # Ok::<(), hdi_tribology::ode::OdeError>(())
/// ```
#[derive(Clone, Debug)]
pub struct ExponentialStepper {
    h: f64,
    a: DMatrix<f64>,
    /// Work: the exponential Euler state, the right-hand side there, a difference.
    ya: Vec<f64>,
    fa: Vec<f64>,
    d: Vec<f64>,
    /// The remainder's change over the previous step, when it ended where the next begins.
    d_prev: Vec<f64>,
    have_prev: bool,
    corr: Vec<f64>,
    curv: Vec<f64>,
    /// `φ₁`, `A` and `φ₂` row by row (row-major), for the products.
    rows1: Vec<f64>,
    rows_a: Vec<f64>,
    rows2: Vec<f64>,
}

impl ExponentialStepper {
    /// A stepper of step `h` for the held matrix `a`.
    ///
    /// # Errors
    /// As [`phi_functions`].
    pub fn new(a: &DMatrix<f64>, h: f64) -> Result<Self, OdeError> {
        let (_, phi1, phi2) = phi_functions(a, h)?;
        let n = a.nrows();
        Ok(ExponentialStepper {
            h,
            a: a.clone(),
            ya: vec![0.0; n],
            fa: vec![0.0; n],
            d: vec![0.0; n],
            d_prev: vec![0.0; n],
            have_prev: false,
            corr: vec![0.0; n],
            curv: vec![0.0; n],
            rows1: phi1.transpose().as_slice().to_vec(),
            rows_a: a.transpose().as_slice().to_vec(),
            rows2: phi2.transpose().as_slice().to_vec(),
        })
    }

    /// Forgets the previous step: the next one does not start where it ended (a jump of the
    /// state), or the right-hand side changed. Its estimate then has the first term only.
    pub fn forget(&mut self) {
        self.have_prev = false;
    }

    /// Whether a step before is known, which the two-step method
    /// ([`step_two`](ExponentialStepper::step_two)) needs.
    pub fn has_previous(&self) -> bool {
        self.have_prev
    }

    /// The step length.
    pub fn h(&self) -> f64 {
        self.h
    }

    /// The held matrix.
    pub fn matrix(&self) -> &DMatrix<f64> {
        &self.a
    }

    /// The state's dimension.
    pub fn dim(&self) -> usize {
        self.a.nrows()
    }

    /// One step from `(t0, y0)`, `f0 = F(t0, y0)`, to `y1` at `t0 + h`; `f(t, y, dy)` writes
    /// `F(t, y)` into `dy`. Returns the error estimate (see the type's documentation): its largest
    /// component weighted by `atol_i + rtol·max(|y0_i|, |y1_i|)` (`tol = (rtol, atol)`), a
    /// max norm, so that at most 1 meets every component's tolerance. A non-finite right-hand side
    /// gives an infinite estimate. The next step takes this one as its previous step (see
    /// [`forget`](ExponentialStepper::forget)).
    ///
    /// # Panics
    /// When a slice is not of the stepper's dimension.
    pub fn step(
        &mut self,
        t0: f64,
        y0: &[f64],
        f0: &[f64],
        f: impl FnMut(f64, &[f64], &mut [f64]),
        tol: (f64, &[f64]),
        y1: &mut [f64],
    ) -> f64 {
        let n = self.dim();
        assert!(y0.len() == n && f0.len() == n && y1.len() == n && tol.1.len() == n);
        // The same loops with the dimension a literal, for the sizes a slider has: unrolled,
        // they cost a third of the loops over a dimension known only at run time (the sums
        // are taken in the same order, so the results are the same to the bit).
        match n {
            4 => self.step_of(4, t0, y0, f0, f, tol, y1),
            5 => self.step_of(5, t0, y0, f0, f, tol, y1),
            6 => self.step_of(6, t0, y0, f0, f, tol, y1),
            7 => self.step_of(7, t0, y0, f0, f, tol, y1),
            8 => self.step_of(8, t0, y0, f0, f, tol, y1),
            _ => self.step_of(n, t0, y0, f0, f, tol, y1),
        }
    }

    /// One step of the two-step method from `(t0, y0)`, `f0 = F(t0, y0)`, to `y1` at `t0 + h`,
    /// with `F(t0 + h, y1)` into `f1`; `None` (nothing done) without a previous step of the same
    /// length ending at `y0` (after [`forget`](ExponentialStepper::forget)). The step is Cox and
    /// Matthews' ETD2 (J. Comput. Phys. 176, 2002, eq. (7)) for the whole right-hand side:
    ///
    /// ```text
    /// y₁ = y₀ + h φ₁(hA) F(t₀, y₀) + h φ₂(hA) d₋₁,
    /// ```
    ///
    /// with `d₋₁` the remainder's change over the previous step (`d` of
    /// [`step`](ExponentialStepper::step)'s documentation): the remainder extrapolated from the
    /// previous step, where `step` interpolates it from a right-hand side inside the step. The
    /// one right-hand side it evaluates is at its end, `f1`, which is the next step's `f0` when
    /// the inputs are kept (first same as last): one right-hand side a step against `step`'s
    /// two. That value also gives the step's own change `d = f1 − f0 − A (y1 − y0)`, and the
    /// estimate is `step`'s: the larger of `h φ₂ d` and `h φ₂ (d − d₋₁)` per component. The
    /// second term is the difference between this step and the one that interpolates the
    /// remainder between the step's ends; for a smooth remainder `g` it is `h³ g″/2` against a
    /// local error of `(5/12) h³ g″` (`step`'s is `−(1/12) h³ g″`), so it bounds the error, and
    /// it sees a remainder that turns within the step, since it reads the step's end.
    ///
    /// ```
    /// use hdi_tribology::nalgebra::DMatrix;
    /// use hdi_tribology::ode::ExponentialStepper;
    /// // y' = -y + sin t from y(0) = 1 to t = 2: one step of `step`, then the two-step method,
    /// // one right-hand side a step, each step's `f1` the next one's `f0`.
    /// let f = |t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0] + t.sin();
    /// let h = 0.02;
    /// let mut s = ExponentialStepper::new(&DMatrix::from_element(1, 1, -1.0), h)?;
    /// let (mut y, mut f0, mut y1, mut f1) = ([1.0], [0.0], [0.0], [0.0]);
    /// f(0.0, &y, &mut f0);
    /// s.step(0.0, &y, &f0, f, (0.0, &[1.0]), &mut y1);
    /// (y, f0) = (y1, [-y1[0] + h.sin()]);
    /// for k in 1..100 {
    ///     let t = k as f64 * h;
    ///     let est = s.step_two(t, &y, &f0, f, (0.0, &[1.0]), &mut y1, &mut f1).expect("a step before");
    ///     assert!(est < 1e-3);
    ///     (y, f0) = (y1, f1);
    /// }
    /// let exact = 0.5 * (2f64.sin() - 2f64.cos()) + 1.5 * (-2f64).exp();
    /// // Second order: 1.2e-4 at h = 0.02 (the one-step method alone: a fifth of that).
    /// assert!((y[0] - exact).abs() < 2e-4);
    /// # Ok::<(), hdi_tribology::ode::OdeError>(())
    /// ```
    ///
    /// # Panics
    /// As [`step`](ExponentialStepper::step), and when `f1` is not of the dimension.
    #[allow(clippy::too_many_arguments)]
    pub fn step_two(
        &mut self,
        t0: f64,
        y0: &[f64],
        f0: &[f64],
        f: impl FnMut(f64, &[f64], &mut [f64]),
        tol: (f64, &[f64]),
        y1: &mut [f64],
        f1: &mut [f64],
    ) -> Option<f64> {
        if !self.have_prev {
            return None;
        }
        let n = self.dim();
        assert!(
            y0.len() == n && f0.len() == n && y1.len() == n && f1.len() == n && tol.1.len() == n
        );
        // As in `step`.
        Some(match n {
            4 => self.two_of(4, t0, y0, f0, f, tol, y1, f1),
            5 => self.two_of(5, t0, y0, f0, f, tol, y1, f1),
            6 => self.two_of(6, t0, y0, f0, f, tol, y1, f1),
            7 => self.two_of(7, t0, y0, f0, f, tol, y1, f1),
            8 => self.two_of(8, t0, y0, f0, f, tol, y1, f1),
            _ => self.two_of(n, t0, y0, f0, f, tol, y1, f1),
        })
    }

    /// [`step_two`](ExponentialStepper::step_two)'s body for a dimension `n` checked by it.
    #[inline(always)]
    #[allow(clippy::too_many_arguments, clippy::needless_range_loop)]
    fn two_of(
        &mut self,
        n: usize,
        t0: f64,
        y0: &[f64],
        f0: &[f64],
        mut f: impl FnMut(f64, &[f64], &mut [f64]),
        tol: (f64, &[f64]),
        y1: &mut [f64],
        f1: &mut [f64],
    ) -> f64 {
        let h = self.h;
        let (y0, f0, y1, f1) = (&y0[..n], &f0[..n], &mut y1[..n], &mut f1[..n]);
        let dot = |rows: &[f64], i: usize, v: &[f64]| row_dot(n, rows, i, v);
        // y1 = y0 + h φ1 f0 + h φ2 d₋₁ (φ2 d₋₁ kept in `curv`).
        for i in 0..n {
            self.curv[i] = dot(&self.rows2, i, &self.d_prev);
            y1[i] = y0[i] + h * dot(&self.rows1, i, f0) + h * self.curv[i];
        }
        f(t0 + h, y1, f1);
        // d = F(y1) − F(y0) − A (y1 − y0).
        for i in 0..n {
            self.corr[i] = y1[i] - y0[i];
        }
        for i in 0..n {
            self.d[i] = f1[i] - f0[i] - dot(&self.rows_a, i, &self.corr);
        }
        // The estimate from φ2 d and φ2 d − φ2 d₋₁.
        let (rtol, atol) = tol;
        let atol = &atol[..n];
        let mut err = 0.0f64;
        for i in 0..n {
            let c = dot(&self.rows2, i, &self.d);
            let e = c.abs().max((c - self.curv[i]).abs());
            err = err.max(weighted(h * e, atol[i], rtol, y0[i], y1[i]));
        }
        std::mem::swap(&mut self.d, &mut self.d_prev);
        finite_or_infinite(err)
    }

    /// [`step`](ExponentialStepper::step)'s body for a dimension `n` checked by it.
    /// Indexed loops: with `n` a constant they unroll.
    #[inline(always)]
    #[allow(clippy::too_many_arguments, clippy::needless_range_loop)]
    fn step_of(
        &mut self,
        n: usize,
        t0: f64,
        y0: &[f64],
        f0: &[f64],
        mut f: impl FnMut(f64, &[f64], &mut [f64]),
        tol: (f64, &[f64]),
        y1: &mut [f64],
    ) -> f64 {
        let h = self.h;
        let (y0, f0, y1) = (&y0[..n], &f0[..n], &mut y1[..n]);
        let dot = |rows: &[f64], i: usize, v: &[f64]| row_dot(n, rows, i, v);
        // a = y0 + h φ1 f0 (rows of the row-major copies).
        for i in 0..n {
            self.ya[i] = y0[i] + h * dot(&self.rows1, i, f0);
        }
        f(t0 + h, &self.ya[..n], &mut self.fa[..n]);
        // d = F(a) − F(y0) − A (a − y0).
        for i in 0..n {
            self.corr[i] = self.ya[i] - y0[i];
        }
        for i in 0..n {
            self.d[i] = self.fa[i] - f0[i] - dot(&self.rows_a, i, &self.corr);
        }
        // The correction φ2 d (times h below), and φ2 (d − d₋₁) for the estimate.
        for i in 0..n {
            self.fa[i] = self.d[i] - self.d_prev[i];
        }
        let prev = self.have_prev;
        for i in 0..n {
            self.corr[i] = dot(&self.rows2, i, &self.d);
            self.curv[i] = if prev {
                dot(&self.rows2, i, &self.fa)
            } else {
                0.0
            };
        }
        let (rtol, atol) = tol;
        let atol = &atol[..n];
        let mut err = 0.0f64;
        for i in 0..n {
            let corr = h * self.corr[i];
            y1[i] = self.ya[i] + corr;
            let e = corr.abs().max(h * self.curv[i].abs());
            err = err.max(weighted(e, atol[i], rtol, y0[i], y1[i]));
        }
        std::mem::swap(&mut self.d, &mut self.d_prev);
        self.have_prev = true;
        finite_or_infinite(err)
    }
}

/// A component's error `e` weighted by `atol + rtol·max(|y0|, |y1|)`: the steps' estimate norm.
#[inline(always)]
fn weighted(e: f64, atol: f64, rtol: f64, y0: f64, y1: f64) -> f64 {
    e / (atol + rtol * y0.abs().max(y1.abs()))
}

/// The estimate, infinite where it is not finite (a non-finite right-hand side).
#[inline(always)]
fn finite_or_infinite(err: f64) -> f64 {
    if err.is_finite() {
        err
    } else {
        f64::INFINITY
    }
}

/// `Σ_j row_j v_j` over row `i` of the row-major `rows` (`n` columns), summed from −0 in order of
/// `j` (as `Iterator::sum` does).
#[inline(always)]
#[allow(clippy::needless_range_loop)]
fn row_dot(n: usize, rows: &[f64], i: usize, v: &[f64]) -> f64 {
    let row = &rows[i * n..i * n + n];
    let v = &v[..n];
    let mut s = -0.0;
    for j in 0..n {
        s += row[j] * v[j];
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DVector;

    /// The exponential of a matrix with known eigenvectors against `V e^{Λ} V⁻¹`.
    #[test]
    fn expm_of_a_diagonalisable_matrix() {
        let v = DMatrix::from_row_slice(3, 3, &[1.0, 2.0, 0.5, 0.0, 1.0, -1.0, 0.3, 0.0, 2.0]);
        let lam = [-50.0, 0.7, -3.0];
        let vi = v.clone().try_inverse().unwrap();
        let a = &v * DMatrix::from_diagonal(&DVector::from_row_slice(&lam)) * &vi;
        let e_l: Vec<f64> = lam.iter().map(|l: &f64| l.exp()).collect();
        let exact = &v * DMatrix::from_diagonal(&DVector::from_vec(e_l)) * &vi;
        let e = expm(&a).unwrap();
        let scale = exact.amax();
        assert!(
            (&e - &exact).amax() < 1e-12 * scale,
            "{}",
            (&e - &exact).amax()
        );
    }

    /// φ-functions of a damped oscillator's matrix against their defining series, summed at a
    /// small argument where the series converges fast, and against `A φ₁ = e^{hA} − I`,
    /// `A φ₂ = φ₁ − I` at a large one.
    #[test]
    fn phi_functions_satisfy_their_recurrences() {
        // ω = 5.5e5 rad/s, ζ = 0.05: a slider's air-bearing mode.
        let w = 5.5e5;
        let a = DMatrix::from_row_slice(2, 2, &[0.0, w, -w, -0.1 * w]);
        for h in [2e-8, 5e-5] {
            let (e, p1, p2) = phi_functions(&a, h).unwrap();
            let ha = &a * h;
            let id = DMatrix::<f64>::identity(2, 2);
            let r1 = &ha * &p1 - (&e - &id);
            let r2 = &ha * &p2 - (&p1 - &id);
            assert!(r1.amax() < 1e-12 * (1.0 + e.amax()), "{h}: {}", r1.amax());
            assert!(r2.amax() < 1e-12 * (1.0 + p1.amax()), "{h}: {}", r2.amax());
            if h < 1e-7 {
                // The series Σ (hA)^k/(k+1)!.
                let (mut term, mut s) = (id.clone(), id.clone());
                for k in 1..30 {
                    term = &term * &ha / (k + 1) as f64;
                    s += &term;
                }
                assert!((&p1 - &s).amax() < 1e-14, "{}", (&p1 - &s).amax());
            }
        }
    }

    /// `y' = -y + sin t`: second order, the error falls fourfold per halving of the step, and
    /// once a previous step is known the estimate bounds each step's own error from above.
    #[test]
    fn the_step_is_second_order_and_its_estimate_conservative() {
        let exact = |t: f64| {
            // y(0) = 1.
            let p = 0.5 * (t.sin() - t.cos());
            p + 1.5 * (-t).exp()
        };
        let f = |t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0] + t.sin();
        let a = DMatrix::from_element(1, 1, -1.0);
        let mut errs = Vec::new();
        for n in [20, 40, 80] {
            let h = 2.0 / n as f64;
            let mut s = ExponentialStepper::new(&a, h).unwrap();
            let (mut y, mut f0, mut y1) = ([1.0], [0.0], [0.0]);
            for k in 0..n {
                let t = k as f64 * h;
                f(t, &y, &mut f0);
                let est = s.step(t, &y, &f0, f, (0.0, &[1.0]), &mut y1);
                // The local error of this step alone, from the exact start.
                let mut y_ex = [0.0];
                let mut probe = s.clone();
                probe.forget();
                f(t, &[exact(t)], &mut f0);
                probe.step(t, &[exact(t)], &f0, f, (0.0, &[1.0]), &mut y_ex);
                let local = (y_ex[0] - exact(t + h)).abs();
                if k > 0 {
                    assert!(local <= est, "step {k}: local {local} > estimate {est}");
                }
                y = y1;
            }
            errs.push((y[0] - exact(2.0)).abs());
        }
        for w in errs.windows(2) {
            let ratio = w[0] / w[1];
            assert!((3.5..4.5).contains(&ratio), "{errs:?}");
        }
    }

    /// The two-step method on `y' = -y + sin t` (one step of `step` first, each step's end
    /// value the next one's start value): second order, its error five times `step`'s (the
    /// ratio of their error constants), and each step's estimate above that step's own error.
    #[test]
    fn the_two_step_method_is_second_order_and_its_estimate_conservative() {
        let exact = |t: f64| 0.5 * (t.sin() - t.cos()) + 1.5 * (-t).exp();
        let f = |t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0] + t.sin();
        let a = DMatrix::from_element(1, 1, -1.0);
        let tol = (0.0, &[1.0][..]);
        let (mut errs, mut errs_one) = (Vec::new(), Vec::new());
        for n in [20, 40, 80] {
            let h = 2.0 / n as f64;
            let mut s = ExponentialStepper::new(&a, h).unwrap();
            let mut one = s.clone();
            let (mut y, mut f0, mut y1, mut f1) = ([1.0], [0.0], [0.0], [0.0]);
            f(0.0, &y, &mut f0);
            s.step(0.0, &y, &f0, f, tol, &mut y1);
            y = y1;
            f(h, &y, &mut f0);
            let mut y_one = [1.0];
            for k in 1..n {
                let t = k as f64 * h;
                // This step's own error: from the exact state at t, with the same history.
                let mut probe = s.clone();
                let (mut fe, mut y_ex, mut f_ex) = ([0.0], [0.0], [0.0]);
                f(t, &[exact(t)], &mut fe);
                probe.step_two(t, &[exact(t)], &fe, f, tol, &mut y_ex, &mut f_ex);
                let local = (y_ex[0] - exact(t + h)).abs();
                let est = s.step_two(t, &y, &f0, f, tol, &mut y1, &mut f1).unwrap();
                assert!(local <= est, "step {k}: local {local} > estimate {est}");
                (y, f0) = (y1, f1);
            }
            for k in 0..n {
                let t = k as f64 * h;
                let mut fo = [0.0];
                f(t, &y_one, &mut fo);
                one.step(t, &y_one, &fo, f, tol, &mut y1);
                y_one = y1;
            }
            errs.push((y[0] - exact(2.0)).abs());
            errs_one.push((y_one[0] - exact(2.0)).abs());
        }
        for w in errs.windows(2) {
            let ratio = w[0] / w[1];
            assert!((3.5..4.5).contains(&ratio), "{errs:?}");
        }
        for (e, o) in errs.iter().zip(&errs_one) {
            assert!(
                (4.0..6.0).contains(&(e / o)),
                "{errs:?} against {errs_one:?}"
            );
        }
        // Without a step before there is no two-step step.
        let mut s = ExponentialStepper::new(&a, 0.1).unwrap();
        let (mut y1, mut f1) = ([0.0], [0.0]);
        assert!(s
            .step_two(0.0, &[1.0], &[-1.0], f, tol, &mut y1, &mut f1)
            .is_none());
    }

    /// A remainder that turns within the step, a kink at its middle: the estimate, which reads
    /// the step's end, sees it, where the extrapolation from the step before cannot.
    #[test]
    fn the_two_step_estimate_sees_a_kink_inside_the_step() {
        let a = DMatrix::from_element(1, 1, -1.0);
        let h = 0.1;
        // y' = -y + c(t), c rising at slope 1 up to t = 0.25, then falling at slope 20.
        let c = |t: f64| {
            if t < 0.25 {
                t
            } else {
                0.25 - 20.0 * (t - 0.25)
            }
        };
        let f = move |t: f64, y: &[f64], dy: &mut [f64]| dy[0] = -y[0] + c(t);
        let tol = (0.0, &[1e-2][..]);
        let mut s = ExponentialStepper::new(&a, h).unwrap();
        let (mut y, mut f0, mut y1, mut f1) = ([0.0], [0.0], [0.0], [0.0]);
        f(0.0, &y, &mut f0);
        let e0 = s.step(0.0, &y, &f0, f, tol, &mut y1);
        y = y1;
        f(h, &y, &mut f0);
        let e1 = s.step_two(h, &y, &f0, f, tol, &mut y1, &mut f1).unwrap();
        (y, f0) = (y1, f1);
        // Both steps before the kink pass (`h φ₂ d` = 4.8e-3 against 1e-2).
        assert!(e0 < 1.0 && e1 < 1.0, "{e0} {e1}");
        // The step over the kink at 0.25.
        let e2 = s
            .step_two(2.0 * h, &y, &f0, f, tol, &mut y1, &mut f1)
            .unwrap();
        assert!(e2 > 1.0, "{e2}");
    }

    #[test]
    fn bad_inputs_are_named() {
        let a = DMatrix::from_element(2, 3, 0.0);
        assert!(matches!(expm(&a), Err(OdeError::InvalidInput { ref field, .. }) if field == "a"));
        let a = DMatrix::from_element(1, 1, 1.0);
        assert!(
            matches!(phi_functions(&a, 0.0), Err(OdeError::InvalidInput { ref field, .. }) if field == "h")
        );
        let a = DMatrix::from_element(1, 1, f64::NAN);
        assert!(expm(&a).is_err());
    }
}
