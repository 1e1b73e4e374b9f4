//! The kinetic side: the Abramowitz function `T₋₁`, Gauss–Legendre rules and the Nyström
//! solution of the integral equation of plane Poiseuille flow (linearised BGK model, diffuse
//! reflection at both walls).
//!
//! In units of the mean free path `ℓ = μ v₀ / p` (`v₀ = √(2kT/m)`), the channel is
//! `0 ≤ t ≤ D` with `D = (√π/2)·h/λ` the inverse Knudsen number. The reduced velocity
//! `φ(t)` (minus twice `D` times the flow velocity over `v₀` per unit dimensionless pressure
//! gradient) solves
//!
//! ```text
//! φ(t) = π^{-1/2} ∫₀ᴰ T₋₁(|t − s|) (φ(s) + 1) ds,      Q_P = D⁻² ∫₀ᴰ φ(t) dt,
//! ```
//!
//! with `T₋₁(y) = ∫₀^∞ c⁻¹ exp(−c² − y/c) dc`. The solution is even about `D/2`, so only
//! `[0, D/2]` is discretised and the kernel gains its mirror image `T₋₁(D − t − s)`.

use std::f64::consts::PI;
use std::sync::OnceLock;

/// Euler–Mascheroni constant γ.
pub(crate) const EULER_GAMMA: f64 = 0.577_215_664_901_532_9;

/// Number of terms kept in the small-argument series of `T₋₁`.
const SERIES_TERMS: usize = 14;
/// Below this argument `T₋₁` is summed from its series, above it from a Chebyshev fit.
const SERIES_LIMIT: f64 = 1.5;
/// Above this argument `T₋₁ < 1e-28` and is returned as zero.
const NEGLIGIBLE: f64 = 300.0;

/// Coefficients of `T₋₁(y) = −ln y · Σ a_k y^{2k} + Σ a_k c_k y^{2k} + Σ b_k y^{2k+1}`:
/// `a_k = (−1)^k/((2k)! k!)`, `c_k = ψ(2k+1) + ψ(k+1)/2`,
/// `b_k = −Γ(−k−½)/(2·(2k+1)!) = √π (−2)^k / ((2k+1)!! (2k+1)!)`.
/// They follow from the Mellin transform `∫₀^∞ y^{s−1} T₋₁(y) dy = Γ(s) Γ(s/2) / 2`, whose
/// double poles at `s = −2k` give the logarithmic terms and simple poles at `s = −2k−1` the
/// odd powers.
struct SeriesCoefficients {
    a: [f64; SERIES_TERMS],
    ac: [f64; SERIES_TERMS],
    b: [f64; SERIES_TERMS],
}

const fn series_coefficients() -> SeriesCoefficients {
    let mut a = [0.0; SERIES_TERMS];
    let mut ac = [0.0; SERIES_TERMS];
    let mut b = [0.0; SERIES_TERMS];
    // ψ(n+1) = −γ + H_n for integer n.
    let mut k = 0;
    while k < SERIES_TERMS {
        let mut fact_2k = 1.0; // (2k)!
        let mut i = 2;
        while i <= 2 * k {
            fact_2k *= i as f64;
            i += 1;
        }
        let mut fact_k = 1.0; // k!
        let mut i = 2;
        while i <= k {
            fact_k *= i as f64;
            i += 1;
        }
        let mut h_2k = 0.0; // H_{2k}
        let mut i = 1;
        while i <= 2 * k {
            h_2k += 1.0 / i as f64;
            i += 1;
        }
        let mut h_k = 0.0; // H_k
        let mut i = 1;
        while i <= k {
            h_k += 1.0 / i as f64;
            i += 1;
        }
        let psi_2k1 = -EULER_GAMMA + h_2k;
        let psi_k1 = -EULER_GAMMA + h_k;
        let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
        a[k] = sign / (fact_2k * fact_k);
        ac[k] = a[k] * (psi_2k1 + 0.5 * psi_k1);
        // (2k+1)!! and (2k+1)!
        let mut dfact = 1.0;
        let mut i = 3;
        while i <= 2 * k + 1 {
            dfact *= i as f64;
            i += 2;
        }
        let fact_2k1 = fact_2k * (2 * k + 1) as f64;
        let mut pow = 1.0;
        let mut i = 0;
        while i < k {
            pow *= -2.0;
            i += 1;
        }
        b[k] = SQRT_PI * pow / (dfact * fact_2k1);
        k += 1;
    }
    SeriesCoefficients { a, ac, b }
}

/// √π.
pub(crate) const SQRT_PI: f64 = 1.772_453_850_905_516;

static SERIES: SeriesCoefficients = series_coefficients();

/// `T₋₁(y)` from its convergent series, accurate to a few ulp of O(1) for `0 < y ≤ 1.5`.
fn t_minus1_series(y: f64) -> f64 {
    let y2 = y * y;
    let mut even = 0.0;
    let mut log_part = 0.0;
    let mut odd = 0.0;
    let mut p = 1.0;
    for k in 0..SERIES_TERMS {
        log_part += SERIES.a[k] * p;
        even += SERIES.ac[k] * p;
        odd += SERIES.b[k] * p;
        p *= y2;
    }
    -y.ln() * log_part + even + y * odd
}

/// `T_n(y)` for `y > 0` by the trapezoidal rule after `c = e^τ`:
/// `T_n(y) = ∫ exp((n+1)τ − e^{2τ} − y e^{−τ}) dτ`, whose integrand is analytic in a strip
/// and decays double-exponentially, so the rule converges geometrically in the step.
#[cfg(test)]
pub(crate) fn abramowitz_trapezoid(n: i32, y: f64) -> f64 {
    abramowitz_trapezoid_scaled(n, y, 0.0)
}

/// `T_n(y)·e^{shift}`, with the shift applied inside the exponent (no overflow).
fn abramowitz_trapezoid_scaled(n: i32, y: f64, shift: f64) -> f64 {
    // Saddle point c₀ = (y/2)^{1/3} of the exponent (for n = 0); integrate where the
    // exponent is within 60 of its minimum.
    let m = 3.0 * (0.5 * y).powf(2.0 / 3.0);
    let span = m + 60.0 + (n.unsigned_abs() as f64) * 4.0;
    let hi = 0.5 * span.ln();
    let lo = if y > 0.0 { (y / span).ln() } else { -40.0 };
    let lo = lo.min(hi - 1.0);
    let h = 0.03;
    let steps = ((hi - lo) / h).ceil() as usize;
    let h = (hi - lo) / steps as f64;
    let mut sum = 0.0;
    for k in 0..=steps {
        let tau = lo + h * k as f64;
        let e = (f64::from(n) + 1.0) * tau - (2.0 * tau).exp() - y * (-tau).exp() + shift;
        let w = if k == 0 || k == steps { 0.5 } else { 1.0 };
        sum += w * e.exp();
    }
    sum * h
}

/// Chebyshev fit of `F(z) = T₋₁(y)·exp(3 (y/2)^{2/3})` in `z = (y/2)^{−1/3}` on
/// `1.5 ≤ y ≤ 300`, i.e. `(150)^{−1/3} ≤ z ≤ (0.75)^{−1/3}`.
struct LargeArgumentFit {
    coef: Vec<f64>,
    z_lo: f64,
    z_max: f64,
}

const FIT_DEGREE: usize = 40;

fn large_argument_fit() -> &'static LargeArgumentFit {
    static FIT: OnceLock<LargeArgumentFit> = OnceLock::new();
    FIT.get_or_init(|| {
        let z_max = (0.5 * SERIES_LIMIT).powf(-1.0 / 3.0);
        let z_lo = (0.5 * NEGLIGIBLE).powf(-1.0 / 3.0);
        let n = FIT_DEGREE + 1;
        // Values at the Chebyshev points of the first kind, z ∈ (0, z_max).
        let values: Vec<f64> = (0..n)
            .map(|k| {
                let x = (PI * (k as f64 + 0.5) / n as f64).cos();
                let z = z_lo + 0.5 * (z_max - z_lo) * (x + 1.0);
                let y = 2.0 * z.powi(-3);
                abramowitz_trapezoid_scaled(-1, y, 3.0 / (z * z))
            })
            .collect();
        let coef = (0..n)
            .map(|j| {
                let s: f64 = (0..n)
                    .map(|k| {
                        let th = PI * (k as f64 + 0.5) / n as f64;
                        values[k] * (j as f64 * th).cos()
                    })
                    .sum();
                if j == 0 {
                    s / n as f64
                } else {
                    2.0 * s / n as f64
                }
            })
            .collect();
        LargeArgumentFit { coef, z_lo, z_max }
    })
}

/// The Abramowitz function `T₋₁(y) = ∫₀^∞ c⁻¹ exp(−c² − y/c) dc` for `y > 0`
/// (logarithmically infinite at `y = 0`).
pub(crate) fn t_minus1(y: f64) -> f64 {
    if y <= SERIES_LIMIT {
        return t_minus1_series(y);
    }
    if y >= NEGLIGIBLE {
        return 0.0;
    }
    let fit = large_argument_fit();
    let c = (0.5 * y).cbrt();
    let z = 1.0 / c;
    let x = (2.0 * z - fit.z_lo - fit.z_max) / (fit.z_max - fit.z_lo);
    // Clenshaw.
    let (mut b1, mut b2) = (0.0, 0.0);
    for &a in fit.coef.iter().skip(1).rev() {
        let b0 = 2.0 * x * b1 - b2 + a;
        b2 = b1;
        b1 = b0;
    }
    let f = x * b1 - b2 + fit.coef[0];
    f * (-3.0 * c * c).exp()
}

/// Gauss–Legendre nodes and weights on `[−1, 1]`, nodes ascending.
pub(crate) fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        let mut z = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let p = if n == 0 { 1.0 } else { p1 };
            let pm = if n == 1 { 1.0 } else { p0 };
            dp = n as f64 * (z * p - pm) / (z * z - 1.0);
            let dz = p / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        x[n - 1 - i] = z;
        x[i] = -z;
        let wi = 2.0 / ((1.0 - z * z) * dp * dp);
        w[i] = wi;
        w[n - 1 - i] = wi;
    }
    (x, w)
}

/// Resolution of the Nyström discretisation of the Poiseuille integral equation.
///
/// The half channel `[0, D/2]` (in mean free paths `ℓ = μv₀/p`) is cut into panels graded
/// geometrically towards the wall: `levels` panels of ratio `grading` cover the zone within one
/// mean free path of the wall (or the whole half channel if it is narrower), the smallest
/// `grading^levels` of that zone wide; beyond it, panels double in width up to `max_width`
/// mean free paths out to the mid-plane. Each panel carries `order` Gauss–Legendre nodes, and
/// the panels within three half-widths of a kernel singularity are integrated with
/// `near_points`-point product rules.
///
/// ```
/// use hdi_tribology::bearing::flow_factor::Resolution;
/// let r = Resolution::STANDARD;
/// assert!(r.validate().is_ok());
/// assert!(Resolution { order: 1, ..r }.validate().is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Resolution {
    /// Gauss–Legendre nodes per panel (2 to 32).
    pub order: usize,
    /// Ratio of successive panel widths towards the wall (between 0.05 and 0.5).
    pub grading: f64,
    /// Number of graded panels (1 to 60).
    pub levels: usize,
    /// Largest panel width away from the walls, in mean free paths (positive).
    pub max_width: f64,
    /// Gauss points of the product rules at the logarithmic singularity (8 to 128).
    pub near_points: usize,
}

impl Resolution {
    /// The resolution the database is built with: `Q_P` to about 1e-10 (relative) against
    /// [`Resolution::REFINED`] for `10⁻³ ≤ D ≤ 100`.
    ///
    /// ```
    /// use hdi_tribology::bearing::flow_factor::Resolution;
    /// assert_eq!(Resolution::STANDARD.order, 10);
    /// ```
    pub const STANDARD: Resolution = Resolution {
        order: 10,
        grading: 0.2,
        levels: 16,
        max_width: 4.0,
        near_points: 40,
    };

    /// A finer resolution for checking [`Resolution::STANDARD`].
    ///
    /// ```
    /// use hdi_tribology::bearing::flow_factor::{poiseuille_flow_rate, Resolution};
    /// let fine = poiseuille_flow_rate(10.0, &Resolution::REFINED)?;
    /// let standard = poiseuille_flow_rate(10.0, &Resolution::STANDARD)?;
    /// assert!((standard / fine - 1.0).abs() < 1e-10);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub const REFINED: Resolution = Resolution {
        order: 16,
        grading: 0.15,
        levels: 26,
        max_width: 2.0,
        near_points: 60,
    };

    /// A coarse resolution (about 1e-9), the first step of a convergence study.
    ///
    /// ```
    /// use hdi_tribology::bearing::flow_factor::{poiseuille_flow_rate, Resolution};
    /// let q = poiseuille_flow_rate(0.1, &Resolution::COARSE)?;
    /// assert!((q - 2.032714285).abs() < 1e-8);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub const COARSE: Resolution = Resolution {
        order: 8,
        grading: 0.2,
        levels: 12,
        max_width: 4.0,
        near_points: 40,
    };

    /// Checks every field's range; errors name the field as `resolution.<field>`.
    ///
    /// ```
    /// use hdi_tribology::bearing::flow_factor::Resolution;
    /// let err = Resolution { near_points: 4, ..Resolution::STANDARD }.validate().unwrap_err();
    /// assert!(err.to_string().contains("resolution.near_points"));
    /// ```
    pub fn validate(&self) -> crate::Result<()> {
        let bad = |field: &str, reason: String| {
            Err(crate::Error::invalid(format!("resolution.{field}"), reason))
        };
        if !(2..=32).contains(&self.order) {
            return bad("order", format!("must be in 2..=32, got {}", self.order));
        }
        if !(self.grading >= 0.05 && self.grading <= 0.5) {
            return bad(
                "grading",
                format!("must be in [0.05, 0.5], got {}", self.grading),
            );
        }
        if !(1..=60).contains(&self.levels) {
            return bad("levels", format!("must be in 1..=60, got {}", self.levels));
        }
        if !(self.max_width > 0.0 && self.max_width.is_finite()) {
            return bad(
                "max_width",
                format!("must be positive and finite, got {}", self.max_width),
            );
        }
        if !(8..=128).contains(&self.near_points) {
            return bad(
                "near_points",
                format!("must be in 8..=128, got {}", self.near_points),
            );
        }
        Ok(())
    }
}

struct Panel {
    a: f64,
    b: f64,
    /// Index of the first node.
    first: usize,
}

/// Panel ends `(a, b)` of the discretisation of the half channel `[0, h]`.
fn panels(h: f64, res: &Resolution) -> Vec<(f64, f64)> {
    let mut bounds = vec![0.0];
    let graded = h.min(1.0);
    for k in (0..res.levels).rev() {
        bounds.push(graded * res.grading.powi(k as i32));
    }
    let remaining = h - graded;
    if remaining > 0.0 {
        let mut widths = Vec::new();
        let mut w = graded * (1.0 - res.grading);
        let mut total = 0.0;
        while total < remaining * (1.0 - 1e-12) {
            w = (2.0 * w).min(res.max_width);
            widths.push(w);
            total += w;
        }
        let scale = remaining / total;
        let mut x = graded;
        let count = widths.len();
        for (i, w) in widths.into_iter().enumerate() {
            x = if i + 1 == count { h } else { x + w * scale };
            bounds.push(x);
        }
    }
    bounds.windows(2).map(|p| (p[0], p[1])).collect()
}

/// The Lagrange basis of one panel (its `nodes` and barycentric weights `bary`) with the Gauss
/// rule (nodes, weights on [−1, 1]) of the product rules for the kernel's singular point.
struct NearRule<'a> {
    nodes: &'a [f64],
    bary: &'a [f64],
    rule: &'a (Vec<f64>, Vec<f64>),
}

impl NearRule<'_> {
    /// Adds `scale·∫ T₋₁(d + u) ℓ_j(e + dir·u) du` over `0 ≤ u ≤ len` to `out[j]`. `d ≥ 0` is
    /// the distance of the singular point from the end `e`.
    fn add_endpoint_integral(&self, e: f64, dir: f64, len: f64, d: f64, out: &mut [f64]) {
        if len <= 0.0 {
            return;
        }
        let (gx, gw) = self.rule;
        let mut basis = vec![0.0; self.nodes.len()];
        let mut accumulate = |u: f64, weight: f64, basis: &mut [f64]| {
            let kernel = t_minus1(d + u) * weight;
            lagrange(e + dir * u, self.nodes, self.bary, basis);
            for (o, l) in out.iter_mut().zip(basis.iter()) {
                *o += kernel * l;
            }
        };
        if d <= 0.0 {
            // u = len·v^q: the logarithm becomes v^{q−1} ln v, smooth enough for Gauss.
            const Q: i32 = 6;
            for (x, w) in gx.iter().zip(gw) {
                let v = 0.5 * (x + 1.0);
                let u = len * v.powi(Q);
                let du = len * f64::from(Q) * v.powi(Q - 1) * 0.5 * w;
                accumulate(u, du, &mut basis);
            }
        } else {
            // u = d(e^w − 1): ln(d + u) = ln d + w is linear in w; chunks of at most 2 in w.
            let big_w = (len / d).ln_1p();
            let chunks = (big_w / 2.0).ceil().max(1.0) as usize;
            let cw = big_w / chunks as f64;
            for c in 0..chunks {
                let w0 = cw * c as f64;
                for (x, w) in gx.iter().zip(gw) {
                    let ww = w0 + 0.5 * cw * (x + 1.0);
                    let ew = ww.exp();
                    let u = d * (ew - 1.0);
                    let du = d * ew * 0.5 * cw * w;
                    accumulate(u, du, &mut basis);
                }
            }
        }
    }

    /// Adds `∫_a^b T₋₁(|σ − s|) ℓ_j(s) ds` to `out[j]`.
    fn add_near(&self, a: f64, b: f64, sigma: f64, out: &mut [f64]) {
        if sigma > a && sigma < b {
            self.add_endpoint_integral(sigma, 1.0, b - sigma, 0.0, out);
            self.add_endpoint_integral(sigma, -1.0, sigma - a, 0.0, out);
        } else if sigma <= a {
            self.add_endpoint_integral(a, 1.0, b - a, a - sigma, out);
        } else {
            self.add_endpoint_integral(b, -1.0, b - a, sigma - b, out);
        }
    }
}

/// Lagrange basis of `nodes` at `x` by the barycentric formula.
fn lagrange(x: f64, nodes: &[f64], bary: &[f64], out: &mut [f64]) {
    for (j, &xj) in nodes.iter().enumerate() {
        if x == xj {
            out.iter_mut().for_each(|o| *o = 0.0);
            out[j] = 1.0;
            return;
        }
    }
    let mut denom = 0.0;
    for ((o, &xj), &bj) in out.iter_mut().zip(nodes).zip(bary) {
        *o = bj / (x - xj);
        denom += *o;
    }
    out.iter_mut().for_each(|o| *o /= denom);
}

/// Panels closer than this many half-widths (centre to singular point) get the product rules.
const NEAR: f64 = 3.0;

/// Solves the Poiseuille integral equation for the inverse Knudsen number `d > 0` and
/// returns `Q_P = D⁻² ∫₀ᴰ φ dt`.
pub(crate) fn solve(d: f64, res: &Resolution) -> f64 {
    let h = 0.5 * d;
    let (gx, gw) = gauss_legendre(res.order);
    // Barycentric weights of the Gauss nodes (independent of the panel up to a factor).
    let bary_ref: Vec<f64> = (0..res.order)
        .map(|j| {
            let p: f64 = (0..res.order)
                .filter(|&k| k != j)
                .map(|k| gx[j] - gx[k])
                .product();
            1.0 / p
        })
        .collect();
    let rule = gauss_legendre(res.near_points);
    let mut nodes = Vec::new();
    let mut weights = Vec::new();
    let mut panel_list = Vec::new();
    for (a, b) in panels(h, res) {
        panel_list.push(Panel {
            a,
            b,
            first: nodes.len(),
        });
        for (x, w) in gx.iter().zip(&gw) {
            nodes.push(0.5 * (a + b) + 0.5 * (b - a) * x);
            weights.push(0.5 * (b - a) * w);
        }
    }
    let n = nodes.len();
    let p = res.order;
    let scale = 1.0 / SQRT_PI;
    let mut m = nalgebra::DMatrix::<f64>::zeros(n, n);
    let mut local = vec![0.0; p];
    for i in 0..n {
        let t = nodes[i];
        for panel in &panel_list {
            let c = 0.5 * (panel.a + panel.b);
            let r = 0.5 * (panel.b - panel.a);
            let pn = &nodes[panel.first..panel.first + p];
            let near = NearRule {
                nodes: pn,
                bary: &bary_ref,
                rule: &rule,
            };
            local.iter_mut().for_each(|v| *v = 0.0);
            for sigma in [t, d - t] {
                if (sigma - c).abs() < NEAR * r {
                    near.add_near(panel.a, panel.b, sigma, &mut local);
                } else {
                    for j in 0..p {
                        let s = pn[j];
                        local[j] += weights[panel.first + j] * t_minus1((sigma - s).abs());
                    }
                }
            }
            for j in 0..p {
                m[(i, panel.first + j)] = scale * local[j];
            }
        }
    }
    let rhs = nalgebra::DVector::from_iterator(n, (0..n).map(|i| m.row(i).sum()));
    let mut a = -m;
    for i in 0..n {
        a[(i, i)] += 1.0;
    }
    let phi = a
        .lu()
        .solve(&rhs)
        .expect("the Poiseuille operator I − K is invertible for D > 0");
    let integral: f64 = phi.iter().zip(&weights).map(|(f, w)| f * w).sum();
    2.0 * integral / (d * d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn series_matches_trapezoid() {
        for &y in &[1e-6, 1e-3, 0.05, 0.3, 0.8, 1.2, 1.5] {
            let s = t_minus1_series(y);
            let q = abramowitz_trapezoid(-1, y);
            assert!((s - q).abs() < 2e-15 * s.abs().max(1.0), "y={y} {s} {q}");
        }
    }

    #[test]
    fn fit_matches_trapezoid() {
        let mut worst: f64 = 0.0;
        for k in 0..400 {
            let y = 1.5 * (299.0f64 / 1.5).powf(k as f64 / 399.0);
            let f = t_minus1(y);
            let q = abramowitz_trapezoid(-1, y);
            worst = worst.max(((f - q) / q).abs());
        }
        assert!(worst < 1e-13, "worst {worst:e}");
    }
}
