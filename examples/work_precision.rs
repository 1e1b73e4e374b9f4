//! Error against run time for every ODE method on standard test problems and on the slider.
//!
//! Solves each problem with each method at relative tolerances 1e-3 … 1e-12, prints a table
//! (problem, method, rtol, error against the reference, wall time, steps, right-hand-side
//! evaluations), writes it to `out/work_precision/table.csv` and draws one log–log chart of
//! error against wall time per problem into the same folder.
//!
//! Problems: a non-stiff one with a closed-form solution, Van der Pol (μ = 1000), Robertson to
//! 1e11, HIRES, OREGO, E5 and Pleiades against the Test Set for IVP Solvers, and the paper
//! scene's fixed-programme
//! touchdown/take-off cycle at V_ac = 0 and 0.6 V, whose errors are |ΔP − ΔP_ref| and
//! |P_TD − P_TD,ref| against a reference computed at rtol 1e-11 (Tsit5, cross-checked with
//! Radau5; the difference of the two is printed).
//!
//! Run with `cargo run --release --example work_precision`; `-- --quick` runs every second
//! tolerance only, `-- --out DIR` writes into `DIR`; `-- --stepping` prints only the cost of
//! stepping the `Integrator` by hand against `solve` (Van der Pol, interleaved runs, CPU time);
//! `-- --slider` runs only the slider rows (no table file, no charts, no sweep report).
//! Once a run has taken more than a few seconds, progress (problem and method done, time so far)
//! goes to stderr; the table stays on stdout.

#[path = "common/output.rs"]
mod output;
#[path = "common/problems.rs"]
mod problems;
#[path = "common/slider_reference.rs"]
mod slider_reference;
#[path = "common/timing.rs"]
mod timing;

use slider_reference::{SLIDER_ATOL_PER_RTOL, SLIDER_REF_RTOL};

use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, CycleResult, HeaterProgramme};
use hdi_tribology::analysis::sweep::ac_sweep;
use hdi_tribology::model::{SliderModel, Voltage};
use hdi_tribology::ode::{solve, Integrator, Method, OdeError, Stats, StepStatus};
use hdi_tribology::report::{palette, Chart, Series};
use hdi_tribology::scene::Scene;
use problems::Problem;
use std::path::Path;
use std::time::{Duration, Instant};

type Res<T> = Result<T, Box<dyn std::error::Error>>;

/// Step cap for explicit methods on stiff problems: far more than any method needs where it is
/// stable, reached in milliseconds when stability, not accuracy, limits the step.
const EXPLICIT_STEP_CAP: usize = 200_000;

/// Repeat a run until this much time has been spent (at least `MIN_REPEATS` times) and keep the
/// fastest repetition: on a shared machine the minimum is the least disturbed run.
const TIMING_BUDGET: Duration = Duration::from_millis(100);
const MIN_REPEATS: usize = 3;
const MAX_REPEATS: usize = 100_000;

/// One row of the table.
struct Row {
    problem: String,
    method: Method,
    rtol: f64,
    /// Error against the reference (the ΔP error for the slider); NaN on failure.
    error: f64,
    /// Second error (|P_TD − P_TD,ref| for the slider); NaN for the standard problems.
    error2: f64,
    /// Fastest wall time of the repetitions (s).
    wall: f64,
    /// Mean CPU time of this thread per repetition (s).
    cpu: f64,
    stats: Stats,
    status: String,
}

/// Runs `f` repeatedly within the timing budget: last value, fastest wall time, mean CPU time.
fn timed<T>(f: impl FnMut() -> T) -> (T, f64, f64) {
    let (out, t) = timing::measure(MIN_REPEATS, MAX_REPEATS, TIMING_BUDGET, f);
    (out, t.wall, t.cpu)
}

fn explicit(m: Method) -> bool {
    matches!(m, Method::Tsit5 | Method::Dop853)
}

fn failure_status(method: Method, stiff: bool, e: &OdeError) -> String {
    match e {
        OdeError::TooManySteps { .. } if stiff && explicit(method) => "failed (stiff)".into(),
        // Rodas5P on E5: its linear algebra cannot resolve the tolerance asked for.
        OdeError::RoundingFloor { t, component, .. } => {
            format!("refused (rounding floor, y[{component}] at t = {t:.3e})")
        }
        OdeError::InvalidInput { .. } if e.to_string().contains("not available") => {
            "unavailable".into()
        }
        other => format!("failed: {other}"),
    }
}

/// Progress on stderr once the run is longer than `PROGRESS_AFTER`.
struct Progress(Instant);

const PROGRESS_AFTER: Duration = Duration::from_secs(3);

impl Progress {
    fn done(&self, what: &str) {
        let t = self.0.elapsed();
        if t >= PROGRESS_AFTER {
            eprintln!("[{:6.1} s] {what} done", t.as_secs_f64());
        }
    }
}

fn run_problem<const N: usize>(
    p: &Problem<N>,
    rtols: &[f64],
    rows: &mut Vec<Row>,
    progress: &Progress,
) {
    for method in Method::ALL {
        run_method(p, method, rtols, rows);
        progress.done(&format!("{} {method}", p.name));
    }
}

fn run_method<const N: usize>(p: &Problem<N>, method: Method, rtols: &[f64], rows: &mut Vec<Row>) {
    {
        for &rtol in rtols {
            let mut opts = p.options(rtol).max_steps(2_000_000);
            if p.stiff && explicit(method) {
                opts = opts.max_steps(EXPLICIT_STEP_CAP);
            }
            let (res, wall, cpu) =
                timed(|| solve(p, 0.0, p.y0_vector(), p.t_end, method, &opts, &mut []));
            let row = match res {
                Ok(sol) => Row {
                    problem: p.name.into(),
                    method,
                    rtol,
                    error: p.error(sol.y_final().as_slice()),
                    error2: f64::NAN,
                    wall,
                    cpu,
                    stats: sol.stats,
                    status: "ok".into(),
                },
                Err(e) => Row {
                    problem: p.name.into(),
                    method,
                    rtol,
                    error: f64::NAN,
                    error2: f64::NAN,
                    wall: f64::NAN,
                    cpu: f64::NAN,
                    stats: Stats::default(),
                    status: failure_status(method, p.stiff, &e),
                },
            };
            let unavailable = row.status == "unavailable";
            print_row(&row);
            rows.push(row);
            if unavailable {
                break;
            }
        }
    }
}

struct Slider {
    scene: Scene,
    model: SliderModel,
    programme: HeaterProgramme,
}

impl Slider {
    fn new() -> Res<Self> {
        let scene = Scene::paper();
        let model = SliderModel::from_scene(&scene)?;
        let programme = HeaterProgramme::fixed_from_scene(&scene)?;
        Ok(Slider {
            scene,
            model,
            programme,
        })
    }

    fn cycle(&self, v_ac: f64, method: Method, rtol: f64) -> hdi_tribology::Result<CycleResult> {
        let model = self.model.with_voltage(Voltage {
            ac_amplitude: v_ac,
            ..self.model.voltage()
        });
        let mut opts = CycleOptions::from_scene(&self.scene)?;
        opts.solver.method = method;
        opts.solver.rtol = rtol;
        opts.solver.atol_displacement = rtol * SLIDER_ATOL_PER_RTOL;
        simulate_cycle(&model, &self.programme, &opts)
    }
}

/// `(ΔP, P_TD)` of a cycle, if both touchdown and take-off were detected.
fn outputs(r: &CycleResult) -> Option<(f64, f64)> {
    Some((r.hysteresis?, r.touchdown?.power))
}

fn run_slider(slider: &Slider, v_ac: f64, rtols: &[f64], rows: &mut Vec<Row>) -> Res<()> {
    let name = format!("slider_{v_ac:.1}V");
    eprintln!("work_precision: {name}, references and every method …");
    let clock = Instant::now();
    let reference = slider.cycle(v_ac, Method::Tsit5, SLIDER_REF_RTOL)?;
    let (dp_ref, ptd_ref) = outputs(&reference).ok_or("reference cycle without touchdown")?;
    let check = slider.cycle(v_ac, Method::Radau5, SLIDER_REF_RTOL)?;
    let (dp_chk, ptd_chk) = outputs(&check).ok_or("check cycle without touchdown")?;
    println!(
        "# {name}: reference (tsit5, rtol {SLIDER_REF_RTOL:.0e}) ΔP = {dp_ref:.9e} W, \
         P_TD = {ptd_ref:.9e} W; radau5 differs by {:.1e} W, {:.1e} W ({:.1} s)",
        (dp_chk - dp_ref).abs(),
        (ptd_chk - ptd_ref).abs(),
        clock.elapsed().as_secs_f64()
    );
    for method in Method::ALL {
        for &rtol in rtols {
            let (res, wall, cpu) = timed(|| slider.cycle(v_ac, method, rtol));
            let row = match res {
                Ok(r) => match outputs(&r) {
                    Some((dp, ptd)) => Row {
                        problem: name.clone(),
                        method,
                        rtol,
                        error: (dp - dp_ref).abs(),
                        error2: (ptd - ptd_ref).abs(),
                        wall,
                        cpu,
                        stats: r.stats,
                        status: "ok".into(),
                    },
                    None => Row {
                        problem: name.clone(),
                        method,
                        rtol,
                        error: f64::NAN,
                        error2: f64::NAN,
                        wall,
                        cpu,
                        stats: r.stats,
                        status: "failed: no touchdown or take-off detected".into(),
                    },
                },
                Err(e) => Row {
                    problem: name.clone(),
                    method,
                    rtol,
                    error: f64::NAN,
                    error2: f64::NAN,
                    wall: f64::NAN,
                    cpu: f64::NAN,
                    stats: Stats::default(),
                    status: if e.to_string().contains("not available") {
                        "unavailable".into()
                    } else {
                        format!("failed: {e}")
                    },
                },
            };
            let unavailable = row.status == "unavailable";
            print_row(&row);
            rows.push(row);
            if unavailable {
                break;
            }
        }
    }
    Ok(())
}

/// Two references closer than this (W) resolve a point of the sweep.
const RESOLVED: f64 = 1e-8;

/// The scene's 11-point AC sweep with its own solver settings on the default thread pool,
/// against reference sweeps at rtol 1e-11 (Tsit5 and Radau5): wall time and largest errors over
/// the amplitudes where the two references agree.
fn sweep_report(slider: &Slider) -> Res<()> {
    eprintln!("work_precision: AC sweeps of the slider …");
    let amplitudes: Vec<f64> = (0..=10).map(|i| f64::from(i) * 0.1).collect();
    let reference_sweep = |method: Method| -> Res<Vec<CycleResult>> {
        let mut o = CycleOptions::from_scene(&slider.scene)?;
        o.solver.method = method;
        o.solver.rtol = SLIDER_REF_RTOL;
        o.solver.atol_displacement = SLIDER_REF_RTOL * SLIDER_ATOL_PER_RTOL;
        Ok(ac_sweep(&slider.model, &slider.programme, &o, &amplitudes)?)
    };
    let reference = reference_sweep(Method::Tsit5)?;
    let check = reference_sweep(Method::Radau5)?;
    // A point is resolved when both references give ΔP and P_TD within RESOLVED.
    let resolved: Vec<bool> = reference
        .iter()
        .zip(&check)
        .map(|(a, b)| match (outputs(a), outputs(b)) {
            (Some(x), Some(y)) => (x.0 - y.0).abs() < RESOLVED && (x.1 - y.1).abs() < RESOLVED,
            _ => false,
        })
        .collect();
    let scene_opts = CycleOptions::from_scene(&slider.scene)?;
    let scene_runs = ac_sweep(&slider.model, &slider.programme, &scene_opts, &amplitudes)?;
    println!(
        "\n# 11-point AC sweep per amplitude: scene settings ({}, rtol {:.0e}) against the references",
        scene_opts.solver.method, scene_opts.solver.rtol
    );
    println!(
        "{:>5} {:>13} {:>13} {:>13} {:>13} {:>13}  reference",
        "V_ac", "ΔP", "ΔP_ref tsit5", "ΔP_ref radau5", "P_TD", "P_TD,ref"
    );
    let fmt = |x: Option<(f64, f64)>, first: bool| {
        x.map_or("none".to_string(), |v| {
            format!("{:.6e}", if first { v.0 } else { v.1 })
        })
    };
    for ((r, rf), (rc, ok)) in scene_runs
        .iter()
        .zip(&reference)
        .zip(check.iter().zip(&resolved))
    {
        println!(
            "{:>5.1} {:>13} {:>13} {:>13} {:>13} {:>13}  {}",
            r.v_ac,
            fmt(outputs(r), true),
            fmt(outputs(rf), true),
            fmt(outputs(rc), true),
            fmt(outputs(r), false),
            fmt(outputs(rf), false),
            if *ok { "resolved" } else { "UNRESOLVED" }
        );
    }
    println!(
        "\n# 11-point AC sweep: wall time ({} threads) and largest errors over the {} resolved amplitudes",
        rayon_threads(),
        resolved.iter().filter(|&&r| r).count()
    );
    for method in [
        scene_opts.solver.method,
        Method::Tsit5,
        Method::Dop853,
        Method::Rodas5P,
        Method::Radau5,
    ] {
        let mut opts = scene_opts;
        opts.solver.method = method;
        let (res, wall, _) =
            timed(|| ac_sweep(&slider.model, &slider.programme, &opts, &amplitudes));
        let runs = res?;
        let (mut e_dp, mut e_ptd) = (0.0_f64, 0.0_f64);
        for ((r, rf), _) in runs
            .iter()
            .zip(&reference)
            .zip(&resolved)
            .filter(|(_, ok)| **ok)
        {
            match (outputs(r), outputs(rf)) {
                (Some((dp, ptd)), Some((dp_ref, ptd_ref))) => {
                    e_dp = e_dp.max((dp - dp_ref).abs());
                    e_ptd = e_ptd.max((ptd - ptd_ref).abs());
                }
                _ => {
                    e_dp = f64::NAN;
                    e_ptd = f64::NAN;
                }
            }
        }
        println!(
            "sweep {:<8} wall {:8.2} ms   max |ΔP − ΔP_ref| {:.2e} W   max |P_TD − P_TD,ref| {:.2e} W",
            method.name(),
            wall * 1e3,
            e_dp,
            e_ptd
        );
    }
    Ok(())
}

fn rayon_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

fn print_header() {
    println!(
        "{:<14} {:<8} {:>7} {:>10} {:>10} {:>10} {:>10} {:>8} {:>6} {:>9}  status",
        "problem", "method", "rtol", "error", "error2", "wall_ms", "cpu_ms", "steps", "rej", "rhs"
    );
}

fn print_row(r: &Row) {
    println!(
        "{:<14} {:<8} {:>7.0e} {:>10.2e} {:>10.2e} {:>10.4} {:>10.4} {:>8} {:>6} {:>9}  {}",
        r.problem,
        r.method.name(),
        r.rtol,
        r.error,
        r.error2,
        r.wall * 1e3,
        r.cpu * 1e3,
        r.stats.accepted,
        r.stats.rejected,
        r.stats.rhs_evals,
        r.status
    );
}

fn write_table(path: &Path, rows: &[Row]) -> Res<()> {
    let mut s = String::from(
        "problem,method,rtol,error,error2,wall_s,cpu_s,steps,rejected,rhs_evals,jac_evals,lu_decomps,status\n",
    );
    let num = |v: f64| {
        if v.is_finite() {
            format!("{v:e}")
        } else {
            String::new()
        }
    };
    for r in rows {
        s.push_str(&format!(
            "{},{},{:e},{},{},{},{},{},{},{},{},{},{}\n",
            r.problem,
            r.method.name(),
            r.rtol,
            num(r.error),
            num(r.error2),
            num(r.wall),
            num(r.cpu),
            r.stats.accepted,
            r.stats.rejected,
            r.stats.rhs_evals,
            r.stats.jac_evals,
            r.stats.lu_decomps,
            r.status.replace(',', ";")
        ));
    }
    std::fs::write(path, s)?;
    Ok(())
}

/// One chart of `error` (or `error2`) against CPU time, one line per method.
fn chart(
    out: &Path,
    problem: &str,
    file: &str,
    y_label: &str,
    rows: &[Row],
    second: bool,
) -> Res<()> {
    let labels: Vec<String> = Method::ALL.iter().map(|m| m.name().to_string()).collect();
    // Each method keeps its colour in every chart, whichever methods have points.
    let series: Vec<Series> = Method::ALL
        .iter()
        .zip(&labels)
        .zip(palette::SERIES.iter().cycle())
        .filter_map(|((&m, label), &colour)| {
            let points: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.problem == problem && r.method == m && r.status == "ok")
                .map(|r| (r.cpu * 1e3, if second { r.error2 } else { r.error }))
                .filter(|&(_, e)| e > 0.0)
                .map(|(t, e)| (t.log10(), e.log10()))
                .collect();
            (!points.is_empty()).then(|| Series::line(label, points).colour(colour))
        })
        .collect();
    if series.is_empty() {
        return Ok(());
    }
    let title = format!("{problem}: error against run time (log–log)");
    let y_label = format!("log10 {y_label}");
    // Decimal logarithms on linear axes: tick labels read as exponents.
    Chart {
        title: &title,
        x_label: "log10 CPU time of the thread (ms)",
        y_label: &y_label,
        series,
        ..Chart::default()
    }
    .to_svg(&out.join(file), 720, 480)?;
    Ok(())
}

fn main() -> Res<()> {
    let clock = Instant::now();
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.iter().any(|a| a == "--stepping") {
        return stepping_overhead();
    }
    let out = &output::out_dir("work_precision", &args)?;
    let quick = args.iter().any(|a| a == "--quick");
    let all: Vec<f64> = (3..=12).map(|k| 10f64.powi(-k)).collect();
    let rtols: Vec<f64> = if quick {
        all.iter().copied().step_by(2).collect()
    } else {
        all.clone()
    };
    // Tighter than 1e-9 is within a few hundred of the slider reference's own tolerance.
    let slider_rtols: Vec<f64> = rtols.iter().copied().filter(|&r| r >= 1e-9).collect();

    let mut rows = Vec::new();
    let progress = Progress(clock);
    print_header();
    if args.iter().any(|a| a == "--slider") {
        let slider = Slider::new()?;
        for v_ac in [0.0, 0.6] {
            run_slider(&slider, v_ac, &slider_rtols, &mut rows)?;
        }
        return Ok(());
    }
    run_problem(&problems::exact(), &rtols, &mut rows, &progress);
    run_problem(&problems::van_der_pol(), &rtols, &mut rows, &progress);
    run_problem(&problems::robertson(), &rtols, &mut rows, &progress);
    run_problem(&problems::hires(), &rtols, &mut rows, &progress);
    run_problem(&problems::orego(), &rtols, &mut rows, &progress);
    run_problem(&problems::e5(), &rtols, &mut rows, &progress);
    run_problem(&problems::pleiades(), &rtols, &mut rows, &progress);
    let slider = Slider::new()?;
    for v_ac in [0.0, 0.6] {
        run_slider(&slider, v_ac, &slider_rtols, &mut rows)?;
        progress.done(&format!("slider at {v_ac:.1} V"));
    }

    sweep_report(&slider)?;

    write_table(&out.join("table.csv"), &rows)?;
    for (p, label) in [
        ("exact", "max abs error at t = 10"),
        ("vdp", "max rel error at t = 2000"),
        ("robertson", "max rel error at t = 1e11"),
        ("hires", "max rel error at t = 321.8122"),
        ("orego", "max rel error at t = 360"),
        ("e5", "max rel error (floor 1e-24) at t = 1e13"),
        ("pleiades", "max rel error at t = 3"),
    ] {
        chart(out, p, &format!("{p}.svg"), label, &rows, false)?;
    }
    for p in ["slider_0.0V", "slider_0.6V"] {
        chart(
            out,
            p,
            &format!("{p}_dp.svg"),
            "|ΔP − ΔP_ref| (W)",
            &rows,
            false,
        )?;
        chart(
            out,
            p,
            &format!("{p}_ptd.svg"),
            "|P_TD − P_TD,ref| (W)",
            &rows,
            true,
        )?;
    }
    println!(
        "wrote {} rows to {} in {:.1} s",
        rows.len(),
        out.display(),
        clock.elapsed().as_secs_f64()
    );
    Ok(())
}

/// CPU time of `solve` against the same integration stepped by hand (`Integrator::step` until
/// the end), on Van der Pol with every stiff method at rtol 1e-6 and 1e-8. The two are run in
/// alternation, 15 rounds of at least 100 ms each, so that both see the same machine load; the
/// median of the per-round ratios is printed.
fn stepping_overhead() -> Res<()> {
    let p = problems::van_der_pol();
    println!(
        "| method | rtol | solve CPU (ms) | stepped CPU (ms) | median stepped/solve | steps |"
    );
    println!("|---|---|---|---|---|---|");
    for method in [Method::Rodas5P, Method::Radau5, Method::Auto, Method::Tsit5] {
        for rtol in [1e-6, 1e-8] {
            let mut opts = p.options(rtol);
            if method == Method::Tsit5 {
                opts = opts.max_steps(EXPLICIT_STEP_CAP * 10);
            }
            let mut ratios = Vec::new();
            let (mut a_sum, mut b_sum) = (0.0, 0.0);
            let mut steps = 0;
            for _ in 0..15 {
                let (sol, _, a) =
                    timed(|| solve(&p, 0.0, p.y0_vector(), p.t_end, method, &opts, &mut []));
                let (end, _, b) = timed(|| {
                    let mut it = Integrator::new(&p, 0.0, p.y0_vector(), p.t_end, method, &opts)?;
                    while it.step()? != StepStatus::ReachedEnd {}
                    Ok::<_, OdeError>(*it.state())
                });
                let sol = sol?;
                // The same steps, bit for bit.
                assert_eq!(sol.y_final(), &end?);
                steps = sol.stats.accepted;
                ratios.push(b / a);
                a_sum += a;
                b_sum += b;
            }
            ratios.sort_by(f64::total_cmp);
            println!(
                "| {method} | {rtol:.0e} | {:.4} | {:.4} | {:.3} | {steps} |",
                a_sum / 15.0 * 1e3,
                b_sum / 15.0 * 1e3,
                ratios[7]
            );
        }
    }
    Ok(())
}
