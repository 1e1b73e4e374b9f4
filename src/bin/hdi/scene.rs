//! `hdi scene`: the scene, validated, as TOML or JSON.

use crate::common::{self, CliError, SceneArgs};

/// The scene as TOML (or JSON), validated, in SI units: a starting point for scenes of your own.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    scene: SceneArgs,
    /// Write JSON instead of TOML.
    #[arg(long)]
    json: bool,
}

pub fn run(a: Args) -> Result<(), CliError> {
    let scene = a.scene.load()?;
    scene.validate()?;
    let text = if a.json {
        scene.to_json_string()?
    } else {
        scene.to_toml_string()?
    };
    common::print_text(text.trim_end())
}
