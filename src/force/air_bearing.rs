//! Air-bearing models behind the [`AirBearing`] trait, and their serde description.

use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::fmt::Debug;
use std::sync::{Mutex, OnceLock};

use crate::bearing::geometry::{MAX_CELLS, MIN_CELLS};
use crate::bearing::{solve_attitude, AttitudeOptions, BearingSpec, Equilibrium};
use crate::error::{check_finite, check_non_negative, check_positive};
use crate::numerics::cubic_hermite;
use crate::{Error, Result};

/// Air bearing: force (N, positive = away from the disk) at displacement `y` (m, positive = away
/// from the disk) and velocity `v` (m/s).
///
/// ```
/// use hdi_tribology::force::{AirBearing, LinearBearing};
/// let ab = LinearBearing::new(3e5, 0.05).unwrap();
/// assert!((ab.force(1e-9, 0.0) + 3e-4).abs() < 1e-18);
/// assert_eq!(ab.stiffness(0.0), 3e5);
/// ```
pub trait AirBearing: Debug + Send + Sync {
    /// Force, N.
    fn force(&self, y: f64, v: f64) -> f64;
    /// Stiffness `−∂F/∂y`, N/m.
    fn stiffness(&self, y: f64) -> f64;
    /// Damping `−∂F/∂v`, N s/m.
    fn damping(&self, y: f64) -> f64;
}

/// Linear spring–damper: `F = −k y − c v`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearBearing {
    k: f64,
    c: f64,
}

impl LinearBearing {
    /// Stiffness `k > 0` (N/m) and damping `c ≥ 0` (N s/m).
    pub fn new(k: f64, c: f64) -> Result<Self> {
        check_positive("air_bearing.stiffness_n_per_m", k)?;
        check_non_negative("air_bearing.damping_n_s_per_m", c)?;
        Ok(LinearBearing { k, c })
    }
}

impl AirBearing for LinearBearing {
    fn force(&self, y: f64, v: f64) -> f64 {
        -self.k * y - self.c * v
    }
    fn stiffness(&self, _y: f64) -> f64 {
        self.k
    }
    fn damping(&self, _y: f64) -> f64 {
        self.c
    }
}

/// Cubic spring with damper: `F = −k y − k₃ y³ − c v` (k₃ < 0 softens).
///
/// ```
/// use hdi_tribology::force::{AirBearing, CubicBearing};
/// let ab = CubicBearing::new(3e5, 1e20, 0.05).unwrap();
/// assert!((ab.stiffness(1e-8) - (3e5 + 3.0 * 1e20 * 1e-16)).abs() < 1e-6);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CubicBearing {
    k: f64,
    k3: f64,
    c: f64,
}

impl CubicBearing {
    /// Linear stiffness `k > 0` (N/m), cubic stiffness `k₃` (N/m³), damping `c ≥ 0` (N s/m).
    pub fn new(k: f64, k3: f64, c: f64) -> Result<Self> {
        check_positive("air_bearing.stiffness_n_per_m", k)?;
        check_finite("air_bearing.cubic_stiffness_n_per_m3", k3)?;
        check_non_negative("air_bearing.damping_n_s_per_m", c)?;
        Ok(CubicBearing { k, k3, c })
    }
}

impl AirBearing for CubicBearing {
    fn force(&self, y: f64, v: f64) -> f64 {
        -self.k * y - self.k3 * y * y * y - self.c * v
    }
    fn stiffness(&self, y: f64) -> f64 {
        self.k + 3.0 * self.k3 * y * y
    }
    fn damping(&self, _y: f64) -> f64 {
        self.c
    }
}

/// Power law on the pad gap `g = h0 + y`: `F = F0 [(h0/g)^n − 1] − c v`; stiffness `n F0/h0` at
/// `y = 0`. For `g ≤ 0` (the pad through the disk) the law has no meaning and force and stiffness
/// are NaN.
///
/// ```
/// use hdi_tribology::force::{AirBearing, PowerLawBearing};
/// let ab = PowerLawBearing::new(1e-2, 3.0, 1e-8, 0.05).unwrap();
/// assert_eq!(ab.force(0.0, 0.0), 0.0);
/// assert!((ab.stiffness(0.0) - 3.0 * 1e-2 / 1e-8).abs() < 1e-6);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PowerLawBearing {
    f0: f64,
    n: f64,
    h0: f64,
    c: f64,
}

impl PowerLawBearing {
    /// Preload `F0 > 0` (N), exponent `n > 0`, reference gap `h0 > 0` (m), damping `c ≥ 0`.
    pub fn new(f0: f64, n: f64, h0: f64, c: f64) -> Result<Self> {
        check_positive("air_bearing.preload_n", f0)?;
        check_positive("air_bearing.exponent", n)?;
        check_positive("air_bearing.reference_gap_m", h0)?;
        check_non_negative("air_bearing.damping_n_s_per_m", c)?;
        Ok(PowerLawBearing { f0, n, h0, c })
    }
}

impl AirBearing for PowerLawBearing {
    fn force(&self, y: f64, v: f64) -> f64 {
        let g = self.h0 + y;
        if g <= 0.0 {
            return f64::NAN;
        }
        self.f0 * ((self.h0 / g).powf(self.n) - 1.0) - self.c * v
    }
    fn stiffness(&self, y: f64) -> f64 {
        let g = self.h0 + y;
        if g <= 0.0 {
            return f64::NAN;
        }
        self.n * self.f0 / g * (self.h0 / g).powf(self.n)
    }
    fn damping(&self, _y: f64) -> f64 {
        self.c
    }
}

/// Serde description of an air bearing, tagged by `model`.
///
/// ```
/// use hdi_tribology::force::AirBearingModel;
/// let m: AirBearingModel = toml::from_str(
///     "model = \"linear\"\nstiffness_n_per_m = 3e5\ndamping_n_s_per_m = 0.05").unwrap();
/// assert_eq!(m.build().unwrap().stiffness(0.0), 3e5);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum AirBearingModel {
    /// [`LinearBearing`].
    Linear {
        /// k, N/m.
        stiffness_n_per_m: f64,
        /// c, N s/m.
        damping_n_s_per_m: f64,
    },
    /// [`CubicBearing`].
    Cubic {
        /// k, N/m.
        stiffness_n_per_m: f64,
        /// k₃, N/m³.
        cubic_stiffness_n_per_m3: f64,
        /// c, N s/m.
        damping_n_s_per_m: f64,
    },
    /// [`ReynoldsBearing`]: the bearing solved from the slider's geometry.
    Reynolds {
        /// The bearing file (TOML, JSON or the text format of
        /// [`BearingSpec`]); a relative path is relative to the scene file.
        geometry: String,
        /// Control volumes a side of the bearing's grid (default 129).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        cells: Option<usize>,
        /// Disk radius, mm, in place of the file's.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        radius_mm: Option<f64>,
        /// Disk speed, 1/min, in place of the file's.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        rpm: Option<f64>,
        /// Skew angle, °, in place of the file's.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        skew_deg: Option<f64>,
        /// Suspension preload, mN, in place of the file's.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        preload_mn: Option<f64>,
    },
    /// [`PowerLawBearing`].
    PowerLaw {
        /// F0, N.
        preload_n: f64,
        /// n.
        exponent: f64,
        /// h0, m (normally the nominal clearance).
        reference_gap_m: f64,
        /// c, N s/m.
        damping_n_s_per_m: f64,
    },
}

impl AirBearingModel {
    /// The model's name as a scene file writes it (`model = "…"`).
    ///
    /// ```
    /// use hdi_tribology::scene::Scene;
    /// assert_eq!(Scene::paper().air_bearing.name(), "linear");
    /// ```
    pub fn name(&self) -> &'static str {
        match self {
            AirBearingModel::Linear { .. } => "linear",
            AirBearingModel::Cubic { .. } => "cubic",
            AirBearingModel::Reynolds { .. } => "reynolds",
            AirBearingModel::PowerLaw { .. } => "power_law",
        }
    }

    /// Validates and builds the model.
    pub fn build(&self) -> Result<Box<dyn AirBearing>> {
        Ok(match *self {
            AirBearingModel::Linear {
                stiffness_n_per_m,
                damping_n_s_per_m,
            } => Box::new(LinearBearing::new(stiffness_n_per_m, damping_n_s_per_m)?),
            AirBearingModel::Cubic {
                stiffness_n_per_m,
                cubic_stiffness_n_per_m3,
                damping_n_s_per_m,
            } => Box::new(CubicBearing::new(
                stiffness_n_per_m,
                cubic_stiffness_n_per_m3,
                damping_n_s_per_m,
            )?),
            AirBearingModel::PowerLaw {
                preload_n,
                exponent,
                reference_gap_m,
                damping_n_s_per_m,
            } => Box::new(PowerLawBearing::new(
                preload_n,
                exponent,
                reference_gap_m,
                damping_n_s_per_m,
            )?),
            AirBearingModel::Reynolds { .. } => Box::new(ReynoldsBearing::of_spec(
                &self
                    .bearing_spec()?
                    .expect("a reynolds bearing has a geometry"),
            )?),
        })
    }

    /// The bearing of a `reynolds` model: its geometry file read, the scene's operating
    /// conditions and grid in place of the file's; `None` for the lumped models. Errors name
    /// `air_bearing.<field>`, and for a bad geometry the file and the region.
    pub fn bearing_spec(&self) -> Result<Option<BearingSpec>> {
        let AirBearingModel::Reynolds {
            geometry,
            cells,
            radius_mm,
            rpm,
            skew_deg,
            preload_mn,
        } = self
        else {
            return Ok(None);
        };
        let field = "air_bearing.geometry";
        let mut spec = BearingSpec::from_path(geometry).map_err(|e| match e {
            Error::Io { source, .. } => {
                Error::invalid(field, format!("cannot read \"{geometry}\": {source}"))
            }
            other => Error::invalid(field, format!("\"{geometry}\": {other}")),
        })?;
        let n = cells.unwrap_or(DEFAULT_REYNOLDS_CELLS);
        if !(MIN_CELLS..=MAX_CELLS).contains(&n) {
            return Err(Error::invalid(
                "air_bearing.cells",
                format!("{n} control volumes a side, outside {MIN_CELLS}..={MAX_CELLS}"),
            ));
        }
        spec.grid.nx = n;
        spec.grid.ny = n;
        let op = &mut spec.operating;
        for (name, value, slot) in [
            ("radius_mm", radius_mm, &mut op.radius_mm),
            ("rpm", rpm, &mut op.rpm),
            ("skew_deg", skew_deg, &mut op.skew_deg),
            ("preload_mn", preload_mn, &mut op.preload_mn),
        ] {
            if let Some(v) = *value {
                *slot = check_finite(&format!("air_bearing.{name}"), v)?;
            }
        }
        // Check now, naming the scene's fields: the operating conditions the scene gave.
        spec.build().map_err(|e| match e {
            Error::InvalidInput { field: f, reason } if f.starts_with("operating.") => {
                Error::invalid(f.replacen("operating.", "air_bearing.", 1), reason)
            }
            other => Error::invalid(field, format!("\"{geometry}\": {other}")),
        })?;
        Ok(Some(spec))
    }
}

/// Control volumes a side of a `reynolds` air bearing's grid unless the scene says otherwise:
/// the bulge's spacing within 0.15 % of its grid limit on the example slider.
pub const DEFAULT_REYNOLDS_CELLS: usize = 129;

/// Heave offsets of the force table of a [`ReynoldsBearing`], as fractions of the smallest
/// spacing at the equilibrium.
const HEAVE_NODES: [f64; 12] = [
    -0.7, -0.5, -0.35, -0.22, -0.12, -0.05, 0.0, 0.05, 0.12, 0.25, 0.5, 1.0,
];

/// The air bearing solved from the slider's geometry (`crate::bearing`), as the slider model's
/// heave law: the force about the equilibrium attitude along a heave (pitch and roll held),
/// `F(y) = F_ab(h_eq + y) − preload`, a cubic Hermite interpolant of the force and its slope
/// (from the pressure's sensitivity, not differences) at heave offsets from −70 % to +100 % of
/// the smallest spacing, continued linearly beyond them; its stiffness at `y = 0` is the
/// bearing's own `K[0][0]`, and its damping the bearing's low-frequency heave damping
/// `C[0][0]`. The 3 × 3 stiffness and damping about the equilibrium are kept for a structure
/// that pitches.
///
/// ```
/// use hdi_tribology::bearing::BearingSpec;
/// use hdi_tribology::force::{AirBearing, ReynoldsBearing};
/// let mut spec = BearingSpec::from_path(concat!(
///     env!("CARGO_MANIFEST_DIR"), "/scenes/bearing/two_rail_taper_flat.toml"))?;
/// spec.grid.nx = 33;
/// spec.grid.ny = 33;
/// let ab = ReynoldsBearing::of_spec(&spec)?;
/// assert_eq!(ab.force(0.0, 0.0), 0.0);
/// assert_eq!(ab.stiffness(0.0), ab.stiffness_matrix()[0][0]);
/// assert!(ab.force(-10e-9, 0.0) > 0.0 && ab.force(10e-9, 0.0) < 0.0);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct ReynoldsBearing {
    /// Heave offsets, m, ascending.
    y: Vec<f64>,
    /// Force relative to the preload, N.
    f: Vec<f64>,
    /// `dF/dy`, N/m.
    df: Vec<f64>,
    stiffness: [[f64; 3]; 3],
    damping: [[f64; 3]; 3],
    pivot_to_trailing_edge: f64,
    pivot_to_bulge: f64,
}

/// Bearings already solved in this process, by their description.
fn solved() -> &'static Mutex<HashMap<String, ReynoldsBearing>> {
    static SOLVED: OnceLock<Mutex<HashMap<String, ReynoldsBearing>>> = OnceLock::new();
    SOLVED.get_or_init(|| Mutex::new(HashMap::new()))
}

impl ReynoldsBearing {
    /// Solves the bearing of `spec` (or takes it from those already solved in this process:
    /// the scene's validation and the model's assembly build it twice).
    pub fn of_spec(spec: &BearingSpec) -> Result<Self> {
        let key = serde_json::to_string(spec)
            .map_err(|e| Error::invalid("air_bearing", e.to_string()))?;
        if let Some(b) = solved().lock().ok().and_then(|m| m.get(&key).cloned()) {
            return Ok(b);
        }
        let eq = solve_attitude(&spec.build()?, &AttitudeOptions::default())?;
        let b = Self::from_equilibrium(&eq)?;
        if let Ok(mut m) = solved().lock() {
            m.insert(key, b.clone());
        }
        Ok(b)
    }

    /// The heave law about a solved equilibrium.
    pub fn from_equilibrium(eq: &Equilibrium) -> Result<Self> {
        let hmin = eq.min_spacing();
        let offsets: Vec<f64> = HEAVE_NODES.iter().map(|t| t * hmin).collect();
        let curve = eq.heave_curve(&offsets)?;
        let f0 = curve
            .iter()
            .find(|c| c.0 == 0.0)
            .map_or(eq.loads[0], |c| c.1);
        let b = eq.reynolds.bearing.clone();
        Ok(ReynoldsBearing {
            y: curve.iter().map(|c| c.0).collect(),
            f: curve.iter().map(|c| c.1 - f0).collect(),
            df: curve.iter().map(|c| c.2).collect(),
            stiffness: eq.stiffness(),
            damping: eq.damping()?,
            pivot_to_trailing_edge: b.length - b.pivot[0],
            pivot_to_bulge: b.bulge[0] - b.pivot[0],
        })
    }

    /// The bearing's stiffness about the equilibrium, `−∂(force, pitch moment, roll moment) /
    /// ∂(fly height, pitch, roll)` ([`Equilibrium::stiffness`]).
    pub fn stiffness_matrix(&self) -> [[f64; 3]; 3] {
        self.stiffness
    }

    /// The bearing's low-frequency damping about the equilibrium ([`Equilibrium::damping`]).
    pub fn damping_matrix(&self) -> [[f64; 3]; 3] {
        self.damping
    }

    /// The heave–pitch stiffness and damping in the coordinates of a pitching slider (heave
    /// `y` of the pivot, pitch `θ` about the pivot, positive lifting the trailing edge), and the
    /// pivot's distance to the trailing edge (m). The bearing's pitch `α` turns about the
    /// trailing edge and raises the leading edge: `h_TE = y + (L − x_p) θ`, `α = −θ`, and the
    /// moment about the pivot that lifts the trailing edge is minus the bearing's pitch
    /// moment, so `K' = S K T` with `T = [[1, L − x_p], [0, −1]]`, `S = diag(1, −1)` (and the
    /// same for the damping). Neither is symmetric in general.
    pub fn heave_pitch(&self) -> ([[f64; 2]; 2], [[f64; 2]; 2], f64) {
        let a = self.pivot_to_trailing_edge;
        let map = |m: [[f64; 3]; 3]| {
            [
                [m[0][0], a * m[0][0] - m[0][1]],
                [-m[1][0], -a * m[1][0] + m[1][1]],
            ]
        };
        (map(self.stiffness), map(self.damping), a)
    }

    /// The distance along the slider from the pivot to the bulge (m, positive towards the
    /// trailing edge): the lever `L` of the bulge in the coordinates of
    /// [`ReynoldsBearing::heave_pitch`], whose displacement is `y + L θ`. The geometry's
    /// `bulge_um` and `operating.pivot_um` give it; with the defaults (the bulge at the trailing
    /// edge) it is the pivot's distance to the trailing edge.
    ///
    /// ```
    /// use hdi_tribology::bearing::BearingSpec;
    /// use hdi_tribology::force::ReynoldsBearing;
    /// let mut spec = BearingSpec::from_path(concat!(
    ///     env!("CARGO_MANIFEST_DIR"), "/scenes/bearing/two_rail_taper_flat.toml"))?;
    /// spec.grid.nx = 33;
    /// spec.grid.ny = 33;
    /// let ab = ReynoldsBearing::of_spec(&spec)?;
    /// // The example's bulge sits on the trailing edge, its pivot at the centre.
    /// assert_eq!(ab.bulge_lever(), ab.heave_pitch().2);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn bulge_lever(&self) -> f64 {
        self.pivot_to_bulge
    }

    /// `F(y)` and `dF/dy`.
    fn eval(&self, y: f64) -> (f64, f64) {
        let n = self.y.len();
        if y <= self.y[0] {
            return (self.f[0] + self.df[0] * (y - self.y[0]), self.df[0]);
        }
        if y >= self.y[n - 1] {
            return (
                self.f[n - 1] + self.df[n - 1] * (y - self.y[n - 1]),
                self.df[n - 1],
            );
        }
        let k = self.y.partition_point(|&v| v <= y) - 1;
        let (y0, y1) = (self.y[k], self.y[k + 1]);
        let h = y1 - y0;
        let t = (y - y0) / h;
        if t == 0.0 {
            return (self.f[k], self.df[k]);
        }
        let (f0, f1, d0, d1) = (self.f[k], self.f[k + 1], self.df[k] * h, self.df[k + 1] * h);
        let (f, df_dt) = cubic_hermite(t, f0, d0, f1, d1);
        (f, df_dt / h)
    }
}

impl AirBearing for ReynoldsBearing {
    fn force(&self, y: f64, v: f64) -> f64 {
        self.eval(y).0 - self.damping[0][0] * v
    }
    fn stiffness(&self, y: f64) -> f64 {
        -self.eval(y).1
    }
    fn damping(&self, _y: f64) -> f64 {
        self.damping[0][0]
    }
}
