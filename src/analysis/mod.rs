//! The analyses: static equilibria, touchdown and take-off, pull-in, clearance change,
//! dynamic touchdown/take-off cycles, AC sweeps and linear response.
//!
//! Static analyses need no time integration; dynamic ones integrate [`crate::model::SliderSystem`]
//! with [`crate::ode`].

pub mod cycle;
pub mod energy;
pub mod equilibrium;
pub mod protocol;
pub mod pull_in;
pub mod record;
pub mod response;
pub mod roots;
pub mod sensitivity;
pub mod sweep;
pub mod touchdown;

pub use cycle::{
    simulate_cycle, CycleOptions, CycleResult, Detection, Detector, HeaterProgramme,
    SolverSettings, TimeSeries,
};
pub use energy::LagEnergy;
pub use equilibrium::{
    flying_equilibrium, s_curve, Equilibrium, EquilibriumSolver, Fold, SCurve, ScanGrid,
};
pub use protocol::Protocol;
pub use pull_in::{clearance_change, pull_in_voltage, ClearanceChange, PullIn};
pub use response::{linear_response, LinearResponse, Mode, StateSpace};
pub use sensitivity::transition_shift;
pub use sweep::{ac_sweep, ac_sweep_refined, RefinedCycle, Refinement};
pub use touchdown::{
    static_hysteresis, takeoff_power, touchdown_power, Cause, StaticHysteresis, StaticOptions,
    Transition,
};
