//! `hdi static`: the static analyses at the scene's DC voltage.

use hdi_tribology::analysis::record::StaticRecord;
use hdi_tribology::analysis::{
    pull_in_voltage, s_curve, static_hysteresis, Fold, PullIn, ScanGrid, StaticOptions,
};
use hdi_tribology::model::SliderModel;
use serde::Serialize;

use crate::common::{self, CliError, SceneArgs};

/// Static analyses at the scene's DC voltage, JSON, each key with its unit: scene, touchdown and
/// takeoff ({power_w, at: the equilibrium there, cause}), hysteresis_w, pull_in (at zero heater
/// power: {voltage_v, d_m, cause}; null without voltage terms), folds [{power_w, d_m,
/// jump_in}], and status: "converged" (each value is a root found to the solver's tolerance; a
/// root that is not found is an error) with flags ["negative_hysteresis"] when take-off lies
/// above touchdown.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    scene: SceneArgs,
}

#[derive(Serialize)]
struct Report {
    #[serde(flatten)]
    record: StaticRecord,
    pull_in: Option<PullIn>,
    folds: Vec<Fold>,
}

pub fn run(a: Args) -> Result<(), CliError> {
    let scene = a.scene.load()?;
    let model = SliderModel::from_scene(&scene)?;
    let opts = StaticOptions::new(scene.detector.contact_threshold_n);
    let h = static_hysteresis(&model, &opts)?;
    let pull_in = if model.forces().has_voltage_terms() {
        Some(pull_in_voltage(&model, 0.0, &opts)?)
    } else {
        None
    };
    let curve = s_curve(&model, None, &ScanGrid::default())?;
    let record = StaticRecord::new(&scene.name, h);
    if !record.flags.is_empty() {
        common::warn(&format!(
            "negative static hysteresis {}: take-off lies above touchdown",
            common::mw(h.hysteresis)
        ));
    }
    common::print_json(&Report {
        record,
        pull_in,
        folds: curve.folds,
    })
}
