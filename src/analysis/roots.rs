//! Bracketed scalar root finding (Brent's method) used by the analyses.

use crate::error::{Error, Result};

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
    let (mut a, mut b) = (a, b);
    let (mut fa, mut fb) = (f(a), f(b));
    if !fa.is_finite() || !fb.is_finite() {
        return Err(Error::no_convergence(
            "root bracket",
            format!("non-finite value at an end of [{a:e}, {b:e}]"),
        ));
    }
    if fa == 0.0 {
        return Ok(a);
    }
    if fb == 0.0 {
        return Ok(b);
    }
    if fa.signum() == fb.signum() {
        return Err(Error::no_convergence(
            "root bracket",
            format!("no sign change on [{a:e}, {b:e}]"),
        ));
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
            return Err(Error::no_convergence(
                "root search",
                format!("non-finite value at {b:e}"),
            ));
        }
    }
    Err(Error::no_convergence(
        "root search",
        "200 iterations without reaching the tolerance",
    ))
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
