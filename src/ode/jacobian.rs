//! Jacobian evaluation shared by the stiff methods: analytic when offered, else differences;
//! plus a spectral-radius estimate for stiffness switching.

use super::stepper::{zeros_like, Ctx};
use super::system::{finite_difference_jacobian, OdeSystem};
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OMatrix, OVector};

/// Fills `jac` with ∂f/∂y at `(t, y)` (`f0 = f(t, y)`); `false` if it is not finite.
pub(crate) fn eval_jacobian<D: Dim, S: OdeSystem<D> + ?Sized>(
    sys: &S,
    t: f64,
    y: &OVector<f64, D>,
    f0: &OVector<f64, D>,
    jac: &mut OMatrix<f64, D, D>,
    work: &mut OVector<f64, D>,
    ctx: &mut Ctx<D>,
) -> bool
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    ctx.stats.jac_evals += 1;
    if !sys.jacobian(t, y, jac) {
        ctx.stats.rhs_evals += finite_difference_jacobian(sys, t, y, f0, &ctx.atol, jac, work);
    }
    jac.as_slice().iter().all(|v| v.is_finite())
}

/// [`eval_jacobian`] and `∂f/∂t` at one point, through
/// [`OdeSystem::jacobian_and_time_derivative`] (one call for a system whose two share work):
/// zero for an autonomous system, a forward difference when the system does not give it;
/// `false` if the Jacobian is not finite.
#[allow(clippy::too_many_arguments)]
pub(crate) fn eval_jacobian_and_time_derivative<D: Dim, S: OdeSystem<D> + ?Sized>(
    sys: &S,
    t: f64,
    y: &OVector<f64, D>,
    f0: &OVector<f64, D>,
    h: f64,
    jac: &mut OMatrix<f64, D, D>,
    dfdt: &mut OVector<f64, D>,
    work: &mut OVector<f64, D>,
    ctx: &mut Ctx<D>,
) -> bool
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    if sys.is_autonomous() {
        dfdt.fill(0.0);
        return eval_jacobian(sys, t, y, f0, jac, work, ctx);
    }
    ctx.stats.jac_evals += 1;
    let (jac_given, dfdt_given) = sys.jacobian_and_time_derivative(t, y, jac, dfdt);
    if !jac_given {
        ctx.stats.rhs_evals += finite_difference_jacobian(sys, t, y, f0, &ctx.atol, jac, work);
    }
    if !dfdt_given {
        difference_time_derivative(sys, t, y, f0, h, dfdt, ctx);
    }
    jac.as_slice().iter().all(|v| v.is_finite())
}

/// `∂f/∂t` by a forward difference, `h` setting the time scale of the increment.
fn difference_time_derivative<D: Dim, S: OdeSystem<D> + ?Sized>(
    sys: &S,
    t: f64,
    y: &OVector<f64, D>,
    f0: &OVector<f64, D>,
    h: f64,
    dfdt: &mut OVector<f64, D>,
    ctx: &mut Ctx<D>,
) where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let delta = f64::EPSILON.sqrt() * t.abs().max(h.abs()).max(f64::MIN_POSITIVE);
    let tp = t + delta;
    let delta = tp - t;
    ctx.rhs(sys, tp, y, dfdt);
    *dfdt -= f0;
    *dfdt /= delta;
}

/// A stiff method's spectral radius for Auto's return test, kept at each new Jacobian as the
/// cheap lower bound `|tr J|/n` and replaced by the power-iteration estimate (16 products with
/// J) only when asked: the one home of that rule for Rodas5P and Radau5.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Radius {
    rho: Option<f64>,
    /// `rho` is the estimate, not only the bound.
    exact: bool,
}

impl Radius {
    /// A new Jacobian: its bound.
    pub fn at_new_jacobian<D: Dim>(&mut self, jac: &OMatrix<f64, D, D>)
    where
        DefaultAllocator: Allocator<D, D>,
    {
        self.rho = Some(radius_lower_bound(jac));
        self.exact = false;
    }

    /// The bound or the estimate, whichever is held.
    pub fn get(&self) -> Option<f64> {
        self.rho
    }

    /// The estimate for `jac` (the Jacobian of the bound held), computed once.
    pub fn exact<D: Dim>(&mut self, jac: &OMatrix<f64, D, D>, like: &OVector<f64, D>) -> Option<f64>
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        if !self.exact && self.rho.is_some() {
            self.rho = Some(spectral_radius(jac, like));
            self.exact = true;
        }
        self.rho
    }
}

/// A lower bound of the spectral radius of `jac`: `|tr J| / n` (the trace is the sum of the
/// eigenvalues), at the cost of `n` additions.
pub(crate) fn radius_lower_bound<D: Dim>(jac: &OMatrix<f64, D, D>) -> f64
where
    DefaultAllocator: Allocator<D, D>,
{
    let n = jac.nrows();
    (0..n).map(|i| jac[(i, i)]).sum::<f64>().abs() / n.max(1) as f64
}

/// Estimate of the spectral radius of `jac` by the growth rate of power iterations (valid for
/// complex dominant pairs too, where the direction does not converge but the growth does).
pub(crate) fn spectral_radius<D: Dim>(jac: &OMatrix<f64, D, D>, like: &OVector<f64, D>) -> f64
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let n = like.len();
    let mut v = zeros_like(like);
    for i in 0..n {
        // A start vector unlikely to be orthogonal to the dominant eigenvectors.
        v[i] = 1.0 + 0.37 * i as f64 * if i % 2 == 0 { 1.0 } else { -1.0 };
    }
    let mut w = zeros_like(like);
    let mut log_growth = 0.0;
    let mut counted = 0;
    const ITERS: usize = 16;
    for it in 0..ITERS {
        let nv = v.norm();
        if nv.is_nan() || nv <= 0.0 || !nv.is_finite() {
            return if it == 0 { 0.0 } else { f64::INFINITY };
        }
        v /= nv;
        w.gemv(1.0, jac, &v, 0.0);
        let nw = w.norm();
        if nw == 0.0 {
            return 0.0;
        }
        if it >= ITERS / 2 {
            log_growth += nw.ln();
            counted += 1;
        }
        std::mem::swap(&mut v, &mut w);
    }
    (log_growth / counted as f64).exp()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

    #[test]
    fn spectral_radius_of_oscillator_and_stiff_diagonal() {
        // Eigenvalues ±iω: the norm growth rate is ω although the direction never converges.
        let w = 2.0 * std::f64::consts::PI * 87e3;
        let r = spectral_radius(&Matrix2::new(0.0, 1.0, -w * w, 0.0), &Vector2::zeros());
        // Power-iteration estimate of the growth rate: within 20 % (start-vector bias^(1/8)).
        assert!((r / w - 1.0).abs() < 0.2, "{r} vs {w}");
        let r = spectral_radius(
            &Matrix3::from_diagonal(&Vector3::new(-1e4, -1.0, -3.0)),
            &Vector3::zeros(),
        );
        assert!((r / 1e4 - 1.0).abs() < 1e-6, "{r}");
    }

    #[test]
    fn trace_bound_lies_below_the_radius() {
        // Stiff diagonal: |tr|/n = 3335 against ρ = 1e4; the oscillator's trace is zero.
        let d = Matrix3::from_diagonal(&Vector3::new(-1e4, -1.0, -4.0));
        assert_eq!(radius_lower_bound(&d), 10005.0 / 3.0);
        assert!(radius_lower_bound(&d) <= spectral_radius(&d, &Vector3::zeros()));
        let w = 5.0;
        assert_eq!(
            radius_lower_bound(&Matrix2::new(0.0, 1.0, -w * w, 0.0)),
            0.0
        );
        // A damped oscillator with a full matrix: eigenvalues −0.5 ± i·√(w² − 0.25).
        let j = Matrix2::new(0.0, 1.0, -w * w, -1.0);
        let b = radius_lower_bound(&j);
        assert_eq!(b, 0.5);
        assert!(b <= w, "{b}");
    }
}
