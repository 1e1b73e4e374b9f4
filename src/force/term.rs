//! The [`InterfaceTerm`] trait and the small enums that classify a term.

use serde::{Deserialize, Serialize};
use std::fmt::Debug;

use crate::Result;

/// How a term depends on time.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Coupling {
    /// Depends on the gap only.
    Static,
    /// Proportional to the square of the instantaneous voltage; the term returns the force per V².
    PerVoltSquared,
}

/// Which gap a term sees: the bulge gap `d`, or the pad gap `d + δ` (δ the thermal protrusion).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GapReference {
    /// The gap at the heater bulge, `d`.
    #[default]
    Bulge,
    /// The gap at the flat pad around the bulge, `d + δ`.
    Pad,
}

impl GapReference {
    pub(crate) fn index(self) -> usize {
        match self {
            GapReference::Bulge => 0,
            GapReference::Pad => 1,
        }
    }
}

/// What physics a term stands for; used to split a [`crate::force::Breakdown`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TermKind {
    /// Van der Waals / Lennard-Jones attraction and repulsion.
    Intermolecular,
    /// Asperity contact (the friction and the contact indicator use these terms).
    Contact,
    /// Electrostatic attraction.
    Electrostatic,
    /// Anything else a user adds.
    Other,
}

/// A term's force at one separation and its slope, from [`InterfaceTerm::force`].
///
/// ```
/// use hdi_tribology::force::TermForce;
/// let f = TermForce { value: -2e-4, slope: 3e5 };
/// assert!(f.value < 0.0 && f.slope > 0.0);
/// assert_eq!(TermForce::from((1.0, 2.0)), TermForce { value: 1.0, slope: 2.0 });
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TermForce {
    /// The force `F(d)` in N (per V² for a [`Coupling::PerVoltSquared`] term), positive away from
    /// the disk.
    pub value: f64,
    /// Its derivative `dF/dd` in N/m (per V² likewise).
    pub slope: f64,
}

impl From<(f64, f64)> for TermForce {
    /// `(F, dF/dd)`.
    fn from((value, slope): (f64, f64)) -> Self {
        TermForce { value, slope }
    }
}

/// A force law between head and disk as a function of the mean-plane separation `d` (m).
///
/// Forces are in N, positive when they push the head away from the disk; for
/// [`Coupling::PerVoltSquared`] terms the force is per V². Implement this trait to add a term of
/// your own; [`crate::force::InterfaceForces`] tabulates it with the built-in ones.
///
/// ```
/// use hdi_tribology::force::{Coupling, GapReference, InterfaceTerm, TermForce, TermKind};
/// /// A soft exponential repulsion F = F0 exp(−d/λ).
/// #[derive(Debug)]
/// struct Soft { f0: f64, lambda: f64 }
/// impl InterfaceTerm for Soft {
///     fn name(&self) -> &str { "soft repulsion" }
///     fn kind(&self) -> TermKind { TermKind::Other }
///     fn coupling(&self) -> Coupling { Coupling::Static }
///     fn gap(&self) -> GapReference { GapReference::Bulge }
///     fn force(&self, d: f64) -> hdi_tribology::Result<TermForce> {
///         let f = self.f0 * (-d / self.lambda).exp();
///         Ok(TermForce { value: f, slope: -f / self.lambda })
///     }
/// }
/// let s = Soft { f0: 1e-3, lambda: 1e-9 };
/// assert!(s.force(1e-9).unwrap().value > 0.0);
/// ```
pub trait InterfaceTerm: Debug + Send + Sync {
    /// A short human-readable name.
    fn name(&self) -> &str;
    /// What physics the term stands for.
    fn kind(&self) -> TermKind;
    /// How the term depends on time.
    fn coupling(&self) -> Coupling;
    /// Which gap the term sees.
    fn gap(&self) -> GapReference;
    /// Exact (direct quadrature) force in N (per V² for [`Coupling::PerVoltSquared`]) and its
    /// derivative dF/dd in N/m.
    fn force(&self, d: f64) -> Result<TermForce>;
    /// Real contact area (m²); 0 for non-contact terms.
    fn real_contact_area(&self, d: f64) -> Result<f64> {
        let _ = d;
        Ok(0.0)
    }
    /// Real contact area (m²) and its derivative with respect to `d` (m²/m).
    ///
    /// The default differentiates [`InterfaceTerm::real_contact_area`] by a central difference
    /// (about 1e-10 relative); override it when the derivative is known exactly.
    fn real_contact_area_and_slope(&self, d: f64) -> Result<(f64, f64)> {
        let a = self.real_contact_area(d)?;
        let h = 1e-6 * d.abs().max(1e-10);
        let slope = (self.real_contact_area(d + h)? - self.real_contact_area(d - h)?) / (2.0 * h);
        Ok((a, slope))
    }
    /// Whether the term contributes a real contact area (by default: contact terms).
    fn has_contact_area(&self) -> bool {
        self.kind() == TermKind::Contact
    }
    /// Separations where the force or its derivative is not smooth (for example the cutoff of a
    /// smooth surface). Tables are split there instead of being refined across a kink.
    fn kinks(&self) -> Vec<f64> {
        Vec::new()
    }
}

/// A term's value and slope at `d`, computed by `eval`: an error when `d` is not finite, or when
/// parameters too large for `f64` made them overflow (±∞ or NaN): no term returns a non-finite
/// result as `Ok`.
pub(crate) fn finite_eval(
    name: &str,
    what: &str,
    d: f64,
    eval: impl FnOnce() -> Result<(f64, f64)>,
) -> Result<(f64, f64)> {
    if !d.is_finite() {
        return Err(crate::Error::invalid(
            "d",
            format!("must be finite, got {d}"),
        ));
    }
    let r = eval()?;
    if r.0.is_finite() && r.1.is_finite() {
        Ok(r)
    } else {
        Err(crate::Error::invalid(
            name,
            format!(
                "the {what} at d = {d:e} m overflows ({}, slope {}): the term's parameters are too large",
                r.0, r.1
            ),
        ))
    }
}
