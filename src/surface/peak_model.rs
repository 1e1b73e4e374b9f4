//! Serde description of any peak-height law, for scene files.

use super::{Discrete, Empirical, Gaussian, PeakDistribution, RiceMaxima, Rician};
use crate::{Error, Result};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// A peak-height law as written in a scene file (`family = "..."`), SI units.
///
/// ```
/// use hdi_tribology::surface::PeakModel;
/// let m: PeakModel = toml::from_str("family = \"rice_maxima\"\nsigma_m = 1e-9\nepsilon = 0.6")
///     .unwrap();
/// let law = m.build().unwrap();
/// assert!(law.mean() > 0.0);
/// let bad = PeakModel::Gaussian { mean_m: 0.0, std_m: -1.0 };
/// assert!(bad.build().unwrap_err().to_string().contains("peaks.std_m"));
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "family", rename_all = "snake_case", deny_unknown_fields)]
pub enum PeakModel {
    /// [`Gaussian`] with mean and standard deviation (m).
    Gaussian {
        /// Mean peak height (m).
        mean_m: f64,
        /// Standard deviation (m).
        std_m: f64,
    },
    /// [`RiceMaxima`]: maxima of a Gaussian process.
    RiceMaxima {
        /// rms height of the process (m).
        sigma_m: f64,
        /// Spectral width parameter in (0, 1].
        epsilon: f64,
    },
    /// [`Rician`] law.
    Rician {
        /// Location ν (m).
        nu_m: f64,
        /// Scale s (m).
        s_m: f64,
    },
    /// [`Empirical`] from a histogram.
    Histogram {
        /// Bin edges (m), strictly increasing.
        edges_m: Vec<f64>,
        /// Counts per bin (any positive scale).
        counts: Vec<f64>,
    },
    /// [`Empirical`] from a sample of heights.
    Sample {
        /// Measured peak heights (m).
        heights_m: Vec<f64>,
    },
    /// [`Discrete`] ensemble of given heights.
    Discrete {
        /// Peak heights (m).
        heights_m: Vec<f64>,
    },
    /// [`Discrete`] ensemble of `n` heights drawn from another law with `seed`.
    DiscreteSampled {
        /// The parent law.
        from: Box<PeakModel>,
        /// Number of peaks.
        n: usize,
        /// Seed of the random stream.
        seed: u64,
    },
}

/// Renames the field of an input error to `prefix.name`.
fn rename(e: Error, prefix: &str, name: &str) -> Error {
    match e {
        Error::InvalidInput { reason, .. } => Error::invalid(format!("{prefix}.{name}"), reason),
        other => other,
    }
}

/// Maps the constructors' field names to the serde names.
fn serde_name(field: &str) -> &'static str {
    match field.rsplit('.').next().unwrap_or("") {
        "mean" => "mean_m",
        "std" => "std_m",
        "sigma" => "sigma_m",
        "epsilon" => "epsilon",
        "nu" => "nu_m",
        "s" => "s_m",
        "edges" => "edges_m",
        "counts" => "counts",
        "n" => "n",
        _ => "heights_m",
    }
}

fn renamed<T>(r: Result<T>, prefix: &str) -> Result<T> {
    r.map_err(|e| match &e {
        Error::InvalidInput { field, .. } => {
            let name = serde_name(field);
            rename(e, prefix, name)
        }
        _ => e,
    })
}

impl PeakModel {
    /// Validates and builds the law; errors name the field as `peaks.<field>`
    /// (`peaks.from.<field>` inside `discrete_sampled`).
    pub fn build(&self) -> Result<Arc<dyn PeakDistribution>> {
        self.build_at("peaks")
    }

    fn build_at(&self, prefix: &str) -> Result<Arc<dyn PeakDistribution>> {
        Ok(match self {
            PeakModel::Gaussian { mean_m, std_m } => {
                Arc::new(renamed(Gaussian::new(*mean_m, *std_m), prefix)?)
            }
            PeakModel::RiceMaxima { sigma_m, epsilon } => {
                Arc::new(renamed(RiceMaxima::new(*sigma_m, *epsilon), prefix)?)
            }
            PeakModel::Rician { nu_m, s_m } => Arc::new(renamed(Rician::new(*nu_m, *s_m), prefix)?),
            PeakModel::Histogram { edges_m, counts } => {
                Arc::new(renamed(Empirical::from_histogram(edges_m, counts), prefix)?)
            }
            PeakModel::Sample { heights_m } => {
                Arc::new(renamed(Empirical::from_sample(heights_m), prefix)?)
            }
            PeakModel::Discrete { heights_m } => {
                Arc::new(renamed(Discrete::from_heights(heights_m.clone()), prefix)?)
            }
            PeakModel::DiscreteSampled { from, n, seed } => {
                let parent = from.build_at(&format!("{prefix}.from"))?;
                Arc::new(renamed(
                    Discrete::sample(parent.as_ref(), *n, *seed),
                    prefix,
                )?)
            }
        })
    }
}
