//! A generic ODE stepper that knows no physics: explicit, Rosenbrock and Radau methods with
//! step size control, dense output, events and automatic stiffness switching.
//!
//! A problem is an [`OdeSystem`] (or a closure in [`FnSystem`]) on nalgebra vectors: a
//! fixed-size `SVector` stays on the stack, a `DVector` serves larger systems. [`solve`] takes
//! the system, the time span, a [`Method`] and [`Options`], and returns a [`Solution`] with
//! saved states, a dense interpolant ([`Solution::sample`]), located [`Event`]s and [`Stats`].
//! Failures are typed ([`OdeError`]) and say at which `t` and why. A right-hand side whose law
//! changes branch where a function of the state changes sign names its switching functions
//! ([`OdeSystem::switches`]): steps end on their roots, so no step crosses the kink. A
//! right-hand side with costly parts that depend on the time alone keeps them per time
//! ([`OdeSystem::rhs_memo`], [`TimeMemo`]): the methods' evaluations that share a time compute
//! them once.
//!
//! The stiff Van der Pol oscillator `y₁' = y₂`, `y₂' = μ(1 − y₁²)y₂ − y₁`, μ = 1000, against
//! the reference value at t = 2000 of the Test Set for IVP Solvers (Mazzia et al.):
//!
//! ```
//! use hdi_tribology::ode::{solve, FnSystem, Method, Options};
//! use nalgebra::Vector2;
//!
//! let mu = 1000.0;
//! let vdp = FnSystem::new(move |_t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>| {
//!     dy[0] = y[1];
//!     dy[1] = mu * (1.0 - y[0] * y[0]) * y[1] - y[0];
//! });
//! let opts = Options::default().rtol(1e-7).atol(1e-7);
//! let sol = solve(&vdp, 0.0, Vector2::new(2.0, 0.0), 2000.0, Method::Auto, &opts, &mut [])?;
//! assert!((sol.y_final()[0] - 1.706167732170469).abs() < 1e-5);
//! assert!(sol.sample(1000.0).is_some()); // dense output over the whole range
//! println!("{} steps, {} switches", sol.stats.accepted, sol.stats.stiffness_switches);
//! # Ok::<(), hdi_tribology::ode::OdeError>(())
//! ```

mod ark436;
mod cancel;
mod dense;
mod dop853;
mod driver;
mod error;
mod event;
mod exponential;
mod floor_step;
mod integrator;
mod jacobian;
pub(crate) mod lu;
mod options;
mod problem;
mod radau5;
mod rodas5p;
mod solution;
mod stepper;
mod system;
mod tsit5;

pub use cancel::{Cancel, CANCEL_CHECK_INTERVAL};
pub use dense::{DenseOutput, StepPolynomial};
pub use driver::solve_observed;
pub use error::OdeError;
pub use event::{Direction, Event, EventHit};
pub use exponential::{expm, phi_functions, ExponentialStepper, PhiFunctions};
pub use integrator::{Integrator, StepStatus};
pub use options::{Method, Options, SaveAt, Tolerance, MIN_RTOL};
pub use problem::OdeProblem;
pub use solution::{Solution, Stats};
pub use system::{
    complex_step_jacobian, finite_difference_jacobian, FnSystem, NoJacobian, OdeSystem, TimeMemo,
};

use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OVector};

/// Integrates `y' = f(t, y)` from `(t0, y0)` to `tf > t0` with `method`.
///
/// `events` may be empty (`&mut []`). See the [module documentation](self) for a stiff
/// example; here a fixed-size state, a terminal event and dense output:
///
/// ```
/// use hdi_tribology::ode::{solve, Direction, Event, FnSystem, Method, Options};
/// use nalgebra::Vector2;
///
/// // A ball dropped from 10 m: stop when the height falls through zero.
/// let ball = FnSystem::new(|_t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>| {
///     dy[0] = y[1];
///     dy[1] = -9.81;
/// });
/// let mut events = [Event::new(|_t, y: &Vector2<f64>| y[0])
///     .direction(Direction::Falling)
///     .terminal(true)];
/// let opts = Options::default().rtol(1e-10).atol(1e-12);
/// let sol = solve(&ball, 0.0, Vector2::new(10.0, 0.0), 5.0, Method::Tsit5, &opts, &mut events)?;
/// assert_eq!(sol.terminated_by_event, Some(0));
/// assert!((sol.t_final() - (2.0 * 10.0 / 9.81f64).sqrt()).abs() < 1e-10);
/// let half = sol.sample(0.5).unwrap();
/// assert!((half[0] - (10.0 - 0.5 * 9.81 * 0.25)).abs() < 1e-10);
/// # Ok::<(), hdi_tribology::ode::OdeError>(())
/// ```
///
/// # Errors
/// [`OdeError::InvalidInput`] for bad arguments or options; [`OdeError::StepTooSmall`],
/// [`OdeError::TooManySteps`], [`OdeError::NonFinite`], [`OdeError::NewtonDivergence`] or
/// [`OdeError::SingularMatrix`] when the integration cannot go on.
pub fn solve<D: Dim, S: OdeSystem<D> + ?Sized>(
    sys: &S,
    t0: f64,
    y0: OVector<f64, D>,
    tf: f64,
    method: Method,
    opts: &Options,
    events: &mut [Event<'_, D>],
) -> Result<Solution<D>, OdeError>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    solve_observed(sys, t0, y0, tf, method, opts, events, |_, _| {})
}
