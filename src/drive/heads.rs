//! Several heads on one disk stack: one spindle and one clock; each head its own slider,
//! heater, sensors and surface.

use super::plant::{check_period, Command, Drive, Plant};
use super::sensors::Sensors;
use super::{DriveError, Zone};
use crate::error::{Error, Result};
use crate::numerics::rng::SplitMix64;
use crate::scene::{Scene, MAX_HEADS};
use std::sync::Arc;

/// The seed of head `head`'s surface and sensor noise in a drive seeded `seed`: head 0 takes
/// the drive's own seed (so head 0 of a drive is the one-head drive of the same seed), every
/// other head a seed mixed from both (SplitMix64), so that no two heads of a drive, nor the
/// heads of drives with nearby seeds, share a surface.
///
/// ```
/// use hdi_tribology::drive::head_seed;
/// assert_eq!(head_seed(7, 0), 7);
/// assert_ne!(head_seed(7, 1), head_seed(8, 1));
/// assert_ne!(head_seed(7, 1), head_seed(7, 2));
/// assert_ne!(head_seed(7, 1), 8);
/// ```
pub fn head_seed(seed: u64, head: usize) -> u64 {
    if head == 0 {
        return seed;
    }
    SplitMix64::new(seed ^ (head as u64).wrapping_mul(0xD6E8_FEB8_6659_FD93)).next_u64()
}

/// A drive of several heads before it runs: one [`Plant`] per head (its slider, zone, heater,
/// sensors and disk surface), all on one spindle at one radius (one actuator) under one ambient
/// temperature. [`MultiPlant::drive`] starts a [`MultiDrive`].
///
/// The heads do not interact in this model (no coupling through the actuator arm or the air
/// flow): each head's sensors are those of a one-head drive on its plant, to the bit.
///
/// ```
/// use hdi_tribology::drive::{scene_zone, Command, DriveOptions, MultiPlant};
/// use hdi_tribology::scene::Scene;
/// let scene = Scene::paper();
/// let zone = scene_zone(&scene, 0.025)?;
/// let plant = MultiPlant::uniform(&scene, &zone, 4, 1, DriveOptions::default())?;
/// let mut drive = plant.drive()?;
/// let commands = [60.0, 62.0, 64.0, 66.0].map(Command::heater_mw);
/// let sensors = drive.step(&commands, 50e-6)?;
/// assert_eq!(sensors.len(), 4);
/// // One clock: every head is at the same time.
/// assert!(sensors.iter().all(|s| s.time_s == 50e-6));
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct MultiPlant {
    heads: Vec<Arc<Plant>>,
}

impl MultiPlant {
    /// The drive of the given heads (1 to [`MAX_HEADS`]), checked to share one spindle speed,
    /// one radius and one ambient temperature history (each head keeps its own clearance per
    /// kelvin: a property of its slider).
    ///
    /// # Errors
    /// [`Error::InvalidInput`] naming `heads` (none, or too many) or `heads[k].rpm`,
    /// `heads[k].radius`, `heads[k].ambient` for a head that differs from head 0.
    pub fn new(heads: Vec<Plant>) -> Result<Self> {
        check_count("heads", heads.len())?;
        let first = &heads[0];
        for (k, p) in heads.iter().enumerate().skip(1) {
            let same = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs());
            if !same(p.rpm(), first.rpm()) {
                return Err(Error::invalid(
                    format!("heads[{k}].rpm"),
                    format!(
                        "one spindle turns every surface: head 0 at {} rpm, head {k} at {} rpm",
                        first.rpm(),
                        p.rpm()
                    ),
                ));
            }
            if !same(p.zone().radius, first.zone().radius) {
                return Err(Error::invalid(
                    format!("heads[{k}].radius"),
                    format!(
                        "the heads sit on one actuator, at one radius: head 0 at {} mm, head \
                         {k} at {} mm",
                        first.zone().radius * 1e3,
                        p.zone().radius * 1e3
                    ),
                ));
            }
            let (a, b) = (p.ambient(), first.ambient());
            if (a.rate, a.amplitude, a.period, a.step, a.step_time)
                != (b.rate, b.amplitude, b.period, b.step, b.step_time)
            {
                return Err(Error::invalid(
                    format!("heads[{k}].ambient"),
                    "one drive has one ambient temperature: head 0's drift and step differ",
                ));
            }
        }
        Ok(MultiPlant {
            heads: heads.into_iter().map(Arc::new).collect(),
        })
    }

    /// `heads` heads, each the slider of `scene` in `zone` with `opts`, head `k` seeded
    /// [`head_seed`]`(seed, k)`: its own disk surface (run-out and random waviness drawn from
    /// its seed) and its own sensor noise. The model is built once and shared.
    ///
    /// # Errors
    /// Those of [`Plant::new`]; `heads` out of 1 to [`MAX_HEADS`].
    pub fn uniform(
        scene: &Scene,
        zone: &Zone,
        heads: usize,
        seed: u64,
        opts: super::DriveOptions,
    ) -> Result<Self> {
        check_count("heads", heads)?;
        let first = Plant::new(scene, zone, seed, opts)?;
        Self::of_plant(first, heads)
    }

    /// `heads` heads, each `plant` with head `k` reseeded [`head_seed`]`(plant.seed(), k)`
    /// (head 0 is `plant` itself).
    ///
    /// # Errors
    /// `heads` out of 1 to [`MAX_HEADS`].
    pub fn of_plant(plant: Plant, heads: usize) -> Result<Self> {
        check_count("heads", heads)?;
        let seed = plant.seed();
        let mut all = Vec::with_capacity(heads);
        for k in 1..heads {
            all.push(plant.with_seed(head_seed(seed, k))?);
        }
        all.insert(0, plant);
        Self::new(all)
    }

    /// Starts a drive on every head: at rest in its flying equilibrium, time 0.
    ///
    /// # Errors
    /// See [`Drive::new`].
    pub fn drive(&self) -> Result<MultiDrive> {
        let heads = self
            .heads
            .iter()
            .map(|p| Drive::new(Arc::new((**p).clone())))
            .collect::<Result<Vec<_>>>()?;
        Ok(MultiDrive {
            heads,
            broken: None,
        })
    }

    /// The number of heads.
    pub fn heads(&self) -> usize {
        self.heads.len()
    }

    /// Head `k`'s plant (`None` past the last head).
    pub fn head(&self, k: usize) -> Option<&Plant> {
        self.heads.get(k).map(|p| &**p)
    }
}

fn check_count(name: &str, n: usize) -> Result<()> {
    if !(1..=MAX_HEADS as usize).contains(&n) {
        return Err(Error::invalid(
            name,
            format!("a drive has 1 to {MAX_HEADS} heads, got {n}"),
        ));
    }
    Ok(())
}

/// A running drive of several heads: one clock, stepped for all heads at once, each head with
/// its own command ([`MultiDrive::step`]). Each head's sensors equal, to the bit, those of a
/// one-head [`Drive`] on its plant given the same commands: stepping the heads together costs
/// what stepping them one by one does (docs/benchmarks.md, "Drive").
pub struct MultiDrive {
    heads: Vec<Drive>,
    /// The head whose step failed: the others had moved on, so the clock is no longer one.
    broken: Option<usize>,
}

impl std::fmt::Debug for MultiDrive {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MultiDrive")
            .field("heads", &self.heads.len())
            .field("t", &self.time())
            .finish_non_exhaustive()
    }
}

impl MultiDrive {
    /// Holds `commands[k]` on head `k` for `dt` seconds and returns every head's sensors at
    /// the end, in head order.
    ///
    /// # Errors
    /// See [`MultiDrive::step_into`].
    pub fn step(&mut self, commands: &[Command], dt: f64) -> Result<Vec<Sensors>> {
        let mut out = vec![Sensors::default(); self.heads.len()];
        self.step_into(commands, dt, &mut out)?;
        Ok(out)
    }

    /// [`MultiDrive::step`] into `out` (one slot per head), with no allocation.
    ///
    /// ```
    /// use hdi_tribology::drive::{scene_zone, Command, DriveOptions, MultiPlant, Sensors};
    /// use hdi_tribology::scene::Scene;
    /// let scene = Scene::paper();
    /// let zone = scene_zone(&scene, 0.025)?;
    /// let mut drive = MultiPlant::uniform(&scene, &zone, 2, 3, DriveOptions::default())?.drive()?;
    /// let mut out = [Sensors::default(); 2];
    /// drive.step_into(&[Command::heater_mw(60.0); 2], 50e-6, &mut out)?;
    /// // Each surface its own waviness: the heads see different disk heights.
    /// assert_ne!(out[0].truth.disk_height_nm, out[1].truth.disk_height_nm);
    /// let e = drive.step_into(&[Command::heater_mw(-1.0), Command::heater_mw(60.0)], 50e-6, &mut out);
    /// assert!(e.unwrap_err().to_string().contains("commands[0].heater_power_mw"));
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::InvalidInput`] naming `commands` or `out` (not one per head),
    /// `commands[k].<field>` (a command out of range) or `dt`, before any head moves; a head's
    /// integration failure, after which the drive refuses further steps
    /// ([`DriveError::HeadsOutOfStep`]: the heads before it had moved on).
    pub fn step_into(&mut self, commands: &[Command], dt: f64, out: &mut [Sensors]) -> Result<()> {
        if let Some(head) = self.broken {
            return Err(DriveError::HeadsOutOfStep { head }.into());
        }
        let n = self.heads.len();
        for (name, len) in [("commands", commands.len()), ("out", out.len())] {
            if len != n {
                return Err(Error::invalid(
                    name,
                    format!("one per head: the drive has {n} heads, got {len}"),
                ));
            }
        }
        for (k, c) in commands.iter().enumerate() {
            c.validate().map_err(|e| match e {
                Error::InvalidInput { field, reason } => Error::InvalidInput {
                    field: field.replacen("command.", &format!("commands[{k}]."), 1),
                    reason,
                },
                other => other,
            })?;
        }
        check_period(dt)?;
        for (k, ((drive, c), s)) in self.heads.iter_mut().zip(commands).zip(out).enumerate() {
            match drive.step_checked(c, dt) {
                Ok(v) => *s = v,
                Err(e) => {
                    self.broken = Some(k);
                    return Err(e);
                }
            }
        }
        Ok(())
    }

    /// The number of heads.
    pub fn heads(&self) -> usize {
        self.heads.len()
    }

    /// Head `k`'s drive, to read (`None` past the last head).
    pub fn head(&self, k: usize) -> Option<&Drive> {
        self.heads.get(k)
    }

    /// Simulated time so far (s): one clock for every head.
    pub fn time(&self) -> f64 {
        self.heads[0].time()
    }
}
