//! Numbers the documentation quotes, generated from the code that computes them.
//!
//! A quoted number sits in a marked span of a Markdown file (`README.md`, `docs/*.md`):
//!
//! ```text
//! touchdown at <!-- num:paper.static.touchdown_mw -->74.324<!-- /num --> mW
//! ```
//!
//! The span's text is what the reader sees (the comments are hidden); its key names the number
//! that a source (an example's run, or a computation cheap enough for a test) produces as a
//! [`Quoted`]. [`check`] compares every span whose key a source produced with the value, within
//! the number's tolerance: by default one unit of the last digit the span prints (so a value on a
//! rounding boundary may print either way), or the wider one the number states
//! ([`Quoted::within`]). [`write`] puts the freshly formatted values into the spans.
//! `cargo run --release --example docs_numbers -- --write` regenerates every number;
//! `-- --check` reports each one that drifted (docs/architecture.md, "Numbers in the docs").

use std::path::{Path, PathBuf};

/// The opening of a marked span, before its key.
const OPEN: &str = "<!-- num:";
/// The end of the opening comment.
const OPEN_END: &str = " -->";
/// The closing comment of a span.
const CLOSE: &str = "<!-- /num -->";

/// One number the docs quote: its key and its value. A span chooses how many decimals it
/// shows; [`write`] keeps them.
#[derive(Clone, Debug, PartialEq)]
pub struct Quoted {
    /// The key of its spans (`source.what`: lower case, digits, dots and underscores).
    pub key: String,
    /// The value, in the unit the docs quote it in.
    pub value: f64,
    /// Quoted as a power of ten with no decimals (`1e-8`), as tolerances are.
    pub power_of_ten: bool,
    /// The largest difference accepted between a quoted value and `value`: `None` for one
    /// unit of the last digit the quote prints, `Some(0.0)` for the exact text.
    pub tol: Option<f64>,
}

impl Quoted {
    /// A number quoted in decimals.
    pub fn new(key: &str, value: f64) -> Self {
        Quoted {
            key: key.to_string(),
            value,
            power_of_ten: false,
            tol: None,
        }
    }

    /// A tolerance quoted as a power of ten (`1e-8`): the text must match exactly.
    pub fn power_of_ten(key: &str, value: f64) -> Self {
        Quoted {
            power_of_ten: true,
            tol: Some(0.0),
            ..Self::new(key, value)
        }
    }

    /// A count: the text must match exactly.
    pub fn count(key: &str, value: usize) -> Self {
        Quoted {
            tol: Some(0.0),
            ..Self::new(key, value as f64)
        }
    }

    /// With a stated tolerance instead of one unit of the last printed digit.
    pub fn within(mut self, tol: f64) -> Self {
        self.tol = Some(tol);
        self
    }

    /// The value as a span that now reads `existing` should read: as many decimals as it
    /// shows (3 when it is not a number), a leading minus as U+2212.
    pub fn text_like(&self, existing: &str) -> String {
        let t = if self.power_of_ten {
            format!("{:.0e}", self.value)
        } else {
            let decimals = match parse(existing) {
                Some(_) => existing.trim().split_once('.').map_or(0, |(_, f)| {
                    f.chars().take_while(char::is_ascii_digit).count()
                }),
                None => 3,
            };
            format!("{:.*}", decimals, self.value)
        };
        // A leading minus is a minus sign; an exponent's stays a hyphen (`1e-8`).
        match t.strip_prefix('-') {
            Some(rest) => format!("\u{2212}{rest}"),
            None => t,
        }
    }

    /// Why `quoted` (a span's text) does not quote this number, if it does not.
    pub fn disagrees(&self, quoted: &str) -> Option<String> {
        let Some(q) = parse(quoted) else {
            return Some(format!("{quoted:?} is not a number"));
        };
        let fresh = self.text_like(quoted);
        let (ok, tol) = if self.tol == Some(0.0) {
            (quoted.trim() == fresh, "exact".to_string())
        } else {
            let t = self.tol.unwrap_or_else(|| last_digit_unit(quoted));
            ((q - self.value).abs() <= t * (1.0 + 1e-9), format!("{t:e}"))
        };
        (!ok).then(|| format!("quotes {quoted}, the code gives {fresh} (tolerance {tol})"))
    }
}

/// A quoted number as Rust reads it: U+2212 as a minus sign.
fn parse(text: &str) -> Option<f64> {
    text.trim().replace('\u{2212}', "-").parse().ok()
}

/// One unit of the last digit of a decimal number as written (`74.324` → 0.001, `1e-8` →
/// 1e-8, `12` → 1).
pub fn last_digit_unit(text: &str) -> f64 {
    let t = text.trim().replace('\u{2212}', "-");
    let (mantissa, exp) = match t.split_once(['e', 'E']) {
        Some((m, e)) => (m.to_string(), e.parse::<i32>().unwrap_or(0)),
        None => (t.clone(), 0),
    };
    let decimals = mantissa.split_once('.').map_or(0, |(_, f)| f.len()) as i32;
    10f64.powi(exp - decimals)
}

/// One marked span of a document.
#[derive(Clone, Debug, PartialEq)]
pub struct Span {
    /// The file, relative to the repository's root.
    pub file: PathBuf,
    /// Its line (1-based).
    pub line: usize,
    /// The key.
    pub key: String,
    /// The quoted text between the comments.
    pub text: String,
    /// Byte range of `text` in the file.
    range: std::ops::Range<usize>,
}

/// The documents that may quote numbers: `README.md` and `docs/*.md` below `root`.
pub fn documents(root: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut files = vec![PathBuf::from("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .filter_map(|p| p.strip_prefix(root).ok().map(Path::to_path_buf))
        .collect();
    docs.sort();
    files.extend(docs);
    Ok(files)
}

/// The marked spans of one document's text; an error names a span that is not closed or has
/// no key.
pub fn spans_of(file: &Path, text: &str) -> Result<Vec<Span>, String> {
    let mut out = Vec::new();
    let mut at = 0;
    while let Some(i) = text[at..].find(OPEN) {
        let start = at + i;
        let line = text[..start].matches('\n').count() + 1;
        let here = || format!("{}:{line}", file.display());
        let key_start = start + OPEN.len();
        let key_end = text[key_start..]
            .find(OPEN_END)
            .map(|j| key_start + j)
            .ok_or_else(|| format!("{}: a number's opening comment is not closed", here()))?;
        let key = text[key_start..key_end].trim();
        let valid = |c: char| c.is_ascii_lowercase() || c.is_ascii_digit() || "._".contains(c);
        if key.is_empty() || !key.chars().all(valid) {
            return Err(format!("{}: the key {key:?} is not a key", here()));
        }
        let body = key_end + OPEN_END.len();
        let end = text[body..]
            .find(CLOSE)
            .map(|j| body + j)
            .ok_or_else(|| format!("{}: the number {key} has no {CLOSE}", here()))?;
        if text[body..end].contains(OPEN) || text[body..end].contains('\n') {
            return Err(format!(
                "{}: the number {key} is not closed on its line",
                here()
            ));
        }
        out.push(Span {
            file: file.to_path_buf(),
            line,
            key: key.to_string(),
            text: text[body..end].to_string(),
            range: body..end,
        });
        at = end + CLOSE.len();
    }
    Ok(out)
}

/// Every marked span of the documents below `root`.
pub fn spans(root: &Path) -> Result<Vec<Span>, String> {
    let mut out = Vec::new();
    for file in documents(root).map_err(|e| e.to_string())? {
        let text = std::fs::read_to_string(root.join(&file))
            .map_err(|e| format!("{}: {e}", file.display()))?;
        out.extend(spans_of(&file, &text)?);
    }
    Ok(out)
}

/// What [`check`] found: the spans that disagree with their numbers, and the spans no number
/// of `numbers` has a key for.
#[derive(Clone, Debug, Default)]
pub struct Report {
    /// `file:line key: what is wrong`.
    pub drifted: Vec<String>,
    /// Spans whose key none of the numbers has.
    pub unchecked: Vec<Span>,
    /// How many spans agreed.
    pub agreed: usize,
}

/// Compares every span of the documents below `root` with the number of its key in `numbers`.
/// Spans of other keys are listed as unchecked (another source quotes them).
pub fn check(root: &Path, numbers: &[Quoted]) -> Result<Report, String> {
    let mut report = Report::default();
    for span in spans(root)? {
        match numbers.iter().find(|q| q.key == span.key) {
            Some(q) => match q.disagrees(&span.text) {
                Some(why) => report.drifted.push(format!(
                    "{}:{} {}: {why}",
                    span.file.display(),
                    span.line,
                    span.key
                )),
                None => report.agreed += 1,
            },
            None => report.unchecked.push(span),
        }
    }
    Ok(report)
}

/// Panics, listing every span that disagrees with its number in `numbers`; returns how many
/// spans agreed.
pub fn assert_quoted(root: &Path, numbers: &[Quoted]) -> usize {
    let report = check(root, numbers).unwrap_or_else(|e| panic!("{e}"));
    assert!(
        report.drifted.is_empty(),
        "numbers in the docs drifted from the code (`cargo run --release --example \
         docs_numbers -- --write` regenerates them; read the prose around each):\n{}",
        report.drifted.join("\n")
    );
    report.agreed
}

/// Writes the text of each number of `numbers` into every span of its key; returns the spans
/// whose text changed, as `file:line key: old -> new`. Files are rewritten whole (atomically)
/// and only when something changed.
pub fn write(root: &Path, numbers: &[Quoted]) -> Result<Vec<String>, String> {
    let mut changed = Vec::new();
    for file in documents(root).map_err(|e| e.to_string())? {
        let path = root.join(&file);
        let text =
            std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", file.display()))?;
        let mut out = String::with_capacity(text.len());
        let mut last = 0;
        for span in spans_of(&file, &text)? {
            let Some(q) = numbers.iter().find(|q| q.key == span.key) else {
                continue;
            };
            let fresh = q.text_like(&span.text);
            if fresh != span.text {
                changed.push(format!(
                    "{}:{} {}: {} -> {fresh}",
                    file.display(),
                    span.line,
                    span.key,
                    span.text,
                ));
            }
            out.push_str(&text[last..span.range.start]);
            out.push_str(&fresh);
            last = span.range.end;
        }
        out.push_str(&text[last..]);
        if out != text {
            hdi_tribology::report::write_file(&path, &out).map_err(|e| e.to_string())?;
        }
    }
    Ok(changed)
}

/// The repository's root (where `Cargo.toml` is).
pub fn repository_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}
