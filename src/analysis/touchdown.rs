//! Static touchdown and take-off powers and the hysteresis between them (MODEL.md section 6).
//!
//! Touchdown: follow the stable equilibrium from large gaps towards the disk (power rising)
//! until its contact force reaches the threshold `F_th` or the branch ends at a fold. Take-off:
//! start on the contact branch `excess` above the touchdown power and follow it back (power
//! falling) until the contact force drops below `F_th` or that branch ends at a fold.

use super::equilibrium::{Equilibrium, EquilibriumSolver, ScanGrid};
use crate::error::{Error, Result};
use crate::model::SliderModel;
use serde::Serialize;

/// Why a transition happened.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Cause {
    /// The contact force crossed the detector threshold on a stable branch.
    Threshold,
    /// The stable branch ended at a fold (a jump).
    Fold,
}

/// A touchdown or take-off found on the static equilibria.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Transition {
    /// Heater power (W).
    pub power: f64,
    /// The equilibrium where it happens.
    pub at: Equilibrium,
    /// Threshold crossing or fold.
    pub cause: Cause,
}

/// Options of the static touchdown/take-off analysis.
///
/// ```
/// let o = hdi_tribology::analysis::touchdown::StaticOptions::new(5e-5);
/// assert_eq!(o.takeoff_start_excess, 0.03);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StaticOptions {
    /// Contact-force threshold `F_th` (N) standing in for the acoustic-emission detector.
    pub contact_threshold: f64,
    /// How far above the touchdown power the take-off search starts on the contact branch (W).
    pub takeoff_start_excess: f64,
    /// Gap grid of the scans (folds and thresholds are then refined to 1e-12 relative).
    pub grid: ScanGrid,
}

impl StaticOptions {
    /// Options with threshold `F_th` and the defaults of MODEL.md (take-off search from
    /// 30 mW above touchdown).
    pub fn new(contact_threshold: f64) -> Self {
        StaticOptions {
            contact_threshold,
            takeoff_start_excess: 0.03,
            grid: ScanGrid::default(),
        }
    }

    fn validate(&self) -> Result<()> {
        crate::error::check_positive("contact_threshold", self.contact_threshold)?;
        crate::error::check_positive("takeoff_start_excess", self.takeoff_start_excess)?;
        Ok(())
    }
}

/// Touchdown and take-off at one DC voltage.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct StaticHysteresis {
    /// Touchdown.
    pub touchdown: Transition,
    /// Take-off.
    pub takeoff: Transition,
    /// `P_TD − P_TO` (W).
    pub hysteresis: f64,
}

/// Touchdown power at the model's DC voltage.
///
/// ```no_run
/// use hdi_tribology::{analysis::touchdown::{touchdown_power, StaticOptions}, model::SliderModel, scene::Scene};
/// let model = SliderModel::from_scene(&Scene::paper())?;
/// let td = touchdown_power(&model, &StaticOptions::new(5e-5))?;
/// println!("P_TD = {:.2} mW ({:?})", td.power * 1e3, td.cause);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn touchdown_power(model: &SliderModel, opts: &StaticOptions) -> Result<Transition> {
    opts.validate()?;
    let volt2 = model.voltage.effective_dc().powi(2);
    touchdown_at(model, volt2, opts)
}

/// Touchdown at a given `V²` (V²).
pub(crate) fn touchdown_at(
    model: &SliderModel,
    volt2: f64,
    opts: &StaticOptions,
) -> Result<Transition> {
    let solver = EquilibriumSolver::new(model, volt2);
    let (lo, hi) = model.forces().table_range();
    let mut prev: Option<Equilibrium> = None;
    for d in opts.grid.descending(lo, hi) {
        let e = solver.at_gap(d)?;
        if let Some(p) = prev {
            if !e.is_stable() {
                let at = solver.refine_fold(e.d, p.d)?;
                return Ok(Transition {
                    power: at.power,
                    at,
                    cause: Cause::Fold,
                });
            }
            if e.contact_force >= opts.contact_threshold {
                let at = solver.refine_threshold(e.d, p.d, opts.contact_threshold)?;
                return Ok(Transition {
                    power: at.power,
                    at,
                    cause: Cause::Threshold,
                });
            }
        } else if !e.is_stable() || e.contact_force >= opts.contact_threshold {
            return Err(Error::analysis(
                "touchdown",
                format!("the equilibrium at the largest tabulated gap ({d:e} m) is already unstable or in contact: widen the table range"),
            ));
        }
        prev = Some(e);
    }
    Err(Error::analysis(
        "touchdown",
        "the flying branch neither reaches the contact threshold nor folds inside the table range",
    ))
}

/// Take-off power at the model's DC voltage, starting on the contact branch at
/// `start_power` (W) and following it to lower power.
pub fn takeoff_power(
    model: &SliderModel,
    start_power: f64,
    opts: &StaticOptions,
) -> Result<Transition> {
    opts.validate()?;
    crate::error::check_finite("start_power", start_power)?;
    let volt2 = model.voltage.effective_dc().powi(2);
    takeoff_at(model, volt2, start_power, opts)
}

pub(crate) fn takeoff_at(
    model: &SliderModel,
    volt2: f64,
    start_power: f64,
    opts: &StaticOptions,
) -> Result<Transition> {
    let solver = EquilibriumSolver::new(model, volt2);
    let (mut lo, hi) = model.forces().table_range();
    let target = model.protrusion(start_power);
    // The start lies deeper than the scan's lower end if the protrusion there is too small:
    // extend the scan downwards (the forces fall back to direct evaluation outside the table).
    let step = (hi - lo).max(1e-9) * 0.1;
    let mut extended = 0;
    while solver.at_gap(lo)?.protrusion < target {
        lo -= step;
        extended += 1;
        if extended > 50 {
            return Err(Error::analysis(
                "take-off",
                format!(
                    "no contact equilibrium at {start_power} W within {} m of interpenetration",
                    -lo
                ),
            ));
        }
    }
    let mut ascending = opts.grid.descending(lo, hi);
    ascending.reverse();
    let mut started = false;
    let mut prev: Option<Equilibrium> = None;
    for d in ascending {
        let e = solver.at_gap(d)?;
        if !started {
            if e.protrusion <= target {
                if !e.is_stable() {
                    return Err(Error::analysis(
                        "take-off",
                        format!(
                            "the equilibrium at {start_power} W on the contact side is unstable"
                        ),
                    ));
                }
                started = true;
            } else {
                prev = Some(e);
                continue;
            }
        }
        if let Some(p) = prev {
            if !e.is_stable() {
                let at = solver.refine_fold(p.d, e.d)?;
                return Ok(Transition {
                    power: at.power,
                    at,
                    cause: Cause::Fold,
                });
            }
            if e.contact_force < opts.contact_threshold {
                let at = solver.refine_threshold(p.d, e.d, opts.contact_threshold)?;
                return Ok(Transition {
                    power: at.power,
                    at,
                    cause: Cause::Threshold,
                });
            }
        }
        prev = Some(e);
    }
    Err(Error::analysis(
        "take-off",
        "the contact branch neither falls below the threshold nor folds inside the table range",
    ))
}

/// Touchdown, take-off (from `takeoff_start_excess` above touchdown) and their difference at the
/// model's DC voltage.
///
/// ```no_run
/// use hdi_tribology::{analysis::touchdown::{static_hysteresis, StaticOptions}, model::SliderModel, scene::Scene};
/// let model = SliderModel::from_scene(&Scene::paper())?;
/// let h = static_hysteresis(&model, &StaticOptions::new(5e-5))?;
/// println!("ΔP = {:.2} mW", h.hysteresis * 1e3);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn static_hysteresis(model: &SliderModel, opts: &StaticOptions) -> Result<StaticHysteresis> {
    let touchdown = touchdown_power(model, opts)?;
    let takeoff = takeoff_power(model, touchdown.power + opts.takeoff_start_excess, opts)?;
    Ok(StaticHysteresis {
        touchdown,
        takeoff,
        hysteresis: touchdown.power - takeoff.power,
    })
}
