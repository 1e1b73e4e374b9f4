//! The main job: the paper's figures for the built-in paper scene.
//!
//! Writes SVG plots and CSV tables into `out/paper/` and prints a summary table:
//! - Fig. 1: contact indicator against heater power over a touchdown-triggered cycle;
//! - Fig. 2(b): clearance change against DC voltage, with a parabolic fit;
//! - Fig. 3(a–c): forces and spacing against time at 0 V and 0.6 V AC;
//! - Fig. 3(d): hysteresis against AC amplitude;
//! - Fig. 4: mean temperature rise against hysteresis, under both programmes.
//!
//! Run with `cargo run --release --example paper`; `-- --method NAME` picks another ODE method
//! (tsit5, dop853, rodas5p, radau5, auto) than the scene's.

use hdi_tribology::analysis::cycle::{CycleResult, TimeSeries};
use hdi_tribology::analysis::response::simulated_dither;
use hdi_tribology::analysis::*;
use hdi_tribology::model::{SliderModel, Voltage};
use hdi_tribology::report::{write_csv, Chart, Series};
use hdi_tribology::scene::Scene;
use std::path::Path;
use std::time::Instant;

type Res<T> = Result<T, Box<dyn std::error::Error>>;

fn main() -> Res<()> {
    let clock = Instant::now();
    let out = Path::new("out/paper");
    std::fs::create_dir_all(out)?;
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene)?;
    let static_opts = StaticOptions::new(scene.detector.contact_threshold_n);
    let mut opts = CycleOptions::from_scene(&scene)?;
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--method") {
        let name = args.get(i + 1).ok_or("--method needs a name")?;
        opts.solver.method = name.parse()?;
    }
    let fixed = HeaterProgramme::Fixed(SliderModel::programme_from_knots(&scene.heater.programme)?);
    let t = &scene.heater.triggered;
    let triggered = HeaterProgramme::Triggered {
        start_power: t.start_power_w,
        ramp_rate: t.ramp_rate_w_per_s,
        overshoot: t.overshoot_w,
    };
    let amplitudes: Vec<f64> = (0..=10).map(|i| i as f64 * 0.1).collect();

    // Static analyses.
    let curve = s_curve(&model, None, &ScanGrid::default())?;
    let stat = static_hysteresis(&model, &static_opts)?;
    let pull_in = pull_in_voltage(&model, 0.0, &static_opts)?;
    println!("# Paper scene: static analyses (V_dc = φ)");
    println!(
        "touchdown power   {:8.3} mW  ({:?} at d = {:.3} nm)",
        mw(stat.touchdown.power),
        stat.touchdown.cause,
        nm(stat.touchdown.at.d)
    );
    println!(
        "take-off power    {:8.3} mW  ({:?} at d = {:.3} nm)",
        mw(stat.takeoff.power),
        stat.takeoff.cause,
        nm(stat.takeoff.at.d)
    );
    println!("static hysteresis {:8.3} mW", mw(stat.hysteresis));
    println!(
        "pull-in voltage   {:8.3} V   at 0 mW ({:?})",
        pull_in.voltage, pull_in.cause
    );
    for f in &curve.folds {
        println!(
            "fold              {:8.3} mW  at d = {:.3} nm ({})",
            mw(f.power),
            nm(f.d),
            if f.jump_in {
                "flying branch ends"
            } else {
                "contact branch ends"
            }
        );
    }
    write_csv(
        &out.join("s_curve.csv"),
        &["d_m", "power_w", "stiffness_n_per_m", "contact_force_n"],
        &[
            &curve.points.iter().map(|p| p.d).collect::<Vec<_>>(),
            &curve.points.iter().map(|p| p.power).collect::<Vec<_>>(),
            &curve.points.iter().map(|p| p.stiffness).collect::<Vec<_>>(),
            &curve
                .points
                .iter()
                .map(|p| p.contact_force)
                .collect::<Vec<_>>(),
        ],
    )?;

    // Fig. 2(b): clearance change against DC voltage.
    let volts: Vec<f64> = (-10..=10).map(|i| i as f64 * 0.1).collect();
    let fh = clearance_change(&model, &volts, &static_opts)?;
    let dfh: Vec<f64> = fh.iter().map(|c| c.clearance_change).collect();
    let (a, b, c) = parabola_fit(&volts, &dfh);
    println!("\n# Fig. 2(b): clearance change against DC voltage");
    println!(
        "fit ΔFH = {:.4} nm/V² · V² + {:.2e} nm/V · V + {:.2e} nm",
        nm(a),
        nm(b),
        nm(c)
    );
    for v in [-1.0, -0.5, 0.5, 1.0] {
        let i = volts.iter().position(|x| (x - v).abs() < 1e-9).unwrap_or(0);
        println!("ΔFH({v:+.1} V) = {:.4} nm", nm(dfh[i]));
    }
    write_csv(
        &out.join("fig2b_clearance_vs_dc.csv"),
        &["v_dc", "clearance_change_m"],
        &[&volts, &dfh],
    )?;
    let fit: Vec<(f64, f64)> = (-100..=100)
        .map(|i| {
            let v = i as f64 * 0.01;
            (v, nm(a * v * v + b * v + c))
        })
        .collect();
    Chart {
        title: "Fig. 2(b) clearance change against DC voltage",
        x_label: "V_dc − φ (V)",
        y_label: "ΔFH (nm)",
        series: vec![
            Series {
                label: "static model",
                points: volts.iter().zip(&dfh).map(|(v, d)| (*v, nm(*d))).collect(),
                markers: true,
            },
            Series {
                label: "parabolic fit",
                points: fit,
                markers: false,
            },
        ],
        log: (false, false),
    }
    .to_svg(&out.join("fig2b_clearance_vs_dc.svg"), 800, 500)?;

    // Fig. 3(a–c): time series at 0 V and 0.6 V AC under the fixed programme.
    let mut with_series = opts;
    with_series.keep_series = true;
    let at = |v_ac: f64| {
        model.with_voltage(Voltage {
            ac_amplitude: v_ac,
            ..model.voltage
        })
    };
    let c0 = simulate_cycle(&at(0.0), &fixed, &with_series)?;
    let c6 = simulate_cycle(&at(0.6), &fixed, &with_series)?;
    for (name, cyc, title) in [
        ("fig3a_forces_0V", &c0, "Fig. 3(a) forces, V_ac = 0 V"),
        ("fig3c_forces_0.6V", &c6, "Fig. 3(c) forces, V_ac = 0.6 V"),
    ] {
        let s = series(cyc)?;
        s.write_csv(&out.join(format!("{name}.csv")))?;
        forces_chart(title, s, 0.0, f64::INFINITY).to_svg(
            &out.join(format!("{name}.svg")),
            1000,
            550,
        )?;
    }
    let s6 = series(&c6)?;
    let (z0, z1) = (2.0e-3, 2.2e-3);
    forces_chart("Fig. 3(b) zoom, V_ac = 0.6 V", s6, z0, z1).to_svg(
        &out.join("fig3b_zoom_forces_0.6V.svg"),
        1000,
        550,
    )?;
    Chart {
        title: "Fig. 3(b) zoom, spacing, V_ac = 0.6 V",
        x_label: "t (ms)",
        y_label: "d (nm)",
        series: vec![Series {
            label: "bulge gap d",
            points: window(s6, z0, z1, |s, i| nm(s.d[i])),
            markers: false,
        }],
        log: (false, false),
    }
    .to_svg(&out.join("fig3b_zoom_spacing_0.6V.svg"), 1000, 400)?;

    // Fig. 3(d) and Fig. 4: sweeps under both programmes. Where the AC makes contact
    // intermittent, the running mean hovers near F_th and the detected powers depend on the
    // tolerance: each amplitude is rerun with a tenfold tighter tolerance until touchdown and
    // take-off move by less than 1 % of the static hysteresis.
    let refine = Refinement::new(0.01 * stat.hysteresis);
    let sweep_clock = Instant::now();
    let fixed_refined = ac_sweep_refined(&model, &fixed, &opts, &amplitudes, &refine)?;
    let fixed_wall = sweep_clock.elapsed().as_secs_f64();
    let trig_refined = ac_sweep_refined(&model, &triggered, &opts, &amplitudes, &refine)?;
    println!(
        "\n# Fig. 3(d) / Fig. 4: cycles against AC amplitude (f = {} kHz, {}, rtol from {:e})",
        scene.voltage.ac_frequency_hz / 1e3,
        opts.solver.method,
        opts.solver.rtol,
    );
    println!("detection lags the running mean's window T_w = {:.1} µs: dynamic hysteresis is biased up by ≈ ramp × T_w", scene.detector.window_s * 1e6);
    println!(
        "{:>6} | {:>9} {:>9} {:>9} {:>7} {:>9} {:>7} | {:>9} {:>9} {:>7} {:>9} {:>7}",
        "V_ac",
        "P_TD",
        "P_TO",
        "ΔP",
        "rtol",
        "mean ΔT",
        "steps",
        "P_TD trig",
        "ΔP trig",
        "rtol",
        "ΔT trig",
        "ms"
    );
    let rtol = |r: &RefinedCycle| format!("{:.0e}{}", r.rtol, if r.converged { " " } else { "?" });
    for (fr, tr) in fixed_refined.iter().zip(&trig_refined) {
        let (f, t) = (&fr.cycle, &tr.cycle);
        println!(
            "{:>6.2} | {:>9} {:>9} {:>9} {:>7} {:>9.3} {:>7} | {:>9} {:>9} {:>7} {:>9.3} {:>7.1}",
            f.v_ac,
            opt_mw(f.touchdown.map(|d| d.power)),
            opt_mw(f.takeoff.map(|d| d.power)),
            opt_mw(f.hysteresis),
            rtol(fr),
            f.mean_temperature_rise,
            fr.stats.accepted,
            opt_mw(t.touchdown.map(|d| d.power)),
            opt_mw(t.hysteresis),
            rtol(tr),
            t.mean_temperature_rise,
            1e3 * (fr.wall_seconds + tr.wall_seconds),
        );
    }
    println!(
        "rtol: the tolerance at which touchdown and take-off moved by less than {:.3} mW from the \
         run before (\"?\": still moving at the last of {} runs: intermittent contact, the running \
         mean near F_th); steps and ms over all runs",
        mw(refine.power_tol),
        refine.max_runs
    );
    println!(
        "fixed-programme refined sweep of {} amplitudes: {:.1} ms wall",
        amplitudes.len(),
        1e3 * fixed_wall
    );
    println!("(powers in mW, ΔT in K)");
    let cycles = |s: &[RefinedCycle]| s.iter().map(|r| r.cycle.clone()).collect::<Vec<_>>();
    let (fixed_sweep, trig_sweep) = (cycles(&fixed_refined), cycles(&trig_refined));
    sweep_csv(
        &out.join("fig3d_hysteresis_vs_ac_fixed.csv"),
        &fixed_refined,
    )?;
    sweep_csv(&out.join("fig4_triggered_sweep.csv"), &trig_refined)?;
    let hyst = |s: &[CycleResult]| -> Vec<(f64, f64)> {
        s.iter()
            .filter_map(|r| r.hysteresis.map(|h| (r.v_ac, mw(h))))
            .collect()
    };
    Chart {
        title: "Fig. 3(d) hysteresis against AC amplitude, f = 10.5 kHz",
        x_label: "V_ac (V)",
        y_label: "P_TD − P_TO (mW)",
        series: vec![
            Series {
                label: "fixed programme",
                points: hyst(&fixed_sweep),
                markers: true,
            },
            Series {
                label: "touchdown-triggered",
                points: hyst(&trig_sweep),
                markers: true,
            },
            Series {
                label: "static, V_ac = 0",
                points: vec![(0.0, mw(stat.hysteresis)), (1.0, mw(stat.hysteresis))],
                markers: false,
            },
        ],
        log: (false, false),
    }
    .to_svg(&out.join("fig3d_hysteresis_vs_ac.svg"), 800, 500)?;
    let temp = |s: &[CycleResult]| -> Vec<(f64, f64)> {
        s.iter()
            .filter_map(|r| r.hysteresis.map(|h| (mw(h), r.mean_temperature_rise)))
            .collect()
    };
    Chart {
        title: "Fig. 4 mean temperature rise against hysteresis",
        x_label: "P_TD − P_TO (mW)",
        y_label: "mean ΔT (K)",
        series: vec![
            Series {
                label: "touchdown-triggered",
                points: temp(&trig_sweep),
                markers: true,
            },
            Series {
                label: "fixed programme",
                points: temp(&fixed_sweep),
                markers: true,
            },
        ],
        log: (false, false),
    }
    .to_svg(&out.join("fig4_temperature_vs_hysteresis.svg"), 800, 500)?;

    // Fig. 1: contact indicator against heater power over triggered cycles.
    let mut trig_series = Vec::new();
    for v in [0.0, 0.6] {
        let r = simulate_cycle(&at(v), &triggered, &with_series)?;
        let s = series(&r)?;
        s.write_csv(&out.join(format!("fig1_triggered_{v:.1}V.csv")))?;
        trig_series.push((v, r));
    }
    let mut fig1 = Vec::new();
    let labels = ["V_ac = 0 V", "V_ac = 0.6 V"];
    let marks = ["touchdown / take-off, 0 V", "touchdown / take-off, 0.6 V"];
    for (k, (_, r)) in trig_series.iter().enumerate() {
        let s = series(r)?;
        let pts = (0..s.t.len())
            .filter(|&i| s.indicator[i].is_finite())
            .map(|i| (mw(s.power[i]), s.indicator[i] * 1e6))
            .collect();
        fig1.push(Series {
            label: labels[k],
            points: pts,
            markers: false,
        });
        let th = scene.detector.contact_threshold_n * 1e6;
        let m: Vec<(f64, f64)> = [r.touchdown, r.takeoff]
            .iter()
            .flatten()
            .map(|d| (mw(d.power), th))
            .collect();
        fig1.push(Series {
            label: marks[k],
            points: m,
            markers: true,
        });
    }
    Chart {
        title: "Fig. 1 contact indicator over a touchdown-triggered cycle",
        x_label: "heater power (mW)",
        y_label: "running mean of F_c (µN)",
        series: fig1,
        log: (false, false),
    }
    .to_svg(&out.join("fig1_indicator_vs_power.svg"), 900, 550)?;

    // Linear response: predicted against simulated dither at 0.6 V.
    let m6 = at(0.6);
    let lr = linear_response(&m6, scene.heater.triggered.start_power_w)?;
    let sim = simulated_dither(&m6, scene.heater.triggered.start_power_w, &opts, 40, 10)?;
    println!(
        "\n# Linear response at {} mW, V_ac = 0.6 V",
        mw(scene.heater.triggered.start_power_w)
    );
    if let Some(mode) = lr.modes.iter().find(|m| m.im > 0.0) {
        println!(
            "air-bearing mode {:.2} kHz, damping ratio {:.4}",
            mode.frequency / 1e3,
            mode.damping_ratio
        );
    }
    println!(
        "dither at 2f: predicted {:.5} nm, simulated {:.5} nm",
        nm(lr.dither_amplitude),
        nm(sim)
    );
    println!(
        "\nwrote SVG and CSV files to {}; total {:.2} s",
        out.display(),
        clock.elapsed().as_secs_f64()
    );
    Ok(())
}

fn mw(p: f64) -> f64 {
    p * 1e3
}

fn nm(x: f64) -> f64 {
    x * 1e9
}

fn opt_mw(p: Option<f64>) -> String {
    p.map_or("—".to_string(), |p| format!("{:.3}", mw(p)))
}

/// Least-squares parabola `a x² + b x + c`.
fn parabola_fit(x: &[f64], y: &[f64]) -> (f64, f64, f64) {
    use nalgebra::{DMatrix, DVector};
    let a = DMatrix::from_fn(x.len(), 3, |i, j| x[i].powi(2 - j as i32));
    let sol = a
        .svd(true, true)
        .solve(&DVector::from_column_slice(y), 1e-30)
        .unwrap_or(DVector::zeros(3));
    (sol[0], sol[1], sol[2])
}

fn series(r: &CycleResult) -> Res<&TimeSeries> {
    r.series
        .as_ref()
        .ok_or_else(|| "cycle kept no time series".into())
}

fn window(
    s: &TimeSeries,
    t0: f64,
    t1: f64,
    f: impl Fn(&TimeSeries, usize) -> f64,
) -> Vec<(f64, f64)> {
    (0..s.t.len())
        .filter(|&i| s.t[i] >= t0 && s.t[i] <= t1)
        .map(|i| (s.t[i] * 1e3, f(s, i)))
        .collect()
}

fn forces_chart<'a>(title: &'a str, s: &TimeSeries, t0: f64, t1: f64) -> Chart<'a> {
    let un = |f: fn(&TimeSeries, usize) -> f64| window(s, t0, t1, move |s, i| f(s, i) * 1e3);
    Chart {
        title,
        x_label: "t (ms)",
        y_label: "force (mN)",
        series: vec![
            Series {
                label: "total",
                points: un(|s, i| s.total[i]),
                markers: false,
            },
            Series {
                label: "air bearing",
                points: un(|s, i| s.air_bearing[i]),
                markers: false,
            },
            Series {
                label: "intermolecular",
                points: un(|s, i| s.intermolecular[i]),
                markers: false,
            },
            Series {
                label: "electrostatic",
                points: un(|s, i| s.electrostatic[i]),
                markers: false,
            },
            Series {
                label: "contact",
                points: un(|s, i| s.contact[i]),
                markers: false,
            },
        ],
        log: (false, false),
    }
}

fn sweep_csv(path: &Path, rs: &[RefinedCycle]) -> Res<()> {
    let col = |f: &dyn Fn(&RefinedCycle) -> f64| rs.iter().map(f).collect::<Vec<f64>>();
    write_csv(
        path,
        &[
            "v_ac",
            "touchdown_power_w",
            "takeoff_power_w",
            "hysteresis_w",
            "mean_temperature_rise_k",
            "rtol",
            "power_change_w",
            "converged",
            "runs",
            "steps",
            "wall_seconds",
        ],
        &[
            &col(&|r| r.cycle.v_ac),
            &col(&|r| r.cycle.touchdown.map_or(f64::NAN, |d| d.power)),
            &col(&|r| r.cycle.takeoff.map_or(f64::NAN, |d| d.power)),
            &col(&|r| r.cycle.hysteresis.unwrap_or(f64::NAN)),
            &col(&|r| r.cycle.mean_temperature_rise),
            &col(&|r| r.rtol),
            &col(&|r| r.change),
            &col(&|r| f64::from(u8::from(r.converged))),
            &col(&|r| r.runs as f64),
            &col(&|r| r.stats.accepted as f64),
            &col(&|r| r.wall_seconds),
        ],
    )?;
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
