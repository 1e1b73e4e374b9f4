//! Property tests of the interface forces over wide parameter ranges: finite everywhere, contact
//! non-negative and non-increasing in `d`, attraction non-positive, tables equal to direct
//! quadrature.
//!
//! Case counts are chosen for run time (each table build costs tens of milliseconds); the counts
//! are reported in `docs/validity.md`.

#[path = "common/seeded.rs"]
mod seeded;

use hdi_tribology::force::TermForce;
use hdi_tribology::force::{
    Electrostatic, Footprint, GapReference, GreenwoodWilliamson, InterfaceForces, InterfaceTerm,
    Intermolecular,
};
use hdi_tribology::quadrature::TableOptions;
use hdi_tribology::surface::{Gaussian, GaussianHeights, PeakDistribution, RiceMaxima, Rician};
use proptest::prelude::*;
use std::sync::Arc;

/// A log-uniform value in [10^lo, 10^hi].
fn log_range(lo: f64, hi: f64) -> impl Strategy<Value = f64> + Clone {
    (lo..hi).prop_map(|e: f64| 10f64.powf(e))
}

fn peaks() -> impl Strategy<Value = Arc<dyn PeakDistribution>> {
    let s = log_range(-11.0, -8.3); // 0.01 nm … 5 nm
    prop_oneof![
        (s.clone(), -1.0..1.0f64).prop_map(|(s, m)| {
            Arc::new(Gaussian::new(m * s, s).unwrap()) as Arc<dyn PeakDistribution>
        }),
        (s.clone(), 0.05..1.0f64).prop_map(|(s, e)| {
            Arc::new(RiceMaxima::new(s, e).unwrap()) as Arc<dyn PeakDistribution>
        }),
        (s, 0.0..3.0f64).prop_map(
            |(s, nu)| Arc::new(Rician::new(nu * s, s).unwrap()) as Arc<dyn PeakDistribution>
        ),
    ]
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

proptest! {
    #![proptest_config(seeded::config(256))]

    /// Greenwood–Williamson contact: finite, ≥ 0, slope ≤ 0, non-increasing in d, area ≥ 0,
    /// from far outside the peaks down to deep interference (−10 σ).
    #[test]
    fn contact_is_finite_non_negative_and_non_increasing(
        e in log_range(9.0, 12.0),
        r in log_range(-9.0, -5.0),
        eta in log_range(12.0, 16.0),
        peaks in peaks(),
        fp in footprint(),
        u in proptest::collection::vec(-10.0..12.0f64, 2..8),
    ) {
        let s = peaks.std_dev();
        let gw = GreenwoodWilliamson::new(e, r, eta, peaks.clone(), fp, GapReference::Bulge).unwrap();
        let mut ds: Vec<f64> = u.iter().map(|x| peaks.mean() + x * s).collect();
        ds.sort_by(f64::total_cmp);
        let mut prev: Option<f64> = None;
        for &d in &ds {
            let TermForce { value: f, slope } = gw.force(d).unwrap();
            let a = gw.real_contact_area(d).unwrap();
            prop_assert!(f.is_finite() && slope.is_finite() && a.is_finite(), "d = {d}: {f} {slope} {a}");
            prop_assert!(f >= 0.0 && slope <= 0.0 && a >= 0.0, "d = {d}: {f} {slope} {a}");
            if let Some(p) = prev {
                // Non-increasing up to rounding of the partial moments (a few ulps of the larger).
                prop_assert!(f <= p * (1.0 + 1e-12) + 1e-300, "F({d}) = {f} > {p}");
            }
            prev = Some(f);
        }
    }

    /// Electrostatic force per V² ≤ 0 and intermolecular force ≤ 0 for every d when the cutoff
    /// is the zero of the 3–9 law (only its attractive side is averaged); all finite, also for
    /// σ = 0 and below the cutoff.
    #[test]
    fn attraction_is_non_positive_and_finite(
        a in log_range(-21.0, -18.0),
        b in log_range(-78.0, -74.0),
        sigma in prop_oneof![Just(0.0), log_range(-11.0, -8.3)],
        td in prop_oneof![Just(0.0), log_range(-10.0, -8.0)],
        fp in footprint(),
        u in proptest::collection::vec(-5.0..30.0f64, 1..6),
    ) {
        let heights = GaussianHeights::new(sigma).unwrap();
        let lj = Intermolecular::new(a, b, None, heights, fp, GapReference::Bulge).unwrap();
        let hc = lj.averaged().cutoff();
        let es = Electrostatic::new(td, hc, heights, fp, GapReference::Bulge).unwrap();
        let scale = sigma.max(hc);
        for x in u {
            let d = hc + x * scale;
            let TermForce { value: fm, slope: sm } = lj.force(d).unwrap();
            let TermForce { value: fe, slope: se } = es.force(d).unwrap();
            prop_assert!(fm.is_finite() && sm.is_finite(), "LJ at {d}: {fm} {sm}");
            prop_assert!(fe.is_finite() && se.is_finite(), "ES at {d}: {fe} {se}");
            prop_assert!(fm <= 0.0, "LJ at {d} = {fm} > 0");
            prop_assert!(fe <= 0.0, "ES at {d} = {fe} > 0");
        }
    }
}

proptest! {
    // Each case tabulates three terms (about 0.05–0.3 s): few cases.
    #![proptest_config(seeded::config(32))]

    /// The merged tables agree with direct quadrature to the table tolerance, relative to the
    /// largest term magnitude at that gap (terms of opposite sign cancel in the sum, so the
    /// accuracy of the sum is that of its largest part).
    #[test]
    fn tables_agree_with_direct_quadrature(
        a in log_range(-21.0, -18.0),
        e in log_range(10.0, 12.0),
        eta in log_range(13.0, 16.0),
        sigma in log_range(-10.5, -8.7),
        u in proptest::collection::vec(0.0..1.0f64, 8),
    ) {
        let heights = GaussianHeights::new(sigma).unwrap();
        let fp = Footprint::Paraboloid { radius_of_curvature_m: 0.02, max_radius_m: None };
        let peaks: Arc<dyn PeakDistribution> = Arc::new(RiceMaxima::new(sigma, 0.7).unwrap());
        let lj = Intermolecular::new(a, 1e-76, None, heights, fp, GapReference::Bulge).unwrap();
        let hc = lj.averaged().cutoff();
        let es = Electrostatic::new(0.0, hc, heights, fp, GapReference::Bulge).unwrap();
        let gw = GreenwoodWilliamson::new(e, 1e-7, eta, peaks, fp, GapReference::Bulge).unwrap();
        let terms: Vec<Box<dyn InterfaceTerm>> = vec![Box::new(lj), Box::new(es), Box::new(gw)];
        let direct: Vec<Box<dyn InterfaceTerm>> = {
            let h = GaussianHeights::new(sigma).unwrap();
            let p: Arc<dyn PeakDistribution> = Arc::new(RiceMaxima::new(sigma, 0.7).unwrap());
            vec![
                Box::new(Intermolecular::new(a, 1e-76, None, h, fp, GapReference::Bulge).unwrap()),
                Box::new(Electrostatic::new(0.0, hc, h, fp, GapReference::Bulge).unwrap()),
                Box::new(GreenwoodWilliamson::new(e, 1e-7, eta, p, fp, GapReference::Bulge).unwrap()),
            ]
        };
        let range = (-5.0 * sigma, 3e-8);
        let opts = TableOptions::default();
        let forces = InterfaceForces::build(terms, range, &opts).unwrap();
        for x in u {
            let d = range.0 + x * (range.1 - range.0);
            let g = hdi_tribology::force::Gaps::same(d);
            let parts: Vec<f64> = direct.iter().map(|t| t.force(d).unwrap().value).collect();
            let exact_static = parts[0] + parts[2];
            let biggest = parts[0].abs().max(parts[2].abs());
            let tab = forces.static_part(g).value;
            // 1e-9 table tolerance (plus its absolute floor), ×10 for the sum of two tables.
            prop_assert!((tab - exact_static).abs() <= 1e-8 * biggest + 1e-15,
                "static at {d}: table {tab} direct {exact_static}");
            let tab_e = forces.per_volt2_part(g).value;
            prop_assert!((tab_e - parts[1]).abs() <= 1e-8 * parts[1].abs() + 1e-15,
                "electrostatic at {d}: table {tab_e} direct {}", parts[1]);
            let tab_c = forces.contact(g).value;
            prop_assert!((tab_c - parts[2]).abs() <= 1e-8 * parts[2].abs() + 1e-15,
                "contact at {d}: table {tab_c} direct {}", parts[2]);
        }
    }
}
