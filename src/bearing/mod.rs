//! The air bearing from the slider's geometry: the steady compressible Reynolds equation with
//! rarefaction on the air-bearing surface's rails and recesses, the attitude at which it carries
//! the suspension's preload, and what the rest of the crate takes from it (stiffness, damping, a
//! force–spacing curve).
//!
//! This is a layer of its own: surface geometry, gas properties and numerics. It knows nothing
//! of the analyses, the ODE stepper or the drive. The equations, the discretisation, the
//! validation and the limits are in `docs/air_bearing.md`.
//!
//! - [`geometry`]: the slider's surface and operating conditions as data (TOML, JSON, text);
//! - [`grid`]: the control-volume grid, refined at the steps, and the surface on it;
//! - [`reynolds`]: the discretised equation and its Newton solve;
//! - [`linear`]: the sparse linear algebra (ILU(0)-preconditioned GMRES);
//! - [`attitude`]: the attitude solve and its outputs.

pub mod attitude;
mod error;
pub mod flow_factor;
pub mod geometry;
pub mod grid;
pub mod linear;
pub mod map;
pub mod reynolds;

pub use attitude::{solve_attitude, AttitudeOptions, Equilibrium};
pub use error::{BearingError, Solve};
pub use flow_factor::FlowModel;
pub use geometry::{
    Bearing, BearingSpec, GridSpec, OperatingConditions, Polygon, Region, SliderGeometry, Taper,
};
pub use grid::Grid;
pub use reynolds::{Attitude, Interrupt, NewtonStats, Reynolds, Sides};
