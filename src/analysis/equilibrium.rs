//! Static equilibria along the heater power: the S-curve, its folds and their stability.
//!
//! At fixed heater power and DC voltage the slider rests where `K q = e₀ F_ab(q₀) + b F_if(d)`
//! (for the rigid slider `F_ab(y, 0) + F_if(d) = 0`). The equilibria are parametrised by the bulge
//! gap `d`: for each `d` the static balance ([`SliderModel::balance`]) gives the coordinates `q`,
//! hence the protrusion `δ = h0 + bᵀq − d` and the power `P = δ/η`. An equilibrium is stable
//! where the total stiffness condensed onto the bulge ([`SliderModel::total_stiffness`];
//! `k_ab − ∂F_if/∂y` for the rigid slider) is positive; folds are where it vanishes.

use super::roots::{brent, brent_polished};
use crate::error::{failure_kind, num, Error, Result, Stage};
use crate::force::ForceEval;
use crate::model::{Dofs, LinearBalance, Rest, SliderModel, StaticBounds};
use crate::units::{to_mw, to_nm};
use serde::Serialize;

impl Stage {
    /// The stable flying equilibrium at a heater power.
    pub const FLYING_EQUILIBRIUM: Stage = Stage::named("flying equilibrium");
}

/// Why there is no stable flying equilibrium at a heater power. Numbers are in engineering
/// units, as the field names say.
///
/// ```
/// use hdi_tribology::analysis::equilibrium::FlyingError;
/// let e: hdi_tribology::Error = FlyingError::NoFlyingEquilibrium { power_mw: 60.0 }.into();
/// assert_eq!(e.to_string(), "flying equilibrium: no flying equilibrium at 60.0000 mW inside the table range");
/// ```
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FlyingError {
    /// The flying branch ends at a fold before the power is reached; the head is in contact at
    /// that power.
    #[error(
        "the flying branch ends at a fold (d = {} nm) before the protrusion of {} mW is reached: \
         the head is in contact there",
        num(*.fold_gap_nm),
        num(*.power_mw)
    )]
    FlyingBranchEnds {
        /// The heater power asked for (mW).
        power_mw: f64,
        /// Bulge gap of the fold (nm).
        fold_gap_nm: f64,
    },
    /// None inside the force tables at this power.
    #[error("no flying equilibrium at {} mW inside the table range", num(*.power_mw))]
    NoFlyingEquilibrium {
        /// The heater power asked for (mW).
        power_mw: f64,
    },
    /// The largest tabulated gap is already below the equilibrium.
    #[error(
        "the largest tabulated gap ({} nm) is already below the equilibrium: widen the table range",
        num(*.gap_nm)
    )]
    TableTooNarrow {
        /// The largest tabulated gap (nm).
        gap_nm: f64,
    },
}

failure_kind!(FlyingError, convergence = |_| false, {
        FlyingBranchEnds => Stage::FLYING_EQUILIBRIUM,
        NoFlyingEquilibrium => Stage::FLYING_EQUILIBRIUM,
        TableTooNarrow => Stage::FLYING_EQUILIBRIUM,
});

/// One equilibrium of the slider.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Equilibrium {
    /// Bulge gap `d` (m).
    #[serde(rename = "d_m")]
    pub d: f64,
    /// Air-bearing displacement `y` of the slider body (m): `q₀`.
    #[serde(rename = "y_m")]
    pub y: f64,
    /// All coordinates `q` of the structure (m, rad); not serialized (its length is the
    /// structure's, which the equilibrium does not know).
    #[serde(skip)]
    pub q: Dofs,
    /// Protrusion `δ` (m).
    #[serde(rename = "protrusion_m")]
    pub protrusion: f64,
    /// Heater power `P = δ/η` (W).
    #[serde(rename = "power_w")]
    pub power: f64,
    /// Total stiffness `k_ab − ∂F_if/∂y` (N/m); positive is stable.
    #[serde(rename = "stiffness_n_per_m")]
    pub stiffness: f64,
    /// Interface force (N).
    #[serde(rename = "interface_force_n")]
    pub interface_force: f64,
    /// Contact force (N).
    #[serde(rename = "contact_force_n")]
    pub contact_force: f64,
}

impl Equilibrium {
    /// Whether the equilibrium is stable.
    pub fn is_stable(&self) -> bool {
        self.stiffness > 0.0
    }

    /// The state of rest at this equilibrium, to start a simulation from.
    pub fn rest(&self) -> Rest {
        Rest {
            q: self.q,
            protrusion: self.protrusion,
            interface_force: self.interface_force,
        }
    }
}

/// Where an S-curve branch turns back: a jump into or out of contact.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Fold {
    /// Heater power at the fold (W).
    #[serde(rename = "power_w")]
    pub power: f64,
    /// Bulge gap at the fold (m).
    #[serde(rename = "d_m")]
    pub d: f64,
    /// `true` where the power has a local maximum along decreasing `d` (the flying branch ends
    /// and the head jumps into contact); `false` at a local minimum (the contact branch ends).
    pub jump_in: bool,
}

/// The gap grid of a scan, and how the brackets it finds are refined.
///
/// ```
/// use hdi_tribology::analysis::equilibrium::ScanGrid;
/// let g = ScanGrid::default();
/// assert!(g.fine_step < g.coarse_step && g.skip_proven);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScanGrid {
    /// Spacing (m) below `fine_until`.
    pub fine_step: f64,
    /// Spacing (m) above `fine_until`.
    pub coarse_step: f64,
    /// Gap (m) below which the fine spacing is used.
    pub fine_until: f64,
    /// Refine folds, threshold crossings and equilibria first on the force tables, then polish
    /// the root with direct forces from a small bracket around it (the default: about half as
    /// many direct evaluations). `false` runs Brent's method on the direct forces over the whole
    /// grid interval. Both give the root to the same tolerance (1e-12 relative).
    pub polish_from_tables: bool,
    /// Let the touchdown and take-off scans pass over stretches of the grid without computing
    /// their equilibria where bounds on the force tables prove that none of them would change
    /// the scan (every one stable with the contact force on the same side of the threshold, or
    /// every one unstable, or every power on the same side of the one sought). The results are
    /// those of the full scan, to the bit; `false` computes every grid point. The bounds need a
    /// static balance linear in the interface force (a linear air bearing and no pad-gap term);
    /// other models compute every point either way.
    pub skip_proven: bool,
}

impl Default for ScanGrid {
    fn default() -> Self {
        ScanGrid {
            fine_step: 2e-12,
            coarse_step: 5e-11,
            fine_until: 5e-9,
            polish_from_tables: true,
            skip_proven: true,
        }
    }
}

/// Largest number of points a scan may have: about 80 MB of gaps and far more equilibria than
/// any scene needs. A finer grid is refused rather than allowed to exhaust memory.
pub const MAX_SCAN_POINTS: usize = 10_000_000;

impl ScanGrid {
    /// Checks that the steps are finite and positive, `fine_until` finite, and that the scan of
    /// `[lo, hi]` has at most [`MAX_SCAN_POINTS`] points. Errors name `grid.<field>`.
    ///
    /// ```
    /// use hdi_tribology::analysis::equilibrium::ScanGrid;
    /// assert!(ScanGrid::default().validate(-4e-9, 3e-8).is_ok());
    /// let g = ScanGrid { fine_step: 0.0, ..ScanGrid::default() };
    /// assert!(g.validate(0.0, 1e-8).unwrap_err().to_string().contains("grid.fine_step"));
    /// ```
    pub fn validate(&self, lo: f64, hi: f64) -> Result<()> {
        crate::error::check_positive("grid.fine_step", self.fine_step)?;
        crate::error::check_positive("grid.coarse_step", self.coarse_step)?;
        crate::error::check_finite("grid.fine_until", self.fine_until)?;
        crate::error::check_finite("grid.lo", lo)?;
        crate::error::check_finite("grid.hi", hi)?;
        // Points below and above `fine_until`, counted in floating point (no overflow).
        let fine_span = (self.fine_until.min(hi) - lo).max(0.0);
        let coarse_span = (hi - self.fine_until.max(lo)).max(0.0);
        let points = fine_span / self.fine_step + coarse_span / self.coarse_step + 2.0;
        if points > MAX_SCAN_POINTS as f64 {
            let (name, step) = if fine_span / self.fine_step >= coarse_span / self.coarse_step {
                ("grid.fine_step", self.fine_step)
            } else {
                ("grid.coarse_step", self.coarse_step)
            };
            return Err(Error::invalid(
                name,
                format!(
                    "{step:e} m makes {points:.3e} points on [{lo:e}, {hi:e}] m, more than \
                     {MAX_SCAN_POINTS}"
                ),
            ));
        }
        Ok(())
    }

    /// Gaps from `hi` down to `lo`, decreasing; fails when [`ScanGrid::validate`] does.
    pub fn descending(&self, lo: f64, hi: f64) -> Result<Vec<f64>> {
        Ok(self.iter_descending(lo, hi)?.collect())
    }

    /// The gaps of [`ScanGrid::descending`], made one at a time (a scan that stops early makes
    /// only the points it reads).
    ///
    /// ```
    /// use hdi_tribology::analysis::equilibrium::ScanGrid;
    /// let g = ScanGrid::default();
    /// let lazy: Vec<f64> = g.iter_descending(-4e-9, 3e-8)?.collect();
    /// assert_eq!(lazy, g.descending(-4e-9, 3e-8)?);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn iter_descending(&self, lo: f64, hi: f64) -> Result<impl Iterator<Item = f64>> {
        self.validate(lo, hi)?;
        let (fine, coarse, until) = (self.fine_step, self.coarse_step, self.fine_until);
        let mut d = hi;
        let mut n = 0;
        let mut done = false;
        // Bounded: validate() capped the number of points.
        Ok(std::iter::from_fn(move || {
            if done {
                return None;
            }
            if d > lo && n < MAX_SCAN_POINTS {
                let out = d;
                d -= if d > until { coarse } else { fine };
                n += 1;
                return Some(out);
            }
            done = true;
            Some(lo)
        }))
    }
}

/// Passes over stretches of a scan's grid that bounds on the force tables prove uneventful
/// ([`ScanGrid::skip_proven`]): the stride grows while the proofs hold and shrinks, down to one
/// point, where they fail (near a fold, a threshold or the power sought, whose grid points are
/// then computed one by one).
pub(crate) struct Skipper<'a> {
    model: &'a SliderModel,
    linear: Option<LinearBalance>,
    stride: usize,
}

/// Largest stride of a [`Skipper`] (grid points).
const MAX_STRIDE: usize = 1024;

impl<'a> Skipper<'a> {
    /// A skipper for the equilibria of `model` at `V² = volt2`; it never skips unless
    /// `grid.skip_proven` is set and the model's balance is linear in the interface force.
    pub(crate) fn new(model: &'a SliderModel, volt2: f64, grid: &ScanGrid) -> Self {
        Skipper {
            model,
            linear: grid
                .skip_proven
                .then(|| model.linear_balance(volt2))
                .flatten(),
            stride: 16,
        }
    }

    /// How many grid points from `gaps[i]` on `quiet` proves uneventful from the bounds of
    /// their equilibria ([`SliderModel::static_bounds`]); 0 when none (compute `gaps[i]`).
    pub(crate) fn skip(
        &mut self,
        gaps: &[f64],
        i: usize,
        quiet: impl Fn(&StaticBounds) -> bool,
    ) -> usize {
        let Some(lin) = &self.linear else { return 0 };
        loop {
            let m = self.stride.min(gaps.len().saturating_sub(i));
            if m == 0 {
                return 0;
            }
            let (x, y) = (gaps[i], gaps[i + m - 1]);
            let proven = self
                .model
                .static_bounds(lin, x.min(y), x.max(y))
                .is_some_and(|b| quiet(&b));
            if proven {
                self.stride = (2 * self.stride).min(MAX_STRIDE);
                return m;
            }
            if self.stride == 1 {
                return 0;
            }
            self.stride /= 2;
        }
    }
}

/// Analyses in heater power need a heater that moves the bulge: `η > 0` (with `η = 0` every
/// power gives the same protrusion, and powers found from protrusions would be ±∞ or NaN).
pub(crate) fn check_heater(model: &SliderModel) -> Result<()> {
    crate::error::check_positive("heater.efficiency_m_per_w", model.efficiency()).map(|_| ())
}

/// Evaluates equilibria of one model at one `V²`, tabulated or exact.
#[derive(Clone, Copy, Debug)]
pub struct EquilibriumSolver<'a> {
    model: &'a SliderModel,
    volt2: f64,
    polish: bool,
}

impl<'a> EquilibriumSolver<'a> {
    /// A solver for `V² = volt2` (use `(V_dc − φ)²` for the DC equilibria).
    pub fn new(model: &'a SliderModel, volt2: f64) -> Self {
        EquilibriumSolver {
            model,
            volt2,
            polish: true,
        }
    }

    /// The same solver refining as `grid` says ([`ScanGrid::polish_from_tables`]).
    ///
    /// ```no_run
    /// use hdi_tribology::analysis::equilibrium::{EquilibriumSolver, ScanGrid};
    /// use hdi_tribology::{model::SliderModel, scene::Scene};
    /// let model = SliderModel::from_scene(&Scene::paper())?;
    /// let direct = ScanGrid { polish_from_tables: false, ..ScanGrid::default() };
    /// let solver = EquilibriumSolver::new(&model, 0.0).refining_as(&direct);
    /// let fold = solver.refine_fold(1.0e-9, 1.5e-9);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn refining_as(self, grid: &ScanGrid) -> Self {
        EquilibriumSolver {
            polish: grid.polish_from_tables,
            ..self
        }
    }

    /// The direct equilibrium where `quantity` of the equilibria changes sign in `[a, b]`, to
    /// 1e-12 relative in the gap: the last direct evaluation is reused, not repeated.
    fn refine(
        &self,
        a: f64,
        b: f64,
        quantity: impl Fn(&Equilibrium) -> f64,
    ) -> Result<Equilibrium> {
        let tol = fold_tolerance(a, b, self.model.nominal_clearance());
        let mut seen: Vec<Equilibrium> = Vec::new();
        let exact = |d| match self.at_gap_exact(d) {
            Ok(e) => {
                seen.push(e);
                quantity(&e)
            }
            Err(_) => f64::NAN,
        };
        let d = if self.polish {
            let approx = |d| self.at_gap(d).map_or(f64::NAN, |e| quantity(&e));
            brent_polished(approx, exact, a, b, tol)?
        } else {
            brent(exact, a, b, tol)?
        };
        match seen.iter().rev().find(|e| e.d == d) {
            Some(e) => Ok(*e),
            None => self.at_gap_exact(d),
        }
    }

    /// The equilibrium whose bulge gap is `d`, through the tables.
    pub fn at_gap(&self, d: f64) -> Result<Equilibrium> {
        let (q, f) = self.model.balance(d, self.volt2, false)?;
        Ok(self.assemble(d, q, &f))
    }

    /// The equilibrium whose bulge gap is `d`, from direct evaluation of every term.
    pub fn at_gap_exact(&self, d: f64) -> Result<Equilibrium> {
        let (q, f) = self.model.balance(d, self.volt2, true)?;
        Ok(self.assemble(d, q, &f))
    }

    /// The protrusion (m) of the equilibrium whose bulge gap is `d`, through the tables: the
    /// [`EquilibriumSolver::at_gap`] equilibrium's `protrusion`, without the rest of it.
    pub fn protrusion_at(&self, d: f64) -> Result<f64> {
        let (q, _) = self.model.balance(d, self.volt2, false)?;
        Ok(self.protrusion(d, &q))
    }

    /// `δ = h0 + bᵀq − d`: the gap geometry solved for the protrusion.
    fn protrusion(&self, d: f64, q: &Dofs) -> f64 {
        let m = self.model;
        m.nominal_clearance() + m.structure().bulge_displacement(q) - d
    }

    fn assemble(&self, d: f64, q: Dofs, f: &ForceEval) -> Equilibrium {
        let m = self.model;
        let protrusion = self.protrusion(d, &q);
        let g = m.gaps_at(d, q[0]);
        Equilibrium {
            d,
            y: q[0],
            q,
            protrusion,
            power: m.power_for(protrusion),
            stiffness: m.total_stiffness(&q, f),
            interface_force: f.value,
            contact_force: m.contact_force(g),
        }
    }

    /// Locates the gap in `[a, b]` where the stiffness changes sign, to `1e-12` relative.
    pub fn refine_fold(&self, a: f64, b: f64) -> Result<Equilibrium> {
        self.refine(a, b, |e| e.stiffness)
    }

    /// Locates the gap in `[a, b]` where the contact force equals `threshold`.
    pub fn refine_threshold(&self, a: f64, b: f64, threshold: f64) -> Result<Equilibrium> {
        self.refine(a, b, |e| e.contact_force - threshold)
    }
}

/// Absolute tolerance on a gap: 1e-12 relative to the larger of the gap and 1e-3·h0.
fn fold_tolerance(a: f64, b: f64, h0: f64) -> f64 {
    1e-12 * a.abs().max(b.abs()).max(1e-3 * h0)
}

/// The equilibria of a model over a range of gaps, with their folds.
#[derive(Clone, Debug, Serialize)]
pub struct SCurve {
    /// `V²` the curve was computed at (V²).
    #[serde(rename = "volt2_v2")]
    pub volt2: f64,
    /// Equilibria ordered by decreasing gap (increasing power on stable flying parts).
    pub points: Vec<Equilibrium>,
    /// Folds, located to 1e-12 relative in `d`, in order of decreasing gap.
    pub folds: Vec<Fold>,
}

/// The S-curve at the model's DC voltage `(V_dc − φ)²`, over the gaps `[d_lo, d_hi]` (`None`:
/// the model's table range).
///
/// ```no_run
/// use hdi_tribology::{analysis::equilibrium::{s_curve, ScanGrid}, model::SliderModel, scene::Scene};
/// let model = SliderModel::from_scene(&Scene::paper())?;
/// let curve = s_curve(&model, None, &ScanGrid::default())?;
/// for f in &curve.folds {
///     println!("fold at {:.3} mW, d = {:.3} nm", f.power * 1e3, f.d * 1e9);
/// }
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn s_curve(model: &SliderModel, range: Option<(f64, f64)>, grid: &ScanGrid) -> Result<SCurve> {
    check_heater(model)?;
    let volt2 = model.voltage().dc_squared();
    let (lo, hi) = range.unwrap_or_else(|| model.forces().table_range());
    if lo.partial_cmp(&hi) != Some(std::cmp::Ordering::Less) {
        return Err(Error::invalid(
            "range",
            format!("need d_lo < d_hi, got [{lo:e}, {hi:e}]"),
        ));
    }
    let solver = EquilibriumSolver::new(model, volt2).refining_as(grid);
    let mut points = Vec::new();
    for d in grid.descending(lo, hi)? {
        points.push(solver.at_gap(d)?);
    }
    let mut folds = Vec::new();
    for w in points.windows(2) {
        if (w[0].stiffness > 0.0) != (w[1].stiffness > 0.0) {
            let e = solver.refine_fold(w[1].d, w[0].d)?;
            // Along decreasing d a stable part that ends is a power maximum (jump into contact).
            folds.push(Fold {
                power: e.power,
                d: e.d,
                jump_in: w[0].stiffness > 0.0,
            });
        }
    }
    Ok(SCurve {
        volt2,
        points,
        folds,
    })
}

/// The stable flying equilibrium at heater power `power` (W) and `V² = volt2`: the first
/// equilibrium reached scanning down from the largest tabulated gap.
///
/// Fails when the flying branch ends (fold) before reaching that power: the head is then in
/// contact at that power.
///
/// ```no_run
/// use hdi_tribology::{analysis::equilibrium::{flying_equilibrium, ScanGrid}, model::SliderModel, scene::Scene};
/// let model = SliderModel::from_scene(&Scene::paper())?;
/// let e = flying_equilibrium(&model, 0.06, 0.0, &ScanGrid::default())?;
/// println!("d = {:.3} nm at 60 mW", e.d * 1e9);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn flying_equilibrium(
    model: &SliderModel,
    power: f64,
    volt2: f64,
    grid: &ScanGrid,
) -> Result<Equilibrium> {
    crate::error::check_finite("power", power)?;
    crate::error::check_non_negative("volt2", volt2)?;
    let solver = EquilibriumSolver::new(model, volt2).refining_as(grid);
    let target = model.protrusion(power);
    let (lo, hi) = model.forces().table_range();
    let mut prev: Option<Equilibrium> = None;
    for d in grid.iter_descending(lo, hi)? {
        let e = solver.at_gap(d)?;
        if !e.is_stable() {
            // The fold lies between this grid point and the last stable one: locate it, and if
            // the power asked for is reached before it, the equilibrium lies in that last
            // stretch (the power is nearly stationary there, so only direct forces decide).
            // The fold's gap: refined when a stable point precedes it, else this grid point.
            let mut fold_d = d;
            if let Some(p) = prev {
                let fold = solver.refine_fold(e.d, p.d)?;
                fold_d = fold.d;
                if fold.protrusion >= target {
                    return solver.refine(fold.d, p.d, |q| q.protrusion - target);
                }
            }
            return Err(FlyingError::FlyingBranchEnds {
                power_mw: to_mw(power),
                fold_gap_nm: to_nm(fold_d),
            }
            .into());
        }
        if e.protrusion >= target {
            let Some(p) = prev else {
                return Err(FlyingError::TableTooNarrow { gap_nm: to_nm(d) }.into());
            };
            let tol = fold_tolerance(e.d, p.d, model.nominal_clearance());
            let d = brent(
                |x| solver.at_gap(x).map_or(f64::NAN, |q| q.protrusion - target),
                e.d,
                p.d,
                tol,
            )?;
            return solver.at_gap(d);
        }
        prev = Some(e);
    }
    Err(FlyingError::NoFlyingEquilibrium {
        power_mw: to_mw(power),
    }
    .into())
}
