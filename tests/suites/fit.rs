//! Fitting: bad data files, the goodness-of-fit tests, recovery of known parameters, the
//! sensitivities, and what `trusted` means.
//!
//! One test program of several (Cargo.toml, `[[test]]`): each file below stays a file of its own
//! under `tests/`, and its tests are named `<file>::<test>`.

#[path = "../fit_data.rs"]
mod fit_data;
#[path = "../fit_goodness.rs"]
mod fit_goodness;
#[path = "../fit_indicator.rs"]
mod fit_indicator;
#[path = "../fit_recovery.rs"]
mod fit_recovery;
#[path = "../fit_sensitivity.rs"]
mod fit_sensitivity;
#[path = "../fit_trust.rs"]
mod fit_trust;
