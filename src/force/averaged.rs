//! Non-contact terms: a pressure law averaged over Gaussian surface heights (points with local gap
//! below the cutoff excluded) and integrated over a footprint, by one-dimensional quadrature.

use std::f64::consts::PI;

use statrs::function::erf::erfc;

use super::term::finite_eval;
use super::{
    Coupling, Footprint, GapReference, InterfaceTerm, PressureLaw, Scaled, TermForce, TermKind,
};
use crate::error::check_positive;
use crate::quadrature::{integrate_with_breaks, QuadOptions};
use crate::surface::GaussianHeights;
use crate::{Error, Result};

/// Half-width of the Gaussian window in units of σ: exp(−40²/2) ≈ 1e-348 underflows, so nothing
/// outside contributes even against the 1/h⁹ growth of the repulsive law.
const WINDOW_SIGMAS: f64 = 40.0;

/// Gauss–Legendre nodes (positive half) and weights, 8 points on [−1, 1].
const GAUSS_LEGENDRE_8: [(f64, f64); 4] = [
    (0.183_434_642_495_65, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887),
    (0.796_666_477_413_627, 0.222_381_034_453_374),
    (0.960_289_856_497_536, 0.101_228_536_290_376),
];

/// Relative tolerance of the direct quadrature: three decades below the default table tolerance,
/// so that quadrature noise does not disturb the table builder.
const QUAD_REL_TOL: f64 = 1e-12;

/// A [`PressureLaw`] averaged over surface heights and integrated over a [`Footprint`].
///
/// With Gaussian heights of standard deviation σ and cutoff `h_c` (points closer than `h_c` are in
/// contact and excluded) the mean pressure is `p̄(d) = ∫_{h_c}^∞ p(h) φ_σ(d − h) dh`. A flat
/// footprint gives `F = area · p̄(d)`; a paraboloid gives the Derjaguin integral
/// `F = 2π Rc ∫_d^{d+Δ} p̄(s) ds`, evaluated as a single integral through the interaction energy
/// `W` (see `docs/model.md`). σ = 0 is evaluated in closed form.
///
/// ```
/// use hdi_tribology::force::{AveragedTerm, Coupling, Coulomb, Footprint, GapReference, InterfaceTerm, TermKind};
/// use hdi_tribology::surface::GaussianHeights;
/// # fn main() -> hdi_tribology::Result<()> {
/// let plate = Footprint::Flat { area_m2: 1e-8 };
/// let t = AveragedTerm::new("plates", TermKind::Electrostatic, Coupling::PerVoltSquared,
///     Coulomb::new(0.0)?, 1e-10, GaussianHeights::new(0.0)?, plate, GapReference::Bulge)?;
/// let f = t.force(5e-9)?.value;
/// let exact = -hdi_tribology::units::EPSILON_0 * 1e-8 / (2.0 * 25e-18);
/// assert!((f - exact).abs() < 1e-14 * exact.abs());
/// # Ok(()) }
/// ```
#[derive(Clone, Debug)]
pub struct AveragedTerm<L> {
    name: String,
    kind: TermKind,
    coupling: Coupling,
    law: L,
    cutoff: f64,
    sigma: f64,
    footprint: Footprint,
    gap: GapReference,
}

impl<L: PressureLaw> AveragedTerm<L> {
    /// Builds the term; `cutoff` (m, > 0) is the local gap below which points count as in
    /// contact, `heights` the surface-height statistics.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        name: impl Into<String>,
        kind: TermKind,
        coupling: Coupling,
        law: L,
        cutoff: f64,
        heights: GaussianHeights,
        footprint: Footprint,
        gap: GapReference,
    ) -> Result<Self> {
        check_positive("cutoff_m", cutoff)?;
        footprint.validate("footprint")?;
        let sigma = heights.sigma();
        if !(sigma.is_finite() && sigma >= 0.0) {
            return Err(Error::invalid(
                "height_sigma_m",
                format!("must be finite and >= 0, got {sigma}"),
            ));
        }
        for (what, v) in [
            ("pressure", law.pressure(cutoff)),
            ("energy", law.energy(cutoff)),
        ] {
            if !v.is_finite() {
                return Err(Error::invalid(
                    "cutoff_m",
                    format!("the {what} of the law is not finite at the cutoff {cutoff} m"),
                ));
            }
        }
        Ok(AveragedTerm {
            name: name.into(),
            kind,
            coupling,
            law,
            cutoff,
            sigma,
            footprint,
            gap,
        })
    }

    /// The pressure law.
    pub fn law(&self) -> &L {
        &self.law
    }

    /// The cutoff `h_c`, m.
    pub fn cutoff(&self) -> f64 {
        self.cutoff
    }

    /// Standard deviation of the surface heights, m.
    pub fn sigma(&self) -> f64 {
        self.sigma
    }

    /// The footprint.
    pub fn footprint(&self) -> Footprint {
        self.footprint
    }

    fn gauss(&self, x: f64) -> f64 {
        let s = self.sigma;
        (-0.5 * (x / s) * (x / s)).exp() / (s * (2.0 * PI).sqrt())
    }

    /// `∫_{h_c}^∞ k(h) φ_σ(d − h) dh` for σ > 0.
    /// `part` selects the kernel's entry of [`PressureLaw::magnitudes`] (0: p, 1: p', 2: W).
    fn weighted(&self, d: f64, kernel: impl Fn(f64) -> f64, part: usize) -> Result<f64> {
        let (s, hc) = (self.sigma, self.cutoff);
        // Integrate over the offset u = h − d from the Gaussian's centre: the Gaussian argument is
        // then exact however large d is against σ (with h itself as variable, rounding of d − h
        // would jitter the weight when d/σ is large).
        let a = (hc - d).max(-WINDOW_SIGMAS * s);
        let b = WINDOW_SIGMAS * s;
        if b <= a {
            return Ok(0.0);
        }
        let mut breaks: Vec<f64> = [
            -8.0 * s,
            -2.0 * s,
            0.0,
            2.0 * s,
            8.0 * s,
            1.5 * hc - d,
            2.0 * hc - d,
            4.0 * hc - d,
        ]
        .into_iter()
        .filter(|&x| x > a && x < b)
        .collect();
        breaks.sort_by(f64::total_cmp);
        breaks.dedup();
        let integrand = |u: f64| kernel(d + u) * self.gauss(u);
        // The size of the largest contributions sets the absolute tolerance: where positive and
        // negative parts cancel (a force passing through zero, the slope of the 3–9 law) rounding
        // limits the accuracy to about 1e-16 of them, so relative accuracy alone is unreachable.
        let scale = std::iter::once(a)
            .chain(breaks.iter().copied())
            .map(|u| (self.law.magnitudes(d + u)[part] * self.gauss(u) * s).abs())
            .fold(0.0, f64::max);
        if scale == 0.0 {
            return Ok(0.0);
        }
        let opts = QuadOptions {
            // (floored far above the subnormals, where no relative accuracy exists)
            abs_tol: (1e-14 * scale).max(1e-290),
            rel_tol: QUAD_REL_TOL,
            max_intervals: 2000,
        };
        let est = integrate_with_breaks(integrand, a, b, &breaks, &opts).map_err(|e| {
            Error::from(super::ForceError::Quadrature {
                term: self.name.clone(),
                d_nm: d * 1e9,
                source: e.into(),
            })
        })?;
        Ok(est.value)
    }

    /// Mean pressure `p̄(d)`, Pa.
    pub fn mean_pressure(&self, d: f64) -> Result<f64> {
        if self.sigma == 0.0 {
            return Ok(if d >= self.cutoff {
                self.law.pressure(d)
            } else {
                0.0
            });
        }
        self.weighted(d, |h| self.law.pressure(h), 0)
    }

    /// `dp̄/dd`, Pa/m.
    pub fn mean_pressure_slope(&self, d: f64) -> Result<f64> {
        let hc = self.cutoff;
        if self.sigma == 0.0 {
            return Ok(if d >= hc {
                self.law.pressure_slope(d)
            } else {
                0.0
            });
        }
        let edge = self.gauss(d - hc) * self.law.pressure(hc);
        Ok(edge + self.weighted(d, |h| self.law.pressure_slope(h), 1)?)
    }

    /// `∫_d^∞ p̄(s) ds = W(h_c) Φc((d − h_c)/σ) + ∫_{h_c}^∞ W(h) φ_σ(d − h) dh`, J/m².
    pub fn mean_energy(&self, d: f64) -> Result<f64> {
        let hc = self.cutoff;
        if self.sigma == 0.0 {
            return Ok(self.law.energy(d.max(hc)));
        }
        let survival = 0.5 * erfc((d - hc) / (self.sigma * std::f64::consts::SQRT_2));
        Ok(self.law.energy(hc) * survival + self.weighted(d, |h| self.law.energy(h), 2)?)
    }
}

impl<L: PressureLaw> InterfaceTerm for AveragedTerm<L> {
    fn name(&self) -> &str {
        &self.name
    }
    fn kind(&self) -> TermKind {
        self.kind
    }
    fn coupling(&self) -> Coupling {
        self.coupling
    }
    fn gap(&self) -> GapReference {
        self.gap
    }
    fn force(&self, d: f64) -> Result<TermForce> {
        finite_eval(self.name(), "force", d, || {
            self.footprint.reduce(
                1.0,
                || {
                    Ok((
                        self.mean_pressure(d)?.into(),
                        self.mean_pressure_slope(d)?.into(),
                    ))
                },
                |delta| {
                    if delta.is_infinite() {
                        Ok((self.mean_energy(d)?.into(), self.mean_pressure(d)?.into()))
                    } else if self.sigma > 0.0 && delta < 0.1 * self.sigma {
                        // A band much thinner than σ: I(d) − I(d + Δ) would cancel; p̄ is smooth on
                        // the scale σ, so 8-point Gauss–Legendre over the band is exact to
                        // ~(Δ/2σ)¹⁶.
                        let (mid, half) = (d + 0.5 * delta, 0.5 * delta);
                        let mut f = 0.0;
                        for (x, w) in GAUSS_LEGENDRE_8 {
                            f += w
                                * (self.mean_pressure(mid - half * x)?
                                    + self.mean_pressure(mid + half * x)?);
                        }
                        let df = self.mean_pressure(d)? - self.mean_pressure(d + delta)?;
                        Ok((Scaled::new(half, f), df.into()))
                    } else {
                        let f = self.mean_energy(d)? - self.mean_energy(d + delta)?;
                        let df = self.mean_pressure(d)? - self.mean_pressure(d + delta)?;
                        Ok((f.into(), df.into()))
                    }
                },
            )
        })
        .map(TermForce::from)
    }
    fn kinks(&self) -> Vec<f64> {
        // With roughness the cutoff is smeared over σ and the force is smooth on the scale of the
        // table. Only a smooth or nearly smooth surface (σ below 1 % of h_c) has a kink (or, flat,
        // a jump) at h_c, smeared over ±40σ at most: cut there, and at the edges of that window so
        // that the narrow transition is tabulated on its own scale.
        if self.sigma >= 0.01 * self.cutoff {
            return Vec::new();
        }
        let w = WINDOW_SIGMAS * self.sigma;
        let mut centres = vec![self.cutoff];
        let delta = self.footprint.derjaguin_depth();
        if delta > 0.0 && delta.is_finite() {
            centres.push(self.cutoff - delta);
        }
        let mut k = Vec::new();
        for c in centres {
            k.push(c);
            if w > 0.0 {
                k.extend([c - w, c + w]);
            }
        }
        k
    }
}

/// Implements [`InterfaceTerm`] for a term that wraps an [`AveragedTerm`] in its field `inner`,
/// forwarding every method.
macro_rules! forward_term {
    ($term:ty) => {
        impl $crate::force::InterfaceTerm for $term {
            fn name(&self) -> &str {
                self.inner.name()
            }
            fn kind(&self) -> $crate::force::TermKind {
                self.inner.kind()
            }
            fn coupling(&self) -> $crate::force::Coupling {
                self.inner.coupling()
            }
            fn gap(&self) -> $crate::force::GapReference {
                self.inner.gap()
            }
            fn force(&self, d: f64) -> $crate::Result<$crate::force::TermForce> {
                self.inner.force(d)
            }
            fn real_contact_area(&self, d: f64) -> $crate::Result<f64> {
                self.inner.real_contact_area(d)
            }
            fn real_contact_area_and_slope(&self, d: f64) -> $crate::Result<(f64, f64)> {
                self.inner.real_contact_area_and_slope(d)
            }
            fn has_contact_area(&self) -> bool {
                self.inner.has_contact_area()
            }
            fn kinks(&self) -> Vec<f64> {
                self.inner.kinks()
            }
        }
    };
}
pub(crate) use forward_term;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::force::LennardJones39;

    /// The footprint reduction as each term wrote it out before [`Footprint::reduce`] held it.
    fn written_out<L: PressureLaw>(t: &AveragedTerm<L>, d: f64) -> (f64, f64) {
        let (p, e) = (
            |s: f64| t.mean_pressure(s).unwrap(),
            |s: f64| t.mean_energy(s).unwrap(),
        );
        match t.footprint {
            Footprint::Flat { area_m2 } => {
                (area_m2 * p(d), area_m2 * t.mean_pressure_slope(d).unwrap())
            }
            Footprint::Paraboloid {
                radius_of_curvature_m,
                ..
            } => {
                let c = 2.0 * PI * radius_of_curvature_m;
                let delta = t.footprint.derjaguin_depth();
                if delta.is_infinite() {
                    (c * e(d), -c * p(d))
                } else if t.sigma > 0.0 && delta < 0.1 * t.sigma {
                    let (mid, half) = (d + 0.5 * delta, 0.5 * delta);
                    let mut f = 0.0;
                    for (x, w) in GAUSS_LEGENDRE_8 {
                        f += w * (p(mid - half * x) + p(mid + half * x));
                    }
                    (c * half * f, -c * (p(d) - p(d + delta)))
                } else {
                    (c * (e(d) - e(d + delta)), -c * (p(d) - p(d + delta)))
                }
            }
        }
    }

    #[test]
    fn the_footprint_reduction_gives_the_written_out_numbers_to_the_bit() {
        for sigma in [0.0, 0.7e-9] {
            for footprint in Footprint::samples() {
                let t = AveragedTerm::new(
                    "lj",
                    TermKind::Intermolecular,
                    Coupling::Static,
                    LennardJones39::new(1e-19, 1e-76).unwrap(),
                    2e-10,
                    GaussianHeights::new(sigma).unwrap(),
                    footprint,
                    GapReference::Bulge,
                )
                .unwrap();
                for d in [1e-10, 4e-10, 1.3e-9, 5e-9] {
                    let f = t.force(d).unwrap();
                    let (value, slope) = written_out(&t, d);
                    assert_eq!(
                        (f.value.to_bits(), f.slope.to_bits()),
                        (value.to_bits(), slope.to_bits()),
                        "σ = {sigma}, {footprint:?}, d = {d}"
                    );
                }
            }
        }
    }
}
