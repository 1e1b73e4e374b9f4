//! A problem held as one value: system, time span and initial state.

use super::error::OdeError;
use super::event::Event;
use super::integrator::Integrator;
use super::options::{Method, Options};
use super::solution::Solution;
use super::system::OdeSystem;
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OVector};

/// An initial-value problem `y' = f(t, y)`, `y(t0) = y0`, on `[t0, tf]`, to be solved with
/// any method and options, or stepped.
///
/// ```
/// use hdi_tribology::nalgebra::Vector1;
/// use hdi_tribology::ode::{FnSystem, Method, OdeProblem, Options};
/// let decay = FnSystem::new(|_t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>| dy[0] = -y[0]);
/// let p = OdeProblem::new(decay, (0.0, 2.0), Vector1::new(1.0));
/// let opts = Options::default().rtol(1e-9).atol(1e-12);
/// for m in [Method::Tsit5, Method::Radau5] {
///     let sol = p.solve(m, &opts)?;
///     assert!((sol.y_final()[0] - (-2f64).exp()).abs() < 1e-8);
/// }
/// let mut it = p.integrator(Method::Dop853, &opts)?;
/// it.advance_to(1.0)?;
/// assert!((it.state()[0] - (-1f64).exp()).abs() < 1e-9);
/// # Ok::<(), hdi_tribology::ode::OdeError>(())
/// ```
#[derive(Debug, Clone)]
pub struct OdeProblem<S, D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    /// The right-hand side (and optional Jacobian).
    pub system: S,
    /// Start time.
    pub t0: f64,
    /// End time.
    pub tf: f64,
    /// State at `t0`.
    pub y0: OVector<f64, D>,
}

impl<S: OdeSystem<D>, D: Dim> OdeProblem<S, D>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// The problem on the span `(t0, tf)`.
    pub fn new(system: S, span: (f64, f64), y0: OVector<f64, D>) -> Self {
        OdeProblem {
            system,
            t0: span.0,
            tf: span.1,
            y0,
        }
    }

    /// Solves it with [`solve`](super::solve), without events.
    ///
    /// # Errors
    /// As [`solve`](super::solve).
    pub fn solve(&self, method: Method, opts: &Options) -> Result<Solution<D>, OdeError> {
        self.solve_with_events(method, opts, &mut [])
    }

    /// Solves it with [`solve`](super::solve) and events.
    ///
    /// # Errors
    /// As [`solve`](super::solve).
    pub fn solve_with_events(
        &self,
        method: Method,
        opts: &Options,
        events: &mut [Event<'_, D>],
    ) -> Result<Solution<D>, OdeError> {
        super::solve(
            &self.system,
            self.t0,
            self.y0.clone(),
            self.tf,
            method,
            opts,
            events,
        )
    }

    /// An [`Integrator`] at its start, to be stepped.
    ///
    /// # Errors
    /// As [`Integrator::new`].
    pub fn integrator(
        &self,
        method: Method,
        opts: &Options,
    ) -> Result<Integrator<'_, D, &S>, OdeError> {
        Integrator::new(
            &self.system,
            self.t0,
            self.y0.clone(),
            self.tf,
            method,
            opts,
        )
    }
}
