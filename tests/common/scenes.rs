//! Test scenes shared by several test files.
#![allow(dead_code)]

use hdi_tribology::force::Footprint;
use hdi_tribology::scene::{ElectrostaticSpec, Scene};

/// The few-peak deformable-slider scene of the mechanism maps, `scenes/paper_bulge.toml`.
pub fn paper_bulge() -> Scene {
    Scene::from_path(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/paper_bulge.toml"
    ))
    .expect("the repository's scene reads")
}

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

/// The structures of `benches/static_analyses.rs` on the paper scene: `rigid`, a `bulge` of
/// 5e-13 kg on 4e5 N/m, and `pitch` for a 1 mg slider 1 mm long pivoting at its middle
/// (L = 0.5 mm), with the bearing's heave stiffness over the pads (k L²/3) as pitch stiffness
/// and a small heave–pitch coupling.
pub fn bench_structures() -> Vec<(&'static str, hdi_tribology::scene::StructureSpec)> {
    use hdi_tribology::scene::StructureSpec;
    let paper = Scene::paper();
    let (k_ab, l) = (3e5, 0.5e-3);
    vec![
        ("rigid", StructureSpec::Rigid),
        (
            "bulge",
            StructureSpec::Bulge {
                mass_kg: 5e-13,
                stiffness_n_per_m: 4e5,
                damping_ratio: 0.05,
            },
        ),
        (
            "pitch",
            StructureSpec::Pitch {
                inertia_kg_m2: paper.slider.mass_kg * l * l / 3.0,
                stiffness_n_m_per_rad: Some(k_ab * l * l / 3.0),
                coupling_stiffness_n_per_rad: Some(10.0),
                damping_n_m_s_per_rad: Some(1e-9),
                coupling_damping_n_s_per_rad: Some(0.0),
                trailing_edge_m: Some(l),
                from_bearing: false,
            },
        ),
    ]
}
