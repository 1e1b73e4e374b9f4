//! Interface forces between head and disk: trait-based pressure terms averaged over roughness and a
//! footprint, their merged look-up tables for the hot path, and the air-bearing models.
//!
//! Each [`InterfaceTerm`] gives a force (N, positive = away from the disk) as a function of the
//! mean-plane separation `d` by direct quadrature. [`InterfaceForces`] tabulates the enabled terms
//! once per scene, merging terms with the same time dependence and gap reference, so that one
//! evaluation of every force costs a handful of table look-ups.
//!
//! ```
//! use hdi_tribology::force::{Footprint, GapReference, InterfaceTerm, Intermolecular, lj_zero};
//! use hdi_tribology::surface::GaussianHeights;
//! # fn main() -> hdi_tribology::Result<()> {
//! let (a, b) = (1e-19, 1e-76);
//! let sphere = Footprint::Paraboloid { radius_of_curvature_m: 0.02, max_radius_m: None };
//! let smooth = GaussianHeights::new(0.0)?;
//! let lj = Intermolecular::new(a, b, None, smooth, sphere, GapReference::Bulge)?;
//! let d = 2e-9;
//! let f = lj.force(d)?.value;
//! // smooth sphere, Derjaguin: −A Rc/(6 d²) + B Rc/(180 d⁸)
//! let exact = -a * 0.02 / (6.0 * d * d) + b * 0.02 / (180.0 * d.powi(8));
//! assert!((f - exact).abs() <= 1e-12 * exact.abs());
//! assert!(lj_zero(a, b) > 2.2e-10 && lj_zero(a, b) < 2.3e-10);
//! # Ok(()) }
//! ```

mod air_bearing;
mod averaged;
mod contact;
mod electrostatic;
mod error;
mod footprint;
mod fused;
mod interface;
mod intermolecular;
mod meniscus;
mod pressure;
mod stateful;
mod term;

pub use air_bearing::{
    AirBearing, AirBearingModel, CubicBearing, LinearBearing, PowerLawBearing, ReynoldsBearing,
    DEFAULT_REYNOLDS_CELLS,
};
pub use averaged::AveragedTerm;
pub use contact::{composite_modulus, GreenwoodWilliamson};
pub use electrostatic::Electrostatic;
pub use error::ForceError;
pub use footprint::{Footprint, Scaled};
pub(crate) use interface::by_coupling;
pub use interface::{
    Breakdown, ForceEval, Gaps, HotForces, HotValues, InterfaceForces, OutsideTables,
};
pub use intermolecular::Intermolecular;
pub use meniscus::{lian_rupture_distance, Meniscus, MeniscusParams, Pickup, Wetting};
pub use pressure::{lj_zero, Coulomb, LennardJones39, PressureLaw};
pub use stateful::{
    Branch, RatePartials, RelaxingState, StateForce, StatefulTerm, MAX_TERM_STATES,
};
pub use term::{Coupling, GapReference, InterfaceTerm, TermForce, TermKind};
