//! Compact dense output: per step, the monomial coefficients of the method's interpolant.

use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OVector};
use serde::{Deserialize, Serialize};

/// The interpolant of one step: `y(t0 + θh) = Σ_m a_m θ^m`, `θ ∈ [0, 1]`.
///
/// Coefficients are stored component-major within each power: `coeffs[m * n + i]` is
/// component `i` of `a_m`.
#[derive(Debug, Clone, Default)]
pub(crate) struct StepPoly {
    pub t0: f64,
    pub h: f64,
    pub n: usize,
    pub coeffs: Vec<f64>,
}

/// The interpolant of the last accepted step of an [`super::Integrator`]
/// ([`super::Integrator::last_step`]): `y(t0 + θh) = Σ_m a_m θ^m` on `θ ∈ [0, 1]`, with
/// `coeffs[m * n + i]` component `i` of `a_m`.
///
/// ```
/// use hdi_tribology::ode::{FnSystem, Integrator, Method, Options};
/// use nalgebra::Vector1;
/// let sys = FnSystem::new(|_t, y: &Vector1<f64>, dy: &mut Vector1<f64>| dy[0] = -y[0]);
/// let o = Options::default().rtol(1e-10).atol(1e-12).dense(true);
/// let mut it = Integrator::new(sys, 0.0, Vector1::new(1.0), 1.0, Method::Tsit5, &o)?;
/// it.step()?;
/// let p = it.last_step();
/// let theta = 0.5;
/// let y: f64 = (0..p.coeffs.len() / p.n).rev().fold(0.0, |acc, m| acc * theta + p.coeffs[m * p.n]);
/// assert!((y - (-(p.t0 + theta * p.h)).exp()).abs() < 1e-8);
/// # Ok::<(), hdi_tribology::ode::OdeError>(())
/// ```
#[derive(Clone, Copy, Debug)]
pub struct StepPolynomial<'a> {
    /// Start of the step.
    pub t0: f64,
    /// Length of the step.
    pub h: f64,
    /// Number of components.
    pub n: usize,
    /// Monomial coefficients, component-major within each power.
    pub coeffs: &'a [f64],
}

impl StepPolynomial<'_> {
    /// The interpolated state at `t` (inside the step) into `out`, one entry per component.
    ///
    /// ```
    /// use hdi_tribology::ode::{FnSystem, Integrator, Method, Options};
    /// use nalgebra::Vector1;
    /// let sys = FnSystem::new(|_t, y: &Vector1<f64>, dy: &mut Vector1<f64>| dy[0] = -y[0]);
    /// let o = Options::default().rtol(1e-10).atol(1e-12).dense(true);
    /// let mut it = Integrator::new(sys, 0.0, Vector1::new(1.0), 1.0, Method::Tsit5, &o)?;
    /// it.step()?;
    /// let p = it.last_step();
    /// let mut y = [0.0];
    /// p.state_at(p.t0 + 0.5 * p.h, &mut y);
    /// assert!((y[0] - (-(p.t0 + 0.5 * p.h)).exp()).abs() < 1e-8);
    /// # Ok::<(), hdi_tribology::ode::OdeError>(())
    /// ```
    pub fn state_at(&self, t: f64, out: &mut [f64]) {
        horner(
            self.coeffs,
            self.n,
            theta(self.t0, self.h, t),
            &mut out[..self.n],
        );
    }
}

impl StepPoly {
    /// This interpolant, as the public view.
    pub(crate) fn view(&self) -> StepPolynomial<'_> {
        StepPolynomial {
            t0: self.t0,
            h: self.h,
            n: self.n,
            coeffs: &self.coeffs,
        }
    }

    pub fn new(n: usize) -> Self {
        StepPoly {
            t0: 0.0,
            h: 0.0,
            n,
            coeffs: Vec::with_capacity(9 * n),
        }
    }

    /// Starts a polynomial of degree `deg` for the step `[t0, t0 + h]`; all coefficients zero.
    pub fn begin(&mut self, t0: f64, h: f64, deg: usize) {
        self.t0 = t0;
        self.h = h;
        self.coeffs.clear();
        self.coeffs.resize((deg + 1) * self.n, 0.0);
    }

    #[allow(dead_code)]
    pub fn degree(&self) -> usize {
        (self.coeffs.len() / self.n.max(1)).saturating_sub(1)
    }

    /// Mutable coefficient `a_m[i]`.
    pub fn at(&mut self, m: usize, i: usize) -> &mut f64 {
        &mut self.coeffs[m * self.n + i]
    }

    /// The coefficient vectors `a_0 … a_deg` (as begun), each of the state's length.
    pub fn rows_mut<const K: usize>(&mut self) -> [&mut [f64]; K] {
        let n = self.n;
        let mut rest = &mut self.coeffs[..K * n];
        std::array::from_fn(|_| {
            let (row, tail) = std::mem::take(&mut rest).split_at_mut(n);
            rest = tail;
            row
        })
    }

    /// Evaluates at time `t` (extrapolates outside the step) into `out`.
    pub fn eval_into<D: Dim>(&self, t: f64, out: &mut OVector<f64, D>)
    where
        DefaultAllocator: Allocator<D>,
    {
        horner(
            &self.coeffs,
            self.n,
            theta(self.t0, self.h, t),
            out.as_mut_slice(),
        );
    }
}

/// The fraction `θ = (t − t0)/h` of the step `[t0, t0 + h]` at `t` (0 for an empty step).
#[inline]
fn theta(t0: f64, h: f64, t: f64) -> f64 {
    if h != 0.0 {
        (t - t0) / h
    } else {
        0.0
    }
}

fn horner(coeffs: &[f64], n: usize, theta: f64, out: &mut [f64]) {
    let deg = coeffs.len() / n - 1;
    for (i, o) in out.iter_mut().enumerate() {
        let mut acc = coeffs[deg * n + i];
        for m in (0..deg).rev() {
            acc = acc * theta + coeffs[m * n + i];
        }
        *o = acc;
    }
}

/// Dense output over a whole integration: the step interpolants, stored compactly.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct DenseOutput {
    n: usize,
    t_start: Vec<f64>,
    h: Vec<f64>,
    offset: Vec<usize>,
    coeffs: Vec<f64>,
    end_override: Option<f64>,
}

impl DenseOutput {
    pub(crate) fn new(n: usize) -> Self {
        DenseOutput {
            n,
            ..Default::default()
        }
    }

    pub(crate) fn push(&mut self, p: &StepPoly) {
        self.t_start.push(p.t0);
        self.h.push(p.h);
        self.offset.push(self.coeffs.len());
        self.coeffs.extend_from_slice(&p.coeffs);
        // A step after a truncated one (an event that acted) extends the range again.
        self.end_override = None;
    }

    /// Drops everything after time `t` (a terminal event inside the last step).
    pub(crate) fn truncate_last(&mut self, t: f64) {
        // The last step's interpolant stays valid on [t0, t]; only the covered range shrinks.
        if let Some(&t0) = self.t_start.last() {
            self.end_override = Some(t.max(t0));
        }
    }

    /// Number of stored steps.
    pub fn len(&self) -> usize {
        self.t_start.len()
    }

    /// True when no step is stored.
    pub fn is_empty(&self) -> bool {
        self.t_start.is_empty()
    }

    /// Bytes held by the coefficients and step tables (a measure of compactness).
    pub fn memory_bytes(&self) -> usize {
        8 * (self.coeffs.len() + self.t_start.len() + self.h.len() + self.offset.len())
    }

    /// Covered time range `(start, end)`, if any step is stored.
    pub fn range(&self) -> Option<(f64, f64)> {
        let first = *self.t_start.first()?;
        let last = self
            .end_override
            .unwrap_or(*self.t_start.last()? + *self.h.last()?);
        Some((first, last))
    }

    /// Evaluates the interpolant at `t` into `out`; `false` when `t` is outside the range.
    pub fn eval_into<D: Dim>(&self, t: f64, out: &mut OVector<f64, D>) -> bool
    where
        DefaultAllocator: Allocator<D>,
    {
        let Some((a, b)) = self.range() else {
            return false;
        };
        if !(t >= a && t <= b) || out.len() != self.n {
            return false;
        }
        // Last step whose start is <= t.
        let k = self.t_start.partition_point(|&s| s <= t).saturating_sub(1);
        let lo = self.offset[k];
        let hi = self.offset.get(k + 1).copied().unwrap_or(self.coeffs.len());
        let theta = theta(self.t_start[k], self.h[k], t);
        horner(&self.coeffs[lo..hi], self.n, theta, out.as_mut_slice());
        true
    }
}
