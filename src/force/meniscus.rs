//! Lubricant menisci with memory: capillary bridges between the head and the asperity peaks of a
//! lubricated disk, formed when the local gap falls below the mobile lubricant thickness and
//! broken only past a larger rupture distance, with the bridge population carried in a state,
//! and optionally the lubricant the head picks up in contact as a second state.
//!
//! See `docs/analyses.md` (section "Lubricant menisci") for the equations, the parameter ranges
//! and their sources.

use std::f64::consts::PI;
use std::sync::Arc;

use super::stateful::{Branch, RatePartials, StateForce, StatefulTerm, MAX_TERM_STATES};
use super::{Footprint, ForceEval, Gaps, Scaled};
use crate::error::{check_non_negative, check_positive};
use crate::quadrature::{Table, TableOptions};
use crate::surface::PeakDistribution;
use crate::{Error, Result};

/// Which surfaces the lubricant wets, which sets the force of one bridge on a sphere of radius
/// `R` (Israelachvili, *Intermolecular and Surface Forces*, 3rd ed., §17.7, sphere on a flat).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Wetting {
    /// The disk's lubricant wets the disk fully (θ = 0 there) and meets the head at the contact
    /// angle θ: `2πRγ(1 + cos θ)`.
    #[default]
    Disk,
    /// Both surfaces carry lubricant at the contact angle θ (a head that has picked up
    /// lubricant): `4πRγ cos θ`.
    Both,
}

impl Wetting {
    /// The force of one bridge (N) on a sphere of radius `radius` (m) for surface tension
    /// `gamma` (N/m) and contact angle `theta` (rad).
    ///
    /// ```
    /// use hdi_tribology::force::Wetting;
    /// let (r, g) = (1e-7, 0.025);
    /// let f = Wetting::Disk.bridge_force(r, g, 0.0);
    /// assert!((f - 4.0 * std::f64::consts::PI * r * g).abs() < 1e-20);
    /// assert_eq!(f, Wetting::Both.bridge_force(r, g, 0.0));
    /// ```
    pub fn bridge_force(self, radius: f64, gamma: f64, theta: f64) -> f64 {
        match self {
            Wetting::Disk => 2.0 * PI * radius * gamma * (1.0 + theta.cos()),
            Wetting::Both => 4.0 * PI * radius * gamma * theta.cos(),
        }
    }
}

/// The rupture distance of a liquid bridge of volume `volume` (m³) at contact angle `theta`
/// (rad): `s_r = (1 + θ/2) V^{1/3}` (Lian, Thornton & Adams 1993).
///
/// ```
/// let s = hdi_tribology::force::lian_rupture_distance(1e-24, 0.0);
/// assert!((s - 1e-8).abs() < 1e-22);
/// ```
pub fn lian_rupture_distance(volume: f64, theta: f64) -> f64 {
    (1.0 + 0.5 * theta) * volume.cbrt()
}

/// The lubricant and its bridges.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeniscusParams {
    /// Surface tension γ, N/m.
    pub surface_tension: f64,
    /// Contact angle θ, rad, in [0, π/2].
    pub contact_angle: f64,
    /// Which surfaces are wet.
    pub wetting: Wetting,
    /// Mobile lubricant thickness `t_m` (m, > 0): a bridge forms where the local gap falls below
    /// it.
    pub mobile_thickness: f64,
    /// Rupture distance `s_r` (m); `None`: the Lian law with the bridge volume `π R t_m²`.
    pub rupture_distance: Option<f64>,
    /// Healing time τ_h (s, > 0): the closest approach relaxes towards the gap with it.
    pub healing_time: f64,
    /// Formation time τ_f (s, ≥ 0): the closest approach follows a closing gap with it; 0 for
    /// bridges that form at once (the closest approach is the gap while it closes).
    pub formation_time: f64,
    /// The head's pick-up of lubricant (a second state); `None`: no pick-up, one state.
    pub pickup: Option<Pickup>,
}

/// The lubricant film the head picks up in contact and loses over time, `t_h`:
///
/// `ṫ_h = r_p S(d − t_m) − t_h/τ_p`,
///
/// with `S(d − t_m)` the fraction of the peaks whose top lies within the disk's mobile film of
/// the head at the bulge gap `d` (the survival of the peak heights): the head gains lubricant
/// at the rate `r_p` with every peak wetting it, and loses it with the time `τ_p` (spreading,
/// evaporation, transfer back). A bridge then forms where the local gap falls below
/// `t_m + t_h` (the disk's mobile film plus the head's), and breaks past `t_m + t_h + s_r`.
/// At rest `t_h = r_p τ_p S(d − t_m)`: the saturation `r_p τ_p` when every peak wets the head.
///
/// ```
/// use hdi_tribology::force::Pickup;
/// let p = Pickup { rate: 1e-6, loss_time: 1e-3 };
/// assert!((p.saturation() - 1e-9).abs() < 1e-24);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pickup {
    /// Gain rate `r_p` with every peak wetting the head (m/s, > 0).
    pub rate: f64,
    /// Loss time `τ_p` (s, > 0).
    pub loss_time: f64,
}

impl Pickup {
    /// The film at rest with every peak wetting the head, `r_p τ_p` (m).
    pub fn saturation(&self) -> f64 {
        self.rate * self.loss_time
    }
}

/// Lubricant menisci on the asperity peaks, with the closest approach `d*` as their state.
///
/// The peaks above `z` carry bridges when `z > max(d* − t_m, d − t_m − s_r)`: a bridge formed at
/// the closest approach (local gap below `t_m`) and not yet stretched past `t_m + s_r`. With the
/// per-bridge force `f_b` ([`Wetting::bridge_force`]) and the asperity density `η_s`, the mean
/// pressure is `−f_b η_s M_0(e)`, `e = d − t_m + max(d* − d, −s_r)`, `M_0` the survival of the
/// peak heights. Over a paraboloid footprint the bands of `d` and `d*` shift together (the bulge
/// keeps its shape), so Derjaguin's integral is the partial moment `M_1` in closed form; the
/// force is tabulated in `e` once.
///
/// `d*` obeys `ẋ = (d − x)/τ` with `τ = τ_f` while the gap closes below `x` and `τ_h` while it
/// is above: two branches split by the sign of `d − d*` ([`StatefulTerm::switching`]), which
/// the simulations hold over each step and switch at the located root. At rest `d* = d` (the
/// statics): the branch of bridges formed at the gap itself.
///
/// With `τ_f = 0` bridges form at once: on the formation branch the force reads the gap
/// ([`StatefulTerm::force_on`]), `d*` is held, the branch ends where the gap stops closing
/// ([`StatefulTerm::switching_on`]) and `d*` is set to the gap there ([`StatefulTerm::enter`]).
/// That law needs the branch held, as every simulation holds it: by the sign alone
/// ([`StatefulTerm::rates`]) `d*` would not follow a closing gap.
///
/// ```
/// use std::sync::Arc;
/// use hdi_tribology::force::{Footprint, Gaps, Meniscus, MeniscusParams, StatefulTerm, Wetting};
/// use hdi_tribology::surface::Gaussian;
/// # fn main() -> hdi_tribology::Result<()> {
/// let p = MeniscusParams {
///     surface_tension: 0.025, contact_angle: 0.0, wetting: Wetting::Disk,
///     mobile_thickness: 1e-9, rupture_distance: Some(3e-9),
///     healing_time: 1e-5, formation_time: 1e-7, pickup: None,
/// };
/// let peaks = Arc::new(Gaussian::new(0.0, 0.7e-9)?);
/// let m = Meniscus::new(p, 1e-7, 1.5e14, peaks, Footprint::Flat { area_m2: 1e-8 })?;
/// // On approach (d* = d) and on separation (d* = d − 1 nm) at the same gap:
/// let g = Gaps::same(1.5e-9);
/// let approach = m.force(g, &[1.5e-9]).force.value;
/// let separation = m.force(g, &[0.5e-9]).force.value;
/// assert!(separation < approach && approach < 0.0);
/// # Ok(()) }
/// ```
#[derive(Clone, Debug)]
pub struct Meniscus {
    params: MeniscusParams,
    bridge_force: f64,
    rupture: f64,
    density: f64,
    peaks: Arc<dyn PeakDistribution>,
    footprint: Footprint,
    /// The force and its slope in `e`, where tabulated.
    table: Option<Arc<Table>>,
    /// With a pick-up: the fraction of the peaks above `z` and its slope, where tabulated.
    survival: Option<Arc<Table>>,
}

impl Meniscus {
    /// The menisci on asperities of radius `asperity_radius` (m) and areal density
    /// `asperity_density` (m⁻²) with heights from `peaks`, over `footprint`. Errors name the
    /// field of the `[lubricant]` scene section.
    pub fn new(
        params: MeniscusParams,
        asperity_radius: f64,
        asperity_density: f64,
        peaks: Arc<dyn PeakDistribution>,
        footprint: Footprint,
    ) -> Result<Self> {
        check_positive("surface_tension_n_per_m", params.surface_tension)?;
        let theta = params.contact_angle;
        if !(theta.is_finite() && (0.0..=0.5 * PI).contains(&theta)) {
            return Err(Error::invalid(
                "contact_angle_deg",
                format!(
                    "must lie in [0, 90] deg, got {} deg",
                    crate::units::fmt_short(theta.to_degrees())
                ),
            ));
        }
        check_positive("mobile_thickness_m", params.mobile_thickness)?;
        if let Some(s) = params.rupture_distance {
            check_non_negative("rupture_distance_m", s)?;
        }
        check_positive("healing_time_s", params.healing_time)?;
        check_non_negative("formation_time_s", params.formation_time)?;
        if let Some(p) = params.pickup {
            check_positive("pickup_rate_m_per_s", p.rate)?;
            check_positive("pickup_loss_time_s", p.loss_time)?;
        }
        check_positive("asperity_radius_m", asperity_radius)?;
        check_positive("asperity_density_per_m2", asperity_density)?;
        footprint.validate("footprint")?;
        let rupture = params.rupture_distance.unwrap_or_else(|| {
            lian_rupture_distance(
                PI * asperity_radius * params.mobile_thickness.powi(2),
                theta,
            )
        });
        Ok(Meniscus {
            bridge_force: params.wetting.bridge_force(
                asperity_radius,
                params.surface_tension,
                theta,
            ),
            params,
            rupture,
            density: asperity_density,
            peaks,
            footprint,
            table: None,
            survival: None,
        })
    }

    /// The same term with its force tabulated for bulge gaps in `[lo, hi]` (m); outside, and
    /// for discrete peak ensembles (whose survival has steps), it evaluates the partial moments
    /// directly.
    pub fn tabulated(mut self, (lo, hi): (f64, f64), opts: &TableOptions) -> Result<Self> {
        if !self.tabulates() {
            return Ok(self);
        }
        let (t_m, s_r) = (self.params.mobile_thickness, self.rupture);
        // The head's film shifts `e` down by up to its saturation.
        let t_h = self.params.pickup.map_or(0.0, |p| p.saturation());
        let table = Table::build(|e| self.direct(e), lo - t_m - t_h - s_r, hi - t_m, opts)?;
        self.table = Some(Arc::new(table));
        if self.params.pickup.is_some() {
            let survival = Table::build(|z| Ok(self.survival_direct(z)), lo - t_m, hi - t_m, opts)?;
            self.survival = Some(Arc::new(survival));
        }
        Ok(self)
    }

    /// Whether [`Meniscus::tabulated`] gives the term a table (not for discrete peak ensembles).
    pub(crate) fn tabulates(&self) -> bool {
        self.peaks.atoms().is_none()
    }

    /// The force table of [`Meniscus::tabulated`], if any.
    pub(crate) fn table(&self) -> Option<&Table> {
        self.table.as_deref()
    }

    /// The same term with a table that [`Meniscus::tabulated`] built for it before (read back
    /// from the table cache).
    pub(crate) fn with_table(mut self, table: Table) -> Self {
        self.table = Some(Arc::new(table));
        self
    }

    /// The parameters.
    pub fn params(&self) -> MeniscusParams {
        self.params
    }

    /// The force of one bridge `f_b` (N).
    pub fn bridge_force(&self) -> f64 {
        self.bridge_force
    }

    /// The rupture distance `s_r` in use (m).
    pub fn rupture_distance(&self) -> f64 {
        self.rupture
    }

    /// The force (N, negative: an attraction) and its slope when the peaks above `e` carry
    /// bridges at the gap `e + t_m`, by direct evaluation of the partial moments.
    fn direct(&self, e: f64) -> Result<(f64, f64)> {
        let k = -self.bridge_force * self.density;
        let m = |z: f64, p: f64| self.peaks.partial_moment(z, p);
        let band = |p: f64, delta: f64| {
            if delta.is_infinite() {
                m(e, p)
            } else {
                m(e, p) - m(e + delta, p)
            }
        };
        let (f, df) = self.footprint.reduce(
            k,
            || Ok::<_, Error>((m(e, 0.0).into(), Scaled::new(-1.0, self.peaks.pdf(e)))),
            |delta| Ok((band(1.0, delta).into(), band(0.0, delta).into())),
        )?;
        if f.is_finite() && df.is_finite() {
            Ok((f, df))
        } else {
            Err(super::ForceError::Meniscus {
                e_nm: e * 1e9,
                force_n: f,
                slope_n_per_m: df,
            }
            .into())
        }
    }

    /// The fraction of the peaks above `z` and its slope `−p(z)`.
    fn survival_direct(&self, z: f64) -> (f64, f64) {
        (self.peaks.partial_moment(z, 0.0), -self.peaks.pdf(z))
    }

    /// The fraction of the peaks above `z` and its slope, from the table where there is one.
    fn survival(&self, z: f64) -> (f64, f64) {
        self.survival
            .as_ref()
            .and_then(|t| t.eval(z))
            .unwrap_or_else(|| self.survival_direct(z))
    }

    /// The head's film at rest at the bulge gap `d` (m), and its slope in `d`: `r_p τ_p S(d − t_m)`
    /// (0 without a pick-up).
    pub fn pickup_at_rest(&self, d: f64) -> (f64, f64) {
        match self.params.pickup {
            Some(p) => {
                let (s, ds) = self.survival(d - self.params.mobile_thickness);
                (p.saturation() * s, p.saturation() * ds)
            }
            None => (0.0, 0.0),
        }
    }

    /// The force and its slope in `e` (0 where the evaluation fails: far outside the peaks).
    fn at(&self, e: f64) -> (f64, f64) {
        if let Some((f, df)) = self.table.as_ref().and_then(|t| t.eval(e)) {
            return (f, df);
        }
        self.direct(e).unwrap_or((0.0, 0.0))
    }

    /// The force at the bulge gap `d` with the closest approach `d_star` (m), and its partial
    /// derivatives along `d` and `d_star`.
    pub fn force_at(&self, d: f64, d_star: f64) -> (f64, f64, f64) {
        let (f, d_bulge, d_star, _) = self.force_with_pickup(d, d_star, 0.0);
        (f, d_bulge, d_star)
    }

    /// The force with the head's film `t_h` (m) on top of the disk's mobile film, and its partial
    /// derivatives along `d`, `d_star` and `t_h`. With `t_h = 0` it is [`Meniscus::force_at`].
    pub fn force_with_pickup(&self, d: f64, d_star: f64, t_h: f64) -> (f64, f64, f64, f64) {
        let (e, held) = self.band_edge(d, d_star, t_h);
        let (f, df) = self.at(e);
        if held {
            (f, 0.0, df, -df)
        } else {
            (f, df, 0.0, -df)
        }
    }

    /// The value of [`Meniscus::force_with_pickup`] alone (the same number).
    fn force_value_at(&self, d: f64, d_star: f64, t_h: f64) -> f64 {
        let e = self.band_edge(d, d_star, t_h).0;
        match self.table.as_ref().and_then(|t| t.value(e)) {
            Some(f) => f,
            None => self.at(e).0,
        }
    }

    /// The lowest peak height `e` that carries a bridge at the gap `d` after the closest
    /// approach `d_star` with the head's film `t_h`, and whether the bridges are those formed
    /// at `d_star` (true) or those not yet stretched past the rupture distance (false).
    fn band_edge(&self, d: f64, d_star: f64, t_h: f64) -> (f64, bool) {
        let t = self.params.mobile_thickness + t_h;
        if d - d_star < self.rupture {
            (d_star - t, true)
        } else {
            (d - t - self.rupture, false)
        }
    }

    /// The head's film `t_h` in the term's states (0 without a pick-up).
    fn head_film(&self, x: &[f64]) -> f64 {
        if self.params.pickup.is_some() {
            x[1]
        } else {
            0.0
        }
    }

    /// Whether bridges form at once (`τ_f = 0`): on the formation branch `d*` is the gap itself,
    /// and the branch ends where the gap stops closing.
    fn instant(&self) -> bool {
        self.params.formation_time == 0.0
    }

    /// Whether `branch` is the formation branch of instant bridges.
    fn forming_at_once(&self, branch: Branch) -> bool {
        branch == Branch::Lower && self.instant()
    }

    /// The time constant of `d*` on `branch`: healing above the gap's switch, formation below.
    fn tau(&self, branch: Branch) -> f64 {
        match branch {
            Branch::Upper => self.params.healing_time,
            Branch::Lower => self.params.formation_time,
        }
    }
}

impl StatefulTerm for Meniscus {
    fn name(&self) -> &str {
        "meniscus"
    }
    /// One (`d*`), or two with a pick-up (`d*`, `t_h`).
    fn states(&self) -> usize {
        1 + self.params.pickup.is_some() as usize
    }
    fn equilibrium(&self, g: Gaps, x: &mut [f64]) {
        x[0] = g.bulge;
        if self.params.pickup.is_some() {
            x[1] = self.pickup_at_rest(g.bulge).0;
        }
    }
    fn rates(&self, g: Gaps, x: &[f64], dx: &mut [f64]) {
        self.rates_on(Branch::of(self.switching(g, x)), g, x, dx)
    }
    fn rate_partials(&self, g: Gaps, x: &[f64]) -> RatePartials {
        self.rate_partials_on(Branch::of(self.switching(g, x)), g, x)
    }
    /// Two branches, healing and formation.
    fn switches(&self) -> bool {
        true
    }
    /// `d − d*`: healing where non-negative, formation where the gap is below `d*`.
    fn switching(&self, g: Gaps, x: &[f64]) -> f64 {
        g.bulge - x[0]
    }
    /// Formation at once holds `d*` where the branch began (the force reads the gap) and sets it
    /// to the gap where the gap stops closing ([`StatefulTerm::enter`]).
    fn rates_on(&self, branch: Branch, g: Gaps, x: &[f64], dx: &mut [f64]) {
        dx[0] = if self.forming_at_once(branch) {
            0.0
        } else {
            (g.bulge - x[0]) / self.tau(branch)
        };
        if let Some(p) = self.params.pickup {
            let (s, _) = self.survival(g.bulge - self.params.mobile_thickness);
            dx[1] = p.rate * s - x[1] / p.loss_time;
        }
    }
    /// `1/τ` of the branch, or the pick-up's loss rate where that is faster.
    fn fastest_rate_on(&self, branch: Branch) -> Option<f64> {
        let loss = self.params.pickup.map(|p| 1.0 / p.loss_time);
        if self.forming_at_once(branch) {
            return loss;
        }
        Some((1.0 / self.tau(branch)).max(loss.unwrap_or(0.0)))
    }
    fn rate_partials_on(&self, branch: Branch, g: Gaps, _x: &[f64]) -> RatePartials {
        let rate = if self.forming_at_once(branch) {
            0.0
        } else {
            1.0 / self.tau(branch)
        };
        let mut p = RatePartials::default();
        p.d_bulge[0] = rate;
        p.d_state[0][0] = -rate;
        if let Some(k) = self.params.pickup {
            let (_, ds) = self.survival(g.bulge - self.params.mobile_thickness);
            p.d_bulge[1] = k.rate * ds;
            p.d_state[1][1] = -1.0 / k.loss_time;
        }
        p
    }
    fn force_value(&self, g: Gaps, x: &[f64]) -> f64 {
        self.force_value_at(g.bulge, x[0], self.head_film(x))
    }
    /// While bridges form at once: the gap's rate (the branch ends where it stops closing).
    fn switching_on(
        &self,
        branch: Branch,
        gaps: &dyn Fn() -> Gaps,
        rate: &dyn Fn() -> Gaps,
        x: &[f64],
    ) -> f64 {
        if self.forming_at_once(branch) {
            rate().bulge
        } else {
            self.switching(gaps(), x)
        }
    }
    /// While bridges form at once the closest approach is the gap: `F(d − t_m − t_h)`.
    fn force_on(&self, branch: Branch, g: Gaps, x: &[f64]) -> StateForce {
        if !self.forming_at_once(branch) {
            return self.force(g, x);
        }
        // `d* = d`: the slope along the gap is the sum of the two partials.
        let (f, d_bulge, d_star, d_th) =
            self.force_with_pickup(g.bulge, g.bulge, self.head_film(x));
        let mut d_state = [0.0; MAX_TERM_STATES];
        if self.params.pickup.is_some() {
            d_state[1] = d_th;
        }
        StateForce {
            force: ForceEval {
                value: f,
                d_bulge: d_bulge + d_star,
                d_pad: 0.0,
            },
            d_state,
        }
    }
    fn force_value_on(&self, branch: Branch, g: Gaps, x: &[f64]) -> f64 {
        let d_star = if self.forming_at_once(branch) {
            g.bulge
        } else {
            x[0]
        };
        self.force_value_at(g.bulge, d_star, self.head_film(x))
    }
    /// Leaving the formation at once, where the gap stops closing: `d*` is the gap there.
    fn enter(&self, branch: Branch, g: Gaps, x: &mut [f64]) {
        if branch == Branch::Upper && self.instant() {
            x[0] = g.bulge;
        }
    }
    fn force(&self, g: Gaps, x: &[f64]) -> StateForce {
        let mut d_state = [0.0; MAX_TERM_STATES];
        let t_h = self.head_film(x);
        let (f, d_bulge, d_star, d_th) = self.force_with_pickup(g.bulge, x[0], t_h);
        d_state[0] = d_star;
        if self.params.pickup.is_some() {
            d_state[1] = d_th;
        }
        StateForce {
            force: ForceEval {
                value: f,
                d_bulge,
                d_pad: 0.0,
            },
            d_state,
        }
    }
    /// `d*` is a gap and `t_h` a thickness: the displacement tolerance.
    fn tolerances(&self, displacement: f64, atol: &mut [f64]) {
        atol[0] = displacement;
        if self.params.pickup.is_some() {
            atol[1] = displacement;
        }
    }
    /// At rest `d* = d` and `t_h = r_p τ_p S(d − t_m)`, and the force sees `d`, `d*` and `t_h`
    /// alone.
    fn rests_on_bulge_gap(&self) -> bool {
        true
    }
    /// `ḋ* = (d − d*)/τ` (τ_h or τ_f by branch; 0 while bridges form at once) and
    /// `ṫ_h = r_p S(d − t_m) − t_h/τ_p`.
    fn rates_diagonal_affine(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::Gaussian;

    /// 1 nm of mobile lubricant at 0.3 rad, τ_h = 10 µs, τ_f = 0.1 µs, no pick-up.
    fn sample() -> MeniscusParams {
        MeniscusParams {
            surface_tension: 0.025,
            contact_angle: 0.3,
            wetting: Wetting::Disk,
            mobile_thickness: 1e-9,
            rupture_distance: None,
            healing_time: 1e-5,
            formation_time: 1e-7,
            pickup: None,
        }
    }

    #[test]
    fn the_table_agrees_with_direct_evaluation() {
        let p = sample();
        let peaks = Arc::new(Gaussian::new(0.0, 0.7e-9).unwrap());
        for footprint in Footprint::samples() {
            let m = Meniscus::new(p, 1e-7, 1.5e14, peaks.clone(), footprint).unwrap();
            let t = m
                .clone()
                .tabulated((-4e-9, 3e-8), &TableOptions::default())
                .unwrap();
            for e in [-3e-9, -1e-9, 0.0, 1.3e-9, 4e-9] {
                let (a, b) = (m.at(e), t.at(e));
                // the table's promise: rel_tol of the value, or its abs_tol of 1e-16 N
                let allowed = (2e-9 * a.0.abs()).max(1e-16);
                assert!(
                    (a.0 - b.0).abs() <= allowed,
                    "{footprint:?} {e}: {a:?} {b:?}"
                );
            }
        }
    }

    /// Formation at once: on the formation branch the force is that of bridges at the gap, its
    /// slope along the gap is the derivative of that value (a central difference), and entering
    /// the healing branch sets `d*` to the gap with the force unchanged; a rate that does not
    /// move `d*`, and a switching function that is the gap's rate.
    #[test]
    fn formation_at_once_reads_the_gap_and_hands_over_continuously() {
        let p = MeniscusParams {
            formation_time: 0.0,
            pickup: Some(Pickup {
                rate: 1e-5,
                loss_time: 5e-5,
            }),
            ..sample()
        };
        let peaks = Arc::new(Gaussian::new(0.0, 0.7e-9).unwrap());
        let m = Meniscus::new(p, 1e-7, 1.5e14, peaks, Footprint::Flat { area_m2: 1e-12 })
            .unwrap()
            .tabulated((-4e-9, 3e-8), &TableOptions::default())
            .unwrap();
        let (d, t_h) = (0.6e-9, 0.1e-9);
        // d* from an earlier, higher point of the closing gap
        let x = [1.5e-9, t_h];
        let g = Gaps::same(d);
        let f = m.force_on(Branch::Lower, g, &x);
        let value = m.force_value_on(Branch::Lower, g, &x);
        assert_eq!(f.force.value, value);
        assert_eq!(value, m.force_with_pickup(d, d, t_h).0);
        let h = 1e-13;
        let at = |d: f64| m.force_value_on(Branch::Lower, Gaps::same(d), &x);
        let slope = (at(d + h) - at(d - h)) / (2.0 * h);
        assert!(
            (f.force.d_bulge - slope).abs() <= 1e-6 * slope.abs(),
            "{} against {slope}",
            f.force.d_bulge
        );
        assert_eq!(f.d_state[0], 0.0);
        let mut dx = [1.0, 0.0];
        m.rates_on(Branch::Lower, g, &x, &mut dx);
        assert_eq!(dx[0], 0.0);
        let rate = || Gaps::same(-2e-4);
        assert_eq!(m.switching_on(Branch::Lower, &|| g, &rate, &x), -2e-4);
        assert_eq!(m.fastest_rate_on(Branch::Lower), Some(1.0 / 5e-5));
        let mut y = x;
        m.enter(Branch::Upper, g, &mut y);
        assert_eq!(y, [d, t_h]);
        assert_eq!(m.force_value_on(Branch::Upper, g, &y), value);
        // entering formation changes nothing; a formation time above zero keeps its law
        m.enter(Branch::Lower, g, &mut y);
        assert_eq!(y, [d, t_h]);
        let slow = Meniscus::new(
            MeniscusParams {
                formation_time: 1e-7,
                ..p
            },
            1e-7,
            1.5e14,
            Arc::new(Gaussian::new(0.0, 0.7e-9).unwrap()),
            Footprint::Flat { area_m2: 1e-12 },
        )
        .unwrap();
        assert_eq!(
            slow.force_value_on(Branch::Lower, g, &x),
            slow.force_value(g, &x)
        );
        assert_eq!(slow.switching_on(Branch::Lower, &|| g, &rate, &x), d - x[0]);
    }
}
