//! The one run loop: it steps a slider's integrator and shows every accepted step to
//! observers, which record, watch and end the run (the cycle's recorder, step pace, table exit,
//! pad guard and touchdown watch; the drive's step budget and contact slope).
//!
//! An observer is a type of its own, and observers compose as tuples, so a run with several of
//! them costs what the same checks cost written inline: each is known at compile time.

use crate::error::{Error, Result};
use crate::model::SliderSystem;
use crate::ode::{Integrator, OdeError, Stats, StepPolynomial, StepStatus};
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim};

/// What an observer wants after a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flow {
    /// Go on stepping.
    Continue,
    /// End the run here (the state stays at the end of this step).
    Stop,
}

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ended {
    /// A step ended on the integrator's end time.
    End,
    /// The time asked for was reached or passed (the last step may run past it).
    Time,
    /// An observer said [`Flow::Stop`].
    Stopped,
}

/// One accepted step as an observer sees it.
#[derive(Clone, Copy, Debug)]
pub struct StepView<'a> {
    /// The time the step ended at.
    pub t: f64,
    /// The state there.
    pub state: &'a [f64],
    /// What the integrator reported of the step.
    pub status: StepStatus,
    /// The step's weighted error estimate against the tolerances (at most 1 under adaptive
    /// control; any size with fixed steps).
    pub error: f64,
    /// The integrator's counts so far.
    pub stats: Stats,
    /// The step's interpolant.
    pub last_step: StepPolynomial<'a>,
    /// The slider and its inputs.
    pub system: &'a SliderSystem,
}

/// Something that sees every accepted step of a run: a recorder, a detector, a guard.
///
/// It returns [`Flow::Stop`] to end the run, or an error to end it with that error.
///
/// ```
/// use hdi_tribology::analysis::{flying_equilibrium, ScanGrid};
/// use hdi_tribology::heater::Programme;
/// use hdi_tribology::model::SliderModel;
/// use hdi_tribology::scene::Scene;
/// use hdi_tribology::sim::{run, Flow, Observer, Problem, StepView};
///
/// /// Counts the steps and keeps the smallest bulge gap.
/// struct Closest { steps: usize, gap: f64 }
/// impl Observer for Closest {
///     fn accepted(&mut self, step: &StepView<'_>) -> hdi_tribology::Result<Flow> {
///         self.steps += 1;
///         self.gap = self.gap.min(step.system.gaps(step.t, step.state).bulge);
///         Ok(Flow::Continue)
///     }
/// }
///
/// let model = SliderModel::from_scene(&Scene::paper())?;
/// let rest = flying_equilibrium(&model, 0.06, 0.0, &ScanGrid::default())?.rest();
/// let problem = Problem::builder(&model, model.inputs(Programme::constant(0.06, 1e-4)?), true)
///     .build()?;
/// let n = problem.system().layout().len();
/// let y0 = problem.initial_state(nalgebra::Dyn(n), &rest);
/// let mut it = problem.integrator(0.0, y0, 1e-4)?;
/// let mut closest = Closest { steps: 0, gap: f64::INFINITY };
/// run(&mut it, None, &mut closest, Into::into)?;
/// assert!(closest.steps > 0 && closest.gap > 0.0);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub trait Observer {
    /// Sees the step just accepted.
    fn accepted(&mut self, step: &StepView<'_>) -> Result<Flow>;
}

/// No observer.
impl Observer for () {
    fn accepted(&mut self, _: &StepView<'_>) -> Result<Flow> {
        Ok(Flow::Continue)
    }
}

impl<O: Observer + ?Sized> Observer for &mut O {
    fn accepted(&mut self, step: &StepView<'_>) -> Result<Flow> {
        (**self).accepted(step)
    }
}

/// Observers in a tuple see each step in order; the first error ends the run, and the run
/// stops after the step when any of them says stop (all of them have seen it).
macro_rules! tuple_observer {
    ($($o:ident),+) => {
        impl<$($o: Observer),+> Observer for ($($o,)+) {
            #[allow(non_snake_case)]
            fn accepted(&mut self, step: &StepView<'_>) -> Result<Flow> {
                let ($($o,)+) = self;
                let mut flow = Flow::Continue;
                $(
                    if $o.accepted(step)? == Flow::Stop {
                        flow = Flow::Stop;
                    }
                )+
                Ok(flow)
            }
        }
    };
}
tuple_observer!(A);
tuple_observer!(A, B);
tuple_observer!(A, B, C);
tuple_observer!(A, B, C, E);

/// Steps `it` until its end time, or until its time reaches `until` when given, or until an
/// observer stops the run or fails. The stepper's errors become the crate's through `ode_error`
/// (for example with the context of the run).
///
/// An observer's stop takes precedence over the end time when both come on one step.
///
/// # Errors
/// The first error of the stepper (through `ode_error`) or of an observer.
pub fn run<D: Dim, O: Observer>(
    it: &mut Integrator<'static, D, SliderSystem>,
    until: Option<f64>,
    observer: &mut O,
    ode_error: impl Fn(OdeError) -> Error,
) -> Result<Ended>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    loop {
        if until.is_some_and(|t1| it.t() >= t1) {
            return Ok(Ended::Time);
        }
        let status = it.step().map_err(&ode_error)?;
        let flow = observer.accepted(&StepView {
            t: it.t(),
            state: it.state().as_slice(),
            status,
            error: it.last_error(),
            stats: it.stats(),
            last_step: it.last_step(),
            system: it.system(),
        })?;
        if flow == Flow::Stop {
            return Ok(Ended::Stopped);
        }
        if status == StepStatus::ReachedEnd {
            return Ok(Ended::End);
        }
    }
}
