//! `hdi calibrate`: touchdown calibration as drive firmware does it.

use hdi_tribology::analysis::sweep::Flag;
use hdi_tribology::calibration::CalibrationRecord;
use hdi_tribology::calibration::{
    calibrate, CalibrationOptions, ContactForceRms, MeanContactForce, Relative, TouchdownDetector,
    VibrationRms, MAX_LEVELS,
};
use hdi_tribology::model::Voltage;
use hdi_tribology::units::fmt_short;

use crate::common::{self, non_negative, positive, volts, CliError, SceneArgs};

/// Heater steps of --step-mw from --start-mw up to --max-mw until the detector fires, then back
/// down to take-off; the heater is then set --margin-mw below touchdown. JSON, each key with its
/// unit: scene, detector (as given), detector_name, touchdown_power_w, takeoff_power_w,
/// hysteresis_w, set_power_w, clearance_m (static model at the set power without dither),
/// contrast (detector level at touchdown over the level before), steps (every level), levels,
/// simulated_time_s, stats, wall_seconds, status (complete or incomplete) and flags:
/// no_takeoff; takeoff_without_dither when a high-pass detector (ae, vibration) ran without a
/// dither, whose take-off is then only the first step down (docs/clearance.md). A detector that
/// fires at the start power already is an error: there is no touchdown to find.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    scene: SceneArgs,
    /// First heater power (mW) [default: the power whose protrusion leaves 5 nm of the nominal
    /// clearance].
    #[arg(long, value_name = "MW", value_parser = non_negative, allow_hyphen_values = true)]
    start_mw: Option<f64>,
    /// Heater step (mW).
    #[arg(long, value_name = "MW", default_value = "0.5", value_parser = positive,
          allow_hyphen_values = true)]
    step_mw: f64,
    /// Highest heater power (mW) [default: --start-mw + 60].
    #[arg(long, value_name = "MW", value_parser = non_negative, allow_hyphen_values = true)]
    max_mw: Option<f64>,
    /// Back-off from touchdown to the set power (mW).
    #[arg(long, value_name = "MW", default_value = "15", value_parser = non_negative,
          allow_hyphen_values = true)]
    margin_mw: f64,
    /// Touchdown detector: mean contact force over the scene's window and threshold; `ae`,
    /// high-passed contact-force RMS above 10 uN (5 kHz corner, 50 us RMS, an acoustic-emission
    /// proxy); `vibration`, high-passed displacement RMS above 0.02 nm and 3x its level at the
    /// start.
    #[arg(long, value_enum, default_value = "mean")]
    detector: DetectorKind,
    /// AC dither amplitude (V) at the scene's frequency while calibrating [default: the scene's
    /// voltage.ac_amplitude_v].
    #[arg(long, value_name = "V", value_parser = volts, allow_hyphen_values = true)]
    dither_v: Option<f64>,
    /// Stop at touchdown: do not step back down to take-off.
    #[arg(long)]
    no_takeoff: bool,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum DetectorKind {
    Mean,
    Ae,
    Vibration,
}

impl DetectorKind {
    /// The name as given on the command line.
    fn name(self) -> &'static str {
        match self {
            DetectorKind::Mean => "mean",
            DetectorKind::Ae => "ae",
            DetectorKind::Vibration => "vibration",
        }
    }
}

pub fn run(a: Args) -> Result<(), CliError> {
    let scene = a.scene.load()?;
    let mut model = common::model(&scene)?;
    let start_mw = a
        .start_mw
        .unwrap_or_else(|| 1e3 * model.power_for(model.nominal_clearance() - 5e-9).max(0.0));
    let start_shown = match a.start_mw {
        Some(_) => format!("--start-mw {}", fmt_short(start_mw)),
        None => format!("the default --start-mw {}", fmt_short(start_mw)),
    };
    let max_mw = a.max_mw.unwrap_or(start_mw + 60.0);
    if max_mw < start_mw {
        return Err(CliError::Usage(format!(
            "--max-mw {} lies below {start_shown}",
            fmt_short(max_mw)
        )));
    }
    let levels = (max_mw - start_mw) / a.step_mw;
    if levels > MAX_LEVELS as f64 {
        return Err(CliError::Usage(format!(
            "--max-mw {} with --step-mw {} from {start_shown} makes {} heater levels, more than \
             {MAX_LEVELS}: raise --step-mw or lower --max-mw",
            fmt_short(max_mw),
            fmt_short(a.step_mw),
            fmt_short(levels.floor()),
        )));
    }
    let mut opts = CalibrationOptions::from_mw(start_mw, a.step_mw, max_mw, a.margin_mw);
    opts.find_takeoff = !a.no_takeoff;
    if let Some(v) = a.dither_v {
        model = model.with_voltage(Voltage {
            ac_amplitude: v,
            ..model.voltage()
        });
    }
    let (th, window) = (scene.detector.contact_threshold_n, scene.detector.window_s);
    let mut detector: Box<dyn TouchdownDetector> = match a.detector {
        DetectorKind::Mean => Box::new(MeanContactForce::new(th, window)?),
        DetectorKind::Ae => Box::new(ContactForceRms::new(1e-5, 5e3, 5e-5)?),
        DetectorKind::Vibration => Box::new(Relative::new(
            VibrationRms::new(2e-11, 5e3, 5e-5)?,
            3.0,
            1e-4,
            2e-4,
        )?),
    };
    let clock = std::time::Instant::now();
    let progress = common::Progress::spinner("calibrate: heater staircase");
    let c = calibrate(&model, detector.as_mut(), &opts).map_err(|e| {
        CliError::Failed(match e {
            hdi_tribology::Error::InvalidInput { ref field, .. } if field == "margin" => {
                format!("--margin-mw {}: {e}", fmt_short(a.margin_mw))
            }
            _ => {
                let dither = a
                    .dither_v
                    .map_or_else(String::new, |v| format!(", --dither-v {}", fmt_short(v)));
                format!(
                    "{e} ({start_shown}, --step-mw {}{dither})",
                    fmt_short(a.step_mw)
                )
            }
        })
    })?;
    drop(progress);
    let without_dither =
        c.takeoff_power.is_some() && detector.high_pass() && model.voltage().ac_amplitude == 0.0;
    if without_dither {
        common::warn(&format!(
            "the take-off {} is not a take-off: the {} detector hears only changes, and without \
             a dither it hears nothing in steady contact, so it stops firing at the first step \
             down (docs/clearance.md); give --dither-v or use --detector mean",
            common::mw(c.takeoff_power.unwrap_or(f64::NAN)),
            a.detector.name(),
        ));
    }
    let mut record = CalibrationRecord::new(
        &scene.name,
        a.detector.name(),
        c,
        opts.find_takeoff,
        clock.elapsed().as_secs_f64(),
    );
    if without_dither {
        record = record.flagged(Flag::TakeoffWithoutDither);
    }
    if opts.find_takeoff && record.calibration.takeoff_power.is_none() {
        common::warn(&format!(
            "no take-off found down to {start_shown}: no hysteresis"
        ));
    }
    common::print_json(&record)
}
