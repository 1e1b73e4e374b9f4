//! Writing results: CSV tables (always) and SVG line charts (feature `plot`).

use crate::error::{Error, Result};
use std::fmt::Write as _;
use std::path::Path;

/// Writes columns of equal length as CSV with a header line. Values are written with full
/// precision (`{:e}` round-trips).
///
/// ```
/// let dir = std::env::temp_dir().join("hdi_report_doc");
/// std::fs::create_dir_all(&dir).unwrap();
/// let path = dir.join("t.csv");
/// hdi_tribology::report::write_csv(&path, &["x", "y"], &[&[1.0, 2.0], &[3.0, 4.0]])?;
/// assert_eq!(std::fs::read_to_string(&path).unwrap(), "x,y\n1e0,3e0\n2e0,4e0\n");
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn write_csv(path: &Path, headers: &[&str], columns: &[&[f64]]) -> Result<()> {
    if headers.len() != columns.len() {
        return Err(Error::invalid(
            "columns",
            format!("{} headers for {} columns", headers.len(), columns.len()),
        ));
    }
    let rows = columns.first().map_or(0, |c| c.len());
    if let Some(i) = columns.iter().position(|c| c.len() != rows) {
        return Err(Error::invalid(
            format!("columns[{i}]"),
            format!("has {} rows, the first has {rows}", columns[i].len()),
        ));
    }
    let mut s = headers.join(",");
    s.push('\n');
    for r in 0..rows {
        for (i, c) in columns.iter().enumerate() {
            if i > 0 {
                s.push(',');
            }
            let _ = write!(s, "{:e}", c[r]);
        }
        s.push('\n');
    }
    write_file(path, &s)
}

/// Writes a whole file at once (so a failure leaves no half-written table behind a name).
pub fn write_file(path: &Path, contents: &str) -> Result<()> {
    let tmp = path.with_extension("partial");
    std::fs::write(&tmp, contents)
        .and_then(|_| std::fs::rename(&tmp, path))
        .map_err(|source| Error::Io {
            path: path.display().to_string(),
            source,
        })
}

/// A short tick label: powers of ten on log axes, up to four significant digits otherwise.
///
/// ```
/// use hdi_tribology::report::tick_label;
/// assert_eq!(tick_label(9.999999998e-5, true), "1e-4");
/// assert_eq!(tick_label(0.25, false), "0.25");
/// assert_eq!(tick_label(123456.0, false), "1.235e5");
/// assert_eq!(tick_label(-3.0, false), "-3");
/// ```
pub fn tick_label(v: f64, log: bool) -> String {
    if v == 0.0 {
        return "0".into();
    }
    if log {
        return format!("{:.0e}", v);
    }
    let a = v.abs();
    if !(1e-3..1e4).contains(&a) {
        return format!("{:.3e}", v).replace(".000e", "e");
    }
    let s = format!("{:.*}", (3 - a.log10().floor() as i32).max(0) as usize, v);
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// One line (or set of markers) of a chart.
#[derive(Clone, Debug)]
pub struct Series<'a> {
    /// Legend label.
    pub label: &'a str,
    /// Points `(x, y)`.
    pub points: Vec<(f64, f64)>,
    /// Draw markers instead of a line.
    pub markers: bool,
}

/// A line chart written as SVG (no system fonts needed).
#[derive(Clone, Debug)]
pub struct Chart<'a> {
    /// Title.
    pub title: &'a str,
    /// X-axis label.
    pub x_label: &'a str,
    /// Y-axis label.
    pub y_label: &'a str,
    /// The series.
    pub series: Vec<Series<'a>>,
    /// Logarithmic axes `(x, y)`.
    pub log: (bool, bool),
}

#[cfg(feature = "plot")]
#[cfg_attr(docsrs, doc(cfg(feature = "plot")))]
impl Chart<'_> {
    /// Draws the chart into an SVG file of `width × height` pixels.
    ///
    /// ```
    /// use hdi_tribology::report::{Chart, Series};
    /// let path = std::env::temp_dir().join("hdi_chart_doc.svg");
    /// Chart { title: "y = x²", x_label: "x", y_label: "y", log: (false, false),
    ///         series: vec![Series { label: "x²", markers: false,
    ///                               points: (0..10).map(|i| (i as f64, (i * i) as f64)).collect() }] }
    ///     .to_svg(&path, 640, 400)?;
    /// assert!(std::fs::read_to_string(&path).unwrap().contains("<svg"));
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn to_svg(&self, path: &Path, width: u32, height: u32) -> Result<()> {
        let mut svg = String::new();
        self.draw(&mut svg, width, height)
            .map_err(|e| Error::analysis("chart", format!("{}: {e}", self.title)))?;
        write_file(path, &svg)
    }

    fn draw(&self, out: &mut String, width: u32, height: u32) -> std::result::Result<(), String> {
        use plotters::prelude::*;
        let finite: Vec<(f64, f64)> = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().copied())
            .filter(|(x, y)| {
                x.is_finite()
                    && y.is_finite()
                    && (!self.log.0 || *x > 0.0)
                    && (!self.log.1 || *y > 0.0)
            })
            .collect();
        if finite.is_empty() {
            return Err("no finite points to draw".into());
        }
        let span = |v: &mut dyn Iterator<Item = f64>, log: bool| {
            let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            });
            if log {
                (lo / 1.5, hi * 1.5)
            } else {
                let pad = if hi > lo {
                    0.05 * (hi - lo)
                } else {
                    lo.abs().max(1e-30) * 0.1
                };
                (lo - pad, hi + pad)
            }
        };
        let xr = span(&mut finite.iter().map(|p| p.0), self.log.0);
        let yr = span(&mut finite.iter().map(|p| p.1), self.log.1);
        let root = SVGBackend::with_string(out, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let mut builder = ChartBuilder::on(&root);
        builder
            .caption(self.title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70);
        let colours = [&BLUE, &RED, &GREEN, &MAGENTA, &CYAN, &BLACK];
        macro_rules! draw_series {
            ($chart:expr) => {{
                let mut chart = $chart;
                chart
                    .configure_mesh()
                    .x_desc(self.x_label)
                    .y_desc(self.y_label)
                    .x_label_formatter(&|v| tick_label(*v, self.log.0))
                    .y_label_formatter(&|v| tick_label(*v, self.log.1))
                    .draw()
                    .map_err(|e| e.to_string())?;
                for (i, s) in self.series.iter().enumerate() {
                    let colour = *colours[i % colours.len()];
                    let pts: Vec<(f64, f64)> = s
                        .points
                        .iter()
                        .copied()
                        .filter(|(x, y)| {
                            x.is_finite()
                                && y.is_finite()
                                && (!self.log.0 || *x > 0.0)
                                && (!self.log.1 || *y > 0.0)
                        })
                        .collect();
                    let anno = if s.markers {
                        chart
                            .draw_series(pts.iter().map(|&p| Circle::new(p, 3, colour.filled())))
                            .map_err(|e| e.to_string())?
                    } else {
                        chart
                            .draw_series(LineSeries::new(pts, colour.stroke_width(2)))
                            .map_err(|e| e.to_string())?
                    };
                    anno.label(s.label).legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2))
                    });
                }
                chart
                    .configure_series_labels()
                    .background_style(WHITE.mix(0.8))
                    .border_style(BLACK)
                    .draw()
                    .map_err(|e| e.to_string())?;
            }};
        }
        match self.log {
            (false, false) => draw_series!(builder
                .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
                .map_err(|e| e.to_string())?),
            (true, false) => draw_series!(builder
                .build_cartesian_2d((xr.0..xr.1).log_scale(), yr.0..yr.1)
                .map_err(|e| e.to_string())?),
            (false, true) => draw_series!(builder
                .build_cartesian_2d(xr.0..xr.1, (yr.0..yr.1).log_scale())
                .map_err(|e| e.to_string())?),
            (true, true) => draw_series!(builder
                .build_cartesian_2d((xr.0..xr.1).log_scale(), (yr.0..yr.1).log_scale())
                .map_err(|e| e.to_string())?),
        }
        root.present().map_err(|e| e.to_string())?;
        Ok(())
    }
}
