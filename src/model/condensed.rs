//! The quasi-static condensation of a fast bulge mode (a singular perturbation of the structure).
//!
//! On the `bulge` structure the bulge is a mass `m_b` on a spring `k_b` and damper `c_b` to the
//! body: `m_b z̈ = F_if(d) + k_b (y − z) + c_b (ẏ − ż)`. When that mode is far faster than
//! everything else (the body on the air bearing, the forcing, the lags), the limit `m_b → 0` at a
//! fixed damping ratio (Tikhonov's theorem; Kokotović, Khalil & O'Reilly, *Singular
//! Perturbation Methods in Control*, 1986, ch. 1) leaves the bulge on its quasi-static
//! equilibrium: `k_b (z − y) = F_if(d)`, and the body feels `F_if` through the spring. In gaps,
//! with `d_r = h0 + y − δ` the bulge gap of an undeformed spring, the bulge gap `d` solves
//!
//! ```text
//!     k_b (d − d_r) = F_if(d)                        (without an interface lag)
//!     d = d_r + F_lag / k_b                          (with one: the spring carries the lagged force)
//! ```
//!
//! The slow system is the body alone: one coordinate instead of two, and no mode at hundreds of
//! megahertz for the integrator to resolve. It holds only where the fast subsystem (the bulge on
//! a frozen body) has one stable equilibrium that it reaches far faster than the slow system
//! moves: [`QuasiStaticBulge::check`] states the conditions and measures them on the model.

use crate::error::{Error, Result};

/// How many times faster than the slow system the condensed mode must be
/// ([`QuasiStaticBulge::check`]).
pub const SEPARATION: f64 = 10.0;

/// A Newton step of the settled bulge gap below this is converged (m): a hundredth of a
/// hundredth of the tightest displacement tolerance the analyses use (1e-16 m).
const SETTLED: f64 = 1e-20;

/// A step that no longer shrinks and is below this (m) has reached the tables' rounding.
const STALLED: f64 = 1e-16;

/// The bulge mode of a `bulge` structure, condensed to its quasi-static equilibrium: the spring
/// `k_b` between body and bulge, and the mass and damping that the condensation drops (kept for
/// [`QuasiStaticBulge::check`]).
///
/// ```
/// use hdi_tribology::model::Structure;
/// let s = Structure::bulge(1e-6, 5e-13, 4e5, 0.05)?;
/// let q = s.quasi_static_bulge().expect("a bulge structure");
/// assert_eq!(q.stiffness(), 4e5);
/// assert!((q.decay_rate() - 0.05 * (4e5f64 / 5e-13).sqrt()).abs() < 1e-6 * q.decay_rate());
/// assert!(Structure::rigid(1e-6)?.quasi_static_bulge().is_none());
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QuasiStaticBulge {
    stiffness: f64,
    mass: f64,
    damping: f64,
}

impl QuasiStaticBulge {
    /// The condensation of a bulge of mass `mass` (kg) on a spring `stiffness` (N/m) and damper
    /// `damping` (N s/m).
    pub(crate) fn new(mass: f64, stiffness: f64, damping: f64) -> Self {
        QuasiStaticBulge {
            stiffness,
            mass,
            damping,
        }
    }

    /// The spring between body and bulge `k_b` (N/m).
    pub fn stiffness(&self) -> f64 {
        self.stiffness
    }

    /// The bulge mass the condensation drops (kg).
    pub fn mass(&self) -> f64 {
        self.mass
    }

    /// The damping between body and bulge the condensation drops (N s/m).
    pub fn damping(&self) -> f64 {
        self.damping
    }

    /// The natural angular frequency of the bulge on a fixed body, `√(k_b/m_b)` (rad/s).
    pub fn angular_frequency(&self) -> f64 {
        (self.stiffness / self.mass).sqrt()
    }

    /// The decay rate of the bulge's ringing, `c_b/(2 m_b) = ζ_b ω_b` (1/s).
    pub fn decay_rate(&self) -> f64 {
        0.5 * self.damping / self.mass
    }

    /// The bulge gap `d` where the spring balances the interface force, `k_b (d − d_r) = F(d)`,
    /// by Newton's method safeguarded by bisection; `eval(d)` gives `(what, F, ∂F/∂d)`, and the
    /// settled gap's `what` is returned. `None`
    /// where no root with `k_b − ∂F/∂d > 0` is found (the fast subsystem has no stable
    /// equilibrium there: the condensation does not hold).
    pub(crate) fn settle<T: Copy>(
        &self,
        d_rigid: f64,
        eval: impl Fn(f64) -> (T, f64, f64),
    ) -> Option<T> {
        let k = self.stiffness;
        // Bracket of the root: G(lo) < 0 < G(hi) once both are known.
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        let mut d = d_rigid;
        let mut last = f64::INFINITY;
        for _ in 0..60 {
            let (at, f, slope) = eval(d);
            let g = k * (d - d_rigid) - f;
            let stiff = k - slope;
            if !(g.is_finite() && stiff.is_finite()) {
                return None;
            }
            if g < 0.0 {
                lo = lo.max(d);
            } else {
                hi = hi.min(d);
            }
            let newton = if stiff > 0.0 { d - g / stiff } else { f64::NAN };
            // A Newton step below the resolution of `d` is converged, even though `d` is now
            // an end of the bracket (which would otherwise send the next point off to bisect).
            if (newton - d).abs() <= SETTLED {
                return Some(at);
            }
            let next = if newton > lo && newton < hi {
                newton
            } else if lo.is_finite() && hi.is_finite() {
                0.5 * (lo + hi)
            } else {
                // No bracket yet and Newton points out of it: step by the spring alone.
                d - g / k
            };
            let step = (next - d).abs();
            // Converged far below any displacement tolerance, or stalled at the tables' own
            // rounding (a step that no longer shrinks, itself below 1e-16 m).
            let done = step <= SETTLED || g == 0.0 || (step >= 0.5 * last && step <= STALLED);
            if done {
                return (stiff > 0.0).then_some(at);
            }
            last = step;
            d = next;
        }
        None
    }

    /// Whether the condensation holds for a model: the conditions of the singular perturbation,
    /// measured on the model's interface forces and voltage. With `k_f = min (k_b − ∂F/∂d)` over
    /// the force tables' range and the squared voltages the model reaches, and `ω_s` the
    /// fastest rate of the slow system (the body on the bearing and the interface force seen
    /// through the spring, the 2f forcing, the lags), it holds when
    ///
    /// - `k_f > 0`: the bulge on a frozen body has one equilibrium at every gap (no fold of
    ///   its own, so the quasi-static bulge never has to jump);
    /// - `√(k_f/m_b) ≥ S ω_s`: the mode stays fast even where the interface force softens it;
    /// - `ζ_b ω_b = c_b/(2 m_b) ≥ S ω_s`: its ringing dies out before the slow system moves;
    /// - with an interface lag `τ`, the lag's negative damping of the fast mode,
    ///   `max|∂F/∂d| τ / (1 + (ω_b τ)²)`, stays below `c_b / S` (the lagged contact does not
    ///   excite the bulge);
    ///
    /// with `S` = [`SEPARATION`]. The force tables' slopes are read on a grid of 1 pm over their
    /// range; below the range the contact stiffens and only makes `k_b − ∂F/∂d` larger.
    pub fn check(&self, model: &super::SliderModel) -> CondensationCheck {
        self.check_on(model, &ForceSlopes::of(model.forces()))
    }

    /// [`QuasiStaticBulge::check`] on slopes read once ([`ForceSlopes::of`] the model's
    /// forces): for many checks on one set of tables, as in a map.
    pub fn check_on(&self, model: &super::SliderModel, slopes: &ForceSlopes) -> CondensationCheck {
        let v = model.voltage();
        let top = v.effective_dc().abs() + v.ac_amplitude.abs();
        let volt2 = [0.0, top * top];
        let k = self.stiffness;
        // The largest softening slope, and the largest |F̃'| = |F' k/(k − F')| the body feels.
        let (mut softest, mut body, mut steepest) = (f64::INFINITY, 0.0f64, 0.0f64);
        for (s, e) in slopes.static_part.iter().zip(&slopes.per_volt2) {
            for w in volt2 {
                let slope = s + w * e;
                let stiff = k - slope;
                softest = softest.min(stiff);
                steepest = steepest.max(slope.abs());
                if stiff > 0.0 {
                    body = body.max((slope * k / stiff).abs());
                }
            }
        }
        let m = model.structure().body_mass();
        let bearing = model.bearing();
        let mut slow = ((bearing.stiffness(0.0) + body) / m).sqrt();
        slow = slow.max(bearing.damping(0.0) / m);
        if v.is_time_dependent() {
            slow = slow.max(4.0 * std::f64::consts::PI * v.frequency.abs());
        }
        for tau in [model.interface_lag(), model.thermal_lag()] {
            if tau > 0.0 {
                slow = slow.max(1.0 / tau);
            }
        }
        let fast = if softest > 0.0 {
            (softest / self.mass).sqrt()
        } else {
            0.0
        };
        let tau = model.interface_lag();
        let w = self.angular_frequency();
        let lag_damping = if tau > 0.0 {
            steepest * tau / (1.0 + (w * tau).powi(2))
        } else {
            0.0
        };
        let mut refused = Vec::new();
        if softest <= 0.0 {
            refused.push(format!(
                "the interface force's slope exceeds the bulge spring by {:.3e} N/m: the bulge \
                 folds on its own",
                -softest
            ));
        } else if fast < SEPARATION * slow {
            refused.push(format!(
                "the bulge mode, softened by the interface to {:.3e} rad/s, is not {SEPARATION}× \
                 the slow rate {slow:.3e} rad/s",
                fast
            ));
        }
        if self.decay_rate() < SEPARATION * slow {
            refused.push(format!(
                "the bulge's ringing decays at {:.3e} 1/s, not {SEPARATION}× the slow rate \
                 {slow:.3e} rad/s",
                self.decay_rate()
            ));
        }
        if lag_damping * SEPARATION > self.damping {
            refused.push(format!(
                "the interface lag's negative damping {lag_damping:.3e} N s/m is more than 1/{SEPARATION} of the \
                 bulge damping {:.3e} N s/m",
                self.damping
            ));
        }
        CondensationCheck {
            fast_stiffness: softest,
            fast_rate: fast,
            decay_rate: self.decay_rate(),
            slow_rate: slow,
            lag_damping,
            refused,
        }
    }
}

/// The slopes `∂F/∂d` of the static and per-V² parts of the interface force on a grid of 1 pm
/// over the force tables' range: what [`QuasiStaticBulge::check_on`] reads.
///
/// ```no_run
/// use hdi_tribology::{model::{ForceSlopes, SliderModel}, scene::Scene};
/// let model = SliderModel::from_scene(&Scene::from_path("scenes/paper_bulge.toml")?)?;
/// let slopes = ForceSlopes::of(model.forces());
/// let q = model.structure().quasi_static_bulge().expect("a bulge");
/// assert_eq!(q.check_on(&model, &slopes), q.check(&model));
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct ForceSlopes {
    static_part: Vec<f64>,
    per_volt2: Vec<f64>,
}

impl ForceSlopes {
    /// The slopes of `forces` on their tables' range.
    pub fn of(forces: &crate::force::InterfaceForces) -> Self {
        let (low, high) = forces.table_range();
        let n = (((high - low) / 1e-12).ceil() as usize).clamp(2, 200_000);
        let (mut static_part, mut per_volt2) =
            (Vec::with_capacity(n + 1), Vec::with_capacity(n + 1));
        for i in 0..=n {
            let d = low + (high - low) * i as f64 / n as f64;
            let h = forces.evaluate(crate::force::Gaps::same(d));
            static_part.push(h.static_part.d_bulge);
            per_volt2.push(h.per_volt2.d_bulge);
        }
        ForceSlopes {
            static_part,
            per_volt2,
        }
    }
}

/// The outcome of [`QuasiStaticBulge::check`]: the rates it compared and, where the
/// condensation does not hold, why.
#[derive(Clone, Debug, PartialEq)]
pub struct CondensationCheck {
    /// The smallest `k_b − ∂F/∂d` over the gaps and voltages (N/m).
    pub fast_stiffness: f64,
    /// `√(k_f/m_b)`: the slowest the bulge mode gets (rad/s).
    pub fast_rate: f64,
    /// The decay rate of the bulge's ringing `c_b/(2 m_b)` (1/s).
    pub decay_rate: f64,
    /// The fastest rate of the slow system (1/s).
    pub slow_rate: f64,
    /// The interface lag's negative damping of the bulge mode (N s/m; 0 without a lag).
    pub lag_damping: f64,
    /// Why the condensation does not hold; empty where it does.
    pub refused: Vec<String>,
}

impl CondensationCheck {
    /// Whether every condition holds.
    pub fn passes(&self) -> bool {
        self.refused.is_empty()
    }

    /// The check as an error naming the structure, where it does not pass.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] on `structure`, with the reasons.
    pub fn require(&self) -> Result<()> {
        if self.passes() {
            Ok(())
        } else {
            Err(Error::invalid(
                "structure",
                format!(
                    "the quasi-static bulge does not hold: {}",
                    self.refused.join("; ")
                ),
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear interface force `F = a − s d` has the closed-form root `(k d_r + a)/(k + s)`.
    #[test]
    fn settle_finds_the_linear_root() {
        let q = QuasiStaticBulge::new(1e-13, 4e5, 1e-5);
        for (a, s) in [(1e-4, 2e5), (-3e-4, -1e5), (0.0, 0.0), (2e-4, -3.9e5)] {
            let d_r = 1.3e-9;
            let r = q.settle(d_r, |d| (d, a - s * d, -s)).expect("a root");
            let exact = (4e5 * d_r + a) / (4e5 + s);
            assert!((r - exact).abs() <= 1e-22, "{r} vs {exact}");
        }
    }

    /// A root that Newton reaches to the last bit while that point is an end of the bracket is
    /// returned there, not left to bisect away and back (which stalled up to 1e-16 m off: an
    /// error in the gap as large as a Jacobian's difference step).
    #[test]
    fn settle_stops_where_newton_no_longer_moves() {
        let (k, c) = (2e6, 1e14);
        let q = QuasiStaticBulge::new(1e-13, k, 1e-5);
        let mut worst = 0.0f64;
        for i in 0..4000 {
            // A Hertz-like stiffening force `c u² − a`, u = 2 nm − d, attractive at the rigid
            // gap, so that Newton brackets the root from above and then closes in from below.
            let d_r = 0.5e-9 + 0.2e-9 * (i % 400) as f64 / 400.0;
            let a = 3e-4 + 1e-4 * (i / 400) as f64 / 10.0;
            let f = |d: f64| {
                let u = 2e-9 - d;
                (c * u * u - a, -2.0 * c * u)
            };
            let r = q.settle(d_r, |d| (d, f(d).0, f(d).1)).expect("a root");
            // The root of k (d − d_r) = c u² − a: c u² + k u − e = 0, e = k (2 nm − d_r) + a,
            // in the form without cancellation.
            let e = k * (2e-9 - d_r) + a;
            let exact = 2e-9 - 2.0 * e / (k + (k * k + 4.0 * c * e).sqrt());
            worst = worst.max((r - exact).abs() / exact);
        }
        assert!(worst < 1e-14, "settled {worst:e} off");
    }

    /// A slope beyond the spring has no stable root: refused.
    #[test]
    fn settle_refuses_a_fold() {
        let q = QuasiStaticBulge::new(1e-13, 4e5, 1e-5);
        assert!(q.settle(1e-9, |d| ((), 5e5 * d, 5e5)).is_none());
    }
}
