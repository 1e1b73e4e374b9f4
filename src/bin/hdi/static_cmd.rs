//! `hdi static`: the static analyses at the scene's DC voltage.

use hdi_tribology::analysis::record::StaticRecord;
use hdi_tribology::analysis::touchdown::TransitionError;
use hdi_tribology::analysis::{
    pull_in_voltage, s_curve, takeoff_power, touchdown_power, Fold, PullIn, ScanGrid, StaticOptions,
};
use serde::Serialize;

use crate::common::{self, CliError, SceneArgs};

/// Static analyses at the scene's DC voltage, JSON, each key with its unit: scene, touchdown and
/// takeoff ({power_w, at: the equilibrium there, cause}), hysteresis_w, pull_in (at zero heater
/// power: {voltage_v, d_m, cause}; null without voltage terms), folds [{power_w, d_m,
/// jump_in}], and status: "converged" (each value is a root found to the solver's tolerance; a
/// touchdown that is not found is an error) with flags: "no_takeoff" when the head stays in
/// contact down to zero heater power (takeoff and hysteresis_w null, the reason warned about on
/// stderr), "negative_hysteresis" when take-off lies above touchdown.
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
    let model = common::model(&scene)?;
    let opts = StaticOptions::new(scene.detector.contact_threshold_n);
    let progress = common::Progress::spinner("static: touchdown, take-off, pull-in, folds");
    let touchdown = touchdown_power(&model, &opts)?;
    let takeoff = match takeoff_power(&model, touchdown.power + opts.takeoff_start_excess, &opts) {
        Ok(t) => Some(t),
        Err(hdi_tribology::Error::Analysis(e))
            if matches!(
                e.downcast_ref(),
                Some(TransitionError::NoTakeOff { .. } | TransitionError::NoTakeOffInTable { .. })
            ) =>
        {
            common::warn(&format!("no take-off: {e}"));
            None
        }
        Err(e) => return Err(e.into()),
    };
    let pull_in = if model.forces().has_voltage_terms() {
        Some(pull_in_voltage(&model, 0.0, &opts)?)
    } else {
        None
    };
    let curve = s_curve(&model, None, &ScanGrid::default())?;
    drop(progress);
    let record = StaticRecord::of(&scene.name, touchdown, takeoff);
    if let Some(h) = record.hysteresis.filter(|&h| h < 0.0) {
        common::warn(&format!(
            "negative static hysteresis {}: take-off lies above touchdown",
            common::mw(h)
        ));
    }
    common::print_json(&Report {
        record,
        pull_in,
        folds: curve.folds,
    })
}
