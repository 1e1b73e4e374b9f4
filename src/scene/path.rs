//! Scene fields by name, as a user writes them: `surface.height_sigma_nm`, `stiffness_n_per_m`.
//!
//! The one resolver of such names, on a scene's serde form (its JSON value): `hdi fit --free`,
//! the Python `scene[...]` and `Scene.with_values` all go through it. A name is dotted sections
//! and a key; the key is the field's own (SI) or the same field in an engineering unit
//! ([`engineering_unit`]). Reading gives the value in the unit of the name; writing an
//! engineering-unit name writes that key in place of the SI one and leaves the conversion (and the
//! check of the value) to the scene reader, so that its errors name the field as written.

use serde_json::{Map, Value};
use thiserror::Error;

use super::engineering_unit;

/// Why a scene field name does not resolve; each kind carries the name as written.
///
/// ```
/// use hdi_tribology::scene::{FieldPath, PathError, Scene};
/// let v = serde_json::to_value(Scene::paper()).unwrap();
/// let e = FieldPath::at(&v, "nothing.height_sigma_m").unwrap_err();
/// let (name, section) = ("nothing.height_sigma_m".into(), "nothing".into());
/// assert_eq!(e, PathError::NoSection { name, section });
/// assert_eq!(e.name(), "nothing.height_sigma_m");
/// assert_eq!(e.reason(), "the scene has no section `nothing`");
/// // as a crate error: invalid input, named as written
/// let e: hdi_tribology::Error = e.into();
/// assert_eq!(e.to_string(), "invalid nothing.height_sigma_m: the scene has no section `nothing`");
/// ```
#[derive(Clone, Debug, PartialEq, Error)]
#[non_exhaustive]
pub enum PathError {
    /// A section of the name is not a section of the scene (absent, or switched off).
    #[error("scene has no section `{section}` in `{name}`")]
    NoSection {
        /// The name as written.
        name: String,
        /// The first section not found.
        section: String,
    },
    /// The name's key is not a field of its section.
    #[error("`{name}` is not a field of the scene")]
    NoField {
        /// The name as written.
        name: String,
    },
    /// No numeric field of the scene ends in the name.
    #[error("`{name}` is not a numeric field of the scene")]
    NoNumericField {
        /// The name as written.
        name: String,
    },
    /// More than one numeric field ends in the name.
    #[error("`{name}` is ambiguous; name one of: {}", .candidates.join(", "))]
    Ambiguous {
        /// The name as written.
        name: String,
        /// The full names, in the unit written, that it could mean.
        candidates: Vec<String>,
    },
    /// An engineering-unit name of a field that holds no number (or list of numbers) to convert.
    #[error("`{name}` holds {found}, not a number in {unit}")]
    NotANumber {
        /// The name as written.
        name: String,
        /// The unit of the name.
        unit: String,
        /// What the field holds.
        found: String,
    },
}

impl PathError {
    /// The name as written.
    pub fn name(&self) -> &str {
        match self {
            PathError::NoSection { name, .. }
            | PathError::NoField { name }
            | PathError::NoNumericField { name }
            | PathError::Ambiguous { name, .. }
            | PathError::NotANumber { name, .. } => name,
        }
    }

    /// What is wrong, without the name (for a message that names the field itself).
    pub fn reason(&self) -> String {
        match self {
            PathError::NoSection { section, .. } => {
                format!("the scene has no section `{section}`")
            }
            PathError::NoField { .. } => "not a field of the scene".into(),
            PathError::NoNumericField { .. } => {
                "no numeric scene field of that name (write it as in a scene file, e.g. \
                 `height_sigma_nm`, `contact_potential_v`, `efficiency_nm_per_mw`)"
                    .into()
            }
            PathError::Ambiguous { candidates, .. } => {
                format!("ambiguous; name one of: {}", candidates.join(", "))
            }
            PathError::NotANumber { unit, found, .. } => {
                format!("holds {found}, not a number in {unit}")
            }
        }
    }
}

impl From<PathError> for crate::Error {
    fn from(e: PathError) -> Self {
        crate::Error::invalid(e.name(), e.reason())
    }
}

/// A scene field resolved from its name as written: where the scene holds it (SI) and the
/// factor of the name's unit.
///
/// ```
/// use hdi_tribology::scene::{FieldPath, Scene};
/// # fn main() -> hdi_tribology::Result<()> {
/// let mut v = serde_json::to_value(Scene::paper()).unwrap();
/// let sigma = FieldPath::at(&v, "surface.height_sigma_nm")?;
/// assert_eq!(sigma.keys(), ["surface", "height_sigma_m"]);
/// assert!((sigma.read(&v)?.as_f64().unwrap() - 0.7).abs() < 1e-12);
/// sigma.write(&mut v, 0.5.into());
/// FieldPath::at(&v, "surface.peaks.sigma_nm")?.write(&mut v, 0.5.into());
/// let s = Scene::from_json_str(&v.to_string())?;
/// assert!((s.surface.height_sigma_m - 0.5e-9).abs() < 1e-24);
/// // sections may be left off where the key alone names one numeric field
/// let eta = FieldPath::find_numeric(&v, "efficiency_nm_per_mw")?;
/// assert_eq!(eta.keys(), ["heater", "efficiency_m_per_w"]);
/// assert_eq!((eta.unit(), eta.factor()), ("nm_per_mw", 1e-6));
/// let k = FieldPath::find_numeric(&v, "stiffness_n_per_m")?;
/// assert_eq!(k.keys(), ["air_bearing", "stiffness_n_per_m"]);
/// assert_eq!(k.unit(), "n_per_m");
/// let e = FieldPath::at(&v, "surface.no_such_nm").and_then(|f| f.read(&v)).unwrap_err();
/// assert_eq!(e.to_string(), "`surface.no_such_nm` is not a field of the scene");
/// # Ok(()) }
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct FieldPath {
    name: String,
    keys: Vec<String>,
    key: String,
    factor: f64,
    unit: String,
}

impl FieldPath {
    /// `name` read from the scene's root: every section written, then the key, SI or in an
    /// engineering unit. A key its section does not hold yet resolves (a write adds it and the
    /// reader judges it); [`read`](FieldPath::read) refuses it.
    pub fn at(root: &Value, name: &str) -> Result<FieldPath, PathError> {
        let mut sections: Vec<&str> = name.split('.').collect();
        let key = sections.pop().unwrap_or_default();
        let mut node = root;
        for s in &sections {
            node = node
                .as_object()
                .and_then(|o| o.get(*s))
                .filter(|n| !n.is_null())
                .ok_or_else(|| PathError::NoSection {
                    name: name.to_string(),
                    section: s.to_string(),
                })?;
        }
        let section = node.as_object().ok_or_else(|| PathError::NoField {
            name: name.to_string(),
        })?;
        let (si_key, factor) = match engineering_unit(key) {
            Some((si, f, _)) if !section.contains_key(key) => (si, f),
            _ => (key.to_string(), 1.0),
        };
        let mut keys: Vec<String> = sections.iter().map(|s| s.to_string()).collect();
        keys.push(si_key);
        Ok(FieldPath::new(name, keys, key, factor))
    }

    /// `name` as the numeric field whose path ends in it: the key (SI or in an engineering unit)
    /// with as many of its sections as make it unique (`height_sigma_nm`,
    /// `contact.footprint.radius_of_curvature_mm`). Fields inside lists are not searched.
    pub fn find_numeric(root: &Value, name: &str) -> Result<FieldPath, PathError> {
        let mut sections: Vec<&str> = name.split('.').collect();
        let key = sections.pop().unwrap_or_default();
        let eng = engineering_unit(key);
        let factor_for = |leaf: &str| {
            if leaf == key {
                Some(1.0)
            } else {
                eng.as_ref().filter(|(si, _, _)| si == leaf).map(|e| e.1)
            }
        };
        let mut leaves = Vec::new();
        numeric_leaves(root, &mut Vec::new(), &mut leaves);
        let mut matches: Vec<FieldPath> = leaves
            .into_iter()
            .filter(|l| {
                l.len() > sections.len()
                    && l[l.len() - 1 - sections.len()..l.len() - 1]
                        .iter()
                        .zip(&sections)
                        .all(|(a, b)| a == b)
            })
            .filter_map(|l| {
                let factor = factor_for(l.last()?)?;
                Some(FieldPath::new(name, l, key, factor))
            })
            .collect();
        match matches.len() {
            0 => Err(PathError::NoNumericField {
                name: name.to_string(),
            }),
            1 => Ok(matches.remove(0)),
            _ => Err(PathError::Ambiguous {
                name: name.to_string(),
                candidates: matches.iter().map(FieldPath::written_in_full).collect(),
            }),
        }
    }

    fn new(name: &str, keys: Vec<String>, key: &str, factor: f64) -> FieldPath {
        let unit = unit_suffix(key, keys.last().map_or("", String::as_str));
        FieldPath {
            name: name.to_string(),
            keys,
            key: key.to_string(),
            factor,
            unit,
        }
    }

    /// The name as written.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The keys from the scene's root to the field as the scene holds it (SI).
    pub fn keys(&self) -> &[String] {
        &self.keys
    }

    /// The factor of the name's unit: SI value = value in the name's unit × factor (1 for an SI
    /// name).
    pub fn factor(&self) -> f64 {
        self.factor
    }

    /// The unit the name carries, as its key spells it: `nm`, `nm_per_mw`, `n_per_m`, `v`; empty
    /// for a key without one.
    pub fn unit(&self) -> &str {
        &self.unit
    }

    /// The full dotted path with the key as written (`surface.height_sigma_nm`).
    fn written_in_full(&self) -> String {
        let (_, sections) = self.keys.split_last().unwrap_or((&self.key, &[]));
        let mut all = sections.to_vec();
        all.push(self.key.clone());
        all.join(".")
    }

    /// The field as the scene holds it (SI), if it holds it.
    pub fn get<'a>(&self, root: &'a Value) -> Option<&'a Value> {
        self.keys.iter().try_fold(root, |v, k| v.get(k))
    }

    /// The field's value in the unit of the name: a number, or a list of numbers, divided by the
    /// factor; anything else as the scene holds it when the name is the field's own.
    pub fn read(&self, root: &Value) -> Result<Value, PathError> {
        let v = self.get(root).ok_or_else(|| PathError::NoField {
            name: self.name.clone(),
        })?;
        if !self.is_renamed() {
            return Ok(v.clone());
        }
        // On the decimal the scene holds: 7e-10 m reads 0.7 nm (not 0.7000000000000001).
        let scale = |x: &Value| {
            x.as_f64()
                .map(|x| Value::from(crate::units::unscale(x, self.factor)))
        };
        let scaled = match v {
            Value::Null => Some(Value::Null),
            Value::Array(xs) => xs
                .iter()
                .map(scale)
                .collect::<Option<Vec<_>>>()
                .map(Value::Array),
            x => scale(x),
        };
        scaled.ok_or_else(|| PathError::NotANumber {
            name: self.name.clone(),
            unit: self.unit.clone(),
            found: v.to_string(),
        })
    }

    /// Writes `value`, in the unit of the name. An engineering-unit key takes the place of the SI
    /// one: the scene reader converts it, and names it as written if it refuses the value.
    pub fn write(&self, root: &mut Value, value: Value) {
        if let Some(section) = self.section_mut(root) {
            if self.is_renamed() {
                section.remove(self.keys.last().map_or("", String::as_str));
            }
            section.insert(self.key.clone(), value);
        }
    }

    /// Writes the SI value `x` in the field as the scene holds it.
    pub fn write_si(&self, root: &mut Value, x: f64) {
        if let (Some(section), Some(last)) = (self.section_mut(root), self.keys.last()) {
            section.insert(last.clone(), Value::from(x));
        }
    }

    fn is_renamed(&self) -> bool {
        self.keys.last() != Some(&self.key)
    }

    fn section_mut<'a>(&self, root: &'a mut Value) -> Option<&'a mut Map<String, Value>> {
        let (_, sections) = self.keys.split_last()?;
        sections
            .iter()
            .try_fold(root, |v, k| v.get_mut(k))?
            .as_object_mut()
    }
}

/// Every numeric field of the scene (outside lists), as key paths.
fn numeric_leaves(v: &Value, prefix: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    if let Value::Object(m) = v {
        for (k, x) in m {
            prefix.push(k.clone());
            match x {
                Value::Number(_) => out.push(prefix.clone()),
                Value::Object(_) => numeric_leaves(x, prefix, out),
                _ => {}
            }
            prefix.pop();
        }
    }
}

/// The unit a key carries: what follows the SI field's stem (`height_sigma_nm` → `nm`); for an
/// SI key, from its first SI unit token on (`stiffness_n_per_m` → `n_per_m`).
fn unit_suffix(key: &str, si: &str) -> String {
    const SI_TOKENS: &[&str] = &[
        "m", "n", "v", "j", "w", "s", "pa", "hz", "kg", "m2", "per", "k",
    ];
    if si == key {
        let tokens: Vec<&str> = key.split('_').collect();
        return match tokens.iter().skip(1).position(|t| SI_TOKENS.contains(t)) {
            Some(i) => tokens[i + 1..].join("_"),
            None => String::new(),
        };
    }
    let common = si
        .char_indices()
        .zip(key.chars())
        .take_while(|((_, a), b)| a == b)
        .filter(|((_, a), _)| *a == '_')
        .map(|((i, _), _)| i + 1)
        .last()
        .unwrap_or(0);
    key.get(common..).unwrap_or("").to_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    fn paper() -> Value {
        serde_json::to_value(Scene::paper()).unwrap()
    }

    #[test]
    fn names_round_trip_in_si_and_engineering_units_through_the_reader() {
        // name written, value in its unit, the field as held, its SI value
        let fields = [
            (
                "surface.height_sigma_nm",
                0.5,
                "surface.height_sigma_m",
                0.5e-9,
            ),
            (
                "surface.peaks.sigma_nm",
                0.5,
                "surface.peaks.sigma_m",
                0.5e-9,
            ),
            (
                "voltage.ac_frequency_khz",
                20.0,
                "voltage.ac_frequency_hz",
                20e3,
            ),
            ("nominal_clearance_m", 9e-9, "nominal_clearance_m", 9e-9),
            (
                "heater.efficiency_nm_per_mw",
                0.12,
                "heater.efficiency_m_per_w",
                0.12e-6,
            ),
        ];
        let mut v = paper();
        for (name, x, held, _) in fields {
            let f = FieldPath::at(&v, name).unwrap();
            assert_eq!(f.keys().join("."), held);
            f.write(&mut v, x.into());
            // the value as written, before the reader converts it
            assert_eq!(FieldPath::at(&v, name).unwrap().read(&v).unwrap(), x);
        }
        let v = serde_json::to_value(Scene::from_json_str(&v.to_string()).unwrap()).unwrap();
        for (name, x, held, si) in fields {
            let back = FieldPath::at(&v, name).unwrap();
            assert_eq!(back.keys().join("."), held);
            let got = back.read(&v).unwrap().as_f64().unwrap();
            assert!((got - x).abs() <= 1e-15 * x, "{name}: {got}");
            let got = back.get(&v).and_then(Value::as_f64).unwrap();
            assert!((got - si).abs() <= 1e-15 * si, "{name}: {got}");
            // the same field found by its key alone, where that is unambiguous
            if let Ok(found) = FieldPath::find_numeric(&v, name.rsplit('.').next().unwrap()) {
                assert_eq!((found.keys(), found.factor()), (back.keys(), back.factor()));
            }
        }
        // anything else reads as held: a section, a name
        let peaks = FieldPath::at(&v, "surface.peaks")
            .unwrap()
            .read(&v)
            .unwrap();
        assert!(peaks.is_object());
        assert_eq!(
            FieldPath::at(&v, "name").unwrap().read(&v).unwrap(),
            "paper"
        );
        // an SI value written in place
        let mut w = v.clone();
        let k = FieldPath::find_numeric(&w, "stiffness_n_per_m").unwrap();
        k.write_si(&mut w, 1.5e5);
        assert_eq!(k.read(&w).unwrap(), 1.5e5);
    }

    #[test]
    fn errors_name_the_field_as_written() {
        let v = paper();
        // a key its section does not hold resolves (a write adds it), and does not read
        let e = FieldPath::at(&v, "surface.no_such_field")
            .and_then(|f| f.read(&v))
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "`surface.no_such_field` is not a field of the scene"
        );
        let e = FieldPath::at(&v, "surface.no_such_nm")
            .and_then(|f| f.read(&v))
            .unwrap_err();
        assert_eq!(e.name(), "surface.no_such_nm");
        let e = FieldPath::at(&v, "nominal_clearance_m.x").unwrap_err();
        assert_eq!(
            e.to_string(),
            "`nominal_clearance_m.x` is not a field of the scene"
        );
        let e = FieldPath::at(&v, "surface.peaks.sigma_m.x.y").unwrap_err();
        assert_eq!(
            e.to_string(),
            "scene has no section `x` in `surface.peaks.sigma_m.x.y`"
        );
        let e = FieldPath::find_numeric(&v, "radius_of_curvature_mm").unwrap_err();
        assert!(
            matches!(&e, PathError::Ambiguous { candidates, .. }
                if candidates.iter().any(|c| c == "contact.footprint.radius_of_curvature_mm")),
            "{e}"
        );
        let e = crate::Error::from(FieldPath::find_numeric(&v, "height_sigma_km").unwrap_err());
        assert!(
            e.to_string()
                .starts_with("invalid height_sigma_km: no numeric scene field of that name"),
            "{e}"
        );
        let e = FieldPath::at(&v, "name_nm").and_then(|f| f.read(&v));
        assert!(matches!(e, Err(PathError::NoField { .. })), "{e:?}");
    }
}
