//! The crate's error type: every variant says what went wrong and where.
//!
//! There is one error type, [`Error`](enum@Error). Bad input, a bad scene or data file, an
//! output that cannot be written, a file error and a failed ODE step each have a variant of their
//! own. A failure of an analysis or a numerical procedure is a [`Failure`]: its kind is a typed
//! enum owned by the module that raises it (touchdown's `TransitionError`, the cycle's
//! `CycleError`, …), so this file knows no analysis. Match on a kind with [`Failure::downcast_ref`]; bindings that cannot match use
//! [`Failure::stage`] and [`Failure::kind`].

use std::any::Any;
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
    /// A numerical procedure did not reach its tolerance: a [`Failure`] whose kind says which
    /// procedure and why.
    #[error("{} did not converge: {}", .0.stage(), .0.reason())]
    NoConvergence(Failure),
    /// An analysis could not produce its result for this scene: a [`Failure`] whose typed kind
    /// the analysis owns.
    #[error("{0}")]
    Analysis(Failure),
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
    /// A data file (measured curves, a command file) is bad: which file, where in it, and why.
    #[error(transparent)]
    Data(#[from] DataError),
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

    /// The [`Failure`] of an analysis or a numerical procedure, if this is one.
    ///
    /// ```
    /// use hdi_tribology::analysis::pull_in::{pull_in_voltage, PullInError};
    /// use hdi_tribology::analysis::touchdown::StaticOptions;
    /// use hdi_tribology::{model::SliderModel, scene::Scene};
    /// let mut scene = Scene::paper();
    /// scene.electrostatic = None;
    /// let model = SliderModel::from_scene(&scene)?;
    /// let e = pull_in_voltage(&model, 0.0, &StaticOptions::new(5e-5)).unwrap_err();
    /// let failure = e.failure().expect("a failure");
    /// assert_eq!(failure.downcast_ref::<PullInError>(), Some(&PullInError::NoElectrostatics));
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn failure(&self) -> Option<&Failure> {
        match self {
            Error::Analysis(f) | Error::NoConvergence(f) => Some(f),
            _ => None,
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

/// A bad data file: which file, where in it, and why.
///
/// ```
/// use hdi_tribology::fit::DataSet;
/// let e = DataSet::from_csv_str("dc_voltage_v,touchdown_power_mw\n0.5,nan\n", "td.csv").unwrap_err();
/// assert_eq!((e.line, e.column), (Some(2), Some(2)));
/// assert_eq!(e.to_string(), "td.csv, line 2, column 2 (`touchdown_power_mw`): must be a finite number, got `nan`");
/// ```
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct DataError {
    /// The file (or the origin given for a string).
    pub file: String,
    /// Line in the file, 1-based (the header is line 1 unless comments precede it).
    pub line: Option<u64>,
    /// Column, 1-based.
    pub column: Option<usize>,
    /// The column's name as the file spells it.
    pub column_name: Option<String>,
    /// What is wrong, with the value as written.
    pub reason: String,
}

impl fmt::Display for DataError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(l) = self.line {
            write!(f, ", line {l}")?;
        }
        if let Some(c) = self.column {
            write!(f, ", column {c}")?;
        }
        if let Some(n) = &self.column_name {
            write!(f, " (`{n}`)")?;
        }
        write!(f, ": {}", self.reason)
    }
}

impl std::error::Error for DataError {}

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

/// What failed: the analysis or numerical procedure a [`Failure`] comes from, as messages name
/// it. Each module that raises failures declares its stages as associated constants next to its
/// kinds (for example [`Stage::TAKE_OFF`] in the touchdown module).
///
/// ```
/// use hdi_tribology::error::Stage;
/// assert_eq!(Stage::TAKE_OFF.to_string(), "take-off");
/// assert_eq!(Stage::named("my analysis").name(), "my analysis");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Stage(&'static str);

impl Stage {
    /// A stage of this name (a custom term or analysis can declare its own).
    pub const fn named(name: &'static str) -> Self {
        Stage(name)
    }

    /// The stage's name as the messages write it.
    pub fn name(self) -> &'static str {
        self.0
    }
}

impl fmt::Display for Stage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.0)
    }
}

/// The typed kind of a [`Failure`]: an enum owned by the module that raises it, whose `Display`
/// is the reason (without the stage's name), with numbers in engineering units as its field names
/// say. Any `Clone` type implementing it converts into [`Error`](enum@Error) with `?` or `.into()`.
///
/// ```
/// use hdi_tribology::error::{Error, FailureKind, Stage};
/// #[derive(Clone, Debug, PartialEq)]
/// enum MyError { TooHot { temperature_k: f64 } }
/// impl std::fmt::Display for MyError {
///     fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
///         let MyError::TooHot { temperature_k } = self;
///         write!(f, "the head reached {temperature_k} K")
///     }
/// }
/// impl FailureKind for MyError {
///     fn stage(&self) -> Stage { Stage::named("my analysis") }
///     fn name(&self) -> &'static str { "TooHot" }
/// }
/// let e: Error = MyError::TooHot { temperature_k: 900.0 }.into();
/// assert_eq!(e.to_string(), "my analysis: the head reached 900 K");
/// let f = e.failure().unwrap();
/// assert_eq!((f.stage(), f.kind()), (Stage::named("my analysis"), "TooHot"));
/// assert!(matches!(f.downcast_ref::<MyError>(), Some(MyError::TooHot { .. })));
/// ```
pub trait FailureKind: CloneKind + Any + fmt::Display + fmt::Debug + Send + Sync {
    /// What failed.
    fn stage(&self) -> Stage;
    /// The variant's name, e.g. `"NoTakeOff"` (for bindings that cannot match on the enum).
    fn name(&self) -> &'static str;
    /// `true` when a numerical procedure stopped short of its tolerance (the error is then
    /// [`Error::NoConvergence`]), `false` when an analysis cannot give its result for this scene
    /// ([`Error::Analysis`], the default).
    fn is_convergence(&self) -> bool {
        false
    }
}

/// Implements [`FailureKind`] for an enum from a table of its variants and their stages (the
/// variant's name is its identifier); `convergence` decides, for a value of the enum, whether it
/// is a convergence failure ([`Error::NoConvergence`]).
macro_rules! failure_kind {
    ($ty:ident, convergence = $conv:expr, { $($variant:ident => $stage:expr),+ $(,)? }) => {
        impl $crate::error::FailureKind for $ty {
            fn stage(&self) -> $crate::error::Stage {
                match self {
                    $( $ty::$variant { .. } => $stage, )+
                }
            }

            fn name(&self) -> &'static str {
                match self {
                    $( $ty::$variant { .. } => stringify!($variant), )+
                }
            }

            fn is_convergence(&self) -> bool {
                let convergence: fn(&$ty) -> bool = $conv;
                convergence(self)
            }
        }
    };
}
pub(crate) use failure_kind;

/// Cloning a boxed [`FailureKind`]; implemented for every `Clone` kind.
#[doc(hidden)]
pub trait CloneKind {
    /// A boxed copy.
    fn clone_kind(&self) -> Box<dyn FailureKind>;
}

impl<T: FailureKind + Clone> CloneKind for T {
    fn clone_kind(&self) -> Box<dyn FailureKind> {
        Box::new(self.clone())
    }
}

/// An analysis or a numerical procedure could not give its result: its [`Stage`] and its typed
/// kind, owned by the module that raised it. `Display` writes `stage: reason`.
///
/// ```
/// use hdi_tribology::analysis::pull_in::{pull_in_voltage, PullInError};
/// use hdi_tribology::analysis::touchdown::StaticOptions;
/// use hdi_tribology::error::{Error, Stage};
/// use hdi_tribology::{model::SliderModel, scene::Scene};
/// let mut scene = Scene::paper();
/// scene.electrostatic = None;
/// let model = SliderModel::from_scene(&scene)?;
/// match pull_in_voltage(&model, 0.0, &StaticOptions::new(5e-5)) {
///     Err(Error::Analysis(e)) => {
///         assert_eq!(e.stage(), Stage::PULL_IN);
///         assert_eq!(e.kind(), "NoElectrostatics");
///         assert_eq!(e.to_string(), "pull-in voltage: the scene has no electrostatic term");
///         assert_eq!(e.downcast_ref(), Some(&PullInError::NoElectrostatics));
///     }
///     other => panic!("{other:?}"),
/// }
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub struct Failure(Box<dyn FailureKind>);

impl Failure {
    /// A failure of this kind.
    pub fn new(kind: impl FailureKind) -> Self {
        Failure(Box::new(kind))
    }

    /// What failed.
    pub fn stage(&self) -> Stage {
        self.0.stage()
    }

    /// The kind's variant name, e.g. `"NoTakeOff"`.
    pub fn kind(&self) -> &'static str {
        self.0.name()
    }

    /// Why it failed, without the stage's name (the message after `stage: `).
    pub fn reason(&self) -> String {
        self.0.to_string()
    }

    /// The typed kind, if it is a `K`.
    pub fn downcast_ref<K: FailureKind>(&self) -> Option<&K> {
        (self.0.as_ref() as &dyn Any).downcast_ref::<K>()
    }

    /// `true` if the kind is a `K`.
    pub fn is<K: FailureKind>(&self) -> bool {
        self.downcast_ref::<K>().is_some()
    }
}

impl Clone for Failure {
    fn clone(&self) -> Self {
        Failure(self.0.clone_kind())
    }
}

impl fmt::Debug for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(&self.0, f)
    }
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.stage(), self.0)
    }
}

impl std::error::Error for Failure {}

impl<K: FailureKind> From<K> for Failure {
    fn from(kind: K) -> Self {
        Failure::new(kind)
    }
}

impl<K: FailureKind> From<K> for Error {
    fn from(kind: K) -> Self {
        let convergence = kind.is_convergence();
        let f = Failure::new(kind);
        if convergence {
            Error::NoConvergence(f)
        } else {
            Error::Analysis(f)
        }
    }
}

/// A state the code should never reach: a bug, not a property of the scene.
///
/// ```
/// use hdi_tribology::error::{Internal, Stage};
/// let e: hdi_tribology::Error = Internal { stage: Stage::named("fit"), what: "an SVD failed" }.into();
/// assert_eq!(e.to_string(), "fit: internal error: an SVD failed");
/// ```
#[derive(Clone, Debug, PartialEq, Error)]
#[error("internal error: {what}")]
pub struct Internal {
    /// Where.
    pub stage: Stage,
    /// What went wrong.
    pub what: &'static str,
}

impl FailureKind for Internal {
    fn stage(&self) -> Stage {
        self.stage
    }

    fn name(&self) -> &'static str {
        "Internal"
    }
}

/// A number for a message: fixed with 4 decimals in `[1e-3, 1e6)`, else exponent notation.
///
/// ```
/// use hdi_tribology::error::num;
/// assert_eq!(num(60.0), "60.0000");
/// assert_eq!(num(2.5e-7), "2.5000e-7");
/// ```
pub fn num(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || (1e-3..1e6).contains(&a) {
        format!("{x:.4}")
    } else {
        format!("{x:.4e}")
    }
}
