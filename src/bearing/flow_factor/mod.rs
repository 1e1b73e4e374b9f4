//! The rarefied-gas Poiseuille flow factor of the Reynolds equation.
//!
//! In a gas film of spacing `h` with mean free path `λ`, the pressure-driven (Poiseuille) flow
//! per unit width is `−(h³/12μ)·Q·∂p/∂x`, where `Q = 1` for a continuum and grows with the
//! Knudsen number `Kn = λ/h`. The kinetic value is `Q = Q_P(D)/(D/6)`, with `Q_P` the
//! dimensionless Poiseuille flow rate of the linearised Boltzmann equation and
//! `D = (√π/2)/Kn` the inverse Knudsen number.
//!
//! This module computes `Q_P` itself, from the BGK model with diffuse reflection at both
//! walls ([`poiseuille_flow_rate`]: the integral equation for the velocity profile, solved by
//! a Nyström method), and stores it as a database ([`FlowFactor`]: a cubic spline in `ln D`
//! between `D = 10⁻³` and `D = 10^2.5`, extended by the free-molecular and slip asymptotes).
//! [`FlowModel`] puts it beside the closed-form slip models. The equations, the
//! discretisation, the comparison with published values and the accuracy are in
//! `docs/air_bearing_flow_factor.md`.
//!
//! ```
//! use hdi_tribology::bearing::flow_factor::FlowModel;
//! let kn = 0.5; // λ/h
//! let q = FlowModel::FukuiKaneko.factor(kn);
//! assert!(q > FlowModel::Continuum.factor(kn));
//! assert!((q - 5.328).abs() < 1e-3);
//! ```

mod kinetic;
mod table;

pub use kinetic::Resolution;

use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

use crate::numerics::cubic_hermite;
use kinetic::{EULER_GAMMA, SQRT_PI};

/// Viscous slip coefficient of the BGK model with diffuse reflection, `σ_P = 1.016191`, in
/// units of the mean free path `ℓ = μv₀/p`: the continuum limit of the flow rate is
/// `Q_P = D/6 + σ_P + O(1/D)` (Cercignani; Loyalka, Petrellis & Storvick 1975).
///
/// ```
/// use hdi_tribology::bearing::flow_factor::{poiseuille_flow_rate, Resolution, SLIP_COEFFICIENT};
/// let d = 300.0;
/// let q = poiseuille_flow_rate(d, &Resolution::STANDARD)?;
/// assert!((q - d / 6.0 - SLIP_COEFFICIENT).abs() < 5e-3);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub const SLIP_COEFFICIENT: f64 = 1.016_191;

/// Constant of the free-molecular limit `Q_P = π^{−1/2}(−ln D + c₀) + O(D ln²D)`:
/// `c₀ = 3(1 − γ)/2` (γ Euler's constant), from `T₋₁(y) = −ln y − 3γ/2 + O(y)`.
///
/// ```
/// use hdi_tribology::bearing::flow_factor::FREE_MOLECULAR_CONSTANT;
/// assert!((FREE_MOLECULAR_CONSTANT - 0.634176).abs() < 1e-6);
/// ```
pub const FREE_MOLECULAR_CONSTANT: f64 = 1.5 * (1.0 - EULER_GAMMA);

/// The inverse Knudsen number `D = (√π/2)·h/λ` of a spacing `h` and mean free path `λ`
/// (both in m). Returns `+∞` for `λ = 0`.
///
/// ```
/// use hdi_tribology::bearing::flow_factor::inverse_knudsen;
/// let d = inverse_knudsen(10e-9, 65e-9);
/// assert!((d - 0.1363).abs() < 1e-4);
/// ```
pub fn inverse_knudsen(spacing: f64, mean_free_path: f64) -> f64 {
    0.5 * SQRT_PI * spacing / mean_free_path
}

/// The Poiseuille flow rate `Q_P(D)` of the linearised BGK equation with diffuse walls,
/// solved at the inverse Knudsen number `d = D` with the given resolution.
///
/// Costs from 10 ms (`D ≤ 10`) to a few hundred ms (`D = 300`): this is the generator of the
/// database, not something to call in a solver loop (use [`FlowFactor`] there). Errors name
/// `inverse_knudsen` (must be positive and at most 10⁴) or the resolution's fields.
///
/// ```
/// use hdi_tribology::bearing::flow_factor::{poiseuille_flow_rate, Resolution};
/// // Knudsen's minimum: the flow rate at D = 1 is below both neighbours a decade away.
/// let q = |d| poiseuille_flow_rate(d, &Resolution::STANDARD).unwrap();
/// assert!(q(1.0) < q(0.1) && q(1.0) < q(10.0));
/// assert!((q(1.0) - 1.538678).abs() < 1e-6);
/// ```
pub fn poiseuille_flow_rate(d: f64, resolution: &Resolution) -> crate::Result<f64> {
    resolution.validate()?;
    if !(d > 0.0 && d <= 1e4) {
        return Err(crate::Error::invalid(
            "inverse_knudsen",
            format!("must be in (0, 1e4], got {d}"),
        ));
    }
    Ok(kinetic::solve(d, resolution))
}

/// Smallest inverse Knudsen number of the database's table (`10⁻³`, i.e. `Kn ≈ 886`).
///
/// ```
/// use hdi_tribology::bearing::flow_factor::{inverse_knudsen, TABLE_D_MIN};
/// // A 0.05 nm gap in air (λ ≈ 65 nm) is below the table: the free-molecular tail applies.
/// assert!(inverse_knudsen(0.05e-9, 65e-9) < TABLE_D_MIN);
/// ```
pub const TABLE_D_MIN: f64 = 1e-3;
/// Largest inverse Knudsen number of the database's table (`10^2.5 ≈ 316`, `Kn ≈ 0.0028`).
///
/// ```
/// use hdi_tribology::bearing::flow_factor::{inverse_knudsen, TABLE_D_MAX};
/// // A 30 µm gap in air is above the table: the slip expansion applies.
/// assert!(inverse_knudsen(30e-6, 65e-9) > TABLE_D_MAX);
/// ```
pub const TABLE_D_MAX: f64 = 316.227_766_016_837_94;

/// The inverse Knudsen numbers of the database's table: `10^(−3 + k/24)`, `k = 0..=132`.
///
/// ```
/// use hdi_tribology::bearing::flow_factor::{table_nodes, TABLE_D_MAX, TABLE_D_MIN};
/// let d = table_nodes();
/// assert_eq!(d.len(), 133);
/// assert_eq!(d[0], TABLE_D_MIN);
/// assert!((d[132] / TABLE_D_MAX - 1.0).abs() < 1e-14);
/// ```
pub fn table_nodes() -> Vec<f64> {
    (0..table::FLOW_RATE.len()).map(node).collect()
}

fn node(k: usize) -> f64 {
    10f64.powf(table::LOG10_D_MIN + k as f64 / table::PER_DECADE)
}

/// Recomputes the database's table, `Q_P` at [`table_nodes`], with the given resolution
/// (about 5 s at [`Resolution::STANDARD`] in an optimised build).
///
/// ```no_run
/// use hdi_tribology::bearing::flow_factor::{generate_table, FlowFactor, Resolution};
/// let fresh = generate_table(&Resolution::STANDARD)?;
/// for (a, b) in fresh.iter().zip(FlowFactor::get().table()) {
///     assert!((a / b - 1.0).abs() < 1e-10);
/// }
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn generate_table(resolution: &Resolution) -> crate::Result<Vec<f64>> {
    table_nodes()
        .into_iter()
        .map(|d| poiseuille_flow_rate(d, resolution))
        .collect()
}

/// The database of the Poiseuille flow rate: `Q_P(D)` and the flow factor
/// `Q(Kn) = Q_P/(D/6)` with their derivatives, O(1) per call and without allocation.
///
/// Inside the table (`10⁻³ ≤ D ≤ 10^2.5`) the smooth part `g = Q_P − D/6` is a clamped cubic
/// spline in `ln D` through the stored solver values (24 nodes per decade). Above it,
/// `g = σ_P + c₁/D + c₂/D²`; below it,
/// `Q_P = π^{−1/2}(−ln D + c₀) + (D/π)(ln²D + α ln D + β)`; the constants `c₁, c₂, α, β`
/// join value and slope to the spline at the table's ends.
///
/// ```
/// use hdi_tribology::bearing::flow_factor::FlowFactor;
/// let db = FlowFactor::get();
/// let (q, dq) = db.flow_rate_and_derivative(1.0716); // Knudsen's minimum
/// assert!((q - 1.538082).abs() < 1e-6);
/// assert!(dq.abs() < 1e-4);
/// ```
#[derive(Debug)]
pub struct FlowFactor {
    /// `Q_P` at the nodes.
    values: Vec<f64>,
    /// `g = Q_P − D/6` at the nodes.
    g: Vec<f64>,
    /// `dg/d(ln D)` at the nodes (spline slopes).
    slope: Vec<f64>,
    x0: f64,
    h: f64,
    /// Continuum tail: `g = σ + c1/D + c2/D²`.
    c1: f64,
    c2: f64,
    /// Free-molecular tail: `(D/π)(α ln D + β)`.
    alpha: f64,
    beta: f64,
}

impl FlowFactor {
    /// The database, built on first use from the stored table (microseconds).
    ///
    /// ```
    /// use hdi_tribology::bearing::flow_factor::FlowFactor;
    /// assert!(std::ptr::eq(FlowFactor::get(), FlowFactor::get()));
    /// ```
    pub fn get() -> &'static FlowFactor {
        static DB: OnceLock<FlowFactor> = OnceLock::new();
        DB.get_or_init(|| FlowFactor::from_table(&table::FLOW_RATE))
    }

    /// A database from `Q_P` at [`table_nodes`] (for instance from [`generate_table`]).
    /// Errors name `table` if the length is not that of [`table_nodes`] or a value is not
    /// positive and finite.
    ///
    /// ```
    /// use hdi_tribology::bearing::flow_factor::FlowFactor;
    /// let same = FlowFactor::from_values(FlowFactor::get().table())?;
    /// assert_eq!(same.flow_rate(2.0), FlowFactor::get().flow_rate(2.0));
    /// assert!(FlowFactor::from_values(&[1.0, 2.0]).is_err());
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn from_values(values: &[f64]) -> crate::Result<FlowFactor> {
        let n = table::FLOW_RATE.len();
        if values.len() != n {
            return Err(crate::Error::invalid(
                "table",
                format!("must hold {n} values, got {}", values.len()),
            ));
        }
        if let Some(v) = values.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
            return Err(crate::Error::invalid(
                "table",
                format!("values must be positive and finite, got {v}"),
            ));
        }
        Ok(FlowFactor::from_table(values))
    }

    fn from_table(values: &[f64]) -> FlowFactor {
        let n = values.len();
        let h = std::f64::consts::LN_10 / table::PER_DECADE;
        let x0 = table::LOG10_D_MIN * std::f64::consts::LN_10;
        let g: Vec<f64> = values
            .iter()
            .enumerate()
            .map(|(k, q)| q - node(k) / 6.0)
            .collect();
        // End slopes by fourth-order one-sided differences.
        let d0 = (-25.0 * g[0] + 48.0 * g[1] - 36.0 * g[2] + 16.0 * g[3] - 3.0 * g[4]) / (12.0 * h);
        let dn = (25.0 * g[n - 1] - 48.0 * g[n - 2] + 36.0 * g[n - 3] - 16.0 * g[n - 4]
            + 3.0 * g[n - 5])
            / (12.0 * h);
        let slope = clamped_spline_slopes(&g, h, d0, dn);
        // Continuum tail, matched at D_max: g = σ + c1/D + c2/D², dg/dD = slope/D.
        let dm = node(n - 1);
        let gm = g[n - 1] - SLIP_COEFFICIENT;
        let gd = slope[n - 1] / dm;
        let c2 = dm * dm * (-gd * dm - gm);
        let c1 = gm * dm - c2 / dm;
        // Free-molecular tail, matched at D_min.
        let d = node(0);
        let l = d.ln();
        let pi = std::f64::consts::PI;
        let q = values[0];
        let dq = slope[0] / d + 1.0 / 6.0;
        let base = (-l + FREE_MOLECULAR_CONSTANT) / SQRT_PI + d / pi * l * l;
        let dbase = -1.0 / (SQRT_PI * d) + (l * l + 2.0 * l) / pi;
        // (D/π)(αL + β) = q − base;  (1/π)(αL + β + α) = dq − dbase.
        let r1 = (q - base) * pi / d; // αL + β
        let r2 = (dq - dbase) * pi; // αL + β + α
        let alpha = r2 - r1;
        let beta = r1 - alpha * l;
        FlowFactor {
            values: values.to_vec(),
            g,
            slope,
            x0,
            h,
            c1,
            c2,
            alpha,
            beta,
        }
    }

    /// `Q_P` at [`table_nodes`], as stored (or as given to [`FlowFactor::from_values`]).
    ///
    /// ```
    /// use hdi_tribology::bearing::flow_factor::{table_nodes, FlowFactor};
    /// assert_eq!(FlowFactor::get().table().len(), table_nodes().len());
    /// ```
    pub fn table(&self) -> &[f64] {
        &self.values
    }

    /// `Q_P(D)` for `D > 0`.
    ///
    /// ```
    /// use hdi_tribology::bearing::flow_factor::FlowFactor;
    /// let q = FlowFactor::get().flow_rate(1e4);
    /// assert!((q - (1e4 / 6.0 + 1.016191)).abs() < 1e-3);
    /// ```
    pub fn flow_rate(&self, d: f64) -> f64 {
        self.flow_rate_and_derivative(d).0
    }

    /// `Q_P(D)` and `dQ_P/dD` for `D > 0` (NaN otherwise).
    ///
    /// ```
    /// use hdi_tribology::bearing::flow_factor::FlowFactor;
    /// let (q, dq) = FlowFactor::get().flow_rate_and_derivative(1e-5);
    /// assert!(q > 6.0 && dq < 0.0); // logarithmic growth as D → 0
    /// ```
    pub fn flow_rate_and_derivative(&self, d: f64) -> (f64, f64) {
        let (g, dg) = self.smooth_part(d);
        (g + d / 6.0, dg + 1.0 / 6.0)
    }

    /// `g = Q_P − D/6` and `dg/dD`.
    fn smooth_part(&self, d: f64) -> (f64, f64) {
        if d.is_nan() || d <= 0.0 {
            return (f64::NAN, f64::NAN);
        }
        if d.is_infinite() {
            return (SLIP_COEFFICIENT, 0.0);
        }
        let x = d.ln();
        let last = self.g.len() - 1;
        let s = (x - self.x0) / self.h;
        if s > last as f64 {
            let inv = 1.0 / d;
            let g = SLIP_COEFFICIENT + inv * (self.c1 + self.c2 * inv);
            let dg = -inv * inv * (self.c1 + 2.0 * self.c2 * inv);
            return (g, dg);
        }
        if s < 0.0 {
            let pi = std::f64::consts::PI;
            let q = (-x + FREE_MOLECULAR_CONSTANT) / SQRT_PI
                + d / pi * (x * x + self.alpha * x + self.beta);
            let dq = -1.0 / (SQRT_PI * d)
                + (x * x + 2.0 * x + self.alpha * x + self.alpha + self.beta) / pi;
            return (q - d / 6.0, dq - 1.0 / 6.0);
        }
        let i = (s.floor() as usize).min(last - 1);
        let t = s - i as f64;
        let (g0, g1) = (self.g[i], self.g[i + 1]);
        let (m0, m1) = (self.slope[i] * self.h, self.slope[i + 1] * self.h);
        let (g, dg_dt) = cubic_hermite(t, g0, m0, g1, m1);
        (g, dg_dt / (self.h * d))
    }

    /// The flow factor `Q(Kn) = Q_P/(D/6)`, `D = (√π/2)/Kn`, for `Kn ≥ 0` (`Q(0) = 1`).
    ///
    /// ```
    /// use hdi_tribology::bearing::flow_factor::FlowFactor;
    /// assert_eq!(FlowFactor::get().factor(0.0), 1.0);
    /// ```
    pub fn factor(&self, knudsen: f64) -> f64 {
        self.factor_and_derivative(knudsen).0
    }

    /// `Q(Kn)` and `dQ/dKn` for finite `Kn ≥ 0` (NaN for negative, infinite or NaN `Kn`).
    ///
    /// ```
    /// use hdi_tribology::bearing::flow_factor::FlowFactor;
    /// let (q, dq) = FlowFactor::get().factor_and_derivative(1e-6);
    /// // Continuum limit: Q ≈ 1 + (12σ_P/√π)·Kn, an effective slip length 1.1466 λ.
    /// assert!((dq - 6.0 * 1.1466).abs() < 1e-3 && (q - 1.0) < 1e-5);
    /// ```
    pub fn factor_and_derivative(&self, knudsen: f64) -> (f64, f64) {
        if knudsen == 0.0 {
            return (1.0, 12.0 * SLIP_COEFFICIENT / SQRT_PI);
        }
        if knudsen.is_nan() || knudsen < 0.0 {
            return (f64::NAN, f64::NAN);
        }
        let d = 0.5 * SQRT_PI / knudsen;
        if d == 0.0 {
            return (f64::NAN, f64::NAN);
        }
        let (g, dg) = self.smooth_part(d);
        // Q = 1 + 6g/D, dQ/dD = 6(dg·D − g)/D², dD/dKn = −D/Kn.
        let q = 1.0 + 6.0 * g / d;
        let dq_dd = 6.0 * (dg * d - g) / (d * d);
        (q, -dq_dd * d / knudsen)
    }
}

/// Slopes of the clamped cubic spline through `y` on a uniform grid of step `h`.
fn clamped_spline_slopes(y: &[f64], h: f64, d0: f64, dn: f64) -> Vec<f64> {
    let n = y.len();
    let mut m = vec![0.0; n];
    m[0] = d0;
    m[n - 1] = dn;
    if n <= 2 {
        return m;
    }
    // m[i−1] + 4 m[i] + m[i+1] = 3 (y[i+1] − y[i−1]) / h, i = 1..n−2 (Thomas algorithm).
    let k = n - 2;
    let mut c = vec![0.0; k];
    let mut r = vec![0.0; k];
    for j in 0..k {
        let i = j + 1;
        let mut rhs = 3.0 * (y[i + 1] - y[i - 1]) / h;
        if i == 1 {
            rhs -= d0;
        }
        if i == n - 2 {
            rhs -= dn;
        }
        let (denom, prev_r) = if j == 0 {
            (4.0, 0.0)
        } else {
            (4.0 - c[j - 1], r[j - 1])
        };
        c[j] = 1.0 / denom;
        r[j] = (rhs - prev_r) / denom;
    }
    for j in (0..k).rev() {
        let next = if j + 1 < k { m[j + 2] } else { 0.0 };
        m[j + 1] = r[j] - c[j] * next;
    }
    m
}

/// Which Poiseuille flow factor `Q(Kn)` the Reynolds equation uses, `Kn = λ/h`.
///
/// - `continuum`: `Q = 1`;
/// - `first_order_slip`: `Q = 1 + 6 Kn` (Burgdorfer 1959, slip length λ);
/// - `second_order_slip`: `Q = 1 + 6 Kn + 6 Kn²` (Hsia & Domoto 1983);
/// - `fukui_kaneko`: the linearised-Boltzmann (BGK) database, [`FlowFactor`], after the
///   approach of Fukui & Kaneko (1988, 1990).
///
/// ```
/// use hdi_tribology::bearing::flow_factor::FlowModel;
/// let m: FlowModel = serde_json::from_str("\"fukui_kaneko\"").unwrap();
/// assert_eq!(m, FlowModel::FukuiKaneko);
/// assert_eq!(FlowModel::SecondOrderSlip.factor_and_derivative(0.5), (5.5, 12.0));
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FlowModel {
    /// No slip: `Q = 1`.
    Continuum,
    /// First-order slip: `Q = 1 + 6 Kn`.
    #[default]
    FirstOrderSlip,
    /// Second-order slip: `Q = 1 + 6 Kn + 6 Kn²`.
    SecondOrderSlip,
    /// The BGK database: `Q = Q_P(D)/(D/6)`.
    FukuiKaneko,
}

impl FlowModel {
    /// `Q(Kn)` for `Kn ≥ 0` (NaN for the database at negative `Kn`; see
    /// [`FlowModel::checked_factor_and_derivative`]).
    ///
    /// ```
    /// use hdi_tribology::bearing::flow_factor::FlowModel;
    /// assert_eq!(FlowModel::FirstOrderSlip.factor(0.5), 4.0);
    /// ```
    pub fn factor(self, knudsen: f64) -> f64 {
        self.factor_and_derivative(knudsen).0
    }

    /// `Q(Kn)` and `dQ/dKn`.
    ///
    /// ```
    /// use hdi_tribology::bearing::flow_factor::FlowModel;
    /// assert_eq!(FlowModel::Continuum.factor_and_derivative(3.0), (1.0, 0.0));
    /// let (q, dq) = FlowModel::FukuiKaneko.factor_and_derivative(1.0);
    /// assert!(q > 7.0 && dq > 0.0);
    /// ```
    pub fn factor_and_derivative(self, knudsen: f64) -> (f64, f64) {
        let k = knudsen;
        match self {
            FlowModel::Continuum => (1.0, 0.0),
            FlowModel::FirstOrderSlip => (1.0 + 6.0 * k, 6.0),
            FlowModel::SecondOrderSlip => (1.0 + 6.0 * k + 6.0 * k * k, 6.0 + 12.0 * k),
            FlowModel::FukuiKaneko => FlowFactor::get().factor_and_derivative(k),
        }
    }

    /// [`FlowModel::factor_and_derivative`] after checking that `Kn` is finite and not
    /// negative (the error names `knudsen`).
    ///
    /// ```
    /// use hdi_tribology::bearing::flow_factor::FlowModel;
    /// assert!(FlowModel::FukuiKaneko.checked_factor_and_derivative(-1.0).is_err());
    /// assert!(FlowModel::FukuiKaneko.checked_factor_and_derivative(0.1).is_ok());
    /// ```
    pub fn checked_factor_and_derivative(self, knudsen: f64) -> crate::Result<(f64, f64)> {
        if !(knudsen >= 0.0 && knudsen.is_finite()) {
            return Err(crate::Error::invalid(
                "knudsen",
                format!("must be finite and >= 0, got {knudsen}"),
            ));
        }
        Ok(self.factor_and_derivative(knudsen))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spline_reproduces_a_cubic() {
        let h = 0.3;
        let f = |x: f64| 0.5 * x * x * x - x * x + 2.0;
        let df = |x: f64| 1.5 * x * x - 2.0 * x;
        let y: Vec<f64> = (0..12).map(|i| f(i as f64 * h)).collect();
        let m = clamped_spline_slopes(&y, h, df(0.0), df(11.0 * h));
        for (i, mi) in m.iter().enumerate() {
            assert!((mi - df(i as f64 * h)).abs() < 1e-12, "{i}: {mi}");
        }
    }

    #[test]
    fn t_minus1_integrates_to_t0_at_zero() {
        // ∫₀^∞ T₋₁(y) dy = T₀(0) = √π/2.
        let (x, w) = kinetic::gauss_legendre(60);
        let mut sum = 0.0;
        // Pieces [0, 1e-12], then geometric pieces up to 300.
        let mut a = 0.0;
        let mut b = 1e-12;
        while a < 300.0 {
            let pts: Vec<f64> = x
                .iter()
                .map(|xi| {
                    // s = a + (b − a)·((xi+1)/2)^4 on the first piece only.
                    0.5 * (xi + 1.0)
                })
                .collect();
            for (v, wi) in pts.iter().zip(&w) {
                let (s, ds) = if a == 0.0 {
                    (b * v.powi(6), b * 6.0 * v.powi(5) * 0.5 * wi)
                } else {
                    (a + (b - a) * v, (b - a) * 0.5 * wi)
                };
                sum += kinetic::t_minus1(s) * ds;
            }
            a = b;
            b = (2.0 * b).min(300.0);
        }
        assert!((sum - 0.5 * SQRT_PI).abs() < 1e-12, "{sum}");
    }

    #[test]
    fn abramowitz_recurrence() {
        // 2 T₂(y) = T₀(y) + y T₋₁(y).
        for &y in &[0.01, 0.3, 1.0, 1.5, 2.0, 7.0, 30.0] {
            let t2 = kinetic::abramowitz_trapezoid(2, y);
            let t0 = kinetic::abramowitz_trapezoid(0, y);
            let lhs = 2.0 * t2;
            let rhs = t0 + y * kinetic::t_minus1(y);
            assert!((lhs - rhs).abs() < 1e-13 * lhs, "y={y}: {lhs} {rhs}");
        }
    }
}

#[cfg(test)]
mod generate {
    use super::*;

    /// Prints `table.rs`: `cargo test --lib bearing::flow_factor::generate -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn print_table() {
        let t0 = std::time::Instant::now();
        let v = generate_table(&Resolution::STANDARD).unwrap();
        eprintln!("generated in {:?}", t0.elapsed());
        let mut s = String::new();
        for q in v {
            s.push_str(&format!("    {q:?},\n"));
        }
        println!("BEGIN\n{s}END");
    }
}

#[cfg(test)]
mod reference_values {
    use super::*;

    /// Prints the table of `docs/air_bearing_flow_factor.md`:
    /// `cargo test --lib bearing::flow_factor::reference_values -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn print_reference_values() {
        for d in [
            1e-3, 0.01, 0.03, 0.1, 0.15, 0.3, 1.0, 3.0, 5.0, 10.0, 30.0, 100.0,
        ] {
            let s = poiseuille_flow_rate(d, &Resolution::STANDARD).unwrap();
            let r = poiseuille_flow_rate(d, &Resolution::REFINED).unwrap();
            let db = FlowFactor::get().flow_rate(d);
            println!(
                "| {d} | {s:.9} | {:.1e} | {:.1e} | {:.4} |",
                (s / r - 1.0).abs(),
                (db / r - 1.0).abs(),
                6.0 * s / d
            );
        }
        for kn in [0.01, 0.05, 0.1, 0.3, 0.5, 1.0, 3.0, 10.0, 100.0] {
            println!(
                "| {kn} | {:.4} | {:.4} | {:.4} | {:.4} |",
                FlowModel::FirstOrderSlip.factor(kn),
                FlowModel::SecondOrderSlip.factor(kn),
                FlowModel::FukuiKaneko.factor(kn),
                FlowModel::FukuiKaneko.factor_and_derivative(kn).1
            );
        }
        let t0 = std::time::Instant::now();
        let mut acc = 0.0;
        for i in 0..1_000_000 {
            let kn = 1e-3 * (1.0 + i as f64 * 1e-3);
            acc += FlowModel::FukuiKaneko.factor_and_derivative(kn).1;
        }
        println!("1e6 evaluations: {:?} ({acc})", t0.elapsed());
        println!("{:?}", FlowFactor::get().flow_rate_and_derivative(1.0));
        println!("{:?}", FlowFactor::get().flow_rate_and_derivative(1.0716));
    }
}
