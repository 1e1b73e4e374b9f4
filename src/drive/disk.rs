//! The disk surface under the head: axial run-out and waviness, once per revolution.

use super::rng::Rng;
use crate::error::{check_finite, check_non_negative, check_positive, Error, Result};
use std::f64::consts::PI;

/// One fixed harmonic of the disk surface per revolution: `a sin(n θ + φ)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Harmonic {
    /// Order `n` (cycles per revolution, ≥ 1).
    pub order: u32,
    /// Amplitude `a` (m).
    pub amplitude: f64,
    /// Phase `φ` (rad).
    pub phase: f64,
}

/// What the disk surface does under the head, per revolution.
///
/// The surface height is `w(θ) = Σ a_n sin(n θ + φ_n)` with `θ = 2π rpm t / 60` (the zone's
/// spindle speed): the fixed
/// `harmonics` (the once-around run-out is order 1) plus `random_orders.0 ..= random_orders.1`
/// harmonics of seeded random amplitude (normal, with a `1/n` spectrum scaled so that their sum
/// has root-mean-square height `random_rms`) and uniform phase.
///
/// ```
/// use hdi_tribology::drive::DiskSpec;
/// let d = DiskSpec::default();
/// assert_eq!(d.harmonics[0].order, 1);
/// assert!(d.random_rms > 0.0);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct DiskSpec {
    /// Fixed harmonics (run-out and known waviness).
    pub harmonics: Vec<Harmonic>,
    /// Root-mean-square height of the random waviness (m, ≥ 0).
    pub random_rms: f64,
    /// Lowest and highest order of the random waviness.
    pub random_orders: (u32, u32),
}

impl Default for DiskSpec {
    /// Illustrative defaults: 1 µm once-around axial run-out and 0.3 nm (rms) of random
    /// waviness in orders 20–400 (at 5400 rpm, 1.8–36 kHz: below the air-bearing mode of the
    /// paper scene, 87 kHz, so the slider follows most of it).
    fn default() -> Self {
        DiskSpec {
            harmonics: vec![Harmonic {
                order: 1,
                amplitude: 1e-6,
                phase: 0.0,
            }],
            random_rms: 0.3e-9,
            random_orders: (20, 400),
        }
    }
}

impl DiskSpec {
    /// A perfectly flat disk (no run-out, no waviness).
    pub fn flat() -> Self {
        DiskSpec {
            harmonics: Vec::new(),
            random_rms: 0.0,
            random_orders: (1, 1),
        }
    }

    pub(crate) fn validate(&self) -> Result<()> {
        for (i, h) in self.harmonics.iter().enumerate() {
            if h.order == 0 {
                return Err(Error::invalid(
                    format!("disk.harmonics[{i}].order"),
                    "must be at least 1",
                ));
            }
            check_finite(&format!("disk.harmonics[{i}].amplitude"), h.amplitude)?;
            check_finite(&format!("disk.harmonics[{i}].phase"), h.phase)?;
        }
        check_non_negative("disk.random_rms", self.random_rms)?;
        let (lo, hi) = self.random_orders;
        if self.random_rms > 0.0 && (lo == 0 || hi < lo) {
            return Err(Error::invalid(
                "disk.random_orders",
                format!("needs 1 ≤ lowest ≤ highest, got ({lo}, {hi})"),
            ));
        }
        let top = self
            .harmonics
            .iter()
            .map(|h| h.order)
            .chain((self.random_rms > 0.0).then_some(hi))
            .max()
            .unwrap_or(0);
        if top > MAX_ORDER {
            return Err(Error::invalid(
                "disk.harmonics",
                format!("orders above {MAX_ORDER} per revolution are not resolved, got {top}"),
            ));
        }
        Ok(())
    }
}

/// Highest harmonic order the per-revolution table resolves (16 nodes per period).
const MAX_ORDER: u32 = 512;
pub(crate) const NODES: usize = 16 * MAX_ORDER as usize;

/// The disk surface tabulated once per revolution: height, velocity, acceleration and jerk at
/// evenly spaced angles, interpolated by cubic Hermite polynomials (so a right-hand side costs a
/// table look-up, not a sum of sines).
#[derive(Clone, Debug)]
pub(crate) struct Disk {
    period: f64,
    /// `(w, ẇ, ẅ, w⃛)` at the nodes.
    nodes: Vec<[f64; 4]>,
    flat: bool,
    /// The harmonics summed into the table (nonzero amplitudes only).
    harmonics: Vec<Harmonic>,
    /// The spindle's angular speed (rad/s).
    omega: f64,
}

impl Disk {
    pub(crate) fn new(spec: &DiskSpec, rpm: f64, seed: u64) -> Result<Self> {
        spec.validate()?;
        check_positive("zone rpm", rpm)?;
        let mut all = spec.harmonics.clone();
        if spec.random_rms > 0.0 {
            let mut rng = Rng::new(seed, 0xD15C);
            let (lo, hi) = spec.random_orders;
            let mut raw: Vec<Harmonic> = (lo..=hi)
                .map(|n| Harmonic {
                    order: n,
                    amplitude: rng.normal() / n as f64,
                    phase: 2.0 * PI * rng.uniform(),
                })
                .collect();
            // The mean square of a sum of sines is half the sum of squared amplitudes.
            let ms: f64 = raw.iter().map(|h| 0.5 * h.amplitude * h.amplitude).sum();
            let scale = if ms > 0.0 {
                spec.random_rms / ms.sqrt()
            } else {
                0.0
            };
            for h in &mut raw {
                h.amplitude *= scale;
            }
            all.extend(raw);
        }
        let omega = 2.0 * PI * rpm / 60.0;
        let flat = all.iter().all(|h| h.amplitude == 0.0);
        let mut nodes = vec![[0.0; 4]; if flat { 0 } else { NODES }];
        for h in all.iter().filter(|h| h.amplitude != 0.0) {
            let w = h.order as f64 * omega;
            let d_theta = 2.0 * PI * h.order as f64 / NODES as f64;
            let step = (d_theta.cos(), d_theta.sin());
            let mut z = (0.0, 0.0);
            for (i, v) in nodes.iter_mut().enumerate() {
                // Rotate the phasor node by node; re-anchor it exactly every 64 nodes.
                z = if i % 64 == 0 {
                    let a = d_theta * i as f64 + h.phase;
                    (a.cos(), a.sin())
                } else {
                    (z.0 * step.0 - z.1 * step.1, z.0 * step.1 + z.1 * step.0)
                };
                let (c, s) = z;
                v[0] += h.amplitude * s;
                v[1] += h.amplitude * w * c;
                v[2] -= h.amplitude * w * w * s;
                v[3] -= h.amplitude * w * w * w * c;
            }
        }
        all.retain(|h| h.amplitude != 0.0);
        Ok(Disk {
            period: 60.0 / rpm,
            nodes,
            flat,
            harmonics: all,
            omega,
        })
    }

    /// The node interval holding `t` and the position in it, `s ∈ [0, 1)`.
    /// The harmonics of the surface (those of nonzero amplitude): the height is
    /// `Σ amplitude · sin(order · Ω t + phase)`, `Ω` = [`Disk::omega`].
    pub(crate) fn harmonics(&self) -> &[Harmonic] {
        &self.harmonics
    }

    /// The angular speed of the spindle (rad/s).
    pub(crate) fn omega(&self) -> f64 {
        self.omega
    }

    /// The node of the table at `t`, the fraction of the node interval past it, and the
    /// interval (s): the grid of every table over a revolution ([`NODES`] nodes).
    #[inline]
    pub(crate) fn locate(&self, t: f64) -> (usize, f64, f64) {
        let h = self.period / NODES as f64;
        let x = t / h;
        // `x.floor()` by the integer conversion: the same node and fraction for every finite `x`
        // within ±2⁵³ (and NaN), where `floor` itself is a library call on a baseline x86-64
        // build. `+ 0.0` gives `−0` the floor's `+0` fraction.
        let mut n = x as i64;
        if n as f64 > x {
            n -= 1;
        }
        // Integer wrap (NODES is a power of two): no floating-point remainder per call.
        let i = n.rem_euclid(NODES as i64) as usize;
        (i, (x - n as f64) + 0.0, h)
    }

    /// Cubic Hermite interpolation of component `k` (with its derivative `k + 1`) at `t`:
    /// value and time derivative.
    fn hermite(&self, t: f64, k: usize) -> (f64, f64) {
        if self.flat {
            return (0.0, 0.0);
        }
        let (i, s, h) = self.locate(t);
        let (a, b) = (&self.nodes[i], &self.nodes[(i + 1) % NODES]);
        let (p0, m0, p1, m1) = (a[k], a[k + 1] * h, b[k], b[k + 1] * h);
        let (value, slope) = crate::numerics::cubic_hermite(s, p0, m0, p1, m1);
        (value, slope / h)
    }

    /// Surface acceleration `ẅ(t)` alone (m/s²): the right-hand side's one look-up.
    #[inline]
    pub(crate) fn acceleration_value(&self, t: f64) -> f64 {
        if self.flat {
            return 0.0;
        }
        let (i, s, h) = self.locate(t);
        let (a, b) = (&self.nodes[i], &self.nodes[(i + 1) % NODES]);
        let (p0, m0, p1, m1) = (a[2], a[3] * h, b[2], b[3] * h);
        // Horner form of the same cubic Hermite polynomial.
        let d = p1 - p0;
        p0 + s * (m0 + s * (3.0 * d - 2.0 * m0 - m1 + s * (m0 + m1 - 2.0 * d)))
    }

    /// Surface height `w(t)` (m) and its rate (m/s).
    pub(crate) fn height(&self, t: f64) -> (f64, f64) {
        self.hermite(t, 0)
    }

    /// Surface acceleration `ẅ(t)` (m/s²) and jerk (m/s³).
    pub(crate) fn acceleration(&self, t: f64) -> (f64, f64) {
        self.hermite(t, 2)
    }

    pub(crate) fn is_flat(&self) -> bool {
        self.flat
    }
}

impl crate::model::BaseMotion for Disk {
    fn acceleration(&self, t: f64) -> (f64, f64) {
        Disk::acceleration(self, t)
    }
    #[inline]
    fn acceleration_value(&self, t: f64) -> f64 {
        Disk::acceleration_value(self, t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_located_node_is_the_floors_to_the_bit() {
        let disk = Disk::new(&DiskSpec::default(), 7200.0, 1).unwrap();
        let h = disk.period / NODES as f64;
        let mut ts = vec![
            0.0,
            -0.0,
            h,
            -h,
            3.0 * h,
            1e-300,
            -1e-300,
            1e4,
            -1e4,
            0.5 * h,
        ];
        ts.extend((0..2000).map(|j| (j as f64 - 1000.0) * 0.37e-5 + 1e-3 * (j as f64).sin()));
        for t in ts {
            let x = t / h;
            let k = x.floor();
            let want = ((k as i64).rem_euclid(NODES as i64) as usize, x - k);
            let (i, s, _) = disk.locate(t);
            assert_eq!((i, s.to_bits()), (want.0, want.1.to_bits()), "t = {t:e}");
        }
    }

    #[test]
    fn table_matches_the_sum_of_sines() {
        let spec = DiskSpec {
            harmonics: vec![
                Harmonic {
                    order: 1,
                    amplitude: 1e-6,
                    phase: 0.3,
                },
                Harmonic {
                    order: 300,
                    amplitude: 1e-9,
                    phase: 1.0,
                },
            ],
            random_rms: 0.0,
            random_orders: (1, 1),
        };
        let disk = Disk::new(&spec, 7200.0, 1).unwrap();
        let om = 2.0 * PI * 7200.0 / 60.0;
        for j in 0..500 {
            let t = j as f64 * 3.7e-6;
            let exact: f64 = spec
                .harmonics
                .iter()
                .map(|h| {
                    let w = h.order as f64 * om;
                    -h.amplitude * w * w * (w * t + h.phase).sin()
                })
                .sum();
            let amp = 1e-9 * (300.0 * om).powi(2);
            assert!(
                (disk.acceleration(t).0 - exact).abs() < 2e-4 * amp,
                "t = {t}"
            );
            let w_exact: f64 = spec
                .harmonics
                .iter()
                .map(|h| h.amplitude * (h.order as f64 * om * t + h.phase).sin())
                .sum();
            assert!((disk.height(t).0 - w_exact).abs() < 1e-13);
        }
    }

    #[test]
    fn acceleration_value_is_the_hermite_value() {
        let d = Disk::new(&DiskSpec::default(), 7200.0, 3).unwrap();
        for j in 0..2000 {
            let t = -0.01 + j as f64 * 1.37e-5;
            let (a, b) = (d.acceleration(t).0, d.acceleration_value(t));
            assert!((a - b).abs() <= 1e-12 * a.abs().max(1.0), "{t}: {a} vs {b}");
        }
    }

    #[test]
    fn random_waviness_has_its_rms() {
        let spec = DiskSpec {
            harmonics: vec![],
            ..DiskSpec::default()
        };
        let disk = Disk::new(&spec, 5400.0, 42).unwrap();
        let n = 20_000;
        let ms: f64 = (0..n)
            .map(|i| disk.height(i as f64 * disk.period / n as f64).0.powi(2))
            .sum::<f64>()
            / n as f64;
        assert!(
            (ms.sqrt() / spec.random_rms - 1.0).abs() < 1e-3,
            "{}",
            ms.sqrt()
        );
    }
}
