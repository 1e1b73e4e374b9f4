//! The ODE solvers: explicit and stiff methods against closed forms and the Test Set for IVP
//! Solvers, events, switches, options, errors and cancellation.
//!
//! One test program of several (Cargo.toml, `[[test]]`): each file below stays a file of its own
//! under `tests/`, and its tests are named `<file>::<test>`.

// Several files include the same helper file (`tests/common/`, `examples/common/`) as a module
// of their own, as they did when each file was a program.
#![allow(clippy::duplicate_mod)]

#[path = "../ode_cancel.rs"]
mod ode_cancel;
#[path = "../ode_errors.rs"]
mod ode_errors;
#[path = "../ode_events.rs"]
mod ode_events;
#[path = "../ode_exact.rs"]
mod ode_exact;
#[path = "../ode_integrator.rs"]
mod ode_integrator;
#[path = "../ode_options.rs"]
mod ode_options;
#[path = "../ode_stiff.rs"]
mod ode_stiff;
#[path = "../ode_switches.rs"]
mod ode_switches;
#[path = "../ode_systems.rs"]
mod ode_systems;
#[path = "../ode_testset.rs"]
mod ode_testset;
