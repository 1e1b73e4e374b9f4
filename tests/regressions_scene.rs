//! Cases that once failed, kept as regression tests (found by the property tests and fuzzing).

use hdi_tribology::scene::Scene;

/// JSON dropped the last bit of some numbers: serde_json's default float parser is not
/// correctly rounded (found by `invariants_scene`, Hamaker constant 10^-19.3087…). The crate now
/// parses JSON floats exactly.
#[test]
fn json_round_trip_keeps_every_bit_of_a_hamaker_constant() {
    let mut s = Scene::paper();
    let a = 4.9128345928709434e-20_f64;
    if let Some(m) = s.intermolecular.as_mut() {
        m.hamaker_attractive_j = a;
    }
    let back = Scene::from_json_str(&s.to_json_string().unwrap()).unwrap();
    let got = back.intermolecular.map(|m| m.hamaker_attractive_j).unwrap();
    assert_eq!(got.to_bits(), a.to_bits(), "{got:e} != {a:e}");
    let back = Scene::from_toml_str(&s.to_toml_string().unwrap()).unwrap();
    assert_eq!(back, s);
}

/// The same for many numbers at once: every finite double survives JSON and TOML bit for bit.
#[test]
fn json_and_toml_round_trips_keep_every_bit_of_many_numbers() {
    let mut x = 0x9e37_79b9_7f4a_7c15_u64;
    let mut s = Scene::paper();
    for _ in 0..2000 {
        // xorshift: arbitrary bit patterns, kept when they form a valid positive modulus.
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        let v = f64::from_bits(x >> 1);
        if !(v.is_finite() && v > 0.0) {
            continue;
        }
        if let Some(c) = s.contact.as_mut() {
            c.composite_modulus_pa = v;
        }
        let json = Scene::from_json_str(&s.to_json_string().unwrap()).unwrap();
        let toml = Scene::from_toml_str(&s.to_toml_string().unwrap()).unwrap();
        for back in [json, toml] {
            let got = back.contact.map(|c| c.composite_modulus_pa).unwrap();
            assert_eq!(got.to_bits(), v.to_bits(), "{got:e} != {v:e}");
        }
    }
}

/// A single discrete asperity below the mean plane (so the peak heights have zero spread, and
/// the surface heights too) used to get a default table range that stopped above the peak, and
/// the scene refused itself (found by `invariants_scene`: peak at −1.52 nm, h0 = 1.05 nm). The
/// default range now starts below the mean peak height whatever the spread.
#[test]
fn default_table_range_covers_a_single_peak_below_the_mean_plane() {
    use hdi_tribology::force::Gaps;
    use hdi_tribology::surface::PeakModel;
    let mut s = Scene::paper();
    s.nominal_clearance_m = 1.053923788566322e-9;
    s.surface.height_sigma_m = 0.0;
    s.surface.peaks = PeakModel::Discrete {
        heights_m: vec![-1.516751910554614e-9],
    };
    s.intermolecular = None;
    s.electrostatic = None;
    assert!(s.validate().is_ok(), "{:?}", s.validate());
    let (lo, hi) = s.table_range();
    assert!(lo < -1.516751910554614e-9 && hi > s.nominal_clearance_m);
    let forces = s.build_interface().unwrap();
    // The peak is touched only below d = −1.52 nm: no contact above it, contact below.
    let above = forces.evaluate(Gaps::same(-1.5e-9));
    let below = forces.evaluate(Gaps::same(-1.55e-9));
    assert!(above.contact.value.abs() < 1e-15, "{above:?}");
    assert!(below.contact.value > 1e-12, "{below:?}");
}
