//! `hdi static`: the static analyses at the scene's DC voltage.

use hdi_tribology::analysis::{
    pull_in_voltage, s_curve, takeoff_power, touchdown_power, ScanGrid, StaticOptions,
};
use hdi_tribology::error::AnalysisError;
use hdi_tribology::model::SliderModel;
use serde::Serialize;

use crate::common::{self, CliError, SceneArgs};

/// Static analyses at the scene's DC voltage, JSON: touchdown_power, takeoff_power, hysteresis
/// (W), pull_in_voltage (V, at zero heater power; null without voltage terms), folds
/// [{power, d}], and status: "converged" (each value is a root found to the solver's
/// tolerance; a touchdown that is not found is an error) with flags: "no_takeoff" when the head
/// stays in contact down to zero heater power (take-off and hysteresis null, the reason warned
/// about on stderr), "negative_hysteresis" when take-off lies above touchdown.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    scene: SceneArgs,
}

#[derive(Serialize)]
struct Fold {
    power: f64,
    d: f64,
}

#[derive(Serialize)]
struct Report {
    touchdown_power: f64,
    takeoff_power: Option<f64>,
    hysteresis: Option<f64>,
    pull_in_voltage: Option<f64>,
    folds: Vec<Fold>,
    status: &'static str,
    flags: Vec<&'static str>,
}

pub fn run(a: Args) -> Result<(), CliError> {
    let scene = a.scene.load()?;
    let model = SliderModel::from_scene(&scene)?;
    let opts = StaticOptions::new(scene.detector.contact_threshold_n);
    let progress = common::Progress::spinner("static: touchdown, take-off, pull-in, folds");
    let touchdown = touchdown_power(&model, &opts)?;
    let mut flags = Vec::new();
    let takeoff = match takeoff_power(&model, touchdown.power + opts.takeoff_start_excess, &opts) {
        Ok(t) => Some(t.power),
        Err(hdi_tribology::Error::Analysis(
            e @ (AnalysisError::NoTakeOff { .. } | AnalysisError::NoTakeOffInTable { .. }),
        )) => {
            flags.push("no_takeoff");
            common::warn(&format!("no take-off: {e}"));
            None
        }
        Err(e) => return Err(e.into()),
    };
    let hysteresis = takeoff.map(|t| touchdown.power - t);
    let pull_in_voltage = if model.forces().has_voltage_terms() {
        Some(pull_in_voltage(&model, 0.0, &opts)?.voltage)
    } else {
        None
    };
    let curve = s_curve(&model, None, &ScanGrid::default())?;
    drop(progress);
    if let Some(h) = hysteresis.filter(|&h| h < 0.0) {
        flags.push("negative_hysteresis");
        common::warn(&format!(
            "negative static hysteresis {}: take-off lies above touchdown",
            common::mw(h)
        ));
    }
    common::print_json(&Report {
        touchdown_power: touchdown.power,
        takeoff_power: takeoff,
        hysteresis,
        pull_in_voltage,
        folds: curve
            .folds
            .iter()
            .map(|f| Fold {
                power: f.power,
                d: f.d,
            })
            .collect(),
        status: "converged",
        flags,
    })
}
