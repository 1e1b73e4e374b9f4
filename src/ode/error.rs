//! Typed failures of the ODE stepper: each says at which `t` and why.

use thiserror::Error;

/// Why an integration stopped without reaching its end.
///
/// ```
/// use hdi_tribology::ode::OdeError;
/// let e = OdeError::TooManySteps { t: 0.5, max_steps: 10 };
/// assert!(e.to_string().contains("t = 0.5"));
/// ```
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum OdeError {
    /// An argument or option is out of range or inconsistent.
    #[error("invalid {field}: {reason}")]
    InvalidInput {
        /// Name of the offending argument or option, e.g. `options.rtol`.
        field: String,
        /// Why it was rejected, including the value seen.
        reason: String,
    },
    /// The step size controller asked for a step below the floor.
    #[error("step size {h:e} fell below its floor {h_min:e} at t = {t}")]
    StepTooSmall {
        /// Time reached.
        t: f64,
        /// Step size asked for.
        h: f64,
        /// The floor (the larger of `Options::h_min` and a few ulps of `t`).
        h_min: f64,
    },
    /// The step budget `Options::max_steps` (accepted plus rejected) was used up.
    #[error("maximum number of steps {max_steps} reached at t = {t}")]
    TooManySteps {
        /// Time reached.
        t: f64,
        /// The budget.
        max_steps: usize,
    },
    /// The right-hand side, the Jacobian or the state became NaN or infinite.
    #[error("non-finite {what} at t = {t}")]
    NonFinite {
        /// Time at which it was seen.
        t: f64,
        /// What was non-finite (`state`, `right-hand side`, `Jacobian`, ...).
        what: String,
    },
    /// The Newton iteration of an implicit method kept diverging as the step shrank.
    #[error("Newton iteration diverged at t = {t} (h = {h:e}): {reason}")]
    NewtonDivergence {
        /// Time reached.
        t: f64,
        /// Last step size tried.
        h: f64,
        /// Details.
        reason: String,
    },
    /// Rodas5P cannot resolve a component to the tolerance asked for: the rounding of its
    /// stage solves (`ε·|J|·|Δy|`, multiplied by up to `hγ` in slow and conserved directions and
    /// invisible to its error estimate) exceeds `atol_i / rtol`, the smallest size of that
    /// component the tolerance declares significant. Radau5 (whose result is defined by a
    /// residual in `f` alone) has no such floor; `Method::Auto` switches to it by itself.
    #[error(
        "Rodas5P cannot resolve component {component} at t = {t} (h = {h:e}): the rounding of its linear solves reaches {floor:e}, above atol/rtol = {significant:e}; use Radau5 or Auto"
    )]
    RoundingFloor {
        /// Time reached.
        t: f64,
        /// Step size tried.
        h: f64,
        /// Index of the component.
        component: usize,
        /// Estimated rounding error of the step in that component.
        floor: f64,
        /// `atol / rtol` of that component.
        significant: f64,
    },
    /// The integration was cancelled from outside ([`Cancel`](super::Cancel)).
    #[error("cancelled at t = {t}")]
    Cancelled {
        /// Time reached.
        t: f64,
    },
    /// The iteration matrix of a stiff method stayed singular as the step shrank.
    #[error("singular iteration matrix at t = {t} (h = {h:e})")]
    SingularMatrix {
        /// Time reached.
        t: f64,
        /// Last step size tried.
        h: f64,
    },
}

impl OdeError {
    /// Shorthand for [`OdeError::InvalidInput`].
    pub fn invalid(field: impl Into<String>, reason: impl Into<String>) -> Self {
        OdeError::InvalidInput {
            field: field.into(),
            reason: reason.into(),
        }
    }
}
