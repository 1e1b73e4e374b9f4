//! Speed of the slider simulation on the paper scene: one fixed-programme touchdown/take-off
//! cycle per ODE method at rtol 1e-6 on one thread (V_ac = 0 and 0.6 V), and the 11-point AC
//! sweep (0 … 1 V) on a two-thread pool with the scene's own solver settings.
//!
//! Run with `cargo bench --bench cycle`. The accuracy of these runs against a tight-tolerance
//! reference is printed by `cargo run --release --example work_precision`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, HeaterProgramme};
use hdi_tribology::analysis::sweep::ac_sweep;
use hdi_tribology::model::{SliderModel, Voltage};
use hdi_tribology::ode::Method;
use hdi_tribology::scene::Scene;
use std::hint::black_box;
use std::time::Duration;

struct Setup {
    scene: Scene,
    model: SliderModel,
    programme: HeaterProgramme,
}

fn setup() -> Setup {
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene).expect("the paper scene is valid");
    let knots = SliderModel::programme_from_knots(&scene.heater.programme)
        .expect("the paper programme is valid");
    Setup {
        scene,
        model,
        programme: HeaterProgramme::Fixed(knots),
    }
}

fn cycles(c: &mut Criterion) {
    let s = setup();
    let mut group = c.benchmark_group("paper_cycle_rtol_1e-6");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2));
    for v_ac in [0.0, 0.6] {
        let model = s.model.with_voltage(Voltage {
            ac_amplitude: v_ac,
            ..s.model.voltage()
        });
        for method in [
            Method::Tsit5,
            Method::Dop853,
            Method::Rodas5P,
            Method::Radau5,
            Method::Auto,
        ] {
            let mut opts = CycleOptions::from_scene(&s.scene).expect("scene options");
            opts.solver.method = method;
            opts.solver.rtol = 1e-6;
            let id = BenchmarkId::new(method.name(), format!("{v_ac:.1}V"));
            group.bench_with_input(id, &opts, |b, opts| {
                b.iter(|| simulate_cycle(black_box(&model), &s.programme, opts).expect("cycle"))
            });
        }
    }
    group.finish();
}

fn sweep(c: &mut Criterion) {
    let s = setup();
    let opts = CycleOptions::from_scene(&s.scene).expect("scene options");
    let amplitudes: Vec<f64> = (0..=10).map(|i| f64::from(i) * 0.1).collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("thread pool");
    let mut group = c.benchmark_group("paper_ac_sweep_11_points");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(4));
    for method in [opts.solver.method, Method::Tsit5] {
        let mut o = opts;
        o.solver.method = method;
        group.bench_function(BenchmarkId::new("2_threads", method.name()), |b| {
            b.iter(|| {
                pool.install(|| ac_sweep(black_box(&s.model), &s.programme, &o, &amplitudes))
                    .expect("sweep")
            })
        });
    }
    group.finish();
}

criterion_group!(benches, cycles, sweep);
criterion_main!(benches);
