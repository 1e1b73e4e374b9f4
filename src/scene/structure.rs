//! The `[structure]` section: how the slider deforms and moves, as lumped masses, springs and
//! dampers, and where the bulge sits on them.
//!
//! Degree of freedom 0 is always the heave of the slider body at the air bearing (`slider.mass_kg`
//! and the `[air_bearing]` law act there); the interface forces act on the bulge, whose
//! displacement towards and away from the disk is `bᵀq` with the influence vector `b`.

use serde::{Deserialize, Serialize};

use crate::error::{check_finite, check_non_negative, check_positive};
use crate::{Error, Result};

/// Largest number of mechanical degrees of freedom of a structure.
pub const MAX_DOF: usize = 3;

/// The slider's structure. `rigid` (the default) is one mass on the air bearing.
///
/// ```
/// use hdi_tribology::scene::{Scene, StructureSpec};
/// let text = Scene::paper().to_toml_string()? + r#"
/// [structure]
/// preset = "bulge"
/// mass_kg = 1e-13
/// stiffness_n_per_m = 4e5
/// damping_ratio = 0.05
/// "#;
/// let scene = Scene::from_toml_str(&text)?;
/// assert!(matches!(scene.structure, StructureSpec::Bulge { .. }));
/// assert_eq!(Scene::paper().structure, StructureSpec::Rigid);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(tag = "preset", rename_all = "snake_case", deny_unknown_fields)]
pub enum StructureSpec {
    /// One rigid mass `slider.mass_kg` on the air bearing; the bulge moves with it.
    #[default]
    Rigid,
    /// Body heave plus the heater-driven bulge as its own mass on a spring and damper to the
    /// body; the interface forces act on the bulge. Coordinates: body heave `y`, bulge `z`.
    Bulge {
        /// Effective mass of the bulge `m_b` (kg).
        mass_kg: f64,
        /// Stiffness `k_b` between bulge and body (N/m).
        stiffness_n_per_m: f64,
        /// Damping ratio `ζ_b = c_b / (2 √(k_b m_b))` of the bulge on a fixed body.
        damping_ratio: f64,
    },
    /// Body heave `y` plus pitch `θ` (positive lifts the trailing edge), with the air bearing's
    /// pitch stiffness and damping and their coupling to heave; the bulge sits rigidly at the
    /// trailing edge, `z = y + L θ`.
    ///
    /// The four matrix entries and `L` are given, or, with `from_bearing = true` and
    /// `air_bearing.model = "reynolds"`, taken from the bearing solved from the slider's
    /// geometry: its heave–pitch stiffness and damping at the equilibrium
    /// ([`ReynoldsBearing::heave_pitch`](crate::force::ReynoldsBearing::heave_pitch)) and `L`
    /// the distance from its pivot to its bulge along the slider. Then none of the five may be
    /// given: each has one source.
    ///
    /// ```
    /// use hdi_tribology::scene::StructureSpec;
    /// let s: StructureSpec = toml::from_str(
    ///     "preset = \"pitch\"\ninertia_kg_m2 = 1.4e-12\nfrom_bearing = true").unwrap();
    /// assert!(s.from_bearing() && s.pitch_values().is_none());
    /// assert!(s.validate().is_ok()); // the bearing is the scene's: `Scene::validate` asks for it
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    Pitch {
        /// Pitch inertia about the pivot `I` (kg m²).
        inertia_kg_m2: f64,
        /// Pitch stiffness `k_θθ` (N m/rad); required unless `from_bearing`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        stiffness_n_m_per_rad: Option<f64>,
        /// Heave–pitch coupling stiffness `k_yθ = k_θy` (N/rad); required unless `from_bearing`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        coupling_stiffness_n_per_rad: Option<f64>,
        /// Pitch damping `c_θθ` (N m s/rad); required unless `from_bearing`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        damping_n_m_s_per_rad: Option<f64>,
        /// Heave–pitch coupling damping `c_yθ = c_θy` (N s/rad); required unless `from_bearing`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        coupling_damping_n_s_per_rad: Option<f64>,
        /// Distance `L` from the pivot to the bulge at the trailing edge (m); required unless
        /// `from_bearing`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        trailing_edge_m: Option<f64>,
        /// Whether the matrices and `L` come from the `reynolds` air bearing (default false).
        #[serde(default, skip_serializing_if = "std::ops::Not::not")]
        from_bearing: bool,
    },
    /// Any linear structure of 1 to [`MAX_DOF`] degrees of freedom:
    /// `M q̈ + C q̇ + K q = e₀ F_ab + b F_if`. Degree of freedom 0 is the body heave, where the
    /// air-bearing law acts and `slider.mass_kg` is ignored (the mass matrix holds it). The
    /// matrices are symmetric, `M` positive definite, `C` and `K` symmetric; `K`
    /// holds the structure's own springs only (the air bearing's heave law is added on DOF 0).
    General {
        /// Mass matrix `M` (rows; kg, kg m, kg m² by coordinate).
        mass: Vec<Vec<f64>>,
        /// Damping matrix `C` (rows).
        damping: Vec<Vec<f64>>,
        /// Stiffness matrix `K` (rows).
        stiffness: Vec<Vec<f64>>,
        /// Bulge influence vector `b`: the bulge displacement is `bᵀq`.
        bulge_influence: Vec<f64>,
    },
}

impl StructureSpec {
    /// Whether this is the default rigid slider.
    pub fn is_rigid(&self) -> bool {
        *self == StructureSpec::Rigid
    }

    /// The preset's name as written in a scene file.
    pub fn preset(&self) -> &'static str {
        match self {
            StructureSpec::Rigid => "rigid",
            StructureSpec::Bulge { .. } => "bulge",
            StructureSpec::Pitch { .. } => "pitch",
            StructureSpec::General { .. } => "general",
        }
    }

    /// The pitch preset's values in the order [`Structure::pitch`](crate::model::Structure::pitch)
    /// takes them: `(I, [k_θθ, k_yθ], [c_θθ, c_yθ], L)`; `None` for the other presets, and for a
    /// pitch preset that takes them from the air bearing or lacks one of them.
    ///
    /// ```
    /// use hdi_tribology::scene::StructureSpec;
    /// assert_eq!(StructureSpec::Rigid.pitch_values(), None);
    /// ```
    pub fn pitch_values(&self) -> Option<(f64, [f64; 2], [f64; 2], f64)> {
        match *self {
            StructureSpec::Pitch {
                inertia_kg_m2,
                stiffness_n_m_per_rad: Some(k),
                coupling_stiffness_n_per_rad: Some(k_c),
                damping_n_m_s_per_rad: Some(c),
                coupling_damping_n_s_per_rad: Some(c_c),
                trailing_edge_m: Some(l),
                from_bearing: false,
            } => Some((inertia_kg_m2, [k, k_c], [c, c_c], l)),
            _ => None,
        }
    }

    /// Whether the structure takes its matrices from the scene's `reynolds` air bearing (the
    /// `pitch` preset with `from_bearing = true`).
    ///
    /// ```
    /// assert!(!hdi_tribology::scene::StructureSpec::Rigid.from_bearing());
    /// ```
    pub fn from_bearing(&self) -> bool {
        matches!(
            self,
            StructureSpec::Pitch {
                from_bearing: true,
                ..
            }
        )
    }

    /// Field-by-field checks; errors name `structure.<field>`. The matrix properties of the
    /// general form (symmetry, definiteness) are checked when the model is built.
    pub fn validate(&self) -> Result<()> {
        match self {
            StructureSpec::Rigid => {}
            StructureSpec::Bulge {
                mass_kg,
                stiffness_n_per_m,
                damping_ratio,
            } => {
                check_positive("structure.mass_kg", *mass_kg)?;
                check_positive("structure.stiffness_n_per_m", *stiffness_n_per_m)?;
                check_non_negative("structure.damping_ratio", *damping_ratio)?;
            }
            &StructureSpec::Pitch {
                inertia_kg_m2,
                stiffness_n_m_per_rad,
                coupling_stiffness_n_per_rad,
                damping_n_m_s_per_rad,
                coupling_damping_n_s_per_rad,
                trailing_edge_m,
                from_bearing,
            } => {
                check_positive("structure.inertia_kg_m2", inertia_kg_m2)?;
                let given = [
                    ("stiffness_n_m_per_rad", stiffness_n_m_per_rad),
                    ("coupling_stiffness_n_per_rad", coupling_stiffness_n_per_rad),
                    ("damping_n_m_s_per_rad", damping_n_m_s_per_rad),
                    ("coupling_damping_n_s_per_rad", coupling_damping_n_s_per_rad),
                    ("trailing_edge_m", trailing_edge_m),
                ];
                for (name, value) in given {
                    let field = format!("structure.{name}");
                    match (value, from_bearing) {
                        (Some(_), true) => {
                            let what = if name == "trailing_edge_m" {
                                "the distance from the pivot to the bulge from the bearing's \
                                 geometry (its operating.pivot_um and bulge_um)"
                            } else {
                                "the air bearing's heave-pitch stiffness and damping"
                            };
                            return Err(Error::invalid(
                                field,
                                format!(
                                    "given together with structure.from_bearing = true, which \
                                     takes {what}: give the one or the other"
                                ),
                            ));
                        }
                        (None, false) => {
                            return Err(Error::invalid(
                                field,
                                "required by the pitch preset, unless structure.from_bearing = \
                                 true takes the matrices from a reynolds air bearing",
                            ));
                        }
                        _ => {}
                    }
                }
                if let Some((_, [k, k_c], [c, c_c], l)) = self.pitch_values() {
                    check_positive("structure.stiffness_n_m_per_rad", k)?;
                    check_finite("structure.coupling_stiffness_n_per_rad", k_c)?;
                    check_non_negative("structure.damping_n_m_s_per_rad", c)?;
                    check_finite("structure.coupling_damping_n_s_per_rad", c_c)?;
                    check_finite("structure.trailing_edge_m", l)?;
                }
            }
            StructureSpec::General {
                mass,
                damping,
                stiffness,
                bulge_influence,
            } => {
                let n = bulge_influence.len();
                if n == 0 || n > MAX_DOF {
                    return Err(Error::invalid(
                        "structure.bulge_influence",
                        format!("needs 1 to {MAX_DOF} entries, got {n}"),
                    ));
                }
                for (i, &b) in bulge_influence.iter().enumerate() {
                    check_finite(&format!("structure.bulge_influence[{i}]"), b)?;
                }
                if bulge_influence.iter().all(|&b| b == 0.0) {
                    return Err(Error::invalid(
                        "structure.bulge_influence",
                        "must not be all zero: the interface forces would act on nothing",
                    ));
                }
                for (name, m) in [
                    ("mass", mass),
                    ("damping", damping),
                    ("stiffness", stiffness),
                ] {
                    if m.len() != n || m.iter().any(|row| row.len() != n) {
                        return Err(Error::invalid(
                            format!("structure.{name}"),
                            format!("must be {n} × {n} (the length of structure.bulge_influence)"),
                        ));
                    }
                    for (i, row) in m.iter().enumerate() {
                        for (j, &x) in row.iter().enumerate() {
                            check_finite(&format!("structure.{name}[{i}][{j}]"), x)?;
                        }
                    }
                }
            }
        }
        Ok(())
    }
}
