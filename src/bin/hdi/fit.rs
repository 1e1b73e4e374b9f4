//! `hdi fit`: fit free scene fields to measured curves.

use std::path::{Path, PathBuf};

use hdi_tribology::fit::{run_cli, CliArgs, FitError, FitOptions};

use crate::common::{self, CliError, Output, SceneArgs};

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

/// Checks the --plot folder before the fit: a folder, or a name whose nearest existing
/// ancestor is a folder (it is then created after the fit).
fn check_plot_dir(dir: &Path) -> Result<(), CliError> {
    let shown = format!("--plot {}", dir.display());
    if !cfg!(feature = "plot") {
        return Err(CliError::Failed(format!(
            "{shown}: this build has no `plot` feature"
        )));
    }
    let mut p = dir;
    loop {
        match std::fs::metadata(p) {
            Ok(m) if m.is_dir() => return Ok(()),
            Ok(_) if p == dir => {
                return Err(CliError::Failed(format!(
                    "{shown}: is a file, give a folder for the plots"
                )))
            }
            Ok(_) => {
                return Err(CliError::Failed(format!(
                    "{shown}: {} is a file, not a folder",
                    p.display()
                )))
            }
            Err(_) => match p.parent() {
                Some(up) if !up.as_os_str().is_empty() => p = up,
                _ => return Ok(()),
            },
        }
    }
}

/// Writes the plots `run_cli` drew in `scratch` into `dir`, each through [`Output`].
fn deliver_plots(scratch: &Path, dir: &Path) -> Result<(), CliError> {
    std::fs::create_dir_all(dir)
        .map_err(|e| CliError::Failed(format!("--plot {}: {e}", dir.display())))?;
    let read = |e: std::io::Error| CliError::Failed(format!("--plot: {e}"));
    let mut names: Vec<_> = std::fs::read_dir(scratch)
        .map_err(read)?
        .map(|e| e.map(|e| e.file_name()))
        .collect::<Result<_, _>>()
        .map_err(read)?;
    names.sort();
    for name in names {
        let bytes = std::fs::read(scratch.join(&name)).map_err(read)?;
        Output::prepare(&dir.join(&name), "--plot")?.write(&bytes)?;
    }
    Ok(())
}

pub fn run(a: Args) -> Result<(), CliError> {
    if let Some(dir) = &a.plot {
        check_plot_dir(dir)?;
    }
    let scene = a.scene.load()?;
    // The library draws into a scratch folder; the plots then go through the one writer.
    let scratch = match a.plot {
        Some(_) => Some(
            tempfile::tempdir()
                .map_err(|e| CliError::Failed(format!("--plot: no scratch folder: {e}")))?,
        ),
        None => None,
    };
    let args = CliArgs {
        scene,
        data: a.data,
        free: a.free,
        options: FitOptions {
            starts: a.starts as usize,
            seed: a.seed,
            ..FitOptions::default()
        },
        plot: scratch.as_ref().map(|d| d.path().to_path_buf()),
    };
    let progress = common::Progress::spinner("fit: least squares");
    let json = run_cli(&args).map_err(|e: FitError| CliError::Failed(e.to_string()))?;
    drop(progress);
    if let (Some(scratch), Some(dir)) = (&scratch, &a.plot) {
        deliver_plots(scratch.path(), dir)?;
    }
    let value: serde_json::Value =
        serde_json::from_str(&json).map_err(|e| CliError::Failed(e.to_string()))?;
    if value["trusted"] == serde_json::Value::Bool(false) {
        common::warn("the fit is not trusted; see \"warnings\" in the output");
    }
    common::print_text(&json)
}
