//! `hdi`: the command line of hdi-tribology.
//!
//! Subcommands share two helpers: loading a scene (a TOML/JSON file or `--paper`) and printing
//! JSON. Errors print one line `hdi: <message>` on stderr and exit with 2 (usage) or 1 (scene or
//! computation).

use std::io::Write;
use std::process::ExitCode;

use hdi_tribology::analysis::cycle::CycleResult;
use hdi_tribology::analysis::{
    ac_sweep, ac_sweep_refined, pull_in_voltage, s_curve, simulate_cycle, static_hysteresis,
    CycleOptions, HeaterProgramme, Refinement, ScanGrid, StaticOptions,
};
use hdi_tribology::force::{Breakdown, Gaps};
use hdi_tribology::model::{SliderModel, Voltage};
use hdi_tribology::scene::Scene;
use serde::Serialize;

const USAGE: &str = "usage: hdi <command> [options]

commands:
  forces (SCENE_FILE | --paper) (--gaps D1,D2,... | --gaps-nm D1,D2,...)
        [--protrusion-m DELTA | --protrusion-nm DELTA]
      interface forces at bulge gaps D (m; nm with --gaps-nm), JSON, one object per gap: d, intermolecular,
      contact, electrostatic_per_volt2, electrostatic (at the scene's DC voltage minus the
      contact potential), other, real_contact_area, total (SI, positive = away from the disk).
      Pad-gap terms see D + DELTA (default DELTA = 0).
  static (SCENE_FILE | --paper)
      static analyses at the scene's DC voltage, JSON: touchdown_power, takeoff_power,
      hysteresis (W), pull_in_voltage (V, at zero heater power), folds [{power, d}].
  cycle (SCENE_FILE | --paper) [--v-ac V] [--triggered] [--csv FILE] [--method M] [--rtol R]
      one touchdown/take-off cycle under the scene's fixed programme (or the touchdown-triggered
      protocol), JSON: v_ac, touchdown_power, takeoff_power, hysteresis, mean_temperature_rise,
      steps, wall_seconds. --csv writes the time series of spacing and forces.
  sweep (SCENE_FILE | --paper) [--v-ac V1,V2,...] [--triggered] [--method M] [--rtol R]
        [--refine POWER_TOL_W]
      one cycle per AC amplitude (default: the scene's sweep list), JSON list of cycle objects.
      --refine reruns each amplitude with a tenfold tighter tolerance (at most 4 runs) until
      touchdown and take-off move by at most POWER_TOL_W, and adds rtol, power_change,
      converged and runs to each object.
  calibrate (SCENE_FILE | --paper) [--start-mw P] [--step-mw S] [--max-mw M] [--margin-mw G]
        [--detector mean|ae|vibration] [--dither-v V] [--no-takeoff]
      touchdown calibration as drive firmware does it: heater steps of S mW (default 0.5) from
      P (default: the power whose protrusion leaves 5 nm of the nominal clearance) up to M
      (default P + 60) until the detector fires, then back down to take-off; the heater is set
      G mW (default 15) below touchdown. Detectors: mean contact force over the scene's window
      and threshold (default), `ae` (high-passed contact-force RMS above 10 uN, 5 kHz corner,
      50 us RMS: an acoustic-emission proxy), `vibration` (high-passed displacement RMS above
      0.02 nm and 3x its level at the start). --dither-v adds an AC dither of V volts at the
      scene's frequency while calibrating. JSON: detector, touchdown_power, takeoff_power,
      hysteresis, set_power, clearance (m, static model at the set power without dither),
      contrast, levels, simulated_time, wall_seconds.
  scene (SCENE_FILE | --paper) [--json]
      the scene as TOML (or JSON), validated: a starting point for scenes of your own.
  help
      this text";

/// Why the program stops.
enum CliError {
    /// Bad command line: exit code 2.
    Usage(String),
    /// Bad scene or failed computation: exit code 1.
    Failed(String),
}

impl From<hdi_tribology::Error> for CliError {
    fn from(e: hdi_tribology::Error) -> Self {
        CliError::Failed(e.to_string())
    }
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(CliError::Usage(msg)) => {
            eprintln!("hdi: {msg} (try `hdi help`)");
            ExitCode::from(2)
        }
        Err(CliError::Failed(msg)) => {
            eprintln!("hdi: {}", msg.replace('\n', " "));
            ExitCode::from(1)
        }
    }
}

fn run(args: &[String]) -> Result<(), CliError> {
    let Some((command, rest)) = args.split_first() else {
        return Err(CliError::Usage("missing command".into()));
    };
    match command.as_str() {
        "forces" => forces(rest),
        "static" => static_analyses(rest),
        "cycle" => cycle(rest),
        "sweep" => sweep(rest),
        "calibrate" => calibrate_cmd(rest),
        "scene" => scene(rest),
        "help" | "--help" | "-h" => {
            print_text(USAGE)?;
            Ok(())
        }
        other => Err(CliError::Usage(format!("unknown command `{other}`"))),
    }
}

/// Where the scene comes from.
enum SceneSource {
    Paper,
    File(String),
}

/// Options shared by the subcommands, plus those a subcommand accepts as `--name value`.
struct Parsed {
    scene: Option<SceneSource>,
    values: Vec<(String, String)>,
    flags: Vec<String>,
}

/// Splits `args` into the scene source (`--paper` or one positional file) and `--name value`
/// pairs whose names are in `accepted`, and value-less `--name` flags whose names are in `flags`.
fn parse_args(args: &[String], accepted: &[&str], flags: &[&str]) -> Result<Parsed, CliError> {
    let mut parsed = Parsed {
        scene: None,
        values: Vec::new(),
        flags: Vec::new(),
    };
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let source = if a == "--paper" {
            SceneSource::Paper
        } else if let Some(flag) = a.strip_prefix("--").filter(|f| flags.contains(f)) {
            if !parsed.flags.iter().any(|f| f == flag) {
                parsed.flags.push(flag.to_string());
            }
            continue;
        } else if let Some(name) = a.strip_prefix("--") {
            let (name, value) = match name.split_once('=') {
                Some((n, v)) => (n.to_string(), v.to_string()),
                None => {
                    let v = it
                        .next()
                        .ok_or_else(|| CliError::Usage(format!("option --{name} needs a value")))?;
                    (name.to_string(), v.clone())
                }
            };
            if !accepted.contains(&name.as_str()) {
                return Err(CliError::Usage(format!("unknown option --{name}")));
            }
            if parsed.values.iter().any(|(n, _)| *n == name) {
                return Err(CliError::Usage(format!("option --{name} given twice")));
            }
            parsed.values.push((name, value));
            continue;
        } else {
            SceneSource::File(a.clone())
        };
        if parsed.scene.is_some() {
            return Err(CliError::Usage(
                "give exactly one scene: a file or --paper".into(),
            ));
        }
        parsed.scene = Some(source);
    }
    Ok(parsed)
}

impl Parsed {
    fn flag(&self, name: &str) -> bool {
        self.flags.iter().any(|f| f == name)
    }

    fn value(&self, name: &str) -> Option<&str> {
        self.values
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }

    fn load_scene(&self) -> Result<Scene, CliError> {
        match &self.scene {
            None => Err(CliError::Usage("missing scene: a file or --paper".into())),
            Some(SceneSource::Paper) => Ok(Scene::paper()),
            // parse errors already carry the file name; validation errors get it here
            Some(SceneSource::File(path)) => Scene::from_path(path).map_err(|e| match e {
                hdi_tribology::Error::InvalidInput { .. } => {
                    CliError::Failed(format!("{path}: {e}"))
                }
                other => CliError::from(other),
            }),
        }
    }
}

fn parse_number(option: &str, s: &str) -> Result<f64, CliError> {
    let x: f64 = s
        .trim()
        .parse()
        .map_err(|_| CliError::Usage(format!("--{option}: `{s}` is not a number")))?;
    if !x.is_finite() {
        return Err(CliError::Usage(format!("--{option}: `{s}` is not finite")));
    }
    Ok(x)
}

fn parse_list(option: &str, s: &str) -> Result<Vec<f64>, CliError> {
    let v = s
        .split(',')
        .filter(|p| !p.trim().is_empty())
        .map(|p| parse_number(option, p))
        .collect::<Result<Vec<_>, _>>()?;
    if v.is_empty() {
        return Err(CliError::Usage(format!("--{option}: empty list")));
    }
    Ok(v)
}

fn print_text(text: &str) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    writeln!(out, "{text}").map_err(|e| CliError::Failed(format!("cannot write output: {e}")))
}

fn print_json<T: Serialize>(value: &T) -> Result<(), CliError> {
    let text = serde_json::to_string_pretty(value)
        .map_err(|e| CliError::Failed(format!("cannot write JSON: {e}")))?;
    print_text(&text)
}

#[derive(Serialize)]
struct ForcesRow {
    d: f64,
    #[serde(flatten)]
    forces: Breakdown,
}

fn forces(args: &[String]) -> Result<(), CliError> {
    let parsed = parse_args(
        args,
        &["gaps", "gaps-nm", "protrusion-m", "protrusion-nm"],
        &[],
    )?;
    let gaps = match (parsed.value("gaps"), parsed.value("gaps-nm")) {
        (Some(m), None) => parse_list("gaps", m)?,
        (None, Some(nm)) => parse_list("gaps-nm", nm)?
            .into_iter()
            .map(hdi_tribology::units::nm)
            .collect(),
        (Some(_), Some(_)) => {
            return Err(CliError::Usage(
                "give the gaps once: --gaps (m) or --gaps-nm".into(),
            ))
        }
        (None, None) => {
            return Err(CliError::Usage(
                "forces needs --gaps D1,D2,... (m) or --gaps-nm D1,D2,...".into(),
            ))
        }
    };
    let protrusion = match (parsed.value("protrusion-m"), parsed.value("protrusion-nm")) {
        (Some(m), None) => parse_number("protrusion-m", m)?,
        (None, Some(nm)) => hdi_tribology::units::nm(parse_number("protrusion-nm", nm)?),
        (None, None) => 0.0,
        (Some(_), Some(_)) => {
            return Err(CliError::Usage(
                "give the protrusion once: --protrusion-m or --protrusion-nm".into(),
            ))
        }
    };
    let scene = parsed.load_scene()?;
    let interface = scene.build_interface()?;
    let volt2 = scene.dc_volt2();
    let rows: Vec<ForcesRow> = gaps
        .iter()
        .map(|&d| ForcesRow {
            d,
            forces: interface.breakdown(
                Gaps {
                    bulge: d,
                    pad: d + protrusion,
                },
                volt2,
            ),
        })
        .collect();
    if let Some(bad) = rows.iter().find(|r| !r.forces.total.is_finite()) {
        return Err(CliError::Failed(format!(
            "forces at d = {} m are not finite",
            bad.d
        )));
    }
    print_json(&rows)
}

#[derive(Serialize)]
struct FoldRow {
    power: f64,
    d: f64,
}

#[derive(Serialize)]
struct StaticReport {
    touchdown_power: f64,
    takeoff_power: f64,
    hysteresis: f64,
    pull_in_voltage: Option<f64>,
    folds: Vec<FoldRow>,
}

fn static_analyses(args: &[String]) -> Result<(), CliError> {
    let parsed = parse_args(args, &[], &[])?;
    let scene = parsed.load_scene()?;
    let model = SliderModel::from_scene(&scene)?;
    let opts = StaticOptions::new(scene.detector.contact_threshold_n);
    let h = static_hysteresis(&model, &opts)?;
    let pull_in_voltage = if model.forces().has_voltage_terms() {
        Some(pull_in_voltage(&model, 0.0, &opts)?.voltage)
    } else {
        None
    };
    let curve = s_curve(&model, None, &ScanGrid::default())?;
    print_json(&StaticReport {
        touchdown_power: h.touchdown.power,
        takeoff_power: h.takeoff.power,
        hysteresis: h.hysteresis,
        pull_in_voltage,
        folds: curve
            .folds
            .iter()
            .map(|f| FoldRow {
                power: f.power,
                d: f.d,
            })
            .collect(),
    })
}

#[derive(Serialize)]
struct CycleReport {
    v_ac: f64,
    touchdown_power: Option<f64>,
    takeoff_power: Option<f64>,
    hysteresis: Option<f64>,
    mean_temperature_rise: f64,
    steps: usize,
    wall_seconds: f64,
}

impl From<&CycleResult> for CycleReport {
    fn from(r: &CycleResult) -> Self {
        CycleReport {
            v_ac: r.v_ac,
            touchdown_power: r.touchdown.map(|d| d.power),
            takeoff_power: r.takeoff.map(|d| d.power),
            hysteresis: r.hysteresis,
            mean_temperature_rise: r.mean_temperature_rise,
            steps: r.stats.accepted,
            wall_seconds: r.wall_seconds,
        }
    }
}

/// Model, programme and cycle options of a scene, with the command line's overrides.
fn cycle_setup(
    parsed: &Parsed,
    scene: &Scene,
) -> Result<(SliderModel, HeaterProgramme, CycleOptions), CliError> {
    let model = SliderModel::from_scene(scene)?;
    let mut opts = CycleOptions::from_scene(scene)?;
    if let Some(m) = parsed.value("method") {
        opts.solver.method = m
            .parse()
            .map_err(|e: hdi_tribology::ode::OdeError| CliError::Usage(format!("--method: {e}")))?;
    }
    if let Some(r) = parsed.value("rtol") {
        opts.solver.rtol = parse_number("rtol", r)?;
    }
    let programme = if parsed.flag("triggered") {
        let t = &scene.heater.triggered;
        HeaterProgramme::Triggered {
            start_power: t.start_power_w,
            ramp_rate: t.ramp_rate_w_per_s,
            overshoot: t.overshoot_w,
        }
    } else {
        HeaterProgramme::Fixed(SliderModel::programme_from_knots(&scene.heater.programme)?)
    };
    Ok((model, programme, opts))
}

fn cycle(args: &[String]) -> Result<(), CliError> {
    let parsed = parse_args(args, &["v-ac", "csv", "method", "rtol"], &["triggered"])?;
    let scene = parsed.load_scene()?;
    let (mut model, programme, mut opts) = cycle_setup(&parsed, &scene)?;
    if let Some(v) = parsed.value("v-ac") {
        model = model.with_voltage(Voltage {
            ac_amplitude: parse_number("v-ac", v)?,
            ..model.voltage
        });
    }
    let csv = parsed.value("csv");
    opts.keep_series = csv.is_some();
    let r = simulate_cycle(&model, &programme, &opts)?;
    if let (Some(path), Some(s)) = (csv, r.series.as_ref()) {
        s.write_csv(std::path::Path::new(path))?;
    }
    print_json(&CycleReport::from(&r))
}

fn sweep(args: &[String]) -> Result<(), CliError> {
    let parsed = parse_args(args, &["v-ac", "method", "rtol", "refine"], &["triggered"])?;
    let scene = parsed.load_scene()?;
    let (model, programme, opts) = cycle_setup(&parsed, &scene)?;
    let amplitudes = match parsed.value("v-ac") {
        Some(list) => parse_list("v-ac", list)?,
        None => scene.sweep.ac_amplitudes_v.clone(),
    };
    if amplitudes.is_empty() {
        return Err(CliError::Usage(
            "no amplitudes: give --v-ac or a [sweep] list in the scene".into(),
        ));
    }
    if let Some(tol) = parsed.value("refine") {
        let refine = Refinement::new(parse_number("refine", tol)?);
        let rows: Vec<RefinedReport> =
            ac_sweep_refined(&model, &programme, &opts, &amplitudes, &refine)?
                .iter()
                .map(|r| RefinedReport {
                    cycle: CycleReport {
                        steps: r.stats.accepted,
                        wall_seconds: r.wall_seconds,
                        ..CycleReport::from(&r.cycle)
                    },
                    rtol: r.rtol,
                    power_change: r.change,
                    converged: r.converged,
                    runs: r.runs,
                })
                .collect();
        return print_json(&rows);
    }
    let rows: Vec<CycleReport> = ac_sweep(&model, &programme, &opts, &amplitudes)?
        .iter()
        .map(CycleReport::from)
        .collect();
    print_json(&rows)
}

/// A row of `sweep --refine`: the last cycle (steps and wall time over all runs) and how the
/// tolerance was refined.
#[derive(Serialize)]
struct RefinedReport {
    #[serde(flatten)]
    cycle: CycleReport,
    rtol: f64,
    power_change: f64,
    converged: bool,
    runs: usize,
}

#[derive(Serialize)]
struct CalibrationReport {
    detector: String,
    touchdown_power: f64,
    takeoff_power: Option<f64>,
    hysteresis: Option<f64>,
    set_power: f64,
    clearance: f64,
    contrast: f64,
    levels: usize,
    simulated_time: f64,
    wall_seconds: f64,
}

fn calibrate_cmd(args: &[String]) -> Result<(), CliError> {
    use hdi_tribology::clearance::{
        calibrate, CalibrationOptions, ContactForceRms, MeanContactForce, Relative,
        TouchdownDetector, VibrationRms,
    };
    let parsed = parse_args(
        args,
        &[
            "start-mw",
            "step-mw",
            "max-mw",
            "margin-mw",
            "detector",
            "dither-v",
        ],
        &["no-takeoff"],
    )?;
    let scene = parsed.load_scene()?;
    let mut model = SliderModel::from_scene(&scene)?;
    let mw_option = |name: &str| {
        parsed
            .value(name)
            .map(|v| parse_number(name, v))
            .transpose()
    };
    let start_mw = match mw_option("start-mw")? {
        Some(p) => p,
        None => {
            1e3 * ((scene.nominal_clearance_m - 5e-9) / scene.heater.efficiency_m_per_w).max(0.0)
        }
    };
    let step_mw = mw_option("step-mw")?.unwrap_or(0.5);
    let max_mw = mw_option("max-mw")?.unwrap_or(start_mw + 60.0);
    let margin_mw = mw_option("margin-mw")?.unwrap_or(15.0);
    let mut opts = CalibrationOptions::from_mw(start_mw, step_mw, max_mw, margin_mw);
    opts.find_takeoff = !parsed.flag("no-takeoff");
    if let Some(v) = parsed.value("dither-v") {
        model = model.with_voltage(Voltage {
            ac_amplitude: parse_number("dither-v", v)?,
            ..model.voltage
        });
    }
    let (th, window) = (scene.detector.contact_threshold_n, scene.detector.window_s);
    let mut detector: Box<dyn TouchdownDetector> = match parsed.value("detector").unwrap_or("mean")
    {
        "mean" => Box::new(MeanContactForce::new(th, window)?),
        "ae" => Box::new(ContactForceRms::new(1e-5, 5e3, 5e-5)?),
        "vibration" => Box::new(Relative::new(
            VibrationRms::new(2e-11, 5e3, 5e-5)?,
            3.0,
            1e-4,
            2e-4,
        )?),
        other => {
            return Err(CliError::Usage(format!(
                "--detector: `{other}` is not one of mean, ae, vibration"
            )))
        }
    };
    let clock = std::time::Instant::now();
    let c = calibrate(&model, detector.as_mut(), &opts)?;
    print_json(&CalibrationReport {
        hysteresis: c.hysteresis(),
        detector: c.detector,
        touchdown_power: c.touchdown_power,
        takeoff_power: c.takeoff_power,
        set_power: c.set_power,
        clearance: c.clearance,
        contrast: c.contrast,
        levels: c.steps.len(),
        simulated_time: c.simulated_time,
        wall_seconds: clock.elapsed().as_secs_f64(),
    })
}

fn scene(args: &[String]) -> Result<(), CliError> {
    let parsed = parse_args(args, &[], &["json"])?;
    let scene = parsed.load_scene()?;
    scene.validate()?;
    let text = if parsed.flag("json") {
        scene.to_json_string()?
    } else {
        scene.to_toml_string()?
    };
    print_text(text.trim_end())
}
