//! The slider's air-bearing surface and its operating conditions as data.
//!
//! A [`BearingSpec`] is what a user writes (TOML, JSON or the text format of
//! [`BearingSpec::from_text`]), in engineering units with the unit in each field's name. It is
//! validated into a [`Bearing`] (SI inside) by [`BearingSpec::build`]; every error names the field
//! as written, and a polygon by its name (or its index in `regions` when it has none).
//!
//! ## The surface
//!
//! Coordinates: `x` along the slider's length from the leading edge (`x = 0`) to the trailing edge
//! (`x = L`), `y` across its width from `0` to `W`. The recess depth below the air-bearing surface
//! at a point is the depth of the **last** region (in the order written) whose polygon contains
//! the point, or `base_depth_nm` where none does: regions are painted in order. To it are added
//! the leading-edge taper (a bevel of height `t` falling linearly to zero at the taper length),
//! the crown and the camber (parabolic, zero at the edges, lowering the centre towards the disk
//! by `crown_nm` along `x` and `camber_nm` along `y`).

use std::fmt;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::flow_factor::FlowModel;

/// Default ratio of the coarsest to the finest cell of the grid.
pub const DEFAULT_REFINEMENT: f64 = 4.0;
/// Fewest control volumes along a side.
pub const MIN_CELLS: usize = 8;
/// Most control volumes along a side.
pub const MAX_CELLS: usize = 4097;
use crate::error::{check_finite, check_non_negative, check_positive};
use crate::{Error, Result};

/// The largest skew angle accepted, degrees.
pub const MAX_SKEW_DEG: f64 = 30.0;
/// Ambient pressure of the standard atmosphere, kPa.
pub const STANDARD_PRESSURE_KPA: f64 = 101.325;
/// Viscosity of air at 20 °C, µPa s.
pub const AIR_VISCOSITY_UPA_S: f64 = 18.06;
/// Mean free path of air at the standard atmosphere and 20 °C, nm.
pub const AIR_MEAN_FREE_PATH_NM: f64 = 63.5;
/// Relative tolerance of the coordinate checks (vertices on the slider's outline, closure).
const COORD_TOL: f64 = 1e-9;

/// A leading-edge taper: its length along `x`, and either its angle or its height at the
/// leading edge.
///
/// ```
/// use hdi_tribology::bearing::Taper;
/// let t = Taper { length_um: 200.0, angle_mrad: Some(10.0), height_um: None };
/// assert!((t.height_m("slider.taper").unwrap() - 200e-6 * 0.01f64.tan()).abs() < 1e-18);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Taper {
    /// Length of the taper along the slider, µm.
    pub length_um: f64,
    /// Taper angle, mrad (give this or `height_um`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle_mrad: Option<f64>,
    /// Height of the taper at the leading edge, µm (give this or `angle_mrad`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height_um: Option<f64>,
}

impl Taper {
    /// The taper's height at the leading edge, m; `field` prefixes the field names of errors.
    pub fn height_m(&self, field: &str) -> Result<f64> {
        let len = check_positive(&format!("{field}.length_um"), self.length_um)? * 1e-6;
        match (self.angle_mrad, self.height_um) {
            (Some(a), None) => {
                check_positive(&format!("{field}.angle_mrad"), a)?;
                Ok(len * (a * 1e-3).tan())
            }
            (None, Some(h)) => Ok(check_positive(&format!("{field}.height_um"), h)? * 1e-6),
            _ => Err(Error::invalid(
                field,
                "give exactly one of angle_mrad and height_um",
            )),
        }
    }
}

/// A rail or a recess: a closed polygon (the last vertex repeats the first) with its depth below
/// the air-bearing surface.
///
/// ```
/// use hdi_tribology::bearing::Region;
/// let r = Region {
///     name: Some("centre pad".into()),
///     depth_nm: 0.0,
///     polygon_um: vec![[0.0, 0.0], [10.0, 0.0], [10.0, 5.0], [0.0, 0.0]],
/// };
/// assert_eq!(r.label(3), "\"centre pad\"");
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Region {
    /// The region's name, used in messages.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Depth below the air-bearing surface, nm (0 for a rail at the surface).
    pub depth_nm: f64,
    /// Vertices `[x, y]`, µm, closed: the last repeats the first.
    pub polygon_um: Vec<[f64; 2]>,
}

impl Region {
    /// How messages name the region: its name in quotes, or its index in `regions`.
    pub fn label(&self, index: usize) -> String {
        match &self.name {
            Some(n) => format!("\"{n}\""),
            None => format!("#{index}"),
        }
    }
}

/// The slider's air-bearing surface.
///
/// ```
/// use hdi_tribology::bearing::SliderGeometry;
/// let g = SliderGeometry::flat(1250.0, 1000.0);
/// assert_eq!(g.regions.len(), 0);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SliderGeometry {
    /// Length along the disk's motion (leading to trailing edge), µm.
    pub length_um: f64,
    /// Width, µm.
    pub width_um: f64,
    /// Depth of the surface outside every region, nm (0: the whole slider is air-bearing
    /// surface unless a region says otherwise).
    #[serde(default)]
    pub base_depth_nm: f64,
    /// Crown: how far the centre of the length stands nearer the disk than its ends, nm.
    #[serde(default)]
    pub crown_nm: f64,
    /// Camber: the same across the width, nm.
    #[serde(default)]
    pub camber_nm: f64,
    /// The leading-edge taper, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub taper: Option<Taper>,
    /// Rails and recesses, painted in order.
    #[serde(default)]
    pub regions: Vec<Region>,
}

impl SliderGeometry {
    /// A flat slider of this length and width (µm) with no regions.
    pub fn flat(length_um: f64, width_um: f64) -> Self {
        SliderGeometry {
            length_um,
            width_um,
            base_depth_nm: 0.0,
            crown_nm: 0.0,
            camber_nm: 0.0,
            taper: None,
            regions: Vec::new(),
        }
    }
}

/// Where and how the slider flies.
///
/// ```
/// use hdi_tribology::bearing::OperatingConditions;
/// let op = OperatingConditions::new(20.0, 7200.0, 25.0);
/// assert!((op.disk_speed_m_per_s() - 15.08).abs() < 0.01);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OperatingConditions {
    /// Radius of the track, mm.
    pub radius_mm: f64,
    /// Disk speed, revolutions per minute.
    pub rpm: f64,
    /// Skew: angle of the disk's velocity to the slider's length, degrees, within ±30.
    #[serde(default)]
    pub skew_deg: f64,
    /// Ambient pressure, kPa.
    #[serde(default = "standard_pressure")]
    pub ambient_pressure_kpa: f64,
    /// Viscosity of the gas, µPa s.
    #[serde(default = "air_viscosity")]
    pub viscosity_upa_s: f64,
    /// Mean free path of the gas at the ambient pressure, nm.
    #[serde(default = "air_mean_free_path")]
    pub mean_free_path_nm: f64,
    /// The suspension's preload, mN, acting at the pivot.
    pub preload_mn: f64,
    /// The pivot (load point) `[x, y]`, µm; default the slider's centre.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pivot_um: Option<[f64; 2]>,
    /// Static pitch torque of the suspension about the pivot, µN m: the moment about the pivot
    /// that the bearing's pressure must make at equilibrium, positive when it raises the leading
    /// edge (the pressure's centre ahead of the pivot).
    #[serde(default)]
    pub pitch_torque_un_m: f64,
    /// Static roll torque, µN m: positive when it raises the `+y` side (the pressure's centre on
    /// the `+y` side of the pivot).
    #[serde(default)]
    pub roll_torque_un_m: f64,
    /// The rarefaction model of the Poiseuille flow.
    #[serde(default)]
    pub flow_model: FlowModel,
}

fn standard_pressure() -> f64 {
    STANDARD_PRESSURE_KPA
}
fn air_viscosity() -> f64 {
    AIR_VISCOSITY_UPA_S
}
fn air_mean_free_path() -> f64 {
    AIR_MEAN_FREE_PATH_NM
}

impl OperatingConditions {
    /// Radius (mm), rpm and preload (mN); air at the standard atmosphere, no skew, the pivot at
    /// the centre, no static torques, first-order slip.
    pub fn new(radius_mm: f64, rpm: f64, preload_mn: f64) -> Self {
        OperatingConditions {
            radius_mm,
            rpm,
            skew_deg: 0.0,
            ambient_pressure_kpa: STANDARD_PRESSURE_KPA,
            viscosity_upa_s: AIR_VISCOSITY_UPA_S,
            mean_free_path_nm: AIR_MEAN_FREE_PATH_NM,
            preload_mn,
            pivot_um: None,
            pitch_torque_un_m: 0.0,
            roll_torque_un_m: 0.0,
            flow_model: FlowModel::default(),
        }
    }

    /// The disk's speed under the slider, `2π r rpm / 60`, m/s.
    pub fn disk_speed_m_per_s(&self) -> f64 {
        2.0 * std::f64::consts::PI * self.radius_mm * 1e-3 * self.rpm / 60.0
    }
}

/// The grid the Reynolds equation is solved on.
///
/// ```
/// use hdi_tribology::bearing::GridSpec;
/// let g = GridSpec::default();
/// assert_eq!((g.nx, g.ny), (257, 257));
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridSpec {
    /// Control volumes along the length.
    #[serde(default = "default_cells")]
    pub nx: usize,
    /// Control volumes across the width.
    #[serde(default = "default_cells")]
    pub ny: usize,
    /// How much finer the grid is at a rail's step and at the trailing edge than elsewhere
    /// (1: uniform).
    #[serde(default = "default_refinement")]
    pub refinement: f64,
}

fn default_cells() -> usize {
    257
}
fn default_refinement() -> f64 {
    DEFAULT_REFINEMENT
}

impl Default for GridSpec {
    fn default() -> Self {
        GridSpec {
            nx: default_cells(),
            ny: default_cells(),
            refinement: default_refinement(),
        }
    }
}

/// A whole bearing problem as written: the slider, where it flies, the grid, and the bulge.
///
/// ```
/// use hdi_tribology::bearing::BearingSpec;
/// let spec = BearingSpec::from_toml_str(r#"
///     [slider]
///     length_um = 1250
///     width_um = 1000
///     [operating]
///     radius_mm = 20
///     rpm = 7200
///     preload_mn = 25
/// "#)?;
/// let bearing = spec.build()?;
/// assert!((bearing.length - 1.25e-3).abs() < 1e-15);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BearingSpec {
    /// The air-bearing surface.
    pub slider: SliderGeometry,
    /// Where and how it flies.
    pub operating: OperatingConditions,
    /// The grid.
    #[serde(default)]
    pub grid: GridSpec,
    /// The bulge (the point whose spacing is reported besides the trailing edge's), `[x, y]`,
    /// µm; default the trailing edge's centre.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bulge_um: Option<[f64; 2]>,
}

/// A region validated into SI: depth and vertices (m), open (no repeated last vertex).
#[derive(Clone, Debug, PartialEq)]
pub struct Polygon {
    /// How messages name it.
    pub label: String,
    /// Depth, m.
    pub depth: f64,
    /// Vertices, m, without the closing repeat.
    pub vertices: Vec<[f64; 2]>,
}

/// A validated bearing problem, SI throughout.
#[derive(Clone, Debug, PartialEq)]
pub struct Bearing {
    /// Length `L`, m.
    pub length: f64,
    /// Width `W`, m.
    pub width: f64,
    /// Depth outside every region, m.
    pub base_depth: f64,
    /// Crown, m.
    pub crown: f64,
    /// Camber, m.
    pub camber: f64,
    /// Taper `(length, height)`, m.
    pub taper: Option<(f64, f64)>,
    /// Regions, painted in order.
    pub polygons: Vec<Polygon>,
    /// Disk speed, m/s.
    pub speed: f64,
    /// Skew, rad.
    pub skew: f64,
    /// Ambient pressure, Pa.
    pub ambient_pressure: f64,
    /// Viscosity, Pa s.
    pub viscosity: f64,
    /// Mean free path at the ambient pressure, m.
    pub mean_free_path: f64,
    /// Preload, N.
    pub preload: f64,
    /// Pivot, m.
    pub pivot: [f64; 2],
    /// Static pitch torque, N m.
    pub pitch_torque: f64,
    /// Static roll torque, N m.
    pub roll_torque: f64,
    /// Rarefaction model.
    pub flow_model: FlowModel,
    /// Grid.
    pub grid: GridSpec,
    /// Bulge point, m.
    pub bulge: [f64; 2],
}

impl Bearing {
    /// Depth of the surface below the air-bearing surface at `(x, y)` (m), regions, taper, crown
    /// and camber included (crown and camber lower it, so they count negative).
    ///
    /// ```
    /// # use hdi_tribology::bearing::BearingSpec;
    /// # let spec = BearingSpec::from_toml_str("[slider]\nlength_um = 1000\nwidth_um = 800\n\
    /// #   crown_nm = 20\n[operating]\nradius_mm = 20\nrpm = 7200\npreload_mn = 20")?;
    /// let b = spec.build()?;
    /// assert!((b.depth_at(0.5e-3, 0.0) + 20e-9).abs() < 1e-18);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn depth_at(&self, x: f64, y: f64) -> f64 {
        let mut d = self.base_depth;
        for p in &self.polygons {
            if contains(&p.vertices, x, y) {
                d = p.depth;
            }
        }
        d + self.smooth_depth(x, y)
    }

    /// The smooth part of the depth: taper, crown and camber (m).
    pub fn smooth_depth(&self, x: f64, y: f64) -> f64 {
        let mut d = 0.0;
        if let Some((lt, ht)) = self.taper {
            if x < lt {
                d += ht * (1.0 - x / lt);
            }
        }
        let u = 2.0 * x / self.length - 1.0;
        let v = 2.0 * y / self.width - 1.0;
        d - self.crown * (1.0 - u * u) - self.camber * (1.0 - v * v)
    }

    /// Bearing number `Λ = 6 μ U L / (p_a h_m²)` at the reference spacing `h_m` (m).
    pub fn bearing_number(&self, reference_spacing: f64) -> f64 {
        6.0 * self.viscosity * self.speed * self.length
            / (self.ambient_pressure * reference_spacing * reference_spacing)
    }
}

/// Even–odd point-in-polygon test (vertices open).
pub(crate) fn contains(v: &[[f64; 2]], x: f64, y: f64) -> bool {
    let mut inside = false;
    let n = v.len();
    let mut j = n - 1;
    for i in 0..n {
        let (xi, yi) = (v[i][0], v[i][1]);
        let (xj, yj) = (v[j][0], v[j][1]);
        if (yi > y) != (yj > y) && x < xj + (y - yj) * (xi - xj) / (yi - yj) {
            inside = !inside;
        }
        j = i;
    }
    inside
}

/// Whether the closed segments `a–b` and `c–d` meet.
fn segments_meet(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2], tol: f64) -> bool {
    let orient = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
    };
    let sign = |v: f64| {
        if v > tol {
            1
        } else if v < -tol {
            -1
        } else {
            0
        }
    };
    let on = |p: [f64; 2], q: [f64; 2], r: [f64; 2]| {
        r[0] >= p[0].min(q[0]) - tol
            && r[0] <= p[0].max(q[0]) + tol
            && r[1] >= p[1].min(q[1]) - tol
            && r[1] <= p[1].max(q[1]) + tol
    };
    let (o1, o2) = (sign(orient(a, b, c)), sign(orient(a, b, d)));
    let (o3, o4) = (sign(orient(c, d, a)), sign(orient(c, d, b)));
    if o1 != o2 && o3 != o4 && o1 != 0 && o2 != 0 && o3 != 0 && o4 != 0 {
        return true;
    }
    (o1 == 0 && on(a, b, c))
        || (o2 == 0 && on(a, b, d))
        || (o3 == 0 && on(c, d, a))
        || (o4 == 0 && on(c, d, b))
}

fn validate_region(r: &Region, index: usize, length: f64, width: f64) -> Result<Polygon> {
    let label = r.label(index);
    let field = format!("slider.regions[{index}] {label}");
    if !r.depth_nm.is_finite() || r.depth_nm < 0.0 {
        return Err(Error::invalid(
            format!("{field}.depth_nm"),
            format!(
                "the etch depth must be finite and >= 0, got {} nm",
                r.depth_nm
            ),
        ));
    }
    let pts = &r.polygon_um;
    for (k, p) in pts.iter().enumerate() {
        if !p[0].is_finite() || !p[1].is_finite() {
            return Err(Error::invalid(
                format!("{field}.polygon_um[{k}]"),
                format!("must be finite, got [{}, {}]", p[0], p[1]),
            ));
        }
    }
    let scale = length.max(width) * 1e6;
    let tol = COORD_TOL * scale;
    let closed = pts.len() >= 2 && {
        let (a, b) = (pts[0], pts[pts.len() - 1]);
        (a[0] - b[0]).abs() <= tol && (a[1] - b[1]).abs() <= tol
    };
    if !closed {
        return Err(Error::invalid(
            format!("{field}.polygon_um"),
            "the polygon is open: its last vertex must repeat the first",
        ));
    }
    let v: Vec<[f64; 2]> = pts[..pts.len() - 1].to_vec();
    if v.len() < 3 {
        return Err(Error::invalid(
            format!("{field}.polygon_um"),
            format!(
                "a polygon needs at least 3 distinct vertices, got {}",
                v.len()
            ),
        ));
    }
    let (l_um, w_um) = (length * 1e6, width * 1e6);
    for (k, p) in v.iter().enumerate() {
        if p[0] < -tol || p[0] > l_um + tol || p[1] < -tol || p[1] > w_um + tol {
            return Err(Error::invalid(
                format!("{field}.polygon_um[{k}]"),
                format!(
                    "the vertex [{}, {}] µm lies outside the slider (0..{l_um} µm by 0..{w_um} µm)",
                    p[0], p[1]
                ),
            ));
        }
    }
    let n = v.len();
    let mut area2 = 0.0;
    for i in 0..n {
        let (a, b) = (v[i], v[(i + 1) % n]);
        area2 += a[0] * b[1] - b[0] * a[1];
        if (a[0] - b[0]).abs() <= tol && (a[1] - b[1]).abs() <= tol {
            return Err(Error::invalid(
                format!("{field}.polygon_um[{}]", (i + 1) % n),
                "repeats the vertex before it",
            ));
        }
    }
    for i in 0..n {
        for j in i + 1..n {
            // Adjacent edges share a vertex; skip them.
            if j == i + 1 || (i == 0 && j == n - 1) {
                continue;
            }
            if segments_meet(v[i], v[(i + 1) % n], v[j], v[(j + 1) % n], tol * scale) {
                return Err(Error::invalid(
                    format!("{field}.polygon_um"),
                    format!(
                        "the polygon intersects itself: edge {i}–{} meets edge {j}–{}",
                        (i + 1) % n,
                        (j + 1) % n
                    ),
                ));
            }
        }
    }
    if area2.abs() <= tol * scale {
        return Err(Error::invalid(
            format!("{field}.polygon_um"),
            "the polygon encloses no area",
        ));
    }
    Ok(Polygon {
        label,
        depth: r.depth_nm * 1e-9,
        vertices: v.iter().map(|p| [p[0] * 1e-6, p[1] * 1e-6]).collect(),
    })
}

fn check_point(field: &str, p: [f64; 2], length: f64, width: f64) -> Result<[f64; 2]> {
    let (l_um, w_um) = (length * 1e6, width * 1e6);
    if !(p[0].is_finite() && p[1].is_finite())
        || p[0] < 0.0
        || p[0] > l_um
        || p[1] < 0.0
        || p[1] > w_um
    {
        return Err(Error::invalid(
            field,
            format!(
                "[{}, {}] µm lies outside the slider (0..{l_um} µm by 0..{w_um} µm)",
                p[0], p[1]
            ),
        ));
    }
    Ok([p[0] * 1e-6, p[1] * 1e-6])
}

impl BearingSpec {
    /// Validates the problem and converts it to SI.
    pub fn build(&self) -> Result<Bearing> {
        let s = &self.slider;
        let o = &self.operating;
        let length = check_positive("slider.length_um", s.length_um)? * 1e-6;
        let width = check_positive("slider.width_um", s.width_um)? * 1e-6;
        let base_depth = check_non_negative("slider.base_depth_nm", s.base_depth_nm)? * 1e-9;
        let crown = check_finite("slider.crown_nm", s.crown_nm)? * 1e-9;
        let camber = check_finite("slider.camber_nm", s.camber_nm)? * 1e-9;
        let taper = match &s.taper {
            None => None,
            Some(t) => {
                let h = t.height_m("slider.taper")?;
                if t.length_um * 1e-6 > length {
                    return Err(Error::invalid(
                        "slider.taper.length_um",
                        format!(
                            "the taper ({} µm) is longer than the slider ({} µm)",
                            t.length_um, s.length_um
                        ),
                    ));
                }
                Some((t.length_um * 1e-6, h))
            }
        };
        let polygons = s
            .regions
            .iter()
            .enumerate()
            .map(|(i, r)| validate_region(r, i, length, width))
            .collect::<Result<Vec<_>>>()?;
        check_positive("operating.radius_mm", o.radius_mm)?;
        if !o.rpm.is_finite() || o.rpm <= 0.0 {
            return Err(Error::invalid(
                "operating.rpm",
                format!("the disk must turn (speed > 0), got {} rpm", o.rpm),
            ));
        }
        if !o.skew_deg.is_finite() || o.skew_deg.abs() > MAX_SKEW_DEG {
            return Err(Error::invalid(
                "operating.skew_deg",
                format!("must lie within ±{MAX_SKEW_DEG}°, got {}°", o.skew_deg),
            ));
        }
        let ambient_pressure =
            check_positive("operating.ambient_pressure_kpa", o.ambient_pressure_kpa)? * 1e3;
        let viscosity = check_positive("operating.viscosity_upa_s", o.viscosity_upa_s)? * 1e-6;
        let mean_free_path =
            check_non_negative("operating.mean_free_path_nm", o.mean_free_path_nm)? * 1e-9;
        let preload = check_positive("operating.preload_mn", o.preload_mn)? * 1e-3;
        let pivot = match o.pivot_um {
            Some(p) => check_point("operating.pivot_um", p, length, width)?,
            None => [length / 2.0, width / 2.0],
        };
        let pitch_torque = check_finite("operating.pitch_torque_un_m", o.pitch_torque_un_m)? * 1e-6;
        let roll_torque = check_finite("operating.roll_torque_un_m", o.roll_torque_un_m)? * 1e-6;
        let g = &self.grid;
        for (f, n) in [("grid.nx", g.nx), ("grid.ny", g.ny)] {
            if !(MIN_CELLS..=MAX_CELLS).contains(&n) {
                return Err(Error::invalid(
                    f,
                    format!(
                        "must lie within {}..={} control volumes, got {n}",
                        MIN_CELLS, MAX_CELLS
                    ),
                ));
            }
        }
        if !g.refinement.is_finite() || g.refinement < 1.0 {
            return Err(Error::invalid(
                "grid.refinement",
                format!("must be finite and >= 1, got {}", g.refinement),
            ));
        }
        let bulge = match self.bulge_um {
            Some(p) => check_point("bulge_um", p, length, width)?,
            None => [length, width / 2.0],
        };
        Ok(Bearing {
            length,
            width,
            base_depth,
            crown,
            camber,
            taper,
            polygons,
            speed: o.disk_speed_m_per_s(),
            skew: o.skew_deg.to_radians(),
            ambient_pressure,
            viscosity,
            mean_free_path,
            preload,
            pivot,
            pitch_torque,
            roll_torque,
            flow_model: o.flow_model,
            grid: g.clone(),
            bulge,
        })
    }

    /// Parses TOML.
    pub fn from_toml_str(s: &str) -> Result<Self> {
        let de = toml::Deserializer::parse(s).map_err(|e| Error::Scene {
            origin: "<string>".into(),
            reason: e.to_string(),
        })?;
        serde_path_to_error::deserialize(de).map_err(|e| Error::Scene {
            origin: "<string>".into(),
            reason: format!("{}: {}", e.path(), e.inner()),
        })
    }

    /// Parses JSON.
    ///
    /// ```
    /// use hdi_tribology::bearing::BearingSpec;
    /// let s = BearingSpec::from_toml_str(
    ///     "[slider]\nlength_um = 1000\nwidth_um = 800\n[operating]\nradius_mm = 20\nrpm = 7200\npreload_mn = 20")?;
    /// let back = BearingSpec::from_json_str(&serde_json::to_string(&s).unwrap())?;
    /// assert_eq!(s, back);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn from_json_str(s: &str) -> Result<Self> {
        let mut de = serde_json::Deserializer::from_str(s);
        serde_path_to_error::deserialize(&mut de).map_err(|e| Error::Scene {
            origin: "<string>".into(),
            reason: format!("{}: {}", e.path(), e.inner()),
        })
    }

    /// Reads a file: `.toml`, `.json`, or anything else in the text format
    /// ([`BearingSpec::from_text`]).
    pub fn from_path(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| Error::Io {
            path: path.display().to_string(),
            source: e,
        })?;
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        let parsed = match ext {
            "toml" => Self::from_toml_str(&text),
            "json" => Self::from_json_str(&text),
            _ => Self::from_text(&text),
        };
        parsed.map_err(|e| match e {
            Error::Scene { reason, .. } => Error::Scene {
                origin: path.display().to_string(),
                reason,
            },
            other => other,
        })
    }

    /// Parses the line-based text format.
    ///
    /// One `key value` pair per line; `#` starts a comment. The keys are the TOML field names
    /// (`length_um`, `radius_mm`, `skew_deg`, ...), pairs such as `pivot_um` and `bulge_um` take
    /// two numbers, `taper_length_um` with `taper_angle_mrad` or `taper_height_um` give the
    /// taper, and `flow_model` a model's name. A region starts with
    /// `region NAME depth_nm D` (NAME without spaces, or `-` for none), is followed by one
    /// `x y` vertex per line (µm), and ends with `end`.
    ///
    /// ```
    /// use hdi_tribology::bearing::BearingSpec;
    /// let s = BearingSpec::from_text("
    ///     length_um 1000
    ///     width_um 800
    ///     base_depth_nm 2000
    ///     region pad depth_nm 0
    ///       900 300
    ///       1000 300
    ///       1000 500
    ///       900 500
    ///       900 300
    ///     end
    ///     radius_mm 20
    ///     rpm 7200
    ///     preload_mn 20
    /// ")?;
    /// assert_eq!(s.slider.regions[0].name.as_deref(), Some("pad"));
    /// s.build()?;
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn from_text(text: &str) -> Result<Self> {
        text::parse(text)
    }

    /// Writes the problem in the text format ([`BearingSpec::from_text`] reads it back).
    pub fn to_text(&self) -> String {
        text::write(self)
    }
}

impl fmt::Display for Polygon {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} ({} vertices)", self.label, self.vertices.len())
    }
}

mod text {
    use super::*;

    fn err(line: usize, reason: impl Into<String>) -> Error {
        Error::Scene {
            origin: "<string>".into(),
            reason: format!("line {line}: {}", reason.into()),
        }
    }

    fn num(line: usize, key: &str, s: Option<&str>) -> Result<f64> {
        let s = s.ok_or_else(|| err(line, format!("{key} needs a number")))?;
        s.parse::<f64>()
            .map_err(|_| err(line, format!("{key}: \"{s}\" is not a number")))
    }

    pub(super) fn parse(text: &str) -> Result<BearingSpec> {
        let mut slider = SliderGeometry::flat(f64::NAN, f64::NAN);
        let mut op = OperatingConditions::new(f64::NAN, f64::NAN, f64::NAN);
        let mut grid = GridSpec::default();
        let mut bulge = None;
        let (mut t_len, mut t_ang, mut t_h) = (None, None, None);
        let mut seen = std::collections::HashSet::new();
        let mut current: Option<Region> = None;
        for (i, raw) in text.lines().enumerate() {
            let line = i + 1;
            let body = raw.split('#').next().unwrap_or("").trim();
            if body.is_empty() {
                continue;
            }
            let mut w = body.split_whitespace();
            let key = w.next().unwrap_or("");
            if let Some(r) = current.as_mut() {
                if key == "end" {
                    slider
                        .regions
                        .push(current.take().expect("a region is open"));
                    continue;
                }
                let x = num(line, "vertex x", Some(key))?;
                let y = num(line, "vertex y", w.next())?;
                r.polygon_um.push([x, y]);
                if w.next().is_some() {
                    return Err(err(line, "a vertex is two numbers, x y (µm)"));
                }
                continue;
            }
            if key != "region" && !seen.insert(key.to_string()) {
                return Err(err(line, format!("{key} given twice")));
            }
            let mut one = |k: &str| num(line, k, w.next());
            match key {
                "length_um" => slider.length_um = one(key)?,
                "width_um" => slider.width_um = one(key)?,
                "base_depth_nm" => slider.base_depth_nm = one(key)?,
                "crown_nm" => slider.crown_nm = one(key)?,
                "camber_nm" => slider.camber_nm = one(key)?,
                "taper_length_um" => t_len = Some(one(key)?),
                "taper_angle_mrad" => t_ang = Some(one(key)?),
                "taper_height_um" => t_h = Some(one(key)?),
                "radius_mm" => op.radius_mm = one(key)?,
                "rpm" => op.rpm = one(key)?,
                "skew_deg" => op.skew_deg = one(key)?,
                "ambient_pressure_kpa" => op.ambient_pressure_kpa = one(key)?,
                "viscosity_upa_s" => op.viscosity_upa_s = one(key)?,
                "mean_free_path_nm" => op.mean_free_path_nm = one(key)?,
                "preload_mn" => op.preload_mn = one(key)?,
                "pitch_torque_un_m" => op.pitch_torque_un_m = one(key)?,
                "roll_torque_un_m" => op.roll_torque_un_m = one(key)?,
                "pivot_um" => op.pivot_um = Some([one(key)?, one(key)?]),
                "bulge_um" => bulge = Some([one(key)?, one(key)?]),
                "refinement" => grid.refinement = one(key)?,
                "nx" | "ny" => {
                    let v = one(key)?;
                    if v.fract() != 0.0 || v < 0.0 {
                        return Err(err(line, format!("{key} must be a whole number, got {v}")));
                    }
                    if key == "nx" {
                        grid.nx = v as usize;
                    } else {
                        grid.ny = v as usize;
                    }
                }
                "flow_model" => {
                    let name = w
                        .next()
                        .ok_or_else(|| err(line, "flow_model needs a model's name"))?;
                    op.flow_model =
                        serde_json::from_value(serde_json::Value::String(name.to_string()))
                            .map_err(|e| err(line, format!("flow_model: {e}")))?;
                }
                "region" => {
                    let name = w.next().ok_or_else(|| err(line, "region needs a name"))?;
                    if w.next() != Some("depth_nm") {
                        return Err(err(line, "expected: region NAME depth_nm D"));
                    }
                    let depth = num(line, "depth_nm", w.next())?;
                    current = Some(Region {
                        name: (name != "-").then(|| name.to_string()),
                        depth_nm: depth,
                        polygon_um: Vec::new(),
                    });
                }
                other => return Err(err(line, format!("unknown key \"{other}\""))),
            }
            if w.next().is_some() {
                return Err(err(line, format!("too many values after {key}")));
            }
        }
        if current.is_some() {
            return Err(err(text.lines().count(), "a region has no \"end\""));
        }
        for (k, v) in [
            ("length_um", slider.length_um),
            ("width_um", slider.width_um),
            ("radius_mm", op.radius_mm),
            ("rpm", op.rpm),
            ("preload_mn", op.preload_mn),
        ] {
            if v.is_nan() {
                return Err(err(text.lines().count(), format!("{k} is missing")));
            }
        }
        if t_len.is_some() || t_ang.is_some() || t_h.is_some() {
            slider.taper = Some(Taper {
                length_um: t_len.ok_or_else(|| err(0, "taper_length_um is missing"))?,
                angle_mrad: t_ang,
                height_um: t_h,
            });
        }
        Ok(BearingSpec {
            slider,
            operating: op,
            grid,
            bulge_um: bulge,
        })
    }

    pub(super) fn write(s: &BearingSpec) -> String {
        use std::fmt::Write;
        let mut o = String::new();
        let g = &s.slider;
        let p = &s.operating;
        let _ = writeln!(o, "length_um {}\nwidth_um {}", g.length_um, g.width_um);
        let _ = writeln!(
            o,
            "base_depth_nm {}\ncrown_nm {}\ncamber_nm {}",
            g.base_depth_nm, g.crown_nm, g.camber_nm
        );
        if let Some(t) = &g.taper {
            let _ = writeln!(o, "taper_length_um {}", t.length_um);
            if let Some(a) = t.angle_mrad {
                let _ = writeln!(o, "taper_angle_mrad {a}");
            }
            if let Some(h) = t.height_um {
                let _ = writeln!(o, "taper_height_um {h}");
            }
        }
        for r in &g.regions {
            let name = r.name.as_deref().unwrap_or("-").replace(' ', "_");
            let _ = writeln!(o, "region {name} depth_nm {}", r.depth_nm);
            for v in &r.polygon_um {
                let _ = writeln!(o, "  {} {}", v[0], v[1]);
            }
            let _ = writeln!(o, "end");
        }
        let _ = writeln!(
            o,
            "radius_mm {}\nrpm {}\nskew_deg {}\nambient_pressure_kpa {}\nviscosity_upa_s {}\n\
             mean_free_path_nm {}\npreload_mn {}\npitch_torque_un_m {}\nroll_torque_un_m {}",
            p.radius_mm,
            p.rpm,
            p.skew_deg,
            p.ambient_pressure_kpa,
            p.viscosity_upa_s,
            p.mean_free_path_nm,
            p.preload_mn,
            p.pitch_torque_un_m,
            p.roll_torque_un_m
        );
        if let Some(v) = p.pivot_um {
            let _ = writeln!(o, "pivot_um {} {}", v[0], v[1]);
        }
        let model = serde_json::to_value(p.flow_model)
            .ok()
            .and_then(|v| v.as_str().map(str::to_string))
            .unwrap_or_default();
        let _ = writeln!(o, "flow_model {model}");
        let _ = writeln!(
            o,
            "nx {}\nny {}\nrefinement {}",
            s.grid.nx, s.grid.ny, s.grid.refinement
        );
        if let Some(b) = s.bulge_um {
            let _ = writeln!(o, "bulge_um {} {}", b[0], b[1]);
        }
        o
    }
}
