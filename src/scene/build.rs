//! Turning a validated scene into its parts: interface terms, their tables, the air bearing.

use std::sync::Arc;

use super::{Scene, WettingSpec};
use crate::force::{
    lj_zero, AirBearing, Electrostatic, GreenwoodWilliamson, InterfaceForces, InterfaceTerm,
    Intermolecular, Meniscus, MeniscusParams, Pickup, Wetting,
};
use crate::quadrature::TableOptions;
use crate::surface::{Discrete, GaussianHeights, PeakDistribution, PeakModel};
use crate::{Error, Result};

/// Prefixes the field of an input error with `prefix`.
fn in_field(e: Error, prefix: &str) -> Error {
    match e {
        Error::InvalidInput { field, reason } => Error::InvalidInput {
            field: format!("{prefix}{field}"),
            reason,
        },
        other => other,
    }
}

impl Scene {
    /// The asperity peak-height distribution (errors name `surface.peaks.<field>`).
    pub fn peaks(&self) -> Result<Arc<dyn PeakDistribution>> {
        self.surface.peaks.build().map_err(|e| match e {
            Error::InvalidInput { field, reason } if field.starts_with("peaks") => {
                Error::InvalidInput {
                    field: format!("surface.{field}"),
                    reason,
                }
            }
            other => in_field(other, "surface.peaks."),
        })
    }

    /// Heights of a discrete peak ensemble (given or sampled), `None` for continuous laws.
    fn discrete_peak_heights(&self) -> Result<Option<Vec<f64>>> {
        Ok(match &self.surface.peaks {
            PeakModel::Discrete { heights_m } => Some(heights_m.clone()),
            PeakModel::DiscreteSampled { from, n, seed } => {
                let parent = from
                    .build()
                    .map_err(|e| in_field(e, "surface.peaks.from."))?;
                let d = Discrete::sample(parent.as_ref(), *n, *seed)
                    .map_err(|e| in_field(e, "surface.peaks."))?;
                Some(d.heights().to_vec())
            }
            _ => None,
        })
    }

    /// The surface-height statistics of the non-contact terms.
    pub fn heights(&self) -> Result<GaussianHeights> {
        GaussianHeights::new(self.surface.height_sigma_m).map_err(|e| match e {
            Error::InvalidInput { reason, .. } => Error::invalid("surface.height_sigma_m", reason),
            other => other,
        })
    }

    /// Contact potential φ (V); 0 when the electrostatic term is off.
    pub fn contact_potential_v(&self) -> f64 {
        self.electrostatic
            .as_ref()
            .map_or(0.0, |e| e.contact_potential_v)
    }

    /// `(V_dc − φ)²`, V²: the squared voltage of a static (DC) analysis.
    pub fn dc_volt2(&self) -> f64 {
        let v = self.voltage.dc_v - self.contact_potential_v();
        v * v
    }

    /// The non-contact cutoff of the electrostatic term: its own, else that of the
    /// intermolecular term (given or `h_e`).
    fn electrostatic_cutoff(&self) -> Option<f64> {
        let e = self.electrostatic.as_ref()?;
        e.cutoff_m.or_else(|| {
            self.intermolecular.as_ref().map(|m| {
                m.cutoff_m
                    .unwrap_or_else(|| lj_zero(m.hamaker_attractive_j, m.hamaker_repulsive_j_m6))
            })
        })
    }

    /// The enabled interface terms (only those), validated.
    pub fn interface_terms(&self) -> Result<Vec<Box<dyn InterfaceTerm>>> {
        self.validate()?;
        let mut terms: Vec<Box<dyn InterfaceTerm>> = Vec::new();
        if let Some(m) = &self.intermolecular {
            let t = Intermolecular::new(
                m.hamaker_attractive_j,
                m.hamaker_repulsive_j_m6,
                m.cutoff_m,
                self.heights()?,
                m.footprint,
                m.gap,
            )
            .map_err(|e| in_field(e, "intermolecular."))?;
            terms.push(Box::new(t));
        }
        if let Some(e) = &self.electrostatic {
            let hc = self.electrostatic_cutoff().ok_or_else(|| {
                Error::invalid(
                    "electrostatic.cutoff_m",
                    "required when the intermolecular term is off",
                )
            })?;
            let t = Electrostatic::new(
                e.dielectric_thickness_m,
                hc,
                self.heights()?,
                e.footprint,
                e.gap,
            )
            .map_err(|err| in_field(err, "electrostatic."))?;
            terms.push(Box::new(t));
        }
        if let Some(c) = &self.contact {
            let t = GreenwoodWilliamson::new(
                c.composite_modulus_pa,
                c.asperity_radius_m,
                c.asperity_density_per_m2,
                self.peaks()?,
                c.footprint,
                c.gap,
            )
            .map_err(|e| in_field(e, "contact."))?;
            let t = match self.discrete_peak_heights()? {
                Some(h) => t.with_discrete_peaks(&h),
                None => t,
            };
            terms.push(Box::new(t));
        }
        Ok(terms)
    }

    /// The lubricant menisci of the `[lubricant]` section on the asperities of `[contact]`,
    /// tabulated over [`Scene::table_range`]; `None` when the section is absent or the mobile
    /// thickness is zero (the model is then exactly that of the scene without it).
    pub fn meniscus(&self) -> Result<Option<Meniscus>> {
        self.validate()?;
        let (Some(l), Some(c)) = (&self.lubricant, &self.contact) else {
            return Ok(None);
        };
        let mobile = l.mobile_thickness_m();
        if mobile <= 0.0 {
            return Ok(None);
        }
        let params = MeniscusParams {
            surface_tension: l.surface_tension_n_per_m,
            contact_angle: l.contact_angle_deg.to_radians(),
            wetting: match l.wetting {
                WettingSpec::Disk => Wetting::Disk,
                WettingSpec::Both => Wetting::Both,
            },
            mobile_thickness: mobile,
            rupture_distance: l.rupture_distance_m,
            healing_time: l.healing_time_s,
            formation_time: l.formation_time_s,
            pickup: match (l.pickup_rate_m_per_s, l.pickup_loss_time_s) {
                (Some(rate), Some(loss_time)) => Some(Pickup { rate, loss_time }),
                _ => None,
            },
        };
        let opts = TableOptions {
            rel_tol: self.table.rel_tol,
            ..TableOptions::default()
        };
        let m = Meniscus::new(
            params,
            c.asperity_radius_m,
            c.asperity_density_per_m2,
            self.peaks()?,
            c.footprint,
        )
        .map_err(|e| in_field(e, "lubricant."))?
        .tabulated(self.table_range(), &opts)?;
        Ok(Some(m))
    }

    /// Range of separations `d` (m) that the force tables cover.
    ///
    /// Default: from `min(0, mean peak height) − 5 s` (s the larger of the surface-height and
    /// peak-height standard deviations; `min(0, mean peak height) − 0.1 h0` when both are zero,
    /// as for a single discrete peak), which reaches well into hard contact, up to `3 h0`. `table.d_min_m` / `table.d_max_m` override either end. Outside
    /// the range the forces are still exact (direct quadrature), only slower.
    pub fn table_range(&self) -> (f64, f64) {
        let (mut mean, mut std) = (0.0_f64, 0.0_f64);
        if self.contact.is_some() {
            if let Ok(p) = self.peaks() {
                mean = p.mean();
                std = p.std_dev();
            }
        }
        let s = self.surface.height_sigma_m.max(std);
        let lo = if s > 0.0 && s.is_finite() {
            mean.min(0.0) - 5.0 * s
        } else {
            mean.min(0.0) - 0.1 * self.nominal_clearance_m
        };
        let hi = 3.0 * self.nominal_clearance_m;
        (
            self.table.d_min_m.unwrap_or(lo),
            self.table.d_max_m.unwrap_or(hi),
        )
    }

    /// Validates the scene and tabulates its enabled interface terms.
    pub fn build_interface(&self) -> Result<InterfaceForces> {
        let terms = self.interface_terms()?;
        let opts = TableOptions {
            rel_tol: self.table.rel_tol,
            ..TableOptions::default()
        };
        InterfaceForces::build(terms, self.table_range(), &opts)
    }

    /// The air bearing.
    pub fn build_air_bearing(&self) -> Result<Box<dyn AirBearing>> {
        self.air_bearing.build()
    }
}
