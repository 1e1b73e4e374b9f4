//! Pull-in voltage and clearance change with DC voltage (MODEL.md section 6).
//!
//! At fixed protrusion `δ = ηP` the equilibria are parametrised by the bulge gap `d`: the bulge
//! sits at `z = d − h0 + δ`, the structure on the air bearing needs the load `F_s(z)` on the bulge
//! to hold it there ([`SliderModel::bulge_load`]; `−F_ab(z, 0)` for the rigid slider), and the
//! voltage that holds the head there is `V²(d) = (F_s(z) − F_static(d))/G_e(d)`. Pull-in is the first maximum of `V²` (where the
//! total stiffness vanishes) or the first gap whose contact force reaches `F_th`, scanning `d`
//! down from the zero-voltage equilibrium.

use super::equilibrium::EquilibriumSolver;
use super::roots::{brent, brent_polished};
use super::touchdown::{touchdown_at, touchdown_signed, Cause, StaticOptions};
use crate::error::{check_finite, failure_kind, num, Error, Result, Stage};
use crate::model::{SliderModel, Voltage};
use serde::Serialize;

impl Stage {
    /// The static pull-in voltage.
    pub const PULL_IN: Stage = Stage::named("pull-in voltage");
}

/// Why there is no pull-in voltage.
///
/// ```
/// use hdi_tribology::analysis::pull_in::PullInError;
/// let e: hdi_tribology::Error = PullInError::NoPullIn { power_mw: 60.0 }.into();
/// assert_eq!(e.to_string(), "pull-in voltage: no pull-in inside the table range at 60.0000 mW");
/// ```
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PullInError {
    /// No fold and no threshold crossing inside the force tables.
    #[error("no pull-in inside the table range at {} mW", num(*.power_mw))]
    NoPullIn {
        /// The heater power the pull-in was sought at (mW).
        power_mw: f64,
    },
    /// The scene has no electrostatic term.
    #[error("the scene has no electrostatic term")]
    NoElectrostatics,
}

failure_kind!(PullInError, convergence = |_| false, {
        NoPullIn => Stage::PULL_IN,
        NoElectrostatics => Stage::PULL_IN,
});

/// The pull-in voltage at one heater power.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PullIn {
    /// `|V_dc − φ|` at pull-in (V).
    #[serde(rename = "voltage_v")]
    pub voltage: f64,
    /// Bulge gap just before the jump (m).
    #[serde(rename = "d_m")]
    pub d: f64,
    /// Fold of the flying branch or contact threshold.
    pub cause: Cause,
}

struct VoltageBalance<'a> {
    model: &'a SliderModel,
    delta: f64,
}

impl VoltageBalance<'_> {
    /// The gap in `[a, b]` where `quantity` of [`VoltageBalance::at`] changes sign, to `tol`,
    /// and the direct values there (the last direct evaluation reused, not repeated).
    fn refine(
        &self,
        a: f64,
        b: f64,
        tol: f64,
        polish: bool,
        quantity: impl Fn(&(f64, f64, f64)) -> f64,
    ) -> Result<(f64, (f64, f64, f64))> {
        let mut seen: Vec<(f64, (f64, f64, f64))> = Vec::new();
        let exact = |x| match self.at(x, true) {
            Ok(r) => {
                seen.push((x, r));
                quantity(&r)
            }
            Err(_) => f64::NAN,
        };
        let d = if polish {
            let approx = |x| self.at(x, false).map_or(f64::NAN, |r| quantity(&r));
            brent_polished(approx, exact, a, b, tol)?
        } else {
            brent(exact, a, b, tol)?
        };
        match seen.iter().rev().find(|r| r.0 == d) {
            Some(&r) => Ok(r),
            None => Ok((d, self.at(d, true)?)),
        }
    }

    /// `(V², total stiffness, contact force)` at gap `d`, tabulated or exact.
    fn at(&self, d: f64, exact: bool) -> Result<(f64, f64, f64)> {
        let m = self.model;
        let (q, load, k_structure) = m.bulge_load(d - m.nominal_clearance() + self.delta)?;
        let g = m.gaps(&q, self.delta);
        let (s, e) = if exact {
            m.interface_parts_exact(g)?
        } else {
            (m.forces().static_part(g), m.forces().per_volt2_part(g))
        };
        // Stateful terms (voltage-independent) at their states' equilibrium, as every static
        // analysis sees them.
        let s = m.with_stateful(s, g);
        let volt2 = (load - s.value) / e.value;
        let k = k_structure - (s.d_bulge + s.d_pad) - volt2 * (e.d_bulge + e.d_pad);
        Ok((volt2, k, m.contact_force(g)))
    }
}

/// Pull-in voltage `|V_dc − φ|` at heater power `power` (W).
///
/// Returns 0 V when the head is already past touchdown at that power without voltage.
///
/// ```no_run
/// use hdi_tribology::{analysis::{pull_in::pull_in_voltage, touchdown::StaticOptions}, model::SliderModel, scene::Scene};
/// let model = SliderModel::from_scene(&Scene::paper())?;
/// let pi = pull_in_voltage(&model, 0.0, &StaticOptions::new(5e-5))?;
/// println!("V_pi = {:.3} V", pi.voltage);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn pull_in_voltage(model: &SliderModel, power: f64, opts: &StaticOptions) -> Result<PullIn> {
    check_finite("power", power)?;
    if !model.forces().has_voltage_terms() {
        return Err(PullInError::NoElectrostatics.into());
    }
    // Past touchdown without voltage, pull-in is at zero volts. Without any touchdown in the
    // table range (e.g. electrostatics alone) the scan below decides.
    match touchdown_signed(model, 0.0, opts) {
        Ok(td0) if power >= td0.power => {
            return Ok(PullIn {
                voltage: 0.0,
                d: td0.at.d,
                cause: td0.cause,
            });
        }
        Ok(_) | Err(Error::Analysis(_)) => {}
        Err(e) => return Err(e),
    }
    let delta = model.protrusion(power);
    let vb = VoltageBalance { model, delta };
    // Zero-voltage equilibrium at this power: the flying one, on the tables.
    let d0 = EquilibriumSolver::new(model, 0.0);
    let (lo, hi) = model.forces().table_range();
    let grid = opts.grid.iter_descending(lo, hi)?;
    let mut started = false;
    let mut prev: Option<(f64, f64, f64, f64)> = None; // (d, V², k, F_c)
    for d in grid {
        if !started {
            // Flying equilibria have δ(d) increasing as d falls; start once δ(d) reaches δ.
            if d0.at_gap(d)?.protrusion < delta {
                continue;
            }
            started = true;
        }
        let (v2, k, fc) = vb.at(d, false)?;
        if let Some((pd, _pv2, _pk, _)) = prev {
            let tol = 1e-12 * d.abs().max(1e-3 * model.nominal_clearance());
            let polish = opts.grid.polish_from_tables;
            if k <= 0.0 {
                let (df, (v2f, _, _)) = vb.refine(d, pd, tol, polish, |r| r.1)?;
                return Ok(PullIn {
                    voltage: v2f.max(0.0).sqrt(),
                    d: df,
                    cause: Cause::Fold,
                });
            }
            if fc >= opts.contact_threshold {
                let th = opts.contact_threshold;
                let (dt, (v2t, _, _)) = vb.refine(d, pd, tol, polish, |r| r.2 - th)?;
                return Ok(PullIn {
                    voltage: v2t.max(0.0).sqrt(),
                    d: dt,
                    cause: Cause::Threshold,
                });
            }
        }
        prev = Some((d, v2, k, fc));
    }
    Err(PullInError::NoPullIn {
        power_mw: crate::units::to_mw(power),
    }
    .into())
}

/// One point of the clearance change against DC voltage.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ClearanceChange {
    /// DC voltage `V_dc` (V).
    #[serde(rename = "dc_voltage_v")]
    pub dc_voltage: f64,
    /// Touchdown power at that voltage (W).
    #[serde(rename = "touchdown_power_w")]
    pub touchdown_power: f64,
    /// `ΔFH = η (P_TD(V_dc) − P_TD(φ))` (m); negative is a loss of clearance.
    #[serde(rename = "clearance_change_m")]
    pub clearance_change: f64,
}

impl ClearanceChange {
    /// The clearance change `ΔFH` in nanometres.
    ///
    /// ```
    /// use hdi_tribology::analysis::pull_in::ClearanceChange;
    /// let c = ClearanceChange { dc_voltage: 1.0, touchdown_power: 0.064, clearance_change: -1.0e-9 };
    /// assert!((c.clearance_change_nm() + 1.0).abs() < 1e-12);
    /// ```
    pub fn clearance_change_nm(&self) -> f64 {
        crate::units::to_nm(self.clearance_change)
    }
}

/// Clearance change `ΔFH(V_dc) = η (P_TD(V_dc) − P_TD(φ))` at each DC voltage (paper Fig. 2b).
///
/// ```no_run
/// use hdi_tribology::{analysis::{pull_in::clearance_change, touchdown::StaticOptions}, model::SliderModel, scene::Scene};
/// let model = SliderModel::from_scene(&Scene::paper())?;
/// for c in clearance_change(&model, &[-1.0, 1.0], &StaticOptions::new(5e-5))? {
///     println!("{} V: {:.3} nm", c.dc_voltage, c.clearance_change * 1e9);
/// }
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn clearance_change(
    model: &SliderModel,
    dc_voltages: &[f64],
    opts: &StaticOptions,
) -> Result<Vec<ClearanceChange>> {
    super::equilibrium::check_heater(model)?;
    let reference = touchdown_at(model, 0.0, opts)?.power;
    dc_voltages
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            check_finite(&format!("dc_voltages[{i}]"), v)?;
            let voltage = Voltage {
                dc: v,
                ..model.voltage()
            };
            let m = model.with_voltage(voltage);
            let p = touchdown_at(&m, voltage.dc_squared(), opts)?.power;
            Ok(ClearanceChange {
                dc_voltage: v,
                touchdown_power: p,
                clearance_change: model.protrusion(p - reference),
            })
        })
        .collect()
}
