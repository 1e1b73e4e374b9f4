//! Engineering units in scene files: a field may be given in nm, mW, kHz, GPa, … instead of SI,
//! with the unit in its name (`height_sigma_nm = 0.5` for `height_sigma_m = 0.5e-9`). The keys
//! are renamed to their SI form, and the values scaled, before the scene is deserialised.

use std::collections::BTreeMap;

use crate::{Error, Result};

/// Engineering suffix, SI suffix, factor to SI, and the unit's name. Longest suffixes first, so
/// `_per_um2` is not read as `_um2`, nor `_nm_per_mw` as `_mw`.
const SUFFIXES: &[(&str, &str, f64, &str)] = &[
    ("_nm_per_mw", "_m_per_w", 1e-6, "nm/mW"),
    ("_mw_per_ms", "_w_per_s", 1.0, "mW/ms"),
    ("_mw_per_s", "_w_per_s", 1e-3, "mW/s"),
    ("_per_um2", "_per_m2", 1e12, "µm⁻²"),
    ("_um2", "_m2", 1e-12, "µm²"),
    ("_mm2", "_m2", 1e-6, "mm²"),
    ("_nm", "_m", 1e-9, "nm"),
    ("_um", "_m", 1e-6, "µm"),
    ("_mm", "_m", 1e-3, "mm"),
    ("_mw", "_w", 1e-3, "mW"),
    ("_khz", "_hz", 1e3, "kHz"),
    ("_mhz", "_hz", 1e6, "MHz"),
    ("_gpa", "_pa", 1e9, "GPa"),
    ("_ms", "_s", 1e-3, "ms"),
    ("_us", "_s", 1e-6, "µs"),
    ("_ns", "_s", 1e-9, "ns"),
    ("_un", "_n", 1e-6, "µN"),
];

/// The heater programme in (ms, mW) pairs: renamed to `programme`, in (s, W).
const PROGRAMME: (&str, &str, [f64; 2], &str) =
    ("programme_ms_mw", "programme", [1e-3, 1e-3], "ms, mW");

/// How to convert one key: its SI name, and the factor for each column of the value.
struct Rule {
    si_key: String,
    factors: Factors,
    unit: &'static str,
}

enum Factors {
    /// A number, or a list of numbers: every one scaled alike.
    All(f64),
    /// A list of pairs, each column scaled by its own factor.
    Pairs([f64; 2]),
}

fn rule(key: &str) -> Option<Rule> {
    if key == PROGRAMME.0 {
        return Some(Rule {
            si_key: PROGRAMME.1.to_string(),
            factors: Factors::Pairs(PROGRAMME.2),
            unit: PROGRAMME.3,
        });
    }
    SUFFIXES.iter().find_map(|&(eng, si, f, unit)| {
        let stem = key.strip_suffix(eng)?;
        (!stem.is_empty()).then(|| Rule {
            si_key: format!("{stem}{si}"),
            factors: Factors::All(f),
            unit,
        })
    })
}

/// The SI name of a field key given in an engineering unit, the factor that takes its value to
/// SI, and the unit's name; `None` for a key in SI (or not a unit at all). Lists of pairs
/// (`heater.programme_ms_mw`) are not single-factor keys and give `None` too.
///
/// ```
/// use hdi_tribology::scene::engineering_unit;
/// assert_eq!(engineering_unit("height_sigma_nm"), Some(("height_sigma_m".to_string(), 1e-9, "nm")));
/// assert_eq!(engineering_unit("height_sigma_m"), None);
/// ```
pub fn engineering_unit(key: &str) -> Option<(String, f64, &'static str)> {
    match rule(key)? {
        Rule {
            si_key,
            factors: Factors::All(f),
            unit,
        } => Some((si_key, f, unit)),
        Rule {
            factors: Factors::Pairs(_),
            ..
        } => None,
    }
}

/// A renamed field: its path as the file gave it, and for a field scaled by one factor, that
/// factor to SI and the unit's name.
#[derive(Debug)]
struct Given {
    path: String,
    scale: Option<(f64, &'static str)>,
}

/// The renames made, as dotted paths: SI field → the field as the file gave it.
#[derive(Debug, Default)]
pub(super) struct Renames(BTreeMap<String, Given>);

impl Renames {
    fn insert(&mut self, prefix: &str, rule: &Rule, eng_key: &str) {
        let scale = match rule.factors {
            Factors::All(f) => Some((f, rule.unit)),
            Factors::Pairs(_) => None,
        };
        self.0.insert(
            path(prefix, &rule.si_key),
            Given {
                path: path(prefix, eng_key),
                scale,
            },
        );
    }

    pub(super) fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// A dotted path as the file gave it (an SI path the reader renamed is named as given).
    pub(super) fn given(&self, path: &str) -> String {
        self.lookup(path)
            .map_or_else(|| path.to_string(), |(g, rest)| format!("{}{rest}", g.path))
    }

    /// The renamed field that `path` is, or lies inside, and the rest of `path` after it.
    fn lookup<'a>(&self, path: &'a str) -> Option<(&Given, &'a str)> {
        self.0.iter().find_map(|(si, given)| {
            let rest = path.strip_prefix(si.as_str())?;
            (rest.is_empty() || rest.starts_with(['[', '.'])).then_some((given, rest))
        })
    }

    /// A deserialiser's "unknown field" message names the key as the file spelt it.
    pub(super) fn respell(&self, msg: String) -> String {
        let last = |p: &str| p.rsplit('.').next().unwrap_or(p).to_string();
        self.0.iter().fold(msg, |m, (si, given)| {
            m.replace(
                &format!("unknown field `{}`", last(si)),
                &format!("unknown field `{}`", last(&given.path)),
            )
        })
    }

    /// A validation error on a renamed field names the field as the file gave it, with the value
    /// seen (`got …`) in the file's unit.
    pub(super) fn annotate(&self, e: Error) -> Error {
        match e {
            Error::InvalidInput { field, reason } => match self.lookup(&field) {
                Some((
                    Given {
                        path,
                        scale: Some((f, unit)),
                    },
                    rest,
                )) => Error::InvalidInput {
                    field: format!("{path}{rest}"),
                    reason: in_unit(&reason, *f, unit),
                },
                Some((Given { path, scale: None }, rest)) => Error::InvalidInput {
                    field: format!("{field} (given as {path}{rest})"),
                    reason,
                },
                None => Error::InvalidInput { field, reason },
            },
            other => other,
        }
    }
}

/// SI unit names a message may write after a value, dropped when the value is rewritten.
const SI_UNITS: &[&str] = &["m", "m²", "m⁻²", "s", "W", "Hz", "Pa", "N", "m/W", "W/s"];

/// `reason` with its values rewritten from SI in the engineering unit (`factor` to SI): the
/// value after `got ` and every number followed by an SI unit name, so that a bound and the
/// value seen read in the unit the file used (`must not exceed 1e-7 m, got -5e-10` becomes
/// `must not exceed 100 nm, got -0.5 nm`).
fn in_unit(reason: &str, factor: f64, unit: &str) -> String {
    let words: Vec<&str> = reason.split(' ').collect();
    let mut out: Vec<String> = Vec::with_capacity(words.len());
    let mut i = 0;
    while i < words.len() {
        let word = words[i];
        // A number may carry a sign prefix (±) and trailing punctuation (`,` or `)`).
        let body_start = word.find(|c: char| c != '±').unwrap_or(word.len());
        let body_end = word.find([',', ')']).unwrap_or(word.len()).max(body_start);
        let (sign, body, tail) = (
            &word[..body_start],
            &word[body_start..body_end],
            &word[body_end..],
        );
        let next_is_si = tail.is_empty()
            && words
                .get(i + 1)
                .map(|w| w.trim_end_matches([',', ')']))
                .is_some_and(|w| SI_UNITS.contains(&w));
        let after_got = i > 0 && words[i - 1] == "got";
        match body.parse::<f64>() {
            Ok(x) if next_is_si || after_got => {
                let value = format!("{sign}{}", crate::units::fmt_short(x / factor));
                if next_is_si {
                    let next = words[i + 1];
                    let rest = &next[next.trim_end_matches([',', ')']).len()..];
                    out.push(format!("{value} {unit}{rest}"));
                    i += 2;
                } else {
                    out.push(format!("{value} {unit}{tail}"));
                    i += 1;
                }
            }
            _ => {
                out.push(word.to_string());
                i += 1;
            }
        }
    }
    out.join(" ")
}

fn path(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_string()
    } else {
        format!("{prefix}.{key}")
    }
}

/// Scales `x` (from the file, in the engineering unit) to SI on the decimal the file writes
/// (100 nm is 1e-7 m, not 1.0000000000000001e-7), refusing overflow.
fn scale(x: f64, f: f64, field: &str, unit: &str) -> Result<f64> {
    let y = crate::units::rescale(x, f);
    if x.is_finite() && !y.is_finite() {
        return Err(Error::invalid(
            field,
            format!("{x} {unit} overflows in SI units"),
        ));
    }
    Ok(y)
}

fn not_number(field: &str, unit: &str, what: &str) -> Error {
    Error::invalid(field, format!("must be {what} in {unit}"))
}

fn both(field_eng: &str, si_key: &str) -> Error {
    Error::invalid(
        field_eng,
        format!("give the field in one unit only, not together with `{si_key}`"),
    )
}

/// TOML: the engineering-unit keys of a parsed document, and their values, as text edits of the
/// file, so the edited file is parsed as usual and the parser's errors can be mapped back to the
/// file as written.
pub(super) mod toml_doc {
    use toml::de::{DeTable, DeValue};
    use toml::Spanned;

    use super::*;
    use crate::scene::toml_text::{float_text, number, Edits};

    fn convert(
        v: &Spanned<DeValue<'_>>,
        factors: &Factors,
        field: &str,
        unit: &str,
        edits: &mut Edits,
    ) -> Result<()> {
        match (v.get_ref(), factors) {
            (DeValue::Array(items), _) => {
                for (i, item) in items.iter().enumerate() {
                    let field = format!("{field}[{i}]");
                    match factors {
                        Factors::All(f) => convert(item, &Factors::All(*f), &field, unit, edits)?,
                        Factors::Pairs(p) => match item.get_ref() {
                            DeValue::Array(pair) if pair.len() == 2 => {
                                for (c, f) in pair.iter().zip(p) {
                                    convert(c, &Factors::All(*f), &field, unit, edits)?;
                                }
                            }
                            _ => return Err(not_number(&field, unit, "a pair of numbers")),
                        },
                    }
                }
            }
            (x, Factors::All(f)) => {
                let x = number(x).ok_or_else(|| not_number(field, unit, "a number"))?;
                edits.push(v.span(), float_text(scale(x, *f, field, unit)?));
            }
            (_, Factors::Pairs(_)) => {
                return Err(not_number(field, unit, "a list of pairs of numbers"))
            }
        }
        Ok(())
    }

    /// The edits that rename and convert the engineering-unit keys of `table` and of the tables
    /// inside it.
    pub(in crate::scene) fn convert_table(
        table: &DeTable<'_>,
        prefix: &str,
        renames: &mut Renames,
        edits: &mut Edits,
    ) -> Result<()> {
        // SI key → the engineering key renamed to it, to refuse two spellings of one field.
        let mut produced = BTreeMap::new();
        for (k, v) in table.iter() {
            let key = k.get_ref().as_ref();
            let field = path(prefix, key);
            match rule(key) {
                Some(r) => {
                    if table.contains_key(r.si_key.as_str()) {
                        return Err(both(&field, &r.si_key));
                    }
                    if let Some(other) = produced.insert(r.si_key.clone(), key) {
                        return Err(both(&field, other));
                    }
                    convert(v, &r.factors, &field, r.unit, edits)?;
                    edits.push(k.span(), r.si_key.clone());
                    renames.insert(prefix, &r, key);
                }
                None => {
                    if let DeValue::Table(t) = v.get_ref() {
                        convert_table(t, &field, renames, edits)?;
                    }
                }
            }
        }
        Ok(())
    }
}

/// JSON: the same renaming on a parsed value.
pub(super) mod json_doc {
    use serde_json::{Map, Number, Value};

    use super::*;

    fn convert(v: &mut Value, factors: &Factors, field: &str, unit: &str) -> Result<()> {
        match (v, factors) {
            (Value::Array(items), _) => {
                for (i, item) in items.iter_mut().enumerate() {
                    let field = format!("{field}[{i}]");
                    match factors {
                        Factors::All(f) => convert(item, &Factors::All(*f), &field, unit)?,
                        Factors::Pairs(p) => match item {
                            Value::Array(pair) if pair.len() == 2 => {
                                for (c, f) in pair.iter_mut().zip(p) {
                                    convert(c, &Factors::All(*f), &field, unit)?;
                                }
                            }
                            _ => return Err(not_number(&field, unit, "a pair of numbers")),
                        },
                    }
                }
                Ok(())
            }
            (x, Factors::All(f)) => {
                let n = x
                    .as_f64()
                    .ok_or_else(|| not_number(field, unit, "a number"))?;
                let y = scale(n, *f, field, unit)?;
                *x = Number::from_f64(y).map_or(Value::Null, Value::Number);
                Ok(())
            }
            (_, Factors::Pairs(_)) => Err(not_number(field, unit, "a list of pairs of numbers")),
        }
    }

    /// Renames and converts the engineering-unit keys of `obj` and of the objects inside it.
    pub(in crate::scene) fn convert_object(
        obj: &mut Map<String, Value>,
        prefix: &str,
        renames: &mut Renames,
    ) -> Result<()> {
        let keys: Vec<String> = obj.keys().cloned().collect();
        for key in keys {
            let field = path(prefix, &key);
            match rule(&key) {
                Some(r) => {
                    if obj.contains_key(&r.si_key) {
                        return Err(both(&field, &r.si_key));
                    }
                    let Some(mut v) = obj.remove(&key) else {
                        continue;
                    };
                    convert(&mut v, &r.factors, &field, r.unit)?;
                    renames.insert(prefix, &r, &key);
                    obj.insert(r.si_key, v);
                }
                None => {
                    if let Some(Value::Object(o)) = obj.get_mut(&key) {
                        convert_object(o, &field, renames)?;
                    }
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_rewritten_in_the_given_unit() {
        assert_eq!(
            in_unit("must be finite and >= 0, got -5e-10", 1e-9, "nm"),
            "must be finite and >= 0, got -0.5 nm"
        );
        assert_eq!(
            in_unit("must not exceed 1e-7 m, got 1e291 m", 1e-9, "nm"),
            "must not exceed 100 nm, got 1e300 nm"
        );
        assert_eq!(
            in_unit("got 0.5 W, too much", 1e-3, "mW"),
            "got 500 mW, too much"
        );
        assert_eq!(in_unit("no value", 1e-3, "mW"), "no value");
        assert_eq!(
            in_unit("must be at most 1e7 Hz, got 1e15 Hz", 1e3, "kHz"),
            "must be at most 10000 kHz, got 1e12 kHz"
        );
        assert_eq!(
            in_unit("must lie in [1e-11, 0.01], got 2 s", 1e-3, "ms"),
            "must lie in [1e-11, 0.01], got 2000 ms"
        );
    }

    #[test]
    fn longest_suffix_wins() {
        let r = rule("asperity_density_per_um2").unwrap();
        assert_eq!(r.si_key, "asperity_density_per_m2");
        let r = rule("efficiency_nm_per_mw").unwrap();
        assert_eq!(r.si_key, "efficiency_m_per_w");
        let r = rule("area_um2").unwrap();
        assert_eq!(r.si_key, "area_m2");
        assert!(rule("max_steps").is_none());
        assert!(rule("nominal_clearance_m").is_none());
        assert!(rule("_nm").is_none());
    }
}
