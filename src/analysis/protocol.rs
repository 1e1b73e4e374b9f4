//! The one home of the scene → protocol translation: which heater programmes, detector, solver
//! settings and static options a scene asks for. Analyses take these, never the scene.
//!
//! ```no_run
//! use hdi_tribology::analysis::{simulate_cycle, static_hysteresis, Protocol};
//! use hdi_tribology::{model::SliderModel, scene::Scene};
//! let scene = Scene::paper();
//! let model = SliderModel::from_scene(&scene)?;
//! let p = Protocol::from_scene(&scene)?;
//! let h = static_hysteresis(&model, &p.statics)?;
//! let r = simulate_cycle(&model, &p.fixed, &p.cycle)?;
//! println!("static {:.3} mW, dynamic {} mW", h.hysteresis_mw(), r.hysteresis_text());
//! # Ok::<(), hdi_tribology::Error>(())
//! ```

use super::cycle::{CycleOptions, Detector, HeaterProgramme, SolverSettings};
use super::touchdown::StaticOptions;
use crate::error::{Error, Result};
use crate::heater::Programme;
use crate::ode::{self, Method};
use crate::scene::Scene;

/// Everything an analysis needs from a scene besides the model.
#[derive(Clone, Debug, PartialEq)]
pub struct Protocol {
    /// The fixed programme of `heater.programme`.
    pub fixed: HeaterProgramme,
    /// The touchdown-triggered programme of `heater.triggered`.
    pub triggered: HeaterProgramme,
    /// Detector and solver settings of the cycles.
    pub cycle: CycleOptions,
    /// Options of the static analyses (threshold of `detector.contact_threshold_n`).
    pub statics: StaticOptions,
}

impl Protocol {
    /// The protocol of a scene; errors name the scene's fields.
    pub fn from_scene(scene: &Scene) -> Result<Self> {
        Ok(Protocol {
            fixed: HeaterProgramme::fixed_from_scene(scene)?,
            triggered: HeaterProgramme::triggered_from_scene(scene),
            cycle: CycleOptions::from_scene(scene)?,
            statics: StaticOptions::from_scene(scene),
        })
    }
}

impl HeaterProgramme {
    /// The fixed programme of the scene's `heater.programme` knots.
    ///
    /// ```
    /// use hdi_tribology::{analysis::HeaterProgramme, scene::Scene};
    /// let p = HeaterProgramme::fixed_from_scene(&Scene::paper())?;
    /// assert!(matches!(p, HeaterProgramme::Fixed(_)));
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn fixed_from_scene(scene: &Scene) -> Result<Self> {
        let knots = scene
            .heater
            .programme
            .iter()
            .map(|k| (k[0], k[1]))
            .collect();
        Ok(HeaterProgramme::Fixed(Programme::new(knots)?))
    }

    /// The touchdown-triggered programme of the scene's `heater.triggered` section.
    pub fn triggered_from_scene(scene: &Scene) -> Self {
        let t = &scene.heater.triggered;
        HeaterProgramme::Triggered {
            start_power: t.start_power_w,
            ramp_rate: t.ramp_rate_w_per_s,
            overshoot: t.overshoot_w,
        }
    }
}

impl StaticOptions {
    /// Static options with the scene's detector threshold and the defaults of MODEL.md.
    ///
    /// ```
    /// use hdi_tribology::{analysis::StaticOptions, scene::Scene};
    /// assert_eq!(StaticOptions::from_scene(&Scene::paper()).contact_threshold, 5e-5);
    /// ```
    pub fn from_scene(scene: &Scene) -> Self {
        StaticOptions::new(scene.detector.contact_threshold_n)
    }
}

impl CycleOptions {
    /// The detector and solver settings of a scene, without time series and without the stop
    /// below the force tables ([`CycleOptions::stop_outside_tables`]), with the energy audit of
    /// an interface lag ([`CycleOptions::energy_audit`]).
    pub fn from_scene(scene: &Scene) -> Result<Self> {
        let method: Method = scene
            .solver
            .method
            .parse()
            .map_err(|e: ode::OdeError| Error::invalid("solver.method", e.to_string()))?;
        Ok(CycleOptions {
            detector: Detector {
                contact_threshold: scene.detector.contact_threshold_n,
                window: scene.detector.window_s,
            },
            solver: SolverSettings {
                method,
                rtol: scene.solver.rtol,
                atol_displacement: scene.solver.atol_m,
                max_step: scene.solver.max_step_s,
                max_steps: scene.solver.max_steps,
            },
            keep_series: false,
            series_window: None,
            stop_outside_tables: false,
            energy_audit: true,
            stop_at_takeoff: false,
            mean_temperature: true,
        })
    }
}
