//! Reading and writing scenes as TOML or JSON.

use std::path::Path;

use serde::Deserialize;

use super::eng_units::{json_doc, toml_doc, Renames};
use super::toml_text::Edits;
use super::Scene;
use crate::{Error, Result};

/// Largest scene file read (64 MiB): room for measured peak-height samples of millions of
/// values, far below what would strain memory.
const MAX_SCENE_BYTES: u64 = 64 << 20;

impl Scene {
    /// Parses a TOML scene and validates it. Fields may be given in engineering units (see
    /// the [module docs](crate::scene#engineering-units)).
    ///
    /// ```
    /// use hdi_tribology::scene::Scene;
    /// let mut text = Scene::paper().to_toml_string()?;
    /// text = text.replace("nominal_clearance_m = 1e-8", "nominal_clearance_nm = 12.5");
    /// let s = Scene::from_toml_str(&text)?;
    /// assert!((s.nominal_clearance_m - 12.5e-9).abs() < 1e-23);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn from_toml_str(s: &str) -> Result<Scene> {
        validated(read_toml(s, "<string>")?)
    }

    /// Parses a JSON scene and validates it. Fields may be given in engineering units, as in
    /// [`Scene::from_toml_str`].
    pub fn from_json_str(s: &str) -> Result<Scene> {
        validated(read_json(s, "<string>")?)
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
        let read = match ext.as_deref() {
            Some("toml") => read_toml(&text, &origin)?,
            Some("json") => read_json(&text, &origin)?,
            _ => {
                return Err(Error::Scene {
                    origin,
                    reason: "unknown file type (expected a .toml or .json extension)".into(),
                })
            }
        };
        let (mut scene, renames) = read;
        // A bearing geometry named relative to the scene file.
        if let crate::force::AirBearingModel::Reynolds { geometry, .. } = &mut scene.air_bearing {
            let g = Path::new(geometry.as_str());
            if g.is_relative() {
                if let Some(dir) = path.parent() {
                    *geometry = dir.join(g).display().to_string();
                }
            }
        }
        validated((scene, renames))
    }

    /// The scene as TOML.
    pub fn to_toml_string(&self) -> Result<String> {
        toml::to_string(self)
            .map(|text| super::toml_text::tidy_floats(&text))
            .map_err(|e| Error::Scene {
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

/// The scene once validated; an error on a field given in engineering units says so.
fn validated((scene, renames): (Scene, Renames)) -> Result<Scene> {
    scene.validate().map_err(|e| renames.annotate(e))?;
    Ok(scene)
}

fn scene_error(origin: &str, reason: String) -> Error {
    Error::Scene {
        origin: origin.into(),
        reason,
    }
}

/// A TOML scene, with engineering-unit fields converted by editing the text; the parser's
/// errors are mapped back to the line, column and field as written in the file.
fn read_toml(s: &str, origin: &str) -> Result<(Scene, Renames)> {
    let doc =
        toml::de::DeTable::parse(s).map_err(|e| scene_error(origin, toml_message(s, &e, None)))?;
    let mut renames = Renames::default();
    let mut edits = Edits::default();
    toml_doc::convert_table(doc.get_ref(), "", &mut renames, &mut edits)?;
    if edits.is_empty() {
        return Scene::deserialize(toml::de::Deserializer::from(doc))
            .map(|scene| (scene, renames))
            .map_err(|e| scene_error(origin, toml_message(s, &e, None)));
    }
    let edited = edits.apply(s);
    match toml::from_str(&edited) {
        Ok(scene) => Ok((scene, renames)),
        Err(e) => Err(scene_error(
            origin,
            renames.respell(toml_message(s, &e, Some(&edits))),
        )),
    }
}

/// A JSON scene, with engineering-unit fields converted. Without such fields it is read
/// straight from the text, so the parser's errors keep their line and column. Errors name the
/// dotted path of the field.
fn read_json(s: &str, origin: &str) -> Result<(Scene, Renames)> {
    let mut value: serde_json::Value =
        serde_json::from_str(s).map_err(|e| scene_error(origin, e.to_string()))?;
    let mut renames = Renames::default();
    if let serde_json::Value::Object(o) = &mut value {
        json_doc::convert_object(o, "", &mut renames)?;
    }
    let scene = if renames.is_empty() {
        serde_path_to_error::deserialize::<_, Scene>(&mut serde_json::Deserializer::from_str(s))
    } else {
        serde_path_to_error::deserialize::<_, Scene>(value.clone())
    };
    match scene {
        Ok(scene) => Ok((scene, renames)),
        Err(e) => {
            let msg = e.inner().to_string();
            let mut path = e.path().to_string();
            // Inside a tagged section (`air_bearing`, `peaks`, …) serde loses the field: find
            // the one field there whose value the message names.
            if let Some(key) = json_at(&value, &path).and_then(|v| field_with(v, &msg)) {
                path = if path == "." {
                    key
                } else {
                    format!("{path}.{key}")
                };
            }
            let msg = renames.respell(msg);
            Err(scene_error(
                origin,
                format!("{}: {msg}", renames.given(&path)),
            ))
        }
    }
}

/// The value at a dotted path (`a.b[2].c`, `.` for the root) of a JSON document.
fn json_at<'a>(v: &'a serde_json::Value, path: &str) -> Option<&'a serde_json::Value> {
    if path == "." {
        return Some(v);
    }
    path.split('.').try_fold(v, |v, part| {
        let (key, indices) = part.split_once('[').unwrap_or((part, ""));
        let v = if key.is_empty() { v } else { v.get(key)? };
        indices
            .split('[')
            .filter(|i| !i.is_empty())
            .try_fold(v, |v, i| {
                v.get(i.trim_end_matches(']').parse::<usize>().ok()?)
            })
    })
}

/// The one key of `v` (an object) whose value is the "invalid type" value of `msg`.
fn field_with(v: &serde_json::Value, msg: &str) -> Option<String> {
    use serde_json::Value;
    let unexpected = msg
        .strip_prefix("invalid type: ")?
        .split(", expected")
        .next()?;
    let shown = |x: &Value| match x {
        Value::String(s) => format!("string {s:?}"),
        Value::Bool(b) => format!("boolean `{b}`"),
        Value::Number(n) if n.is_f64() => format!("floating point `{n}`"),
        Value::Number(n) => format!("integer `{n}`"),
        Value::Null => "null".into(),
        Value::Array(_) => "sequence".into(),
        Value::Object(_) => "map".into(),
    };
    let mut hits = v
        .as_object()?
        .iter()
        .filter(|(_, x)| shown(x) == unexpected);
    match (hits.next(), hits.next()) {
        (Some((k, _)), None) => Some(k.clone()),
        _ => None,
    }
}

/// The TOML parser's message on one line, prefixed by its line and column in `s`. With `edits`,
/// the error is in the edited text and its position is mapped back to `s`.
fn toml_message(s: &str, e: &toml::de::Error, edits: Option<&Edits>) -> String {
    let msg = e.message().trim().replace('\n', "; ");
    match e.span() {
        Some(span) => {
            let start = edits.map_or(span.start, |ed| ed.original_offset(span.start));
            let before = s.get(..start).unwrap_or(s);
            let line = before.matches('\n').count() + 1;
            let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
            match field_at(s, start).or_else(|| field_in_table(s, start, &msg)) {
                Some(field) => format!("line {line}, column {col}, {field}: {msg}"),
                None => format!("line {line}, column {col}: {msg}"),
            }
        }
        None => msg,
    }
}

/// The field of the `[table]` whose header holds byte `at` (the parser points at the header when
/// a tagged section such as `[air_bearing]` fails) and whose value is the "invalid type" value
/// of `msg`, when exactly one is.
fn field_in_table(s: &str, at: usize, msg: &str) -> Option<String> {
    let start = s.get(..at)?.rfind('\n').map_or(0, |i| i + 1);
    let mut lines = s.get(start..)?.lines();
    let header = lines.next()?.trim();
    let table = header
        .strip_prefix('[')?
        .split(']')
        .next()?
        .trim()
        .to_string();
    let unexpected = msg
        .strip_prefix("invalid type: ")?
        .split(", expected")
        .next()?;
    // `string "x"` is written `"x"`, `integer `5`` is written `5`
    let token = unexpected
        .split_once(' ')
        .map(|(_, t)| t.trim_matches('`'))
        .unwrap_or(unexpected);
    let mut hits = lines
        .take_while(|l| !l.trim_start().starts_with('['))
        .filter_map(|l| l.split_once('='))
        .filter(|(_, v)| {
            let v = v.split(" #").next().unwrap_or(v).trim();
            v == token
        })
        .map(|(k, _)| k.trim().trim_matches('"').to_string());
    match (hits.next(), hits.next()) {
        (Some(k), None) => Some(format!("{table}.{k}")),
        _ => None,
    }
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
