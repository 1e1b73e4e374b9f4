//! The smooth limit σ → 0, where the roughness averages become singular (the Gaussian weight
//! tends to a delta function): the averaged forces must converge to the smooth closed forms, with
//! the error shrinking like σ², down to σ far below one ulp of the gap — never blow up.

use hdi_tribology::force::TermForce;
use hdi_tribology::force::{
    Electrostatic, Footprint, GapReference, GreenwoodWilliamson, InterfaceTerm, Intermolecular,
};
use hdi_tribology::surface::{Gaussian, GaussianHeights, PeakDistribution};
use hdi_tribology::units::EPSILON_0;
use std::sync::Arc;

const A: f64 = 1e-19;
const B: f64 = 1e-76;
const RC: f64 = 0.02;

fn sphere() -> Footprint {
    Footprint::Paraboloid {
        radius_of_curvature_m: RC,
        max_radius_m: None,
    }
}

fn flat() -> Footprint {
    Footprint::Flat { area_m2: 1e-8 }
}

/// Smooth closed forms (MODEL.md §3.3): sphere `−A Rc/(6d²) + B Rc/(180 d⁸)`, `−π Rc ε₀/d` per V²;
/// flat `area·p(d)`.
fn smooth_lj(fp: Footprint, d: f64) -> f64 {
    match fp {
        Footprint::Paraboloid { .. } => -A * RC / (6.0 * d * d) + B * RC / (180.0 * d.powi(8)),
        Footprint::Flat { area_m2 } => {
            area_m2
                * (-A / (6.0 * std::f64::consts::PI * d.powi(3))
                    + B / (45.0 * std::f64::consts::PI * d.powi(9)))
        }
    }
}

fn smooth_es(fp: Footprint, d: f64) -> f64 {
    match fp {
        Footprint::Paraboloid { .. } => -std::f64::consts::PI * RC * EPSILON_0 / d,
        Footprint::Flat { area_m2 } => -area_m2 * EPSILON_0 / (2.0 * d * d),
    }
}

const SIGMAS: [f64; 9] = [
    1e-10, 3e-11, 1e-11, 1e-12, 1e-13, 1e-15, 1e-18, 1e-24, 1e-40,
];

#[test]
fn non_contact_terms_converge_to_the_smooth_closed_forms() {
    let hc = hdi_tribology::force::lj_zero(A, B);
    for fp in [sphere(), flat()] {
        for sigma in SIGMAS {
            let h = GaussianHeights::new(sigma).unwrap();
            let lj = Intermolecular::new(A, B, None, h, fp, GapReference::Bulge).unwrap();
            let es = Electrostatic::new(0.0, hc, h, fp, GapReference::Bulge).unwrap();
            for d in [0.5e-9, 1e-9, 2e-9, 5e-9, 2e-8] {
                let TermForce { value: f, slope: s } = lj.force(d).unwrap();
                let TermForce {
                    value: fe,
                    slope: se,
                } = es.force(d).unwrap();
                assert!(f.is_finite() && s.is_finite() && fe.is_finite() && se.is_finite());
                // The expansion below needs σ small against the distance to the cutoff.
                if sigma > 0.05 * (d - hc) {
                    continue;
                }
                // Leading correction of a Gaussian average: p''σ²/2, i.e. (n(n+1)/2)(σ/d)² for
                // p ∝ d^{-n} (n ≤ 9); twice that bounds the whole series for σ/d ≤ 0.05. The
                // cutoff's share is below exp(−((d − h_c)/σ)²/2) < 1e-80 here. 1e-11: quadrature
                // tolerance 1e-12 with headroom.
                let tol = |n: f64| n * (n + 1.0) * (sigma / d).powi(2) + 1e-11;
                let want = smooth_lj(fp, d);
                let scale = (A * RC / (6.0 * d * d)).max(want.abs());
                assert!(
                    (f - want).abs() <= tol(9.0) * scale,
                    "LJ {fp:?} σ = {sigma:e}, d = {d:e}: {f:e} vs {want:e}"
                );
                let want = smooth_es(fp, d);
                assert!(
                    (fe - want).abs() <= tol(2.0) * want.abs(),
                    "ES {fp:?} σ = {sigma:e}, d = {d:e}: {fe:e} vs {want:e}"
                );
            }
        }
    }
}

/// Greenwood–Williamson with every peak at one height is `(4/3)E*√R η_s (−d)^{3/2}` per area
/// (flat) and `2π Rc (4/3)E*√R η_s · 0.4 (−d)^{5/2}` (sphere) below it, zero above: Gaussian peaks
/// of vanishing spread converge to it.
#[test]
fn contact_converges_to_the_single_height_law() {
    let (e, r, eta) = (1e11_f64, 1e-7_f64, 1.5e14_f64);
    let k = 4.0 / 3.0 * e * r.sqrt() * eta;
    for sigma in SIGMAS {
        let peaks: Arc<dyn PeakDistribution> = Arc::new(Gaussian::new(0.0, sigma).unwrap());
        for fp in [sphere(), flat()] {
            let gw = GreenwoodWilliamson::new(e, r, eta, peaks.clone(), fp, GapReference::Bulge)
                .unwrap();
            for d in [-2e-9, -5e-10, -1e-10, 1e-10, 1e-9] {
                let TermForce { value: f, slope: s } = gw.force(d).unwrap();
                assert!(f.is_finite() && s.is_finite() && f >= 0.0);
                let x = (-d).max(0.0);
                let want = match fp {
                    Footprint::Flat { area_m2 } => area_m2 * k * x.powf(1.5),
                    Footprint::Paraboloid { .. } => {
                        2.0 * std::f64::consts::PI * RC * k * 0.4 * x.powf(2.5)
                    }
                };
                // Relative error of the moment (z − d)^p averaged over N(0, σ²): p(p−1)/2 (σ/d)²
                // (p ≤ 2.5); above the peaks the force is a Gaussian tail, far below 1e-12 of the
                // force scale at 1 nm interference once σ ≤ 1e-10·(1/13).
                let scale = match fp {
                    Footprint::Flat { area_m2 } => area_m2 * k * 1e-9f64.powf(1.5),
                    Footprint::Paraboloid { .. } => {
                        2.0 * std::f64::consts::PI * RC * k * 0.4 * 1e-9f64.powf(2.5)
                    }
                };
                let tol = if d < 0.0 {
                    2.0 * (sigma / d).powi(2) * want + 1e-12 * scale
                } else {
                    // A Gaussian tail beyond d/σ ≥ 1 standard deviations, bounded by the
                    // tail of the moment at the largest σ here.
                    scale * (-(d / sigma).powi(2) / 2.0).exp() * 10.0 + 1e-12 * scale
                };
                assert!(
                    (f - want).abs() <= tol,
                    "GW {fp:?} σ = {sigma:e}, d = {d:e}: {f:e} vs {want:e}"
                );
            }
        }
    }
}
