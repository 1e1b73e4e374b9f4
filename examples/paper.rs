//! The main job: the paper's figures for the built-in paper scene.
//!
//! Writes SVG plots and CSV tables into the output directory and prints a summary table:
//! - Fig. 1: the contact indicator (normalized by the threshold F_th) against the heater power
//!   measured from touchdown, over touchdown-triggered cycles (`--fig1-absolute`: against the
//!   absolute power, in µN);
//! - Fig. 2(b): clearance change against DC voltage, with a parabolic fit;
//! - Fig. 3(a), (c): forces against time at 0 V and 0.6 V AC, on one y range;
//! - Fig. 3(b): a zoom of the total, electrostatic and air-bearing forces at 0.6 V with the
//!   spacing on a second axis, in the letter's colours;
//! - Fig. 3(d): hysteresis against AC amplitude under both programmes;
//! - Fig. 4: mean temperature rise against hysteresis, under both programmes.
//!
//! Fig. 3(d) and Fig. 4 come in two panels on the same axes, to be shown side by side: the rigid
//! slider of the paper scene, and the deformable slider of `scenes/paper_bulge.toml` (`_bulge`
//! in the file name). The summary prints the bulge's touchdown, take-off and hysteresis next to
//! the rigid slider's, with the status and flags `hdi sweep` reports.
//!
//! In Fig. 3(d) and Fig. 4 a point whose powers did not agree over the last three tolerances is
//! drawn hollow, a negative hysteresis (not physical) as a cross, and an amplitude without a
//! touchdown or take-off is named in a note on the figure.
//!
//! Run with `cargo run --release --example paper -- [--out DIR] [--method NAME]
//! [--fig1-absolute] [--wall-seconds]`. The output directory is `DIR`, else
//! `$HDI_OUT_DIR/paper`, else `out/paper`. `--method` picks another ODE method (tsit5, dop853,
//! rodas5p, radau5, auto) than the scene's; `--wall-seconds` adds the run-dependent wall time
//! to the sweep tables.

use hdi_tribology::analysis::response::simulated_dither;
use hdi_tribology::analysis::*;
use hdi_tribology::model::{SliderModel, Voltage};
use hdi_tribology::ode::Method;
use hdi_tribology::report::{palette, write_csv, Chart, Colour, CsvTable, Marker, Series};
use hdi_tribology::scene::Scene;
use std::path::Path;
use std::time::Instant;

#[path = "common/doc_numbers.rs"]
#[allow(dead_code)]
pub mod doc_numbers;
#[path = "common/figures.rs"]
#[allow(dead_code)]
mod figures;
#[path = "common/output.rs"]
mod output;

type Res<T> = Result<T, Box<dyn std::error::Error>>;

/// What the command line asks for besides the output directory.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// An ODE method other than the scene's.
    method: Option<Method>,
    /// Fig. 1 against the absolute heater power, the indicator in µN.
    fig1_absolute: bool,
    /// Add the wall time (different on every run) to the sweep tables.
    wall_seconds: bool,
}

impl Options {
    fn parse(args: &[String]) -> Res<Self> {
        let method = match args.iter().position(|a| a == "--method") {
            Some(i) => Some(args.get(i + 1).ok_or("--method needs a name")?.parse()?),
            None => None,
        };
        Ok(Options {
            method,
            fig1_absolute: args.iter().any(|a| a == "--fig1-absolute"),
            wall_seconds: args.iter().any(|a| a == "--wall-seconds"),
        })
    }
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let options = Options::parse(&args)?;
    let out = output::out_dir("paper", &args)?;
    run(&options, &out).map(|_| ())
}

/// The fixed programme's colour and marker in every figure.
const FIXED: (Colour, Marker) = (palette::BLUE, Marker::Circle);
/// The touchdown-triggered programme's colour and marker in every figure.
const TRIGGERED: (Colour, Marker) = (palette::VERMILION, Marker::Triangle);

/// What the example computed, for the numbers the docs quote ([`doc_numbers`]).
pub struct Summary {
    /// The rigid slider's static loop.
    pub stat: StaticHysteresis,
    /// The rigid slider's sweeps and single results.
    pub rigid: Rigid,
    /// The bulge's static loop and sweep.
    pub bulge: Bulge,
    /// The refinement every sweep used.
    pub refine: Refinement,
}

/// Computes everything and writes the files into `out`.
pub fn run(options: &Options, out: &Path) -> Res<Summary> {
    let clock = Instant::now();
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene)?;
    let static_opts = StaticOptions::from_scene(&scene);
    let stat = static_hysteresis(&model, &static_opts)?;
    // From integer counts, each the decimal it names: i / 10 is 0.3 where i · 0.1 is
    // 0.30000000000000004.
    let amplitudes: Vec<f64> = (0..=10).map(|i| f64::from(i) / 10.0).collect();
    // Where the AC makes contact intermittent, the running mean hovers near F_th and the
    // detected powers depend on the tolerance: each amplitude is rerun with a tenfold tighter
    // tolerance until touchdown and take-off move by less than 1 % of the rigid slider's static
    // hysteresis, on both structures, in three successive runs: with AC a take-off can land a
    // whole period of V² early in two successive runs alike (the bulge at 0.8 V does).
    let refine = Refinement {
        agreeing_runs: 3,
        max_runs: 5,
        ..Refinement::new(0.01 * stat.hysteresis)
    };

    // The bulge's refined sweep is the longest single job (its 0.8 V point runs five cycles,
    // down to rtol 1e-10): it starts first and runs beside the rigid slider's figures.
    let (rigid, bulge) = std::thread::scope(|s| -> Res<_> {
        let bulge = s.spawn(|| Bulge::run(options, &amplitudes, &refine));
        let rigid = rigid_slider(options, out, &scene, &model, &stat, &refine, &amplitudes);
        let bulge = bulge
            .join()
            .map_err(|_| "the bulge sweep stopped unexpectedly")?;
        Ok((rigid?, bulge?))
    })?;
    let (fixed_refined, trig_refined) = (&rigid.fixed, &rigid.triggered);

    // The rigid and bulge panels of Fig. 3(d) and Fig. 4, on the same axes.
    bulge.print(fixed_refined, &stat);
    sweep_table(&bulge.fixed, options.wall_seconds)
        .write(&out.join("fig3d_hysteresis_vs_ac_bulge_fixed.csv"))?;
    let rigid_sweeps = [
        Sweep {
            name: "fixed programme",
            style: FIXED,
            results: fixed_refined,
        },
        Sweep {
            name: "touchdown-triggered programme",
            style: TRIGGERED,
            results: trig_refined,
        },
    ];
    let bulge_sweeps = [Sweep {
        name: "fixed programme",
        style: FIXED,
        results: &bulge.fixed,
    }];
    let mut fig3d = [
        fig3d_chart(RIGID_TITLES[0], &rigid_sweeps, stat.hysteresis, &refine),
        fig3d_chart(
            BULGE_TITLES[0],
            &bulge_sweeps,
            bulge.stat.hysteresis,
            &refine,
        ),
    ];
    let mut fig4 = [
        fig4_chart(RIGID_TITLES[1], &rigid_sweeps, &refine),
        fig4_chart(BULGE_TITLES[1], &bulge_sweeps, &refine),
    ];
    share_ranges(&mut fig3d, true);
    // Fig. 4's panels differ by a factor of ten in temperature: each fits its data.
    share_ranges(&mut fig4, false);
    let files = [
        [
            "fig3d_hysteresis_vs_ac.svg",
            "fig3d_hysteresis_vs_ac_bulge.svg",
        ],
        [
            "fig4_temperature_vs_hysteresis.svg",
            "fig4_temperature_vs_hysteresis_bulge.svg",
        ],
    ];
    for (charts, names) in [fig3d, fig4].iter().zip(files) {
        for (chart, name) in charts.iter().zip(names) {
            chart.to_svg(&out.join(name), PANEL.0, PANEL.1)?;
        }
    }
    println!(
        "\nwrote SVG and CSV files to {}; total {:.2} s",
        out.display(),
        clock.elapsed().as_secs_f64()
    );
    Ok(Summary {
        stat,
        rigid,
        bulge,
        refine,
    })
}

/// The rigid slider's refined sweeps and the single numbers its figures rest on.
pub struct Rigid {
    /// The refined sweep under the fixed programme.
    pub fixed: Vec<RefinedCycle>,
    /// The refined sweep under the touchdown-triggered programme.
    pub triggered: Vec<RefinedCycle>,
    /// The x² coefficient of the parabola through ΔFH(V_dc) (m/V²).
    pub parabola: f64,
    /// The dither amplitude at 2f at 60 mW and 0.6 V: predicted, simulated (m).
    pub dither: (f64, f64),
}

/// The rigid slider of the paper scene: prints its static analyses, writes every figure but
/// Fig. 3(d) and Fig. 4, and returns its refined sweeps under the fixed and the triggered
/// programme.
fn rigid_slider(
    options: &Options,
    out: &Path,
    scene: &Scene,
    model: &SliderModel,
    stat: &StaticHysteresis,
    refine: &Refinement,
    amplitudes: &[f64],
) -> Res<Rigid> {
    let static_opts = StaticOptions::from_scene(scene);
    let mut opts = CycleOptions::from_scene(scene)?;
    if let Some(m) = options.method {
        opts.solver.method = m;
    }
    let fixed = HeaterProgramme::fixed_from_scene(scene)?;
    let triggered = HeaterProgramme::triggered_from_scene(scene);

    // Static analyses.
    let curve = s_curve(model, None, &ScanGrid::default())?;
    let pull_in = pull_in_voltage(model, 0.0, &static_opts)?;
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
    let col = |f: fn(&Equilibrium) -> f64| curve.points.iter().map(f).collect::<Vec<f64>>();
    write_csv(
        &out.join("s_curve.csv"),
        &["d_m", "power_w", "stiffness_n_per_m", "contact_force_n"],
        &[
            &col(|p| p.d),
            &col(|p| p.power),
            &col(|p| p.stiffness),
            &col(|p| p.contact_force),
        ],
    )?;

    // Fig. 2(b): clearance change against DC voltage.
    let volts: Vec<f64> = (-10..=10).map(|i| f64::from(i) / 10.0).collect();
    let fh = clearance_change(model, &volts, &static_opts)?;
    let dfh: Vec<f64> = fh.iter().map(|c| c.clearance_change).collect();
    let fit = parabola_fit(&volts, &dfh);
    let (a, b, c) = fit;
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
        &["v_dc_minus_phi_v", "clearance_change_m"],
        &[&volts, &dfh],
    )?;
    fig2b_chart(&volts, &dfh, fit).to_svg(&out.join("fig2b_clearance_vs_dc.svg"), 860, 500)?;

    // Fig. 3(a–c): time series at 0 V and 0.6 V AC under the fixed programme.
    let mut with_series = opts;
    with_series.keep_series = true;
    let at = |v_ac: f64| {
        model.with_voltage(Voltage {
            ac_amplitude: v_ac,
            ..model.voltage()
        })
    };
    let c0 = simulate_cycle(&at(0.0), &fixed, &with_series)?;
    let c6 = simulate_cycle(&at(0.6), &fixed, &with_series)?;
    let (s0, s6) = (series(&c0)?, series(&c6)?);
    s0.write_csv(&out.join("fig3a_forces_0V.csv"))?;
    s6.write_csv(&out.join("fig3c_forces_0.6V.csv"))?;
    let period = 0.5 / scene.voltage.ac_frequency_hz;
    let (fig3a, fig3c) = fig3ac_charts(s0, s6, period);
    fig3a.to_svg(&out.join("fig3a_forces_0V.svg"), 1000, 550)?;
    fig3c.to_svg(&out.join("fig3c_forces_0.6V.svg"), 1000, 550)?;
    let zoom = (2.0e-3, 2.2e-3);
    fig3b_table(s6, zoom).write(&out.join("fig3b_zoom_0.6V.csv"))?;
    figures::zoom_chart(
        "Fig. 3(b) zoom, V_ac = 0.6 V: forces (left) and spacing (right)",
        s6,
        zoom,
    )
    .to_svg(&out.join("fig3b_zoom_0.6V.svg"), 1000, 550)?;

    // Fig. 3(d) and Fig. 4: refined sweeps under both programmes.
    let sweep_clock = Instant::now();
    let fixed_refined = ac_sweep_refined(model, &fixed, &opts, amplitudes, refine)?;
    let fixed_wall = sweep_clock.elapsed().as_secs_f64();
    let trig_refined = ac_sweep_refined(model, &triggered, &opts, amplitudes, refine)?;
    println!(
        "\n# Fig. 3(d) / Fig. 4: cycles against AC amplitude (f = {} kHz, {}, rtol from {:e})",
        scene.voltage.ac_frequency_hz / 1e3,
        opts.solver.method,
        opts.solver.rtol,
    );
    println!("detection lags the running mean's window T_w = {:.1} µs: dynamic hysteresis is biased up by ≈ ramp × T_w", scene.detector.window_s * 1e6);
    println!(
        "{:>6} | {:>9} {:>9} {:>10} {:>7} {:>9} {:>7} | {:>9} {:>10} {:>7} {:>9} {:>7}",
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
    for (fr, tr) in fixed_refined.iter().zip(&trig_refined) {
        let (f, t) = (&fr.cycle, &tr.cycle);
        println!(
            "{:>6.2} | {:>9} {:>9} {:>10} {:>7} {:>9.3} {:>7} | {:>9} {:>10} {:>7} {:>9.3} {:>7.1}",
            f.v_ac,
            opt_mw(f.touchdown.map(|d| d.power)),
            opt_mw(f.takeoff.map(|d| d.power)),
            hyst_mw(f.hysteresis),
            rtol_mark(fr),
            f.mean_temperature_rise,
            fr.stats.accepted,
            opt_mw(t.touchdown.map(|d| d.power)),
            hyst_mw(t.hysteresis),
            rtol_mark(tr),
            t.mean_temperature_rise,
            1e3 * (fr.wall_seconds + tr.wall_seconds),
        );
    }
    println!(
        "rtol: the tolerance of the last of {} successive runs whose touchdown and take-off moved \
         by less than {:.3} mW from one to the next (\"?\": still moving at the last of {} runs: \
         intermittent contact, the running mean near F_th; drawn hollow); ΔP \"(neg)\": a \
         negative hysteresis, not physical (drawn as a cross); steps and ms over all runs",
        refine.agreeing_runs,
        mw(refine.power_tol),
        refine.max_runs
    );
    println!(
        "fixed-programme refined sweep of {} amplitudes: {:.1} ms wall (beside the bulge's sweep)",
        amplitudes.len(),
        1e3 * fixed_wall
    );
    println!("(powers in mW, ΔT in K)");
    sweep_table(&fixed_refined, options.wall_seconds)
        .write(&out.join("fig3d_hysteresis_vs_ac_fixed.csv"))?;
    sweep_table(&trig_refined, options.wall_seconds)
        .write(&out.join("fig4_triggered_sweep.csv"))?;

    // Fig. 1: contact indicator against heater power over triggered cycles.
    let mut fig1 = Vec::new();
    for v in [0.0, 0.6] {
        let r = simulate_cycle(&at(v), &triggered, &with_series)?;
        series(&r)?.write_csv(&out.join(format!("fig1_triggered_{v:.1}V.csv")))?;
        fig1.push(r);
    }
    let fig1_cycles = [("V_{ac} = 0 V", &fig1[0]), ("V_{ac} = 0.6 V", &fig1[1])];
    let threshold = scene.detector.contact_threshold_n;
    fig1_chart(&fig1_cycles, threshold, options.fig1_absolute)?.to_svg(
        &out.join("fig1_indicator_vs_power.svg"),
        1000,
        550,
    )?;
    // The same cycles against the absolute power, to set beside the letter's frame: there a
    // lower touchdown moves every point of its cycle to the right, take-off included.
    fig1_chart(&fig1_cycles, threshold, true)?.to_svg(
        &out.join("fig1_indicator_vs_absolute_power.svg"),
        1000,
        550,
    )?;
    for (label, r) in fig1_cycles {
        let (td, to) = (r.touchdown.map(|d| d.power), r.takeoff.map(|d| d.power));
        println!(
            "Fig. 1 {}: touchdown {} mW, take-off {} mW; take-off from touchdown {} mW",
            label.replace("_{ac}", "_ac"),
            opt_mw(td),
            opt_mw(to),
            td.zip(to)
                .map_or("—".into(), |(a, b)| format!("{:.3}", mw(b - a)))
        );
    }

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
    Ok(Rigid {
        fixed: fixed_refined,
        triggered: trig_refined,
        parabola: a,
        dither: (lr.dither_amplitude, sim),
    })
}

// Used by this example's test and by examples/docs_numbers.rs, which includes this file.
#[allow(dead_code)]
/// The numbers of this run that the docs quote (docs/analyses.md), keyed `paper.…`: the static
/// loops, every refined sweep point (`paper.fixed.v0_6.dp_mw`: the fixed programme's hysteresis
/// at 0.6 V in mW; `td_mw`, `to_mw`, `dt_k`, `rtol`; `triggered`, `bulge`), the parabola of
/// Fig. 2(b) and the dither at 0.6 V.
pub fn doc_numbers(s: &Summary) -> Vec<doc_numbers::Quoted> {
    use doc_numbers::Quoted;
    let mut q = vec![
        Quoted::new("paper.refine_tol_mw", mw(s.refine.power_tol)),
        Quoted::new("paper.parabola_nm_per_v2", nm(s.rigid.parabola)),
        Quoted::new("paper.dither_predicted_nm", nm(s.rigid.dither.0)),
        Quoted::new("paper.dither_simulated_nm", nm(s.rigid.dither.1)),
    ];
    for (name, stat) in [("rigid", &s.stat), ("bulge", &s.bulge.stat)] {
        q.extend([
            Quoted::new(
                &format!("paper.{name}.static.td_mw"),
                mw(stat.touchdown.power),
            ),
            Quoted::new(
                &format!("paper.{name}.static.to_mw"),
                mw(stat.takeoff.power),
            ),
            Quoted::new(&format!("paper.{name}.static.dp_mw"), mw(stat.hysteresis)),
        ]);
    }
    let sweeps = [
        ("fixed", &s.rigid.fixed),
        ("triggered", &s.rigid.triggered),
        ("bulge", &s.bulge.fixed),
    ];
    for (name, sweep) in sweeps {
        for r in sweep.iter() {
            let c = &r.cycle;
            // `v0_6`: the amplitude to 0.1 V, as the docs name it.
            let at = format!(
                "paper.{name}.v{}",
                format!("{:.1}", c.v_ac).replace('.', "_")
            );
            q.push(Quoted::new(&format!("{at}.dt_k"), c.mean_temperature_rise));
            q.push(Quoted::power_of_ten(&format!("{at}.rtol"), r.rtol));
            let detected = [
                ("td_mw", c.touchdown.map(|d| d.power)),
                ("to_mw", c.takeoff.map(|d| d.power)),
                ("dp_mw", c.hysteresis),
                // A take-off above the touchdown: a negative hysteresis, quoted as its size.
                (
                    "to_above_td_mw",
                    c.hysteresis.filter(|h| *h < 0.0).map(|h| -h),
                ),
            ];
            for (what, v) in detected {
                if let Some(v) = v {
                    q.push(Quoted::new(&format!("{at}.{what}"), mw(v)));
                }
            }
        }
    }
    q
}

/// Size of each figure panel (px); the rigid and bulge panels of a figure are shown side by side.
const PANEL: (u32, u32) = (900, 560);
/// Titles of the rigid panels of Fig. 3(d) and Fig. 4.
const RIGID_TITLES: [&str; 2] = [
    "Fig. 3(d) hysteresis against V_ac — rigid slider (paper scene)",
    "Fig. 4 mean ΔT against hysteresis — rigid slider (paper scene)",
];
/// Titles of the bulge panels of Fig. 3(d) and Fig. 4.
const BULGE_TITLES: [&str; 2] = [
    "Fig. 3(d) hysteresis against V_ac — bulge (paper_bulge scene)",
    "Fig. 4 mean ΔT against hysteresis — bulge (paper_bulge scene)",
];

/// The deformable slider of `scenes/paper_bulge.toml`: its static loop and its refined sweep
/// under the fixed programme.
pub struct Bulge {
    stat: StaticHysteresis,
    fixed: Vec<RefinedCycle>,
    refine: Refinement,
    /// Wall time of the sweep (s).
    wall: f64,
}

impl Bulge {
    /// Static analyses and the refined fixed-programme sweep of the shipped bulge scene, refined
    /// to the same power tolerance as the rigid slider's (`refine`), so that both panels carry
    /// the same error bar.
    fn run(
        options: &Options,
        amplitudes: &[f64],
        refine: &Refinement,
    ) -> hdi_tribology::Result<Self> {
        let scene = Scene::from_toml_str(include_str!("../scenes/paper_bulge.toml"))?;
        let model = SliderModel::from_scene(&scene)?;
        let p = Protocol::from_scene(&scene)?;
        let mut opts = p.cycle;
        if let Some(m) = options.method {
            opts.solver.method = m;
        }
        let stat = static_hysteresis(&model, &p.statics)?;
        let clock = Instant::now();
        let fixed = ac_sweep_refined(&model, &p.fixed, &opts, amplitudes, refine)?;
        Ok(Bulge {
            stat,
            fixed,
            refine: *refine,
            wall: clock.elapsed().as_secs_f64(),
        })
    }

    /// The bulge's numbers beside the rigid slider's, fixed programme, with the status and
    /// flags `hdi sweep` prints.
    fn print(&self, rigid: &[RefinedCycle], rigid_stat: &StaticHysteresis) {
        println!(
            "\n# Rigid (paper scene) against bulge (scenes/paper_bulge.toml), fixed programme"
        );
        println!(
            "static: rigid P_TD {:.3} / P_TO {:.3} / ΔP {:.3} mW; bulge {:.3} / {:.3} / {:.3} mW",
            mw(rigid_stat.touchdown.power),
            mw(rigid_stat.takeoff.power),
            mw(rigid_stat.hysteresis),
            mw(self.stat.touchdown.power),
            mw(self.stat.takeoff.power),
            mw(self.stat.hysteresis),
        );
        println!(
            "{:>6} | {:>8} {:>8} {:>10} {:>7} {:>13} {:<22} | {:>8} {:>8} {:>10} {:>7} {:>13} {:<22}",
            "V_ac", "P_TD", "P_TO", "ΔP", "rtol", "status", "flags", "P_TD", "P_TO", "ΔP", "rtol",
            "status", "flags"
        );
        for (r, b) in rigid.iter().zip(&self.fixed) {
            println!(
                "{:>6.2} | {} | {}",
                r.cycle.v_ac,
                summary_cells(r),
                summary_cells(b)
            );
        }
        println!(
            "left: rigid, right: bulge, both refined to {:.3} mW over {} successive runs (\"?\": \
             not converged); flags as `hdi sweep` prints them; bulge sweep {:.1} ms wall",
            mw(self.refine.power_tol),
            self.refine.agreeing_runs,
            1e3 * self.wall
        );
    }
}

/// The tolerance a refined cycle ended at, "?" when it had not converged there.
fn rtol_mark(r: &RefinedCycle) -> String {
    format!("{:.0e}{}", r.rtol, if r.converged { " " } else { "?" })
}

/// P_TD, P_TO, ΔP (mW), rtol, status and flags of one refined cycle, as `hdi sweep` names them.
fn summary_cells(r: &RefinedCycle) -> String {
    let c = &r.cycle;
    let flags: Vec<String> = r
        .flags()
        .iter()
        .map(|f| {
            serde_json::to_value(f)
                .ok()
                .and_then(|v| v.as_str().map(str::to_string))
                .unwrap_or_else(|| f.to_string())
        })
        .collect();
    format!(
        "{:>8} {:>8} {:>10} {:>7} {:>13} {:<22}",
        opt_mw(c.touchdown.map(|d| d.power)),
        opt_mw(c.takeoff.map(|d| d.power)),
        hyst_mw(c.hysteresis),
        rtol_mark(r),
        if r.converged {
            "converged"
        } else {
            "not_converged"
        },
        if flags.is_empty() {
            "—".to_string()
        } else {
            flags.join(",")
        }
    )
}

/// Width of the legend panel of Fig. 3(d) and Fig. 4 (px), the same on both panels.
const LEGEND_WIDTH: u32 = 300;

/// Gives the panels of one figure (all on the same kind of axes) the same legend width and,
/// with `ranges`, the same x and y ranges, those that show every point of every panel, so that
/// the rigid and bulge panels compare at a glance; without, each panel's axes fit its data.
fn share_ranges(charts: &mut [Chart<'_>], ranges: bool) {
    let log = charts.first().map_or((false, false), |c| c.log);
    let points = || {
        charts
            .iter()
            .flat_map(|c| c.series.iter())
            .flat_map(|s| s.points.iter().copied())
            .filter(|&(x, y)| {
                x.is_finite() && y.is_finite() && (!log.0 || x > 0.0) && (!log.1 || y > 0.0)
            })
    };
    let span = |v: &mut dyn Iterator<Item = f64>, log: bool| {
        let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
        (lo <= hi).then(|| match log {
            true => (lo / 1.3, hi * 1.3),
            false => {
                let pad = if hi > lo { 0.05 * (hi - lo) } else { 1.0 };
                (lo - pad, hi + pad)
            }
        })
    };
    let x = span(&mut points().map(|p| p.0), log.0);
    let y = span(&mut points().map(|p| p.1), log.1);
    for c in charts.iter_mut() {
        if ranges {
            c.x_range = x;
            c.y_range = y;
        }
        c.legend_width = Some(LEGEND_WIDTH);
        // Each panel is set for the full two-column width (7 in): at one column its legend and
        // notes would leave no room for the plot.
        c.print_width_in = Some(7.0);
    }
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

/// A hysteresis in mW, marked when negative (not physical).
fn hyst_mw(h: Option<f64>) -> String {
    match h {
        Some(h) if h < 0.0 => format!("{:.3}(neg)", mw(h)),
        _ => opt_mw(h),
    }
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

/// The sweep table: powers in W, missing detections empty, counts as integers; the wall time
/// only when asked for (it differs on every run).
fn sweep_table(rs: &[RefinedCycle], wall_seconds: bool) -> CsvTable {
    let power = |f: fn(&CycleResult) -> Option<f64>| rs.iter().map(move |r| f(&r.cycle));
    let t = CsvTable::new()
        .real("v_ac_v", rs.iter().map(|r| r.cycle.v_ac))
        .optional("touchdown_power_w", power(|c| c.touchdown.map(|d| d.power)))
        .optional("takeoff_power_w", power(|c| c.takeoff.map(|d| d.power)))
        .optional("hysteresis_w", rs.iter().map(|r| r.cycle.hysteresis))
        .real(
            "mean_temperature_rise_k",
            rs.iter().map(|r| r.cycle.mean_temperature_rise),
        )
        .real("rtol", rs.iter().map(|r| r.rtol))
        .real("power_change_w", rs.iter().map(|r| r.change))
        .flag("converged", rs.iter().map(|r| r.converged))
        .flag(
            "hysteresis_negative",
            rs.iter()
                .map(|r| r.cycle.hysteresis.is_some_and(|h| h < 0.0)),
        )
        .integer("runs", rs.iter().map(|r| r.runs as u64))
        .integer("steps", rs.iter().map(|r| r.stats.accepted as u64));
    if wall_seconds {
        t.real("wall_seconds_s", rs.iter().map(|r| r.wall_seconds))
    } else {
        t
    }
}

/// One programme's refined sweep, with its colour and marker.
struct Sweep<'a> {
    name: &'a str,
    style: (Colour, Marker),
    results: &'a [RefinedCycle],
}

/// The points `point(r)` of a sweep split by status: converged and non-negative (filled),
/// still moving at the tightest tolerance (hollow), negative hysteresis (cross). Sweeps
/// without a hysteresis (no touchdown or no take-off) are left out.
fn status_series<'a>(
    sweep: &Sweep<'a>,
    labels: [&'a str; 3],
    point: impl Fn(&CycleResult, f64) -> (f64, f64),
    label_vac: bool,
) -> Vec<Series<'a>> {
    let (colour, marker) = sweep.style;
    let pick = |keep: &dyn Fn(&RefinedCycle, f64) -> bool| {
        let kept: Vec<(&RefinedCycle, f64)> = sweep
            .results
            .iter()
            .filter_map(|r| r.cycle.hysteresis.map(|h| (r, h)))
            .filter(|&(r, h)| keep(r, h))
            .collect();
        let texts = kept
            .iter()
            .map(|(r, _)| match label_vac {
                true => format!("{:.1}", r.cycle.v_ac),
                false => String::new(),
            })
            .collect();
        (
            kept.iter().map(|&(r, h)| point(&r.cycle, h)).collect(),
            texts,
        )
    };
    let (good, good_texts) = pick(&|r, h| r.converged && h >= 0.0);
    let (moving, moving_texts) = pick(&|r, h| !r.converged && h >= 0.0);
    let (negative, negative_texts) = pick(&|_, h| h < 0.0);
    let mut out = vec![Series::markers(labels[0], good)
        .colour(colour)
        .marker(marker)
        .width(5)
        .point_labels(good_texts)];
    if !moving.is_empty() {
        out.push(
            Series::markers(labels[1], moving)
                .colour(colour)
                .marker(marker)
                .width(5)
                .hollow()
                .point_labels(moving_texts),
        );
    }
    if !negative.is_empty() {
        out.push(
            Series::markers(labels[2], negative)
                .colour(colour)
                .marker(Marker::Cross)
                .width(5)
                .point_labels(negative_texts),
        );
    }
    out
}

/// [`status_series`] of the sweeps (fixed, then triggered if run), the first labelled `names`.
fn sweep_series<'a>(
    sweeps: &[Sweep<'a>],
    names: [&'a str; 2],
    point: impl Fn(&CycleResult, f64) -> (f64, f64) + Copy,
    label_vac: bool,
) -> Vec<Series<'a>> {
    let labels = [
        [names[0], "fixed, not converged", "fixed, negative"],
        [names[1], "triggered, not converged", "triggered, negative"],
    ];
    sweeps
        .iter()
        .zip(labels)
        .flat_map(|(sweep, labels)| status_series(sweep, labels, point, label_vac))
        .collect()
}

/// The name of a marker symbol, for notes on a figure.
fn marker_name(m: Marker) -> &'static str {
    match m {
        Marker::Circle => "circles",
        Marker::Square => "squares",
        Marker::Triangle => "triangles",
        Marker::Diamond => "diamonds",
        Marker::Cross => "crosses",
    }
}

/// Notes on what the hollow and crossed markers mean (where a panel shows them), and which
/// amplitudes have no hysteresis to draw.
fn status_notes(sweeps: &[Sweep<'_>], refine: &Refinement) -> Vec<String> {
    let shown = |f: &dyn Fn(&RefinedCycle, f64) -> bool| {
        sweeps
            .iter()
            .flat_map(|s| s.results.iter())
            .any(|r| r.cycle.hysteresis.is_some_and(|h| f(r, h)))
    };
    let mut notes = Vec::new();
    if shown(&|r, h| !r.converged && h >= 0.0) {
        notes.push(format!(
            "Hollow: touchdown or take-off moved by more than {:.3} mW between two of the last {} \
             tolerances (intermittent contact): not converged.",
            mw(refine.power_tol),
            refine.agreeing_runs
        ));
    }
    if shown(&|_, h| h < 0.0) {
        notes.push("Cross: negative hysteresis, not physical.".to_string());
    }
    for sweep in sweeps {
        let missing: Vec<String> = sweep
            .results
            .iter()
            .filter(|r| r.cycle.hysteresis.is_none())
            .map(|r| {
                let what = if r.cycle.touchdown.is_none() {
                    "no touchdown"
                } else {
                    "no take-off"
                };
                format!("{:.1} V ({what})", r.cycle.v_ac)
            })
            .collect();
        if !missing.is_empty() {
            notes.push(format!(
                "Not drawn, {}: {}.",
                sweep.name,
                missing.join(", ")
            ));
        }
    }
    notes
}

/// A note on a panel whose touchdown-triggered programme was not run.
const FIXED_ONLY: &str = "Fixed programme only: the rigid and bulge panels compare it; the \
                          touchdown-triggered programme is not run on the bulge.";

/// Fig. 3(d): hysteresis (mW) against AC amplitude under the programmes of `sweeps` (fixed,
/// then triggered if run), with the static value.
fn fig3d_chart<'a>(
    title: &'a str,
    sweeps: &'a [Sweep<'a>],
    static_hysteresis: f64,
    refine: &Refinement,
) -> Chart<'a> {
    let mut series = vec![Series::line(
        "static, V_{ac} = 0",
        vec![(0.0, mw(static_hysteresis)), (1.0, mw(static_hysteresis))],
    )
    .colour(palette::BLACK)
    .width(1)
    .dashed()];
    series.extend(sweep_series(
        sweeps,
        ["fixed programme", "touchdown-triggered"],
        |c, h| (c.v_ac, mw(h)),
        false,
    ));
    // With both programmes, their markers are set a little either side of the amplitude, so
    // that equal values do not hide one another.
    let dodge = 0.012;
    if sweeps.len() > 1 {
        for s in series.iter_mut().filter(|s| s.markers) {
            let dx = if s.colour == Some(TRIGGERED.0) {
                dodge
            } else {
                -dodge
            };
            s.points.iter_mut().for_each(|p| p.0 += dx);
        }
    }
    let mut notes = vec![if sweeps.len() > 1 {
        format!(
            "The letter's Fig. 3(d) uses the fixed programme ({}); the experiment's protocol \
             is the touchdown-triggered programme ({}). Their markers sit {dodge} V either side \
             of the amplitude.",
            marker_name(FIXED.1),
            marker_name(TRIGGERED.1)
        )
    } else {
        FIXED_ONLY.to_string()
    }];
    notes.extend(status_notes(sweeps, refine));
    Chart {
        title,
        x_label: "V_{ac} (V)",
        y_label: "P_{TD} − P_{TO} (mW)",
        series,
        notes,
        ..Chart::default()
    }
}

/// Fig. 4: mean temperature rise (K) against hysteresis (mW) under the programmes of `sweeps`
/// (fixed, then triggered if run).
fn fig4_chart<'a>(title: &'a str, sweeps: &'a [Sweep<'a>], refine: &Refinement) -> Chart<'a> {
    let series = sweep_series(
        sweeps,
        ["fixed programme", "touchdown-triggered (letter)"],
        |c, h| (mw(h), c.mean_temperature_rise),
        true,
    );
    let mut notes = vec![match sweeps {
        [fixed, triggered, ..] => format!(
            "The letter's Fig. 4 uses the {} ({}); the {} ({}) is shown for comparison.",
            triggered.name,
            marker_name(triggered.style.1),
            fixed.name,
            marker_name(fixed.style.1),
        ),
        _ => FIXED_ONLY.to_string(),
    }];
    notes.push("Beside each point: its V_{ac} (V).".to_string());
    notes.extend(status_notes(sweeps, refine));
    // Room on the right of the points for their labels.
    let (lo, hi) = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.0))
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
    let pad = if hi > lo { hi - lo } else { 1.0 };
    Chart {
        title,
        x_label: "P_{TD} − P_{TO} (mW)",
        y_label: "mean ΔT (K)",
        series,
        notes,
        x_range: (lo <= hi).then_some((lo - 0.05 * pad, hi + 0.25 * pad)),
        ..Chart::default()
    }
}

/// Fig. 2(b): the static clearance change (nm) against DC voltage, the parabolic fit drawn
/// under the points.
fn fig2b_chart<'a>(volts: &[f64], dfh: &[f64], (a, b, c): (f64, f64, f64)) -> Chart<'a> {
    let fit: Vec<(f64, f64)> = (-100..=100)
        .map(|i| {
            let v = i as f64 * 0.01;
            (v, nm(a * v * v + b * v + c))
        })
        .collect();
    Chart {
        title: "Fig. 2(b) clearance change against DC voltage",
        x_label: "V_{dc} − φ (V)",
        y_label: "ΔFH (nm)",
        series: vec![
            Series::line("parabolic fit", fit)
                .colour(palette::BLACK)
                .width(1),
            Series::markers(
                "static model",
                volts.iter().zip(dfh).map(|(v, d)| (*v, nm(*d))).collect(),
            )
            .colour(palette::BLUE)
            .width(5),
        ],
        ..Chart::default()
    }
}

/// The data of Fig. 3(b): every sample of the zoom's window, as the time series' CSV names
/// its columns.
fn fig3b_table(s: &TimeSeries, span: (f64, f64)) -> CsvTable {
    let col = |f: fn(&TimeSeries, usize) -> f64| {
        figures::window(s, span, f)
            .into_iter()
            .map(|p| p.1)
            .collect::<Vec<f64>>()
    };
    CsvTable::new()
        .real("t_s", col(|s, i| s.t[i]))
        .real("total_n", col(|s, i| s.total[i]))
        .real("electrostatic_n", col(|s, i| s.electrostatic[i]))
        .real("air_bearing_n", col(|s, i| s.air_bearing[i]))
        .real("d_m", col(|s, i| s.d[i]))
}

/// Fig. 3(a) and (c): the forces over the whole cycle at 0 V and 0.6 V, on one y range, each
/// as its mean over one period of `V²` (`period`, s) with its range over the period shaded.
fn fig3ac_charts<'a>(s0: &TimeSeries, s6: &TimeSeries, period: f64) -> (Chart<'a>, Chart<'a>) {
    let all = (f64::NEG_INFINITY, f64::INFINITY);
    let note = format!(
        "Lines: each force's mean over one period of V² ({:.1} µs); shaded: its range over \
         that period.",
        period * 1e6
    );
    let chart = |title, s| {
        let (series, zero) = figures::force_envelopes(s, all, period);
        let mut notes = vec![note.clone()];
        if !zero.is_empty() {
            notes.push(format!("Zero throughout, not drawn: {}.", zero.join(", ")));
        }
        Chart {
            title,
            x_label: "t (ms)",
            y_label: "force (mN)",
            series,
            notes,
            ..Chart::default()
        }
    };
    let mut a = chart("Fig. 3(a) forces, V_ac = 0 V", s0);
    let mut c = chart("Fig. 3(c) forces, V_ac = 0.6 V", s6);
    let range = match (a.data_y_range(), c.data_y_range()) {
        (Some(p), Some(q)) => Some((p.0.min(q.0), p.1.max(q.1))),
        (p, q) => p.or(q),
    };
    a.y_range = range;
    c.y_range = range;
    (a, c)
}

/// Where Fig. 1 marks the direction of a cycle's loop `curve` (points in the order run): on
/// the flying branch on the way up (the `k`-th cycle a little further along, so that the
/// cycles' marks there do not cover each other), halfway up the jump into contact, halfway
/// back along the contact branch, and on the drop at take-off.
fn loop_arrows(curve: &[(f64, f64)], k: usize) -> Vec<usize> {
    let top = curve.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
    if curve.len() < 4 || !top.is_finite() || top <= 0.0 {
        return Vec::new();
    }
    // Up at half the top; down a quarter of the way up, below where the contact branch
    // itself may sink before the head leaves.
    let (Some(up), Some(down)) = (
        curve.iter().position(|p| p.1 >= 0.5 * top),
        curve.iter().rposition(|p| p.1 >= 0.25 * top),
    ) else {
        return Vec::new();
    };
    // The turn: the highest power, between the jump up and the drop.
    let turn = (up..=down).max_by(|&a, &b| curve[a].0.total_cmp(&curve[b].0));
    let nearest = |range: std::ops::Range<usize>, x: f64| {
        range.min_by(|&a, &b| (curve[a].0 - x).abs().total_cmp(&(curve[b].0 - x).abs()))
    };
    let f = 0.45 + 0.2 * (k % 2) as f64;
    let mut at = Vec::new();
    at.extend(nearest(0..up, curve[0].0 + f * (curve[up].0 - curve[0].0)));
    at.push(up);
    if let Some(t) = turn {
        at.extend(nearest(t..down, 0.5 * (curve[t].0 + curve[down].0)));
    }
    at.push(down);
    at
}

/// Fig. 1: the contact indicator over touchdown-triggered cycles, with their touchdown and
/// take-off. By default normalized by the threshold F_th against the heater power from each
/// cycle's touchdown, as the letter plots it; `absolute`: in µN against the heater power.
fn fig1_chart<'a>(
    cycles: &[(&'a str, &CycleResult)],
    threshold: f64,
    absolute: bool,
) -> Res<Chart<'a>> {
    let colours = [palette::BLACK, palette::VERMILION];
    let mut lines = Vec::new();
    let mut notes = Vec::new();
    for (k, &(label, r)) in cycles.iter().enumerate() {
        let s = series(r)?;
        let colour = colours[k % colours.len()];
        let origin = match (absolute, r.touchdown) {
            (true, _) => 0.0,
            (false, Some(td)) => td.power,
            (false, None) => {
                notes.push(format!("{label}: no touchdown detected, not drawn."));
                continue;
            }
        };
        let (x, y) = (
            move |p: f64| mw(p - origin),
            move |f: f64| if absolute { f * 1e6 } else { f / threshold },
        );
        let curve: Vec<(f64, f64)> = (0..s.t.len())
            .filter(|&i| s.indicator[i].is_finite())
            .map(|i| (x(s.power[i]), y(s.indicator[i])))
            .collect();
        let arrows = loop_arrows(&curve, k);
        lines.push(Series::line(label, curve).colour(colour).arrows(arrows));
        let events: Vec<(f64, f64)> = [r.touchdown, r.takeoff]
            .iter()
            .flatten()
            .map(|d| (x(d.power), y(threshold)))
            .collect();
        // Nested sizes, so that the cycles' diamonds at one place do not hide each other.
        lines.push(
            Series::markers("", events)
                .colour(colour)
                .marker(Marker::Diamond)
                .width(9 - 4 * (k as u32 % 2))
                .hollow(),
        );
    }
    // The threshold the diamonds sit on, across the curves.
    let (lo, hi) = lines
        .iter()
        .flat_map(|l| l.points.iter().map(|p| p.0))
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
    if lo < hi {
        let level = if absolute { threshold * 1e6 } else { 1.0 };
        lines.insert(
            0,
            Series::line("threshold F_{th}", vec![(lo, level), (hi, level)])
                .colour(palette::BLACK)
                .width(1)
                .dashed(),
        );
    }
    notes.insert(
        0,
        "Hollow diamonds: detected touchdown and take-off, where the running mean crosses F_{th}. \
         Arrowheads: the way each cycle runs (power up, contact, power down, take-off)."
            .into(),
    );
    let (title, x_label, y_label) = if absolute {
        (
            "Fig. 1 contact indicator over touchdown-triggered cycles",
            "heater power (mW)",
            "running mean of F_{c} (µN)",
        )
    } else {
        (
            "Fig. 1 normalized contact indicator over touchdown-triggered cycles",
            "heater power − touchdown power (mW)",
            "running mean of F_{c} / F_{th}",
        )
    };
    Ok(Chart {
        title,
        x_label,
        y_label,
        series: lines,
        notes,
        ..Chart::default()
    })
}

#[cfg(test)]
mod tests {
    /// `cargo test` runs the example (into a temporary directory), so CI runs every example.
    #[test]
    fn example_runs() {
        let dir = tempfile::tempdir().unwrap();
        let summary = super::run(&super::Options::default(), dir.path())
            .expect("the example runs to completion");
        // The numbers docs/analyses.md quotes from this run are the run's.
        let root = super::doc_numbers::repository_root();
        let agreed = super::doc_numbers::assert_quoted(&root, &super::doc_numbers(&summary));
        assert!(agreed > 0, "the docs quote numbers of the paper example");
        let table = std::fs::read_to_string(dir.path().join("fig4_triggered_sweep.csv")).unwrap();
        let header = table.lines().next().unwrap();
        assert!(header.starts_with("v_ac_v,") && !header.contains("wall_seconds"));
        // The amplitudes as a user types them, from integer counts: 0.3, not 0.30000000000000004.
        let amplitudes: Vec<&str> = table
            .lines()
            .skip(1)
            .map(|l| l.split(',').next().unwrap())
            .collect();
        let typed: Vec<String> = (0..=10)
            .map(|i| match i {
                0 => "0".into(),
                10 => "1".into(),
                i => format!("0.{i}"),
            })
            .collect();
        assert_eq!(amplitudes, typed);
        // A missing value is an empty field: the indicator before its window has filled.
        let series = std::fs::read_to_string(dir.path().join("fig3a_forces_0V.csv")).unwrap();
        assert!(series.lines().next().unwrap().ends_with(",indicator_n"));
        assert!(series.lines().nth(1).unwrap().ends_with(','));
        assert!(!series.contains("NaN"));
        for name in [
            "fig1_indicator_vs_power.svg",
            "fig1_indicator_vs_absolute_power.svg",
            "fig2b_clearance_vs_dc.svg",
            "fig3a_forces_0V.svg",
            "fig3b_zoom_0.6V.svg",
            "fig3c_forces_0.6V.svg",
            "fig3d_hysteresis_vs_ac.svg",
            "fig3d_hysteresis_vs_ac_bulge.svg",
            "fig3d_hysteresis_vs_ac_bulge_fixed.csv",
            "fig4_temperature_vs_hysteresis.svg",
            "fig4_temperature_vs_hysteresis_bulge.svg",
        ] {
            assert!(dir.path().join(name).is_file(), "{name} written");
        }
    }
}
