//! Python bindings of `hdi-tribology`: a thin layer over the crate's public API.
//!
//! Every function here converts its arguments, calls one function of the crate with the GIL
//! released, and converts the result. Nothing of the physics or the analyses lives here, and no
//! result is mirrored: each comes back as the crate serializes it (`analysis::record`, the JSON
//! of the `hdi` program), wrapped in a read-only object of `hdi_tribology._results`. Inputs are
//! in engineering units where the name says so (`_mw`, `_nm`, `_v`).
//!
//! Long calls run on a thread of their own while the calling thread checks for signals: Ctrl-C
//! cancels the work ([`Cancel`]) and raises `KeyboardInterrupt` as soon as it has stopped.

// A Python function's keyword arguments are its options: many arguments are the API here.
#![allow(clippy::too_many_arguments)]

use std::sync::{Arc, RwLock};
use std::time::Duration;

use hdi_tribology::analysis::record::{CycleRecord, StaticRecord};
use hdi_tribology::analysis::StateSpace;
use hdi_tribology::analysis::{
    self, CycleOptions, HeaterProgramme, Refinement, ScanGrid, StaticOptions,
};
use hdi_tribology::calibration::CalibrationRecord;
use hdi_tribology::calibration::{
    self, CalibrationOptions, ContactForceRms, MeanContactForce, Relative, TouchdownDetector,
    VibrationRms,
};
use hdi_tribology::drive::{
    check_commands, replay_heads_each, sensor_row, spec_zone, Command, CommandRow, DiskSpec, Drive,
    DriveOptions, DriveScheme, MultiDrive, MultiPlant, Plant, Sensors, DEFAULT_RADIUS,
    SENSOR_COLUMNS,
};
use hdi_tribology::fit::{DataSet, FitOptions, FreeParameter};
use hdi_tribology::force::{Gaps, RelaxingState};
use hdi_tribology::model::{Dofs, SliderModel, Voltage};
use hdi_tribology::ode::Cancel;
use hdi_tribology::scene::MAX_DOF;
use hdi_tribology::scene::{DriveSpec, FieldPath, PathError};
use hdi_tribology::units;
use nalgebra::{DMatrix, DVector};
use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyReadonlyArray1, PyUntypedArrayMethods};
use pyo3::exceptions::{PyKeyError, PyRuntimeError, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use serde::Serialize;
use serde_json::Value;

mod bearing;

type Scn = hdi_tribology::scene::Scene;

// ---------------------------------------------------------------------------------------------
// Errors: each crate error becomes the Python exception of `hdi_tribology._errors` of its kind,
// with the crate's fields as attributes.

fn to_py_err(e: hdi_tribology::Error) -> PyErr {
    use hdi_tribology::Error as E;
    let message = e.to_string();
    let (class, attrs): (&str, Vec<(&str, String)>) = match e {
        E::Data(d) => return data_error(d),
        E::InvalidInput { field, reason } => (
            "InvalidInputError",
            vec![("field", field), ("reason", reason)],
        ),
        E::Scene { origin, reason } => ("SceneError", vec![("origin", origin), ("reason", reason)]),
        E::NoConvergence(f) => (
            "NoConvergenceError",
            vec![
                ("what", f.stage().to_string()),
                ("reason", f.reason()),
                ("kind", f.kind().to_string()),
            ],
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

fn json_to_py<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    json_module(py)?.call_method1("loads", (v.to_string(),))
}

/// The crate's serde form of `x`: the one representation of a result.
fn to_value(x: &impl Serialize) -> PyResult<Value> {
    serde_json::to_value(x).map_err(|e| invalid("result", format!("cannot convert it: {e}")))
}

/// The object of class `class` of `hdi_tribology._results` holding `v`.
fn record<'py>(py: Python<'py>, class: &str, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    let data = json_to_py(py, v)?;
    py.import("hdi_tribology._results")?
        .getattr(class)?
        .call1((data,))
}

/// An equilibrium's serde form with what it cannot know itself: its coordinates `q`, one per
/// degree of freedom of the structure, and whether it is `stable`.
fn equilibrium_value(e: &analysis::Equilibrium, dofs: usize) -> PyResult<Value> {
    let mut v = to_value(e)?;
    if let Value::Object(m) = &mut v {
        m.insert("stable".into(), Value::Bool(e.is_stable()));
        m.insert(
            "q".into(),
            to_value(&e.q.iter().take(dofs).collect::<Vec<_>>())?,
        );
    }
    Ok(v)
}

/// Runs `work` without the GIL on this thread, watching a [`Cancel`] flag whose check runs
/// Python's signal handlers (from the integration's steps, at most every 50 ms): on Ctrl-C (or
/// any handler that raises) the work stops at its next step and the handler's exception
/// (`KeyboardInterrupt`) is raised here. For work that runs on rayon's threads, see
/// [`on_own_thread`].
fn interruptible<T: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> hdi_tribology::Result<T> + Send,
) -> PyResult<T> {
    let caught: Arc<std::sync::Mutex<Option<PyErr>>> = Arc::default();
    let slot = caught.clone();
    let cancel = Cancel::with_check(move || {
        Python::attach(|py| match py.check_signals() {
            Ok(()) => false,
            Err(e) => {
                if let Ok(mut s) = slot.lock() {
                    *s = Some(e);
                }
                true
            }
        })
    });
    let out = py.detach(|| cancel.watch(work));
    if let Some(e) = caught.lock().ok().and_then(|mut s| s.take()) {
        return Err(e);
    }
    out.map_err(to_py_err)
}

/// Runs `work` without the GIL on a thread of its own, watching a [`Cancel`] flag, while this
/// thread checks for signals every 50 ms: on Ctrl-C (or any signal handler that raises) the
/// flag is raised, the work stops at its next integration step, and the handler's exception
/// (`KeyboardInterrupt`) is raised here. For work on rayon's threads (sweeps, fits), whose
/// steps run on threads where Python's signal handlers cannot run; it costs a thread start.
fn on_own_thread<T: Send, E: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> Result<T, E> + Send,
    err: impl Fn(E) -> PyErr,
) -> PyResult<T> {
    let cancel = Cancel::new();
    let (tx, rx) = std::sync::mpsc::channel();
    // (a lock only to share the receiver with the detached waits; one thread uses it)
    let rx = std::sync::Mutex::new(rx);
    std::thread::scope(|s| {
        let worker = {
            let cancel = cancel.clone();
            s.spawn(move || {
                let out = cancel.watch(work);
                let _ = tx.send(());
                out
            })
        };
        loop {
            let timed_out = py.detach(|| match rx.lock() {
                Ok(rx) => matches!(
                    rx.recv_timeout(Duration::from_millis(50)),
                    Err(std::sync::mpsc::RecvTimeoutError::Timeout)
                ),
                Err(_) => false,
            });
            if !timed_out {
                break;
            }
            if let Err(signal) = py.check_signals() {
                cancel.cancel();
                let _ = py.detach(|| worker.join());
                return Err(signal);
            }
        }
        match py.detach(|| worker.join()) {
            Ok(out) => out.map_err(err),
            Err(panic) => std::panic::resume_unwind(panic),
        }
    })
}

/// A count given as a Python int: an `InvalidInputError` naming `name` when it is below `min`
/// or too large.
fn count(name: &str, v: i128, min: i128) -> PyResult<usize> {
    if v < min {
        return Err(invalid(name, format!("must be at least {min}, got {v}")));
    }
    usize::try_from(v).map_err(|_| invalid(name, format!("is too large: {v}")))
}

/// A seed given as a Python int: 0 to 2⁶⁴ − 1.
fn seed_of(name: &str, v: i128) -> PyResult<u64> {
    u64::try_from(v).map_err(|_| invalid(name, format!("must lie in [0, 2^64 - 1], got {v}")))
}

/// A finite number ≥ 0 in the unit `unit`, named `name`.
fn non_negative(name: &str, v: f64, unit: &str) -> PyResult<f64> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(invalid(
            name,
            format!("must be finite and ≥ 0 {unit}, got {v} {unit}"),
        ))
    }
}

// ---------------------------------------------------------------------------------------------
// Scene

/// A whole head–disk interface, validated (see `docs/scene_format.md`).
///
/// Fields are SI with the unit in their name; `scene["surface.height_sigma_nm"]` reads (and
/// assignment writes) any dimensional field in an engineering unit instead. `keys()`, `in` and
/// iteration list the fields by their dotted SI paths. A scene may be shared between threads:
/// each assignment replaces it whole, under a lock.
#[pyclass(module = "hdi_tribology", name = "Scene", frozen)]
struct Scene {
    inner: RwLock<Scn>,
}

impl Scene {
    fn of(inner: Scn) -> Self {
        Scene {
            inner: RwLock::new(inner),
        }
    }

    /// A copy of the scene as it is now.
    fn get(&self) -> Scn {
        match self.inner.read() {
            Ok(s) => s.clone(),
            Err(poisoned) => poisoned.into_inner().clone(),
        }
    }
}

fn scene_from_dict(py: Python<'_>, d: &Bound<'_, PyAny>) -> PyResult<Scn> {
    let text: String = json_module(py)?
        .call_method1("dumps", (plain(py, d)?,))?
        .extract()?;
    py.detach(|| Scn::from_json_str(&text)).py()
}

/// The scene's serde form (SI), which the library's field paths resolve against.
fn scene_value(s: &Scn) -> PyResult<Value> {
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

/// `v` with numpy scalars and arrays (anywhere inside lists and dicts) as plain Python values.
fn plain<'py>(py: Python<'py>, v: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    let np = py.import("numpy")?;
    let generic = np.getattr("generic")?;
    let ndarray = np.getattr("ndarray")?;
    if v.is_instance(&generic)? || v.is_instance(&ndarray)? {
        return v.call_method0("tolist");
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let out = PyDict::new(py);
        for (k, x) in d.iter() {
            out.set_item(k, plain(py, &x)?)?;
        }
        return Ok(out.into_any());
    }
    if let Ok(l) = v.cast::<PyList>() {
        let out = PyList::empty(py);
        for x in l.iter() {
            out.append(plain(py, &x)?)?;
        }
        return Ok(out.into_any());
    }
    Ok(v.clone())
}

/// A Python value for the field `path`, as the scene's serde form holds values.
fn py_to_json(py: Python<'_>, path: &str, v: &Bound<'_, PyAny>) -> PyResult<Value> {
    let text: String = json_module(py)?
        .call_method1("dumps", (plain(py, v)?,))
        .map_err(|e| invalid(path, format!("not a value a scene can hold: {e}")))?
        .extract()?;
    serde_json::from_str(&text).map_err(|e| {
        invalid(
            path,
            format!("`{text}` is not a value a scene can hold: {e}"),
        )
    })
}

/// The dotted paths of every leaf of `v` (a number, string, list or null), below `prefix`.
fn leaf_paths(v: &Value, prefix: &str, out: &mut Vec<String>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                let p = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                leaf_paths(x, &p, out);
            }
        }
        _ => out.push(prefix.to_string()),
    }
}

/// `scene` with the fields `values` (dotted paths as given, values already converted) set,
/// validated. A name the scene has no field of is a `KeyError`, as reading it is: one that
/// neither reads before nor after (an optional section, absent before, reads after).
fn with_fields(scene: &Scn, values: &[(String, Value)]) -> PyResult<Scn> {
    let mut root = scene_value(scene)?;
    let mut absent = Vec::new();
    for (path, value) in values {
        let field = FieldPath::at(&root, path).map_err(path_err)?;
        if let Err(e) = field.read(&root) {
            absent.push((path, e));
        }
        field.write(&mut root, value.clone());
    }
    let updated = Scn::from_json_str(&root.to_string());
    let unknown = |path: &str, e: PathError| {
        PyKeyError::new_err(format!("`{path}` is not a field of the scene ({e})"))
    };
    match updated {
        Err(hdi_tribology::Error::Scene { .. }) if !absent.is_empty() => {
            let (path, e) = absent.swap_remove(0);
            Err(unknown(path, e))
        }
        Err(e) => Err(to_py_err(e)),
        Ok(new) => {
            let after = scene_value(&new)?;
            for (path, e) in absent {
                let reads = FieldPath::at(&after, path).and_then(|f| f.read(&after));
                if reads.is_err() {
                    return Err(unknown(path, e));
                }
            }
            Ok(new)
        }
    }
}

#[pymethods]
impl Scene {
    /// The built-in scene of the letter (SI units inside).
    #[staticmethod]
    fn paper() -> Self {
        Scene::of(Scn::paper())
    }

    /// Reads a `.toml` or `.json` scene file and validates it.
    #[staticmethod]
    fn from_file(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Self> {
        Ok(Scene::of(py.detach(|| Scn::from_path(&path)).py()?))
    }

    /// Parses a TOML scene and validates it.
    #[staticmethod]
    fn from_toml(text: &str) -> PyResult<Self> {
        Ok(Scene::of(Scn::from_toml_str(text).py()?))
    }

    /// Parses a JSON scene and validates it.
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        Ok(Scene::of(Scn::from_json_str(text).py()?))
    }

    /// A scene from a dict shaped as the JSON file (fields may use engineering units).
    #[staticmethod]
    fn from_dict(py: Python<'_>, d: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(Scene::of(scene_from_dict(py, d)?))
    }

    /// The scene as a dict of plain Python values, SI units.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &scene_value(&self.get())?)
    }

    /// The scene as TOML text.
    fn to_toml(&self) -> PyResult<String> {
        self.get().to_toml_string().py()
    }

    /// The scene as JSON text.
    fn to_json(&self) -> PyResult<String> {
        self.get().to_json_string().py()
    }

    /// The scene's name.
    #[getter]
    fn name(&self) -> String {
        self.get().name
    }

    /// A field by its dotted path, in SI (`"surface.height_sigma_m"`) or in an engineering unit
    /// (`"surface.height_sigma_nm"`).
    fn __getitem__<'py>(&self, py: Python<'py>, path: &str) -> PyResult<Bound<'py, PyAny>> {
        let root = scene_value(&self.get())?;
        let v = FieldPath::at(&root, path)
            .and_then(|f| f.read(&root))
            .map_err(path_err)?;
        json_to_py(py, &v)
    }

    /// Sets a field by its dotted path (SI or engineering unit; numpy scalars and arrays
    /// taken); the scene is validated again and left unchanged when the new value is refused. A
    /// name the scene has no field of is a `KeyError`.
    fn __setitem__(&self, py: Python<'_>, path: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let value = py_to_json(py, path, value)?;
        let mut guard = self
            .inner
            .write()
            .map_err(|_| PyRuntimeError::new_err("the scene was poisoned by a panic"))?;
        let updated = with_fields(&guard, &[(path.to_string(), value)])?;
        *guard = updated;
        Ok(())
    }

    /// A copy with the given fields (dotted paths, SI or engineering units) replaced, validated.
    fn with_values(&self, py: Python<'_>, values: &Bound<'_, PyDict>) -> PyResult<Self> {
        let mut given = Vec::new();
        for (k, v) in values.iter() {
            let path: String = k.extract()?;
            let value = py_to_json(py, &path, &v)?;
            given.push((path, value));
        }
        let scene = self.get();
        Ok(Scene::of(py.detach(|| with_fields(&scene, &given))?))
    }

    /// Every field's dotted path, SI (`"surface.height_sigma_m"`), in the order of the file.
    fn keys(&self) -> PyResult<Vec<String>> {
        let mut out = Vec::new();
        leaf_paths(&scene_value(&self.get())?, "", &mut out);
        Ok(out)
    }

    /// Whether `path` names a field (SI or engineering unit).
    fn __contains__(&self, path: &str) -> PyResult<bool> {
        let root = scene_value(&self.get())?;
        Ok(FieldPath::at(&root, path)
            .and_then(|f| f.read(&root))
            .is_ok())
    }

    fn __iter__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        PyList::new(py, self.keys()?)?.call_method0("__iter__")
    }

    fn __len__(&self) -> PyResult<usize> {
        Ok(self.keys()?.len())
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<Scene>()
            .is_ok_and(|o| self.get() == o.get().get())
    }

    fn __repr__(&self) -> String {
        format!("Scene(name={:?})", self.get().name)
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        let text = slf.get().get().to_json_string().py()?;
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

impl Model {
    fn build(py: Python<'_>, scene: Scn) -> PyResult<Self> {
        let scene = Arc::new(scene);
        let s = scene.clone();
        let model = interruptible(py, move || SliderModel::from_scene(&s))?;
        Ok(Model {
            scene,
            model: Arc::new(model),
        })
    }
}

#[pymethods]
impl Model {
    #[new]
    fn new(py: Python<'_>, scene: &Scene) -> PyResult<Self> {
        Model::build(py, scene.get())
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
        Scene::of((*self.scene).clone())
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
        let m = Model::build(py, s.get().get())?;
        return Ok((m.scene, m.model));
    }
    Err(PyTypeError::new_err(
        "target: expected a hdi_tribology.Model or hdi_tribology.Scene",
    ))
}

// ---------------------------------------------------------------------------------------------
// Forces

fn array<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyAny> {
    PyArray1::from_vec(py, v).into_any()
}

/// How one column of `forces` is read from a breakdown.
type ForceColumn = fn(&hdi_tribology::force::Breakdown) -> f64;

/// The columns of `forces`, named as `hdi forces` names its keys (`force::Breakdown`'s serde
/// form), and how each is read from a breakdown.
const FORCE_COLUMNS: [(&str, ForceColumn); 7] = [
    ("intermolecular_n", |b| b.intermolecular),
    ("contact_n", |b| b.contact),
    ("electrostatic_per_volt2_n_per_v2", |b| {
        b.electrostatic_per_volt2
    }),
    ("electrostatic_n", |b| b.electrostatic),
    ("other_n", |b| b.other),
    ("real_contact_area_m2", |b| b.real_contact_area),
    ("total_n", |b| b.total),
];

/// Gaps per chunk of `forces`: between chunks the call checks for Ctrl-C.
const FORCE_CHUNK: usize = 4096;

/// Every interface force at bulge gaps `gaps_nm` (nm; any array_like: a scalar, a list, an int
/// or float32 array, of any shape), pad gaps `gaps_nm + protrusion_nm`, at the scene's DC
/// voltage. Returns a dict of float64 arrays shaped as `gaps_nm`: `d_m` (m),
/// `intermolecular_n`, `contact_n`, `electrostatic_n`, `other_n`, `total_n` (N, positive away
/// from the disk), `electrostatic_per_volt2_n_per_v2` (N/V²), `real_contact_area_m2` (m²), and
/// the bool array `in_table_range`. Ctrl-C stops it within one chunk of gaps.
#[pyfunction]
#[pyo3(signature = (target, gaps_nm, protrusion_nm = 0.0))]
fn forces<'py>(
    py: Python<'py>,
    target: &Bound<'py, PyAny>,
    gaps_nm: &Bound<'py, PyAny>,
    protrusion_nm: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let np = py.import("numpy")?;
    let given = np
        .call_method1("asarray", (gaps_nm, "float64"))
        .map_err(|e| invalid("gaps_nm", format!("not an array of numbers: {e}")))?;
    let given = given
        .cast_into::<PyArrayDyn<f64>>()
        .map_err(|_| invalid("gaps_nm", "not an array of numbers"))?;
    let shape: Vec<usize> = given.shape().to_vec();
    let flat: Vec<f64> = given.readonly().as_array().iter().copied().collect();
    if let Some(i) = flat.iter().position(|g| !g.is_finite()) {
        let index: Vec<usize> = np
            .call_method1("unravel_index", (i, shape.clone()))?
            .extract()?;
        let at = index
            .iter()
            .map(|k| k.to_string())
            .collect::<Vec<_>>()
            .join(", ");
        return Err(invalid(
            &format!("gaps_nm[{at}]"),
            format!("must be finite, got {} nm", flat[i]),
        ));
    }
    if !protrusion_nm.is_finite() {
        return Err(invalid(
            "protrusion_nm",
            format!("must be finite, got {protrusion_nm:?} nm"),
        ));
    }
    // in metres as typed in nm, as `hdi forces --gaps-nm`: 1.1 nm is 1.1e-9 m
    let gaps: Vec<f64> = flat.iter().map(|&g| units::shift_decimal(g, -9)).collect();
    let protrusion = units::shift_decimal(protrusion_nm, -9);
    let (scene, model) = model_of(py, target)?;
    let (lo, hi) = model.forces().table_range();
    let volt2 = scene.dc_volt2();
    let mut rows = Vec::with_capacity(gaps.len());
    for chunk in gaps.chunks(FORCE_CHUNK) {
        let part = py.detach(|| {
            let one = |&d: &f64| {
                model.breakdown(
                    Gaps {
                        bulge: d,
                        pad: d + protrusion,
                    },
                    volt2,
                )
            };
            use rayon::prelude::*;
            chunk.par_iter().map(one).collect::<Vec<_>>()
        });
        rows.extend(part);
        py.check_signals()?;
    }
    let in_range: Vec<bool> = gaps
        .iter()
        .map(|&d| (lo..=hi).contains(&d) && (lo..=hi).contains(&(d + protrusion)))
        .collect();
    let shaped = |a: Bound<'py, PyAny>| a.call_method1("reshape", (shape.clone(),));
    let out = PyDict::new(py);
    out.set_item("d_m", shaped(array(py, gaps))?)?;
    for (name, get) in FORCE_COLUMNS {
        out.set_item(name, shaped(array(py, rows.iter().map(get).collect()))?)?;
    }
    out.set_item(
        "in_table_range",
        shaped(PyArray1::from_vec(py, in_range).into_any())?,
    )?;
    Ok(out)
}

// ---------------------------------------------------------------------------------------------
// Static analyses

fn static_options(scene: &Scn, threshold_un: Option<f64>) -> PyResult<StaticOptions> {
    let threshold = match threshold_un {
        Some(t) if !(t.is_finite() && t > 0.0) => {
            return Err(invalid(
                "contact_threshold_un",
                format!("must be finite and > 0 µN, got {t:?} µN"),
            ))
        }
        Some(t) => t * 1e-6,
        None => scene.detector.contact_threshold_n,
    };
    Ok(StaticOptions::new(threshold))
}

/// Replaces the `at` equilibrium of the transition at `key` of `v` by its full form.
fn with_equilibrium(
    v: &mut Value,
    key: &str,
    e: &analysis::Equilibrium,
    dofs: usize,
) -> PyResult<()> {
    if let Some(t) = v.get_mut(key) {
        t["at"] = equilibrium_value(e, dofs)?;
    }
    Ok(())
}

/// Static touchdown and take-off powers at the scene's DC voltage, with the contact threshold
/// of the scene's detector (or `contact_threshold_un`, µN): a `StaticHysteresis`, as `hdi
/// static` prints it.
#[pyfunction]
#[pyo3(signature = (target, contact_threshold_un = None))]
fn static_hysteresis<'py>(
    py: Python<'py>,
    target: &Bound<'py, PyAny>,
    contact_threshold_un: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let (scene, model) = model_of(py, target)?;
    let opts = static_options(&scene, contact_threshold_un)?;
    let h = interruptible(py, || analysis::static_hysteresis(&model, &opts))?;
    let dofs = model.structure().dofs();
    let mut v = to_value(&StaticRecord::new(&scene.name, h))?;
    with_equilibrium(&mut v, "touchdown", &h.touchdown.at, dofs)?;
    with_equilibrium(&mut v, "takeoff", &h.takeoff.at, dofs)?;
    record(py, "StaticHysteresis", &v)
}

/// The voltage that pulls the head into contact at heater power `power_mw` (mW): a `PullIn`.
#[pyfunction]
#[pyo3(signature = (target, power_mw = 0.0, contact_threshold_un = None))]
fn pull_in_voltage<'py>(
    py: Python<'py>,
    target: &Bound<'py, PyAny>,
    power_mw: f64,
    contact_threshold_un: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let power = units::mw(non_negative("power_mw", power_mw, "mW")?);
    let (scene, model) = model_of(py, target)?;
    let opts = static_options(&scene, contact_threshold_un)?;
    let p = interruptible(py, || analysis::pull_in_voltage(&model, power, &opts))?;
    record(py, "PullIn", &to_value(&p)?)
}

/// Columns of the serde forms of `rows`: one float64 array per numeric key, a bool array per
/// boolean key (the keys of the JSON of one row).
fn columns<'py>(py: Python<'py>, rows: &[Value], out: &Bound<'py, PyDict>) -> PyResult<()> {
    let Some(Value::Object(first)) = rows.first() else {
        return Ok(());
    };
    for key in first.keys() {
        if first[key].is_boolean() {
            let col: Vec<bool> = rows
                .iter()
                .map(|r| r[key].as_bool().unwrap_or(false))
                .collect();
            out.set_item(key, PyArray1::from_vec(py, col))?;
        } else if first[key].is_number() || first[key].is_null() {
            let col: Vec<f64> = rows
                .iter()
                .map(|r| r[key].as_f64().unwrap_or(f64::NAN))
                .collect();
            out.set_item(key, array(py, col))?;
        }
    }
    Ok(())
}

/// Clearance change with DC voltage (the letter's Fig. 2b). Returns a dict of float64 arrays,
/// the keys of `ClearanceChange`'s serde form: `dc_voltage_v` (V), `touchdown_power_w` (W),
/// `clearance_change_m` (m).
#[pyfunction]
#[pyo3(signature = (target, dc_voltages_v, contact_threshold_un = None))]
fn clearance_change<'py>(
    py: Python<'py>,
    target: &Bound<'py, PyAny>,
    dc_voltages_v: Vec<f64>,
    contact_threshold_un: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    for (i, v) in dc_voltages_v.iter().enumerate() {
        if !v.is_finite() {
            return Err(invalid(
                &format!("dc_voltages_v[{i}]"),
                format!("must be finite, got {v} V"),
            ));
        }
    }
    let (scene, model) = model_of(py, target)?;
    let opts = static_options(&scene, contact_threshold_un)?;
    let rows = interruptible(py, || {
        analysis::clearance_change(&model, &dc_voltages_v, &opts)
    })?;
    let values = rows.iter().map(to_value).collect::<PyResult<Vec<_>>>()?;
    let out = PyDict::new(py);
    columns(py, &values, &out)?;
    if rows.is_empty() {
        for k in ["dc_voltage_v", "touchdown_power_w", "clearance_change_m"] {
            out.set_item(k, array(py, Vec::new()))?;
        }
    }
    Ok(out)
}

/// The S-curve of static equilibria along the bulge gap, at the scene's DC voltage. Returns a
/// dict: float64 arrays `d_m`, `power_w`, `y_m`, `protrusion_m`, `stiffness_n_per_m`,
/// `interface_force_n`, `contact_force_n`, a bool array `stable`, `volt2_v2`, and `folds`, a
/// list of dicts `{power_w, d_m, jump_in}`.
#[pyfunction]
fn s_curve<'py>(py: Python<'py>, target: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
    let (_, model) = model_of(py, target)?;
    let c = interruptible(py, || analysis::s_curve(&model, None, &ScanGrid::default()))?;
    let dofs = model.structure().dofs();
    let points = c
        .points
        .iter()
        .map(|e| equilibrium_value(e, dofs))
        .collect::<PyResult<Vec<_>>>()?;
    let out = PyDict::new(py);
    columns(py, &points, &out)?;
    out.set_item("volt2_v2", c.volt2)?;
    out.set_item("folds", json_to_py(py, &to_value(&c.folds)?)?)?;
    Ok(out)
}

// ---------------------------------------------------------------------------------------------
// Cycles and sweeps

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
    if let Some(r) = rtol {
        if !(r.is_finite() && r > 0.0 && r < 1.0) {
            return Err(invalid("rtol", format!("must lie in (0, 1), got {r}")));
        }
    }
    if let Some(a) = atol_nm {
        if !(a.is_finite() && a > 0.0) {
            return Err(invalid(
                "atol_nm",
                format!("must be finite and > 0 nm, got {a} nm"),
            ));
        }
    }
    let (scene, model) = model_of(py, target)?;
    let mut opts = CycleOptions::from_scene(&scene).py()?;
    if let Some(m) = method {
        opts.solver.method = m
            .parse()
            .map_err(|e: hdi_tribology::ode::OdeError| invalid("method", e.to_string()))?;
    }
    // as `hdi cycle`: a new rtol scales the absolute tolerance with it unless that is given
    if let Some(r) = rtol {
        opts.solver = opts.solver.with_rtol(r);
    }
    if let Some(a) = atol_nm {
        // in metres as typed in nm, as `hdi cycle --atol-nm`
        opts.solver.atol_displacement = units::shift_decimal(a, -9);
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

/// The model at AC amplitude `v_ac` (V), or `None` for the model itself.
fn at_amplitude(model: &SliderModel, v_ac: Option<f64>) -> PyResult<Option<SliderModel>> {
    match v_ac {
        None => Ok(None),
        Some(a) => Ok(Some(model.with_voltage(Voltage {
            ac_amplitude: non_negative("v_ac", a, "V")?,
            ..model.voltage()
        }))),
    }
}

/// One touchdown/take-off cycle under the scene's heater programme (or the touchdown-triggered
/// protocol), at AC amplitude `v_ac` (V; default: the scene's), run once at the tolerances given.
///
/// Returns a dict: the summary `cycle` (a `Cycle`, as `hdi cycle --no-refine` prints it),
/// `touchdown` and `takeoff` (`Detection` or `None`), and with `series=True` float64 arrays, one
/// value per accepted step, the columns of the CSV of `hdi cycle --csv`: `t_s` (s), `power_w`
/// (W), `d_m` (m), `air_bearing_n`, `intermolecular_n`, `electrostatic_n`, `contact_n`,
/// `total_n` (N), `temperature_rise_k` (K), `indicator_n` (N, NaN before the detector window
/// has filled: an empty field in the CSV), and `term_states` when the model has terms with
/// memory. With `stop_at_takeoff=True` the run ends at the step where the detector sees
/// take-off (`CycleOptions::stop_at_takeoff`): the same touchdown and take-off to the bit, the
/// rest (steps, series, mean temperature rise, `duration_s`) over the time run. With
/// `mean_temperature=False` the heat integral is left out of the state
/// (`CycleOptions::mean_temperature`): the cycle's `mean_temperature_rise_k` is `None`, and the
/// powers move within the tolerance.
#[pyfunction]
#[pyo3(signature = (target, v_ac = None, *, triggered = false, method = None, rtol = None, atol_nm = None, series = true, stop_at_takeoff = false, mean_temperature = true))]
#[allow(clippy::too_many_arguments)]
fn simulate_cycle<'py>(
    py: Python<'py>,
    target: &Bound<'py, PyAny>,
    v_ac: Option<f64>,
    triggered: bool,
    method: Option<&str>,
    rtol: Option<f64>,
    atol_nm: Option<f64>,
    series: bool,
    stop_at_takeoff: bool,
    mean_temperature: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let mut setup = cycle_setup(py, target, triggered, method, rtol, atol_nm)?;
    setup.opts.keep_series = series;
    setup.opts.stop_at_takeoff = stop_at_takeoff;
    setup.opts.mean_temperature = mean_temperature;
    let changed = at_amplitude(&setup.model, v_ac)?;
    let m: &SliderModel = changed.as_ref().unwrap_or(&setup.model);
    let mut r = interruptible(py, || {
        analysis::simulate_cycle(m, &setup.programme, &setup.opts)
    })?;
    let s = r.series.take();
    let rec = CycleRecord::unchecked(&setup.scene.name, &setup.programme, r, &setup.opts);
    let cycle = record(py, "Cycle", &to_value(&rec)?)?;
    let out = PyDict::new(py);
    out.set_item("touchdown", cycle.getattr("touchdown")?)?;
    out.set_item("takeoff", cycle.getattr("takeoff")?)?;
    out.set_item("cycle", cycle)?;
    if let Some(s) = s {
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

/// Runs `work` on a rayon pool of `threads` threads (the global pool when `None`), watching
/// the caller's cancellation flag there.
fn on_threads<T: Send>(
    threads: Option<usize>,
    work: impl FnOnce() -> hdi_tribology::Result<T> + Send,
) -> hdi_tribology::Result<T> {
    match threads {
        None => work(),
        Some(n) => {
            let cancel = Cancel::current();
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| hdi_tribology::Error::invalid("threads", e.to_string()))?
                .install(|| Cancel::carry(&cancel, work))
        }
    }
}

/// The amplitudes asked for (the scene's sweep list when `None`), each finite and ≥ 0 V.
fn amplitudes_or_scene(scene: &Scn, amplitudes_v: Option<Vec<f64>>) -> PyResult<Vec<f64>> {
    let a = amplitudes_v.unwrap_or_else(|| scene.sweep.ac_amplitudes_v.clone());
    if a.is_empty() {
        return Err(invalid(
            "amplitudes_v",
            "no amplitudes: give a list or a [sweep] list in the scene",
        ));
    }
    for (i, &v) in a.iter().enumerate() {
        non_negative(&format!("amplitudes_v[{i}]"), v, "V")?;
    }
    Ok(a)
}

fn threads_of(threads: Option<i128>) -> PyResult<Option<usize>> {
    threads.map(|t| count("threads", t, 1)).transpose()
}

/// One cycle per AC amplitude (V; default: the scene's sweep list), in parallel on rayon
/// (`threads` threads, default all cores) with the GIL released, each run once: a list of
/// `Cycle` (status `"unchecked"`), in the order of the amplitudes, as `hdi sweep --no-refine`
/// prints them; results do not depend on the thread count.
#[pyfunction]
#[pyo3(signature = (target, amplitudes_v = None, *, triggered = false, method = None, rtol = None, atol_nm = None, threads = None))]
fn ac_sweep<'py>(
    py: Python<'py>,
    target: &Bound<'py, PyAny>,
    amplitudes_v: Option<Vec<f64>>,
    triggered: bool,
    method: Option<&str>,
    rtol: Option<f64>,
    atol_nm: Option<f64>,
    threads: Option<i128>,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let threads = threads_of(threads)?;
    let setup = cycle_setup(py, target, triggered, method, rtol, atol_nm)?;
    let amplitudes = amplitudes_or_scene(&setup.scene, amplitudes_v)?;
    let rows = on_own_thread(
        py,
        || {
            on_threads(threads, || {
                analysis::ac_sweep(&setup.model, &setup.programme, &setup.opts, &amplitudes)
            })
        },
        to_py_err,
    )?;
    rows.into_iter()
        .map(|c| {
            let rec = CycleRecord::unchecked(&setup.scene.name, &setup.programme, c, &setup.opts);
            record(py, "Cycle", &to_value(&rec)?)
        })
        .collect()
}

/// `ac_sweep` with the tolerances refined per amplitude (tenfold tighter per run, at most
/// `max_runs` runs) until touchdown and take-off move by at most `power_tol_mw` (mW) and the
/// mean temperature rise by at most `temperature_tol_k` (K) over `agreeing_runs` successive runs.
/// Returns a list of `Cycle`, as `hdi sweep` prints them; check `status` (and `flags`) before
/// trusting a row.
#[pyfunction]
#[pyo3(signature = (target, power_tol_mw, amplitudes_v = None, *, temperature_tol_k = 0.05, max_runs = 4, agreeing_runs = 2, triggered = false, method = None, rtol = None, atol_nm = None, threads = None))]
fn ac_sweep_refined<'py>(
    py: Python<'py>,
    target: &Bound<'py, PyAny>,
    power_tol_mw: f64,
    amplitudes_v: Option<Vec<f64>>,
    temperature_tol_k: f64,
    max_runs: i128,
    agreeing_runs: i128,
    triggered: bool,
    method: Option<&str>,
    rtol: Option<f64>,
    atol_nm: Option<f64>,
    threads: Option<i128>,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let threads = threads_of(threads)?;
    if !(power_tol_mw.is_finite() && power_tol_mw > 0.0) {
        return Err(invalid(
            "power_tol_mw",
            format!("must be finite and > 0 mW, got {power_tol_mw} mW"),
        ));
    }
    if !(temperature_tol_k.is_finite() && temperature_tol_k > 0.0) {
        return Err(invalid(
            "temperature_tol_k",
            format!("must be finite and > 0 K, got {temperature_tol_k} K"),
        ));
    }
    let max_runs = count("max_runs", max_runs, 2)?;
    let agreeing_runs = count("agreeing_runs", agreeing_runs, 2)?;
    if agreeing_runs > max_runs {
        return Err(invalid(
            "agreeing_runs",
            format!("must be at most max_runs ({max_runs}), got {agreeing_runs}"),
        ));
    }
    let setup = cycle_setup(py, target, triggered, method, rtol, atol_nm)?;
    let amplitudes = amplitudes_or_scene(&setup.scene, amplitudes_v)?;
    let refine = Refinement {
        temperature_tol: temperature_tol_k,
        max_runs,
        agreeing_runs,
        ..Refinement::new(units::mw(power_tol_mw))
    };
    let rows = on_own_thread(
        py,
        || {
            on_threads(threads, || {
                analysis::ac_sweep_refined(
                    &setup.model,
                    &setup.programme,
                    &setup.opts,
                    &amplitudes,
                    &refine,
                )
            })
        },
        to_py_err,
    )?;
    rows.into_iter()
        .map(|r| {
            let rec = CycleRecord::refined(&setup.scene.name, &setup.programme, r);
            record(py, "Cycle", &to_value(&rec)?)
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// Linear response

/// A mode's serde form with its shape cut to the structure's `dofs` coordinates.
fn mode_value(m: &analysis::Mode, dofs: usize) -> PyResult<Value> {
    let mut v = to_value(m)?;
    v["shape"] = to_value(&m.shape.iter().take(dofs).collect::<Vec<_>>())?;
    Ok(v)
}

/// The linear response about the flying equilibrium at one heater power.
#[pyclass(module = "hdi_tribology", frozen)]
struct LinearResponse {
    inner: analysis::LinearResponse,
    dofs: usize,
}

/// One mode as pickled: eigenvalue (re, im), frequency, damping ratio, shape (`MAX_DOF`).
type ModeState = (f64, f64, f64, f64, Vec<f64>);
/// An equilibrium as pickled: d, y, q (`MAX_DOF`), protrusion, power, stiffness, interface
/// force, contact force.
type EquilibriumState = (f64, f64, Vec<f64>, f64, f64, f64, f64, f64);
/// A whole response as pickled: every number it holds, so it comes back to the bit: dofs, the
/// equilibrium, the modes, stable, gain at 2f, force at 2f, dither, the state's size n, A
/// (row by row), u and c.
type ResponseState = (
    usize,
    EquilibriumState,
    Vec<ModeState>,
    bool,
    f64,
    f64,
    f64,
    usize,
    Vec<f64>,
    Vec<f64>,
    Vec<f64>,
);

impl LinearResponse {
    fn state(&self) -> ResponseState {
        let r = &self.inner;
        let e = &r.equilibrium;
        let ss = &r.state_space;
        let n = ss.a.nrows();
        (
            self.dofs,
            (
                e.d,
                e.y,
                e.q.iter().copied().collect(),
                e.protrusion,
                e.power,
                e.stiffness,
                e.interface_force,
                e.contact_force,
            ),
            r.modes
                .iter()
                .map(|m| (m.re, m.im, m.frequency, m.damping_ratio, m.shape.to_vec()))
                .collect(),
            r.stable,
            r.gain_at_2f,
            r.force_at_2f,
            r.dither_amplitude,
            n,
            (0..n)
                .flat_map(|i| (0..n).map(move |j| (i, j)))
                .map(|(i, j)| ss.a[(i, j)])
                .collect(),
            ss.input.iter().copied().collect(),
            ss.output.iter().copied().collect(),
        )
    }

    fn from_state(s: ResponseState) -> PyResult<Self> {
        let (dofs, e, modes, stable, gain, force, dither, n, a, input, output) = s;
        let bad = |what: &str| invalid("state", format!("not a pickled LinearResponse: {what}"));
        let coordinates = |v: &[f64], what: &str| -> PyResult<[f64; MAX_DOF]> {
            v.try_into().map_err(|_| bad(what))
        };
        if a.len() != n * n || input.len() != n || output.len() != n {
            return Err(bad("the state-space matrices do not fit their size"));
        }
        let (d, y, q, protrusion, power, stiffness, interface_force, contact_force) = e;
        let inner = analysis::LinearResponse {
            equilibrium: analysis::Equilibrium {
                d,
                y,
                q: Dofs::from(coordinates(&q, "q")?),
                protrusion,
                power,
                stiffness,
                interface_force,
                contact_force,
            },
            modes: modes
                .into_iter()
                .map(|(re, im, frequency, damping_ratio, shape)| {
                    Ok(analysis::Mode {
                        re,
                        im,
                        frequency,
                        damping_ratio,
                        shape: coordinates(&shape, "shape")?,
                    })
                })
                .collect::<PyResult<_>>()?,
            stable,
            gain_at_2f: gain,
            force_at_2f: force,
            dither_amplitude: dither,
            state_space: StateSpace {
                a: DMatrix::from_row_slice(n, n, &a),
                input: DVector::from_vec(input),
                output: DVector::from_vec(output),
            },
        };
        Ok(LinearResponse { inner, dofs })
    }
}

#[pymethods]
impl LinearResponse {
    /// The equilibrium (under the mean V²).
    #[getter]
    fn equilibrium<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        record(
            py,
            "Equilibrium",
            &equilibrium_value(&self.inner.equilibrium, self.dofs)?,
        )
    }
    /// Every mode (`Mode`: eigenvalue, frequency, damping ratio, shape), by ascending
    /// frequency: one pair of complex eigenvalues per vibrating degree of freedom, plus real ones
    /// for overdamped motions and lags.
    #[getter]
    fn modes<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyAny>>> {
        self.inner
            .modes
            .iter()
            .map(|m| record(py, "Mode", &mode_value(m, self.dofs)?))
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
    /// The response as plain Python values (`hdi_tribology.analysis.LinearResponse`'s serde
    /// form: the equilibrium, the modes, `stable`, `gain_at_2f_m_per_n`, `force_at_2f_n`,
    /// `dither_amplitude_m`).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let mut v = to_value(&self.inner)?;
        v["equilibrium"] = equilibrium_value(&self.inner.equilibrium, self.dofs)?;
        v["modes"] = Value::Array(
            self.inner
                .modes
                .iter()
                .map(|m| mode_value(m, self.dofs))
                .collect::<PyResult<_>>()?,
        );
        json_to_py(py, &v)
    }
    /// Equal when every number is: the equilibrium, the modes, the figures at 2f and the
    /// state-space matrices.
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<LinearResponse>()
            .is_ok_and(|o| self.dofs == o.get().dofs && self.inner == o.get().inner)
    }
    /// Pickles every number it holds: it comes back equal, to the bit.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (ResponseState,))> {
        Ok((slf.get_type().getattr("_from_state")?, (slf.get().state(),)))
    }
    /// The response from the state `__reduce__` gives (for pickle).
    #[staticmethod]
    fn _from_state(state: ResponseState) -> PyResult<Self> {
        Self::from_state(state)
    }
    fn __repr__(&self) -> String {
        format!(
            "LinearResponse(power_w={}, d_m={}, stable={}, dither_amplitude_m={})",
            self.inner.equilibrium.power,
            self.inner.equilibrium.d,
            if self.inner.stable { "True" } else { "False" },
            self.inner.dither_amplitude
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
    let power = units::mw(non_negative("power_mw", power_mw, "mW")?);
    let (_, model) = model_of(py, target)?;
    let inner = interruptible(py, || analysis::linear_response(&model, power))?;
    Ok(LinearResponse {
        inner,
        dofs: model.structure().dofs(),
    })
}

/// The stable flying equilibrium at heater power `power_mw` (mW), reached scanning down from the
/// largest tabulated gap, under the time-mean V² of the voltage (the scene's, with AC amplitude
/// `v_ac` in V when given): the equilibrium `linear_response` linearises about. Raises
/// `NoConvergenceError`/`AnalysisError` when the flying branch ends (fold) below that power:
/// the head is then in contact.
#[pyfunction]
#[pyo3(signature = (target, power_mw, *, v_ac = None))]
fn flying_equilibrium<'py>(
    py: Python<'py>,
    target: &Bound<'py, PyAny>,
    power_mw: f64,
    v_ac: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let power = units::mw(non_negative("power_mw", power_mw, "mW")?);
    let (_, model) = model_of(py, target)?;
    let changed = at_amplitude(&model, v_ac)?;
    let m: &SliderModel = changed.as_ref().unwrap_or(&model);
    let e = interruptible(py, || {
        analysis::flying_equilibrium(m, power, m.voltage().mean_squared(), &ScanGrid::default())
    })?;
    record(
        py,
        "Equilibrium",
        &equilibrium_value(&e, model.structure().dofs())?,
    )
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
    settle: i128,
    periods: i128,
    method: Option<&str>,
    rtol: Option<f64>,
    atol_nm: Option<f64>,
) -> PyResult<f64> {
    let power = units::mw(non_negative("power_mw", power_mw, "mW")?);
    let settle = count("settle", settle, 0)?;
    let periods = count("periods", periods, 1)?;
    let setup = cycle_setup(py, target, false, method, rtol, atol_nm)?;
    let changed = at_amplitude(&setup.model, v_ac)?;
    let m: &SliderModel = changed.as_ref().unwrap_or(&setup.model);
    interruptible(py, || {
        analysis::response::simulated_dither(m, power, &setup.opts, settle, periods)
    })
}

// ---------------------------------------------------------------------------------------------
// Calibration

/// Touchdown calibration: heater steps of `step_mw` from `start_mw` (default: the power whose
/// protrusion leaves 5 nm of the nominal clearance) up to `max_mw` (default `start_mw + 60`)
/// until the detector fires, then down to take-off; the heater is set `margin_mw` below
/// touchdown. Detectors: `"mean"` (the scene's), `"ae"` (acoustic-emission proxy),
/// `"vibration"`. `dither_v` adds an AC dither (V) while calibrating. Returns a `Calibration`,
/// as `hdi calibrate` prints it.
#[pyfunction]
#[pyo3(signature = (target, *, detector = "mean", start_mw = None, step_mw = 0.5, max_mw = None, margin_mw = 15.0, dither_v = None, find_takeoff = true))]
fn calibrate<'py>(
    py: Python<'py>,
    target: &Bound<'py, PyAny>,
    detector: &str,
    start_mw: Option<f64>,
    step_mw: f64,
    max_mw: Option<f64>,
    margin_mw: f64,
    dither_v: Option<f64>,
    find_takeoff: bool,
) -> PyResult<Bound<'py, PyAny>> {
    if let Some(s) = start_mw {
        non_negative("start_mw", s, "mW")?;
    }
    if let Some(m) = max_mw {
        non_negative("max_mw", m, "mW")?;
    }
    if !(step_mw.is_finite() && step_mw > 0.0) {
        return Err(invalid(
            "step_mw",
            format!("must be finite and > 0 mW, got {step_mw} mW"),
        ));
    }
    non_negative("margin_mw", margin_mw, "mW")?;
    let (scene, model) = model_of(py, target)?;
    let start_mw = start_mw.unwrap_or_else(|| {
        1e3 * ((scene.nominal_clearance_m - 5e-9) / scene.heater.efficiency_m_per_w).max(0.0)
    });
    let max_mw = max_mw.unwrap_or(start_mw + 60.0);
    let mut opts = CalibrationOptions::from_mw(start_mw, step_mw, max_mw, margin_mw);
    opts.find_takeoff = find_takeoff;
    let dithered = at_amplitude(&model, dither_v).map_err(|_| {
        invalid(
            "dither_v",
            format!("must be finite and ≥ 0 V, got {dither_v:?} V"),
        )
    })?;
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
    let clock = std::time::Instant::now();
    let c = interruptible(py, || calibration::calibrate(model, det.as_mut(), &opts))?;
    let rec = CalibrationRecord::new(
        &scene.name,
        detector,
        c,
        find_takeoff,
        clock.elapsed().as_secs_f64(),
    );
    record(py, "Calibration", &to_value(&rec)?)
}

// ---------------------------------------------------------------------------------------------
// Drive

/// What a drive is made of: one `Scene` or `Model` for every head, or a list of scenes (one per
/// head).
enum Heads {
    Model(Arc<SliderModel>),
    Scenes(Vec<hdi_tribology::scene::Scene>),
}

fn heads_of(scene: &Bound<'_, PyAny>) -> PyResult<Heads> {
    const WANT: &str = "scene: expected a Scene, a Model or a list of Scenes (one per head)";
    if let Ok(m) = scene.cast::<Model>() {
        return Ok(Heads::Model(m.get().model.clone()));
    }
    if let Ok(s) = scene.cast::<Scene>() {
        return Ok(Heads::Scenes(vec![s.get().get()]));
    }
    if scene.is_instance_of::<pyo3::types::PyString>() {
        return Err(PyTypeError::new_err(WANT));
    }
    let Ok(items) = scene.try_iter() else {
        return Err(PyTypeError::new_err(WANT));
    };
    let mut scenes = Vec::new();
    for item in items {
        let item = item?;
        let s = item
            .cast::<Scene>()
            .map_err(|_| PyTypeError::new_err(WANT))?;
        scenes.push(s.get().get());
    }
    if scenes.is_empty() {
        return Err(invalid("scene", "an empty list: one scene per head"));
    }
    Ok(Heads::Scenes(scenes))
}

/// The drive of a `Drive`, a `MultiDrive` or a replay: the (first) scene in its zone with its
/// `[drive]` section, the keyword `settings` (the names of `DriveSpec::settings`, in their
/// engineering units) over it, the seed, and the tolerances; a list of scenes gives one head
/// each (all in the first scene's zone). `one_head` refuses more than one head (a `Drive`).
fn plant_of(
    py: Python<'_>,
    scene: &Bound<'_, PyAny>,
    seed: u64,
    flat_disk: bool,
    settings: Option<&Bound<'_, PyDict>>,
    atol_pm: [Option<f64>; 2],
    one_head: bool,
) -> PyResult<MultiPlant> {
    let heads = heads_of(scene)?;
    let mut spec = match &heads {
        Heads::Scenes(s) => s[0].drive.clone().unwrap_or_default(),
        Heads::Model(_) => DriveSpec::default(),
    };
    let mut heads_given = false;
    let mut bounded = None;
    let mut scheme = None;
    if let Some(kw) = settings {
        for (k, v) in kw.iter() {
            let key: String = k.extract()?;
            if key == "steps_per_period" {
                // The bounded mode (`DriveOptions::bounded`): the plant checks the range and
                // names `steps_per_period`, as written here.
                let n: usize = v
                    .extract()
                    .map_err(|_| invalid(&key, "must be a whole number of steps, at least 1"))?;
                bounded = Some(n);
                continue;
            }
            if key == "scheme" {
                // `DriveOptions::scheme` by its name; a bad one is named `scheme`.
                let name: String = v
                    .extract()
                    .map_err(|_| invalid(&key, "must be \"integrator\" or \"exponential\""))?;
                scheme = Some(name.parse::<DriveScheme>().py()?);
                continue;
            }
            if key == "waviness_orders" {
                let o: [u32; 2] = v.extract()?;
                spec.set_waviness_orders(o, &key).py()?;
                continue;
            }
            if !DriveSpec::settings().any(|(n, _)| n == key) {
                return Err(PyTypeError::new_err(format!(
                    "unexpected keyword argument '{key}'; the drive settings are {}",
                    DriveSpec::settings()
                        .map(|(n, _)| n)
                        .collect::<Vec<_>>()
                        .join(", ")
                )));
            }
            let x: f64 = v.extract().map_err(|_| invalid(&key, "must be a number"))?;
            spec.set(&key, x, &key).py()?;
            heads_given |= key == "heads";
        }
    }
    if let Heads::Scenes(s) = &heads {
        if s.len() > 1 {
            if heads_given && spec.heads as usize != s.len() {
                return Err(invalid(
                    "heads",
                    format!(
                        "{} heads for a list of {} scenes, one per head",
                        spec.heads,
                        s.len()
                    ),
                ));
            }
            spec.heads = s.len() as u32;
        }
    }
    if one_head && spec.heads != 1 {
        return Err(invalid(
            "heads",
            format!(
                "a Drive is one head, got {}: MultiDrive steps several on one disk",
                spec.heads
            ),
        ));
    }
    let mut opts = DriveOptions::from_spec(&spec);
    if flat_disk {
        opts.disk = DiskSpec::flat();
    }
    let mut opts = opts
        .with_tolerances_pm(atol_pm[0], atol_pm[1], ["atol_pm", "atol_flight_pm"])
        .py()?;
    if let Some(n) = bounded {
        opts = opts.bounded(n);
    }
    if let Some(s) = scheme {
        opts.scheme = s;
    }
    let radius = spec.radius_m.unwrap_or(DEFAULT_RADIUS);
    let n = spec.heads as usize;
    // A `Model` drives as it is (its terms with memory included), a `Scene` at its own zone.
    match heads {
        Heads::Model(model) => interruptible(py, || {
            MultiPlant::of_plant(Plant::from_model(&model, radius, seed, opts)?, n)
        }),
        Heads::Scenes(scenes) if scenes.len() == 1 => interruptible(py, || {
            let zone = spec_zone(&scenes[0], &spec)?;
            MultiPlant::uniform(&scenes[0], &zone, n, seed, opts)
        }),
        Heads::Scenes(scenes) => interruptible(py, || {
            let zone = spec_zone(&scenes[0], &spec)?;
            let plants = scenes
                .iter()
                .enumerate()
                .map(|(k, s)| {
                    // Each head its own slider at the drive's radius and spindle speed.
                    let mut z = hdi_tribology::drive::scene_zone(s, zone.radius)?;
                    z.disk_speed = zone.disk_speed;
                    Plant::new(
                        s,
                        &z,
                        hdi_tribology::drive::head_seed(seed, k),
                        opts.clone(),
                    )
                    .map_err(|e| match e {
                        hdi_tribology::Error::InvalidInput { field, reason } => {
                            hdi_tribology::Error::invalid(format!("scene[{k}].{field}"), reason)
                        }
                        other => other,
                    })
                })
                .collect::<hdi_tribology::Result<Vec<_>>>()?;
            MultiPlant::new(plants)
        }),
    }
}

/// A command checked as a command file's row, in the argument names of `Drive.step`
/// (`name(arg)` gives the name an error shows).
fn check_command(c: &Command, name: impl Fn(&str) -> String) -> PyResult<()> {
    let row = CommandRow {
        time_s: 0.0,
        heater_mw: c.heater_power_mw,
        voltage_dc_v: c.dc_voltage_v,
        voltage_ac_v: c.ac_amplitude_v,
        ac_frequency_khz: c.ac_frequency_khz,
    };
    let arg = |column: &str| {
        name(match column {
            "heater_mw" => "heater_power_mw",
            "voltage_dc_v" => "dc_voltage_v",
            "voltage_ac_v" => "ac_amplitude_v",
            other => other,
        })
    };
    check_commands(&[row, CommandRow { time_s: 1.0, ..row }], "step", |_, n| {
        arg(n)
    })
    .py()
}

fn check_period(period_s: f64) -> PyResult<()> {
    if !(period_s.is_finite() && period_s > 0.0 && period_s <= 1.0) {
        return Err(invalid(
            "period_s",
            format!("must be a period in (0, 1] s, got {period_s} s"),
        ));
    }
    Ok(())
}

/// One period of a drive, the command and period checked as a command file's row (in the
/// argument names of `Drive.step`).
fn step_checked(drive: &mut Drive, c: &Command, period_s: f64) -> PyResult<Sensors> {
    check_command(c, str::to_string)?;
    check_period(period_s)?;
    drive.step(c, period_s).py()
}

/// A `Sensors` record: the drive's sensors as the crate serializes them, the read-back
/// amplitudes flat as in the C ABI, and the harmonic-ratio clearance change against the first
/// period's log ratio `lr0`.
fn sensors_value(s: &Sensors, lr0: f64, wavelength_m: f64) -> PyResult<Value> {
    let row = sensor_row(s, lr0, wavelength_m);
    let mut v = to_value(s)?;
    if let Value::Object(m) = &mut v {
        m.remove("readback");
        m.insert(
            "readback_fundamental_v".into(),
            to_value(&s.readback.fundamental_v)?,
        );
        m.insert("readback_third_v".into(), to_value(&s.readback.third_v)?);
        m.insert("hr_clearance_change_nm".into(), to_value(&row[6])?);
    }
    Ok(v)
}

/// A simulated drive for firmware prototyping (the native half of `hdi_tribology.Drive`, which
/// checks that it is used from the thread that made it: the integrator's event closures are not
/// `Send`). See `hdi_tribology.Drive`.
#[pyclass(module = "hdi_tribology._core", name = "Drive", unsendable)]
struct PyDrive {
    inner: Drive,
    wavelength: f64,
    /// The first period's read-back log ratio: the reference of the harmonic-ratio change.
    reference: Option<f64>,
}

#[pymethods]
impl PyDrive {
    #[new]
    #[pyo3(signature = (scene, *, seed = 1, flat_disk = false, atol_pm = None, atol_flight_pm = None, **settings))]
    fn new(
        py: Python<'_>,
        scene: &Bound<'_, PyAny>,
        seed: i128,
        flat_disk: bool,
        atol_pm: Option<f64>,
        atol_flight_pm: Option<f64>,
        settings: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let seed = seed_of("seed", seed)?;
        let tol = [atol_pm, atol_flight_pm];
        let plant = plant_of(py, scene, seed, flat_disk, settings, tol, true)?;
        let Some(plant) = plant.head(0) else {
            return Err(invalid("heads", "a Drive has one head"));
        };
        let wavelength = plant.sensor_spec().readback.wavelength;
        Ok(PyDrive {
            inner: plant.drive().py()?,
            wavelength,
            reference: None,
        })
    }

    /// Holds the command — heater power `heater_power_mw` (mW), DC voltage `dc_voltage_v` (V),
    /// AC dither `ac_amplitude_v` (V) at `ac_frequency_khz` (kHz), the names of the Rust
    /// `Command` and the C `HdiCommand` — for one controller period of `period_s` (s), and
    /// returns the `Sensors` at its end (the fields of the C `HdiSensors`, the truth in
    /// `truth`, and `hr_clearance_change_nm`, the harmonic-ratio clearance change since the
    /// drive's first period).
    #[pyo3(signature = (heater_power_mw, *, dc_voltage_v = 0.0, ac_amplitude_v = 0.0, ac_frequency_khz = 0.0, period_s = 50e-6))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        heater_power_mw: f64,
        dc_voltage_v: f64,
        ac_amplitude_v: f64,
        ac_frequency_khz: f64,
        period_s: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let command = Command {
            heater_power_mw,
            dc_voltage_v,
            ac_amplitude_v,
            ac_frequency_khz,
        };
        let s = step_checked(&mut self.inner, &command, period_s)?;
        let lr0 = *self.reference.get_or_insert(s.readback.log_ratio());
        record(py, "Sensors", &sensors_value(&s, lr0, self.wavelength)?)
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

    /// The integrator's work so far, as the crate serializes it: a dict of `accepted`,
    /// `rejected`, `rhs_evals`, `jac_evals`, `lu_decomps`, … .
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &to_value(&self.inner.stats())?)
    }

    /// The seed of the disk's random waviness and of the sensor noise.
    #[getter]
    fn seed(&self) -> u64 {
        self.inner.plant().seed()
    }

    /// How the last period was advanced: a dict of `steps` and `error_estimate` (the bounded
    /// mode's flag: above 1 where a step missed the tolerances).
    #[getter]
    fn last_period<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &to_value(&self.inner.last_period())?)
    }

    /// The zone's scene name and radius (mm).
    #[getter]
    fn zone(&self) -> (String, f64) {
        let z = self.inner.plant().zone();
        (z.name.clone(), z.radius * 1e3)
    }
}

/// One command argument of `MultiDrive.step`: a number for every head, or one per head.
fn per_head(v: &Bound<'_, PyAny>, name: &str, heads: usize) -> PyResult<Vec<f64>> {
    if let Ok(x) = v.extract::<f64>() {
        return Ok(vec![x; heads]);
    }
    let xs: Vec<f64> = v.extract().map_err(|_| {
        invalid(
            name,
            "must be a number or a sequence of numbers, one per head",
        )
    })?;
    if xs.len() != heads {
        return Err(invalid(
            name,
            format!(
                "one value per head: the drive has {heads} heads, got {}",
                xs.len()
            ),
        ));
    }
    Ok(xs)
}

/// A drive of several heads on one disk for firmware prototyping (the native half of
/// `hdi_tribology.MultiDrive`). See `hdi_tribology.MultiDrive`.
#[pyclass(module = "hdi_tribology._core", name = "MultiDrive", unsendable)]
struct PyMultiDrive {
    inner: MultiDrive,
    wavelengths: Vec<f64>,
    seeds: Vec<u64>,
    /// Each head's first read-back log ratio: the reference of its harmonic-ratio change.
    reference: Vec<Option<f64>>,
    out: Vec<Sensors>,
}

#[pymethods]
impl PyMultiDrive {
    #[new]
    #[pyo3(signature = (scene, *, seed = 1, flat_disk = false, atol_pm = None, atol_flight_pm = None, **settings))]
    fn new(
        py: Python<'_>,
        scene: &Bound<'_, PyAny>,
        seed: i128,
        flat_disk: bool,
        atol_pm: Option<f64>,
        atol_flight_pm: Option<f64>,
        settings: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let seed = seed_of("seed", seed)?;
        let tol = [atol_pm, atol_flight_pm];
        let plant = plant_of(py, scene, seed, flat_disk, settings, tol, false)?;
        let n = plant.heads();
        let head = |k: usize| {
            plant
                .head(k)
                .ok_or_else(|| invalid("heads", "no such head"))
        };
        let mut wavelengths = Vec::with_capacity(n);
        let mut seeds = Vec::with_capacity(n);
        for k in 0..n {
            wavelengths.push(head(k)?.sensor_spec().readback.wavelength);
            seeds.push(head(k)?.seed());
        }
        Ok(PyMultiDrive {
            inner: plant.drive().py()?,
            wavelengths,
            seeds,
            reference: vec![None; n],
            out: vec![Sensors::default(); n],
        })
    }

    /// Holds head `k`'s command for one controller period of `period_s` (s) on every head
    /// and returns the list of their `Sensors`, in head order. Each of `heater_power_mw` (mW),
    /// `dc_voltage_v` (V), `ac_amplitude_v` (V) and `ac_frequency_khz` (kHz) is a number for
    /// every head or a sequence of one per head.
    #[pyo3(signature = (heater_power_mw, *, dc_voltage_v = None, ac_amplitude_v = None, ac_frequency_khz = None, period_s = 50e-6))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        heater_power_mw: &Bound<'py, PyAny>,
        dc_voltage_v: Option<&Bound<'py, PyAny>>,
        ac_amplitude_v: Option<&Bound<'py, PyAny>>,
        ac_frequency_khz: Option<&Bound<'py, PyAny>>,
        period_s: f64,
    ) -> PyResult<Bound<'py, PyList>> {
        let n = self.inner.heads();
        let arg = |v: Option<&Bound<'py, PyAny>>, name: &str| match v {
            Some(v) => per_head(v, name, n),
            None => Ok(vec![0.0; n]),
        };
        let p = per_head(heater_power_mw, "heater_power_mw", n)?;
        let (dc, ac, f) = (
            arg(dc_voltage_v, "dc_voltage_v")?,
            arg(ac_amplitude_v, "ac_amplitude_v")?,
            arg(ac_frequency_khz, "ac_frequency_khz")?,
        );
        let commands: Vec<Command> = (0..n)
            .map(|k| Command {
                heater_power_mw: p[k],
                dc_voltage_v: dc[k],
                ac_amplitude_v: ac[k],
                ac_frequency_khz: f[k],
            })
            .collect();
        for (k, c) in commands.iter().enumerate() {
            check_command(c, |name| format!("{name}[{k}]"))?;
        }
        check_period(period_s)?;
        self.inner
            .step_into(&commands, period_s, &mut self.out)
            .py()?;
        let list = PyList::empty(py);
        for (k, s) in self.out.iter().enumerate() {
            let lr0 = *self.reference[k].get_or_insert(s.readback.log_ratio());
            list.append(record(
                py,
                "Sensors",
                &sensors_value(s, lr0, self.wavelengths[k])?,
            )?)?;
        }
        Ok(list)
    }

    /// The number of heads.
    #[getter]
    fn heads(&self) -> usize {
        self.inner.heads()
    }

    /// Simulated time so far (s): one clock for every head.
    #[getter]
    fn time_s(&self) -> f64 {
        self.inner.time()
    }

    /// Each head's seed (its surface and sensor noise): `head_seed(seed, k)`.
    #[getter]
    fn seeds(&self) -> Vec<u64> {
        self.seeds.clone()
    }
}

/// Replays commands through a new drive, as `hdi drive SCENE --commands FILE` does, and returns
/// the sensor columns as float64 arrays (the CSV's columns, `SENSOR_COLUMNS`; units in their
/// names), bit for bit the CLI's. Each command holds from its `time_s` until the next; the last
/// time ends the run. `voltage_ac_v` and `ac_frequency_khz` default to zeros; `atol_pm` and
/// `atol_flight_pm` are the tolerances of `Drive`. The GIL is released while the drive runs,
/// and Ctrl-C stops it.
#[pyfunction]
#[pyo3(signature = (scene, time_s, heater_mw, voltage_dc_v, voltage_ac_v = None, ac_frequency_khz = None, *, rate_khz = 20.0, seed = 1, flat_disk = false, atol_pm = None, atol_flight_pm = None, **settings))]
fn replay<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    time_s: Vec<f64>,
    heater_mw: Vec<f64>,
    voltage_dc_v: Vec<f64>,
    voltage_ac_v: Option<Vec<f64>>,
    ac_frequency_khz: Option<Vec<f64>>,
    rate_khz: f64,
    seed: i128,
    flat_disk: bool,
    atol_pm: Option<f64>,
    atol_flight_pm: Option<f64>,
    settings: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let seed = seed_of("seed", seed)?;
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
        flat_disk,
        settings,
        [atol_pm, atol_flight_pm],
        false,
    )?;
    let dt = 1e-3 / rate_khz;
    let (heads, columns) = interruptible(py, || {
        let mut heads: Vec<i64> = Vec::new();
        let mut cols: Vec<Vec<f64>> = vec![Vec::new(); SENSOR_COLUMNS.len()];
        replay_heads_each(&plant, &rows, dt, |head, row| {
            heads.push(head as i64);
            for (c, v) in cols.iter_mut().zip(row) {
                c.push(*v);
            }
            Ok(())
        })?;
        Ok((heads, cols))
    })?;
    let out = PyDict::new(py);
    if plant.heads() > 1 {
        out.set_item("head", PyArray1::from_vec(py, heads))?;
    }
    for (name, col) in SENSOR_COLUMNS.iter().zip(columns) {
        out.set_item(name, array(py, col))?;
    }
    Ok(out)
}

// ---------------------------------------------------------------------------------------------
// Fit

/// `DataFileError` with the bad file's parts.
fn data_error(d: hdi_tribology::error::DataError) -> PyErr {
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

/// Fits the `free` parameters of `scene` to measured curves (CSV files in engineering units,
/// see `docs/fit.md`). Each parameter is named as a scene file names it, in that name's unit,
/// with optional bounds: `"height_sigma_nm"`, `"efficiency_nm_per_mw=0.05:0.2"`.
///
/// Returns a dict: the JSON `hdi fit` prints, with `scene` the fitted `Scene`: `parameters`
/// (list of dicts: name, value, unit, standard_error, …), `correlation`, `residuals`,
/// `identifiability`, `points`, `chi2`, `residual_scale`, `converged`, `termination`,
/// `evaluations`, `starts`, `integration`, `trusted` and `warnings`. Check `trusted` and
/// `warnings`. Ctrl-C stops it.
#[pyfunction]
#[pyo3(signature = (scene, data, free, *, starts = 1, seed = 1, max_evaluations = 400))]
fn fit<'py>(
    py: Python<'py>,
    scene: &Scene,
    data: Vec<std::path::PathBuf>,
    free: Vec<String>,
    starts: i128,
    seed: i128,
    max_evaluations: i128,
) -> PyResult<Bound<'py, PyAny>> {
    let options = FitOptions {
        starts: count("starts", starts, 1)?,
        seed: seed_of("seed", seed)?,
        max_evaluations: count("max_evaluations", max_evaluations, 1)?,
        ..FitOptions::default()
    };
    if data.is_empty() {
        return Err(invalid("data", "give at least one data file"));
    }
    if free.is_empty() {
        return Err(invalid("free", "give at least one parameter to fit"));
    }
    let scene_in = scene.get();
    let result = on_own_thread(
        py,
        || -> Result<_, hdi_tribology::Error> {
            let sets = data
                .iter()
                .map(DataSet::from_path)
                .collect::<Result<Vec<_>, _>>()?;
            let free = free
                .iter()
                .enumerate()
                .map(|(i, f)| {
                    f.parse::<FreeParameter>().map_err(|e| match e {
                        hdi_tribology::Error::InvalidInput { reason, .. } => {
                            hdi_tribology::Error::invalid(format!("free[{i}]"), reason)
                        }
                        other => other,
                    })
                })
                .collect::<Result<Vec<_>, _>>()?;
            hdi_tribology::fit::fit(&scene_in, &sets, &free, &options)
        },
        to_py_err,
    )?;
    let out = json_to_py(py, &to_value(&result)?)?;
    out.set_item("scene", Scene::of(result.scene))?;
    Ok(out)
}

// ---------------------------------------------------------------------------------------------

/// The native core of the `hdi_tribology` Python package.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // numpy's C API is fetched now, not inside a later call that a pending Ctrl-C could break.
    let _ = PyArray1::<f64>::zeros(m.py(), 0, false);
    m.add_class::<Scene>()?;
    m.add_class::<Model>()?;
    m.add_class::<LinearResponse>()?;
    m.add_class::<PyDrive>()?;
    m.add_class::<PyMultiDrive>()?;
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
