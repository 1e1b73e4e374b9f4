//! Tables against direct quadrature over the whole range, for every merged table and term.

use std::sync::Arc;

use hdi_tribology::force::{
    Coupling, Electrostatic, Footprint, GapReference, Gaps, GreenwoodWilliamson, HotForces,
    InterfaceForces, InterfaceTerm, Intermolecular, OutsideTables, TermKind,
};
use hdi_tribology::quadrature::TableOptions;
use hdi_tribology::scene::Scene;
use hdi_tribology::surface::{Gaussian, GaussianHeights};

/// Deterministic points spread over [lo, hi] (a Weyl sequence: no clustering, no RNG crate).
fn points(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let g = 0.618_033_988_749_894_9;
    (0..n)
        .map(|i| lo + (hi - lo) * ((0.5 + i as f64 * g) % 1.0))
        .collect()
}

struct Exact<'a>(&'a [Box<dyn InterfaceTerm>]);

impl Exact<'_> {
    fn sum(&self, d: f64, pick: impl Fn(&dyn InterfaceTerm) -> bool) -> (f64, f64) {
        self.0
            .iter()
            .filter(|t| pick(t.as_ref()))
            .map(|t| t.force(d).map(|f| (f.value, f.slope)).unwrap())
            .fold((0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1))
    }
    /// Σ|F_i| and Σ|F_i'| over the picked terms: the scale a merged table is accurate to.
    fn magnitude(&self, d: f64, pick: impl Fn(&dyn InterfaceTerm) -> bool) -> (f64, f64) {
        self.0
            .iter()
            .filter(|t| pick(t.as_ref()))
            .map(|t| t.force(d).map(|f| (f.value, f.slope)).unwrap())
            .fold((0.0, 0.0), |a, b| (a.0 + b.0.abs(), a.1 + b.1.abs()))
    }
    fn area(&self, d: f64) -> (f64, f64) {
        self.0
            .iter()
            .map(|t| t.real_contact_area_and_slope(d).unwrap())
            .fold((0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1))
    }
}

/// The acceptance bound: 1e-8 relative, or 1e-15 N where a force passes through zero.
/// For a merged table `scale` is Σ|F_i| (each term is held to the bound; their sum may cancel).
fn value_ok(table: f64, exact: f64, scale: f64, abs: f64) -> bool {
    (table - exact).abs() <= 1e-8 * scale.max(exact.abs()) + abs
}

/// Slopes are interpolated by the derivative of the Hermite cubic: one order of node spacing
/// less accurate than values. With spacing ~1e-2 of the local length scale, 1e-6 relative to the
/// largest of the local slope and value/scale (scale = 0.1 nm, the finest feature) is the bound.
fn slope_ok(table: f64, exact: f64, (value, slope): (f64, f64), abs: f64) -> bool {
    (table - exact).abs() <= 1e-6 * slope.max(exact.abs()).max(value / 1e-10) + abs / 1e-10
}

fn check_all(forces: &InterfaceForces, n: usize) {
    let (lo, hi) = forces.table_range();
    let exact = Exact(forces.terms());
    let mut worst = [0.0_f64; 4];
    for d in points(lo, hi, n) {
        let g = Gaps::same(d);
        let stat = |t: &dyn InterfaceTerm| t.coupling() == Coupling::Static;
        let volt = |t: &dyn InterfaceTerm| t.coupling() == Coupling::PerVoltSquared;
        let cont = |t: &dyn InterfaceTerm| t.kind() == TermKind::Contact;
        let cases = [
            (
                forces.static_part(g),
                exact.sum(d, stat),
                exact.magnitude(d, stat),
            ),
            (
                forces.per_volt2_part(g),
                exact.sum(d, volt),
                exact.magnitude(d, volt),
            ),
            (
                forces.contact(g),
                exact.sum(d, cont),
                exact.magnitude(d, cont),
            ),
        ];
        for (k, (tab, (v, s), mag)) in cases.into_iter().enumerate() {
            let abs = 2e-15; // up to two terms, 1e-15 N each
            assert!(
                value_ok(tab.value, v, mag.0, abs),
                "case {k} at d = {d}: table {} exact {v}",
                tab.value
            );
            assert!(
                slope_ok(tab.d_bulge, s, mag, abs),
                "case {k} slope at d = {d}: table {} exact {s}",
                tab.d_bulge
            );
            worst[k] = worst[k].max((tab.value - v).abs() / (mag.0 + abs / 1e-8));
            worst[3] = worst[3]
                .max((tab.d_bulge - s).abs() / (1e-6 * mag.1.max(mag.0 / 1e-10) + abs / 1e-10));
        }
        // the fused look-up, held to the same bounds
        let hot = forces.evaluate(g);
        let fused = [
            (
                hot.static_part,
                exact.sum(d, stat),
                exact.magnitude(d, stat),
            ),
            (hot.per_volt2, exact.sum(d, volt), exact.magnitude(d, volt)),
            (hot.contact, exact.sum(d, cont), exact.magnitude(d, cont)),
        ];
        for (k, (tab, (v, s), mag)) in fused.into_iter().enumerate() {
            let abs = 3e-15; // two tables in series, up to two terms each
            assert!(
                value_ok(tab.value, v, mag.0, abs),
                "fused {k} at d = {d}: {} vs {v}",
                tab.value
            );
            assert!(
                slope_ok(tab.d_bulge, s, mag, abs),
                "fused {k} slope at d = {d}: {} vs {s}",
                tab.d_bulge
            );
        }
        let (a, _) = exact.area(d);
        // contact-area tables: the same relative bound, absolute 1e-8 × 1e-16 m²
        assert!(
            value_ok(forces.real_contact_area(g), a, a, 1e-24),
            "area at d = {d}"
        );
        let b = forces.breakdown(g, 0.49);
        // per-kind tables, each held to the strict bound against its own term
        let kind = |k: TermKind| exact.sum(d, |t| t.kind() == k).0;
        for (got, want) in [
            (b.intermolecular, kind(TermKind::Intermolecular)),
            (b.contact, kind(TermKind::Contact)),
            (b.electrostatic_per_volt2, kind(TermKind::Electrostatic)),
        ] {
            assert!(
                value_ok(got, want, want, 1e-15),
                "per-kind table at d = {d}: {got} vs {want}"
            );
        }
        let total = exact.sum(d, stat).0 + 0.49 * exact.sum(d, volt).0;
        let scale = exact.magnitude(d, stat).0 + 0.49 * exact.magnitude(d, volt).0;
        assert!(
            value_ok(b.total, total, scale, 3e-15),
            "breakdown total at d = {d}"
        );
    }
    eprintln!("worst relative errors (static, per V², contact) and slope error / bound: {worst:?}");
}

#[test]
fn paper_scene_tables_match_direct_quadrature_over_the_whole_range() {
    let forces = Scene::paper().build_interface().unwrap();
    assert!(forces.has_contact() && forces.has_voltage_terms() && !forces.uses_pad_gap());
    eprintln!(
        "paper scene: {} table nodes over {:?}",
        forces.table_nodes(),
        forces.table_range()
    );
    check_all(&forces, 400);
}

#[test]
fn mixed_footprints_and_gaps_tabulate_correctly() {
    let h = GaussianHeights::new(5e-10).unwrap();
    let peaks = Arc::new(Gaussian::new(2e-10, 6e-10).unwrap());
    let cap = Footprint::Paraboloid {
        radius_of_curvature_m: 0.02,
        max_radius_m: Some(2e-5),
    };
    let plate = Footprint::Flat { area_m2: 1e-8 };
    let terms: Vec<Box<dyn InterfaceTerm>> = vec![
        Box::new(Intermolecular::new(1e-19, 1e-76, None, h, cap, GapReference::Bulge).unwrap()),
        Box::new(Intermolecular::new(5e-20, 1e-76, None, h, plate, GapReference::Pad).unwrap()),
        Box::new(Electrostatic::new(1e-9, 2e-10, h, plate, GapReference::Pad).unwrap()),
        Box::new(Electrostatic::new(0.0, 2e-10, h, cap, GapReference::Bulge).unwrap()),
        Box::new(
            GreenwoodWilliamson::new(1e11, 1e-7, 1.5e14, peaks, cap, GapReference::Bulge).unwrap(),
        ),
    ];
    let forces = InterfaceForces::build(terms, (-3e-9, 20e-9), &TableOptions::default()).unwrap();
    assert!(forces.uses_pad_gap());
    let exact = Exact(forces.terms());
    for d in points(-3e-9, 20e-9, 150) {
        let g = Gaps {
            bulge: d,
            pad: d + 1e-9,
        };
        let st = forces.static_part(g);
        let pv = forces.per_volt2_part(g);
        let pick = |gap, c| move |t: &dyn InterfaceTerm| t.gap() == gap && t.coupling() == c;
        let both = |gap, c, x: f64| (exact.sum(x, pick(gap, c)), exact.magnitude(x, pick(gap, c)));
        let (sb, mb) = both(GapReference::Bulge, Coupling::Static, d);
        let (sp, mp) = both(GapReference::Pad, Coupling::Static, d + 1e-9);
        let (vb, nb) = both(GapReference::Bulge, Coupling::PerVoltSquared, d);
        let (vp, np) = both(GapReference::Pad, Coupling::PerVoltSquared, d + 1e-9);
        assert!(
            value_ok(st.value, sb.0 + sp.0, mb.0 + mp.0, 3e-15),
            "static at {d}"
        );
        assert!(
            value_ok(pv.value, vb.0 + vp.0, nb.0 + np.0, 2e-15),
            "per V² at {d}"
        );
        assert!(
            slope_ok(st.d_bulge, sb.1, mb, 2e-15) && slope_ok(st.d_pad, sp.1, mp, 1e-15),
            "static slopes at {d}"
        );
        assert!(
            slope_ok(pv.d_bulge, vb.1, nb, 1e-15) && slope_ok(pv.d_pad, vp.1, np, 1e-15),
            "per V² slopes at {d}"
        );
    }
}

#[test]
fn outside_the_range_the_exact_terms_are_used() {
    let forces = Scene::paper().build_interface().unwrap();
    let (lo, hi) = forces.table_range();
    let exact = Exact(forces.terms());
    for d in [lo - 1e-9, hi + 1e-9, 10.0 * hi] {
        let e = exact.sum(d, |t| t.coupling() == Coupling::Static);
        let t = forces.static_part(Gaps::same(d));
        assert_eq!((t.value, t.d_bulge), e, "no clamping at d = {d}");
    }
    assert!(forces.static_part(Gaps::same(f64::NAN)).value.is_nan());
}

#[test]
fn smooth_flat_electrostatics_jumps_at_the_cutoff_and_the_table_follows() {
    let hc = 3e-10;
    let plate = Footprint::Flat { area_m2: 1e-8 };
    let t = Electrostatic::new(
        0.0,
        hc,
        GaussianHeights::new(0.0).unwrap(),
        plate,
        GapReference::Bulge,
    )
    .unwrap();
    let forces =
        InterfaceForces::build(vec![Box::new(t)], (-1e-9, 5e-9), &TableOptions::default()).unwrap();
    let below = forces.per_volt2_part(Gaps::same(hc * (1.0 - 1e-9))).value;
    let at = forces.per_volt2_part(Gaps::same(hc)).value;
    let above = forces.per_volt2_part(Gaps::same(hc * (1.0 + 1e-9))).value;
    assert_eq!(below, 0.0);
    let p = -hdi_tribology::units::EPSILON_0 * 1e-8 / (2.0 * hc * hc);
    assert!((at - p).abs() < 1e-8 * p.abs() && (above - p).abs() < 1e-8 * p.abs());
}

#[test]
fn interface_forces_can_be_shared_across_threads_and_may_be_empty() {
    fn shareable<T: Send + Sync + Clone>() {}
    shareable::<InterfaceForces>();
    let none = InterfaceForces::build(Vec::new(), (-1e-9, 1e-8), &TableOptions::default()).unwrap();
    let g = Gaps::same(1e-9);
    assert_eq!(none.static_part(g).value, 0.0);
    assert_eq!(none.breakdown(g, 1.0).total, 0.0);
    assert!(!none.has_contact() && !none.has_voltage_terms() && !none.uses_pad_gap());
    assert!(InterfaceForces::build(Vec::new(), (1e-8, -1e-9), &TableOptions::default()).is_err());
}

#[test]
fn shipped_scenes_tables_match_direct_quadrature() {
    for name in [
        "flat_gaussian.toml",
        "dielectric.toml",
        "finite_radius.toml",
    ] {
        let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("scenes")
            .join(name);
        let forces = Scene::from_path(&path).unwrap().build_interface().unwrap();
        eprintln!("{name}: {} table nodes", forces.table_nodes());
        check_all(&forces, 150);
    }
}

/// The values alone (`values`, what a right-hand side reads) are the values of `evaluate` and
/// `real_contact_area`, bit for bit, with or without the fused table, inside the tables and in
/// the exact fallback outside them: the few-peak scene has kinked tables (no fused table), the
/// paper scene a fused one, the mixed scene terms on the pad gap.
#[test]
fn values_alone_equal_the_values_of_the_full_evaluation() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes");
    for name in ["paper.toml", "paper_bulge.toml", "finite_radius.toml"] {
        let scene = Scene::from_path(format!("{dir}/{name}")).unwrap();
        let forces = scene.build_interface().unwrap();
        let (lo, hi) = forces.table_range();
        for d in points(lo - 0.2 * (hi - lo), hi + 0.2 * (hi - lo), 400) {
            for volt2 in [0.0, 0.36] {
                let g = Gaps {
                    bulge: d,
                    pad: d + 2e-9,
                };
                let v = forces.values(g, volt2);
                let h = forces.evaluate(g);
                assert_eq!(
                    v.interface.to_bits(),
                    (h.static_part.value + volt2 * h.per_volt2.value).to_bits(),
                    "{name}: interface at {d:e}, V² = {volt2}"
                );
                assert_eq!(
                    v.contact.to_bits(),
                    h.contact.value.to_bits(),
                    "{name}: contact at {d:e}"
                );
                assert_eq!(
                    v.area.to_bits(),
                    forces.real_contact_area(g).to_bits(),
                    "{name}: area at {d:e}"
                );
            }
        }
    }
}

/// Forces that refuse the exact fallback ([`OutsideTables::Refused`]) are the same numbers
/// inside the tables, bit for bit, through every hot-path function, and NaN outside them, below
/// and above (the contact force too, which is clamped at zero only inside): fused tables (the
/// paper scene), kinked ones (the few-peak scene) and terms on the pad gap.
#[test]
fn refused_forces_are_the_tables_inside_and_nan_outside() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes");
    for name in ["paper.toml", "paper_bulge.toml", "finite_radius.toml"] {
        let exact = Scene::from_path(format!("{dir}/{name}"))
            .unwrap()
            .build_interface()
            .unwrap();
        assert_eq!(exact.outside_tables(), OutsideTables::Exact);
        let refused = exact.clone().with_outside_tables(OutsideTables::Refused);
        let (lo, hi) = exact.table_range();
        let bits = |h: HotForces| {
            [h.static_part, h.per_volt2, h.contact]
                .map(|e| [e.value, e.d_bulge, e.d_pad].map(f64::to_bits))
        };
        for d in points(lo, hi - 2e-9, 300) {
            let g = Gaps {
                bulge: d,
                pad: d + 2e-9,
            };
            assert_eq!(
                bits(refused.evaluate(g)),
                bits(exact.evaluate(g)),
                "{name} {d:e}"
            );
            let (a, b) = (refused.values(g, 0.36), exact.values(g, 0.36));
            assert_eq!(
                [a.interface, a.contact, a.area].map(f64::to_bits),
                [b.interface, b.contact, b.area].map(f64::to_bits),
                "{name} {d:e}"
            );
            assert_eq!(refused.breakdown(g, 0.36), exact.breakdown(g, 0.36));
        }
        for d in [lo - 1e-9, lo - 1e-6, hi + 1e-9, 1e3 * hi] {
            let g = Gaps::same(d);
            let (h, v) = (refused.evaluate(g), refused.values(g, 0.36));
            assert!(
                h.static_part.value.is_nan() && v.interface.is_nan(),
                "{name} {d:e}"
            );
            assert!(
                exact.evaluate(g).static_part.value.is_finite(),
                "{name} {d:e}"
            );
            assert!(refused.breakdown(g, 0.36).total.is_nan(), "{name} {d:e}");
        }
        // Below the tables, where the contact force is large, the refusal is not clamped away.
        let below = Gaps::same(lo - 1e-9);
        assert!(
            refused.contact(below).value.is_nan() && refused.values(below, 0.0).contact.is_nan()
        );
        assert!(exact.contact(below).value > 0.0);
    }
}
