//! Writing results: CSV tables (always) and SVG charts (feature `plot`).
//!
//! Tables go through the [`csv`] crate. Real numbers are written in the shortest form that reads
//! back to the same `f64` (plain decimals between 1e-4 and 1e15, exponent form outside), counts
//! as integers and flags as `true`/`false`; a missing value (`None`, or `NaN` in a column of
//! reals) is an empty field, which spreadsheets, pandas and `numpy.genfromtxt` read as missing
//! (NaN). Physical
//! quantities carry their SI unit as a suffix of the column name (`v_dc_v`, `power_w`, `d_m`).
//! Every file is written whole under a temporary name beside it and renamed into place, so a
//! failure leaves neither a half-written table nor a temporary file behind.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// One column of a [`CsvTable`].
#[derive(Clone, Debug, PartialEq)]
enum Column {
    Real(Vec<f64>),
    Optional(Vec<Option<f64>>),
    Integer(Vec<u64>),
    Flag(Vec<bool>),
}

impl Column {
    fn len(&self) -> usize {
        match self {
            Column::Real(v) => v.len(),
            Column::Optional(v) => v.len(),
            Column::Integer(v) => v.len(),
            Column::Flag(v) => v.len(),
        }
    }
    fn cell(&self, row: usize) -> String {
        match self {
            Column::Real(v) => missing_or_real(v[row]),
            Column::Optional(v) => v[row].map_or(String::new(), real_cell),
            Column::Integer(v) => v[row].to_string(),
            Column::Flag(v) => v[row].to_string(),
        }
    }
}

/// A CSV cell of a column of reals: empty for `NaN` (a missing value), else [`real_cell`].
fn missing_or_real(v: f64) -> String {
    if v.is_nan() {
        String::new()
    } else {
        real_cell(v)
    }
}

/// A real number in the shortest form that reads back to the same `f64`: plain decimal for
/// magnitudes in [1e-4, 1e15), exponent form outside; `NaN`, `inf`, `-inf` as such (a CSV
/// column writes `NaN` as an empty field: [`CsvTable::real`]).
///
/// ```
/// use hdi_tribology::report::real_cell;
/// assert_eq!(real_cell(0.7), "0.7");
/// assert_eq!(real_cell(2.0), "2");
/// assert_eq!(real_cell(1.5e-9), "1.5e-9");
/// assert_eq!(real_cell(-3e20), "-3e20");
/// assert_eq!(real_cell(0.0), "0");
/// for v in [0.1 + 0.2, 6.02214076e23, 1e-300, 1234.5678] {
///     assert_eq!(real_cell(v).parse::<f64>().unwrap(), v);
/// }
/// ```
pub fn real_cell(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || !a.is_finite() || (1e-4..1e15).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A CSV table built column by column, each column with its own kind of value.
///
/// ```
/// use hdi_tribology::report::CsvTable;
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("sweep.csv");
/// CsvTable::new()
///     .real("v_ac_v", [0.0, 0.5])
///     .optional("hysteresis_w", [Some(6.4e-3), None])
///     .integer("steps", [2849, 3012])
///     .flag("converged", [true, false])
///     .write(&path)?;
/// assert_eq!(
///     std::fs::read_to_string(&path).unwrap(),
///     "v_ac_v,hysteresis_w,steps,converged\n0,0.0064,2849,true\n0.5,,3012,false\n"
/// );
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CsvTable {
    headers: Vec<String>,
    columns: Vec<Column>,
}

impl CsvTable {
    /// An empty table.
    pub fn new() -> Self {
        Self::default()
    }

    fn push(mut self, header: &str, column: Column) -> Self {
        self.headers.push(header.to_string());
        self.columns.push(column);
        self
    }

    /// Adds a column of real numbers; `NaN` stands for a missing value and is written as an
    /// empty field, as [`CsvTable::optional`] writes `None` (`inf` and `-inf` as such).
    ///
    /// ```
    /// use hdi_tribology::report::CsvTable;
    /// let t = CsvTable::new().real("indicator_n", [f64::NAN, 2.5e-5, f64::INFINITY]);
    /// assert_eq!(t.to_csv_string()?, "indicator_n\n\"\"\n2.5e-5\ninf\n");
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn real(self, header: &str, values: impl IntoIterator<Item = f64>) -> Self {
        self.push(header, Column::Real(values.into_iter().collect()))
    }

    /// Adds a column of real numbers that may be missing (written as an empty field).
    pub fn optional(self, header: &str, values: impl IntoIterator<Item = Option<f64>>) -> Self {
        self.push(header, Column::Optional(values.into_iter().collect()))
    }

    /// Adds a column of counts, written as integers.
    pub fn integer(self, header: &str, values: impl IntoIterator<Item = u64>) -> Self {
        self.push(header, Column::Integer(values.into_iter().collect()))
    }

    /// Adds a column of flags, written as `true` / `false`.
    pub fn flag(self, header: &str, values: impl IntoIterator<Item = bool>) -> Self {
        self.push(header, Column::Flag(values.into_iter().collect()))
    }

    /// The number of data rows; an error when the columns differ in length.
    pub fn rows(&self) -> Result<usize> {
        let rows = self.columns.first().map_or(0, Column::len);
        match self.columns.iter().position(|c| c.len() != rows) {
            Some(i) => Err(Error::invalid(
                format!("column {}", self.headers[i]),
                format!(
                    "has {} rows, column {} has {rows}",
                    self.columns[i].len(),
                    self.headers[0]
                ),
            )),
            None => Ok(rows),
        }
    }

    /// The table as CSV text, header line first.
    pub fn to_csv_string(&self) -> Result<String> {
        let rows = self.rows()?;
        let mut w = csv::Writer::from_writer(Vec::new());
        let err = |e: csv::Error| Error::output("CSV", e.to_string());
        w.write_record(&self.headers).map_err(err)?;
        for r in 0..rows {
            w.write_record(self.columns.iter().map(|c| c.cell(r)))
                .map_err(err)?;
        }
        let bytes = w
            .into_inner()
            .map_err(|e| Error::output("CSV", e.to_string()))?;
        String::from_utf8(bytes).map_err(|e| Error::output("CSV", e.to_string()))
    }

    /// Writes the table to `path` whole (see [`write_file`]).
    pub fn write(&self, path: &Path) -> Result<()> {
        write_file(path, &self.to_csv_string()?)
    }
}

/// Writes columns of real numbers of equal length as CSV with a header line (a [`CsvTable`] of
/// [`CsvTable::real`] columns).
///
/// ```
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("t.csv");
/// hdi_tribology::report::write_csv(&path, &["x_m", "y_n"], &[&[1.0, 2.5], &[3e-9, 4.0]])?;
/// assert_eq!(std::fs::read_to_string(&path).unwrap(), "x_m,y_n\n1,3e-9\n2.5,4\n");
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn write_csv(path: &Path, headers: &[&str], columns: &[&[f64]]) -> Result<()> {
    if headers.len() != columns.len() {
        return Err(Error::invalid(
            "columns",
            format!("{} headers for {} columns", headers.len(), columns.len()),
        ));
    }
    headers
        .iter()
        .zip(columns)
        .fold(CsvTable::new(), |t, (h, c)| t.real(h, c.iter().copied()))
        .write(path)
}

/// Writes a whole file at once: the contents go to a temporary file beside `path` (its full
/// name plus a unique suffix, so `x.csv` and `x.svg` never share one), which is then renamed
/// onto `path`. On failure the temporary file is removed and `path` is left as it was.
///
/// ```
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("note.txt");
/// hdi_tribology::report::write_file(&path, "hello\n")?;
/// assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
/// assert!(hdi_tribology::report::write_file(&dir.path().join("no/such/dir.txt"), "x").is_err());
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn write_file(path: &Path, contents: &str) -> Result<()> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let io = |source| Error::Io {
        path: path.display().to_string(),
        source,
    };
    let name = path
        .file_name()
        .ok_or_else(|| {
            io(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "not a file name",
            ))
        })?
        .to_string_lossy();
    let tmp: PathBuf = path.with_file_name(format!(
        ".{name}.{}-{}.partial",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let result = std::fs::write(&tmp, contents).and_then(|_| std::fs::rename(&tmp, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(io)
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

/// A tick label on a linear axis spanning `span`: a value that is zero up to rounding of the
/// tick arithmetic (below 1e-9 of the span) reads `0`, not `-1.110e-16`.
///
/// ```
/// use hdi_tribology::report::snapped_tick_label;
/// assert_eq!(snapped_tick_label(-1.1102230246251565e-16, 1.2), "0");
/// assert_eq!(snapped_tick_label(-0.2, 1.2), "-0.2");
/// assert_eq!(snapped_tick_label(3e-12, 1e-11), "3.000e-12".replace(".000e", "e"));
/// ```
pub fn snapped_tick_label(v: f64, span: f64) -> String {
    if v.abs() <= 1e-9 * span.abs() {
        "0".into()
    } else {
        tick_label(v, false)
    }
}

/// An sRGB colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Colour(pub u8, pub u8, pub u8);

/// The Okabe–Ito palette, distinguishable under the common colour-vision deficiencies; charts
/// take their default series colours from it in this order.
pub mod palette {
    use super::Colour;
    /// Blue (#0072B2).
    pub const BLUE: Colour = Colour(0x00, 0x72, 0xB2);
    /// Vermilion (#D55E00).
    pub const VERMILION: Colour = Colour(0xD5, 0x5E, 0x00);
    /// Bluish green (#009E73).
    pub const GREEN: Colour = Colour(0x00, 0x9E, 0x73);
    /// Reddish purple (#CC79A7).
    pub const PURPLE: Colour = Colour(0xCC, 0x79, 0xA7);
    /// Orange (#E69F00).
    pub const ORANGE: Colour = Colour(0xE6, 0x9F, 0x00);
    /// Sky blue (#56B4E9).
    pub const SKY_BLUE: Colour = Colour(0x56, 0xB4, 0xE9);
    /// Yellow (#F0E442).
    pub const YELLOW: Colour = Colour(0xF0, 0xE4, 0x42);
    /// Black.
    pub const BLACK: Colour = Colour(0, 0, 0);
    /// The default order of series colours.
    pub const SERIES: [Colour; 7] = [BLUE, VERMILION, GREEN, PURPLE, ORANGE, SKY_BLUE, BLACK];
}

/// The symbol of a series drawn as markers (and of its legend entry).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Marker {
    /// A disc.
    #[default]
    Circle,
    /// A square.
    Square,
    /// A triangle, point up.
    Triangle,
    /// A diamond.
    Diamond,
    /// A diagonal cross (never filled).
    Cross,
}

/// One line (or set of markers) of a chart. Build one with [`Series::line`] or
/// [`Series::markers`] and adjust it with the methods that follow.
#[derive(Clone, Debug, Default)]
pub struct Series<'a> {
    /// Legend label; an empty label leaves the series out of the legend.
    pub label: &'a str,
    /// Points `(x, y)`; non-finite points (and non-positive ones on a log axis) are skipped.
    pub points: Vec<(f64, f64)>,
    /// Draw markers instead of a line.
    pub markers: bool,
    /// The marker symbol, when `markers`.
    pub marker: Marker,
    /// Draw the markers as outlines only.
    pub hollow: bool,
    /// The colour; `None` takes the next one of [`palette::SERIES`].
    pub colour: Option<Colour>,
    /// Line width (or marker size) in pixels; 0 for the default (2 px lines, 4 px markers).
    pub width: u32,
    /// Draw the line dashed.
    pub dashed: bool,
    /// Plot against the chart's second y axis (on the right, [`Chart::y2_label`]).
    pub secondary: bool,
    /// A shaded band instead of a line: the upper edge at each point, `points` giving the
    /// lower edge ([`Series::band`]). Drawn under every line and marker.
    pub upper: Vec<f64>,
    /// Text beside each point (empty: none), placed where it overlaps no marker and no other
    /// label; points closer than a label's height share one label ([`Series::point_labels`]).
    pub labels: Vec<String>,
    /// Arrowheads along a line at these point indices, pointing the way the points run (the
    /// direction a loop is travelled).
    pub arrows: Vec<usize>,
}

impl<'a> Series<'a> {
    /// A solid line through `points`.
    pub fn line(label: &'a str, points: Vec<(f64, f64)>) -> Self {
        Series {
            label,
            points,
            ..Self::default()
        }
    }
    /// Filled circles at `points`.
    pub fn markers(label: &'a str, points: Vec<(f64, f64)>) -> Self {
        Series {
            markers: true,
            ..Self::line(label, points)
        }
    }
    /// A shaded band between `lower` (points `(x, y_lo)`) and `upper` (`y_hi` at the same x),
    /// in the series colour, lightened; a band without a label stays out of the legend.
    ///
    /// ```
    /// use hdi_tribology::report::Series;
    /// let b = Series::band("range", vec![(0.0, -1.0), (1.0, -2.0)], vec![1.0, 2.0]);
    /// assert_eq!(b.upper.len(), b.points.len());
    /// ```
    pub fn band(label: &'a str, lower: Vec<(f64, f64)>, upper: Vec<f64>) -> Self {
        Series {
            upper,
            ..Self::line(label, lower)
        }
    }
    setters! {
        /// With a text beside each point (`labels[i]` beside `points[i]`; empty for none).
        point_labels(labels: Vec<String>) => labels = labels;
        /// With arrowheads at these point indices, pointing along the line.
        arrows(at: Vec<usize>) => arrows = at;
        /// With this colour.
        colour(c: Colour) => colour = Some(c);
        /// With this marker symbol.
        marker(m: Marker) => marker = m;
        /// With this line width (marker size) in pixels.
        width(px: u32) => width = px;
        /// Markers as outlines only.
        hollow() => hollow = true;
        /// Dashed line.
        dashed() => dashed = true;
        /// On the second y axis.
        on_secondary() => secondary = true;
    }
}

/// A line chart written as SVG (no system fonts needed), its legend to the right of the plot so
/// that it never covers data.
///
/// Lines are drawn first, in the order given, then markers, so that points stay on top of the
/// curves fitted through them.
#[derive(Clone, Debug, Default)]
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
    /// The label of the second y axis, on the right (linear axes only); used when a series is
    /// [`Series::secondary`].
    pub y2_label: &'a str,
    /// Fixed x range instead of the data's.
    pub x_range: Option<(f64, f64)>,
    /// Fixed y range instead of the data's (so that two panels can share one).
    pub y_range: Option<(f64, f64)>,
    /// Fixed range of the second y axis.
    pub y2_range: Option<(f64, f64)>,
    /// Lines of text under the legend (what the markers mean, which protocol is the letter's).
    pub notes: Vec<String>,
    /// Width of the legend panel (px) instead of one sized to the longest label, so that panels
    /// shown side by side get plot areas of one size; at most half the chart's width.
    ///
    /// ```
    /// use hdi_tribology::report::{Chart, Series};
    /// let panel = |label| Chart {
    ///     series: vec![Series::line(label, vec![(0.0, 0.0), (1.0, 1.0)])],
    ///     legend_width: Some(260),
    ///     ..Chart::default()
    /// };
    /// // Both panels keep 260 px for the legend, whatever their labels.
    /// let (a, b) = (panel("a"), panel("a much longer label"));
    /// assert_eq!(a.legend_width, b.legend_width);
    /// ```
    pub legend_width: Option<u32>,
    /// The width the figure is printed at, in inches, which sets its font sizes (8–9 pt there);
    /// `None`: one column (3.5 in) below 950 px, two columns (7 in) from there.
    pub print_width_in: Option<f64>,
}

/// Whether `(x, y)` can be drawn on axes with the given log flags.
fn drawable((x, y): (f64, f64), log: (bool, bool)) -> bool {
    x.is_finite() && y.is_finite() && (!log.0 || x > 0.0) && (!log.1 || y > 0.0)
}

/// The span of `values` with a margin: 5 % on linear axes, a factor 1.5 on log axes.
fn padded_span(values: impl Iterator<Item = f64>, log: bool) -> Option<(f64, f64)> {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    });
    if lo > hi {
        return None;
    }
    Some(if log {
        (lo / 1.5, hi * 1.5)
    } else {
        let pad = if hi > lo {
            0.05 * (hi - lo)
        } else {
            lo.abs().max(1e-30) * 0.1
        };
        (lo - pad, hi + pad)
    })
}

impl Chart<'_> {
    /// The y range (with margin) that shows every drawable point of the primary-axis series
    /// (and both edges of a band), to share between panels through [`Chart::y_range`].
    ///
    /// ```
    /// use hdi_tribology::report::{Chart, Series};
    /// let a = Chart { series: vec![Series::line("a", vec![(0.0, -1.0), (1.0, 1.0)])], ..Chart::default() };
    /// let (lo, hi) = a.data_y_range().unwrap();
    /// assert!(lo < -1.0 && hi > 1.0);
    /// ```
    pub fn data_y_range(&self) -> Option<(f64, f64)> {
        padded_span(self.points(false).map(|p| p.1), self.log.1)
    }

    fn points(&self, secondary: bool) -> impl Iterator<Item = (f64, f64)> + '_ {
        let log = self.log;
        self.series
            .iter()
            .filter(move |s| s.secondary == secondary)
            .flat_map(|s| {
                // A band's upper edge counts as its points do.
                let upper = s.points.iter().zip(&s.upper).map(|(p, &y)| (p.0, y));
                s.points.iter().copied().chain(upper)
            })
            .filter(move |&p| drawable(p, log))
    }
}

/// Average width of a character over the font size asked of plotters (which sets glyphs at
/// 1/1.24 of it), for sizing the legend panel and the tick label areas.
#[cfg(feature = "plot")]
const CHAR_EM: f64 = 0.46;

/// Charts are drawn on a canvas this many times finer than the SVG's size, which then scales it
/// down (`viewBox`): plotters rounds coordinates to whole pixels, so curves are placed to a
/// quarter of a pixel of the figure instead of a whole one.
#[cfg(feature = "plot")]
const SUPERSAMPLE: u32 = 4;

/// Font sizes, in points at the printed width ([`Chart::print_width_in`]): tick labels, axis
/// labels, legend, notes. No text is below 8 pt in print.
#[cfg(feature = "plot")]
const FONT_PT: (f64, f64, f64, f64) = (8.5, 9.0, 8.5, 8.0);

/// Opacity of a band ([`Series::band`]).
#[cfg(feature = "plot")]
const BAND_ALPHA: f64 = 0.3;

/// The triangle of an arrowhead of half-size `s` (pixels) centred on point `i` of a line
/// (`px`: its points in pixels, `None` where not drawn), pointing from the line's points before
/// it to those after it (the nearest ones at least `s` away); `None` where the line has no
/// direction there.
#[cfg(feature = "plot")]
fn arrowhead(px: &[Option<(i32, i32)>], i: usize, s: i32) -> Option<Vec<(i32, i32)>> {
    let p = (*px.get(i)?)?;
    let far = |q: &(i32, i32)| (q.0 - p.0).abs().max((q.1 - p.1).abs()) >= s;
    let after = px[i + 1..].iter().flatten().find(|q| far(q)).copied();
    let before = px[..i].iter().rev().flatten().find(|q| far(q)).copied();
    let (a, b) = match (before, after) {
        (Some(a), Some(b)) => (a, b),
        (None, Some(b)) => (p, b),
        (Some(a), None) => (a, p),
        (None, None) => return None,
    };
    let (dx, dy) = ((b.0 - a.0) as f64, (b.1 - a.1) as f64);
    let n = dx.hypot(dy);
    if n == 0.0 {
        return None;
    }
    let (ux, uy) = (dx / n, dy / n);
    let s = s as f64;
    let at = |along: f64, across: f64| {
        (
            p.0 + (ux * along - uy * across).round() as i32,
            p.1 + (uy * along + ux * across).round() as i32,
        )
    };
    Some(vec![at(1.2 * s, 0.0), at(-s, 0.8 * s), at(-s, -0.8 * s)])
}

/// Text set for print: a hyphen-minus before a digit (or a decimal point) becomes a minus sign
/// (U+2212), `_{…}` a subscript and `^{…}` a superscript (SVG `tspan`s). `text` is the escaped
/// content of one SVG `text` element.
///
/// ```
/// use hdi_tribology::report::typeset;
/// assert_eq!(typeset("-0.5"), "\u{2212}0.5");
/// assert_eq!(typeset("touchdown-power"), "touchdown-power");
/// assert_eq!(
///     typeset("V_{ac} (V)"),
///     "V<tspan baseline-shift=\"sub\" font-size=\"75%\">ac</tspan> (V)"
/// );
/// ```
pub fn typeset(text: &str) -> String {
    let chars: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let next = chars.get(i + 1).copied();
        let prev = i.checked_sub(1).map(|j| chars[j]);
        if c == '-'
            && next.is_some_and(|n| n.is_ascii_digit() || n == '.')
            && prev.is_none_or(|p| !p.is_alphanumeric())
        {
            out.push('\u{2212}');
            i += 1;
            continue;
        }
        if (c == '_' || c == '^') && next == Some('{') {
            if let Some(len) = chars[i + 2..].iter().position(|&ch| ch == '}') {
                let inner: String = chars[i + 2..i + 2 + len].iter().collect();
                let shift = if c == '_' { "sub" } else { "super" };
                out.push_str(&format!(
                    "<tspan baseline-shift=\"{shift}\" font-size=\"75%\">{}</tspan>",
                    typeset(&inner)
                ));
                i += len + 3;
                continue;
            }
        }
        out.push(c);
        i += 1;
    }
    out
}

/// The SVG plotters drew at [`SUPERSAMPLE`] times the size, shown at `width × height`, with
/// every text element [`typeset`].
#[cfg(feature = "plot")]
fn finish_svg(svg: &str, width: u32, height: u32) -> String {
    let k = SUPERSAMPLE;
    let big = format!(r#"width="{}" height="{}""#, width * k, height * k);
    typeset_svg(&svg.replacen(&big, &format!(r#"width="{width}" height="{height}""#), 1))
}

/// An SVG document with the content of every `text` element [`typeset`]: minus signs,
/// subscripts (`V_{ac}`) and superscripts (`10^{-3}`) for print, for figures drawn outside
/// [`Chart`].
///
/// ```
/// use hdi_tribology::report::typeset_svg;
/// let svg = r#"<svg><text x="1">V_{ac} = -1</text></svg>"#;
/// assert_eq!(
///     typeset_svg(svg),
///     "<svg><text x=\"1\">V<tspan baseline-shift=\"sub\" font-size=\"75%\">ac</tspan> = \u{2212}1</text></svg>"
/// );
/// ```
pub fn typeset_svg(svg: &str) -> String {
    let mut out = String::with_capacity(svg.len());
    let mut rest = svg;
    while let Some(open) = rest.find("<text") {
        let Some(gt) = rest[open..].find('>') else {
            break;
        };
        let body_start = open + gt + 1;
        let Some(end) = rest[body_start..].find("</text>") else {
            break;
        };
        out.push_str(&rest[..body_start]);
        out.push_str(&typeset(&rest[body_start..body_start + end]));
        rest = &rest[body_start + end..];
    }
    out.push_str(rest);
    out
}

/// Splits `text` into lines of at most `width` characters at spaces.
#[cfg(feature = "plot")]
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines = Vec::new();
    for para in text.split('\n') {
        let mut line = String::new();
        for word in para.split_whitespace() {
            if !line.is_empty() && line.chars().count() + 1 + word.chars().count() > width {
                lines.push(std::mem::take(&mut line));
            }
            if !line.is_empty() {
                line.push(' ');
            }
            line.push_str(word);
        }
        lines.push(line);
    }
    lines
}

/// A marker of `size` pixels centred on one point, in data or pixel coordinates.
#[cfg(feature = "plot")]
struct MarkerElement<C> {
    at: C,
    shape: Marker,
    size: i32,
    colour: plotters::style::RGBColor,
    hollow: bool,
    stroke: u32,
}

#[cfg(feature = "plot")]
fn marker_element<C>(
    shape: Marker,
    at: C,
    size: i32,
    colour: plotters::style::RGBColor,
    hollow: bool,
) -> MarkerElement<C> {
    MarkerElement {
        at,
        shape,
        size: size * SUPERSAMPLE as i32,
        colour,
        hollow,
        stroke: 2 * SUPERSAMPLE,
    }
}

#[cfg(feature = "plot")]
impl<'a, C: 'a> plotters::element::PointCollection<'a, C> for &'a MarkerElement<C> {
    type Point = &'a C;
    type IntoIter = std::iter::Once<&'a C>;
    fn point_iter(self) -> Self::IntoIter {
        std::iter::once(&self.at)
    }
}

#[cfg(feature = "plot")]
impl<C, DB: plotters_backend::DrawingBackend> plotters::element::Drawable<DB> for MarkerElement<C> {
    fn draw<I: Iterator<Item = plotters_backend::BackendCoord>>(
        &self,
        mut pos: I,
        backend: &mut DB,
        _: (u32, u32),
    ) -> std::result::Result<(), plotters_backend::DrawingErrorKind<DB::ErrorType>> {
        use plotters::style::{Color, ShapeStyle};
        let Some((x, y)) = pos.next() else {
            return Ok(());
        };
        let s = self.size;
        let fill = !self.hollow && self.shape != Marker::Cross;
        let style = if fill {
            self.colour.filled()
        } else {
            ShapeStyle::from(&self.colour).stroke_width(self.stroke)
        };
        let polygon = |backend: &mut DB, v: Vec<(i32, i32)>| {
            let v: Vec<(i32, i32)> = v.into_iter().map(|(a, b)| (x + a, y + b)).collect();
            if fill {
                backend.fill_polygon(v, &style)
            } else {
                let first = v[0];
                backend.draw_path(v.into_iter().chain(std::iter::once(first)), &style)
            }
        };
        match self.shape {
            Marker::Circle => backend.draw_circle((x, y), s as u32, &style, fill),
            Marker::Square => backend.draw_rect((x - s, y - s), (x + s, y + s), &style, fill),
            Marker::Triangle => polygon(backend, vec![(0, -s - 1), (s + 1, s), (-s - 1, s)]),
            Marker::Diamond => polygon(
                backend,
                vec![(0, -s - 1), (s + 1, 0), (0, s + 1), (-s - 1, 0)],
            ),
            Marker::Cross => {
                backend.draw_line((x - s, y - s), (x + s, y + s), &style)?;
                backend.draw_line((x - s, y + s), (x + s, y - s), &style)
            }
        }
    }
}

/// Font sizes in the canvas's pixels: tick labels, axis labels, legend, notes.
#[cfg(feature = "plot")]
#[derive(Clone, Copy)]
struct FontPx {
    tick: f64,
    axis: f64,
    legend: f64,
    note: f64,
}

/// The ranges a chart draws: x, y and the second y axis's.
#[cfg(feature = "plot")]
#[derive(Clone, Copy)]
struct Ranges {
    x: (f64, f64),
    y: (f64, f64),
    y2: (f64, f64),
}

/// A part of the SVG canvas.
#[cfg(feature = "plot")]
type Area<'b> =
    plotters::drawing::DrawingArea<plotters::backend::SVGBackend<'b>, plotters::coord::Shift>;

/// What each part of a chart draws with: the whole canvas (for what is placed in its pixels),
/// the colour of each series, the font sizes.
#[cfg(feature = "plot")]
struct Canvas<'r, 'b> {
    root: &'r Area<'b>,
    colours: &'r [plotters::style::RGBColor],
    fonts: FontPx,
}

/// A drawing error in words.
#[cfg(feature = "plot")]
fn draw_error(e: &dyn std::fmt::Display) -> String {
    e.to_string()
}

/// A dashed line through `points` (dashes of 7 px, gaps of 5 px, in the figure's pixels).
#[cfg(feature = "plot")]
fn dashed<P: Clone>(
    points: Vec<P>,
    style: plotters::style::ShapeStyle,
) -> plotters::element::DashedPathElement<std::vec::IntoIter<P>, u32> {
    let k = SUPERSAMPLE;
    plotters::element::DashedPathElement::new(points, 7 * k, 5 * k, style)
}

/// How a series is drawn, one for the plot and its legend entry alike.
#[cfg(feature = "plot")]
impl Series<'_> {
    /// Which layer the series is drawn in: bands (0) under lines (1) under markers (2).
    fn layer(&self) -> u8 {
        if !self.upper.is_empty() {
            0
        } else if self.markers {
            2
        } else {
            1
        }
    }

    /// The points that can be drawn on axes with the log flags `log`.
    fn drawable_points(&self, log: (bool, bool)) -> Vec<(f64, f64)> {
        self.points
            .iter()
            .copied()
            .filter(|&p| drawable(p, log))
            .collect()
    }

    /// The outline of a band: its lower edge forwards, then its upper edge backwards.
    fn band_outline(&self, log: (bool, bool)) -> Vec<(f64, f64)> {
        let upper: Vec<(f64, f64)> = self
            .points
            .iter()
            .zip(&self.upper)
            .map(|(&(x, _), &y)| (x, y))
            .filter(|&p| drawable(p, log))
            .rev()
            .collect();
        self.drawable_points(log).into_iter().chain(upper).collect()
    }

    /// The marker's half-size in the figure's pixels (4 unless set).
    fn marker_size(&self) -> i32 {
        if self.width == 0 {
            4
        } else {
            self.width as i32
        }
    }

    /// The line's style in colour `c`, 2 figure pixels wide unless set.
    fn line_style(&self, c: plotters::style::RGBColor) -> plotters::style::ShapeStyle {
        use plotters::style::Color;
        c.stroke_width(SUPERSAMPLE * if self.width == 0 { 2 } else { self.width })
    }

    /// The label of point `i` (at `px`, in pixels), shared with the points after it that lie
    /// within `h` pixels: the text and the first point after them.
    fn shared_label(&self, px: &[Option<(i32, i32)>], i: usize, h: i32) -> (String, usize) {
        let mut j = i + 1;
        let mut text = self.labels[i].clone();
        while let (Some(Some(a)), Some(Some(b))) = (px.get(i), px.get(j)) {
            if (a.0 - b.0).abs().max((a.1 - b.1).abs()) > h || j >= self.labels.len() {
                break;
            }
            if !self.labels[j].is_empty() {
                text = format!("{text}, {}", self.labels[j]);
            }
            j += 1;
        }
        (text, j)
    }
}

#[cfg(feature = "plot")]
#[cfg_attr(docsrs, doc(cfg(feature = "plot")))]
impl Chart<'_> {
    /// Draws the chart into an SVG file of `width × height` pixels.
    ///
    /// ```
    /// use hdi_tribology::report::{palette, Chart, Marker, Series};
    /// let dir = tempfile::tempdir().unwrap();
    /// let path = dir.path().join("chart.svg");
    /// let pts: Vec<(f64, f64)> = (0..10).map(|i| (i as f64, (i * i) as f64)).collect();
    /// Chart {
    ///     title: "y = x²",
    ///     x_label: "x",
    ///     y_label: "y",
    ///     series: vec![
    ///         Series::line("x²", pts.clone()),
    ///         Series::markers("samples", pts).marker(Marker::Square).colour(palette::VERMILION),
    ///     ],
    ///     ..Chart::default()
    /// }
    /// .to_svg(&path, 640, 400)?;
    /// assert!(std::fs::read_to_string(&path).unwrap().contains("<svg"));
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn to_svg(&self, path: &Path, width: u32, height: u32) -> Result<()> {
        let mut svg = String::new();
        self.draw(&mut svg, width, height)
            .map_err(|e| Error::output(format!("chart {:?}", self.title), e))?;
        write_file(path, &finish_svg(&svg, width, height))
    }

    fn draw(&self, out: &mut String, width: u32, height: u32) -> std::result::Result<(), String> {
        use plotters::prelude::*;
        let k = SUPERSAMPLE;
        let fonts = self.font_px(width);
        let (width, height) = (width * k, height * k);
        let has2 = self.points(true).next().is_some();
        if has2 && self.log != (false, false) {
            return Err("a second y axis needs linear axes".into());
        }
        let ranges = self.ranges()?;
        let colours = self.colours();
        let root = SVGBackend::with_string(out, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| draw_error(&e))?;
        let labelled: Vec<usize> = (0..self.series.len())
            .filter(|&i| !self.series[i].label.is_empty())
            .collect();
        let legend_w = self.legend_panel_width(&labelled, fonts.legend, width);
        let (plot_area, legend_area) = root.split_horizontally(width - legend_w);
        let canvas = Canvas {
            root: &root,
            colours: &colours,
            fonts,
        };
        self.draw_plot(&canvas, &plot_area, ranges, has2)?;
        self.draw_legend(&canvas, &legend_area, &labelled, legend_w)?;
        root.present().map_err(|e| draw_error(&e))?;
        Ok(())
    }

    /// Font sizes in the canvas's pixels for a figure `width` pixels wide: points at the printed
    /// width.
    fn font_px(&self, width: u32) -> FontPx {
        let print_in = self
            .print_width_in
            .unwrap_or(if width < 950 { 3.5 } else { 7.0 });
        // plotters writes a font of size `f` as `font-size = f/1.24` in SVG: ask for 1.24 times
        // the size wanted.
        let px_per_pt = 1.24 * (width * SUPERSAMPLE) as f64 / (print_in * 72.0);
        FontPx {
            tick: FONT_PT.0 * px_per_pt,
            axis: FONT_PT.1 * px_per_pt,
            legend: FONT_PT.2 * px_per_pt,
            note: FONT_PT.3 * px_per_pt,
        }
    }

    /// The x, y and second y ranges drawn: those given, else the data's with a margin.
    fn ranges(&self) -> std::result::Result<Ranges, String> {
        let log = self.log;
        let x = self
            .x_range
            .or_else(|| {
                padded_span(
                    self.points(false).chain(self.points(true)).map(|p| p.0),
                    log.0,
                )
            })
            .ok_or("no finite points to draw")?;
        let y = self
            .y_range
            .or_else(|| self.data_y_range())
            .unwrap_or((0.0, 1.0));
        let y2 = self
            .y2_range
            .or_else(|| padded_span(self.points(true).map(|p| p.1), false))
            .unwrap_or((0.0, 1.0));
        Ok(Ranges { x, y, y2 })
    }

    /// The colour of each series: its own, else the palette's next.
    fn colours(&self) -> Vec<plotters::style::RGBColor> {
        let mut next = 0;
        self.series
            .iter()
            .map(|s| {
                let c = s.colour.unwrap_or_else(|| {
                    next += 1;
                    palette::SERIES[(next - 1) % palette::SERIES.len()]
                });
                plotters::style::RGBColor(c.0, c.1, c.2)
            })
            .collect()
    }

    /// The width of the legend panel (canvas pixels) on a canvas `width` wide: the one given,
    /// else one that fits the longest of the `labelled` series' labels (none without labels or
    /// notes).
    fn legend_panel_width(&self, labelled: &[usize], legend_px: f64, width: u32) -> u32 {
        let k = SUPERSAMPLE;
        let widest = labelled
            .iter()
            .map(|&i| self.series[i].label.chars().count() + 4)
            .max()
            .unwrap_or(0);
        if let Some(w) = self.legend_width {
            (w * k).min(width / 2)
        } else if labelled.is_empty() && self.notes.is_empty() {
            0
        } else {
            ((widest as f64 * CHAR_EM * legend_px) as u32 + 6 * k)
                .clamp(110 * k, (width as f64 * 0.4) as u32)
        }
    }

    /// The plot: its axes and grid, the series on their axes (bands first, then lines, then
    /// markers on top), and the arrowheads and point labels of the primary-axis series.
    fn draw_plot(
        &self,
        canvas: &Canvas<'_, '_>,
        plot_area: &Area<'_>,
        ranges: Ranges,
        has2: bool,
    ) -> std::result::Result<(), String> {
        use plotters::prelude::*;
        let k = SUPERSAMPLE;
        let (fonts, log, err) = (canvas.fonts, self.log, draw_error);
        let Ranges {
            x: xr,
            y: yr,
            y2: y2r,
        } = ranges;
        let mut builder = ChartBuilder::on(plot_area);
        // The title is the caption's job, not the plot's.
        builder
            .margin(12 * k)
            .x_label_area_size((fonts.tick + fonts.axis * 1.3) as u32)
            .y_label_area_size((fonts.tick * CHAR_EM * 4.5 + fonts.axis * 1.5) as u32);
        if has2 {
            builder.right_y_label_area_size((fonts.tick * CHAR_EM * 4.5 + fonts.axis * 1.5) as u32);
        }
        let (xs, ys, y2s) = (xr.1 - xr.0, yr.1 - yr.0, y2r.1 - y2r.0);
        let grid = RGBAColor(0, 0, 0, 0.12);
        let label = |v: f64, log: bool, span: f64| {
            if log {
                tick_label(v, true)
            } else {
                snapped_tick_label(v, span)
            }
        };
        // The series on one axis, layer by layer.
        macro_rules! draw_all {
            ($chart:ident . $method:ident, $secondary:expr) => {
                for layer in 0..3 {
                    for (s, &c) in self.series.iter().zip(canvas.colours) {
                        if s.secondary != $secondary || s.layer() != layer {
                            continue;
                        }
                        let pts = s.drawable_points(log);
                        let drawn = if !s.upper.is_empty() {
                            let band =
                                Polygon::new(s.band_outline(log), c.mix(BAND_ALPHA).filled());
                            $chart.$method(std::iter::once(band))
                        } else if s.markers {
                            let size = s.marker_size();
                            $chart.$method(
                                pts.iter()
                                    .map(|&p| marker_element(s.marker, p, size, c, s.hollow)),
                            )
                        } else if s.dashed {
                            $chart.$method(std::iter::once(dashed(pts, s.line_style(c))))
                        } else {
                            $chart.$method(LineSeries::new(pts, s.line_style(c)))
                        };
                        drawn.map_err(|e| err(&e))?;
                    }
                }
            };
        }
        macro_rules! primary {
            ($chart:ident) => {{
                $chart
                    .configure_mesh()
                    .x_desc(self.x_label)
                    .y_desc(self.y_label)
                    .x_label_formatter(&|v| label(*v, log.0, xs))
                    .y_label_formatter(&|v| label(*v, log.1, ys))
                    .max_light_lines(0)
                    .bold_line_style(grid.stroke_width(k))
                    .axis_style(BLACK.stroke_width(k))
                    .set_all_tick_mark_size(3 * k)
                    .x_labels(6)
                    .y_labels(6)
                    .axis_desc_style(("sans-serif", fonts.axis))
                    .label_style(("sans-serif", fonts.tick))
                    .draw()
                    .map_err(|e| err(&e))?;
                draw_all!($chart.draw_series, false);
                let area = $chart.plotting_area().get_pixel_range();
                self.annotate(canvas, &|p| $chart.backend_coord(&p), area)?;
            }};
        }
        macro_rules! build {
            ($x:expr, $y:expr) => {
                builder.build_cartesian_2d($x, $y).map_err(|e| err(&e))?
            };
        }
        match log {
            (false, false) => {
                let mut chart = build!(xr.0..xr.1, yr.0..yr.1);
                if has2 {
                    let mut chart = chart.set_secondary_coord(xr.0..xr.1, y2r.0..y2r.1);
                    primary!(chart);
                    chart
                        .configure_secondary_axes()
                        .y_desc(self.y2_label)
                        .y_label_formatter(&|v| snapped_tick_label(*v, y2s))
                        .axis_style(BLACK.stroke_width(k))
                        .set_all_tick_mark_size(3 * k)
                        .y_labels(6)
                        .axis_desc_style(("sans-serif", fonts.axis))
                        .label_style(("sans-serif", fonts.tick))
                        .draw()
                        .map_err(|e| err(&e))?;
                    draw_all!(chart.draw_secondary_series, true);
                } else {
                    primary!(chart);
                }
            }
            (true, false) => {
                let mut chart = build!((xr.0..xr.1).log_scale(), yr.0..yr.1);
                primary!(chart);
            }
            (false, true) => {
                let mut chart = build!(xr.0..xr.1, (yr.0..yr.1).log_scale());
                primary!(chart);
            }
            (true, true) => {
                let mut chart = build!((xr.0..xr.1).log_scale(), (yr.0..yr.1).log_scale());
                primary!(chart);
            }
        }
        Ok(())
    }

    /// The arrowheads and point labels of the primary-axis series, in the canvas's pixels:
    /// `to_px` places a point of the data, `area` is the plot's pixel range. A label goes where
    /// it stays inside the plot, clear of every marker and of the labels placed before it.
    fn annotate(
        &self,
        canvas: &Canvas<'_, '_>,
        to_px: &dyn Fn((f64, f64)) -> (i32, i32),
        area: (std::ops::Range<i32>, std::ops::Range<i32>),
    ) -> std::result::Result<(), String> {
        use plotters::prelude::*;
        let (ki, log, legend_px) = (SUPERSAMPLE as i32, self.log, canvas.fonts.legend);
        let label_font = ("sans-serif", legend_px).into_font().color(&BLACK);
        // Every marker is an obstacle to the labels.
        let mut placed: Vec<(i32, i32, i32, i32)> = Vec::new();
        for s in self.series.iter().filter(|s| s.markers && !s.secondary) {
            let r = ki * s.marker_size() + ki;
            for &p in s.points.iter().filter(|&&p| drawable(p, log)) {
                let (x, y) = to_px(p);
                placed.push((x - r, y - r, x + r, y + r));
            }
        }
        for (s, c) in self.series.iter().zip(canvas.colours) {
            if s.secondary {
                continue;
            }
            let px: Vec<Option<(i32, i32)>> = s
                .points
                .iter()
                .map(|&p| drawable(p, log).then(|| to_px(p)))
                .collect();
            for &i in &s.arrows {
                if let Some(head) = arrowhead(&px, i, 5 * ki) {
                    canvas
                        .root
                        .draw(&Polygon::new(head, c.filled()))
                        .map_err(|e| draw_error(&e))?;
                }
            }
            let h = (legend_px / 1.24) as i32;
            let width = |t: &str| (t.chars().count() as f64 * CHAR_EM * legend_px) as i32;
            let mut i = 0;
            while i < s.labels.len().min(px.len()) {
                let (text, j) = s.shared_label(&px, i, h);
                if let (Some(p), false) = (px[i], text.is_empty()) {
                    let (w, gap) = (width(&text), 4 * ki + h / 2);
                    // Right of the point, above, below, left: a label to the left reads as the
                    // right-hand label of the point before.
                    let spots = [
                        (p.0 + gap, p.1 - h / 2),
                        (p.0 - w / 2, p.1 - gap - h),
                        (p.0 - w / 2, p.1 + gap),
                        (p.0 - gap - w, p.1 - h / 2),
                    ];
                    // Inside the plot, clear of the markers and the labels placed so far.
                    let (xr, yr) = &area;
                    let inside = |&(x, y): &(i32, i32)| {
                        x >= xr.start && x + w <= xr.end && y >= yr.start && y + h <= yr.end
                    };
                    let clear = |&(x, y): &(i32, i32)| {
                        placed
                            .iter()
                            .all(|&(a, b, c, d)| x + w < a || x > c || y + h < b || y > d)
                    };
                    let (x, y) = spots
                        .iter()
                        .copied()
                        .find(|s| inside(s) && clear(s))
                        .or_else(|| spots.iter().copied().find(|s| inside(s)))
                        .unwrap_or(spots[0]);
                    placed.push((x, y, x + w, y + h));
                    canvas
                        .root
                        .draw(&Text::new(text, (x, y), label_font.clone()))
                        .map_err(|e| draw_error(&e))?;
                }
                i = j;
            }
        }
        Ok(())
    }

    /// The legend, in its own panel (`legend_w` canvas pixels wide) right of the plot: a symbol
    /// and the wrapped label of each `labelled` series, then the notes.
    fn draw_legend(
        &self,
        canvas: &Canvas<'_, '_>,
        area: &Area<'_>,
        labelled: &[usize],
        legend_w: u32,
    ) -> std::result::Result<(), String> {
        use plotters::prelude::*;
        let (k, legend_px, note_px) = (SUPERSAMPLE, canvas.fonts.legend, canvas.fonts.note);
        let err = draw_error;
        let font = ("sans-serif", legend_px).into_font().color(&BLACK);
        let ki = k as i32;
        let step = (legend_px * 1.45) as i32;
        let mut y = 12 * ki + step / 2;
        for &i in labelled {
            let (s, c) = (&self.series[i], canvas.colours[i]);
            let sym = (legend_px * 1.8) as i32;
            let line = vec![(4 * ki, y), (4 * ki + sym, y)];
            let drawn = if !s.upper.is_empty() {
                let half = (legend_px * 0.35) as i32;
                area.draw(&Rectangle::new(
                    [(4 * ki, y - half), (4 * ki + sym, y + half)],
                    c.mix(BAND_ALPHA).filled(),
                ))
            } else if s.markers {
                let at = (4 * ki + sym / 2, y);
                area.draw(&marker_element(s.marker, at, s.marker_size(), c, s.hollow))
            } else if s.dashed {
                area.draw(&dashed(line, s.line_style(c)))
            } else {
                area.draw(&PathElement::new(line, s.line_style(c)))
            };
            drawn.map_err(|e| err(&e))?;
            // Labels wrap to the panel's width.
            let room = (legend_w as f64 - (12 * ki + sym) as f64) / (CHAR_EM * legend_px);
            for (n, line) in wrap(s.label, room.max(6.0) as usize)
                .into_iter()
                .enumerate()
            {
                if n > 0 {
                    y += (legend_px * 1.2) as i32;
                }
                let at = (8 * ki + sym, y - (legend_px * 0.5) as i32);
                area.draw(&Text::new(line, at, font.clone()))
                    .map_err(|e| err(&e))?;
            }
            y += step;
        }
        let note_font = ("sans-serif", note_px)
            .into_font()
            .color(&RGBColor(60, 60, 60));
        let chars = ((legend_w as f64 - 8.0 * k as f64) / (CHAR_EM * note_px)).max(10.0) as usize;
        y += step / 3;
        for note in &self.notes {
            for line in wrap(note, chars) {
                let at = (4 * ki, y - (note_px * 0.5) as i32);
                area.draw(&Text::new(line, at, note_font.clone()))
                    .map_err(|e| err(&e))?;
                y += (note_px * 1.3) as i32;
            }
            y += step / 4;
        }
        Ok(())
    }
}
