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
