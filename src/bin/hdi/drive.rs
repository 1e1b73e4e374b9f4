//! `hdi drive`: a command file replayed through the simulated drive; the sensor CSV written.

use std::path::PathBuf;

use hdi_tribology::drive::{
    read_commands, replay, scene_zone, whole_periods, DiskSpec, DriveOptions, Plant,
};

use crate::common::{self, positive, CliError, CountLines, Output, SceneArgs};

/// Replays --commands (CSV: time_s, heater_mw, voltage_dc_v and optionally voltage_ac_v,
/// ac_frequency_khz; each row holds until the next, the last row's time ends the run) through the
/// simulated drive at the controller rate, and writes one sensor row per period: time_s,
/// heater_mw, contact_resistance_ohm, acoustic_v, readback_fundamental_v, readback_third_v,
/// hr_clearance_change_nm, then the true values true_gap_nm, true_contact_force_un,
/// true_sensor_temperature_k, true_disk_height_nm, true_ambient_k (docs/clearance.md).
/// With --out the CSV goes to that file (written whole or not at all) and a JSON summary to
/// standard output; without it the CSV goes to standard output.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    scene: SceneArgs,
    /// Command file (CSV with a header).
    #[arg(long, value_name = "FILE")]
    commands: PathBuf,
    /// Sensor CSV to write [default: standard output].
    #[arg(long, value_name = "FILE")]
    out: Option<PathBuf>,
    /// Controller rate (kHz).
    #[arg(long, value_name = "KHZ", default_value = "20", value_parser = positive,
          allow_hyphen_values = true)]
    rate_khz: f64,
    /// Seed of the disk's random waviness and of the sensor noise.
    #[arg(long, default_value = "1")]
    seed: u64,
    /// Radius of the zone (mm); the scene gives its clearance, stiffness and disk speed.
    #[arg(long, value_name = "MM", default_value = "25", value_parser = positive,
          allow_hyphen_values = true)]
    radius_mm: f64,
    /// A flat disk (no run-out, no waviness).
    #[arg(long)]
    flat_disk: bool,
    /// Displacement tolerance of the integration near contact (pm) [default: 0.01].
    #[arg(long, value_name = "PM", value_parser = positive, allow_hyphen_values = true)]
    atol_pm: Option<f64>,
    /// Displacement tolerance in flight, where the contact force barely depends on the gap (pm,
    /// at least --atol-pm; equal to it for one tolerance throughout; docs/clearance.md,
    /// "Accuracy": 1 pm runs a wavy disk about 3 times faster in flight, at a cost in accuracy
    /// where the head snaps into contact) [default: --atol-pm].
    #[arg(long, value_name = "PM", value_parser = positive, allow_hyphen_values = true)]
    atol_flight_pm: Option<f64>,
}

pub fn run(a: Args) -> Result<(), CliError> {
    let scene = a.scene.load()?;
    let opts = DriveOptions {
        disk: if a.flat_disk {
            DiskSpec::flat()
        } else {
            DiskSpec::default()
        },
        ..DriveOptions::default()
    }
    .with_tolerances_pm(
        a.atol_pm,
        a.atol_flight_pm,
        ["--atol-pm", "--atol-flight-pm"],
    )
    // Both are positive numbers by now: what is left is a flag that does not fit the other.
    .map_err(|e| CliError::Usage(e.to_string()))?;
    let shown = a.commands.display().to_string();
    let file = std::fs::File::open(&a.commands)
        .map_err(|e| CliError::Failed(format!("--commands {shown}: {e}")))?;
    let rows = read_commands(std::io::BufReader::new(file), &shown)?;
    let dt = 1e-3 / a.rate_khz;
    // A run ends on a period boundary: an end between two is refused, not cut.
    let periods = whole_periods(&rows, dt, &shown)?;
    let out = a
        .out
        .as_deref()
        .map(|p| Output::prepare(p, "--out"))
        .transpose()?;
    let plant = Plant::new(
        &scene,
        &scene_zone(&scene, a.radius_mm * 1e-3)?,
        a.seed,
        opts,
    )?;
    // One line per period, and the header.
    let progress = common::Progress::bar("drive", periods as u64 + 1, "lines");
    match out {
        Some(out) => {
            let mut summary = None;
            out.write_with(|w| {
                let w = CountLines {
                    inner: w,
                    progress: &progress,
                };
                summary = Some(replay(&plant, &rows, dt, w)?);
                Ok(())
            })?;
            drop(progress);
            common::print_json(&summary)
        }
        None => {
            // Whole or nothing on standard output too: the run finishes before anything is printed.
            let mut buf = Vec::new();
            let w = CountLines {
                inner: &mut buf,
                progress: &progress,
            };
            replay(&plant, &rows, dt, w)?;
            drop(progress);
            common::write_stdout(&buf)
        }
    }
}
