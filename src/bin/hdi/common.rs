//! What the subcommands share: the scene source, number parsers, output files, JSON.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use hdi_tribology::cache::{CacheReport, TableCache};
use hdi_tribology::force::InterfaceForces;
use hdi_tribology::model::SliderModel;
use hdi_tribology::scene::Scene;
use hdi_tribology::units::{fmt_short, to_mw, to_nm};
use serde::Serialize;

/// Why the program stops.
pub enum CliError {
    /// Bad command line found after parsing (e.g. two options that do not fit): exit code 2.
    Usage(String),
    /// Bad scene or failed computation: exit code 1.
    Failed(String),
    /// Standard output's reader has gone (`hdi ... | head -1`): the program ends quietly,
    /// exit code 0, as the reader asked for no more.
    ClosedPipe,
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

/// A relative tolerance of the ODE solver, in [`MIN_RTOL`](hdi_tribology::ode::MIN_RTOL), 1):
/// the range scenes and the solver take.
pub fn rtol(s: &str) -> Result<f64, String> {
    let x = number(s)?;
    let min = hdi_tribology::ode::MIN_RTOL;
    if (min..1.0).contains(&x) {
        Ok(x)
    } else {
        Err(format!("must lie in [{min:.1e}, 1) (100 ε up to 1)"))
    }
}

/// A voltage amplitude (V), at least 0 and at most the scenes' bound
/// [`MAX_VOLTAGE_V`](hdi_tribology::scene::MAX_VOLTAGE_V).
pub fn volts(s: &str) -> Result<f64, String> {
    let x = non_negative(s)?;
    check_volts(x)?;
    Ok(x)
}

fn check_volts(x: f64) -> Result<(), String> {
    let max = hdi_tribology::scene::MAX_VOLTAGE_V;
    if x <= max {
        Ok(())
    } else {
        Err(format!(
            "must be at most {} V, as in a scene",
            fmt_short(max)
        ))
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

/// A comma-separated list of voltage amplitudes (V), each as [`volts`].
pub fn list_volts(s: &str) -> Result<List, String> {
    let l = list(s)?;
    if let Some(i) = l.0.iter().position(|&x| x < 0.0) {
        return Err(format!("entry {} is negative: must be >= 0", i + 1));
    }
    for (i, &x) in l.0.iter().enumerate() {
        check_volts(x).map_err(|e| format!("entry {}: {e}", i + 1))?;
    }
    Ok(l)
}

/// An output file, checked before any computation and written whole or not at all.
///
/// The one writer of every file the CLI writes. What it does depends on what the path names
/// (docs/cli.md, "Output files"):
/// - a regular file, or a name not yet taken: the data goes to a temporary file of a unique
///   name in the same directory, renamed onto the final name only once complete (removed on any
///   failure). A new file gets mode 0666 minus the umask (0644 under the usual umask 022), as a
///   shell redirection gives it; a file that exists keeps its permissions.
/// - a symbolic link: followed to its target, which is written as above; the link stays a link.
///   A dangling link creates its target.
/// - a character device or a FIFO (`/dev/null`, `/dev/stdout`, a named pipe, `>(gzip > x)`):
///   written to directly, as a shell redirection would, once the whole output is ready. It is
///   never replaced by a file.
/// - anything else (a directory, a block device, a socket): refused before any computation.
pub struct Output {
    /// `--csv out.csv`: the option and the path as the user gave them, for messages.
    shown: String,
    target: Target,
}

enum Target {
    /// A regular file (possibly behind links), written through a temporary file beside it.
    File {
        /// The final name, links resolved.
        path: PathBuf,
        tmp: tempfile::NamedTempFile,
        /// The permissions of the file being replaced, kept.
        keep: Option<std::fs::Permissions>,
    },
    /// A character device or FIFO, opened and written at the end.
    Stream(PathBuf),
}

/// Most links followed before giving up (the kernel's own limit is 40).
const MAX_LINKS: usize = 40;

/// What a path names, links followed: its final name and the kind of object there (None: no
/// object yet).
fn resolve(path: &Path, shown: &str) -> Result<(PathBuf, Option<std::fs::FileType>), CliError> {
    let mut p = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        let meta = match std::fs::symlink_metadata(&p) {
            Ok(m) => m,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok((p, None)),
            Err(e) => return Err(CliError::Failed(format!("{shown}: {e}"))),
        };
        if !meta.file_type().is_symlink() {
            return Ok((p, Some(meta.file_type())));
        }
        let link = std::fs::read_link(&p).map_err(|e| CliError::Failed(format!("{shown}: {e}")))?;
        p = match p.parent() {
            Some(dir) => dir.join(link),
            None => link,
        };
    }
    Err(CliError::Failed(format!(
        "{shown}: more than {MAX_LINKS} symbolic links in a row (a loop?)"
    )))
}

/// A device or FIFO that is written to directly.
#[cfg(unix)]
fn is_stream(t: std::fs::FileType) -> bool {
    use std::os::unix::fs::FileTypeExt;
    t.is_char_device() || t.is_fifo()
}

#[cfg(not(unix))]
fn is_stream(_t: std::fs::FileType) -> bool {
    false
}

/// The kind of a file that is neither regular nor a stream, for the refusal.
fn kind(t: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() {
        "a directory, give a file name"
    } else {
        "not a regular file"
    }
}

impl Output {
    /// Checks that `path` (given as `option`) can be written, before anything is computed: a
    /// regular file that can be written (or a new name in an existing directory that takes
    /// one), a link to such, or a character device or FIFO.
    pub fn prepare(path: &Path, option: &'static str) -> Result<Self, CliError> {
        let shown = format!("{option} {}", path.display());
        // Links are followed by the kernel here, magic ones (/dev/stdout) included.
        if let Ok(meta) = std::fs::metadata(path) {
            if is_stream(meta.file_type()) {
                return Ok(Output {
                    shown,
                    target: Target::Stream(path.to_path_buf()),
                });
            }
        }
        let (real, found) = resolve(path, &shown)?;
        let keep = match found {
            Some(t) if t.is_file() => {
                // Opened, not truncated: a file the user cannot write is refused now, as a
                // shell redirection would refuse it.
                std::fs::OpenOptions::new()
                    .write(true)
                    .open(&real)
                    .map_err(|e| CliError::Failed(format!("{shown}: cannot write it: {e}")))?;
                Some(
                    std::fs::metadata(&real)
                        .map_err(|e| CliError::Failed(format!("{shown}: {e}")))?
                        .permissions(),
                )
            }
            Some(t) => return Err(CliError::Failed(format!("{shown}: is {}", kind(t)))),
            None => None,
        };
        let dir = match real.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        if !dir.is_dir() {
            return Err(CliError::Failed(format!(
                "{shown}: the directory {} does not exist",
                dir.display()
            )));
        }
        let stem = real
            .file_stem()
            .map_or_else(|| "out".into(), |s| s.to_string_lossy());
        let suffix = real
            .extension()
            .map_or_else(String::new, |e| format!(".{}", e.to_string_lossy()));
        let prefix = format!(".{stem}.");
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(&suffix);
        #[cfg(unix)]
        {
            // 0666 minus the umask, as for any new file (tempfile's own default is 0600).
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
        let tmp = builder
            .tempfile_in(dir)
            .map_err(|e| CliError::Failed(format!("{shown}: cannot write there: {e}")))?;
        Ok(Output {
            shown,
            target: Target::File {
                path: real,
                tmp,
                keep,
            },
        })
    }

    /// Writes `bytes` as the whole content.
    pub fn write(self, bytes: &[u8]) -> Result<(), CliError> {
        self.write_with(|w| {
            w.write_all(bytes)
                .map_err(|e| CliError::Failed(e.to_string()))
        })
    }

    /// Writes what `fill` writes as the whole content: streamed into the temporary file for a
    /// regular file, gathered first for a device or FIFO (which sees all of it or nothing).
    pub fn write_with(
        self,
        fill: impl FnOnce(&mut dyn Write) -> Result<(), CliError>,
    ) -> Result<(), CliError> {
        let shown = self.shown;
        let failed = |e: std::io::Error| CliError::Failed(format!("{shown}: cannot write: {e}"));
        match self.target {
            Target::File {
                path,
                mut tmp,
                keep,
            } => {
                {
                    let mut w = std::io::BufWriter::new(tmp.as_file_mut());
                    fill(&mut w)?;
                    w.flush().map_err(failed)?;
                }
                if let Some(perm) = keep {
                    tmp.as_file().set_permissions(perm).map_err(failed)?;
                }
                // Checked again: the name must still hold a regular file or nothing.
                if let Ok(m) = std::fs::symlink_metadata(&path) {
                    if !m.file_type().is_file() {
                        return Err(CliError::Failed(format!(
                            "{shown}: is no longer a regular file, not replaced"
                        )));
                    }
                }
                tmp.persist(&path).map(|_| ()).map_err(|e| failed(e.error))
            }
            Target::Stream(path) => {
                let mut buf = Vec::new();
                fill(&mut buf)?;
                let mut f = std::fs::OpenOptions::new()
                    .write(true)
                    .open(&path)
                    .map_err(failed)?;
                f.write_all(&buf).and_then(|_| f.flush()).map_err(failed)
            }
        }
    }

    /// Delivers a file that a library function writes by path: written into a scratch
    /// directory, then written here whole.
    pub fn write_via_path(
        self,
        fill: impl FnOnce(&Path) -> Result<(), CliError>,
    ) -> Result<(), CliError> {
        let scratch = tempfile::tempdir()
            .map_err(|e| CliError::Failed(format!("{}: no scratch directory: {e}", self.shown)))?;
        let file = scratch.path().join("output");
        fill(&file)?;
        let bytes = std::fs::read(&file)
            .map_err(|e| CliError::Failed(format!("{}: cannot read back: {e}", self.shown)))?;
        self.write(&bytes)
    }
}

/// Writes `bytes` on standard output; a reader that has gone (`hdi ... | head -1`) ends the
/// program quietly.
pub fn write_stdout(bytes: &[u8]) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    match out.write_all(bytes).and_then(|_| out.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Err(CliError::ClosedPipe),
        r => r.map_err(|e| CliError::Failed(format!("cannot write output: {e}"))),
    }
}

/// Prints `text` and a newline on standard output.
pub fn print_text(text: &str) -> Result<(), CliError> {
    write_stdout(format!("{text}\n").as_bytes())
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

/// `--quiet`: no progress on the terminal.
static QUIET: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Sets `--quiet` for the whole run.
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, std::sync::atomic::Ordering::Relaxed);
}

/// `--no-cache`: no table cache for the whole run.
static NO_CACHE: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Sets `--no-cache` for the whole run.
pub fn set_no_cache(off: bool) {
    NO_CACHE.store(off, std::sync::atomic::Ordering::Relaxed);
}

/// The table cache of this run: none with `--no-cache` or `HDI_CACHE=off`, else the one of
/// [`TableCache::from_env`].
fn table_cache() -> Result<Option<TableCache>, CliError> {
    if NO_CACHE.load(std::sync::atomic::Ordering::Relaxed) {
        return Ok(None);
    }
    Ok(TableCache::from_env()?)
}

/// Warns about each notice of a cached build.
fn warn_cache(report: &CacheReport) {
    for n in &report.notices {
        warn(n);
    }
}

/// The model of `scene`, its tables through the run's table cache.
pub fn model(scene: &Scene) -> Result<SliderModel, CliError> {
    let (model, report) = SliderModel::from_scene_with_cache(scene, table_cache()?.as_ref())?;
    warn_cache(&report);
    Ok(model)
}

/// The interface forces of `scene`, their tables through the run's table cache.
pub fn interface(scene: &Scene) -> Result<InterfaceForces, CliError> {
    let Some(cache) = table_cache()? else {
        return Ok(scene.build_interface()?);
    };
    let (forces, report) = scene.build_interface_cached(&cache)?;
    warn_cache(&report);
    Ok(forces)
}

/// How long a run goes before its progress shows.
const PROGRESS_AFTER: std::time::Duration = std::time::Duration::from_secs(1);

/// Progress on standard error while a run lasts: shown only on a terminal, only once the run has
/// gone on for [`PROGRESS_AFTER`], never with `--quiet`; cleared when dropped. Results and
/// warnings are unaffected.
pub struct Progress {
    bar: indicatif::ProgressBar,
}

impl Progress {
    /// A spinner with the elapsed time and `what` (a run whose length is not known ahead).
    pub fn spinner(what: &str) -> Progress {
        let bar =
            indicatif::ProgressBar::with_draw_target(None, indicatif::ProgressDrawTarget::hidden());
        bar.set_style(
            indicatif::ProgressStyle::with_template("{spinner} {elapsed} {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
        );
        bar.set_message(what.to_string());
        Progress::start(bar)
    }

    /// A bar of `total` units named `unit` (e.g. periods), with `what` and the time left.
    pub fn bar(what: &str, total: u64, unit: &str) -> Progress {
        let bar = indicatif::ProgressBar::with_draw_target(
            Some(total),
            indicatif::ProgressDrawTarget::hidden(),
        );
        let template =
            format!("{{bar:30}} {{pos}}/{{len}} {unit}, {{elapsed}} (~{{eta}} left) {{msg}}");
        bar.set_style(
            indicatif::ProgressStyle::with_template(&template)
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        bar.set_message(what.to_string());
        Progress::start(bar)
    }

    /// Shows `bar` after [`PROGRESS_AFTER`] unless the run has ended, `--quiet` was given or
    /// standard error is not a terminal.
    fn start(bar: indicatif::ProgressBar) -> Progress {
        use std::io::IsTerminal;
        if !QUIET.load(std::sync::atomic::Ordering::Relaxed) && std::io::stderr().is_terminal() {
            let shown = bar.clone();
            std::thread::spawn(move || {
                std::thread::sleep(PROGRESS_AFTER);
                if !shown.is_finished() {
                    shown.set_draw_target(indicatif::ProgressDrawTarget::stderr());
                    shown.enable_steady_tick(std::time::Duration::from_millis(120));
                }
            });
        }
        Progress { bar }
    }

    /// Counts `n` more units done.
    pub fn inc(&self, n: u64) {
        self.bar.inc(n);
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}

/// A writer that counts the lines passing through it on a [`Progress`] bar.
pub struct CountLines<'a, W: Write> {
    /// Where the bytes go.
    pub inner: W,
    /// The bar that counts them.
    pub progress: &'a Progress,
}

impl<W: Write> Write for CountLines<'_, W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        let lines = buf[..n].iter().filter(|&&b| b == b'\n').count();
        self.progress.inc(lines as u64);
        Ok(n)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}
