//! Field-by-field validation of a scene; every error names the dotted field path.

use super::Scene;
use crate::error::{check_finite, check_non_negative, check_positive};
use crate::surface::PeakModel;
use crate::units::fmt_short;
use crate::{Error, Result};

/// Largest voltage magnitude (V) a scene may apply: far above any head–disk interface (pull-in
/// happens at a few volts), far below where `V²` loses meaning.
pub const MAX_VOLTAGE_V: f64 = 1e3;

/// Highest AC frequency (Hz): a cycle resolves every period of `V²`, so its work grows with the
/// frequency; 10 MHz keeps a paper-length cycle to a few million steps.
pub const MAX_AC_FREQUENCY_HZ: f64 = 1e7;

/// Largest step limit of a scene's solver: a work budget of about a few minutes per cycle.
pub const MAX_STEPS: usize = 100_000_000;

/// Largest roughness (surface-height or peak-height standard deviation) relative to the nominal
/// clearance: beyond it the slider flies inside the roughness and the averaged forces lose
/// meaning (and, far beyond, overflow).
pub const MAX_SIGMA_OVER_CLEARANCE: f64 = 10.0;

/// Smallest nominal clearance (m): 0.1 nm, about an atom's size; below it the continuum forces
/// of the model lose meaning.
pub const MIN_NOMINAL_CLEARANCE_M: f64 = 1e-10;

/// Largest nominal clearance (m): 1 µm, a hundred times the clearance of any drive with thermal
/// fly-height control; the force tables and the lumped model are built for gaps of nanometres.
pub const MAX_NOMINAL_CLEARANCE_M: f64 = 1e-6;

/// Largest air-bearing stiffness (N/m) at the flying gap: 1e10, a thousand times that of any
/// slider's air bearing (1e5 to 1e7 N/m; the paper's scene has 3e5). Far beyond it the pull-in
/// voltage and the settling times lose meaning.
pub const MAX_AIR_BEARING_STIFFNESS_N_PER_M: f64 = 1e10;

/// Checks `lo ≤ value ≤ hi`, naming `field` and the unit.
fn check_range(field: &str, value: f64, lo: f64, hi: f64, unit: &str) -> Result<()> {
    check_finite(field, value)?;
    if !(lo..=hi).contains(&value) {
        return Err(Error::invalid(
            field,
            format!(
                "must lie between {} {unit} and {} {unit}, got {} {unit}",
                fmt_short(lo),
                fmt_short(hi),
                fmt_short(value)
            ),
        ));
    }
    Ok(())
}

/// Checks `|value| ≤ bound`, naming `field` and the unit.
fn check_magnitude(field: &str, value: f64, bound: f64, unit: &str) -> Result<()> {
    check_finite(field, value)?;
    if value.abs() > bound {
        let within = if value < 0.0 {
            "lie within ±"
        } else {
            "be at most "
        };
        return Err(Error::invalid(
            field,
            format!(
                "must {within}{} {unit}, got {} {unit}",
                fmt_short(bound),
                fmt_short(value)
            ),
        ));
    }
    Ok(())
}

impl Scene {
    /// Checks every field; the error names the field (dotted path) and the reason.
    pub fn validate(&self) -> Result<()> {
        if self.name.trim().is_empty() {
            return Err(Error::invalid("name", "must not be empty"));
        }
        check_positive("nominal_clearance_m", self.nominal_clearance_m)?;
        check_range(
            "nominal_clearance_m",
            self.nominal_clearance_m,
            MIN_NOMINAL_CLEARANCE_M,
            MAX_NOMINAL_CLEARANCE_M,
            "m",
        )?;
        check_non_negative("surface.height_sigma_m", self.surface.height_sigma_m)?;
        self.validate_sigma()?;
        if let Some(m) = &self.intermolecular {
            check_positive(
                "intermolecular.hamaker_attractive_j",
                m.hamaker_attractive_j,
            )?;
            check_positive(
                "intermolecular.hamaker_repulsive_j_m6",
                m.hamaker_repulsive_j_m6,
            )?;
            if let Some(c) = m.cutoff_m {
                check_positive("intermolecular.cutoff_m", c)?;
            }
            m.footprint.validate("intermolecular.footprint")?;
        }
        if let Some(e) = &self.electrostatic {
            check_magnitude(
                "electrostatic.contact_potential_v",
                e.contact_potential_v,
                MAX_VOLTAGE_V,
                "V",
            )?;
            check_non_negative(
                "electrostatic.dielectric_thickness_m",
                e.dielectric_thickness_m,
            )?;
            match e.cutoff_m {
                Some(c) => {
                    check_positive("electrostatic.cutoff_m", c)?;
                }
                None if self.intermolecular.is_none() => {
                    return Err(Error::invalid(
                        "electrostatic.cutoff_m",
                        "required when the intermolecular term is off (its default is h_e)",
                    ))
                }
                None => {}
            }
            e.footprint.validate("electrostatic.footprint")?;
        }
        if let Some(c) = &self.contact {
            check_positive("contact.composite_modulus_pa", c.composite_modulus_pa)?;
            check_positive("contact.asperity_radius_m", c.asperity_radius_m)?;
            check_positive("contact.asperity_density_per_m2", c.asperity_density_per_m2)?;
            c.footprint.validate("contact.footprint")?;
        }
        self.validate_lubricant()?;
        self.validate_air_bearing()?;
        if let Some(d) = &self.drive {
            d.validate()?;
        }
        check_positive("slider.mass_kg", self.slider.mass_kg)?;
        check_non_negative("slider.interface_lag_s", self.slider.interface_lag_s)?;
        self.validate_structure()?;
        self.validate_heater()?;
        let v = &self.voltage;
        check_magnitude("voltage.dc_v", v.dc_v, MAX_VOLTAGE_V, "V")?;
        check_non_negative("voltage.ac_amplitude_v", v.ac_amplitude_v)?;
        check_magnitude(
            "voltage.ac_amplitude_v",
            v.ac_amplitude_v,
            MAX_VOLTAGE_V,
            "V",
        )?;
        check_positive("voltage.ac_frequency_hz", v.ac_frequency_hz)?;
        check_magnitude(
            "voltage.ac_frequency_hz",
            v.ac_frequency_hz,
            MAX_AC_FREQUENCY_HZ,
            "Hz",
        )?;
        check_positive(
            "detector.contact_threshold_n",
            self.detector.contact_threshold_n,
        )?;
        check_positive("detector.window_s", self.detector.window_s)?;
        let f = &self.friction;
        check_non_negative("friction.coefficient", f.coefficient)?;
        check_non_negative("friction.disk_speed_m_per_s", f.disk_speed_m_per_s)?;
        check_positive(
            "friction.head_conductivity_w_per_m_k",
            f.head_conductivity_w_per_m_k,
        )?;
        self.validate_solver()?;
        for (i, &a) in self.sweep.ac_amplitudes_v.iter().enumerate() {
            let field = format!("sweep.ac_amplitudes_v[{i}]");
            check_non_negative(&field, a)?;
            check_magnitude(&field, a, MAX_VOLTAGE_V, "V")?;
        }
        Ok(())
    }

    /// σ: bounded by the clearance, and one value for one surface. The Rice-maxima peak law
    /// describes the maxima of the surface whose heights have `surface.height_sigma_m`, so its
    /// `sigma_m` must be that σ, unless `surface.independent_peak_sigma` says they differ on
    /// purpose.
    fn validate_sigma(&self) -> Result<()> {
        let h0 = self.nominal_clearance_m;
        let bound = MAX_SIGMA_OVER_CLEARANCE * h0;
        let too_rough = |field: &str, s: f64| {
            Error::invalid(
                field,
                format!(
                    "must not exceed {} x nominal_clearance_m = {} m, got {} m",
                    fmt_short(MAX_SIGMA_OVER_CLEARANCE),
                    fmt_short(bound),
                    fmt_short(s)
                ),
            )
        };
        let sigma = self.surface.height_sigma_m;
        if sigma > bound {
            return Err(too_rough("surface.height_sigma_m", sigma));
        }
        if self.contact.is_none() {
            return Ok(());
        }
        let p = self.peaks()?;
        if p.std_dev() > bound || p.mean().abs() > bound {
            return Err(too_rough("surface.peaks", p.std_dev().max(p.mean().abs())));
        }
        if let PeakModel::RiceMaxima { sigma_m, .. } = self.surface.peaks {
            // equal up to rounding (one may be given in nm, the other in m)
            let differ = (sigma_m - sigma).abs() > 1e-12 * sigma_m.abs().max(sigma.abs());
            if differ && !self.surface.independent_peak_sigma {
                return Err(Error::invalid(
                    "surface.peaks.sigma_m",
                    format!(
                        "is {} m but surface.height_sigma_m is {} m: the Rice-maxima peaks are \
                         those of the same surface, give both the same σ (or set \
                         surface.independent_peak_sigma = true if they differ on purpose)",
                        fmt_short(sigma_m),
                        fmt_short(sigma)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The lubricant: thicknesses, bonded within total, θ in [0°, 90°], γ > 0, times > 0, and
    /// the asperities of a `[contact]` section to form on.
    fn validate_lubricant(&self) -> Result<()> {
        let Some(l) = &self.lubricant else {
            return Ok(());
        };
        check_non_negative("lubricant.total_thickness_m", l.total_thickness_m)?;
        check_non_negative("lubricant.bonded_thickness_m", l.bonded_thickness_m)?;
        if l.bonded_thickness_m > l.total_thickness_m {
            return Err(Error::invalid(
                "lubricant.bonded_thickness_m",
                format!(
                    "must not exceed the total thickness of {} m, got {} m",
                    fmt_short(l.total_thickness_m),
                    fmt_short(l.bonded_thickness_m)
                ),
            ));
        }
        check_positive(
            "lubricant.surface_tension_n_per_m",
            l.surface_tension_n_per_m,
        )?;
        let theta = l.contact_angle_deg;
        if !(theta.is_finite() && (0.0..=90.0).contains(&theta)) {
            return Err(Error::invalid(
                "lubricant.contact_angle_deg",
                format!("must lie in [0, 90] deg, got {} deg", fmt_short(theta)),
            ));
        }
        check_positive("lubricant.healing_time_s", l.healing_time_s)?;
        check_non_negative("lubricant.formation_time_s", l.formation_time_s)?;
        if let Some(s) = l.rupture_distance_m {
            check_non_negative("lubricant.rupture_distance_m", s)?;
        }
        match (l.pickup_rate_m_per_s, l.pickup_loss_time_s) {
            (Some(r), Some(t)) => {
                check_positive("lubricant.pickup_rate_m_per_s", r)?;
                check_positive("lubricant.pickup_loss_time_s", t)?;
            }
            (Some(_), None) => {
                return Err(Error::invalid(
                    "lubricant.pickup_loss_time_s",
                    "is required with lubricant.pickup_rate_m_per_s",
                ))
            }
            (None, Some(_)) => {
                return Err(Error::invalid(
                    "lubricant.pickup_rate_m_per_s",
                    "is required with lubricant.pickup_loss_time_s",
                ))
            }
            (None, None) => {}
        }
        if self.contact.is_none() && l.mobile_thickness_m() > 0.0 {
            return Err(Error::invalid(
                "lubricant",
                "needs a [contact] section: the bridges form on its asperities",
            ));
        }
        Ok(())
    }

    fn validate_heater(&self) -> Result<()> {
        let h = &self.heater;
        check_non_negative("heater.efficiency_m_per_w", h.efficiency_m_per_w)?;
        check_non_negative("heater.thermal_lag_s", h.thermal_lag_s)?;
        if h.programme.len() < 2 {
            return Err(Error::invalid(
                "heater.programme",
                format!(
                    "needs at least 2 knots [t_s, power_w], got {}",
                    h.programme.len()
                ),
            ));
        }
        for (i, &[t, p]) in h.programme.iter().enumerate() {
            check_finite(&format!("heater.programme[{i}].t_s"), t)?;
            check_non_negative(&format!("heater.programme[{i}].power_w"), p)?;
            if i > 0 && t <= h.programme[i - 1][0] {
                return Err(Error::invalid(
                    format!("heater.programme[{i}].t_s"),
                    format!(
                        "times must increase strictly, got {} s after {} s",
                        fmt_short(t),
                        fmt_short(h.programme[i - 1][0])
                    ),
                ));
            }
        }
        let tr = &h.triggered;
        check_non_negative("heater.triggered.start_power_w", tr.start_power_w)?;
        check_positive("heater.triggered.ramp_rate_w_per_s", tr.ramp_rate_w_per_s)?;
        check_non_negative("heater.triggered.overshoot_w", tr.overshoot_w)?;
        Ok(())
    }

    /// The air bearing's own fields, and its stiffness at the flying gap within
    /// [`MAX_AIR_BEARING_STIFFNESS_N_PER_M`].
    fn validate_air_bearing(&self) -> Result<()> {
        use crate::force::AirBearingModel;
        let k = self.air_bearing.build()?.stiffness(0.0);
        let field = match self.air_bearing {
            AirBearingModel::Linear { .. } | AirBearingModel::Cubic { .. } => {
                "air_bearing.stiffness_n_per_m"
            }
            AirBearingModel::PowerLaw { .. } => "air_bearing.preload_n",
            AirBearingModel::Reynolds { .. } => "air_bearing.geometry",
        };
        if k > MAX_AIR_BEARING_STIFFNESS_N_PER_M {
            let what = match self.air_bearing {
                AirBearingModel::PowerLaw { .. } => {
                    format!("gives a stiffness n F0 / h0 of {} N/m", fmt_short(k))
                }
                _ => format!("is {} N/m", fmt_short(k)),
            };
            return Err(Error::invalid(
                field,
                format!(
                    "{what}, above {} N/m, a thousand times the stiffest slider air bearing",
                    fmt_short(MAX_AIR_BEARING_STIFFNESS_N_PER_M)
                ),
            ));
        }
        Ok(())
    }

    fn validate_solver(&self) -> Result<()> {
        let s = &self.solver;
        if s.method.parse::<crate::ode::Method>().is_err() {
            let names: Vec<&str> = crate::ode::Method::ALL.iter().map(|m| m.name()).collect();
            return Err(Error::invalid(
                "solver.method",
                format!(
                    "unknown method {:?}, expected one of {}",
                    s.method,
                    names.join(", ")
                ),
            ));
        }
        let min = crate::ode::MIN_RTOL;
        if !(s.rtol >= min && s.rtol < 1.0) {
            return Err(Error::invalid(
                "solver.rtol",
                format!(
                    "must lie in [{min:.1e}, 1) (100 ε up to 1), got {}",
                    fmt_short(s.rtol)
                ),
            ));
        }
        check_positive("solver.atol_m", s.atol_m)?;
        if let Some(h) = s.max_step_s {
            check_positive("solver.max_step_s", h)?;
        }
        if s.max_steps == 0 || s.max_steps > MAX_STEPS {
            return Err(Error::invalid(
                "solver.max_steps",
                format!(
                    "must lie in 1..={} (a work budget), got {}",
                    fmt_short(MAX_STEPS as f64),
                    s.max_steps
                ),
            ));
        }
        let t = &self.table;
        // the direct quadrature behind the tables is good to about 1e-12
        if !(t.rel_tol >= 1e-11 && t.rel_tol <= 1e-2) {
            return Err(Error::invalid(
                "table.rel_tol",
                format!("must lie in [1e-11, 0.01], got {}", fmt_short(t.rel_tol)),
            ));
        }
        if let Some(lo) = t.d_min_m {
            check_finite("table.d_min_m", lo)?;
        }
        if let Some(hi) = t.d_max_m {
            check_finite("table.d_max_m", hi)?;
        }
        let (lo, hi) = self.table_range();
        if !(lo.is_finite() && hi.is_finite()) {
            return Err(Error::invalid(
                "table",
                format!(
                    "the range ({}, {}) m is not finite: the lengths of the scene overflow",
                    fmt_short(lo),
                    fmt_short(hi)
                ),
            ));
        }
        if lo.partial_cmp(&hi) != Some(std::cmp::Ordering::Less) {
            return Err(Error::invalid(
                "table",
                format!(
                    "d_min_m must be below d_max_m, got range ({}, {}) m",
                    fmt_short(lo),
                    fmt_short(hi)
                ),
            ));
        }
        // The range must cover the scene: the flying gap at zero heater power (about h0), and
        // with contact on, the asperity peaks (where contact starts).
        if hi < self.nominal_clearance_m {
            return Err(Error::invalid(
                "table.d_max_m",
                format!(
                    "must reach the nominal clearance {} m (the flying gap at zero heater power), got {} m",
                    fmt_short(self.nominal_clearance_m),
                    fmt_short(hi)
                ),
            ));
        }
        if self.contact.is_some() {
            if let Ok(p) = self.peaks() {
                if lo > p.mean() {
                    return Err(Error::invalid(
                        "table.d_min_m",
                        format!(
                            "must reach down to the mean asperity peak height {} m, where contact starts, got {} m",
                            fmt_short(p.mean()),
                            fmt_short(lo)
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}

impl Scene {
    /// The structure's own fields, that a structure taking its matrices from the air bearing has
    /// a `reynolds` one, and that pad-gap terms (which act on the body) are only used with the
    /// rigid structure, where body and bulge are one.
    fn validate_structure(&self) -> Result<()> {
        self.structure.validate()?;
        if self.structure.from_bearing()
            && !matches!(
                self.air_bearing,
                crate::force::AirBearingModel::Reynolds { .. }
            )
        {
            return Err(self.no_bearing_for_structure());
        }
        if self.structure.is_rigid() {
            return Ok(());
        }
        let pad = [
            (
                "intermolecular.gap",
                self.intermolecular.as_ref().map(|t| t.gap),
            ),
            (
                "electrostatic.gap",
                self.electrostatic.as_ref().map(|t| t.gap),
            ),
            ("contact.gap", self.contact.as_ref().map(|t| t.gap)),
        ];
        for (field, gap) in pad {
            if gap == Some(crate::force::GapReference::Pad) {
                return Err(Error::invalid(
                    field,
                    format!(
                        "\"pad\" needs the rigid structure: with structure.preset = \"{}\" the \
                         interface forces act on the bulge only",
                        self.structure.preset()
                    ),
                ));
            }
        }
        Ok(())
    }
}
