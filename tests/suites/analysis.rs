//! The analyses: static and dynamic, refined sweeps, cycles, the interface lag, menisci, stateful
//! terms, the quasi-static bulge, the report writers; and the repository's own checks: the
//! numbers the docs quote, and every file of `tests/` in one test program.
//!
//! One test program of several (Cargo.toml, `[[test]]`): each file below stays a file of its own
//! under `tests/`, and its tests are named `<file>::<test>`.

// Several files include the same helper file (`tests/common/`, `examples/common/`) as a module
// of their own, as they did when each file was a program.
#![allow(clippy::duplicate_mod)]

#[path = "../analysis_dynamic.rs"]
mod analysis_dynamic;
#[path = "../analysis_refined_sweep.rs"]
mod analysis_refined_sweep;
#[path = "../analysis_static.rs"]
mod analysis_static;
#[path = "../cycle_mean_temperature.rs"]
mod cycle_mean_temperature;
#[path = "../cycle_series_window.rs"]
mod cycle_series_window;
#[path = "../cycle_stop_at_takeoff.rs"]
mod cycle_stop_at_takeoff;
#[path = "../docs_numbers.rs"]
mod docs_numbers;
#[path = "../invariants_analysis.rs"]
mod invariants_analysis;
#[path = "../lag_energy.rs"]
mod lag_energy;
#[path = "../lag_tolerance.rs"]
mod lag_tolerance;
#[path = "../meniscus.rs"]
mod meniscus;
#[path = "../model_stateful.rs"]
mod model_stateful;
#[path = "../quasi_static_bulge.rs"]
mod quasi_static_bulge;
#[path = "../regressions_cycle.rs"]
mod regressions_cycle;
#[path = "../report_output.rs"]
mod report_output;
#[path = "../static_skip.rs"]
mod static_skip;
#[path = "../test_programs.rs"]
mod test_programs;

// `examples/common/static_numbers.rs` (a module of `docs_numbers`) reads its quotes through
// `crate::doc_numbers`, as the examples that include it declare it.
use docs_numbers::doc_numbers;
