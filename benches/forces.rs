//! Interface forces of the paper scene: one full evaluation (static part + per-V² part + contact)
//! through the tables against direct quadrature of every term.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, Criterion, Throughput};
use hdi_tribology::force::{Gaps, InterfaceForces};
use hdi_tribology::scene::Scene;

/// Separations spread over the flying and contact regimes (0.3–15 nm), not sorted, so that
/// successive look-ups do not share a cache line by construction.
fn gaps(n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| 0.3e-9 + 14.7e-9 * ((0.5 + i as f64 * 0.618_033_988_749_895) % 1.0))
        .collect()
}

fn full_eval(f: &InterfaceForces, d: f64) -> f64 {
    let g = Gaps::same(d);
    let s = f.static_part(g);
    let e = f.per_volt2_part(g);
    let c = f.contact(g);
    s.value + s.d_bulge + 0.25 * (e.value + e.d_bulge) + c.value + c.d_bulge
}

fn fused_eval(f: &InterfaceForces, d: f64) -> f64 {
    let h = f.evaluate(Gaps::same(d));
    let (s, e, c) = (h.static_part, h.per_volt2, h.contact);
    s.value + s.d_bulge + 0.25 * (e.value + e.d_bulge) + c.value + c.d_bulge
}

fn direct_eval(f: &InterfaceForces, d: f64) -> f64 {
    f.terms()
        .iter()
        .map(|t| {
            let (v, s) = t
                .force(d)
                .map_or((f64::NAN, f64::NAN), |f| (f.value, f.slope));
            v + s
        })
        .sum()
}

fn bench(c: &mut Criterion) {
    let forces = Scene::paper()
        .build_interface()
        .expect("paper scene builds");
    let mut group = c.benchmark_group("interface forces (paper scene)");
    let table_points = gaps(1024);
    group.throughput(Throughput::Elements(table_points.len() as u64));
    group.bench_function("tables: static + per V² + contact", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &d in &table_points {
                acc += full_eval(&forces, black_box(d));
            }
            acc
        })
    });
    group.bench_function("fused table: evaluate()", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &d in &table_points {
                acc += fused_eval(&forces, black_box(d));
            }
            acc
        })
    });
    // An ODE trajectory moves d a little per step: successive look-ups hit neighbouring nodes.
    let path: Vec<f64> = (0..1024)
        .map(|i| 5.0e-9 + 4.5e-9 * (2.0 * std::f64::consts::PI * i as f64 / 1024.0).sin())
        .collect();
    group.bench_function("tables along a trajectory", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &d in &path {
                acc += full_eval(&forces, black_box(d));
            }
            acc
        })
    });
    let direct_points = gaps(16);
    group.throughput(Throughput::Elements(direct_points.len() as u64));
    group.bench_function("direct quadrature of every term", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &d in &direct_points {
                acc += direct_eval(&forces, black_box(d));
            }
            acc
        })
    });
    group.finish();
    c.bench_function("build the paper scene's tables", |b| {
        b.iter(|| Scene::paper().build_interface().map(|f| f.table_nodes()))
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3))
        .sample_size(20);
    targets = bench
}

/// CPU time of this thread in ns (Linux `schedstat`; updated at scheduler ticks, so each
/// measurement below runs for about a second), unaffected by other processes competing for the
/// cores, unlike criterion's wall-clock figures on a loaded machine.
fn thread_cpu_ns() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

/// Prints CPU nanoseconds per full evaluation, tables and direct, and their ratio.
fn cpu_time_report() {
    let Ok(forces) = Scene::paper().build_interface() else {
        return;
    };
    let pts = gaps(1024);
    let per_eval = |reps: usize, pts: &[f64], f: &dyn Fn(f64) -> f64| -> Option<f64> {
        let t0 = thread_cpu_ns()?;
        let mut acc = 0.0;
        for _ in 0..reps {
            for &d in pts {
                acc += f(black_box(d));
            }
        }
        black_box(acc);
        Some((thread_cpu_ns()? - t0) / (reps * pts.len()) as f64)
    };
    let table = per_eval(15_000, &pts, &|d| full_eval(&forces, d));
    let fused = per_eval(15_000, &pts, &|d| fused_eval(&forces, d));
    let direct = per_eval(8, &pts, &|d| direct_eval(&forces, d));
    if let (Some(t), Some(u), Some(q)) = (table, fused, direct) {
        println!(
            "CPU time per full evaluation (paper scene): three tables {t:.1} ns, fused table {u:.1} ns, \
             direct quadrature {:.1} µs; ratios {:.0} and {:.0}",
            q / 1e3,
            q / t,
            q / u
        );
    }
}

fn main() {
    benches();
    cpu_time_report();
    Criterion::default().configure_from_args().final_summary();
}
