//! The simulated drive: the plant, its bounded mode, several heads, base excitation, replay,
//! controllers, and the clearance detectors and calibration.
//!
//! One test program of several (Cargo.toml, `[[test]]`): each file below stays a file of its own
//! under `tests/`, and its tests are named `<file>::<test>`.

#[path = "../clearance_calibration.rs"]
mod clearance_calibration;
#[path = "../clearance_detectors.rs"]
mod clearance_detectors;
#[path = "../drive_base_excitation.rs"]
mod drive_base_excitation;
#[path = "../drive_bounded.rs"]
mod drive_bounded;
#[path = "../drive_controllers.rs"]
mod drive_controllers;
#[path = "../drive_heads.rs"]
mod drive_heads;
#[path = "../drive_plant.rs"]
mod drive_plant;
#[path = "../drive_replay.rs"]
mod drive_replay;
