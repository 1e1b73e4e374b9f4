//! Property tests over wide parameter ranges: finite values, signs, monotonicity.

#[path = "common/seeded.rs"]
mod seeded;

use std::sync::Arc;

use hdi_tribology::force::TermForce;
use hdi_tribology::force::{
    AirBearing, CubicBearing, Electrostatic, Footprint, GapReference, GreenwoodWilliamson,
    InterfaceTerm, Intermolecular, PowerLawBearing,
};
use hdi_tribology::surface::{Gaussian, GaussianHeights};
use proptest::prelude::*;

fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo.ln()..hi.ln()).prop_map(f64::exp)
}

fn footprint() -> impl Strategy<Value = Footprint> {
    prop_oneof![
        log_uniform(1e-10, 1e-6).prop_map(|a| Footprint::Flat { area_m2: a }),
        (
            log_uniform(1e-3, 1e-1),
            proptest::option::of(log_uniform(1e-6, 1e-3))
        )
            .prop_map(|(rc, r)| Footprint::Paraboloid {
                radius_of_curvature_m: rc,
                max_radius_m: r,
            }),
    ]
}

fn sigma() -> impl Strategy<Value = f64> {
    prop_oneof![Just(0.0), log_uniform(1e-12, 2e-9)]
}

proptest! {
    #![proptest_config(seeded::config(64))]

    /// With the default cutoff h_e every non-contacting point is attracted (p < 0 for h > h_e),
    /// so the averaged 3–9 force is attractive or zero at any separation, on any footprint.
    #[test]
    fn intermolecular_with_default_cutoff_never_repels(
        a in log_uniform(1e-21, 1e-18), b in log_uniform(1e-80, 1e-74),
        s in sigma(), fp in footprint(), d in -3e-9..5e-8f64,
    ) {
        let t = Intermolecular::new(a, b, None, GaussianHeights::new(s).unwrap(), fp, GapReference::Bulge).unwrap();
        let TermForce { value: f, slope: df } = t.force(d).unwrap();
        prop_assert!(f.is_finite() && df.is_finite());
        prop_assert!(f <= 0.0, "F = {f}");
    }

    /// On an untruncated paraboloid dF/dd = −2πRc p̄(d) ≥ 0: the electrostatic attraction
    /// weakens monotonically with the separation, and is never repulsive.
    #[test]
    fn electrostatic_on_a_sphere_is_attractive_and_weakens_with_distance(
        td in prop_oneof![Just(0.0), log_uniform(1e-11, 2e-9)], hc in log_uniform(1e-10, 5e-10),
        s in sigma(), rc in log_uniform(1e-3, 1e-1), d in -3e-9..5e-8f64, step in 1e-11..1e-9f64,
    ) {
        let fp = Footprint::Paraboloid { radius_of_curvature_m: rc, max_radius_m: None };
        let t = Electrostatic::new(td, hc, GaussianHeights::new(s).unwrap(), fp, GapReference::Bulge).unwrap();
        let TermForce { value: f, slope: df } = t.force(d).unwrap();
        let TermForce { value: g, slope: _ } = t.force(d + step).unwrap();
        prop_assert!(f < 0.0 && df >= 0.0 && df.is_finite());
        // allow for the quadrature tolerance (1e-12 relative) when the two values nearly agree
        prop_assert!(g >= f - 1e-11 * f.abs(), "F({d}) = {f}, F({}) = {g}", d + step);
    }

    /// Contact pushes, and pushes harder the closer the surfaces; the contact area behaves
    /// likewise.
    #[test]
    fn contact_is_repulsive_and_monotone(
        mean in -1e-9..1e-9f64, sd in log_uniform(1e-10, 2e-9), e in log_uniform(1e9, 1e12),
        r in log_uniform(1e-8, 1e-5), eta in log_uniform(1e12, 1e16), fp in footprint(),
        d in -5e-9..2e-8f64,
    ) {
        let peaks = Arc::new(Gaussian::new(mean, sd).unwrap());
        let t = GreenwoodWilliamson::new(e, r, eta, peaks, fp, GapReference::Bulge).unwrap();
        let TermForce { value: f, slope: df } = t.force(d).unwrap();
        let (a, da) = t.real_contact_area_and_slope(d).unwrap();
        prop_assert!(f.is_finite() && df.is_finite() && a.is_finite() && da.is_finite());
        prop_assert!(f >= 0.0 && df <= 0.0 && a >= 0.0 && da <= 0.0, "{f} {df} {a} {da}");
    }

    /// Air bearings restore: the force opposes the displacement and the stiffness is positive
    /// wherever the law is defined.
    #[test]
    fn air_bearings_restore(
        k in log_uniform(1e3, 1e7), k3 in log_uniform(1e10, 1e25), n in 0.5..6.0f64,
        h0 in log_uniform(1e-9, 1e-7), frac in -0.9..3.0f64,
    ) {
        let y = frac * h0;
        let cubic = CubicBearing::new(k, k3, 0.01).unwrap();
        let power = PowerLawBearing::new(k * h0 / n, n, h0, 0.01).unwrap();
        for ab in [&cubic as &dyn AirBearing, &power] {
            prop_assert!(ab.force(y, 0.0) * y <= 0.0 && ab.stiffness(y) > 0.0);
            prop_assert!(ab.force(y, 1.0) < ab.force(y, 0.0));
        }
    }
}
