//! `hdi sweep`: one cycle per AC amplitude.

use crate::common::{self, list_volts, CliError, List, SceneArgs};
use crate::cycle::CycleArgs;

/// One cycle per AC amplitude, JSON list of the objects `hdi cycle` prints (see `hdi cycle
/// --help`): each refined until converged unless --no-refine, each with its status and flags.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    scene: SceneArgs,
    /// AC amplitudes (V), comma-separated [default: the scene's sweep.ac_amplitudes_v].
    #[arg(long, value_name = "V1,V2,...", value_parser = list_volts,
          allow_hyphen_values = true)]
    v_ac: Option<List>,
    #[command(flatten)]
    cycle: CycleArgs,
}

pub fn run(a: Args) -> Result<(), CliError> {
    let scene = a.scene.load()?;
    let (model, programme, opts) = a.cycle.setup(&scene)?;
    let amplitudes = match a.v_ac {
        Some(List(v)) => v,
        None => scene.sweep.ac_amplitudes_v.clone(),
    };
    if amplitudes.is_empty() {
        return Err(CliError::Usage(
            "no amplitudes: give --v-ac or a sweep.ac_amplitudes_v list in the scene".into(),
        ));
    }
    let _progress = common::Progress::spinner(&format!(
        "sweep: {} amplitudes, each refined until converged",
        amplitudes.len()
    ));
    let rows: Vec<_> = a
        .cycle
        .run(&scene, &model, &programme, &opts, &amplitudes)?
        .into_iter()
        .map(|(r, _)| r)
        .collect();
    common::print_json(&rows)
}
