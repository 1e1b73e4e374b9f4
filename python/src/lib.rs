//! Python bindings of `hdi-tribology`: a thin layer over the crate's public API.
//!
//! Every function here converts its arguments, calls one function of the crate with the GIL
//! released, and converts the result. Nothing of the physics or the analyses lives here. Inputs
//! are in engineering units where the name says so (`_mw`, `_nm`, `_v`); results carry their
//! SI unit in their name (`power_w`, `d_m`) and engineering-unit properties beside them.

// A Python function's keyword arguments are its options: many arguments are the API here.
#![allow(clippy::too_many_arguments)]

use std::sync::Arc;

use hdi_tribology::analysis::sweep::{self, Flag};
use hdi_tribology::analysis::{
    self, CycleOptions, CycleResult, HeaterProgramme, Refinement, ScanGrid, StaticOptions,
};
use hdi_tribology::calibration::{
    self, CalibrationOptions, ContactForceRms, MeanContactForce, Relative, TouchdownDetector,
    VibrationRms,
};
use hdi_tribology::drive::{
    check_commands, replay_each, scene_zone, sensor_row, Command, CommandRow, DiskSpec, Drive,
    DriveOptions, Plant, SENSOR_COLUMNS,
};
use hdi_tribology::fit::{DataSet, FitError, FitOptions, FreeParameter};
use hdi_tribology::force::{Gaps, RelaxingState};
use hdi_tribology::model::{SliderModel, Voltage};
use hdi_tribology::scene::{FieldPath, PathError};
use hdi_tribology::units;
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::exceptions::{PyKeyError, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

mod bearing;

type Scn = hdi_tribology::scene::Scene;

// ---------------------------------------------------------------------------------------------
// Errors: each crate error becomes the Python exception of `hdi_tribology._errors` of its kind,
// with the crate's fields as attributes.

fn to_py_err(e: hdi_tribology::Error) -> PyErr {
    use hdi_tribology::Error as E;
    let message = e.to_string();
    let (class, attrs): (&str, Vec<(&str, String)>) = match e {
        E::InvalidInput { field, reason } => (
            "InvalidInputError",
            vec![("field", field), ("reason", reason)],
        ),
        E::Scene { origin, reason } => ("SceneError", vec![("origin", origin), ("reason", reason)]),
        E::NoConvergence { what, reason } => (
            "NoConvergenceError",
            vec![("what", what), ("reason", reason)],
        ),
        E::Analysis(a) => (
            "AnalysisError",
            vec![
                ("what", a.stage().to_string()),
                ("reason", a.reason()),
                ("kind", a.kind().to_string()),
            ],
        ),
        E::Output { what, reason } => ("HdiError", vec![("what", what), ("reason", reason)]),
        E::Ode(o) => ("SolverError", vec![("reason", o.to_string())]),
        E::Io { path, source } => (
            "FileError",
            vec![("path", path), ("reason", source.to_string())],
        ),
        other => ("HdiError", vec![("reason", other.to_string())]),
    };
    py_error(class, &message, attrs)
}

/// An instance of the exception class `class` of `hdi_tribology._errors`, with `attrs` set.
fn py_error<V: for<'py> IntoPyObject<'py>>(
    class: &str,
    message: &str,
    attrs: Vec<(&str, V)>,
) -> PyErr {
    Python::attach(|py| {
        let made = (|| -> PyResult<PyErr> {
            let cls = py.import("hdi_tribology._errors")?.getattr(class)?;
            let kwargs = PyDict::new(py);
            for (k, v) in attrs {
                kwargs.set_item(k, v)?;
            }
            let inst = cls.call((message,), Some(&kwargs))?;
            Ok(PyErr::from_value(inst))
        })();
        made.unwrap_or_else(|e| e)
    })
}

/// An error on an argument of a Python function, named as the caller wrote it.
fn invalid(field: &str, reason: impl Into<String>) -> PyErr {
    to_py_err(hdi_tribology::Error::invalid(field, reason))
}

trait OrPy<T> {
    fn py(self) -> PyResult<T>;
}

impl<T> OrPy<T> for hdi_tribology::Result<T> {
    fn py(self) -> PyResult<T> {
        self.map_err(to_py_err)
    }
}

fn json_module(py: Python<'_>) -> PyResult<Bound<'_, PyModule>> {
    py.import("json")
}

// ---------------------------------------------------------------------------------------------
// Scene

/// A whole head–disk interface, validated (see `docs/scene_format.md`).
///
/// Fields are SI with the unit in their name; `scene["surface.height_sigma_nm"]` reads (and
/// assignment writes) any dimensional field in an engineering unit instead.
#[pyclass(module = "hdi_tribology", name = "Scene", eq)]
#[derive(Clone, PartialEq)]
struct Scene {
    inner: Scn,
}

fn scene_to_dict<'py>(py: Python<'py>, s: &Scn) -> PyResult<Bound<'py, PyAny>> {
    let text = s.to_json_string().py()?;
    json_module(py)?.call_method1("loads", (text,))
}

fn scene_from_dict(py: Python<'_>, d: &Bound<'_, PyAny>) -> PyResult<Scn> {
    let text: String = json_module(py)?.call_method1("dumps", (d,))?.extract()?;
    py.detach(|| Scn::from_json_str(&text)).py()
}

/// The scene's serde form (SI), which the library's field paths resolve against.
fn scene_value(s: &Scn) -> PyResult<serde_json::Value> {
    serde_json::to_value(s).map_err(|e| invalid("scene", e.to_string()))
}

/// A name that is not a field of the scene is a `KeyError`; a field without a number to convert
/// to the name's unit a `TypeError`.
fn path_err(e: PathError) -> PyErr {
    match e {
        PathError::NoSection { .. } | PathError::NoField { .. } => {
            PyKeyError::new_err(e.to_string())
        }
        PathError::NotANumber { .. } => PyTypeError::new_err(e.to_string()),
        other => to_py_err(other.into()),
    }
}

fn json_to_py<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    json_module(py)?.call_method1("loads", (v.to_string(),))
}

/// A Python value for the field `path`, as the scene's serde form holds values.
fn py_to_json(py: Python<'_>, path: &str, v: &Bound<'_, PyAny>) -> PyResult<serde_json::Value> {
    let text: String = json_module(py)?.call_method1("dumps", (v,))?.extract()?;
    serde_json::from_str(&text).map_err(|e| {
        invalid(
            path,
            format!("`{text}` is not a value a scene can hold: {e}"),
        )
    })
}

#[pymethods]
impl Scene {
    /// The built-in scene of the letter (SI units inside).
    #[staticmethod]
    fn paper() -> Self {
        Scene {
            inner: Scn::paper(),
        }
    }

    /// Reads a `.toml` or `.json` scene file and validates it.
    #[staticmethod]
    fn from_file(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Self> {
        let inner = py.detach(|| Scn::from_path(&path)).py()?;
        Ok(Scene { inner })
    }

    /// Parses a TOML scene and validates it.
    #[staticmethod]
    fn from_toml(text: &str) -> PyResult<Self> {
        Ok(Scene {
            inner: Scn::from_toml_str(text).py()?,
        })
    }

    /// Parses a JSON scene and validates it.
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        Ok(Scene {
            inner: Scn::from_json_str(text).py()?,
        })
    }

    /// A scene from a dict shaped as the JSON file (fields may use engineering units).
    #[staticmethod]
    fn from_dict(py: Python<'_>, d: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(Scene {
            inner: scene_from_dict(py, d)?,
        })
    }

    /// The scene as a dict of plain Python values, SI units.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        scene_to_dict(py, &self.inner)
    }

    /// The scene as TOML text.
    fn to_toml(&self) -> PyResult<String> {
        self.inner.to_toml_string().py()
    }

    /// The scene as JSON text.
    fn to_json(&self) -> PyResult<String> {
        self.inner.to_json_string().py()
    }

    /// The scene's name.
    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }

    /// A field by its dotted path, in SI (`"surface.height_sigma_m"`) or in an engineering unit
    /// (`"surface.height_sigma_nm"`).
    fn __getitem__<'py>(&self, py: Python<'py>, path: &str) -> PyResult<Bound<'py, PyAny>> {
        let root = scene_value(&self.inner)?;
        let v = FieldPath::at(&root, path)
            .and_then(|f| f.read(&root))
            .map_err(path_err)?;
        json_to_py(py, &v)
    }

    /// Sets a field by its dotted path (SI or engineering unit); the scene is validated again and
    /// left unchanged when the new value is refused.
    fn __setitem__(
        &mut self,
        py: Python<'_>,
        path: &str,
        value: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let updated = PyDict::new(py);
        updated.set_item(path, value)?;
        *self = self.with_values(py, &updated)?;
        Ok(())
    }

    /// A copy with the given fields (dotted paths, SI or engineering units) replaced, validated.
    fn with_values(&self, py: Python<'_>, values: &Bound<'_, PyDict>) -> PyResult<Self> {
        let mut root = scene_value(&self.inner)?;
        for (k, v) in values.iter() {
            let path: String = k.extract()?;
            let value = py_to_json(py, &path, &v)?;
            FieldPath::at(&root, &path)
                .map_err(path_err)?
                .write(&mut root, value);
        }
        let text = root.to_string();
        Ok(Scene {
            inner: py.detach(|| Scn::from_json_str(&text)).py()?,
        })
    }

    fn __repr__(&self) -> String {
        format!("Scene(name={:?})", self.inner.name)
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        let text = slf.borrow().inner.to_json_string().py()?;
        Ok((slf.get_type().getattr("from_json")?, (text,)))
    }
}

// ---------------------------------------------------------------------------------------------
// Model

/// A scene built into the slider model: force tables, air bearing, heater and voltage. Building
/// takes a fraction of a second; analyses of the same scene should share one model.
#[pyclass(module = "hdi_tribology", name = "Model", frozen)]
struct Model {
    scene: Arc<Scn>,
    model: Arc<SliderModel>,
}

#[pymethods]
impl Model {
    #[new]
    fn new(py: Python<'_>, scene: &Scene) -> PyResult<Self> {
        let scene = Arc::new(scene.inner.clone());
        let s = scene.clone();
        let model = py.detach(move || SliderModel::from_scene(&s)).py()?;
        Ok(Model {
            scene,
            model: Arc::new(model),
        })
    }

    /// The structure's preset, as the scene file names it: `"rigid"`, `"bulge"`, `"pitch"` or
    /// `"general"`.
    #[getter]
    fn structure(&self) -> &'static str {
        self.scene.structure.preset()
    }

    /// Degrees of freedom of the structure: the length of `Equilibrium.q` and `Mode.shape`.
    #[getter]
    fn dofs(&self) -> usize {
        self.model.structure().dofs()
    }

    /// The same model with one more state of its own: `x` relaxing towards `target_per_nm`
    /// times the bulge gap (nm) with time constant `tau_s` (s), adding the force
    /// `force_un_per_state` · x (µN), and starting from `start` (its equilibrium when `None`).
    /// With the defaults it is the pure relaxation `x(t) = start · e^{−t/τ}`, which changes
    /// nothing else: a check that every analysis carries the states of terms with memory
    /// (`term_states` of `simulate_cycle` and of `Drive`).
    #[pyo3(signature = (tau_s, start = None, *, target_per_nm = 0.0, force_un_per_state = 0.0))]
    fn with_relaxing_state(
        &self,
        tau_s: f64,
        start: Option<f64>,
        target_per_nm: f64,
        force_un_per_state: f64,
    ) -> PyResult<Self> {
        let term = RelaxingState::new(tau_s, target_per_nm * 1e9, force_un_per_state * 1e-6, start)
            .map_err(|e| match e {
                hdi_tribology::Error::InvalidInput { field, reason } => {
                    let arg = match field.as_str() {
                        "relaxing_state.tau_s" => "tau_s",
                        "relaxing_state.target_per_m" => "target_per_nm",
                        "relaxing_state.force_n" => "force_un_per_state",
                        "relaxing_state.start" => "start",
                        other => other,
                    };
                    invalid(arg, reason)
                }
                other => to_py_err(other),
            })?;
        Ok(Model {
            scene: self.scene.clone(),
            model: Arc::new(self.model.with_stateful_term(term).py()?),
        })
    }

    /// The scene the model was built from (a copy).
    #[getter]
    fn scene(&self) -> Scene {
        Scene {
            inner: (*self.scene).clone(),
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "Model(scene={:?}, structure={:?})",
            self.scene.name,
            self.structure()
        )
    }
}

/// A `Model`, built from a `Scene` where one is given.
fn model_of(py: Python<'_>, target: &Bound<'_, PyAny>) -> PyResult<(Arc<Scn>, Arc<SliderModel>)> {
    if let Ok(m) = target.cast::<Model>() {
        let m = m.get();
        return Ok((m.scene.clone(), m.model.clone()));
    }
    if let Ok(s) = target.cast::<Scene>() {
        let m = Model::new(py, &s.borrow())?;
        return Ok((m.scene, m.model));
    }
    Err(pyo3::exceptions::PyTypeError::new_err(
        "expected a hdi_tribology.Model or hdi_tribology.Scene",
    ))
}

// ---------------------------------------------------------------------------------------------
// Forces

fn array<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyAny> {
    PyArray1::from_vec(py, v).into_any()
}

/// Every interface force at bulge gaps `gaps_nm` (nm), pad gaps `gaps_nm + protrusion_nm`, at
/// the scene's DC voltage. Returns a dict of float64 arrays shaped as `gaps_nm`: `d_m` (m),
/// `intermolecular_n`, `contact_n`, `electrostatic_n`, `other_n`, `total_n` (N, positive away
/// from the disk), `electrostatic_per_volt2_n_per_v2` (N/V²), `real_contact_area_m2` (m²).
#[pyfunction]
#[pyo3(signature = (target, gaps_nm, protrusion_nm = 0.0))]
fn forces<'py>(
    py: Python<'py>,
    target: &Bound<'py, PyAny>,
    gaps_nm: PyReadonlyArray1<'py, f64>,
    protrusion_nm: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let gaps: Vec<f64> = gaps_nm.as_array().iter().map(|&g| units::nm(g)).collect();
    for (i, &g) in gaps.iter().enumerate() {
        if !g.is_finite() {
            return Err(invalid(
                &format!("gaps_nm[{i}]"),
                format!("must be finite, got {g:?}"),
            ));
        }
    }
    if !protrusion_nm.is_finite() {
        return Err(invalid(
            "protrusion_nm",
            format!("must be finite, got {protrusion_nm:?}"),
        ));
    }
    let protrusion = units::nm(protrusion_nm);
    let (scene, model) = model_of(py, target)?;
    let (lo, hi) = model.forces().table_range();
    let in_range: Vec<bool> = gaps
        .iter()
        .map(|&d| (lo..=hi).contains(&d) && (lo..=hi).contains(&(d + protrusion)))
        .collect();
    let rows = py.detach(|| {
        let volt2 = scene.dc_volt2();
        gaps.iter()
            .map(|&d| {
                model.breakdown(
                    Gaps {
                        bulge: d,
                        pad: d + protrusion,
                    },
                    volt2,
                )
            })
            .collect::<Vec<_>>()
    });
    let out = PyDict::new(py);
    let col = |f: fn(&hdi_tribology::force::Breakdown) -> f64| rows.iter().map(f).collect();
    out.set_item("d_m", array(py, gaps))?;
    out.set_item("intermolecular_n", array(py, col(|b| b.intermolecular)))?;
    out.set_item("contact_n", array(py, col(|b| b.contact)))?;
    out.set_item(
        "electrostatic_per_volt2_n_per_v2",
        array(py, col(|b| b.electrostatic_per_volt2)),
    )?;
    out.set_item("electrostatic_n", array(py, col(|b| b.electrostatic)))?;
    out.set_item("other_n", array(py, col(|b| b.other)))?;
    out.set_item(
        "real_contact_area_m2",
        array(py, col(|b| b.real_contact_area)),
    )?;
    out.set_item("total_n", array(py, col(|b| b.total)))?;
    out.set_item("in_table_range", PyArray1::from_vec(py, in_range))?;
    Ok(out)
}

// ---------------------------------------------------------------------------------------------
// Static analyses

/// A static equilibrium of the slider.
#[pyclass(module = "hdi_tribology", frozen, get_all)]
#[derive(Clone)]
struct Equilibrium {
    /// Bulge gap (m).
    d_m: f64,
    /// Head displacement away from the disk (m).
    y_m: f64,
    /// Thermal protrusion (m).
    protrusion_m: f64,
    /// Heater power (W).
    power_w: f64,
    /// Total stiffness (N/m).
    stiffness_n_per_m: f64,
    /// Interface force (N).
    interface_force_n: f64,
    /// Contact force (N).
    contact_force_n: f64,
    /// Whether the equilibrium is stable.
    stable: bool,
    /// Every coordinate of the structure (m for displacements, rad for the pitch; one per degree
    /// of freedom: `[y]` for the rigid slider, `[y, z]` for `bulge`, `[y, θ]` for `pitch`).
    q: Vec<f64>,
}

impl Equilibrium {
    /// The equilibrium `e` of a structure of `dofs` coordinates.
    fn of(e: &analysis::Equilibrium, dofs: usize) -> Self {
        Equilibrium {
            q: e.q.iter().take(dofs).copied().collect(),
            d_m: e.d,
            y_m: e.y,
            protrusion_m: e.protrusion,
            power_w: e.power,
            stiffness_n_per_m: e.stiffness,
            interface_force_n: e.interface_force,
            contact_force_n: e.contact_force,
            stable: e.is_stable(),
        }
    }
}

#[pymethods]
impl Equilibrium {
    /// Bulge gap (nm).
    #[getter]
    fn d_nm(&self) -> f64 {
        units::to_nm(self.d_m)
    }
    /// Heater power (mW).
    #[getter]
    fn power_mw(&self) -> f64 {
        units::to_mw(self.power_w)
    }
    fn __repr__(&self) -> String {
        format!(
            "Equilibrium(d_nm={:.4}, power_mw={:.4}, stiffness_n_per_m={:.4e}, stable={})",
            self.d_nm(),
            self.power_mw(),
            self.stiffness_n_per_m,
            if self.stable { "True" } else { "False" }
        )
    }
}

/// A touchdown or take-off on the static equilibria.
#[pyclass(module = "hdi_tribology", frozen, get_all)]
#[derive(Clone)]
struct Transition {
    /// Heater power (W).
    power_w: f64,
    /// `"fold"` (the branch ends) or `"threshold"` (the contact force crosses the detector's).
    cause: String,
    /// The equilibrium where it happens.
    at: Equilibrium,
}

fn cause_name(c: analysis::Cause) -> String {
    match c {
        analysis::Cause::Fold => "fold".into(),
        analysis::Cause::Threshold => "threshold".into(),
    }
}

impl Transition {
    fn of(t: &analysis::Transition, dofs: usize) -> Self {
        Transition {
            power_w: t.power,
            cause: cause_name(t.cause),
            at: Equilibrium::of(&t.at, dofs),
        }
    }
}

#[pymethods]
impl Transition {
    /// Heater power (mW).
    #[getter]
    fn power_mw(&self) -> f64 {
        units::to_mw(self.power_w)
    }
    fn __repr__(&self) -> String {
        format!(
            "Transition(power_mw={:.4}, cause={:?}, d_nm={:.4})",
            self.power_mw(),
            self.cause,
            self.at.d_nm()
        )
    }
}

/// Static touchdown, take-off and their hysteresis.
#[pyclass(module = "hdi_tribology", frozen, get_all)]
struct StaticHysteresis {
    /// Touchdown.
    touchdown: Transition,
    /// Take-off.
    takeoff: Transition,
    /// Touchdown minus take-off power (W).
    hysteresis_w: f64,
}

#[pymethods]
impl StaticHysteresis {
    /// Touchdown minus take-off power (mW).
    #[getter]
    fn hysteresis_mw(&self) -> f64 {
        units::to_mw(self.hysteresis_w)
    }
    fn __repr__(&self) -> String {
        format!(
            "StaticHysteresis(touchdown_mw={:.4}, takeoff_mw={:.4}, hysteresis_mw={:.4})",
            self.touchdown.power_mw(),
            self.takeoff.power_mw(),
            self.hysteresis_mw()
        )
    }
}

fn static_options(scene: &Scn, threshold_un: Option<f64>) -> PyResult<StaticOptions> {
    let threshold = match threshold_un {
        Some(t) if !(t.is_finite() && t > 0.0) => {
            return Err(invalid(
                "contact_threshold_un",
                format!("must be finite and > 0 µN, got {t:?}"),
            ))
        }
        Some(t) => t * 1e-6,
        None => scene.detector.contact_threshold_n,
    };
    Ok(StaticOptions::new(threshold))
}

/// Static touchdown and take-off powers at the scene's DC voltage, with the contact threshold
/// of the scene's detector (or `contact_threshold_un`, µN).
#[pyfunction]
#[pyo3(signature = (target, contact_threshold_un = None))]
fn static_hysteresis(
    py: Python<'_>,
    target: &Bound<'_, PyAny>,
    contact_threshold_un: Option<f64>,
) -> PyResult<StaticHysteresis> {
    let (scene, model) = model_of(py, target)?;
    let opts = static_options(&scene, contact_threshold_un)?;
    let h = py
        .detach(|| analysis::static_hysteresis(&model, &opts))
        .py()?;
    let dofs = model.structure().dofs();
    Ok(StaticHysteresis {
        touchdown: Transition::of(&h.touchdown, dofs),
        takeoff: Transition::of(&h.takeoff, dofs),
        hysteresis_w: h.hysteresis,
    })
}

/// The pull-in voltage.
#[pyclass(module = "hdi_tribology", frozen, get_all)]
struct PullIn {
    /// Pull-in voltage |V − φ| (V).
    voltage_v: f64,
    /// Bulge gap where the head jumps in (m).
    d_m: f64,
    /// `"fold"` or `"threshold"`.
    cause: String,
}

#[pymethods]
impl PullIn {
    fn __repr__(&self) -> String {
        format!(
            "PullIn(voltage_v={:.4}, d_nm={:.4}, cause={:?})",
            self.voltage_v,
            units::to_nm(self.d_m),
            self.cause
        )
    }
}

/// The voltage that pulls the head into contact at heater power `power_mw` (mW).
#[pyfunction]
#[pyo3(signature = (target, power_mw = 0.0, contact_threshold_un = None))]
fn pull_in_voltage(
    py: Python<'_>,
    target: &Bound<'_, PyAny>,
    power_mw: f64,
    contact_threshold_un: Option<f64>,
) -> PyResult<PullIn> {
    let (scene, model) = model_of(py, target)?;
    let opts = static_options(&scene, contact_threshold_un)?;
    let p = py
        .detach(|| analysis::pull_in_voltage(&model, units::mw(power_mw), &opts))
        .py()?;
    Ok(PullIn {
        voltage_v: p.voltage,
        d_m: p.d,
        cause: cause_name(p.cause),
    })
}

/// Clearance change with DC voltage (the letter's Fig. 2b). Returns a dict of float64 arrays:
/// `dc_voltage_v` (V), `touchdown_power_w` (W), `clearance_change_m` (m).
#[pyfunction]
#[pyo3(signature = (target, dc_voltages_v, contact_threshold_un = None))]
fn clearance_change<'py>(
    py: Python<'py>,
    target: &Bound<'py, PyAny>,
    dc_voltages_v: Vec<f64>,
    contact_threshold_un: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let (scene, model) = model_of(py, target)?;
    let opts = static_options(&scene, contact_threshold_un)?;
    let rows = py
        .detach(|| analysis::clearance_change(&model, &dc_voltages_v, &opts))
        .py()?;
    let out = PyDict::new(py);
    out.set_item(
        "dc_voltage_v",
        array(py, rows.iter().map(|r| r.dc_voltage).collect()),
    )?;
    out.set_item(
        "touchdown_power_w",
        array(py, rows.iter().map(|r| r.touchdown_power).collect()),
    )?;
    out.set_item(
        "clearance_change_m",
        array(py, rows.iter().map(|r| r.clearance_change).collect()),
    )?;
    Ok(out)
}

/// The S-curve of static equilibria along the bulge gap, at the scene's DC voltage. Returns a
/// dict: float64 arrays `d_m`, `power_w`, `y_m`, `stiffness_n_per_m`, `contact_force_n`, a
/// bool array `stable`, and `folds`, a list of dicts `{power_w, d_m, jump_in}`.
#[pyfunction]
fn s_curve<'py>(py: Python<'py>, target: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
    let (_, model) = model_of(py, target)?;
    let c = py
        .detach(|| analysis::s_curve(&model, None, &ScanGrid::default()))
        .py()?;
    let out = PyDict::new(py);
    let col = |f: fn(&analysis::Equilibrium) -> f64| c.points.iter().map(f).collect();
    out.set_item("d_m", array(py, col(|e| e.d)))?;
    out.set_item("power_w", array(py, col(|e| e.power)))?;
    out.set_item("y_m", array(py, col(|e| e.y)))?;
    out.set_item("stiffness_n_per_m", array(py, col(|e| e.stiffness)))?;
    out.set_item("contact_force_n", array(py, col(|e| e.contact_force)))?;
    let stable: Vec<bool> = c.points.iter().map(|e| e.is_stable()).collect();
    out.set_item("stable", PyArray1::from_vec(py, stable))?;
    let folds = PyList::empty(py);
    for f in &c.folds {
        let d = PyDict::new(py);
        d.set_item("power_w", f.power)?;
        d.set_item("d_m", f.d)?;
        d.set_item("jump_in", f.jump_in)?;
        folds.append(d)?;
    }
    out.set_item("folds", folds)?;
    Ok(out)
}

// ---------------------------------------------------------------------------------------------
// Cycles and sweeps

/// A detected touchdown or take-off in a cycle.
#[pyclass(module = "hdi_tribology", frozen, get_all)]
#[derive(Clone)]
struct Detection {
    /// Time of detection (s).
    time_s: f64,
    /// Programme heater power then (W).
    power_w: f64,
}

#[pymethods]
impl Detection {
    /// Programme heater power then (mW).
    #[getter]
    fn power_mw(&self) -> f64 {
        units::to_mw(self.power_w)
    }
    fn __repr__(&self) -> String {
        format!(
            "Detection(time_s={:.6e}, power_mw={:.4})",
            self.time_s,
            self.power_mw()
        )
    }
}

fn detection(d: Option<analysis::cycle::Detection>) -> Option<Detection> {
    d.map(|d| Detection {
        time_s: d.time,
        power_w: d.power,
    })
}

/// One touchdown/take-off cycle, without its time series.
#[pyclass(module = "hdi_tribology", frozen, get_all)]
#[derive(Clone)]
struct Cycle {
    /// AC amplitude (V).
    v_ac_v: f64,
    /// Touchdown, `None` if none was detected.
    touchdown: Option<Detection>,
    /// Take-off, `None` if none was detected.
    takeoff: Option<Detection>,
    /// Touchdown minus take-off power (W), `None` unless both were detected.
    hysteresis_w: Option<f64>,
    /// Mean flash temperature rise while in contact (K).
    mean_temperature_rise_k: f64,
    /// Simulated time (s).
    duration_s: f64,
    /// Accepted solver steps.
    steps: usize,
    /// Rejected solver steps.
    rejected_steps: usize,
    /// Wall time of the simulation in Rust (s).
    wall_seconds: f64,
    /// What is wrong with the cycle, empty when nothing is: `no_touchdown`, `no_takeoff`,
    /// `negative_hysteresis` (a detection artefact, not a hysteresis).
    flags: Vec<String>,
}

impl From<&CycleResult> for Cycle {
    fn from(r: &CycleResult) -> Self {
        Cycle {
            v_ac_v: r.v_ac,
            touchdown: detection(r.touchdown),
            takeoff: detection(r.takeoff),
            hysteresis_w: r.hysteresis,
            mean_temperature_rise_k: r.mean_temperature_rise,
            duration_s: r.duration,
            steps: r.stats.accepted,
            rejected_steps: r.stats.rejected,
            wall_seconds: r.wall_seconds,
            flags: flag_names(&sweep::flags(r)),
        }
    }
}

/// The crate's flags by their snake_case names (`no_touchdown`, `negative_hysteresis`, …), as
/// the `hdi` program prints them.
fn flag_names(flags: &[Flag]) -> Vec<String> {
    flags
        .iter()
        .map(|f| match serde_json::to_value(f) {
            Ok(serde_json::Value::String(s)) => s,
            _ => f.to_string(),
        })
        .collect()
}

fn fmt_flags(flags: &[String]) -> String {
    if flags.is_empty() {
        String::new()
    } else {
        format!(", flags={flags:?}")
    }
}

fn fmt_opt_mw(x: Option<f64>) -> String {
    x.map_or("None".into(), |p| format!("{:.4}", units::to_mw(p)))
}

#[pymethods]
impl Cycle {
    /// Touchdown minus take-off power (mW), `None` unless both were detected.
    #[getter]
    fn hysteresis_mw(&self) -> Option<f64> {
        self.hysteresis_w.map(units::to_mw)
    }
    fn __repr__(&self) -> String {
        format!(
            "Cycle(v_ac_v={}, touchdown_mw={}, takeoff_mw={}, hysteresis_mw={}, steps={}{})",
            self.v_ac_v,
            fmt_opt_mw(self.touchdown.as_ref().map(|d| d.power_w)),
            fmt_opt_mw(self.takeoff.as_ref().map(|d| d.power_w)),
            fmt_opt_mw(self.hysteresis_w),
            self.steps,
            fmt_flags(&self.flags)
        )
    }
}

/// How a cycle is run: programme, options and the AC amplitude override.
struct CycleSetup {
    scene: Arc<Scn>,
    model: Arc<SliderModel>,
    programme: HeaterProgramme,
    opts: CycleOptions,
}

fn cycle_setup(
    py: Python<'_>,
    target: &Bound<'_, PyAny>,
    triggered: bool,
    method: Option<&str>,
    rtol: Option<f64>,
    atol_nm: Option<f64>,
) -> PyResult<CycleSetup> {
    let (scene, model) = model_of(py, target)?;
    let mut opts = CycleOptions::from_scene(&scene).py()?;
    if let Some(m) = method {
        opts.solver.method = m
            .parse()
            .map_err(|e: hdi_tribology::ode::OdeError| invalid("method", e.to_string()))?;
    }
    // as `hdi cycle`: a new rtol scales the absolute tolerance with it unless that is given
    if let Some(r) = rtol {
        opts.solver.atol_displacement *= r / opts.solver.rtol;
        opts.solver.rtol = r;
    }
    if let Some(a) = atol_nm {
        opts.solver.atol_displacement = units::nm(a);
    }
    let programme = if triggered {
        HeaterProgramme::triggered_from_scene(&scene)
    } else {
        HeaterProgramme::fixed_from_scene(&scene).py()?
    };
    Ok(CycleSetup {
        scene,
        model,
        programme,
        opts,
    })
}

/// One touchdown/take-off cycle under the scene's heater programme (or the touchdown-triggered
/// protocol), at AC amplitude `v_ac` (V; default: the scene's).
///
/// Returns a dict: the summary `cycle` (a `Cycle`), `touchdown` and `takeoff` (`Detection` or
/// `None`), and with `series=True` float64 arrays, one value per accepted step: `t_s` (s),
/// `power_w` (W), `d_m` (m), `air_bearing_n`, `intermolecular_n`, `electrostatic_n`,
/// `contact_n`, `total_n` (N), `temperature_rise_k` (K), `indicator_n` (N, NaN before the
/// detector window has filled).
#[pyfunction]
#[pyo3(signature = (target, v_ac = None, *, triggered = false, method = None, rtol = None, atol_nm = None, series = true))]
fn simulate_cycle<'py>(
    py: Python<'py>,
    target: &Bound<'py, PyAny>,
    v_ac: Option<f64>,
    triggered: bool,
    method: Option<&str>,
    rtol: Option<f64>,
    atol_nm: Option<f64>,
    series: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let mut setup = cycle_setup(py, target, triggered, method, rtol, atol_nm)?;
    setup.opts.keep_series = series;
    let r = py
        .detach(|| match v_ac {
            Some(a) => {
                let m = setup.model.with_voltage(Voltage {
                    ac_amplitude: a,
                    ..setup.model.voltage()
                });
                analysis::simulate_cycle(&m, &setup.programme, &setup.opts)
            }
            None => analysis::simulate_cycle(&setup.model, &setup.programme, &setup.opts),
        })
        .py()?;
    let out = PyDict::new(py);
    let summary = Cycle::from(&r);
    out.set_item("touchdown", summary.touchdown.clone())?;
    out.set_item("takeoff", summary.takeoff.clone())?;
    out.set_item("cycle", summary)?;
    if let Some(s) = r.series {
        out.set_item("t_s", array(py, s.t))?;
        out.set_item("power_w", array(py, s.power))?;
        out.set_item("d_m", array(py, s.d))?;
        out.set_item("air_bearing_n", array(py, s.air_bearing))?;
        out.set_item("intermolecular_n", array(py, s.intermolecular))?;
        out.set_item("electrostatic_n", array(py, s.electrostatic))?;
        out.set_item("contact_n", array(py, s.contact))?;
        out.set_item("total_n", array(py, s.total))?;
        out.set_item("temperature_rise_k", array(py, s.temperature_rise))?;
        out.set_item("indicator_n", array(py, s.indicator))?;
        if !s.term_states.is_empty() {
            let rows: Vec<Vec<f64>> = s.term_states;
            out.set_item("term_states", numpy::PyArray2::from_vec2(py, &rows)?)?;
        }
    }
    Ok(out)
}

/// Runs `work` on a rayon pool of `threads` threads (the global pool when `None`).
fn on_threads<T: Send>(
    threads: Option<usize>,
    work: impl FnOnce() -> hdi_tribology::Result<T> + Send,
) -> PyResult<T> {
    match threads {
        None => work().py(),
        Some(0) => Err(invalid("threads", "must be at least 1, got 0")),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| invalid("threads", e.to_string()))?
            .install(work)
            .py(),
    }
}

fn amplitudes_or_scene(scene: &Scn, amplitudes_v: Option<Vec<f64>>) -> PyResult<Vec<f64>> {
    let a = amplitudes_v.unwrap_or_else(|| scene.sweep.ac_amplitudes_v.clone());
    if a.is_empty() {
        return Err(invalid(
            "amplitudes_v",
            "no amplitudes: give a list or a [sweep] list in the scene",
        ));
    }
    Ok(a)
}

/// One cycle per AC amplitude (V; default: the scene's sweep list), in parallel on rayon
/// (`threads` threads, default all cores) with the GIL released. Returns a list of `Cycle`, in
/// the order of the amplitudes; results do not depend on the thread count.
#[pyfunction]
#[pyo3(signature = (target, amplitudes_v = None, *, triggered = false, method = None, rtol = None, atol_nm = None, threads = None))]
fn ac_sweep(
    py: Python<'_>,
    target: &Bound<'_, PyAny>,
    amplitudes_v: Option<Vec<f64>>,
    triggered: bool,
    method: Option<&str>,
    rtol: Option<f64>,
    atol_nm: Option<f64>,
    threads: Option<usize>,
) -> PyResult<Vec<Cycle>> {
    let setup = cycle_setup(py, target, triggered, method, rtol, atol_nm)?;
    let amplitudes = amplitudes_or_scene(&setup.scene, amplitudes_v)?;
    let rows = py.detach(|| {
        on_threads(threads, || {
            analysis::ac_sweep(&setup.model, &setup.programme, &setup.opts, &amplitudes)
        })
    })?;
    Ok(rows.iter().map(Cycle::from).collect())
}

/// A cycle run at tighter and tighter tolerances until its powers settle.
#[pyclass(module = "hdi_tribology", frozen, get_all)]
struct RefinedCycle {
    /// The last (most accurate) cycle.
    cycle: Cycle,
    /// Its relative tolerance.
    rtol: f64,
    /// Its absolute tolerance on the displacement (m).
    atol_m: f64,
    /// Largest change of touchdown or take-off power from the run before (W); infinite when a
    /// detection came or went between the two.
    power_change_w: f64,
    /// Change of the mean temperature rise from the run before (K).
    temperature_change_k: f64,
    /// Whether both changes are within the tolerances asked for.
    converged: bool,
    /// `"converged"` or `"not_converged"`.
    status: String,
    /// The cycle's flags, and `not_converged`.
    flags: Vec<String>,
    /// Cycles run.
    runs: usize,
    /// Accepted steps over all runs.
    steps: usize,
    /// Wall time over all runs (s).
    wall_seconds: f64,
}

#[pymethods]
impl RefinedCycle {
    fn __repr__(&self) -> String {
        format!(
            "RefinedCycle(v_ac_v={}, hysteresis_mw={}, rtol={:e}, power_change_mw={:.3e}, status={:?}, runs={}{})",
            self.cycle.v_ac_v,
            fmt_opt_mw(self.cycle.hysteresis_w),
            self.rtol,
            units::to_mw(self.power_change_w),
            self.status,
            self.runs,
            fmt_flags(&self.flags)
        )
    }
}

/// `ac_sweep` with the tolerances refined per amplitude (tenfold tighter per run, at most
/// `max_runs` runs) until touchdown and take-off move by at most `power_tol_mw` (mW) and the
/// mean temperature rise by at most `temperature_tol_k` (K) over `agreeing_runs` successive runs.
/// Returns a list of `RefinedCycle`; check `converged` (or `flags`) before trusting a row.
#[pyfunction]
#[pyo3(signature = (target, power_tol_mw, amplitudes_v = None, *, temperature_tol_k = 0.05, max_runs = 4, agreeing_runs = 2, triggered = false, method = None, rtol = None, atol_nm = None, threads = None))]
fn ac_sweep_refined(
    py: Python<'_>,
    target: &Bound<'_, PyAny>,
    power_tol_mw: f64,
    amplitudes_v: Option<Vec<f64>>,
    temperature_tol_k: f64,
    max_runs: usize,
    agreeing_runs: usize,
    triggered: bool,
    method: Option<&str>,
    rtol: Option<f64>,
    atol_nm: Option<f64>,
    threads: Option<usize>,
) -> PyResult<Vec<RefinedCycle>> {
    let setup = cycle_setup(py, target, triggered, method, rtol, atol_nm)?;
    let amplitudes = amplitudes_or_scene(&setup.scene, amplitudes_v)?;
    let refine = Refinement {
        temperature_tol: temperature_tol_k,
        max_runs,
        agreeing_runs,
        ..Refinement::new(units::mw(power_tol_mw))
    };
    let rows = py.detach(|| {
        on_threads(threads, || {
            analysis::ac_sweep_refined(
                &setup.model,
                &setup.programme,
                &setup.opts,
                &amplitudes,
                &refine,
            )
        })
    })?;
    Ok(rows
        .iter()
        .map(|r| RefinedCycle {
            cycle: Cycle::from(&r.cycle),
            rtol: r.rtol,
            atol_m: r.atol,
            power_change_w: r.change,
            temperature_change_k: r.temperature_change,
            converged: r.converged,
            status: if r.converged {
                "converged"
            } else {
                "not_converged"
            }
            .into(),
            flags: flag_names(&r.flags()),
            runs: r.runs,
            steps: r.stats.accepted,
            wall_seconds: r.wall_seconds,
        })
        .collect())
}

// ---------------------------------------------------------------------------------------------
// Linear response

/// One mode of the linearised slider.
#[pyclass(module = "hdi_tribology", frozen, get_all)]
#[derive(Clone)]
struct Mode {
    /// Eigenvalue λ (1/s), complex.
    eigenvalue: numpy::Complex64,
    /// `|Im λ| / 2π` (Hz).
    frequency_hz: f64,
    /// Damping ratio `−Re λ / |λ|`.
    damping_ratio: f64,
    /// Mode shape over the structure's coordinates (one per degree of freedom, as
    /// `Equilibrium.q`): the eigenvector's displacement part scaled so that its largest entry is
    /// 1 and rotated to be real there. All zero for a mode of the lags alone (thermal or
    /// interface lag), which moves no coordinate.
    shape: Vec<f64>,
}

#[pymethods]
impl Mode {
    fn __repr__(&self) -> String {
        format!(
            "Mode(frequency_hz={:.6e}, damping_ratio={:.4e}, shape={:?})",
            self.frequency_hz, self.damping_ratio, self.shape
        )
    }
}

/// The linear response about the flying equilibrium at one heater power.
#[pyclass(module = "hdi_tribology", frozen)]
struct LinearResponse {
    inner: analysis::LinearResponse,
    dofs: usize,
}

#[pymethods]
impl LinearResponse {
    /// The equilibrium (under the mean V²).
    #[getter]
    fn equilibrium(&self) -> Equilibrium {
        Equilibrium::of(&self.inner.equilibrium, self.dofs)
    }
    /// Every mode (`Mode`: eigenvalue, frequency, damping ratio, shape), by ascending
    /// frequency: one pair of complex eigenvalues per vibrating degree of freedom, plus real ones
    /// for overdamped motions and lags.
    #[getter]
    fn modes(&self) -> Vec<Mode> {
        self.inner
            .modes
            .iter()
            .map(|m| Mode {
                eigenvalue: numpy::Complex64::new(m.re, m.im),
                frequency_hz: m.frequency,
                damping_ratio: m.damping_ratio,
                shape: m.shape.iter().take(self.dofs).copied().collect(),
            })
            .collect()
    }
    /// Eigenvalues as complex numbers (1/s).
    #[getter]
    fn eigenvalues(&self) -> Vec<numpy::Complex64> {
        self.inner
            .modes
            .iter()
            .map(|m| numpy::Complex64::new(m.re, m.im))
            .collect()
    }
    /// Mode frequencies |Im λ|/2π (Hz).
    #[getter]
    fn frequencies_hz(&self) -> Vec<f64> {
        self.inner.modes.iter().map(|m| m.frequency).collect()
    }
    /// Damping ratios −Re λ/|λ|.
    #[getter]
    fn damping_ratios(&self) -> Vec<f64> {
        self.inner.modes.iter().map(|m| m.damping_ratio).collect()
    }
    /// Whether every eigenvalue has a negative real part.
    #[getter]
    fn stable(&self) -> bool {
        self.inner.stable
    }
    /// |H(i·2π·2f)| (m/N).
    #[getter]
    fn gain_at_2f_m_per_n(&self) -> f64 {
        self.inner.gain_at_2f
    }
    /// Force amplitude at 2f (N).
    #[getter]
    fn force_at_2f_n(&self) -> f64 {
        self.inner.force_at_2f
    }
    /// Predicted dither amplitude at 2f (m).
    #[getter]
    fn dither_amplitude_m(&self) -> f64 {
        self.inner.dither_amplitude
    }
    /// Predicted dither amplitude at 2f (nm).
    #[getter]
    fn dither_amplitude_nm(&self) -> f64 {
        units::to_nm(self.inner.dither_amplitude)
    }
    /// H(iω) (m/N) at each angular frequency `omega_rad_s` (rad/s), a complex128 array.
    fn transfer<'py>(
        &self,
        py: Python<'py>,
        omega_rad_s: PyReadonlyArray1<'py, f64>,
    ) -> Bound<'py, PyArray1<numpy::Complex64>> {
        let w: Vec<f64> = omega_rad_s.as_array().to_vec();
        let h: Vec<_> = py.detach(|| w.iter().map(|&w| self.inner.transfer(w)).collect());
        PyArray1::from_vec(py, h)
    }
    fn __repr__(&self) -> String {
        format!(
            "LinearResponse(power_mw={:.4}, d_nm={:.4}, stable={}, dither_amplitude_nm={:.4e})",
            units::to_mw(self.inner.equilibrium.power),
            units::to_nm(self.inner.equilibrium.d),
            if self.inner.stable { "True" } else { "False" },
            self.dither_amplitude_nm()
        )
    }
}

/// The linearised slider about its flying equilibrium at heater power `power_mw` (mW).
#[pyfunction]
fn linear_response(
    py: Python<'_>,
    target: &Bound<'_, PyAny>,
    power_mw: f64,
) -> PyResult<LinearResponse> {
    let (_, model) = model_of(py, target)?;
    let inner = py
        .detach(|| analysis::linear_response(&model, units::mw(power_mw)))
        .py()?;
    Ok(LinearResponse {
        inner,
        dofs: model.structure().dofs(),
    })
}

/// The model at AC amplitude `v_ac` (V), or the model itself when `None`.
fn at_amplitude(model: &SliderModel, v_ac: Option<f64>) -> PyResult<Option<SliderModel>> {
    match v_ac {
        None => Ok(None),
        Some(a) if !a.is_finite() => Err(invalid("v_ac", format!("must be finite, got {a:?} V"))),
        Some(a) => Ok(Some(model.with_voltage(Voltage {
            ac_amplitude: a,
            ..model.voltage()
        }))),
    }
}

/// The stable flying equilibrium at heater power `power_mw` (mW), reached scanning down from the
/// largest tabulated gap, under the time-mean V² of the voltage (the scene's, with AC amplitude
/// `v_ac` in V when given): the equilibrium `linear_response` linearises about. Raises
/// `NoConvergenceError`/`AnalysisError` when the flying branch ends (fold) below that power:
/// the head is then in contact.
#[pyfunction]
#[pyo3(signature = (target, power_mw, *, v_ac = None))]
fn flying_equilibrium(
    py: Python<'_>,
    target: &Bound<'_, PyAny>,
    power_mw: f64,
    v_ac: Option<f64>,
) -> PyResult<Equilibrium> {
    let (_, model) = model_of(py, target)?;
    let changed = at_amplitude(&model, v_ac)?;
    let m: &SliderModel = changed.as_ref().unwrap_or(&model);
    let e = py
        .detach(|| {
            analysis::flying_equilibrium(
                m,
                units::mw(power_mw),
                m.voltage().mean_squared(),
                &ScanGrid::default(),
            )
        })
        .py()?;
    Ok(Equilibrium::of(&e, model.structure().dofs()))
}

/// The dither of the bulge at twice the AC frequency from a simulation at constant heater power
/// `power_mw` (mW) and AC amplitude `v_ac` (V; default the scene's): half the peak-to-peak
/// bulge displacement over the last `periods` periods of V², after `settle` periods for the
/// start-up transient, in m. The simulated counterpart of `LinearResponse.dither_amplitude_m`.
/// Raises `AnalysisError` when the voltage has no AC part.
#[pyfunction]
#[pyo3(signature = (target, power_mw, v_ac = None, *, settle = 40, periods = 10, method = None, rtol = None, atol_nm = None))]
fn simulated_dither(
    py: Python<'_>,
    target: &Bound<'_, PyAny>,
    power_mw: f64,
    v_ac: Option<f64>,
    settle: usize,
    periods: usize,
    method: Option<&str>,
    rtol: Option<f64>,
    atol_nm: Option<f64>,
) -> PyResult<f64> {
    let setup = cycle_setup(py, target, false, method, rtol, atol_nm)?;
    let changed = at_amplitude(&setup.model, v_ac)?;
    let m: &SliderModel = changed.as_ref().unwrap_or(&setup.model);
    py.detach(|| {
        analysis::response::simulated_dither(m, units::mw(power_mw), &setup.opts, settle, periods)
    })
    .py()
}

// ---------------------------------------------------------------------------------------------
// Calibration

/// The outcome of a touchdown calibration as drive firmware does it.
#[pyclass(module = "hdi_tribology", frozen, get_all)]
struct Calibration {
    /// Detector used.
    detector: String,
    /// First heater level where contact was seen (W).
    touchdown_power_w: f64,
    /// First level on the way down without contact (W), `None` if not searched or not found.
    takeoff_power_w: Option<f64>,
    /// Operating power: touchdown power minus the margin (W).
    set_power_w: f64,
    /// Static flying clearance at the set power, DC voltage only (m).
    clearance_m: f64,
    /// Detector level at touchdown over the level before.
    contrast: f64,
    /// Heater levels run.
    levels: usize,
    /// Simulated time (s).
    simulated_time_s: f64,
}

#[pymethods]
impl Calibration {
    /// Touchdown minus take-off level (W), `None` without a take-off.
    #[getter]
    fn hysteresis_w(&self) -> Option<f64> {
        self.takeoff_power_w.map(|t| self.touchdown_power_w - t)
    }
    /// Static flying clearance at the set power (nm).
    #[getter]
    fn clearance_nm(&self) -> f64 {
        units::to_nm(self.clearance_m)
    }
    fn __repr__(&self) -> String {
        format!(
            "Calibration(detector={:?}, touchdown_mw={:.4}, takeoff_mw={}, set_power_mw={:.4}, clearance_nm={:.4})",
            self.detector,
            units::to_mw(self.touchdown_power_w),
            fmt_opt_mw(self.takeoff_power_w),
            units::to_mw(self.set_power_w),
            self.clearance_nm()
        )
    }
}

/// Touchdown calibration: heater steps of `step_mw` from `start_mw` (default: the power whose
/// protrusion leaves 5 nm of the nominal clearance) up to `max_mw` (default `start_mw + 60`)
/// until the detector fires, then down to take-off; the heater is set `margin_mw` below
/// touchdown. Detectors: `"mean"` (the scene's), `"ae"` (acoustic-emission proxy),
/// `"vibration"`. `dither_v` adds an AC dither (V) while calibrating.
#[pyfunction]
#[pyo3(signature = (target, *, detector = "mean", start_mw = None, step_mw = 0.5, max_mw = None, margin_mw = 15.0, dither_v = None, find_takeoff = true))]
fn calibrate(
    py: Python<'_>,
    target: &Bound<'_, PyAny>,
    detector: &str,
    start_mw: Option<f64>,
    step_mw: f64,
    max_mw: Option<f64>,
    margin_mw: f64,
    dither_v: Option<f64>,
    find_takeoff: bool,
) -> PyResult<Calibration> {
    let (scene, model) = model_of(py, target)?;
    let start_mw = start_mw.unwrap_or_else(|| {
        1e3 * ((scene.nominal_clearance_m - 5e-9) / scene.heater.efficiency_m_per_w).max(0.0)
    });
    let max_mw = max_mw.unwrap_or(start_mw + 60.0);
    let mut opts = CalibrationOptions::from_mw(start_mw, step_mw, max_mw, margin_mw);
    opts.find_takeoff = find_takeoff;
    let dithered = dither_v.map(|v| {
        model.with_voltage(Voltage {
            ac_amplitude: v,
            ..model.voltage()
        })
    });
    let model: &SliderModel = dithered.as_ref().unwrap_or(&model);
    let (th, window) = (scene.detector.contact_threshold_n, scene.detector.window_s);
    let mut det: Box<dyn TouchdownDetector + Send> = match detector {
        "mean" => Box::new(MeanContactForce::new(th, window).py()?),
        "ae" => Box::new(ContactForceRms::new(1e-5, 5e3, 5e-5).py()?),
        "vibration" => Box::new(
            Relative::new(VibrationRms::new(2e-11, 5e3, 5e-5).py()?, 3.0, 1e-4, 2e-4).py()?,
        ),
        other => {
            return Err(invalid(
                "detector",
                format!("`{other}` is not one of mean, ae, vibration"),
            ))
        }
    };
    let c = py
        .detach(|| calibration::calibrate(model, det.as_mut(), &opts))
        .py()?;
    Ok(Calibration {
        detector: c.detector.clone(),
        touchdown_power_w: c.touchdown_power,
        takeoff_power_w: c.takeoff_power,
        set_power_w: c.set_power,
        clearance_m: c.clearance,
        contrast: c.contrast,
        levels: c.steps.len(),
        simulated_time_s: c.simulated_time,
    })
}

// ---------------------------------------------------------------------------------------------
// Drive

/// The plant of a `Drive` or a replay: the scene in the zone at `radius_mm`, the disk and the
/// seed, with the drive's default sensors, heater lag and solver.
fn plant_of(
    py: Python<'_>,
    scene: &Bound<'_, PyAny>,
    seed: u64,
    radius_mm: f64,
    flat_disk: bool,
    initial_power_mw: f64,
    atol_pm: [Option<f64>; 2],
) -> PyResult<Plant> {
    if !(radius_mm.is_finite() && radius_mm > 0.0) {
        return Err(invalid(
            "radius_mm",
            format!("must be a positive number of mm, got {radius_mm}"),
        ));
    }
    if !(initial_power_mw.is_finite() && initial_power_mw >= 0.0) {
        return Err(invalid(
            "initial_power_mw",
            format!("must be ≥ 0 mW, got {initial_power_mw} mW"),
        ));
    }
    let opts = DriveOptions {
        initial_power: units::mw(initial_power_mw),
        disk: if flat_disk {
            DiskSpec::flat()
        } else {
            DiskSpec::default()
        },
        ..DriveOptions::default()
    }
    .with_tolerances_pm(atol_pm[0], atol_pm[1], ["atol_pm", "atol_flight_pm"])
    .py()?;
    // A `Model` drives as it is (its terms with memory included), a `Scene` at its own zone.
    if let Ok(m) = scene.cast::<Model>() {
        let model = m.get().model.clone();
        return py
            .detach(|| Plant::from_model(&model, radius_mm * 1e-3, seed, opts))
            .py();
    }
    let scene = scene.cast::<Scene>().map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err("scene: expected a Scene or a Model")
    })?;
    let scene = &scene.borrow().inner;
    py.detach(|| Plant::new(scene, &scene_zone(scene, radius_mm * 1e-3)?, seed, opts))
        .py()
}

/// One controller period's sensors, as the firmware reads them, and the true values behind
/// them, in the units their names carry (the columns of `hdi drive`, `docs/clearance.md`).
#[pyclass(module = "hdi_tribology", frozen, get_all)]
struct Sensors {
    /// Time at the end of the period (s).
    time_s: f64,
    /// Heater power held over the period (mW).
    heater_mw: f64,
    /// Embedded contact sensor's resistance (Ω).
    contact_resistance_ohm: f64,
    /// Acoustic-emission RMS (V).
    acoustic_v: f64,
    /// Read-back amplitude, fundamental (V).
    readback_fundamental_v: f64,
    /// Read-back amplitude, third harmonic (V).
    readback_third_v: f64,
    /// Harmonic-ratio clearance change since the drive's first period (nm; Wallace).
    hr_clearance_change_nm: f64,
    /// True bulge gap at the end of the period (nm).
    true_gap_nm: f64,
    /// True contact force, mean over the period (µN).
    true_contact_force_un: f64,
    /// True contact-sensor temperature (K above its reference).
    true_sensor_temperature_k: f64,
    /// Disk surface height under the head (nm).
    true_disk_height_nm: f64,
    /// Ambient temperature change since the start (K).
    true_ambient_k: f64,
    /// True protrusion at the end of the period (nm).
    true_protrusion_nm: f64,
    /// True frictional power over the period (mW).
    true_friction_power_mw: f64,
}

impl Sensors {
    /// From one row of `replay_each` (the columns of `SENSOR_COLUMNS`, in order) and the
    /// true values the row leaves out.
    fn of(row: &[f64; 12], truth: &hdi_tribology::drive::Truth) -> Self {
        Sensors {
            time_s: row[0],
            heater_mw: row[1],
            contact_resistance_ohm: row[2],
            acoustic_v: row[3],
            readback_fundamental_v: row[4],
            readback_third_v: row[5],
            hr_clearance_change_nm: row[6],
            true_gap_nm: row[7],
            true_contact_force_un: row[8],
            true_sensor_temperature_k: row[9],
            true_disk_height_nm: row[10],
            true_ambient_k: row[11],
            true_protrusion_nm: units::to_nm(truth.protrusion),
            true_friction_power_mw: units::to_mw(truth.friction_power),
        }
    }
}

#[pymethods]
impl Sensors {
    fn __repr__(&self) -> String {
        format!(
            "Sensors(time_s={:.6e}, heater_mw={:.4}, contact_resistance_ohm={:.6}, acoustic_v={:.4e}, \
             hr_clearance_change_nm={:.4}, true_gap_nm={:.4}, true_contact_force_un={:.4})",
            self.time_s,
            self.heater_mw,
            self.contact_resistance_ohm,
            self.acoustic_v,
            self.hr_clearance_change_nm,
            self.true_gap_nm,
            self.true_contact_force_un
        )
    }
}

/// A simulated drive for firmware prototyping: the scene's slider flying over a disk with
/// run-out and waviness (or a flat one), with a heater, a head–disk voltage and the sensors
/// firmware reads, stepped at the controller's rate (`docs/clearance.md`).
///
/// `Drive(scene, *, seed=1, radius_mm=25, flat_disk=False, initial_power_mw=60, atol_pm=None,
/// atol_flight_pm=None)` starts at rest in the flying equilibrium at `initial_power_mw`.
/// `atol_pm` (default 0.01) and `atol_flight_pm` (default `atol_pm`, at least `atol_pm`) are
/// the integration's displacement tolerances near contact and in flight (pm; equal for one
/// tolerance throughout; `docs/clearance.md`, "Accuracy"). The same seed gives the same disk and the
/// same sensor noise, bit for bit; stepping it with the commands of a command file gives the
/// rows `replay` (and `hdi drive`) gives. A `Drive` belongs to the thread that made it.
#[pyclass(module = "hdi_tribology", name = "Drive", unsendable)]
struct PyDrive {
    inner: Drive,
    wavelength: f64,
    /// The first period's read-back log ratio: the reference of the harmonic-ratio change.
    reference: Option<f64>,
}

#[pymethods]
impl PyDrive {
    #[new]
    #[pyo3(signature = (scene, *, seed = 1, radius_mm = 25.0, flat_disk = false, initial_power_mw = 60.0, atol_pm = None, atol_flight_pm = None))]
    fn new(
        py: Python<'_>,
        scene: &Bound<'_, PyAny>,
        seed: u64,
        radius_mm: f64,
        flat_disk: bool,
        initial_power_mw: f64,
        atol_pm: Option<f64>,
        atol_flight_pm: Option<f64>,
    ) -> PyResult<Self> {
        let tol = [atol_pm, atol_flight_pm];
        let plant = plant_of(py, scene, seed, radius_mm, flat_disk, initial_power_mw, tol)?;
        let wavelength = plant.sensor_spec().readback.wavelength;
        Ok(PyDrive {
            inner: plant.into_drive().py()?,
            wavelength,
            reference: None,
        })
    }

    /// Holds the heater at `heater_mw` (mW) and the voltage at `dc_v` (V) plus an AC dither of
    /// amplitude `ac_v` (V) at `ac_khz` (kHz) for one controller period of `dt_us` (µs), and
    /// returns the `Sensors` at its end.
    #[pyo3(signature = (heater_mw, *, dc_v = 0.0, ac_v = 0.0, ac_khz = 0.0, dt_us = 50.0))]
    fn step(
        &mut self,
        heater_mw: f64,
        dc_v: f64,
        ac_v: f64,
        ac_khz: f64,
        dt_us: f64,
    ) -> PyResult<Sensors> {
        let row = CommandRow {
            time_s: 0.0,
            heater_mw,
            voltage_dc_v: dc_v,
            voltage_ac_v: ac_v,
            ac_frequency_khz: ac_khz,
        };
        let arg = |name: &str| {
            match name {
                "heater_mw" => "heater_mw",
                "voltage_dc_v" => "dc_v",
                "voltage_ac_v" => "ac_v",
                "ac_frequency_khz" => "ac_khz",
                other => other,
            }
            .to_string()
        };
        check_commands(&[row, CommandRow { time_s: 1.0, ..row }], "step", |_, n| {
            arg(n)
        })
        .py()?;
        if !(dt_us.is_finite() && dt_us > 0.0 && dt_us <= 1e6) {
            return Err(invalid(
                "dt_us",
                format!("must be a period in (0, 1e6] µs, got {dt_us} µs"),
            ));
        }
        let command = Command {
            heater_power: units::mw(heater_mw),
            dc_voltage: dc_v,
            ac_amplitude: ac_v,
            ac_frequency: ac_khz * 1e3,
        };
        let s = self.inner.step(&command, dt_us / 1e6).py()?;
        let lr = s.readback.log_ratio();
        let lr0 = *self.reference.get_or_insert(lr);
        let row = sensor_row(&s, lr0, self.wavelength);
        Ok(Sensors::of(&row, &s.truth))
    }

    /// Simulated time so far (s).
    #[getter]
    fn time_s(&self) -> f64 {
        self.inner.time()
    }

    /// The states of the model's terms with memory at the drive's time (a list; empty without
    /// such terms, see `Model.with_relaxing_state`).
    #[getter]
    fn term_states(&self) -> Vec<f64> {
        self.inner.term_states().to_vec()
    }

    /// The integrator's work so far: a dict of `accepted`, `rejected`, `rhs_evals`,
    /// `jac_evals` and `lu_decomps`.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let st = self.inner.stats();
        let d = PyDict::new(py);
        d.set_item("accepted", st.accepted)?;
        d.set_item("rejected", st.rejected)?;
        d.set_item("rhs_evals", st.rhs_evals)?;
        d.set_item("jac_evals", st.jac_evals)?;
        d.set_item("lu_decomps", st.lu_decomps)?;
        Ok(d)
    }

    /// The seed of the disk's random waviness and of the sensor noise.
    #[getter]
    fn seed(&self) -> u64 {
        self.inner.plant().seed()
    }

    fn __repr__(&self) -> String {
        format!(
            "Drive(scene={:?}, seed={}, radius_mm={}, time_s={:.6e})",
            self.inner.plant().zone().name,
            self.inner.plant().seed(),
            self.inner.plant().zone().radius * 1e3,
            self.inner.time()
        )
    }
}

/// Replays commands through a new drive, as `hdi drive SCENE --commands FILE` does, and returns
/// the sensor columns as float64 arrays (the CSV's columns, `SENSOR_COLUMNS`; units in their
/// names), bit for bit the CLI's. Each command holds from its `time_s` until the next; the last
/// time ends the run. `voltage_ac_v` and `ac_frequency_khz` default to zeros; `atol_pm` and
/// `atol_flight_pm` are the tolerances of `Drive`. The GIL is released while the drive runs.
#[pyfunction]
#[pyo3(signature = (scene, time_s, heater_mw, voltage_dc_v, voltage_ac_v = None, ac_frequency_khz = None, *, rate_khz = 20.0, seed = 1, radius_mm = 25.0, flat_disk = false, atol_pm = None, atol_flight_pm = None))]
fn replay<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    time_s: Vec<f64>,
    heater_mw: Vec<f64>,
    voltage_dc_v: Vec<f64>,
    voltage_ac_v: Option<Vec<f64>>,
    ac_frequency_khz: Option<Vec<f64>>,
    rate_khz: f64,
    seed: u64,
    radius_mm: f64,
    flat_disk: bool,
    atol_pm: Option<f64>,
    atol_flight_pm: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let n = time_s.len();
    let ac = voltage_ac_v.unwrap_or_else(|| vec![0.0; n]);
    let f = ac_frequency_khz.unwrap_or_else(|| vec![0.0; n]);
    for (name, len) in [
        ("heater_mw", heater_mw.len()),
        ("voltage_dc_v", voltage_dc_v.len()),
        ("voltage_ac_v", ac.len()),
        ("ac_frequency_khz", f.len()),
    ] {
        if len != n {
            return Err(invalid(
                name,
                format!("has {len} values, time_s has {n}: one per command"),
            ));
        }
    }
    if !(rate_khz.is_finite() && rate_khz > 0.0) {
        return Err(invalid(
            "rate_khz",
            format!("must be a positive rate in kHz, got {rate_khz}"),
        ));
    }
    let rows: Vec<CommandRow> = (0..n)
        .map(|i| CommandRow {
            time_s: time_s[i],
            heater_mw: heater_mw[i],
            voltage_dc_v: voltage_dc_v[i],
            voltage_ac_v: ac[i],
            ac_frequency_khz: f[i],
        })
        .collect();
    check_commands(&rows, "time_s", |i, name| format!("{name}[{i}]")).py()?;
    let plant = plant_of(
        py,
        scene,
        seed,
        radius_mm,
        flat_disk,
        units::to_mw(DriveOptions::default().initial_power),
        [atol_pm, atol_flight_pm],
    )?;
    let dt = 1e-3 / rate_khz;
    let columns = py
        .detach(|| {
            let mut cols: Vec<Vec<f64>> = vec![Vec::new(); SENSOR_COLUMNS.len()];
            replay_each(&plant, &rows, dt, |row| {
                for (c, v) in cols.iter_mut().zip(row) {
                    c.push(*v);
                }
                Ok(())
            })?;
            Ok::<_, hdi_tribology::Error>(cols)
        })
        .py()?;
    let out = PyDict::new(py);
    for (name, col) in SENSOR_COLUMNS.iter().zip(columns) {
        out.set_item(name, array(py, col))?;
    }
    Ok(out)
}

// ---------------------------------------------------------------------------------------------
// Fit

fn fit_error(e: FitError) -> PyErr {
    match e {
        FitError::Data(d) => {
            let message = d.to_string();
            Python::attach(|py| {
                let attrs: Vec<(&str, Py<PyAny>)> = vec![
                    (
                        "file",
                        d.file.into_pyobject(py).map(|o| o.into_any().unbind()),
                    ),
                    (
                        "line",
                        d.line.into_pyobject(py).map(|o| o.into_any().unbind()),
                    ),
                    (
                        "column",
                        d.column.into_pyobject(py).map(|o| o.into_any().unbind()),
                    ),
                    (
                        "column_name",
                        d.column_name
                            .into_pyobject(py)
                            .map(|o| o.into_any().unbind()),
                    ),
                    (
                        "reason",
                        d.reason.into_pyobject(py).map(|o| o.into_any().unbind()),
                    ),
                ]
                .into_iter()
                .filter_map(|(k, v)| v.ok().map(|v| (k, v)))
                .collect();
                py_error("DataFileError", &message, attrs)
            })
        }
        FitError::Other(e) => to_py_err(e),
        other => py_error("HdiError", &other.to_string(), Vec::<(&str, String)>::new()),
    }
}

/// Fits the `free` parameters of `scene` to measured curves (CSV files in engineering units,
/// see `docs/fit.md`). Each parameter is named as a scene file names it, in that name's unit,
/// with optional bounds: `"height_sigma_nm"`, `"efficiency_nm_per_mw=0.05:0.2"`.
///
/// Returns a dict: `scene` (the fitted `Scene`), `parameters` (list of dicts: name, value,
/// unit, standard_error, …), `correlation`, `residuals`, `identifiability`, `points`, `chi2`,
/// `residual_scale`, `converged`, `termination`, `evaluations`, `starts`, `integration`,
/// `trusted` and `warnings`, as `hdi fit` prints them. Check `trusted` and `warnings`.
#[pyfunction]
#[pyo3(signature = (scene, data, free, *, starts = 1, seed = 1, max_evaluations = 400))]
fn fit<'py>(
    py: Python<'py>,
    scene: &Scene,
    data: Vec<std::path::PathBuf>,
    free: Vec<String>,
    starts: usize,
    seed: u64,
    max_evaluations: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let options = FitOptions {
        starts,
        seed,
        max_evaluations,
        ..FitOptions::default()
    };
    let scene_in = scene.inner.clone();
    let result = py
        .detach(|| -> Result<_, FitError> {
            let sets = data
                .iter()
                .map(DataSet::from_path)
                .collect::<Result<Vec<_>, _>>()?;
            let free = free
                .iter()
                .map(|f| f.parse::<FreeParameter>())
                .collect::<Result<Vec<_>, _>>()?;
            hdi_tribology::fit::fit(&scene_in, &sets, &free, &options)
        })
        .map_err(fit_error)?;
    let text = serde_json::to_string(&result)
        .map_err(|e| invalid("fit", format!("cannot convert the result: {e}")))?;
    let out = json_module(py)?.call_method1("loads", (text,))?;
    out.set_item(
        "scene",
        Scene {
            inner: result.scene,
        },
    )?;
    Ok(out)
}

// ---------------------------------------------------------------------------------------------

/// The native core of the `hdi_tribology` Python package.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Scene>()?;
    m.add_class::<Model>()?;
    m.add_class::<Equilibrium>()?;
    m.add_class::<Transition>()?;
    m.add_class::<StaticHysteresis>()?;
    m.add_class::<PullIn>()?;
    m.add_class::<Detection>()?;
    m.add_class::<Cycle>()?;
    m.add_class::<RefinedCycle>()?;
    m.add_class::<Mode>()?;
    m.add_class::<LinearResponse>()?;
    m.add_class::<Calibration>()?;
    m.add_class::<Sensors>()?;
    m.add_class::<PyDrive>()?;
    m.add_function(wrap_pyfunction!(forces, m)?)?;
    m.add_function(wrap_pyfunction!(static_hysteresis, m)?)?;
    m.add_function(wrap_pyfunction!(pull_in_voltage, m)?)?;
    m.add_function(wrap_pyfunction!(clearance_change, m)?)?;
    m.add_function(wrap_pyfunction!(s_curve, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_cycle, m)?)?;
    m.add_function(wrap_pyfunction!(ac_sweep, m)?)?;
    m.add_function(wrap_pyfunction!(ac_sweep_refined, m)?)?;
    m.add_function(wrap_pyfunction!(linear_response, m)?)?;
    m.add_function(wrap_pyfunction!(flying_equilibrium, m)?)?;
    m.add_function(wrap_pyfunction!(simulated_dither, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(fit, m)?)?;
    m.add_function(wrap_pyfunction!(replay, m)?)?;
    bearing::register(m)?;
    m.add("SENSOR_COLUMNS", SENSOR_COLUMNS.to_vec())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
