//! Timing of short runs on a shared machine: the fastest wall-clock repetition and the mean CPU
//! time of the calling thread over all repetitions.
//!
//! The CPU time comes from Linux's `/proc/thread-self/schedstat`, which the kernel updates at
//! scheduler ticks (a few ms); over at least `budget` of repetitions that granularity is a few
//! percent. It does not count time spent waiting for a core, unlike the wall clock, so it is the
//! fairer figure when other processes load the machine. Elsewhere it is `None`.
#![allow(dead_code)]

use std::time::{Duration, Instant};

/// CPU time consumed so far by the calling thread (s), where the kernel reports it.
pub fn thread_cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: f64 = s.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}

/// Time per run of a repeated closure.
#[derive(Clone, Copy, Debug)]
pub struct Timing {
    /// Fastest wall-clock repetition (s).
    pub wall: f64,
    /// Mean CPU time of this thread per repetition (s); NaN where unavailable.
    pub cpu: f64,
}

/// Runs `f` at least `min_reps` times and until `budget` has passed (at most `max_reps` times);
/// returns the last result and the timing.
pub fn measure<T>(
    min_reps: usize,
    max_reps: usize,
    budget: Duration,
    mut f: impl FnMut() -> T,
) -> (T, Timing) {
    let start = Instant::now();
    let cpu0 = thread_cpu_seconds();
    let mut best = f64::INFINITY;
    let mut n = 0;
    loop {
        let t = Instant::now();
        let out = f();
        best = best.min(t.elapsed().as_secs_f64());
        n += 1;
        if n >= max_reps || (n >= min_reps && start.elapsed() >= budget) {
            let cpu = match (cpu0, thread_cpu_seconds()) {
                (Some(a), Some(b)) => (b - a) / n as f64,
                _ => f64::NAN,
            };
            return (out, Timing { wall: best, cpu });
        }
    }
}
