//! Speed of table look-ups, partial moments and adaptive integration.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use hdi_tribology::quadrature::{integrate, QuadOptions, Table, TableOptions};
use hdi_tribology::surface::{
    Empirical, Gaussian, PeakDistribution, RiceMaxima, Rician, Xoshiro256,
};

fn lookups(c: &mut Criterion) {
    let law = Gaussian::new(0.0, 1e-9).unwrap();
    let (lo, hi) = (-5e-9, 12e-9);
    let opts = TableOptions {
        rel_tol: 1e-9,
        abs_tol: 1e-40,
        max_nodes: 200_000,
    };
    let table = Table::build(
        |d| {
            Ok((
                law.partial_moment(d, 1.5),
                -1.5 * law.partial_moment(d, 0.5),
            ))
        },
        lo,
        hi,
        &opts,
    )
    .unwrap();
    println!(
        "contact table: {} nodes, {} panels",
        table.len(),
        table.panels()
    );
    let mut rng = Xoshiro256::new(1);
    let xs: Vec<f64> = (0..4096)
        .map(|_| lo + (hi - lo) * rng.next_open01())
        .collect();
    c.bench_function("table eval (random points)", |b| {
        let mut i = 0;
        b.iter(|| {
            i = (i + 1) & 4095;
            black_box(table.eval(black_box(xs[i])))
        })
    });
    // An ODE trajectory moves d a little per step: neighbouring look-ups.
    let path: Vec<f64> = (0..4096)
        .map(|i| lo + (hi - lo) * (0.5 + 0.45 * (f64::from(i) * 1e-3).sin()))
        .collect();
    c.bench_function("table eval baseline (loop and black_box only)", |b| {
        let mut i = 0;
        b.iter(|| {
            i = (i + 1) & 4095;
            black_box(Some((black_box(path[i]), 0.0)))
        })
    });
    c.bench_function("table eval (trajectory)", |b| {
        let mut i = 0;
        b.iter(|| {
            i = (i + 1) & 4095;
            black_box(table.eval(black_box(path[i])))
        })
    });
    // A force evaluation reads three tables at the same d (contact, its
    // derivative source, and a non-contact term).
    let t2 = table.clone();
    let t3 = Table::build(
        |d| Ok((law.partial_moment(d, 1.0), -law.partial_moment(d, 0.0))),
        lo,
        hi,
        &opts,
    )
    .unwrap();
    c.bench_function("three table evals at one d (trajectory)", |b| {
        let mut i = 0;
        b.iter(|| {
            i = (i + 1) & 4095;
            let d = black_box(path[i]);
            black_box((table.eval(d), t2.eval(d), t3.eval(d)))
        })
    });
    // Throughput: 4096 look-ups per iteration (divide the time by 4096).
    c.bench_function("4096 table evals (trajectory, throughput)", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &d in &path {
                if let Some((v, dv)) = table.eval(black_box(d)) {
                    acc += v + dv;
                }
            }
            black_box(acc)
        })
    });
    c.bench_function("table build (Gaussian M_1.5, 1e-9)", |b| {
        b.iter(|| {
            Table::build(
                |d| {
                    Ok((
                        law.partial_moment(d, 1.5),
                        -1.5 * law.partial_moment(d, 0.5),
                    ))
                },
                lo,
                hi,
                &opts,
            )
            .unwrap()
        })
    });
}

fn moments(c: &mut Criterion) {
    let laws: Vec<(&str, Box<dyn PeakDistribution>)> = vec![
        ("gaussian", Box::new(Gaussian::new(0.0, 1e-9).unwrap())),
        ("rice_maxima", Box::new(RiceMaxima::new(1e-9, 0.5).unwrap())),
        ("rician", Box::new(Rician::new(1e-9, 1e-9).unwrap())),
        (
            "empirical_100_bins",
            Box::new(
                Empirical::from_histogram(
                    &(0..=100).map(|i| f64::from(i) * 1e-10).collect::<Vec<_>>(),
                    &[1.0; 100],
                )
                .unwrap(),
            ),
        ),
    ];
    for (name, law) in &laws {
        for p in [1.0, 1.5] {
            c.bench_function(&format!("partial_moment {name} p={p}"), |b| {
                let mut k = 0.0;
                b.iter(|| {
                    k = if k > 4.0 { -4.0 } else { k + 0.37 };
                    black_box(law.partial_moment(black_box(k * 1e-9), p))
                })
            });
        }
    }
}

fn quadrature(c: &mut Criterion) {
    let o = QuadOptions::default();
    c.bench_function("integrate exp(-x^2) over R, 1e-12", |b| {
        b.iter(|| {
            integrate(
                |x: f64| (-x * x).exp(),
                f64::NEG_INFINITY,
                f64::INFINITY,
                &o,
            )
            .unwrap()
        })
    });
}

criterion_group!(benches, lookups, moments, quadrature);
criterion_main!(benches);
