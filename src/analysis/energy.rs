//! The energy audit of an interface lag: the work the lag part of the interface force does on
//! the slider over a run, beside what the damping takes out (docs/validity.md, "The lag's energy
//! audit").
//!
//! The lag `τ Ḟ_eff = F(d) − F_eff` drives the slider with `F_eff`, not with the force `F(d)` of
//! the gaps now. The difference does the power `(F_eff − F) bᵀq̇ = −τ Ḟ_eff bᵀq̇` on the moving
//! slider; to first order in `τ` it is `−τ F'(d) ḋ bᵀq̇`, which on the contact branch (`F' < 0`)
//! feeds energy into every swing. No term of the model supplies that
//! energy: the audit measures how much the lag creates.

use crate::model::SliderSystem;
use crate::ode::StepPolynomial;
use crate::scene::MAX_DOF;
use crate::sim::{Flow, Observer, StepView};
use crate::Result;
use serde::Serialize;

/// The work of an interface lag over a run, and what the damping took out in the same time.
///
/// ```no_run
/// use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, HeaterProgramme};
/// use hdi_tribology::{model::SliderModel, scene::Scene};
/// let scene = Scene::paper();
/// let model = SliderModel::from_scene(&scene)?.with_interface_lag(2e-8);
/// let programme = HeaterProgramme::fixed_from_scene(&scene)?;
/// let r = simulate_cycle(&model, &programme, &CycleOptions::from_scene(&scene)?)?;
/// let e = r.lag_energy.expect("the model has an interface lag");
/// println!("the lag put in {:.3e} J, the damping took out {:.3e} J", e.lag_work, e.damping_work);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct LagEnergy {
    /// `∫ (F_eff − F(d)) bᵀq̇ dt` (J): the work the lag part of the interface force did on the
    /// slider; positive when the lag put energy into the motion.
    #[serde(rename = "lag_work_j")]
    pub lag_work: f64,
    /// `∫ (vᵀCv + (F_ab(y, 0) − F_ab(y, v)) v) dt` (J): what the structure's and the air
    /// bearing's damping took out of the motion in the same time.
    #[serde(rename = "damping_work_j")]
    pub damping_work: f64,
}

impl LagEnergy {
    fn add(&mut self, o: LagEnergy, sign: f64) {
        self.lag_work += sign * o.lag_work;
        self.damping_work += sign * o.damping_work;
    }
}

/// The most terms of a step's interpolant the audit takes (DOP853's dense output has eight).
const MAX_TERMS: usize = 8;

/// The observer that integrates [`LagEnergy`] over a run. On each accepted step both powers are
/// polynomials in time on the step's interpolant: the lag's is `−τ Ḟ_eff bᵀq̇` by the lag law
/// (no force is evaluated), the damping's `q̇ᵀ(C + c e₀e₀ᵀ)q̇`, with the air bearing's damping
/// `c` at the step's start (the crate's bearings all have a damping that does not depend on the
/// spacing). Their products are integrated exactly, term by term. Idle (and free) when the system
/// has no interface lag.
#[derive(Clone, Debug)]
pub(crate) struct Audit {
    on: bool,
    total: LagEnergy,
    /// The last step's span.
    last: (f64, f64),
}

impl Audit {
    /// An audit of runs of `sys`: on when asked for and `sys` has an interface lag.
    pub(crate) fn of(sys: &SliderSystem, asked: bool) -> Self {
        Audit {
            on: asked && sys.lag_audit_parts(0.0).is_some(),
            total: LagEnergy::default(),
            last: (0.0, 0.0),
        }
    }

    /// The work on `[a, b]` inside the step of interpolant `p`, of the system `sys` (NaN for an
    /// interpolant of more than [`MAX_TERMS`] terms, which no method of the crate has).
    fn over(&self, p: StepPolynomial<'_>, sys: &SliderSystem, a: f64, b: f64) -> LagEnergy {
        let n = p.n.max(1);
        let terms = p.coeffs.len() / n;
        let parts = sys.lag_audit_parts(p.coeffs.first().copied().unwrap_or(0.0));
        let (Some(parts), false) = (parts, p.h == 0.0 || terms == 0) else {
            return LagEnergy::default();
        };
        if terms > MAX_TERMS {
            return LagEnergy {
                lag_work: f64::NAN,
                damping_work: f64::NAN,
            };
        }
        let lay = sys.layout();
        let dofs = lay.dofs;
        // The coefficients the powers need: the velocities', and the lagged force's.
        let mut vel = [[0.0; MAX_TERMS]; MAX_DOF];
        let mut lagged = [0.0; MAX_TERMS];
        for (m, a) in p.coeffs.chunks_exact(n).enumerate() {
            for (i, v) in vel.iter_mut().enumerate().take(dofs) {
                v[m] = a[lay.velocity(i)];
            }
            lagged[m] = a[parts.lagged];
        }
        // ∫ θ^(q−1) dθ from θ(a) to θ(b), q = 1 … 2·terms.
        let (ta, tb) = ((a - p.t0) / p.h, (b - p.t0) / p.h);
        let mut segment = [0.0; 2 * MAX_TERMS + 1];
        let (mut pa, mut pb) = (1.0, 1.0);
        for (q, seg) in segment.iter_mut().enumerate().take(2 * terms + 1).skip(1) {
            pa *= ta;
            pb *= tb;
            *seg = (pb - pa) / q as f64;
        }
        // bᵀq̇ and (C + c e₀e₀ᵀ) q̇, coefficient by coefficient.
        let mut along = [0.0; MAX_TERMS];
        let mut damped = [[0.0; MAX_TERMS]; MAX_DOF];
        for k in 0..terms {
            for i in 0..dofs {
                along[k] += parts.bulge[i] * vel[i][k];
                for (j, vj) in vel.iter().enumerate().take(dofs) {
                    damped[i][k] += parts.damping[(i, j)] * vj[k];
                }
            }
        }
        // ∫ Ḟ_eff bᵀq̇ dt = Σ m a_m u_k ∫ θ^(m−1+k) dθ (the step length cancels), and
        // ∫ q̇ᵀDq̇ dt = h Σ v_i,m (Dv)_i,k ∫ θ^(m+k) dθ.
        let (mut lag, mut damping) = (0.0, 0.0);
        for m in 0..terms {
            let am = m as f64 * lagged[m];
            for k in 0..terms {
                lag += am * along[k] * segment[(m + k).max(1)];
                for i in 0..dofs {
                    damping += vel[i][m] * damped[i][k] * segment[m + k + 1];
                }
            }
        }
        LagEnergy {
            lag_work: -parts.tau * lag,
            damping_work: damping * p.h,
        }
    }

    /// Takes back the work after `t` inside the last step (a run cut back to `t`), `p` that
    /// step's interpolant.
    pub(crate) fn cut(&mut self, p: StepPolynomial<'_>, sys: &SliderSystem, t: f64) {
        let (t0, t1) = self.last;
        if self.on && t >= t0 && t < t1 {
            let extra = self.over(p, sys, t, t1);
            self.total.add(extra, -1.0);
            self.last = (t0, t);
        }
    }

    /// The energies so far, when the system has an interface lag.
    pub(crate) fn energy(&self) -> Option<LagEnergy> {
        self.on.then_some(self.total)
    }
}

impl Observer for Audit {
    fn accepted(&mut self, step: &StepView<'_>) -> Result<Flow> {
        if self.on {
            let t0 = step.last_step.t0;
            let w = self.over(step.last_step, step.system, t0, step.t);
            self.total.add(w, 1.0);
            self.last = (t0, step.t);
        }
        Ok(Flow::Continue)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::heater::Programme;
    use crate::model::SliderModel;
    use crate::scene::Scene;

    /// On a step whose interpolant has `v(θ) = 1 + θ` and `F_eff(θ) = θ²` (m/s and N, `θ` the
    /// step's fraction), the lag does `−τ ∫ Ḟ_eff v dt = −τ ∫ 2θ(1 + θ) dθ` and the damping
    /// takes out `c h ∫ (1 + θ)² dθ`: closed forms on any part of the step, and a cut takes back
    /// exactly the part after it.
    #[test]
    fn one_step_integrates_exactly_and_a_cut_takes_back_the_rest() {
        let tau = 2e-8;
        let model = SliderModel::from_scene(&Scene::paper())
            .unwrap()
            .with_interface_lag(tau);
        let sys = SliderSystem::new(
            &model,
            model.inputs(Programme::constant(0.06, 1e-3).unwrap()),
            false,
        );
        let lay = sys.layout();
        let (n, v, f) = (lay.len(), lay.velocity(0), lay.lagged_force.unwrap());
        // Degree 4, as Rodas5P's: a_0, a_1, a_2 carry the polynomials, a_3 = a_4 = 0.
        let mut coeffs = vec![0.0; 5 * n];
        coeffs[v] = 1.0;
        coeffs[n + v] = 1.0;
        coeffs[2 * n + f] = 1.0;
        let (t0, h) = (1e-3, 4e-7);
        let p = StepPolynomial {
            t0,
            h,
            n,
            coeffs: &coeffs,
        };
        let c = model.bearing().damping(0.0);
        let lag = |a: f64, b: f64| -tau * ((b * b - a * a) + 2.0 / 3.0 * (b.powi(3) - a.powi(3)));
        let damp = |a: f64, b: f64| c * h * ((1.0 + b).powi(3) - (1.0 + a).powi(3)) / 3.0;
        // θ comes from times: (t0 + h − t0)/h is 1 only to about t0/h ulps (2.5e3 here).
        let mut audit = Audit::of(&sys, true);
        let whole = audit.over(p, &sys, t0, t0 + h);
        assert!((whole.lag_work - lag(0.0, 1.0)).abs() <= 1e-11 * lag(0.0, 1.0).abs());
        assert!((whole.damping_work - damp(0.0, 1.0)).abs() <= 1e-11 * damp(0.0, 1.0));
        audit.total = whole;
        audit.last = (t0, t0 + h);
        audit.cut(p, &sys, t0 + 0.3 * h);
        let kept = audit.energy().unwrap();
        assert!((kept.lag_work - lag(0.0, 0.3)).abs() <= 1e-11 * lag(0.0, 0.3).abs());
        assert!((kept.damping_work - damp(0.0, 0.3)).abs() <= 1e-11 * damp(0.0, 0.3));
        // Off when not asked for.
        assert_eq!(Audit::of(&sys, false).energy(), None);
    }
}
