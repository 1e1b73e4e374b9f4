//! The forward model of a fit: parameter values → scene → slider model → predicted curves.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use serde_json::Value;

use super::data::{CurveKind, DataSet, Quantity};
use super::params::Resolved;
use crate::analysis::sweep::Refinement;
use crate::analysis::{
    ac_sweep_refined, static_hysteresis, touchdown_power, transition_shift, CycleOptions,
    HeaterProgramme, StaticOptions, Transition,
};
use crate::analysis::{s_curve, ScanGrid};
use crate::force::InterfaceForces;
use crate::model::{SliderModel, Voltage};
use crate::quadrature::TableOptions;
use crate::scene::Scene;
use crate::Result;

/// Force tables kept for reuse (parameters that do not touch the forces share them).
const CACHED_TABLES: usize = 16;

/// One predicted value (SI).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Predicted {
    pub value: f64,
    /// The model did not detect the transition within the heater programme: `value` is the end of
    /// the programme's range, a bound on the true one.
    pub clipped: bool,
    /// The static transition behind the value (static curves).
    pub transition: Option<Transition>,
    /// The refinement of a cycle's tolerance (dynamic curves).
    pub refined: Option<Refined>,
}

/// How a dynamic value's tolerance was refined.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Refined {
    /// The detected powers moved by at most the power tolerance at the last refinement.
    pub converged: bool,
    /// Change of the detected powers at the last refinement (W; ∞ when a detection came or went).
    pub change: f64,
    /// Relative tolerance of the cycle kept.
    pub rtol: f64,
}

/// Which data sets an evaluation covers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Sets {
    /// Every data set.
    All,
    /// Only those without static transitions (cycles, the indicator); the others left empty.
    NoTransitions,
}

/// Evaluates the model for parameter vectors (in the parameters' own units).
pub(super) struct Evaluator<'a> {
    base: Value,
    pub params: &'a [Resolved],
    pub data: &'a [DataSet],
    static_table_rel_tol: f64,
    /// Tolerance refinement of the cycles.
    refinement: Refinement,
    /// Residuals left out of the fit (flattened in the order of [`weighted`]).
    pub excluded: Vec<bool>,
    /// The last full prediction (parameters and values), reused by the Jacobian.
    last: Mutex<Option<(Vec<f64>, Preds)>>,
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
        refinement: Refinement,
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
            refinement,
            excluded: Vec::new(),
            last: Mutex::new(None),
            tables: Mutex::new(Vec::new()),
            evaluations: AtomicUsize::new(0),
        }
    }

    /// The scene with the parameters set to `x`, validated.
    pub fn scene(&self, x: &[f64]) -> Result<Scene> {
        let mut v = self.base.clone();
        for (p, &xi) in self.params.iter().zip(x) {
            p.write(&mut v, xi);
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

    /// The model of the static curves at `scene`: its tables no finer than the static
    /// tolerance, and reaching the static scans' largest gap.
    fn static_model(&self, scene: &Scene) -> Result<SliderModel> {
        let mut s = scene.clone();
        s.table.rel_tol = s.table.rel_tol.max(self.static_table_rel_tol);
        s.table.d_max_m = s.table.d_max_m.or(self.static_d_max);
        self.model(&s)
    }

    /// Predictions for every data set, observed column and row (reused when `x` is the last
    /// point predicted).
    pub fn predict(&self, x: &[f64]) -> Result<Preds> {
        if let Some((lx, p)) = self.last.lock().ok().as_ref().and_then(|l| l.as_ref()) {
            if lx == x {
                return Ok(p.clone());
            }
        }
        let p = self.predict_sets(x, Sets::All)?;
        if let Ok(mut l) = self.last.lock() {
            *l = Some((x.to_vec(), p.clone()));
        }
        Ok(p)
    }

    /// Predictions for the data sets `sets` selects (the others empty).
    pub fn predict_sets(&self, x: &[f64], sets: Sets) -> Result<Preds> {
        self.evaluations.fetch_add(1, Ordering::Relaxed);
        let scene = self.scene(x)?;
        let mut static_model = None;
        let mut dynamic_model = None;
        let mut out = Vec::with_capacity(self.data.len());
        for ds in self.data {
            let cols = match ds.kind {
                _ if sets == Sets::NoTransitions && ds.is_transitions() => Vec::new(),
                CurveKind::IndicatorVsPower => {
                    let m = built(&mut static_model, || self.static_model(&scene))?;
                    predict_indicator(m, ds)?
                }
                CurveKind::StaticVsDc => {
                    let m = built(&mut static_model, || self.static_model(&scene))?;
                    match predict_static(m, &scene, ds) {
                        Ok(c) => c,
                        // The coarse tables can lose a bracket of the scan: the scene's own.
                        Err(_) => {
                            let m = built(&mut dynamic_model, || self.model(&scene))?;
                            predict_static(m, &scene, ds)?
                        }
                    }
                }
                CurveKind::CycleVsAc => {
                    let m = built(&mut dynamic_model, || self.model(&scene))?;
                    predict_cycles(m, &scene, ds, &self.refinement)?
                }
            };
            out.push(cols);
        }
        Ok(out)
    }

    /// Weighted residuals `(model − measured)/uncertainty`, all data sets in order (excluded
    /// ones 0).
    pub fn residuals(&self, x: &[f64]) -> Result<Vec<f64>> {
        Ok(weighted(self.data, &self.predict(x)?, &self.excluded))
    }

    /// The slider model of the scene at `x` for direct (untabulated) evaluation only: its tables
    /// cover a short stretch of gaps above every scan, coarsely, so building it costs almost
    /// nothing; every force near a transition is then evaluated directly.
    /// `like` is another direct model with the key of its forces: when the scene at `x` has the
    /// same forces (the parameter does not touch them), they are shared. Returns the model and
    /// the key of its forces.
    pub fn direct_model(
        &self,
        x: &[f64],
        like: Option<&(SliderModel, String)>,
    ) -> Result<(SliderModel, String)> {
        let scene = self.scene(x)?;
        let key = force_key(&scene);
        if let Some((m, _)) = like.filter(|(_, k)| *k == key) {
            return Ok((
                SliderModel::from_scene_with_forces(&scene, m.forces().clone())?,
                key,
            ));
        }
        let hi = 2.0 * scene.table_range().1.max(self.static_d_max.unwrap_or(0.0));
        let forces = InterfaceForces::build(
            scene.interface_terms()?,
            (hi, hi * 1.001),
            &TableOptions {
                rel_tol: 1e-2,
                ..TableOptions::default()
            },
        )?;
        Ok((SliderModel::from_scene_with_forces(&scene, forces)?, key))
    }

    /// `∂(model value)/∂x_j` of every static value (W per unit of the parameter), by the
    /// transitions' first-order shifts under a change of one parameter
    /// ([`transition_shift`]: no rescan, no table build); `None` rows for dynamic values.
    /// `steps[j]` is the change of parameter `j` and whether to take it both ways (central).
    pub fn static_sensitivities(
        &self,
        x: &[f64],
        pred: &Preds,
        steps: &[(f64, bool)],
    ) -> Result<Vec<Vec<Option<f64>>>> {
        let n = x.len();
        let base = self.direct_model(x, None)?;
        let moved = |j: usize, h: f64| -> Result<SliderModel> {
            let mut xs = x.to_vec();
            xs[j] += h;
            Ok(self.direct_model(&xs, Some(&base))?.0)
        };
        let base = &base.0;
        let column = |j: usize| -> Result<Vec<Option<f64>>> {
            let (h, central) = steps[j];
            let plus = moved(j, h)?;
            let minus = if central { Some(moved(j, -h)?) } else { None };
            let mut col = Vec::new();
            for (ds, p) in self.data.iter().zip(pred) {
                for pc in p {
                    for (i, q) in pc.iter().enumerate() {
                        let Some(t) = q.transition else {
                            col.push(None);
                            continue;
                        };
                        let at = |m: &SliderModel| {
                            m.with_voltage(Voltage {
                                dc: ds.x[i],
                                ac_amplitude: 0.0,
                                ..m.voltage()
                            })
                        };
                        let b = at(base);
                        let up = transition_shift(&b, &at(&plus), &t)?;
                        col.push(Some(match &minus {
                            Some(mi) => (up - transition_shift(&b, &at(mi), &t)?) / (2.0 * h),
                            None => up / h,
                        }));
                    }
                }
            }
            Ok(col)
        };
        #[cfg(feature = "parallel")]
        {
            use rayon::prelude::*;
            let cancel = crate::ode::Cancel::current();
            (0..n)
                .into_par_iter()
                .map(|i| crate::ode::Cancel::carry(&cancel, || column(i)))
                .collect()
        }
        #[cfg(not(feature = "parallel"))]
        {
            (0..n).map(column).collect()
        }
    }
}

/// Predictions per data set, measured column and row.
pub(super) type Preds = Vec<Vec<Vec<Predicted>>>;

/// Weighted residuals of predictions.
/// `excluded` (flattened, may be empty) sets residuals to 0; a data set left empty by
/// [`Sets::NoTransitions`] gives NaN residuals.
pub(super) fn weighted(
    data: &[DataSet],
    pred: &[Vec<Vec<Predicted>>],
    excluded: &[bool],
) -> Vec<f64> {
    let mut r = Vec::new();
    for (ds, p) in data.iter().zip(pred) {
        for (k, o) in ds.observed.iter().enumerate() {
            for (i, y) in o.values.iter().enumerate() {
                let w = o
                    .errors
                    .as_ref()
                    .map_or(o.quantity.default_weight(), |e| e[i]);
                let v = p
                    .get(k)
                    .and_then(|pc| pc.get(i))
                    .map_or(f64::NAN, |q| (q.value - y) / w);
                let out = excluded.get(r.len()).copied().unwrap_or(false);
                r.push(if out { 0.0 } else { v });
            }
        }
    }
    r
}

/// The weight (W) of every residual, flattened as in [`weighted`].
pub(super) fn weights(data: &[DataSet]) -> Vec<f64> {
    let mut w = Vec::new();
    for ds in data {
        for o in &ds.observed {
            for i in 0..o.values.len() {
                w.push(
                    o.errors
                        .as_ref()
                        .map_or(o.quantity.default_weight(), |e| e[i]),
                );
            }
        }
    }
    w
}

/// The model in `slot`, built by `build` the first time it is asked for.
fn built(
    slot: &mut Option<SliderModel>,
    build: impl FnOnce() -> Result<SliderModel>,
) -> Result<&SliderModel> {
    if slot.is_none() {
        *slot = Some(build()?);
    }
    Ok(slot.as_ref().expect("built above"))
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
            ..m.voltage()
        });
        rows.push(if needs_takeoff {
            let h = static_hysteresis(&mv, &opts)?;
            (h.touchdown, Some(h.takeoff))
        } else {
            (touchdown_power(&mv, &opts)?, None)
        });
    }
    Ok(ds
        .observed
        .iter()
        .map(|o| {
            rows.iter()
                .map(|&(td, to)| {
                    let t = if o.quantity == Quantity::TouchdownPower {
                        Some(td)
                    } else {
                        to
                    };
                    Predicted {
                        value: t.map_or(f64::NAN, |t| t.power),
                        clipped: false,
                        transition: t,
                        refined: None,
                    }
                })
                .collect()
        })
        .collect())
}

/// The contact indicator in its quasi-static limit: the contact force of the equilibrium reached
/// as the heater power rises to each x (the stable flying branch up to touchdown, then the stable
/// contact branch), at the model's DC voltage; between the scan's equilibria the force is
/// interpolated linearly in power.
fn predict_indicator(m: &SliderModel, ds: &DataSet) -> Result<Vec<Vec<Predicted>>> {
    let curve = s_curve(m, None, &ScanGrid::default())?;
    // The path of rising power: stable equilibria, in order of decreasing gap, each above the
    // power of the last one kept (a fold's jump lands where the contact branch passes its power).
    let mut path: Vec<(f64, f64)> = Vec::new();
    for e in curve.points.iter().filter(|e| e.is_stable()) {
        if path.last().is_none_or(|&(p, _)| e.power > p) {
            path.push((e.power, e.contact_force));
        }
    }
    let mut values = Vec::with_capacity(ds.x.len());
    for &p in &ds.x {
        let k = path.partition_point(|&(pk, _)| pk < p);
        let v = match (k.checked_sub(1).and_then(|i| path.get(i)), path.get(k)) {
            (Some(&(p0, f0)), Some(&(p1, f1))) => f0 + (f1 - f0) * (p - p0) / (p1 - p0),
            (None, Some(&(_, f1))) => f1,
            _ => {
                return Err(super::FitFailure::BeyondEquilibria {
                    origin: ds.origin.clone(),
                    heater_power_mw: crate::units::to_mw(p),
                    last_power_mw: path.last().map_or(f64::NAN, |l| crate::units::to_mw(l.0)),
                }
                .into())
            }
        };
        values.push(Predicted {
            value: v,
            clipped: false,
            transition: None,
            refined: None,
        });
    }
    Ok(vec![values; ds.observed.len()])
}

fn predict_cycles(
    m: &SliderModel,
    scene: &Scene,
    ds: &DataSet,
    refinement: &Refinement,
) -> Result<Vec<Vec<Predicted>>> {
    let knots = &scene.heater.programme;
    let programme = HeaterProgramme::Fixed(SliderModel::programme_from_knots(knots)?);
    let (p_min, p_max) = knots
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), k| {
            (a.min(k[1]), b.max(k[1]))
        });
    let opts = CycleOptions::from_scene(scene)?;
    let cycles = ac_sweep_refined(m, &programme, &opts, &ds.x, refinement)?;
    Ok(ds
        .observed
        .iter()
        .map(|o| {
            cycles
                .iter()
                .map(|r| {
                    let c = &r.cycle;
                    let (d, fallback) = match o.quantity {
                        Quantity::TouchdownPower => (c.touchdown, p_max),
                        // (the reader pairs the indicator with heater power, never with cycles)
                        Quantity::TakeoffPower | Quantity::ContactIndicator => (c.takeoff, p_min),
                    };
                    Predicted {
                        value: d.map_or(fallback, |d| d.power),
                        clipped: d.is_none(),
                        transition: None,
                        refined: Some(Refined {
                            converged: r.converged,
                            change: r.change,
                            rtol: r.rtol,
                        }),
                    }
                })
                .collect()
        })
        .collect())
}
