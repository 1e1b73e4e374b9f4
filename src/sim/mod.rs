//! The one simulation path: a [`Problem`] built from a model plus its inputs owns the
//! tolerances, the method choice, the integrator's options and the fixed-size state dispatch;
//! the cycle, the linear response and the drive all start their integrations from one.
//!
//! `sim` joins the physics ([`crate::model`]) and the stepper ([`crate::ode`]), which know
//! nothing of each other.

mod run;

pub use run::{run, Ended, Flow, Observer, StepView};

use crate::error::{Error, FailureKind, Result, Stage};
use crate::model::{Inputs, Rest, SliderModel, SliderSystem};
use crate::ode::{Integrator, Method, OdeError, Options, SaveAt, Solution};
use nalgebra::{
    allocator::Allocator, DefaultAllocator, Dim, DimName, OVector, U10, U11, U3, U4, U5, U6, U7,
    U8, U9,
};
use std::sync::Arc;

/// Above this many explicit steps over a run, `Auto` starts with its stiff method
/// ([`Method::for_problem`]): the explicit phase would only spend steps finding out.
pub const EXPLICIT_STEPS_FOR_STIFF: f64 = 1e5;

/// The slider of a model under its inputs, with everything its integration needs: the
/// tolerances of each state, the method and the options. Built by [`Problem::builder`].
///
/// ```no_run
/// use hdi_tribology::{heater::Programme, model::SliderModel, ode::Method, scene::Scene, sim::Problem};
/// let model = SliderModel::from_scene(&Scene::paper())?;
/// let inputs = model.inputs(Programme::constant(0.06, 1e-3)?);
/// let problem = Problem::builder(&model, inputs, false)
///     .rtol(1e-6)
///     .tolerances(1e-14, 0.0, 0.0)
///     .method_for_span(Method::Auto, 1e-3)
///     .build()?;
/// assert_eq!(problem.options().rtol, 1e-6);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct Problem {
    system: SliderSystem,
    method: Method,
    options: Options,
}

/// Builds a [`Problem`] ([`Problem::builder`]).
#[derive(Clone, Debug)]
pub struct ProblemBuilder {
    system: SliderSystem,
    options: Options,
    method: Method,
    span: Option<f64>,
}

impl Problem {
    /// A builder for the slider of `model` under `inputs`; `integrals` adds the contact impulse
    /// and heat states. The model is shared, not rebuilt.
    pub fn builder(model: &SliderModel, inputs: Inputs, integrals: bool) -> ProblemBuilder {
        ProblemBuilder::of(SliderSystem::new(model, inputs, integrals))
    }

    /// [`Problem::builder`] on a model already shared.
    pub fn shared(model: Arc<SliderModel>, inputs: Inputs, integrals: bool) -> ProblemBuilder {
        ProblemBuilder::of(SliderSystem::shared(model, inputs, integrals))
    }

    /// The system.
    pub fn system(&self) -> &SliderSystem {
        &self.system
    }

    /// The method, resolved ([`ProblemBuilder::method_for_span`]).
    pub fn method(&self) -> Method {
        self.method
    }

    /// The integrator's options.
    pub fn options(&self) -> &Options {
        &self.options
    }

    /// The state at rest at `rest` ([`SliderSystem::initial_state`]), on this problem's layout.
    pub fn initial_state<D: Dim>(&self, dim: D, rest: &Rest) -> OVector<f64, D>
    where
        DefaultAllocator: Allocator<D>,
    {
        self.system.initial_state(dim, rest)
    }

    /// A steppable integrator from `(t0, y0)` towards `tf`.
    ///
    /// # Errors
    /// The integrator's own set-up errors.
    pub fn integrator<D: Dim>(
        self,
        t0: f64,
        y0: OVector<f64, D>,
        tf: f64,
    ) -> std::result::Result<Integrator<'static, D, SliderSystem>, OdeError>
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        Integrator::new(self.system, t0, y0, tf, self.method, &self.options)
    }

    /// Integrates from `(t0, y0)` to `tf` in one call, saving as the options say.
    ///
    /// # Errors
    /// The stepper's errors.
    pub fn solve<D: Dim>(
        &self,
        t0: f64,
        y0: OVector<f64, D>,
        tf: f64,
    ) -> std::result::Result<Solution<D>, OdeError>
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        crate::ode::solve(
            &self.system,
            t0,
            y0,
            tf,
            self.method,
            &self.options,
            &mut [],
        )
    }

    /// Replaces the inputs the problem starts with.
    pub fn set_inputs(&mut self, inputs: Inputs) {
        self.system.set_inputs(inputs);
    }

    /// A [`SizedIntegrator`] at rest at `rest` at time `t0`, towards `tf`; `prepare` sees the
    /// initial state first.
    ///
    /// # Errors
    /// A layout of another size than 4 to 11 (named by `stage`); the integrator's set-up errors.
    pub fn start(
        self,
        stage: Stage,
        t0: f64,
        rest: &Rest,
        tf: f64,
        mut prepare: impl FnMut(&[f64]),
    ) -> Result<SizedIntegrator> {
        macro_rules! start {
            ($variant:ident, $dim:expr) => {{
                let y0 = self.initial_state($dim, rest);
                prepare(y0.as_slice());
                SizedIntegrator::$variant(self.integrator(t0, y0, tf)?)
            }};
        }
        Ok(match self.system.layout().len() {
            4 => start!(S4, U4),
            5 => start!(S5, U5),
            6 => start!(S6, U6),
            7 => start!(S7, U7),
            8 => start!(S8, U8),
            9 => start!(S9, U9),
            10 => start!(S10, U10),
            11 => start!(S11, U11),
            n => return Err(Self::no_size(stage, n)),
        })
    }

    fn no_size(stage: Stage, n: usize) -> Error {
        NoFixedSize { stage, states: n }.into()
    }

    /// Runs `job` on a state vector sized at compile time for this problem's layout (3 to 11
    /// states), so that a step allocates nothing; `stage` names the analysis in the error for
    /// any other size.
    ///
    /// # Errors
    /// A layout of another size; the job's own errors.
    pub fn dispatch<J: SizedRun>(self, stage: Stage, job: J) -> Result<J::Output> {
        match self.system.layout().len() {
            3 => job.run::<U3>(self),
            4 => job.run::<U4>(self),
            5 => job.run::<U5>(self),
            6 => job.run::<U6>(self),
            7 => job.run::<U7>(self),
            8 => job.run::<U8>(self),
            9 => job.run::<U9>(self),
            10 => job.run::<U10>(self),
            11 => job.run::<U11>(self),
            n => Err(Self::no_size(stage, n)),
        }
    }
}

/// A state size with no compile-time-sized integrator: a bug (every layout a scene can have is
/// covered), not a property of the scene.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("internal error: no fixed-size state of {states} components")]
pub struct NoFixedSize {
    /// The analysis that asked.
    pub stage: Stage,
    /// The state's size.
    pub states: usize,
}

impl FailureKind for NoFixedSize {
    fn stage(&self) -> Stage {
        self.stage
    }

    fn name(&self) -> &'static str {
        "Internal"
    }
}

/// A steppable integrator kept beyond one call (the drive keeps one for its whole life), on a
/// state sized at compile time for the layouts a scene can have ([`Problem::start`]).
// Built once and never moved per step: the size difference of the variants costs nothing.
#[allow(clippy::large_enum_variant, missing_docs)]
pub enum SizedIntegrator {
    S4(Integrator<'static, U4, SliderSystem>),
    S5(Integrator<'static, U5, SliderSystem>),
    S6(Integrator<'static, U6, SliderSystem>),
    S7(Integrator<'static, U7, SliderSystem>),
    S8(Integrator<'static, U8, SliderSystem>),
    S9(Integrator<'static, U9, SliderSystem>),
    S10(Integrator<'static, U10, SliderSystem>),
    S11(Integrator<'static, U11, SliderSystem>),
}

/// `with_sized!(integrator, it => body)`: runs `body` with `it` the integrator inside a
/// [`SizedIntegrator`] (by value, reference or mutable reference, as given).
macro_rules! with_sized {
    ($integ:expr, $it:ident => $body:expr) => {
        match $integ {
            $crate::sim::SizedIntegrator::S4($it) => $body,
            $crate::sim::SizedIntegrator::S5($it) => $body,
            $crate::sim::SizedIntegrator::S6($it) => $body,
            $crate::sim::SizedIntegrator::S7($it) => $body,
            $crate::sim::SizedIntegrator::S8($it) => $body,
            $crate::sim::SizedIntegrator::S9($it) => $body,
            $crate::sim::SizedIntegrator::S10($it) => $body,
            $crate::sim::SizedIntegrator::S11($it) => $body,
        }
    };
}
pub(crate) use with_sized;

/// Work on a [`Problem`] with a state of a size known at compile time
/// ([`Problem::dispatch`]).
pub trait SizedRun {
    /// What the work gives.
    type Output;
    /// Does the work on a state of `D` components.
    ///
    /// # Errors
    /// The work's own.
    fn run<D: DimName>(self, problem: Problem) -> Result<Self::Output>
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>;
}

impl ProblemBuilder {
    fn of(system: SliderSystem) -> Self {
        ProblemBuilder {
            system,
            options: Options::default(),
            method: Method::Auto,
            span: None,
        }
    }

    /// The system the problem will hold.
    pub fn system(&self) -> &SliderSystem {
        &self.system
    }

    /// Leaves the heat integral out of the state ([`SliderSystem::without_heat`]), and its
    /// tolerance where [`ProblemBuilder::tolerances`] already set one per state.
    ///
    /// ```
    /// use hdi_tribology::{heater::Programme, model::SliderModel, scene::Scene, sim::Problem};
    /// let model = SliderModel::from_scene(&Scene::paper())?;
    /// let inputs = model.inputs(Programme::constant(0.06, 1e-3)?);
    /// let problem = Problem::builder(&model, inputs, true)
    ///     .tolerances(1e-14, 1e-12, 1e-10)
    ///     .without_heat()
    ///     .build()?;
    /// assert_eq!((problem.system().layout().len(), problem.system().layout().heat), (3, None));
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn without_heat(mut self) -> Self {
        if let (Some(i), crate::ode::Tolerance::PerComponent(atol)) =
            (self.system.layout().heat, &mut self.options.atol)
        {
            if atol.len() == self.system.layout().len() {
                atol.remove(i);
            }
        }
        self.system = self.system.without_heat();
        self
    }

    /// Relative tolerance.
    pub fn rtol(mut self, rtol: f64) -> Self {
        self.options = self.options.rtol(rtol);
        self
    }

    /// Absolute tolerances of every state for a displacement tolerance `displacement` (m), an
    /// impulse tolerance (N s) and a heat tolerance (K s) ([`SliderSystem::tolerances`]).
    pub fn tolerances(mut self, displacement: f64, impulse: f64, heat: f64) -> Self {
        let atol = self.system.tolerances(displacement, impulse, heat);
        self.options = self.options.atol_per_component(atol);
        self
    }

    /// The largest step under the inputs' voltage: `given`, else a fortieth of the AC period
    /// ([`crate::model::Voltage::max_step`]).
    pub fn max_step(mut self, given: Option<f64>) -> Self {
        self.options = self.options.h_max(self.system.max_step(given));
        self
    }

    /// The largest step as given (s), whatever the voltage (for runs whose voltage changes).
    pub fn h_max(mut self, h: f64) -> Self {
        self.options = self.options.h_max(h);
        self
    }

    /// The most steps of one integration.
    pub fn max_steps(mut self, n: usize) -> Self {
        self.options = self.options.max_steps(n);
        self
    }

    /// Times the steps must land on (kinks of the inputs).
    pub fn stops(mut self, t: Vec<f64>) -> Self {
        self.options = self.options.t_stops(t);
        self
    }

    /// Keep each step's interpolant (for reading states between steps).
    pub fn dense(mut self) -> Self {
        self.options = self.options.dense(true);
        self
    }

    /// What a one-call [`Problem::solve`] keeps.
    pub fn save(mut self, save: SaveAt) -> Self {
        self.options = self.options.save(save);
        self
    }

    /// The method, as given.
    pub fn method(mut self, method: Method) -> Self {
        self.method = method;
        self.span = None;
        self
    }

    /// The method for a run over `span` (s): as given, except that `Auto` starts stiff on a
    /// slider whose fastest rate no explicit step can follow ([`Method::for_problem`],
    /// [`EXPLICIT_STEPS_FOR_STIFF`]).
    pub fn method_for_span(mut self, method: Method, span: f64) -> Self {
        self.method = method;
        self.span = Some(span);
        self
    }

    /// The problem.
    ///
    /// # Errors
    /// Options that do not fit the layout (named `solver`).
    pub fn build(self) -> Result<Problem> {
        let n = self.system.layout().len();
        self.options
            .validate(n)
            .map_err(|e| Error::invalid("solver", e.to_string()))?;
        let method = match self.span {
            Some(span) => self.method.for_problem(
                self.options.rtol,
                self.system.model().fastest_rate(),
                span,
                EXPLICIT_STEPS_FOR_STIFF,
            ),
            None => self.method,
        };
        Ok(Problem {
            system: self.system,
            method,
            options: self.options,
        })
    }
}
