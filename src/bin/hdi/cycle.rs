//! `hdi cycle`: one touchdown/take-off cycle; also the cycle options and report `hdi sweep` uses.

use std::path::PathBuf;

use crate::common::{self, positive, rtol, volts, CliError, Output, SceneArgs};
use hdi_tribology::analysis::record::CycleRecord;
use hdi_tribology::analysis::sweep::Flag;
use hdi_tribology::analysis::{
    ac_sweep, ac_sweep_refined, CycleOptions, HeaterProgramme, Refinement, TimeSeries,
};
use hdi_tribology::model::SliderModel;
use hdi_tribology::scene::Scene;
use hdi_tribology::units::{fmt_short, mw as from_mw, shift_decimal};

/// One touchdown/take-off cycle under the scene's fixed heater programme (or the
/// touchdown-triggered protocol), JSON, each key with its unit: scene, programme (fixed or
/// triggered), v_ac_v, touchdown and takeoff ({time_s, power_w} or null), hysteresis_w,
/// mean_temperature_rise_k, duration_s, method (as asked, or the stiff method `auto` ran from
/// the start), stats and wall_seconds (of the run kept), rtol, atol_m, runs, power_change_w,
/// temperature_change_k, total_stats, total_wall_seconds (over every run), status and flags
/// (docs/python.md, "Results"); with an interface lag also lag_work_j and damping_work_j (the
/// lag's energy audit, docs/analyses.md).
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
        let model = common::model(scene)?;
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
            // In metres as typed in nm: 0.01 nm is 1e-11 m (not 1.0000000000000001e-11).
            opts.solver.atol_displacement = shift_decimal(a, -9);
        }
        let programme = if self.triggered {
            HeaterProgramme::triggered_from_scene(scene)
        } else {
            HeaterProgramme::fixed_from_scene(scene)?
        };
        Ok((model, programme, opts))
    }

    /// One record per amplitude, refined unless --no-refine; flags are warned about on stderr.
    pub fn run(
        &self,
        scene: &Scene,
        model: &SliderModel,
        programme: &HeaterProgramme,
        opts: &CycleOptions,
        amplitudes: &[f64],
    ) -> Result<Vec<(CycleRecord, Option<TimeSeries>)>, CliError> {
        let name = scene.name.as_str();
        let rows: Vec<(CycleRecord, Option<TimeSeries>)> = if self.no_refine {
            ac_sweep(model, programme, opts, amplitudes)?
                .into_iter()
                .map(|mut c| {
                    let series = c.series.take();
                    (CycleRecord::unchecked(name, programme, c, opts), series)
                })
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
            let last = refine.tolerance(opts.solver.rtol, usize::from(self.max_runs) - 1);
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
                .map(|mut r| {
                    let series = r.cycle.series.take();
                    (CycleRecord::refined(name, programme, r), series)
                })
                .collect()
        };
        for (r, _) in &rows {
            warn(r);
        }
        Ok(rows)
    }
}

/// One line on stderr per flag of `r`.
fn warn(r: &CycleRecord) {
    let c = &r.cycle;
    let at = format!("--v-ac {}", fmt_short(c.v_ac));
    for f in &r.flags {
        let detail = match f {
            Flag::NegativeHysteresis => format!(
                ": take-off {} lies above touchdown {} (hysteresis {}), a detection artefact, \
                 not a hysteresis",
                common::mw(c.takeoff.map_or(f64::NAN, |d| d.power)),
                common::mw(c.touchdown.map_or(f64::NAN, |d| d.power)),
                common::mw(c.hysteresis.unwrap_or(f64::NAN)),
            ),
            Flag::NotConverged => format!(
                " after {} runs down to rtol {}: touchdown/take-off still moved by {}, \
                 mean temperature rise by {} K",
                r.runs,
                fmt_short(r.rtol),
                r.power_change_w.map_or("a detection".into(), common::mw),
                fmt_short(r.temperature_change_k.unwrap_or(f64::NAN)),
            ),
            Flag::NoTouchdown | Flag::NoTakeoff | Flag::TakeoffWithoutDither => String::new(),
        };
        common::warn(&format!("{at}: {f}{detail}"));
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
    let (record, series) = a
        .cycle
        .run(&scene, &model, &programme, &opts, &[v_ac])?
        .pop()
        .ok_or_else(|| CliError::Failed("the cycle gave no result".into()))?;
    drop(progress);
    if let (Some(out), Some(series)) = (out, series) {
        out.write_via_path(|p| Ok(series.write_csv(p)?))?;
    }
    common::print_json(&record)
}
