//! Globally adaptive 21-point Gauss–Kronrod integration (G10/K21).

use super::mapping::{mapped_eval, ordered_limits, Mapping};
use super::QuadratureError;
use super::{Estimate, QuadOptions};
use crate::error::Stage;
use crate::{Error, Result};
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Kronrod abscissae on [−1, 1] (positive half, decreasing; the last is the centre).
/// Entries 1, 3, 5, 7, 9 are the 10-point Gauss–Legendre abscissae.
// Published digits are kept in full; the compiler rounds them correctly.
#[allow(clippy::excessive_precision)]
pub(crate) const XGK: [f64; 11] = [
    0.995_657_163_025_808_080_735_527_280_689_003,
    0.973_906_528_517_171_720_077_964_012_084_452,
    0.930_157_491_355_708_226_001_207_180_059_508,
    0.865_063_366_688_984_510_732_096_688_423_493,
    0.780_817_726_586_416_897_063_717_578_345_042,
    0.679_409_568_299_024_406_234_327_365_114_874,
    0.562_757_134_668_604_683_339_000_099_272_694,
    0.433_395_394_129_247_190_799_265_943_165_784,
    0.294_392_862_701_460_198_131_126_603_103_866,
    0.148_874_338_981_631_210_884_826_001_129_720,
    0.0,
];

/// Kronrod weights matching [`XGK`].
// Published digits are kept in full; the compiler rounds them correctly.
#[allow(clippy::excessive_precision)]
pub(crate) const WGK: [f64; 11] = [
    0.011_694_638_867_371_874_278_064_396_062_192,
    0.032_558_162_307_964_727_478_818_972_459_390,
    0.054_755_896_574_351_996_031_381_300_244_580,
    0.075_039_674_810_919_952_767_043_140_916_190,
    0.093_125_454_583_697_605_535_065_465_083_366,
    0.109_387_158_802_297_641_899_210_590_325_805,
    0.123_491_976_262_065_851_077_208_980_040_298,
    0.134_709_217_311_473_325_928_054_001_771_707,
    0.142_775_938_577_060_080_797_094_273_138_717,
    0.147_739_104_901_338_491_374_841_515_972_068,
    0.149_445_554_002_916_905_664_936_468_389_821,
];

/// 10-point Gauss weights for abscissae `XGK[1], XGK[3], …, XGK[9]`.
// Published digits are kept in full; the compiler rounds them correctly.
#[allow(clippy::excessive_precision)]
pub(crate) const WG: [f64; 5] = [
    0.066_671_344_308_688_137_593_568_809_893_332,
    0.149_451_349_150_580_593_145_776_339_657_697,
    0.219_086_362_515_982_043_995_534_934_228_163,
    0.269_266_719_309_996_355_091_226_921_569_469,
    0.295_524_224_714_752_870_173_892_994_651_338,
];

const WHAT: Stage = Stage::GAUSS_KRONROD;

/// One subinterval with its local estimate, ordered by local error.
#[derive(Clone, Copy, Debug)]
struct Segment {
    a: f64,
    b: f64,
    value: f64,
    error: f64,
    /// Rounding level of the local estimate, 50ε·∫|f|.
    floor: f64,
}

impl PartialEq for Segment {
    fn eq(&self, other: &Self) -> bool {
        self.error.total_cmp(&other.error) == Ordering::Equal
    }
}
impl Eq for Segment {}
impl PartialOrd for Segment {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Segment {
    fn cmp(&self, other: &Self) -> Ordering {
        self.error.total_cmp(&other.error)
    }
}

/// Applies the 21-point Kronrod rule and its embedded 10-point Gauss rule on
/// `[a, b]` in the mapped variable. The error estimate follows the usual
/// heuristic: `|K − G|` scaled against the integrand's variation, and never
/// below the rounding level of `∫|f|`.
fn kronrod<F: FnMut(f64) -> f64>(
    f: &mut F,
    map: &Mapping,
    a: f64,
    b: f64,
    evals: &mut usize,
) -> Result<Segment> {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let fc = mapped_eval(f, map, c, WHAT)?;
    let mut fv = [(0.0, 0.0); 10];
    let mut resk = WGK[10] * fc;
    let mut resg = 0.0;
    let mut resabs = WGK[10] * fc.abs();
    for j in 0..10 {
        let dx = h * XGK[j];
        let f1 = mapped_eval(f, map, c - dx, WHAT)?;
        let f2 = mapped_eval(f, map, c + dx, WHAT)?;
        fv[j] = (f1, f2);
        resk += WGK[j] * (f1 + f2);
        resabs += WGK[j] * (f1.abs() + f2.abs());
        if j % 2 == 1 {
            resg += WG[j / 2] * (f1 + f2);
        }
    }
    *evals += 21;
    let mean = 0.5 * resk;
    let mut resasc = WGK[10] * (fc - mean).abs();
    for j in 0..10 {
        resasc += WGK[j] * ((fv[j].0 - mean).abs() + (fv[j].1 - mean).abs());
    }
    let ah = h.abs();
    let value = resk * h;
    let resabs = resabs * ah;
    let resasc = resasc * ah;
    let mut error = ((resk - resg) * h).abs();
    if resasc != 0.0 && error != 0.0 {
        error = resasc * (200.0 * error / resasc).powf(1.5).min(1.0);
    }
    let floor = 50.0 * f64::EPSILON * resabs;
    if resabs > f64::MIN_POSITIVE / (50.0 * f64::EPSILON) {
        error = error.max(floor);
    }
    Ok(Segment {
        a,
        b,
        value,
        error,
        floor,
    })
}

/// Adaptive Gauss–Kronrod (G10/K21) integration of `f` over `[a, b]` with a
/// global error estimate; `a` and/or `b` may be infinite (rational substitution).
///
/// Returns `Err(NoConvergence)` when `max_intervals` subintervals do not meet
/// `max(abs_tol, rel_tol·|value|)` (targets below the rounding level
/// `50ε·∫|f|` are met at that level; the reported error says so), when an interval can no longer be split, or
/// when the integrand returns a non-finite value. `a > b` gives the negated
/// integral over `[b, a]`.
///
/// ```
/// use hdi_tribology::quadrature::{integrate, QuadOptions};
/// let est = integrate(|x: f64| 1.0 / x.sqrt(), 0.0, 1.0, &QuadOptions::default()).unwrap();
/// assert!((est.value - 2.0).abs() < 1e-11);
/// assert!(est.error <= 1e-11);
/// ```
pub fn integrate<F: FnMut(f64) -> f64>(
    f: F,
    a: f64,
    b: f64,
    opts: &QuadOptions,
) -> Result<Estimate> {
    integrate_with_breaks(f, a, b, &[], opts)
}

/// Same as [`integrate`], with interior break points (kinks, steps, peaks)
/// where the range is split before adaptation. Break points outside `(a, b)`
/// or non-finite are ignored.
///
/// ```
/// use hdi_tribology::quadrature::{integrate_with_breaks, QuadOptions};
/// // |x − 0.3| has a kink at 0.3: ∫_0^1 = (0.3² + 0.7²)/2 = 0.29
/// let est = integrate_with_breaks(|x: f64| (x - 0.3).abs(), 0.0, 1.0, &[0.3],
///                                 &QuadOptions::default()).unwrap();
/// assert!((est.value - 0.29).abs() < 1e-14);
/// ```
pub fn integrate_with_breaks<F: FnMut(f64) -> f64>(
    f: F,
    a: f64,
    b: f64,
    breaks: &[f64],
    opts: &QuadOptions,
) -> Result<Estimate> {
    integrate_adaptive(f, a, b, breaks, opts, Exhausted::Fail)
}

/// What [`integrate_adaptive`] gives when its interval budget is spent (or an interval cannot be
/// split) before the target is met.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Exhausted {
    /// An error: [`QuadratureError::IntervalBudget`] or [`QuadratureError::CannotSplit`].
    Fail,
    /// The best estimate, whose `error` field then exceeds the target. Non-finite integrand
    /// values are still errors.
    BestEstimate,
}

/// [`integrate_with_breaks`], with what to do when the interval budget is spent.
pub(crate) fn integrate_adaptive<F: FnMut(f64) -> f64>(
    mut f: F,
    a: f64,
    b: f64,
    breaks: &[f64],
    opts: &QuadOptions,
    exhausted: Exhausted,
) -> Result<Estimate> {
    let strict = exhausted == Exhausted::Fail;
    opts.validate()?;
    let Some((lo, hi, sign)) = ordered_limits(a, b)? else {
        return Ok(Estimate::EMPTY);
    };
    let (map, ta, tb) = Mapping::new(lo, hi)?;
    let mut cuts: Vec<f64> = breaks
        .iter()
        .filter(|x| x.is_finite() && **x > lo && **x < hi)
        .map(|&x| map.inverse(x))
        .filter(|t| *t > ta && *t < tb)
        .collect();
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    if cuts.len() + 1 > opts.max_intervals {
        return Err(Error::invalid(
            "quad.max_intervals",
            format!(
                "{} break points need more than max_intervals = {} intervals",
                cuts.len(),
                opts.max_intervals
            ),
        ));
    }

    let mut evals = 0usize;
    let mut heap = BinaryHeap::with_capacity(opts.max_intervals.min(4096));
    let mut left = ta;
    for &c in cuts.iter().chain(std::iter::once(&tb)) {
        heap.push(kronrod(&mut f, &map, left, c, &mut evals)?);
        left = c;
    }

    loop {
        // Re-summing each round avoids drift from repeated add/subtract of errors.
        let (value, error, floor) = heap.iter().fold((0.0, 0.0, 0.0), |(v, e, r), s| {
            (v + s.value, e + s.error, r + s.floor)
        });
        // Only the part of the error above the rounding level can be refined away.
        if error - floor <= opts.target(value) || (!strict && heap.len() >= opts.max_intervals) {
            return Ok(Estimate {
                value: sign * value,
                error,
                evaluations: evals,
            });
        }
        if heap.len() >= opts.max_intervals {
            return Err(QuadratureError::IntervalBudget {
                max_intervals: opts.max_intervals,
                error,
                value,
                target: opts.target(value),
            }
            .into());
        }
        let Some(worst) = heap.pop() else {
            return Err(QuadratureError::NoIntervalLeft.into());
        };
        let mid = 0.5 * (worst.a + worst.b);
        if !(mid > worst.a && mid < worst.b) {
            if !strict {
                heap.push(worst);
                return Ok(Estimate {
                    value: sign * value,
                    error,
                    evaluations: evals,
                });
            }
            return Err(QuadratureError::CannotSplit {
                x: map.apply(mid).0,
                error,
                target: opts.target(value),
            }
            .into());
        }
        heap.push(kronrod(&mut f, &map, worst.a, mid, &mut evals)?);
        heap.push(kronrod(&mut f, &map, mid, worst.b, &mut evals)?);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Legendre P_n(x) and P_n'(x) by the three-term recurrence.
    fn legendre(n: usize, x: f64) -> (f64, f64) {
        let (mut p0, mut p1) = (1.0, x);
        for k in 2..=n {
            let k = k as f64;
            let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
            p0 = p1;
            p1 = p2;
        }
        let dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
        (p1, dp)
    }

    #[test]
    fn gauss_nodes_are_legendre_roots_with_matching_weights() {
        for i in 0..5 {
            let x = XGK[2 * i + 1];
            let (p, dp) = legendre(10, x);
            // |P10| near a root is ~|P10'|·δx; 1e-14 bounds δx to ~1e-15.
            assert!(p.abs() < 1e-14, "P10({x}) = {p}");
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            assert!((w - WG[i]).abs() < 1e-15, "weight {i}: {w} vs {}", WG[i]);
        }
    }

    #[test]
    fn kronrod_rule_is_exact_to_degree_31() {
        // Σ w x^k over the symmetric rule equals ∫_{−1}^{1} x^k = 2/(k+1) for even k.
        for k in (0..=30).step_by(2) {
            let mut s = WGK[10] * if k == 0 { 1.0 } else { 0.0 };
            for j in 0..10 {
                s += 2.0 * WGK[j] * XGK[j].powi(k);
            }
            let exact = 2.0 / (k as f64 + 1.0);
            assert!((s - exact).abs() < 4e-16, "degree {k}: {s} vs {exact}");
        }
        // ...and not beyond: at degree 32 the rule errs by ~4e-12, far above the
        // rounding level of the sums above (a rule of higher degree would mean
        // these are not the K21 constants).
        let mut s = 0.0;
        for j in 0..10 {
            s += 2.0 * WGK[j] * XGK[j].powi(32);
        }
        assert!((s - 2.0 / 33.0).abs() > 1e-13);
    }
}
