//! Replaying a command file through a drive: the way in for tools that are not Rust.

use super::heads::MultiPlant;
use super::plant::{Command, Plant};
use super::sensors::{clearance_change, Sensors};
use crate::error::{Error, Result};
use std::io::{Read, Write};

/// One row of a command file: from `time` on, until the next row, the drive holds this command.
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize)]
pub struct CommandRow {
    /// Time the row takes effect (s).
    pub time_s: f64,
    /// Heater power (mW).
    pub heater_mw: f64,
    /// DC head–disk voltage (V).
    pub voltage_dc_v: f64,
    /// AC dither amplitude (V); 0 when the column is absent.
    #[serde(default)]
    pub voltage_ac_v: f64,
    /// AC dither frequency (kHz); 0 when the column is absent.
    #[serde(default)]
    pub ac_frequency_khz: f64,
}

/// The columns of the sensor file [`replay`] writes, with their units, in order.
pub const SENSOR_COLUMNS: [&str; 12] = [
    "time_s",
    "heater_mw",
    "contact_resistance_ohm",
    "acoustic_v",
    "readback_fundamental_v",
    "readback_third_v",
    "hr_clearance_change_nm",
    "true_gap_nm",
    "true_contact_force_un",
    "true_sensor_temperature_k",
    "true_disk_height_nm",
    "true_ambient_k",
];

/// Most periods one replay may run.
pub const MAX_REPLAY_PERIODS: f64 = 1e7;

/// The columns of a command file: name, unit, and whether it may be left out.
const COMMAND_COLUMNS: [(&str, &str, bool); 5] = [
    ("time_s", "s", false),
    ("heater_mw", "mW", false),
    ("voltage_dc_v", "V", false),
    ("voltage_ac_v", "V", true),
    ("ac_frequency_khz", "kHz", true),
];

/// Reads a command file (CSV with a header naming the columns of [`CommandRow`]; the AC columns
/// may be left out, no other column may be there). `origin` names the file in errors.
///
/// # Errors
/// A column that is not a command column (a misspelt `voltage_ac` would otherwise run with no
/// dither), a column missing or given twice, a row of the wrong length, a value that is not a
/// number or out of range (heater above 1000 mW, a voltage beyond ±1000 V, an AC frequency
/// above 10 MHz), times that are not strictly increasing from 0: an [`Error::InvalidInput`]
/// naming the file, the line and the column.
///
/// ```
/// use hdi_tribology::drive::read_commands;
/// let csv = "time_s,heater_mw,voltage_dc_v\n0,60,0\n0.001,70,0\n0.002,70,0\n";
/// let rows = read_commands(csv.as_bytes(), "commands.csv")?;
/// assert_eq!(rows.len(), 3);
/// assert_eq!(rows[1].heater_mw, 70.0);
/// let bad = "time_s,heater_mw,voltage_dc_v\n0,60,0\n0.001,-5,0\n";
/// let e = read_commands(bad.as_bytes(), "commands.csv").unwrap_err();
/// assert!(e.to_string().contains("commands.csv line 3, heater_mw"), "{e}");
/// let typo = "time_s,heater_mw,voltage_dc_v,voltage_ac\n0,60,0,1\n0.001,60,0,1\n";
/// let e = read_commands(typo.as_bytes(), "commands.csv").unwrap_err();
/// assert!(e.to_string().contains("`voltage_ac`"), "{e}");
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn read_commands<R: Read>(input: R, origin: &str) -> Result<Vec<CommandRow>> {
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .flexible(true)
        .from_reader(input);
    let header = rdr.headers().map_err(|e| csv_error(origin, e))?.clone();
    // Where each command column sits in the file.
    let mut at: [Option<usize>; 5] = [None; 5];
    let known = || {
        COMMAND_COLUMNS
            .iter()
            .map(|c| c.0)
            .collect::<Vec<_>>()
            .join(", ")
    };
    for (j, name) in header.iter().enumerate() {
        let field = || format!("{origin} line 1, column {} `{name}`", j + 1);
        match COMMAND_COLUMNS.iter().position(|c| c.0 == name) {
            Some(k) if at[k].is_some() => {
                return Err(Error::invalid(field(), "is given twice"));
            }
            Some(k) => at[k] = Some(j),
            None => {
                return Err(Error::invalid(
                    field(),
                    format!(
                        "is not a command column; the columns are {} (the last two may be left \
                         out)",
                        known()
                    ),
                ))
            }
        }
    }
    if let Some(k) = (0..5).find(|&k| at[k].is_none() && !COMMAND_COLUMNS[k].2) {
        let (name, unit, _) = COMMAND_COLUMNS[k];
        return Err(Error::invalid(
            format!("{origin} line 1"),
            format!(
                "the column {name} ({unit}) is missing; the columns are {}",
                known()
            ),
        ));
    }
    let mut rows: Vec<CommandRow> = Vec::new();
    for rec in rdr.records() {
        let rec = rec.map_err(|e| csv_error(origin, e))?;
        let line = rec.position().map_or(rows.len() + 2, |p| p.line() as usize);
        let field = |name: &str| format!("{origin} line {line}, {name}");
        if rec.len() != header.len() {
            return Err(Error::invalid(
                format!("{origin} line {line}"),
                format!("has {} fields, the header {}", rec.len(), header.len()),
            ));
        }
        let mut v = [0.0; 5];
        for (k, &(name, unit, _)) in COMMAND_COLUMNS.iter().enumerate() {
            let Some(j) = at[k] else { continue };
            let text = rec.get(j).unwrap_or("");
            v[k] = match text.parse::<f64>() {
                _ if text.is_empty() => {
                    return Err(Error::invalid(field(name), format!("is empty ({unit})")))
                }
                Ok(x) => x,
                Err(_) => {
                    return Err(Error::invalid(
                        field(name),
                        format!("`{text}` is not a number ({unit})"),
                    ))
                }
            };
        }
        let row = CommandRow {
            time_s: v[0],
            heater_mw: v[1],
            voltage_dc_v: v[2],
            voltage_ac_v: v[3],
            ac_frequency_khz: v[4],
        };
        check_row(&row, rows.last(), field)?;
        rows.push(row);
    }
    check_count(&rows, origin)?;
    Ok(rows)
}

/// A reading error of the csv crate in words, with the file and line.
fn csv_error(origin: &str, e: csv::Error) -> Error {
    let line = e.position().map(|p| p.line());
    let at = line.map_or_else(|| origin.to_string(), |l| format!("{origin} line {l}"));
    match e.kind() {
        csv::ErrorKind::Io(err) => Error::invalid(origin, format!("cannot read: {err}")),
        csv::ErrorKind::Utf8 { .. } => Error::invalid(at, "is not UTF-8 text"),
        _ => Error::invalid(at, e.to_string()),
    }
}

/// The last row's time as a whole number of periods `dt` (s), or an error naming `origin`:
/// a replay runs whole periods, and an end between two would be cut without a word.
///
/// ```
/// use hdi_tribology::drive::{read_commands, whole_periods};
/// let rows = read_commands("time_s,heater_mw,voltage_dc_v\n0,60,0\n0.001,60,0\n".as_bytes(), "c.csv")?;
/// assert_eq!(whole_periods(&rows, 50e-6, "c.csv")?, 20);
/// assert!(whole_periods(&rows, 30e-6, "c.csv").is_err());
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn whole_periods(rows: &[CommandRow], dt: f64, origin: &str) -> Result<usize> {
    crate::error::check_positive("dt", dt)?;
    let end = rows.last().map_or(0.0, |r| r.time_s);
    let n = end / dt;
    let whole = n.round();
    if (n - whole).abs() > 1e-9 * whole.max(1.0) {
        let (below, above) = (n.floor() * dt, n.ceil() * dt);
        return Err(Error::invalid(
            format!("{origin}, the last row's time_s"),
            format!(
                "{} s is {} periods of {} µs, not a whole number: end at {} s or {} s",
                crate::units::fmt_short(end),
                crate::units::fmt_short(n),
                crate::units::fmt_short(dt * 1e6),
                crate::units::fmt_short(below),
                crate::units::fmt_short(above),
            ),
        ));
    }
    Ok(whole as usize)
}

/// Checks command rows given as columns rather than read from a file (for bindings and
/// programs that hold the commands in memory), with the rules of [`read_commands`]; `field`
/// names a value in errors from its row index and column name.
///
/// ```
/// use hdi_tribology::drive::{check_commands, CommandRow};
/// let row = |t: f64, p: f64| CommandRow { time_s: t, heater_mw: p, voltage_dc_v: 0.0,
///     voltage_ac_v: 0.0, ac_frequency_khz: 0.0 };
/// let field = |i: usize, name: &str| format!("{name}[{i}]");
/// assert!(check_commands(&[row(0.0, 60.0), row(1e-3, 65.0)], "commands", field).is_ok());
/// let e = check_commands(&[row(0.0, 60.0), row(0.0, 65.0)], "commands", field).unwrap_err();
/// assert!(e.to_string().contains("time_s[1]"), "{e}");
/// ```
pub fn check_commands(
    rows: &[CommandRow],
    origin: &str,
    field: impl Fn(usize, &str) -> String,
) -> Result<()> {
    for (i, row) in rows.iter().enumerate() {
        let prev = i.checked_sub(1).map(|j| &rows[j]);
        check_row(row, prev, |name| field(i, name))?;
    }
    check_count(rows, origin)
}

/// The unit of a command column.
fn unit_of(name: &str) -> &'static str {
    COMMAND_COLUMNS
        .iter()
        .find(|c| c.0 == name)
        .map_or("", |c| c.1)
}

/// One row's values and its time against the row before.
fn check_row(
    row: &CommandRow,
    prev: Option<&CommandRow>,
    field: impl Fn(&str) -> String,
) -> Result<()> {
    let check = |name: &str, v: f64, ok: bool, want: &str| -> Result<()> {
        if v.is_finite() && ok {
            Ok(())
        } else {
            Err(Error::invalid(
                field(name),
                format!("must be {want}, got {v} {}", unit_of(name)),
            ))
        }
    };
    let max_mw = super::plant::MAX_HEATER_POWER * 1e3;
    let max_v = crate::scene::MAX_VOLTAGE_V;
    let max_khz = crate::scene::MAX_AC_FREQUENCY_HZ * 1e-3;
    check("time_s", row.time_s, row.time_s >= 0.0, "≥ 0 s")?;
    check(
        "heater_mw",
        row.heater_mw,
        (0.0..=max_mw).contains(&row.heater_mw),
        &format!("in [0, {max_mw}] mW (far above any fly-height heater)"),
    )?;
    check(
        "voltage_dc_v",
        row.voltage_dc_v,
        row.voltage_dc_v.abs() <= max_v,
        &format!("within ±{max_v} V, as in a scene"),
    )?;
    check(
        "voltage_ac_v",
        row.voltage_ac_v,
        (0.0..=max_v).contains(&row.voltage_ac_v),
        &format!("in [0, {max_v}] V, as in a scene"),
    )?;
    check(
        "ac_frequency_khz",
        row.ac_frequency_khz,
        (0.0..=max_khz).contains(&row.ac_frequency_khz),
        &format!("in [0, {max_khz}] kHz, as in a scene"),
    )?;
    match prev {
        None if row.time_s != 0.0 => Err(Error::invalid(
            field("time_s"),
            format!("the first row must be at 0 s, got {} s", row.time_s),
        )),
        Some(p) if row.time_s <= p.time_s => Err(Error::invalid(
            field("time_s"),
            format!(
                "times must increase strictly, got {} s after {} s",
                row.time_s, p.time_s
            ),
        )),
        _ => Ok(()),
    }
}

/// A command list needs the first command and the end time.
fn check_count(rows: &[CommandRow], origin: &str) -> Result<()> {
    if rows.len() < 2 {
        return Err(Error::invalid(
            origin,
            "needs at least two rows: the first command and the end time",
        ));
    }
    Ok(())
}

/// What a replay did.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ReplaySummary {
    /// Periods run.
    pub periods: usize,
    /// Drive time simulated (s).
    #[serde(rename = "simulated_time_s")]
    pub simulated_time: f64,
    /// Heads run (each period gives one row per head); written only when more than one.
    #[serde(skip_serializing_if = "is_one")]
    pub heads: usize,
    /// In the bounded mode ([`DriveOptions::steps_per_period`](super::DriveOptions)), how far
    /// its fixed steps were from the tolerances; written only in that mode.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bounded: Option<BoundedSummary>,
}

/// The error flags of a replay in the bounded mode, over every period and head.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct BoundedSummary {
    /// Steps per period.
    pub steps_per_period: usize,
    /// Periods (of any head) whose error estimate was above 1: a step missed the tolerances.
    pub periods_over_tolerance: usize,
    /// The largest error estimate of a period.
    pub max_error_estimate: f64,
}

fn is_one(n: &usize) -> bool {
    *n == 1
}

/// Replays `rows` (see [`read_commands`]) through a drive started on `plant`, stepping at period
/// `dt` (s), and writes one CSV row of sensors per period to `out` ([`SENSOR_COLUMNS`]: time in
/// s, heater in mW, resistance in Ω, AE and read-back amplitudes in V, the harmonic-ratio
/// clearance change since the first period in nm, then the true gap in nm, the period-mean
/// contact force in µN, the contact-sensor temperature and the ambient change in K and the disk
/// height in nm). Each row's command holds from its time until the next row's; the last row's
/// time ends the run. A period takes the command in force at its start.
///
/// # Errors
/// Invalid `dt`; more than [`MAX_REPLAY_PERIODS`] periods (checked before anything is
/// written); a command out of range; integration and write failures.
///
/// ```
/// use hdi_tribology::drive::{read_commands, replay, scene_zone, DriveOptions, Plant};
/// use hdi_tribology::scene::Scene;
/// let scene = Scene::paper();
/// let plant = Plant::new(&scene, &scene_zone(&scene, 0.025)?, 1, DriveOptions::default())?;
/// let rows = read_commands("time_s,heater_mw,voltage_dc_v\n0,60,0\n0.001,65,0\n0.002,65,0\n".as_bytes(), "c.csv")?;
/// let mut out = Vec::new();
/// let summary = replay(&plant, &rows, 50e-6, &mut out)?;
/// assert_eq!(summary.periods, 40);
/// let text = String::from_utf8(out).unwrap();
/// assert_eq!(text.lines().count(), 41); // header + one row per period
/// assert!(text.starts_with("time_s,heater_mw,contact_resistance_ohm"));
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn replay<W: Write>(
    plant: &Plant,
    rows: &[CommandRow],
    dt: f64,
    out: W,
) -> Result<ReplaySummary> {
    replay_heads(&MultiPlant::new(vec![plant.clone()])?, rows, dt, out)
}

/// [`replay`] on every head of a drive of several heads, each head holding the same commands:
/// one CSV row per period and head, in head order, led by a `head` column (0 for the first)
/// when there is more than one head; with one head, the file of [`replay`].
///
/// ```
/// use hdi_tribology::drive::{read_commands, replay_heads, scene_zone, DriveOptions, MultiPlant};
/// use hdi_tribology::scene::Scene;
/// let scene = Scene::paper();
/// let zone = scene_zone(&scene, 0.025)?;
/// let plant = MultiPlant::uniform(&scene, &zone, 2, 1, DriveOptions::default())?;
/// let rows = read_commands("time_s,heater_mw,voltage_dc_v\n0,60,0\n0.0005,60,0\n".as_bytes(), "c.csv")?;
/// let mut out = Vec::new();
/// let summary = replay_heads(&plant, &rows, 50e-6, &mut out)?;
/// assert_eq!((summary.periods, summary.heads), (10, 2));
/// let text = String::from_utf8(out).unwrap();
/// assert!(text.starts_with("head,time_s,heater_mw"));
/// assert_eq!(text.lines().count(), 21);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
///
/// # Errors
/// As [`replay`].
pub fn replay_heads<W: Write>(
    plant: &MultiPlant,
    rows: &[CommandRow],
    dt: f64,
    out: W,
) -> Result<ReplaySummary> {
    let io = |e: csv::Error| Error::invalid("output", e.to_string());
    let mut w = csv::Writer::from_writer(out);
    let several = plant.heads() > 1;
    let write_header = |w: &mut csv::Writer<W>| {
        if several {
            w.write_field("head").map_err(io)?;
        }
        w.write_record(SENSOR_COLUMNS).map_err(io)
    };
    // The header goes out with the first row, so that nothing is written when the checks of
    // `replay_heads_each` fail.
    let mut header = false;
    let summary = replay_heads_each(plant, rows, dt, |head, row| {
        if !header {
            write_header(&mut w)?;
            header = true;
        }
        if several {
            w.write_field(head.to_string()).map_err(io)?;
        }
        w.serialize(row).map_err(io)
    })?;
    if !header {
        write_header(&mut w)?;
    }
    w.flush()
        .map_err(|e| Error::invalid("output", e.to_string()))?;
    Ok(summary)
}

/// [`replay`] without the file: `each` receives every period's row of sensors, in the columns
/// and units of [`SENSOR_COLUMNS`], as it is made (for bindings that collect the columns).
///
/// ```
/// use hdi_tribology::drive::{read_commands, replay_each, scene_zone, DriveOptions, Plant};
/// use hdi_tribology::scene::Scene;
/// let scene = Scene::paper();
/// let plant = Plant::new(&scene, &scene_zone(&scene, 0.025)?, 1, DriveOptions::default())?;
/// let rows = read_commands("time_s,heater_mw,voltage_dc_v\n0,60,0\n0.0005,60,0\n".as_bytes(), "c.csv")?;
/// let mut gaps = Vec::new();
/// replay_each(&plant, &rows, 50e-6, |row| Ok(gaps.push(row[7])))?;
/// assert_eq!(gaps.len(), 10);
/// assert!(gaps.iter().all(|&g| g > 0.0)); // flying: the true gap in nm
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
///
/// # Errors
/// As [`replay`]; an error `each` returns stops the replay and is passed on.
pub fn replay_each(
    plant: &Plant,
    rows: &[CommandRow],
    dt: f64,
    mut each: impl FnMut(&[f64; 12]) -> Result<()>,
) -> Result<ReplaySummary> {
    let one = MultiPlant::new(vec![plant.clone()])?;
    replay_heads_each(&one, rows, dt, |_, row| each(row))
}

/// [`replay_heads`] without the file: `each` receives the head and its row of sensors, for
/// every period and head, in that order.
///
/// # Errors
/// As [`replay`]; an error `each` returns stops the replay and is passed on.
pub fn replay_heads_each(
    plant: &MultiPlant,
    rows: &[CommandRow],
    dt: f64,
    mut each: impl FnMut(usize, &[f64; 12]) -> Result<()>,
) -> Result<ReplaySummary> {
    crate::error::check_positive("dt", dt)?;
    let end = rows.last().map_or(0.0, |r| r.time_s);
    let periods = (end / dt * (1.0 + 1e-12)).floor();
    if periods > MAX_REPLAY_PERIODS {
        return Err(Error::invalid(
            "dt",
            format!(
                "{end} s at {} µs is more than {MAX_REPLAY_PERIODS} periods",
                dt * 1e6
            ),
        ));
    }
    let periods = periods as usize;
    let heads = plant.heads();
    let wavelengths: Vec<f64> = (0..heads)
        .filter_map(|k| plant.head(k))
        .map(|p| p.sensor_spec().readback.wavelength)
        .collect();
    let mut drive = plant.drive()?;
    let mut commands = vec![Command::default(); heads];
    let mut sensors = vec![Sensors::default(); heads];
    let mut reference = vec![None; heads];
    let mut bounded = plant
        .head(0)
        .and_then(|p| p.steps_per_period())
        .map(|n| BoundedSummary {
            steps_per_period: n,
            periods_over_tolerance: 0,
            max_error_estimate: 0.0,
        });
    let mut k = 0usize;
    for n in 0..periods {
        let t0 = n as f64 * dt;
        while k + 1 < rows.len() && rows[k + 1].time_s <= t0 * (1.0 + 1e-12) {
            k += 1;
        }
        let r = rows[k];
        commands.fill(Command {
            heater_power_mw: r.heater_mw,
            dc_voltage_v: r.voltage_dc_v,
            ac_amplitude_v: r.voltage_ac_v,
            ac_frequency_khz: r.ac_frequency_khz,
        });
        drive.step_into(&commands, dt, &mut sensors)?;
        for (h, s) in sensors.iter().enumerate() {
            let lr0 = *reference[h].get_or_insert(s.readback.log_ratio());
            each(h, &sensor_row(s, lr0, wavelengths[h]))?;
            if let Some(b) = bounded.as_mut() {
                let e = drive
                    .head(h)
                    .map_or(f64::NAN, |d| d.last_period().error_estimate);
                b.max_error_estimate = b.max_error_estimate.max(e);
                // A NaN estimate (no step yet) counts as a miss.
                b.periods_over_tolerance += usize::from(e.is_nan() || e > 1.0);
            }
        }
    }
    Ok(ReplaySummary {
        periods,
        simulated_time: drive.time(),
        heads,
        bounded,
    })
}

/// One period's [`Sensors`] as a row of the sensor file, in the columns and units of
/// [`SENSOR_COLUMNS`]. The harmonic-ratio clearance change is taken against
/// `reference_log_ratio`, the read-back `ln(A_1/A_3)` of the first period, with `wavelength_m`
/// the read-back's bit wavelength (m, as the drive's [`ReadbackSpec`](super::ReadbackSpec)
/// holds it).
///
/// ```
/// use hdi_tribology::drive::{scene_zone, sensor_row, Command, DriveOptions, Plant};
/// use hdi_tribology::scene::Scene;
/// let scene = Scene::paper();
/// let plant = Plant::new(&scene, &scene_zone(&scene, 0.025)?, 1, DriveOptions::default())?;
/// let mut drive = plant.drive()?;
/// let s = drive.step(&Command::heater_mw(60.0), 50e-6)?;
/// let row = sensor_row(&s, s.readback.log_ratio(), plant.sensor_spec().readback.wavelength);
/// assert_eq!(row[1], 60.0); // heater, mW
/// assert_eq!(row[6], 0.0); // no clearance change against itself
/// assert_eq!(row[7], s.truth.gap_nm);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn sensor_row(s: &Sensors, reference_log_ratio: f64, wavelength_m: f64) -> [f64; 12] {
    let tr = &s.truth;
    let change_m = clearance_change(reference_log_ratio, s.readback.log_ratio(), wavelength_m);
    [
        s.time_s,
        s.heater_power_mw,
        s.contact_resistance_ohm,
        s.acoustic_v,
        s.readback.fundamental_v,
        s.readback.third_v,
        change_m * 1e9,
        tr.gap_nm,
        tr.mean_contact_force_un,
        tr.sensor_temperature_k,
        tr.disk_height_nm,
        tr.ambient_k,
    ]
}
