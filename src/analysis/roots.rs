//! Bracketed scalar root finding (Brent's method) used by the analyses.

use crate::error::{failure_kind, Result, Stage};

impl Stage {
    /// Brent's bracketed root search.
    pub const ROOT_SEARCH: Stage = Stage::named("root search");
}

/// Why a bracketed root search failed (always [`Error::NoConvergence`](crate::Error::NoConvergence)).
///
/// ```
/// use hdi_tribology::analysis::roots::{brent, RootError};
/// let e = brent(|x| x * x + 1.0, 0.0, 2.0, 1e-12).unwrap_err();
/// let kind = e.failure().and_then(|f| f.downcast_ref::<RootError>());
/// assert_eq!(kind, Some(&RootError::NoSignChange { a: 0.0, b: 2.0 }));
/// ```
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RootError {
    /// The function is not finite at an end of the bracket.
    #[error("non-finite value at an end of [{a:e}, {b:e}]")]
    NonFiniteEnd {
        /// Low end.
        a: f64,
        /// High end.
        b: f64,
    },
    /// The function has the same sign at both ends.
    #[error("no sign change on [{a:e}, {b:e}]")]
    NoSignChange {
        /// Low end.
        a: f64,
        /// High end.
        b: f64,
    },
    /// The function is not finite at an iterate.
    #[error("non-finite value at {x:e}")]
    NonFinite {
        /// The iterate.
        x: f64,
    },
    /// The iteration budget is used up.
    #[error("{iterations} iterations without reaching the tolerance")]
    Iterations {
        /// The budget.
        iterations: usize,
    },
}

failure_kind!(RootError, convergence = |_| true, {
        NonFiniteEnd => Stage::ROOT_SEARCH,
        NoSignChange => Stage::ROOT_SEARCH,
        NonFinite => Stage::ROOT_SEARCH,
        Iterations => Stage::ROOT_SEARCH,
});

/// Finds a root of `f` in `[a, b]` where `f(a)` and `f(b)` differ in sign, to an interval width
/// of `xtol` (plus a few ulps). Bounded to 200 iterations.
///
/// ```
/// use hdi_tribology::analysis::roots::brent;
/// let r = brent(|x| x * x - 2.0, 0.0, 2.0, 1e-15)?;
/// assert!((r - 2f64.sqrt()).abs() < 1e-14);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn brent<F: FnMut(f64) -> f64>(mut f: F, a: f64, b: f64, xtol: f64) -> Result<f64> {
    let (fa, fb) = (f(a), f(b));
    brent_from(f, (a, fa), (b, fb), xtol)
}

/// A root of `exact` in `[a, b]` to `xtol`, as [`brent`] on `exact` gives it, found with fewer
/// evaluations of `exact` when a cheap `approx` of it (the same function through the force
/// tables) is at hand: Brent's method on `approx` first, then a Newton step on `exact` with the
/// slope of `approx`, and Brent's method on `exact` in the small bracket this step opens (widened
/// fourfold while it holds no sign change). Falls back to [`brent`] on `exact` over `[a, b]`
/// whenever a step fails, so that it fails exactly when that does.
///
/// ```
/// use hdi_tribology::analysis::roots::brent_polished;
/// // An approximation off by 1e-9 relative, like a force table.
/// let r = brent_polished(|x| x * x - 2.0 * (1.0 + 1e-9), |x| x * x - 2.0, 0.0, 2.0, 1e-15)?;
/// assert!((r - 2f64.sqrt()).abs() < 1e-14);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn brent_polished<F, G>(mut approx: F, mut exact: G, a: f64, b: f64, xtol: f64) -> Result<f64>
where
    F: FnMut(f64) -> f64,
    G: FnMut(f64) -> f64,
{
    let (lo, hi) = (a.min(b), a.max(b));
    let Some((x0, f0, step)) = (|| {
        let r = brent(&mut approx, a, b, xtol).ok()?;
        let f0 = exact(r);
        // The slope of the approximation at its root, over a few tolerances (inside [a, b]).
        let h = (64.0 * xtol).min(0.25 * (hi - lo));
        let (u, v) = ((r - h).max(lo), (r + h).min(hi));
        let slope = (approx(v) - approx(u)) / (v - u);
        let step = -f0 / slope;
        (f0.is_finite() && step.is_finite()).then_some((r, f0, step))
    })() else {
        return brent(exact, a, b, xtol);
    };
    if f0 == 0.0 {
        return Ok(x0);
    }
    // Twice the Newton step, so that the root lies inside the first bracket when the slope is
    // right to a factor of two; at least two tolerances.
    let mut width = (2.0 * step.abs()).max(2.0 * xtol);
    let dir = step.signum();
    let (mut x, mut fx) = (x0, f0);
    while width <= hi - lo {
        let x1 = (x + dir * width).clamp(lo, hi);
        let f1 = exact(x1);
        if !f1.is_finite() {
            break;
        }
        if f1 == 0.0 {
            return Ok(x1);
        }
        if f1.signum() != fx.signum() {
            return brent_from(exact, (x, fx), (x1, f1), xtol);
        }
        if x1 == lo || x1 == hi {
            break;
        }
        (x, fx) = (x1, f1);
        width *= 4.0;
    }
    brent(exact, a, b, xtol)
}

/// [`brent`] with the values at the ends already known.
fn brent_from<F: FnMut(f64) -> f64>(
    mut f: F,
    (a, fa): (f64, f64),
    (b, fb): (f64, f64),
    xtol: f64,
) -> Result<f64> {
    let (mut a, mut b) = (a, b);
    let (mut fa, mut fb) = (fa, fb);
    if !fa.is_finite() || !fb.is_finite() {
        return Err(RootError::NonFiniteEnd { a, b }.into());
    }
    if fa == 0.0 {
        return Ok(a);
    }
    if fb == 0.0 {
        return Ok(b);
    }
    if fa.signum() == fb.signum() {
        return Err(RootError::NoSignChange { a, b }.into());
    }
    let (mut c, mut fc) = (a, fa);
    let mut d = b - a;
    let mut e = d;
    for _ in 0..200 {
        if fb.signum() == fc.signum() {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol = 2.0 * f64::EPSILON * b.abs() + 0.5 * xtol;
        let m = 0.5 * (c - b);
        if m.abs() <= tol || fb == 0.0 {
            return Ok(b);
        }
        if e.abs() >= tol && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = 2.0 * m * s;
                q = 1.0 - s;
            } else {
                let qa = fa / fc;
                let r = fb / fc;
                p = s * (2.0 * m * qa * (qa - r) - (b - a) * (r - 1.0));
                q = (qa - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < (3.0 * m * q - (tol * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = m;
                e = m;
            }
        } else {
            d = m;
            e = m;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol { d } else { tol.copysign(m) };
        fb = f(b);
        if !fb.is_finite() {
            return Err(RootError::NonFinite { x: b }.into());
        }
    }
    Err(RootError::Iterations { iterations: 200 }.into())
}

#[cfg(test)]
mod tests {
    use super::brent;

    #[test]
    fn finds_roots_of_smooth_and_steep_functions() {
        let r = brent(|x| x.cos() - x, 0.0, 1.0, 1e-14).unwrap();
        assert!((r.cos() - r).abs() < 1e-13);
        let r = brent(|x| (x - 1e-9).powi(9), 0.0, 1.0, 1e-15).unwrap();
        assert!((r - 1e-9).abs() < 1e-6);
        assert!(brent(|x| x * x + 1.0, -1.0, 1.0, 1e-12).is_err());
        assert!(brent(|_| f64::NAN, -1.0, 1.0, 1e-12).is_err());
    }
}
