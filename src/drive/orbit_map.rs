//! The drive's period on a dither's settled orbit, linearised in the heater power: a command
//! that changes the heater every period, under a held dither on a flat disk, read from the
//! orbit's table ([`super::orbit`]) and a table of the period's linear map.
//!
//! Near the orbit `x*(t)` of the heater power `P*`, the deviation `δ = x − x*` and the offset
//! `u = P − P*` obey `δ̇ = A(t) δ + b(t) u`, with `A = ∂f/∂x` and `b = ∂f/∂P` on the orbit, both
//! periodic with the dither's period `T`. Over a drive period `[t0, t0 + Δt]` with `u` held, the
//! augmented state `(δ, u)` moves by the transition matrix `P̂(t0)` of `Â = [[A, b], [0, 0]]`,
//! which depends on `t0` through the dither's phase alone. The map is tabulated over one period
//! of the phase:
//! - the propagator of each of [`GRID`] intervals of `T` is `exp(h Â)` at the interval's
//!   midpoint (the second-order Magnus step; the Jacobian is the model's own);
//! - `P̂` at each node is the product of the `⌊Δt/h⌋` propagators that follow it, taken as
//!   products of runs of 2^j intervals, and a last partial interval;
//! - the even nodes, with the slopes `Â(t0 + Δt) P̂ − P̂ Â(t0)`, hold a cubic Hermite table; the
//!   odd ones check it.
//!
//! No inverse of a transition matrix is formed: the contact modes decay by e^−100 and more over
//! a period of the dither, where a Floquet factorisation `Y(t1) Y(t0)⁻¹` would lose every digit.
//!
//! The map is trusted for the heater offsets and deviations its test covers. From the orbit's
//! start, the integrator runs [`TEST_PERIODS`] drive periods with the heater offset by `±u`, at
//! tolerances [`TIGHTER`] times tighter than the drive's, and the map chained from the same
//! start must agree with it within [`AGREEMENT`] of the drive's tolerances at each period's end
//! (so the test also bounds the orbit's own error); `u` starts at the first of
//! [`TEST_OFFSETS`] and halves after a miss. A period is then read from the map only while `|u|`
//! is within the offset that passed and the deviation at its start within the largest the test
//! saw, in units of the tolerances; the table's interpolation is checked at the odd nodes over
//! that region. A test run against an integrator at the drive's own tolerances would measure
//! that integrator's error instead: in contact it disagreed by 0.5–1.9 tolerances whatever
//! `u`, where the tighter run finds 0.02.

use super::orbit::{restart, step_onto, Orbit, Refused, NODES};
use super::state::{state_vector, MAX_STATE};
use crate::model::{Heater, SliderSystem};
use crate::numerics::cubic_hermite;
use crate::ode::{expm, Integrator, OdeSystem, Tolerance};
use nalgebra::{allocator::Allocator, DMatrix, DVector, DefaultAllocator, Dim, Dyn};

/// Propagator intervals per period of the dither; the map's table holds every other node.
pub(crate) const GRID: usize = 2 * NODES;

/// The heater offsets (W) the test tries, largest first.
pub(crate) const TEST_OFFSETS: [f64; 4] = [8e-6, 4e-6, 2e-6, 1e-6];

/// How much tighter than the drive's the tolerances of the test's integrator runs are.
const TIGHTER: f64 = 10.0;

/// Drive periods of each test run.
pub(crate) const TEST_PERIODS: usize = 6;

/// The largest disagreement of the map with the integrator in the test, and of the table's
/// interpolation at the odd nodes over the trusted region, in units of the tolerances.
pub(crate) const AGREEMENT: f64 = 0.5;

/// The deviation from the orbit (in units of the tolerances) below which a period at the
/// orbit's heater power is read from the orbit's table alone, as a held dither's periods are
/// (whose table is trusted at half a tolerance from the orbit): the deviation a heater change
/// leaves decays by about 0.39 a period of the dither and would otherwise be carried on for
/// ever, down to subnormal numbers.
pub(crate) const ON_ORBIT: f64 = 0.01;

/// The longest drive period the map takes, in periods of the dither.
const MAX_DITHER_PERIODS: f64 = 64.0;

/// The heater step of the central difference of `b = ∂f/∂P` (W).
const HEATER_STEP: f64 = 1e-6;

/// The linearised period map of one orbit and one drive period.
#[derive(Clone, Debug)]
pub(crate) struct OrbitMap {
    /// The drive period (s) and the orbit's heater power `P*` (W).
    dt: f64,
    heater: f64,
    /// State length `n`; the augmented state has `n + 1`.
    n: usize,
    /// `P̂` and its slope in `t0` at node `k` (`0..=NODES`), entry `(i, j)`:
    /// `[(k * (n + 1) + i) * (n + 1) + j]`.
    values: Vec<f64>,
    slopes: Vec<f64>,
    /// Whether component `c` is a period integral (its deviation starts at zero each period).
    integral: Vec<bool>,
    atol: Vec<f64>,
    rtol: f64,
    /// The table's node spacing in time (s).
    step: f64,
    /// The largest heater offset (W) and deviation (tolerance units) trusted.
    offset: f64,
    radius: f64,
    /// The largest of the test's and the interpolation check's errors, in tolerance units.
    pub(crate) error: f64,
}

/// `Â = [[A, b], [0, 0]]` on the orbit at time `t`.
struct Augmented<'a> {
    orbit: &'a Orbit,
    sys: &'a SliderSystem,
    up: SliderSystem,
    down: SliderSystem,
    n: usize,
    x: DVector<f64>,
    fu: DVector<f64>,
    fd: DVector<f64>,
    jac: DMatrix<f64>,
}

impl<'a> Augmented<'a> {
    fn new(orbit: &'a Orbit, sys: &'a SliderSystem, heater: f64, n: usize) -> Self {
        let at = |p: f64| {
            let mut s = sys.clone();
            let mut inputs = s.inputs().clone();
            inputs.heater = Heater::Power(p);
            s.set_inputs(inputs);
            s
        };
        Augmented {
            orbit,
            sys,
            up: at(heater + HEATER_STEP),
            down: at(heater - HEATER_STEP),
            n,
            x: DVector::zeros(n),
            fu: DVector::zeros(n),
            fd: DVector::zeros(n),
            jac: DMatrix::zeros(n, n),
        }
    }

    /// `Â(t)` into `out` (`(n + 1) × (n + 1)`).
    fn at(&mut self, t: f64, out: &mut DMatrix<f64>) {
        let n = self.n;
        self.orbit.state_at(t, self.x.as_mut_slice());
        OdeSystem::<Dyn>::jacobian(self.sys, t, &self.x, &mut self.jac);
        OdeSystem::<Dyn>::rhs(&self.up, t, &self.x, &mut self.fu);
        OdeSystem::<Dyn>::rhs(&self.down, t, &self.x, &mut self.fd);
        out.fill(0.0);
        out.view_mut((0, 0), (n, n)).copy_from(&self.jac);
        for i in 0..n {
            out[(i, n)] = (self.fu[i] - self.fd[i]) / (2.0 * HEATER_STEP);
        }
    }
}

impl OrbitMap {
    /// Tabulates the map of drive periods `dt` (s) on `orbit`, the orbit of the heater power
    /// the integrator's system holds, and tests it against the integrator (module docs), with
    /// the per-component absolute tolerances `atol` and relative `rtol`. The integrator is left
    /// wherever the test ends, with the system's inputs as they were; at most `max_steps` steps
    /// a test run.
    pub(crate) fn build<D: Dim>(
        it: &mut Integrator<'static, D, SliderSystem>,
        orbit: &Orbit,
        dt: f64,
        atol: &[f64],
        rtol: f64,
        max_steps: usize,
    ) -> Result<OrbitMap, Refused>
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        let Heater::Power(heater) = it.system().inputs().heater else {
            return Err(Refused::Unsettled);
        };
        let (t_ref, period) = orbit.timing();
        if !(dt > 0.0 && dt <= MAX_DITHER_PERIODS * period) {
            return Err(Refused::Unsettled);
        }
        let n = atol.len();
        let m = n + 1;
        let h = period / GRID as f64;
        let whole = (dt / h).floor() as usize;
        let rest = dt - whole as f64 * h;
        let mut integral = vec![false; n];
        for c in orbit.integrals().into_iter().flatten() {
            integral[c] = true;
        }
        let (values, slopes, odd) = {
            let mut hat = Augmented::new(orbit, it.system(), heater, n);
            let mut a = DMatrix::zeros(m, m);
            let mut prop = |t: f64, len: f64, hat: &mut Augmented<'_>| {
                hat.at(t, &mut a);
                expm(&(&a * len)).map_err(|_| Refused::Integrator)
            };
            // Runs of 2^j intervals from each node: `runs[j][k]`.
            let mut runs: Vec<Vec<DMatrix<f64>>> = vec![(0..GRID)
                .map(|k| prop(t_ref + (k as f64 + 0.5) * h, h, &mut hat))
                .collect::<Result<_, _>>()?];
            while (1usize << runs.len()) <= whole {
                let s = 1usize << (runs.len() - 1);
                let last = &runs[runs.len() - 1];
                let next = (0..GRID)
                    .map(|k| &last[(k + s) % GRID] * &last[k])
                    .collect();
                runs.push(next);
            }
            let mut a0 = DMatrix::zeros(m, m);
            let mut a1 = DMatrix::zeros(m, m);
            let mut maps = Vec::with_capacity(GRID);
            let mut slopes = Vec::with_capacity(GRID);
            for k in 0..GRID {
                let mut acc = DMatrix::<f64>::identity(m, m);
                let mut pos = k;
                for (j, run) in runs.iter().enumerate() {
                    if whole >> j & 1 == 1 {
                        acc = &run[pos % GRID] * &acc;
                        pos += 1 << j;
                    }
                }
                if rest > 1e-9 * h {
                    acc = prop(t_ref + pos as f64 * h + 0.5 * rest, rest, &mut hat)? * &acc;
                }
                let t0 = t_ref + k as f64 * h;
                hat.at(t0, &mut a0);
                hat.at(t0 + dt, &mut a1);
                slopes.push(&a1 * &acc - &acc * &a0);
                maps.push(acc);
            }
            maps.push(maps[0].clone());
            slopes.push(slopes[0].clone());
            let flat = |ms: &[DMatrix<f64>], parity: usize| -> Vec<f64> {
                let mut v = Vec::with_capacity((NODES + 1) * m * m);
                for mat in ms.iter().skip(parity).step_by(2) {
                    for i in 0..m {
                        for j in 0..m {
                            v.push(mat[(i, j)]);
                        }
                    }
                }
                v
            };
            (flat(&maps, 0), flat(&slopes, 0), flat(&maps, 1))
        };
        let mut map = OrbitMap {
            dt,
            heater,
            n,
            values,
            slopes,
            integral,
            atol: atol.to_vec(),
            rtol,
            step: period / NODES as f64,
            offset: 0.0,
            radius: 0.0,
            error: 0.0,
        };
        // The test: the integrator and the chained map from the orbit's start, the heater
        // offset by ±u.
        let mut start = vec![0.0; n];
        orbit.state_at(t_ref, &mut start);
        // The integrator's own tolerances, restored after the test whatever its outcome.
        let (rtol0, atol0) = (it.rtol(), it.atol().to_vec());
        let tested = (|| -> Result<Option<(f64, f64, f64)>, crate::ode::OdeError> {
            let tight = atol0.iter().map(|a| a / TIGHTER).collect();
            it.set_tolerances(rtol0 / TIGHTER, Tolerance::PerComponent(tight))?;
            for &u in &TEST_OFFSETS {
                let mut worst = 0.0f64;
                let mut reach = 0.0f64;
                for sign in [1.0, -1.0] {
                    let (w, r) =
                        map.test(it, orbit, t_ref, &start, heater + sign * u, max_steps)?;
                    worst = worst.max(w);
                    reach = reach.max(r);
                }
                if worst <= AGREEMENT {
                    return Ok(Some((u, reach, worst)));
                }
            }
            Ok(None)
        })();
        set_heater(it, heater);
        it.set_tolerances(rtol0, Tolerance::PerComponent(atol0))
            .map_err(|_| Refused::Integrator)?;
        let Some((offset, radius, worst)) = tested.map_err(|_| Refused::Integrator)? else {
            return Err(Refused::Unsettled);
        };
        map.offset = offset;
        map.radius = radius;
        // The table between its nodes, over the trusted region.
        let interp = map.interpolation_error(orbit, &odd);
        if interp > AGREEMENT {
            return Err(Refused::Interpolation);
        }
        map.error = worst.max(interp);
        Ok(map)
    }

    /// One test run: the integrator from `(t, x)` at the heater power `p` over
    /// [`TEST_PERIODS`] drive periods against the map chained from the same start; the largest
    /// disagreement and the largest deviation from the orbit, both in tolerance units.
    fn test<D: Dim>(
        &self,
        it: &mut Integrator<'static, D, SliderSystem>,
        orbit: &Orbit,
        t: f64,
        x: &[f64],
        p: f64,
        max_steps: usize,
    ) -> Result<(f64, f64), crate::ode::OdeError>
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        set_heater(it, p);
        let dim = D::from_usize(self.n);
        let x0 = state_vector::<D>(dim, |i| x[i]);
        restart(it, t, x0, t + self.dt)?;
        let start = it.stats().accepted;
        let mut lin = x.to_vec();
        let mut next = vec![0.0; self.n];
        let mut o0 = vec![0.0; self.n];
        let (mut worst, mut reach) = (0.0f64, 0.0f64);
        for i in 1..=TEST_PERIODS {
            let (t0, t1) = (t + (i - 1) as f64 * self.dt, t + i as f64 * self.dt);
            step_onto(it, t1, start, max_steps)?;
            orbit.state_at(t0, &mut o0);
            reach = reach.max(self.propagate(orbit, t0, &o0, t1, &lin, p - self.heater, &mut next));
            let s = it.state();
            for c in 0..self.n {
                let w = self.atol[c] + self.rtol * s[c].abs();
                worst = worst.max((s[c] - next[c]).abs() / w);
            }
            std::mem::swap(&mut lin, &mut next);
        }
        Ok((worst, reach))
    }

    /// The largest miss of the table at the odd nodes `odd` (the maps there, flattened as the
    /// table), weighted by the trusted region: in tolerance units of the orbit's state.
    fn interpolation_error(&self, orbit: &Orbit, odd: &[f64]) -> f64 {
        let (m, n) = (self.n + 1, self.n);
        let (t_ref, period) = orbit.timing();
        let mut x = vec![0.0; n];
        let mut worst = 0.0f64;
        for k in 0..NODES {
            orbit.state_at(t_ref + (k as f64 + 0.5) * period / NODES as f64, &mut x);
            for i in 0..n {
                let mut miss = 0.0;
                for j in 0..m {
                    let v = self.entry(k, 0.5, i, j) - odd[(k * m + i) * m + j];
                    let scale = if j == n {
                        self.offset
                    } else if self.integral[j] {
                        0.0
                    } else {
                        self.radius * (self.atol[j] + self.rtol * x[j].abs())
                    };
                    miss += v.abs() * scale;
                }
                worst = worst.max(miss / (self.atol[i] + self.rtol * x[i].abs()));
            }
        }
        worst
    }

    /// Entry `(i, j)` of the table at `θ` in interval `k`.
    fn entry(&self, k: usize, theta: f64, i: usize, j: usize) -> f64 {
        let m = self.n + 1;
        let hh = self.step;
        let (a, b) = ((k * m + i) * m + j, ((k + 1) * m + i) * m + j);
        cubic_hermite(
            theta,
            self.values[a],
            hh * self.slopes[a],
            self.values[b],
            hh * self.slopes[b],
        )
        .0
    }

    /// The largest heater offset from the orbit's (W) the map is trusted with.
    pub(crate) fn offset(&self) -> f64 {
        self.offset
    }

    /// The orbit's heater power (W).
    pub(crate) fn heater(&self) -> f64 {
        self.heater
    }

    /// The state at the end `t1` of a drive period of `dt` (s) that starts at `t0` in state
    /// `x0` at the heater power `p` (W), into `x1`, the integrals `x0`'s plus their change: when
    /// `dt` is the map's and the heater offset and the deviation at `t0` are within the
    /// trusted region. `None` (and `x1` not written) otherwise; `Some(false)` when the period
    /// is the orbit's own: the heater at the orbit's power and the deviation within [`ON_ORBIT`]
    /// of the tolerances, read from the orbit's table as a held dither is.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn period_end(
        &self,
        orbit: &Orbit,
        t0: f64,
        t1: f64,
        dt: f64,
        x0: &[f64],
        p: f64,
        x1: &mut [f64],
    ) -> Option<bool> {
        let u = p - self.heater;
        if dt != self.dt || u.abs() > self.offset {
            return None;
        }
        let mut o0 = [0.0; MAX_STATE];
        orbit.state_at(t0, &mut o0[..self.n]);
        let deviation = (0..self.n)
            .filter(|&c| !self.integral[c])
            .map(|c| (x0[c] - o0[c]).abs() / (self.atol[c] + self.rtol * x0[c].abs()))
            .fold(0.0f64, f64::max);
        if deviation > self.radius {
            return None;
        }
        if u == 0.0 && deviation <= ON_ORBIT {
            orbit.period_end(t0, t1, x0, x1);
            return Some(false);
        }
        self.propagate(orbit, t0, &o0[..self.n], t1, x0, u, x1);
        Some(true)
    }

    /// The state at `t1` of a period `[t0, t1]` that starts in `x0`, the orbit's state there
    /// being `o0`, with the heater offset `u` (W) from the orbit's, into `x1`; the deviation at
    /// the end in tolerance units.
    #[allow(clippy::too_many_arguments)]
    fn propagate(
        &self,
        orbit: &Orbit,
        t0: f64,
        o0: &[f64],
        t1: f64,
        x0: &[f64],
        u: f64,
        x1: &mut [f64],
    ) -> f64 {
        let (n, m) = (self.n, self.n + 1);
        let mut v = [0.0; MAX_STATE + 1];
        for c in 0..n {
            v[c] = if self.integral[c] { 0.0 } else { x0[c] - o0[c] };
        }
        v[n] = u;
        let (t_ref, period) = orbit.timing();
        let s = (t0 - t_ref) / period;
        let s = (s - s.floor()) * NODES as f64;
        let k = (s as usize).min(NODES - 1);
        let theta = s - k as f64;
        let hh = self.step;
        orbit.state_at(t1, x1);
        let mut reach = 0.0f64;
        for i in 0..n {
            let (mut a, mut b, mut c, mut d) = (0.0, 0.0, 0.0, 0.0);
            let (r0, r1) = ((k * m + i) * m, ((k + 1) * m + i) * m);
            for (j, vj) in v[..m].iter().enumerate() {
                a += self.values[r0 + j] * vj;
                b += self.slopes[r0 + j] * vj;
                c += self.values[r1 + j] * vj;
                d += self.slopes[r1 + j] * vj;
            }
            let delta = cubic_hermite(theta, a, hh * b, c, hh * d).0;
            if self.integral[i] {
                x1[i] = x0[i] + (x1[i] - o0[i]) + delta;
            } else {
                x1[i] += delta;
                reach = reach.max(delta.abs() / (self.atol[i] + self.rtol * x1[i].abs()));
            }
        }
        reach
    }
}

/// Sets the heater power (W) of the integrator's system, the rest of its inputs kept.
fn set_heater<D: Dim>(it: &mut Integrator<'static, D, SliderSystem>, p: f64)
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let mut inputs = it.system().inputs().clone();
    inputs.heater = Heater::Power(p);
    it.system_mut().set_inputs(inputs);
}
