//! Rarefied-gas Poiseuille flow factor.
mod kinetic;
