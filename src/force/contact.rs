//! Greenwood–Williamson asperity contact over a peak-height distribution.

use std::f64::consts::PI;
use std::sync::Arc;

use super::term::finite_eval;
use super::{Coupling, Footprint, GapReference, InterfaceTerm, Scaled, TermForce, TermKind};
use crate::error::check_positive;
use crate::surface::PeakDistribution;
use crate::{Error, Result};

/// Composite elastic modulus of two bodies, `1/E* = (1−ν₁²)/E₁ + (1−ν₂²)/E₂` (Pa).
///
/// ```
/// let e = hdi_tribology::force::composite_modulus(200e9, 0.25, 200e9, 0.25).unwrap();
/// assert!((e - 200e9 / (2.0 * (1.0 - 0.0625))).abs() < 1e-3);
/// ```
pub fn composite_modulus(e1: f64, nu1: f64, e2: f64, nu2: f64) -> Result<f64> {
    check_positive("e1", e1)?;
    check_positive("e2", e2)?;
    for (field, nu) in [("nu1", nu1), ("nu2", nu2)] {
        if !(nu.is_finite() && nu > -1.0 && nu <= 0.5) {
            return Err(Error::invalid(
                field,
                format!("must lie in (-1, 0.5], got {nu}"),
            ));
        }
    }
    Ok(1.0 / ((1.0 - nu1 * nu1) / e1 + (1.0 - nu2 * nu2) / e2))
}

/// Greenwood–Williamson elastic contact of spherical asperities (radius `R`, areal density `η_s`)
/// with peak heights from a [`PeakDistribution`]:
/// `p_c(d) = (4/3) E* √R η_s M_{3/2}(d)` with the partial moments
/// `M_p(d) = ∫_d^∞ (z − d)^p f_p(z) dz`, integrated over a footprint in closed form through
/// `∫_d^∞ M_p = M_{p+1}/(p+1)`. Real contact area per nominal area: `π R η_s M_1(d)`.
///
/// ```
/// use std::sync::Arc;
/// use hdi_tribology::force::{Footprint, GapReference, GreenwoodWilliamson, InterfaceTerm};
/// use hdi_tribology::surface::Gaussian;
/// # fn main() -> hdi_tribology::Result<()> {
/// let peaks = Arc::new(Gaussian::new(0.0, 1e-9)?);
/// let gw = GreenwoodWilliamson::new(1e11, 1e-7, 1.5e14, peaks,
///     Footprint::Flat { area_m2: 1e-8 }, GapReference::Bulge)?;
/// let f = gw.force(1e-9)?;
/// assert!(f.value > 0.0 && f.slope < 0.0);
/// assert!(gw.real_contact_area(1e-9)? > 0.0);
/// # Ok(()) }
/// ```
#[derive(Clone, Debug)]
pub struct GreenwoodWilliamson {
    modulus: f64,
    radius: f64,
    density: f64,
    peaks: Arc<dyn PeakDistribution>,
    footprint: Footprint,
    gap: GapReference,
    peak_heights: Vec<f64>,
}

impl GreenwoodWilliamson {
    /// Composite modulus `E*` (Pa), asperity radius `R` (m), asperity areal density `η_s` (m⁻²).
    pub fn new(
        composite_modulus: f64,
        asperity_radius: f64,
        asperity_density: f64,
        peaks: Arc<dyn PeakDistribution>,
        footprint: Footprint,
        gap: GapReference,
    ) -> Result<Self> {
        check_positive("composite_modulus_pa", composite_modulus)?;
        check_positive("asperity_radius_m", asperity_radius)?;
        check_positive("asperity_density_per_m2", asperity_density)?;
        footprint.validate("footprint")?;
        Ok(GreenwoodWilliamson {
            modulus: composite_modulus,
            radius: asperity_radius,
            density: asperity_density,
            peaks,
            footprint,
            gap,
            peak_heights: Vec::new(),
        })
    }

    /// Declares the heights of a discrete peak ensemble. Its partial moments are not smooth at
    /// the peak heights; on a flat footprint (force `∝ M_{3/2}`) the tables are split there.
    /// The paraboloid integrates them once more (`M_{5/2}`) and needs no split.
    pub fn with_discrete_peaks(mut self, heights: &[f64]) -> Self {
        self.peak_heights = heights.iter().copied().filter(|h| h.is_finite()).collect();
        self
    }

    /// The peak-height distribution.
    pub fn peaks(&self) -> &Arc<dyn PeakDistribution> {
        &self.peaks
    }

    fn moment(&self, d: f64, p: f64) -> Result<f64> {
        let m = self.peaks.partial_moment(d, p);
        if m.is_finite() {
            Ok(m)
        } else {
            Err(super::ForceError::PartialMoment {
                order: p,
                d_nm: d * 1e9,
                value: m,
            }
            .into())
        }
    }

    /// `M_p(d) − M_p(d + Δ)` (Δ may be infinite).
    fn moment_band(&self, d: f64, p: f64, delta: f64) -> Result<f64> {
        let m = self.moment(d, p)?;
        if delta.is_infinite() {
            Ok(m)
        } else {
            Ok(m - self.moment(d + delta, p)?)
        }
    }

    /// `k M_p` per nominal area (the pressure for `p = 3/2`, the real contact area for `p = 1`)
    /// over the footprint, with its slope: `dM_p/dd = −p M_{p−1}` and
    /// `∫_d^∞ M_p = M_{p+1}/(p + 1)`.
    fn over_footprint(&self, d: f64, k: f64, p: f64) -> Result<(f64, f64)> {
        self.footprint.reduce(
            k,
            || {
                Ok((
                    self.moment(d, p)?.into(),
                    Scaled::new(-p, self.moment(d, p - 1.0)?),
                ))
            },
            |delta| {
                Ok((
                    Scaled::new(1.0 / (p + 1.0), self.moment_band(d, p + 1.0, delta)?),
                    self.moment_band(d, p, delta)?.into(),
                ))
            },
        )
    }
}

impl InterfaceTerm for GreenwoodWilliamson {
    fn name(&self) -> &str {
        "contact"
    }
    fn kind(&self) -> TermKind {
        TermKind::Contact
    }
    fn coupling(&self) -> Coupling {
        Coupling::Static
    }
    fn gap(&self) -> GapReference {
        self.gap
    }
    fn force(&self, d: f64) -> Result<TermForce> {
        finite_eval(self.name(), "force", d, || {
            let k = 4.0 / 3.0 * self.modulus * self.radius.sqrt() * self.density;
            self.over_footprint(d, k, 1.5)
        })
        .map(TermForce::from)
    }
    fn real_contact_area(&self, d: f64) -> Result<f64> {
        Ok(self.real_contact_area_and_slope(d)?.0)
    }
    fn kinks(&self) -> Vec<f64> {
        match self.footprint {
            Footprint::Flat { .. } => self.peak_heights.clone(),
            Footprint::Paraboloid { .. } => Vec::new(),
        }
    }
    fn real_contact_area_and_slope(&self, d: f64) -> Result<(f64, f64)> {
        finite_eval(self.name(), "real contact area", d, || {
            self.over_footprint(d, PI * self.radius * self.density, 1.0)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::Gaussian;

    /// Force and real contact area with their slopes, as the term wrote the footprint reduction
    /// out before [`Footprint::reduce`] held it.
    fn written_out(gw: &GreenwoodWilliamson, d: f64) -> [(f64, f64); 2] {
        let m = |s: f64, p: f64| gw.moment(s, p).unwrap();
        let band = |p: f64, delta: f64| gw.moment_band(d, p, delta).unwrap();
        let kf = 4.0 / 3.0 * gw.modulus * gw.radius.sqrt() * gw.density;
        let ka = PI * gw.radius * gw.density;
        match gw.footprint {
            Footprint::Flat { area_m2 } => [
                (area_m2 * kf * m(d, 1.5), -area_m2 * kf * 1.5 * m(d, 0.5)),
                (area_m2 * ka * m(d, 1.0), -area_m2 * ka * m(d, 0.0)),
            ],
            Footprint::Paraboloid {
                radius_of_curvature_m,
                ..
            } => {
                let delta = gw.footprint.derjaguin_depth();
                let (cf, ca) = (
                    2.0 * PI * radius_of_curvature_m * kf,
                    2.0 * PI * radius_of_curvature_m * ka,
                );
                [
                    (cf * 0.4 * band(2.5, delta), -cf * band(1.5, delta)),
                    (ca * 0.5 * band(2.0, delta), -ca * band(1.0, delta)),
                ]
            }
        }
    }

    #[test]
    fn the_footprint_reduction_gives_the_written_out_numbers_to_the_bit() {
        let peaks = Arc::new(Gaussian::new(2e-10, 6e-10).unwrap());
        for footprint in Footprint::samples() {
            let gw = GreenwoodWilliamson::new(
                1.1e11,
                1.3e-7,
                1.7e14,
                peaks.clone(),
                footprint,
                GapReference::Bulge,
            )
            .unwrap();
            for d in [-1e-9, 0.0, 7e-10, 2.1e-9] {
                let f = gw.force(d).unwrap();
                let area = gw.real_contact_area_and_slope(d).unwrap();
                let bits = |(v, s): (f64, f64)| (v.to_bits(), s.to_bits());
                let [force, contact] = written_out(&gw, d);
                assert_eq!(
                    bits((f.value, f.slope)),
                    bits(force),
                    "{footprint:?}, d = {d}"
                );
                assert_eq!(bits(area), bits(contact), "{footprint:?}, d = {d}");
            }
        }
    }
}
