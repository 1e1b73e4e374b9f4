//! The result of an integration: saved states, dense output, events and statistics.

use super::dense::DenseOutput;
use super::event::EventHit;
use super::options::Method;
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OVector};
use serde::{Deserialize, Serialize};

/// Work counters of one integration.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Stats {
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected steps (error too large, Newton failure, non-finite trial state).
    pub rejected: usize,
    /// Right-hand-side evaluations, including those of finite-difference Jacobians.
    pub rhs_evals: usize,
    /// Jacobian evaluations (analytic or finite-difference).
    pub jac_evals: usize,
    /// LU factorisations.
    pub lu_decomps: usize,
    /// Linear solves with an LU factorisation.
    pub lin_solves: usize,
    /// Newton iterations (Radau5).
    pub newton_iters: usize,
    /// Newton iterations that failed to converge (Radau5).
    pub newton_failures: usize,
    /// Switches between the explicit and the stiff method (`Auto`).
    pub stiffness_switches: usize,
    /// Accepted steps taken by a stiff method.
    pub stiff_steps: usize,
    /// Event-function evaluations.
    pub event_evals: usize,
    /// Steps ended on a root of the system's switching functions, where the system changed
    /// branch ([`OdeSystem::switches`](super::OdeSystem::switches)); 0 when read from a record
    /// written without it.
    #[serde(default)]
    pub branch_switches: usize,
    /// Steps taken by the step floor's backward Euler step where the method's trial failed at
    /// the floor ([`Integrator::set_step_floor`](super::Integrator::set_step_floor)); 0 when
    /// read from a record written without it.
    #[serde(default)]
    pub floor_steps: usize,
}

impl std::ops::AddAssign<&Stats> for Stats {
    /// Adds the counts of another integration (e.g. one segment of a longer run).
    fn add_assign(&mut self, s: &Stats) {
        self.accepted += s.accepted;
        self.rejected += s.rejected;
        self.rhs_evals += s.rhs_evals;
        self.jac_evals += s.jac_evals;
        self.lu_decomps += s.lu_decomps;
        self.lin_solves += s.lin_solves;
        self.newton_iters += s.newton_iters;
        self.newton_failures += s.newton_failures;
        self.stiffness_switches += s.stiffness_switches;
        self.stiff_steps += s.stiff_steps;
        self.event_evals += s.event_evals;
        self.branch_switches += s.branch_switches;
        self.floor_steps += s.floor_steps;
    }
}

/// Saved output of [`solve`](super::solve).
#[derive(Debug, Clone)]
pub struct Solution<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    /// Saved times (see [`SaveAt`](super::SaveAt)).
    pub t: Vec<f64>,
    /// Saved states, one per entry of `t`.
    pub y: Vec<OVector<f64, D>>,
    /// Located events, in time order.
    pub events: Vec<EventHit<D>>,
    /// Work counters.
    pub stats: Stats,
    /// Index of the terminal event that stopped the integration, if any.
    pub terminated_by_event: Option<usize>,
    /// Method asked for.
    pub method: Method,
    /// Time reached (the end time, or the time of a terminal event).
    pub t_end: f64,
    /// State at `t_end`.
    pub y_end: OVector<f64, D>,
    /// Per-step interpolants, when `Options::dense` was on.
    pub dense: Option<DenseOutput>,
}

impl<D: Dim> Solution<D>
where
    DefaultAllocator: Allocator<D>,
{
    /// State at any `t` in the integrated range from the dense output; `None` outside the range
    /// or when dense output was off.
    pub fn sample(&self, t: f64) -> Option<OVector<f64, D>> {
        let dense = self.dense.as_ref()?;
        let mut out = self.y_end.clone();
        dense.eval_into(t, &mut out).then_some(out)
    }

    /// Time reached.
    pub fn t_final(&self) -> f64 {
        self.t_end
    }

    /// State reached.
    pub fn y_final(&self) -> &OVector<f64, D> {
        &self.y_end
    }
}
