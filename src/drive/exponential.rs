//! The drive's exponential scheme ([`DriveScheme::Exponential`](super::DriveScheme)): each
//! period one exponential step, or 2 to 16 substeps, with the slider's Jacobian held across
//! periods and the known periodic forcings (the disk's waviness, an AC dither) taken out exactly
//! by their particular solutions; the existing integrator for the periods the scheme cannot
//! answer for.
//!
//! The split. With `J` the slider's Jacobian (held), taken at the slow state (the state less
//! the known forcings' responses, so that it does not swing with the disk's phase), the
//! forcings that are known functions of time are the disk's motion, `u_d(t) = −r ẅ(t)` on the
//! accelerations, and the dither's part of the interface force, `u_v(t) = e (V(t)² − mean)`
//! with `e = ∂f/∂(V²)` there. Each is a sum of sinusoids (the disk's harmonics; `V²` has its
//! lines at `ω` and `2ω`), so `p′ = J p + u` has the periodic solution
//! `p(t) = Σ Re(C_k e^{iω_k t})` with `(iω_k − J) C_k = U_k`. The state is integrated as
//! `z = x − p(t)`: `z′ = f(t, z + p) − p′(t)`, whose remainder `z′ − J z` holds what is left
//! of the nonlinear forces, the mean voltage and the heater. The disk's `p` is tabulated over
//! a revolution on the disk's own grid (values and slopes by an inverse FFT, cubic Hermite
//! between the nodes) for the `J` it was built with; the dither's is summed per evaluation
//! (two lines).
//!
//! The step is [`crate::ode::ExponentialStepper`]'s (ETD2RK) on `z`, at the drive's contact
//! tolerances, per component; a period of one step that continues the one before, to the bit,
//! under the same inputs but the heater, takes its two-step method instead
//! ([`ExponentialStepper::step_two`], one right-hand side a period,
//! [`ExpScheme::continuation`]), and so does every substep after a period's first, from the
//! substep before (one right-hand side a substep). Where the forces curve over the disk's
//! sweep (near the peaks, in contact), the disk's table also takes out the periodic part of
//! their remainder beyond `J` along that sweep ([`Periodic`], the curvature), when a period
//! needed it and the table before lasted [`CURVATURE_WAIT`]. Before the step, a check of the
//! contact force's curvature over the forcings' reach ([`ExpScheme::straight`]) refuses what
//! the estimate cannot see. A period whose estimate is above 1 is tried again with the Jacobian taken
//! afresh at its start (the disk's table rebuilt when that moved `J` by more than
//! [`REBUILD_SHIFT`]), then with twice the substeps, up to [`LEVELS`]; if it still misses,
//! the period is run by the integrator from the same start, as the default drive runs it, and
//! the following periods too, for a number that doubles with each consecutive miss, up to
//! [`MAX_SKIP`] ([`MAX_SKIP_DITHER`] with a dither); so are the periods after a disk table
//! replaced within [`SHORT_TABLE`] periods of its build, for a wait that doubles up to
//! [`MAX_CHURN_SKIP`]. A held command on a flat disk without a
//! dither is left to the integrator (`src/drive/plant.rs`), whose steps span many periods
//! there; with a dither, once the slider has settled onto the dither's periodic orbit, the
//! periods are read from a table of that orbit (`src/drive/orbit.rs`).

use super::disk::{Disk, NODES};
use super::orbit::Orbit;
use super::orbit_map::OrbitMap;
use super::state::{state_vector, MAX_STATE};
use crate::force::Gaps;
use crate::model::{Inputs, SliderSystem, StateLayout, Voltage};
use crate::ode::lu::Lu;
use crate::ode::{ExponentialStepper, OdeSystem};
use nalgebra::{
    allocator::Allocator, DMatrix, DVector, DefaultAllocator, Dim, Dyn, OMatrix, OVector,
};
use num_complex::Complex64;
use std::f64::consts::PI;

/// Relative change of the held Jacobian (largest entry change over the largest entry of its
/// row, the integrals' rows aside) beyond which a refresh also rebuilds the disk's table. The
/// table's response is off by about this fraction of its size when the held Jacobian has
/// moved this far from the one it was built with, and that error oscillates at the disk's
/// frequencies within a period, where the step's estimate cannot see it: 1e-4 of the ~15 pm
/// the default waviness moves the gap is a sixth of the 0.01 pm displacement tolerance.
pub(crate) const REBUILD_SHIFT: f64 = 1e-4;

/// Most passes of the disk table's curvature ([`Periodic`]). Each leaves out of its sweep what
/// the pass before had not found. On the paper scene, the part left out moves the gap by
/// 3.5e-13, 1.9e-14, 7.9e-16 and 2.4e-17 m after one to four passes at the jump into contact
/// (80 mW), and by 4–7e-15 and 4–6e-17 m after one and two in settled contact;
/// [`ExpScheme::straight`] needs it within about 6e-14 m there.
pub(crate) const CURVATURE_PASSES: usize = 4;

/// The passes end once the part left out moves the gaps by this fraction of the smallest
/// displacement tolerance or less.
pub(crate) const ENOUGH_UNSWEPT: f64 = 0.01;

/// Fewest and most periods a table must have lasted before the next one takes the curvature
/// (its passes cost some 20 000 of the scheme's periods, 10–20 ms). The wait doubles each time a
/// table with the curvature is replaced sooner than the wait (the state moves, as in a ramp of the
/// heater), and halves when one lasted.
pub(crate) const CURVATURE_WAIT: (usize, usize) = (64, 65_536);

/// A disk table replaced (the held Jacobian moved past [`REBUILD_SHIFT`]) within this many
/// periods of its build did not pay for itself: a rebuild costs about a millisecond, what the
/// integrator costs over the scheme in some hundred periods. The periods that follow are left to the
/// integrator, for a number that doubles with each such table in a row, up to
/// [`MAX_CHURN_SKIP`] (a heater ramp moves the Jacobian every 10–20 periods).
pub(crate) const SHORT_TABLE: usize = 128;

/// Most periods left to the integrator after tables replaced within [`SHORT_TABLE`] periods
/// of their build: the integrator's extra time over so many periods is about ten rebuilds'.
pub(crate) const MAX_CHURN_SKIP: usize = 512;

/// Substep levels: a period is `1`, `2`, `4`, `8` or `16` exponential steps.
pub(crate) const LEVELS: usize = 5;

/// Periods in a row with an estimate below [`CALM_ERROR`] after which the scheme tries half as
/// many substeps.
pub(crate) const CALM: usize = 32;

/// See [`CALM`].
pub(crate) const CALM_ERROR: f64 = 0.25;

/// Most periods run by the integrator after consecutive misses before the exponential step is
/// tried again.
pub(crate) const MAX_SKIP: usize = 64;

/// [`MAX_SKIP`] with a dither. Its attempts miss at every level in every case measured
/// (docs/benchmarks.md), and each costs a refresh at every level, with the disk's table rebuilt
/// on a wavy disk: about 4 ms, the integrator's time for some 200 periods. After 64 periods
/// that left the dither case at 3× the default's cost per period.
pub(crate) const MAX_SKIP_DITHER: usize = 4096;

/// The periodic solution of `p′ = J p + u(t)` for a sum of harmonics, tabulated over a
/// revolution: values and slopes at the disk's nodes, interpolated by cubic Hermite
/// polynomials, each interval's held in power form for a look-up of five multiply-adds
/// ([`crate::numerics::cubic_hermite_power`]).
///
/// With the curvature ([`Periodic::of_disk`]), `u` also holds what the forces leave beyond `J`
/// along the disk's sweep: `q(t) = f(x_s + p(t)) − f(x_s) − J p(t)` at the slow state `x_s`
/// the table is built at. Its lines are those of the sampled `q` over the revolution (a
/// discrete Fourier transform on the disk's nodes), each answered like a harmonic's; the mean of
/// `q` stays in the remainder. `p` is the table's own response, so `q` is found by at most
/// [`CURVATURE_PASSES`] passes: the first along the response to the disk's motion alone, each
/// next along the response the pass before found.
#[derive(Clone, Debug)]
struct Periodic {
    /// The components with a response (others stay zero).
    active: Vec<usize>,
    /// Interval `i` (from node `i` to the next), active component `j`:
    /// `[i * active.len() + j]`, the cubic's coefficients in the interval's own coordinate and
    /// its slope's in time ([`crate::numerics::cubic_hermite_power`]).
    cubics: Vec<[f64; 7]>,
    /// The largest magnitude of each component over the revolution (0 where not active).
    largest: Vec<f64>,
    /// Where the table holds the curvature: the largest magnitude of each component of what
    /// its last pass changed, the part of the response the sweep of that pass left out.
    unswept: Option<Vec<f64>>,
    /// How far the curvature's response moves the gaps (m): the reach of its first pass, 0
    /// without it.
    found: f64,
}

/// What [`Periodic::of_disk`] needs to take the curvature: `q_of(p, q)` writes the forces'
/// remainder `q` beyond `J` at the offset `p` from the slow state; the passes end once the part
/// their sweep left out moves the gaps (the positions `0..dofs`) by `enough` (m) or less, or
/// after [`CURVATURE_PASSES`].
struct Curvature<'a> {
    q_of: &'a mut dyn FnMut(&[f64], &mut [f64]),
    dofs: usize,
    enough: f64,
}

/// `C` of `(iω − J) C = U` for one `J` and many `ω`: the complex `n × n` system factored in
/// place by partial pivoting ([`crate::ode::lu::Lu`]), its storage reused.
struct Resolvent<'a> {
    j: &'a DMatrix<f64>,
    lu: Lu<Complex64, Dyn>,
    b: DVector<Complex64>,
}

impl<'a> Resolvent<'a> {
    fn new(j: &'a DMatrix<f64>) -> Self {
        let n = j.nrows();
        Resolvent {
            j,
            lu: Lu::new(Dyn(n)),
            b: DVector::zeros(n),
        }
    }

    /// `C` of `(iω − J) C = U`; `None` where the system is singular.
    fn solve(&mut self, w: f64, u: &[Complex64]) -> Option<Vec<Complex64>> {
        let n = self.j.nrows();
        for (r, ur) in u.iter().enumerate().take(n) {
            for c in 0..n {
                self.lu.m[(r, c)] = Complex64::new(-self.j[(r, c)], if r == c { w } else { 0.0 });
            }
            self.b[r] = *ur;
        }
        if !self.lu.factor() {
            return None;
        }
        self.lu.solve_mut(&mut self.b);
        self.b
            .iter()
            .all(|c| c.is_finite())
            .then(|| self.b.iter().copied().collect())
    }
}

impl Periodic {
    /// The response to the disk's motion `u = −r ẅ` on the velocities `base` (`(index, r)`):
    /// each harmonic's `C_k` solved for, then the values and slopes at the nodes summed by an
    /// inverse fast Fourier transform over the revolution (the nodes are a power of two).
    ///
    /// With `curvature` (`q_of(p, q)` writes the forces' remainder `q` beyond `J` at the offset
    /// `p` from the slow state), the response to that remainder along the disk's sweep too.
    fn of_disk(
        disk: &Disk,
        j: &DMatrix<f64>,
        base: &[(usize, f64)],
        curvature: Option<Curvature>,
    ) -> Option<Self> {
        let n = j.nrows();
        let zero = Complex64::new(0.0, 0.0);
        let mut solver = Resolvent::new(j);
        // Per component, the spectrum of p over the orders of the revolution.
        let mut spectra = vec![vec![zero; NODES]; n];
        let mut u = vec![zero; n];
        for h in disk.harmonics() {
            let w = h.order as f64 * disk.omega();
            // ẅ = −A ω² sin(ωt + φ) = Re(i A ω² e^{iφ} e^{iωt}).
            let acc =
                Complex64::new(0.0, h.amplitude * w * w) * Complex64::from_polar(1.0, h.phase);
            u.iter_mut().for_each(|x| *x = zero);
            for &(i, r) in base {
                u[i] = -r * acc;
            }
            let c = solver.solve(w, &u)?;
            for (k, ck) in c.iter().enumerate() {
                spectra[k][h.order as usize % NODES] += ck;
            }
        }
        let mut unswept = None;
        let mut found = 0.0;
        if let Some(Curvature { q_of, dofs, enough }) = curvature {
            let largest: &mut Vec<f64> = unswept.insert(vec![0.0; n]);
            // The sweep at the nodes: the linear response's, then with each pass's change.
            let mut values = real_values(&spectra.iter().map(Vec::as_slice).collect::<Vec<_>>());
            let mut response = vec![vec![zero; NODES]; n];
            for pass in 0..CURVATURE_PASSES {
                let next = Self::curvature(disk, &mut solver, &values, q_of)?;
                let changes: Vec<Vec<Complex64>> = next
                    .iter()
                    .zip(&response)
                    .map(|(now, was)| now.iter().zip(was).map(|(x, y)| x - y).collect())
                    .collect();
                let changed = real_values(&changes.iter().map(Vec::as_slice).collect::<Vec<_>>());
                for (k, change) in changed.iter().enumerate() {
                    largest[k] = 0.0;
                    for (v, c) in values[k].iter_mut().zip(change) {
                        *v += c;
                        largest[k] = largest[k].max(c.abs());
                    }
                }
                response = next;
                let reach = largest[..dofs].iter().sum::<f64>();
                if pass == 0 {
                    found = reach;
                }
                if reach <= enough {
                    break;
                }
            }
            for (s, r) in spectra.iter_mut().zip(&response) {
                for (a, b) in s.iter_mut().zip(r) {
                    *a += b;
                }
            }
        }
        let active: Vec<usize> = (0..n)
            .filter(|&k| spectra[k].iter().any(|c| c.norm() > 0.0))
            .collect();
        let na = active.len();
        let mut cubics = vec![[0.0; 7]; NODES * na];
        let mut largest = vec![0.0; n];
        // The nodes' spacing in time.
        let hn = disk.locate(0.0).2;
        for (j, &k) in active.iter().enumerate() {
            let slopes: Vec<Complex64> = spectra[k]
                .iter()
                .enumerate()
                .map(|(m, c)| Complex64::new(0.0, m as f64 * disk.omega()) * c)
                .collect();
            let both = real_values(&[&spectra[k], &slopes]);
            let (values, slopes) = (&both[0], &both[1]);
            largest[k] = values.iter().fold(0.0, |a: f64, v| a.max(v.abs()));
            for i in 0..NODES {
                let next = (i + 1) % NODES;
                cubics[i * na + j] = crate::numerics::cubic_hermite_power(
                    hn,
                    values[i],
                    slopes[i],
                    values[next],
                    slopes[next],
                );
            }
        }
        Some(Periodic {
            active,
            cubics,
            largest,
            unswept,
            found,
        })
    }

    /// The spectra of the response to the curvature `q_of` along the sweep `values` (each
    /// component at the disk's nodes): `q` at the nodes, its lines by the transform, each line's
    /// `C` from `solver` (the mean and the Nyquist line left out).
    fn curvature(
        disk: &Disk,
        solver: &mut Resolvent,
        values: &[Vec<f64>],
        q_of: &mut dyn FnMut(&[f64], &mut [f64]),
    ) -> Option<Vec<Vec<Complex64>>> {
        let n = values.len();
        let zero = Complex64::new(0.0, 0.0);
        let mut samples = vec![vec![0.0; NODES]; n];
        let (mut p, mut q) = (vec![0.0; n], vec![0.0; n]);
        for i in 0..NODES {
            for (pk, v) in p.iter_mut().zip(values) {
                *pk = v[i];
            }
            q_of(&p, &mut q);
            if q.iter().any(|x| !x.is_finite()) {
                return None;
            }
            for (l, &qk) in samples.iter_mut().zip(&q) {
                l[i] = qk;
            }
        }
        // `q(t) = Re Σ_{0<m<N/2} (2 Q_m / N) e^{i m Ω t}` besides the mean and the Nyquist line.
        let lines = real_lines(&samples);
        let scale = 2.0 / NODES as f64;
        let mut out = vec![vec![zero; NODES]; n];
        let mut u = vec![zero; n];
        for m in 1..NODES / 2 {
            for (uk, l) in u.iter_mut().zip(&lines) {
                *uk = l[m] * scale;
            }
            if u.iter().all(|c| c.norm() == 0.0) {
                continue;
            }
            let c = solver.solve(m as f64 * disk.omega(), &u)?;
            for (o, ck) in out.iter_mut().zip(c) {
                o[m] = ck;
            }
        }
        Some(out)
    }

    /// How far the part of the response the curvature's last sweep left out moves the gaps
    /// (m): the sum over the positions `0..dofs` of its largest magnitude.
    fn unswept_reach(&self, dofs: usize) -> f64 {
        self.unswept
            .as_ref()
            .map_or(0.0, |c| c[..dofs].iter().sum())
    }

    /// Whether the table holds the curvature.
    fn is_curved(&self) -> bool {
        self.unswept.is_some()
    }

    /// The largest magnitude of component `k` over the revolution.
    fn largest(&self, k: usize) -> f64 {
        self.largest[k]
    }

    /// Adds `p(t)` to `p` and `p′(t)` to `dp`.
    #[inline]
    fn add(&self, disk: &Disk, t: f64, p: &mut [f64], dp: &mut [f64]) {
        let (i, s, _) = disk.locate(t);
        let na = self.active.len();
        for (&c, q) in self.active.iter().zip(&self.cubics[i * na..(i + 1) * na]) {
            p[c] += q[0] + s * (q[1] + s * (q[2] + s * q[3]));
            dp[c] += q[4] + s * (q[5] + s * q[6]);
        }
    }
}

/// The larger of the two gaps' distances between `a` and `b` (m).
fn offset(a: Gaps, b: Gaps) -> f64 {
    (a.bulge - b.bulge).abs().max((a.pad - b.pad).abs())
}

/// `Re Σ_m s_m e^{2πi m i/N}` at every `i`, for each spectrum `s` of `spectra` (of the same
/// power-of-two length): two per transform. The real part of a sum is the sum over the
/// Hermitian part `h_m = (s_m + conj(s_{N−m}))/2`, whose transform is real; two such, `h` and
/// `g`, are one transform of `h + i g`, whose real and imaginary parts they give.
fn real_values(spectra: &[&[Complex64]]) -> Vec<Vec<f64>> {
    let Some(n) = spectra.first().map(|s| s.len()) else {
        return Vec::new();
    };
    let zero = Complex64::new(0.0, 0.0);
    let i1 = Complex64::new(0.0, 1.0);
    let mut out = vec![vec![0.0; n]; spectra.len()];
    let mut buf = vec![zero; n];
    for (pair, outs) in spectra.chunks(2).zip(out.chunks_mut(2)) {
        let hermitian = |s: &[Complex64], m: usize| 0.5 * (s[m] + s[(n - m) % n].conj());
        for (m, b) in buf.iter_mut().enumerate() {
            *b = hermitian(pair[0], m) + pair.get(1).map_or(zero, |s| i1 * hermitian(s, m));
        }
        inverse_fft(&mut buf);
        for (k, o) in outs.iter_mut().enumerate() {
            for (x, b) in o.iter_mut().zip(&buf) {
                *x = if k == 0 { b.re } else { b.im };
            }
        }
    }
    out
}

/// `Q_m = Σ_i q_i e^{−2πi m i/N}` for each real sequence `q` of `samples` (of the same
/// power-of-two length): two per transform. With `W` the transform (`e^{+…}`) of `a + i b`,
/// `A_m = (W_{N−m} + conj(W_m))/2` and `B_m = (W_{N−m} − conj(W_m))/(2i)`.
fn real_lines(samples: &[Vec<f64>]) -> Vec<Vec<Complex64>> {
    let Some(n) = samples.first().map(Vec::len) else {
        return Vec::new();
    };
    let zero = Complex64::new(0.0, 0.0);
    let mut out = vec![vec![zero; n]; samples.len()];
    let mut buf = vec![zero; n];
    for (pair, outs) in samples.chunks(2).zip(out.chunks_mut(2)) {
        for (i, b) in buf.iter_mut().enumerate() {
            *b = Complex64::new(pair[0][i], pair.get(1).map_or(0.0, |q| q[i]));
        }
        inverse_fft(&mut buf);
        for (k, o) in outs.iter_mut().enumerate() {
            for (m, x) in o.iter_mut().enumerate() {
                let (w, v) = (buf[(n - m) % n], buf[m].conj());
                *x = if k == 0 {
                    0.5 * (w + v)
                } else {
                    Complex64::new(0.0, -0.5) * (w - v)
                };
            }
        }
    }
    out
}

/// `x_i ← Σ_m x_m e^{2πi m i / N}` in place (no `1/N`), `N` a power of two: the iterative
/// radix-2 Cooley–Tukey transform with its twiddles re-anchored exactly at each stage. The
/// twiddles `e^{2πi m/N}`, `m < N/2`, are computed once: stage `len` takes every `N/len`-th,
/// whose angle `(2π/N)(k N/len)` is `(2π/len) k` to the bit (the factors are powers of two),
/// laid out stage by stage so that each stage reads its own in order.
///
/// The twiddles of the disk's [`NODES`] are computed once per process.
fn inverse_fft(x: &mut [Complex64]) {
    let n = x.len();
    debug_assert!(n.is_power_of_two());
    // Stage `len` at `half − 1`, `half = len / 2`: `n − 1` twiddles in all.
    let of = |n: usize| -> Vec<Complex64> {
        let step = 2.0 * PI / n as f64;
        let all: Vec<Complex64> = (0..n / 2)
            .map(|m| Complex64::from_polar(1.0, step * m as f64))
            .collect();
        let mut staged = Vec::with_capacity(n);
        let mut len = 2;
        while len <= n {
            staged.extend((0..len / 2).map(|k| all[k * (n / len)]));
            len *= 2;
        }
        staged
    };
    static NODE_TWIDDLES: std::sync::OnceLock<Vec<Complex64>> = std::sync::OnceLock::new();
    let own;
    let twiddles: &[Complex64] = if n == NODES {
        NODE_TWIDDLES.get_or_init(|| of(NODES))
    } else {
        own = of(n);
        &own
    };
    let bits = n.trailing_zeros();
    for i in 0..n {
        let r = i.reverse_bits() >> (usize::BITS - bits);
        if r > i {
            x.swap(i, r);
        }
    }
    let mut len = 2;
    while len <= n {
        let half = len / 2;
        let stage = &twiddles[half - 1..len - 1];
        for block in x.chunks_exact_mut(len) {
            let (lo, hi) = block.split_at_mut(half);
            for ((a, b), w) in lo.iter_mut().zip(hi.iter_mut()).zip(stage) {
                let (u, v) = (*a, *b * w);
                *a = u + v;
                *b = u - v;
            }
        }
        len *= 2;
    }
}

/// The periodic solution for the dither's lines: `V² − mean = 2 V₀ V_a sin ωt − (V_a²/2) cos 2ωt`.
#[derive(Clone, Debug)]
struct Dither {
    voltage: Voltage,
    w: f64,
    c1: Vec<Complex64>,
    c2: Vec<Complex64>,
}

impl Dither {
    fn new(voltage: Voltage, j: &DMatrix<f64>, e: &[f64]) -> Option<Self> {
        let w = 2.0 * PI * voltage.frequency;
        let v0 = voltage.dc - voltage.contact_potential;
        let va = voltage.ac_amplitude;
        // sin ωt = Re(−i e^{iωt}); cos 2ωt = Re(e^{2iωt}).
        let u1: Vec<Complex64> = e
            .iter()
            .map(|&x| Complex64::new(0.0, -2.0 * v0 * va * x))
            .collect();
        let u2: Vec<Complex64> = e
            .iter()
            .map(|&x| Complex64::new(-0.5 * va * va * x, 0.0))
            .collect();
        let mut solver = Resolvent::new(j);
        Some(Dither {
            voltage,
            w,
            c1: solver.solve(w, &u1)?,
            c2: solver.solve(2.0 * w, &u2)?,
        })
    }

    #[inline]
    fn add(&self, t: f64, p: &mut [f64], dp: &mut [f64]) {
        let (s, c) = (self.w * t).sin_cos();
        let e1 = Complex64::new(c, s);
        let e2 = e1 * e1;
        for k in 0..p.len() {
            let (a, b) = (self.c1[k] * e1, self.c2[k] * e2);
            p[k] += a.re + b.re;
            dp[k] -= self.w * a.im + 2.0 * self.w * b.im;
        }
    }
}

/// What the exponential scheme did so far ([`crate::drive::Drive::scheme_counts`]).
///
/// ```
/// use hdi_tribology::drive::{scene_zone, Command, DiskSpec, DriveOptions, DriveScheme, Plant};
/// use hdi_tribology::scene::Scene;
/// let scene = Scene::paper();
/// let opts = DriveOptions {
///     scheme: DriveScheme::Exponential,
///     disk: DiskSpec::flat(),
///     ..DriveOptions::default()
/// };
/// let mut drive = Plant::new(&scene, &scene_zone(&scene, 0.025)?, 1, opts)?.into_drive()?;
/// // A command that changes every period, the firmware case.
/// for k in 0..200 {
///     let mw = 70.0 + if k % 2 == 0 { 1e-3 } else { -1e-3 };
///     drive.step(&Command::heater_mw(mw), 50e-6)?;
/// }
/// let c = drive.scheme_counts();
/// // Each period is counted once, by whoever advanced it.
/// assert_eq!(c.exponential + c.fallbacks + c.skipped + c.spanned, 200);
/// assert!(c.exponential > 100, "{c:?}");
/// // Most of them continue the period before: one right-hand side each.
/// assert!(c.two_step > c.exponential / 2 && c.two_step <= c.exponential, "{c:?}");
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct SchemeCounts {
    /// Periods advanced by one exponential step.
    pub exponential: u64,
    /// Of those, the periods that continued the one before by the two-step method
    /// ([`crate::ode::ExponentialStepper::step_two`]), one right-hand side each.
    pub two_step: u64,
    /// Periods run by the integrator after the exponential step missed the tolerances there.
    pub fallbacks: u64,
    /// Periods run by the integrator without a try: after misses, and after disk tables replaced
    /// within 128 periods of their build (see docs/clearance.md, "The exponential scheme").
    pub skipped: u64,
    /// Periods of a command held on a flat disk without a dither, past the four after each
    /// change: left to the integrator, whose steps span them.
    pub spanned: u64,
    /// Refreshes of the held Jacobian.
    pub refreshes: u64,
    /// Rebuilds of the disk's response table.
    pub rebuilds: u64,
    /// Of those, the tables that took the forces' curvature along the disk's sweep (see
    /// docs/clearance.md, "The exponential scheme").
    pub curved: u64,
    /// Periods of a dither held on a flat disk read from its settled orbit's table (see
    /// `src/drive/orbit.rs`).
    pub orbit: u64,
    /// Tables of a dither's orbit built.
    pub orbit_tables: u64,
    /// Tries to tabulate a dither's orbit that did not pass their checks.
    pub orbit_refusals: u64,
    /// Periods of a dither on a flat disk under a heater changed within the trusted offset,
    /// read from the orbit's linearised period map (see `src/drive/orbit_map.rs`); they are
    /// also counted in `orbit`.
    pub orbit_mapped: u64,
    /// Linearised period maps built.
    pub orbit_maps: u64,
    /// Tries to build a linearised period map refused by its test or its interpolation check.
    pub orbit_map_refusals: u64,
    /// Periods that left an orbit's table: a heater offset or a deviation outside what the
    /// map's test covered, or a change the table cannot take.
    pub orbit_exits: u64,
}

/// A wait that doubles with each miss in a row: the periods left to wait, and the next wait.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Backoff {
    wait: usize,
    next: usize,
}

impl Backoff {
    /// A miss: wait twice as long as after the last one, within `[least, most]` periods.
    pub(crate) fn missed(&mut self, least: usize, most: usize) {
        self.next = (2 * self.next).clamp(least, most);
        self.wait = self.next;
    }

    /// A success: the next miss waits the least again.
    pub(crate) fn succeeded(&mut self) {
        self.next = 0;
    }

    /// Whether this period is still waited out (counted off).
    pub(crate) fn waits(&mut self) -> bool {
        let waits = self.wait > 0;
        if waits {
            self.wait -= 1;
        }
        waits
    }
}

/// The state of the exponential scheme of one drive.
#[derive(Clone, Debug)]
pub(crate) struct ExpScheme {
    /// Positions at `0..dofs`; the contact impulse's index.
    dofs: usize,
    impulse: Option<usize>,
    heat: Option<usize>,
    /// A bound on how far the known forcings move the gaps (m): the sum over the positions of
    /// their responses' largest magnitude.
    reach: f64,
    /// Where [`ExpScheme::straight`] holds without looking the contact force up.
    gentle: Option<Gentle>,
    rtol: f64,
    atol: Vec<f64>,
    /// `(index, r)` of the velocities a disk translation moves.
    base: Vec<(usize, f64)>,
    /// The held Jacobian and the period it is held for (none before the first refresh).
    held: Option<(DMatrix<f64>, f64)>,
    /// Steppers of `h / 2^l`, `l < LEVELS`, for the held Jacobian, each built when its level is
    /// first used (its φ-functions are most of a refresh's cost).
    steppers: Vec<Option<ExponentialStepper>>,
    /// The level of substeps in use, the level of the last step, and how many calm periods in a
    /// row it has had (see [`ExpScheme::attempt`]).
    level: usize,
    last_level: usize,
    calm: usize,
    disk: Option<Periodic>,
    /// The Jacobian the disk's table was built with.
    disk_j: Option<DMatrix<f64>>,
    /// The gaps of the slow state the disk's table was built at, and the time it was built.
    table_gaps: Option<Gaps>,
    built_at: f64,
    /// Periods a table must have lasted before the next one takes the curvature
    /// ([`CURVATURE_WAIT`]).
    curvature_wait: usize,
    /// Whether the next table should take the curvature: a period needed substeps or missed
    /// [`ExpScheme::straight`] under a table without it, or the last table's curvature moved
    /// the gaps by more than its passes' end.
    curvature_needed: bool,
    dither: Option<Dither>,
    /// The state at the drive's time, when the scheme holds it (the integrator's is stale).
    pub(crate) owned: Option<[f64; MAX_STATE]>,
    /// Periods to leave to the integrator after misses.
    misses: Backoff,
    /// Periods to leave to the integrator after tables replaced within [`SHORT_TABLE`].
    churn: Backoff,
    pub(crate) counts: SchemeCounts,
    /// Work vectors.
    p: Vec<f64>,
    dp: Vec<f64>,
    /// The time (its bits) whose known forcings `p`, `dp` hold, as the forcings are now: a
    /// period that starts where the one before ended reads them instead of computing them
    /// again (the same numbers).
    known_at: Option<u64>,
    z0: Vec<f64>,
    f0: Vec<f64>,
    z1: Vec<f64>,
    /// Where the last period advanced by one step ended, and its inputs: the next period may
    /// take the two-step method from there ([`ExpScheme::continuation`]). Its state `x`, `z`
    /// and, where the two-step method evaluated it, the right-hand side of `z` are in `end_x`,
    /// `end_z`, `end_f`.
    last_end: Option<StepEnd>,
    end_x: Vec<f64>,
    end_z: Vec<f64>,
    end_f: Vec<f64>,
    /// The end of the last one-step period `step` ran, for `last_end` when the period is taken:
    /// whether the right-hand side there is known; `z` and it in `ended_z`, `ended_f`.
    ended: Option<bool>,
    ended_z: Vec<f64>,
    ended_f: Vec<f64>,
    /// The settled orbit of a dither held on a flat disk, and the wait before the next try to
    /// tabulate it after a refusal.
    pub(crate) orbit: Option<Orbit>,
    pub(crate) orbit_wait: Backoff,
    /// The orbit's period map linearised in the heater power, when it passed its test.
    pub(crate) orbit_map: Option<OrbitMap>,
    /// Periods read from the orbit's table since it was built, and whether it was built under
    /// a changing heater and has not yet served `ORBIT_PAYBACK` of them (see
    /// `src/drive/plant.rs`).
    pub(crate) orbit_served: usize,
    pub(crate) orbit_unpaid: bool,
    /// The heater's drift per period, averaged (W; see `src/drive/plant.rs`).
    pub(crate) heater_drift: f64,
    /// Whether the last period was read from the orbit's table alone, at the orbit's heater
    /// power: the state is then the orbit's, and so is the next period's under the same
    /// command.
    pub(crate) on_orbit: bool,
    /// Periods since the voltage or the clearance last changed, or the heater by more than
    /// the map's test covers (the orbit's settling periods).
    pub(crate) voltage_held: usize,
}

/// The end of a period advanced by one exponential step (its state in `ExpScheme::end_x`,
/// `end_z`, `end_f`): its time, whether the right-hand side there is known (the two-step method
/// evaluated it), and the inputs it ran under (the heater's power, the voltage, the clearance
/// offset).
#[derive(Clone, Copy, Debug)]
struct StepEnd {
    t: f64,
    f_known: bool,
    heater: f64,
    voltage: Voltage,
    clearance: f64,
}

/// Per gap (bulge, pad), the stretch over which every contact slope is within `slope` (N/m)
/// ([`crate::force::InterfaceForces::contact_gentle`]). It serves [`ExpScheme::straight`]
/// for every bound `S` from `slope` up to `4 slope`: a stretch within a tighter bound is within
/// the looser one, so the verdict does not depend on which was found, and a reach or period
/// that moves a little (a refresh) does not find it again (about 1 M instructions).
#[derive(Clone, Copy, Debug)]
struct Gentle {
    slope: f64,
    stretches: [(f64, f64); 2],
}

/// How one attempt went.
pub(crate) enum Attempt<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    /// The state at the period's end and the error estimate.
    Done(OVector<f64, D>, f64),
    /// Missed the tolerances (the estimate): the integrator runs the period.
    Missed,
}

impl ExpScheme {
    pub(crate) fn new(
        layout: &StateLayout,
        rtol: f64,
        atol: Vec<f64>,
        base: Vec<(usize, f64)>,
    ) -> Self {
        let n = atol.len();
        ExpScheme {
            dofs: layout.dofs,
            impulse: layout.contact_impulse,
            heat: layout.heat,
            reach: 0.0,
            gentle: None,
            rtol,
            atol,
            base,
            held: None,
            steppers: Vec::new(),
            level: 0,
            last_level: 0,
            calm: 0,
            disk: None,
            disk_j: None,
            table_gaps: None,
            built_at: f64::NEG_INFINITY,
            curvature_wait: CURVATURE_WAIT.0,
            curvature_needed: false,
            dither: None,
            owned: None,
            misses: Backoff::default(),
            churn: Backoff::default(),
            counts: SchemeCounts::default(),
            p: vec![0.0; n],
            dp: vec![0.0; n],
            known_at: None,
            z0: vec![0.0; n],
            f0: vec![0.0; n],
            z1: vec![0.0; n],
            last_end: None,
            end_x: vec![0.0; n],
            end_z: vec![0.0; n],
            end_f: vec![0.0; n],
            ended: None,
            ended_z: vec![0.0; n],
            ended_f: vec![0.0; n],
            orbit: None,
            orbit_wait: Backoff::default(),
            orbit_map: None,
            on_orbit: false,
            orbit_served: 0,
            orbit_unpaid: false,
            heater_drift: 0.0,
            voltage_held: 0,
        }
    }

    /// The scheme's per-component absolute tolerances (the drive's contact tolerances).
    pub(crate) fn atol(&self) -> &[f64] {
        &self.atol
    }

    /// The scheme's relative tolerance.
    pub(crate) fn rtol(&self) -> f64 {
        self.rtol
    }

    /// The dither switched off: its lines and the wait its misses ran up (up to
    /// [`MAX_SKIP_DITHER`] periods) are dropped, and the next period is tried.
    pub(crate) fn dither_off(&mut self) {
        self.dither = None;
        self.known_at = None;
        self.reach = self.reach_of_forcings();
        self.misses = Backoff::default();
    }

    /// Whether the next period is left to the integrator without a try (counted): after misses,
    /// where the integrator holds the state, and after tables replaced within [`SHORT_TABLE`]
    /// periods, where the plant hands it the scheme's state ([`ExpScheme::owned`]).
    pub(crate) fn skips(&mut self) -> bool {
        if self.churn.waits() || (self.owned.is_none() && self.misses.waits()) {
            self.counts.skipped += 1;
            true
        } else {
            false
        }
    }

    /// Builds the stepper of `level` for the held Jacobian if it is not built yet; whether there
    /// is one.
    fn stepper(&mut self, level: usize) -> bool {
        if self.steppers[level].is_none() {
            let Some((j, h)) = &self.held else {
                return false;
            };
            match ExponentialStepper::new(j, h / (1 << level) as f64) {
                Ok(s) => self.steppers[level] = Some(s),
                Err(_) => return false,
            }
        }
        true
    }

    /// The Jacobian at `(t, x − p(t))`, the per-`V²` vector `e` there, and everything built on them
    /// (the stepper of period `h`, the dither's response; the disk's table when there is none
    /// or `J` moved by more than [`REBUILD_SHIFT`] from the one it was built with).
    fn refresh<D: Dim>(
        &mut self,
        sys: &SliderSystem,
        disk: &Disk,
        t: f64,
        x: &OVector<f64, D>,
        h: f64,
    ) -> bool
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        let n = x.len();
        let dim = x.shape_generic().0;
        // Linearised about the state less the known forcings' responses (as held so far): the
        // slow state, whose Jacobian does not swing with the disk's phase.
        Self::known(disk, &self.disk, &self.dither, t, &mut self.p, &mut self.dp);
        // The table or the dither's lines may change below.
        self.known_at = None;
        let slow = state_vector::<D>(dim, |i| x[i] - self.p[i]);
        let mut jd = OMatrix::<f64, D, D>::zeros_generic(dim, dim);
        OdeSystem::<D>::jacobian(sys, t, &slow, &mut jd);
        let j = DMatrix::from_iterator(n, n, jd.iter().copied());
        if j.iter().any(|v| !v.is_finite()) {
            return false;
        }
        self.steppers.clear();
        self.steppers.resize(LEVELS, None);
        self.held = Some((j.clone(), h));
        if !self.stepper(0) {
            return false;
        }
        self.counts.refreshes += 1;
        // The integrals' rows (their columns are zero) do not move the other states: a change
        // there leaves the table's mechanical response as it was.
        let integral = |r: usize| self.impulse == Some(r) || self.heat == Some(r);
        let shifted = match &self.disk_j {
            None => true,
            Some(jp) => (0..n).filter(|&r| !integral(r)).any(|r| {
                let scale = (0..n).map(|c| jp[(r, c)].abs()).fold(0.0, f64::max);
                (0..n).any(|c| (j[(r, c)] - jp[(r, c)]).abs() > REBUILD_SHIFT * scale)
            }),
        };
        // The curvature is taken with the voltage held: under a dither, `V²` swings within
        // the period and its product with the disk's sweep is not periodic in the revolution.
        let v = sys.inputs().voltage;
        let dithered = v.is_time_dependent();
        let gaps = sys.gaps(t, &slow);
        let lasted = self.lasted(t, h);
        let curving = !dithered && lasted && self.curvature_needed;
        let curved = self.disk.as_ref().is_some_and(Periodic::is_curved);
        let stale = self.disk.as_ref().is_some_and(|d| {
            (d.is_curved() && dithered)
                || (curving
                    && (!d.is_curved()
                        || self
                            .table_gaps
                            .is_some_and(|r| offset(gaps, r) > d.unswept_reach(self.dofs))))
        });
        if !disk.is_flat() && (self.disk.is_none() || shifted || stale) {
            if shifted && self.disk.is_some() {
                if t - self.built_at < SHORT_TABLE as f64 * h {
                    self.churn.missed(1, MAX_CHURN_SKIP);
                } else {
                    self.churn.succeeded();
                }
            }
            if curved {
                self.curvature_wait = if lasted {
                    (self.curvature_wait / 2).max(CURVATURE_WAIT.0)
                } else {
                    (self.curvature_wait * 2).min(CURVATURE_WAIT.1)
                };
            }
            let table = if !curving {
                Periodic::of_disk(disk, &j, &self.base, None)
            } else {
                let dim = slow.shape_generic().0;
                let mut f_slow = OVector::<f64, D>::zeros_generic(dim, nalgebra::U1);
                OdeSystem::<D>::rhs(sys, t, &slow, &mut f_slow);
                let mut fx = f_slow.clone();
                let mut q_of = |p: &[f64], q: &mut [f64]| {
                    let x = state_vector::<D>(dim, |i| slow[i] + p[i]);
                    OdeSystem::<D>::rhs(sys, t, &x, &mut fx);
                    for (r, qr) in q.iter_mut().enumerate() {
                        let jp: f64 = p.iter().enumerate().map(|(c, pc)| j[(r, c)] * pc).sum();
                        *qr = fx[r] - f_slow[r] - jp;
                    }
                };
                let enough = ENOUGH_UNSWEPT * self.min_position_atol();
                let curvature = Curvature {
                    q_of: &mut q_of,
                    dofs: self.dofs,
                    enough,
                };
                Periodic::of_disk(disk, &j, &self.base, Some(curvature))
            };
            self.disk = table;
            self.disk_j = Some(j.clone());
            self.table_gaps = Some(gaps);
            self.built_at = t;
            if let Some(d) = self.disk.as_ref().filter(|d| d.is_curved()) {
                self.counts.curved += 1;
                // Needed again only where the curvature moves the gaps by more than the passes
                // leave out at their end, or a sign of need comes anew.
                self.curvature_needed = d.found > ENOUGH_UNSWEPT * self.min_position_atol();
            }
            self.counts.rebuilds += 1;
            if self.disk.is_none() {
                return false;
            }
        }
        self.dither = None;
        if dithered {
            let e = per_volt2(sys, t, &slow);
            self.dither = Dither::new(v, &j, &e);
            if self.dither.is_none() {
                return false;
            }
        }
        self.reach = self.reach_of_forcings();
        true
    }

    /// The smallest of the positions' absolute tolerances (m).
    fn min_position_atol(&self) -> f64 {
        self.atol[..self.dofs]
            .iter()
            .fold(f64::INFINITY, |a, &b| a.min(b))
    }

    /// Whether the disk's table has lasted [`ExpScheme::curvature_wait`] periods of `h` at `t`.
    fn lasted(&self, t: f64, h: f64) -> bool {
        t - self.built_at >= self.curvature_wait as f64 * h
    }

    /// Whether a refresh at `t` would rebuild the disk's table with the curvature: one without
    /// it, or one whose slow gaps are off by `off` (m), more than the part its sweep left out
    /// (see [`ExpScheme::refresh`]).
    fn wants_curvature(&self, sys: &SliderSystem, t: f64, h: f64, off: f64) -> bool {
        !sys.inputs().voltage.is_time_dependent()
            && self.curvature_needed
            && self.lasted(t, h)
            && self
                .disk
                .as_ref()
                .is_some_and(|d| !d.is_curved() || off > d.unswept_reach(self.dofs))
    }

    /// How far the known forcings move the gaps (m): the sum over the positions of their
    /// responses' largest magnitude.
    fn reach_of_forcings(&self) -> f64 {
        (0..self.dofs)
            .map(|k| {
                let table = self.disk.as_ref().map_or(0.0, |d| d.largest(k));
                let lines = self
                    .dither
                    .as_ref()
                    .map_or(0.0, |d| d.c1[k].norm() + d.c2[k].norm());
                table + lines
            })
            .sum()
    }

    /// Whether the contact force is straight enough over the gaps the known forcings sweep for
    /// one exponential step: its remainder beyond the held linear part, about
    /// `½ |F_c″| A²` over the reach `A`, oscillates within the period at the forcings'
    /// frequencies, where the step's estimate (from the period's ends) cannot see it. Its
    /// effect on the contact impulse over a period, `h A |F_c′(d − A) − F_c′(d + A)| / 4`, must
    /// be within the impulse's tolerance.
    ///
    /// Where each gap's sweep `[d − A, d + A]` lies in a stretch whose contact slopes are all
    /// within `S = atol / (4 h A)` (found for half of that, and kept while the reach and period
    /// move within a factor of two; [`Gentle`]), the bound is at most
    /// `h A (2S + 2S) / 4 = atol / 4`, and the check holds without the two look-ups: the same
    /// verdict.
    ///
    /// Where the disk's table holds the curvature along the sweep from the slow gaps `d_r` it
    /// was built at ([`Periodic`]), the remainder left is `(F_c′(d_r + δ(t)) − F_c′(d_r)) D`,
    /// with `D` the slow gaps' offset from `d_r` plus the reach of the part of the response the
    /// last pass's sweep left out: its impulse over the period is within
    /// `h D |F_c′(d − A) − F_c′(d + A)|`, and that bound passes the check too. When it misses by
    /// an offset larger than that reach, and a table built at the slow state here would pass,
    /// the Jacobian and the table are taken afresh there ([`ExpScheme::refresh`]) and the
    /// bound checked again.
    pub(crate) fn straight<D: Dim>(
        &mut self,
        sys: &SliderSystem,
        disk: &Disk,
        t: f64,
        x: &OVector<f64, D>,
        h: f64,
    ) -> bool
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        let (Some(i), a) = (self.impulse, self.reach) else {
            return true;
        };
        if a == 0.0 {
            return true;
        }
        let forces = sys.model().forces();
        let budget = self.atol[i] / (4.0 * h * a);
        let gentle = match self.gentle {
            Some(g) if g.slope <= budget && budget <= 4.0 * g.slope => g.stretches,
            _ => {
                // Found for half the budget: it then serves budgets from half to twice this one.
                let slope = 0.5 * budget;
                let stretches = forces.contact_gentle(slope);
                self.gentle = Some(Gentle { slope, stretches });
                stretches
            }
        };
        let g = sys.gaps(t, x);
        let within = |d: f64, (from, to): (f64, f64)| d - a >= from && d + a <= to;
        if within(g.bulge, gentle[0]) && within(g.pad, gentle[1]) {
            return true;
        }
        let slope = |s: f64| {
            let c = forces.contact(Gaps {
                bulge: g.bulge + s,
                pad: g.pad + s,
            });
            c.d_bulge + c.d_pad
        };
        let spread = (slope(-a) - slope(a)).abs();
        let atol = self.atol[i];
        if 0.25 * h * a * spread <= atol {
            return true;
        }
        let curved = |s: &Self| {
            s.disk
                .as_ref()
                .filter(|d| d.is_curved())
                .map(|d| d.unswept_reach(s.dofs))
        };
        let mut off = f64::INFINITY;
        if let Some(reach) = curved(self) {
            off = self.slow_offset(sys, disk, t, x);
            if h * (off + reach) * spread <= atol {
                return true;
            }
            if 2.0 * h * reach * spread > atol {
                // A table built here would miss too.
                return false;
            }
        }
        self.curvature_needed = true;
        if self.wants_curvature(sys, t, h, off) && self.refresh(sys, disk, t, x, h) {
            if let Some(reach) = curved(self) {
                return h * (self.slow_offset(sys, disk, t, x) + reach) * spread <= atol;
            }
        }
        false
    }

    /// The slow gaps' offset (m) at `(t, x)` from those the disk's table was built at
    /// ([`offset`]); the known forcings at `t` are left in the work vectors.
    fn slow_offset<D: Dim>(
        &mut self,
        sys: &SliderSystem,
        disk: &Disk,
        t: f64,
        x: &OVector<f64, D>,
    ) -> f64
    where
        DefaultAllocator: Allocator<D>,
    {
        let Some(at) = self.table_gaps else {
            return f64::INFINITY;
        };
        if self.known_at != Some(t.to_bits()) {
            Self::known(disk, &self.disk, &self.dither, t, &mut self.p, &mut self.dp);
            self.known_at = Some(t.to_bits());
        }
        let mut slow = [0.0; MAX_STATE];
        for (s, (xi, pi)) in slow.iter_mut().zip(x.iter().zip(&self.p)) {
            *s = xi - pi;
        }
        offset(sys.gaps(t, &slow[..]), at)
    }

    /// `p(t)` and `p′(t)` of the known forcings into the work vectors.
    fn known(
        disk: &Disk,
        table: &Option<Periodic>,
        dither: &Option<Dither>,
        t: f64,
        p: &mut [f64],
        dp: &mut [f64],
    ) {
        p.iter_mut().for_each(|x| *x = 0.0);
        dp.iter_mut().for_each(|x| *x = 0.0);
        if let Some(d) = table {
            d.add(disk, t, p, dp);
        }
        if let Some(d) = dither {
            d.add(t, p, dp);
        }
    }

    /// Whether the period from `(t0, x0)` continues the last one, for the two-step method
    /// ([`ExponentialStepper::step_two`]): one step a period, no dither, a stepper with a step
    /// before, and the last period advanced by one step ended here, to the bit in the state,
    /// under the same voltage and clearance. Its start `z` is then the last period's end
    /// (`end_z`), and so is `F(t0, z)` where the last period evaluated it (`end_f`, then
    /// `Some(true)`), with a changed heater power added ([`SliderSystem::heater_shift`];
    /// without a thermal lag the power moves the gaps, and `F` is evaluated afresh: `Some(false)`).
    /// `None`: the one-step method runs, as after a refresh, a miss or a change of level.
    fn continuation<D: Dim>(
        &mut self,
        sys: &SliderSystem,
        t0: f64,
        x0: &OVector<f64, D>,
        h: f64,
        level: usize,
    ) -> Option<bool>
    where
        DefaultAllocator: Allocator<D>,
    {
        let end = self.last_end.take()?;
        let inputs = sys.inputs();
        let continues = level == 0
            && self.dither.is_none()
            && self.steppers[0]
                .as_ref()
                .is_some_and(ExponentialStepper::has_previous)
            && (t0 - end.t).abs() <= 1e-9 * h
            && end.voltage == inputs.voltage
            && end.clearance == inputs.clearance_offset
            && x0
                .iter()
                .zip(&self.end_x)
                .all(|(a, b)| a.to_bits() == b.to_bits());
        if !continues {
            return None;
        }
        let heater = inputs.heater.power(t0);
        if !end.f_known || heater == end.heater {
            return Some(end.f_known);
        }
        match sys.heater_shift(x0, end.heater, heater) {
            Some((i, delta)) => {
                self.end_f[i] += delta;
                Some(true)
            }
            None => Some(false),
        }
    }

    /// `2^level` exponential steps over `[t0, t0 + h]` from `x0`: the state at its end and the
    /// largest error estimate.
    fn step<D: Dim>(
        &mut self,
        sys: &SliderSystem,
        disk: &Disk,
        t0: f64,
        h: f64,
        x0: &OVector<f64, D>,
        level: usize,
    ) -> (OVector<f64, D>, f64)
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        let n = x0.len();
        let dim = x0.shape_generic().0;
        // A level that cannot be built misses (an infinite estimate).
        self.stepper(level);
        if level != self.last_level {
            if let Some(s) = self.steppers[level].as_mut() {
                s.forget();
            }
            self.last_level = level;
        }
        let mut cont = self.continuation(sys, t0, x0, h, level);
        let ExpScheme {
            rtol,
            atol,
            steppers,
            disk: table,
            dither,
            p,
            dp,
            known_at,
            z0,
            f0,
            z1,
            end_z,
            end_f,
            ended,
            ended_z,
            ended_f,
            ..
        } = self;
        *ended = None;
        let Some(stepper) = steppers[level].as_mut() else {
            return (x0.clone(), f64::INFINITY);
        };
        let m = 1usize << level;
        let hs = h / m as f64;
        let (table, dither) = (&*table, &*dither);
        // Without a known forcing `p` is zero and `z` is `x`: the sums with it are skipped.
        let forced = table.is_some() || dither.is_some();
        let mut x = x0.clone();
        let mut fx = OVector::<f64, D>::zeros_generic(dim, nalgebra::U1);
        let mut err = 0.0f64;
        // Whether the last substep was the two-step method's: its end and the right-hand side
        // there are in `z1` and `ended_f`, the next substep's start.
        let mut inner_known = false;
        for k in 0..m {
            let ts = t0 + k as f64 * hs;
            let c = if k == 0 { cont.take() } else { None };
            if inner_known {
                // `z1` was read into `x`; `ended_f` is scratch when the period has substeps.
                std::mem::swap(z0, z1);
                std::mem::swap(f0, ended_f);
            } else if c == Some(true) {
                // The last period's end, and its right-hand side there. `continuation` took
                // `last_end`: `end_z` and `end_f` are not read again before the next accepted
                // period fills them, and are swapped in rather than copied.
                std::mem::swap(z0, end_z);
                std::mem::swap(f0, end_f);
            } else {
                OdeSystem::<D>::rhs(sys, ts, &x, &mut fx);
                if forced {
                    if *known_at != Some(ts.to_bits()) {
                        Self::known(disk, table, dither, ts, p, dp);
                    }
                    for i in 0..n {
                        f0[i] = fx[i] - dp[i];
                    }
                } else {
                    f0.copy_from_slice(fx.as_slice());
                }
                match c {
                    Some(_) => std::mem::swap(z0, end_z),
                    None if forced => {
                        for i in 0..n {
                            z0[i] = x[i] - p[i];
                        }
                    }
                    None => z0.copy_from_slice(x.as_slice()),
                }
            }
            let mut pw = [0.0; MAX_STATE];
            let mut dpw = [0.0; MAX_STATE];
            // The time of the forcings in `pw`, `dpw`: the stage at the substep's end is the
            // end itself, whose forcings are then not computed again.
            let mut at = f64::NAN;
            let f = |t: f64, z: &[f64], dz: &mut [f64]| {
                let mut fx = OVector::<f64, D>::zeros_generic(dim, nalgebra::U1);
                if !forced {
                    let x = state_vector::<D>(dim, |i| z[i]);
                    OdeSystem::<D>::rhs(sys, t, &x, &mut fx);
                    dz.copy_from_slice(fx.as_slice());
                    return;
                }
                let (pw, dpw) = (&mut pw[..n], &mut dpw[..n]);
                Self::known(disk, table, dither, t, pw, dpw);
                at = t;
                let x = state_vector::<D>(dim, |i| z[i] + pw[i]);
                OdeSystem::<D>::rhs(sys, t, &x, &mut fx);
                for i in 0..n {
                    dz[i] = fx[i] - dpw[i];
                }
            };
            // The two-step method for a period that continues the last one and for every
            // substep after a period's first, which continues the substep before.
            let e = if c.is_some() || k > 0 {
                if c.is_some() {
                    *ended = Some(true);
                }
                inner_known = true;
                stepper.step_two(ts, z0, f0, f, (*rtol, atol), z1, ended_f)
            } else {
                Some(stepper.step(ts, z0, f0, f, (*rtol, atol), z1))
            };
            // `continuation` checked that the stepper has a step before, and a substep after
            // the first has the one before it.
            err = err.max(e.unwrap_or(f64::INFINITY));
            if forced {
                let te = if k + 1 == m { t0 + h } else { ts + hs };
                if te.to_bits() == at.to_bits() {
                    p.copy_from_slice(&pw[..n]);
                    dp.copy_from_slice(&dpw[..n]);
                } else {
                    Self::known(disk, table, dither, te, p, dp);
                }
                *known_at = Some(te.to_bits());
                for i in 0..n {
                    x[i] = z1[i] + p[i];
                }
            } else {
                x.as_mut_slice().copy_from_slice(z1);
            }
        }
        if m == 1 {
            // `z1` is the substeps' output, not read again.
            std::mem::swap(ended_z, z1);
            ended.get_or_insert(false);
        }
        (x, err)
    }

    /// Tries one period `[t0, t0 + h]` from `x0`: the stepper as held, then, on a miss, once
    /// more after a refresh at `(t0, x0)`.
    pub(crate) fn attempt<D: Dim>(
        &mut self,
        sys: &SliderSystem,
        disk: &Disk,
        t0: f64,
        h: f64,
        x0: &OVector<f64, D>,
    ) -> Attempt<D>
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        let stale = match (&self.held, &self.dither) {
            (None, _) => true,
            (Some((_, held)), _) if *held != h => true,
            (_, d) => {
                let v = sys.inputs().voltage;
                let want = v.is_time_dependent();
                match d {
                    Some(d) => !want || d.voltage != v,
                    None => want,
                }
            }
        } || (self.level > 0 && self.wants_curvature(sys, t0, h, 0.0));
        if self.level > 0 && !self.disk.as_ref().is_some_and(Periodic::is_curved) {
            self.curvature_needed = true;
        }
        let mut fresh = false;
        if stale {
            if !self.refresh(sys, disk, t0, x0, h) {
                return self.missed();
            }
            fresh = true;
        }
        let mut level = self.level;
        let (x1, err) = loop {
            let (x1, err) = self.step(sys, disk, t0, h, x0, level);
            if err <= 1.0 {
                break (x1, err);
            }
            if !fresh {
                if !self.refresh(sys, disk, t0, x0, h) {
                    return self.missed();
                }
                fresh = true;
            } else if level + 1 < LEVELS {
                level += 1;
            } else {
                break (x1, err);
            }
        };
        // The step holds the branches of the stateful terms as they were at its start: a
        // period that ends past a switch is left to the integrator, which stops on it.
        let switched = (0..OdeSystem::<D>::switches(sys))
            .any(|i| OdeSystem::<D>::switching(sys, i, t0 + h, &x1) < 0.0);
        if err <= 1.0 && x1.iter().all(|v| v.is_finite()) && !switched {
            self.misses.succeeded();
            self.counts.exponential += 1;
            if let (0, Some(f_known)) = (level, self.ended.take()) {
                self.counts.two_step += u64::from(f_known);
                let inputs = sys.inputs();
                self.end_x.copy_from_slice(x1.as_slice());
                std::mem::swap(&mut self.end_z, &mut self.ended_z);
                std::mem::swap(&mut self.end_f, &mut self.ended_f);
                self.last_end = Some(StepEnd {
                    t: t0 + h,
                    f_known,
                    heater: inputs.heater.power(t0),
                    voltage: inputs.voltage,
                    clearance: inputs.clearance_offset,
                });
            }
            // Up at once when the period needed it; down after CALM periods well within the
            // tolerances.
            if level != self.level || err > CALM_ERROR {
                self.calm = 0;
            } else {
                self.calm += 1;
            }
            self.level = level;
            if self.calm >= CALM && self.level > 0 {
                self.level -= 1;
                self.calm = 0;
            }
            Attempt::Done(x1, err)
        } else {
            self.missed()
        }
    }

    pub(crate) fn missed<D: Dim>(&mut self) -> Attempt<D>
    where
        DefaultAllocator: Allocator<D>,
    {
        self.counts.fallbacks += 1;
        let most = if self.dither.is_some() {
            MAX_SKIP_DITHER
        } else {
            MAX_SKIP
        };
        self.misses.missed(1, most);
        self.owned = None;
        for s in self.steppers.iter_mut().flatten() {
            s.forget();
        }
        Attempt::Missed
    }
}

/// `∂f/∂(V²)` at `(t, x)`: the right-hand side under `V² = 1` less that under `V² = 0` (the
/// interface force is affine in `V²`), the other inputs kept.
fn per_volt2<D: Dim>(sys: &SliderSystem, t: f64, x: &OVector<f64, D>) -> Vec<f64>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    let at = |v0: f64| {
        let mut s = sys.clone();
        let cp = sys.inputs().voltage.contact_potential;
        let inputs = Inputs {
            voltage: Voltage {
                dc: cp + v0,
                ac_amplitude: 0.0,
                frequency: 0.0,
                contact_potential: cp,
            },
            ..sys.inputs().clone()
        };
        s.set_inputs(inputs);
        let mut f = OVector::<f64, D>::zeros_generic(x.shape_generic().0, nalgebra::U1);
        OdeSystem::<D>::rhs(&s, t, x, &mut f);
        f
    };
    let (one, zero) = (at(1.0), at(0.0));
    one.iter().zip(zero.iter()).map(|(a, b)| a - b).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The transform against the direct sum.
    #[test]
    fn the_fft_is_the_direct_sum() {
        let n = 64;
        let x: Vec<Complex64> = (0..n)
            .map(|m| Complex64::new((m as f64 * 0.37).sin(), (m as f64 * 1.3).cos()))
            .collect();
        let mut y = x.clone();
        inverse_fft(&mut y);
        for (i, yi) in y.iter().enumerate() {
            let direct: Complex64 = x
                .iter()
                .enumerate()
                .map(|(m, xm)| {
                    xm * Complex64::from_polar(1.0, 2.0 * PI * (m * i) as f64 / n as f64)
                })
                .sum();
            assert!((yi - direct).norm() < 1e-12, "{i}");
        }
    }

    /// The transform on the disk's nodes (its twiddles kept) against the same on a grid of its
    /// own, at a few outputs, and the resolvent against the residual of the system it solves.
    #[test]
    fn the_node_transform_and_the_resolvent() {
        let x: Vec<Complex64> = (0..NODES)
            .map(|m| {
                Complex64::new((m as f64 * 0.37).sin(), (m as f64 * 1.3).cos()) / (1.0 + m as f64)
            })
            .collect();
        for _ in 0..2 {
            let mut y = x.clone();
            inverse_fft(&mut y);
            for i in [0, 1, 77, NODES - 1] {
                let direct: Complex64 = x
                    .iter()
                    .enumerate()
                    .map(|(m, xm)| {
                        xm * Complex64::from_polar(
                            1.0,
                            2.0 * PI * ((m * i) % NODES) as f64 / NODES as f64,
                        )
                    })
                    .sum();
                assert!((y[i] - direct).norm() < 1e-11, "{i}: {} vs {direct}", y[i]);
            }
        }
        // A damped oscillator and a lag, as a slider's Jacobian has them.
        let j = DMatrix::from_row_slice(3, 3, &[0.0, 1.0, 0.0, -4e10, -2e4, 3e5, 0.0, 0.0, -1e4]);
        let u = [
            Complex64::new(1.0, -2.0),
            Complex64::new(0.5, 3.0),
            Complex64::new(-1.0, 0.25),
        ];
        let mut r = Resolvent::new(&j);
        for w in [0.0, 1e3, 2e5, 3e6] {
            let c = r.solve(w, &u).unwrap();
            for (row, uk) in u.iter().enumerate() {
                let jc: Complex64 = (0..3).map(|col| c[col] * j[(row, col)]).sum();
                let residual = Complex64::new(0.0, w) * c[row] - jc - uk;
                let scale = (0..3)
                    .map(|col| (c[col] * j[(row, col)]).norm())
                    .sum::<f64>()
                    + uk.norm();
                assert!(
                    residual.norm() <= 1e-13 * scale,
                    "ω {w}, row {row}: {residual}"
                );
            }
        }
        // Two real outputs per transform, three inputs (one unpaired), against direct sums.
        let n = 64;
        let spectra: Vec<Vec<Complex64>> = (0..3)
            .map(|k| {
                (0..n)
                    .map(|m| {
                        Complex64::new(
                            (m as f64 * 0.3 + k as f64).sin(),
                            (m as f64 * 0.7 - k as f64).cos(),
                        )
                    })
                    .collect()
            })
            .collect();
        let values = real_values(&spectra.iter().map(Vec::as_slice).collect::<Vec<_>>());
        let lines = real_lines(&values);
        for (k, s) in spectra.iter().enumerate() {
            for (i, value) in values[k].iter().enumerate() {
                let direct: f64 = s
                    .iter()
                    .enumerate()
                    .map(|(m, c)| {
                        (c * Complex64::from_polar(1.0, 2.0 * PI * ((m * i) % n) as f64 / n as f64))
                            .re
                    })
                    .sum();
                assert!((value - direct).abs() < 1e-12, "{k} {i}");
            }
            for (m, line) in lines[k].iter().enumerate() {
                let direct: Complex64 = values[k]
                    .iter()
                    .enumerate()
                    .map(|(i, q)| {
                        q * Complex64::from_polar(1.0, -2.0 * PI * ((m * i) % n) as f64 / n as f64)
                    })
                    .sum();
                assert!((line - direct).norm() < 1e-11, "{k} {m}");
            }
        }
        // Singular at ω = 0 when J is.
        let singular = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
        assert!(Resolvent::new(&singular).solve(0.0, &u[..2]).is_none());
    }
}
