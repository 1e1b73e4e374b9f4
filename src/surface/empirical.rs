//! Empirical peak heights from a measured histogram or sample (e.g. an AFM scan).

use super::PeakDistribution;
use crate::{Error, Result};

/// Largest accepted number of bins or samples.
pub const MAX_INPUT_LEN: usize = 10_000_000;
/// Largest number of bins produced from a sample.
const MAX_SAMPLE_BINS: usize = 100_000;

/// Piecewise-constant density: probability `w_i` spread uniformly over bin
/// `[e_i, e_{i+1})`. Normalised by the crate; partial moments in closed form per bin.
///
/// ```
/// use hdi_tribology::surface::{Empirical, PeakDistribution};
/// // uniform on [0, 2] in two bins
/// let e = Empirical::from_histogram(&[0.0, 1.0, 2.0], &[3.0, 3.0]).unwrap();
/// assert!((e.pdf(0.5) - 0.5).abs() < 1e-15);
/// // M_1(1) = ∫_1^2 (z−1)/2 dz = 1/4
/// assert!((e.partial_moment(1.0, 1.0) - 0.25).abs() < 1e-15);
/// assert!(Empirical::from_histogram(&[0.0, 1.0], &[-1.0]).is_err());
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Empirical {
    edges: Vec<f64>,
    /// Probability of each bin (sums to 1).
    weights: Vec<f64>,
    /// Density of each bin (1/m).
    density: Vec<f64>,
    mean: f64,
    std: f64,
}

fn check_len(field: &str, n: usize) -> Result<()> {
    if n > MAX_INPUT_LEN {
        return Err(Error::invalid(
            field,
            format!("too many entries: {n} > {MAX_INPUT_LEN}"),
        ));
    }
    Ok(())
}

/// Every one of `heights` finite; else an error naming `field` and the first that is not.
pub(super) fn check_finite_heights(field: &str, heights: &[f64]) -> Result<()> {
    match heights.iter().enumerate().find(|(_, z)| !z.is_finite()) {
        Some((i, z)) => Err(Error::invalid(
            field,
            format!("height {i} is not finite: {z}"),
        )),
        None => Ok(()),
    }
}

/// `(b − d)^{q} − (a − d)^{q}` for d ≤ a < b, without cancellation when the bin
/// is narrow compared with its distance from d.
fn power_difference(a: f64, b: f64, d: f64, q: f64) -> f64 {
    let x = a - d;
    if x > 0.0 {
        x.powf(q) * (q * ((b - a) / x).ln_1p()).exp_m1()
    } else {
        (b - d).powf(q)
    }
}

impl Empirical {
    /// From bin edges (strictly increasing, finite, `counts.len() + 1` of them)
    /// and non-negative counts with a positive total. Errors name
    /// `peaks.edges` / `peaks.counts`.
    pub fn from_histogram(edges: &[f64], counts: &[f64]) -> Result<Self> {
        Self::from_histogram_named(edges, counts, "peaks.edges", "peaks.counts")
    }

    pub(crate) fn from_histogram_named(
        edges: &[f64],
        counts: &[f64],
        edges_field: &str,
        counts_field: &str,
    ) -> Result<Self> {
        check_len(counts_field, counts.len())?;
        check_len(edges_field, edges.len())?;
        if counts.is_empty() {
            return Err(Error::invalid(counts_field, "must not be empty"));
        }
        if edges.len() != counts.len() + 1 {
            return Err(Error::invalid(
                edges_field,
                format!(
                    "needs counts.len() + 1 = {} edges, got {}",
                    counts.len() + 1,
                    edges.len()
                ),
            ));
        }
        if let Some((i, e)) = edges.iter().enumerate().find(|(_, e)| !e.is_finite()) {
            return Err(Error::invalid(
                edges_field,
                format!("edge {i} is not finite: {e}"),
            ));
        }
        if let Some(i) = edges.windows(2).position(|w| w[1] <= w[0]) {
            return Err(Error::invalid(
                edges_field,
                format!(
                    "must be strictly increasing; edge {} = {} is not above edge {} = {}",
                    i + 1,
                    edges[i + 1],
                    i,
                    edges[i]
                ),
            ));
        }
        if let Some((i, c)) = counts
            .iter()
            .enumerate()
            .find(|(_, c)| !(c.is_finite() && **c >= 0.0))
        {
            return Err(Error::invalid(
                counts_field,
                format!("count {i} must be finite and >= 0, got {c}"),
            ));
        }
        let total: f64 = counts.iter().sum();
        if !(total > 0.0 && total.is_finite()) {
            return Err(Error::invalid(
                counts_field,
                format!("total must be finite and > 0, got {total}"),
            ));
        }
        let weights: Vec<f64> = counts.iter().map(|c| c / total).collect();
        let density: Vec<f64> = weights
            .iter()
            .zip(edges.windows(2))
            .map(|(w, e)| w / (e[1] - e[0]))
            .collect();
        // Uniform within each bin: E[z] = Σ w (a+b)/2, E[(z−m)²] per bin about m.
        let mean: f64 = weights
            .iter()
            .zip(edges.windows(2))
            .map(|(w, e)| w * 0.5 * (e[0] + e[1]))
            .sum();
        let var: f64 = weights
            .iter()
            .zip(edges.windows(2))
            .map(|(w, e)| {
                let c = 0.5 * (e[0] + e[1]) - mean;
                let h = e[1] - e[0];
                w * (c * c + h * h / 12.0)
            })
            .sum();
        Ok(Empirical {
            edges: edges.to_vec(),
            weights,
            density,
            mean,
            std: var.sqrt(),
        })
    }

    /// From a sample of peak heights, binned by the Freedman–Diaconis rule
    /// (bin width `2·IQR·n^{−1/3}`; Scott's `3.49·s·n^{−1/3}` when the
    /// interquartile range is zero), bins spanning `[min, max]`, at most 100 000
    /// bins. Needs at least two distinct finite values. Errors name `peaks.sample`.
    pub fn from_sample(sample: &[f64]) -> Result<Self> {
        Self::from_sample_named(sample, "peaks.sample")
    }

    pub(crate) fn from_sample_named(sample: &[f64], field: &str) -> Result<Self> {
        check_len(field, sample.len())?;
        if sample.len() < 2 {
            return Err(Error::invalid(
                field,
                format!("needs at least 2 heights, got {}", sample.len()),
            ));
        }
        check_finite_heights(field, sample)?;
        let mut sorted = sample.to_vec();
        sorted.sort_by(f64::total_cmp);
        let n = sorted.len();
        let (lo, hi) = (sorted[0], sorted[n - 1]);
        if hi <= lo {
            return Err(Error::invalid(
                field,
                format!("all heights are equal ({lo}); a density needs spread"),
            ));
        }
        let quantile = |q: f64| {
            let x = q * (n - 1) as f64;
            let i = x.floor() as usize;
            let f = x - i as f64;
            if i + 1 < n {
                sorted[i] + f * (sorted[i + 1] - sorted[i])
            } else {
                sorted[n - 1]
            }
        };
        let iqr = quantile(0.75) - quantile(0.25);
        let cbrt_n = (n as f64).cbrt();
        let mut width = 2.0 * iqr / cbrt_n;
        if width <= 0.0 {
            let mean = sorted.iter().sum::<f64>() / n as f64;
            let var = sorted.iter().map(|z| (z - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
            width = 3.49 * var.sqrt() / cbrt_n;
        }
        let bins = (((hi - lo) / width).ceil() as usize).clamp(1, MAX_SAMPLE_BINS);
        let step = (hi - lo) / bins as f64;
        let mut edges: Vec<f64> = (0..=bins).map(|i| lo + step * i as f64).collect();
        edges[bins] = hi;
        let mut counts = vec![0.0; bins];
        for &z in &sorted {
            let i = (((z - lo) / step) as usize).min(bins - 1);
            counts[i] += 1.0;
        }
        Self::from_histogram_named(&edges, &counts, field, field)
    }

    /// Bin edges (m).
    pub fn edges(&self) -> &[f64] {
        &self.edges
    }

    /// Probability of each bin (sums to 1).
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }
}

impl PeakDistribution for Empirical {
    fn pdf(&self, z: f64) -> f64 {
        let n = self.density.len();
        if !(z >= self.edges[0] && z < self.edges[n]) {
            return 0.0;
        }
        // Index of the last edge ≤ z.
        let i = self.edges.partition_point(|&e| e <= z) - 1;
        self.density[i.min(n - 1)]
    }

    fn partial_moment(&self, d: f64, p: f64) -> f64 {
        let q = p + 1.0;
        let first = self.edges.partition_point(|&e| e <= d).saturating_sub(1);
        let mut sum = 0.0;
        for i in first..self.density.len() {
            let (a, b) = (self.edges[i], self.edges[i + 1]);
            if b <= d {
                continue;
            }
            sum += self.density[i] * power_difference(a.max(d), b, d, q);
        }
        sum / q
    }

    fn support(&self) -> (f64, f64) {
        (self.edges[0], self.edges[self.edges.len() - 1])
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
        // Walk down from the top bin: the cumulative weight above each edge.
        let mut above = 0.0;
        for i in (0..self.weights.len()).rev() {
            let w = self.weights[i];
            if above + w >= q && w > 0.0 {
                let frac = (q - above) / w;
                let (a, b) = (self.edges[i], self.edges[i + 1]);
                return Some(b - frac * (b - a));
            }
            above += w;
        }
        Some(self.edges[0])
    }
}

impl Empirical {
    /// [`Empirical::from_sample`] with the measured peak heights in nanometres, as a profiler
    /// exports them.
    ///
    /// ```
    /// use hdi_tribology::surface::{Empirical, PeakDistribution};
    /// let e = Empirical::from_sample_nm(&[0.1, 0.4, 0.5, 0.9, 1.3, 0.7, 0.2])?;
    /// assert!((e.mean() - 0.55e-9).abs() < 0.2e-9);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn from_sample_nm(sample_nm: &[f64]) -> Result<Self> {
        let sample: Vec<f64> = sample_nm.iter().map(|&h| crate::units::nm(h)).collect();
        Empirical::from_sample(&sample)
    }
}
