//! What drives the slider from outside: the heater, the head–disk voltage, a change of the
//! clearance and the motion of the disk surface, as one [`Inputs`] value.
//!
//! The model ([`super::SliderModel`]) holds the physics of a scene and never changes; a
//! simulation holds its inputs beside it and may replace them between steps
//! ([`super::SliderSystem::set_inputs`]): the drive does so at every new command.

use super::Voltage;
use crate::heater::Programme;
use std::fmt::Debug;
use std::sync::Arc;

/// The heater's input: a power held constant, or a programme of power over time.
///
/// ```
/// use hdi_tribology::{heater::Programme, model::Heater};
/// let held = Heater::Power(0.07);
/// assert_eq!(held.power_and_rate(1.0), (0.07, 0.0));
/// let ramp = Heater::from(Programme::new(vec![(0.0, 0.0), (1.0, 0.1)])?);
/// assert!((ramp.power(0.5) - 0.05).abs() < 1e-15);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub enum Heater {
    /// A power (W) held for as long as the inputs hold.
    Power(f64),
    /// A piecewise-linear programme of power (W) over time (s).
    Programme(Programme),
}

impl Heater {
    /// Heater power at time `t` (W).
    #[inline]
    pub fn power(&self, t: f64) -> f64 {
        match self {
            Heater::Power(p) => *p,
            Heater::Programme(p) => p.power(t),
        }
    }

    /// Heater power (W) and its rate (W/s) at time `t` (the rate of a programme is its slope on
    /// the right of a knot).
    #[inline]
    pub fn power_and_rate(&self, t: f64) -> (f64, f64) {
        match self {
            Heater::Power(p) => (*p, 0.0),
            Heater::Programme(p) => p.power_and_rate(t),
        }
    }

    /// The programme, when the heater follows one.
    pub fn programme(&self) -> Option<&Programme> {
        match self {
            Heater::Power(_) => None,
            Heater::Programme(p) => Some(p),
        }
    }
}

impl From<Programme> for Heater {
    fn from(p: Programme) -> Self {
        Heater::Programme(p)
    }
}

/// A motion of the disk surface under the head, given as its acceleration (the slider's state
/// is relative to the surface, so the surface enters as a base excitation).
///
/// ```
/// use hdi_tribology::model::BaseMotion;
/// /// A surface that oscillates as `w(t) = a sin(ωt)`.
/// #[derive(Debug)]
/// struct Sine { a: f64, w: f64 }
/// impl BaseMotion for Sine {
///     fn acceleration(&self, t: f64) -> (f64, f64) {
///         let (s, c) = (self.w * t).sin_cos();
///         (-self.a * self.w * self.w * s, -self.a * self.w.powi(3) * c)
///     }
/// }
/// let m = Sine { a: 1e-9, w: 1e3 };
/// assert_eq!(m.acceleration_value(0.1), m.acceleration(0.1).0);
/// ```
pub trait BaseMotion: Debug + Send + Sync {
    /// Surface acceleration `ẅ(t)` (m/s²) and jerk (m/s³).
    fn acceleration(&self, t: f64) -> (f64, f64);
    /// The acceleration alone (what the right-hand side reads); by default from
    /// [`BaseMotion::acceleration`].
    #[inline]
    fn acceleration_value(&self, t: f64) -> f64 {
        self.acceleration(t).0
    }
}

/// Everything that drives the slider from outside, in SI units.
///
/// [`super::SliderModel::inputs`] gives the scene's own (its voltage, no clearance change, no
/// disk motion) for a heater; a field at a time can then be changed:
///
/// ```no_run
/// use hdi_tribology::{model::{Heater, SliderModel}, scene::Scene};
/// let model = SliderModel::from_scene(&Scene::paper())?;
/// let mut inputs = model.inputs(Heater::Power(0.07));
/// inputs.voltage.ac_amplitude = 0.5;
/// inputs.clearance_offset = -0.2e-9; // 0.2 nm closer, e.g. from an ambient drift
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct Inputs {
    /// The heater.
    pub heater: Heater,
    /// The head–disk voltage.
    pub voltage: Voltage,
    /// Change of the nominal clearance `h0` (m): both gaps are wider by it.
    pub clearance_offset: f64,
    /// The motion of the disk surface, `None` for a surface at rest.
    pub base_motion: Option<Arc<dyn BaseMotion>>,
}

impl Inputs {
    /// A heater and a voltage, with no clearance change and the disk at rest.
    ///
    /// ```
    /// use hdi_tribology::model::{Heater, Inputs, Voltage};
    /// let v = Voltage { dc: 0.0, ac_amplitude: 0.0, frequency: 0.0, contact_potential: 0.0 };
    /// let i = Inputs::new(Heater::Power(0.05), v);
    /// assert_eq!((i.clearance_offset, i.base_motion.is_none()), (0.0, true));
    /// ```
    pub fn new(heater: Heater, voltage: Voltage) -> Self {
        Inputs {
            heater,
            voltage,
            clearance_offset: 0.0,
            base_motion: None,
        }
    }
}
