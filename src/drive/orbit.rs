//! The dither's settled orbit: under a held command on a flat disk the only forcing that moves
//! is the AC voltage, `V(t) = V_dc − φ + V_a sin ωt`, and the slider settles onto a periodic
//! orbit of its period `T = 2π/ω` (the drive's own period is another length). The exponential
//! scheme ([`super::DriveScheme::Exponential`]) then tabulates that orbit once, from two
//! periods of `T` run by the drive's integrator, and reads each later period's end from the
//! table, for as long as the command holds.
//!
//! The table is taken on the second of the two periods, at `2M` nodes landed on by the
//! integrator: the even nodes, with the right-hand side as their slopes, hold the cubic
//! Hermite table; the odd ones check it. It is trusted only when
//! - the orbit has settled: the second period's end is within the tolerances of its start,
//!   with the distance left to the orbit bounded by the geometric series of the drift from one
//!   period to the next (`|Δ₂| / (1 − r)`, `r = |Δ₂| / |Δ₁|` the contraction, at most
//!   [`MAX_CONTRACTION`]) within [`SETTLED`] of the tolerances;
//! - the table's cubic interpolation misses no odd node by more than [`INTERPOLATION`] of the
//!   tolerances;
//! - the period integrals (contact impulse, flash-temperature integral) grow by the same
//!   amount in both periods, within their tolerances.
//!
//! The integrals are not periodic: their growth per period of `T` is kept with the table, and
//! a period's change is the table's change within `T` plus whole periods of growth.

use crate::model::{SliderSystem, StateLayout};
use crate::ode::{Integrator, OdeSystem};
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OVector};

/// Table intervals per period of the dither: a cubic Hermite interpolant of a sinusoid with
/// `M` intervals per period errs by about `(2π/M)⁴/384` of its amplitude, 1.5e-8 at 128; the
/// nonlinear response's harmonics are checked at the odd nodes.
pub(crate) const NODES: usize = 128;

/// Largest contraction per period of the dither the settled check accepts: a slower approach
/// to the orbit could not be bounded from two periods.
pub(crate) const MAX_CONTRACTION: f64 = 0.5;

/// The distance left to the orbit, in units of the tolerances, that the check accepts.
pub(crate) const SETTLED: f64 = 0.5;

/// The interpolation error at the odd nodes, in units of the tolerances, that the check
/// accepts.
pub(crate) const INTERPOLATION: f64 = 0.25;

/// The settled orbit of a dither: the state over one period `T` of the voltage.
#[derive(Clone, Debug)]
pub(crate) struct Orbit {
    /// Time of node 0 (s) and the period (s).
    t_ref: f64,
    period: f64,
    n: usize,
    /// Values and slopes at node `k` (`0..=NODES`), component `c`: `[k * n + c]`; the integrals
    /// counted from node 0.
    values: Vec<f64>,
    slopes: Vec<f64>,
    /// The integrals' growth over one period (zero elsewhere).
    growth: Vec<f64>,
    integrals: [Option<usize>; 2],
    /// The largest of the checks' errors, in units of the tolerances.
    pub(crate) error: f64,
}

/// Why a try to tabulate the orbit did not give one (for the counts and the docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Refused {
    /// Not settled within the tolerances, or approaching the orbit too slowly to tell.
    Unsettled,
    /// The cubic table misses the odd nodes.
    Interpolation,
    /// The integrator failed or ran over the step budget.
    Integrator,
}

/// Restarts the integrator at `(t, x)` with the end time `tf` (> `t`), in the order its checks
/// allow whatever its current time and end time.
pub(crate) fn restart<D: Dim>(
    it: &mut Integrator<'static, D, SliderSystem>,
    t: f64,
    x: OVector<f64, D>,
    tf: f64,
) -> Result<(), crate::ode::OdeError>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    if t < it.tf() {
        it.reinit(t, x)?;
        it.set_tf(tf)
    } else {
        it.set_tf(tf)?;
        it.reinit(t, x)
    }
}

/// Steps the integrator onto `end` (its end time from here), failing once more than
/// `max_steps` steps have been accepted since the count stood at `first`.
pub(crate) fn step_onto<D: Dim>(
    it: &mut Integrator<'static, D, SliderSystem>,
    end: f64,
    first: usize,
    max_steps: usize,
) -> Result<(), crate::ode::OdeError>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    it.set_tf(end)?;
    while it.t() < end {
        it.step()?;
        if it.stats().accepted - first > max_steps {
            return Err(crate::ode::OdeError::invalid(
                "max_steps",
                "over the budget",
            ));
        }
    }
    Ok(())
}

impl Orbit {
    /// Runs the integrator from `(t, x)` over two periods of the dither of frequency
    /// `frequency` (Hz) and tabulates the second when it passes the checks (module docs), with
    /// the per-component absolute tolerances `atol` and relative `rtol`, after `lead` periods
    /// of settling. The integrator is left at `t + (lead + 2)T` whatever the outcome; at most
    /// `max_steps` steps are taken.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn build<D: Dim>(
        it: &mut Integrator<'static, D, SliderSystem>,
        layout: &StateLayout,
        t: f64,
        x: OVector<f64, D>,
        frequency: f64,
        lead: usize,
        atol: &[f64],
        rtol: f64,
        max_steps: usize,
    ) -> Result<Orbit, Refused>
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        let n = x.len();
        let period = 1.0 / frequency;
        let (t, x) = if lead > 0 {
            let end = t + lead as f64 * period;
            let first = it.stats().accepted;
            let ran = restart(it, t, x, end).and_then(|()| step_onto(it, end, first, max_steps));
            ran.map_err(|_| Refused::Integrator)?;
            (end, it.state().clone())
        } else {
            (t, x)
        };
        let half = period / (2 * NODES) as f64;
        // `2 NODES` nodes a period over both periods; the second's are kept.
        let count = 4 * NODES;
        let node_time = |k: usize| t + k as f64 * half;
        let start = it.stats().accepted;
        let mut states: Vec<f64> = Vec::with_capacity((2 * NODES + 1) * n);
        let mut slopes: Vec<f64> = Vec::with_capacity((2 * NODES + 1) * n);
        let mut ends = vec![vec![0.0; n]; 3];
        ends[0].copy_from_slice(x.as_slice());
        let ran = (|| -> Result<(), crate::ode::OdeError> {
            restart(it, t, x, node_time(1))?;
            let mut f = it.state().clone();
            for k in 1..=count {
                // Step by step onto the node (the end time), the budget counted per step.
                step_onto(it, node_time(k), start, max_steps)?;
                if k == 2 * NODES {
                    ends[1].copy_from_slice(it.state().as_slice());
                }
                if k >= 2 * NODES {
                    let s = it.state();
                    it.system().rhs(node_time(k), s, &mut f);
                    states.extend_from_slice(s.as_slice());
                    slopes.extend_from_slice(f.as_slice());
                }
            }
            ends[2].copy_from_slice(it.state().as_slice());
            Ok(())
        })();
        if ran.is_err() {
            return Err(Refused::Integrator);
        }
        let integrals = [layout.contact_impulse, layout.heat];
        let integral = |c: usize| integrals.contains(&Some(c));
        let weight = |c: usize, v: f64| atol[c] + rtol * v.abs();
        // Settled: the drift over the second period, and its contraction from the first.
        let (mut d1, mut d2) = (0.0f64, 0.0f64);
        for c in (0..n).filter(|&c| !integral(c)) {
            let w = weight(c, ends[1][c]);
            d1 = d1.max((ends[1][c] - ends[0][c]).abs() / w);
            d2 = d2.max((ends[2][c] - ends[1][c]).abs() / w);
        }
        let r = if d1 > 0.0 { d2 / d1 } else { 0.0 };
        let mut growth = vec![0.0; n];
        let mut integral_error = 0.0f64;
        for c in integrals.into_iter().flatten() {
            let (g1, g2) = (ends[1][c] - ends[0][c], ends[2][c] - ends[1][c]);
            growth[c] = g2;
            integral_error = integral_error.max((g2 - g1).abs() / atol[c]);
        }
        let settled = if r <= MAX_CONTRACTION {
            d2 / (1.0 - r)
        } else {
            f64::INFINITY
        };
        if settled > SETTLED || integral_error > SETTLED {
            return Err(Refused::Unsettled);
        }
        // The table on the even nodes of the second period, counted from its start.
        let row = |k: usize| k * n;
        let mut values = Vec::with_capacity((NODES + 1) * n);
        let mut table_slopes = Vec::with_capacity((NODES + 1) * n);
        for k in (0..=2 * NODES).step_by(2) {
            for c in 0..n {
                let base = if integral(c) { states[c] } else { 0.0 };
                values.push(states[row(k) + c] - base);
                table_slopes.push(slopes[row(k) + c]);
            }
        }
        let mut orbit = Orbit {
            t_ref: node_time(2 * NODES),
            period,
            n,
            values,
            slopes: table_slopes,
            growth,
            integrals,
            error: settled.max(integral_error),
        };
        let mut at = vec![0.0; n];
        let mut worst = 0.0f64;
        for k in (1..2 * NODES).step_by(2) {
            orbit.local(0, k / 2, 0.5, &mut at);
            for c in 0..n {
                let base = if integral(c) { states[c] } else { 0.0 };
                let truth = states[row(k) + c] - base;
                worst = worst.max((at[c] - truth).abs() / weight(c, truth));
            }
        }
        if worst > INTERPOLATION {
            return Err(Refused::Interpolation);
        }
        orbit.error = orbit.error.max(worst);
        Ok(orbit)
    }

    /// Period `whole` of the table, interval `k` and the place `θ` in it of time `t`.
    fn place(&self, t: f64) -> (i64, usize, f64) {
        let s = (t - self.t_ref) / self.period;
        let whole = s.floor();
        let u = (s - whole) * NODES as f64;
        let k = (u as usize).min(NODES - 1);
        (whole as i64, k, u - k as f64)
    }

    /// The state at `θ ∈ [0, 1]` of interval `k` of period `whole` into `out`, the integrals
    /// counted from the table's start (whole periods of growth included).
    fn local(&self, whole: i64, k: usize, theta: f64, out: &mut [f64]) {
        for (c, o) in out.iter_mut().enumerate().take(self.n) {
            *o = self.component(whole, k, theta, c);
        }
    }

    /// Component `c` of [`Orbit::local`].
    fn component(&self, whole: i64, k: usize, theta: f64, c: usize) -> f64 {
        let h = self.period / NODES as f64;
        let (i0, i1) = (k * self.n + c, (k + 1) * self.n + c);
        let (v, _) = crate::numerics::cubic_hermite(
            theta,
            self.values[i0],
            h * self.slopes[i0],
            self.values[i1],
            h * self.slopes[i1],
        );
        v + whole as f64 * self.growth[c]
    }

    /// The time of the table's node 0 (s) and the period of the dither (s).
    pub(crate) fn timing(&self) -> (f64, f64) {
        (self.t_ref, self.period)
    }

    /// The indices of the period integrals in the state.
    pub(crate) fn integrals(&self) -> [Option<usize>; 2] {
        self.integrals
    }

    /// The orbit's state at time `t` into `out`, the integrals counted from the table's start.
    pub(crate) fn state_at(&self, t: f64, out: &mut [f64]) {
        let (w, k, th) = self.place(t);
        self.local(w, k, th, out);
    }

    /// The state at the end `t1` of a period that starts at `t0` in state `x0`: the orbit's
    /// state at `t1`, the integrals `x0`'s plus their change over `[t0, t1]` on the orbit.
    pub(crate) fn period_end(&self, t0: f64, t1: f64, x0: &[f64], x1: &mut [f64]) {
        let (w1, k1, th1) = self.place(t1);
        self.local(w1, k1, th1, x1);
        let (w0, k0, th0) = self.place(t0);
        for c in self.integrals.into_iter().flatten() {
            x1[c] = x0[c] + (x1[c] - self.component(w0, k0, th0, c));
        }
    }
}
