//! Why a quadrature or a table build fell short of its tolerance.

use crate::error::{FailureKind, Stage};

impl Stage {
    /// Adaptive Gauss–Kronrod integration.
    pub const GAUSS_KRONROD: Stage = Stage::named("adaptive Gauss-Kronrod integration");
    /// Tanh-sinh integration.
    pub const TANH_SINH: Stage = Stage::named("tanh-sinh integration");
    /// Building an interpolation table.
    pub const TABLE_BUILD: Stage = Stage::named("table build");
}

/// Why a quadrature or a table build fell short of its tolerance (always
/// [`Error::NoConvergence`](crate::Error::NoConvergence)). Values are in the integrand's units.
///
/// ```
/// use hdi_tribology::quadrature::{integrate, QuadOptions, QuadratureError};
/// let opts = QuadOptions { max_intervals: 2, ..QuadOptions::default() };
/// let e = integrate(|x: f64| (50.0 * x).sin().abs(), 0.0, 10.0, &opts).unwrap_err();
/// let kind = e.failure().and_then(|f| f.downcast_ref::<QuadratureError>());
/// assert!(matches!(kind, Some(QuadratureError::IntervalBudget { max_intervals: 2, .. })), "{e}");
/// ```
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum QuadratureError {
    /// The integrand is not finite at a node.
    #[error("the integrand is not finite ({y}) at x = {x}")]
    NotFinite {
        /// Which method.
        stage: Stage,
        /// The node.
        x: f64,
        /// The integrand's value there.
        y: f64,
    },
    /// Gauss–Kronrod: the budget of subintervals is used up.
    #[error(
        "max_intervals = {max_intervals} reached with estimated error {error:e} for value \
         {value:e} (target {target:e})"
    )]
    IntervalBudget {
        /// The budget.
        max_intervals: usize,
        /// The estimated error.
        error: f64,
        /// The estimate.
        value: f64,
        /// The error asked for.
        target: f64,
    },
    /// Gauss–Kronrod: no subinterval left to refine.
    #[error("no interval left to refine")]
    NoIntervalLeft,
    /// Gauss–Kronrod: the worst subinterval cannot be split in floating point.
    #[error(
        "interval around x = {x} cannot be split further; estimated error {error:e} (target \
         {target:e})"
    )]
    CannotSplit {
        /// The subinterval's middle.
        x: f64,
        /// The estimated error.
        error: f64,
        /// The error asked for.
        target: f64,
    },
    /// Tanh-sinh: the evaluation budget is used up.
    #[error("evaluation budget {budget} exhausted; last change {last_change:e}")]
    EvaluationBudget {
        /// The budget.
        budget: usize,
        /// The last change of the estimate.
        last_change: f64,
    },
    /// Tanh-sinh: the step halvings are used up.
    #[error("no convergence after {halvings} halvings; value {value:e}")]
    Halvings {
        /// Halvings made.
        halvings: usize,
        /// The last estimate.
        value: f64,
    },
    /// Table build: more nodes are needed than allowed.
    #[error(
        "needs more than max_nodes = {max_nodes} nodes (reached {reached}) for rel_tol = \
         {rel_tol:e}, abs_tol = {abs_tol:e} on [{lo:e}, {hi:e}]"
    )]
    TableNodes {
        /// The budget.
        max_nodes: usize,
        /// Nodes reached.
        reached: usize,
        /// The relative tolerance.
        rel_tol: f64,
        /// The absolute tolerance.
        abs_tol: f64,
        /// The range's low end.
        lo: f64,
        /// The range's high end.
        hi: f64,
    },
    /// Table build: the node spacing reaches the rounding level.
    #[error("node spacing reaches rounding level near {x}")]
    TableSpacing {
        /// Where.
        x: f64,
    },
}

impl FailureKind for QuadratureError {
    fn stage(&self) -> Stage {
        use QuadratureError as E;
        match self {
            E::NotFinite { stage, .. } => *stage,
            E::IntervalBudget { .. } | E::NoIntervalLeft | E::CannotSplit { .. } => {
                Stage::GAUSS_KRONROD
            }
            E::EvaluationBudget { .. } | E::Halvings { .. } => Stage::TANH_SINH,
            E::TableNodes { .. } | E::TableSpacing { .. } => Stage::TABLE_BUILD,
        }
    }

    fn name(&self) -> &'static str {
        use QuadratureError as E;
        match self {
            E::NotFinite { .. } => "NotFinite",
            E::IntervalBudget { .. } => "IntervalBudget",
            E::NoIntervalLeft => "NoIntervalLeft",
            E::CannotSplit { .. } => "CannotSplit",
            E::EvaluationBudget { .. } => "EvaluationBudget",
            E::Halvings { .. } => "Halvings",
            E::TableNodes { .. } => "TableNodes",
            E::TableSpacing { .. } => "TableSpacing",
        }
    }

    fn is_convergence(&self) -> bool {
        true
    }
}
