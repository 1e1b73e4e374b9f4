//! Static touchdown and take-off powers and the hysteresis between them (MODEL.md section 6).
//!
//! Touchdown: follow the stable equilibrium from large gaps towards the disk (power rising)
//! until its contact force reaches the threshold `F_th` or the branch ends at a fold. Take-off:
//! start on the contact branch `excess` above the touchdown power and follow it back (power
//! falling) until the contact force drops below `F_th` or that branch ends at a fold.

use super::equilibrium::{Equilibrium, EquilibriumSolver, ScanGrid, Skipper};
use crate::error::{failure_kind, num, Result, Stage};
use crate::model::SliderModel;
use crate::units::{to_mw, to_nm};
use serde::Serialize;

impl Stage {
    /// Static touchdown.
    pub const TOUCHDOWN: Stage = Stage::named("touchdown");
    /// Static take-off.
    pub const TAKE_OFF: Stage = Stage::named("take-off");
}

/// Why a static touchdown or take-off could not be found. Numbers are in engineering units, as
/// the field names say.
///
/// ```
/// use hdi_tribology::analysis::touchdown::TransitionError;
/// use hdi_tribology::error::{FailureKind, Stage};
/// let e = TransitionError::NoTakeOff { gap_nm: 0.3, power_mw: -2.0 };
/// assert_eq!(e.stage(), Stage::TAKE_OFF);
/// assert!(e.to_string().contains("adhesion holds it"));
/// ```
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TransitionError {
    /// Touchdown: the head is in contact already at zero heater power (the transition lies at
    /// negative power).
    #[error(
        "the head is in contact already at zero heater power (the {} at d = {} nm lies at {} mW \
         < 0)",
        if *.at_fold { "fold" } else { "threshold crossing" },
        num(*.gap_nm),
        num(*.power_mw)
    )]
    InContactAtZeroPower {
        /// `true` at a fold, `false` at a threshold crossing.
        at_fold: bool,
        /// Bulge gap at the transition (nm).
        gap_nm: f64,
        /// Heater power of the transition (mW), negative.
        power_mw: f64,
    },
    /// Take-off: the head stays in contact down to zero heater power (adhesion holds it).
    #[error(
        "the head stays in contact down to zero heater power (the contact branch ends at d = {} \
         nm, {} mW < 0): adhesion holds it",
        num(*.gap_nm),
        num(*.power_mw)
    )]
    NoTakeOff {
        /// Bulge gap where the contact branch ends (nm).
        gap_nm: f64,
        /// Heater power there (mW), negative.
        power_mw: f64,
    },
    /// Touchdown: the flying branch neither reaches the contact threshold nor folds inside the
    /// force tables.
    #[error(
        "the flying branch neither reaches the contact threshold nor folds inside the table range \
         (up to {} mW): widen the table range",
        num(*.max_power_mw)
    )]
    NoTouchdown {
        /// The largest heater power reached (mW).
        max_power_mw: f64,
    },
    /// Take-off: the contact branch neither falls below the threshold nor folds inside the force
    /// tables.
    #[error(
        "the contact branch neither falls below the threshold nor folds inside the table range \
         (down to {} mW): widen the table range",
        num(*.min_power_mw)
    )]
    NoTakeOffInTable {
        /// The smallest heater power reached on the contact branch (mW).
        min_power_mw: f64,
    },
    /// Touchdown: the equilibrium at the largest tabulated gap is already unstable or in contact.
    #[error(
        "the equilibrium at the largest tabulated gap ({} nm) is already unstable or in contact: \
         widen the table range",
        num(*.gap_nm)
    )]
    TableTooNarrow {
        /// The largest tabulated gap (nm).
        gap_nm: f64,
    },
    /// Take-off: no contact equilibrium at the start power within this interpenetration.
    #[error(
        "no contact equilibrium at {} mW within {} nm of interpenetration",
        num(*.power_mw),
        num(*.depth_nm)
    )]
    NoContactEquilibrium {
        /// The start power (mW).
        power_mw: f64,
        /// The deepest interpenetration searched (nm).
        depth_nm: f64,
    },
    /// Take-off: the contact equilibrium at the start power is unstable.
    #[error("the equilibrium at {} mW on the contact side is unstable", num(*.power_mw))]
    UnstableContactStart {
        /// The start power (mW).
        power_mw: f64,
    },
}

failure_kind!(TransitionError, convergence = |_| false, {
        InContactAtZeroPower => Stage::TOUCHDOWN,
        NoTakeOff => Stage::TAKE_OFF,
        NoTouchdown => Stage::TOUCHDOWN,
        NoTakeOffInTable => Stage::TAKE_OFF,
        TableTooNarrow => Stage::TOUCHDOWN,
        NoContactEquilibrium => Stage::TAKE_OFF,
        UnstableContactStart => Stage::TAKE_OFF,
});

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
    #[serde(rename = "power_w")]
    pub power: f64,
    /// The equilibrium where it happens.
    pub at: Equilibrium,
    /// Threshold crossing or fold.
    pub cause: Cause,
}

impl Transition {
    /// The heater power in milliwatts.
    ///
    /// ```
    /// # use hdi_tribology::analysis::{equilibrium::Equilibrium, touchdown::{Cause, Transition}};
    /// # let at = Equilibrium { d: 0.0, y: 0.0, q: Default::default(), protrusion: 0.0, power: 0.0,
    /// #     stiffness: 0.0, interface_force: 0.0, contact_force: 0.0 };
    /// let t = Transition { power: 0.0743, at, cause: Cause::Fold };
    /// assert!((t.power_mw() - 74.3).abs() < 1e-12);
    /// ```
    pub fn power_mw(&self) -> f64 {
        crate::units::to_mw(self.power)
    }
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
    #[serde(rename = "hysteresis_w")]
    pub hysteresis: f64,
}

impl StaticHysteresis {
    /// `P_TD − P_TO` in milliwatts.
    pub fn hysteresis_mw(&self) -> f64 {
        crate::units::to_mw(self.hysteresis)
    }
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
    super::equilibrium::check_heater(model)?;
    let volt2 = model.voltage().dc_squared();
    touchdown_at(model, volt2, opts)
}

/// Touchdown at a given `V²` (V²).
///
/// The head follows the stable equilibrium from large gaps down (power rising). At a fold it jumps
/// towards the disk and lands on the next stable equilibrium at the same power; the fold is the
/// touchdown when the contact force there reaches `F_th` (the usual case), otherwise the scan
/// goes on from the landing point. A transition at negative power means the head is in contact
/// already at zero heater power: an error.
pub(crate) fn touchdown_at(
    model: &SliderModel,
    volt2: f64,
    opts: &StaticOptions,
) -> Result<Transition> {
    let t = touchdown_signed(model, volt2, opts)?;
    transition(t.at, t.cause, true)
}

/// As [`touchdown_at`], but a transition at negative power is returned as it is (the pull-in
/// analysis reads it as "in contact at zero voltage").
pub(crate) fn touchdown_signed(
    model: &SliderModel,
    volt2: f64,
    opts: &StaticOptions,
) -> Result<Transition> {
    let solver = EquilibriumSolver::new(model, volt2).refining_as(&opts.grid);
    let (lo, hi) = model.forces().table_range();
    let th = opts.contact_threshold;
    let gaps = opts.grid.descending(lo, hi)?;
    let mut skip = Skipper::new(model, volt2, &opts.grid);
    // The gap of the last grid point passed (its equilibrium is needed only for an error).
    let mut prev: Option<f64> = None;
    // A fold passed, not yet landed: (fold, its power).
    let mut jump: Option<Equilibrium> = None;
    let mut i = 0;
    while i < gaps.len() {
        // Pass over grid points proven not to change the scan below.
        let passed = match (jump, prev) {
            (Some(fold), _) => skip.skip(&gaps, i, |b| {
                b.stable == Some(false) || model.power_for(b.protrusion.hi) < fold.power
            }),
            (None, Some(_)) => skip.skip(&gaps, i, |b| b.stable == Some(true) && b.contact.hi < th),
            (None, None) => 0,
        };
        if passed > 0 {
            i += passed;
            prev = Some(gaps[i - 1]);
            continue;
        }
        let d = gaps[i];
        i += 1;
        let e = solver.at_gap(d)?;
        if let Some(fold) = jump {
            // The contact side rises again through the fold's power on a stable part.
            if e.is_stable() && e.power >= fold.power {
                if e.contact_force >= th {
                    return Ok(Transition {
                        power: fold.power,
                        at: fold,
                        cause: Cause::Fold,
                    });
                }
                jump = None;
            }
            prev = Some(d);
            continue;
        }
        if let Some(p) = prev {
            if !e.is_stable() {
                let at = solver.refine_fold(e.d, p)?;
                if at.power < 0.0 {
                    return Ok(Transition {
                        power: at.power,
                        at,
                        cause: Cause::Fold,
                    });
                }
                jump = Some(at);
                prev = Some(d);
                continue;
            }
            if e.contact_force >= th {
                let at = solver.refine_threshold(e.d, p, th)?;
                return Ok(Transition {
                    power: at.power,
                    at,
                    cause: Cause::Threshold,
                });
            }
        } else if !e.is_stable() || e.contact_force >= th {
            return Err(TransitionError::TableTooNarrow { gap_nm: to_nm(d) }.into());
        }
        prev = Some(d);
    }
    if let Some(fold) = jump {
        // The landing lies beyond the table range: the jump goes deep into contact.
        return Ok(Transition {
            power: fold.power,
            at: fold,
            cause: Cause::Fold,
        });
    }
    Err(TransitionError::NoTouchdown {
        max_power_mw: power_reached_mw(&solver, prev)?,
    }
    .into())
}

/// The heater power (mW) of the equilibrium at `last`, the last gap a scan reached; NaN where it
/// reached none.
fn power_reached_mw(solver: &EquilibriumSolver<'_>, last: Option<f64>) -> Result<f64> {
    match last {
        Some(d) => Ok(to_mw(solver.at_gap(d)?.power)),
        None => Ok(f64::NAN),
    }
}

/// A transition, or the error that says the head never leaves (or is already in) contact at
/// non-negative heater power.
fn transition(at: Equilibrium, cause: Cause, touchdown: bool) -> Result<Transition> {
    if at.power < 0.0 {
        let (gap_nm, power_mw) = (to_nm(at.d), to_mw(at.power));
        return Err(if touchdown {
            TransitionError::InContactAtZeroPower {
                at_fold: cause == Cause::Fold,
                gap_nm,
                power_mw,
            }
        } else {
            TransitionError::NoTakeOff { gap_nm, power_mw }
        }
        .into());
    }
    Ok(Transition {
        power: at.power,
        at,
        cause,
    })
}

/// Take-off power at the model's DC voltage, starting on the contact branch at
/// `start_power` (W) and following it to lower power.
pub fn takeoff_power(
    model: &SliderModel,
    start_power: f64,
    opts: &StaticOptions,
) -> Result<Transition> {
    opts.validate()?;
    super::equilibrium::check_heater(model)?;
    crate::error::check_finite("start_power", start_power)?;
    let volt2 = model.voltage().dc_squared();
    takeoff_at(model, volt2, start_power, opts)
}

/// Take-off at a given `V²`, from the contact equilibrium at `start_power`.
///
/// The head follows the stable contact equilibrium up in gap (power falling). At a fold it jumps
/// away from the disk and lands on the next stable equilibrium at the same power; the fold is the
/// take-off when the contact force there is below `F_th` (the usual case), otherwise the scan
/// goes on from the landing point. Reaching negative power first means the head stays in contact
/// at zero heater power: an error.
pub(crate) fn takeoff_at(
    model: &SliderModel,
    volt2: f64,
    start_power: f64,
    opts: &StaticOptions,
) -> Result<Transition> {
    let solver = EquilibriumSolver::new(model, volt2).refining_as(&opts.grid);
    let (mut lo, hi) = model.forces().table_range();
    let th = opts.contact_threshold;
    let target = model.protrusion(start_power);
    // The start lies deeper than the scan's lower end if the protrusion there is too small:
    // extend the scan downwards (the forces fall back to direct evaluation outside the table).
    let step = (hi - lo).max(1e-9) * 0.1;
    let mut extended = 0;
    while solver.protrusion_at(lo)? < target {
        lo -= step;
        extended += 1;
        if extended > 50 {
            return Err(TransitionError::NoContactEquilibrium {
                power_mw: to_mw(start_power),
                depth_nm: to_nm(-lo),
            }
            .into());
        }
    }
    let mut ascending = opts.grid.descending(lo, hi)?;
    ascending.reverse();
    let mut skip = Skipper::new(model, volt2, &opts.grid);
    // Up to the start only the protrusion is needed: the gap of the last point before it is the
    // first step's `prev`.
    let mut before: Option<f64> = None;
    let mut started = false;
    // The gap of the last grid point passed (its equilibrium is needed only for an error).
    let mut prev: Option<f64> = None;
    let mut jump: Option<Equilibrium> = None;
    let mut i = 0;
    while i < ascending.len() {
        // Pass over grid points proven not to change the scan below.
        let passed = match (started, jump) {
            (false, _) => skip.skip(&ascending, i, |b| b.protrusion.lo > target),
            (true, Some(fold)) => skip.skip(&ascending, i, |b| {
                b.stable == Some(false) || model.power_for(b.protrusion.lo) > fold.power
            }),
            (true, None) => skip.skip(&ascending, i, |b| {
                b.stable == Some(true) && b.contact.lo >= th && b.protrusion.lo >= 0.0
            }),
        };
        if passed > 0 {
            i += passed;
            if started {
                prev = Some(ascending[i - 1]);
            } else {
                before = Some(ascending[i - 1]);
            }
            continue;
        }
        let d = ascending[i];
        i += 1;
        if !started && solver.protrusion_at(d)? > target {
            before = Some(d);
            continue;
        }
        let e = solver.at_gap(d)?;
        if !started {
            if !e.is_stable() {
                return Err(TransitionError::UnstableContactStart {
                    power_mw: to_mw(start_power),
                }
                .into());
            }
            started = true;
            prev = before;
        }
        if let Some(fold) = jump {
            // The flying side falls again through the fold's power on a stable part.
            if e.is_stable() && e.power <= fold.power {
                if e.contact_force < th {
                    return transition(fold, Cause::Fold, false);
                }
                jump = None;
            }
            prev = Some(d);
            continue;
        }
        if let Some(p) = prev {
            if !e.is_stable() {
                let at = solver.refine_fold(p, e.d)?;
                if at.power < 0.0 {
                    return transition(at, Cause::Fold, false);
                }
                jump = Some(at);
                prev = Some(d);
                continue;
            }
            if e.contact_force < th {
                let at = solver.refine_threshold(p, e.d, th)?;
                return transition(at, Cause::Threshold, false);
            }
            if e.power < 0.0 {
                return transition(e, Cause::Fold, false);
            }
        }
        prev = Some(d);
    }
    if let Some(fold) = jump {
        return transition(fold, Cause::Fold, false);
    }
    Err(TransitionError::NoTakeOffInTable {
        min_power_mw: power_reached_mw(&solver, prev)?,
    }
    .into())
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
