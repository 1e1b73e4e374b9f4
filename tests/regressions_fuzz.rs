//! Scene-reader fuzzing cases that once failed, kept as regression tests.

use hdi_tribology::force::TermForce;
use hdi_tribology::scene::Scene;

/// Accepted scenes whose parameters overflow f64 (found by `bad_input_fuzz`: a radius of
/// curvature, a modulus or an asperity density of 1e308) gave forces of ±∞ or NaN as `Ok`.
/// A term must return a finite force or an error.
#[test]
fn overflowing_parameters_give_an_error_not_infinity() {
    let base = Scene::paper().to_toml_string().unwrap();
    for (key, value) in [
        ("radius_of_curvature_m", "1e308"),
        ("composite_modulus_pa", "1e308"),
        ("asperity_density_per_m2", "1e308"),
    ] {
        let text: Vec<String> = base
            .lines()
            .map(|l| {
                if l.starts_with(&format!("{key} = ")) {
                    format!("{key} = {value}")
                } else {
                    l.to_string()
                }
            })
            .collect();
        let scene = Scene::from_toml_str(&text.join("\n")).unwrap();
        let (lo, hi) = scene.table_range();
        for t in scene.interface_terms().unwrap() {
            for d in [lo, 0.5 * (lo + hi), hi] {
                if let Ok(TermForce { value: f, slope: s }) = t.force(d) {
                    assert!(
                        f.is_finite() && s.is_finite(),
                        "{key} = {value}: {} at {d}: {f} {s}",
                        t.name()
                    );
                }
            }
        }
        assert!(scene.build_interface().is_err(), "{key} = {value}");
    }
}
