//! The simulated drive: the slider of a scene in a zone, stepped at the controller's rate.

use super::disk::{Disk, DiskSpec};
use super::sensors::{Physical, SensorSpec, SensorState, Sensors, Truth};
use crate::analysis::{flying_equilibrium, CycleOptions, ScanGrid};
use crate::clearance::Zone;
use crate::error::{check_finite, check_non_negative, Error, Result};
use crate::heater::Programme;
use crate::model::{Rest, SliderModel, SliderSystem, StateLayout, Voltage};
use crate::ode::{Integrator, Method, OdeSystem, Options, Stats};
use crate::scene::Scene;
use nalgebra::{
    allocator::Allocator, DefaultAllocator, Dim, OMatrix, OVector, U10, U4, U5, U6, U7, U8, U9,
};
use std::cell::RefCell;
use std::f64::consts::PI;

/// What the controller sets for the next period.
///
/// ```
/// use hdi_tribology::drive::Command;
/// let c = Command::heater_mw(72.5).with_dither(0.5, 10.5e3);
/// assert_eq!(c.heater_power, 0.0725);
/// assert_eq!(c.ac_amplitude, 0.5);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Command {
    /// Heater power (W, ≥ 0); the protrusion follows through the heater's thermal lag.
    pub heater_power: f64,
    /// DC head–disk voltage (V).
    pub dc_voltage: f64,
    /// AC dither amplitude (V).
    pub ac_amplitude: f64,
    /// AC dither frequency (Hz).
    pub ac_frequency: f64,
}

impl Command {
    /// Heater power in milliwatts, no voltage.
    pub fn heater_mw(p_mw: f64) -> Self {
        Command {
            heater_power: crate::units::mw(p_mw),
            ..Command::default()
        }
    }

    /// The same command with an AC dither of `amplitude` (V) at `frequency` (Hz).
    pub fn with_dither(self, amplitude: f64, frequency: f64) -> Self {
        Command {
            ac_amplitude: amplitude,
            ac_frequency: frequency,
            ..self
        }
    }

    fn validate(&self) -> Result<()> {
        check_non_negative("command.heater_power", self.heater_power)?;
        if self.heater_power > MAX_HEATER_POWER {
            return Err(Error::invalid(
                "command.heater_power",
                format!(
                    "must not exceed {} mW, got {} mW",
                    MAX_HEATER_POWER * 1e3,
                    self.heater_power * 1e3
                ),
            ));
        }
        check_finite("command.dc_voltage", self.dc_voltage)?;
        check_finite("command.ac_amplitude", self.ac_amplitude)?;
        check_non_negative("command.ac_frequency", self.ac_frequency)?;
        Ok(())
    }
}

/// Largest heater power a command may ask for (W): far above any thermal fly-height heater.
const MAX_HEATER_POWER: f64 = 1.0;

/// Ambient temperature drift and what it does to the clearance.
///
/// `ΔT_amb(t) = rate · t + amplitude · sin(2π t / period)`; the nominal clearance moves by
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
}

impl Default for Ambient {
    /// No drift; 0.03 nm/K when there is one.
    fn default() -> Self {
        Ambient {
            rate: 0.0,
            amplitude: 0.0,
            period: 1.0,
            clearance_per_kelvin: 0.03e-9,
        }
    }
}

impl Ambient {
    /// Temperature change at `t` (K).
    pub fn temperature(&self, t: f64) -> f64 {
        self.rate * t + self.amplitude * (2.0 * PI * t / self.period).sin()
    }
}

/// Options of [`Plant::new`].
///
/// ```
/// use hdi_tribology::drive::DriveOptions;
/// let o = DriveOptions::default();
/// assert_eq!(o.initial_power, 0.060);
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
    /// ODE method. The scene's tolerances are used, not its method: a controller period is
    /// several air-bearing periods long, and a stiff method steps over it in one step near
    /// equilibrium, where an explicit one needs many (docs/benchmarks.md, "Drive").
    pub method: Method,
}

impl Default for DriveOptions {
    /// Start at 60 mW; 100 µs heater time constant; the default disk and sensors; no drift;
    /// Rodas5P.
    fn default() -> Self {
        DriveOptions {
            initial_power: 0.060,
            heater_time_constant: 1e-4,
            disk: DiskSpec::default(),
            ambient: Ambient::default(),
            sensors: SensorSpec::default(),
            method: Method::Rodas5P,
        }
    }
}

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

/// The slider's ODE with the disk surface moving under it.
///
/// The state is relative to the disk surface `w(t)` (every force of the model depends on the
/// gap and its rate only), so the surface's motion enters as the inertial force `−m ẅ(t)`;
/// everything else is the model's own [`SliderSystem`], evaluated on the model of the current
/// command (heater, voltage, ambient clearance), which [`Drive::step`] sets before each period.
struct DriveSystem {
    current: RefCell<SliderModel>,
    programme: Programme,
    disk: Disk,
}

impl DriveSystem {
    /// The model's ODE for the current command. Cloning the programme shares its knots: no
    /// allocation.
    fn with_slider<R>(&self, f: impl FnOnce(&SliderSystem<'_>) -> R) -> R {
        let m = self.current.borrow();
        f(&SliderSystem::new(&m, self.programme.clone(), true))
    }
}

impl<D: Dim> OdeSystem<D> for DriveSystem
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn rhs(&self, t: f64, y: &OVector<f64, D>, dy: &mut OVector<f64, D>) {
        self.with_slider(|s| s.rhs(t, y, dy));
        if !self.disk.is_flat() {
            // The disk's motion enters the (rigid) slider's relative coordinate as −ẅ; the
            // plant refuses a moving disk under other structures.
            dy[1] -= self.disk.acceleration(t).0;
        }
    }

    fn jacobian(&self, t: f64, y: &OVector<f64, D>, j: &mut OMatrix<f64, D, D>) -> bool {
        self.with_slider(|s| s.jacobian(t, y, j))
    }

    fn time_derivative(&self, t: f64, y: &OVector<f64, D>, d: &mut OVector<f64, D>) -> bool {
        let ok = self.with_slider(|s| s.time_derivative(t, y, d));
        if ok && !self.disk.is_flat() {
            d[1] -= self.disk.acceleration(t).1;
        }
        ok
    }
}

/// A drive before it runs: the slider of a scene in a zone, its disk, heater, sensors and
/// solver settings. [`Plant::drive`] starts a [`Drive`] on it (several in turn, each from the
/// same start).
///
/// ```
/// use hdi_tribology::drive::{scene_zone, Command, DriveOptions, Plant};
/// use hdi_tribology::scene::Scene;
/// let scene = Scene::paper();
/// let plant = Plant::new(&scene, &scene_zone(&scene, 0.025)?, 7, DriveOptions::default())?;
/// let mut drive = plant.drive()?;
/// let mut s = drive.step(&Command::heater_mw(60.0), 50e-6)?;
/// for _ in 0..40 {
///     s = drive.step(&Command::heater_mw(65.0), 50e-6)?;
/// }
/// // 5 mW more heater closes the gap by about η·5 mW = 0.5 nm.
/// println!("gap {:.3} nm, sensor {:.4} Ω", s.truth.gap * 1e9, s.contact_resistance);
/// assert!(s.truth.gap < 4.5e-9);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub struct Plant {
    system: DriveSystem,
    base: SliderModel,
    layout: StateLayout,
    start: Rest,
    start_sensors: Physical,
    sensors: SensorSpec,
    ambient: Ambient,
    method: Method,
    ode: Options,
    max_steps: usize,
    zone: Zone,
    seed: u64,
    disk_spec: DiskSpec,
    rpm: f64,
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
        check_non_negative("initial_power", opts.initial_power)?;
        check_non_negative("heater_time_constant", opts.heater_time_constant)?;
        check_finite("ambient.rate", opts.ambient.rate)?;
        check_finite("ambient.amplitude", opts.ambient.amplitude)?;
        crate::error::check_positive("ambient.period", opts.ambient.period)?;
        check_finite(
            "ambient.clearance_per_kelvin",
            opts.ambient.clearance_per_kelvin,
        )?;
        opts.sensors.validate()?;
        let zoned = zone.scene(scene)?;
        let solver = CycleOptions::from_scene(&zoned)?.solver;
        let mut base = SliderModel::from_scene(&zoned)?;
        if base.thermal_lag == 0.0 {
            base.thermal_lag = opts.heater_time_constant;
        }
        let rpm = zone.disk_speed * 60.0 / (2.0 * PI * zone.radius);
        let disk = Disk::new(&opts.disk, rpm, seed)?;
        // The heater command enters as the protrusion per unit power of a constant 1 W programme
        // (`η P` = `(η P) · 1 W`), so a new command needs no new programme.
        let programme = Programme::constant(1.0, 1.0)?;
        let dc = base.with_voltage(Voltage {
            dc: 0.0,
            ac_amplitude: 0.0,
            ..base.voltage
        });
        let eq = flying_equilibrium(
            &dc,
            opts.initial_power,
            dc.voltage.squared(0.0),
            &ScanGrid::default(),
        )?;
        let probe = SliderSystem::new(&base, programme.clone(), true);
        let layout = probe.layout();
        if layout.dofs > 1 && !disk.is_flat() {
            return Err(Error::invalid(
                "drive.disk",
                "run-out and waviness are modelled for the rigid structure only; \
                 use a flat disk with the scene's [structure]",
            ));
        }
        // The period means of the contact force and flash temperature: 1 µN and 1 mK over 50 µs.
        let atol = probe.tolerances(solver.atol_displacement, 1e-6 * 5e-5, 1e-3 * 5e-5);
        let ode = Options::default()
            .rtol(solver.rtol)
            .atol_per_component(atol)
            .h_max(solver.max_step.unwrap_or(f64::INFINITY))
            // Bounded per period in `Drive::step`; the integrator lives as long as the drive.
            .max_steps(usize::MAX)
            .dense(false);
        ode.validate(layout.len())
            .map_err(|e| Error::invalid("solver", e.to_string()))?;
        let friction = base.friction.coefficient * zone.disk_speed;
        let start_sensors = Physical {
            gap: eq.d,
            heater_power: opts.initial_power,
            friction_power: friction * base.contact_force(base.gaps(&eq.q, eq.protrusion)),
            ambient: 0.0,
        };
        Ok(Plant {
            system: DriveSystem {
                current: RefCell::new(base.clone()),
                programme,
                disk,
            },
            base,
            layout,
            start: eq.rest(),
            start_sensors,
            sensors: opts.sensors,
            ambient: opts.ambient,
            method: opts.method,
            ode,
            max_steps: solver.max_steps,
            zone: zone.clone(),
            seed,
            disk_spec: opts.disk,
            rpm,
        })
    }

    /// The same plant with another seed: a new random disk and new sensor noise, the model's
    /// tables shared (no rebuild), for runs over many seeds.
    ///
    /// # Errors
    /// None in practice (the disk was valid for the first seed).
    pub fn with_seed(&self, seed: u64) -> Result<Plant> {
        Ok(Plant {
            system: DriveSystem {
                current: RefCell::new(self.base.clone()),
                programme: self.system.programme.clone(),
                disk: Disk::new(&self.disk_spec, self.rpm, seed)?,
            },
            base: self.base.clone(),
            layout: self.layout,
            start: self.start,
            start_sensors: self.start_sensors,
            sensors: self.sensors,
            ambient: self.ambient,
            method: self.method,
            ode: self.ode.clone(),
            max_steps: self.max_steps,
            zone: self.zone.clone(),
            seed,
            disk_spec: self.disk_spec.clone(),
            rpm: self.rpm,
        })
    }

    /// Starts a drive: at rest in the flying equilibrium at the initial power, time 0, the
    /// sensor noise at the start of its seeded stream.
    ///
    /// # Errors
    /// A state size the drive has no fixed-size vector for; integrator set-up failures.
    pub fn drive(&self) -> Result<Drive<'_>> {
        let sys = &self.system;
        let (m, o) = (self.method, &self.ode);
        let probe = SliderSystem::new(&self.base, sys.programme.clone(), true);
        let rest = &self.start;
        macro_rules! start {
            ($variant:ident, $dim:expr) => {
                Integ::$variant(Integrator::new(
                    sys,
                    0.0,
                    probe.initial_state($dim, rest),
                    1.0,
                    m,
                    o,
                )?)
            };
        }
        let integ = match self.layout.len() {
            4 => start!(S4, U4),
            5 => start!(S5, U5),
            6 => start!(S6, U6),
            7 => start!(S7, U7),
            8 => start!(S8, U8),
            9 => start!(S9, U9),
            10 => start!(S10, U10),
            n => {
                return Err(crate::error::AnalysisError::Internal {
                    stage: crate::error::Stage::Drive,
                    detail: format!("no fixed-size state of {n} components"),
                }
                .into())
            }
        };
        Ok(Drive {
            plant: self,
            integ,
            sensors: SensorState::new(self.sensors, self.seed, &self.start_sensors),
            t: 0.0,
        })
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
}

/// The integrator, on a state sized at compile time for the layouts a scene can have.
// One per drive, built once and never moved per step: the size difference costs nothing.
#[allow(clippy::large_enum_variant)]
enum Integ<'p> {
    S4(Integrator<'p, U4, DriveSystem>),
    S5(Integrator<'p, U5, DriveSystem>),
    S6(Integrator<'p, U6, DriveSystem>),
    S7(Integrator<'p, U7, DriveSystem>),
    S8(Integrator<'p, U8, DriveSystem>),
    S9(Integrator<'p, U9, DriveSystem>),
    S10(Integrator<'p, U10, DriveSystem>),
}

macro_rules! with_integ {
    ($integ:expr, $it:ident => $body:expr) => {
        match $integ {
            Integ::S4($it) => $body,
            Integ::S5($it) => $body,
            Integ::S6($it) => $body,
            Integ::S7($it) => $body,
            Integ::S8($it) => $body,
            Integ::S9($it) => $body,
            Integ::S10($it) => $body,
        }
    };
}

/// A simulated drive: the slider of a [`Plant`] flying over its wavy disk, with a heater, a
/// head–disk voltage and the sensors firmware reads, stepped at the controller's rate.
///
/// Each [`Drive::step`] holds the [`Command`] over one period, advances the slider dynamics
/// from where the last period ended with the crate's steppable [`Integrator`] (the model's
/// [`SliderSystem`] plus the disk's motion; nothing is re-solved and nothing allocated) and
/// returns the [`Sensors`] at its end. The same seed gives the same disk and the same sensor
/// noise, bit for bit.
pub struct Drive<'p> {
    plant: &'p Plant,
    integ: Integ<'p>,
    sensors: SensorState,
    t: f64,
}

impl std::fmt::Debug for Drive<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Drive")
            .field("plant", self.plant)
            .field("t", &self.t)
            .finish_non_exhaustive()
    }
}

impl Drive<'_> {
    /// Holds `command` for `dt` seconds, advances the slider and returns the sensors at the end.
    ///
    /// # Errors
    /// An invalid command or period (named field); an integration failure.
    pub fn step(&mut self, command: &Command, dt: f64) -> Result<Sensors> {
        command.validate()?;
        crate::error::check_positive("dt", dt)?;
        if dt > 1.0 {
            return Err(Error::invalid(
                "dt",
                format!("a controller period must not exceed 1 s, got {dt} s"),
            ));
        }
        let plant = self.plant;
        let (t0, t1) = (self.t, self.t + dt);
        let ambient = plant.ambient.temperature(t0);
        {
            // Cloning the model shares its tables (reference counts): no allocation.
            let mut m = plant.system.current.borrow_mut();
            *m = plant.base.clone();
            m.efficiency = plant.base.efficiency * command.heater_power;
            m.nominal_clearance += plant.ambient.clearance_per_kelvin * ambient;
            m.voltage = Voltage {
                dc: command.dc_voltage,
                ac_amplitude: command.ac_amplitude,
                frequency: command.ac_frequency,
                contact_potential: plant.base.voltage.contact_potential,
            };
        }
        let layout = plant.layout;
        let max_steps = plant.max_steps;
        let truth = with_integ!(&mut self.integ, it => {
            advance(it, &layout, t0, t1, max_steps)?;
            plant.system.with_slider(|s| observe(s, it.state(), &layout, t1, dt))
        });
        self.t = t1;
        let m = plant.system.current.borrow();
        let friction_power =
            m.friction.coefficient * plant.zone.disk_speed * truth.mean_contact_force;
        let phys = Physical {
            gap: truth.gap,
            heater_power: command.heater_power,
            friction_power,
            ambient,
        };
        let (r, ae, readback, temp) = self.sensors.sample(t1, dt, &phys);
        Ok(Sensors {
            t: t1,
            contact_resistance: r,
            acoustic: ae,
            readback,
            heater_power: command.heater_power,
            truth: Truth {
                friction_power,
                sensor_temperature: temp,
                disk_height: plant.system.disk.height(t1).0,
                ambient,
                ..truth
            },
        })
    }

    /// Simulated time so far (s).
    pub fn time(&self) -> f64 {
        self.t
    }

    /// Solver work so far.
    pub fn stats(&self) -> Stats {
        with_integ!(&self.integ, it => it.stats())
    }

    /// The plant.
    pub fn plant(&self) -> &Plant {
        self.plant
    }

    /// The slider model of the zone (with the heater time constant the drive uses).
    pub fn model(&self) -> &SliderModel {
        &self.plant.base
    }
}

/// Integrates one period; the one place the drive calls the ODE stepper.
///
/// The command may have changed, and the period integrals restart at zero: both are
/// discontinuities, so the integrator restarts at `t0` (its first step is the whole period,
/// which the step control cuts down in a transient) and steps to `t1`.
fn advance<D: Dim>(
    it: &mut Integrator<'_, D, DriveSystem>,
    layout: &StateLayout,
    t0: f64,
    t1: f64,
    max_steps: usize,
) -> Result<()>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let mut y = it.state().clone();
    for i in [layout.contact_impulse, layout.heat].into_iter().flatten() {
        y[i] = 0.0;
    }
    it.set_tf(t1)?;
    it.reinit(t0, y)?;
    let mut n = 0usize;
    while it.t() < t1 {
        if n >= max_steps {
            return Err(Error::no_convergence(
                "drive period",
                format!("more than {max_steps} steps (solver.max_steps) in [{t0}, {t1}] s"),
            ));
        }
        it.step()?;
        n += 1;
    }
    Ok(())
}

/// The true values at the end of a period.
fn observe<D: Dim>(
    sys: &SliderSystem<'_>,
    y: &OVector<f64, D>,
    layout: &StateLayout,
    t: f64,
    dt: f64,
) -> Truth
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let m = sys.model();
    let g = sys.gaps(t, y);
    let mean = |i: Option<usize>| i.map_or(0.0, |i| y[i] / dt);
    Truth {
        gap: g.bulge,
        pad_gap: g.pad,
        displacement: y[0],
        velocity: y[layout.velocity(0)],
        protrusion: sys.protrusion(t, y),
        mean_contact_force: mean(layout.contact_impulse),
        contact_force: m.contact_force(g),
        interface_force: m.interface_force(g, m.voltage.squared(t)).value,
        mean_flash_temperature: mean(layout.heat),
        ..Truth::default()
    }
}
