//! # hdi-tribology
//!
//! Tribology of the head–disk interface (HDI) of hard disk drives: how a flying
//! head, a nanometre above a disk spinning at 5–40 m/s, approaches, touches and
//! leaves it.
//!
//! The crate implements the lumped model of the letter "Electrostatically
//! tunable adhesion in a high speed sliding interface": an electrostatic force,
//! an intermolecular (Hamaker, Lennard-Jones 3–9) force, a Greenwood–Williamson
//! asperity contact force and an air bearing, averaged over surface roughness
//! and asperity-peak statistics, driving the rigid-body motion of the head.
//!
//! Layout (data flows one way):
//! - [`surface`]: surface-height and asperity-peak-height statistics;
//! - [`quadrature`]: adaptive integration and precomputed tables;
//! - [`force`]: interface terms (trait based), footprints and air bearings;
//! - [`scene`]: a serde description of a whole scene, validated into parts;
//! - [`ode`]: a generic ODE stepper that knows no physics;
//! - [`model`] and [`analysis`]: the slider model and the analyses (touchdown,
//!   take-off, hysteresis, pull-in, temperature rise) that join physics and ODE.
//!
//! All quantities are SI inside the crate; [`units`] has helpers for the
//! engineering units used at the edges (nm, mW, kHz, GPa).
#![forbid(unsafe_code)]
#![cfg_attr(docsrs, feature(doc_cfg))]

pub mod analysis;
pub mod clearance;
pub mod error;
pub mod force;
pub mod heater;
pub mod model;
pub mod ode;
pub mod quadrature;
pub mod report;
pub mod scene;
pub mod surface;
pub mod units;

pub use error::{Error, Result};
