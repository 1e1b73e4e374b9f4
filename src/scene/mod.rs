//! Scenes: a serde description of a whole head–disk interface (surfaces, enabled terms, air
//! bearing, heater, voltages, detector, solver settings), read from TOML or JSON and validated.
//!
//! Every dimensional field is SI with its unit in its name (files may use engineering units, see
//! [below](#engineering-units)). A scene builds only what it enables:
//! a missing `intermolecular`, `electrostatic` or `contact` section switches that term off.
//!
//! ```
//! use hdi_tribology::scene::Scene;
//! # fn main() -> hdi_tribology::Result<()> {
//! let paper = Scene::paper();
//! paper.validate()?;
//! let again = Scene::from_toml_str(&paper.to_toml_string()?)?;
//! assert_eq!(again, paper);
//! let mut bad = paper.clone();
//! bad.surface.height_sigma_m = -1e-9;
//! let err = Scene::from_toml_str(&bad.to_toml_string()?).unwrap_err().to_string();
//! assert!(err.contains("surface.height_sigma_m"), "{err}");
//! # Ok(()) }
//! ```
//!
//! # Engineering units
//!
//! A scene file may give any dimensional field in an engineering unit instead, with that unit in
//! its name: the reader replaces the suffix and scales the value (numbers and lists of numbers)
//! before anything else sees it, so the scene in memory, and every file it writes, is SI.
//!
//! | SI suffix | may be given as |
//! |---|---|
//! | `_m` | `_nm`, `_um` (µm), `_mm` |
//! | `_m2` | `_um2`, `_mm2` |
//! | `_per_m2` | `_per_um2` |
//! | `_s` | `_ms`, `_us` (µs), `_ns` |
//! | `_w` | `_mw` |
//! | `_hz` | `_khz`, `_mhz` |
//! | `_pa` | `_gpa` |
//! | `_n` | `_un` (µN) |
//! | `_m_per_w` | `_nm_per_mw` |
//! | `_w_per_s` | `_mw_per_s`, `_mw_per_ms` |
//! | `heater.programme` (s, W) | `heater.programme_ms_mw` (ms, mW) |
//!
//! A field given in two units, or an engineering-unit field that is not a number, is refused by
//! name; a validation error on a converted field names it as given, with the value in its unit
//! (the heater programme, two units in one field, names both spellings).
//!
//! ```
//! use hdi_tribology::scene::Scene;
//! # fn main() -> hdi_tribology::Result<()> {
//! let text = Scene::paper()
//!     .to_toml_string()?
//!     .replace("height_sigma_m = 7e-10", "height_sigma_nm = 0.5")
//!     .replace("sigma_m = 7e-10", "sigma_nm = 0.5"); // σ of the Rice-maxima peaks: the same
//! let s = Scene::from_toml_str(&text)?;
//! assert!((s.surface.height_sigma_m - 0.5e-9).abs() < 1e-24);
//! let bad = text.replace("height_sigma_nm = 0.5", "height_sigma_nm = -0.5");
//! let err = Scene::from_toml_str(&bad).unwrap_err().to_string();
//! assert!(err.contains("surface.height_sigma_nm: must be finite and >= 0, got -0.5 nm"), "{err}");
//! # Ok(()) }
//! ```
//!
//! # Fields by name
//!
//! [`FieldPath`] resolves a field named as a user writes it, in SI or in an engineering unit
//! (`surface.height_sigma_nm`), on the scene's serde form: `hdi fit --free` and the Python
//! `scene[...]` and `Scene.with_values` go through it.

mod build;
mod drive_spec;
mod eng_units;
mod io;
mod paper;
mod path;
mod spec;
mod structure;
mod toml_text;
mod validate;

pub use drive_spec::{DriveAmbientSpec, DriveDiskSpec, DriveSensorsSpec, DriveSpec, MAX_HEADS};
pub use eng_units::engineering_unit;
pub use path::{FieldPath, PathError};

pub use spec::{
    ContactSpec, DetectorSpec, ElectrostaticSpec, FrictionSpec, HeaterSpec, IntermolecularSpec,
    LubricantSpec, Scene, SliderSpec, SolverSpec, SurfaceSpec, SweepSpec, TableSpec, TriggeredSpec,
    VoltageSpec, WettingSpec,
};
pub use structure::{StructureSpec, MAX_DOF};
pub use validate::{
    MAX_AC_FREQUENCY_HZ, MAX_AIR_BEARING_STIFFNESS_N_PER_M, MAX_NOMINAL_CLEARANCE_M, MAX_STEPS,
    MAX_VOLTAGE_V, MIN_NOMINAL_CLEARANCE_M,
};
