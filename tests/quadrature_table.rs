//! Hermite tables against the exact functions they tabulate.

use hdi_tribology::quadrature::{QuadratureError, Table, TableOptions};
use hdi_tribology::surface::special::{norm_pdf, norm_sf};
use hdi_tribology::surface::Xoshiro256;
use hdi_tribology::{Error, Result};

type Exact = Box<dyn Fn(f64) -> (f64, f64)>;

/// (name, exact (value, derivative), lo, hi, options)
fn cases() -> Vec<(&'static str, Exact, f64, f64, TableOptions)> {
    let sigma = 1e-9;
    vec![
        (
            "sin on [0, 10]",
            Box::new(|x: f64| (x.sin(), x.cos())),
            0.0,
            10.0,
            TableOptions::default(),
        ),
        (
            // A contact-like force: 1e-2 N times a Gaussian survival, falling to
            // ~1e-35 N at the top of the range; the absolute tolerance takes over
            // for the tiny values.
            "contact-like tail",
            Box::new(move |d: f64| {
                (
                    1e-2 * norm_sf(d / sigma),
                    -1e-2 * norm_pdf(d / sigma) / sigma,
                )
            }),
            -5.0 * sigma,
            12.0 * sigma,
            TableOptions {
                rel_tol: 1e-9,
                abs_tol: 1e-30,
                max_nodes: 200_000,
            },
        ),
        (
            // Lennard-Jones 3-9 type pressure, changing sign at h = 1.
            "LJ 3-9 with a sign change",
            Box::new(|h: f64| {
                (
                    -1.0 / h.powi(3) + 1.0 / h.powi(9),
                    3.0 / h.powi(4) - 9.0 / h.powi(10),
                )
            }),
            0.7,
            20.0,
            TableOptions {
                rel_tol: 1e-9,
                abs_tol: 1e-14,
                max_nodes: 200_000,
            },
        ),
    ]
}

/// Largest |f| over [x − h, x + h] (sampled at its ends and centre), which covers
/// the interval holding x: the tolerance promised by the builder is relative to
/// the largest magnitude on the interval.
fn local_scale(f: &dyn Fn(f64) -> (f64, f64), x: f64, table: &Table) -> f64 {
    let h = table.spacing_at(x).unwrap();
    let (lo, hi) = table.range();
    [x - h, x, x + h]
        .iter()
        .map(|&y| f(y.clamp(lo, hi)).0.abs())
        .fold(0.0, f64::max)
}

#[test]
fn values_meet_the_tolerance_at_random_points() {
    let mut rng = Xoshiro256::new(2024);
    for (name, f, lo, hi, opts) in cases() {
        let table = Table::build(|x| Ok(f(x)), lo, hi, &opts).unwrap();
        assert_eq!(table.range(), (lo, hi));
        assert!(!table.is_empty());
        let mut worst: f64 = 0.0;
        for _ in 0..20_000 {
            let x = lo + (hi - lo) * rng.next_open01();
            let (v, _) = table.eval(x).unwrap();
            let (e, _) = f(x);
            let tol = (opts.rel_tol * local_scale(&*f, x, &table)).max(opts.abs_tol);
            worst = worst.max((v - e).abs() / tol);
        }
        // The builder enforces the tolerance at every interval midpoint, where the
        // cubic Hermite error (x−a)²(x−b)²·f⁗/24 peaks; elsewhere it is smaller
        // unless f⁗ varies within the interval (by a few per cent at these
        // spacings), hence the factor 1.1.
        assert!(worst <= 1.1, "{name}: worst error / tolerance = {worst}");
        // Exact at the ends.
        assert!((table.eval(lo).unwrap().0 - f(lo).0).abs() <= 1e-15 * f(lo).0.abs());
        assert!((table.eval(hi).unwrap().0 - f(hi).0).abs() <= 1e-15 * f(hi).0.abs() + 1e-300);
    }
}

#[test]
fn derivative_matches_exact_and_finite_differences() {
    let mut rng = Xoshiro256::new(7);
    for (name, f, lo, hi, opts) in cases() {
        let table = Table::build(|x| Ok(f(x)), lo, hi, &opts).unwrap();
        for _ in 0..5_000 {
            let x = lo + (hi - lo) * (0.001 + 0.998 * rng.next_open01());
            let (_, dv) = table.eval(x).unwrap();
            let (_, de) = f(x);
            let h = table.spacing_at(x).unwrap();
            // Hermite bounds: value error ≤ h⁴|f⁗|/384 and derivative error
            // ≤ h³|f⁗|/(72√3), so derivative error ≤ 3.08·(value error)/h. The value
            // error is at most the midpoint tolerance; |f| can change by a factor
            // ~2 across one interval in the steep tail, hence 2·3.08.
            let tol_v = (opts.rel_tol * local_scale(&*f, x, &table)).max(opts.abs_tol);
            let tol_d = 2.0 * 3.08 * tol_v / h;
            assert!(
                (dv - de).abs() <= tol_d + 1e-12 * de.abs(),
                "{name}: at {x:e} derivative {dv:e} exact {de:e} (tol {tol_d:e})"
            );
            // The interpolant is C¹: its derivative matches a central difference of
            // its own values. On one cubic piece |p'''| ≤ 12|Δy|/h³ + 6(|m0|+|m1|)/h²,
            // so with step = 1e-3·h the O(step²·p'''/6) term is below ~1e-5 of the
            // local scale max(|f'|, |f|/h) over the neighbouring interval; rounding
            // (ε|f|/step) is far smaller.
            let step = 1e-3 * h;
            if x - step >= lo && x + step <= hi {
                let fd = (table.eval(x + step).unwrap().0 - table.eval(x - step).unwrap().0)
                    / (2.0 * step);
                let scale = [x - h, x, x + h]
                    .iter()
                    .map(|&y| {
                        let (v, d) = f(y.clamp(lo, hi));
                        d.abs().max(v.abs() / h)
                    })
                    .fold(0.0, f64::max);
                assert!(
                    (fd - dv).abs() <= 1e-5 * scale,
                    "{name}: at {x:e} fd {fd:e} vs {dv:e}"
                );
            }
        }
    }
}

#[test]
fn outside_the_range_is_none() {
    let t = Table::build(
        |x: f64| Ok((x * x, 2.0 * x)),
        -1.0,
        2.0,
        &TableOptions::default(),
    )
    .unwrap();
    assert!(t.eval(-1.000_001).is_none());
    assert!(t.eval(2.000_001).is_none());
    assert!(t.eval(f64::NAN).is_none());
    assert!(t.eval(f64::INFINITY).is_none());
    assert!(t.eval(-1.0).is_some() && t.eval(2.0).is_some());
    // A cubic Hermite reproduces a quadratic exactly.
    let (v, d) = t.eval(0.3).unwrap();
    assert!((v - 0.09).abs() < 1e-15 && (d - 0.6).abs() < 1e-14);
}

#[test]
fn too_many_nodes_is_an_error() {
    let opts = TableOptions {
        rel_tol: 1e-12,
        abs_tol: 1e-15,
        max_nodes: 100,
    };
    match Table::build(|x: f64| Ok((x.sin(), x.cos())), 0.0, 100.0, &opts) {
        Err(Error::NoConvergence(f)) => assert!(
            matches!(
                f.downcast_ref(),
                Some(QuadratureError::TableNodes { max_nodes: 100, .. })
            ),
            "{f}"
        ),
        other => panic!("expected NoConvergence, got {other:?}"),
    }
}

#[test]
fn bad_inputs_are_rejected() {
    let f = |x: f64| -> Result<(f64, f64)> { Ok((x, 1.0)) };
    let o = TableOptions::default();
    let field = |r: Result<Table>| match r {
        Err(Error::InvalidInput { field, .. }) => field,
        other => panic!("{other:?}"),
    };
    assert_eq!(field(Table::build(f, 1.0, 1.0, &o)), "table.hi");
    assert_eq!(field(Table::build(f, f64::NAN, 1.0, &o)), "table.lo");
    let bad = TableOptions { rel_tol: -1.0, ..o };
    assert_eq!(field(Table::build(f, 0.0, 1.0, &bad)), "table.rel_tol");
    // Non-finite values from the function.
    assert_eq!(
        field(Table::build(|x: f64| Ok((1.0 / x, 0.0)), 0.0, 1.0, &o)),
        "table.f"
    );
    // Errors of the function propagate.
    let r = Table::build(
        |_x: f64| Err(QuadratureError::NoIntervalLeft.into()),
        0.0,
        1.0,
        &o,
    );
    assert!(
        matches!(&r, Err(Error::NoConvergence(f)) if f.is::<QuadratureError>()),
        "{r:?}"
    );
}

#[test]
fn refinement_is_local() {
    // A narrow bump on a wide flat range: far fewer nodes than a uniform grid at
    // the finest spacing would need.
    let f = |x: f64| {
        let g = (-(x * x) / 2e-4).exp();
        (1.0 + g, -x / 1e-4 * g)
    };
    let t = Table::build(|x| Ok(f(x)), -10.0, 10.0, &TableOptions::default()).unwrap();
    let finest = t.spacing_at(0.0).unwrap();
    let coarsest = t.spacing_at(-9.0).unwrap();
    assert!(coarsest > 100.0 * finest, "{coarsest} vs {finest}");
    assert!((t.len() as f64) < 0.05 * 20.0 / finest);
}
