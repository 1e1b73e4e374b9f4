//! The slider as an ODE: state layout, right-hand side and analytic Jacobian.

use super::{Dofs, SliderModel};
use crate::force::Gaps;
use crate::heater::Programme;
use crate::ode::OdeSystem;
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OMatrix, OVector};

/// Where each quantity sits in the state vector. Only what the scene needs is there: one position
/// and one velocity per degree of freedom of the structure, the protrusion only with a thermal
/// lag, the lagged force only with an interface lag, and the two running integrals only when a
/// cycle needs them.
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
    /// `Q = ∫ F_c dt` (N s): the running mean of the contact force is `(Q(t) − Q(t − T_w))/T_w`.
    pub contact_impulse: Option<usize>,
    /// `Θ = ∫ ΔT dt` (K s): the time mean of the flash temperature.
    pub heat: Option<usize>,
    len: usize,
}

impl StateLayout {
    /// Positions and velocities of `dofs` coordinates first, then the optional states.
    pub fn new(dofs: usize, thermal_lag: bool, interface_lag: bool, integrals: bool) -> Self {
        let mut len = 2 * dofs;
        let mut next = |on: bool| {
            on.then(|| {
                len += 1;
                len - 1
            })
        };
        let delta = next(thermal_lag);
        let lagged_force = next(interface_lag);
        let contact_impulse = next(integrals);
        let heat = next(integrals);
        StateLayout {
            dofs,
            delta,
            lagged_force,
            contact_impulse,
            heat,
            len,
        }
    }

    /// Index of the velocity of coordinate `i`.
    pub fn velocity(&self, i: usize) -> usize {
        self.dofs + i
    }

    /// Number of states.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Always false: positions and velocities are always there.
    pub fn is_empty(&self) -> bool {
        false
    }
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

/// [`SliderModel`] under a heater programme, as an [`OdeSystem`].
///
/// ```no_run
/// use hdi_tribology::{heater::Programme, model::{SliderModel, SliderSystem}, scene::Scene};
/// let model = SliderModel::from_scene(&Scene::paper())?;
/// let sys = SliderSystem::new(&model, Programme::constant(0.06, 1e-3)?, false);
/// assert_eq!(sys.layout().len(), 2 * model.structure.dofs());
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct SliderSystem<'a> {
    model: &'a SliderModel,
    programme: Programme,
    layout: StateLayout,
}

/// Forces and their derivatives at one state.
struct Local {
    g: Gaps,
    /// `F_if` and partials.
    f: crate::force::ForceEval,
    /// The tabulated sums behind `f`, with the contact force.
    hot: crate::force::HotForces,
}

impl<'a> SliderSystem<'a> {
    /// The slider under `programme`; `integrals` adds the contact impulse and heat states.
    pub fn new(model: &'a SliderModel, programme: Programme, integrals: bool) -> Self {
        let layout = StateLayout::new(
            model.structure.dofs(),
            model.thermal_lag > 0.0,
            model.interface_lag > 0.0,
            integrals,
        );
        SliderSystem {
            model,
            programme,
            layout,
        }
    }

    /// The state layout.
    pub fn layout(&self) -> StateLayout {
        self.layout
    }

    /// The heater programme.
    pub fn programme(&self) -> &Programme {
        &self.programme
    }

    /// The model.
    pub fn model(&self) -> &SliderModel {
        self.model
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
        s
    }

    /// The coordinates `q` of state `s`.
    #[inline]
    pub fn coordinates<D: Dim>(&self, s: &OVector<f64, D>) -> Dofs
    where
        DefaultAllocator: Allocator<D>,
    {
        self.block(s, 0)
    }

    /// The velocities `q̇` of state `s`.
    #[inline]
    pub fn velocities<D: Dim>(&self, s: &OVector<f64, D>) -> Dofs
    where
        DefaultAllocator: Allocator<D>,
    {
        self.block(s, self.layout.velocity(0))
    }

    /// `dofs` entries of `s` from `start`, as coordinates.
    #[inline]
    fn block<D: Dim>(&self, s: &OVector<f64, D>, start: usize) -> Dofs
    where
        DefaultAllocator: Allocator<D>,
    {
        let mut q = super::structure::zero_dofs();
        for i in 0..self.layout.dofs {
            q[i] = s[start + i];
        }
        q
    }

    /// Protrusion at time `t` and state `s`.
    pub fn protrusion<D: Dim>(&self, t: f64, s: &OVector<f64, D>) -> f64
    where
        DefaultAllocator: Allocator<D>,
    {
        match self.layout.delta {
            Some(i) => s[i],
            None => self.model.protrusion(self.programme.power(t)),
        }
    }

    /// Gaps at time `t` and state `s`.
    pub fn gaps<D: Dim>(&self, t: f64, s: &OVector<f64, D>) -> Gaps
    where
        DefaultAllocator: Allocator<D>,
    {
        self.model.gaps(&self.coordinates(s), self.protrusion(t, s))
    }

    /// The air-bearing force at state `s` (N).
    pub fn bearing_force<D: Dim>(&self, s: &OVector<f64, D>) -> f64
    where
        DefaultAllocator: Allocator<D>,
    {
        self.model.bearing().force(s[0], s[self.layout.velocity(0)])
    }

    fn local<D: Dim>(&self, t: f64, s: &OVector<f64, D>) -> Local
    where
        DefaultAllocator: Allocator<D>,
    {
        let delta = self.protrusion(t, s);
        let g = self.model.gaps(&self.coordinates(s), delta);
        let volt2 = self.model.voltage.squared(t);
        let (f, hot) = self.model.hot_forces(g, volt2);
        Local { g, f, hot }
    }

    /// The derivative of the flash temperature (the heat state's rate) along the bulge gap at
    /// the point of `l`: the derivative of the interpolants the right-hand side reads.
    fn heat_slope(&self, l: &Local) -> f64 {
        let m = self.model;
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
        let m = self.model;
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
    }

    /// `∂f/∂t` at time `t` and the point of `l`, `dd` the flash temperature's slope there.
    fn time_derivative_at<D: Dim>(&self, t: f64, l: &Local, dd: f64, dfdt: &mut OVector<f64, D>)
    where
        DefaultAllocator: Allocator<D>,
    {
        let m = self.model;
        dfdt.fill(0.0);
        let (_, p_rate) = self.programme.power_and_rate(t);
        // Protrusion moves with the programme only without a thermal lag.
        let delta_rate = match self.layout.delta {
            Some(_) => 0.0,
            None => m.protrusion(p_rate),
        };
        let f_t = -l.f.d_bulge * delta_rate + m.voltage.squared_rate(t) * l.hot.per_volt2.value;
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
    }
}

impl<D: Dim> OdeSystem<D> for SliderSystem<'_>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn rhs(&self, t: f64, s: &OVector<f64, D>, ds: &mut OVector<f64, D>) {
        let m = self.model;
        let st = &m.structure;
        let lay = self.layout;
        // The values alone: no slope is needed here.
        let (q, v) = (self.coordinates(s), self.velocities(s));
        let delta = self.protrusion(t, s);
        let hot = m.hot_values(m.gaps(&q, delta), m.voltage.squared(t));
        let drive = match lay.lagged_force {
            Some(i) => s[i],
            None => hot.interface,
        };
        let f_ab = m.bearing().force(q[0], v[0]);
        let a = st.mass_solve(&st.generalised_force(&q, &v, f_ab, drive));
        for i in 0..lay.dofs {
            ds[i] = v[i];
            ds[lay.velocity(i)] = a[i];
        }
        if let Some(i) = lay.delta {
            ds[i] = (m.protrusion(self.programme.power(t)) - delta) / m.thermal_lag;
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

    fn jacobian(&self, t: f64, s: &OVector<f64, D>, j: &mut OMatrix<f64, D, D>) -> bool {
        let l = self.local(t, s);
        self.jacobian_at(&l, self.heat_slope_if_kept(&l), s, j);
        true
    }

    fn time_derivative(&self, t: f64, s: &OVector<f64, D>, dfdt: &mut OVector<f64, D>) -> bool {
        let l = self.local(t, s);
        self.time_derivative_at(t, &l, self.heat_slope_if_kept(&l), dfdt);
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
        let l = self.local(t, s);
        let dd = self.heat_slope_if_kept(&l);
        self.jacobian_at(&l, dd, s, j);
        self.time_derivative_at(t, &l, dd, dfdt);
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
        for i in 0..st.dofs() {
            r = r.max(w[i]).max(c[(i, i)] / m[(i, i)]);
        }
        for tau in [self.interface_lag, self.thermal_lag] {
            if tau > 0.0 {
                r = r.max(1.0 / tau);
            }
        }
        r
    }

    /// The largest step (s): `given`, else a fortieth of the voltage period with AC (no peak of
    /// `V²` is stepped over), else unlimited.
    pub fn max_step(&self, given: Option<f64>) -> f64 {
        let v = self.voltage;
        given.unwrap_or(if v.is_time_dependent() {
            1.0 / (40.0 * v.frequency.abs())
        } else {
            f64::INFINITY
        })
    }
}

impl SliderSystem<'_> {
    /// Absolute tolerances of every state for the displacement tolerance `displacement` (m):
    /// positions to `displacement` (rotations to it over their lever), velocities times their
    /// angular frequency, the protrusion to `displacement`, the lagged force times the stiffness
    /// at the bulge, and the integrals to `impulse` (N s) and `heat` (K s).
    ///
    /// ```
    /// use hdi_tribology::{heater::Programme, model::{SliderModel, SliderSystem}, scene::Scene};
    /// let model = SliderModel::from_scene(&Scene::paper())?;
    /// let sys = SliderSystem::new(&model, Programme::constant(0.06, 1e-3)?, true);
    /// let atol = sys.tolerances(1e-14, 1e-12, 1e-10);
    /// assert_eq!(atol.len(), 4);
    /// assert!((atol[1] / 1e-14 - (3e5f64 / 1e-6).sqrt()).abs() < 1e-6);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn tolerances(&self, displacement: f64, impulse: f64, heat: f64) -> Vec<f64> {
        let m = self.model;
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
            atol[i] = displacement * st.condensed(&j).abs();
        }
        if let Some(i) = lay.contact_impulse {
            atol[i] = impulse;
        }
        if let Some(i) = lay.heat {
            atol[i] = heat;
        }
        atol
    }
}
