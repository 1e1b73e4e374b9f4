//! # hdi-tribology
//!
//! Tribology of the head–disk interface (HDI) of hard disk drives: how a flying head, a few
//! nanometres above a disk spinning at 5–40 m/s, approaches it, touches it and leaves it.
//!
//! ## The physics in a page
//!
//! The head flies on an **air bearing** at a nominal clearance `h0` (about 10 nm). A heater in
//! the head raises a thermal bulge of height `δ = ηP` (η ≈ 0.1 nm/mW), so the gap at the bulge
//! is `d = h0 + y − δ`, where `y` is the head's displacement away from the disk. Across that
//! gap act:
//!
//! - an **intermolecular** force, the Lennard-Jones 3–9 law between half-spaces,
//!   `p = −A/(6πh³) + B/(45πh⁹)` (Hamaker constants A, B);
//! - an **electrostatic** force `p = −ε₀V²/(2(h + t_d)²)` under the voltage
//!   `V(t) = V_dc + V_ac sin 2πft − φ` (φ the contact potential);
//! - **asperity contact** after Greenwood and Williamson: peaks of radius R and areal density
//!   η_s, with heights drawn from a peak distribution, pressed with the composite modulus E*.
//!
//! The non-contact laws are averaged over Gaussian surface heights and the contact law over
//! the peak heights. All three are integrated over the bulge's footprint (a paraboloid of
//! radius ≈ 20 mm, by Derjaguin's approximation). The head then moves as one rigid body,
//! `m ÿ = F_ab(y, ẏ) + F_if(d, t)`.
//!
//! Raising the heater power moves the head along an S-shaped curve of equilibria. The flying
//! branch ends at a fold (the head jumps into contact: **touchdown**). The contact branch ends
//! at another fold, at lower power (the head jumps off: **take-off**). The difference is the
//! **hysteresis**, a few mW. An AC voltage makes the head dither at twice its frequency. In
//! this model that brings touchdown earlier, and above a few tenths of a volt the hysteresis
//! collapses: the effect reported in the letter "Electrostatically tunable adhesion in a high
//! speed sliding interface", which the built-in paper scene reproduces. The equations as
//! implemented, with the letter's typos corrected, are in `docs/model.md` and
//! `docs/analyses.md`.
//!
//! ## Quick start
//!
//! ```
//! use hdi_tribology::analysis::{pull_in_voltage, static_hysteresis, StaticOptions};
//! use hdi_tribology::model::SliderModel;
//! use hdi_tribology::scene::Scene;
//!
//! let scene = Scene::paper();
//! let model = SliderModel::from_scene(&scene)?;
//! let opts = StaticOptions::new(scene.detector.contact_threshold_n);
//! let h = static_hysteresis(&model, &opts)?;
//! assert!(h.touchdown.power > h.takeoff.power);
//! println!(
//!     "touchdown {:.2} mW, take-off {:.2} mW, pull-in at 0 mW: {:.2} V",
//!     h.touchdown.power_mw(),
//!     h.takeoff.power_mw(),
//!     pull_in_voltage(&model, 0.0, &opts)?.voltage
//! );
//! # Ok::<(), hdi_tribology::Error>(())
//! ```
//!
//! Dynamic cycles, AC sweeps and the linear response are in [`analysis`]; the stepper in
//! [`ode`] can be used on any ODE.
//!
//! ## Layout
//!
//! Data flows one way:
//! - [`numerics`]: building blocks that know no physics (seeded random generators);
//! - [`surface`]: surface-height and asperity-peak-height statistics;
//! - [`quadrature`]: adaptive integration and precomputed tables;
//! - [`force`]: interface terms (trait based), footprints and air bearings;
//! - [`bearing`]: the air bearing from the slider's geometry (the Reynolds equation with
//!   rarefaction, the attitude solve, stiffness and damping);
//! - [`scene`]: a serde description of a whole scene, validated into parts, and its fields by
//!   dotted name ([`scene::FieldPath`]);
//! - [`ode`]: a generic ODE stepper that knows no physics;
//! - [`heater`]: heater power programmes;
//! - [`model`]: the slider model of a scene (never rewritten), the [`model::Inputs`] that drive
//!   it, and the two as an ODE system ([`model::SliderSystem`]);
//! - [`cache`]: a disk cache of a scene's force tables (a warm start; off unless asked for);
//! - [`sim`]: the one simulation path: a problem built from a model and its inputs (tolerances,
//!   method, options, fixed-size state);
//! - [`analysis`]: the analyses (touchdown, take-off, hysteresis, pull-in, temperature rise,
//!   cycles, sweeps, the linear response);
//! - [`error`]: the crate's error type, with typed kinds per analysis;
//! - [`drive`]: a simulated drive that firmware code can step;
//! - [`calibration`]: firmware clearance calibration on the simulated drive;
//! - [`fit`]: fitting a scene's parameters to measured curves;
//! - [`report`]: CSV tables and SVG charts; [`units`]: engineering units at the edges.
//!
//! All quantities are SI inside the crate; [`units`] has helpers for the engineering units
//! used at the edges (nm, mW, kHz, GPa).
//!
//! ## Features
//!
//! - `plot` (default): SVG charts through plotters' SVG backend ([`report::Chart`]).
//! - `parallel` (default): AC sweeps on rayon; results do not depend on the thread count.
//! - `cli`: the `hdi` command-line program.
#![forbid(unsafe_code)]
#![deny(missing_docs)]
#![warn(rustdoc::all)]
#![cfg_attr(docsrs, feature(doc_cfg))]

/// Builder methods that set one field each: `name(arg: T) => field = value;` makes
/// `pub fn name(mut self, arg: T) -> Self` that sets `self.field = value`, and `name() => …`
/// one without an argument. Defined before the modules, so that every module can use it.
macro_rules! setters {
    ($($(#[$doc:meta])* $name:ident($($arg:ident: $ty:ty)?) => $field:ident = $value:expr;)*) => {$(
        $(#[$doc])*
        pub fn $name(mut self $(, $arg: $ty)?) -> Self {
            self.$field = $value;
            self
        }
    )*};
}

pub mod analysis;
pub mod bearing;
pub mod cache;
pub mod calibration;
pub mod drive;
pub mod error;
pub mod fit;
pub mod force;
pub mod heater;
pub mod model;
pub mod numerics;
pub mod ode;
pub mod quadrature;
pub mod report;
pub mod scene;
pub mod sim;
pub mod surface;
pub mod units;

pub use error::{Error, Result};
/// The linear algebra crate of the public API (state vectors, Jacobian matrices), re-exported
/// so that a system can be written without matching its version by hand.
pub use nalgebra;
