//! Scenes: a serde description of a whole head–disk interface (surfaces, enabled terms, air
//! bearing, heater, voltages, detector, solver settings), read from TOML or JSON and validated.
//!
//! Every dimensional field is SI with its unit in its name. A scene builds only what it enables:
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

mod build;
mod io;
mod paper;
mod spec;
mod validate;

pub use spec::{
    ContactSpec, DetectorSpec, ElectrostaticSpec, FrictionSpec, HeaterSpec, IntermolecularSpec,
    Scene, SliderSpec, SolverSpec, SurfaceSpec, SweepSpec, TableSpec, TriggeredSpec, VoltageSpec,
};
