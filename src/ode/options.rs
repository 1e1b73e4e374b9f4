//! What to solve with: the [`Method`] and the [`Options`] (tolerances, step limits, output).

use super::error::OdeError;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Integration method.
///
/// ```
/// use hdi_tribology::ode::Method;
/// let m: Method = "rodas5p".parse().unwrap();
/// assert_eq!(m, Method::Rodas5P);
/// assert_eq!(m.to_string(), "rodas5p");
/// assert!("euler".parse::<Method>().is_err());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Tsitouras' explicit Runge–Kutta 5(4), FSAL, 4th-order dense output. Non-stiff default.
    Tsit5,
    /// Dormand–Prince explicit Runge–Kutta 8(5,3) with 7th-order dense output, for tight
    /// tolerances on non-stiff problems.
    Dop853,
    /// Rosenbrock method Rodas5P (Steinebach), order 5, L-stable, 4th-order dense output.
    /// Refuses with [`OdeError::RoundingFloor`](super::OdeError::RoundingFloor) a problem whose
    /// absolute tolerance lies below the rounding of its linear solves (E5 of the Test Set).
    Rodas5P,
    /// Radau IIA, 3 stages, order 5, L-stable, with simplified Newton iterations.
    Radau5,
    /// An explicit method while the problem is non-stiff, a stiff method while it is stiff,
    /// switching both ways. The explicit method is DOP853 for `rtol` below 1e-8 and Tsit5 from
    /// 1e-8 on; the stiff method is Radau5 for `rtol` below 1e-6 and Rodas5P from 1e-6 on (by
    /// the measured work–precision of each pair; the tolerance at the start decides). When
    /// Rodas5P refuses a step for its rounding floor, Auto goes on with Radau5. With Tsit5 and
    /// Rodas5P it also weighs the cost: a stiff run whose steps are no longer than twice the
    /// explicit step before it (the steps held by accuracy, as under an AC forcing) hands back
    /// once an explicit step could be as long, and the next tries wait longer. For a system
    /// with branches ([`crate::ode::OdeSystem::branch_rate`]) that pair also goes stiff at
    /// once on entering a branch whose declared rate holds the explicit step under half the
    /// coming one, and hands back where such a branch ends and the stiffness went with it.
    /// Where the system declares that branch's stiff rows
    /// ([`crate::ode::OdeSystem::stiff_diagonal`]) and the rest is not stiff, it steps the
    /// branch with the additive pair ARK4(3)6L\[2\]SA instead (those rows implicit, by a
    /// division each; the others explicit), back to Tsit5 where the branch ends.
    Auto,
}

impl Method {
    /// All methods, in the order of the enum.
    pub const ALL: [Method; 5] = [
        Method::Tsit5,
        Method::Dop853,
        Method::Rodas5P,
        Method::Radau5,
        Method::Auto,
    ];

    /// Nominal order of the method's solution (of the stiff method for `Auto`).
    pub fn order(self) -> usize {
        match self {
            Method::Tsit5 | Method::Rodas5P | Method::Radau5 | Method::Auto => 5,
            Method::Dop853 => 8,
        }
    }

    /// The lowercase name used by `FromStr`, `Display` and serde.
    pub fn name(self) -> &'static str {
        match self {
            Method::Tsit5 => "tsit5",
            Method::Dop853 => "dop853",
            Method::Rodas5P => "rodas5p",
            Method::Radau5 => "radau5",
            Method::Auto => "auto",
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Smallest relative tolerance, 100 ε (≈ 2.2e-14): below it the error estimates are rounding
/// noise. Scenes and the command line take `rtol` in `[MIN_RTOL, 1)`.
///
/// ```
/// use hdi_tribology::ode::{Options, MIN_RTOL};
/// assert!(Options::default().rtol(MIN_RTOL).validate(1).is_ok());
/// assert!(Options::default().rtol(MIN_RTOL / 2.0).validate(1).is_err());
/// ```
pub const MIN_RTOL: f64 = 100.0 * f64::EPSILON;

impl FromStr for Method {
    type Err = OdeError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let lower = s.trim().to_ascii_lowercase();
        Method::ALL
            .into_iter()
            .find(|m| m.name() == lower)
            .ok_or_else(|| {
                OdeError::invalid(
                    "method",
                    format!(
                        "unknown method {s:?}; expected tsit5, dop853, rodas5p, radau5 or auto"
                    ),
                )
            })
    }
}

/// Absolute tolerance: one value for all components or one per component.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Tolerance {
    /// Same absolute tolerance for every component.
    Scalar(f64),
    /// One absolute tolerance per component (length = state dimension).
    PerComponent(Vec<f64>),
}

/// Checks a per-component absolute tolerance: `n` entries, each finite and `>= 0`.
pub(crate) fn check_atol_components(v: &[f64], n: usize) -> Result<(), OdeError> {
    if v.len() != n {
        return Err(OdeError::invalid(
            "options.atol",
            format!("has {} components, the state has {n}", v.len()),
        ));
    }
    if let Some((i, a)) = v
        .iter()
        .enumerate()
        .find(|(_, a)| !(a.is_finite() && **a >= 0.0))
    {
        return Err(OdeError::invalid(
            format!("options.atol[{i}]"),
            format!("must be finite and >= 0, got {a}"),
        ));
    }
    Ok(())
}

impl Tolerance {
    /// Tolerance of component `i` (`PerComponent` must have been validated for length).
    pub fn get(&self, i: usize) -> f64 {
        match self {
            Tolerance::Scalar(a) => *a,
            Tolerance::PerComponent(v) => v.get(i).copied().unwrap_or(f64::NAN),
        }
    }
}

/// Which states the [`Solution`](super::Solution) keeps in `t` and `y`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum SaveAt {
    /// The initial point and every accepted step (and a terminal event's point).
    Steps,
    /// Only these times, interpolated on the dense output; they must lie in `[t0, tf]` and be
    /// sorted ascending. A terminal event cuts the list at its time.
    Times(Vec<f64>),
    /// Only the final point.
    Final,
}

/// Integration options; `Options::default()` and builder-style setters.
///
/// ```
/// use hdi_tribology::ode::{Options, SaveAt};
/// let opts = Options::default().rtol(1e-8).atol(1e-10).h_max(1e-3).save(SaveAt::Final);
/// assert!(opts.validate(2).is_ok());
/// assert!(Options::default().rtol(-1.0).validate(2).is_err());
/// // Serde: missing fields take their defaults.
/// let o: Options = serde_json::from_str(r#"{"rtol": 1e-9, "h_max": 2e-6}"#).unwrap();
/// assert_eq!((o.rtol, o.h_max, o.max_steps), (1e-9, 2e-6, Options::default().max_steps));
/// let back: Options = serde_json::from_str(&serde_json::to_string(&Options::default()).unwrap()).unwrap();
/// assert_eq!(back, Options::default());
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Options {
    /// Relative tolerance (> 0, ≥ 100 ε).
    pub rtol: f64,
    /// Absolute tolerance, scalar or per component (≥ 0).
    pub atol: Tolerance,
    /// Initial step size; `None` selects it automatically.
    pub h_init: Option<f64>,
    /// Largest step size allowed (> 0); keeps steps from jumping over short features.
    /// Infinite by default (serialised as `null` / absent).
    #[serde(with = "infinite_as_none")]
    pub h_max: f64,
    /// Smallest step size allowed (≥ 0); a smaller step request is an error.
    pub h_min: f64,
    /// Budget of step attempts, accepted plus rejected.
    pub max_steps: usize,
    /// Times where the right-hand side has kinks; steps end exactly on them.
    pub t_stops: Vec<f64>,
    /// Which states to save.
    pub save: SaveAt,
    /// Keep the interpolation coefficients of every step so that
    /// [`Solution::sample`](super::Solution::sample) works over the whole range.
    pub dense: bool,
    /// Absolute time tolerance to which event times are located.
    pub event_tol: f64,
    /// Step size control on (default). Off: constant steps of `h_init` (required), every step
    /// accepted — for convergence-order studies.
    pub adaptive: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            rtol: 1e-6,
            atol: Tolerance::Scalar(1e-8),
            h_init: None,
            h_max: f64::INFINITY,
            h_min: 0.0,
            max_steps: 100_000,
            t_stops: Vec::new(),
            save: SaveAt::Steps,
            dense: true,
            event_tol: 1e-12,
            adaptive: true,
        }
    }
}

impl Options {
    setters! {
        /// Sets the relative tolerance.
        rtol(rtol: f64) => rtol = rtol;
        /// Sets one absolute tolerance for all components.
        atol(atol: f64) => atol = Tolerance::Scalar(atol);
        /// Sets one absolute tolerance per component.
        atol_per_component(atol: Vec<f64>) => atol = Tolerance::PerComponent(atol);
        /// Sets the initial step size.
        h_init(h: f64) => h_init = Some(h);
        /// Sets the largest step size.
        h_max(h: f64) => h_max = h;
        /// Sets the step size floor.
        h_min(h: f64) => h_min = h;
        /// Sets the budget of step attempts.
        max_steps(n: usize) => max_steps = n;
        /// Sets the times where the right-hand side has kinks.
        t_stops(t: Vec<f64>) => t_stops = t;
        /// Sets what to save.
        save(save: SaveAt) => save = save;
        /// Turns dense output on or off.
        dense(dense: bool) => dense = dense;
        /// Sets the time tolerance of event location.
        event_tol(tol: f64) => event_tol = tol;
        /// Turns step size control on (default) or off (constant steps of `h_init`).
        adaptive(adaptive: bool) => adaptive = adaptive;
    }

    /// Checks every option for a state of dimension `n`.
    pub fn validate(&self, n: usize) -> Result<(), OdeError> {
        if !(self.rtol.is_finite() && self.rtol >= MIN_RTOL && self.rtol < 1.0) {
            return Err(OdeError::invalid(
                "options.rtol",
                format!(
                    "must be finite, in [{MIN_RTOL:.1e}, 1) (100 ε), got {}",
                    self.rtol
                ),
            ));
        }
        match &self.atol {
            Tolerance::Scalar(a) => {
                if !(a.is_finite() && *a >= 0.0) {
                    return Err(OdeError::invalid(
                        "options.atol",
                        format!("must be finite and >= 0, got {a}"),
                    ));
                }
            }
            Tolerance::PerComponent(v) => check_atol_components(v, n)?,
        }
        if let Some(h) = self.h_init {
            if !(h.is_finite() && h > 0.0) {
                return Err(OdeError::invalid(
                    "options.h_init",
                    format!("must be finite and > 0, got {h}"),
                ));
            }
        }
        if !self.adaptive && self.h_init.is_none() {
            return Err(OdeError::invalid(
                "options.h_init",
                "constant steps (adaptive = false) need h_init",
            ));
        }
        if self.h_max.is_nan() || self.h_max <= 0.0 {
            return Err(OdeError::invalid(
                "options.h_max",
                format!("must be > 0, got {}", self.h_max),
            ));
        }
        if !(self.h_min.is_finite() && self.h_min >= 0.0 && self.h_min <= self.h_max) {
            return Err(OdeError::invalid(
                "options.h_min",
                format!("must be finite, >= 0 and <= h_max, got {}", self.h_min),
            ));
        }
        if self.max_steps == 0 {
            return Err(OdeError::invalid("options.max_steps", "must be > 0, got 0"));
        }
        if let Some(t) = self.t_stops.iter().find(|t| !t.is_finite()) {
            return Err(OdeError::invalid(
                "options.t_stops",
                format!("must be finite, got {t}"),
            ));
        }
        if let SaveAt::Times(ts) = &self.save {
            if let Some(t) = ts.iter().find(|t| !t.is_finite()) {
                return Err(OdeError::invalid(
                    "options.save",
                    format!("times must be finite, got {t}"),
                ));
            }
            if ts.windows(2).any(|w| w[1] < w[0]) {
                return Err(OdeError::invalid(
                    "options.save",
                    "times must be sorted ascending",
                ));
            }
        }
        if !(self.event_tol.is_finite() && self.event_tol > 0.0) {
            return Err(OdeError::invalid(
                "options.event_tol",
                format!("must be finite and > 0, got {}", self.event_tol),
            ));
        }
        Ok(())
    }
}

/// Serde for a value that is infinite by default: `None`/`null` stands for +∞ (JSON has no
/// infinity).
mod infinite_as_none {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        let o = if v.is_infinite() && *v > 0.0 {
            None
        } else {
            Some(*v)
        };
        o.serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::INFINITY))
    }
}
