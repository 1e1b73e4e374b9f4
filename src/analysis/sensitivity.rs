//! How a static transition moves when the model changes, to first order, without re-solving it.
//!
//! The static equilibria are parametrised by the bulge gap `d`: at each `d` the balance gives the
//! power `P(d; θ)` for model parameters `θ`. A transition sits at a gap `d*`:
//!
//! - at a **fold** `∂P/∂d = 0`, so by the implicit-function theorem the fold power moves as
//!   `dP*/dθ = ∂P/∂θ` at fixed `d*` (the shift of the fold's gap changes the power only to second
//!   order);
//! - at a **threshold crossing** the contact force `F_c(d; θ)` equals `F_th`, so the gap moves by
//!   `dd*/dθ = −(∂F_c/∂θ)/(∂F_c/∂d)` and `dP*/dθ = ∂P/∂θ + (∂P/∂d)·dd*/dθ`.
//!
//! Both need only the balance at the transition's gap under the changed model (one Newton step
//! from the transition's coordinates with direct evaluation of the forces: no scan and no
//! tables), and for a threshold the slopes along `d` of the unchanged model. [`transition_shift`] gives the first-order change of the power between
//! two models; a central difference of two such shifts is the sensitivity to a parameter.

use super::equilibrium::{Equilibrium, EquilibriumSolver};
use super::touchdown::{Cause, Transition};
use crate::error::{failure_kind, num, Error, Result, Stage};
use crate::force::{GapReference, TermKind};
use crate::model::{Dofs, SliderModel};

impl Stage {
    /// The first-order shift of a transition power with a parameter.
    pub const TRANSITION_SENSITIVITY: Stage = Stage::named("transition sensitivity");
}

/// Why the first-order shift of a transition power is not defined.
///
/// ```
/// use hdi_tribology::analysis::sensitivity::SensitivityError;
/// let e: hdi_tribology::Error = SensitivityError::SingularTangent { gap_nm: 1.5 }.into();
/// assert_eq!(
///     e.to_string(),
///     "transition sensitivity: the balance's tangent is singular at d = 1.5000 nm"
/// );
/// ```
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SensitivityError {
    /// The balance's tangent is singular at this gap.
    #[error("the balance's tangent is singular at d = {} nm", num(*.gap_nm))]
    SingularTangent {
        /// The gap (nm).
        gap_nm: f64,
    },
    /// The contact force does not change with the gap there.
    #[error("the contact force does not change with the gap at d = {} nm", num(*.gap_nm))]
    FlatContactForce {
        /// The gap (nm).
        gap_nm: f64,
    },
}

failure_kind!(SensitivityError, convergence = |_| false, {
        SingularTangent => Stage::TRANSITION_SENSITIVITY,
        FlatContactForce => Stage::TRANSITION_SENSITIVITY,
});

/// Contact force (N) at coordinates `q` and protrusion `delta`, from direct evaluation of the
/// contact terms.
fn contact_force_exact(model: &SliderModel, q: &Dofs, delta: f64) -> Result<f64> {
    let g = model.gaps(q, delta);
    let mut f = 0.0;
    for t in model.forces().terms() {
        if t.kind() == TermKind::Contact {
            let d = match t.gap() {
                GapReference::Bulge => g.bulge,
                GapReference::Pad => g.pad,
            };
            f += t.force(d)?.value;
        }
    }
    Ok(f)
}

/// The balance of `changed` at gap `d`, one Newton step from `q` (a balance of a nearby model):
/// its coordinates and protrusion, exact to first order in the difference of the models.
fn stepped(changed: &SliderModel, d: f64, q: &Dofs) -> Result<(Dofs, f64)> {
    let (step, _) = changed.exact_balance_step(d, changed.voltage().dc_squared(), q)?;
    let step =
        step.ok_or_else(|| Error::from(SensitivityError::SingularTangent { gap_nm: d * 1e9 }))?;
    let q1 = q + step;
    // d = h0 + bᵀq − δ
    let delta = changed.gaps(&q1, 0.0).bulge - d;
    Ok((q1, delta))
}

/// The first-order change of the power (W) of transition `t` of `model` (found by a static
/// analysis of `model` at its DC voltage) when the model becomes `changed` (the same terms, some
/// parameters moved a little): `P*(changed) − P*(model)` to first order in the change. Each model
/// is taken at its own DC voltage (`(V_dc − φ)²`), so a change of the contact potential is a
/// change like any other. Forces are evaluated directly (untabulated), so `changed` may carry
/// tables of any range and accuracy. The changed balance is one Newton step from the
/// transition's coordinates; a threshold crossing also takes the slopes of the power and the
/// contact force along the gap, by central differences on `model`.
///
/// ```no_run
/// use hdi_tribology::analysis::{sensitivity::transition_shift, touchdown_power, StaticOptions};
/// use hdi_tribology::{model::SliderModel, scene::Scene};
/// let scene = Scene::paper();
/// let model = SliderModel::from_scene(&scene)?;
/// let td = touchdown_power(&model, &StaticOptions::new(scene.detector.contact_threshold_n))?;
/// let mut moved = scene.clone();
/// moved.heater.efficiency_m_per_w *= 1.001;
/// let dp = transition_shift(&model, &SliderModel::from_scene(&moved)?, &td)?;
/// println!("η ∂P_TD/∂η ≈ {:.3} mW", dp * 1e3 / 1e-3);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn transition_shift(model: &SliderModel, changed: &SliderModel, t: &Transition) -> Result<f64> {
    let e0 = &t.at;
    let d = e0.d;
    let (q1, delta1) = stepped(changed, d, &e0.q)?;
    let dp_fixed_gap = changed.power_for(delta1) - e0.power;
    match t.cause {
        Cause::Fold => Ok(dp_fixed_gap),
        Cause::Threshold => {
            // Slopes along the gap of the unchanged model, by central differences.
            let base = EquilibriumSolver::new(model, model.voltage().dc_squared());
            let h = 1e-5 * model.nominal_clearance().abs().max(1e-12);
            let (lo, hi) = (base.at_gap_exact(d - h)?, base.at_gap_exact(d + h)?);
            let dp_dd = (hi.power - lo.power) / (2.0 * h);
            let fc = |m: &SliderModel, e: &Equilibrium| contact_force_exact(m, &e.q, e.protrusion);
            let dfc_dd = (fc(model, &hi)? - fc(model, &lo)?) / (2.0 * h);
            let dfc = contact_force_exact(changed, &q1, delta1)? - fc(model, e0)?;
            if dfc_dd == 0.0 || !dfc_dd.is_finite() {
                return Err(SensitivityError::FlatContactForce { gap_nm: d * 1e9 }.into());
            }
            Ok(dp_fixed_gap - dp_dd * dfc / dfc_dd)
        }
    }
}
