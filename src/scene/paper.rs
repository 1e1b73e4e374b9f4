//! The built-in paper scene (the crate's single home of the physics defaults).

use super::spec::*;
use super::structure::StructureSpec;
use crate::force::{AirBearingModel, Footprint, GapReference};
use crate::surface::PeakModel;

impl Scene {
    /// The paper scene: every term on, all on the bulge gap with a paraboloid footprint of radius
    /// of curvature 20 mm, Rice-maxima peaks; identical to `scenes/paper.toml`.
    ///
    /// ```
    /// let s = hdi_tribology::scene::Scene::paper();
    /// assert_eq!(s.nominal_clearance_m, 1e-8);
    /// assert!(s.intermolecular.is_some() && s.electrostatic.is_some() && s.contact.is_some());
    /// ```
    pub fn paper() -> Scene {
        let bulge = Footprint::Paraboloid {
            radius_of_curvature_m: 0.02,
            max_radius_m: None,
        };
        let (stiffness, mass, zeta) = (3.0e5, 1.0e-6, 0.05);
        let f_ac = 1.05e4;
        // one σ for the surface heights and the Rice-maxima peaks of the same surface
        let sigma = 7.0e-10;
        Scene {
            name: "paper".into(),
            nominal_clearance_m: 1.0e-8,
            surface: SurfaceSpec {
                height_sigma_m: sigma,
                peaks: PeakModel::RiceMaxima {
                    sigma_m: sigma,
                    epsilon: 0.7,
                },
                independent_peak_sigma: false,
            },
            intermolecular: Some(IntermolecularSpec {
                hamaker_attractive_j: 1.0e-19,
                hamaker_repulsive_j_m6: 1.0e-76,
                cutoff_m: None,
                footprint: bulge,
                gap: GapReference::Bulge,
            }),
            electrostatic: Some(ElectrostaticSpec {
                contact_potential_v: 0.0,
                dielectric_thickness_m: 0.0,
                cutoff_m: None,
                footprint: bulge,
                gap: GapReference::Bulge,
            }),
            contact: Some(ContactSpec {
                composite_modulus_pa: 1.0e11,
                asperity_radius_m: 1.0e-7,
                asperity_density_per_m2: 1.5e14,
                footprint: bulge,
                gap: GapReference::Bulge,
            }),
            lubricant: None,
            air_bearing: AirBearingModel::Linear {
                stiffness_n_per_m: stiffness,
                damping_n_s_per_m: 2.0 * zeta * (stiffness * mass).sqrt(),
            },
            slider: SliderSpec {
                mass_kg: mass,
                interface_lag_s: 0.0,
            },
            structure: StructureSpec::Rigid,
            heater: HeaterSpec {
                efficiency_m_per_w: 1.0e-7,
                thermal_lag_s: 0.0,
                programme: vec![
                    [0.0, 0.060],
                    [3.6e-3, 0.078],
                    [4.0e-3, 0.078],
                    [7.6e-3, 0.060],
                ],
                triggered: TriggeredSpec {
                    start_power_w: 0.060,
                    ramp_rate_w_per_s: 5.0,
                    overshoot_w: 0.001,
                },
            },
            voltage: VoltageSpec {
                dc_v: 0.0,
                ac_amplitude_v: 0.0,
                ac_frequency_hz: f_ac,
            },
            detector: DetectorSpec {
                contact_threshold_n: 5.0e-5,
                window_s: 1.0 / (2.0 * f_ac),
            },
            friction: FrictionSpec {
                coefficient: 0.2,
                disk_speed_m_per_s: 10.0,
                head_conductivity_w_per_m_k: 20.0,
            },
            solver: SolverSpec::default(),
            table: TableSpec::default(),
            sweep: SweepSpec {
                ac_amplitudes_v: vec![0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0],
            },
            drive: None,
        }
    }
}
