//! Property tests of scene serialisation: any valid scene written as TOML or JSON and read back
//! is the same scene, bit for bit, and gives the same forces.

#[path = "common/seeded.rs"]
mod seeded;

use hdi_tribology::force::TermForce;
use hdi_tribology::force::{AirBearingModel, Footprint, GapReference};
use hdi_tribology::scene::{ContactSpec, ElectrostaticSpec, IntermolecularSpec, Scene};
use hdi_tribology::surface::PeakModel;
use proptest::prelude::*;

fn log_range(lo: f64, hi: f64) -> impl Strategy<Value = f64> + Clone {
    (lo..hi).prop_map(|e: f64| 10f64.powf(e))
}

fn footprint() -> impl Strategy<Value = Footprint> {
    prop_oneof![
        log_range(-12.0, -6.0).prop_map(|a| Footprint::Flat { area_m2: a }),
        (
            log_range(-4.0, -1.0),
            proptest::option::of(log_range(-6.0, -3.0))
        )
            .prop_map(|(rc, r)| Footprint::Paraboloid {
                radius_of_curvature_m: rc,
                max_radius_m: r,
            }),
    ]
}

fn gap() -> impl Strategy<Value = GapReference> {
    prop_oneof![Just(GapReference::Bulge), Just(GapReference::Pad)]
}

fn peak_model() -> impl Strategy<Value = PeakModel> {
    let s = log_range(-11.0, -8.3);
    prop_oneof![
        (s.clone(), -1.0..1.0f64).prop_map(|(s, m)| PeakModel::Gaussian {
            mean_m: m * s,
            std_m: s
        }),
        (s.clone(), 0.05..1.0f64).prop_map(|(s, e)| PeakModel::RiceMaxima {
            sigma_m: s,
            epsilon: e
        }),
        (s.clone(), 0.0..3.0f64).prop_map(|(s, nu)| PeakModel::Rician {
            nu_m: nu * s,
            s_m: s
        }),
        proptest::collection::vec(-5e-9..5e-9f64, 1..20)
            .prop_map(|h| PeakModel::Discrete { heights_m: h }),
        (s, 1usize..50, any::<u64>()).prop_map(|(s, n, seed)| PeakModel::DiscreteSampled {
            from: Box::new(PeakModel::Gaussian {
                mean_m: 0.0,
                std_m: s
            }),
            n,
            seed
        }),
    ]
}

prop_compose! {
    fn scene()(
        h0 in log_range(-9.0, -7.0),
        sigma in prop_oneof![Just(0.0), log_range(-11.0, -8.3)],
        peaks in peak_model(),
        lj in proptest::option::of((log_range(-21.0, -18.0), log_range(-78.0, -74.0), footprint(), gap())),
        es in proptest::option::of((-1.0..1.0f64, log_range(-10.0, -9.0), footprint(), gap())),
        gw in proptest::option::of((log_range(9.0, 12.0), log_range(-9.0, -5.0), log_range(12.0, 16.0), footprint(), gap())),
        k in log_range(3.0, 7.0),
        zeta in log_range(-4.0, 1.0),
        m in log_range(-8.0, -4.0),
        lags in (prop_oneof![Just(0.0), log_range(-9.0, -3.0)], prop_oneof![Just(0.0), log_range(-9.0, -3.0)]),
        eta in log_range(-8.0, -6.0),
        volts in (-20.0..20.0f64, 0.0..5.0f64, log_range(0.0, 6.5)),
        rtol in log_range(-10.0, -3.0),
    ) -> Scene {
        let mut s = Scene::paper();
        s.name = "random".into();
        s.nominal_clearance_m = h0;
        s.surface.height_sigma_m = sigma;
        s.surface.peaks = peaks;
        s.surface.independent_peak_sigma = true; // drawn independently on purpose
        s.intermolecular = lj.map(|(a, b, footprint, gap)| IntermolecularSpec {
            hamaker_attractive_j: a,
            hamaker_repulsive_j_m6: b,
            cutoff_m: None,
            footprint,
            gap,
        });
        s.electrostatic = es.map(|(phi, hc, footprint, gap)| ElectrostaticSpec {
            contact_potential_v: phi,
            dielectric_thickness_m: 0.0,
            cutoff_m: Some(hc),
            footprint,
            gap,
        });
        s.contact = gw.map(|(e, r, n, footprint, gap)| ContactSpec {
            composite_modulus_pa: e,
            asperity_radius_m: r,
            asperity_density_per_m2: n,
            footprint,
            gap,
        });
        s.air_bearing = AirBearingModel::Linear {
            stiffness_n_per_m: k,
            damping_n_s_per_m: 2.0 * zeta * (k * m).sqrt(),
        };
        s.slider.mass_kg = m;
        s.slider.interface_lag_s = lags.0;
        s.heater.thermal_lag_s = lags.1;
        s.heater.efficiency_m_per_w = eta;
        s.voltage.dc_v = volts.0;
        s.voltage.ac_amplitude_v = volts.1;
        s.voltage.ac_frequency_hz = volts.2;
        s.solver.rtol = rtol;
        s
    }
}

/// Every enabled term's direct force at a few gaps, as bits.
fn force_bits(s: &Scene) -> Vec<u64> {
    let terms = s.interface_terms().unwrap();
    let (lo, hi) = s.table_range();
    let mut out = Vec::new();
    for d in [lo, 0.3 * lo + 0.7 * hi, hi] {
        for t in &terms {
            let TermForce {
                value: f,
                slope: df,
            } = t.force(d).unwrap();
            out.push(f.to_bits());
            out.push(df.to_bits());
        }
    }
    out
}

proptest! {
    #![proptest_config(seeded::config(200))]

    #[test]
    fn toml_and_json_round_trips_are_exact(s in scene()) {
        prop_assert!(s.validate().is_ok(), "{:?}", s.validate());
        let from_toml = Scene::from_toml_str(&s.to_toml_string().unwrap()).unwrap();
        let from_json = Scene::from_json_str(&s.to_json_string().unwrap()).unwrap();
        prop_assert_eq!(&from_toml, &s);
        prop_assert_eq!(&from_json, &s);
        // PartialEq on f64 would accept −0.0 for 0.0; the debug text tells them apart.
        prop_assert_eq!(format!("{from_toml:?}"), format!("{s:?}"));
        prop_assert_eq!(format!("{from_json:?}"), format!("{s:?}"));
        let bits = force_bits(&s);
        prop_assert_eq!(force_bits(&from_toml), bits.clone());
        prop_assert_eq!(force_bits(&from_json), bits);
    }
}
