//! A discrete ensemble of N asperity peaks ("the interaction is only with a few
//! peaks"), given or drawn reproducibly from a continuous law.

use super::empirical::{check_finite_heights, MAX_INPUT_LEN};
use super::PeakDistribution;
use crate::numerics::rng::Xoshiro256;
use crate::quadrature::{Table, TableOptions};
use crate::{Error, Result};

/// N peaks of given heights; `M_p(d) = (1/N) Σ (z_i − d)_+^p`, where for p = 0
/// a peak counts when `z_i > d` strictly.
///
/// ```
/// use hdi_tribology::surface::{Discrete, Gaussian, PeakDistribution};
/// let d = Discrete::from_heights(vec![1.0, 3.0]).unwrap();
/// assert_eq!(d.partial_moment(2.0, 1.0), 0.5);
/// let parent = Gaussian::new(0.0, 1.0).unwrap();
/// let a = Discrete::sample(&parent, 100, 7).unwrap();
/// let b = Discrete::sample(&parent, 100, 7).unwrap();
/// assert_eq!(a, b);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Discrete {
    /// Sorted ascending.
    heights: Vec<f64>,
    mean: f64,
    std: f64,
}

impl Discrete {
    /// An ensemble from peak heights (m): non-empty, finite, at most 10 000 000.
    /// Errors name `peaks.heights`.
    pub fn from_heights(heights: Vec<f64>) -> Result<Self> {
        Self::from_heights_named(heights, "peaks.heights")
    }

    pub(crate) fn from_heights_named(mut heights: Vec<f64>, field: &str) -> Result<Self> {
        if heights.is_empty() {
            return Err(Error::invalid(field, "must not be empty"));
        }
        if heights.len() > MAX_INPUT_LEN {
            return Err(Error::invalid(
                field,
                format!("too many heights: {} > {MAX_INPUT_LEN}", heights.len()),
            ));
        }
        check_finite_heights(field, &heights)?;
        heights.sort_by(f64::total_cmp);
        let n = heights.len() as f64;
        let mean = heights.iter().sum::<f64>() / n;
        let var = heights.iter().map(|z| (z - mean).powi(2)).sum::<f64>() / n;
        Ok(Discrete {
            heights,
            mean,
            std: var.sqrt(),
        })
    }

    /// Draws `n` peak heights from `parent` with a seeded xoshiro256** stream
    /// (same seed, same uniform stream on every platform; the heights then pass through
    /// the family's functions in floating point, whose library calls may round differently
    /// on another platform). Sampling inverts the
    /// survival function: exactly for families that provide
    /// [`PeakDistribution::inverse_survival`], through a table of
    /// `partial_moment(·, 0)` with absolute accuracy 1e-13 otherwise; discrete
    /// parents are resampled uniformly. Errors name `peaks.n`.
    pub fn sample(parent: &dyn PeakDistribution, n: usize, seed: u64) -> Result<Self> {
        Self::sample_named(parent, n, seed, "peaks.n")
    }

    pub(crate) fn sample_named(
        parent: &dyn PeakDistribution,
        n: usize,
        seed: u64,
        field: &str,
    ) -> Result<Self> {
        if n == 0 || n > MAX_INPUT_LEN {
            return Err(Error::invalid(
                field,
                format!("must be in 1..={MAX_INPUT_LEN}, got {n}"),
            ));
        }
        let mut rng = Xoshiro256::new(seed);
        let mut out = Vec::with_capacity(n);
        if let Some(atoms) = parent.atoms() {
            for _ in 0..n {
                out.push(atoms[rng.next_below(atoms.len())]);
            }
        } else if parent.inverse_survival(0.5).is_some() {
            for _ in 0..n {
                let q = rng.next_open01();
                let z = parent.inverse_survival(q).ok_or_else(|| {
                    Error::from(crate::error::Internal {
                        stage: crate::error::Stage::named("peak sampling"),
                        what: "inverse survival failed",
                    })
                })?;
                out.push(z);
            }
        } else {
            let (lo, hi) = parent.support();
            let opts = TableOptions {
                rel_tol: 1e-10,
                abs_tol: 1e-13,
                max_nodes: 200_000,
            };
            let table = Table::build(
                |z| Ok((parent.partial_moment(z, 0.0), -parent.pdf(z))),
                lo,
                hi,
                &opts,
            )?;
            for _ in 0..n {
                let q = rng.next_open01();
                out.push(invert_decreasing(&table, q, lo, hi));
            }
        }
        Self::from_heights_named(out, field)
    }

    /// Peak heights, sorted ascending (m).
    pub fn heights(&self) -> &[f64] {
        &self.heights
    }

    /// Number of peaks.
    pub fn len(&self) -> usize {
        self.heights.len()
    }

    /// Always false: an ensemble has at least one peak.
    pub fn is_empty(&self) -> bool {
        self.heights.is_empty()
    }
}

/// Bisection for `S(z) = q` on a tabulated decreasing survival function.
fn invert_decreasing(table: &Table, q: f64, lo: f64, hi: f64) -> f64 {
    let (mut a, mut b) = (lo, hi);
    for _ in 0..100 {
        let m = 0.5 * (a + b);
        if !(m > a && m < b) {
            break;
        }
        let s = table.eval(m).map_or(0.0, |v| v.0);
        if s > q {
            a = m;
        } else {
            b = m;
        }
    }
    0.5 * (a + b)
}

impl PeakDistribution for Discrete {
    fn pdf(&self, _z: f64) -> f64 {
        0.0
    }

    fn partial_moment(&self, d: f64, p: f64) -> f64 {
        let first = self.heights.partition_point(|&z| z <= d);
        let above = &self.heights[first..];
        let sum: f64 = if p == 0.0 {
            above.len() as f64
        } else {
            above.iter().map(|&z| (z - d).powf(p)).sum()
        };
        sum / self.heights.len() as f64
    }

    fn support(&self) -> (f64, f64) {
        (self.heights[0], self.heights[self.heights.len() - 1])
    }

    fn mean(&self) -> f64 {
        self.mean
    }

    fn std_dev(&self) -> f64 {
        self.std
    }

    fn inverse_survival(&self, q: f64) -> Option<f64> {
        if !(q > 0.0 && q < 1.0) {
            return None;
        }
        let n = self.heights.len();
        let i = (((1.0 - q) * n as f64) as usize).min(n - 1);
        Some(self.heights[i])
    }

    fn atoms(&self) -> Option<&[f64]> {
        Some(&self.heights)
    }
}

impl Discrete {
    /// [`Discrete::from_heights`] with the heights in nanometres.
    ///
    /// ```
    /// use hdi_tribology::surface::Discrete;
    /// let d = Discrete::from_heights_nm(&[0.5, -0.25, 1.0])?;
    /// assert_eq!(d, Discrete::from_heights(vec![0.5e-9, -0.25e-9, 1e-9])?);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn from_heights_nm(heights_nm: &[f64]) -> Result<Self> {
        Discrete::from_heights(heights_nm.iter().map(|&h| crate::units::nm(h)).collect())
    }
}
