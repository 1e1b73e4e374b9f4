//! The `hdi` program, run as a user runs it (the `cli` feature): every subcommand's output, usage,
//! bad input, and the shipped scenes.
//!
//! One test program of several (Cargo.toml, `[[test]]`): each file below stays a file of its own
//! under `tests/`, and its tests are named `<file>::<test>`.

#[path = "../bad_input_cli.rs"]
mod bad_input_cli;
#[path = "../cli_analyses.rs"]
mod cli_analyses;
#[path = "../cli_bearing.rs"]
mod cli_bearing;
#[path = "../cli_forces.rs"]
mod cli_forces;
#[path = "../cli_trust.rs"]
mod cli_trust;
#[path = "../cli_typed_values.rs"]
mod cli_typed_values;
#[path = "../cli_usage.rs"]
mod cli_usage;
#[path = "../drive_cli.rs"]
mod drive_cli;
#[path = "../fit_cli.rs"]
mod fit_cli;
#[path = "../scenes_shipped.rs"]
mod scenes_shipped;
