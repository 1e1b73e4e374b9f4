//! The serde structures of a scene file.

use serde::{Deserialize, Serialize};

use super::structure::StructureSpec;
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
    /// Lubricant menisci on the contact term's asperities; absent (or no mobile lubricant) = off.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lubricant: Option<LubricantSpec>,
    /// Air-bearing model.
    pub air_bearing: AirBearingModel,
    /// Slider (lumped mass).
    pub slider: SliderSpec,
    /// Structure: rigid (default), bulge, pitch or general (see [`StructureSpec`]).
    #[serde(default, skip_serializing_if = "StructureSpec::is_rigid")]
    pub structure: StructureSpec,
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
    /// The simulated drive (`hdi drive`, `drive::Plant::from_scene`); absent: the library's
    /// default drive.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drive: Option<super::DriveSpec>,
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

/// Lubricant menisci (a term with memory, see `docs/analyses.md`): bridges form on the asperity
/// peaks of the `[contact]` section where the local gap falls below the mobile thickness
/// `total − bonded`, and break past the rupture distance.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LubricantSpec {
    /// Total lubricant thickness on the disk, m (≥ 0).
    pub total_thickness_m: f64,
    /// Bonded part of it, m (0 ≤ bonded ≤ total); the rest is mobile.
    pub bonded_thickness_m: f64,
    /// Surface tension γ, N/m (> 0; PFPE lubricants: about 0.02–0.025).
    pub surface_tension_n_per_m: f64,
    /// Contact angle θ of the lubricant on the head, degrees, in [0, 90].
    pub contact_angle_deg: f64,
    /// Whether the lubricant wets the disk only (`"disk"`, default) or both surfaces (`"both"`).
    #[serde(default)]
    pub wetting: WettingSpec,
    /// Healing time τ_h (s, > 0): how fast the bridges formed at the closest approach drain.
    pub healing_time_s: f64,
    /// Formation time τ_f (s, ≥ 0), default 1e-7 s: how fast bridges form as the gap closes;
    /// 0 for bridges that form at once (the limit τ_f → 0, without its stiff branch).
    #[serde(default = "default_formation_time")]
    pub formation_time_s: f64,
    /// Rupture distance `s_r` (m, ≥ 0); default the Lian law `(1 + θ/2) V^{1/3}` with the bridge
    /// volume `V = π R t_m²`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rupture_distance_m: Option<f64>,
    /// The head's pick-up: gain rate `r_p` with every peak wetting the head (m/s, > 0); with
    /// `pickup_loss_time_s`, a second state `t_h` (none by default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pickup_rate_m_per_s: Option<f64>,
    /// The head's pick-up: loss time `τ_p` (s, > 0); given together with `pickup_rate_m_per_s`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pickup_loss_time_s: Option<f64>,
}

fn default_formation_time() -> f64 {
    1e-7
}

/// Which surfaces the lubricant wets.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WettingSpec {
    /// The disk only: `2πRγ(1 + cos θ)` per bridge.
    #[default]
    Disk,
    /// Both surfaces: `4πRγ cos θ` per bridge.
    Both,
}

impl LubricantSpec {
    /// The mobile thickness `total − bonded` (m).
    pub fn mobile_thickness_m(&self) -> f64 {
        self.total_thickness_m - self.bonded_thickness_m
    }
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
