//! The forward model of a fit: parameter values → scene → slider model → predicted curves.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use serde_json::Value;

use super::data::{CurveKind, DataSet, Quantity};
use super::params::{set, Resolved};
use crate::analysis::{
    ac_sweep, static_hysteresis, touchdown_power, CycleOptions, HeaterProgramme, StaticOptions,
};
use crate::force::InterfaceForces;
use crate::model::{SliderModel, Voltage};
use crate::scene::Scene;
use crate::Result;

/// Weight of a value whose file gives no uncertainty (W): residuals are then in milliwatts.
pub(super) const DEFAULT_WEIGHT_W: f64 = 1e-3;

/// Force tables kept for reuse (parameters that do not touch the forces share them).
const CACHED_TABLES: usize = 16;

/// One predicted value (SI).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Predicted {
    pub value: f64,
    /// The model did not detect the transition within the heater programme: `value` is the end of
    /// the programme's range, a bound on the true one.
    pub clipped: bool,
}

/// Evaluates the model for parameter vectors (in the parameters' own units).
pub(super) struct Evaluator<'a> {
    base: Value,
    pub params: &'a [Resolved],
    pub data: &'a [DataSet],
    static_table_rel_tol: f64,
    /// Upper end of the static curves' tables, pinned to the starting scene's so that the
    /// nominal clearance does not change the tables (beyond it forces are exact quadrature).
    static_d_max: Option<f64>,
    tables: Mutex<Vec<(String, InterfaceForces)>>,
    pub evaluations: AtomicUsize,
}

impl<'a> Evaluator<'a> {
    pub fn new(
        base: Value,
        params: &'a [Resolved],
        data: &'a [DataSet],
        static_table_rel_tol: f64,
    ) -> Self {
        let static_d_max = serde_json::from_value::<Scene>(base.clone())
            .ok()
            .filter(|s| s.table.d_max_m.is_none())
            .map(|s| s.table_range().1);
        Evaluator {
            static_d_max,
            base,
            params,
            data,
            static_table_rel_tol,
            tables: Mutex::new(Vec::new()),
            evaluations: AtomicUsize::new(0),
        }
    }

    /// The scene with the parameters set to `x`, validated.
    pub fn scene(&self, x: &[f64]) -> Result<Scene> {
        let mut v = self.base.clone();
        for (p, &xi) in self.params.iter().zip(x) {
            let si = xi * p.factor;
            set(&mut v, &p.path, si);
            for l in &p.linked {
                set(&mut v, l, si);
            }
        }
        Scene::from_json_str(&v.to_string())
    }

    /// The slider model of `scene`, reusing force tables built before for the same forces.
    fn model(&self, scene: &Scene) -> Result<SliderModel> {
        let key = force_key(scene);
        let found = self
            .tables
            .lock()
            .ok()
            .and_then(|t| t.iter().find(|(k, _)| *k == key).map(|(_, f)| f.clone()));
        let forces = match found {
            Some(f) => f,
            None => {
                let f = scene.build_interface()?;
                if let Ok(mut t) = self.tables.lock() {
                    if t.len() >= CACHED_TABLES {
                        t.remove(0);
                    }
                    t.push((key, f.clone()));
                }
                f
            }
        };
        SliderModel::from_scene_with_forces(scene, forces)
    }

    /// Predictions for every data set, observed column and row. `tighten` scales the cycle
    /// solver's tolerances (1 = the scene's).
    pub fn predict(&self, x: &[f64], tighten: f64) -> Result<Vec<Vec<Vec<Predicted>>>> {
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        let scene = self.scene(x)?;
        let mut static_model = None;
        let mut dynamic_model = None;
        let mut out = Vec::with_capacity(self.data.len());
        for ds in self.data {
            let cols = match ds.kind {
                CurveKind::StaticVsDc => {
                    if static_model.is_none() {
                        let mut s = scene.clone();
                        s.table.rel_tol = s.table.rel_tol.max(self.static_table_rel_tol);
                        s.table.d_max_m = s.table.d_max_m.or(self.static_d_max);
                        static_model = Some(self.model(&s)?);
                    }
                    let m = static_model.as_ref().expect("built above");
                    match predict_static(m, &scene, ds) {
                        Ok(c) => c,
                        // The coarse tables can lose a bracket of the scan: the scene's own.
                        Err(_) => {
                            if dynamic_model.is_none() {
                                dynamic_model = Some(self.model(&scene)?);
                            }
                            let m = dynamic_model.as_ref().expect("built above");
                            predict_static(m, &scene, ds)?
                        }
                    }
                }
                CurveKind::CycleVsAc => {
                    if dynamic_model.is_none() {
                        dynamic_model = Some(self.model(&scene)?);
                    }
                    let m = dynamic_model.as_ref().expect("built above");
                    predict_cycles(m, &scene, ds, tighten)?
                }
            };
            out.push(cols);
        }
        Ok(out)
    }

    /// Weighted residuals `(model − measured)/uncertainty`, all data sets in order.
    pub fn residuals(&self, x: &[f64]) -> Result<Vec<f64>> {
        Ok(weighted(self.data, &self.predict(x, 1.0)?))
    }
}

/// Weighted residuals of predictions.
pub(super) fn weighted(data: &[DataSet], pred: &[Vec<Vec<Predicted>>]) -> Vec<f64> {
    let mut r = Vec::new();
    for (ds, p) in data.iter().zip(pred) {
        for (o, pc) in ds.observed.iter().zip(p) {
            for (i, (y, q)) in o.values.iter().zip(pc).enumerate() {
                let w = o.errors.as_ref().map_or(DEFAULT_WEIGHT_W, |e| e[i]);
                r.push((q.value - y) / w);
            }
        }
    }
    r
}

/// What the force tables depend on: the interface sections without the contact potential (which
/// enters with the voltage), the table settings and range.
fn force_key(scene: &Scene) -> String {
    let mut es = scene.electrostatic.clone();
    if let Some(e) = es.as_mut() {
        e.contact_potential_v = 0.0;
    }
    serde_json::json!({
        "surface": scene.surface,
        "intermolecular": scene.intermolecular,
        "electrostatic": es,
        "contact": scene.contact,
        "table": scene.table,
        "range": scene.table_range(),
    })
    .to_string()
}

fn predict_static(m: &SliderModel, scene: &Scene, ds: &DataSet) -> Result<Vec<Vec<Predicted>>> {
    let opts = StaticOptions::new(scene.detector.contact_threshold_n);
    let needs_takeoff = ds
        .observed
        .iter()
        .any(|o| o.quantity == Quantity::TakeoffPower);
    let mut rows = Vec::with_capacity(ds.x.len());
    for &v in &ds.x {
        let mv = m.with_voltage(Voltage {
            dc: v,
            ac_amplitude: 0.0,
            ..m.voltage
        });
        rows.push(if needs_takeoff {
            let h = static_hysteresis(&mv, &opts)?;
            (h.touchdown.power, h.takeoff.power)
        } else {
            (touchdown_power(&mv, &opts)?.power, f64::NAN)
        });
    }
    Ok(ds
        .observed
        .iter()
        .map(|o| {
            rows.iter()
                .map(|&(td, to)| Predicted {
                    value: if o.quantity == Quantity::TouchdownPower {
                        td
                    } else {
                        to
                    },
                    clipped: false,
                })
                .collect()
        })
        .collect())
}

fn predict_cycles(
    m: &SliderModel,
    scene: &Scene,
    ds: &DataSet,
    tighten: f64,
) -> Result<Vec<Vec<Predicted>>> {
    let knots = &scene.heater.programme;
    let programme = HeaterProgramme::Fixed(SliderModel::programme_from_knots(knots)?);
    let (p_min, p_max) = knots
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), k| {
            (a.min(k[1]), b.max(k[1]))
        });
    let mut opts = CycleOptions::from_scene(scene)?;
    opts.solver.rtol *= tighten;
    opts.solver.atol_displacement *= tighten;
    let cycles = ac_sweep(m, &programme, &opts, &ds.x)?;
    Ok(ds
        .observed
        .iter()
        .map(|o| {
            cycles
                .iter()
                .map(|c| {
                    let (d, fallback) = match o.quantity {
                        Quantity::TouchdownPower => (c.touchdown, p_max),
                        Quantity::TakeoffPower => (c.takeoff, p_min),
                    };
                    Predicted {
                        value: d.map_or(fallback, |d| d.power),
                        clipped: d.is_none(),
                    }
                })
                .collect()
        })
        .collect())
}
