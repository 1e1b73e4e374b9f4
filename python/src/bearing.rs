//! `bearing(geometry, ...)`: the air bearing of a slider's geometry (`hdi_tribology::bearing`):
//! the attitude, the stiffness and damping about it, the load, the pressure field and how the
//! solve converged. The same solve as `hdi bearing GEOMETRY`.

use std::path::PathBuf;

use hdi_tribology::bearing::attitude::LevelReport;
use hdi_tribology::bearing::{solve_attitude, AttitudeOptions, BearingSpec, Interrupt};
use hdi_tribology::ode::Cancel;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::{invalid, on_own_thread, to_py_err, OrPy};

/// The equilibrium of a slider on its air bearing (see `bearing`).
#[pyclass(module = "hdi_tribology", frozen)]
#[derive(PartialEq)]
pub struct AirBearing {
    /// Fly height at the trailing edge's centre (surface depth 0), nm.
    #[pyo3(get)]
    fly_height_nm: f64,
    /// Pitch (positive raises the leading edge), µrad.
    #[pyo3(get)]
    pitch_urad: f64,
    /// Roll (positive raises the +y side), µrad.
    #[pyo3(get)]
    roll_urad: f64,
    /// Spacing at the trailing edge's centre, surface depth included, nm.
    #[pyo3(get)]
    trailing_edge_spacing_nm: f64,
    /// Spacing at the bulge, nm.
    #[pyo3(get)]
    bulge_spacing_nm: f64,
    /// Smallest spacing over the grid's nodes, nm.
    #[pyo3(get)]
    min_spacing_nm: f64,
    /// The bearing's force, mN (the preload at the equilibrium).
    #[pyo3(get)]
    load_mn: f64,
    /// Its pitch and roll moments about the pivot, µN m.
    #[pyo3(get)]
    pitch_moment_un_m: f64,
    #[pyo3(get)]
    roll_moment_un_m: f64,
    /// The bearing number at 10 nm.
    #[pyo3(get)]
    bearing_number: f64,
    /// `K = −∂(force, pitch moment, roll moment)/∂(fly height, pitch, roll)`, SI (N/m, N/rad;
    /// N m/m, N m/rad), rows by load.
    #[pyo3(get)]
    stiffness: [[f64; 3]; 3],
    /// The low-frequency damping, SI (stiffness's units times s).
    #[pyo3(get)]
    damping: [[f64; 3]; 3],
    /// Largest relative imbalance of the force and moments at the end.
    #[pyo3(get)]
    imbalance: f64,
    /// The tolerance it was solved to.
    #[pyo3(get)]
    tolerance: f64,
    levels: Vec<hdi_tribology::bearing::attitude::LevelReport>,
    cells: (usize, usize),
    pressure_pa: Vec<f64>,
    x_um: Vec<f64>,
    y_um: Vec<f64>,
}

#[pymethods]
impl AirBearing {
    /// Whether the force and moments balance the preload and torques to the tolerance.
    #[getter]
    fn converged(&self) -> bool {
        self.imbalance <= self.tolerance
    }
    /// Control volumes `(nx, ny)` of the final grid.
    #[getter]
    fn cells(&self) -> (usize, usize) {
        self.cells
    }
    /// The solve on each grid, coarse to fine: a list of dicts with `cells`, `newton_steps`,
    /// `pressure_newton_steps`, `krylov_iterations`, `relative_imbalance`.
    #[getter]
    fn convergence<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.levels
            .iter()
            .map(|l| {
                let d = PyDict::new(py);
                d.set_item("cells", l.cells)?;
                d.set_item("newton_steps", l.iterations)?;
                d.set_item("pressure_newton_steps", l.pressure_iterations)?;
                d.set_item("krylov_iterations", l.krylov_iterations)?;
                d.set_item("relative_imbalance", l.imbalance)?;
                Ok(d)
            })
            .collect()
    }
    /// Pressure (Pa) per control volume, shape `(ny, nx)`.
    #[getter]
    fn pressure_pa<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let a = PyArray1::from_vec(py, self.pressure_pa.clone());
        Ok(a.reshape([self.cells.1, self.cells.0])?.into_any())
    }
    /// Centres of the control volumes along the slider's length, µm (`nx`).
    #[getter]
    fn x_um<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.x_um.clone())
    }
    /// Centres of the control volumes across its width, µm (`ny`).
    #[getter]
    fn y_um<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.y_um.clone())
    }
    /// Every attribute as plain Python values: the numbers, `stiffness` and `damping` as lists
    /// of rows, `converged`, `cells`, `convergence`, and `pressure_pa` (a list of `ny` rows of
    /// `nx`), `x_um`, `y_um` as lists. `AirBearing._from_dict` gives the result back.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in [
            ("fly_height_nm", self.fly_height_nm),
            ("pitch_urad", self.pitch_urad),
            ("roll_urad", self.roll_urad),
            ("trailing_edge_spacing_nm", self.trailing_edge_spacing_nm),
            ("bulge_spacing_nm", self.bulge_spacing_nm),
            ("min_spacing_nm", self.min_spacing_nm),
            ("load_mn", self.load_mn),
            ("pitch_moment_un_m", self.pitch_moment_un_m),
            ("roll_moment_un_m", self.roll_moment_un_m),
            ("bearing_number", self.bearing_number),
        ] {
            d.set_item(k, v)?;
        }
        d.set_item("stiffness", self.stiffness)?;
        d.set_item("damping", self.damping)?;
        d.set_item("imbalance", self.imbalance)?;
        d.set_item("tolerance", self.tolerance)?;
        d.set_item("converged", self.converged())?;
        d.set_item("cells", self.cells)?;
        d.set_item("convergence", self.convergence(py)?)?;
        let rows: Vec<Vec<f64>> = self
            .pressure_pa
            .chunks(self.cells.0.max(1))
            .map(<[f64]>::to_vec)
            .collect();
        d.set_item("pressure_pa", rows)?;
        d.set_item("x_um", self.x_um.clone())?;
        d.set_item("y_um", self.y_um.clone())?;
        Ok(d)
    }
    /// The result from its `to_dict()` (for pickle).
    #[staticmethod]
    fn _from_dict(d: &Bound<'_, PyDict>) -> PyResult<Self> {
        let get = |k: &str| -> PyResult<Bound<'_, PyAny>> {
            d.get_item(k)?
                .ok_or_else(|| invalid(k, "missing from the AirBearing's dict"))
        };
        let levels = get("convergence")?
            .extract::<Vec<Bound<'_, PyDict>>>()?
            .iter()
            .map(|l| {
                let at = |k: &str| -> PyResult<Bound<'_, PyAny>> {
                    l.get_item(k)?
                        .ok_or_else(|| invalid(k, "missing from a convergence entry"))
                };
                Ok(LevelReport {
                    cells: at("cells")?.extract()?,
                    iterations: at("newton_steps")?.extract()?,
                    pressure_iterations: at("pressure_newton_steps")?.extract()?,
                    krylov_iterations: at("krylov_iterations")?.extract()?,
                    imbalance: at("relative_imbalance")?.extract()?,
                })
            })
            .collect::<PyResult<_>>()?;
        let rows: Vec<Vec<f64>> = get("pressure_pa")?.extract()?;
        Ok(AirBearing {
            fly_height_nm: get("fly_height_nm")?.extract()?,
            pitch_urad: get("pitch_urad")?.extract()?,
            roll_urad: get("roll_urad")?.extract()?,
            trailing_edge_spacing_nm: get("trailing_edge_spacing_nm")?.extract()?,
            bulge_spacing_nm: get("bulge_spacing_nm")?.extract()?,
            min_spacing_nm: get("min_spacing_nm")?.extract()?,
            load_mn: get("load_mn")?.extract()?,
            pitch_moment_un_m: get("pitch_moment_un_m")?.extract()?,
            roll_moment_un_m: get("roll_moment_un_m")?.extract()?,
            bearing_number: get("bearing_number")?.extract()?,
            stiffness: get("stiffness")?.extract()?,
            damping: get("damping")?.extract()?,
            imbalance: get("imbalance")?.extract()?,
            tolerance: get("tolerance")?.extract()?,
            levels,
            cells: get("cells")?.extract()?,
            pressure_pa: rows.concat(),
            x_um: get("x_um")?.extract()?,
            y_um: get("y_um")?.extract()?,
        })
    }
    /// Equal when every attribute is (the pressure field and the convergence included).
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.cast::<AirBearing>().is_ok_and(|o| self == o.get())
    }
    /// Pickles as its `to_dict()`.
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyDict>,))> {
        let d = slf.get().to_dict(slf.py())?;
        Ok((slf.get_type().getattr("_from_dict")?, (d,)))
    }
    fn __repr__(&self) -> String {
        format!(
            "AirBearing(fly_height_nm={:.4}, pitch_urad={:.4}, roll_urad={:.4}, load_mn={:.4}, \
             cells={:?}, converged={})",
            self.fly_height_nm,
            self.pitch_urad,
            self.roll_urad,
            self.load_mn,
            self.cells,
            if self.converged() { "True" } else { "False" }
        )
    }
}

/// The attitude of the slider of the bearing file `geometry` (TOML, JSON or the text format),
/// with `cells` control volumes a side and the disk radius, speed, skew and preload in place of
/// the file's when given.
#[pyfunction]
#[pyo3(signature = (geometry, *, cells=None, radius_mm=None, rpm=None, skew_deg=None, preload_mn=None))]
fn bearing(
    py: Python<'_>,
    geometry: PathBuf,
    cells: Option<usize>,
    radius_mm: Option<f64>,
    rpm: Option<f64>,
    skew_deg: Option<f64>,
    preload_mn: Option<f64>,
) -> PyResult<AirBearing> {
    let mut spec = BearingSpec::from_path(&geometry).py()?;
    if let Some(n) = cells {
        spec.grid.nx = n;
        spec.grid.ny = n;
    }
    let op = &mut spec.operating;
    let overrides = [
        ("radius_mm", radius_mm, &mut op.radius_mm),
        ("rpm", rpm, &mut op.rpm),
        ("skew_deg", skew_deg, &mut op.skew_deg),
        ("preload_mn", preload_mn, &mut op.preload_mn),
    ];
    let mut given = Vec::new();
    for (name, value, slot) in overrides {
        if let Some(v) = value {
            if !v.is_finite() {
                return Err(invalid(name, format!("must be finite, got {v}")));
            }
            *slot = v;
            given.push(name);
        }
    }
    // An argument's error names the argument as the caller wrote it.
    let b = spec.build().map_err(|e| match e {
        hdi_tribology::Error::InvalidInput { field, reason } => {
            let arg = match field.as_str() {
                "grid.nx" | "grid.ny" if cells.is_some() => Some("cells"),
                f => f
                    .strip_prefix("operating.")
                    .and_then(|n| given.iter().copied().find(|g| *g == n)),
            };
            invalid(arg.unwrap_or(&field), reason)
        }
        other => to_py_err(other),
    })?;
    // On a thread of its own, watching a flag that Ctrl-C raises: the solve asks it between
    // its linear solves and stops.
    let opts = AttitudeOptions {
        interrupt: Some(Interrupt::new(Cancel::requested)),
        ..AttitudeOptions::default()
    };
    let (eq, damping) = on_own_thread(
        py,
        || {
            let eq = solve_attitude(&b, &opts)?;
            let c = eq.damping()?;
            Ok::<_, hdi_tribology::Error>((eq, c))
        },
        to_py_err,
    )?;
    let a = eq.attitude;
    Ok(AirBearing {
        fly_height_nm: a.fly_height * 1e9,
        pitch_urad: a.pitch * 1e6,
        roll_urad: a.roll * 1e6,
        trailing_edge_spacing_nm: eq.trailing_edge_spacing() * 1e9,
        bulge_spacing_nm: eq.bulge_spacing() * 1e9,
        min_spacing_nm: eq.min_spacing() * 1e9,
        load_mn: eq.loads[0] * 1e3,
        pitch_moment_un_m: eq.loads[1] * 1e6,
        roll_moment_un_m: eq.loads[2] * 1e6,
        bearing_number: eq.bearing_number(),
        stiffness: eq.stiffness(),
        damping,
        imbalance: eq.levels.last().map_or(f64::INFINITY, |l| l.imbalance),
        tolerance: opts.tolerance,
        levels: eq.levels.clone(),
        cells: eq.reynolds.size(),
        pressure_pa: eq.pressure_pa(),
        x_um: eq.reynolds.grid.xc.iter().map(|x| x * 1e6).collect(),
        y_um: eq.reynolds.grid.yc.iter().map(|y| y * 1e6).collect(),
    })
}

/// Adds `bearing` and its result class to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<AirBearing>()?;
    m.add_function(wrap_pyfunction!(bearing, m)?)
}
