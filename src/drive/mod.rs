//! A simulated drive that firmware code can drive: step it at the controller's rate, read its
//! sensors, close the loop.
//!
//! [`Plant`] is the drive before it runs: the slider of a scene in a [`Zone`] (a radius and disk
//! speed, with the flying conditions there), over a disk
//! with run-out and waviness ([`DiskSpec`]), with a heater behind its thermal lag and a
//! head–disk voltage ([`Command`]); [`Plant::drive`] starts a [`Drive`] on it, and
//! [`Drive::step`] advances it by one controller period and
//! returns the [`Sensors`] firmware reads: the embedded contact sensor, acoustic emission and
//! the read-back amplitudes, each with its bandwidth and seeded noise, plus the [`Truth`] for
//! test oracles. [`MultiPlant`] and [`MultiDrive`] are a drive of several heads on one disk
//! stack: one spindle and one clock, each head its own slider, heater, sensors and surface.
//!
//! ```
//! use hdi_tribology::drive::{scene_zone, Command, DriveOptions, Plant};
//! use hdi_tribology::scene::Scene;
//! let scene = Scene::paper();
//! let zone = scene_zone(&scene, 0.025)?;
//! let plant = Plant::new(&scene, &zone, 1, DriveOptions::default())?;
//! let mut drive = plant.drive()?;
//! // The firmware loop at 20 kHz: read, decide, repeat.
//! let mut power_mw = 60.0;
//! for _ in 0..100 {
//!     let s = drive.step(&Command::heater_mw(power_mw), 50e-6)?;
//!     if s.acoustic_v < 0.01 {
//!         power_mw += 0.05;
//!     }
//! }
//! assert!(power_mw > 60.0);
//! # Ok::<(), hdi_tribology::Error>(())
//! ```

mod controller;
mod disk;
mod error;
mod exponential;
mod heads;
mod orbit;
mod orbit_map;
mod plant;
mod replay;
mod rng;
mod roc;
mod sensors;
mod state;
mod zone;

pub use controller::{
    run, AcousticLevel, Action, Channel, ClearanceHold, ContactSensorSlope, Controller, HoldPhase,
    HoldSettings, HoldTarget, LevelDetector, LevelStats, RunningMean, Staircase, StaircaseOutcome,
    StaircaseSettings, TrueContact,
};
pub use disk::{DiskSpec, Harmonic};
pub use error::DriveError;
pub use exponential::SchemeCounts;
pub use heads::{head_seed, MultiDrive, MultiPlant};
pub use plant::{
    scene_zone, spec_zone, zone_at, Ambient, Command, Drive, DriveOptions, DriveScheme,
    PeriodReport, Plant, DEFAULT_RADIUS, MAX_STEPS_PER_PERIOD,
};
pub use replay::{
    check_commands, read_commands, replay, replay_each, replay_heads, replay_heads_each,
    sensor_row, whole_periods, BoundedSummary, CommandRow, ReplaySummary, MAX_REPLAY_PERIODS,
    SENSOR_COLUMNS,
};
pub use roc::{touchdown_roc, RocPoint};
pub use sensors::{
    AcousticSpec, ContactSensorSpec, Readback, ReadbackSpec, SensorSpec, Sensors, Truth,
};
pub use zone::Zone;
