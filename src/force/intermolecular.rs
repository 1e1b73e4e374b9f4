//! The intermolecular (Lennard-Jones 3–9, Hamaker) term.

use super::{lj_zero, AveragedTerm, Coupling, Footprint, GapReference, LennardJones39, TermKind};
use crate::surface::GaussianHeights;
use crate::Result;

/// Lennard-Jones 3–9 attraction/repulsion, `p(h) = −A/(6π h³) + B/(45π h⁹)`, averaged over the
/// non-contacting surface heights and integrated over a footprint.
///
/// ```
/// use hdi_tribology::force::{Footprint, GapReference, InterfaceTerm, Intermolecular};
/// use hdi_tribology::surface::GaussianHeights;
/// # fn main() -> hdi_tribology::Result<()> {
/// let t = Intermolecular::new(1e-19, 1e-76, None, GaussianHeights::new(7e-10)?,
///     Footprint::Flat { area_m2: 1e-8 }, GapReference::Bulge)?;
/// assert!(t.force(5e-9)?.value < 0.0); // attractive far from contact
/// # Ok(()) }
/// ```
#[derive(Clone, Debug)]
pub struct Intermolecular {
    inner: AveragedTerm<LennardJones39>,
}

impl Intermolecular {
    /// Hamaker constants `A` (J) and `B` (J m⁶); `cutoff` (m) defaults to the zero of the law
    /// [`lj_zero`].
    pub fn new(
        hamaker_a: f64,
        hamaker_b: f64,
        cutoff: Option<f64>,
        heights: GaussianHeights,
        footprint: Footprint,
        gap: GapReference,
    ) -> Result<Self> {
        let law = LennardJones39::new(hamaker_a, hamaker_b)?;
        let hc = cutoff.unwrap_or_else(|| lj_zero(hamaker_a, hamaker_b));
        Ok(Intermolecular {
            inner: AveragedTerm::new(
                "intermolecular",
                TermKind::Intermolecular,
                Coupling::Static,
                law,
                hc,
                heights,
                footprint,
                gap,
            )?,
        })
    }

    /// The averaged term underneath (mean pressure, energy, cutoff).
    pub fn averaged(&self) -> &AveragedTerm<LennardJones39> {
        &self.inner
    }
}

super::averaged::forward_term!(Intermolecular);
