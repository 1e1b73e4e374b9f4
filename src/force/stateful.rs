//! Interface terms with a memory: terms that carry states of their own (a meniscus population, a
//! lubricant pick-up) on top of the slider's coordinates, with their rate laws.
//!
//! A [`StatefulTerm`] declares how many states it has, their equilibrium at given gaps, their
//! rates and the force they add. The model appends the states of its terms to the state of every
//! simulation ([`crate::model::StateLayout::term_states`]), and the static analyses take the
//! equilibrium: no analysis needs an edit of its own for a new term.

use super::{ForceEval, Gaps};
use crate::error::{check_finite, check_positive};
use crate::Result;
use std::fmt::Debug;

/// The most states all the stateful terms of one model may add together.
pub const MAX_TERM_STATES: usize = 4;

/// The derivatives of a term's rates `ẋ_i` at one point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RatePartials {
    /// `∂ẋ_i/∂d_bulge` (per m).
    pub d_bulge: [f64; MAX_TERM_STATES],
    /// `∂ẋ_i/∂d_pad` (per m).
    pub d_pad: [f64; MAX_TERM_STATES],
    /// `∂ẋ_i/∂x_j`, row `i`, column `j`.
    pub d_state: [[f64; MAX_TERM_STATES]; MAX_TERM_STATES],
}

/// A branch of a rate law with two ([`StatefulTerm::switching`]): where the switching function
/// is non-negative (`Upper`) or negative (`Lower`).
///
/// ```
/// use hdi_tribology::force::Branch;
/// assert_eq!((Branch::of(0.0), Branch::of(-1e-30)), (Branch::Upper, Branch::Lower));
/// assert_eq!(Branch::of_flag(Branch::Lower.flag()), Branch::Lower);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Branch {
    /// The switching function is non-negative.
    Upper,
    /// The switching function is negative.
    Lower,
}

impl Branch {
    /// The branch where the switching function has the value `s`.
    pub fn of(s: f64) -> Self {
        if s < 0.0 {
            Branch::Lower
        } else {
            Branch::Upper
        }
    }

    /// The branch as a simulation holds it in its state: +1 (`Upper`) or −1 (`Lower`).
    pub fn flag(self) -> f64 {
        match self {
            Branch::Upper => 1.0,
            Branch::Lower => -1.0,
        }
    }

    /// The branch of a held flag ([`Branch::flag`]).
    pub fn of_flag(flag: f64) -> Self {
        if flag < 0.0 {
            Branch::Lower
        } else {
            Branch::Upper
        }
    }
}

/// A term's force (N, positive = away from the disk, acting where the interface force acts) with
/// its partial derivatives along the gaps and along its own states.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StateForce {
    /// Value and gap derivatives at fixed state.
    pub force: ForceEval,
    /// `∂F/∂x_j` (N per unit of state `j`).
    pub d_state: [f64; MAX_TERM_STATES],
}

/// An interface term with states of its own, `ẋ = r(d, x)`, and a force `F(d, x)`.
///
/// The slices hold the term's own states only (`states()` of them).
///
/// ```
/// use hdi_tribology::force::{Gaps, RelaxingState, StatefulTerm};
/// let t = RelaxingState::new(1e-6, 1e6, -1e-3, None)?; // x → 1e6 d with τ = 1 µs
/// let g = Gaps::same(2e-9);
/// let mut x = [0.0];
/// t.equilibrium(g, &mut x);
/// let mut dx = [1.0];
/// t.rates(g, &x, &mut dx);
/// assert!((x[0] - 2e-3).abs() < 1e-18 && dx[0].abs() < 1e-12);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub trait StatefulTerm: Debug + Send + Sync {
    /// A short name for reports and errors.
    fn name(&self) -> &str;
    /// How many states (at most [`MAX_TERM_STATES`] over all terms of a model).
    fn states(&self) -> usize;
    /// The states at rest at gaps `g` (what the static analyses take).
    fn equilibrium(&self, g: Gaps, x: &mut [f64]);
    /// The states a dynamic run starts from, at rest at gaps `g`; by default the equilibrium.
    fn initial(&self, g: Gaps, x: &mut [f64]) {
        self.equilibrium(g, x)
    }
    /// The rates `ẋ` at gaps `g` and states `x`.
    fn rates(&self, g: Gaps, x: &[f64], dx: &mut [f64]);
    /// The derivatives of the rates at gaps `g` and states `x`.
    fn rate_partials(&self, g: Gaps, x: &[f64]) -> RatePartials;
    /// The force at gaps `g` and states `x`, with its derivatives.
    fn force(&self, g: Gaps, x: &[f64]) -> StateForce;
    /// The value of [`StatefulTerm::force`] alone (the same number), for the right-hand side;
    /// by default through `force`.
    fn force_value(&self, g: Gaps, x: &[f64]) -> f64 {
        self.force(g, x).force.value
    }
    /// The absolute accuracy each state needs when displacements are integrated to
    /// `displacement` (m).
    fn tolerances(&self, displacement: f64, atol: &mut [f64]);
    /// Whether the force at rest (the force at the [`StatefulTerm::equilibrium`] states) depends
    /// on the bulge gap alone, never on the pad gap: the static balance, which holds the bulge
    /// gap, then evaluates it once per balance instead of once per Newton step. False by
    /// default (a term that says true and sees the pad gap would get a wrong balance).
    fn rests_on_bulge_gap(&self) -> bool {
        false
    }
    /// Whether every rate of the term, on each branch, is affine in the term's state of its own
    /// row, with a slope constant on the branch (the diagonal of
    /// [`StatefulTerm::rate_partials_on`]), and free of the term's other states:
    /// `ẋ_i = a_i(d) + b_i x_i`. The simulations may then step the term's states implicitly, row
    /// by row, where a branch is fast (`ode::OdeSystem::stiff_diagonal`). False by default (a
    /// term that says true and is not would be integrated wrongly).
    fn rates_diagonal_affine(&self) -> bool {
        false
    }
    /// Whether the rate law has two smooth branches split by the sign of
    /// [`StatefulTerm::switching`]: false by default. The simulations then hold the branch in
    /// their state, integrate [`StatefulTerm::rates_on`] over each step and change branch at
    /// the located root (`ode::OdeSystem::switches`), so no step crosses the law's kink; the
    /// static analyses read [`StatefulTerm::rates`], which picks the branch by the sign.
    fn switches(&self) -> bool {
        false
    }
    /// The switching function at gaps `g` and states `x` (its sign picks the branch; a length
    /// or any other unit). Called only when [`StatefulTerm::switches`] says so.
    fn switching(&self, _g: Gaps, _x: &[f64]) -> f64 {
        0.0
    }
    /// The rates of `branch`'s law, continued smoothly past the switch; by default
    /// [`StatefulTerm::rates`].
    fn rates_on(&self, _branch: Branch, g: Gaps, x: &[f64], dx: &mut [f64]) {
        self.rates(g, x, dx)
    }
    /// The fastest rate (1/s) of `branch`'s law, where the term knows it (`None` by default):
    /// an explicit method starts the branch within its stability bound.
    fn fastest_rate_on(&self, _branch: Branch) -> Option<f64> {
        None
    }
    /// The derivatives of [`StatefulTerm::rates_on`]; by default [`StatefulTerm::rate_partials`].
    fn rate_partials_on(&self, _branch: Branch, g: Gaps, x: &[f64]) -> RatePartials {
        self.rate_partials(g, x)
    }
    /// The switching function the simulations watch while they hold `branch`, at the gaps
    /// `gaps()` and their rates (m/s) `rate()` (each computed when called: a term asks for what
    /// it reads); by default [`StatefulTerm::switching`]. Its sign picks the branch as that of
    /// `switching` does: a branch may end on a condition of its own (a gap that stops closing),
    /// not only on the sign of `switching`.
    fn switching_on(
        &self,
        _branch: Branch,
        gaps: &dyn Fn() -> Gaps,
        _rate: &dyn Fn() -> Gaps,
        x: &[f64],
    ) -> f64 {
        self.switching(gaps(), x)
    }
    /// The force while the simulations hold `branch`; by default [`StatefulTerm::force`].
    fn force_on(&self, _branch: Branch, g: Gaps, x: &[f64]) -> StateForce {
        self.force(g, x)
    }
    /// The value of [`StatefulTerm::force_on`] alone (the same number); by default
    /// [`StatefulTerm::force_value`].
    fn force_value_on(&self, _branch: Branch, g: Gaps, x: &[f64]) -> f64 {
        self.force_value(g, x)
    }
    /// Called when a simulation switches into `branch` at gaps `g`: the term may set its states
    /// there (nothing by default). The force must be continuous across the switch.
    fn enter(&self, _branch: Branch, _g: Gaps, _x: &mut [f64]) {}
    /// [`StatefulTerm::rates_on`] into `dx` and the value of [`StatefulTerm::force_value_on`]
    /// (the same numbers) in one call, for the right-hand side; by default the two calls.
    fn rates_and_force_value_on(&self, branch: Branch, g: Gaps, x: &[f64], dx: &mut [f64]) -> f64 {
        self.rates_on(branch, g, x, dx);
        self.force_value_on(branch, g, x)
    }
}

/// One first-order state that relaxes towards a target proportional to the bulge gap,
/// `τ ẋ = a d − x`, and adds the force `F = k x`.
///
/// Its closed forms make it the check of the state-carrying machinery: with `a = 0` and
/// `k = 0` ([`RelaxingState::relaxation`]) it decays as `x(t) = x₀ e^{−(t−t₀)/τ}` and changes
/// nothing else; with `a, k ≠ 0` it is a lagged spring on the gap (at equilibrium `F = k a d`).
///
/// ```
/// use hdi_tribology::force::{Gaps, RelaxingState, StatefulTerm};
/// let r = RelaxingState::relaxation(2e-4, 1.0)?;
/// let mut x = [0.0];
/// r.initial(Gaps::same(5e-9), &mut x);
/// let mut dx = [0.0];
/// r.rates(Gaps::same(5e-9), &x, &mut dx);
/// assert_eq!((x[0], dx[0]), (1.0, -1.0 / 2e-4));
/// assert!(RelaxingState::relaxation(0.0, 1.0).is_err());
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RelaxingState {
    tau: f64,
    target_per_gap: f64,
    force_per_state: f64,
    start: Option<f64>,
}

impl RelaxingState {
    /// Time constant `tau` (s, > 0), target per metre of bulge gap `a`, force per unit of state
    /// `k` (N), and the state a run starts from (`None`: the equilibrium `a d`).
    pub fn new(
        tau: f64,
        target_per_gap: f64,
        force_per_state: f64,
        start: Option<f64>,
    ) -> Result<Self> {
        check_positive("relaxing_state.tau_s", tau)?;
        check_finite("relaxing_state.target_per_m", target_per_gap)?;
        check_finite("relaxing_state.force_n", force_per_state)?;
        if let Some(x0) = start {
            check_finite("relaxing_state.start", x0)?;
        }
        Ok(RelaxingState {
            tau,
            target_per_gap,
            force_per_state,
            start,
        })
    }

    /// A pure relaxation from `start` towards 0 with time constant `tau` (s), with no force.
    pub fn relaxation(tau: f64, start: f64) -> Result<Self> {
        Self::new(tau, 0.0, 0.0, Some(start))
    }

    /// The time constant (s).
    pub fn tau(&self) -> f64 {
        self.tau
    }
}

impl StatefulTerm for RelaxingState {
    fn name(&self) -> &str {
        "relaxing state"
    }
    fn states(&self) -> usize {
        1
    }
    fn equilibrium(&self, g: Gaps, x: &mut [f64]) {
        x[0] = self.target_per_gap * g.bulge;
    }
    fn initial(&self, g: Gaps, x: &mut [f64]) {
        match self.start {
            Some(x0) => x[0] = x0,
            None => self.equilibrium(g, x),
        }
    }
    fn rates(&self, g: Gaps, x: &[f64], dx: &mut [f64]) {
        dx[0] = (self.target_per_gap * g.bulge - x[0]) / self.tau;
    }
    fn rate_partials(&self, _g: Gaps, _x: &[f64]) -> RatePartials {
        let mut p = RatePartials::default();
        p.d_bulge[0] = self.target_per_gap / self.tau;
        p.d_state[0][0] = -1.0 / self.tau;
        p
    }
    /// The state's scale per metre of gap: `|a|`, or `|x₀|` per nanometre when larger.
    fn tolerances(&self, displacement: f64, atol: &mut [f64]) {
        let per_m = self
            .target_per_gap
            .abs()
            .max(self.start.map_or(0.0, |x0| x0.abs() / 1e-9));
        atol[0] = displacement * per_m.max(f64::MIN_POSITIVE);
    }
    /// The equilibrium `a d` and the force `k x` see the bulge gap alone.
    fn rests_on_bulge_gap(&self) -> bool {
        true
    }
    /// `ẋ = (a d − x)/τ`.
    fn rates_diagonal_affine(&self) -> bool {
        true
    }
    fn force(&self, _g: Gaps, x: &[f64]) -> StateForce {
        let mut d_state = [0.0; MAX_TERM_STATES];
        d_state[0] = self.force_per_state;
        StateForce {
            force: ForceEval {
                value: self.force_per_state * x[0],
                d_bulge: 0.0,
                d_pad: 0.0,
            },
            d_state,
        }
    }
}
