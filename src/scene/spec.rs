//! The serde structures of a scene file.

use serde::{Deserialize, Serialize};

use crate::force::{AirBearingModel, Footprint, GapReference};
use crate::surface::PeakModel;

/// A whole scene. See the module documentation and `scenes/paper.toml`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// A label for outputs.
    pub name: String,
    /// Nominal clearance `h0` (m): protrusion tip to disk mean plane, heater off, no interface force.
    pub nominal_clearance_m: f64,
    /// Surface-height and asperity-peak statistics.
    pub surface: SurfaceSpec,
    /// Lennard-Jones 3–9 term; absent = off.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub intermolecular: Option<IntermolecularSpec>,
    /// Electrostatic term; absent = off.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub electrostatic: Option<ElectrostaticSpec>,
    /// Greenwood–Williamson contact; absent = off.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact: Option<ContactSpec>,
    /// Air-bearing model.
    pub air_bearing: AirBearingModel,
    /// Slider (lumped mass).
    pub slider: SliderSpec,
    /// Heater and its programmes.
    pub heater: HeaterSpec,
    /// Applied voltage.
    pub voltage: VoltageSpec,
    /// Contact detector.
    pub detector: DetectorSpec,
    /// Friction and flash temperature.
    pub friction: FrictionSpec,
    /// ODE solver settings (all defaulted).
    #[serde(default)]
    pub solver: SolverSpec,
    /// Force-table settings (all defaulted).
    #[serde(default)]
    pub table: TableSpec,
    /// Parameter sweep (empty by default).
    #[serde(default)]
    pub sweep: SweepSpec,
}

/// Roughness statistics.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceSpec {
    /// Standard deviation of the (combined) surface heights σ (m), ≥ 0; 0 = smooth. The one σ
    /// of the surface: with `rice_maxima` peaks, `peaks.sigma_m` must equal it.
    pub height_sigma_m: f64,
    /// Asperity peak-height distribution (used by the contact term).
    pub peaks: PeakModel,
    /// Set when `peaks.sigma_m` of `rice_maxima` peaks differs from `height_sigma_m` on purpose
    /// (default false: a difference is refused as a slip).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub independent_peak_sigma: bool,
}

/// Lennard-Jones 3–9 term.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntermolecularSpec {
    /// Attractive Hamaker constant `A`, J.
    pub hamaker_attractive_j: f64,
    /// Repulsive constant `B`, J m⁶.
    pub hamaker_repulsive_j_m6: f64,
    /// Non-contact cutoff `h_c` (m); default the zero of the law `h_e`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cutoff_m: Option<f64>,
    /// Footprint.
    pub footprint: Footprint,
    /// Gap reference (default bulge).
    #[serde(default)]
    pub gap: GapReference,
}

/// Electrostatic term.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ElectrostaticSpec {
    /// Contact potential φ, V (subtracted from the applied voltage).
    pub contact_potential_v: f64,
    /// Dielectric-equivalent thickness `t_d` (m), default 0.
    #[serde(default)]
    pub dielectric_thickness_m: f64,
    /// Non-contact cutoff `h_c` (m); default that of the intermolecular term, required when that
    /// term is off.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cutoff_m: Option<f64>,
    /// Footprint.
    pub footprint: Footprint,
    /// Gap reference (default bulge).
    #[serde(default)]
    pub gap: GapReference,
}

/// Greenwood–Williamson contact.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Composite modulus `E*`, Pa.
    pub composite_modulus_pa: f64,
    /// Asperity radius `R`, m.
    pub asperity_radius_m: f64,
    /// Asperity areal density `η_s`, m⁻².
    pub asperity_density_per_m2: f64,
    /// Footprint.
    pub footprint: Footprint,
    /// Gap reference (default bulge).
    #[serde(default)]
    pub gap: GapReference,
}

/// Slider.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SliderSpec {
    /// Lumped mass, kg.
    pub mass_kg: f64,
    /// Interface lag `τ_lag` (s), default 0 (no state).
    #[serde(default)]
    pub interface_lag_s: f64,
}

/// Heater.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeaterSpec {
    /// Protrusion per power `η`, m/W.
    pub efficiency_m_per_w: f64,
    /// Thermal lag `τ_th` (s), default 0 (no state).
    #[serde(default)]
    pub thermal_lag_s: f64,
    /// Fixed programme: knots `[t_s, power_w]`, piecewise linear; ≥ 2 knots, strictly increasing t.
    pub programme: Vec<[f64; 2]>,
    /// Touchdown-triggered programme.
    pub triggered: TriggeredSpec,
}

/// Touchdown-triggered heater programme.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TriggeredSpec {
    /// Starting (and final) power, W.
    pub start_power_w: f64,
    /// Ramp rate both ways, W/s.
    pub ramp_rate_w_per_s: f64,
    /// Power added after touchdown before ramping down, W.
    pub overshoot_w: f64,
}

/// Applied voltage `V(t) = V_dc + V_ac sin(2π f t)` (the contact potential is subtracted).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VoltageSpec {
    /// DC voltage, V.
    pub dc_v: f64,
    /// AC amplitude, V.
    pub ac_amplitude_v: f64,
    /// AC frequency, Hz.
    pub ac_frequency_hz: f64,
}

/// Contact detector (running mean of the contact force).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DetectorSpec {
    /// Threshold on the running mean of the contact force, N.
    pub contact_threshold_n: f64,
    /// Running-mean window, s.
    pub window_s: f64,
}

/// Friction and flash temperature.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrictionSpec {
    /// Friction coefficient μ.
    pub coefficient: f64,
    /// Disk speed, m/s.
    pub disk_speed_m_per_s: f64,
    /// Thermal conductivity of the head, W/(m K).
    pub head_conductivity_w_per_m_k: f64,
}

/// ODE solver settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SolverSpec {
    /// Method name (default "auto").
    pub method: String,
    /// Relative tolerance, in (0, 1).
    pub rtol: f64,
    /// Absolute tolerance for the displacement, m.
    pub atol_m: f64,
    /// Largest step, s (none by default).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_step_s: Option<f64>,
    /// Step limit.
    pub max_steps: usize,
}

impl Default for SolverSpec {
    fn default() -> Self {
        SolverSpec {
            method: "auto".into(),
            rtol: 1e-6,
            atol_m: 1e-14,
            max_step_s: None,
            max_steps: 10_000_000,
        }
    }
}

/// Force-table settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TableSpec {
    /// Lower end of the tabulated separations (m); default see [`Scene::table_range`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub d_min_m: Option<f64>,
    /// Upper end (m); default 3 h0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub d_max_m: Option<f64>,
    /// Relative accuracy of the tables against direct quadrature.
    pub rel_tol: f64,
}

impl Default for TableSpec {
    fn default() -> Self {
        TableSpec {
            d_min_m: None,
            d_max_m: None,
            rel_tol: 1e-9,
        }
    }
}

/// Parameter sweep.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SweepSpec {
    /// AC amplitudes to sweep, V.
    pub ac_amplitudes_v: Vec<f64>,
}
