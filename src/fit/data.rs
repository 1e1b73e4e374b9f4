//! Measured curves read from CSV files, in engineering units, with one clear error per bad file.

use std::collections::BTreeMap;
use std::path::Path;

use crate::error::DataError;

use serde::Serialize;

/// What a curve measures, decided by its x column.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CurveKind {
    /// Static touchdown (and take-off) power against DC voltage (the letter's Fig. 2b):
    /// x column `dc_voltage_*`.
    StaticVsDc,
    /// Dynamic touchdown and take-off power against AC amplitude (Fig. 2d), one cycle of the
    /// scene's fixed heater programme per amplitude: x column `ac_amplitude_*`.
    CycleVsAc,
    /// The contact indicator against heater power (the letter's Fig. 1), in its quasi-static
    /// limit: the contact force of the equilibrium the head reaches as the heater power rises to
    /// this value (the flying branch, then the contact branch after touchdown), at the scene's
    /// DC voltage with the AC off: x column `heater_power_*`.
    IndicatorVsPower,
}

/// A measured quantity of a curve.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// Touchdown power.
    TouchdownPower,
    /// Take-off power.
    TakeoffPower,
    /// Contact indicator, as a contact force.
    ContactIndicator,
}

impl Quantity {
    /// The column stem, e.g. `touchdown_power`.
    pub fn stem(self) -> &'static str {
        match self {
            Quantity::TouchdownPower => "touchdown_power",
            Quantity::TakeoffPower => "takeoff_power",
            Quantity::ContactIndicator => "contact_indicator",
        }
    }

    /// The weight (SI) of a value whose file gives no uncertainty: 1 mW for powers, 1 µN for the
    /// contact indicator; the overall scale is then estimated from the scatter.
    pub fn default_weight(self) -> f64 {
        match self {
            Quantity::TouchdownPower | Quantity::TakeoffPower => 1e-3,
            Quantity::ContactIndicator => 1e-6,
        }
    }
}

/// A unit of a column: its suffix and the factor to SI.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Unit {
    /// The suffix as written (`mw`, `v`, …).
    pub suffix: &'static str,
    /// Factor from this unit to SI.
    pub to_si: f64,
}

const VOLTS: &[Unit] = &[
    Unit {
        suffix: "v",
        to_si: 1.0,
    },
    Unit {
        suffix: "mv",
        to_si: 1e-3,
    },
];
const WATTS: &[Unit] = &[
    Unit {
        suffix: "mw",
        to_si: 1e-3,
    },
    Unit {
        suffix: "w",
        to_si: 1.0,
    },
    Unit {
        suffix: "uw",
        to_si: 1e-6,
    },
];

const NEWTONS: &[Unit] = &[
    Unit {
        suffix: "un",
        to_si: 1e-6,
    },
    Unit {
        suffix: "n",
        to_si: 1.0,
    },
    Unit {
        suffix: "mn",
        to_si: 1e-3,
    },
    Unit {
        suffix: "nn",
        to_si: 1e-9,
    },
];

/// The role of a column.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Role {
    X(CurveKind),
    Y(Quantity),
    Err(Quantity),
}

/// Column stems of the x and the measured columns, their role and their units. The uncertainty
/// of a measured column is the column of its stem and [`ERR`], in its units.
const COLUMNS: &[(&str, Role, &[Unit])] = &[
    ("dc_voltage", Role::X(CurveKind::StaticVsDc), VOLTS),
    ("ac_amplitude", Role::X(CurveKind::CycleVsAc), VOLTS),
    ("heater_power", Role::X(CurveKind::IndicatorVsPower), WATTS),
    ("touchdown_power", Role::Y(Quantity::TouchdownPower), WATTS),
    ("takeoff_power", Role::Y(Quantity::TakeoffPower), WATTS),
    (
        "contact_indicator",
        Role::Y(Quantity::ContactIndicator),
        NEWTONS,
    ),
];

/// What ends the stem of an uncertainty column (`touchdown_power_err_mw`).
const ERR: &str = "_err";

/// The role and units of a column stem, an uncertainty's among them; `None` for an unknown one.
fn column(stem: &str) -> Option<(Role, &'static [Unit])> {
    match stem.strip_suffix(ERR) {
        Some(measured) => COLUMNS.iter().find_map(|&(s, role, units)| match role {
            Role::Y(q) if s == measured => Some((Role::Err(q), units)),
            _ => None,
        }),
        None => COLUMNS
            .iter()
            .find(|(s, _, _)| *s == stem)
            .map(|&(_, role, units)| (role, units)),
    }
}

/// One measured column of a curve, in SI, with its optional 1σ uncertainties.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Observed {
    /// What it measures.
    pub quantity: Quantity,
    /// Values (SI).
    pub values: Vec<f64>,
    /// Standard uncertainty of each value (SI), when the file gives one.
    pub errors: Option<Vec<f64>>,
    /// The unit the file used (results are given back in it).
    pub unit: Unit,
}

/// One measured curve: an x column and one or more measured columns.
///
/// Columns are named `<quantity>_<unit>`: x is `dc_voltage_v` (or `_mv`), `ac_amplitude_v`
/// (or `_mv`) or `heater_power_mw` (or `_w`, `_uw`); measured columns are `touchdown_power_mw`
/// and `takeoff_power_mw` (or `_w`, `_uw`) against a voltage, `contact_indicator_un` (or `_n`,
/// `_mn`, `_nn`) against heater power, each with an optional uncertainty column
/// `touchdown_power_err_mw` etc. Lines starting with `#` are comments.
///
/// ```
/// use hdi_tribology::fit::{CurveKind, DataSet};
/// let d = DataSet::from_csv_str(
///     "# Fig. 2(b)\ndc_voltage_v,touchdown_power_mw\n-0.5,72.5\n0,74.3\n0.5,72.5\n",
///     "td.csv",
/// ).unwrap();
/// assert_eq!(d.kind, CurveKind::StaticVsDc);
/// assert_eq!(d.x, vec![-0.5, 0.0, 0.5]);
/// assert!((d.observed[0].values[1] - 0.0743).abs() < 1e-15);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DataSet {
    /// Where it came from (file name).
    pub origin: String,
    /// The kind of curve.
    pub kind: CurveKind,
    /// The x column as the file names it.
    pub x_name: String,
    /// x values (SI: volts).
    pub x: Vec<f64>,
    /// The unit of the x column in the file.
    pub x_unit: Unit,
    /// The measured columns.
    pub observed: Vec<Observed>,
    /// Line of each row in the file.
    pub lines: Vec<u64>,
}

fn err(file: &str, line: Option<u64>, col: Option<(usize, &str)>, reason: String) -> DataError {
    DataError {
        file: file.to_string(),
        line,
        column: col.map(|c| c.0 + 1),
        column_name: col.map(|c| c.1.to_string()),
        reason,
    }
}

/// The role and unit of a header name, or why it is not known.
fn classify(name: &str) -> Result<(Role, Unit), String> {
    let known = || {
        COLUMNS
            .iter()
            .flat_map(|&(stem, role, units)| {
                let own = format!("{stem}_{}", units[0].suffix);
                let err =
                    matches!(role, Role::Y(_)).then(|| format!("{stem}{ERR}_{}", units[0].suffix));
                std::iter::once(own).chain(err)
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    let Some((stem, unit)) = name.rsplit_once('_') else {
        return Err(format!("unknown column; known columns: {}", known()));
    };
    let Some((role, units)) = column(stem) else {
        return Err(format!("unknown column; known columns: {}", known()));
    };
    match units.iter().find(|u| u.suffix == unit) {
        Some(u) => Ok((role, *u)),
        None => Err(format!(
            "unknown unit `{unit}` for {stem}; known units: {}",
            units
                .iter()
                .map(|u| u.suffix)
                .collect::<Vec<_>>()
                .join(", ")
        )),
    }
}

/// A reader's error where it happened in the file `origin`.
fn csv_error(origin: &str, e: csv::Error) -> DataError {
    let line = e.position().map(|p| p.line());
    let reason = match e.kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => format!("{len} fields, the header has {expected_len}"),
        _ => e.to_string(),
    };
    err(origin, line, None, reason)
}

/// The header of a data file: the names, the line they stand on, and the role and unit of each
/// column.
struct Header {
    names: csv::StringRecord,
    line: u64,
    roles: Vec<(usize, Role, Unit)>,
}

/// The data rows of a file: the x values (SI), the line of each row, and each column's values
/// (SI) by column.
struct Rows {
    x: Vec<f64>,
    lines: Vec<u64>,
    cols: BTreeMap<usize, Vec<f64>>,
}

impl Header {
    /// Reads the header and classifies its columns, each quantity at most once.
    fn read(rdr: &mut csv::Reader<&[u8]>, origin: &str) -> Result<Header, DataError> {
        let header_line = rdr.position().line().max(1);
        let names = rdr.headers().map_err(|e| csv_error(origin, e))?.clone();
        let line = rdr.position().line().saturating_sub(1).max(header_line);
        let mut roles: Vec<(usize, Role, Unit)> = Vec::new();
        for (i, name) in names.iter().enumerate() {
            let (role, unit) =
                classify(name).map_err(|r| err(origin, Some(line), Some((i, name)), r))?;
            if let Some((j, _, _)) = roles
                .iter()
                .find(|(_, r, _)| matches!((r, role), (Role::X(_), Role::X(_))) || *r == role)
            {
                return Err(err(
                    origin,
                    Some(line),
                    Some((i, name)),
                    format!("the same quantity as column {} (`{}`)", j + 1, &names[*j]),
                ));
            }
            roles.push((i, role, unit));
        }
        Ok(Header { names, line, roles })
    }

    /// An error in the header of `origin`, about column `i` when given.
    fn error(&self, origin: &str, i: Option<usize>, reason: String) -> DataError {
        err(
            origin,
            Some(self.line),
            i.map(|i| (i, &self.names[i])),
            reason,
        )
    }

    /// The x column: its index, the kind of curve it makes and its unit.
    fn x_column(&self, origin: &str) -> Result<(usize, CurveKind, Unit), DataError> {
        match self.roles.iter().find(|(_, r, _)| matches!(r, Role::X(_))) {
            Some(&(xi, Role::X(kind), x_unit)) => Ok((xi, kind, x_unit)),
            _ => Err(self.error(
                origin,
                None,
                "missing column: no x column (`dc_voltage_v`, `ac_amplitude_v` or `heater_power_mw`)"
                    .into(),
            )),
        }
    }

    /// The measured columns (index, quantity, unit), checked against the x column `xi` of
    /// `kind`: at least one, of a quantity measured against that x, and every uncertainty
    /// beside its own column.
    fn measured_columns(
        &self,
        origin: &str,
        xi: usize,
        kind: CurveKind,
    ) -> Result<Vec<(usize, Quantity, Unit)>, DataError> {
        let indicator = kind == CurveKind::IndicatorVsPower;
        let ys: Vec<(usize, Quantity, Unit)> = self
            .roles
            .iter()
            .filter_map(|&(i, r, u)| match r {
                Role::Y(q) => Some((i, q, u)),
                _ => None,
            })
            .collect();
        if ys.is_empty() {
            return Err(self.error(
                origin,
                None,
                if indicator {
                    "missing column: no measured column (`contact_indicator_un`)".into()
                } else {
                    "missing column: no measured column (`touchdown_power_mw` or `takeoff_power_mw`)"
                        .into()
                },
            ));
        }
        // The indicator is measured against power, the transitions against a voltage.
        for &(i, q, _) in &ys {
            if (q == Quantity::ContactIndicator) != indicator {
                return Err(self.error(
                    origin,
                    Some(i),
                    format!(
                        "cannot be measured against `{}`: {}",
                        &self.names[xi],
                        if indicator {
                            "against heater power give `contact_indicator_un`"
                        } else {
                            "the contact indicator is given against `heater_power_mw`"
                        }
                    ),
                ));
            }
        }
        for &(i, r, _) in &self.roles {
            if let Role::Err(q) = r {
                if !ys.iter().any(|y| y.1 == q) {
                    return Err(self.error(
                        origin,
                        Some(i),
                        format!(
                            "missing column: an uncertainty of {} without the column itself",
                            q.stem()
                        ),
                    ));
                }
            }
        }
        Ok(ys)
    }

    /// Reads the data rows under the header, each value checked, the x values (column `xi`)
    /// each once; at least one row.
    fn read_rows(
        &self,
        rdr: &mut csv::Reader<&[u8]>,
        origin: &str,
        xi: usize,
    ) -> Result<Rows, DataError> {
        let mut rows = Rows {
            x: Vec::new(),
            lines: Vec::new(),
            cols: BTreeMap::new(),
        };
        let mut first_at: Vec<(f64, u64)> = Vec::new();
        for rec in rdr.records() {
            let rec = rec.map_err(|e| csv_error(origin, e))?;
            let line = rec.position().map_or(0, |p| p.line());
            for &(i, role, unit) in &self.roles {
                let text = rec.get(i).unwrap_or("");
                let at = Some((i, &self.names[i]));
                let v = parse_value(text, role, unit)
                    .map_err(|reason| err(origin, Some(line), at, reason))?;
                if matches!(role, Role::X(_)) {
                    let si = v * unit.to_si;
                    if let Some((_, l0)) = first_at.iter().find(|(x0, _)| *x0 == si) {
                        return Err(err(
                            origin,
                            Some(line),
                            at,
                            format!(
                                "duplicate x value {text} {} (first at line {l0})",
                                unit.suffix
                            ),
                        ));
                    }
                    first_at.push((si, line));
                }
                rows.cols.entry(i).or_default().push(v * unit.to_si);
            }
            rows.x.push(v_at(&rows.cols, xi));
            rows.lines.push(line);
        }
        if rows.x.is_empty() {
            return Err(err(origin, None, None, "no data rows".into()));
        }
        Ok(rows)
    }
}

/// The value of one field (`text`, in the file's `unit`) of a column of `role`: a finite number,
/// and above zero for an uncertainty; else why not.
fn parse_value(text: &str, role: Role, unit: Unit) -> Result<f64, String> {
    if text.is_empty() {
        return Err("missing value".into());
    }
    let v: f64 = text
        .parse()
        .map_err(|_| format!("not a number: `{text}`"))?;
    if !v.is_finite() {
        return Err(format!("must be a finite number, got `{text}`"));
    }
    if matches!(role, Role::Err(_)) && v <= 0.0 {
        return Err(format!(
            "an uncertainty must be > 0, got {text} {}",
            unit.suffix
        ));
    }
    Ok(v)
}

impl DataSet {
    /// Reads a curve from a CSV file.
    pub fn from_path(path: impl AsRef<Path>) -> Result<DataSet, DataError> {
        let path = path.as_ref();
        let origin = path.display().to_string();
        let text =
            std::fs::read_to_string(path).map_err(|e| err(&origin, None, None, e.to_string()))?;
        Self::from_csv_str(&text, &origin)
    }

    /// Reads a curve from CSV text; `origin` names it in errors.
    pub fn from_csv_str(text: &str, origin: &str) -> Result<DataSet, DataError> {
        let mut rdr = csv::ReaderBuilder::new()
            .comment(Some(b'#'))
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let header = Header::read(&mut rdr, origin)?;
        let (xi, kind, x_unit) = header.x_column(origin)?;
        let ys = header.measured_columns(origin, xi, kind)?;
        let rows = header.read_rows(&mut rdr, origin, xi)?;
        let observed = ys
            .iter()
            .map(|&(i, q, unit)| {
                let errors = header
                    .roles
                    .iter()
                    .find(|(_, r, _)| *r == Role::Err(q))
                    .map(|(j, _, _)| rows.cols[j].clone());
                Observed {
                    quantity: q,
                    values: rows.cols[&i].clone(),
                    errors,
                    unit,
                }
            })
            .collect();
        Ok(DataSet {
            origin: origin.to_string(),
            kind,
            x_name: header.names[xi].to_string(),
            x: rows.x,
            x_unit,
            observed,
            lines: rows.lines,
        })
    }

    /// Number of measured values (residuals) in the curve.
    pub fn len(&self) -> usize {
        self.observed.iter().map(|o| o.values.len()).sum()
    }

    /// Whether the curve holds no measured value.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether its model needs time integration.
    pub fn is_dynamic(&self) -> bool {
        self.kind == CurveKind::CycleVsAc
    }

    /// Whether its values are static transitions (whose sensitivities need no re-solve).
    pub fn is_transitions(&self) -> bool {
        self.kind == CurveKind::StaticVsDc
    }
}

fn v_at(cols: &BTreeMap<usize, Vec<f64>>, i: usize) -> f64 {
    cols.get(&i)
        .and_then(|c| c.last().copied())
        .unwrap_or(f64::NAN)
}
