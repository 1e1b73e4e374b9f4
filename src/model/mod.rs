//! The assembled slider: interface forces, air bearing, heater and voltage of one scene.
//!
//! [`SliderModel`] evaluates the physics of MODEL.md sections 2, 4 and 5 at a given state;
//! [`SliderSystem`] lays that physics out as an ODE for [`crate::ode`]. This is the only module
//! that knows both the physics and the stepper.

mod condensed;
mod error;
mod inputs;
mod structure;
mod system;

pub use condensed::{CondensationCheck, ForceSlopes, QuasiStaticBulge, SEPARATION};
pub use error::BalanceError;
pub use inputs::{BaseMotion, Heater, Inputs};
pub use structure::{Dofs, Structure};
pub use system::{Rest, SliderSystem, StateLayout};

use crate::cache::{CacheReport, TableCache};
use crate::error::{Error, Result};
use crate::force::{
    by_coupling, AirBearing, AirBearingModel, Breakdown, ForceEval, Gaps, HotForces, HotValues,
    InterfaceForces, Meniscus, OutsideTables, StatefulTerm,
};
use crate::heater::Programme;
use crate::quadrature::Span;
use crate::scene::Scene;
use std::f64::consts::PI;
use std::sync::Arc;

/// Voltage between head and disk: `V(t) = V_dc + V_ac sin(2π f t) − φ`.
///
/// ```
/// use hdi_tribology::model::Voltage;
/// let v = Voltage { dc: 1.0, ac_amplitude: 0.5, frequency: 1.0e4, contact_potential: 0.2 };
/// assert!((v.at(0.0) - 0.8).abs() < 1e-15);
/// assert!((v.squared(0.25e-4) - 1.3f64.powi(2)).abs() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Voltage {
    /// DC voltage `V_dc` (V).
    pub dc: f64,
    /// AC amplitude `V_ac` (V).
    pub ac_amplitude: f64,
    /// AC frequency `f` (Hz).
    pub frequency: f64,
    /// Contact potential `φ` (V).
    pub contact_potential: f64,
}

impl Voltage {
    /// `V(t)` (V).
    #[inline]
    pub fn at(&self, t: f64) -> f64 {
        let dc = self.dc - self.contact_potential;
        if self.ac_amplitude == 0.0 {
            // No sine to evaluate: the same number as `dc + 0 · sin(…)`.
            return dc;
        }
        dc + self.ac_amplitude * (2.0 * PI * self.frequency * t).sin()
    }

    /// `V(t)²` (V²).
    pub fn squared(&self, t: f64) -> f64 {
        let v = self.at(t);
        v * v
    }

    /// `d(V²)/dt` (V²/s).
    pub fn squared_rate(&self, t: f64) -> f64 {
        let w = 2.0 * PI * self.frequency;
        2.0 * self.at(t) * self.ac_amplitude * w * (w * t).cos()
    }

    /// `(V_dc − φ)²` (V²): the squared voltage of a static (DC) analysis.
    ///
    /// ```
    /// # use hdi_tribology::model::Voltage;
    /// let v = Voltage { dc: 1.0, ac_amplitude: 0.5, frequency: 1.0e4, contact_potential: 0.2 };
    /// assert!((v.dc_squared() - 0.64).abs() < 1e-15);
    /// assert!((v.mean_squared() - (0.64 + 0.125)).abs() < 1e-15);
    /// ```
    pub fn dc_squared(&self) -> f64 {
        self.effective_dc().powi(2)
    }

    /// The time mean of `V(t)²`: `(V_dc − φ)² + V_ac²/2` (V²).
    pub fn mean_squared(&self) -> f64 {
        let v0 = self.effective_dc();
        v0 * v0 + 0.5 * self.ac_amplitude * self.ac_amplitude
    }

    /// Whether the voltage changes in time.
    pub fn is_time_dependent(&self) -> bool {
        self.ac_amplitude != 0.0 && self.frequency != 0.0
    }

    /// The DC part of the effective voltage, `V_dc − φ`.
    pub fn effective_dc(&self) -> f64 {
        self.dc - self.contact_potential
    }

    /// The largest step (s) of an integration under this voltage: `given`, else a fortieth of
    /// the period of `V²`'s source with AC (no peak of `V²` is stepped over), else unlimited.
    ///
    /// ```
    /// # use hdi_tribology::model::Voltage;
    /// let v = Voltage { dc: 0.0, ac_amplitude: 0.5, frequency: 1.0e4, contact_potential: 0.0 };
    /// assert_eq!(v.max_step(None), 1.0 / 4.0e5);
    /// assert_eq!(v.max_step(Some(1e-3)), 1e-3);
    /// ```
    pub fn max_step(&self, given: Option<f64>) -> f64 {
        given.unwrap_or(if self.is_time_dependent() {
            1.0 / (40.0 * self.frequency.abs())
        } else {
            f64::INFINITY
        })
    }
}

/// Friction and flash-temperature parameters (MODEL.md section 5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Friction {
    /// Friction coefficient μ.
    pub coefficient: f64,
    /// Disk speed `v` (m/s).
    pub disk_speed: f64,
    /// Thermal conductivity of the head `k` (W/(m K)).
    pub conductivity: f64,
}

impl Friction {
    /// Flash temperature `ΔT = μ F_c v / (4 a k)` with `a = √(A_r/π)`; zero when there is no
    /// real contact area or no contact force.
    ///
    /// ```
    /// use hdi_tribology::model::Friction;
    /// let fr = Friction { coefficient: 0.2, disk_speed: 10.0, conductivity: 20.0 };
    /// let a: f64 = 1e-7;
    /// let dt = fr.flash_temperature(1e-4, std::f64::consts::PI * a * a);
    /// assert!((dt - 0.2 * 1e-4 * 10.0 / (4.0 * a * 20.0)).abs() < 1e-9);
    /// assert_eq!(fr.flash_temperature(1e-4, 0.0), 0.0);
    /// ```
    pub fn flash_temperature(&self, contact_force: f64, real_area: f64) -> f64 {
        if real_area <= 0.0 || contact_force <= 0.0 {
            return 0.0;
        }
        let a = (real_area / PI).sqrt();
        self.coefficient * contact_force * self.disk_speed / (4.0 * a * self.conductivity)
    }

    /// The derivative of [`Friction::flash_temperature`] along a coordinate that changes the
    /// contact force and the real area at the rates `force_rate` and `area_rate`:
    /// `ΔT (F_c′/F_c − A_r′/(2 A_r))`, zero where the flash temperature is.
    ///
    /// ```
    /// use hdi_tribology::model::Friction;
    /// let fr = Friction { coefficient: 0.2, disk_speed: 10.0, conductivity: 20.0 };
    /// // Along the gap d with F_c = 1e-4 (1 − d/1e-9) N and A_r = 1e-14 (1 − d/1e-9) m²:
    /// let t = |d: f64| fr.flash_temperature(1e-4 * (1.0 - d / 1e-9), 1e-14 * (1.0 - d / 1e-9));
    /// let slope = fr.flash_temperature_slope(1e-4, -1e5, 1e-14, -1e-5);
    /// let h = 1e-15;
    /// let fd = (t(h) - t(-h)) / (2.0 * h);
    /// assert!((slope - fd).abs() < 1e-6 * fd.abs());
    /// assert_eq!(fr.flash_temperature_slope(0.0, 1.0, 1e-14, 1.0), 0.0);
    /// ```
    pub fn flash_temperature_slope(
        &self,
        contact_force: f64,
        force_rate: f64,
        real_area: f64,
        area_rate: f64,
    ) -> f64 {
        let t = self.flash_temperature(contact_force, real_area);
        if t == 0.0 {
            return 0.0;
        }
        t * (force_rate / contact_force - 0.5 * area_rate / real_area)
    }
}

/// The slider with a heater-driven bulge (MODEL.md section 2) on its [`Structure`]: one rigid
/// mass by default, or a body with a bulge or pitch of its own.
///
/// ```no_run
/// use hdi_tribology::{model::{Dofs, SliderModel}, scene::Scene};
/// let model = SliderModel::from_scene(&Scene::paper())?;
/// // Interface force at the flying position with the heater at 60 mW, no voltage:
/// let g = model.gaps(&Dofs::zeros(), model.protrusion(0.06));
/// println!("{} N", model.interface_force(g, 0.0).value);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct SliderModel {
    forces: Arc<InterfaceForces>,
    bearing: Arc<dyn AirBearing>,
    /// Masses, springs and dampers, and where the bulge sits.
    structure: Structure,
    /// Nominal clearance `h0` (m).
    nominal_clearance: f64,
    /// Heater efficiency `η` (m/W).
    efficiency: f64,
    /// Thermal lag `τ_th` (s); 0 removes the state.
    thermal_lag: f64,
    /// Interface lag `τ_lag` (s); 0 removes the state.
    interface_lag: f64,
    /// The scene's head–disk voltage: the voltage of [`SliderModel::inputs`].
    voltage: Voltage,
    /// Friction and flash temperature.
    friction: Friction,
    /// Terms that carry states of their own (none unless added).
    stateful: Arc<[Arc<dyn StatefulTerm>]>,
    /// Whether the bearing is the linear spring (its stiffness does not depend on `y`).
    linear_bearing: bool,
    /// The bulge mode condensed to its quasi-static equilibrium (none: the full structure).
    quasi_static: Option<QuasiStaticBulge>,
}

impl SliderModel {
    /// Builds the model of a scene: validates it, tabulates the enabled interface terms and builds
    /// the air bearing.
    pub fn from_scene(scene: &Scene) -> Result<Self> {
        scene.validate()?;
        Self::assemble(scene, scene.build_interface()?, scene.meniscus()?)
    }

    /// [`SliderModel::from_scene`] with its tables read from `cache` when it holds them for this
    /// scene's inputs (else built and stored there): a warm start. The model is the same, to the
    /// bit, either way. `None` builds the tables afresh, as [`SliderModel::from_scene`] does. The
    /// report says whether the cache was hit and any entry that was found bad and rebuilt (see
    /// [`crate::cache`]).
    ///
    /// ```no_run
    /// use hdi_tribology::{cache::TableCache, model::SliderModel, scene::Scene};
    /// let cache = TableCache::from_env()?; // None when HDI_CACHE=off
    /// let (model, report) = SliderModel::from_scene_with_cache(&Scene::paper(), cache.as_ref())?;
    /// for n in &report.notices {
    ///     eprintln!("warning: {n}");
    /// }
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn from_scene_with_cache(
        scene: &Scene,
        cache: Option<&TableCache>,
    ) -> Result<(Self, CacheReport)> {
        let Some(cache) = cache else {
            return Ok((Self::from_scene(scene)?, CacheReport::default()));
        };
        scene.validate()?;
        let (forces, meniscus, report) = scene.tables_cached(cache)?;
        Ok((Self::assemble(scene, forces, meniscus)?, report))
    }

    /// Builds the model of a scene with interface forces assembled by the caller, e.g. the scene's
    /// terms plus a term of one's own:
    ///
    /// ```no_run
    /// use hdi_tribology::{force::InterfaceForces, model::SliderModel, quadrature::TableOptions, scene::Scene};
    /// let scene = Scene::paper();
    /// let terms = scene.interface_terms()?;
    /// // terms.push(Box::new(MyMeniscus::new(..)));
    /// let forces = InterfaceForces::build(terms, scene.table_range(), &TableOptions::default())?;
    /// let model = SliderModel::from_scene_with_forces(&scene, forces)?;
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn from_scene_with_forces(scene: &Scene, forces: InterfaceForces) -> Result<Self> {
        scene.validate()?;
        Self::assemble(scene, forces, scene.meniscus()?)
    }

    /// The model of `scene` with its tables: the interface forces and the scene's lubricant
    /// menisci, if any.
    fn assemble(
        scene: &Scene,
        forces: InterfaceForces,
        meniscus: Option<Meniscus>,
    ) -> Result<Self> {
        let bearing: Arc<dyn AirBearing> = Arc::from(scene.build_air_bearing()?);
        let contact_potential = scene
            .electrostatic
            .as_ref()
            .map_or(0.0, |e| e.contact_potential_v);
        SliderModel {
            forces: Arc::new(forces),
            bearing,
            structure: Structure::from_scene(scene)?,
            nominal_clearance: scene.nominal_clearance_m,
            efficiency: scene.heater.efficiency_m_per_w,
            thermal_lag: scene.heater.thermal_lag_s,
            interface_lag: scene.slider.interface_lag_s,
            voltage: Voltage {
                dc: scene.voltage.dc_v,
                ac_amplitude: scene.voltage.ac_amplitude_v,
                frequency: scene.voltage.ac_frequency_hz,
                contact_potential,
            },
            friction: Friction {
                coefficient: scene.friction.coefficient,
                disk_speed: scene.friction.disk_speed_m_per_s,
                conductivity: scene.friction.head_conductivity_w_per_m_k,
            },
            stateful: Arc::new([]),
            linear_bearing: matches!(scene.air_bearing, AirBearingModel::Linear { .. }),
            quasi_static: None,
        }
        .with_scene_terms(meniscus)
    }

    /// The model with the stateful terms its scene enables (the lubricant menisci); itself when
    /// there are none.
    fn with_scene_terms(self, meniscus: Option<Meniscus>) -> Result<Self> {
        match meniscus {
            Some(m) => self.with_stateful_term(m),
            None => Ok(self),
        }
    }

    /// The inputs of the scene for a heater: the scene's voltage, no change of clearance, the
    /// disk at rest.
    ///
    /// ```no_run
    /// use hdi_tribology::{model::{Heater, SliderModel}, scene::Scene};
    /// let model = SliderModel::from_scene(&Scene::paper())?;
    /// let inputs = model.inputs(Heater::Power(0.06));
    /// assert_eq!(inputs.voltage, model.voltage());
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn inputs(&self, heater: impl Into<Heater>) -> Inputs {
        Inputs::new(heater.into(), self.voltage)
    }

    /// The same model with another voltage for its analyses (tables are shared, not rebuilt).
    pub fn with_voltage(&self, voltage: Voltage) -> Self {
        SliderModel {
            voltage,
            ..self.clone()
        }
    }

    /// The same model with the AC amplitude `v_ac` (V) of its voltage changed (tables shared).
    ///
    /// ```no_run
    /// use hdi_tribology::{model::SliderModel, scene::Scene};
    /// let model = SliderModel::from_scene(&Scene::paper())?.with_ac_amplitude(0.6);
    /// assert_eq!(model.voltage().ac_amplitude, 0.6);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn with_ac_amplitude(&self, v_ac: f64) -> Self {
        self.with_voltage(Voltage {
            ac_amplitude: v_ac,
            ..self.voltage
        })
    }

    /// The same model with the thermal lag `τ_th` (s; 0 removes the state).
    pub fn with_thermal_lag(&self, tau: f64) -> Self {
        SliderModel {
            thermal_lag: tau,
            ..self.clone()
        }
    }

    /// The same model with the interface lag `τ_lag` (s; 0 removes the state).
    ///
    /// ```no_run
    /// use hdi_tribology::{model::SliderModel, scene::Scene};
    /// let model = SliderModel::from_scene(&Scene::paper())?.with_interface_lag(1e-8);
    /// assert_eq!(model.interface_lag(), 1e-8);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn with_interface_lag(&self, tau: f64) -> Self {
        SliderModel {
            interface_lag: tau,
            ..self.clone()
        }
    }

    /// The same model with its interface forces outside their tables as `outside` says
    /// ([`InterfaceForces::with_outside_tables`]): with [`OutsideTables::Refused`] they are NaN
    /// there, so that no right-hand side pays for direct quadrature (the drive's bounded mode).
    ///
    /// ```no_run
    /// use hdi_tribology::{force::OutsideTables, model::SliderModel, scene::Scene};
    /// let model = SliderModel::from_scene(&Scene::paper())?;
    /// let bounded = model.with_outside_tables(OutsideTables::Refused);
    /// assert_eq!(bounded.forces().outside_tables(), OutsideTables::Refused);
    /// assert_eq!(model.forces().outside_tables(), OutsideTables::Exact);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn with_outside_tables(&self, outside: OutsideTables) -> Self {
        SliderModel {
            forces: Arc::new(self.forces.as_ref().clone().with_outside_tables(outside)),
            ..self.clone()
        }
    }

    /// The same model with one more term that carries states of its own ([`StatefulTerm`]):
    /// every dynamic analysis then integrates its states, and the static analyses take their
    /// equilibrium.
    ///
    /// ```no_run
    /// use hdi_tribology::{force::RelaxingState, model::SliderModel, scene::Scene};
    /// let model = SliderModel::from_scene(&Scene::paper())?;
    /// let with = model.with_stateful_term(RelaxingState::relaxation(1e-4, 1.0)?)?;
    /// assert_eq!(with.stateful_terms().len(), 1);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    ///
    /// # Errors
    /// More than [`crate::force::MAX_TERM_STATES`] states over all terms, or a term with none.
    pub fn with_stateful_term(&self, term: impl StatefulTerm + 'static) -> Result<Self> {
        let (n, total) = (term.states(), self.term_states() + term.states());
        if self.quasi_static.is_some() {
            return Err(Error::invalid(
                term.name(),
                "a model with a quasi-static bulge takes no stateful terms",
            ));
        }
        if n == 0 || total > crate::force::MAX_TERM_STATES {
            return Err(Error::invalid(
                term.name(),
                format!(
                    "a stateful term needs 1 to {} states over all terms of a model, got {n} \
                     more to the {} there",
                    crate::force::MAX_TERM_STATES,
                    self.term_states()
                ),
            ));
        }
        let mut all: Vec<Arc<dyn StatefulTerm>> = self.stateful.to_vec();
        all.push(Arc::new(term));
        Ok(SliderModel {
            stateful: all.into(),
            ..self.clone()
        })
    }

    /// The terms that carry states of their own.
    pub fn stateful_terms(&self) -> &[Arc<dyn StatefulTerm>] {
        &self.stateful
    }

    /// The number of states the stateful terms add.
    pub fn term_states(&self) -> usize {
        self.stateful.iter().map(|t| t.states()).sum()
    }

    /// The number of stateful terms with two branches ([`StatefulTerm::switches`]): the
    /// simulations hold one flag for each.
    pub fn term_branches(&self) -> usize {
        self.stateful.iter().filter(|t| t.switches()).count()
    }

    /// Masses, springs and dampers, and where the bulge sits.
    pub fn structure(&self) -> &Structure {
        &self.structure
    }

    /// Nominal clearance `h0` (m).
    pub fn nominal_clearance(&self) -> f64 {
        self.nominal_clearance
    }

    /// Heater efficiency `η` (m/W).
    pub fn efficiency(&self) -> f64 {
        self.efficiency
    }

    /// Thermal lag `τ_th` (s); 0 when there is none.
    pub fn thermal_lag(&self) -> f64 {
        self.thermal_lag
    }

    /// Interface lag `τ_lag` (s); 0 when there is none.
    pub fn interface_lag(&self) -> f64 {
        self.interface_lag
    }

    /// The scene's head–disk voltage (the voltage of [`SliderModel::inputs`] and of the static
    /// analyses).
    pub fn voltage(&self) -> Voltage {
        self.voltage
    }

    /// Friction and flash-temperature parameters.
    pub fn friction(&self) -> Friction {
        self.friction
    }

    /// The same model on another structure (tables are shared, not rebuilt): a map over the
    /// bulge's frequency or damping is a loop over this.
    ///
    /// ```no_run
    /// use hdi_tribology::{model::{SliderModel, Structure}, scene::Scene};
    /// let rigid = SliderModel::from_scene(&Scene::paper())?;
    /// let bulge = rigid.with_structure(Structure::bulge(1e-6, 1e-13, 4e5, 0.05)?);
    /// assert_eq!(bulge.structure().dofs(), 2);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    ///
    /// The new structure is the full one: a quasi-static bulge of the model before is not kept
    /// ([`SliderModel::with_quasi_static_bulge`]).
    pub fn with_structure(&self, structure: Structure) -> Self {
        SliderModel {
            structure,
            quasi_static: None,
            ..self.clone()
        }
    }

    /// The same model with its bulge mode condensed to its quasi-static equilibrium
    /// ([`QuasiStaticBulge`]): the dynamic analyses then integrate the body alone, with the
    /// bulge gap where the bulge spring balances the interface force. The static analyses are
    /// the same as the full model's (a static equilibrium has no inertia to condense). This does
    /// not check that the condensation holds: [`SliderModel::quasi_static_check`] does, and a
    /// cycle stops with a non-finite right-hand side where the bulge on a frozen body has no
    /// stable equilibrium. The full model is the default; the linear response refuses a
    /// condensed model.
    ///
    /// ```no_run
    /// use hdi_tribology::{model::SliderModel, scene::Scene};
    /// let full = SliderModel::from_scene(&Scene::from_path("scenes/paper_bulge.toml")?)?;
    /// assert!(full.quasi_static_check()?.passes());
    /// let reduced = full.with_quasi_static_bulge()?;
    /// assert!(reduced.quasi_static_bulge().is_some());
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::InvalidInput`] on `structure` for a structure without a bulge of its own on one
    /// spring ([`Structure::quasi_static_bulge`]), and for a model with stateful terms.
    pub fn with_quasi_static_bulge(&self) -> Result<Self> {
        let q = self.bulge_mode()?;
        if !self.stateful.is_empty() {
            return Err(Error::invalid(
                "structure",
                "a quasi-static bulge is not offered with stateful terms (their forces would \
                 enter the bulge's balance)",
            ));
        }
        Ok(SliderModel {
            quasi_static: Some(q),
            ..self.clone()
        })
    }

    /// The condensed bulge mode, where the model has one ([`SliderModel::with_quasi_static_bulge`]).
    pub fn quasi_static_bulge(&self) -> Option<QuasiStaticBulge> {
        self.quasi_static
    }

    /// Whether the bulge mode of this model's structure may be condensed
    /// ([`QuasiStaticBulge::check`]), at the model's voltage and lags.
    ///
    /// # Errors
    /// As [`SliderModel::with_quasi_static_bulge`] for a structure without such a mode.
    pub fn quasi_static_check(&self) -> Result<CondensationCheck> {
        Ok(self.bulge_mode()?.check(self))
    }

    /// An error naming `analysis` where the model has a quasi-static bulge: for the analyses
    /// that read the structure's coordinates, which the condensation removes.
    pub(crate) fn require_full_structure(&self, analysis: &str) -> Result<()> {
        match self.quasi_static {
            Some(_) => Err(Error::invalid(
                "structure",
                format!("{analysis} needs the full structure, not a quasi-static bulge"),
            )),
            None => Ok(()),
        }
    }

    fn bulge_mode(&self) -> Result<QuasiStaticBulge> {
        self.structure.quasi_static_bulge().ok_or_else(|| {
            Error::invalid(
                "structure",
                "a quasi-static bulge needs a body and a bulge of its own on one spring and \
                 damper (the `bulge` preset)",
            )
        })
    }

    /// The tabulated interface forces.
    pub fn forces(&self) -> &InterfaceForces {
        &self.forces
    }

    /// The air bearing.
    pub fn bearing(&self) -> &dyn AirBearing {
        &*self.bearing
    }

    /// Protrusion at steady state for heater power `p` (W): `δ = η P`.
    pub fn protrusion(&self, p: f64) -> f64 {
        self.efficiency * p
    }

    /// Heater power that makes protrusion `delta` at steady state.
    pub fn power_for(&self, delta: f64) -> f64 {
        delta / self.efficiency
    }

    /// The one home of the gap geometry: at coordinates `q` and protrusion `delta` the bulge gap
    /// is `h0 + bᵀq − δ` and the pad gap `h0 + q₀` (for the rigid slider: `h0 + y − δ`, `h0 + y`).
    #[inline]
    pub fn gaps(&self, q: &Dofs, delta: f64) -> Gaps {
        self.gaps_offset(q, delta, 0.0)
    }

    /// [`SliderModel::gaps`] with the nominal clearance changed by `offset` (m): `h0 + offset`
    /// in place of `h0` ([`Inputs::clearance_offset`]).
    #[inline]
    pub fn gaps_offset(&self, q: &Dofs, delta: f64, offset: f64) -> Gaps {
        let h0 = self.nominal_clearance + offset;
        Gaps {
            bulge: h0 + self.structure.bulge_displacement(q) - delta,
            pad: self.pad_gap(q[0], offset),
        }
    }

    /// The gaps at body heave `y` (m) with the bulge spring of a quasi-static bulge undeformed:
    /// the bulge gap `d_r = h0 + offset + y − δ` and the pad gap `h0 + offset + y`
    /// ([`QuasiStaticBulge`] moves the bulge from there).
    #[inline]
    pub fn undeformed_gaps(&self, y: f64, delta: f64, offset: f64) -> Gaps {
        let pad = self.pad_gap(y, offset);
        Gaps {
            bulge: pad - delta,
            pad,
        }
    }

    /// The pad gap `h0 + offset + y` (m) at body heave `y` (m): where the slider body meets
    /// the disk when it reaches zero (the end of the lumped model).
    #[inline]
    pub fn pad_gap(&self, y: f64, offset: f64) -> f64 {
        self.nominal_clearance + offset + y
    }

    /// The gaps when the bulge gap is held at `d` and the body heaves by `y` (m): the pad gap
    /// `h0 + y`. The static balance, parametrised by `d`, uses this form of
    /// [`SliderModel::gaps`] (`d` itself, not recomputed from `q` and `δ` with rounding).
    pub fn gaps_at(&self, d: f64, y: f64) -> Gaps {
        Gaps {
            bulge: d,
            pad: self.pad_gap(y, 0.0),
        }
    }

    /// Interface force `F_if = F_static + V² G_e` and its partial derivatives.
    pub fn interface_force(&self, g: Gaps, volt2: f64) -> ForceEval {
        let (s, e) = self.forces.coupled_sums(g, volt2 != 0.0);
        self.with_stateful(add_scaled(s, e, volt2), g)
    }

    /// Whether every stateful term's force at rest depends on the bulge gap alone
    /// ([`StatefulTerm::rests_on_bulge_gap`]; true when there are none).
    fn stateful_rest_on_bulge_gap(&self) -> bool {
        self.stateful.iter().all(|t| t.rests_on_bulge_gap())
    }

    /// `f` plus the forces of the stateful terms with their states at equilibrium at `g`, and
    /// the total derivatives along the gaps (through the equilibrium's own slope,
    /// `∂x/∂d = −(∂ẋ/∂x)⁻¹ ∂ẋ/∂d`): what a static analysis sees of a term with memory. `f` as
    /// it is when the model has no such terms (at the cost of one check, inline: the drive
    /// reads the interface force every period).
    #[inline]
    pub(crate) fn with_stateful(&self, f: ForceEval, g: Gaps) -> ForceEval {
        if self.stateful.is_empty() {
            return f;
        }
        self.with_stateful_terms(f, g)
    }

    /// [`SliderModel::with_stateful`] with stateful terms.
    fn with_stateful_terms(&self, mut f: ForceEval, g: Gaps) -> ForceEval {
        use crate::force::MAX_TERM_STATES;
        use nalgebra::{SMatrix, SVector};
        for term in self.stateful.iter() {
            let k = term.states();
            let mut x = [0.0; MAX_TERM_STATES];
            term.equilibrium(g, &mut x[..k]);
            let s = term.force(g, &x[..k]);
            let p = term.rate_partials(g, &x[..k]);
            if k == 1 {
                // The 1 × 1 solve in closed form: the division the LU below would do, with
                // its answer where ∂ẋ/∂x = 0 (no slope through the state).
                let a = p.d_state[0][0];
                let slope = |rate: [f64; MAX_TERM_STATES]| {
                    let dx = if a == 0.0 { 0.0 } else { rate[0] / a };
                    -(s.d_state[0] * dx)
                };
                f.value += s.force.value;
                f.d_bulge += s.force.d_bulge + slope(p.d_bulge);
                f.d_pad += s.force.d_pad + slope(p.d_pad);
                continue;
            }
            // ∂ẋ/∂x, padded with the identity beyond the term's states.
            let a = SMatrix::<f64, MAX_TERM_STATES, MAX_TERM_STATES>::from_fn(|r, c| {
                if r < k && c < k {
                    p.d_state[r][c]
                } else if r == c {
                    1.0
                } else {
                    0.0
                }
            });
            let lu = a.lu();
            let slope = |rate: [f64; MAX_TERM_STATES]| -> f64 {
                let dx = lu
                    .solve(&SVector::<f64, MAX_TERM_STATES>::from(rate))
                    .unwrap_or_default();
                -(0..k).map(|j| s.d_state[j] * dx[j]).sum::<f64>()
            };
            f.value += s.force.value;
            f.d_bulge += s.force.d_bulge + slope(p.d_bulge);
            f.d_pad += s.force.d_pad + slope(p.d_pad);
        }
        f
    }

    /// `F_if` and the three tabulated sums it is made of (static, per V², contact), from one
    /// look-up of the fused table where the scene allows it.
    pub fn hot_forces(&self, g: Gaps, volt2: f64) -> (ForceEval, HotForces) {
        let h = self.forces.evaluate(g);
        (add_scaled(h.static_part, h.per_volt2, volt2), h)
    }

    /// The values alone of `F_if`, the contact force and the real contact area at `g` and `V²`,
    /// from the same tables as [`SliderModel::hot_forces`]: what the right-hand side reads.
    ///
    /// ```no_run
    /// use hdi_tribology::{force::Gaps, model::SliderModel, scene::Scene};
    /// let model = SliderModel::from_scene(&Scene::paper())?;
    /// let g = Gaps::same(1e-9);
    /// let v = model.hot_values(g, 0.36);
    /// assert_eq!(v.interface, model.hot_forces(g, 0.36).0.value);
    /// assert!(v.contact > 0.0 && v.area > 0.0);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    #[inline]
    pub fn hot_values(&self, g: Gaps, volt2: f64) -> HotValues {
        self.forces.values(g, volt2)
    }

    /// The static part and the per-V² part of the interface force from direct (untabulated)
    /// evaluation of every term: slow, for refinement and checks.
    pub fn interface_parts_exact(&self, g: Gaps) -> Result<(ForceEval, ForceEval)> {
        use crate::force::{Coupling, GapReference, TermForce};
        let (mut stat, mut per_v2) = (ForceEval::default(), ForceEval::default());
        for term in self.forces.terms() {
            let (d, on_pad) = match term.gap() {
                GapReference::Bulge => (g.bulge, false),
                GapReference::Pad => (g.pad, true),
            };
            let TermForce {
                value: f,
                slope: df,
            } = term.force(d)?;
            let out = match term.coupling() {
                Coupling::Static => &mut stat,
                Coupling::PerVoltSquared => &mut per_v2,
            };
            out.value += f;
            if on_pad {
                out.d_pad += df;
            } else {
                out.d_bulge += df;
            }
        }
        Ok((stat, per_v2))
    }

    /// Interface force from direct (untabulated) evaluation of every term.
    pub fn interface_force_exact(&self, g: Gaps, volt2: f64) -> Result<ForceEval> {
        let (s, e) = self.interface_parts_exact(g)?;
        Ok(self.with_stateful(add_scaled(s, e, volt2), g))
    }

    /// Every force at one state, for reports.
    pub fn breakdown(&self, g: Gaps, volt2: f64) -> Breakdown {
        self.forces.breakdown(g, volt2)
    }

    /// Contact force `F_c` at the given gaps.
    pub fn contact_force(&self, g: Gaps) -> f64 {
        self.forces.contact(g).value
    }

    /// Flash temperature rise `ΔT` at the given gaps (MODEL.md section 5).
    pub fn flash_temperature(&self, g: Gaps) -> f64 {
        if !self.forces.has_contact() {
            return 0.0;
        }
        let v = self.forces.values(g, 0.0);
        self.friction.flash_temperature(v.contact, v.area)
    }

    /// The static balance with the bulge gap held at `d` (the protrusion then follows from
    /// `d = h0 + bᵀq − δ`), for `V² = volt2`: the coordinates `q` where the structure, the air
    /// bearing and the interface force balance, `K q = e₀ F_ab(q₀) + b F_if(d, h0 + q₀)`, and the
    /// interface force there. `exact` polishes the tabulated solution with direct (untabulated)
    /// forces.
    ///
    /// Solved by a safeguarded Newton iteration; with no pad terms and a linear bearing it
    /// converges in one step.
    pub fn balance(&self, d: f64, volt2: f64, exact: bool) -> Result<(Dofs, ForceEval)> {
        let h0 = self.nominal_clearance;
        let st = &self.structure;
        let at = |q0: f64| self.gaps_at(d, q0);
        let residual = |q: &Dofs, f: &ForceEval| self.balance_residual(q, f);
        // With no pad-gap term the interface force depends on `d` alone, which is held: one
        // evaluation serves every Newton step (the same numbers, fewer look-ups). Stateful
        // terms enter at rest, which for most of them is a function of `d` alone too.
        let pad_free = !self.forces.uses_pad_gap() && self.stateful_rest_on_bulge_gap();
        // Start from the linearised bearing.
        let f0 = self.interface_force(at(0.0), volt2);
        let j0 = st.tangent(self.bearing.stiffness(0.0), 0.0, 0.0);
        let mut q = st
            .solve(&j0, &(st.bulge_vector() * f0.value))
            .unwrap_or_default();
        // Keep the pad gap positive: the power-law bearing is singular at g = 0.
        let y_floor = -h0 * (1.0 - 1e-9);
        if q[0] <= y_floor {
            q[0] = 0.5 * y_floor;
        }
        let mut found = None;
        for _ in 0..200 {
            let f = if pad_free {
                f0
            } else {
                self.interface_force(at(q[0]), volt2)
            };
            let (r, j) = residual(&q, &f);
            if !r.iter().all(|x| x.is_finite()) || !j.iter().all(|x| x.is_finite()) {
                // Say which term failed rather than that no balance exists.
                self.interface_force_exact(at(q[0]), volt2)?;
                return Err(BalanceError::NotFinite {
                    d_nm: d * 1e9,
                    y_nm: q[0] * 1e9,
                }
                .into());
            }
            if !st.is_positive(&j) {
                break;
            }
            let Some(step) = st.solve(&j, &r) else { break };
            let mut q_new = q + step;
            if q_new[0] <= y_floor {
                q_new[0] = 0.5 * (q[0] + y_floor);
            }
            if st.step_converged(&(q_new - q), &q, 1e-15 * h0, 1e-12) {
                found = Some((q_new, f));
                break;
            }
            q = q_new;
        }
        let Some((mut q, mut f)) = found else {
            return Err(BalanceError::NoBalance {
                d_nm: d * 1e9,
                volt2_v2: volt2,
            }
            .into());
        };
        if exact {
            // Newton on the balance with direct forces, from the tabulated solution.
            let mut direct = None;
            for _ in 0..50 {
                let (step, fe) = match direct {
                    Some(fe) => (self.balance_step(&q, &fe), fe),
                    None => self.exact_balance_step(d, volt2, &q)?,
                };
                if pad_free {
                    direct = Some(fe);
                }
                f = fe;
                let Some(step) = step else { break };
                q += step;
                if st.step_converged(&step, &q, 1e-16 * h0, 1e-13) {
                    break;
                }
            }
        }
        Ok((q, f))
    }

    /// The static balance of [`SliderModel::balance`] in closed form, where it is linear in the
    /// interface force: with a linear bearing and no term on the pad gap the tangent
    /// `J₀ = K + e₀e₀ᵀk_ab` is constant and the interface force depends on `d` alone, so the
    /// balance is `q = J₀⁻¹ b F_if(d)` and the bulge displacement `bᵀq = s F_if(d)` with the
    /// compliance `s = bᵀJ₀⁻¹b`; the total stiffness ([`SliderModel::total_stiffness`]) is
    /// `1/s − ∂F_if/∂d` (Sherman–Morrison). `None` for other models, or where `J₀` is not positive
    /// (the balance then fails at every gap).
    pub(crate) fn linear_balance(&self, volt2: f64) -> Option<LinearBalance> {
        if !self.linear_bearing || self.forces.uses_pad_gap() || !self.stateful.is_empty() {
            return None;
        }
        let st = &self.structure;
        let n = st.dofs();
        let j0 = st.tangent(self.bearing.stiffness(0.0), 0.0, 0.0);
        if !st.is_positive(&j0) {
            return None;
        }
        let b = st.bulge_vector();
        let w = st.solve(&j0, &b)?;
        let compliance = b.dot(&w);
        let u = w / compliance;
        // |J₀⁻¹|, column by column, for the rounding allowances.
        let mut inverse = [[0.0; crate::scene::MAX_DOF]; crate::scene::MAX_DOF];
        for (c, col) in inverse.iter_mut().enumerate().take(n) {
            let mut e = Dofs::zeros();
            e[c] = 1.0;
            let x = st.solve(&j0, &e)?;
            for (r, v) in col.iter_mut().enumerate().take(n) {
                *v = x[r].abs();
            }
        }
        let through = |r: usize| (0..n).map(|c| inverse[c][r] * b[c].abs()).sum::<f64>();
        let lin = LinearBalance {
            volt2,
            stiffness: 1.0 / compliance,
            compliance,
            heave: w[0],
            stiffness_scale: [
                (0..n)
                    .flat_map(|r| (0..n).map(move |c| (r, c)))
                    .map(|(r, c)| u[r].abs() * j0[(r, c)].abs() * u[c].abs())
                    .sum(),
                (0..n).map(|r| b[r].abs() * u[r].abs()).sum::<f64>().powi(2),
            ],
            compliance_scale: (0..n).map(|r| b[r].abs() * through(r)).sum(),
            heave_scale: through(0),
        };
        let all = [
            lin.stiffness,
            lin.heave,
            lin.stiffness_scale[0],
            lin.stiffness_scale[1],
            lin.compliance_scale,
        ];
        all.iter().all(|x| x.is_finite()).then_some(lin)
    }

    /// What every tabulated equilibrium ([`SliderModel::balance`] with the tables, then
    /// [`SliderModel::total_stiffness`], the contact force and the protrusion `h0 + bᵀq − d`) at
    /// a bulge gap in `[a, b]` is known to be, from bounds on the tables: `None` where the tables
    /// do not bound them, or where the balance could meet the pad-gap floor. Each bound allows
    /// [`PROOF_MARGIN`] times the magnitudes the computation goes through (absolute values of
    /// `J₀`, `J₀⁻¹`, `b` and the forces), far above their rounding.
    pub(crate) fn static_bounds(
        &self,
        lin: &LinearBalance,
        a: f64,
        b: f64,
    ) -> Option<StaticBounds> {
        let f = self.forces.bulge_bounds(a, b, lin.volt2)?;
        let h0 = self.nominal_clearance;
        let m = PROOF_MARGIN;
        let force = f.force.magnitude();
        // The balance keeps the pad gap positive by moving a heave below this floor.
        let heave = f.force.scale(lin.heave);
        if heave.lo - m * (h0 + lin.heave_scale * force) <= -h0 * (1.0 - 1e-9) {
            return None;
        }
        let [c0, c1] = lin.stiffness_scale;
        let tol = m * (c0 + c1 * f.slope.magnitude());
        let stable = if lin.stiffness - f.slope.hi > tol {
            Some(true)
        } else if f.slope.lo - lin.stiffness > tol {
            Some(false)
        } else {
            None
        };
        let lift = f.force.scale(lin.compliance);
        let protrusion = Span {
            lo: h0 + lift.lo - b,
            hi: h0 + lift.hi - a,
        }
        .widen(m * (h0 + a.abs().max(b.abs()) + lin.compliance_scale * force));
        Some(StaticBounds {
            stable,
            contact: f.contact,
            protrusion,
        })
    }

    /// One Newton step of the static balance of [`SliderModel::balance`] at bulge gap `d` from
    /// coordinates `q`, with direct (untabulated) forces: the step (`None` where the tangent is
    /// singular) and the interface force at `q`. From the balance of a slightly different model
    /// it is the first-order change of `q` (used for the sensitivities of static transitions).
    pub fn exact_balance_step(
        &self,
        d: f64,
        volt2: f64,
        q: &Dofs,
    ) -> Result<(Option<Dofs>, ForceEval)> {
        let f = self.interface_force_exact(self.gaps_at(d, q[0]), volt2)?;
        Ok((self.balance_step(q, &f), f))
    }

    /// The Newton step of the static balance at coordinates `q` under interface force `f`
    /// (`None` where the tangent is singular).
    fn balance_step(&self, q: &Dofs, f: &ForceEval) -> Option<Dofs> {
        let (r, j) = self.balance_residual(q, f);
        self.structure.solve(&j, &r)
    }

    /// The static balance's residual and tangent at coordinates `q` under interface force `f`.
    fn balance_residual(&self, q: &Dofs, f: &ForceEval) -> (Dofs, structure::DofMatrix) {
        let st = &self.structure;
        let r = st.generalised_force(q, &Dofs::zeros(), self.bearing.force(q[0], 0.0), f.value);
        let j = st.tangent(self.bearing.stiffness(q[0]), 0.0, f.d_pad);
        (r, j)
    }

    /// The one home of the total stiffness: the stiffness that the bulge meets at coordinates
    /// `q` under an interface force `f`, by static condensation of the structure, air bearing
    /// and interface (`k_ab(y) − ∂F_if/∂y` for the rigid slider); positive means stable.
    pub fn total_stiffness(&self, q: &Dofs, f: &ForceEval) -> f64 {
        let j = self
            .structure
            .tangent(self.bearing.stiffness(q[0]), f.d_bulge, f.d_pad);
        self.structure.condensed(&j)
    }

    /// The coordinates that hold the bulge displacement `bᵀq` at `z` (m) with the air bearing
    /// alone, the load on the bulge that does it (N), and the structure's stiffness condensed
    /// onto the bulge there (N/m). For the rigid slider: `y = z`, `−F_ab(z)`, `k_ab(z)`.
    pub fn bulge_load(&self, z: f64) -> Result<(Dofs, f64, f64)> {
        self.structure.displaced_bulge(
            z,
            |y| (self.bearing.force(y, 0.0), self.bearing.stiffness(y)),
            self.nominal_clearance,
        )
    }

    /// A heater programme from the scene's knots (the analyses' translation of a scene is
    /// `analysis::Protocol::from_scene`, or `analysis::HeaterProgramme::fixed_from_scene`).
    pub fn programme_from_knots(knots: &[[f64; 2]]) -> Result<Programme> {
        Programme::new(knots.iter().map(|k| (k[0], k[1])).collect())
    }
}

/// Relative allowance of the bounds of [`SliderModel::static_bounds`] for the rounding of the
/// computations they bound (some 10⁷ times the unit roundoff).
const PROOF_MARGIN: f64 = 1e-9;

/// The constants of [`SliderModel::linear_balance`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LinearBalance {
    /// `V²` of the balance (V²).
    volt2: f64,
    /// `1/s` (N/m): the total stiffness where the interface force has no slope.
    stiffness: f64,
    /// `s = bᵀJ₀⁻¹b` (m/N).
    compliance: f64,
    /// `e₀ᵀJ₀⁻¹b` (m/N): the heave per unit of interface force.
    heave: f64,
    /// `|u|ᵀ|J₀||u|` and `(|b|ᵀ|u|)²` with `u = J₀⁻¹b/s`: the size of the rounding of the total
    /// stiffness is their sum weighted by 1 and by `|∂F_if/∂d|`.
    stiffness_scale: [f64; 2],
    /// `|b|ᵀ|J₀⁻¹||b|` (m/N): the size of the rounding of `bᵀq` per unit of force.
    compliance_scale: f64,
    /// `e₀ᵀ|J₀⁻¹||b|` (m/N): the same for the heave.
    heave_scale: f64,
}

/// What every tabulated equilibrium over a stretch of bulge gaps is known to be
/// ([`SliderModel::static_bounds`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct StaticBounds {
    /// `Some(true)`: every one is stable (total stiffness > 0); `Some(false)`: every one is
    /// unstable (≤ 0); `None`: not known.
    pub stable: Option<bool>,
    /// Bounds of the contact force (N).
    pub contact: Span,
    /// Bounds of the protrusion (m).
    pub protrusion: Span,
}

/// `a + scale·b`, component by component.
fn add_scaled(a: ForceEval, b: ForceEval, scale: f64) -> ForceEval {
    ForceEval {
        value: by_coupling(a.value, b.value, scale),
        d_bulge: by_coupling(a.d_bulge, b.d_bulge, scale),
        d_pad: by_coupling(a.d_pad, b.d_pad, scale),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::force::{RatePartials, RelaxingState, StateForce};

    /// A term that hides that its force at rest sees the bulge gap alone.
    #[derive(Debug)]
    struct Opaque(RelaxingState);

    impl StatefulTerm for Opaque {
        fn name(&self) -> &str {
            "opaque"
        }
        fn states(&self) -> usize {
            self.0.states()
        }
        fn equilibrium(&self, g: Gaps, x: &mut [f64]) {
            self.0.equilibrium(g, x)
        }
        fn rates(&self, g: Gaps, x: &[f64], dx: &mut [f64]) {
            self.0.rates(g, x, dx)
        }
        fn rate_partials(&self, g: Gaps, x: &[f64]) -> RatePartials {
            self.0.rate_partials(g, x)
        }
        fn force(&self, g: Gaps, x: &[f64]) -> StateForce {
            self.0.force(g, x)
        }
        fn tolerances(&self, displacement: f64, atol: &mut [f64]) {
            self.0.tolerances(displacement, atol)
        }
    }

    /// The balance's shortcut for terms at rest on the bulge gap alone (one force evaluation per
    /// balance) gives the numbers of the Newton iteration that evaluates at every step.
    #[test]
    fn the_bulge_gap_shortcut_keeps_the_balance() {
        let plain = SliderModel::from_scene(&Scene::paper()).unwrap();
        // A lagged spring of −2e-3 N per nm of bulge gap at rest: strong enough to matter.
        let term = RelaxingState::new(1e-6, 1e9, -2e-3, None).unwrap();
        let fast = plain.with_stateful_term(term).unwrap();
        let slow = plain.with_stateful_term(Opaque(term)).unwrap();
        assert!(fast.stateful_rest_on_bulge_gap() && !slow.stateful_rest_on_bulge_gap());
        for d in [0.5e-9, 1.5e-9, 4e-9, 12e-9] {
            for exact in [false, true] {
                let a = fast.balance(d, 0.36, exact).unwrap();
                let b = slow.balance(d, 0.36, exact).unwrap();
                assert_eq!(a, b, "d = {d:e} m, exact: {exact}");
                // and the term is there: its force at rest is part of the balance's force
                let without = plain.balance(d, 0.36, exact).unwrap().1.value;
                assert!(
                    (a.1.value - without - (-2e-3 * 1e9 * d)).abs()
                        < 1e-12 * without.abs().max(1.0)
                );
            }
        }
    }
}
