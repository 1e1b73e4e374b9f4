//! The crate's ODE stepper on a problem that has nothing to do with disks: the Oregonator, a
//! stiff model of the Belousov–Zhabotinsky oscillating reaction (Field & Noyes 1974, in the scaled
//! form of Hairer & Wanner, "Solving ODEs II", problem OREGO).
//!
//! Concentrations spike by five orders of magnitude once per period; an event marks each spike
//! (y₁ rising through 1000) so the period can be read off. The automatic method switches between
//! the explicit Tsit5 and a stiff method; a tight Rodas5P run is the reference.
//!
//! The second part steps the integrator by hand: the same reaction with an acting event that
//! "titrates" the bromide-like species y₂ (halves it) whenever y₁ spikes, observing every step
//! without saving them, and an exact stop at a chosen time.
//!
//! Run with `cargo run --release --example own_ode`.

use hdi_tribology::nalgebra::Vector3;
use hdi_tribology::ode::{
    solve, Direction, Event, FnSystem, Integrator, Method, OdeError, Options, SaveAt, StepStatus,
};
use std::time::Instant;

fn main() -> Result<(), OdeError> {
    let orego = FnSystem::new(|_t: f64, y: &Vector3<f64>, dy: &mut Vector3<f64>| {
        dy[0] = 77.27 * (y[1] + y[0] * (1.0 - 8.375e-6 * y[0] - y[1]));
        dy[1] = (y[2] - (1.0 + y[0]) * y[1]) / 77.27;
        dy[2] = 0.161 * (y[0] - y[2]);
    });
    let y0 = Vector3::new(1.0, 2.0, 3.0);
    let t_end = 720.0; // two periods and a bit

    let run = |method: Method, rtol: f64| {
        let clock = Instant::now();
        // Concentrations span 1 to 1e5: a relative tolerance with a small absolute floor.
        let opts = Options::default()
            .rtol(rtol)
            .atol(rtol * 1e-2)
            .save(SaveAt::Final)
            .dense(false);
        let mut spikes =
            [Event::new(|_t, y: &Vector3<f64>| y[0] - 1000.0).direction(Direction::Rising)];
        let sol = solve(&orego, 0.0, y0, t_end, method, &opts, &mut spikes)?;
        Ok::<_, OdeError>((sol, clock.elapsed().as_secs_f64()))
    };

    let (reference, _) = run(Method::Rodas5P, 1e-11)?;
    println!(
        "{:<8} {:>7} {:>7} {:>8} {:>9} {:>12} {:>12} {:>8}",
        "method", "rtol", "steps", "rejects", "switches", "period", "max rel err", "ms"
    );
    for (method, rtol) in [
        (Method::Auto, 1e-4),
        (Method::Auto, 1e-7),
        (Method::Rodas5P, 1e-7),
        (Method::Tsit5, 1e-7),
    ] {
        // An explicit method is expected to run out of steps on this stiff problem: report it.
        let (sol, wall) = match run(method, rtol) {
            Ok(r) => r,
            Err(e) => {
                println!("{:<8} {:>7.0e} failed: {e}", method.name(), rtol);
                continue;
            }
        };
        let period = match sol.events.as_slice() {
            [a, b, ..] => b.t - a.t,
            _ => f64::NAN,
        };
        // Error at the final time, relative to each component of the reference.
        let err = (0..3)
            .map(|i| ((sol.y_end[i] - reference.y_end[i]) / reference.y_end[i]).abs())
            .fold(0.0, f64::max);
        println!(
            "{:<8} {:>7.0e} {:>7} {:>8} {:>9} {:>12.6} {:>12.2e} {:>8.2}",
            method.name(),
            rtol,
            sol.stats.accepted,
            sol.stats.rejected,
            sol.stats.stiffness_switches,
            period,
            err,
            wall * 1e3
        );
    }
    let spikes: Vec<String> = reference
        .events
        .iter()
        .map(|e| format!("{:.4}", e.t))
        .collect();
    println!("reference spikes (y₁ ↑ 1000) at t = {}", spikes.join(", "));
    println!(
        "reference y(720) = {:.8e}, {:.8e}, {:.8e}",
        reference.y_end[0], reference.y_end[1], reference.y_end[2]
    );
    stepped_by_hand(&orego, y0, t_end)
}

/// The integrator stepped by hand with an acting event and a streaming observer.
fn stepped_by_hand<S>(orego: &S, y0: Vector3<f64>, t_end: f64) -> Result<(), OdeError>
where
    S: hdi_tribology::ode::OdeSystem<hdi_tribology::nalgebra::U3>,
{
    let opts = Options::default().rtol(1e-8).atol(1e-10);
    // At each spike y₂ is halved: the action changes the state and the integration goes on.
    let titrate = Event::new(|_t, y: &Vector3<f64>| y[0] - 1000.0)
        .direction(Direction::Rising)
        .affect(|_t, y| y[1] *= 0.5);
    let mut it = Integrator::new(orego, 0.0, y0, t_end, Method::Auto, &opts)?.events([titrate]);
    // Observer: the peak of y₁ and the number of steps, without storing the trajectory.
    let (mut peak, mut t_peak, mut steps) = (0.0f64, 0.0, 0usize);
    let mut actions: Vec<f64> = Vec::new();
    // Stop exactly at t = 300 on the way (dense output inside the last step lands there).
    it.advance_to(300.0)?;
    let y300 = *it.state();
    // Events located on the way to t = 300 (here: the first spike, which acted).
    actions.extend(it.events_hit().iter().map(|e| e.t));
    loop {
        let status = it.step()?;
        steps += 1;
        if it.state()[0] > peak {
            (peak, t_peak) = (it.state()[0], it.t());
        }
        if let StepStatus::Acted(_) = status {
            actions.push(it.t());
        }
        if status == StepStatus::ReachedEnd {
            break;
        }
    }
    println!(
        "stepped by hand (auto, rtol 1e-8): y(300) = {:.6e}, {:.6e}, {:.6e}",
        y300[0], y300[1], y300[2]
    );
    let times: Vec<String> = actions.iter().map(|t| format!("{t:.4}")).collect();
    println!(
        "  after t = 300: {steps} steps, peak y₁ = {peak:.4e} at t = {t_peak:.3}; y₂ halved at t = {}",
        times.join(", ")
    );
    println!("  work: {:?}", it.stats());
    Ok(())
}

#[cfg(test)]
mod tests {
    /// `cargo test` runs the example, so CI runs every example.
    #[test]
    fn example_runs() {
        super::main().expect("the example runs to completion");
    }
}
