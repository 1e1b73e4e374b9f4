//! The simulated drive: the slider of a scene in a zone, stepped at the controller's rate.

use super::disk::{Disk, DiskSpec};
use super::exponential::{Attempt, Backoff, ExpScheme, SchemeCounts};
use super::orbit::Orbit;
use super::orbit_map::OrbitMap;
use super::sensors::{Physical, SensorSpec, SensorState, Sensors, TrueState};
use super::state::{state_vector, MAX_STATE};
use super::Zone;
use crate::analysis::{flying_equilibrium, CycleOptions, ScanGrid};
use crate::error::{check_finite, check_non_negative, Error, Result};
use crate::force::OutsideTables;
use crate::model::{Heater, Inputs, Rest, SliderModel, SliderSystem, StateLayout, Voltage};
use crate::ode::{Integrator, Method, OdeError, Stats};
use crate::scene::{DriveSpec, Scene};
use crate::sim::{with_sized, Flow, Observer, Problem, SizedIntegrator, StepView};
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OVector};
use std::f64::consts::PI;
use std::sync::Arc;

/// What the controller sets for the next period, in engineering units (the unit in each name,
/// as in the C ABI's `HdiCommand`).
///
/// ```
/// use hdi_tribology::drive::Command;
/// let c = Command::heater_mw(72.5).with_dither(0.5, 10.5);
/// assert_eq!(c.heater_power_mw, 72.5);
/// assert_eq!((c.ac_amplitude_v, c.ac_frequency_khz), (0.5, 10.5));
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Command {
    /// Heater power (mW, ≥ 0); the protrusion follows through the heater's thermal lag.
    pub heater_power_mw: f64,
    /// DC head–disk voltage (V).
    pub dc_voltage_v: f64,
    /// AC dither amplitude (V).
    pub ac_amplitude_v: f64,
    /// AC dither frequency (kHz).
    pub ac_frequency_khz: f64,
}

impl Command {
    /// Heater power in milliwatts, no voltage.
    pub fn heater_mw(p_mw: f64) -> Self {
        Command {
            heater_power_mw: p_mw,
            ..Command::default()
        }
    }

    /// The same command with an AC dither of `amplitude_v` (V) at `frequency_khz` (kHz).
    pub fn with_dither(self, amplitude_v: f64, frequency_khz: f64) -> Self {
        Command {
            ac_amplitude_v: amplitude_v,
            ac_frequency_khz: frequency_khz,
            ..self
        }
    }

    /// The heater power in W (the drive's unit inside).
    pub(crate) fn heater_power(&self) -> f64 {
        crate::units::mw(self.heater_power_mw)
    }

    pub(crate) fn validate(&self) -> Result<()> {
        check_non_negative("command.heater_power_mw", self.heater_power_mw)?;
        if self.heater_power() > MAX_HEATER_POWER {
            return Err(Error::invalid(
                "command.heater_power_mw",
                format!(
                    "must not exceed {} mW, got {} mW",
                    MAX_HEATER_POWER * 1e3,
                    self.heater_power_mw
                ),
            ));
        }
        check_finite("command.dc_voltage_v", self.dc_voltage_v)?;
        check_finite("command.ac_amplitude_v", self.ac_amplitude_v)?;
        check_non_negative("command.ac_frequency_khz", self.ac_frequency_khz)?;
        Ok(())
    }
}

/// Checks a controller period `dt` (s): positive, at most 1 s.
pub(crate) fn check_period(dt: f64) -> Result<()> {
    crate::error::check_positive("dt", dt)?;
    if dt > 1.0 {
        return Err(Error::invalid(
            "dt",
            format!("a controller period must not exceed 1 s, got {dt} s"),
        ));
    }
    Ok(())
}

/// Largest heater power a command may ask for (W): far above any thermal fly-height heater.
pub const MAX_HEATER_POWER: f64 = 1.0;

/// Ambient temperature drift and what it does to the clearance.
///
/// `ΔT_amb(t) = rate · t + amplitude · sin(2π t / period) + step · H(t − step_time)`; the
/// nominal clearance moves by
/// `clearance_per_kelvin · ΔT_amb` (the slider and suspension expand; drives see a few hundredths
/// of a nanometre per kelvin) and the contact sensor reads the ambient change too.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Ambient {
    /// Linear drift (K/s).
    pub rate: f64,
    /// Amplitude of a periodic part (K).
    pub amplitude: f64,
    /// Its period (s, > 0).
    pub period: f64,
    /// Clearance change per kelvin (m/K).
    pub clearance_per_kelvin: f64,
    /// A step of the ambient temperature (K; 0: none), from `step_time` on: a disturbance to
    /// test a clearance loop against.
    pub step: f64,
    /// When the step comes (s, ≥ 0).
    pub step_time: f64,
}

impl Default for Ambient {
    /// No drift; 0.03 nm/K when there is one.
    fn default() -> Self {
        Ambient {
            rate: 0.0,
            amplitude: 0.0,
            period: 1.0,
            clearance_per_kelvin: 0.03e-9,
            step: 0.0,
            step_time: 0.0,
        }
    }
}

impl Ambient {
    /// Temperature change at `t` (K).
    ///
    /// ```
    /// use hdi_tribology::drive::Ambient;
    /// let a = Ambient { rate: 2.0, step: 10.0, step_time: 0.5, ..Ambient::default() };
    /// assert_eq!(a.temperature(0.25), 0.5);
    /// assert_eq!(a.temperature(0.5), 11.0);
    /// ```
    pub fn temperature(&self, t: f64) -> f64 {
        let drift = self.rate * t + self.amplitude * (2.0 * PI * t / self.period).sin();
        if self.step != 0.0 && t >= self.step_time {
            drift + self.step
        } else {
            drift
        }
    }
}

/// Options of [`Plant::new`].
///
/// ```
/// use hdi_tribology::drive::DriveOptions;
/// let o = DriveOptions::default();
/// assert_eq!(o.initial_power, 0.060);
/// assert_eq!(o.atol_displacement, 1e-14);
/// // One displacement tolerance, 0.01 pm, in every period:
/// assert_eq!(o.atol_displacement_flight, o.atol_displacement);
/// // Up to 1 pm where the contact force barely depends on the gap (faster in flight; see
/// // `atol_displacement_flight` for what it costs in accuracy):
/// let flight = DriveOptions { atol_displacement_flight: 1e-12, ..o };
/// assert!(flight.atol_displacement_flight > flight.atol_displacement);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct DriveOptions {
    /// Heater power at the start (W); the slider starts at rest in its flying equilibrium there.
    pub initial_power: f64,
    /// Thermal time constant of the heater (s), used when the scene has none
    /// (`heater.thermal_lag_s = 0`); 0 makes the protrusion follow the command at once.
    pub heater_time_constant: f64,
    /// The disk surface.
    pub disk: DiskSpec,
    /// Ambient drift.
    pub ambient: Ambient,
    /// The sensors.
    pub sensors: SensorSpec,
    /// ODE method. A controller period is several air-bearing periods long, and a stiff method
    /// steps over many periods in one step near equilibrium, where an explicit one needs many
    /// steps per period (docs/benchmarks.md, "Drive").
    pub method: Method,
    /// Relative tolerance of the slider integration.
    pub rtol: f64,
    /// Absolute tolerance on the displacements where the contact force depends strongly on
    /// the gap (m; velocities scaled by their modal frequencies). The default, 0.01 pm (the
    /// scene's own default), keeps the integration error below what the sensors resolve in one
    /// period in contact: there the contact sensor resolves about 0.2 µN of contact force per
    /// period, and the contact force grows by ~4 µN per pm of gap (0.05 pm). At 0.1 pm
    /// throughout, the contact sensor's integration error in contact reaches 0.4 of its noise
    /// (rms) when the command changes every period. tests/drive_plant.rs checks the default
    /// against a tight reference.
    pub atol_displacement: f64,
    /// Absolute tolerance on the displacements where the contact force barely depends on the
    /// gap (m, ≥ `atol_displacement`; by default equal to it: one tolerance throughout).
    /// Above `atol_displacement`, each period runs at
    /// `contact_force_tolerance / |∂F_c/∂d|`, the largest slope of the contact force seen at
    /// the previous period's step ends, held between `atol_displacement` and this; a period
    /// that finds a slope its tolerance was too loose for is run again from its start at
    /// `atol_displacement`; the four periods after each new command also run at
    /// `atol_displacement` (a command past the touchdown fold snaps the slider into contact,
    /// and the snap amplifies the error of the state it starts from). 1 pm, a twentieth of the
    /// spacing the read-back harmonic ratio resolves per period (`λ/(4π)·√2·noise ≈ 22 pm`),
    /// runs the default wavy disk 3.3 times faster in flight, and keeps every sensor within a
    /// fraction of its noise on the programme of tests/drive_plant.rs. It is not the default:
    /// a held command just below the touchdown fold, which the disk's waviness snaps into
    /// contact, starts the snap from the flight tolerance's error, and in the snap's period the
    /// contact sensor was then off by 12 times its noise (docs/clearance.md, "Accuracy").
    pub atol_displacement_flight: f64,
    /// Contact-force error the displacement tolerance is sized for (N, > 0): the tolerance
    /// times the contact force's slope. The default, 0.04 µN, is what 0.01 pm gives in the
    /// paper scene's contact (~4 µN/pm), a fifth of the contact sensor's resolution per period.
    pub contact_force_tolerance: f64,
    /// Largest integration step (s); `None`: unlimited (a step may span many controller
    /// periods; the sensors are read on its interpolant).
    pub max_step: Option<f64>,
    /// The bounded mode, for firmware in the loop: `Some(n)` advances each period in at most
    /// `n` steps: the error control never asks for a step shorter than an `n`-th of the period
    /// and accepts a step of that length whatever its error estimate
    /// ([`Integrator::set_step_floor`](crate::ode::Integrator::set_step_floor)), so a period's
    /// cost has an upper bound whatever the disk and the dither do; the estimate comes back as
    /// a flag ([`PeriodReport::error_estimate`], above 1 when a step missed the tolerances)
    /// instead of as more steps. Where the tolerances allow longer steps they are taken, as
    /// without the bound. `None` (the default): adaptive steps under the tolerances.
    /// docs/clearance.md, "The bounded mode", gives its cost and accuracy. 1 to
    /// [`MAX_STEPS_PER_PERIOD`]; the method must be Radau5 ([`DriveOptions::bounded`] sets
    /// both). Where Radau5's Newton iteration fails at the bound (in a dithered contact, and
    /// in the periods of a snap into contact), the step is tried again shorter, up to 16 times
    /// a period; after those it is taken by backward Euler, extrapolated, with a bounded Newton
    /// iteration of its own, and flagged like any other (the floor's step,
    /// [`Integrator::set_floor_retries`](crate::ode::Integrator::set_floor_retries)); only
    /// where that fails too is the step shortened again. The integration reads the interface
    /// forces from their tables alone ([`OutsideTables::Refused`]): a trial state outside them
    /// fails its step instead of paying for direct quadrature, and a path that leaves them ends
    /// in [`DriveError::LeftTheTables`](super::DriveError::LeftTheTables).
    pub steps_per_period: Option<usize>,
    /// How each period is advanced: the adaptive integrator (the default) or one exponential
    /// step with the Jacobian held across periods ([`DriveScheme`]).
    pub scheme: DriveScheme,
}

/// How the drive advances a period ([`DriveOptions::scheme`]).
///
/// ```
/// use hdi_tribology::drive::{DriveOptions, DriveScheme};
/// assert_eq!(DriveOptions::default().scheme, DriveScheme::Integrator);
/// let o = DriveOptions { scheme: DriveScheme::Exponential, ..DriveOptions::default() };
/// assert_ne!(o, DriveOptions::default());
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub enum DriveScheme {
    /// The adaptive integrator ([`DriveOptions::method`]): steps under the error control, which
    /// span periods while the command holds.
    #[default]
    Integrator,
    /// One exponential step per period, or 2 to 16 substeps where the period needs them
    /// (ETD2RK, [`crate::ode::ExponentialStepper`]; a period of one step that continues the one
    /// before by the two-step ETD2, one right-hand side, `step_two`), with the slider's Jacobian held across
    /// periods and refreshed when a period misses the tolerances; the disk's waviness and an
    /// AC dither are taken out by their exact periodic responses to the held linear part, and
    /// where the forces curve over the disk's sweep (near the peaks, in contact) the disk's
    /// table also takes out their remainder's periodic part along it. A
    /// period whose error estimate still misses the drive's contact tolerances
    /// ([`DriveOptions::atol_displacement`], `rtol`), or where the contact force curves too
    /// much over the gaps the disk and the dither sweep, is run by the integrator from the
    /// same start and flagged ([`PeriodReport::exponential`] false), as are, after
    /// consecutive misses, a doubling number of the following periods (up to 64). A held
    /// command on a flat disk without a dither is left to the integrator after the four
    /// periods that follow each change (its steps span many periods there);
    /// [`Drive::scheme_counts`] counts each kind of period. Faster than the integrator where
    /// the command changes every period or the disk is wavy, slower under a heater ramped on a
    /// wavy disk (its tables rebuilt); docs/clearance.md, "The exponential scheme", gives its
    /// cost and accuracy.
    Exponential,
}

impl DriveScheme {
    /// The scheme's name as the CLI's `--scheme` and Python's `scheme=` take it.
    pub fn name(self) -> &'static str {
        match self {
            DriveScheme::Integrator => "integrator",
            DriveScheme::Exponential => "exponential",
        }
    }
}

impl std::str::FromStr for DriveScheme {
    type Err = Error;

    /// `"integrator"` or `"exponential"` (any case); anything else is an error naming `scheme`.
    ///
    /// ```
    /// use hdi_tribology::drive::DriveScheme;
    /// assert_eq!("Exponential".parse::<DriveScheme>()?, DriveScheme::Exponential);
    /// assert_eq!(DriveScheme::Integrator.name(), "integrator");
    /// let e = "implicit".parse::<DriveScheme>().unwrap_err();
    /// assert!(e.to_string().contains("scheme"), "{e}");
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    fn from_str(s: &str) -> Result<Self> {
        [DriveScheme::Integrator, DriveScheme::Exponential]
            .into_iter()
            .find(|d| d.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| {
                Error::invalid(
                    "scheme",
                    format!("must be integrator or exponential, got {s:?}"),
                )
            })
    }
}

/// Most steps a period may take in the bounded mode ([`DriveOptions::steps_per_period`]).
pub const MAX_STEPS_PER_PERIOD: usize = 64;

/// In the bounded mode, the trials of one period that Radau5 fails at the step floor (its Newton
/// iteration diverges) and tries again shorter; after these, the floor's own step takes them
/// ([`Integrator::set_floor_retries`]). Sixteen leave a dithered contact at 8 to 32 steps a
/// period as it was without the bound (at 4 steps it needs 32); the worst period of a snap
/// into contact asked for 164 (docs/benchmarks.md, "A step of fixed cost at the floor").
pub(crate) const FLOOR_RETRIES: usize = 16;

impl Default for DriveOptions {
    /// Start at 60 mW; 100 µs heater time constant; the default disk and sensors; no drift;
    /// Rodas5P at `rtol = 1e-6`, `atol = 0.01 pm` throughout (0.04 µN of contact force where
    /// a looser flight tolerance is asked for); no step limit.
    fn default() -> Self {
        DriveOptions {
            initial_power: 0.060,
            heater_time_constant: 1e-4,
            disk: DiskSpec::default(),
            ambient: Ambient::default(),
            sensors: SensorSpec::default(),
            method: Method::Rodas5P,
            rtol: 1e-6,
            atol_displacement: 1e-14,
            atol_displacement_flight: 1e-14,
            contact_force_tolerance: 4e-8,
            max_step: None,
            steps_per_period: None,
            scheme: DriveScheme::Integrator,
        }
    }
}

impl DriveOptions {
    /// The same options in the bounded mode: at most `steps_per_period` steps a period, with
    /// Radau5 ([`DriveOptions::steps_per_period`]).
    ///
    /// ```
    /// use hdi_tribology::{drive::DriveOptions, ode::Method};
    /// let o = DriveOptions::default().bounded(8);
    /// assert_eq!((o.steps_per_period, o.method), (Some(8), Method::Radau5));
    /// ```
    pub fn bounded(self, steps_per_period: usize) -> Self {
        DriveOptions {
            steps_per_period: Some(steps_per_period),
            method: Method::Radau5,
            ..self
        }
    }

    /// The same options with the displacement tolerances given in picometres: `contact_pm` near
    /// contact ([`atol_displacement`](DriveOptions::atol_displacement), by default the one these
    /// options hold) and `flight_pm` in flight
    /// ([`atol_displacement_flight`](DriveOptions::atol_displacement_flight), at least
    /// `contact_pm`, equal to it for one tolerance throughout; by default the one these options
    /// hold, or `contact_pm` if that is larger). `names` are the two inputs as the caller's user
    /// writes them (flags, arguments), for the errors.
    ///
    /// ```
    /// use hdi_tribology::drive::DriveOptions;
    /// let names = ["--atol-pm", "--atol-flight-pm"];
    /// let o = DriveOptions::default().with_tolerances_pm(Some(0.01), Some(0.01), names)?;
    /// assert_eq!(o.atol_displacement_flight, o.atol_displacement);
    /// // A larger contact tolerance raises the default flight one with it.
    /// let o = DriveOptions::default().with_tolerances_pm(Some(5.0), None, names)?;
    /// assert_eq!(o.atol_displacement_flight, 5e-12);
    /// let e = DriveOptions::default().with_tolerances_pm(Some(0.1), Some(0.05), names);
    /// assert!(e.unwrap_err().to_string().contains("--atol-flight-pm"));
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::InvalidInput`] naming `names[0]` when `contact_pm` is not positive and finite, or
    /// `names[1]` when `flight_pm` is not finite or below `contact_pm`.
    pub fn with_tolerances_pm(
        self,
        contact_pm: Option<f64>,
        flight_pm: Option<f64>,
        names: [&str; 2],
    ) -> Result<Self> {
        let contact = contact_pm.unwrap_or(self.atol_displacement * 1e12);
        crate::error::check_positive(names[0], contact)?;
        let flight = flight_pm.unwrap_or((self.atol_displacement_flight * 1e12).max(contact));
        crate::error::check_not_below(names[1], flight, names[0], contact, "pm", 1.0)?;
        Ok(DriveOptions {
            atol_displacement: contact * 1e-12,
            atol_displacement_flight: flight * 1e-12,
            ..self
        })
    }
}

impl DriveOptions {
    /// The options a scene's `[drive]` section ([`DriveSpec`]) sets, the defaults elsewhere:
    /// the start power, the heater lag, the run-out (a once-around harmonic of phase 0) and the
    /// random waviness, the ambient drift and step, and the sensor options it names.
    ///
    /// ```
    /// use hdi_tribology::drive::DriveOptions;
    /// use hdi_tribology::scene::DriveSpec;
    /// assert_eq!(DriveOptions::from_spec(&DriveSpec::default()), DriveOptions::default());
    /// let mut spec = DriveSpec::default();
    /// spec.set("runout_nm", 0.0, "runout_nm")?;
    /// spec.set("ae_gain_v_per_sqrt_w", 2.0, "ae_gain_v_per_sqrt_w")?;
    /// let o = DriveOptions::from_spec(&spec);
    /// assert!(o.disk.harmonics.is_empty());
    /// assert_eq!(o.sensors.acoustic.gain, 2.0);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn from_spec(spec: &DriveSpec) -> Self {
        let mut o = DriveOptions::default();
        let set = |slot: &mut f64, v: Option<f64>| {
            if let Some(v) = v {
                *slot = v;
            }
        };
        set(&mut o.initial_power, spec.initial_heater_power_w);
        set(&mut o.heater_time_constant, spec.heater_time_constant_s);
        if let Some(r) = spec.disk.runout_m {
            o.disk.harmonics.retain(|h| h.order != 1);
            if r != 0.0 {
                o.disk.harmonics.insert(
                    0,
                    super::Harmonic {
                        order: 1,
                        amplitude: r,
                        phase: 0.0,
                    },
                );
            }
        }
        set(&mut o.disk.random_rms, spec.disk.waviness_rms_m);
        if let Some([lo, hi]) = spec.disk.waviness_orders {
            o.disk.random_orders = (lo, hi);
        }
        let (a, sa) = (&mut o.ambient, &spec.ambient);
        set(&mut a.rate, sa.rate_k_per_s);
        set(&mut a.amplitude, sa.amplitude_k);
        set(&mut a.period, sa.period_s);
        set(&mut a.clearance_per_kelvin, sa.clearance_per_kelvin_m);
        set(&mut a.step, sa.step_k);
        set(&mut a.step_time, sa.step_time_s);
        let (sn, ss) = (&mut o.sensors, &spec.sensors);
        set(&mut sn.acoustic.gain, ss.ae_gain_v_per_sqrt_w);
        set(&mut sn.acoustic.bandwidth, ss.ae_bandwidth_hz);
        set(&mut sn.acoustic.noise, ss.ae_noise_v);
        set(&mut sn.contact.noise, ss.contact_noise_ohm);
        set(&mut sn.readback.wavelength, ss.readback_wavelength_m);
        o
    }
}

/// The zone of a scene's `[drive]` section: its radius (default 25 mm) and, with `rpm`, the disk
/// speed there (`2π r · rpm / 60`); otherwise the scene's own disk speed ([`scene_zone`]).
///
/// ```
/// use hdi_tribology::{drive::spec_zone, scene::{DriveSpec, Scene}};
/// let mut spec = DriveSpec::default();
/// spec.set("rpm", 7200.0, "rpm")?;
/// let z = spec_zone(&Scene::paper(), &spec)?;
/// assert_eq!(z.radius, 0.025);
/// assert!((z.disk_speed - 2.0 * std::f64::consts::PI * 0.025 * 120.0).abs() < 1e-12);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
///
/// # Errors
/// An invalid scene or spec (named field).
pub fn spec_zone(scene: &Scene, spec: &DriveSpec) -> Result<Zone> {
    spec.validate()?;
    zone_at(scene, spec.radius_m.unwrap_or(DEFAULT_RADIUS), spec.rpm)
}

/// The zone of a scene at `radius` (m) and, with `rpm`, the disk speed there
/// (`2π r · rpm / 60`); otherwise the scene's own disk speed ([`scene_zone`]).
///
/// ```
/// use hdi_tribology::{drive::{scene_zone, zone_at}, scene::Scene};
/// let s = Scene::paper();
/// assert_eq!(zone_at(&s, 0.03, None)?, scene_zone(&s, 0.03)?);
/// let z = zone_at(&s, 0.03, Some(5400.0))?;
/// assert!((z.disk_speed - 2.0 * std::f64::consts::PI * 0.03 * 90.0).abs() < 1e-12);
/// assert!(zone_at(&s, 0.03, Some(-1.0)).is_err());
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
///
/// # Errors
/// An invalid scene, radius or rpm (named field).
pub fn zone_at(scene: &Scene, radius: f64, rpm: Option<f64>) -> Result<Zone> {
    let mut zone = scene_zone(scene, radius)?;
    if let Some(rpm) = rpm {
        crate::error::check_positive("rpm", rpm)?;
        zone.disk_speed = 2.0 * PI * zone.radius * rpm / 60.0;
    }
    Ok(zone)
}

/// The zone radius of a drive that names none (m): 25 mm, a 3.5-inch disk's middle diameter.
pub const DEFAULT_RADIUS: f64 = 0.025;

/// The zone a scene describes by itself: its own clearance, air-bearing stiffness and disk speed,
/// at `radius` (m).
///
/// ```
/// use hdi_tribology::{drive::scene_zone, scene::Scene};
/// let z = scene_zone(&Scene::paper(), 0.025)?;
/// assert_eq!(z.disk_speed, 10.0);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn scene_zone(scene: &Scene, radius: f64) -> Result<Zone> {
    crate::error::check_positive("radius", radius)?;
    Ok(Zone {
        name: scene.name.clone(),
        radius,
        disk_speed: scene.friction.disk_speed_m_per_s,
        nominal_clearance: scene.nominal_clearance_m,
        bearing_stiffness: scene.build_air_bearing()?.stiffness(0.0),
    })
}

/// A drive before it runs: the slider of a scene in a zone, its disk, heater, sensors and
/// solver settings. [`Plant::drive`] starts a [`Drive`] on it (several in turn, each from the
/// same start); [`Plant::into_drive`] and [`Drive::new`] start one that shares the plant
/// (`Arc`), with no borrow: a `Drive` is `'static`, so another language's runtime can hold one.
///
/// ```
/// use hdi_tribology::drive::{scene_zone, Command, DriveOptions, Plant};
/// use hdi_tribology::scene::Scene;
/// let scene = Scene::paper();
/// let plant = Plant::new(&scene, &scene_zone(&scene, 0.025)?, 7, DriveOptions::default())?;
/// let mut drive = plant.into_drive()?; // owns the plant
/// let mut s = drive.step(&Command::heater_mw(60.0), 50e-6)?;
/// for _ in 0..40 {
///     s = drive.step(&Command::heater_mw(65.0), 50e-6)?;
/// }
/// // 5 mW more heater closes the gap by about η·5 mW = 0.5 nm.
/// println!("gap {:.3} nm, sensor {:.4} Ω", s.truth.gap_nm, s.contact_resistance_ohm);
/// assert!(s.truth.gap_nm < 4.5);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone)]
pub struct Plant {
    /// The slider under the start's inputs (the disk's motion among them), with its
    /// tolerances and method.
    problem: Problem,
    /// The disk surface (its motion is in the system's inputs).
    disk: Arc<Disk>,
    base: SliderModel,
    layout: StateLayout,
    start: Rest,
    start_sensors: Physical,
    sensors: SensorSpec,
    ambient: Ambient,
    /// How each period's displacement tolerance is chosen.
    tol: TolRule,
    /// See `Span::rebase`.
    rebase: [f64; 2],
    max_steps: usize,
    zone: Zone,
    seed: u64,
    disk_spec: DiskSpec,
    rpm: f64,
    /// [`DriveOptions::steps_per_period`].
    steps_per_period: Option<usize>,
    /// [`DriveOptions::scheme`].
    scheme: DriveScheme,
    /// `(velocity index, r)` of the coordinates a disk translation moves.
    base_moved: Vec<(usize, f64)>,
    rtol: f64,
}

impl std::fmt::Debug for Plant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Plant")
            .field("zone", &self.zone)
            .field("seed", &self.seed)
            .field("layout", &self.layout)
            .finish_non_exhaustive()
    }
}

impl Plant {
    /// The drive of `scene` moved to `zone` (see [`Zone::scene`]), its disk and noise seeded by
    /// `seed`. Every drive started on it begins at rest in the flying equilibrium at
    /// `opts.initial_power` with no voltage.
    ///
    /// # Errors
    /// Invalid scene, zone or options (named field); no flying equilibrium at the initial power.
    pub fn new(scene: &Scene, zone: &Zone, seed: u64, opts: DriveOptions) -> Result<Self> {
        let zoned = zone.scene(scene)?;
        let max_steps = CycleOptions::from_scene(&zoned)?.solver.max_steps;
        let base = SliderModel::from_scene(&zoned)?;
        let start_voltage = Voltage {
            dc: 0.0,
            ac_amplitude: 0.0,
            ..base.voltage()
        };
        Self::build(base, zone.clone(), seed, opts, start_voltage, max_steps)
    }

    /// The drive of a model as it is (its clearance, bearing, structure and disk speed), at
    /// `radius` (m, for the disk's rpm); every drive started on it begins at rest in the flying
    /// equilibrium at `opts.initial_power` under the model's own voltage at `t = 0`, which the
    /// commands should then carry (`calibration::calibrate` runs this way).
    ///
    /// ```
    /// use hdi_tribology::drive::{Command, DiskSpec, DriveOptions, Plant};
    /// use hdi_tribology::{model::SliderModel, scene::Scene};
    /// let model = SliderModel::from_scene(&Scene::paper())?;
    /// let opts = DriveOptions { disk: DiskSpec::flat(), ..DriveOptions::default() };
    /// let mut drive = Plant::from_model(&model, 0.025, 1, opts)?.into_drive()?;
    /// // The commands carry the model's own DC voltage.
    /// let cmd = Command { dc_voltage_v: model.voltage().dc, ..Command::heater_mw(60.0) };
    /// let s = drive.step(&cmd, 50e-6)?;
    /// // Flying: the heater has closed part of the nominal clearance.
    /// assert!(s.truth.gap_nm > 1.0 && s.truth.gap_nm < model.nominal_clearance() * 1e9);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    ///
    /// # Errors
    /// Invalid radius or options (named field); no flying equilibrium at the initial power.
    pub fn from_model(
        model: &SliderModel,
        radius: f64,
        seed: u64,
        opts: DriveOptions,
    ) -> Result<Self> {
        crate::error::check_positive("radius", radius)?;
        let zone = Zone {
            name: "model".into(),
            radius,
            disk_speed: model.friction().disk_speed,
            nominal_clearance: model.nominal_clearance(),
            bearing_stiffness: model.bearing().stiffness(0.0),
        };
        let v = model.voltage();
        Self::build(
            model.clone(),
            zone,
            seed,
            opts,
            v,
            crate::scene::SolverSpec::default().max_steps,
        )
    }

    fn build(
        mut base: SliderModel,
        zone: Zone,
        seed: u64,
        opts: DriveOptions,
        start_voltage: Voltage,
        max_steps: usize,
    ) -> Result<Self> {
        check_non_negative("initial_power", opts.initial_power)?;
        check_non_negative("heater_time_constant", opts.heater_time_constant)?;
        check_finite("ambient.rate", opts.ambient.rate)?;
        check_finite("ambient.amplitude", opts.ambient.amplitude)?;
        crate::error::check_positive("ambient.period", opts.ambient.period)?;
        check_finite(
            "ambient.clearance_per_kelvin",
            opts.ambient.clearance_per_kelvin,
        )?;
        check_finite("ambient.step", opts.ambient.step)?;
        check_non_negative("ambient.step_time", opts.ambient.step_time)?;
        opts.sensors.validate()?;
        crate::error::check_positive("rtol", opts.rtol)?;
        crate::error::check_positive("atol_displacement", opts.atol_displacement)?;
        crate::error::check_not_below(
            "atol_displacement_flight",
            opts.atol_displacement_flight,
            "atol_displacement",
            opts.atol_displacement,
            "pm",
            1e-12,
        )?;
        crate::error::check_positive("contact_force_tolerance", opts.contact_force_tolerance)?;
        if let Some(h) = opts.max_step {
            crate::error::check_positive("max_step", h)?;
        }
        if let Some(n) = opts.steps_per_period {
            if !(1..=MAX_STEPS_PER_PERIOD).contains(&n) {
                return Err(Error::invalid(
                    "steps_per_period",
                    format!("must be 1 to {MAX_STEPS_PER_PERIOD}, got {n}"),
                ));
            }
            if opts.method != Method::Radau5 {
                return Err(Error::invalid(
                    "method",
                    format!(
                        "the bounded mode (steps_per_period) runs Radau5 (a linearly implicit \
                         step of Rodas5P at the bound is thrown deep into the asperities in \
                         contact), got {}; DriveOptions::bounded sets both",
                        opts.method.name()
                    ),
                ));
            }
        }
        if base.thermal_lag() == 0.0 {
            base = base.with_thermal_lag(opts.heater_time_constant);
        }
        let rpm = zone.disk_speed * 60.0 / (2.0 * PI * zone.radius);
        let disk = Disk::new(&opts.disk, rpm, seed)?;
        let at_start = base.with_voltage(start_voltage);
        let eq = flying_equilibrium(
            &at_start,
            opts.initial_power,
            at_start.voltage().squared(0.0),
            &ScanGrid::default(),
        )?;
        let disk = Arc::new(disk);
        let start_inputs = Inputs {
            heater: Heater::Power(opts.initial_power),
            voltage: start_voltage,
            clearance_offset: 0.0,
            base_motion: base_motion(&disk),
        };
        // The bounded mode bounds each right-hand side too: a trial state outside the force
        // tables fails its step, which is shortened, instead of paying for direct quadrature
        // (about 0.2 ms an evaluation below the paper scene's tables; the diverging Newton
        // iterates of a snap into contact reach micrometres into the disk).
        let integrated = match opts.steps_per_period {
            Some(_) => base.with_outside_tables(OutsideTables::Refused),
            None => base.clone(),
        };
        let builder = Problem::builder(&integrated, start_inputs, true);
        let probe = builder.system();
        let layout = probe.layout();
        // The period means of the contact force and flash temperature: 0.1 µN and 0.1 K over
        // 50 µs (the contact sensor resolves about 0.2 µN of contact force per period in
        // contact; the flash temperature is a truth value only, hundreds of kelvin in contact).
        let (impulse, heat) = (3e-8 * 5e-5, 0.1 * 5e-5);
        // The bounded mode takes its steps whatever the tolerance: one tolerance, for the
        // error estimate.
        let flight = if opts.steps_per_period.is_some() {
            opts.atol_displacement
        } else {
            opts.atol_displacement_flight
        };
        let tol = TolRule::new(
            &probe.tolerances(1.0, 0.0, 0.0),
            &probe.tolerances(0.0, impulse, heat),
            (opts.atol_displacement, flight),
            opts.contact_force_tolerance,
        );
        // Beyond these the relative tolerance allows ten times the absolute one.
        let rebase = [10.0 * impulse / opts.rtol, 10.0 * heat / opts.rtol];
        let problem = builder
            .rtol(opts.rtol)
            .tolerances(opts.atol_displacement, impulse, heat)
            // The voltage changes with the commands: no step limit of its own.
            .h_max(opts.max_step.unwrap_or(f64::INFINITY))
            // Bounded per period in `Drive::step`; the integrator lives as long as the drive.
            .max_steps(usize::MAX)
            // The sensors are read on the interpolant of a step that spans the period's end.
            .dense()
            .method(opts.method)
            .build()?;
        let friction = base.friction().coefficient * zone.disk_speed;
        let start_sensors = Physical {
            gap: eq.d,
            heater_power: opts.initial_power,
            friction_power: friction * base.contact_force(base.gaps(&eq.q, eq.protrusion)),
            ambient: 0.0,
        };
        let base_moved = base
            .structure()
            .base_influence()
            .iter()
            .take(layout.dofs)
            .enumerate()
            .filter(|(_, &r)| r != 0.0)
            .map(|(i, &r)| (layout.velocity(i), r))
            .collect();
        Ok(Plant {
            problem,
            disk,
            base,
            layout,
            start: eq.rest(),
            start_sensors,
            sensors: opts.sensors,
            ambient: opts.ambient,
            tol,
            rebase,
            max_steps,
            zone,
            seed,
            disk_spec: opts.disk,
            rpm,
            steps_per_period: opts.steps_per_period,
            scheme: opts.scheme,
            base_moved,
            rtol: opts.rtol,
        })
    }

    /// The same plant with another seed: a new random disk and new sensor noise, the model's
    /// tables shared (no rebuild), for runs over many seeds.
    ///
    /// # Errors
    /// None in practice (the disk was valid for the first seed).
    pub fn with_seed(&self, seed: u64) -> Result<Plant> {
        let mut p = self.clone();
        p.disk = Arc::new(Disk::new(&self.disk_spec, self.rpm, seed)?);
        let mut inputs = p.problem.system().inputs().clone();
        inputs.base_motion = base_motion(&p.disk);
        p.problem.set_inputs(inputs);
        p.seed = seed;
        Ok(p)
    }

    /// Starts a drive on a copy of this plant (the model's tables are shared, not rebuilt): at
    /// rest in the flying equilibrium at the initial power, time 0, the sensor noise at the
    /// start of its seeded stream.
    ///
    /// # Errors
    /// See [`Drive::new`].
    pub fn drive(&self) -> Result<Drive> {
        Drive::new(Arc::new(self.clone()))
    }

    /// Starts a drive that owns this plant (see [`Plant::drive`]).
    ///
    /// # Errors
    /// See [`Drive::new`].
    pub fn into_drive(self) -> Result<Drive> {
        Drive::new(Arc::new(self))
    }

    /// The zone.
    pub fn zone(&self) -> &Zone {
        &self.zone
    }

    /// The seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The slider model of the zone (with the heater time constant the drive uses).
    pub fn model(&self) -> &SliderModel {
        &self.base
    }

    /// The sensor models.
    pub fn sensor_spec(&self) -> &SensorSpec {
        &self.sensors
    }

    /// The bounded mode's steps per period ([`DriveOptions::steps_per_period`]); `None` for
    /// adaptive steps.
    pub fn steps_per_period(&self) -> Option<usize> {
        self.steps_per_period
    }

    /// The spindle speed (rpm): the zone's disk speed at its radius.
    pub fn rpm(&self) -> f64 {
        self.rpm
    }

    /// The ambient drift.
    pub fn ambient(&self) -> &Ambient {
        &self.ambient
    }
}

/// A simulated drive: the slider of a [`Plant`] flying over its wavy disk, with a heater, a
/// head–disk voltage and the sensors firmware reads, stepped at the controller's rate.
///
/// Each [`Drive::step`] holds the [`Command`] over one period and returns the [`Sensors`] at
/// its end. The slider is advanced by the crate's steppable [`Integrator`], which owns the
/// model's [`SliderSystem`] plus the disk's motion and lives as long as the drive: nothing is
/// re-solved and nothing allocated per period. A new command (or ambient clearance) is set in
/// the integrator's system and the method restarts there; while the command holds, steps run
/// on across period ends under the error control, and the sensors read the step's interpolant
/// at each period end. The same seed gives the same disk and the same sensor noise, bit for
/// bit. A `Drive` owns its plant (`Arc<Plant>`): no borrow, `'static`.
pub struct Drive {
    plant: Arc<Plant>,
    integ: SizedIntegrator,
    sensors: SensorState,
    t: f64,
    /// The run of equal periods the time is counted in ([`PeriodClock`]).
    runs: PeriodClock,
    /// The command and ambient clearance the integrator's system holds (`None` before the first
    /// period).
    held: Option<(Command, f64)>,
    /// Periods since the command last changed: right after a change the controller is likely
    /// to change it again, so the period's last step ends on its end (no step past it wasted).
    unchanged: usize,
    /// The contact impulse and heat integrals at the start of the period.
    integrals0: (f64, f64),
    /// The running displacement tolerance and the state at the period's start.
    tol: TolState,
    /// The states of the model's stateful terms at the drive's time.
    terms: TermStates,
    /// How the last period was advanced.
    period: PeriodReport,
    /// The exponential scheme's state ([`DriveScheme::Exponential`]).
    exp: Option<ExpScheme>,
}

/// How the solver advanced one period ([`Drive::last_period`]).
///
/// ```
/// use hdi_tribology::drive::{Command, DiskSpec, DriveOptions, Plant, scene_zone};
/// use hdi_tribology::scene::Scene;
/// let scene = Scene::paper();
/// let zone = scene_zone(&scene, 0.025)?;
/// // The bounded mode: steps of at least half a period, whatever the disk does.
/// let opts = DriveOptions::default().bounded(2);
/// let mut drive = Plant::new(&scene, &zone, 1, opts)?.into_drive()?;
/// for _ in 0..20 {
///     drive.step(&Command::heater_mw(65.0), 50e-6)?;
///     let p = drive.last_period();
///     // Two, and one more where a step begun in the period before ends in this one.
///     assert!(p.steps <= 3);
///     println!("error estimate {:.2}", p.error_estimate); // above 1: the tolerance was missed
/// }
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct PeriodReport {
    /// Steps that ended within the period (0 when one step spans it; in the bounded mode at
    /// most [`DriveOptions::steps_per_period`] + 1, the one more begun in the period before,
    /// except where Radau5's Newton iteration fails and shortens a step, and one more for each
    /// switch of a stateful term's branch, where a step ends early).
    pub steps: usize,
    /// The largest weighted error estimate of those steps (of the one spanning the period when
    /// none ended in it), against the drive's tolerances: at most 1 under adaptive control; in
    /// the bounded mode, above 1 where a step missed them.
    pub error_estimate: f64,
    /// Whether the period was advanced by one exponential step ([`DriveScheme::Exponential`]);
    /// false under the integrator, and, with the exponential scheme, in a period it left to
    /// the integrator (its estimate missed the tolerances, or the misses before it).
    pub exponential: bool,
}

/// The states of the stateful terms, copied out of a state vector.
#[derive(Clone, Copy, Debug, Default)]
struct TermStates {
    x: [f64; crate::force::MAX_TERM_STATES],
    n: usize,
}

impl TermStates {
    fn of(layout: &StateLayout, y: &[f64]) -> Self {
        let (first, n) = layout.term_states;
        let mut x = [0.0; crate::force::MAX_TERM_STATES];
        x[..n].copy_from_slice(&y[first..first + n]);
        TermStates { x, n }
    }
}

impl std::fmt::Debug for Drive {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Drive")
            .field("plant", &self.plant)
            .field("t", &self.t)
            .finish_non_exhaustive()
    }
}

/// How far ahead of the drive's time the integrator's end time is kept (s): it only bounds
/// the first step after a restart.
const HORIZON: f64 = 1.0;

impl Drive {
    /// Starts a drive on `plant`: at rest in the flying equilibrium at the initial power, time
    /// 0, the sensor noise at the start of its seeded stream.
    ///
    /// # Errors
    /// A state size the drive has no fixed-size vector for; integrator set-up failures.
    pub fn new(plant: Arc<Plant>) -> Result<Self> {
        let mut terms = TermStates::default();
        let mut tol = TolState {
            atol: plant.tol.range.0,
            y0: [0.0; MAX_STATE],
        };
        let integ = plant.problem.clone().start(
            crate::error::Stage::DRIVE,
            0.0,
            &plant.start,
            HORIZON,
            |y0| {
                tol.y0[..y0.len()].copy_from_slice(y0);
                terms = TermStates::of(&plant.layout, y0);
            },
        )?;
        let exp = (plant.scheme == DriveScheme::Exponential).then(|| {
            let t = &plant.tol;
            let atol = (0..t.n)
                .map(|i| t.fixed[i] + t.range.0 * t.per_m[i])
                .collect();
            ExpScheme::new(&plant.layout, plant.rtol, atol, plant.base_moved.clone())
        });
        Ok(Drive {
            sensors: SensorState::new(plant.sensors, plant.seed, &plant.start_sensors),
            plant,
            integ,
            t: 0.0,
            runs: PeriodClock::new(),
            held: None,
            unchanged: 0,
            integrals0: (0.0, 0.0),
            tol,
            terms,
            period: PeriodReport::default(),
            exp,
        })
    }

    /// Holds `command` for `dt` seconds, advances the slider and returns the sensors at the end.
    ///
    /// # Errors
    /// An invalid command or period (named field); an integration failure.
    pub fn step(&mut self, command: &Command, dt: f64) -> Result<Sensors> {
        command.validate()?;
        check_period(dt)?;
        self.step_checked(command, dt)
    }

    /// [`Drive::step`] of a command and period already checked.
    pub(crate) fn step_checked(&mut self, command: &Command, dt: f64) -> Result<Sensors> {
        let plant = &*self.plant;
        let (t0, t1) = (self.t, self.runs.end_of_next(self.t, dt));
        let ambient = plant.ambient.temperature(t0);
        let clearance = plant.ambient.clearance_per_kelvin * ambient;
        let changed = self.held != Some((*command, clearance));
        self.unchanged = if changed { 0 } else { self.unchanged + 1 };
        let layout = plant.layout;
        let span = Span {
            t0,
            t1,
            max_steps: plant.max_steps,
            land: self.unchanged < 2,
            floor: plant.steps_per_period.map(|n| dt / n as f64),
            settling: self.unchanged < SETTLE_PERIODS,
            rebase: plant.rebase,
        };
        let set = changed.then_some(Held {
            command,
            clearance,
            contact_potential: plant.base.voltage().contact_potential,
        });
        let tol = plant.tol.adapts().then_some((&plant.tol, &mut self.tol));
        let (truth, integrals, terms) = with_sized!(&mut self.integ, it => {
            let (y1, period) = match self.exp.as_mut() {
                None => advance(it, &layout, set, &mut self.integrals0, span, tol, None)?,
                Some(exp) => advance_exponential(
                    it,
                    exp,
                    &plant.disk,
                    &layout,
                    set,
                    &mut self.integrals0,
                    span,
                    tol,
                    dt,
                )?,
            };
            self.period = period;
            let terms = TermStates::of(&layout, y1.as_slice());
            let s = it.system();
            let integrals = (
                layout.contact_impulse.map_or(0.0, |i| y1[i]),
                layout.heat.map_or(0.0, |i| y1[i]),
            );
            (observe(s, &y1, &layout, t1, dt, self.integrals0), integrals, terms)
        });
        self.terms = terms;
        self.held = Some((*command, clearance));
        self.integrals0 = integrals;
        self.t = t1;
        self.runs.periods += 1;
        let friction_power =
            plant.base.friction().coefficient * plant.zone.disk_speed * truth.mean_contact_force;
        let heater_power = command.heater_power();
        let phys = Physical {
            gap: truth.gap,
            heater_power,
            friction_power,
            ambient,
        };
        let (r, ae, readback, temp) = self.sensors.sample(t1, dt, &phys);
        let truth = TrueState {
            friction_power,
            sensor_temperature: temp,
            disk_height: plant.disk.height(t1).0,
            ambient,
            ..truth
        };
        // SI inside; the firmware's units at the edge.
        Ok(Sensors {
            time_s: t1,
            contact_resistance_ohm: r,
            acoustic_v: ae,
            readback,
            heater_power_mw: heater_power * 1e3,
            truth: truth.truth(),
        })
    }

    /// The states of the model's stateful terms ([`crate::force::StatefulTerm`]) at the drive's
    /// time, in the order of the terms; empty without such terms.
    ///
    /// ```no_run
    /// use hdi_tribology::drive::{Command, DriveOptions, Plant};
    /// use hdi_tribology::{force::RelaxingState, model::SliderModel, scene::Scene};
    /// let model = SliderModel::from_scene(&Scene::paper())?
    ///     .with_stateful_term(RelaxingState::relaxation(2e-4, 1.0)?)?;
    /// let mut drive = Plant::from_model(&model, 0.025, 1, DriveOptions::default())?.into_drive()?;
    /// drive.step(&Command::heater_mw(60.0), 50e-6)?;
    /// assert!((drive.term_states()[0] - (-0.25f64).exp()).abs() < 1e-4);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn term_states(&self) -> &[f64] {
        &self.terms.x[..self.terms.n]
    }

    /// Simulated time so far (s).
    pub fn time(&self) -> f64 {
        self.t
    }

    /// How the solver advanced the last period: its steps and error estimate (the flag of the
    /// bounded mode, [`DriveOptions::steps_per_period`]).
    pub fn last_period(&self) -> PeriodReport {
        self.period
    }

    /// What the exponential scheme did so far ([`DriveScheme::Exponential`]; all zero under
    /// the integrator).
    pub fn scheme_counts(&self) -> SchemeCounts {
        self.exp
            .as_ref()
            .map_or(SchemeCounts::default(), |e| e.counts)
    }

    /// Solver work so far.
    pub fn stats(&self) -> Stats {
        with_sized!(&self.integ, it => it.stats())
    }

    /// The plant.
    pub fn plant(&self) -> &Plant {
        &self.plant
    }

    /// The plant, shared.
    pub fn plant_arc(&self) -> &Arc<Plant> {
        &self.plant
    }

    /// The slider model of the zone (with the heater time constant the drive uses).
    pub fn model(&self) -> &SliderModel {
        &self.plant.base
    }
}

/// The drive's time over a run of equal periods: the run began at `start` (s) with periods of
/// `dt` (s), and `periods` of them have passed. The time is `start + k / rate` when the rate
/// `1/dt` is a whole number of hertz up to rounding (20 kHz: the 3rd period ends at 0.00015 s,
/// as typed), else `start + k·dt`: one rounding from the exact value either way, not a sum of
/// periods whose rounding grows.
#[derive(Clone, Copy, Debug)]
struct PeriodClock {
    start: f64,
    dt: f64,
    rate: Option<f64>,
    periods: u64,
}

impl PeriodClock {
    fn new() -> Self {
        PeriodClock {
            start: 0.0,
            dt: f64::NAN,
            rate: None,
            periods: 0,
        }
    }

    /// The end of the next period of length `dt` from `t` (a new run when `dt` changes).
    fn end_of_next(&mut self, t: f64, dt: f64) -> f64 {
        if dt != self.dt {
            let f = 1.0 / dt;
            let r = f.round();
            let whole = (f - r).abs() <= 4.0 * f64::EPSILON * r;
            *self = PeriodClock {
                start: t,
                dt,
                rate: whole.then_some(r),
                periods: 0,
            };
        }
        let k = (self.periods + 1) as f64;
        self.start + self.rate.map_or(k * dt, |r| k / r)
    }
}

/// A new command to set in the integrator's system.
#[derive(Clone, Copy)]
struct Held<'a> {
    command: &'a Command,
    /// The ambient change of the clearance (m).
    clearance: f64,
    /// The model's contact potential (V).
    contact_potential: f64,
}

impl Held<'_> {
    /// The inputs of the command, the disk's motion kept.
    fn apply(&self, sys: &mut SliderSystem) {
        sys.set_command_inputs(
            Heater::Power(self.command.heater_power()),
            self.voltage(),
            self.clearance,
        );
    }

    /// The head–disk voltage of the command.
    fn voltage(&self) -> Voltage {
        Voltage {
            dc: self.command.dc_voltage_v,
            ac_amplitude: self.command.ac_amplitude_v,
            frequency: crate::units::khz(self.command.ac_frequency_khz),
            contact_potential: self.contact_potential,
        }
    }
}

/// The disk's motion as an input: `None` for a flat disk (nothing to add).
fn base_motion(disk: &Arc<Disk>) -> Option<Arc<dyn crate::model::BaseMotion>> {
    (!disk.is_flat()).then(|| disk.clone() as Arc<dyn crate::model::BaseMotion>)
}

/// How a period's displacement tolerance follows the contact force's slope
/// ([`DriveOptions::atol_displacement_flight`]).
#[derive(Clone, Debug)]
struct TolRule {
    /// Per-component absolute tolerance per metre of displacement tolerance, and the part that
    /// does not scale with it (the period integrals).
    per_m: [f64; MAX_STATE],
    fixed: [f64; MAX_STATE],
    n: usize,
    /// Displacement tolerance in contact and in flight (m).
    range: (f64, f64),
    /// Contact-force error the tolerance is sized for (N).
    force: f64,
}

impl TolRule {
    fn new(per_m: &[f64], fixed: &[f64], range: (f64, f64), force: f64) -> Self {
        let (mut a, mut b) = ([0.0; MAX_STATE], [0.0; MAX_STATE]);
        let n = per_m.len().min(MAX_STATE);
        a[..n].copy_from_slice(&per_m[..n]);
        b[..n].copy_from_slice(&fixed[..n]);
        TolRule {
            per_m: a,
            fixed: b,
            n,
            range,
            force,
        }
    }

    /// Whether the tolerance ever changes.
    fn adapts(&self) -> bool {
        self.range.1 > self.range.0
    }

    /// The displacement tolerance a contact-force slope (N/m) asks for.
    fn required(&self, slope: f64) -> f64 {
        let (lo, hi) = self.range;
        if slope > 0.0 {
            (self.force / slope).clamp(lo, hi)
        } else {
            hi
        }
    }

    /// Sets the integrator's per-component tolerance for displacement tolerance `x` (m).
    fn apply<D: Dim>(&self, x: f64, it: &mut Integrator<'static, D, SliderSystem>) -> Result<()>
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        let mut atol = [0.0; MAX_STATE];
        for (i, a) in atol[..self.n].iter_mut().enumerate() {
            *a = self.fixed[i] + x * self.per_m[i];
        }
        Ok(it.set_atol(&atol[..self.n])?)
    }
}

/// The displacement tolerance of the running period and the state at its start (for a rerun).
#[derive(Clone, Copy)]
struct TolState {
    atol: f64,
    y0: [f64; MAX_STATE],
}

/// Largest slope of the contact force at a state (N/m), on either gap.
fn contact_slope(sys: &SliderSystem, t: f64, y: &[f64]) -> f64 {
    let c = sys.model().forces().contact(sys.gaps(t, y));
    c.d_bulge.abs().max(c.d_pad.abs())
}

/// One period `[t0, t1]`.
#[derive(Clone, Copy)]
struct Span {
    t0: f64,
    t1: f64,
    max_steps: usize,
    /// End the period's last step on `t1` rather than step past it.
    land: bool,
    /// Sizes of the contact impulse and heat integrals beyond which they are set back to zero.
    rebase: [f64; 2],
    /// Within `SETTLE_PERIODS` of a new command: the contact tolerance throughout.
    settling: bool,
    /// The bounded mode's shortest step (s).
    floor: Option<f64>,
}

/// Periods after a new command that run at the contact tolerance: a command past the
/// touchdown fold snaps the slider into contact within two or three periods, and the snap
/// amplifies any error of the state it starts from.
const SETTLE_PERIODS: usize = 4;

/// Integrates one period and returns the state at its end; the one place the drive calls the
/// ODE stepper.
///
/// A new command is a discontinuity of the right-hand side at `t0`: it is set in the
/// integrator's system (`system_mut`) and the method restarts at `t0` with a fresh step-size
/// estimate (`reinit`); when the last step ran past `t0`, the state there is read on that
/// step's interpolant first. (Keeping the old step size instead is worse here: after a step
/// shortened onto a period's end it is small, and grows back only by the controller's bounded
/// factor per step.) Without a new command nothing restarts: steps run on under the error
/// control, across period ends, and the state at `t1` is read on the interpolant of the step
/// that spans it.
///
/// The period integrals (contact impulse, heat) run on across periods; the period means are
/// their differences. They are set back to zero at a restart once they have grown so large
/// that the relative tolerance would loosen their error control more than tenfold.
///
/// With `tol`, the displacement tolerance follows the contact force's slope at the step ends
/// ([`DriveOptions::atol_displacement_flight`]): a period that meets a slope its tolerance was
/// more than twice too loose for is run again from `t0` at the contact tolerance; otherwise
/// the next period tightens to what the slope asks, or loosens once that is twice the
/// tolerance or more.
fn advance<D: Dim>(
    it: &mut Integrator<'static, D, SliderSystem>,
    layout: &StateLayout,
    set: Option<Held<'_>>,
    integrals0: &mut (f64, f64),
    span: Span,
    tol: Option<(&TolRule, &mut TolState)>,
    start: Option<OVector<f64, D>>,
) -> Result<(OVector<f64, D>, PeriodReport)>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let Span { t0, t1, rebase, .. } = span;
    if let Some(floor) = span.floor {
        it.set_step_floor(Some(floor))?;
        it.set_floor_retries(Some(FLOOR_RETRIES));
    }
    let integrals = [layout.contact_impulse, layout.heat];
    let grown = start.is_none()
        && integrals
            .iter()
            .zip(rebase)
            .any(|(i, bound)| i.is_some_and(|i| it.state()[i].abs() > bound));
    let mut tol = tol;
    if set.is_some() || grown || start.is_some() {
        let mut y = state_at_start(it, t0, start)?;
        if grown {
            for i in integrals.into_iter().flatten() {
                y[i] = 0.0;
            }
            *integrals0 = (0.0, 0.0);
        }
        if let Some(held) = set {
            held.apply(it.system_mut());
        }
        if let Some((rule, st)) = tol.as_mut() {
            st.y0[..y.len()].copy_from_slice(y.as_slice());
            if span.settling && st.atol > rule.range.0 {
                st.atol = rule.range.0;
                rule.apply(st.atol, it)?;
            }
        }
        if it.tf() <= t0 {
            it.set_tf(t1)?;
        }
        it.reinit(t0, y)?;
    }
    let mut ran = run_period(it, span, tol.is_some())?;
    if let Some((rule, st)) = tol {
        let need = if span.settling {
            rule.range.0
        } else {
            ran.slope.map_or(st.atol, |s| rule.required(s))
        };
        if need < 0.5 * st.atol {
            // Too loose for this period: again from its start at the contact tolerance.
            st.atol = rule.range.0;
            rule.apply(st.atol, it)?;
            let y0 = state_vector::<D>(D::from_usize(layout.len()), |i| st.y0[i]);
            if it.tf() <= t0 {
                it.set_tf(t1)?;
            }
            it.reinit(t0, y0)?;
            ran = run_period(it, span, false)?;
        } else if need < st.atol || need >= 2.0 * st.atol {
            st.atol = need;
            rule.apply(need, it)?;
        }
        let y1 = end_state(it, t1)?;
        st.y0[..y1.len()].copy_from_slice(y1.as_slice());
        return Ok((y1, ran.report(it)));
    }
    Ok((end_state(it, t1)?, ran.report(it)))
}

/// One period under the exponential scheme ([`DriveScheme::Exponential`]): one exponential
/// step from the state at `t0` (the scheme's own, or the integrator's when the period before
/// was the integrator's), or, where it misses the tolerances or the misses before it leave the
/// period to the integrator, [`advance`] from the same start.
#[allow(clippy::too_many_arguments)]
fn advance_exponential<D: Dim>(
    it: &mut Integrator<'static, D, SliderSystem>,
    exp: &mut ExpScheme,
    disk: &Disk,
    layout: &StateLayout,
    set: Option<Held<'_>>,
    integrals0: &mut (f64, f64),
    span: Span,
    mut tol: Option<(&TolRule, &mut TolState)>,
    dt: f64,
) -> Result<(OVector<f64, D>, PeriodReport)>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let v = it.system().inputs().voltage;
    // A change of the heater alone, by no more than the orbit's linearised map can take
    // (`src/drive/orbit_map.rs`), keeps a dither's orbit, its map and the wait for them; not
    // with stateful terms, which have no map.
    let small = mappable(layout)
        && set.as_ref().is_some_and(|held| {
            let inputs = it.system().inputs();
            let p = held.command.heater_power();
            let reach = exp
                .orbit_map
                .as_ref()
                .map_or(MAX_HEATER_OFFSET, |m| m.offset());
            let from = exp
                .orbit_map
                .as_ref()
                .map_or(inputs.heater.power(span.t0), |m| m.heater());
            held.voltage() == v
                && held.clearance == inputs.clearance_offset
                && (p - from).abs() <= reach
        });
    exp.voltage_held = if set.is_some() && !small {
        0
    } else {
        exp.voltage_held + 1
    };
    // The heater's drift per period, averaged over about `DRIFT_PERIODS` (W).
    let step = match &set {
        Some(held) if small => {
            held.command.heater_power() - it.system().inputs().heater.power(span.t0)
        }
        _ => 0.0,
    };
    exp.heater_drift = if set.is_some() && !small {
        0.0
    } else {
        exp.heater_drift + (step - exp.heater_drift) / DRIFT_PERIODS
    };
    if let Some(held) = &set {
        if !small {
            // A table built under a changing heater that is left before it paid for itself
            // (a heater ramp) puts off the next try by a doubling wait; any other change
            // starts afresh.
            let unpaid = exp.orbit.is_some() && exp.orbit_unpaid;
            exp.orbit = None;
            exp.orbit_map = None;
            if unpaid && held.voltage() == v {
                exp.orbit_wait.missed(ORBIT_WAIT.0, ORBIT_WAIT.1);
            } else {
                exp.orbit_wait = Backoff::default();
            }
        } else if exp.orbit_map.is_none() && exp.orbit.take().is_some() {
            // A table without a map reads held periods only.
            exp.counts.orbit_exits += 1;
            exp.orbit_wait.missed(ORBIT_WAIT.0, ORBIT_WAIT.1);
        }
        // The dither switched off: the wait its misses ran up says nothing of the periods
        // without it.
        if v.is_time_dependent() && !held.voltage().is_time_dependent() {
            exp.dither_off();
        }
    }
    // A dither on a flat disk, past the settling periods and outside the bounded mode (a try
    // runs two periods of the dither): its settled orbit (`src/drive/orbit.rs`).
    let orbiting = disk.is_flat()
        && exp.voltage_held >= SETTLE_PERIODS
        && span.floor.is_none()
        && v.is_time_dependent();
    if orbiting {
        let again = tol.as_mut().map(|(rule, st)| (&**rule, &mut **st));
        let period = OrbitPeriod {
            layout,
            span,
            dt,
            frequency: v.frequency,
        };
        if let Some(report) = orbit_period(it, exp, set, integrals0, period, again)? {
            return Ok(report);
        }
    }
    let Span { t0, rebase, .. } = span;
    if exp.skips() {
        return match exp.owned.take() {
            None => advance(it, layout, set, integrals0, span, tol, None),
            Some(x) => {
                let x0 = state_vector::<D>(D::from_usize(layout.len()), |i| x[i]);
                from_the_schemes_state(it, layout, set, integrals0, span, tol, x0)
            }
        };
    }
    // A held command on a flat disk without a dither: nothing moves within the periods, and
    // the integrator's steps span many of them at the cost of the read-out alone.
    let still = disk.is_flat()
        && set.is_none()
        && !span.settling
        && it.system().inputs().voltage.ac_amplitude == 0.0;
    if still {
        exp.counts.spanned += 1;
        return match exp.owned.take() {
            None => advance(it, layout, None, integrals0, span, tol, None),
            Some(x) => {
                let mut x0 = state_vector::<D>(D::from_usize(layout.len()), |i| x[i]);
                rebase_integrals(layout, rebase, &mut x0, integrals0);
                advance(it, layout, None, integrals0, span, tol, Some(x0))
            }
        };
    }
    let owned = exp.owned.take();
    let from_integrator = owned.is_none();
    let dim = D::from_usize(layout.len());
    let owned = owned.map(|x| state_vector::<D>(dim, |i| x[i]));
    let mut x0 = state_at_start(it, t0, owned)?;
    if !exp.straight(it.system(), disk, t0, &x0, dt) {
        let _ = exp.missed::<D>();
        if from_integrator {
            // The integrator holds the state: the period as the default drive runs it.
            return advance(it, layout, set, integrals0, span, tol, None);
        }
    } else {
        if let Some(held) = set {
            held.apply(it.system_mut());
        }
        rebase_integrals(layout, rebase, &mut x0, integrals0);
        match exp.attempt(it.system(), disk, t0, dt, &x0) {
            Attempt::Done(x1, err) => {
                let mut x = [0.0; MAX_STATE];
                x[..x1.len()].copy_from_slice(x1.as_slice());
                exp.owned = Some(x);
                return Ok((
                    x1,
                    PeriodReport {
                        steps: 1,
                        error_estimate: err,
                        exponential: true,
                    },
                ));
            }
            Attempt::Missed => {
                // The integrator from the same start; its last step ends on the period's end,
                // so that the restart's first step does not run on over several periods of the
                // disk's motion.
                let landed = Span { land: true, ..span };
                return advance(it, layout, None, integrals0, landed, tol, Some(x0));
            }
        }
    }
    // The scheme held the state and the contact force is not straight enough.
    from_the_schemes_state(it, layout, set, integrals0, span, tol, x0)
}

/// The period by the integrator from the state the exponential scheme held, `x0`, under the new
/// command `set`; its last step ends on the period's end.
fn from_the_schemes_state<D: Dim>(
    it: &mut Integrator<'static, D, SliderSystem>,
    layout: &StateLayout,
    set: Option<Held<'_>>,
    integrals0: &mut (f64, f64),
    span: Span,
    tol: Option<(&TolRule, &mut TolState)>,
    mut x0: OVector<f64, D>,
) -> Result<(OVector<f64, D>, PeriodReport)>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    rebase_integrals(layout, span.rebase, &mut x0, integrals0);
    if let Some(held) = set {
        held.apply(it.system_mut());
    }
    let landed = Span { land: true, ..span };
    advance(it, layout, None, integrals0, landed, tol, Some(x0))
}

/// What [`orbit_period`] needs of the period besides the scheme.
struct OrbitPeriod<'a> {
    layout: &'a StateLayout,
    span: Span,
    /// The drive's period (s) and the dither's frequency (Hz).
    dt: f64,
    frequency: f64,
}

/// Whether a dither's orbit on this state may have a linearised map: not with the states or
/// branches of stateful terms, whose laws may switch within a period.
fn mappable(layout: &StateLayout) -> bool {
    layout.term_states.1 == 0 && layout.branches.1 == 0
}

/// The largest change of the heater (W) that keeps a dither's orbit before its map is built
/// (the largest offset the map's test tries).
const MAX_HEATER_OFFSET: f64 = super::orbit_map::TEST_OFFSETS[0];

/// A period of a dither on a flat disk: read from the settled orbit's table when there is one
/// (through its linearised map when there is one, so that the heater may change within the
/// map's trusted offset); otherwise, when a try is due, run by the integrator and followed by a
/// try to tabulate the orbit and its map from its end (the integrator restarted there whatever
/// the outcome, and the next try put off by a doubling wait after a refusal). A period outside
/// the map's trusted region drops the table and is the integrator's. `None`: neither, the
/// period is the exponential scheme's as without a dither.
fn orbit_period<D: Dim>(
    it: &mut Integrator<'static, D, SliderSystem>,
    exp: &mut ExpScheme,
    set: Option<Held<'_>>,
    integrals0: &mut (f64, f64),
    period: OrbitPeriod<'_>,
    tol: Option<(&TolRule, &mut TolState)>,
) -> Result<Option<(OVector<f64, D>, PeriodReport)>>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let OrbitPeriod {
        layout,
        span,
        dt,
        frequency,
    } = period;
    let Span { t0, t1, rebase, .. } = span;
    let dim = D::from_usize(layout.len());
    let start = |exp: &mut ExpScheme, it: &Integrator<'static, D, SliderSystem>| {
        let owned = exp.owned.take().map(|x| state_vector::<D>(dim, |i| x[i]));
        state_at_start(it, t0, owned)
    };
    let landed = Span { land: true, ..span };
    if exp.orbit.is_some() {
        let mut x0 = start(exp, it)?;
        rebase_integrals(layout, rebase, &mut x0, integrals0);
        if let Some(held) = &set {
            held.apply(it.system_mut());
        }
        let p = it.system().inputs().heater.power(t0);
        let mut x1 = x0.clone();
        let read = match (&exp.orbit, &exp.orbit_map) {
            // A held command on the orbit, or a table without a map: the table alone.
            (Some(orbit), map) if set.is_none() && (exp.on_orbit || map.is_none()) => {
                orbit.period_end(t0, t1, x0.as_slice(), x1.as_mut_slice());
                Some((orbit.error, false))
            }
            (Some(orbit), Some(map)) => map
                .period_end(orbit, t0, t1, dt, x0.as_slice(), p, x1.as_mut_slice())
                .map(|mapped| (orbit.error.max(map.error), mapped)),
            _ => None,
        };
        exp.on_orbit = read.is_some_and(|(_, mapped)| !mapped);
        let Some((error, mapped)) = read else {
            // Outside what the table and its map hold: the integrator from the same start.
            exp.orbit = None;
            exp.orbit_map = None;
            exp.orbit_wait.missed(ORBIT_WAIT.0, ORBIT_WAIT.1);
            exp.counts.orbit_exits += 1;
            let ran = advance(it, layout, None, integrals0, landed, tol, Some(x0))?;
            return Ok(Some(ran));
        };
        let mut x = [0.0; MAX_STATE];
        x[..x1.len()].copy_from_slice(x1.as_slice());
        exp.owned = Some(x);
        exp.counts.orbit += 1;
        exp.orbit_served += 1;
        if exp.orbit_unpaid && exp.orbit_served >= ORBIT_PAYBACK {
            exp.orbit_unpaid = false;
            exp.orbit_wait.succeeded();
        }
        if mapped {
            exp.counts.orbit_mapped += 1;
        }
        let report = PeriodReport {
            steps: 0,
            error_estimate: error,
            exponential: true,
        };
        return Ok(Some((x1, report)));
    }
    if exp.orbit_wait.waits() {
        return Ok(None);
    }
    // A heater that drifts out of the map's largest offset before a table could pay for
    // itself: no try.
    if exp.heater_drift.abs() * ORBIT_PAYBACK as f64 > MAX_HEATER_OFFSET {
        return Ok(None);
    }
    let x0 = match exp.owned {
        Some(_) => {
            let mut x0 = start(exp, it)?;
            rebase_integrals(layout, rebase, &mut x0, integrals0);
            Some(x0)
        }
        None => None,
    };
    // The tolerances the integrator runs at, which the checks hold the orbit to.
    let atol: Vec<f64> = match &tol {
        Some((rule, st)) => (0..rule.n)
            .map(|i| rule.fixed[i] + st.atol * rule.per_m[i])
            .collect(),
        None => exp.atol().to_vec(),
    };
    let changed = set.is_some();
    let (y1, report) = advance(it, layout, set, integrals0, landed, tol, x0)?;
    let budget = 4 * span.max_steps + 4 * super::orbit::NODES;
    match Orbit::build(
        it,
        layout,
        t1,
        y1.clone(),
        frequency,
        if changed { ORBIT_LEAD } else { 0 },
        &atol,
        exp.rtol(),
        budget,
    ) {
        Ok(o) => {
            // Under a changing heater a table counts as a success once it has paid for itself
            // (`ORBIT_PAYBACK`); a held command's at once.
            exp.orbit_served = 0;
            exp.orbit_unpaid = changed;
            if !changed {
                exp.orbit_wait.succeeded();
            }
            exp.counts.orbit_tables += 1;
            // A refused map puts off the next try as a refused table does: under a changing
            // heater the table alone is dropped at the next period.
            if mappable(layout) {
                match OrbitMap::build(it, &o, dt, &atol, exp.rtol(), budget) {
                    Ok(m) => {
                        exp.orbit_map = Some(m);
                        exp.counts.orbit_maps += 1;
                    }
                    Err(_) => {
                        exp.orbit_wait.missed(ORBIT_WAIT.0, ORBIT_WAIT.1);
                        exp.counts.orbit_map_refusals += 1;
                    }
                }
            }
            exp.orbit = Some(o);
            exp.on_orbit = false;
        }
        Err(_) => {
            exp.orbit_wait.missed(ORBIT_WAIT.0, ORBIT_WAIT.1);
            exp.counts.orbit_refusals += 1;
        }
    }
    // The integrator ran on past the period: back to its end.
    super::orbit::restart(it, t1, y1.clone(), t1 + HORIZON)?;
    Ok(Some((y1, report)))
}

/// Periods of the dither a try runs before its two periods when the heater changed in the
/// period it follows: the slider's slowest mode contracts by about 0.39 a period of the dither
/// at 10.5 kHz, so a deviation of a few tolerances from the orbit is gone after four.
const ORBIT_LEAD: usize = 4;

/// Periods a table built under a changing heater must serve before it counts as a success:
/// a try that builds the table and its map costs 9–10 ms, the integrator's time for 200–500
/// periods of a dither. A table left sooner (a heater ramp that leaves the map's offset) puts
/// off the next try by a doubling wait, so that a ramp costs about the integrator's time and
/// not a try every few periods (measured: 2–7 times the integrator's time before this wait).
const ORBIT_PAYBACK: usize = 512;

/// The periods the heater's drift is averaged over (an exponential average): a heater that
/// alternates by ±1 µW drifts by about 0.008 µW a period on it, a ramp by its rate.
const DRIFT_PERIODS: f64 = 64.0;

/// The first and the longest wait (periods) before another try to tabulate a dither's orbit
/// after a refusal.
const ORBIT_WAIT: (usize, usize) = (8, 4096);

/// The state at a period's start `t0`: `given`, or else the integrator's, read on the
/// interpolant of its last step when that step ran past `t0`.
fn state_at_start<D: Dim>(
    it: &Integrator<'static, D, SliderSystem>,
    t0: f64,
    given: Option<OVector<f64, D>>,
) -> Result<OVector<f64, D>>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    Ok(match given {
        Some(y) => y,
        None if it.t() > t0 => it.interpolate(t0)?,
        None => it.state().clone(),
    })
}

/// Sets the period integrals of `x` back to zero once either has grown past its bound (see
/// [`advance`]).
fn rebase_integrals<D: Dim>(
    layout: &StateLayout,
    rebase: [f64; 2],
    x: &mut OVector<f64, D>,
    integrals0: &mut (f64, f64),
) where
    DefaultAllocator: Allocator<D>,
{
    let integrals = [layout.contact_impulse, layout.heat];
    if integrals
        .iter()
        .zip(rebase)
        .any(|(i, bound)| i.is_some_and(|i| x[i].abs() > bound))
    {
        for i in integrals.into_iter().flatten() {
            x[i] = 0.0;
        }
        *integrals0 = (0.0, 0.0);
    }
}

/// What one run over a period saw.
struct PeriodRun {
    /// The largest contact-force slope at the step ends, when asked for and a step ended.
    slope: Option<f64>,
    /// Steps that ended in the period and their largest error estimate.
    steps: usize,
    error: f64,
}

impl PeriodRun {
    /// The report of the period: the error of the step spanning it when none ended in it.
    fn report<D: Dim>(&self, it: &Integrator<'static, D, SliderSystem>) -> PeriodReport
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        PeriodReport {
            steps: self.steps,
            error_estimate: if self.steps == 0 {
                it.last_error()
            } else {
                self.error
            },
            exponential: false,
        }
    }
}

/// Steps until the integrator's time reaches `t1` (the end time set for landing or a horizon
/// ahead). With `slopes`, finds the largest contact-force slope at the step ends (`None`
/// when no step ended: the last one spans the period).
fn run_period<D: Dim>(
    it: &mut Integrator<'static, D, SliderSystem>,
    span: Span,
    slopes: bool,
) -> Result<PeriodRun>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let Span {
        t0,
        t1,
        max_steps,
        land,
        ..
    } = span;
    // Landing: the period's end is the integrator's end time, so the last step is shortened
    // onto it. Otherwise the end time stays a horizon ahead.
    let tf = if land { t1 } else { t1 + HORIZON };
    if (land && it.tf() != t1) || (!land && it.tf() < t1 + 0.5 * HORIZON) {
        it.set_tf(tf)?;
    }
    let mut budget = PeriodBudget {
        steps: 0,
        error: 0.0,
        max_steps,
        t0,
        t1,
    };
    let mut slope = Slope(None);
    // In the bounded mode a non-finite trial state is most likely one outside the force tables,
    // which the forces refuse there (`OutsideTables::Refused`): say so, with their range (read
    // only in that mode).
    let refused = span
        .floor
        .map(|_| it.system().model().forces().table_range());
    let ode_error = |e: OdeError| match (e, refused) {
        (OdeError::NonFinite { t, what }, Some(range)) => super::DriveError::LeftTheTables {
            t_s: t,
            table_low_nm: crate::units::to_nm(range.0),
            table_high_nm: crate::units::to_nm(range.1),
            detail: what,
        }
        .into(),
        (e, _) => Error::from(e),
    };
    if slopes {
        crate::sim::run(it, Some(t1), &mut (&mut budget, &mut slope), ode_error)?;
    } else {
        crate::sim::run(it, Some(t1), &mut budget, ode_error)?;
    }
    Ok(PeriodRun {
        slope: slope.0,
        steps: budget.steps,
        error: budget.error,
    })
}

/// A period's step budget: more than `max_steps` steps short of `t1` end the drive's step.
/// It also keeps the largest error estimate of the period's steps.
struct PeriodBudget {
    steps: usize,
    error: f64,
    max_steps: usize,
    t0: f64,
    t1: f64,
}

impl Observer for PeriodBudget {
    fn accepted(&mut self, step: &StepView<'_>) -> Result<Flow> {
        self.steps += 1;
        self.error = self.error.max(step.error);
        let Self {
            max_steps, t0, t1, ..
        } = *self;
        if self.steps >= max_steps && step.t < t1 {
            return Err(super::DriveError::PeriodSteps {
                max_steps,
                t0_s: t0,
                t1_s: t1,
            }
            .into());
        }
        Ok(Flow::Continue)
    }
}

/// The largest contact-force slope at the step ends of a period.
struct Slope(Option<f64>);

impl Observer for Slope {
    fn accepted(&mut self, step: &StepView<'_>) -> Result<Flow> {
        let s = contact_slope(step.system, step.t, step.state);
        self.0 = Some(self.0.map_or(s, |m: f64| m.max(s)));
        Ok(Flow::Continue)
    }
}

/// The state at `t1`, on the interpolant of the last step when it ran past.
fn end_state<D: Dim>(it: &Integrator<'static, D, SliderSystem>, t1: f64) -> Result<OVector<f64, D>>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    Ok(if it.t() == t1 {
        it.state().clone()
    } else {
        it.interpolate(t1)?
    })
}

/// The true values at the end of a period, the period means from the integrals' change since
/// `integrals0`.
fn observe<D: Dim>(
    sys: &SliderSystem,
    y: &OVector<f64, D>,
    layout: &StateLayout,
    t: f64,
    dt: f64,
    integrals0: (f64, f64),
) -> TrueState
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let m = sys.model();
    let g = sys.gaps(t, y);
    let mean = |i: Option<usize>, i0: f64| i.map_or(0.0, |i| (y[i] - i0) / dt);
    TrueState {
        gap: g.bulge,
        pad_gap: g.pad,
        displacement: y[0],
        velocity: y[layout.velocity(0)],
        protrusion: sys.protrusion(t, y),
        mean_contact_force: mean(layout.contact_impulse, integrals0.0),
        contact_force: m.contact_force(g),
        interface_force: m.interface_force(g, sys.inputs().voltage.squared(t)).value,
        mean_flash_temperature: mean(layout.heat, integrals0.1),
        ..TrueState::default()
    }
}
