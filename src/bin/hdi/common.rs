//! What the subcommands share: the scene source, number parsers, output files, JSON.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use hdi_tribology::scene::Scene;
use hdi_tribology::units::{fmt_short, to_mw, to_nm};
use serde::Serialize;

/// Why the program stops.
pub enum CliError {
    /// Bad command line found after parsing (e.g. two options that do not fit): exit code 2.
    Usage(String),
    /// Bad scene or failed computation: exit code 1.
    Failed(String),
}

impl From<hdi_tribology::Error> for CliError {
    fn from(e: hdi_tribology::Error) -> Self {
        CliError::Failed(e.to_string())
    }
}

/// The scene: a file, `-` for standard input, or the built-in paper scene.
#[derive(clap::Args)]
#[group(required = true, multiple = false)]
pub struct SceneArgs {
    /// Scene file (.toml or .json); `-` reads the scene from standard input (JSON if it starts
    /// with `{`, else TOML).
    #[arg(value_name = "SCENE")]
    scene: Option<PathBuf>,
    /// Use the built-in paper scene instead of a file.
    #[arg(long)]
    paper: bool,
}

impl SceneArgs {
    /// The scene, validated; errors name the file (or standard input) and the field.
    pub fn load(&self) -> Result<Scene, CliError> {
        let path = match (&self.scene, self.paper) {
            (_, true) => return Ok(Scene::paper()),
            (Some(p), false) => p,
            (None, false) => return Err(CliError::Usage("give a scene file or --paper".into())),
        };
        if path.as_os_str() == "-" {
            let mut text = String::new();
            std::io::stdin()
                .read_to_string(&mut text)
                .map_err(|e| CliError::Failed(format!("standard input: {e}")))?;
            let scene = if text.trim_start().starts_with('{') {
                Scene::from_json_str(&text)
            } else {
                Scene::from_toml_str(&text)
            };
            return scene.map_err(|e| {
                CliError::Failed(match e {
                    hdi_tribology::Error::Scene { reason, .. } => {
                        format!("scene on standard input: {reason}")
                    }
                    other => format!("scene on standard input: {other}"),
                })
            });
        }
        let name = path.display();
        // parse errors already carry the file name; validation errors get it here
        Scene::from_path(path).map_err(|e| match e {
            hdi_tribology::Error::InvalidInput { .. } => CliError::Failed(format!("{name}: {e}")),
            other => CliError::from(other),
        })
    }
}

/// A finite number.
pub fn number(s: &str) -> Result<f64, String> {
    let x: f64 = s.trim().parse().map_err(|_| "not a number".to_string())?;
    if x.is_finite() {
        Ok(x)
    } else {
        Err("must be finite".into())
    }
}

/// A finite number > 0.
pub fn positive(s: &str) -> Result<f64, String> {
    let x = number(s)?;
    if x > 0.0 {
        Ok(x)
    } else {
        Err("must be > 0".into())
    }
}

/// A finite number ≥ 0.
pub fn non_negative(s: &str) -> Result<f64, String> {
    let x = number(s)?;
    if x >= 0.0 {
        Ok(x)
    } else {
        Err("must be >= 0".into())
    }
}

/// A number in (0, 1).
pub fn fraction(s: &str) -> Result<f64, String> {
    let x = number(s)?;
    if x > 0.0 && x < 1.0 {
        Ok(x)
    } else {
        Err("must lie strictly between 0 and 1".into())
    }
}

/// A comma-separated list of finite numbers, no entry empty.
#[derive(Clone, Debug)]
pub struct List(pub Vec<f64>);

/// Parses a [`List`]; the error names the entry (1-based) that is wrong.
pub fn list(s: &str) -> Result<List, String> {
    s.split(',')
        .enumerate()
        .map(|(i, p)| {
            if p.trim().is_empty() {
                Err(format!("entry {} is empty", i + 1))
            } else {
                number(p).map_err(|e| format!("entry {} `{}`: {e}", i + 1, p.trim()))
            }
        })
        .collect::<Result<Vec<_>, _>>()
        .map(List)
}

/// A comma-separated list of finite numbers ≥ 0.
pub fn list_non_negative(s: &str) -> Result<List, String> {
    let l = list(s)?;
    match l.0.iter().position(|&x| x < 0.0) {
        Some(i) => Err(format!("entry {} is negative: must be >= 0", i + 1)),
        None => Ok(l),
    }
}

/// An output file, checked before any computation and written whole or not at all: the data
/// goes to a temporary file of a unique name in the same directory (keeping the extension), which
/// is renamed to the final name only once complete, and removed on any failure.
pub struct Output {
    path: PathBuf,
    option: &'static str,
    tmp: tempfile::NamedTempFile,
}

impl Output {
    /// Checks that `path` (given as `option`) can be written: not a directory, its directory
    /// exists and takes a new file.
    pub fn prepare(path: &Path, option: &'static str) -> Result<Self, CliError> {
        let shown = path.display();
        if path.is_dir() {
            return Err(CliError::Failed(format!(
                "{option} {shown}: is a directory, give a file name"
            )));
        }
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        if !dir.is_dir() {
            return Err(CliError::Failed(format!(
                "{option} {shown}: the directory {} does not exist",
                dir.display()
            )));
        }
        let stem = path
            .file_stem()
            .map_or_else(|| "out".into(), |s| s.to_string_lossy());
        let suffix = path
            .extension()
            .map_or_else(String::new, |e| format!(".{}", e.to_string_lossy()));
        let tmp = tempfile::Builder::new()
            .prefix(&format!(".{stem}."))
            .suffix(&suffix)
            .tempfile_in(dir)
            .map_err(|e| CliError::Failed(format!("{option} {shown}: cannot write there: {e}")))?;
        Ok(Output {
            path: path.to_path_buf(),
            option,
            tmp,
        })
    }

    /// The temporary file to write to.
    pub fn tmp_path(&self) -> &Path {
        self.tmp.path()
    }

    /// Renames the complete temporary file to the final name.
    pub fn commit(self) -> Result<(), CliError> {
        let (option, path) = (self.option, self.path);
        self.tmp.persist(&path).map(|_| ()).map_err(|e| {
            CliError::Failed(format!(
                "{option} {}: cannot write: {}",
                path.display(),
                e.error
            ))
        })
    }
}

/// Prints `text` and a newline on standard output.
pub fn print_text(text: &str) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    writeln!(out, "{text}").map_err(|e| CliError::Failed(format!("cannot write output: {e}")))
}

/// Prints `value` as pretty JSON on standard output.
pub fn print_json<T: Serialize>(value: &T) -> Result<(), CliError> {
    let text = serde_json::to_string_pretty(value)
        .map_err(|e| CliError::Failed(format!("cannot write JSON: {e}")))?;
    print_text(&text)
}

/// A warning on standard error, one line (the result itself goes to standard output).
pub fn warn(msg: &str) {
    eprintln!("hdi: warning: {msg}");
}

/// A length in nanometres for messages.
pub fn nm(x: f64) -> String {
    format!("{} nm", fmt_short(to_nm(x)))
}

/// A power in milliwatts for messages.
pub fn mw(x: f64) -> String {
    format!("{} mW", fmt_short(to_mw(x)))
}
