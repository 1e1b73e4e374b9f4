//! The analyses: static equilibria, touchdown and take-off, pull-in, clearance change,
//! dynamic touchdown/take-off cycles, AC sweeps and linear response.
//!
//! Static analyses need no time integration; dynamic ones integrate [`crate::model::SliderSystem`]
//! with [`crate::ode`].

pub mod cycle;
pub mod equilibrium;
pub mod pull_in;
pub mod response;
pub mod roots;
pub mod sweep;
pub mod touchdown;

pub use cycle::{simulate_cycle, CycleOptions, CycleResult, HeaterProgramme, TimeSeries};
pub use equilibrium::{flying_equilibrium, s_curve, Equilibrium, Fold, SCurve, ScanGrid};
pub use pull_in::{clearance_change, pull_in_voltage, ClearanceChange, PullIn};
pub use response::{linear_response, LinearResponse};
pub use sweep::{ac_sweep, ac_sweep_refined, RefinedCycle, Refinement};
pub use touchdown::{
    static_hysteresis, takeoff_power, touchdown_power, Cause, StaticHysteresis, StaticOptions,
    Transition,
};
