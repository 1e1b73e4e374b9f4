//! `hdi fit`: fit free scene fields to measured curves.

use std::path::{Path, PathBuf};

use hdi_tribology::fit::{fit, DataSet, FitOptions, FitResult, FreeParameter};
use hdi_tribology::Error;

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

/// Writes the plots drawn in `scratch` into `dir`, each through [`Output`].
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
    let failed = |e: hdi_tribology::Error| CliError::Failed(e.to_string());
    let data = a
        .data
        .iter()
        .map(DataSet::from_path)
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| CliError::Failed(e.to_string()))?;
    let free = a
        .free
        .iter()
        .flat_map(|s| s.split(','))
        .filter(|s| !s.trim().is_empty())
        .map(str::parse)
        .collect::<hdi_tribology::Result<Vec<FreeParameter>>>()?;
    let options = FitOptions {
        starts: a.starts as usize,
        seed: a.seed,
        ..FitOptions::default()
    };
    let progress = common::Progress::spinner("fit: least squares");
    let result = fit(&scene, &data, &free, &options).map_err(failed)?;
    drop(progress);
    if let Some(dir) = &a.plot {
        // Drawn into a scratch folder; each plot then goes through the one writer.
        let scratch = tempfile::tempdir()
            .map_err(|e| CliError::Failed(format!("--plot: no scratch folder: {e}")))?;
        write_plots(&result, scratch.path())?;
        deliver_plots(scratch.path(), dir)?;
    }
    if !result.trusted {
        common::warn("the fit is not trusted; see \"warnings\" in the output");
    }
    common::print_json(&result)
}

/// Writes, per measured column, `<file>_<column>.svg` (data and fit) and
/// `<file>_<column>_residuals.svg` into `dir`; returns the files written.
#[cfg(feature = "plot")]
fn write_plots(result: &FitResult, dir: &Path) -> hdi_tribology::Result<Vec<PathBuf>> {
    use hdi_tribology::report::{Chart, Series};
    std::fs::create_dir_all(dir).map_err(|source| Error::Io {
        path: dir.display().to_string(),
        source,
    })?;
    let mut written = Vec::new();
    for t in &result.residuals {
        let stem = Path::new(&t.file)
            .file_stem()
            .map_or("data".into(), |s| s.to_string_lossy().into_owned());
        let name = format!("{stem}_{}", t.column);
        let pts = |f: fn(&hdi_tribology::fit::ResidualRow) -> f64| {
            t.rows.iter().map(|r| (r.x, f(r))).collect::<Vec<_>>()
        };
        let mut fitted = pts(|r| r.fitted);
        fitted.sort_by(|a, b| a.0.total_cmp(&b.0));
        let title = format!("{} against {}", t.column, t.x_column);
        let path = dir.join(format!("{name}.svg"));
        Chart {
            title: &title,
            x_label: &t.x_column,
            y_label: &t.column,
            series: vec![
                Series::line("fitted model", fitted),
                Series::markers("measured", pts(|r| r.measured)),
            ],
            ..Chart::default()
        }
        .to_svg(&path, 720, 440)?;
        written.push(path);
        let rtitle = format!("residuals (fitted − measured) of {}", t.column);
        let path = dir.join(format!("{name}_residuals.svg"));
        let mut zero = vec![(
            t.rows.iter().map(|r| r.x).fold(f64::INFINITY, f64::min),
            0.0,
        )];
        zero.push((
            t.rows.iter().map(|r| r.x).fold(f64::NEG_INFINITY, f64::max),
            0.0,
        ));
        Chart {
            title: &rtitle,
            x_label: &t.x_column,
            y_label: &t.column,
            series: vec![
                Series::line("zero", zero),
                Series::markers("residual", pts(|r| r.residual)),
            ],
            ..Chart::default()
        }
        .to_svg(&path, 720, 320)?;
        written.push(path);
    }
    Ok(written)
}

/// Without the `plot` feature there is nothing to draw with.
#[cfg(not(feature = "plot"))]
fn write_plots(_result: &FitResult, _dir: &Path) -> hdi_tribology::Result<Vec<PathBuf>> {
    Err(Error::invalid("--plot", "this build has no `plot` feature"))
}
