//! Results as they are printed and returned: the one representation the `hdi` program prints
//! as JSON and the Python package returns as objects, both from `serde`.
//!
//! **Key rule.** Every dimensional key ends in its SI unit, as scene fields and CSV columns do:
//! `_w`, `_m`, `_s`, `_k`, `_n`, `_v`, `_hz`, `_per_s`, `_n_per_m`, `_m_per_n`, `_v2`, `_m2`,
//! `_n_per_v2`; keys without a unit suffix are dimensionless (`contrast`, `damping_ratio`) or
//! counts (`runs`). A value that does not exist is `null` (JSON) or `None` (Python), never NaN.
//! Every record carries the scene's `name` it was computed for, a [`Status`] and its flags.

use serde::Serialize;

use super::cycle::{CycleOptions, CycleResult, HeaterProgramme};
use super::sweep::{flags, Flag, RefinedCycle};
use super::touchdown::{StaticHysteresis, Transition};
use crate::ode::Stats;

/// How far a result can be trusted.
///
/// ```
/// use hdi_tribology::analysis::record::Status;
/// assert_eq!(serde_json::to_string(&Status::NotConverged).unwrap(), "\"not_converged\"");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Every value was found to its tolerance (static roots; a cycle whose refinement agreed).
    Converged,
    /// The refinement ran out of runs before the values agreed.
    NotConverged,
    /// Run once at the tolerances given, its accuracy not checked.
    Unchecked,
    /// Everything searched for was found (a calibration's touchdown and take-off).
    Complete,
    /// Something searched for was not found: see the flags.
    Incomplete,
}

/// One touchdown/take-off cycle with how it was run and how far it can be trusted: the JSON
/// object of `hdi cycle` and `hdi sweep`, and Python's `Cycle`.
///
/// The cycle's own keys (`v_ac_v`, `touchdown`, `takeoff`, `hysteresis_w`,
/// `mean_temperature_rise_k`, `duration_s`, `stats`, `wall_seconds`, all of the run kept) sit
/// beside the refinement's (`rtol`, `atol_m`, `runs`, `power_change_w`,
/// `temperature_change_k`, and `total_stats`, `total_wall_seconds` over every run).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CycleRecord {
    /// The scene's name.
    pub scene: String,
    /// `"fixed"` or `"triggered"` ([`HeaterProgramme::name`]).
    pub programme: &'static str,
    /// The cycle kept (the last run).
    #[serde(flatten)]
    pub cycle: CycleResult,
    /// Its relative tolerance.
    pub rtol: f64,
    /// Its absolute displacement tolerance (m).
    pub atol_m: f64,
    /// Cycles run.
    pub runs: usize,
    /// Largest change of touchdown or take-off power from the run before (W); `None` when not
    /// refined, or when a detection came or went between the two runs.
    pub power_change_w: Option<f64>,
    /// Change of the mean temperature rise from the run before (K); `None` when not refined.
    pub temperature_change_k: Option<f64>,
    /// Solver work over every run.
    pub total_stats: Stats,
    /// Wall time over every run (s).
    pub total_wall_seconds: f64,
    /// `converged`, `not_converged` or `unchecked`.
    pub status: Status,
    /// What is wrong with the cycle ([`Flag`]), empty when nothing is.
    pub flags: Vec<Flag>,
}

impl CycleRecord {
    /// A cycle run once under `opts`, unchecked.
    pub fn unchecked(
        scene: &str,
        programme: &HeaterProgramme,
        cycle: CycleResult,
        opts: &CycleOptions,
    ) -> Self {
        CycleRecord {
            scene: scene.to_string(),
            programme: programme.name(),
            rtol: opts.solver.rtol,
            atol_m: opts.solver.atol_displacement,
            runs: 1,
            power_change_w: None,
            temperature_change_k: None,
            total_stats: cycle.stats,
            total_wall_seconds: cycle.wall_seconds,
            status: Status::Unchecked,
            flags: flags(&cycle),
            cycle,
        }
    }

    /// A refined cycle: converged or not.
    pub fn refined(scene: &str, programme: &HeaterProgramme, r: RefinedCycle) -> Self {
        CycleRecord {
            scene: scene.to_string(),
            programme: programme.name(),
            rtol: r.rtol,
            atol_m: r.atol,
            runs: r.runs,
            power_change_w: Some(r.change).filter(|x| x.is_finite()),
            temperature_change_k: Some(r.temperature_change),
            total_stats: r.stats,
            total_wall_seconds: r.wall_seconds,
            status: if r.converged {
                Status::Converged
            } else {
                Status::NotConverged
            },
            flags: r.flags(),
            cycle: r.cycle,
        }
    }
}

/// Static touchdown and take-off with the scene and a status: `hdi static`'s JSON (with the
/// pull-in voltage and the folds beside) and Python's `StaticHysteresis`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StaticRecord {
    /// The scene's name.
    pub scene: String,
    /// Touchdown.
    pub touchdown: Transition,
    /// Take-off; `None` when the head stays in contact down to zero heater power.
    pub takeoff: Option<Transition>,
    /// `P_TD − P_TO` (W), when there is a take-off.
    #[serde(rename = "hysteresis_w")]
    pub hysteresis: Option<f64>,
    /// `converged`: each value is a root found to the solver's tolerance (a touchdown not found
    /// is an error).
    pub status: Status,
    /// `no_takeoff` without a take-off; `negative_hysteresis` when take-off lies above
    /// touchdown.
    pub flags: Vec<Flag>,
}

impl StaticRecord {
    /// The record of `h` for the scene `scene`.
    pub fn new(scene: &str, h: StaticHysteresis) -> Self {
        Self::of(scene, h.touchdown, Some(h.takeoff))
    }

    /// The record of a touchdown and, when there is one, a take-off, for the scene `scene`.
    ///
    /// ```no_run
    /// use hdi_tribology::analysis::{record::StaticRecord, sweep::Flag, touchdown_power, StaticOptions};
    /// use hdi_tribology::{model::SliderModel, scene::Scene};
    /// let model = SliderModel::from_scene(&Scene::paper())?;
    /// let td = touchdown_power(&model, &StaticOptions::new(5e-5))?;
    /// let r = StaticRecord::of("paper", td, None);
    /// assert_eq!(r.flags, vec![Flag::NoTakeoff]);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn of(scene: &str, touchdown: Transition, takeoff: Option<Transition>) -> Self {
        let hysteresis = takeoff.as_ref().map(|t| touchdown.power - t.power);
        let mut flags = Vec::new();
        match hysteresis {
            None => flags.push(Flag::NoTakeoff),
            Some(h) if h < 0.0 => flags.push(Flag::NegativeHysteresis),
            Some(_) => {}
        }
        StaticRecord {
            scene: scene.to_string(),
            touchdown,
            takeoff,
            hysteresis,
            status: Status::Converged,
            flags,
        }
    }
}
