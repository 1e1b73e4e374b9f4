//! The slider as an ODE: state layout, right-hand side and analytic Jacobian.

use super::SliderModel;
use crate::force::Gaps;
use crate::heater::Programme;
use crate::ode::OdeSystem;
use nalgebra::{allocator::Allocator, DefaultAllocator, Dim, OMatrix, OVector};

/// Where each quantity sits in the state vector. Only what the scene needs is there: the
/// protrusion only with a thermal lag, the lagged force only with an interface lag, and the two
/// running integrals only when a cycle needs them.
///
/// ```
/// use hdi_tribology::model::StateLayout;
/// let l = StateLayout::new(false, true, true);
/// assert_eq!(l.len(), 5);
/// assert_eq!((l.delta, l.lagged_force, l.contact_impulse, l.heat), (None, Some(2), Some(3), Some(4)));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StateLayout {
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
    /// Displacement `y` and velocity `v` first (indices 0 and 1), then the optional states.
    pub fn new(thermal_lag: bool, interface_lag: bool, integrals: bool) -> Self {
        let mut len = 2;
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
            delta,
            lagged_force,
            contact_impulse,
            heat,
            len,
        }
    }

    /// Number of states.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Always false: `y` and `v` are always there.
    pub fn is_empty(&self) -> bool {
        false
    }
}

/// [`SliderModel`] under a heater programme, as an [`OdeSystem`].
///
/// ```no_run
/// use hdi_tribology::{heater::Programme, model::{SliderModel, SliderSystem}, scene::Scene};
/// let model = SliderModel::from_scene(&Scene::paper())?;
/// let sys = SliderSystem::new(&model, Programme::constant(0.06, 1e-3)?, false);
/// assert_eq!(sys.layout().len(), 2);
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
    delta: f64,
    /// `F_if` and partials.
    f: crate::force::ForceEval,
    /// The tabulated sums behind `f`, with the contact force.
    hot: crate::force::HotForces,
}

impl<'a> SliderSystem<'a> {
    /// The slider under `programme`; `integrals` adds the contact impulse and heat states.
    pub fn new(model: &'a SliderModel, programme: Programme, integrals: bool) -> Self {
        let layout = StateLayout::new(
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

    /// Writes the initial state for rest at displacement `y` with protrusion `delta` and interface
    /// force `f_if` into a vector of the layout's length (other entries zero).
    pub fn initial_state<D: Dim>(&self, dim: D, y: f64, delta: f64, f_if: f64) -> OVector<f64, D>
    where
        DefaultAllocator: Allocator<D>,
    {
        let mut s = OVector::<f64, D>::zeros_generic(dim, nalgebra::Const::<1>);
        s[0] = y;
        if let Some(i) = self.layout.delta {
            s[i] = delta;
        }
        if let Some(i) = self.layout.lagged_force {
            s[i] = f_if;
        }
        s
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
        self.model.gaps(s[0], self.protrusion(t, s))
    }

    fn local<D: Dim>(&self, t: f64, s: &OVector<f64, D>) -> Local
    where
        DefaultAllocator: Allocator<D>,
    {
        let delta = self.protrusion(t, s);
        let g = self.model.gaps(s[0], delta);
        let volt2 = self.model.voltage.squared(t);
        let (f, hot) = self.model.hot_forces(g, volt2);
        Local { g, delta, f, hot }
    }

    /// Flash temperature and its derivative with respect to the bulge gap (central difference:
    /// the real contact area is tabulated without its derivative).
    fn heat_rate(&self, g: Gaps) -> (f64, f64) {
        let m = self.model;
        let h = 1e-6 * g.bulge.abs().max(1e-10);
        let up = m.flash_temperature(Gaps {
            bulge: g.bulge + h,
            ..g
        });
        let down = m.flash_temperature(Gaps {
            bulge: g.bulge - h,
            ..g
        });
        (m.flash_temperature(g), (up - down) / (2.0 * h))
    }
}

impl<D: Dim> OdeSystem<D> for SliderSystem<'_>
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
    fn rhs(&self, t: f64, s: &OVector<f64, D>, ds: &mut OVector<f64, D>) {
        let m = self.model;
        let l = self.local(t, s);
        let drive = match self.layout.lagged_force {
            Some(i) => s[i],
            None => l.f.value,
        };
        ds[0] = s[1];
        ds[1] = (m.bearing().force(s[0], s[1]) + drive) / m.mass;
        if let Some(i) = self.layout.delta {
            ds[i] = (m.protrusion(self.programme.power(t)) - l.delta) / m.thermal_lag;
        }
        if let Some(i) = self.layout.lagged_force {
            ds[i] = (l.f.value - s[i]) / m.interface_lag;
        }
        if let Some(i) = self.layout.contact_impulse {
            ds[i] = l.hot.contact.value;
        }
        if let Some(i) = self.layout.heat {
            let area = m.forces().real_contact_area(l.g);
            ds[i] = m.friction.flash_temperature(l.hot.contact.value, area);
        }
    }

    fn jacobian(&self, t: f64, s: &OVector<f64, D>, j: &mut OMatrix<f64, D, D>) -> bool {
        let m = self.model;
        let l = self.local(t, s);
        j.fill(0.0);
        // ∂F_if/∂y moves both gaps; ∂F_if/∂δ only the bulge gap.
        let f_y = l.f.d_bulge + l.f.d_pad;
        let f_delta = -l.f.d_bulge;
        j[(0, 1)] = 1.0;
        j[(1, 0)] = -m.bearing().stiffness(s[0]) / m.mass;
        j[(1, 1)] = -m.bearing().damping(s[0]) / m.mass;
        match self.layout.lagged_force {
            Some(i) => {
                j[(1, i)] = 1.0 / m.mass;
                j[(i, 0)] = f_y / m.interface_lag;
                j[(i, i)] = -1.0 / m.interface_lag;
                if let Some(k) = self.layout.delta {
                    j[(i, k)] = f_delta / m.interface_lag;
                }
            }
            None => {
                j[(1, 0)] += f_y / m.mass;
                if let Some(k) = self.layout.delta {
                    j[(1, k)] = f_delta / m.mass;
                }
            }
        }
        if let Some(k) = self.layout.delta {
            j[(k, k)] = -1.0 / m.thermal_lag;
        }
        if let Some(i) = self.layout.contact_impulse {
            let c = l.hot.contact;
            j[(i, 0)] = c.d_bulge + c.d_pad;
            if let Some(k) = self.layout.delta {
                j[(i, k)] = -c.d_bulge;
            }
        }
        if let Some(i) = self.layout.heat {
            let (_, dd) = self.heat_rate(l.g);
            j[(i, 0)] = dd;
            if let Some(k) = self.layout.delta {
                j[(i, k)] = -dd;
            }
        }
        true
    }

    fn time_derivative(&self, t: f64, s: &OVector<f64, D>, dfdt: &mut OVector<f64, D>) -> bool {
        let m = self.model;
        let l = self.local(t, s);
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
            None => dfdt[1] = f_t / m.mass,
        }
        if let Some(k) = self.layout.delta {
            dfdt[k] = m.protrusion(p_rate) / m.thermal_lag;
        }
        if let Some(i) = self.layout.contact_impulse {
            dfdt[i] = -l.hot.contact.d_bulge * delta_rate;
        }
        if let Some(i) = self.layout.heat {
            let (_, dd) = self.heat_rate(l.g);
            dfdt[i] = -dd * delta_rate;
        }
        true
    }
}
