//! The air bearing's attitude solve on the two-rail taper-flat slider at 129², 257² and 513²
//! control volumes, and the stiffness and damping about the equilibrium.

use criterion::{criterion_group, criterion_main, Criterion};
use hdi_tribology::bearing::{solve_attitude, AttitudeOptions, BearingSpec};

fn spec(n: usize) -> BearingSpec {
    let mut s = BearingSpec::from_path(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/bearing/two_rail_taper_flat.toml"
    ))
    .expect("the example bearing reads");
    s.grid.nx = n;
    s.grid.ny = n;
    s
}

fn attitude(c: &mut Criterion) {
    let mut g = c.benchmark_group("bearing");
    g.sample_size(10);
    for n in [129usize, 257, 513] {
        let b = spec(n).build().expect("the example bearing is valid");
        g.bench_function(format!("attitude_{n}"), |bench| {
            bench.iter(|| solve_attitude(&b, &AttitudeOptions::default()).expect("it flies"))
        });
    }
    let b = spec(257).build().expect("the example bearing is valid");
    let eq = solve_attitude(&b, &AttitudeOptions::default()).expect("it flies");
    g.bench_function("damping_257", |bench| {
        bench.iter(|| eq.damping().expect("the damping solves"))
    });
    g.finish();
}

criterion_group!(benches, attitude);
criterion_main!(benches);
