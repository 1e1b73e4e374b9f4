//! `hdi cycle`: one touchdown/take-off cycle; also the cycle options and report `hdi sweep` uses.

use std::path::PathBuf;

use hdi_tribology::analysis::sweep::{flags, Flag};
use hdi_tribology::analysis::{
    ac_sweep, ac_sweep_refined, CycleOptions, CycleResult, HeaterProgramme, RefinedCycle,
    Refinement,
};
use hdi_tribology::model::SliderModel;
use hdi_tribology::scene::Scene;
use hdi_tribology::units::{fmt_short, mw as from_mw, nm as from_nm};
use serde::Serialize;

use crate::common::{self, positive, rtol, volts, CliError, Output, SceneArgs};

/// One touchdown/take-off cycle under the scene's fixed heater programme (or the
/// touchdown-triggered protocol), JSON: v_ac (V), touchdown_power, takeoff_power, hysteresis
/// (W), mean_temperature_rise (K), steps, wall_seconds, rtol, atol_m, runs, power_change (W),
/// temperature_change (K), status and flags.
///
/// By default the solver tolerances are tightened tenfold per run until touchdown and take-off
/// move by at most --refine-mw and the mean temperature rise by at most --refine-k; status is then
/// "converged" or "not_converged". With --no-refine the cycle runs once and status is
/// "unchecked". Flags: no_touchdown, no_takeoff, negative_hysteresis, not_converged; each flag is
/// also warned about on stderr.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    scene: SceneArgs,
    /// AC amplitude (V) [default: the scene's voltage.ac_amplitude_v].
    #[arg(long, value_name = "V", value_parser = volts, allow_hyphen_values = true)]
    v_ac: Option<f64>,
    /// Write the time series of spacing and forces of the final run as CSV to FILE.
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
    #[command(flatten)]
    pub cycle: CycleArgs,
}

/// The programme, solver and refinement options of `cycle` and `sweep`.
#[derive(clap::Args)]
pub struct CycleArgs {
    /// Run the touchdown-triggered protocol (the scene's heater.triggered) instead of the fixed
    /// programme.
    #[arg(long)]
    triggered: bool,
    /// ODE method (auto, rodas5p, radau5, tsit5, dop853) [default: the scene's solver.method].
    #[arg(long, value_name = "M")]
    method: Option<String>,
    /// Relative tolerance of the first run, in [2.2e-14, 1) (100 ε up to 1, as in a scene; the
    /// refined runs must stay in it too) [default: the scene's solver.rtol]. Without --atol-nm the
    /// absolute tolerance is scaled with it.
    #[arg(long, value_name = "R", value_parser = rtol, allow_hyphen_values = true)]
    rtol: Option<f64>,
    /// Absolute tolerance on the displacement of the first run (nm) [default: the scene's
    /// solver.atol_m, scaled with --rtol].
    #[arg(long, value_name = "NM", value_parser = positive, allow_hyphen_values = true)]
    atol_nm: Option<f64>,
    /// Converged when touchdown and take-off move by at most this (mW) under a tenfold tighter
    /// tolerance.
    #[arg(long, value_name = "MW", default_value = "0.01", value_parser = positive,
          allow_hyphen_values = true)]
    refine_mw: f64,
    /// ... and the mean temperature rise by at most this (K).
    #[arg(long, value_name = "K", default_value = "0.05", value_parser = positive,
          allow_hyphen_values = true)]
    refine_k: f64,
    /// Most runs per cycle while refining, the first included.
    #[arg(long, value_name = "N", default_value = "5",
          value_parser = clap::value_parser!(u8).range(2..=12))]
    max_runs: u8,
    /// Successive runs that must agree (2: one agreeing pair; 3 also catches a take-off a
    /// whole period of V² off in two runs alike), at most --max-runs.
    #[arg(long, value_name = "N", default_value = "2",
          value_parser = clap::value_parser!(u8).range(2..=12))]
    agree: u8,
    /// Run each cycle once at the given tolerances, without checking convergence (status
    /// "unchecked").
    #[arg(long, conflicts_with_all = ["refine_mw", "refine_k", "max_runs", "agree"])]
    no_refine: bool,
}

impl CycleArgs {
    /// The model, programme and cycle options of `scene` with these overrides.
    pub fn setup(
        &self,
        scene: &Scene,
    ) -> Result<(SliderModel, HeaterProgramme, CycleOptions), CliError> {
        let model = SliderModel::from_scene(scene)?;
        let mut opts = CycleOptions::from_scene(scene)?;
        if let Some(m) = &self.method {
            opts.solver.method = m.parse().map_err(|e: hdi_tribology::ode::OdeError| {
                CliError::Usage(format!("invalid value '{m}' for '--method <M>': {e}"))
            })?;
        }
        if let Some(r) = self.rtol {
            opts.solver = opts.solver.with_rtol(r);
        }
        if let Some(a) = self.atol_nm {
            opts.solver.atol_displacement = from_nm(a);
        }
        let programme = if self.triggered {
            HeaterProgramme::triggered_from_scene(scene)
        } else {
            HeaterProgramme::fixed_from_scene(scene)?
        };
        Ok((model, programme, opts))
    }

    /// One report per amplitude, refined unless --no-refine; flags are warned about on stderr.
    pub fn run(
        &self,
        model: &SliderModel,
        programme: &HeaterProgramme,
        opts: &CycleOptions,
        amplitudes: &[f64],
    ) -> Result<Vec<(Report, CycleResult)>, CliError> {
        let rows: Vec<(Report, CycleResult)> = if self.no_refine {
            ac_sweep(model, programme, opts, amplitudes)?
                .into_iter()
                .map(|c| (Report::unchecked(&c, opts), c))
                .collect()
        } else {
            if self.agree > self.max_runs {
                return Err(CliError::Usage(format!(
                    "invalid value '{}' for '--agree <N>': must be at most --max-runs ({})",
                    self.agree, self.max_runs
                )));
            }
            let refine = Refinement {
                power_tol: from_mw(self.refine_mw),
                temperature_tol: self.refine_k,
                max_runs: usize::from(self.max_runs),
                agreeing_runs: usize::from(self.agree),
                ..Refinement::new(from_mw(self.refine_mw))
            };
            // The last run must stay in the solver's range too: checked before the first.
            let last = opts.solver.rtol * refine.factor.powi(i32::from(self.max_runs) - 1);
            let min = hdi_tribology::ode::MIN_RTOL;
            if last < min {
                let from = match self.rtol {
                    Some(r) => format!("--rtol {}", fmt_short(r)),
                    None => format!("the scene's solver.rtol {}", fmt_short(opts.solver.rtol)),
                };
                return Err(CliError::Usage(format!(
                    "{from} with --max-runs {} tightens to rtol {} in the last run, below the \
                     solver's {min:.1e} (100 ε): raise --rtol or lower --max-runs",
                    self.max_runs,
                    fmt_short(last)
                )));
            }
            ac_sweep_refined(model, programme, opts, amplitudes, &refine)?
                .into_iter()
                .map(|r| (Report::refined(&r), r.cycle))
                .collect()
        };
        for (r, _) in &rows {
            r.warn();
        }
        Ok(rows)
    }
}

/// One cycle as printed.
#[derive(Serialize)]
pub struct Report {
    v_ac: f64,
    touchdown_power: Option<f64>,
    takeoff_power: Option<f64>,
    hysteresis: Option<f64>,
    mean_temperature_rise: f64,
    steps: usize,
    wall_seconds: f64,
    rtol: f64,
    atol_m: f64,
    runs: usize,
    power_change: Option<f64>,
    temperature_change: Option<f64>,
    status: &'static str,
    flags: Vec<Flag>,
}

impl Report {
    fn base(c: &CycleResult) -> Report {
        Report {
            v_ac: c.v_ac,
            touchdown_power: c.touchdown.map(|d| d.power),
            takeoff_power: c.takeoff.map(|d| d.power),
            hysteresis: c.hysteresis,
            mean_temperature_rise: c.mean_temperature_rise,
            steps: c.stats.accepted,
            wall_seconds: c.wall_seconds,
            rtol: 0.0,
            atol_m: 0.0,
            runs: 1,
            power_change: None,
            temperature_change: None,
            status: "unchecked",
            flags: flags(c),
        }
    }

    fn unchecked(c: &CycleResult, opts: &CycleOptions) -> Report {
        Report {
            rtol: opts.solver.rtol,
            atol_m: opts.solver.atol_displacement,
            ..Report::base(c)
        }
    }

    fn refined(r: &RefinedCycle) -> Report {
        Report {
            steps: r.stats.accepted,
            wall_seconds: r.wall_seconds,
            rtol: r.rtol,
            atol_m: r.atol,
            runs: r.runs,
            // ∞ (a detection that comes and goes) is printed as null
            power_change: Some(r.change).filter(|x| x.is_finite()),
            temperature_change: Some(r.temperature_change),
            status: if r.converged {
                "converged"
            } else {
                "not_converged"
            },
            flags: r.flags(),
            ..Report::base(&r.cycle)
        }
    }

    /// One line on stderr per flag.
    fn warn(&self) {
        let at = format!("--v-ac {}", fmt_short(self.v_ac));
        for f in &self.flags {
            let detail = match f {
                Flag::NegativeHysteresis => format!(
                    ": take-off {} lies above touchdown {} (hysteresis {}), a detection artefact, \
                     not a hysteresis",
                    common::mw(self.takeoff_power.unwrap_or(f64::NAN)),
                    common::mw(self.touchdown_power.unwrap_or(f64::NAN)),
                    common::mw(self.hysteresis.unwrap_or(f64::NAN)),
                ),
                Flag::NotConverged => format!(
                    " after {} runs down to rtol {}: touchdown/take-off still moved by {}, \
                     mean temperature rise by {} K",
                    self.runs,
                    fmt_short(self.rtol),
                    self.power_change.map_or("a detection".into(), common::mw),
                    fmt_short(self.temperature_change.unwrap_or(f64::NAN)),
                ),
                Flag::NoTouchdown | Flag::NoTakeoff => String::new(),
            };
            common::warn(&format!("{at}: {f}{detail}"));
        }
    }
}

pub fn run(a: Args) -> Result<(), CliError> {
    // The output file is checked before anything is computed.
    let out = a
        .csv
        .as_deref()
        .map(|p| Output::prepare(p, "--csv"))
        .transpose()?;
    let scene = a.scene.load()?;
    let (model, programme, mut opts) = a.cycle.setup(&scene)?;
    opts.keep_series = out.is_some();
    let v_ac = a.v_ac.unwrap_or(model.voltage().ac_amplitude);
    let progress = common::Progress::spinner("cycle: refining until converged");
    let (report, cycle) = a
        .cycle
        .run(&model, &programme, &opts, &[v_ac])?
        .pop()
        .ok_or_else(|| CliError::Failed("the cycle gave no result".into()))?;
    drop(progress);
    if let (Some(out), Some(series)) = (out, cycle.series) {
        out.write_via_path(|p| Ok(series.write_csv(p)?))?;
    }
    common::print_json(&report)
}
