//! Properties of the peak laws and the quadrature over wide parameter ranges.

#[path = "common/seeded.rs"]
mod seeded;

use hdi_tribology::quadrature::{integrate, QuadOptions, Table, TableOptions};
use hdi_tribology::surface::{Gaussian, PeakDistribution, RiceMaxima, Rician};
use proptest::prelude::*;

fn law(kind: u8, scale: f64, shape: f64) -> Box<dyn PeakDistribution> {
    match kind % 3 {
        0 => Box::new(Gaussian::new(shape * scale, scale).unwrap()),
        1 => Box::new(RiceMaxima::new(scale, shape.clamp(1e-3, 1.0)).unwrap()),
        _ => Box::new(Rician::new(shape.abs() * 5.0 * scale, scale).unwrap()),
    }
}

proptest! {
    #![proptest_config(seeded::config(64))]

    /// Partial moments are finite, non-negative, and non-increasing in d.
    #[test]
    fn moments_finite_and_monotone(
        kind in 0u8..3,
        log_scale in -12.0f64..-6.0,
        shape in 0.0f64..1.0,
        k in -30.0f64..30.0,
        p in 0.0f64..4.0,
    ) {
        let scale = 10f64.powf(log_scale);
        let law = law(kind, scale, shape);
        let d = law.mean() + k * law.std_dev();
        let m = law.partial_moment(d, p);
        prop_assert!(m.is_finite() && m >= 0.0, "{law:?} d={d:e} p={p}: {m}");
        let step = 0.05 * law.std_dev();
        let m2 = law.partial_moment(d + step, p);
        // Non-increasing up to the promised 1e-12 relative accuracy.
        prop_assert!(m2 <= m * (1.0 + 2e-12) + 1e-300, "{law:?} d={d:e} p={p}: {m:e} then {m2:e}");
    }

    /// The survival function is in [0, 1] and decreasing; M_p ≤ (max(z) − d)^p-type
    /// bounds are replaced by Jensen: M_p ≥ S·(M_1/S)^p for p ≥ 1.
    #[test]
    fn survival_and_jensen(
        kind in 0u8..3,
        shape in 0.0f64..1.0,
        k in -6.0f64..6.0,
        p in 1.0f64..3.5,
    ) {
        let law = law(kind, 1e-9, shape);
        let d = law.mean() + k * law.std_dev();
        let s = law.partial_moment(d, 0.0);
        prop_assert!((0.0..=1.0 + 1e-15).contains(&s));
        let m1 = law.partial_moment(d, 1.0);
        let mp = law.partial_moment(d, p);
        if s > 1e-200 {
            let jensen = s * (m1 / s).powf(p);
            prop_assert!(mp >= jensen * (1.0 - 1e-11), "{law:?}: {mp:e} < {jensen:e}");
        }
    }

    /// Gauss–Kronrod integrates random cubics exactly and Gaussians of any width.
    #[test]
    fn integrate_cubics_and_gaussians(
        c in proptest::array::uniform4(-10.0f64..10.0),
        a in -5.0f64..0.0,
        b in 0.1f64..5.0,
        log_w in -12.0f64..3.0,
    ) {
        let o = QuadOptions::default();
        let f = |x: f64| c[0] + x * (c[1] + x * (c[2] + x * c[3]));
        let prim = |x: f64| x * (c[0] + x * (c[1] / 2.0 + x * (c[2] / 3.0 + x * c[3] / 4.0)));
        let est = integrate(f, a, b, &o).unwrap();
        let exact = prim(b) - prim(a);
        let scale = [c[0], c[1], c[2], c[3]].iter().map(|v| v.abs()).sum::<f64>() * 125.0 * 5.0;
        prop_assert!((est.value - exact).abs() <= 1e-13 * scale);
        let w = 10f64.powf(log_w);
        let g = |x: f64| (-(x / w).powi(2) / 2.0).exp();
        let est = integrate(g, -40.0 * w, 40.0 * w, &o).unwrap();
        let exact = w * (2.0 * std::f64::consts::PI).sqrt();
        prop_assert!((est.value / exact - 1.0).abs() < 1e-12);
    }

    /// Tables reproduce cubics exactly (up to rounding) on any range.
    #[test]
    fn tables_reproduce_cubics(
        c in proptest::array::uniform4(-3.0f64..3.0),
        lo in -10.0f64..0.0,
        width in 0.01f64..20.0,
        x in 0.0f64..1.0,
    ) {
        let f = |t: f64| c[0] + t * (c[1] + t * (c[2] + t * c[3]));
        let df = |t: f64| c[1] + t * (2.0 * c[2] + t * 3.0 * c[3]);
        let hi = lo + width;
        let table = Table::build(|t| Ok((f(t), df(t))), lo, hi, &TableOptions::default()).unwrap();
        let t = lo + x * width;
        let (v, d) = table.eval(t).unwrap();
        let m = lo.abs().max(hi.abs()).max(1.0);
        let scale = [c[0], c[1], c[2], c[3]].iter().map(|v| v.abs()).sum::<f64>() * m.powi(3);
        prop_assert!((v - f(t)).abs() <= 1e-13 * scale, "{v} vs {}", f(t));
        prop_assert!((d - df(t)).abs() <= 1e-11 * scale / width.min(1.0));
    }
}
