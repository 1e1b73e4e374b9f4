//! Zones: a radius and disk speed, with the flying conditions the drive sees there.

use crate::error::{check_positive, Result};
use crate::force::AirBearingModel;
use crate::scene::Scene;
use serde::{Deserialize, Serialize};

/// One calibration zone of a drive (a band of radii at one disk speed).
///
/// The crate has no air-bearing solver, so a zone carries the flying conditions an air-bearing
/// simulation (or the drive's characterisation) gives there: the nominal clearance and the
/// air-bearing stiffness. Its disk speed sets the sliding speed of the friction and
/// flash-temperature model; frictional heating does not feed back into the protrusion in this
/// model, so the speed does not move the touchdown power by itself.
///
/// ```
/// use hdi_tribology::drive::Zone;
/// let z = Zone::at_rpm("MD", 0.03, 7200.0, 10e-9, 3e5);
/// assert!((z.disk_speed - 2.0 * std::f64::consts::PI * 0.03 * 120.0).abs() < 1e-12);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Zone {
    /// A label for reports.
    pub name: String,
    /// Radius (m).
    pub radius: f64,
    /// Disk speed under the head (m/s).
    pub disk_speed: f64,
    /// Nominal clearance `h0` with the heater off (m).
    pub nominal_clearance: f64,
    /// Air-bearing stiffness at the flying position (N/m).
    pub bearing_stiffness: f64,
}

impl Zone {
    /// A zone at `radius` (m) on a disk turning at `rpm`, with the given clearance (m) and
    /// air-bearing stiffness (N/m).
    pub fn at_rpm(
        name: &str,
        radius: f64,
        rpm: f64,
        nominal_clearance: f64,
        bearing_stiffness: f64,
    ) -> Self {
        Zone {
            name: name.to_string(),
            radius,
            disk_speed: 2.0 * std::f64::consts::PI * radius * rpm / 60.0,
            nominal_clearance,
            bearing_stiffness,
        }
    }

    /// The scene `base` moved to this zone: nominal clearance, disk speed and air-bearing
    /// stiffness replaced. The damping is scaled by `√(k/k_base)` so the damping ratio of the
    /// air-bearing mode stays that of `base`; a cubic bearing's cubic term scales with `k`; a
    /// power-law bearing keeps its exponent `n`, takes `h0` as its reference gap and the preload
    /// `k h0 / n` that gives stiffness `k`.
    ///
    /// ```
    /// use hdi_tribology::{drive::Zone, scene::Scene};
    /// let z = Zone::at_rpm("OD", 0.045, 5400.0, 12e-9, 4e5);
    /// let s = z.scene(&Scene::paper())?;
    /// assert_eq!(s.nominal_clearance_m, 12e-9);
    /// assert_eq!(s.build_air_bearing()?.stiffness(0.0), 4e5);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn scene(&self, base: &Scene) -> Result<Scene> {
        check_positive("zone.radius", self.radius)?;
        check_positive("zone.disk_speed", self.disk_speed)?;
        check_positive("zone.nominal_clearance", self.nominal_clearance)?;
        check_positive("zone.bearing_stiffness", self.bearing_stiffness)?;
        let mut s = base.clone();
        s.name = format!("{} / {}", base.name, self.name);
        s.nominal_clearance_m = self.nominal_clearance;
        s.friction.disk_speed_m_per_s = self.disk_speed;
        let k = self.bearing_stiffness;
        let k_base = base.build_air_bearing()?.stiffness(0.0);
        check_positive("base air-bearing stiffness", k_base)?;
        let ratio = k / k_base;
        s.air_bearing = match base.air_bearing {
            AirBearingModel::Linear {
                damping_n_s_per_m, ..
            } => AirBearingModel::Linear {
                stiffness_n_per_m: k,
                damping_n_s_per_m: damping_n_s_per_m * ratio.sqrt(),
            },
            AirBearingModel::Cubic {
                cubic_stiffness_n_per_m3,
                damping_n_s_per_m,
                ..
            } => AirBearingModel::Cubic {
                stiffness_n_per_m: k,
                cubic_stiffness_n_per_m3: cubic_stiffness_n_per_m3 * ratio,
                damping_n_s_per_m: damping_n_s_per_m * ratio.sqrt(),
            },
            AirBearingModel::PowerLaw {
                exponent,
                damping_n_s_per_m,
                ..
            } => AirBearingModel::PowerLaw {
                preload_n: k * self.nominal_clearance / exponent,
                exponent,
                reference_gap_m: self.nominal_clearance,
                damping_n_s_per_m: damping_n_s_per_m * ratio.sqrt(),
            },
            // A bearing solved from the geometry takes the zone's radius and speed; the
            // zone's stiffness is the one it then has, not an input.
            AirBearingModel::Reynolds {
                ref geometry,
                cells,
                skew_deg,
                preload_mn,
                ..
            } => AirBearingModel::Reynolds {
                geometry: geometry.clone(),
                cells,
                radius_mm: Some(self.radius * 1e3),
                rpm: Some(self.disk_speed * 60.0 / (2.0 * std::f64::consts::PI * self.radius)),
                skew_deg,
                preload_mn,
            },
        };
        s.validate()?;
        Ok(s)
    }
}
