//! Partial moments of continuous peak laws by adaptive quadrature of the density.

use crate::quadrature::{integrate_adaptive, Exhausted, QuadOptions};

/// Quadrature settings for partial moments: a relative target one decade below
/// the promised 1e-12 so that the result meets it; the absolute floor only
/// matters for values that underflow anyway.
const OPTS: QuadOptions = QuadOptions {
    abs_tol: 1e-300,
    rel_tol: 1e-13,
    max_intervals: 400,
};

/// Shape of a continuous law needed to integrate it: its density, the lower end
/// of its support (−∞ allowed), and a centre and scale such that above the
/// centre the density decays at least like a Gaussian of that scale.
pub(crate) struct Shape<'a> {
    pub pdf: &'a dyn Fn(f64) -> f64,
    /// The density is exactly zero below this height (−∞ if never).
    pub lower: f64,
    /// Below this height the law holds less than 1e-19 of its mass.
    pub negligible_below: f64,
    pub centre: f64,
    pub scale: f64,
    /// Heights where the density changes character (peaks, shoulders); they
    /// become break points so that narrow features are never missed.
    pub landmarks: &'a [f64],
}

/// Partial moment when `d` lies more than 1e8 standard deviations below the
/// mean: then `M_p = (m − d)^p·(1 + p(p−1)/2·(s/(m − d))² + …)` and the
/// correction is below 1e-16·p², so the leading term is exact in double
/// precision (and the standardised variable would overflow for huge |d|).
pub(crate) fn far_below(mean: f64, std: f64, d: f64, p: f64) -> Option<f64> {
    let gap = mean - d;
    if gap > 1e8 * std {
        Some(if p == 0.0 { 1.0 } else { gap.powf(p) })
    } else {
        None
    }
}

/// `∫_d^∞ (z − d)^p f(z) dz` for a continuous law.
///
/// Above `d` the substitution `z = d + v²` removes the `(z − d)^p` endpoint
/// behaviour; the upper end is placed where the Gaussian-bounded tail has lost
/// more than 16 orders of magnitude relative to the integral.
pub(crate) fn partial_moment(shape: &Shape<'_>, d: f64, p: f64) -> f64 {
    let s = shape.scale;
    let reach = if d <= shape.centre {
        shape.centre - d + s * (14.0 + 2.0 * p.sqrt())
    } else {
        let t = (d - shape.centre) / s;
        s * (14.0 + 2.0 * p.sqrt()).min((50.0 + 4.0 * p) / t)
    };
    let upper = d + reach;
    if upper.is_nan() {
        return f64::NAN;
    }
    if upper <= shape.lower {
        return 0.0;
    }
    let pdf = shape.pdf;
    let start = shape.lower.max(shape.negligible_below);
    let est = if d < start {
        // The bulk lies wholly above d: (z − d)^p is smooth there, and integrating
        // in z keeps the abscissae exact however far below d is (a substitution
        // z = d + v² would round z at the level ε·|d|). The neglected slice
        // [d, start] weighs less than 1e-19 of the result.
        let breaks: Vec<f64> = shape
            .landmarks
            .iter()
            .copied()
            .filter(|&z| z > start && z < upper)
            .collect();
        integrate_adaptive(
            |z| {
                let f = pdf(z);
                if f == 0.0 {
                    0.0
                } else {
                    (z - d).powf(p) * f
                }
            },
            start,
            upper,
            &breaks,
            &OPTS,
            Exhausted::BestEstimate,
        )
    } else {
        let breaks: Vec<f64> = shape
            .landmarks
            .iter()
            .filter(|&&z| z > d && z < upper)
            .map(|&z| (z - d).sqrt())
            .collect();
        let q = 2.0 * p + 1.0;
        integrate_adaptive(
            |v| {
                let f = pdf(d + v * v);
                if f == 0.0 {
                    0.0
                } else {
                    2.0 * v.powf(q) * f
                }
            },
            0.0,
            reach.sqrt(),
            &breaks,
            &OPTS,
            Exhausted::BestEstimate,
        )
    };
    // The densities are finite everywhere, so the only failure left would be a
    // non-finite integrand; report it as NaN rather than panicking.
    est.map(|e| e.value.max(0.0)).unwrap_or(f64::NAN)
}
