//! `hdi`: the command line of hdi-tribology.
//!
//! Subcommands share two helpers: loading a scene (a TOML/JSON file or `--paper`) and printing
//! JSON. Errors print one line `hdi: <message>` on stderr and exit with 2 (usage) or 1 (scene or
//! computation).

use std::io::Write;
use std::process::ExitCode;

use hdi_tribology::force::{Breakdown, Gaps};
use hdi_tribology::scene::Scene;
use serde::Serialize;

const USAGE: &str = "usage: hdi <command> [options]

commands:
  forces (SCENE_FILE | --paper) --gaps D1,D2,...  [--protrusion-m DELTA]
      interface forces at bulge gaps D (m), JSON, one object per gap: d, intermolecular,
      contact, electrostatic_per_volt2, electrostatic (at the scene's DC voltage minus the
      contact potential), other, real_contact_area, total (SI, positive = away from the disk).
      Pad-gap terms see D + DELTA (default DELTA = 0).
  help
      this text";

/// Why the program stops.
enum CliError {
    /// Bad command line: exit code 2.
    Usage(String),
    /// Bad scene or failed computation: exit code 1.
    Failed(String),
}

impl From<hdi_tribology::Error> for CliError {
    fn from(e: hdi_tribology::Error) -> Self {
        CliError::Failed(e.to_string())
    }
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(CliError::Usage(msg)) => {
            eprintln!("hdi: {msg} (try `hdi help`)");
            ExitCode::from(2)
        }
        Err(CliError::Failed(msg)) => {
            eprintln!("hdi: {}", msg.replace('\n', " "));
            ExitCode::from(1)
        }
    }
}

fn run(args: &[String]) -> Result<(), CliError> {
    let Some((command, rest)) = args.split_first() else {
        return Err(CliError::Usage("missing command".into()));
    };
    match command.as_str() {
        "forces" => forces(rest),
        "help" | "--help" | "-h" => {
            print_text(USAGE)?;
            Ok(())
        }
        other => Err(CliError::Usage(format!("unknown command `{other}`"))),
    }
}

/// Where the scene comes from.
enum SceneSource {
    Paper,
    File(String),
}

/// Options shared by the subcommands, plus those a subcommand accepts as `--name value`.
struct Parsed {
    scene: Option<SceneSource>,
    values: Vec<(String, String)>,
}

/// Splits `args` into the scene source (`--paper` or one positional file) and `--name value`
/// pairs whose names are in `accepted`.
fn parse_args(args: &[String], accepted: &[&str]) -> Result<Parsed, CliError> {
    let mut parsed = Parsed {
        scene: None,
        values: Vec::new(),
    };
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let source = if a == "--paper" {
            SceneSource::Paper
        } else if let Some(name) = a.strip_prefix("--") {
            let (name, value) = match name.split_once('=') {
                Some((n, v)) => (n.to_string(), v.to_string()),
                None => {
                    let v = it
                        .next()
                        .ok_or_else(|| CliError::Usage(format!("option --{name} needs a value")))?;
                    (name.to_string(), v.clone())
                }
            };
            if !accepted.contains(&name.as_str()) {
                return Err(CliError::Usage(format!("unknown option --{name}")));
            }
            if parsed.values.iter().any(|(n, _)| *n == name) {
                return Err(CliError::Usage(format!("option --{name} given twice")));
            }
            parsed.values.push((name, value));
            continue;
        } else {
            SceneSource::File(a.clone())
        };
        if parsed.scene.is_some() {
            return Err(CliError::Usage(
                "give exactly one scene: a file or --paper".into(),
            ));
        }
        parsed.scene = Some(source);
    }
    Ok(parsed)
}

impl Parsed {
    fn value(&self, name: &str) -> Option<&str> {
        self.values
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }

    fn load_scene(&self) -> Result<Scene, CliError> {
        match &self.scene {
            None => Err(CliError::Usage("missing scene: a file or --paper".into())),
            Some(SceneSource::Paper) => Ok(Scene::paper()),
            // parse errors already carry the file name; validation errors get it here
            Some(SceneSource::File(path)) => Scene::from_path(path).map_err(|e| match e {
                hdi_tribology::Error::InvalidInput { .. } => {
                    CliError::Failed(format!("{path}: {e}"))
                }
                other => CliError::from(other),
            }),
        }
    }
}

fn parse_number(option: &str, s: &str) -> Result<f64, CliError> {
    let x: f64 = s
        .trim()
        .parse()
        .map_err(|_| CliError::Usage(format!("--{option}: `{s}` is not a number")))?;
    if !x.is_finite() {
        return Err(CliError::Usage(format!("--{option}: `{s}` is not finite")));
    }
    Ok(x)
}

fn parse_list(option: &str, s: &str) -> Result<Vec<f64>, CliError> {
    let v = s
        .split(',')
        .filter(|p| !p.trim().is_empty())
        .map(|p| parse_number(option, p))
        .collect::<Result<Vec<_>, _>>()?;
    if v.is_empty() {
        return Err(CliError::Usage(format!("--{option}: empty list")));
    }
    Ok(v)
}

fn print_text(text: &str) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    writeln!(out, "{text}").map_err(|e| CliError::Failed(format!("cannot write output: {e}")))
}

fn print_json<T: Serialize>(value: &T) -> Result<(), CliError> {
    let text = serde_json::to_string_pretty(value)
        .map_err(|e| CliError::Failed(format!("cannot write JSON: {e}")))?;
    print_text(&text)
}

#[derive(Serialize)]
struct ForcesRow {
    d: f64,
    #[serde(flatten)]
    forces: Breakdown,
}

fn forces(args: &[String]) -> Result<(), CliError> {
    let parsed = parse_args(args, &["gaps", "protrusion-m"])?;
    let gaps = parse_list(
        "gaps",
        parsed
            .value("gaps")
            .ok_or_else(|| CliError::Usage("forces needs --gaps D1,D2,...".into()))?,
    )?;
    let protrusion = match parsed.value("protrusion-m") {
        Some(s) => parse_number("protrusion-m", s)?,
        None => 0.0,
    };
    let scene = parsed.load_scene()?;
    let interface = scene.build_interface()?;
    let volt2 = scene.dc_volt2();
    let rows: Vec<ForcesRow> = gaps
        .iter()
        .map(|&d| ForcesRow {
            d,
            forces: interface.breakdown(
                Gaps {
                    bulge: d,
                    pad: d + protrusion,
                },
                volt2,
            ),
        })
        .collect();
    if let Some(bad) = rows.iter().find(|r| !r.forces.total.is_finite()) {
        return Err(CliError::Failed(format!(
            "forces at d = {} m are not finite",
            bad.d
        )));
    }
    print_json(&rows)
}
