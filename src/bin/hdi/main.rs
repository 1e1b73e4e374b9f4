//! `hdi`: the command line of hdi-tribology.
//!
//! One file per subcommand; `common` holds what they share: the scene source (a TOML/JSON file,
//! `-` for standard input, or `--paper`), number parsers that name the option and its unit,
//! output files written whole or not at all, and printing JSON with each result's status.
//!
//! Exit codes: 0 success, 1 a bad scene or a failed computation (one line on stderr), 2 a bad
//! command line (clap's usage message).

mod bearing;
mod calibrate;
mod common;
mod cycle;
mod drive;
mod fit;
mod forces;
mod scene;
mod static_cmd;
mod sweep;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

use common::CliError;

/// Tribology of the head–disk interface: interface forces, static and dynamic touchdown and
/// take-off, AC sweeps and clearance calibration. Results are JSON on standard output.
#[derive(Parser)]
#[command(name = "hdi", version, propagate_version = true, max_term_width = 100)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// No progress on the terminal (shown for runs over a second when standard error is a
    /// terminal, never otherwise). Warnings and results are unaffected.
    #[arg(long, short, global = true)]
    quiet: bool,
    /// Build the force tables afresh, without reading or writing the table cache (as
    /// HDI_CACHE=off does). The cache lives in $HDI_CACHE_DIR, else
    /// $XDG_CACHE_HOME/hdi-tribology, else ~/.cache/hdi-tribology; results are the same either
    /// way.
    #[arg(long, global = true)]
    no_cache: bool,
}

#[derive(Subcommand)]
enum Command {
    /// Interface forces at given bulge gaps, by term (SI units, positive = away from the disk).
    Forces(forces::Args),
    /// Static touchdown and take-off powers, hysteresis, pull-in voltage and folds.
    Static(static_cmd::Args),
    /// One touchdown/take-off cycle, its tolerance refined until the result has converged.
    Cycle(cycle::Args),
    /// One cycle per AC amplitude, each refined until it has converged.
    Sweep(sweep::Args),
    /// Touchdown calibration as drive firmware does it: a heater staircase up to touchdown.
    Calibrate(calibrate::Args),
    /// Fit scene fields to measured curves (CSV), with errors and an identifiability report.
    Fit(fit::Args),
    /// The scene, validated, as TOML (or JSON): a starting point for scenes of your own.
    Scene(scene::Args),
    /// A command file (time, heater power, voltage) replayed through the simulated drive; the
    /// sensor CSV written.
    Drive(Box<drive::Args>),
    /// The air bearing of a slider's geometry: attitude, stiffness and damping as JSON, and the
    /// pressure map.
    Bearing(bearing::Args),
}

fn main() -> ExitCode {
    // clap prints help and --version on stdout with exit 0, usage errors on stderr with exit 2.
    let cli = Cli::parse();
    common::set_quiet(cli.quiet);
    common::set_no_cache(cli.no_cache);
    let result = match cli.command {
        Command::Forces(a) => forces::run(a),
        Command::Static(a) => static_cmd::run(a),
        Command::Cycle(a) => cycle::run(a),
        Command::Sweep(a) => sweep::run(a),
        Command::Calibrate(a) => calibrate::run(a),
        Command::Fit(a) => fit::run(a),
        Command::Scene(a) => scene::run(a),
        Command::Drive(a) => drive::run(*a),
        Command::Bearing(a) => bearing::run(a),
    };
    match result {
        Ok(()) | Err(CliError::ClosedPipe) => ExitCode::SUCCESS,
        Err(CliError::Usage(msg)) => {
            eprintln!("error: {msg}\n\nFor more information, try '--help'.");
            ExitCode::from(2)
        }
        Err(CliError::Failed(msg)) => {
            eprintln!("hdi: {}", msg.replace('\n', " "));
            ExitCode::from(1)
        }
    }
}
