//! The slider as an ODE: state layout, right-hand side and analytic Jacobian.

use super::{Dofs, Inputs, QuasiStaticBulge, SliderModel};
use crate::force::{Branch, Gaps, HotValues, StatefulTerm, MAX_TERM_STATES};
use crate::ode::{OdeSystem, TimeMemo};
use crate::scene::MAX_DOF;
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OMatrix, OVector};
use std::ops::Index;
use std::sync::Arc;

/// Where each quantity sits in the state vector. Only what the scene needs is there: one position
/// and one velocity per degree of freedom of the structure, the protrusion only with a thermal
/// lag, the lagged force only with an interface lag, the states of the model's stateful terms
/// ([`crate::force::StatefulTerm`]), and the two running integrals only when a cycle needs them.
///
/// ```
/// use hdi_tribology::model::StateLayout;
/// let l = StateLayout::new(1, false, true, true);
/// assert_eq!(l.len(), 5);
/// assert_eq!((l.delta, l.lagged_force, l.contact_impulse, l.heat), (None, Some(2), Some(3), Some(4)));
/// let two = StateLayout::new(2, false, false, true);
/// assert_eq!((two.velocity(0), two.velocity(1), two.contact_impulse), (2, 3, Some(4)));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StateLayout {
    /// Number of mechanical degrees of freedom `n`: positions at `0..n`, velocities at `n..2n`.
    pub dofs: usize,
    /// Protrusion `δ` (m), with a thermal lag.
    pub delta: Option<usize>,
    /// Lagged interface force `F_eff` (N), with an interface lag.
    pub lagged_force: Option<usize>,
    /// The states of the stateful terms, in the order of the model's terms: `n` of them from
    /// index `start`, as `(start, n)`.
    pub term_states: (usize, usize),
    /// The branches the simulations hold for the stateful terms whose rate law has two
    /// ([`crate::force::StatefulTerm::switches`]), one flag (+1 or −1,
    /// [`crate::force::Branch::flag`]) per such term in the order of the terms, as
    /// `(start, n)`. Their rates are zero: the integrator changes them at the switches.
    pub branches: (usize, usize),
    /// `Q = ∫ F_c dt` (N s): the running mean of the contact force is `(Q(t) − Q(t − T_w))/T_w`.
    pub contact_impulse: Option<usize>,
    /// `Θ = ∫ ΔT dt` (K s): the time mean of the flash temperature.
    pub heat: Option<usize>,
    len: usize,
}

/// The index of the next state of a vector `len` states long so far, when the state is `on`: the
/// vector then grows by one.
fn next_index(len: &mut usize, on: bool) -> Option<usize> {
    on.then(|| {
        *len += 1;
        *len - 1
    })
}

impl StateLayout {
    /// Positions and velocities of `dofs` coordinates first, then the optional states (no
    /// states of stateful terms; see [`StateLayout::of`]).
    pub fn new(dofs: usize, thermal_lag: bool, interface_lag: bool, integrals: bool) -> Self {
        Self::with_term_states(dofs, thermal_lag, interface_lag, 0, integrals)
    }

    /// As [`StateLayout::new`], with `terms` states of stateful terms after the lags.
    pub fn with_term_states(
        dofs: usize,
        thermal_lag: bool,
        interface_lag: bool,
        terms: usize,
        integrals: bool,
    ) -> Self {
        Self::with_branches(dofs, thermal_lag, interface_lag, (terms, 0), integrals)
    }

    /// As [`StateLayout::with_term_states`], with `branches` flags after the terms' states
    /// (`terms` is `(states, branches)`).
    fn with_branches(
        dofs: usize,
        thermal_lag: bool,
        interface_lag: bool,
        (terms, branches): (usize, usize),
        integrals: bool,
    ) -> Self {
        let mut len = 2 * dofs;
        let delta = next_index(&mut len, thermal_lag);
        let lagged_force = next_index(&mut len, interface_lag);
        let term_states = (len, terms);
        len += terms;
        let branches = (len, branches);
        len += branches.1;
        let contact_impulse = next_index(&mut len, integrals);
        let heat = next_index(&mut len, integrals);
        StateLayout {
            dofs,
            delta,
            lagged_force,
            term_states,
            branches,
            contact_impulse,
            heat,
            len,
        }
    }

    /// The one home of a model's layout: its structure's coordinates, its lags and its stateful
    /// terms' states, plus the integrals when asked for.
    ///
    /// ```no_run
    /// use hdi_tribology::{force::RelaxingState, model::{SliderModel, StateLayout}, scene::Scene};
    /// let model = SliderModel::from_scene(&Scene::paper())?;
    /// assert_eq!(StateLayout::of(&model, true).len(), 4);
    /// let with = model.with_stateful_term(RelaxingState::relaxation(1e-4, 1.0)?)?;
    /// let l = StateLayout::of(&with, true);
    /// assert_eq!((l.len(), l.term_states, l.contact_impulse), (5, (2, 1), Some(3)));
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn of(model: &SliderModel, integrals: bool) -> Self {
        // A quasi-static bulge leaves the body alone to integrate.
        let dofs = match model.quasi_static {
            Some(_) => 1,
            None => model.structure().dofs(),
        };
        Self::with_branches(
            dofs,
            model.thermal_lag() > 0.0,
            model.interface_lag() > 0.0,
            (model.term_states(), model.term_branches()),
            integrals,
        )
    }

    /// Index of the velocity of coordinate `i`.
    pub fn velocity(&self, i: usize) -> usize {
        self.dofs + i
    }

    /// Number of states.
    pub fn len(&self) -> usize {
        self.len
    }

    /// The same layout without the heat integral `Θ` (the last state, when there), for runs that
    /// do not report the mean flash temperature.
    ///
    /// ```
    /// use hdi_tribology::model::StateLayout;
    /// let l = StateLayout::new(1, false, true, true).without_heat();
    /// assert_eq!((l.len(), l.contact_impulse, l.heat), (4, Some(3), None));
    /// assert_eq!(StateLayout::new(1, false, false, false).without_heat().len(), 2);
    /// ```
    pub fn without_heat(mut self) -> Self {
        if let Some(i) = self.heat.take() {
            debug_assert_eq!(i + 1, self.len, "the heat integral is the last state");
            self.len -= 1;
        }
        self
    }

    /// Always false: positions and velocities are always there.
    pub fn is_empty(&self) -> bool {
        false
    }
}

/// The slider's parts of the energy audit of an interface lag
/// ([`SliderSystem::lag_audit_parts`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LagAuditParts {
    /// The interface lag `τ` (s).
    pub tau: f64,
    /// The lagged force's index in the state.
    pub lagged: usize,
    /// The bulge influence vector `b`: the interface force does work at the rate `F bᵀq̇`.
    pub bulge: Dofs,
    /// `C + c e₀e₀ᵀ`: the damping takes out `q̇ᵀ(C + c e₀e₀ᵀ)q̇`.
    pub damping: super::structure::DofMatrix,
}

/// A state of rest: coordinates, protrusion and the interface force there (the static equilibria
/// of `analysis` give one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rest {
    /// Coordinates `q`.
    pub q: Dofs,
    /// Protrusion `δ` (m).
    pub protrusion: f64,
    /// Interface force (N).
    pub interface_force: f64,
}

/// [`SliderModel`] under its [`Inputs`], as an [`OdeSystem`].
///
/// The system shares the model (its tables are not copied) and owns the inputs, which
/// [`SliderSystem::set_inputs`] replaces between steps: a new heater power, voltage, clearance
/// change or disk motion is a new value, and the model is never rewritten.
///
/// ```no_run
/// use hdi_tribology::{heater::Programme, model::{SliderModel, SliderSystem}, scene::Scene};
/// let model = SliderModel::from_scene(&Scene::paper())?;
/// let sys = SliderSystem::new(&model, model.inputs(Programme::constant(0.06, 1e-3)?), false);
/// assert_eq!(sys.layout().len(), 2 * model.structure().dofs());
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct SliderSystem {
    model: Arc<SliderModel>,
    inputs: Inputs,
    layout: StateLayout,
    /// Per stateful term: the index of its first state, its number of states and the index of
    /// its branch flag (for a term with two branches), read once from the layout.
    slots: Vec<TermSlot>,
    /// Per switch: the term it belongs to (an index into `slots`).
    switch_terms: Vec<usize>,
    /// `(velocity index, r_i)` of the coordinates a disk translation moves.
    base: [(usize, f64); MAX_DOF],
    n_base: usize,
}

/// Where a stateful term sits in the state ([`SliderSystem::terms`]).
#[derive(Clone, Copy, Debug)]
struct TermSlot {
    /// The index of its first state.
    at: usize,
    /// Its number of states.
    k: usize,
    /// The index of its branch flag, for a term with two branches.
    flag: Option<usize>,
}

/// Forces and their derivatives at one state.
#[derive(Clone, Copy)]
struct Local {
    g: Gaps,
    /// `F_if` and partials.
    f: crate::force::ForceEval,
    /// The tabulated sums behind `f`, with the contact force.
    hot: crate::force::HotForces,
}

impl SliderSystem {
    /// The slider of `model` under `inputs`; `integrals` adds the contact impulse and heat
    /// states. The model is shared with the system (a copy that shares its tables).
    pub fn new(model: &SliderModel, inputs: Inputs, integrals: bool) -> Self {
        Self::shared(Arc::new(model.clone()), inputs, integrals)
    }

    /// The same system without the heat integral ([`StateLayout::without_heat`]): the right-hand
    /// side, the Jacobian and the tolerances then leave out `Θ` and the flash temperature's
    /// slope it needs.
    pub fn without_heat(mut self) -> Self {
        self.layout = self.layout.without_heat();
        self
    }

    /// [`SliderSystem::new`] on a model already shared.
    pub fn shared(model: Arc<SliderModel>, inputs: Inputs, integrals: bool) -> Self {
        let layout = StateLayout::of(&model, integrals);
        let mut base = [(0usize, 0.0); MAX_DOF];
        let mut n_base = 0;
        let moved = model.structure().base_influence().iter().take(layout.dofs);
        for (i, &r) in moved.enumerate() {
            if r != 0.0 {
                base[n_base] = (layout.velocity(i), r);
                n_base += 1;
            }
        }
        let (mut at, mut flag) = (layout.term_states.0, layout.branches.0);
        let mut slots = Vec::with_capacity(model.stateful_terms().len());
        let mut switch_terms = Vec::new();
        for (j, term) in model.stateful_terms().iter().enumerate() {
            let held = term.switches().then(|| {
                switch_terms.push(j);
                flag += 1;
                flag - 1
            });
            slots.push(TermSlot {
                at,
                k: term.states(),
                flag: held,
            });
            at += term.states();
        }
        SliderSystem {
            model,
            inputs,
            layout,
            slots,
            switch_terms,
            base,
            n_base,
        }
    }

    /// The state layout.
    pub fn layout(&self) -> StateLayout {
        self.layout
    }

    /// The inputs.
    pub fn inputs(&self) -> &Inputs {
        &self.inputs
    }

    /// Replaces the inputs (a discontinuity of the right-hand side: an integrator restarts after
    /// it, see [`crate::ode::Integrator::reinit`]).
    pub fn set_inputs(&mut self, inputs: Inputs) {
        self.inputs = inputs;
    }

    /// The heater, the voltage and the clearance offset of the inputs replaced, the disk's
    /// motion kept (without touching its shared handle).
    pub(crate) fn set_command_inputs(
        &mut self,
        heater: super::Heater,
        voltage: super::Voltage,
        clearance_offset: f64,
    ) {
        self.inputs.heater = heater;
        self.inputs.voltage = voltage;
        self.inputs.clearance_offset = clearance_offset;
    }

    /// The model.
    pub fn model(&self) -> &SliderModel {
        &self.model
    }

    /// The model, shared.
    pub fn model_arc(&self) -> &Arc<SliderModel> {
        &self.model
    }

    /// The largest step (s) under the inputs' voltage ([`super::Voltage::max_step`]).
    pub fn max_step(&self, given: Option<f64>) -> f64 {
        self.inputs.voltage.max_step(given)
    }

    /// The one home of "start at rest": the state at `rest` with zero velocities, in a vector of
    /// the layout's length (the integrals start at zero).
    pub fn initial_state<D: Dim>(&self, dim: D, rest: &Rest) -> OVector<f64, D>
    where
        DefaultAllocator: Allocator<D>,
    {
        let mut s = OVector::<f64, D>::zeros_generic(dim, nalgebra::Const::<1>);
        for i in 0..self.layout.dofs {
            s[i] = rest.q[i];
        }
        if let Some(i) = self.layout.delta {
            s[i] = rest.protrusion;
        }
        if let Some(i) = self.layout.lagged_force {
            s[i] = rest.interface_force;
        }
        if self.layout.term_states.1 > 0 {
            let g = self
                .model
                .gaps_offset(&rest.q, rest.protrusion, self.inputs.clearance_offset);
            for (term, at, flag) in self.terms() {
                let k = term.states();
                let mut x = [0.0; MAX_TERM_STATES];
                term.initial(g, &mut x[..k]);
                for (j, v) in x[..k].iter().enumerate() {
                    s[at + j] = *v;
                }
                // The branch the sign picks at the start.
                if let Some(i) = flag {
                    s[i] = Branch::of(term.switching(g, &x[..k])).flag();
                }
            }
        }
        s
    }

    /// The coordinates `q` of state `s`.
    #[inline]
    pub fn coordinates<S: Index<usize, Output = f64> + ?Sized>(&self, s: &S) -> Dofs {
        self.block(s, 0)
    }

    /// The velocities `q̇` of state `s`.
    #[inline]
    pub fn velocities<S: Index<usize, Output = f64> + ?Sized>(&self, s: &S) -> Dofs {
        self.block(s, self.layout.velocity(0))
    }

    /// `dofs` entries of `s` from `start`, as coordinates.
    #[inline]
    fn block<S: Index<usize, Output = f64> + ?Sized>(&self, s: &S, start: usize) -> Dofs {
        let mut q = super::structure::zero_dofs();
        for i in 0..self.layout.dofs {
            q[i] = s[start + i];
        }
        q
    }

    /// Protrusion at time `t` and state `s`.
    pub fn protrusion<S: Index<usize, Output = f64> + ?Sized>(&self, t: f64, s: &S) -> f64 {
        self.protrusion_given(s, || self.inputs.heater.power(t))
    }

    /// Protrusion at state `s` under the heater power `power()` (W), asked for only where the
    /// protrusion follows the power at once.
    #[inline]
    fn protrusion_given<S: Index<usize, Output = f64> + ?Sized>(
        &self,
        s: &S,
        power: impl FnOnce() -> f64,
    ) -> f64 {
        match self.layout.delta {
            Some(i) => s[i],
            None => self.model.protrusion(power()),
        }
    }

    /// What the right-hand side reads of the inputs at time `t`, computed from the time alone:
    /// the squared voltage (V²), the heater's power (W) and its rate (W/s), and the disk's
    /// acceleration (m/s², zero without a base motion).
    fn inputs_at(&self, t: f64) -> [f64; 4] {
        let (power, rate) = self.inputs.heater.power_and_rate(t);
        let accel = self
            .inputs
            .base_motion
            .as_ref()
            .map_or(0.0, |b| b.acceleration_value(t));
        [self.inputs.voltage.squared(t), power, rate, accel]
    }

    /// Gaps at time `t` and state `s`. With a quasi-static bulge, the bulge gap where the bulge
    /// spring balances the interface force (NaN where the bulge has no stable equilibrium).
    pub fn gaps<S: Index<usize, Output = f64> + ?Sized>(&self, t: f64, s: &S) -> Gaps {
        if let Some(q) = self.model.quasi_static {
            return self.settled_gaps(&q, t, s).unwrap_or(Gaps::same(f64::NAN));
        }
        self.model.gaps_offset(
            &self.coordinates(s),
            self.protrusion(t, s),
            self.inputs.clearance_offset,
        )
    }

    /// The air-bearing force at state `s` (N).
    pub fn bearing_force<D: Dim>(&self, s: &OVector<f64, D>) -> f64
    where
        DefaultAllocator: Allocator<D>,
    {
        self.model.bearing().force(s[0], s[self.layout.velocity(0)])
    }

    /// What the energy audit of an interface lag needs of the slider (`analysis::energy`): the
    /// lag `τ` (s), the lagged force's index, the bulge vector `b` and the damping matrix
    /// `C + c e₀e₀ᵀ` (the structure's and the air bearing's, `c` at the body heave `y`). `None`
    /// without a lag state, or with a quasi-static bulge (whose bulge does not move on its own).
    pub(crate) fn lag_audit_parts(&self, y: f64) -> Option<LagAuditParts> {
        let lagged = self.layout.lagged_force?;
        if self.model.quasi_static.is_some() {
            return None;
        }
        let st = &self.model.structure;
        Some(LagAuditParts {
            tau: self.model.interface_lag,
            lagged,
            bulge: st.bulge_vector(),
            damping: st.damping_with(self.model.bearing().damping(y)),
        })
    }

    fn local<D: Dim>(&self, t: f64, s: &OVector<f64, D>) -> Local
    where
        DefaultAllocator: Allocator<D>,
    {
        let g = self.gaps(t, s);
        let volt2 = self.inputs.voltage.squared(t);
        let (f, hot) = self.model.hot_forces(g, volt2);
        Local { g, f, hot }
    }

    /// The interface force that drives the slider at state `s`: the lagged force where the state
    /// keeps one, else the force `hot` of the gaps now.
    fn interface_drive<D: Dim>(&self, s: &OVector<f64, D>, hot: &HotValues) -> f64
    where
        DefaultAllocator: Allocator<D>,
    {
        match self.layout.lagged_force {
            Some(i) => s[i],
            None => hot.interface,
        }
    }

    /// The rates of the states besides the mechanical ones and the stateful terms', at time `t`
    /// and state `s` with the interface's values `hot`: the protrusion's and the lagged force's
    /// first-order lags, and the integrands of the contact impulse and of the heat.
    fn lag_and_integral_rates<D: Dim>(
        &self,
        (power, power_rate): (f64, f64),
        s: &OVector<f64, D>,
        hot: &HotValues,
        ds: &mut OVector<f64, D>,
    ) where
        DefaultAllocator: Allocator<D>,
    {
        let m = &*self.model;
        let lay = self.layout;
        if let Some(i) = lay.delta {
            ds[i] = self.protrusion_rate_given(s, power, power_rate);
        }
        if let Some(i) = lay.lagged_force {
            ds[i] = (hot.interface - s[i]) / m.interface_lag;
        }
        if let Some(i) = lay.contact_impulse {
            ds[i] = hot.contact;
        }
        if let Some(i) = lay.heat {
            ds[i] = m.friction.flash_temperature(hot.contact, hot.area);
        }
    }

    /// The protrusion's rate (m/s) at time `t` and state `s`: the thermal lag's, or the
    /// programme's where the protrusion follows it at once.
    fn protrusion_rate<S: Index<usize, Output = f64> + ?Sized>(&self, t: f64, s: &S) -> f64 {
        let (power, rate) = self.inputs.heater.power_and_rate(t);
        self.protrusion_rate_given(s, power, rate)
    }

    /// [`Self::protrusion_rate`] under the heater's power (W) and its rate (W/s).
    #[inline]
    fn protrusion_rate_given<S: Index<usize, Output = f64> + ?Sized>(
        &self,
        s: &S,
        power: f64,
        power_rate: f64,
    ) -> f64 {
        let m = &*self.model;
        match self.layout.delta {
            Some(i) => (m.protrusion(power) - s[i]) / m.thermal_lag,
            None => m.protrusion(power_rate),
        }
    }

    /// The change of the right-hand side at state `s` when the heater's power moves from `from`
    /// to `to` (W), the other inputs kept: the protrusion's rate alone changes, where a thermal
    /// lag makes the protrusion a state (its index and the change; `None` without one, where the
    /// power moves the gaps at once).
    pub(crate) fn heater_shift<S: Index<usize, Output = f64> + ?Sized>(
        &self,
        s: &S,
        from: f64,
        to: f64,
    ) -> Option<(usize, f64)> {
        let i = self.layout.delta?;
        Some((
            i,
            self.protrusion_rate_given(s, to, 0.0) - self.protrusion_rate_given(s, from, 0.0),
        ))
    }

    /// The rates of the gaps (m/s) at time `t` and state `s`, of a model without a quasi-static
    /// bulge (which takes no stateful terms): the bulge gap's `b·q̇ − δ̇`, the pad gap's `ẏ`.
    fn gap_rates<S: Index<usize, Output = f64> + ?Sized>(&self, t: f64, s: &S) -> Gaps {
        let v = self.velocities(s);
        Gaps {
            bulge: self.model.structure.bulge_displacement(&v) - self.protrusion_rate(t, s),
            pad: v[0],
        }
    }

    /// The heater power's rate at time `t` (W/s) and the protrusion's rate it makes (m/s): the
    /// protrusion moves with the programme only without a thermal lag (with one it is a state,
    /// and its rate here is zero).
    fn power_and_protrusion_rates(&self, t: f64) -> (f64, f64) {
        let (_, p_rate) = self.inputs.heater.power_and_rate(t);
        let delta_rate = match self.layout.delta {
            Some(_) => 0.0,
            None => self.model.protrusion(p_rate),
        };
        (p_rate, delta_rate)
    }

    /// The derivative of the flash temperature (the heat state's rate) along the bulge gap at
    /// the point of `l`: the derivative of the interpolants the right-hand side reads.
    fn heat_slope(&self, l: &Local) -> f64 {
        let m = &*self.model;
        let (area, area_rate) = m.forces().real_contact_area_with_slope(l.g);
        let c = &l.hot.contact;
        m.friction
            .flash_temperature_slope(c.value, c.d_bulge, area, area_rate)
    }

    /// [`Self::heat_slope`] when the state keeps the heat integral, else zero (unused).
    fn heat_slope_if_kept(&self, l: &Local) -> f64 {
        if self.layout.heat.is_some() {
            self.heat_slope(l)
        } else {
            0.0
        }
    }

    /// The Jacobian at the point of `l` (state `s`), `dd` the flash temperature's slope there.
    fn jacobian_at<D: Dim>(
        &self,
        l: &Local,
        dd: f64,
        s: &OVector<f64, D>,
        j: &mut OMatrix<f64, D, D>,
    ) where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        let m = &*self.model;
        let st = &m.structure;
        let lay = self.layout;
        let n = lay.dofs;
        j.fill(0.0);
        let b = st.bulge_vector();
        // ∂F/∂q_c = f_b b_c + f_p [c = 0]: the bulge gap moves with bᵀq, the pad gap with q₀.
        let along = |e: &crate::force::ForceEval, c: usize| {
            let pad = if c == 0 { e.d_pad } else { 0.0 };
            e.d_bulge * b[c] + pad
        };
        let y0 = s[0];
        let k = st.tangent(m.bearing().stiffness(y0), 0.0, 0.0);
        let c = st.damping_with(m.bearing().damping(y0));
        for col in 0..n {
            j[(col, lay.velocity(col))] = 1.0;
            // Columns of −M⁻¹(K + e₀e₀ᵀk_ab) and −M⁻¹(C + e₀e₀ᵀc_ab).
            let (mut fk, mut fc) = (Dofs::zeros(), Dofs::zeros());
            for r in 0..n {
                fk[r] = -k[(r, col)];
                fc[r] = -c[(r, col)];
            }
            let (ak, ac) = (st.mass_solve(&fk), st.mass_solve(&fc));
            for r in 0..n {
                j[(lay.velocity(r), col)] = ak[r];
                j[(lay.velocity(r), lay.velocity(col))] = ac[r];
            }
        }
        // The interface force enters through b, lagged or not.
        let per_force = st.mass_solve(&b);
        let f_delta = -l.f.d_bulge;
        match lay.lagged_force {
            Some(i) => {
                for r in 0..n {
                    j[(lay.velocity(r), i)] = per_force[r];
                }
                for col in 0..n {
                    j[(i, col)] = along(&l.f, col) / m.interface_lag;
                }
                j[(i, i)] = -1.0 / m.interface_lag;
                if let Some(k) = lay.delta {
                    j[(i, k)] = f_delta / m.interface_lag;
                }
            }
            None => {
                for col in 0..n {
                    let mut g = Dofs::zeros();
                    for r in 0..n {
                        g[r] = b[r] * along(&l.f, col);
                    }
                    let a = st.mass_solve(&g);
                    for r in 0..n {
                        j[(lay.velocity(r), col)] += a[r];
                    }
                }
                if let Some(k) = lay.delta {
                    let a = st.mass_solve(&(b * f_delta));
                    for r in 0..n {
                        j[(lay.velocity(r), k)] = a[r];
                    }
                }
            }
        }
        if let Some(k) = lay.delta {
            j[(k, k)] = -1.0 / m.thermal_lag;
        }
        if let Some(i) = lay.contact_impulse {
            for col in 0..n {
                j[(i, col)] = along(&l.hot.contact, col);
            }
            if let Some(k) = lay.delta {
                j[(i, k)] = -l.hot.contact.d_bulge;
            }
        }
        if let Some(i) = lay.heat {
            for col in 0..n {
                j[(i, col)] = dd * b[col];
            }
            if let Some(k) = lay.delta {
                j[(i, k)] = -dd;
            }
        }
        if lay.term_states.1 > 0 {
            self.term_jacobian(l.g, s, j);
        }
    }

    /// `∂f/∂t` at time `t` and the point of `l`, `dd` the flash temperature's slope there.
    fn time_derivative_at<D: Dim>(
        &self,
        t: f64,
        l: &Local,
        dd: f64,
        s: &OVector<f64, D>,
        dfdt: &mut OVector<f64, D>,
    ) where
        DefaultAllocator: Allocator<D>,
    {
        let m = &*self.model;
        dfdt.fill(0.0);
        let (p_rate, delta_rate) = self.power_and_protrusion_rates(t);
        let f_t =
            -l.f.d_bulge * delta_rate + self.inputs.voltage.squared_rate(t) * l.hot.per_volt2.value;
        match self.layout.lagged_force {
            Some(i) => dfdt[i] = f_t / m.interface_lag,
            None => {
                let st = &m.structure;
                let a = st.mass_solve(&(st.bulge_vector() * f_t));
                for r in 0..self.layout.dofs {
                    dfdt[self.layout.velocity(r)] = a[r];
                }
            }
        }
        if let Some(k) = self.layout.delta {
            dfdt[k] = m.protrusion(p_rate) / m.thermal_lag;
        }
        if let Some(i) = self.layout.contact_impulse {
            dfdt[i] = -l.hot.contact.d_bulge * delta_rate;
        }
        if let Some(i) = self.layout.heat {
            dfdt[i] = -dd * delta_rate;
        }
        if self.layout.term_states.1 > 0 {
            self.term_time_derivative(l.g, s, delta_rate, dfdt);
        }
        if let Some(b) = &self.inputs.base_motion {
            let jerk = b.acceleration(t).1;
            for &(i, r) in &self.base[..self.n_base] {
                dfdt[i] -= r * jerk;
            }
        }
    }

    /// Every stateful term with the index of its first state and of its branch flag (the flag
    /// only for a term with two branches).
    fn terms(&self) -> impl Iterator<Item = (&dyn StatefulTerm, usize, Option<usize>)> + '_ {
        self.model
            .stateful_terms()
            .iter()
            .zip(&self.slots)
            .map(|(term, slot)| (&**term as &dyn StatefulTerm, slot.at, slot.flag))
    }

    /// Calls `f(term, index of its first state, index of its branch flag)` for every stateful
    /// term ([`SliderSystem::terms`]).
    fn for_terms(&self, mut f: impl FnMut(&dyn StatefulTerm, usize, Option<usize>)) {
        for (term, at, flag) in self.terms() {
            f(term, at, flag);
        }
    }

    /// The term of switch `i` (the `i`-th term with two branches), the index of its first state
    /// and of its flag.
    fn switching_term(&self, i: usize) -> Option<(&dyn StatefulTerm, TermSlot, usize)> {
        let j = *self.switch_terms.get(i)?;
        let slot = self.slots[j];
        Some((&*self.model.stateful_terms()[j], slot, slot.flag?))
    }

    /// The branch held at flag `flag` of state `s` (the upper one for a term with one law).
    fn held<S: Index<usize, Output = f64> + ?Sized>(flag: Option<usize>, s: &S) -> Branch {
        flag.map_or(Branch::Upper, |i| Branch::of_flag(s[i]))
    }

    /// The sum of the stateful terms' forces at gaps `g` and state `s` (N), with their rates
    /// written into `ds`.
    fn term_rates<D: Dim>(&self, g: Gaps, s: &OVector<f64, D>, ds: &mut OVector<f64, D>) -> f64
    where
        DefaultAllocator: Allocator<D>,
    {
        let mut force = 0.0;
        for (term, slot) in self.model.stateful_terms().iter().zip(&self.slots) {
            let TermSlot { at, k, flag } = *slot;
            let x = &s.as_slice()[at..at + k];
            let mut dx = [0.0; MAX_TERM_STATES];
            let branch = Self::held(flag, s);
            force += term.rates_and_force_value_on(branch, g, x, &mut dx[..k]);
            for (j, v) in dx[..k].iter().enumerate() {
                ds[at + j] = *v;
            }
            if let Some(i) = flag {
                ds[i] = 0.0;
            }
        }
        force
    }

    /// The stateful terms' part of the Jacobian: their forces on the accelerations (through
    /// `M⁻¹b`, not lagged) and their rates' rows.
    fn term_jacobian<D: Dim>(&self, g: Gaps, s: &OVector<f64, D>, j: &mut OMatrix<f64, D, D>)
    where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        let st = &self.model.structure;
        let lay = self.layout;
        let n = lay.dofs;
        let b = st.bulge_vector();
        let per_force = st.mass_solve(&b);
        let along = |d_bulge: f64, d_pad: f64, c: usize| {
            let pad = if c == 0 { d_pad } else { 0.0 };
            d_bulge * b[c] + pad
        };
        self.for_terms(|term, at, flag| {
            let k = term.states();
            let x = &s.as_slice()[at..at + k];
            let branch = Self::held(flag, s);
            let f = term.force_on(branch, g, x);
            let p = term.rate_partials_on(branch, g, x);
            for r in 0..n {
                let v = lay.velocity(r);
                for col in 0..n {
                    j[(v, col)] += per_force[r] * along(f.force.d_bulge, f.force.d_pad, col);
                }
                if let Some(kd) = lay.delta {
                    j[(v, kd)] += per_force[r] * -f.force.d_bulge;
                }
                for c in 0..k {
                    j[(v, at + c)] += per_force[r] * f.d_state[c];
                }
            }
            for i in 0..k {
                for col in 0..n {
                    j[(at + i, col)] = along(p.d_bulge[i], p.d_pad[i], col);
                }
                if let Some(kd) = lay.delta {
                    j[(at + i, kd)] = -p.d_bulge[i];
                }
                for c in 0..k {
                    j[(at + i, at + c)] = p.d_state[i][c];
                }
            }
        });
    }

    /// The stateful terms' part of `∂f/∂t`: through the protrusion's rate `delta_rate` (m/s).
    fn term_time_derivative<D: Dim>(
        &self,
        g: Gaps,
        s: &OVector<f64, D>,
        delta_rate: f64,
        dfdt: &mut OVector<f64, D>,
    ) where
        DefaultAllocator: Allocator<D>,
    {
        if delta_rate == 0.0 {
            return;
        }
        let st = &self.model.structure;
        let lay = self.layout;
        let per_force = st.mass_solve(&st.bulge_vector());
        self.for_terms(|term, at, flag| {
            let k = term.states();
            let x = &s.as_slice()[at..at + k];
            let branch = Self::held(flag, s);
            let f = term.force_on(branch, g, x);
            let p = term.rate_partials_on(branch, g, x);
            for r in 0..lay.dofs {
                dfdt[lay.velocity(r)] += per_force[r] * (-f.force.d_bulge * delta_rate);
            }
            for i in 0..k {
                dfdt[at + i] = -p.d_bulge[i] * delta_rate;
            }
        });
    }
}

impl<D: Dim> OdeSystem<D> for SliderSystem
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    /// One per stateful term with two branches ([`StatefulTerm::switches`]).
    fn switches(&self) -> usize {
        self.layout.branches.1
    }

    /// The term's switching function times its held flag: non-negative while the held branch
    /// is the one the sign picks.
    fn switching(&self, i: usize, t: f64, s: &OVector<f64, D>) -> f64 {
        let Some((term, slot, flag)) = self.switching_term(i) else {
            return 0.0;
        };
        let x = &s.as_slice()[slot.at..slot.at + slot.k];
        let gaps = || self.gaps(t, s);
        let rate = || self.gap_rates(t, s);
        s[flag] * term.switching_on(Self::held(Some(flag), s), &gaps, &rate, x)
    }

    /// The other branch, entered ([`StatefulTerm::enter`]).
    fn switch(&self, i: usize, t: f64, s: &mut OVector<f64, D>) {
        let Some((term, slot, flag)) = self.switching_term(i) else {
            return;
        };
        s[flag] = -s[flag];
        let g = self.gaps(t, s);
        term.enter(
            Self::held(Some(flag), s),
            g,
            &mut s.as_mut_slice()[slot.at..slot.at + slot.k],
        );
    }

    /// The term's fastest rate on the held branch ([`StatefulTerm::fastest_rate_on`]).
    fn branch_rate(&self, i: usize, s: &OVector<f64, D>) -> Option<f64> {
        let (term, _, flag) = self.switching_term(i)?;
        term.fastest_rate_on(Branch::of_flag(s[flag]))
    }

    /// The stateful terms' own relaxation on their held branches: each term state's
    /// `∂ẋ_i/∂x_i` ([`StatefulTerm::rate_partials_on`]), for the terms whose rates are affine
    /// in their own states row by row ([`StatefulTerm::rates_diagonal_affine`]); zero for the
    /// slider's coordinates and the other terms.
    fn stiff_diagonal(&self, t: f64, s: &OVector<f64, D>, lambda: &mut OVector<f64, D>) -> bool {
        lambda.fill(0.0);
        if self.layout.term_states.1 == 0 {
            return false;
        }
        let g = self.gaps(t, s);
        let mut any = false;
        for (term, slot) in self.model.stateful_terms().iter().zip(&self.slots) {
            if !term.rates_diagonal_affine() {
                continue;
            }
            let TermSlot { at, k, flag } = *slot;
            let p = term.rate_partials_on(Self::held(flag, s), g, &s.as_slice()[at..at + k]);
            for c in 0..k {
                lambda[at + c] = p.d_state[c][c];
                any |= p.d_state[c][c] != 0.0;
            }
        }
        any
    }

    /// The rates of the terms [`OdeSystem::stiff_diagonal`] declares, without their forces (the
    /// other rows are left as they are).
    fn stiff_rates(&self, t: f64, s: &OVector<f64, D>, rates: &mut OVector<f64, D>) {
        if self.layout.term_states.1 == 0 {
            return;
        }
        let g = self.gaps(t, s);
        for (term, slot) in self.model.stateful_terms().iter().zip(&self.slots) {
            if !term.rates_diagonal_affine() {
                continue;
            }
            let TermSlot { at, k, flag } = *slot;
            let (x, dx) = (
                &s.as_slice()[at..at + k],
                &mut rates.as_mut_slice()[at..at + k],
            );
            term.rates_on(Self::held(flag, s), g, x, dx);
        }
    }

    fn rhs(&self, t: f64, s: &OVector<f64, D>, ds: &mut OVector<f64, D>) {
        self.rhs_memo(t, s, ds, &mut TimeMemo::default());
    }

    fn rhs_memo(&self, t: f64, s: &OVector<f64, D>, ds: &mut OVector<f64, D>, memo: &mut TimeMemo) {
        let at = memo.get_or_insert_with(t, |t| self.inputs_at(t));
        self.rhs_given(t, s, ds, at);
    }

    fn jacobian(&self, t: f64, s: &OVector<f64, D>, j: &mut OMatrix<f64, D, D>) -> bool {
        if let Some(q) = self.model.quasi_static {
            let mut dfdt =
                OVector::<f64, D>::zeros_generic(s.shape_generic().0, nalgebra::Const::<1>);
            self.condensed_jacobian(&q, t, s, j, &mut dfdt);
            return true;
        }
        let l = self.local(t, s);
        self.jacobian_at(&l, self.heat_slope_if_kept(&l), s, j);
        true
    }

    fn time_derivative(&self, t: f64, s: &OVector<f64, D>, dfdt: &mut OVector<f64, D>) -> bool {
        if let Some(q) = self.model.quasi_static {
            let n = s.shape_generic().0;
            let mut j = OMatrix::<f64, D, D>::zeros_generic(n, n);
            self.condensed_jacobian(&q, t, s, &mut j, dfdt);
            return true;
        }
        let l = self.local(t, s);
        self.time_derivative_at(t, &l, self.heat_slope_if_kept(&l), s, dfdt);
        true
    }

    /// Both from one evaluation of the forces (and of the flash temperature's slope) at `(t, s)`.
    fn jacobian_and_time_derivative(
        &self,
        t: f64,
        s: &OVector<f64, D>,
        j: &mut OMatrix<f64, D, D>,
        dfdt: &mut OVector<f64, D>,
    ) -> (bool, bool) {
        if let Some(q) = self.model.quasi_static {
            self.condensed_jacobian(&q, t, s, j, dfdt);
            return (true, true);
        }
        let l = self.local(t, s);
        let dd = self.heat_slope_if_kept(&l);
        self.jacobian_at(&l, dd, s, j);
        self.time_derivative_at(t, &l, dd, s, dfdt);
        (true, true)
    }
}

/// The one home of the ODE scales: how fast the slider can move, and what absolute accuracy each
/// state needs for a given accuracy of the displacement.
impl SliderModel {
    /// Angular frequency scale of each coordinate (rad/s): `√(J_ii/M_ii)` with the structure's
    /// stiffness plus the bearing's at rest (`√(k_ab/m)` for the rigid slider).
    pub fn angular_frequencies(&self) -> Dofs {
        let st = &self.structure;
        let j = st.tangent(self.bearing().stiffness(0.0), 0.0, 0.0);
        let m = st.mass_matrix();
        let mut w = Dofs::zeros();
        for i in 0..st.dofs() {
            w[i] = (j[(i, i)] / m[(i, i)]).sqrt();
        }
        w
    }

    /// A bound on the fastest rate of the slider (1/s): the structure's and bearing's modes,
    /// their damping rates and the inverse lags (the contact stiffness only raises the first, see
    /// `docs/validity.md`).
    pub fn fastest_rate(&self) -> f64 {
        let st = &self.structure;
        let c = st.damping_with(self.bearing().damping(0.0));
        let m = st.mass_matrix();
        let w = self.angular_frequencies();
        let mut r = 0.0f64;
        // A quasi-static bulge has left only the body's rates.
        let dofs = if self.quasi_static.is_some() {
            1
        } else {
            st.dofs()
        };
        for i in 0..dofs {
            r = r.max(w[i]).max(c[(i, i)] / m[(i, i)]);
        }
        for tau in [self.interface_lag, self.thermal_lag] {
            if tau > 0.0 {
                r = r.max(1.0 / tau);
            }
        }
        r
    }
}

impl SliderSystem {
    /// Absolute tolerances of every state for the displacement tolerance `displacement` (m):
    /// positions to `displacement` (rotations to it over their lever), velocities times their
    /// angular frequency, the protrusion to `displacement`, the lagged force times the stiffness
    /// at the bulge, the stateful terms' states as each term says
    /// ([`crate::force::StatefulTerm::tolerances`]), and the integrals to `impulse` (N s) and
    /// `heat` (K s).
    ///
    /// ```
    /// use hdi_tribology::{heater::Programme, model::{SliderModel, SliderSystem}, scene::Scene};
    /// let model = SliderModel::from_scene(&Scene::paper())?;
    /// let sys = SliderSystem::new(&model, model.inputs(Programme::constant(0.06, 1e-3)?), true);
    /// let atol = sys.tolerances(1e-14, 1e-12, 1e-10);
    /// assert_eq!(atol.len(), 4);
    /// assert!((atol[1] / 1e-14 - (3e5f64 / 1e-6).sqrt()).abs() < 1e-6);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn tolerances(&self, displacement: f64, impulse: f64, heat: f64) -> Vec<f64> {
        let m = &*self.model;
        let st = &m.structure;
        let lay = self.layout;
        let w = m.angular_frequencies();
        let mut atol = vec![0.0; lay.len()];
        for i in 0..lay.dofs {
            let a = displacement / st.length_scale(i);
            atol[i] = a;
            atol[lay.velocity(i)] = a * w[i];
        }
        if let Some(i) = lay.delta {
            atol[i] = displacement;
        }
        if let Some(i) = lay.lagged_force {
            let j = st.tangent(m.bearing().stiffness(0.0), 0.0, 0.0);
            // The fastest of the coordinates integrated (the body alone with a quasi-static bulge).
            let omega = (0..lay.dofs).map(|c| w[c]).fold(0.0f64, f64::max);
            atol[i] = displacement * st.condensed(&j).abs() * lag_tolerance_factor(m, omega);
        }
        if let Some(i) = lay.contact_impulse {
            atol[i] = impulse;
        }
        if let Some(i) = lay.heat {
            atol[i] = heat;
        }
        self.for_terms(|term, at, flag| {
            let k = term.states();
            term.tolerances(displacement, &mut atol[at..at + k]);
            // A flag is ±1 and never integrated: any scale will do.
            if let Some(i) = flag {
                atol[i] = 1.0;
            }
        });
        atol
    }
}

/// How much looser the lagged force's absolute tolerance is than the force that would move the
/// slider by the displacement tolerance at rest: `max(1, 1/(ω τ))`, with `τ` the interface lag and
/// `ω` (`omega`) the fastest angular frequency of the coordinates integrated.
///
/// A local error `e` in the lagged force decays as `e^{−t/τ}`: it acts on the structure as an
/// impulse `e τ`, which changes a mode's velocity by `e τ / m` and its displacement by about
/// `e τ / (m ω) = e ω τ / k`. The velocity's tolerance is the displacement's times `ω`, so a
/// lagged-force error of `k / (ω τ)` times the displacement tolerance moves the velocity and the
/// displacement by no more than their own tolerances. A lag slower than the mode (`ω τ ≥ 1`)
/// acts as a static load, `e / k`: the factor is then 1. The fastest mode gives the smallest
/// factor, so the bound holds for every mode.
fn lag_tolerance_factor(m: &SliderModel, omega: f64) -> f64 {
    let tau = m.interface_lag();
    let wt = omega * tau;
    if wt > 0.0 && wt < 1.0 {
        1.0 / wt
    } else {
        1.0
    }
}

/// The slider with a quasi-static bulge ([`super::QuasiStaticBulge`]): the body alone, the bulge
/// gap settled where the bulge spring balances the interface force (or, with an interface lag,
/// carries the lagged force).
impl SliderSystem {
    /// The gaps at time `t` and state `s` with the bulge settled: where the bulge spring balances
    /// the interface force (by [`QuasiStaticBulge::settle`]) or, with an interface lag, carries
    /// the lagged force. `None` where the bulge on a frozen body has no stable equilibrium.
    fn settled_gaps<S: Index<usize, Output = f64> + ?Sized>(
        &self,
        q: &QuasiStaticBulge,
        t: f64,
        s: &S,
    ) -> Option<Gaps> {
        let m = &*self.model;
        let k = q.stiffness();
        let rigid = m.undeformed_gaps(s[0], self.protrusion(t, s), self.inputs.clearance_offset);
        let bulge = match self.layout.lagged_force {
            Some(i) => rigid.bulge + s[i] / k,
            None => {
                let volt2 = self.inputs.voltage.squared(t);
                let pad = rigid.pad;
                q.settle(rigid.bulge, |bulge| {
                    let f = m.interface_force(Gaps { bulge, pad }, volt2);
                    (bulge, f.value, f.d_bulge)
                })?
            }
        };
        Some(Gaps {
            bulge,
            pad: rigid.pad,
        })
    }

    /// [`Self::settled_gaps`] with the forces there and how the settled bulge gap moves.
    fn settled<S: Index<usize, Output = f64> + ?Sized>(
        &self,
        q: &QuasiStaticBulge,
        t: f64,
        s: &S,
    ) -> Option<SettledBulge> {
        let g = self.settled_gaps(q, t, s)?;
        let k = q.stiffness();
        let (f, hot) = self.model.hot_forces(g, self.inputs.voltage.squared(t));
        let fast = k - f.d_bulge;
        let along = match self.layout.lagged_force {
            Some(_) => [1.0, 1.0 / k, -1.0],
            None => {
                // k (d − d_r) = F(d, pad): ∂d/∂d_r = k/k_f, ∂d/∂pad = F_pad/k_f.
                let rigid = k / fast;
                [rigid + f.d_pad / fast, 0.0, -rigid]
            }
        };
        Some(SettledBulge {
            local: Local { g, f, hot },
            along,
            fast,
        })
    }

    /// The right-hand side at time `t` and state `s`, with what it reads of the inputs there,
    /// `at` ([`Self::inputs_at`]).
    #[inline]
    fn rhs_given<D: Dim>(&self, t: f64, s: &OVector<f64, D>, ds: &mut OVector<f64, D>, at: [f64; 4])
    where
        DefaultAllocator: Allocator<D>,
    {
        if let Some(q) = self.model.quasi_static {
            return self.condensed_rhs(&q, t, s, ds, at);
        }
        let [volt2, power, power_rate, accel] = at;
        let m = &*self.model;
        let st = &m.structure;
        let lay = self.layout;
        // The values alone: no slope is needed here.
        let (q, v) = (self.coordinates(s), self.velocities(s));
        let delta = self.protrusion_given(s, || power);
        let g = m.gaps_offset(&q, delta, self.inputs.clearance_offset);
        let hot = m.hot_values(g, volt2);
        let mut drive = self.interface_drive(s, &hot);
        if lay.term_states.1 > 0 {
            drive += self.term_rates(g, s, ds);
        }
        let f_ab = m.bearing().force(q[0], v[0]);
        let a = st.mass_solve(&st.generalised_force(&q, &v, f_ab, drive));
        for i in 0..lay.dofs {
            ds[i] = v[i];
            ds[lay.velocity(i)] = a[i];
        }
        self.lag_and_integral_rates((power, power_rate), s, &hot, ds);
        if self.inputs.base_motion.is_some() {
            for &(i, r) in &self.base[..self.n_base] {
                ds[i] -= r * accel;
            }
        }
    }

    fn condensed_rhs<D: Dim>(
        &self,
        q: &QuasiStaticBulge,
        t: f64,
        s: &OVector<f64, D>,
        ds: &mut OVector<f64, D>,
        [volt2, power, power_rate, accel]: [f64; 4],
    ) where
        DefaultAllocator: Allocator<D>,
    {
        let lay = self.layout;
        let m = &*self.model;
        let Some(g) = self.settled_gaps(q, t, s) else {
            ds.fill(f64::NAN);
            return;
        };
        let hot = m.hot_values(g, volt2);
        let v = s[lay.velocity(0)];
        let drive = self.interface_drive(s, &hot);
        ds[0] = v;
        ds[lay.velocity(0)] = (m.bearing().force(s[0], v) + drive) / m.structure.body_mass();
        self.lag_and_integral_rates((power, power_rate), s, &hot, ds);
        if self.inputs.base_motion.is_some() {
            ds[lay.velocity(0)] -= accel;
        }
    }

    /// The Jacobian and `∂f/∂t` of the condensed system, by the chain rule through the settled
    /// bulge gap.
    fn condensed_jacobian<D: Dim>(
        &self,
        q: &QuasiStaticBulge,
        t: f64,
        s: &OVector<f64, D>,
        j: &mut OMatrix<f64, D, D>,
        dfdt: &mut OVector<f64, D>,
    ) where
        DefaultAllocator: Allocator<D> + Allocator<D, D>,
    {
        let m = &*self.model;
        let lay = self.layout;
        j.fill(0.0);
        dfdt.fill(0.0);
        let Some(b) = self.settled(q, t, s) else {
            j.fill(f64::NAN);
            dfdt.fill(f64::NAN);
            return;
        };
        let l = &b.local;
        let dd = self.heat_slope_if_kept(l);
        let mass = m.structure.body_mass();
        let (v, y0) = (lay.velocity(0), s[0]);
        // Columns of the body heave, the lagged force and the protrusion.
        let cols = [Some(0), lay.lagged_force, lay.delta];
        // A quantity X(d, pad) along those columns: X′ ∂d/∂col, plus X_pad on the heave.
        let along = |x: &crate::force::ForceEval, c: usize| {
            x.d_bulge * b.along[c] + if c == 0 { x.d_pad } else { 0.0 }
        };
        j[(0, v)] = 1.0;
        j[(v, 0)] = -m.bearing().stiffness(y0) / mass;
        j[(v, v)] = -m.bearing().damping(y0) / mass;
        // The protrusion's and the voltage's explicit rates, and the gap's rate they make.
        let (p_rate, delta_rate) = self.power_and_protrusion_rates(t);
        let f_t = self.inputs.voltage.squared_rate(t) * l.hot.per_volt2.value;
        let d_t = match lay.lagged_force {
            Some(_) => -delta_rate,
            None => (f_t - q.stiffness() * delta_rate) / b.fast,
        };
        let force_t = l.f.d_bulge * d_t + f_t;
        for (c, col) in cols.iter().enumerate() {
            let Some(col) = *col else { continue };
            match lay.lagged_force {
                Some(i) => j[(i, col)] = along(&l.f, c) / m.interface_lag,
                None => j[(v, col)] += along(&l.f, c) / mass,
            }
            if let Some(i) = lay.contact_impulse {
                j[(i, col)] = along(&l.hot.contact, c);
            }
            if let Some(i) = lay.heat {
                j[(i, col)] = dd * b.along[c];
            }
        }
        match lay.lagged_force {
            Some(i) => {
                j[(v, i)] = 1.0 / mass;
                j[(i, i)] -= 1.0 / m.interface_lag;
                dfdt[i] = force_t / m.interface_lag;
            }
            None => dfdt[v] = force_t / mass,
        }
        if let Some(k) = lay.delta {
            j[(k, k)] = -1.0 / m.thermal_lag;
            dfdt[k] = m.protrusion(p_rate) / m.thermal_lag;
        }
        if let Some(i) = lay.contact_impulse {
            dfdt[i] = l.hot.contact.d_bulge * d_t;
        }
        if let Some(i) = lay.heat {
            dfdt[i] = dd * d_t;
        }
        if let Some(motion) = &self.inputs.base_motion {
            dfdt[v] -= motion.acceleration(t).1;
        }
    }
}

/// The bulge of a quasi-static bulge at one state ([`SliderSystem::settled`]).
struct SettledBulge {
    /// The gaps and forces at the settled bulge gap.
    local: Local,
    /// `∂d/∂y`, `∂d/∂F_lag` and `∂d/∂δ`: how the settled bulge gap moves with the body heave,
    /// the lagged force and the protrusion.
    along: [f64; 3],
    /// `k_b − ∂F/∂d` at the settled gap (N/m).
    fast: f64,
}
