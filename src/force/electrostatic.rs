//! The electrostatic term, per V² of the instantaneous voltage.

use super::{AveragedTerm, Coulomb, Coupling, Footprint, GapReference, TermKind};
use crate::surface::GaussianHeights;
use crate::Result;

/// Electrostatic attraction per V², `p(h) = −ε₀ / (2 (h + t_d)²)`, averaged over the
/// non-contacting surface heights and integrated over a footprint: this is `G_e(d)` in
/// `F_e = V(t)² G_e(d)`, with `V` already reduced by the contact potential.
///
/// ```
/// use hdi_tribology::force::{Electrostatic, Footprint, GapReference, InterfaceTerm};
/// use hdi_tribology::surface::GaussianHeights;
/// # fn main() -> hdi_tribology::Result<()> {
/// let rc = 0.02;
/// let t = Electrostatic::new(0.0, 2e-10, GaussianHeights::new(0.0)?,
///     Footprint::Paraboloid { radius_of_curvature_m: rc, max_radius_m: None }, GapReference::Bulge)?;
/// let d = 3e-9;
/// let exact = -std::f64::consts::PI * rc * hdi_tribology::units::EPSILON_0 / d; // smooth sphere
/// assert!((t.force(d)?.value - exact).abs() < 1e-12 * exact.abs());
/// # Ok(()) }
/// ```
#[derive(Clone, Debug)]
pub struct Electrostatic {
    inner: AveragedTerm<Coulomb>,
}

impl Electrostatic {
    /// Dielectric-equivalent thickness `t_d ≥ 0` (m) and the non-contact cutoff `h_c > 0` (m).
    pub fn new(
        dielectric_thickness: f64,
        cutoff: f64,
        heights: GaussianHeights,
        footprint: Footprint,
        gap: GapReference,
    ) -> Result<Self> {
        let law = Coulomb::new(dielectric_thickness)?;
        Ok(Electrostatic {
            inner: AveragedTerm::new(
                "electrostatic",
                TermKind::Electrostatic,
                Coupling::PerVoltSquared,
                law,
                cutoff,
                heights,
                footprint,
                gap,
            )?,
        })
    }

    /// The averaged term underneath (mean pressure, energy, cutoff).
    pub fn averaged(&self) -> &AveragedTerm<Coulomb> {
        &self.inner
    }
}

super::averaged::forward_term!(Electrostatic);
