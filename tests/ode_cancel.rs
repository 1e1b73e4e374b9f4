//! Cancelling an integration from outside: a raised flag stops the next step with
//! `OdeError::Cancelled`; a flag's check is called while the steps run and stops them when it
//! says so; work handed to rayon keeps watching the flag.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Instant;

use hdi_tribology::ode::{Cancel, FnSystem, Integrator, Method, OdeError, Options};
use nalgebra::Vector2;

/// y'' = −y from y = 1 over a very long span: millions of steps, many seconds of work.
fn oscillator() -> FnSystem<impl Fn(f64, &Vector2<f64>, &mut Vector2<f64>)> {
    FnSystem::new(|_t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>| {
        dy[0] = y[1];
        dy[1] = -y[0];
    })
}

#[test]
fn a_raised_flag_stops_the_next_step() {
    let sys = oscillator();
    let opts = Options::default().rtol(1e-10).atol(1e-12);
    let mut it =
        Integrator::new(&sys, 0.0, Vector2::new(1.0, 0.0), 1e7, Method::Tsit5, &opts).unwrap();
    let c = Cancel::new();
    let r = c.watch(|| {
        it.step().unwrap();
        c.cancel();
        it.step()
    });
    assert!(matches!(r, Err(OdeError::Cancelled { .. })), "{r:?}");
    // a thread that watches no flag steps on
    assert!(it.step().is_ok());
}

#[test]
fn a_check_stops_a_long_integration_soon() {
    let sys = oscillator();
    let opts = Options::default()
        .rtol(1e-10)
        .atol(1e-12)
        .max_steps(1_000_000_000);
    let mut it =
        Integrator::new(&sys, 0.0, Vector2::new(1.0, 0.0), 1e7, Method::Tsit5, &opts).unwrap();
    let calls = Arc::new(AtomicUsize::new(0));
    let seen = calls.clone();
    let begun = Instant::now();
    // says "stop" on its third call: about 3 check intervals (150 ms) into the run
    let c = Cancel::with_check(move || seen.fetch_add(1, Ordering::Relaxed) >= 2);
    let r = c.watch(|| it.advance_to(1e7));
    let took = begun.elapsed().as_secs_f64();
    assert!(matches!(r, Err(OdeError::Cancelled { .. })), "{r:?}");
    assert_eq!(calls.load(Ordering::Relaxed), 3);
    assert!(c.is_cancelled());
    // the whole span takes minutes of steps; the check stopped it within a few intervals
    assert!(took < 5.0, "{took} s");
    assert!(it.t() < 1e7);
}

#[cfg(feature = "parallel")]
#[test]
fn rayon_workers_keep_watching_the_callers_flag() {
    use rayon::prelude::*;
    let c = Cancel::new();
    c.cancel();
    let seen: Vec<bool> = c.watch(|| {
        let current = Cancel::current();
        (0..8)
            .into_par_iter()
            .map(|_| Cancel::carry(&current, Cancel::requested))
            .collect()
    });
    assert!(seen.iter().all(|&s| s));
}
