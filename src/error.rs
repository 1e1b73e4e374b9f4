//! The crate's error type: every variant says what went wrong and where.

use std::fmt;
use thiserror::Error;

/// Result alias used throughout the crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong in `hdi-tribology`.
///
/// ```
/// use hdi_tribology::Error;
/// let e = Error::invalid("surface.sigma", "must be finite and > 0, got -1");
/// assert_eq!(e.to_string(), "invalid surface.sigma: must be finite and > 0, got -1");
/// ```
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum Error {
    /// A user-supplied value is out of its valid range or inconsistent.
    #[error("invalid {field}: {reason}")]
    InvalidInput {
        /// Dotted path of the offending field, e.g. `surface.peaks.sigma`.
        field: String,
        /// Why it was rejected, including the value seen.
        reason: String,
    },
    /// A scene file could not be read or parsed.
    #[error("scene {origin}: {reason}")]
    Scene {
        /// File name or `<string>`.
        origin: String,
        /// Parser message (names the field where the parser can).
        reason: String,
    },
    /// A numerical procedure did not reach its tolerance.
    #[error("{what} did not converge: {reason}")]
    NoConvergence {
        /// What was being computed.
        what: String,
        /// Why it stopped.
        reason: String,
    },
    /// An analysis could not produce its result for this scene: a typed [`AnalysisError`] to
    /// `match` on.
    #[error(transparent)]
    Analysis(#[from] AnalysisError),
    /// Writing a result (CSV, chart, JSON) failed, before any file was touched.
    #[error("cannot write {what}: {reason}")]
    Output {
        /// What was being written, e.g. `CSV` or `chart "hysteresis"`.
        what: String,
        /// Why it failed.
        reason: String,
    },
    /// The ODE stepper failed (says at which time and why).
    #[error(transparent)]
    Ode(#[from] crate::ode::OdeError),
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
}

impl Error {
    /// Shorthand for [`Error::InvalidInput`].
    pub fn invalid(field: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::InvalidInput {
            field: field.into(),
            reason: reason.into(),
        }
    }

    /// Shorthand for [`Error::NoConvergence`].
    pub fn no_convergence(what: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::NoConvergence {
            what: what.into(),
            reason: reason.into(),
        }
    }

    /// Shorthand for [`Error::Output`].
    ///
    /// ```
    /// let e = hdi_tribology::Error::output("CSV", "a row of 3 cells, the header has 2");
    /// assert_eq!(e.to_string(), "cannot write CSV: a row of 3 cells, the header has 2");
    /// ```
    pub fn output(what: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::Output {
            what: what.into(),
            reason: reason.into(),
        }
    }
}

/// Checks that `value` is finite; names `field` otherwise.
///
/// ```
/// use hdi_tribology::error::check_finite;
/// assert!(check_finite("h0", 1e-8).is_ok());
/// assert!(check_finite("h0", f64::NAN).is_err());
/// ```
pub fn check_finite(field: &str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::invalid(
            field,
            format!("must be finite, got {value:?}"),
        ))
    }
}

/// Checks that `value` is finite and not below `bound`, the value of the field `bound_field`;
/// the message gives both in `unit`, `scale` being that unit's size in SI (`1e-3` for mW).
///
/// ```
/// use hdi_tribology::error::check_not_below;
/// assert!(check_not_below("max_power", 0.08, "start_power", 0.06, "mW", 1e-3).is_ok());
/// let e = check_not_below("max_power", 0.05, "start_power", 0.06, "mW", 1e-3).unwrap_err();
/// assert!(e.to_string().contains("start_power (60 mW), got 50 mW"));
/// ```
pub fn check_not_below(
    field: &str,
    value: f64,
    bound_field: &str,
    bound: f64,
    unit: &str,
    scale: f64,
) -> Result<f64> {
    check_finite(field, value)?;
    if value < bound {
        return Err(Error::invalid(
            field,
            format!(
                "must not be below {bound_field} ({} {unit}), got {} {unit}",
                bound / scale,
                value / scale
            ),
        ));
    }
    Ok(value)
}

/// Checks that `value` is finite and strictly positive.
///
/// ```
/// use hdi_tribology::error::check_positive;
/// assert!(check_positive("k", 3e5).is_ok());
/// assert!(check_positive("k", 0.0).is_err());
/// ```
pub fn check_positive(field: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::invalid(
            field,
            format!("must be finite and > 0, got {value:?}"),
        ))
    }
}

/// Checks that `value` is finite and non-negative.
///
/// ```
/// use hdi_tribology::error::check_non_negative;
/// assert!(check_non_negative("t_d", 0.0).is_ok());
/// assert!(check_non_negative("t_d", -1e-9).is_err());
/// ```
pub fn check_non_negative(field: &str, value: f64) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(Error::invalid(
            field,
            format!("must be finite and >= 0, got {value:?}"),
        ))
    }
}

/// Which analysis an [`AnalysisError`] comes from.
///
/// ```
/// use hdi_tribology::error::Stage;
/// assert_eq!(Stage::TakeOff.to_string(), "take-off");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Stage {
    /// Static touchdown.
    Touchdown,
    /// Static take-off.
    TakeOff,
    /// The stable flying equilibrium at a heater power.
    FlyingEquilibrium,
    /// The static pull-in voltage.
    PullIn,
    /// A dynamic cycle under a fixed heater programme.
    Cycle,
    /// A dynamic cycle whose heater ramp reverses at touchdown.
    TriggeredCycle,
    /// The linear response about an equilibrium.
    LinearResponse,
    /// The simulated response to the AC dither.
    SimulatedDither,
    /// The firmware clearance calibration.
    ClearanceCalibration,
    /// The drive plant.
    Drive,
    /// A controller running the drive.
    DriveController,
    /// A fit of scene parameters to measurements.
    Fit,
    /// The model curves at the measured points.
    ModelCurves,
    /// Sampling asperity peaks.
    PeakSampling,
    /// The first-order shift of a transition power with a parameter.
    TransitionSensitivity,
    /// The air bearing's attitude (fly height, pitch, roll) from the slider's geometry.
    AirBearing,
}

impl Stage {
    /// The analysis's name as the messages write it.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Touchdown => "touchdown",
            Stage::TakeOff => "take-off",
            Stage::FlyingEquilibrium => "flying equilibrium",
            Stage::PullIn => "pull-in voltage",
            Stage::Cycle => "cycle",
            Stage::TriggeredCycle => "triggered cycle",
            Stage::LinearResponse => "linear response",
            Stage::SimulatedDither => "simulated dither",
            Stage::ClearanceCalibration => "clearance calibration",
            Stage::Drive => "drive",
            Stage::DriveController => "drive controller",
            Stage::Fit => "fit",
            Stage::ModelCurves => "model curves",
            Stage::PeakSampling => "peak sampling",
            Stage::TransitionSensitivity => "transition sensitivity",
            Stage::AirBearing => "air bearing",
        }
    }
}

impl fmt::Display for Stage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A contact that feeds energy into the bounce: the interface lag exceeds the time constant
/// `c/K_contact` of the air-bearing damping against the contact stiffness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SelfExcitation {
    /// The interface lag `τ` (ns).
    pub interface_lag_ns: f64,
    /// `c/K_contact` where the trajectory stopped (ns).
    pub limit_ns: f64,
}

/// Why an analysis could not give its result for this scene. Numbers are in engineering units
/// (nm, mW, ms, ns), as the field names say.
///
/// ```
/// use hdi_tribology::analysis::{pull_in::pull_in_voltage, touchdown::StaticOptions};
/// use hdi_tribology::error::{AnalysisError, Error, Stage};
/// use hdi_tribology::{model::SliderModel, scene::Scene};
/// let mut scene = Scene::paper();
/// scene.electrostatic = None;
/// let model = SliderModel::from_scene(&scene)?;
/// match pull_in_voltage(&model, 0.0, &StaticOptions::new(5e-5)) {
///     Err(Error::Analysis(e @ AnalysisError::NoElectrostatics)) => {
///         assert_eq!(e.stage(), Stage::PullIn);
///         assert_eq!(e.to_string(), "pull-in voltage: the scene has no electrostatic term");
///     }
///     other => panic!("{other:?}"),
/// }
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum AnalysisError {
    /// Touchdown: the head is in contact already at zero heater power (the transition lies at
    /// negative power).
    InContactAtZeroPower {
        /// `true` at a fold, `false` at a threshold crossing.
        at_fold: bool,
        /// Bulge gap at the transition (nm).
        gap_nm: f64,
        /// Heater power of the transition (mW), negative.
        power_mw: f64,
    },
    /// Take-off: the head stays in contact down to zero heater power (adhesion holds it).
    NoTakeOff {
        /// Bulge gap where the contact branch ends (nm).
        gap_nm: f64,
        /// Heater power there (mW), negative.
        power_mw: f64,
    },
    /// No touchdown: the static flying branch neither reaches the contact threshold nor folds
    /// inside the force tables, or a dynamic search or a detector saw no contact.
    NoTouchdown {
        /// The analysis.
        stage: Stage,
        /// The largest heater power reached (mW).
        max_power_mw: f64,
        /// The detector that was watching, if one was.
        detector: Option<String>,
    },
    /// Take-off: the contact branch neither falls below the threshold nor folds inside the force
    /// tables.
    NoTakeOffInTable {
        /// The smallest heater power reached on the contact branch (mW).
        min_power_mw: f64,
    },
    /// Pull-in voltage: no fold and no threshold crossing inside the force tables.
    NoPullIn {
        /// The heater power the pull-in was sought at (mW).
        power_mw: f64,
    },
    /// Pull-in voltage: the scene has no electrostatic term.
    NoElectrostatics,
    /// The simulated dither needs an AC voltage.
    NoAcVoltage,
    /// The largest tabulated gap is already past the start of the scan: widen the table range.
    TableTooNarrow {
        /// The analysis.
        stage: Stage,
        /// The largest tabulated gap (nm).
        gap_nm: f64,
    },
    /// Flying equilibrium: the flying branch ends at a fold before the power is reached; the
    /// head is in contact at that power.
    FlyingBranchEnds {
        /// The heater power asked for (mW).
        power_mw: f64,
        /// Bulge gap of the fold (nm).
        fold_gap_nm: f64,
    },
    /// Flying equilibrium: none inside the force tables at this power.
    NoFlyingEquilibrium {
        /// The heater power asked for (mW).
        power_mw: f64,
    },
    /// Take-off: no contact equilibrium at the start power within this interpenetration.
    NoContactEquilibrium {
        /// The start power (mW).
        power_mw: f64,
        /// The deepest interpenetration searched (nm).
        depth_nm: f64,
    },
    /// Take-off: the contact equilibrium at the start power is unstable.
    UnstableContactStart {
        /// The start power (mW).
        power_mw: f64,
    },
    /// Triggered cycle: the touchdown search would need too many segments of the overshoot.
    TooManySegments {
        /// Heater power span searched, up to a protrusion of twice the clearance (mW).
        span_mw: f64,
        /// The overshoot (mW).
        overshoot_mw: f64,
        /// Segments needed.
        segments: f64,
        /// Segments allowed.
        max_segments: f64,
    },
    /// Cycle: the pad gap reached zero, so the slider body would enter the disk, outside the
    /// lumped model.
    LeftTheModel {
        /// Time (ms).
        t_ms: f64,
        /// Bulge gap there (nm).
        bulge_gap_nm: f64,
        /// Body velocity there (m/s).
        velocity_m_per_s: f64,
        /// Set when an interface lag makes the contact branch self-excited, the likely cause.
        self_excited: Option<SelfExcitation>,
    },
    /// Cycle: an explicit method used up its steps where the system is stiff.
    StepLimit {
        /// The method's name, e.g. `tsit5`.
        method: &'static str,
        /// Its step budget.
        max_steps: usize,
        /// Time reached (ms).
        t_ms: f64,
        /// Fastest decay rate of the bearing, contact and lags (1/s).
        fastest_rate_per_s: f64,
    },
    /// Cycle: the steps are spent more than twice as fast as an even pace over the programme
    /// would spend `solver.max_steps`, so the budget would run out.
    StepPace {
        /// The method's name, e.g. `auto`.
        method: &'static str,
        /// Steps taken so far (accepted and rejected).
        steps: usize,
        /// Time reached (ms).
        t_ms: f64,
        /// Length of the heater programme (ms).
        span_ms: f64,
        /// The step budget.
        max_steps: usize,
        /// For an explicit method: the fastest decay rate of the bearing, contact and lags
        /// (1/s), the likely cause.
        stiff_rate_per_s: Option<f64>,
    },
    /// Cycle, with [`CycleOptions::stop_outside_tables`](crate::analysis::CycleOptions): the bulge
    /// gap of an accepted step is deeper than the force tables reach while the steps are spent
    /// more than twice as fast as an even pace over the programme would spend
    /// `solver.max_steps` (from the start, or since the first step below the tables after an
    /// allowance of 1 % of the budget): a contact bouncing deep in the disk, where the contact
    /// model is far outside its light-contact validity, at a pace that would use up the step
    /// budget.
    LeftTheTables {
        /// Time reached (ms).
        t_ms: f64,
        /// Bulge gap `d` there (nm).
        bulge_gap_nm: f64,
        /// The low end of the force tables (nm).
        table_low_nm: f64,
        /// Steps taken so far (accepted and rejected).
        steps: usize,
        /// Time of the first accepted step below the tables (ms).
        first_below_ms: f64,
        /// Steps taken since then.
        steps_below: usize,
        /// Length of the heater programme (ms).
        span_ms: f64,
        /// The step budget.
        max_steps: usize,
    },
    /// Drive controller: it did not stop within its budget of periods.
    NotFinished {
        /// The budget.
        max_periods: usize,
    },
    /// Clearance calibration: the detector fired at the start power, before the first step.
    ContactAtStart {
        /// The detector.
        detector: String,
        /// The start power (mW).
        start_power_mw: f64,
    },
    /// A computed quantity is not finite.
    NotFinite {
        /// The analysis.
        stage: Stage,
        /// What is not finite.
        quantity: &'static str,
    },
    /// Transition sensitivity: the first-order shift is not defined at this gap.
    NoSensitivity {
        /// The gap (nm).
        gap_nm: f64,
        /// Why, in words.
        why: &'static str,
    },
    /// Model curves: a measured heater power lies beyond the equilibria the model tabulates.
    BeyondEquilibria {
        /// The data set.
        origin: String,
        /// The measured heater power (mW).
        heater_power_mw: f64,
        /// The largest heater power with a tabulated equilibrium (mW).
        last_power_mw: f64,
    },
    /// Fit: too few values settle for the free parameters once the unsettled dynamic ones are
    /// left out.
    TooFewSettled {
        /// Values left in the fit.
        included: usize,
        /// Values in the data.
        points: usize,
        /// The power tolerance they had to settle within (mW).
        tol_mw: f64,
        /// Free parameters.
        free: usize,
    },
    /// Fit: the model could not be evaluated at any start.
    NoModelStart {
        /// The first evaluation error.
        first_error: String,
    },
    /// Model curves: the model detects no transition at a measured point inside the heater
    /// programme.
    NotDetected {
        /// The data set.
        origin: String,
        /// The quantity, e.g. `touchdown`.
        quantity: String,
        /// The measured point's abscissa, as in the data.
        x: f64,
    },
    /// Air bearing: the bearing cannot carry the preload; its load stays below it down to the
    /// smallest spacing the solve allows.
    DoesNotFly {
        /// The preload (mN).
        preload_mn: f64,
        /// The bearing's load at the lowest attitude reached (mN).
        load_mn: f64,
        /// The smallest spacing there (nm).
        min_spacing_nm: f64,
    },
    /// A state the code should never reach (a bug, not a property of the scene).
    Internal {
        /// The analysis.
        stage: Stage,
        /// What went wrong.
        detail: String,
    },
}

/// A number for a message: fixed with 4 decimals in `[1e-3, 1e6)`, else exponent notation.
fn num(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || (1e-3..1e6).contains(&a) {
        format!("{x:.4}")
    } else {
        format!("{x:.4e}")
    }
}

impl AnalysisError {
    /// The analysis that failed.
    ///
    /// ```
    /// use hdi_tribology::error::{AnalysisError, Stage};
    /// assert_eq!(AnalysisError::NoElectrostatics.stage(), Stage::PullIn);
    /// ```
    pub fn stage(&self) -> Stage {
        use AnalysisError as A;
        match self {
            A::InContactAtZeroPower { .. } => Stage::Touchdown,
            A::NoTakeOff { .. }
            | A::NoTakeOffInTable { .. }
            | A::NoContactEquilibrium { .. }
            | A::UnstableContactStart { .. } => Stage::TakeOff,
            A::NoPullIn { .. } | A::NoElectrostatics => Stage::PullIn,
            A::NoAcVoltage => Stage::SimulatedDither,
            A::FlyingBranchEnds { .. } | A::NoFlyingEquilibrium { .. } => Stage::FlyingEquilibrium,
            A::TooManySegments { .. } => Stage::TriggeredCycle,
            A::LeftTheModel { .. }
            | A::LeftTheTables { .. }
            | A::StepLimit { .. }
            | A::StepPace { .. } => Stage::Cycle,
            A::NotFinished { .. } => Stage::DriveController,
            A::ContactAtStart { .. } => Stage::ClearanceCalibration,
            A::NoModelStart { .. } | A::TooFewSettled { .. } => Stage::Fit,
            A::NotDetected { .. } | A::BeyondEquilibria { .. } => Stage::ModelCurves,
            A::NoSensitivity { .. } => Stage::TransitionSensitivity,
            A::DoesNotFly { .. } => Stage::AirBearing,
            A::NoTouchdown { stage, .. }
            | A::TableTooNarrow { stage, .. }
            | A::NotFinite { stage, .. }
            | A::Internal { stage, .. } => *stage,
        }
    }

    /// The variant's name, e.g. `"NoTakeOff"` (for bindings that cannot match on the enum).
    pub fn kind(&self) -> &'static str {
        use AnalysisError as A;
        match self {
            A::InContactAtZeroPower { .. } => "InContactAtZeroPower",
            A::NoTakeOff { .. } => "NoTakeOff",
            A::NoTouchdown { .. } => "NoTouchdown",
            A::NoTakeOffInTable { .. } => "NoTakeOffInTable",
            A::NoPullIn { .. } => "NoPullIn",
            A::NoElectrostatics => "NoElectrostatics",
            A::NoAcVoltage => "NoAcVoltage",
            A::TableTooNarrow { .. } => "TableTooNarrow",
            A::FlyingBranchEnds { .. } => "FlyingBranchEnds",
            A::NoFlyingEquilibrium { .. } => "NoFlyingEquilibrium",
            A::NoContactEquilibrium { .. } => "NoContactEquilibrium",
            A::UnstableContactStart { .. } => "UnstableContactStart",
            A::TooManySegments { .. } => "TooManySegments",
            A::LeftTheModel { .. } => "LeftTheModel",
            A::StepLimit { .. } => "StepLimit",
            A::StepPace { .. } => "StepPace",
            A::LeftTheTables { .. } => "LeftTheTables",
            A::NotFinished { .. } => "NotFinished",
            A::ContactAtStart { .. } => "ContactAtStart",
            A::NotFinite { .. } => "NotFinite",
            A::NoModelStart { .. } => "NoModelStart",
            A::NoSensitivity { .. } => "NoSensitivity",
            A::BeyondEquilibria { .. } => "BeyondEquilibria",
            A::TooFewSettled { .. } => "TooFewSettled",
            A::NotDetected { .. } => "NotDetected",
            A::DoesNotFly { .. } => "DoesNotFly",
            A::Internal { .. } => "Internal",
        }
    }

    /// Why the analysis failed, without the analysis's name (the message after `stage: `).
    ///
    /// ```
    /// use hdi_tribology::error::AnalysisError;
    /// let e = AnalysisError::NoFlyingEquilibrium { power_mw: 60.0 };
    /// assert_eq!(e.to_string(), format!("flying equilibrium: {}", e.reason()));
    /// assert!(e.reason().contains("60.0000 mW"));
    /// ```
    pub fn reason(&self) -> String {
        use AnalysisError as A;
        match self {
            A::InContactAtZeroPower {
                at_fold,
                gap_nm,
                power_mw,
            } => format!(
                "the head is in contact already at zero heater power (the {} at d = {} nm lies at \
                 {} mW < 0)",
                if *at_fold {
                    "fold"
                } else {
                    "threshold crossing"
                },
                num(*gap_nm),
                num(*power_mw)
            ),
            A::NoTakeOff { gap_nm, power_mw } => format!(
                "the head stays in contact down to zero heater power (the contact branch ends at \
                 d = {} nm, {} mW < 0): adhesion holds it",
                num(*gap_nm),
                num(*power_mw)
            ),
            A::NoTouchdown {
                stage: Stage::Touchdown,
                max_power_mw,
                ..
            } => format!(
                "the flying branch neither reaches the contact threshold nor folds inside the \
                 table range (up to {} mW): widen the table range",
                num(*max_power_mw)
            ),
            A::NoTouchdown {
                max_power_mw,
                detector: Some(det),
                ..
            } => format!("{det} saw no contact up to {} mW", num(*max_power_mw)),
            A::NoTouchdown { max_power_mw, .. } => {
                format!("no touchdown detected up to {} mW", num(*max_power_mw))
            }
            A::NoTakeOffInTable { min_power_mw } => format!(
                "the contact branch neither falls below the threshold nor folds inside the table \
                 range (down to {} mW): widen the table range",
                num(*min_power_mw)
            ),
            A::NoPullIn { power_mw } => {
                format!("no pull-in inside the table range at {} mW", num(*power_mw))
            }
            A::NoElectrostatics => "the scene has no electrostatic term".into(),
            A::NoAcVoltage => "the voltage has no AC part".into(),
            A::TableTooNarrow {
                stage: Stage::FlyingEquilibrium,
                gap_nm,
            } => format!(
                "the largest tabulated gap ({} nm) is already below the equilibrium: widen the \
                 table range",
                num(*gap_nm)
            ),
            A::TableTooNarrow { gap_nm, .. } => format!(
                "the equilibrium at the largest tabulated gap ({} nm) is already unstable or in \
                 contact: widen the table range",
                num(*gap_nm)
            ),
            A::FlyingBranchEnds {
                power_mw,
                fold_gap_nm,
            } => format!(
                "the flying branch ends at a fold (d = {} nm) before the protrusion of {} mW is \
                 reached: the head is in contact there",
                num(*fold_gap_nm),
                num(*power_mw)
            ),
            A::NoFlyingEquilibrium { power_mw } => format!(
                "no flying equilibrium at {} mW inside the table range",
                num(*power_mw)
            ),
            A::NoContactEquilibrium { power_mw, depth_nm } => format!(
                "no contact equilibrium at {} mW within {} nm of interpenetration",
                num(*power_mw),
                num(*depth_nm)
            ),
            A::UnstableContactStart { power_mw } => format!(
                "the equilibrium at {} mW on the contact side is unstable",
                num(*power_mw)
            ),
            A::TooManySegments {
                span_mw,
                overshoot_mw,
                segments,
                max_segments,
            } => format!(
                "reaching a protrusion of 2 h0 takes {} mW, {segments:.3e} segments of the \
                 overshoot {} mW (at most {max_segments:e}): raise the overshoot or the heater \
                 efficiency",
                num(*span_mw),
                num(*overshoot_mw)
            ),
            A::LeftTheModel {
                t_ms,
                bulge_gap_nm,
                velocity_m_per_s,
                self_excited,
            } => {
                let mut s = format!(
                    "at t = {} ms the pad gap h0 + y fell to zero (bulge gap d = {} nm, velocity \
                     {} m/s): the slider body would enter the disk, outside the lumped model",
                    num(*t_ms),
                    num(*bulge_gap_nm),
                    num(*velocity_m_per_s)
                );
                if let Some(x) = self_excited {
                    s.push_str(&format!(
                        "; the interface lag {} ns exceeds c/K_contact = {} ns, so each contact \
                         feeds energy into the bounce (self-excited contact branch)",
                        num(x.interface_lag_ns),
                        num(x.limit_ns)
                    ));
                }
                s
            }
            A::StepLimit {
                method,
                max_steps,
                t_ms,
                fastest_rate_per_s,
            } => format!(
                "the explicit method {method} used up its {max_steps} steps at t = {} ms: the \
                 system is stiff there (fastest mode about {fastest_rate_per_s:.3e} 1/s from the \
                 bearing, contact and lags), so stability, not accuracy, limits its step; use \
                 auto, rodas5p or radau5",
                num(*t_ms)
            ),
            A::StepPace {
                method,
                steps,
                t_ms,
                span_ms,
                max_steps,
                stiff_rate_per_s,
            } => {
                let pace = format!(
                    "{steps} steps by t = {} ms, more than twice the pace that spends them evenly \
                     over the {} ms programme",
                    num(*t_ms),
                    num(*span_ms)
                );
                match stiff_rate_per_s {
                    Some(rate) => format!(
                        "the explicit method {method} would use up its {max_steps} steps ({pace}): \
                         the system is stiff there (fastest mode about {rate:.3e} 1/s from the \
                         bearing, contact and lags), so stability, not accuracy, limits its step; \
                         use auto, rodas5p or radau5"
                    ),
                    None => format!(
                        "the cycle would use up solver.max_steps = {max_steps} ({pace}): a contact \
                         that bounces without bound, or a tolerance too strict for the method"
                    ),
                }
            }
            A::LeftTheTables {
                t_ms,
                bulge_gap_nm,
                table_low_nm,
                steps,
                first_below_ms,
                steps_below,
                span_ms,
                max_steps,
            } => format!(
                "at t = {} ms the bulge gap d = {} nm is deeper than the force tables reach \
                 (down to {} nm), where the contact model is far outside its light-contact \
                 validity and every force is an exact quadrature, and the cycle spends its steps \
                 at more than twice the pace that uses solver.max_steps = {max_steps} evenly over \
                 the {} ms programme ({steps} steps, {steps_below} of them since the gap first \
                 went below the tables at {} ms): a contact bouncing below the tables that would \
                 use up the step budget",
                num(*t_ms),
                num(*bulge_gap_nm),
                num(*table_low_nm),
                num(*span_ms),
                num(*first_below_ms)
            ),
            A::NotFinished { max_periods } => {
                format!("did not finish within {max_periods} periods")
            }
            A::ContactAtStart {
                detector,
                start_power_mw,
            } => format!(
                "{detector} fired at the start power {} mW already, before the first heater \
                 step: contact before the staircase began (start lower, or with less dither)",
                num(*start_power_mw)
            ),
            A::NotFinite { quantity, .. } => format!("non-finite {quantity}"),
            A::DoesNotFly {
                preload_mn,
                load_mn,
                min_spacing_nm,
            } => format!(
                "the slider does not fly: the bearing carries {} mN at a smallest spacing of {} \
                 nm, short of the preload {} mN",
                num(*load_mn),
                num(*min_spacing_nm),
                num(*preload_mn)
            ),
            A::NoSensitivity { gap_nm, why } => format!("{why} at d = {} nm", num(*gap_nm)),
            A::BeyondEquilibria {
                origin,
                heater_power_mw,
                last_power_mw,
            } => format!(
                "{origin}: the heater power {} mW lies beyond the equilibria of the table range \
                 (up to {} mW)",
                num(*heater_power_mw),
                num(*last_power_mw)
            ),
            A::TooFewSettled {
                included,
                points,
                tol_mw,
                free,
            } => format!(
                "only {included} of {points} values remain once the dynamic points whose detected \
                 powers do not settle within {tol_mw} mW under tighter tolerances are left out: \
                 too few for {free} free parameters (raise dynamic_power_tol_mw or tighten \
                 solver.rtol)"
            ),
            A::NoModelStart { first_error } => {
                format!("the model could not be evaluated at any start: {first_error}")
            }
            A::NotDetected {
                origin,
                quantity,
                x,
            } => format!(
                "{origin}: the model detects no {quantity} at x = {x} inside the heater programme"
            ),
            A::Internal { detail, .. } => format!("internal error: {detail}"),
        }
    }
}

impl fmt::Display for AnalysisError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.stage(), self.reason())
    }
}

impl std::error::Error for AnalysisError {}
