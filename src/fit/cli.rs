//! `hdi fit`: the command's work on parsed arguments, so the command line only parses.

use std::path::{Path, PathBuf};

use super::{fit, DataSet, FitError, FitOptions, FitResult, FreeParameter};
use crate::scene::Scene;
use crate::Error;

/// The parsed arguments of `hdi fit SCENE --data FILE [--data FILE …] --free NAME[=LO:HI],…
/// [--starts N] [--seed S] [--plot DIR]`.
#[derive(Clone, Debug)]
pub struct CliArgs {
    /// The scene to start from.
    pub scene: Scene,
    /// Data files (CSV).
    pub data: Vec<PathBuf>,
    /// Free parameters as written after `--free` (comma lists already split or not).
    pub free: Vec<String>,
    /// Fit settings (`--starts`, `--seed`).
    pub options: FitOptions,
    /// Folder for SVG plots of the data against the fit, with residuals.
    pub plot: Option<PathBuf>,
}

/// Runs `hdi fit`: reads the data, fits, writes the plots when asked, and returns the JSON to
/// print (the fitted scene, the parameters with their errors, the correlations, the residuals
/// and the identifiability report).
///
/// ```no_run
/// use hdi_tribology::fit::{run_cli, CliArgs, FitOptions};
/// let args = CliArgs {
///     scene: hdi_tribology::scene::Scene::paper(),
///     data: vec!["touchdown_vs_vdc.csv".into()],
///     free: vec!["height_sigma_nm,contact_potential_v".into()],
///     options: FitOptions::default(),
///     plot: Some("out/fit".into()),
/// };
/// println!("{}", run_cli(&args)?);
/// # Ok::<(), hdi_tribology::fit::FitError>(())
/// ```
pub fn run_cli(args: &CliArgs) -> Result<String, FitError> {
    if args.data.is_empty() {
        return Err(Error::invalid("--data", "give at least one data file").into());
    }
    let data = args
        .data
        .iter()
        .map(DataSet::from_path)
        .collect::<Result<Vec<_>, _>>()?;
    let free = args
        .free
        .iter()
        .flat_map(|s| s.split(','))
        .filter(|s| !s.trim().is_empty())
        .map(str::parse)
        .collect::<crate::Result<Vec<FreeParameter>>>()?;
    let result = fit(&args.scene, &data, &free, &args.options)?;
    if let Some(dir) = &args.plot {
        write_plots(&result, dir)?;
    }
    serde_json::to_string_pretty(&result)
        .map_err(|e| Error::output("the fit result as JSON", e.to_string()).into())
}

/// Writes, per measured column, `<file>_<column>.svg` (data and fit) and
/// `<file>_<column>_residuals.svg` into `dir`; returns the files written.
#[cfg(feature = "plot")]
pub fn write_plots(result: &FitResult, dir: &Path) -> crate::Result<Vec<PathBuf>> {
    use crate::report::{Chart, Series};
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
        let pts = |f: fn(&super::ResidualRow) -> f64| {
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
pub fn write_plots(_result: &FitResult, _dir: &Path) -> crate::Result<Vec<PathBuf>> {
    Err(Error::invalid("--plot", "this build has no `plot` feature"))
}
