//! The methods of hdi-tribology against diffsol at equal accuracy on Van der Pol (μ = 1000),
//! Robertson (to 1e11), HIRES, OREGO and E5 (stiff: our stiff methods) and Pleiades (non-stiff,
//! 28 states: our explicit methods; diffsol has implicit methods only).
//!
//! Every solver runs a sweep of relative tolerances; each run's error against the test-set
//! reference and its mean CPU time per run give a work–precision curve. The curves
//! are interpolated (log–log, between neighbouring tolerances) at common error levels, and the
//! table prints the CPU time of each solver there and the ratio to the fastest diffsol solver.
//! Both sides get the same right-hand side and the same analytic Jacobian.
//!
//! Run from this folder with `cargo run --release`; `cargo run --release -- hires orego` runs the
//! named problems only (`vdp`, `robertson`, `hires`, `orego`, `e5`, `pleiades`).

#[path = "../../../examples/common/problems.rs"]
mod problems;
#[path = "../../../examples/common/timing.rs"]
mod timing;

use diffsol::{NalgebraLU, NalgebraMat, OdeBuilder, OdeSolverMethod, OdeSolverStopReason};
use hdi_tribology::ode::{solve, Method};
use problems::Problem;
use std::time::{Duration, Instant};
use timing::measure;

/// Repeat a run at least `MIN_REPEATS` times and until `TIMING_BUDGET` has passed; the figure
/// compared is the mean CPU time of the thread per run (the machine is shared, and CPU time does
/// not count waiting for a core), the fastest wall-clock run is printed beside it.
const TIMING_BUDGET: Duration = Duration::from_millis(150);
const MIN_REPEATS: usize = 3;
const MAX_REPEATS: usize = 100_000;

/// Step cap for the peer's step loop (ours has `Options::max_steps`).
const PEER_STEP_CAP: usize = 2_000_000;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Solver {
    Ours(Method),
    Bdf,
    Esdirk34,
    TrBdf2,
}

impl Solver {
    fn name(self) -> String {
        match self {
            Solver::Ours(m) => m.name().to_string(),
            Solver::Bdf => "diffsol bdf".into(),
            Solver::Esdirk34 => "diffsol esdirk34".into(),
            Solver::TrBdf2 => "diffsol tr_bdf2".into(),
        }
    }
    fn is_peer(self) -> bool {
        !matches!(self, Solver::Ours(_))
    }
}

const STIFF: [Solver; 6] = [
    Solver::Ours(Method::Rodas5P),
    Solver::Ours(Method::Radau5),
    Solver::Ours(Method::Auto),
    Solver::Bdf,
    Solver::Esdirk34,
    Solver::TrBdf2,
];

const NON_STIFF: [Solver; 6] = [
    Solver::Ours(Method::Tsit5),
    Solver::Ours(Method::Dop853),
    Solver::Ours(Method::Auto),
    Solver::Bdf,
    Solver::Esdirk34,
    Solver::TrBdf2,
];

/// Final state and accepted steps, or why the run failed.
fn run<const N: usize>(
    p: &Problem<N>,
    solver: Solver,
    rtol: f64,
) -> Result<(Vec<f64>, usize), String> {
    match solver {
        Solver::Ours(m) => {
            let opts = p.options(rtol).max_steps(PEER_STEP_CAP);
            let sol = solve(p, 0.0, p.y0_vector(), p.t_end, m, &opts, &mut [])
                .map_err(|e| e.to_string())?;
            Ok((sol.y_final().as_slice().to_vec(), sol.stats.accepted))
        }
        peer => run_diffsol(p, peer, rtol).map_err(|e| e.to_string()),
    }
}

fn run_diffsol<const N: usize>(
    p: &Problem<N>,
    solver: Solver,
    rtol: f64,
) -> Result<(Vec<f64>, usize), Box<dyn std::error::Error>> {
    let y0 = p.y0;
    let rhs = p.rhs;
    let mut problem = OdeBuilder::<NalgebraMat<f64>>::new()
        .rtol(rtol)
        .atol((p.atol)(rtol).to_vec())
        .rhs_implicit(
            move |x: &[f64], _p: &[f64], t: f64, y: &mut [f64]| rhs(t, x, y),
            move |x: &[f64], _p: &[f64], t: f64, v: &[f64], y: &mut [f64]| p.jac_times(t, x, v, y),
        )
        .init(
            move |_p: &[f64], _t: f64, y: &mut [f64]| y.copy_from_slice(&y0),
            N,
        )
        .build()?;
    // The default floor on the step (1e-13, absolute) stops every diffsol method on Robertson in
    // its first steps, where the tight absolute tolerance on y₂ asks for steps near 1e-16.
    problem.ode_options.min_timestep = 1e-20;
    fn drive<'a, S: OdeSolverMethod<'a, E>, E: diffsol::OdeEquations<T = f64> + 'a>(
        s: &mut S,
        t_end: f64,
    ) -> Result<(Vec<f64>, usize), Box<dyn std::error::Error>>
    where
        E::V: diffsol::Vector<T = f64>,
    {
        s.set_stop_time(t_end)?;
        for _ in 0..PEER_STEP_CAP {
            if let OdeSolverStopReason::TstopReached = s.step()? {
                let y = diffsol::Vector::clone_as_vec(s.state().y);
                return Ok((y, s.get_statistics().number_of_steps));
            }
        }
        Err("step cap reached".into())
    }
    match solver {
        Solver::Bdf => drive(&mut problem.bdf::<NalgebraLU<f64>>()?, p.t_end),
        Solver::Esdirk34 => drive(&mut problem.esdirk34::<NalgebraLU<f64>>()?, p.t_end),
        Solver::TrBdf2 => drive(&mut problem.tr_bdf2::<NalgebraLU<f64>>()?, p.t_end),
        Solver::Ours(_) => unreachable!("handled by run"),
    }
}

/// One point of a work–precision curve.
#[derive(Clone, Copy)]
struct Point {
    error: f64,
    /// CPU time per run (s).
    wall: f64,
}

/// Wall time at `target` error: interpolated log–log between the first two neighbouring
/// tolerances whose errors bracket it; without a bracket, the cheapest run that is at least as
/// accurate (an upper bound, flagged `true`).
fn time_at(curve: &[Point], target: f64) -> Option<(f64, bool)> {
    let lt = target.ln();
    curve
        .windows(2)
        .find_map(|w| {
            let (a, b) = (w[0], w[1]);
            let (ea, eb) = (a.error.ln(), b.error.ln());
            if (ea - lt) * (eb - lt) > 0.0 || ea == eb {
                return None;
            }
            let s = (lt - ea) / (eb - ea);
            Some(((a.wall.ln() + s * (b.wall.ln() - a.wall.ln())).exp(), false))
        })
        .or_else(|| {
            curve
                .iter()
                .filter(|p| p.error <= target)
                .map(|p| p.wall)
                .min_by(f64::total_cmp)
                .map(|t| (t, true))
        })
}

fn compare<const N: usize>(p: &Problem<N>, rtols: &[f64], targets: &[f64]) {
    let solvers = if p.stiff { STIFF } else { NON_STIFF };
    println!("\n## {}\n", p.name);
    println!("| solver | rtol | error | CPU (ms) | fastest wall (ms) | steps |");
    println!("|---|---|---|---|---|---|");
    let mut curves = Vec::new();
    for s in solvers {
        let mut curve = Vec::new();
        for &rtol in rtols {
            let (res, t) = measure(MIN_REPEATS, MAX_REPEATS, TIMING_BUDGET, || run(p, s, rtol));
            match res {
                Ok((y, steps)) => {
                    let error = p.error(&y);
                    println!(
                        "| {} | {rtol:.1e} | {error:.2e} | {:.4} | {:.4} | {steps} |",
                        s.name(),
                        t.cpu * 1e3,
                        t.wall * 1e3
                    );
                    if error > 0.0 && error.is_finite() {
                        curve.push(Point { error, wall: t.cpu });
                    }
                }
                Err(e) => println!("| {} | {rtol:.1e} | failed: {e} | | | |", s.name()),
            }
        }
        curves.push((s, curve));
    }
    println!("\nAt equal accuracy (mean CPU time per run in ms; ratio = fastest diffsol solver / this solver, > 1: this one is faster; ≤: cheapest run at least that accurate):\n");
    println!("| error | {} |", solvers.map(|s| s.name()).join(" | "));
    println!("|---|{}", "---|".repeat(solvers.len()));
    for &target in targets {
        let times: Vec<Option<(f64, bool)>> =
            curves.iter().map(|(_, c)| time_at(c, target)).collect();
        let peer_best = curves
            .iter()
            .zip(&times)
            .filter(|((s, _), _)| s.is_peer())
            .filter_map(|(_, t)| t.map(|t| t.0))
            .fold(f64::INFINITY, f64::min);
        let cells: Vec<String> = curves
            .iter()
            .zip(&times)
            .map(|((s, _), t)| {
                let Some((t, bound)) = *t else {
                    return "–".into();
                };
                let le = if bound { "≤ " } else { "" };
                if !s.is_peer() && peer_best.is_finite() {
                    format!("{le}{:.3} (×{:.2})", t * 1e3, peer_best / t)
                } else {
                    format!("{le}{:.3}", t * 1e3)
                }
            })
            .collect();
        println!("| {target:.0e} | {} |", cells.join(" | "));
    }
    // The same comparison without interpolation: each solver's cheapest run whose error is at
    // most the target (an upper bound on its time there, exact as the tolerances get denser).
    println!("\nCheapest run at least that accurate (CPU ms; ratio as above):\n");
    println!("| error | {} |", solvers.map(|s| s.name()).join(" | "));
    println!("|---|{}", "---|".repeat(solvers.len()));
    for &target in targets {
        let cheapest = |c: &[Point]| {
            c.iter()
                .filter(|p| p.error <= target)
                .map(|p| p.wall)
                .min_by(f64::total_cmp)
        };
        let peer_best = curves
            .iter()
            .filter(|(s, _)| s.is_peer())
            .filter_map(|(_, c)| cheapest(c))
            .fold(f64::INFINITY, f64::min);
        let cells: Vec<String> = curves
            .iter()
            .map(|(s, c)| match cheapest(c) {
                None => "–".into(),
                Some(t) if !s.is_peer() && peer_best.is_finite() => {
                    format!("{:.3} (×{:.2})", t * 1e3, peer_best / t)
                }
                Some(t) => format!("{:.3}", t * 1e3),
            })
            .collect();
        println!("| {target:.0e} | {} |", cells.join(" | "));
    }
    for (s, c) in &curves {
        if c.windows(2).any(|w| w[1].error > w[0].error) {
            println!(
                "note: {} error not monotone in rtol on {}",
                s.name(),
                p.name
            );
        }
    }
}

fn main() {
    let clock = Instant::now();
    let args: Vec<String> = std::env::args().skip(1).collect();
    // `--per-decade N`: N tolerances per decade (1 by default: 1e-3, 1e-4, …, 1e-12).
    let per_decade: i32 = args
        .iter()
        .position(|a| a == "--per-decade")
        .and_then(|i| args.get(i + 1))
        .map_or(1, |n| n.parse().expect("--per-decade takes a whole number"));
    let rtols: Vec<f64> = (3 * per_decade..=12 * per_decade)
        .map(|k| 10f64.powf(-f64::from(k) / f64::from(per_decade)))
        .collect();
    let targets = [1e-4, 1e-6, 1e-8];
    // Problems named on the command line (`vdp robertson hires orego e5 pleiades`), else all.
    let picked: Vec<String> = args
        .iter()
        .enumerate()
        .filter(|&(i, a)| a != "--per-decade" && (i == 0 || args[i - 1] != "--per-decade"))
        .map(|(_, a)| a.clone())
        .collect();
    let want = |name: &str| picked.is_empty() || picked.iter().any(|p| p == name);
    println!("hdi-tribology (this tree) against diffsol 0.18 (nalgebra dense LU)");
    if want("vdp") {
        compare(&problems::van_der_pol(), &rtols, &targets);
    }
    if want("robertson") {
        compare(&problems::robertson(), &rtols, &targets);
    }
    if want("hires") {
        compare(&problems::hires(), &rtols, &targets);
    }
    if want("orego") {
        compare(&problems::orego(), &rtols, &targets);
    }
    // E5: the error is relative with floor 1e-24; about three digits is the double-precision
    // limit (see tests/ode_testset.rs), so only 1e-2 … 1e-3 are compared.
    if want("e5") {
        let upto = rtols.iter().take_while(|&&r| r >= 1e-8 * 0.999).count();
        compare(&problems::e5(), &rtols[..upto], &[1e-2, 1e-3]);
    }
    if want("pleiades") {
        compare(&problems::pleiades(), &rtols, &targets);
    }
    println!("\ntotal {:.1} s", clock.elapsed().as_secs_f64());
}
