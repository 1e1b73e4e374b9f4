//! The problem side: the [`OdeSystem`] trait, a closure adapter and Jacobian helpers.

use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OMatrix, OVector};
use num_complex::Complex64;

/// A first-order system `y' = f(t, y)` with state in a nalgebra vector of dimension `D`.
///
/// Only [`rhs`](OdeSystem::rhs) is required. Stiff methods use
/// [`jacobian`](OdeSystem::jacobian) when it returns `true` and finite differences otherwise;
/// Rosenbrock methods also use [`time_derivative`](OdeSystem::time_derivative), or nothing
/// when the system declares itself [autonomous](OdeSystem::is_autonomous). They ask for the two
/// together through [`jacobian_and_time_derivative`](OdeSystem::jacobian_and_time_derivative),
/// which calls both unless a system overrides it to share their work.
///
/// ```
/// use hdi_tribology::ode::OdeSystem;
/// use nalgebra::{Matrix2, U2, Vector2};
/// /// Harmonic oscillator y'' = -y.
/// struct Oscillator;
/// impl OdeSystem<U2> for Oscillator {
///     fn rhs(&self, _t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
///         dy[0] = y[1];
///         dy[1] = -y[0];
///     }
///     fn jacobian(&self, _t: f64, _y: &Vector2<f64>, j: &mut Matrix2<f64>) -> bool {
///         *j = Matrix2::new(0.0, 1.0, -1.0, 0.0);
///         true
///     }
/// }
/// let mut dy = Vector2::zeros();
/// Oscillator.rhs(0.0, &Vector2::new(1.0, 0.0), &mut dy);
/// assert_eq!(dy, Vector2::new(0.0, -1.0));
/// ```
pub trait OdeSystem<D: Dim>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// Writes `f(t, y)` into `dydt`.
    fn rhs(&self, t: f64, y: &OVector<f64, D>, dydt: &mut OVector<f64, D>);

    /// Analytic Jacobian `∂f/∂y` into `jac`; return `false` (the default) to ask for finite
    /// differences.
    fn jacobian(&self, _t: f64, _y: &OVector<f64, D>, _jac: &mut OMatrix<f64, D, D>) -> bool {
        false
    }

    /// `∂f/∂t` into `dfdt` for non-autonomous systems; return `false` (the default) to ask for a
    /// finite difference. Autonomous systems may return `true` after writing zeros.
    fn time_derivative(&self, _t: f64, _y: &OVector<f64, D>, _dfdt: &mut OVector<f64, D>) -> bool {
        false
    }

    /// `true` when `f` does not depend on `t`: `∂f/∂t` is then taken as zero without calling
    /// [`time_derivative`](OdeSystem::time_derivative). `false` by default.
    fn is_autonomous(&self) -> bool {
        false
    }

    /// `∂f/∂y` into `jac` and `∂f/∂t` into `dfdt` at one point, for the methods that need both
    /// at every step (Rodas5P on a non-autonomous system). Returns whether each was written, as
    /// [`jacobian`](OdeSystem::jacobian) and [`time_derivative`](OdeSystem::time_derivative) do
    /// (`false`: finite differences); by default it calls the two in turn. Override it when the
    /// two share work, such as one evaluation of the forces at `(t, y)`.
    ///
    /// ```
    /// use hdi_tribology::ode::OdeSystem;
    /// use nalgebra::{Matrix1, U1, Vector1};
    /// /// y' = -k(t) y with k(t) = 1 + t: the two share k.
    /// struct Decay;
    /// impl OdeSystem<U1> for Decay {
    ///     fn rhs(&self, t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>) {
    ///         dy[0] = -(1.0 + t) * y[0];
    ///     }
    ///     fn jacobian_and_time_derivative(
    ///         &self, t: f64, y: &Vector1<f64>, j: &mut Matrix1<f64>, dfdt: &mut Vector1<f64>,
    ///     ) -> (bool, bool) {
    ///         let k = 1.0 + t;
    ///         j[0] = -k;
    ///         dfdt[0] = -y[0];
    ///         (true, true)
    ///     }
    /// }
    /// let (mut j, mut d) = (Matrix1::zeros(), Vector1::zeros());
    /// assert_eq!(Decay.jacobian_and_time_derivative(1.0, &Vector1::new(2.0), &mut j, &mut d), (true, true));
    /// assert_eq!((j[0], d[0]), (-2.0, -2.0));
    /// ```
    fn jacobian_and_time_derivative(
        &self,
        t: f64,
        y: &OVector<f64, D>,
        jac: &mut OMatrix<f64, D, D>,
        dfdt: &mut OVector<f64, D>,
    ) -> (bool, bool) {
        (self.jacobian(t, y, jac), self.time_derivative(t, y, dfdt))
    }

    /// How many switching functions the system has; none by default.
    ///
    /// A right-hand side whose law changes where some function of the state changes sign has a
    /// kink there, and an adaptive method passes a kink only by cutting its step down and
    /// building it up again. A system can spare it that: it holds the branch it is on in its
    /// own state, continues each branch's law smoothly past the switch, and names its switching
    /// functions here. The integrator then locates each root on the step's interpolant, ends
    /// the step there, lets the system change branch ([`switch`](OdeSystem::switch)) and
    /// restarts the method: no step crosses the kink. [`Stats::branch_switches`] counts the
    /// switches.
    ///
    /// A relaxation `ẋ = (u(t) − x)/τ` that follows a rising target with `τ = 0.1` and a
    /// falling one with `τ = 2`, the branch held in `y[1]` (+1: following, −1: lagging):
    ///
    /// ```
    /// use hdi_tribology::ode::{solve, Method, OdeSystem, Options};
    /// use nalgebra::{Vector2, U2};
    /// struct Follower;
    /// impl OdeSystem<U2> for Follower {
    ///     fn rhs(&self, t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
    ///         let tau = if y[1] > 0.0 { 0.1 } else { 2.0 };
    ///         dy[0] = (t.sin() - y[0]) / tau;
    ///         dy[1] = 0.0;
    ///     }
    ///     fn switches(&self) -> usize {
    ///         1
    ///     }
    ///     // Following while the target is above the state, lagging while it is below.
    ///     fn switching(&self, _i: usize, t: f64, y: &Vector2<f64>) -> f64 {
    ///         y[1] * (t.sin() - y[0])
    ///     }
    ///     fn switch(&self, _i: usize, _t: f64, y: &mut Vector2<f64>) {
    ///         y[1] = -y[1];
    ///     }
    ///     // The rate of the held branch's law, 1/τ.
    ///     fn branch_rate(&self, _i: usize, y: &Vector2<f64>) -> Option<f64> {
    ///         Some(if y[1] > 0.0 { 10.0 } else { 0.5 })
    ///     }
    /// }
    /// let opts = Options::default().rtol(1e-8).atol(1e-10);
    /// let sol = solve(&Follower, 0.0, Vector2::new(0.0, 1.0), 20.0, Method::Tsit5, &opts, &mut [])?;
    /// // The state turns with the target: the branch changes twice per period of sin t.
    /// assert!(sol.stats.branch_switches >= 5, "{:?}", sol.stats);
    /// # Ok::<(), hdi_tribology::ode::OdeError>(())
    /// ```
    ///
    /// [`Stats::branch_switches`]: super::Stats::branch_switches
    fn switches(&self) -> usize {
        0
    }

    /// Switching function `i` at `(t, y)`: non-negative while the branch held in `y` is the
    /// right one, negative past its switch. Called only for `i < switches()`.
    ///
    /// The root is located on the step's interpolant, so its time is only as good as the
    /// state's error over the function's slope there. A function that stays within the
    /// integration error of zero along its branch switches at a time that error sets: a state
    /// relaxing towards a moving target `u(t)` with a time `τ` far below the step, switched by
    /// the sign of `u − x ≈ τ u̇`, ends its branch where that sign is lost in the error, about
    /// `error/(τ |ü|)` from the true root (measured: `x′ = (sin t − x)/τ`, τ = 1e-4 while the
    /// target falls below `x` and 1 otherwise, Rodas5P at rtol 1e-6 ended the fast branch up
    /// to 0.04 from the target's minimum, and `x(120)` was 1e-4 off; at rtol 1e-8, 5e-9).
    fn switching(&self, _i: usize, _t: f64, _y: &OVector<f64, D>) -> f64 {
        0.0
    }

    /// Changes the branch of switch `i` held in `y`, at the switch's root `t` (after it, the
    /// switching function is non-negative again). Called only for `i < switches()`.
    fn switch(&self, _i: usize, _t: f64, _y: &mut OVector<f64, D>) {}

    /// The fastest rate (1/s) of the law on the branch of switch `i` held in `y`, where the
    /// system knows it (`None` by default). An explicit method starts a branch, at the start of
    /// the integration and after each switch, with a step within its stability bound for that
    /// rate, instead of finding the bound by failed steps. Called only for `i < switches()`.
    fn branch_rate(&self, _i: usize, _y: &OVector<f64, D>) -> Option<f64> {
        None
    }

    /// The stiff rows and their slopes, written into `lambda`: `Λ_i = ∂f_i/∂y_i` (1/s) for a
    /// stiff row `i`, 0 for the others; `false` (the default) where the system declares none.
    /// A declared row must be affine in its own state, with that slope, and must not depend on
    /// the other declared rows (a fast relaxation `ẏ_i = Λ_i (y_i − u)` towards a target `u` of
    /// the other states).
    ///
    /// `Auto` reads it where a switch enters a branch whose [`branch_rate`] would hold its
    /// explicit step far below the coming one: with a declaration it steps the declared rows
    /// implicitly and the others explicitly (the additive pair ARK4(3)6L\[2\]SA of Kennedy and
    /// Carpenter), at about the cost of an explicit step, instead of handing the branch to its
    /// stiff method. It is read at each step's start and held over the step.
    ///
    /// The relaxation of [`switches`] with a fast branch (`τ = 1e-5`), declared:
    ///
    /// ```
    /// use hdi_tribology::ode::{solve, Method, OdeSystem, Options};
    /// use nalgebra::{Vector2, U2};
    /// struct Follower;
    /// impl OdeSystem<U2> for Follower {
    ///     fn rhs(&self, t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
    ///         let tau = if y[1] > 0.0 { 1e-5 } else { 2.0 };
    ///         dy[0] = (t.sin() - y[0]) / tau;
    ///         dy[1] = 0.0;
    ///     }
    ///     fn switches(&self) -> usize {
    ///         1
    ///     }
    ///     fn switching(&self, _i: usize, t: f64, y: &Vector2<f64>) -> f64 {
    ///         y[1] * (t.sin() - y[0])
    ///     }
    ///     fn switch(&self, _i: usize, _t: f64, y: &mut Vector2<f64>) {
    ///         y[1] = -y[1];
    ///     }
    ///     fn branch_rate(&self, _i: usize, y: &Vector2<f64>) -> Option<f64> {
    ///         Some(if y[1] > 0.0 { 1e5 } else { 0.5 })
    ///     }
    ///     // The fast branch's relaxation is the stiff part: −1/τ on the first state.
    ///     fn stiff_diagonal(&self, _t: f64, y: &Vector2<f64>, lambda: &mut Vector2<f64>) -> bool {
    ///         *lambda = Vector2::new(if y[1] > 0.0 { -1e5 } else { 0.0 }, 0.0);
    ///         y[1] > 0.0
    ///     }
    /// }
    /// let opts = Options::default().rtol(1e-6).atol(1e-9);
    /// let sol = solve(&Follower, 0.0, Vector2::new(0.0, 1.0), 20.0, Method::Auto, &opts, &mut [])?;
    /// // No step at the explicit bound of the fast branch (3.3e-5): far fewer than 20/3.3e-5.
    /// assert!(sol.stats.accepted < 20_000, "{:?}", sol.stats);
    /// # Ok::<(), hdi_tribology::ode::OdeError>(())
    /// ```
    ///
    /// [`branch_rate`]: OdeSystem::branch_rate
    /// [`switches`]: OdeSystem::switches
    fn stiff_diagonal(&self, _t: f64, _y: &OVector<f64, D>, _lambda: &mut OVector<f64, D>) -> bool {
        false
    }

    /// The rates of the rows [`stiff_diagonal`](OdeSystem::stiff_diagonal) declares, at
    /// `(t, y)`, into `rates` (the other rows may hold anything). By default the whole
    /// right-hand side; a system whose stiff rows cost less alone says so here.
    fn stiff_rates(&self, t: f64, y: &OVector<f64, D>, rates: &mut OVector<f64, D>) {
        self.rhs(t, y, rates)
    }

    /// Writes `f(t, y)` into `dydt` as [`rhs`](OdeSystem::rhs) does, with `memo` holding
    /// values the system computed from the time alone on an earlier call. The methods call
    /// this one: several of their evaluations share a time (Rodas5P's last three stages and
    /// the next step's first all fall on `t + h`), and a system whose right-hand side has
    /// costly parts that depend on `t` alone (a sine, a table look-up) computes them once per
    /// time ([`TimeMemo::get_or_insert_with`]). The result must be the same, to the bit, as
    /// `rhs`'s. The integrator empties the memo whenever the method restarts: after the system
    /// is changed ([`Integrator::system_mut`](crate::ode::Integrator::system_mut)), an event
    /// acts, a branch switches, or a step ends at a kink. By default `rhs`.
    ///
    /// ```
    /// use hdi_tribology::nalgebra::{Vector1, U1};
    /// use hdi_tribology::ode::{OdeSystem, TimeMemo};
    /// /// y' = -y + sin t, with the sine kept per time.
    /// struct Forced;
    /// impl Forced {
    ///     fn rhs_with(&self, sin_t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>) {
    ///         dy[0] = -y[0] + sin_t;
    ///     }
    /// }
    /// impl OdeSystem<U1> for Forced {
    ///     fn rhs(&self, t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>) {
    ///         self.rhs_with(t.sin(), y, dy)
    ///     }
    ///     fn rhs_memo(&self, t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>, memo: &mut TimeMemo) {
    ///         let [sin_t, ..] = memo.get_or_insert_with(t, |t| [t.sin(), 0.0, 0.0, 0.0]);
    ///         self.rhs_with(sin_t, y, dy)
    ///     }
    /// }
    /// let (mut a, mut b, mut memo) = (Vector1::zeros(), Vector1::zeros(), TimeMemo::default());
    /// Forced.rhs(0.5, &Vector1::new(1.0), &mut a);
    /// Forced.rhs_memo(0.5, &Vector1::new(1.0), &mut b, &mut memo);
    /// Forced.rhs_memo(0.5, &Vector1::new(1.0), &mut b, &mut memo);
    /// assert_eq!(a, b);
    /// ```
    #[inline]
    fn rhs_memo(
        &self,
        t: f64,
        y: &OVector<f64, D>,
        dydt: &mut OVector<f64, D>,
        _memo: &mut TimeMemo,
    ) {
        self.rhs(t, y, dydt)
    }
}

/// Up to four values a system computed from the time alone, kept for the last time asked (see
/// [`OdeSystem::rhs_memo`]), keyed by the time's bits (so `-0.0` and `0.0` are two times, and a
/// NaN time is never confused with an empty memo). Empty at first.
#[derive(Clone, Copy, Debug)]
pub struct TimeMemo {
    /// The bits of the time of `values`; [`EMPTY`] when empty (a time with those bits, a NaN,
    /// is never kept).
    t: u64,
    values: [f64; 4],
}

/// The key of an empty [`TimeMemo`].
const EMPTY: u64 = u64::MAX;

impl Default for TimeMemo {
    fn default() -> Self {
        TimeMemo {
            t: EMPTY,
            values: [0.0; 4],
        }
    }
}

impl TimeMemo {
    /// The values kept for `t`, computed by `f(t)` and kept when the memo holds another time.
    ///
    /// ```
    /// use hdi_tribology::ode::TimeMemo;
    /// let mut memo = TimeMemo::default();
    /// let mut calls = 0;
    /// for _ in 0..3 {
    ///     memo.get_or_insert_with(2.0, |t| { calls += 1; [t * t, 0.0, 0.0, 0.0] });
    /// }
    /// assert_eq!((memo.get_or_insert_with(2.0, |_| [0.0; 4])[0], calls), (4.0, 1));
    /// // Another time, even one equal to it as a number, is computed afresh.
    /// assert_eq!(memo.get_or_insert_with(-0.0, |t| [1.0 / t, 0.0, 0.0, 0.0])[0], f64::NEG_INFINITY);
    /// assert!(memo.get_or_insert_with(0.0, |t| [1.0 / t, 0.0, 0.0, 0.0])[0] > 0.0);
    /// memo.clear();
    /// assert!(memo.get_or_insert_with(f64::NAN, |t| [t; 4])[0].is_nan());
    /// // Every NaN, whatever its bits, is computed afresh from an empty memo.
    /// memo.clear();
    /// let nan = f64::from_bits(u64::MAX);
    /// assert!(memo.get_or_insert_with(nan, |t| [t; 4])[0].is_nan());
    /// ```
    #[inline]
    pub fn get_or_insert_with(&mut self, t: f64, f: impl FnOnce(f64) -> [f64; 4]) -> [f64; 4] {
        let key = t.to_bits();
        if self.t != key || key == EMPTY {
            self.values = f(t);
            self.t = key;
        }
        self.values
    }

    /// Forgets the values (the system they came from changed).
    pub fn clear(&mut self) {
        self.t = EMPTY;
    }
}

/// Forwards every method of [`OdeSystem`] through a pointer type.
macro_rules! forward_system {
    ($(#[$doc:meta])* $ptr:ty) => {
        $(#[$doc])*
        impl<D: Dim, S: OdeSystem<D> + ?Sized> OdeSystem<D> for $ptr
        where
            DefaultAllocator: Allocator<D> + Allocator<D, D>,
        {
            #[inline]
            fn rhs(&self, t: f64, y: &OVector<f64, D>, dydt: &mut OVector<f64, D>) {
                (**self).rhs(t, y, dydt)
            }
            #[inline]
            fn jacobian(&self, t: f64, y: &OVector<f64, D>, jac: &mut OMatrix<f64, D, D>) -> bool {
                (**self).jacobian(t, y, jac)
            }
            #[inline]
            fn time_derivative(
                &self,
                t: f64,
                y: &OVector<f64, D>,
                dfdt: &mut OVector<f64, D>,
            ) -> bool {
                (**self).time_derivative(t, y, dfdt)
            }
            #[inline]
            fn is_autonomous(&self) -> bool {
                (**self).is_autonomous()
            }
            #[inline]
            fn jacobian_and_time_derivative(
                &self,
                t: f64,
                y: &OVector<f64, D>,
                jac: &mut OMatrix<f64, D, D>,
                dfdt: &mut OVector<f64, D>,
            ) -> (bool, bool) {
                (**self).jacobian_and_time_derivative(t, y, jac, dfdt)
            }
            #[inline]
            fn switches(&self) -> usize {
                (**self).switches()
            }
            #[inline]
            fn switching(&self, i: usize, t: f64, y: &OVector<f64, D>) -> f64 {
                (**self).switching(i, t, y)
            }
            #[inline]
            fn switch(&self, i: usize, t: f64, y: &mut OVector<f64, D>) {
                (**self).switch(i, t, y)
            }
            #[inline]
            fn branch_rate(&self, i: usize, y: &OVector<f64, D>) -> Option<f64> {
                (**self).branch_rate(i, y)
            }
            #[inline]
            fn stiff_diagonal(
                &self,
                t: f64,
                y: &OVector<f64, D>,
                lambda: &mut OVector<f64, D>,
            ) -> bool {
                (**self).stiff_diagonal(t, y, lambda)
            }
            #[inline]
            fn stiff_rates(&self, t: f64, y: &OVector<f64, D>, rates: &mut OVector<f64, D>) {
                (**self).stiff_rates(t, y, rates)
            }
            #[inline]
            fn rhs_memo(
                &self,
                t: f64,
                y: &OVector<f64, D>,
                dydt: &mut OVector<f64, D>,
                memo: &mut TimeMemo,
            ) {
                (**self).rhs_memo(t, y, dydt, memo)
            }
        }
    };
}

forward_system!(
    /// A shared reference to a system is a system:
    /// [`Integrator::new(&sys, ..)`](crate::ode::Integrator::new) borrows it,
    /// `Integrator::new(sys, ..)` owns it.
    &S
);
forward_system!(
    /// A boxed system (for example a `Box<dyn OdeSystem<D>>` chosen at run time) is a system.
    Box<S>
);

/// Adapter turning closures into an [`OdeSystem`]: the right-hand side `|t, y, dydt|`, and
/// optionally the Jacobian `|t, y, jac|` (finite differences otherwise) and a declaration that
/// `f` does not depend on `t` (so `∂f/∂t` is zero, not finite-differenced).
///
/// ```
/// use hdi_tribology::nalgebra::{Matrix2, Vector2, U2};
/// use hdi_tribology::ode::{solve, FnSystem, Method, OdeSystem, Options};
/// // Van der Pol (μ = 1000) with its analytic Jacobian, autonomous.
/// let mu = 1000.0;
/// let vdp = FnSystem::new(move |_t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>| {
///     dy[0] = y[1];
///     dy[1] = mu * (1.0 - y[0] * y[0]) * y[1] - y[0];
/// })
/// .with_jacobian(move |_t: f64, y: &Vector2<f64>, j: &mut Matrix2<f64>| {
///     *j = Matrix2::new(0.0, 1.0, -2.0 * mu * y[0] * y[1] - 1.0, mu * (1.0 - y[0] * y[0]));
/// })
/// .autonomous();
/// let mut j = Matrix2::zeros();
/// assert!(OdeSystem::<U2>::jacobian(&vdp, 0.0, &Vector2::new(2.0, 0.0), &mut j));
/// assert_eq!(j[(1, 1)], -3000.0);
/// let opts = Options::default().rtol(1e-6).atol(1e-6);
/// let sol = solve(&vdp, 0.0, Vector2::new(2.0, 0.0), 2000.0, Method::Rodas5P, &opts, &mut [])?;
/// assert!((sol.y_final()[0] - 1.706167732170469).abs() < 1e-3);
/// // No right-hand side was spent on Jacobians or ∂f/∂t: 7 stages per attempted step, f at
/// // the start of each accepted step, and 2 to start.
/// let (acc, rej) = (sol.stats.accepted, sol.stats.rejected);
/// assert!(sol.stats.jac_evals > 0 && sol.stats.rhs_evals <= 7 * (acc + rej) + acc + 2);
/// # Ok::<(), hdi_tribology::ode::OdeError>(())
/// ```
///
/// The closure alone:
///
/// ```
/// use hdi_tribology::nalgebra::{U1, Vector1};
/// use hdi_tribology::ode::{FnSystem, OdeSystem};
/// let decay = FnSystem::new(|_t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>| dy[0] = -y[0]);
/// let mut dy = Vector1::zeros();
/// OdeSystem::<U1>::rhs(&decay, 0.0, &Vector1::new(2.0), &mut dy);
/// assert_eq!(dy[0], -2.0);
/// ```
pub struct FnSystem<F, J = NoJacobian> {
    f: F,
    jac: J,
    autonomous: bool,
}

/// Marker for an [`FnSystem`] without a Jacobian closure (finite differences are used).
#[derive(Debug, Clone, Copy, Default)]
pub struct NoJacobian;

impl<F> FnSystem<F> {
    /// Wraps `f(t, y, dydt)`.
    pub fn new(f: F) -> Self {
        FnSystem {
            f,
            jac: NoJacobian,
            autonomous: false,
        }
    }
}

impl<F, J> FnSystem<F, J> {
    /// Adds the analytic Jacobian `jac(t, y, j)` writing `∂f/∂y` into `j`.
    pub fn with_jacobian<J2>(self, jac: J2) -> FnSystem<F, J2> {
        FnSystem {
            f: self.f,
            jac,
            autonomous: self.autonomous,
        }
    }

    /// Declares that `f` does not depend on `t`: Rosenbrock methods then take `∂f/∂t = 0`
    /// instead of spending a right-hand side on a difference quotient.
    pub fn autonomous(mut self) -> Self {
        self.autonomous = true;
        self
    }
}

impl<D: Dim, F> OdeSystem<D> for FnSystem<F, NoJacobian>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
    F: Fn(f64, &OVector<f64, D>, &mut OVector<f64, D>),
{
    fn rhs(&self, t: f64, y: &OVector<f64, D>, dydt: &mut OVector<f64, D>) {
        (self.f)(t, y, dydt)
    }

    fn is_autonomous(&self) -> bool {
        self.autonomous
    }
}

impl<D: Dim, F, J> OdeSystem<D> for FnSystem<F, J>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
    F: Fn(f64, &OVector<f64, D>, &mut OVector<f64, D>),
    J: Fn(f64, &OVector<f64, D>, &mut OMatrix<f64, D, D>),
{
    fn rhs(&self, t: f64, y: &OVector<f64, D>, dydt: &mut OVector<f64, D>) {
        (self.f)(t, y, dydt)
    }

    fn jacobian(&self, t: f64, y: &OVector<f64, D>, jac: &mut OMatrix<f64, D, D>) -> bool {
        (self.jac)(t, y, jac);
        true
    }

    fn is_autonomous(&self) -> bool {
        self.autonomous
    }
}

/// Forward-difference Jacobian of `sys` at `(t, y)`, given `f0 = f(t, y)`.
///
/// The increment of component `j` is `√ε · max(|y_j|, scale_j)`, where `scale_j` (e.g. the
/// absolute tolerance) keeps it meaningful for components near zero. `work` is scratch space.
/// Returns the number of right-hand-side evaluations (the state dimension).
///
/// ```
/// use hdi_tribology::ode::{finite_difference_jacobian, FnSystem};
/// use nalgebra::{Matrix2, Vector2};
/// let sys = FnSystem::new(|_t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>| {
///     dy[0] = y[0] * y[1];
///     dy[1] = -3.0 * y[0];
/// });
/// let y = Vector2::new(2.0, 5.0);
/// let f0 = Vector2::new(10.0, -6.0);
/// let mut j = Matrix2::zeros();
/// let mut work = Vector2::zeros();
/// finite_difference_jacobian(&sys, 0.0, &y, &f0, &Vector2::repeat(1e-8), &mut j, &mut work);
/// assert!((j[(0, 0)] - 5.0).abs() < 1e-6 && (j[(0, 1)] - 2.0).abs() < 1e-6);
/// assert!((j[(1, 0)] + 3.0).abs() < 1e-6 && j[(1, 1)].abs() < 1e-6);
/// ```
pub fn finite_difference_jacobian<D: Dim, S: OdeSystem<D> + ?Sized>(
    sys: &S,
    t: f64,
    y: &OVector<f64, D>,
    f0: &OVector<f64, D>,
    scale: &OVector<f64, D>,
    jac: &mut OMatrix<f64, D, D>,
    work: &mut OVector<f64, D>,
) -> usize
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let n = y.len();
    let mut yp = y.clone();
    let sqrt_eps = f64::EPSILON.sqrt();
    for j in 0..n {
        let yj = y[j];
        let mut delta = sqrt_eps * yj.abs().max(scale[j]);
        if delta.is_nan() || delta <= 0.0 || !delta.is_finite() {
            delta = sqrt_eps;
        }
        yp[j] = yj + delta;
        // The increment actually represented in floating point.
        let delta = yp[j] - yj;
        sys.rhs(t, &yp, work);
        for i in 0..n {
            jac[(i, j)] = (work[i] - f0[i]) / delta;
        }
        yp[j] = yj;
    }
    n
}

/// Complex-step Jacobian: `J[:, j] = Im f(t, y + i·δ·e_j) / δ`, exact to rounding for a
/// right-hand side `f` that is analytic and written for complex arithmetic.
///
/// Meant to be called from an [`OdeSystem::jacobian`] implementation.
///
/// ```
/// use hdi_tribology::ode::complex_step_jacobian;
/// use nalgebra::{Matrix2, Vector2};
/// use num_complex::Complex64;
/// let f = |_t: f64, y: &Vector2<Complex64>, dy: &mut Vector2<Complex64>| {
///     dy[0] = y[0].exp() * y[1];
///     dy[1] = y[0] * y[0];
/// };
/// let mut j = Matrix2::zeros();
/// complex_step_jacobian(f, 0.0, &Vector2::new(0.5, 2.0), &mut j);
/// assert!((j[(0, 0)] - 2.0 * 0.5f64.exp()).abs() < 1e-14);
/// assert!((j[(0, 1)] - 0.5f64.exp()).abs() < 1e-14);
/// assert!((j[(1, 0)] - 1.0).abs() < 1e-14 && j[(1, 1)] == 0.0);
/// ```
pub fn complex_step_jacobian<D: Dim, F>(
    f: F,
    t: f64,
    y: &OVector<f64, D>,
    jac: &mut OMatrix<f64, D, D>,
) where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
    F: Fn(f64, &OVector<Complex64, D>, &mut OVector<Complex64, D>),
{
    let n = y.len();
    let (rows, cols) = y.shape_generic();
    let mut yc: OVector<Complex64, D> =
        OVector::from_fn_generic(rows, cols, |i, _| Complex64::new(y[i], 0.0));
    let mut out: OVector<Complex64, D> =
        OVector::from_element_generic(rows, cols, Complex64::new(0.0, 0.0));
    for j in 0..n {
        // Any tiny relative step works (no subtractive cancellation); scaling with |y_j|
        // keeps the imaginary parts representable for states of any magnitude.
        let delta = if y[j] != 0.0 {
            1e-20 * y[j].abs()
        } else {
            1e-20
        };
        yc[j].im = delta;
        f(t, &yc, &mut out);
        for i in 0..n {
            jac[(i, j)] = out[i].im / delta;
        }
        yc[j].im = 0.0;
    }
}
