//! Textbook limits of the interface terms (MODEL.md 3.3) and their derivatives.

use std::f64::consts::PI;
use std::sync::Arc;

use hdi_tribology::force::TermForce;
use hdi_tribology::force::{
    composite_modulus, lj_zero, Electrostatic, Footprint, GapReference, GreenwoodWilliamson,
    InterfaceTerm, Intermolecular,
};
use hdi_tribology::quadrature::{integrate_tanh_sinh, QuadOptions};
use hdi_tribology::surface::{Gaussian, GaussianHeights};
use hdi_tribology::units::EPSILON_0;

const A: f64 = 1e-19;
const B: f64 = 1e-76;
const RC: f64 = 0.02;

fn sphere() -> Footprint {
    Footprint::Paraboloid {
        radius_of_curvature_m: RC,
        max_radius_m: None,
    }
}

fn smooth() -> GaussianHeights {
    GaussianHeights::new(0.0).unwrap()
}

fn rough(s: f64) -> GaussianHeights {
    GaussianHeights::new(s).unwrap()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Tanh–sinh at 1e-13: an independent rule to compare the Gauss–Kronrod based terms with.
fn ts(f: impl FnMut(f64) -> f64, a: f64, b: f64) -> f64 {
    let opts = QuadOptions {
        abs_tol: 0.0,
        rel_tol: 1e-13,
        max_intervals: 4000,
    };
    integrate_tanh_sinh(f, a, b, &opts).unwrap().value
}

fn gauss(z: f64, s: f64) -> f64 {
    (-0.5 * (z / s).powi(2)).exp() / (s * (2.0 * PI).sqrt())
}

fn lj_p(h: f64) -> f64 {
    -A / (6.0 * PI * h.powi(3)) + B / (45.0 * PI * h.powi(9))
}

#[test]
fn smooth_sphere_hamaker_matches_derjaguin_closed_form() {
    let t = Intermolecular::new(A, B, None, smooth(), sphere(), GapReference::Bulge).unwrap();
    for d in [0.3e-9, 0.5e-9, 1e-9, 3e-9, 10e-9, 100e-9] {
        let TermForce {
            value: f,
            slope: df,
        } = t.force(d).unwrap();
        let exact = -A * RC / (6.0 * d * d) + B * RC / (180.0 * d.powi(8));
        let slope = A * RC / (3.0 * d.powi(3)) - 8.0 * B * RC / (180.0 * d.powi(9));
        // closed forms evaluated two ways: rounding only
        assert!(rel(f, exact) < 1e-13, "d = {d}: {f} vs {exact}");
        assert!(rel(df, slope) < 1e-13, "d = {d}: {df} vs {slope}");
    }
}

#[test]
fn smooth_sphere_electrostatics_matches_closed_form_with_and_without_dielectric() {
    for td in [0.0, 1e-9] {
        let t = Electrostatic::new(td, 2e-10, smooth(), sphere(), GapReference::Bulge).unwrap();
        for d in [0.5e-9, 2e-9, 20e-9] {
            let TermForce {
                value: f,
                slope: df,
            } = t.force(d).unwrap();
            let exact = -PI * RC * EPSILON_0 / (d + td);
            let slope = PI * RC * EPSILON_0 / (d + td).powi(2);
            assert!(
                rel(f, exact) < 1e-13 && rel(df, slope) < 1e-13,
                "t_d = {td}, d = {d}"
            );
        }
    }
}

#[test]
fn flat_plates_give_pressure_times_area() {
    let area = 1e-8;
    let plate = Footprint::Flat { area_m2: area };
    let lj = Intermolecular::new(A, B, None, smooth(), plate, GapReference::Bulge).unwrap();
    let el = Electrostatic::new(0.0, 2e-10, smooth(), plate, GapReference::Pad).unwrap();
    for d in [0.4e-9, 1e-9, 5e-9] {
        assert!(rel(lj.force(d).unwrap().value, area * lj_p(d)) < 1e-14);
        let e = -EPSILON_0 * area / (2.0 * d * d);
        assert!(rel(el.force(d).unwrap().value, e) < 1e-14);
    }
    // Below the cutoff a smooth plate has no non-contact points: no force.
    assert_eq!(lj.force(1e-10).unwrap().value, 0.0);
}

#[test]
fn lennard_jones_pressure_vanishes_at_h_e() {
    let he = lj_zero(A, B);
    assert!(rel(he, (2.0 * B / (15.0 * A)).powf(1.0 / 6.0)) < 1e-15);
    let plate = Footprint::Flat { area_m2: 1.0 };
    let lj =
        Intermolecular::new(A, B, Some(0.5 * he), smooth(), plate, GapReference::Bulge).unwrap();
    let TermForce {
        value: f,
        slope: df,
    } = lj.force(he).unwrap();
    // each of the two parts is ~4e8 Pa; the sum cancels to rounding
    assert!(
        f.abs() < 1e-15 * A / (6.0 * PI * he.powi(3)) * 8.0,
        "p(h_e) = {f}"
    );
    assert!(
        df < 0.0,
        "repulsion decreases through h_e, so the force rises as d falls"
    );
    assert!(lj.force(0.9 * he).unwrap().value > 0.0 && lj.force(1.1 * he).unwrap().value < 0.0);
}

#[test]
fn small_roughness_converges_quadratically_to_the_smooth_sphere() {
    let d = 2e-9;
    let f0 = Intermolecular::new(A, B, None, smooth(), sphere(), GapReference::Bulge)
        .unwrap()
        .force(d)
        .unwrap()
        .value;
    let diff = |s: f64| {
        Intermolecular::new(A, B, None, rough(s), sphere(), GapReference::Bulge)
            .unwrap()
            .force(d)
            .unwrap()
            .value
            - f0
    };
    // F(σ) = F0 + σ² F0''/2 + O(σ⁴): with F0'' = −A Rc/d⁴ (leading part) the correction is
    // checked in size (to the O(σ²/d²) ≈ 5e-4 next term) and in its order, at two σ.
    let (e1, e2) = (diff(2e-11), diff(4e-11));
    let f0pp = -A * RC / d.powi(4) + 72.0 * B * RC / (180.0 * d.powi(10));
    assert!(
        rel(e1, 0.5 * 4e-22 * f0pp) < 1e-3,
        "{e1} vs {}",
        0.5 * 4e-22 * f0pp
    );
    assert!((e2 / e1 - 4.0).abs() < 1e-2, "ratio {}", e2 / e1);
    // and a tiny σ is indistinguishable from zero
    // (the two quadratures behind F agree to their 1e-12 tolerance)
    assert!(rel(f0 + diff(1e-15), f0) < 1e-11);
}

#[test]
fn rough_flat_terms_match_an_independent_tanh_sinh_integral() {
    let s = 7e-10;
    let he = lj_zero(A, B);
    let area = 1e-8;
    let plate = Footprint::Flat { area_m2: area };
    let lj = Intermolecular::new(A, B, None, rough(s), plate, GapReference::Bulge).unwrap();
    let el = Electrostatic::new(5e-10, he, rough(s), plate, GapReference::Bulge).unwrap();
    for d in [-1e-9, 0.0, 0.3e-9, 1e-9, 3e-9, 10e-9] {
        let lo = -40.0 * s;
        let hi = (d - he).min(40.0 * s);
        let m = area * ts(|z| lj_p(d - z) * gauss(z, s), lo, hi);
        let e = area
            * ts(
                |z| -EPSILON_0 / (2.0 * (d - z + 5e-10).powi(2)) * gauss(z, s),
                lo,
                hi,
            );
        // both rules are asked for 1e-12..1e-13; 1e-9 leaves room for the two error estimates
        assert!(rel(lj.force(d).unwrap().value, m) < 1e-9, "LJ d = {d}");
        assert!(rel(el.force(d).unwrap().value, e) < 1e-9, "el d = {d}");
    }
}

#[test]
fn gw_with_gaussian_peaks_matches_independent_quadrature() {
    let (mean, sd) = (3e-10, 8e-10);
    let (e, r, eta) = (1e11, 1e-7, 1.5e14);
    let area = 1e-8;
    let peaks = Arc::new(Gaussian::new(mean, sd).unwrap());
    let flat = GreenwoodWilliamson::new(
        e,
        r,
        eta,
        peaks.clone(),
        Footprint::Flat { area_m2: area },
        GapReference::Bulge,
    )
    .unwrap();
    let rmax = 2e-5;
    let cap = GreenwoodWilliamson::new(
        e,
        r,
        eta,
        peaks,
        Footprint::Paraboloid {
            radius_of_curvature_m: RC,
            max_radius_m: Some(rmax),
        },
        GapReference::Bulge,
    )
    .unwrap();
    let pdf = |z: f64| gauss(z - mean, sd);
    let top = mean + 40.0 * sd;
    let k = 4.0 / 3.0 * e * r.sqrt() * eta;
    let delta = rmax * rmax / (2.0 * RC);
    for d in [-1e-9, 0.0, 1e-9, 3e-9] {
        let pc = |s: f64| k * ts(|z| (z - s).powf(1.5) * pdf(z), s, top);
        let ar = |s: f64| PI * r * eta * ts(|z| (z - s) * pdf(z), s, top);
        assert!(
            rel(flat.force(d).unwrap().value, area * pc(d)) < 1e-9,
            "flat d = {d}"
        );
        assert!(
            rel(flat.real_contact_area(d).unwrap(), area * ar(d)) < 1e-9,
            "{} vs {}",
            flat.real_contact_area(d).unwrap(),
            area * ar(d)
        );
        // literal Derjaguin double integral over the truncated paraboloid
        let upper = (d + delta).min(top);
        let f = 2.0 * PI * RC * ts(pc, d, upper);
        let a = 2.0 * PI * RC * ts(ar, d, upper);
        assert!(rel(cap.force(d).unwrap().value, f) < 1e-8, "cap d = {d}");
        assert!(
            rel(cap.real_contact_area(d).unwrap(), a) < 1e-8,
            "cap area d = {d}"
        );
    }
}

/// Every term's derivative against a central finite difference of its own force.
#[test]
fn derivatives_match_finite_differences() {
    let s = 7e-10;
    let peaks = Arc::new(Gaussian::new(0.0, 6e-10).unwrap());
    let cap = Footprint::Paraboloid {
        radius_of_curvature_m: RC,
        max_radius_m: Some(3e-5),
    };
    let plate = Footprint::Flat { area_m2: 1e-8 };
    let terms: Vec<Box<dyn InterfaceTerm>> = vec![
        Box::new(Intermolecular::new(A, B, None, rough(s), sphere(), GapReference::Bulge).unwrap()),
        Box::new(Intermolecular::new(A, B, None, rough(s), plate, GapReference::Bulge).unwrap()),
        Box::new(Electrostatic::new(1e-9, 2e-10, rough(s), cap, GapReference::Bulge).unwrap()),
        Box::new(Electrostatic::new(0.0, 2e-10, rough(s), plate, GapReference::Bulge).unwrap()),
        Box::new(
            GreenwoodWilliamson::new(1e11, 1e-7, 1.5e14, peaks.clone(), cap, GapReference::Bulge)
                .unwrap(),
        ),
        Box::new(
            GreenwoodWilliamson::new(1e11, 1e-7, 1.5e14, peaks, plate, GapReference::Bulge)
                .unwrap(),
        ),
    ];
    for t in &terms {
        for d in [-5e-10, 3e-10, 1e-9, 4e-9] {
            let h = 1e-13;
            let TermForce {
                value: _,
                slope: df,
            } = t.force(d).unwrap();
            let fd = (t.force(d + h).unwrap().value - t.force(d - h).unwrap().value) / (2.0 * h);
            // step 1e-13 m against features of ~1e-10 m: truncation ~1e-6, quadrature noise
            // 1e-12 relative / 1e-3 step ratio ~1e-9
            assert!(
                (df - fd).abs() <= 1e-5 * df.abs().max(fd.abs()) + 1e-30,
                "{} at {d}: {df} vs {fd}",
                t.name()
            );
            if t.has_contact_area() {
                let (_, da) = t.real_contact_area_and_slope(d).unwrap();
                let fa = (t.real_contact_area(d + h).unwrap()
                    - t.real_contact_area(d - h).unwrap())
                    / (2.0 * h);
                assert!(
                    (da - fa).abs() <= 1e-5 * da.abs() + 1e-40,
                    "area slope {da} vs {fa}"
                );
            }
        }
    }
}

#[test]
fn composite_modulus_of_one_rigid_like_body_is_plane_strain_modulus() {
    let e = composite_modulus(1e11, 0.3, 1e30, 0.3).unwrap();
    assert!(rel(e, 1e11 / (1.0 - 0.09)) < 1e-12);
    assert!(composite_modulus(-1.0, 0.3, 1e11, 0.3).is_err());
    assert!(composite_modulus(1e11, 0.7, 1e11, 0.3).is_err());
}

/// A footprint much shallower than σ (r_max = 1 µm: Δ = 25 pm against σ = 0.7 nm) against the
/// literal Derjaguin double integral.
#[test]
fn thin_paraboloid_band_matches_the_literal_double_integral() {
    let s = 7e-10;
    let he = lj_zero(A, B);
    let rmax = 1e-6;
    let fp = Footprint::Paraboloid {
        radius_of_curvature_m: RC,
        max_radius_m: Some(rmax),
    };
    let t = Intermolecular::new(A, B, None, rough(s), fp, GapReference::Bulge).unwrap();
    let delta = rmax * rmax / (2.0 * RC);
    let pbar = |x: f64| {
        ts(
            |z| lj_p(x - z) * gauss(z, s),
            -40.0 * s,
            (x - he).min(40.0 * s),
        )
    };
    for d in [-5e-10, 3e-10, 1e-9, 3e-9] {
        let f = 2.0 * PI * RC * ts(pbar, d, d + delta);
        // nested tanh-sinh at 1e-13 each; Gauss–Legendre exact to (Δ/2σ)^16
        assert!(
            rel(t.force(d).unwrap().value, f) < 1e-9,
            "d = {d}: {} vs {f}",
            t.force(d).unwrap().value
        );
    }
}
