//! Small discrete-time filters for detectors that see irregular or uniform sample streams.

use crate::error::{check_positive, Result};
use std::f64::consts::PI;

/// First-order high-pass filter `H(s) = s τ / (1 + s τ)`, `τ = 1/(2π f_c)`, discretised per sample
/// from the actual sample interval (so the filter does not assume a fixed rate).
///
/// ```
/// use hdi_tribology::calibration::HighPass;
/// let mut hp = HighPass::new(1.0e3)?;
/// // A step of 5 passes at once, then decays as exp(−2π f_c t).
/// hp.filter(0.0, 0.0);
/// let first = hp.filter(1e-6, 5.0);
/// assert!((first - 5.0).abs() < 5.0 * 2e-2);
/// let mut out = first;
/// for i in 2..=1_000 {
///     out = hp.filter(i as f64 * 1e-6, 5.0);
/// }
/// let exact = 5.0 * (-2.0 * std::f64::consts::PI * 1e3 * 999e-6).exp() * first / 5.0;
/// assert!((out - exact).abs() < 1e-12);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct HighPass {
    tau: f64,
    last: Option<(f64, f64, f64)>,
}

impl HighPass {
    /// A high-pass filter with corner frequency `corner` (Hz, > 0).
    pub fn new(corner: f64) -> Result<Self> {
        check_positive("corner_frequency", corner)?;
        Ok(HighPass {
            tau: 1.0 / (2.0 * PI * corner),
            last: None,
        })
    }

    /// Forgets the past: the next sample is taken as the new baseline (output 0).
    pub fn reset(&mut self) {
        self.last = None;
    }

    /// Filters sample `x` taken at time `t`; returns the output. Samples at a non-increasing time
    /// leave the state unchanged and return the previous output.
    pub fn filter(&mut self, t: f64, x: f64) -> f64 {
        match self.last {
            None => {
                self.last = Some((t, x, 0.0));
                0.0
            }
            Some((t0, x0, y0)) => {
                let dt = t - t0;
                if dt <= 0.0 || !dt.is_finite() {
                    return y0;
                }
                // Exact response of the RC high-pass to a linear input between the two samples.
                let a = (-dt / self.tau).exp();
                let slope = (x - x0) / dt;
                let y = y0 * a + slope * self.tau * (1.0 - a);
                self.last = Some((t, x, y));
                y
            }
        }
    }
}

/// Exponentially weighted mean square with time constant `τ`; its square root is the running RMS.
///
/// ```
/// use hdi_tribology::calibration::MeanSquare;
/// let mut ms = MeanSquare::new(1e-4)?;
/// let f = 2.0e4;
/// let mut rms = 0.0;
/// for i in 0..20_000 {
///     let t = i as f64 * 1e-7;
///     rms = ms.update(t, (2.0 * std::f64::consts::PI * f * t).sin()).sqrt();
/// }
/// // A unit sine has an RMS of 1/√2; the exponential window leaves a ripple of about
/// // 1/(4π f τ) ≈ 4 % at twice the frequency.
/// assert!((rms - 0.5f64.sqrt()).abs() < 0.03);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct MeanSquare {
    tau: f64,
    value: f64,
    last_t: Option<f64>,
}

impl MeanSquare {
    /// A mean-square meter with averaging time `tau` (s, > 0).
    pub fn new(tau: f64) -> Result<Self> {
        check_positive("rms_time", tau)?;
        Ok(MeanSquare {
            tau,
            value: 0.0,
            last_t: None,
        })
    }

    /// Forgets the past.
    pub fn reset(&mut self) {
        self.value = 0.0;
        self.last_t = None;
    }

    /// Adds sample `x` at time `t`; returns the mean square.
    pub fn update(&mut self, t: f64, x: f64) -> f64 {
        if let Some(t0) = self.last_t {
            let dt = t - t0;
            if dt > 0.0 && dt.is_finite() {
                let a = (-dt / self.tau).exp();
                self.value = a * self.value + (1.0 - a) * x * x;
                self.last_t = Some(t);
            }
        } else {
            self.last_t = Some(t);
        }
        self.value
    }

    /// The current mean square.
    pub fn value(&self) -> f64 {
        self.value
    }
}
