//! Free parameters: scene fields named as a scene file names them, in the unit of that name.
//!
//! A name is resolved against the scene's own serde form by [`FieldPath::find_numeric`]: the
//! field whose key it is, or whose key the scene reader renames it to (`height_sigma_nm` →
//! `surface.height_sigma_m`, factor 1e-9). No list of fittable fields is kept here: any numeric
//! field of the scene can be freed.

use serde::Serialize;
use serde_json::Value;

use crate::scene::FieldPath;
use crate::{Error, Result};

/// A parameter to fit, in the unit its name carries.
///
/// ```
/// use hdi_tribology::fit::FreeParameter;
/// let p: FreeParameter = "height_sigma_nm=0.3:1.5".parse()?;
/// assert_eq!((p.name.as_str(), p.lower, p.upper), ("height_sigma_nm", Some(0.3), Some(1.5)));
/// let q: FreeParameter = "contact_potential_v".parse()?;
/// assert_eq!((q.lower, q.upper), (None, None));
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FreeParameter {
    /// The field's name as a scene file writes it (`height_sigma_nm`, `contact_potential_v`,
    /// `hamaker_attractive_j`, `efficiency_nm_per_mw`, `nominal_clearance_nm`,
    /// `stiffness_n_per_m`), optionally with its section (`contact.footprint.radius_of_curvature_mm`)
    /// when the name alone is ambiguous.
    pub name: String,
    /// Lower bound, in the name's unit.
    pub lower: Option<f64>,
    /// Upper bound, in the name's unit.
    pub upper: Option<f64>,
    /// Starting value, in the name's unit (default: the scene's value).
    pub start: Option<f64>,
}

impl FreeParameter {
    /// A parameter without bounds (a field that is positive in the scene stays positive).
    pub fn new(name: impl Into<String>) -> Self {
        FreeParameter {
            name: name.into(),
            lower: None,
            upper: None,
            start: None,
        }
    }

    /// The same parameter with bounds `[lower, upper]` in its unit.
    pub fn bounded(mut self, lower: f64, upper: f64) -> Self {
        self.lower = Some(lower);
        self.upper = Some(upper);
        self
    }

    /// The same parameter started from `start` (in its unit).
    pub fn starting_at(mut self, start: f64) -> Self {
        self.start = Some(start);
        self
    }
}

impl std::str::FromStr for FreeParameter {
    type Err = Error;

    /// `name`, `name=LO:HI`, `name=LO:` or `name=:HI`.
    fn from_str(s: &str) -> Result<Self> {
        let (name, bounds) = match s.split_once('=') {
            Some((n, b)) => (n.trim(), Some(b.trim())),
            None => (s.trim(), None),
        };
        if name.is_empty() {
            return Err(Error::invalid(
                "--free",
                format!("empty parameter name in `{s}`"),
            ));
        }
        let mut p = FreeParameter::new(name);
        if let Some(b) = bounds {
            let (lo, hi) = b.split_once(':').ok_or_else(|| {
                Error::invalid(
                    format!("--free {name}"),
                    format!("bounds must read LO:HI, got `{b}`"),
                )
            })?;
            let num = |t: &str| -> Result<Option<f64>> {
                if t.trim().is_empty() {
                    return Ok(None);
                }
                t.trim().parse::<f64>().map(Some).map_err(|_| {
                    Error::invalid(
                        format!("--free {name}"),
                        format!("bound `{t}` is not a number"),
                    )
                })
            };
            p.lower = num(lo)?;
            p.upper = num(hi)?;
        }
        Ok(p)
    }
}

/// How the optimiser's unbounded variable `u` maps to the parameter `x` (user unit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Transform {
    /// `x = lo + (hi − lo)(1 + tanh u)/2`.
    Both { lo: f64, hi: f64 },
    /// `x = lo + s·e^u`.
    Lower { lo: f64, s: f64 },
    /// `x = hi − s·e^u`.
    Upper { hi: f64, s: f64 },
    /// `x = x0 + s·u`.
    Free { x0: f64, s: f64 },
}

impl Transform {
    pub(super) fn x(&self, u: f64) -> f64 {
        match *self {
            Transform::Both { lo, hi } => lo + (hi - lo) * 0.5 * (1.0 + u.tanh()),
            Transform::Lower { lo, s } => lo + s * u.exp(),
            Transform::Upper { hi, s } => hi - s * u.exp(),
            Transform::Free { x0, s } => x0 + s * u,
        }
    }

    /// `dx/du`.
    pub(super) fn dx_du(&self, u: f64) -> f64 {
        match *self {
            Transform::Both { lo, hi } => (hi - lo) * 0.5 / u.cosh().powi(2),
            Transform::Lower { s, .. } => s * u.exp(),
            Transform::Upper { s, .. } => -s * u.exp(),
            Transform::Free { s, .. } => s,
        }
    }

    /// `u` for `x`, with `x` moved inside the bounds by a hair if it sits on one.
    pub(super) fn u(&self, x: f64) -> f64 {
        match *self {
            Transform::Both { lo, hi } => {
                let t = (2.0 * (x - lo) / (hi - lo) - 1.0).clamp(-1.0 + 1e-9, 1.0 - 1e-9);
                t.atanh()
            }
            Transform::Lower { lo, s } => ((x - lo).max(1e-9 * s) / s).ln(),
            Transform::Upper { hi, s } => ((hi - x).max(1e-9 * s) / s).ln(),
            Transform::Free { x0, s } => (x - x0) / s,
        }
    }
}

/// A free parameter resolved to its scene field.
#[derive(Clone, Debug)]
pub(super) struct Resolved {
    /// The field, named as given, with the unit of the name and its factor to SI.
    pub field: FieldPath,
    /// Other fields set to the same SI value (one physical quantity held in two fields).
    pub linked: Vec<FieldPath>,
    /// Starting value (name's unit).
    pub start: f64,
    /// Bounds (name's unit); `None` is open.
    pub lower: Option<f64>,
    /// Upper bound.
    pub upper: Option<f64>,
    /// The scale of the parameter (name's unit): its value, or its range when it may change sign.
    pub scale: f64,
    /// The map from the optimiser's variable.
    pub transform: Transform,
}

impl Resolved {
    /// The name as given.
    pub(super) fn name(&self) -> &str {
        self.field.name()
    }

    /// Sets the parameter, and the fields linked to it, to `x` in its unit.
    pub(super) fn write(&self, scene: &mut Value, x: f64) {
        let si = crate::units::rescale(x, self.field.factor());
        self.field.write_si(scene, si);
        for l in &self.linked {
            l.write_si(scene, si);
        }
    }
}

/// Resolves `p` against the scene's serde form `base`.
pub(super) fn resolve(base: &Value, p: &FreeParameter) -> Result<Resolved> {
    let field = format!("--free {}", p.name);
    let path = FieldPath::find_numeric(base, &p.name)
        .map_err(|e| Error::invalid(field.clone(), e.reason()))?;
    let si = path.get(base).and_then(Value::as_f64).unwrap_or(f64::NAN);
    let linked = linked_fields(base, &path);
    let start = p
        .start
        .unwrap_or_else(|| crate::units::unscale(si, path.factor()));
    let unit = path.unit();
    let bad = |what: &str, v: f64| {
        Error::invalid(
            field.clone(),
            format!("{what} must be finite, got {v:?} {unit}"),
        )
    };
    for (what, v) in [("lower bound", p.lower), ("upper bound", p.upper)] {
        if let Some(v) = v.filter(|v| !v.is_finite()) {
            return Err(bad(what, v));
        }
    }
    if !start.is_finite() {
        return Err(bad("start", start));
    }
    // A field positive in the scene stays positive unless bounds say otherwise.
    let lower = p.lower.or((si > 0.0 && p.upper.is_none()).then_some(0.0));
    let upper = p.upper;
    if let (Some(lo), Some(hi)) = (lower, upper) {
        if lo >= hi {
            return Err(Error::invalid(
                field,
                format!("lower bound {lo} {unit} must be below upper bound {hi} {unit}"),
            ));
        }
    }
    if lower.is_some_and(|lo| start < lo) || upper.is_some_and(|hi| start > hi) {
        return Err(Error::invalid(
            field,
            format!(
                "start {start} {unit} lies outside the bounds [{}, {}] {unit}",
                lower.map_or("-inf".into(), |v| v.to_string()),
                upper.map_or("inf".into(), |v| v.to_string())
            ),
        ));
    }
    let transform = match (lower, upper) {
        (Some(lo), Some(hi)) => Transform::Both { lo, hi },
        (Some(lo), None) => Transform::Lower {
            lo,
            s: if start > lo {
                start - lo
            } else {
                start.abs().max(1.0)
            },
        },
        (None, Some(hi)) => Transform::Upper {
            hi,
            s: if start < hi {
                hi - start
            } else {
                start.abs().max(1.0)
            },
        },
        (None, None) => Transform::Free {
            x0: start,
            s: start.abs().max(1.0),
        },
    };
    // Positive quantities are measured relative to their value; one that may change sign (φ)
    // relative to its allowed range, or to one unit of its name.
    let scale = match (lower, upper) {
        (Some(lo), _) if lo >= 0.0 && start > 0.0 => start,
        (Some(lo), Some(hi)) => 0.5 * (hi - lo),
        _ => start.abs().max(1.0),
    };
    Ok(Resolved {
        field: path,
        linked,
        start,
        lower,
        upper,
        scale,
        transform,
    })
}

/// The other fields that hold the same quantity as `field`: the surface's σ is held by its heights
/// and, for Rice-maxima peaks, by the peak law, one value unless the scene says they differ on
/// purpose (`surface.independent_peak_sigma`, which its validation enforces); freeing either sets
/// both.
fn linked_fields(base: &Value, field: &FieldPath) -> Vec<FieldPath> {
    const HEIGHT: &str = "surface.height_sigma_m";
    const PEAK: &str = "surface.peaks.sigma_m";
    let independent = base
        .pointer("/surface/independent_peak_sigma")
        .and_then(Value::as_bool)
        .unwrap_or(false);
    let other = match field.keys().join(".").as_str() {
        HEIGHT => PEAK,
        PEAK => HEIGHT,
        _ => return Vec::new(),
    };
    if independent {
        return Vec::new();
    }
    FieldPath::at(base, other)
        .ok()
        .filter(|f| f.get(base).is_some())
        .into_iter()
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::scene::Scene;

    fn paper() -> Value {
        serde_json::to_value(Scene::paper()).unwrap()
    }

    fn keys(r: &Resolved) -> Vec<&str> {
        r.field.keys().iter().map(String::as_str).collect()
    }

    #[test]
    fn engineering_names_resolve_through_the_scene_reader() {
        let base = paper();
        let r = resolve(&base, &FreeParameter::new("height_sigma_nm")).unwrap();
        assert_eq!(keys(&r), ["surface", "height_sigma_m"]);
        assert!((r.field.factor() - 1e-9).abs() < 1e-24 && (r.start - 0.7).abs() < 1e-12);
        assert_eq!(r.field.unit(), "nm");
        assert_eq!(r.linked.len(), 1);
        assert_eq!(r.linked[0].keys(), ["surface", "peaks", "sigma_m"]);
        // σ of the peaks set apart on purpose: freeing one σ leaves the other alone.
        let mut apart = Scene::paper();
        apart.surface.independent_peak_sigma = true;
        if let crate::surface::PeakModel::RiceMaxima { sigma_m, .. } = &mut apart.surface.peaks {
            *sigma_m = 0.8e-9;
        }
        let apart = serde_json::to_value(apart).unwrap();
        let r = resolve(&apart, &FreeParameter::new("height_sigma_nm")).unwrap();
        assert!(r.linked.is_empty(), "{:?}", r.linked);
        let r = resolve(&base, &FreeParameter::new("efficiency_nm_per_mw")).unwrap();
        assert_eq!(keys(&r), ["heater", "efficiency_m_per_w"]);
        assert!((r.start - 0.1).abs() < 1e-12, "{}", r.start);
        assert_eq!(r.field.unit(), "nm_per_mw");
        let r = resolve(&base, &FreeParameter::new("hamaker_attractive_j")).unwrap();
        assert_eq!((r.field.factor(), r.start), (1.0, 1e-19));
        let r = resolve(&base, &FreeParameter::new("stiffness_n_per_m")).unwrap();
        assert_eq!(keys(&r), ["air_bearing", "stiffness_n_per_m"]);
        assert_eq!(r.field.unit(), "n_per_m");
        // a unit in which 1 would be refused as a value (σ = 1 µm) names the field all the same
        let r = resolve(&base, &FreeParameter::new("height_sigma_um")).unwrap();
        assert_eq!(keys(&r), ["surface", "height_sigma_m"]);
        assert_eq!((r.field.factor(), r.field.unit()), (1e-6, "um"));
        let r = resolve(&base, &FreeParameter::new("contact_potential_v")).unwrap();
        assert_eq!(r.transform, Transform::Free { x0: 0.0, s: 1.0 });
    }

    #[test]
    fn unknown_and_ambiguous_names_are_refused_by_name() {
        let base = paper();
        let e = resolve(&base, &FreeParameter::new("height_sigma_km")).unwrap_err();
        assert!(e.to_string().contains("--free height_sigma_km"), "{e}");
        let e = resolve(&base, &FreeParameter::new("radius_of_curvature_mm"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("ambiguous") && e.contains("contact.footprint.radius_of_curvature_mm"),
            "{e}"
        );
        let r = resolve(
            &base,
            &FreeParameter::new("contact.footprint.radius_of_curvature_mm"),
        )
        .unwrap();
        assert_eq!(keys(&r), ["contact", "footprint", "radius_of_curvature_m"]);
        let e = resolve(
            &base,
            &FreeParameter::new("height_sigma_nm").bounded(2.0, 1.0),
        )
        .unwrap_err();
        assert!(e.to_string().contains("below upper bound"), "{e}");
    }

    #[test]
    fn transforms_round_trip_and_stay_inside() {
        for t in [
            Transform::Both { lo: 0.2, hi: 2.0 },
            Transform::Lower { lo: 0.0, s: 0.7 },
            Transform::Upper { hi: 1.0, s: 0.5 },
            Transform::Free { x0: 0.0, s: 1.0 },
        ] {
            for x in [0.3, 0.7, 0.9] {
                assert!((t.x(t.u(x)) - x).abs() < 1e-12, "{t:?} {x}");
                let u = t.u(x);
                let fd = (t.x(u + 1e-6) - t.x(u - 1e-6)) / 2e-6;
                assert!((fd - t.dx_du(u)).abs() < 1e-6 * fd.abs().max(1.0));
            }
        }
        let t = Transform::Both { lo: 0.2, hi: 2.0 };
        assert!(t.x(40.0) <= 2.0 && t.x(-40.0) >= 0.2);
    }
}
