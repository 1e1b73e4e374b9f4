//! Reading and writing scenes as TOML or JSON.

use std::path::Path;

use super::Scene;
use crate::{Error, Result};

/// Largest scene file read (64 MiB): room for measured peak-height samples of millions of
/// values, far below what would strain memory.
const MAX_SCENE_BYTES: u64 = 64 << 20;

impl Scene {
    /// Parses a TOML scene and validates it.
    pub fn from_toml_str(s: &str) -> Result<Scene> {
        let scene = parse_toml(s).map_err(|reason| Error::Scene {
            origin: "<string>".into(),
            reason,
        })?;
        scene.validate()?;
        Ok(scene)
    }

    /// Parses a JSON scene and validates it.
    pub fn from_json_str(s: &str) -> Result<Scene> {
        let scene: Scene = serde_json::from_str(s).map_err(|e| Error::Scene {
            origin: "<string>".into(),
            reason: e.to_string(),
        })?;
        scene.validate()?;
        Ok(scene)
    }

    /// Reads a scene file (`.toml` or `.json`, by extension) and validates it. Parse errors are
    /// prefixed with the file name.
    pub fn from_path(path: impl AsRef<Path>) -> Result<Scene> {
        let path = path.as_ref();
        let origin = path.display().to_string();
        // A scene is a few kB; refuse a file that would only exhaust memory in the parser.
        if let Ok(meta) = std::fs::metadata(path) {
            if meta.len() > MAX_SCENE_BYTES {
                return Err(Error::Scene {
                    origin,
                    reason: format!(
                        "the file has {} bytes, more than the {MAX_SCENE_BYTES} a scene may have",
                        meta.len()
                    ),
                });
            }
        }
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: origin.clone(),
            source,
        })?;
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let parsed = match ext.as_deref() {
            Some("toml") => parse_toml(&text),
            Some("json") => serde_json::from_str::<Scene>(&text).map_err(|e| e.to_string()),
            _ => Err("unknown file type (expected a .toml or .json extension)".to_string()),
        };
        let scene = parsed.map_err(|reason| Error::Scene { origin, reason })?;
        scene.validate()?;
        Ok(scene)
    }

    /// The scene as TOML.
    pub fn to_toml_string(&self) -> Result<String> {
        toml::to_string(self).map_err(|e| Error::Scene {
            origin: self.name.clone(),
            reason: format!("cannot write TOML: {e}"),
        })
    }

    /// The scene as pretty-printed JSON.
    pub fn to_json_string(&self) -> Result<String> {
        serde_json::to_string_pretty(self).map_err(|e| Error::Scene {
            origin: self.name.clone(),
            reason: format!("cannot write JSON: {e}"),
        })
    }
}

/// TOML parse with the parser's message on one line, prefixed by its line and column.
fn parse_toml(s: &str) -> std::result::Result<Scene, String> {
    toml::from_str::<Scene>(s).map_err(|e| {
        let msg = e.message().trim().replace('\n', "; ");
        match e.span() {
            Some(span) => {
                let before = s.get(..span.start).unwrap_or(s);
                let line = before.matches('\n').count() + 1;
                let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
                match field_at(s, span.start) {
                    Some(field) => format!("line {line}, column {col}, {field}: {msg}"),
                    None => format!("line {line}, column {col}: {msg}"),
                }
            }
            None => msg,
        }
    })
}

/// The dotted field of the `key = value` line holding byte `at`: the last `[table]` header above
/// it joined with the key (the parser's message names the type, not the field).
fn field_at(s: &str, at: usize) -> Option<String> {
    let start = s.get(..at)?.rfind('\n').map_or(0, |i| i + 1);
    let line = s.get(start..)?.lines().next()?;
    let key = line.split_once('=')?.0.trim().trim_matches('"');
    if key.is_empty() || key.starts_with('[') || key.starts_with('#') {
        return None;
    }
    let table = s
        .get(..start)?
        .lines()
        .rev()
        .map(str::trim)
        .find(|l| l.starts_with('['))
        .map(|l| {
            l.trim_matches(|c| c == '[' || c == ']')
                .split(']')
                .next()
                .unwrap_or("")
                .trim()
                .to_string()
        });
    Some(match table {
        Some(t) if !t.is_empty() => format!("{t}.{key}"),
        _ => key.to_string(),
    })
}
