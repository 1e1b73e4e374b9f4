//! Thermal fly-height control: heater power programmes and the protrusion they make.
//!
//! Protrusion at steady state is `δ = η P` (η in m/W); an optional first-order thermal lag
//! `τ_th δ̇ = η P(t) − δ` is handled by the slider model as an extra state.

use crate::error::{check_finite, check_non_negative, Error, Result};

/// A piecewise-linear heater power programme `P(t)` through knots `(t, P)`.
///
/// Before the first knot the power is that of the first knot; after the last, that of the last.
///
/// ```
/// use hdi_tribology::heater::Programme;
/// use hdi_tribology::units::{mw, ms};
/// let p = Programme::new(vec![(0.0, mw(60.0)), (ms(3.6), mw(78.0)), (ms(4.0), mw(78.0)), (ms(7.6), mw(60.0))])?;
/// assert!((p.power(ms(1.8)) - mw(69.0)).abs() < 1e-15);
/// assert_eq!(p.end_time(), ms(7.6));
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Programme {
    // Shared so that cloning a programme (once per controller step in `drive`) allocates nothing.
    knots: std::sync::Arc<[(f64, f64)]>,
}

impl Programme {
    /// Builds a programme; knot times must be finite and strictly increasing, powers finite and ≥ 0,
    /// and there must be at least two knots.
    pub fn new(knots: Vec<(f64, f64)>) -> Result<Self> {
        if knots.len() < 2 {
            return Err(Error::invalid(
                "heater.programme",
                format!("needs at least 2 knots, got {}", knots.len()),
            ));
        }
        for (i, &(t, p)) in knots.iter().enumerate() {
            check_finite(&format!("heater.programme[{i}].time"), t)?;
            check_non_negative(&format!("heater.programme[{i}].power"), p)?;
            if i > 0 && t <= knots[i - 1].0 {
                return Err(Error::invalid(
                    format!("heater.programme[{i}].time"),
                    format!(
                        "knot times must increase strictly, got {t} after {}",
                        knots[i - 1].0
                    ),
                ));
            }
        }
        Ok(Programme {
            knots: knots.into(),
        })
    }

    /// A constant power held from `t = 0` to `t_end`.
    ///
    /// ```
    /// let p = hdi_tribology::heater::Programme::constant(0.05, 1e-3)?;
    /// assert_eq!(p.power(5e-4), 0.05);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn constant(power: f64, t_end: f64) -> Result<Self> {
        Programme::new(vec![(0.0, power), (t_end, power)])
    }

    /// The knots `(t, P)`.
    pub fn knots(&self) -> &[(f64, f64)] {
        &self.knots
    }

    /// Power at time `t` (W).
    pub fn power(&self, t: f64) -> f64 {
        self.power_and_rate(t).0
    }

    /// Power (W) and its time derivative (W/s) at `t`; at a knot the rate of the segment that
    /// starts there.
    pub fn power_and_rate(&self, t: f64) -> (f64, f64) {
        let k = &self.knots;
        let last = k.len() - 1;
        if t <= k[0].0 {
            return (k[0].1, 0.0);
        }
        if t >= k[last].0 {
            return (k[last].1, 0.0);
        }
        // Index of the segment [k[i], k[i+1]) that holds t.
        let i = k.partition_point(|&(tk, _)| tk <= t) - 1;
        let (t0, p0) = k[i];
        let (t1, p1) = k[i + 1];
        let rate = (p1 - p0) / (t1 - t0);
        (p0 + rate * (t - t0), rate)
    }

    /// Time of the first knot.
    pub fn start_time(&self) -> f64 {
        self.knots[0].0
    }

    /// Time of the last knot.
    pub fn end_time(&self) -> f64 {
        self.knots[self.knots.len() - 1].0
    }

    /// Highest power of the programme.
    pub fn max_power(&self) -> f64 {
        self.knots
            .iter()
            .map(|k| k.1)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Time of the last knot at the highest power: the end of the hold, where take-off detection
    /// starts (PAPER_SCENE conventions).
    pub fn end_of_hold(&self) -> f64 {
        let pmax = self.max_power();
        self.knots
            .iter()
            .rev()
            .find(|k| k.1 == pmax)
            .map_or(self.end_time(), |k| k.0)
    }

    /// Knot times strictly inside `(t0, t1)`: where the right-hand side has kinks.
    pub fn kinks_between(&self, t0: f64, t1: f64) -> Vec<f64> {
        self.knots
            .iter()
            .map(|k| k.0)
            .filter(|&t| t > t0 && t < t1)
            .collect()
    }
}

impl Programme {
    /// [`Programme::new`] from `(time in ms, power in mW)` knots, as a drive's heater table
    /// is usually written.
    ///
    /// ```
    /// use hdi_tribology::heater::Programme;
    /// let p = Programme::from_ms_mw(&[(0.0, 60.0), (3.6, 78.0), (4.0, 78.0), (7.6, 60.0)])?;
    /// assert!((p.power(1.8e-3) - 69e-3).abs() < 1e-15);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn from_ms_mw(knots_ms_mw: &[(f64, f64)]) -> Result<Self> {
        Programme::new(
            knots_ms_mw
                .iter()
                .map(|&(t, p)| (crate::units::ms(t), crate::units::mw(p)))
                .collect(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_and_holds_outside() {
        let p = Programme::new(vec![(1.0, 2.0), (3.0, 6.0), (4.0, 0.0)]).unwrap();
        assert_eq!(p.power(0.0), 2.0);
        assert_eq!(p.power(2.0), 4.0);
        assert_eq!(p.power_and_rate(3.5), (3.0, -6.0));
        assert_eq!(p.power(9.0), 0.0);
        assert_eq!(p.end_of_hold(), 3.0);
        assert_eq!(p.kinks_between(0.0, 3.5), vec![1.0, 3.0]);
    }

    #[test]
    fn rejects_bad_knots() {
        assert!(Programme::new(vec![(0.0, 1.0)]).is_err());
        let e = Programme::new(vec![(0.0, 1.0), (0.0, 2.0)]).unwrap_err();
        assert!(e.to_string().contains("heater.programme[1].time"));
        let e = Programme::new(vec![(0.0, 1.0), (1.0, -2.0)]).unwrap_err();
        assert!(e.to_string().contains("heater.programme[1].power"));
        assert!(Programme::new(vec![(0.0, f64::NAN), (1.0, 2.0)]).is_err());
    }
}
