//! Speed of the ODE stepper on a slider-like proxy (a 2-state oscillator with a mode at
//! 87 kHz, a 21 kHz drive and a stiff one-sided contact, integrated for 7.6 ms) and on the
//! stiff Van der Pol oscillator, for every method, and the same Van der Pol runs stepped by hand
//! with the `Integrator` (`van_der_pol_mu1000_stepped/*`: the overhead of stepping against
//! `solve`). Run: `cargo bench --bench ode`; a table of the work done (steps, evaluations,
//! factorisations) comes first.

use criterion::{criterion_group, criterion_main, Criterion};
use hdi_tribology::ode::{solve, Integrator, Method, OdeSystem, Options, SaveAt, StepStatus};
use nalgebra::{Matrix2, Vector2, U2};
use std::f64::consts::PI;
use std::hint::black_box;
use std::time::Instant;

/// x'' = −ω₀²(x − x₀) − (ω₀/Q)x' + a cos(ω_d t) + K (d − x)^1.5 for x < d.
struct SliderProxy {
    w0: f64,
    q: f64,
    x0: f64,
    a: f64,
    wd: f64,
    k: f64,
    d: f64,
}

impl SliderProxy {
    fn new() -> Self {
        Self::with_contact(1e4)
    }

    /// Contact stiffness at 1 nm indentation = `ratio` · ω₀².
    fn with_contact(ratio: f64) -> Self {
        let w0 = 2.0 * PI * 87e3;
        let wd = 2.0 * PI * 21e3;
        // Drive amplitude chosen so the free response (≈ a/(ω₀² − ω_d²)) reaches 6 nm: the
        // slider dips 2 nm into the contact zone below d = 1 nm.
        let a = 6e-9 * (w0 * w0 - wd * wd);
        SliderProxy {
            w0,
            q: 50.0,
            x0: 5e-9,
            a,
            wd,
            k: ratio * w0 * w0 / (1.5 * 1e-9f64.sqrt()),
            d: 1e-9,
        }
    }
}

impl OdeSystem<U2> for SliderProxy {
    fn rhs(&self, t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
        let pen = (self.d - y[0]).max(0.0);
        dy[0] = y[1];
        dy[1] = -self.w0 * self.w0 * (y[0] - self.x0) - self.w0 / self.q * y[1]
            + self.a * (self.wd * t).cos()
            + self.k * pen * pen.sqrt();
    }
    fn jacobian(&self, _t: f64, y: &Vector2<f64>, j: &mut Matrix2<f64>) -> bool {
        let pen = (self.d - y[0]).max(0.0);
        *j = Matrix2::new(
            0.0,
            1.0,
            -self.w0 * self.w0 - 1.5 * self.k * pen.sqrt(),
            -self.w0 / self.q,
        );
        true
    }
    fn time_derivative(&self, t: f64, _y: &Vector2<f64>, dfdt: &mut Vector2<f64>) -> bool {
        *dfdt = Vector2::new(0.0, -self.a * self.wd * (self.wd * t).sin());
        true
    }
}

fn slider_opts() -> Options {
    Options::default()
        .rtol(1e-6)
        .atol_per_component(vec![1e-14, 1e-8])
        .dense(false)
        .save(SaveAt::Final)
        .max_steps(1_000_000)
}

/// Work and best-of-7 time per method and contact stiffness, as a markdown table on stderr.
/// With a stiff contact the driven impact oscillator is chaotic over 7.6 ms: final states
/// differ between methods and tolerances (they agree over the first millisecond), so the
/// table compares work, not accuracy.
fn work_table() {
    let opts = Options::default()
        .rtol(1e-6)
        .atol_per_component(vec![1e-14, 1e-8])
        .dense(false)
        .save(SaveAt::Final)
        .max_steps(2_000_000);
    eprintln!("| contact K/(m ω₀²) | method | accepted | rejected | rhs evals | Jacobians | LUs | switches | stiff steps | x(7.6 ms) [nm] | best time [ms] |");
    eprintln!("|---|---|---|---|---|---|---|---|---|---|---|");
    for ratio in [1e2, 1e4, 1e6] {
        let sys = SliderProxy::with_contact(ratio);
        for m in Method::ALL {
            let mut best = f64::INFINITY;
            let mut last = None;
            for _ in 0..7 {
                let t0 = Instant::now();
                let sol = solve(
                    &sys,
                    0.0,
                    Vector2::new(5e-9, 0.0),
                    7.6e-3,
                    m,
                    &opts,
                    &mut [],
                );
                best = best.min(t0.elapsed().as_secs_f64());
                last = Some(sol);
            }
            match last {
                Some(Ok(sol)) => {
                    let s = sol.stats;
                    eprintln!(
                        "| {ratio:.0e} | {m} | {} | {} | {} | {} | {} | {} | {} | {:.6} | {:.2} |",
                        s.accepted,
                        s.rejected,
                        s.rhs_evals,
                        s.jac_evals,
                        s.lu_decomps,
                        s.stiffness_switches,
                        s.stiff_steps,
                        sol.y_final()[0] * 1e9,
                        best * 1e3
                    );
                }
                Some(Err(e)) => eprintln!("| {ratio:.0e} | {m} | failed: {e} |"),
                None => {}
            }
        }
    }
}

fn bench(c: &mut Criterion) {
    work_table();
    let sys = SliderProxy::new();
    let y0 = Vector2::new(5e-9, 0.0);
    for m in Method::ALL {
        c.bench_function(&format!("slider_proxy_7.6ms/{m}"), |b| {
            b.iter(|| solve(&sys, 0.0, black_box(y0), 7.6e-3, m, &slider_opts(), &mut []).unwrap())
        });
    }
    let vdp =
        hdi_tribology::ode::FnSystem::new(|_t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>| {
            dy[0] = y[1];
            dy[1] = 1000.0 * (1.0 - y[0] * y[0]) * y[1] - y[0];
        });
    let opts = Options::default()
        .rtol(1e-6)
        .atol(1e-6)
        .save(SaveAt::Final)
        .dense(false);
    for m in [Method::Rodas5P, Method::Radau5, Method::Auto] {
        c.bench_function(&format!("van_der_pol_mu1000/{m}"), |b| {
            b.iter(|| {
                solve(
                    &vdp,
                    0.0,
                    black_box(Vector2::new(2.0, 0.0)),
                    2000.0,
                    m,
                    &opts,
                    &mut [],
                )
                .unwrap()
            })
        });
        c.bench_function(&format!("van_der_pol_mu1000_stepped/{m}"), |b| {
            b.iter(|| {
                let y0 = black_box(Vector2::new(2.0, 0.0));
                let mut it = Integrator::new(&vdp, 0.0, y0, 2000.0, m, &opts).unwrap();
                while it.step().unwrap() != StepStatus::ReachedEnd {}
                *it.state()
            })
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).measurement_time(std::time::Duration::from_secs(2));
    targets = bench
}
criterion_main!(benches);
