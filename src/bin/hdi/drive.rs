//! `hdi drive`: a command file replayed through the simulated drive; the sensor CSV written.

use std::path::PathBuf;

use hdi_tribology::drive::{
    read_commands, replay_heads, spec_zone, whole_periods, DiskSpec, DriveOptions, MultiPlant,
    ReplaySummary,
};

use hdi_tribology::scene::DriveSpec;

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
    /// Radius of the zone (mm; scene `drive.radius_m`, default 25); the scene gives its
    /// clearance, stiffness and disk speed.
    #[arg(long, value_name = "MM", allow_hyphen_values = true)]
    radius_mm: Option<f64>,
    /// Heads on the disk, one per surface (scene `drive.heads`) [default: 1]: every head holds
    /// the same commands over its own surface (head k seeded `drive::head_seed(seed, k)`), and
    /// the CSV gains a leading `head` column, one row per period and head.
    #[arg(long, value_name = "N", allow_hyphen_values = true)]
    heads: Option<f64>,
    /// Spindle speed (rpm) [default: the scene's disk speed at the radius].
    #[arg(long, value_name = "RPM", allow_hyphen_values = true)]
    rpm: Option<f64>,
    /// Heater power at the start (mW) [default: 60].
    #[arg(long, value_name = "MW", allow_hyphen_values = true)]
    initial_heater_power_mw: Option<f64>,
    /// Heater time constant where the scene's heater has none (µs) [default: 100].
    #[arg(long, value_name = "US", allow_hyphen_values = true)]
    heater_time_constant_us: Option<f64>,
    /// Once-around run-out amplitude (nm) [default: 1000].
    #[arg(long, value_name = "NM", allow_hyphen_values = true)]
    runout_nm: Option<f64>,
    /// Random waviness, root-mean-square height (nm) [default: 0.3].
    #[arg(long, value_name = "NM", allow_hyphen_values = true)]
    waviness_rms_nm: Option<f64>,
    /// Ambient drift rate (K/s) [default: 0].
    #[arg(long, value_name = "K_PER_S", allow_hyphen_values = true)]
    ambient_rate_k_per_s: Option<f64>,
    /// Ambient periodic amplitude (K) [default: 0].
    #[arg(long, value_name = "K", allow_hyphen_values = true)]
    ambient_amplitude_k: Option<f64>,
    /// Ambient period (s) [default: 1].
    #[arg(long, value_name = "S", allow_hyphen_values = true)]
    ambient_period_s: Option<f64>,
    /// Clearance change per kelvin of ambient (nm/K) [default: 0.03].
    #[arg(long, value_name = "NM_PER_K", allow_hyphen_values = true)]
    ambient_clearance_per_kelvin_nm: Option<f64>,
    /// Ambient temperature step (K) [default: 0].
    #[arg(long, value_name = "K", allow_hyphen_values = true)]
    ambient_step_k: Option<f64>,
    /// Time of the ambient step (s) [default: 0].
    #[arg(long, value_name = "S", allow_hyphen_values = true)]
    ambient_step_time_s: Option<f64>,
    /// Acoustic-emission gain (V/√W) [default: 1].
    #[arg(long, value_name = "G", allow_hyphen_values = true)]
    ae_gain_v_per_sqrt_w: Option<f64>,
    /// Acoustic-emission RMS detector band (kHz) [default: 5].
    #[arg(long, value_name = "KHZ", allow_hyphen_values = true)]
    ae_bandwidth_khz: Option<f64>,
    /// Acoustic-emission noise per quadrature (V) [default: 0.002].
    #[arg(long, value_name = "V", allow_hyphen_values = true)]
    ae_noise_v: Option<f64>,
    /// Contact-sensor noise per sample (Ω) [default: 0.005].
    #[arg(long, value_name = "OHM", allow_hyphen_values = true)]
    contact_noise_ohm: Option<f64>,
    /// Read-back wavelength (nm) [default: 100].
    #[arg(long, value_name = "NM", allow_hyphen_values = true)]
    readback_wavelength_nm: Option<f64>,
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
    /// The bounded mode, for firmware in the loop: at most N Radau5 steps a period, a step of
    /// a period's N-th accepted whatever its error (1 to 64; 8 keeps every sensor within a
    /// tenth of its noise once in contact; docs/clearance.md, "The bounded mode"). Periods
    /// whose error estimate passed the tolerances are counted in the summary and warned about
    /// [default: adaptive steps].
    #[arg(long, value_name = "N", allow_hyphen_values = true,
          value_parser = clap::value_parser!(u32)
              .range(1..=hdi_tribology::drive::MAX_STEPS_PER_PERIOD as i64))]
    steps_per_period: Option<u32>,
    /// How each period is advanced: integrator (the adaptive integrator) or exponential (one
    /// exponential step a period with the Jacobian held, the integrator where it misses; about
    /// three times faster where the command changes every period; docs/clearance.md, "The
    /// exponential scheme") [default: integrator].
    #[arg(long, value_name = "S")]
    scheme: Option<String>,
}

/// The drive of the scene's `[drive]` section with the flags over it (each flag checked and
/// named as written, in its unit).
fn drive_spec(a: &Args, scene: &hdi_tribology::scene::Scene) -> Result<DriveSpec, CliError> {
    let mut spec = scene.drive.clone().unwrap_or_default();
    let flags = [
        ("heads", a.heads),
        ("radius_mm", a.radius_mm),
        ("rpm", a.rpm),
        ("initial_heater_power_mw", a.initial_heater_power_mw),
        ("heater_time_constant_us", a.heater_time_constant_us),
        ("runout_nm", a.runout_nm),
        ("waviness_rms_nm", a.waviness_rms_nm),
        ("ambient_rate_k_per_s", a.ambient_rate_k_per_s),
        ("ambient_amplitude_k", a.ambient_amplitude_k),
        ("ambient_period_s", a.ambient_period_s),
        (
            "ambient_clearance_per_kelvin_nm",
            a.ambient_clearance_per_kelvin_nm,
        ),
        ("ambient_step_k", a.ambient_step_k),
        ("ambient_step_time_s", a.ambient_step_time_s),
        ("ae_gain_v_per_sqrt_w", a.ae_gain_v_per_sqrt_w),
        ("ae_bandwidth_khz", a.ae_bandwidth_khz),
        ("ae_noise_v", a.ae_noise_v),
        ("contact_noise_ohm", a.contact_noise_ohm),
        ("readback_wavelength_nm", a.readback_wavelength_nm),
    ];
    for (name, v) in flags {
        if let Some(v) = v {
            let flag = format!("--{}", name.replace('_', "-"));
            spec.set(name, v, &flag)
                .map_err(|e| CliError::Usage(e.to_string()))?;
        }
    }
    Ok(spec)
}

/// The bounded mode's periods that missed the tolerances, on standard error.
fn warn_bounded(summary: &ReplaySummary) {
    if let Some(b) = summary.bounded {
        if b.periods_over_tolerance > 0 {
            common::warn(&format!(
                "--steps-per-period {}: {} of {} periods missed the tolerances (largest error \
                 estimate {:.3}; 1 is the tolerance)",
                b.steps_per_period,
                b.periods_over_tolerance,
                summary.periods * summary.heads,
                b.max_error_estimate
            ));
        }
    }
}

pub fn run(a: Args) -> Result<(), CliError> {
    let scene = a.scene.load()?;
    let spec = drive_spec(&a, &scene)?;
    let mut opts = DriveOptions::from_spec(&spec);
    if a.flat_disk {
        opts.disk = DiskSpec::flat();
    }
    let opts = opts
        .with_tolerances_pm(
            a.atol_pm,
            a.atol_flight_pm,
            ["--atol-pm", "--atol-flight-pm"],
        )
        // Both are positive numbers by now: what is left is a flag that does not fit the other.
        .map_err(|e| CliError::Usage(e.to_string()))?;
    let mut opts = match a.steps_per_period {
        Some(n) => opts.bounded(n as usize),
        None => opts,
    };
    if let Some(s) = &a.scheme {
        opts.scheme = s.parse().map_err(|e| match e {
            // Named as the flag is written.
            hdi_tribology::Error::InvalidInput { reason, .. } => {
                CliError::Usage(hdi_tribology::Error::invalid("--scheme", reason).to_string())
            }
            e => CliError::Usage(e.to_string()),
        })?;
    }
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
    let zone = spec_zone(&scene, &spec)?;
    let heads = spec.heads as usize;
    let plant = MultiPlant::uniform(&scene, &zone, heads, a.seed, opts)?;
    // One line per period and head, and the header.
    let progress = common::Progress::bar("drive", (periods * heads) as u64 + 1, "lines");
    match out {
        Some(out) => {
            let mut summary = None;
            out.write_with(|w| {
                let w = CountLines {
                    inner: w,
                    progress: &progress,
                };
                summary = Some(replay_heads(&plant, &rows, dt, w)?);
                Ok(())
            })?;
            drop(progress);
            if let Some(s) = &summary {
                warn_bounded(s);
            }
            common::print_json(&summary)
        }
        None => {
            // Whole or nothing on standard output too: the run finishes before anything is printed.
            let mut buf = Vec::new();
            let w = CountLines {
                inner: &mut buf,
                progress: &progress,
            };
            let summary = replay_heads(&plant, &rows, dt, w)?;
            drop(progress);
            warn_bounded(&summary);
            common::write_stdout(&buf)
        }
    }
}
