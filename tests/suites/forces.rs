//! The interface forces: quadrature, peak-height laws, the force terms against their limits and
//! their tables, property tests, and the table cache.
//!
//! One test program of several (Cargo.toml, `[[test]]`): each file below stays a file of its own
//! under `tests/`, and its tests are named `<file>::<test>`.

// Several files include the same helper file (`tests/common/`, `examples/common/`) as a module
// of their own, as they did when each file was a program.
#![allow(clippy::duplicate_mod)]

#[path = "../force_limits.rs"]
mod force_limits;
#[path = "../force_props.rs"]
mod force_props;
#[path = "../force_tables.rs"]
mod force_tables;
#[path = "../invariants_forces.rs"]
mod invariants_forces;
#[path = "../quadrature_integrate.rs"]
mod quadrature_integrate;
#[path = "../quadrature_table.rs"]
mod quadrature_table;
#[path = "../regressions_forces.rs"]
mod regressions_forces;
#[path = "../surface_inputs.rs"]
mod surface_inputs;
#[path = "../surface_laws.rs"]
mod surface_laws;
#[path = "../surface_props.rs"]
mod surface_props;
#[path = "../table_cache.rs"]
mod table_cache;
