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
        write_plots(&result, &data, scratch.path())?;
        deliver_plots(scratch.path(), dir)?;
    }
    if !result.trusted {
        common::warn("the fit is not trusted; see \"warnings\" in the output");
    }
    common::print_json(&result)
}

#[cfg_attr(not(feature = "plot"), allow(dead_code))]
/// A unit suffix as written in a column or parameter name (`mw`, `nm_per_mw`, `j_m6`) as its
/// symbol (`mW`, `nm/mW`, `J m⁶`); an unknown part is kept as written.
fn unit_symbol(suffix: &str) -> String {
    let part = |p: &str| -> String {
        p.split('_')
            .map(|t| match t {
                "v" => "V",
                "mv" => "mV",
                "w" => "W",
                "mw" => "mW",
                "uw" => "µW",
                "n" => "N",
                "mn" => "mN",
                "un" => "µN",
                "nn" => "nN",
                "m" => "m",
                "mm" => "mm",
                "um" => "µm",
                "nm" => "nm",
                "m2" => "m²",
                "m6" => "m⁶",
                "j" => "J",
                "kg" => "kg",
                "s" => "s",
                "hz" => "Hz",
                "khz" => "kHz",
                "pa" => "Pa",
                "k" => "K",
                other => other,
            })
            .collect::<Vec<_>>()
            .join(" ")
    };
    match suffix.split_once("_per_") {
        Some((num, den)) => format!("{}/{}", part(num), part(den)),
        None => part(suffix),
    }
}

#[cfg_attr(not(feature = "plot"), allow(dead_code))]
/// The axis label of a data column (`dc_voltage_v` → `V_{dc} (V)`), in the typesetting of
/// [`hdi_tribology::report::typeset`].
fn column_label(column: &str) -> String {
    let Some((stem, unit)) = column.rsplit_once('_') else {
        return column.to_string();
    };
    let name = match stem {
        "dc_voltage" => "V_{dc}",
        "ac_amplitude" => "V_{ac}",
        "heater_power" => "heater power",
        "touchdown_power" => "touchdown power P_{TD}",
        "takeoff_power" => "take-off power P_{TO}",
        "contact_indicator" => "contact indicator",
        other => other,
    };
    format!("{name} ({})", unit_symbol(unit))
}

#[cfg_attr(not(feature = "plot"), allow(dead_code))]
/// The fitted parameters as notes: name, value ± standard error and unit symbol.
fn parameter_notes(result: &FitResult) -> Vec<String> {
    use hdi_tribology::report::tick_label;
    let mut notes = vec![format!(
        "Fit ({}): χ² = {}, {} points{}",
        if result.trusted {
            "trusted"
        } else {
            "not trusted"
        },
        tick_label(result.chi2, false),
        result.points,
        if result.trusted {
            "."
        } else {
            "; see the warnings."
        }
    )];
    for p in &result.parameters {
        let name = p
            .name
            .strip_suffix(&format!("_{}", p.unit))
            .unwrap_or(&p.name);
        let unit = unit_symbol(&p.unit);
        notes.push(match p.standard_error {
            Some(se) => format!("{name} = {} {unit}", with_error(p.value, se)),
            None => format!(
                "{name} = {} {unit} (not determined)",
                tick_label(p.value, false)
            ),
        });
    }
    notes
}

#[cfg_attr(not(feature = "plot"), allow(dead_code))]
/// `value ± error` with the error to two significant digits and the value to the same place:
/// `0.70204 ± 0.00069`, or `(1.0056 ± 0.0018)·10^{-19}` where that would need more than six
/// decimals or the value is large.
fn with_error(value: f64, error: f64) -> String {
    if !(value.is_finite() && error.is_finite() && error > 0.0) {
        return format!("{value} ± {error}");
    }
    let place = error.log10().floor() as i32 - 1;
    if (-6..=0).contains(&place) && value.abs() < 1e5 {
        let d = (-place) as usize;
        return format!("{value:.d$} ± {error:.d$}");
    }
    let e = if value != 0.0 {
        value.abs().log10().floor() as i32
    } else {
        place + 1
    };
    let scale = 10f64.powi(e);
    let d = (e - place).max(0) as usize;
    format!("({:.d$} ± {:.d$})·10^{{{e}}}", value / scale, error / scale)
}

/// The fitted model along a fine grid of the x range of `data` (static and indicator curves:
/// `(x, value)` in the file's units per measured column); `None` for cycles (one cycle per
/// point: the model is drawn at the measured amplitudes) or where the model cannot give it.
fn smooth_model(result: &FitResult, data: &DataSet) -> Option<Vec<Vec<(f64, f64)>>> {
    use hdi_tribology::fit::{model_curves, CurveKind};
    if data.kind == CurveKind::CycleVsAc || data.x.len() < 2 {
        return None;
    }
    let lo = data.x.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = data.x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    const N: usize = 60;
    let mut grid = data.clone();
    grid.x = (0..=N)
        .map(|i| lo + (hi - lo) * i as f64 / N as f64)
        .collect();
    grid.lines = (1..=grid.x.len() as u64).collect();
    for o in &mut grid.observed {
        o.values = vec![0.0; grid.x.len()];
        o.errors = None;
    }
    let curves = model_curves(&result.scene, &[grid]).ok()?;
    let c = curves.into_iter().next()?;
    Some(
        c.observed
            .iter()
            .map(|o| {
                c.x.iter()
                    .zip(&o.values)
                    .map(|(x, v)| (x / c.x_unit.to_si, v / o.unit.to_si))
                    .collect()
            })
            .collect(),
    )
}

/// Writes, per measured column, `<file>_<column>.svg` (the data, the fitted model as a smooth
/// curve where one is cheap, and the fitted parameters with their units) and
/// `<file>_<column>_residuals.svg` (model − measured, in the column's unit, against zero) into
/// `dir`; returns the files written.
#[cfg(feature = "plot")]
fn write_plots(
    result: &FitResult,
    data: &[DataSet],
    dir: &Path,
) -> hdi_tribology::Result<Vec<PathBuf>> {
    use hdi_tribology::report::{palette, Chart, Marker, Series};
    std::fs::create_dir_all(dir).map_err(|source| Error::Io {
        path: dir.display().to_string(),
        source,
    })?;
    let notes = parameter_notes(result);
    // The smooth model of each data file (by origin), one curve per measured column.
    type Curves = Vec<Vec<(f64, f64)>>;
    let mut smooth: Vec<(String, Curves)> = Vec::new();
    let mut written = Vec::new();
    for t in &result.residuals {
        let stem = Path::new(&t.file)
            .file_stem()
            .map_or("data".into(), |s| s.to_string_lossy().into_owned());
        let name = format!("{stem}_{}", t.column);
        let pts = |f: fn(&hdi_tribology::fit::ResidualRow) -> f64| {
            t.rows.iter().map(|r| (r.x, f(r))).collect::<Vec<_>>()
        };
        let ds = data.iter().find(|d| d.origin == t.file);
        if let Some(ds) = ds {
            if !smooth.iter().any(|(o, _)| *o == ds.origin) {
                if let Some(c) = smooth_model(result, ds) {
                    smooth.push((ds.origin.clone(), c));
                }
            }
        }
        // The measured column's place among its file's columns.
        let column = ds.and_then(|d| {
            d.observed
                .iter()
                .position(|o| format!("{}_{}", o.quantity.stem(), o.unit.suffix) == t.column)
        });
        let curve = smooth
            .iter()
            .find(|(o, _)| *o == t.file)
            .and_then(|(_, c)| column.and_then(|k| c.get(k)).cloned());
        let model = match curve {
            Some(c) => Series::line("fitted model", c),
            None => {
                let mut at = pts(|r| r.fitted);
                at.sort_by(|a, b| a.0.total_cmp(&b.0));
                Series::line("fitted model (at the measured x)", at)
            }
        };
        let (x_label, y_label) = (column_label(&t.x_column), column_label(&t.column));
        let path = dir.join(format!("{name}.svg"));
        Chart {
            title: &name,
            x_label: &x_label,
            y_label: &y_label,
            series: vec![
                model.colour(palette::BLUE).width(2),
                Series::markers("measured", pts(|r| r.measured))
                    .colour(palette::BLACK)
                    .marker(Marker::Circle),
            ],
            notes: notes.clone(),
            legend_width: Some(260),
            ..Chart::default()
        }
        .to_svg(&path, 1000, 560)?;
        written.push(path);
        let unit = t
            .column
            .rsplit_once('_')
            .map_or(String::new(), |(_, u)| unit_symbol(u));
        let r_label = format!("residual ({unit})");
        let path = dir.join(format!("{name}_residuals.svg"));
        let xs = t.rows.iter().map(|r| r.x);
        let zero = vec![
            (xs.clone().fold(f64::INFINITY, f64::min), 0.0),
            (xs.fold(f64::NEG_INFINITY, f64::max), 0.0),
        ];
        let (kept, left_out): (Vec<_>, Vec<_>) = t.rows.iter().partition(|r| !r.excluded);
        let mut series = vec![
            Series::line("", zero)
                .colour(palette::BLACK)
                .width(1)
                .dashed(),
            Series::markers(
                "residual = model − measured",
                kept.iter().map(|r| (r.x, r.residual)).collect(),
            )
            .colour(palette::BLUE),
        ];
        if !left_out.is_empty() {
            series.push(
                Series::markers(
                    "left out of the fit",
                    left_out.iter().map(|r| (r.x, r.residual)).collect(),
                )
                .colour(palette::BLUE)
                .hollow(),
            );
        }
        Chart {
            title: &name,
            x_label: &x_label,
            y_label: &r_label,
            series,
            ..Chart::default()
        }
        .to_svg(&path, 1000, 420)?;
        written.push(path);
    }
    Ok(written)
}

/// Without the `plot` feature there is nothing to draw with.
#[cfg(not(feature = "plot"))]
fn write_plots(
    _result: &FitResult,
    _data: &[DataSet],
    _dir: &Path,
) -> hdi_tribology::Result<Vec<PathBuf>> {
    Err(Error::invalid("--plot", "this build has no `plot` feature"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_and_columns_read_as_symbols() {
        assert_eq!(unit_symbol("nm_per_mw"), "nm/mW");
        assert_eq!(unit_symbol("j_m6"), "J m⁶");
        assert_eq!(unit_symbol("n_per_m"), "N/m");
        assert_eq!(unit_symbol("un"), "µN");
        assert_eq!(column_label("dc_voltage_mv"), "V_{dc} (mV)");
        assert_eq!(
            column_label("takeoff_power_mw"),
            "take-off power P_{TO} (mW)"
        );
        assert_eq!(column_label("odd"), "odd");
        assert_eq!(with_error(0.702043, 0.000689), "0.70204 ± 0.00069");
        assert_eq!(
            with_error(1.0056e-19, 1.787e-22),
            "(1.0056 ± 0.0018)·10^{-19}"
        );
        assert_eq!(with_error(74.3, 2.5), "74.3 ± 2.5");
    }
}
