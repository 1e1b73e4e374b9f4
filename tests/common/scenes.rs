//! Test scenes shared by several test files.
#![allow(dead_code)]

use hdi_tribology::force::Footprint;
use hdi_tribology::scene::{ElectrostaticSpec, Scene};

/// The paper scene made smooth, with electrostatics alone on the given footprint (no contact, no
/// intermolecular force, contact potential 0 V): the pull-in closed forms hold for it.
pub fn electrostatic_only(footprint: Footprint) -> Scene {
    let mut s = Scene::paper();
    s.name = "electrostatic only".into();
    s.surface.height_sigma_m = 0.0;
    s.intermolecular = None;
    s.contact = None;
    s.electrostatic = Some(ElectrostaticSpec {
        contact_potential_v: 0.0,
        dielectric_thickness_m: 0.0,
        cutoff_m: Some(1e-10),
        footprint,
        gap: Default::default(),
    });
    // Keep the smooth kernel's cutoff (a step in the force) out of the table.
    s.table.d_min_m = Some(1e-9);
    s
}
