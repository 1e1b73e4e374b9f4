//! `hdi fit`: fit free scene fields to measured curves.

use std::path::PathBuf;

use hdi_tribology::fit::{run_cli, CliArgs, FitError, FitOptions};

use crate::common::{self, CliError, SceneArgs};

/// Fits scene fields to measured curves and prints JSON: the fitted scene, each parameter with
/// its standard error (null where the data do not determine it), the correlation matrix, the
/// residuals, the identifiability report in words, and `trusted` with its warnings. Data files
/// are CSV in engineering units (docs/fit.md): `dc_voltage_v` or `ac_amplitude_v`, then
/// `touchdown_power_mw` and/or `takeoff_power_mw`, optionally `touchdown_power_err_mw`; or
/// `heater_power_mw`, then `contact_indicator_un` (Fig. 1).
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    scene: SceneArgs,
    /// A measured curve (CSV); repeat for several.
    #[arg(long = "data", value_name = "FILE", required = true)]
    data: Vec<PathBuf>,
    /// Parameters to fit, named as in a scene file with their unit, each optionally with
    /// bounds in that unit: `height_sigma_nm=0.3:1.5,contact_potential_v`.
    #[arg(long = "free", value_name = "NAME[=LO:HI],...", required = true)]
    free: Vec<String>,
    /// Number of starts (the scene's values, then seeded draws inside the bounds).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1000))]
    starts: u32,
    /// Seed of the extra starts.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Folder for SVG plots of the data against the fit, with residuals.
    #[arg(long, value_name = "DIR")]
    plot: Option<PathBuf>,
}

pub fn run(a: Args) -> Result<(), CliError> {
    let scene = a.scene.load()?;
    let args = CliArgs {
        scene,
        data: a.data,
        free: a.free,
        options: FitOptions {
            starts: a.starts as usize,
            seed: a.seed,
            ..FitOptions::default()
        },
        plot: a.plot,
    };
    let json = run_cli(&args).map_err(|e: FitError| CliError::Failed(e.to_string()))?;
    let value: serde_json::Value =
        serde_json::from_str(&json).map_err(|e| CliError::Failed(e.to_string()))?;
    if value["trusted"] == serde_json::Value::Bool(false) {
        common::warn("the fit is not trusted; see \"warnings\" in the output");
    }
    common::print_text(&json)
}
