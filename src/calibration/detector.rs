//! What a touchdown detector sees, the trait a detector implements, and three detectors.

use super::filters::{HighPass, MeanSquare};
use crate::error::{check_positive, Result};
use std::collections::VecDeque;
use std::fmt::Debug;

/// One sample of the simulated drive, as the firmware's sensors would see it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    /// Time (s).
    pub t: f64,
    /// Heater power commanded at that time (W).
    pub power: f64,
    /// Slider displacement `y` from its flying position, positive away from the disk (m).
    pub displacement: f64,
    /// Slider velocity (m/s).
    pub velocity: f64,
    /// Bulge gap `d` (m).
    pub gap: f64,
    /// Asperity contact force `F_c` (N).
    pub contact_force: f64,
    /// Total interface force `F_if` (N).
    pub interface_force: f64,
}

/// A touchdown detector: fed every sample in time order, it says whether it sees contact.
///
/// Implement it to try your own detection scheme in [`super::calibrate`]: the loop calls
/// [`TouchdownDetector::reset`] once before the first sample and then
/// [`TouchdownDetector::update`] for every sample; a heater step counts as "in contact" when
/// `update` returns `true` for any sample of its measurement window.
///
/// ```
/// use hdi_tribology::calibration::{Sample, TouchdownDetector};
/// /// Contact when the gap falls below a fixed value (a detector no drive has: for tests).
/// #[derive(Debug)]
/// struct GapBelow(f64);
/// impl TouchdownDetector for GapBelow {
///     fn name(&self) -> &str { "gap below" }
///     fn reset(&mut self) {}
///     fn update(&mut self, s: &Sample) -> bool { s.gap < self.0 }
///     fn level(&self) -> f64 { 0.0 }
/// }
/// let mut d = GapBelow(1e-9);
/// assert!(d.update(&Sample { gap: 0.5e-9, ..Sample::default() }));
/// ```
pub trait TouchdownDetector: Debug {
    /// A short name for reports.
    fn name(&self) -> &str;
    /// Forgets everything seen so far.
    fn reset(&mut self);
    /// Takes the next sample; `true` when the detector sees contact now.
    fn update(&mut self, sample: &Sample) -> bool;
    /// The quantity compared with the threshold, after the last update (detector's own unit).
    fn level(&self) -> f64;
    /// `true` for a detector that hears only changes (a high-pass filter before its RMS): in
    /// steady contact without an AC dither it hears nothing, so its take-off without a dither is
    /// the first step down, not a take-off (docs/clearance.md). `false` by default.
    ///
    /// ```
    /// use hdi_tribology::calibration::{ContactForceRms, MeanContactForce, TouchdownDetector};
    /// assert!(ContactForceRms::new(1e-5, 5e3, 5e-5)?.high_pass());
    /// assert!(!MeanContactForce::new(5e-5, 1e-5)?.high_pass());
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    fn high_pass(&self) -> bool {
        false
    }
}

/// The reference detector of the static model: the running mean of the contact force over a
/// trailing window reaches a force threshold (the `F_th` of the static and dynamic analyses).
///
/// ```
/// use hdi_tribology::calibration::{MeanContactForce, Sample, TouchdownDetector};
/// let mut d = MeanContactForce::new(5e-5, 1e-5)?;
/// let mut seen = false;
/// for i in 0..=20 {
///     seen = d.update(&Sample { t: i as f64 * 1e-6, contact_force: 6e-5, ..Sample::default() });
/// }
/// assert!(seen && (d.level() - 6e-5).abs() < 1e-18);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct MeanContactForce {
    threshold: f64,
    window: f64,
    buf: VecDeque<(f64, f64)>,
    mean: f64,
    since: Option<f64>,
}

impl MeanContactForce {
    /// Threshold `threshold` (N, > 0) on the mean over the trailing `window` (s, > 0).
    pub fn new(threshold: f64, window: f64) -> Result<Self> {
        check_positive("threshold", threshold)?;
        check_positive("window", window)?;
        Ok(MeanContactForce {
            threshold,
            window,
            buf: VecDeque::new(),
            mean: 0.0,
            since: None,
        })
    }
}

impl TouchdownDetector for MeanContactForce {
    fn name(&self) -> &str {
        "mean contact force"
    }

    fn reset(&mut self) {
        self.buf.clear();
        self.mean = 0.0;
        self.since = None;
    }

    fn update(&mut self, s: &Sample) -> bool {
        self.buf.push_back((s.t, s.contact_force));
        while self
            .buf
            .front()
            .is_some_and(|&(t, _)| t < s.t - self.window)
        {
            self.buf.pop_front();
        }
        let since = *self.since.get_or_insert(s.t);
        self.mean = self.buf.iter().map(|b| b.1).sum::<f64>() / self.buf.len() as f64;
        // Judge only once a whole window has been seen: a partial one over-weights its samples.
        s.t - since >= self.window && self.mean >= self.threshold
    }

    fn level(&self) -> f64 {
        self.mean
    }
}

/// High-pass filter, then running RMS: the shared core of the two vibration-type detectors.
#[derive(Clone, Debug, PartialEq)]
struct FilteredRms {
    threshold: f64,
    hp: HighPass,
    ms: MeanSquare,
    rms: f64,
}

impl FilteredRms {
    fn new(threshold: f64, corner: f64, rms_time: f64) -> Result<Self> {
        check_positive("threshold", threshold)?;
        Ok(FilteredRms {
            threshold,
            hp: HighPass::new(corner)?,
            ms: MeanSquare::new(rms_time)?,
            rms: 0.0,
        })
    }

    fn reset(&mut self) {
        self.hp.reset();
        self.ms.reset();
        self.rms = 0.0;
    }

    fn update(&mut self, t: f64, x: f64) -> bool {
        let y = self.hp.filter(t, x);
        self.rms = self.ms.update(t, y).sqrt();
        self.rms >= self.threshold
    }
}

/// Declares a detector that hears one signal of the [`Sample`] through a [`FilteredRms`]: the
/// type (its docs first), its constructor with the threshold in `$unit`, and its
/// [`TouchdownDetector`] implementation under `$label`.
macro_rules! filtered_rms_detector {
    ($(#[$doc:meta])* $name:ident, $label:literal, $signal:ident, $unit:literal) => {
        $(#[$doc])*
        #[derive(Clone, Debug, PartialEq)]
        pub struct $name(FilteredRms);

        impl $name {
            #[doc = concat!(
                "Threshold (", $unit, ", > 0) on the RMS, high-pass corner frequency (Hz, > 0) ",
                "and RMS averaging time (s, > 0)."
            )]
            pub fn new(threshold: f64, corner_frequency: f64, rms_time: f64) -> Result<Self> {
                Ok($name(FilteredRms::new(threshold, corner_frequency, rms_time)?))
            }
        }

        impl TouchdownDetector for $name {
            fn name(&self) -> &str {
                $label
            }
            fn high_pass(&self) -> bool {
                true
            }
            fn reset(&mut self) {
                self.0.reset();
            }
            fn update(&mut self, s: &Sample) -> bool {
                self.0.update(s.t, s.$signal)
            }
            fn level(&self) -> f64 {
                self.0.rms
            }
        }
    };
}

filtered_rms_detector! {
    /// Acoustic-emission proxy: RMS of the high-pass filtered contact force above a threshold.
    ///
    /// A real AE sensor hears the stress waves of asperity impacts; the lumped model has no
    /// impacts, so this proxy hears the part of the contact force that changes faster than the
    /// corner frequency: the burst of a jump into contact, and the modulation of the contact by an
    /// AC dither.
    ///
    /// ```
    /// use hdi_tribology::calibration::{ContactForceRms, Sample, TouchdownDetector};
    /// let mut d = ContactForceRms::new(1e-5, 5e3, 5e-5)?;
    /// let mut seen = false;
    /// for i in 0..2000 {
    ///     let t = i as f64 * 1e-6;
    ///     // A contact force modulated at 21 kHz with 50 µN amplitude.
    ///     let fc = 1e-4 + 5e-5 * (2.0 * std::f64::consts::PI * 2.1e4 * t).sin();
    ///     seen = d.update(&Sample { t, contact_force: fc, ..Sample::default() });
    /// }
    /// assert!(seen && d.level() > 3e-5);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    ContactForceRms, "AE proxy (HPF contact-force RMS)", contact_force, "N"
}

filtered_rms_detector! {
    /// Vibration detector: RMS of the high-pass filtered slider displacement above a threshold (a
    /// stand-in for the readback-modulation or PES-based detectors of drives).
    ///
    /// ```
    /// use hdi_tribology::calibration::{Sample, TouchdownDetector, VibrationRms};
    /// let mut d = VibrationRms::new(5e-11, 5e3, 5e-5)?;
    /// // A slow drift of 1 nm over 2 ms leaves slope·τ ≈ 0.016 nm after the filter: not seen.
    /// let mut seen = false;
    /// for i in 0..2000 {
    ///     let t = i as f64 * 1e-6;
    ///     seen |= d.update(&Sample { t, displacement: 1e-9 * t / 2e-3, ..Sample::default() });
    /// }
    /// assert!(!seen);
    /// // A 0.2 nm vibration at 21 kHz on top is (RMS ≈ 0.14 nm).
    /// for i in 2000..4000 {
    ///     let t = i as f64 * 1e-6;
    ///     let y = 1e-9 * t / 2e-3 + 2e-10 * (2.0 * std::f64::consts::PI * 2.1e4 * t).sin();
    ///     seen = d.update(&Sample { t, displacement: y, ..Sample::default() });
    /// }
    /// assert!(seen && d.level() > 1e-10);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    VibrationRms, "vibration (HPF displacement RMS)", displacement, "m"
}

/// Wraps a detector and also judges its level against its own baseline: contact when the inner
/// detector fires (its threshold is then an absolute floor) and its level reaches `ratio` times
/// the mean level seen over `[settle, settle + baseline]` after the reset, as drives do when the
/// flying signal (a dither's modulation, say) is not small.
///
/// Before the baseline is complete it never fires.
///
/// ```
/// use hdi_tribology::calibration::{Relative, Sample, TouchdownDetector, VibrationRms};
/// let inner = VibrationRms::new(1e-11, 5e3, 5e-5)?; // absolute floor 0.01 nm
/// let mut d = Relative::new(inner, 3.0, 1e-4, 1e-4)?;
/// let tone = |t: f64, a: f64| a * (2.0 * std::f64::consts::PI * 2.1e4 * t).sin();
/// let mut seen = false;
/// for i in 0..600 {
///     let t = i as f64 * 1e-6;
///     let a = if i < 400 { 1e-10 } else { 5e-10 }; // the vibration grows fivefold
///     seen = d.update(&Sample { t, displacement: tone(t, a), ..Sample::default() });
///     assert!(!seen || i >= 400);
/// }
/// assert!(seen);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Relative<D: TouchdownDetector> {
    inner: D,
    ratio: f64,
    settle: f64,
    baseline_time: f64,
    name: String,
    start: Option<f64>,
    sum: f64,
    count: usize,
}

impl<D: TouchdownDetector> Relative<D> {
    /// `ratio` (> 1) times the baseline, the baseline averaged over `baseline_time` (s, > 0)
    /// after `settle` (s, ≥ 0) from the reset.
    pub fn new(inner: D, ratio: f64, settle: f64, baseline_time: f64) -> Result<Self> {
        crate::error::check_finite("ratio", ratio)?;
        if ratio <= 1.0 {
            return Err(crate::Error::invalid(
                "ratio",
                format!("must exceed 1, got {ratio}"),
            ));
        }
        crate::error::check_non_negative("settle", settle)?;
        check_positive("baseline_time", baseline_time)?;
        let name = format!("{}, {ratio}x baseline", inner.name());
        Ok(Relative {
            inner,
            ratio,
            settle,
            baseline_time,
            name,
            start: None,
            sum: 0.0,
            count: 0,
        })
    }

    /// The baseline level, once complete.
    pub fn baseline(&self) -> Option<f64> {
        (self.count > 0).then(|| self.sum / self.count as f64)
    }
}

impl<D: TouchdownDetector> TouchdownDetector for Relative<D> {
    fn name(&self) -> &str {
        &self.name
    }
    fn high_pass(&self) -> bool {
        self.inner.high_pass()
    }

    fn reset(&mut self) {
        self.inner.reset();
        self.start = None;
        self.sum = 0.0;
        self.count = 0;
    }

    fn update(&mut self, s: &Sample) -> bool {
        let inner_fired = self.inner.update(s);
        let level = self.inner.level();
        let age = s.t - *self.start.get_or_insert(s.t);
        if age < self.settle {
            return false;
        }
        if age <= self.settle + self.baseline_time {
            self.sum += level;
            self.count += 1;
            return false;
        }
        inner_fired && self.baseline().is_some_and(|b| level >= self.ratio * b)
    }

    fn level(&self) -> f64 {
        self.inner.level()
    }
}
