//! The attitude solve: the fly height, pitch and roll at which the air bearing's force and
//! moments about the pivot balance the preload and the static torques; and what follows from
//! the equilibrium (spacings, stiffness, damping, a force–spacing curve).
//!
//! Newton's method on the three balances, with the Jacobian from the pressure's sensitivities
//! (one linear solve per attitude coordinate with the factored Jacobian of the converged
//! pressure), on a sequence of grids from coarse to fine: each grid starts from the coarser
//! one's attitude and interpolated pressure.

use nalgebra::{Matrix3, Vector3};

use super::error::BearingError;
use super::geometry::Bearing;
use super::grid::nudged;
use super::reynolds::{Attitude, Factored, Interrupt, Reynolds, REFERENCE_SPACING};
use crate::{Error, Result};

/// The smallest spacing the attitude solve lets the slider reach, m: a bearing that does not
/// carry its preload above it does not fly.
pub const SPACING_FLOOR: f64 = 0.5e-9;
/// The coarsest grid of the sequence has at least this many control volumes along a side.
const COARSEST: usize = 24;
/// Relative tolerance of the force and moment balances on the coarser grids.
const COARSE_TOLERANCE: f64 = 1e-4;
/// Largest fraction of the smallest spacing one Newton step may take away.
const MAX_CLOSING: f64 = 0.6;
/// Relative tolerance of the linear solves for the sensitivities that steer Newton's steps.
const STEP_SENSITIVITY_RTOL: f64 = 1e-6;
/// Relative tolerance of the linear solves for the stiffness at the equilibrium.
const FINAL_SENSITIVITY_RTOL: f64 = 1e-8;
/// The Jacobian in use is kept while each step cuts the imbalance by at least this factor.
const FAST_CONVERGENCE: f64 = 0.2;
/// The pressure of an attitude step is solved to this fraction of the last imbalance (on the
/// largest change of `p/p_a` in a Newton step).
const PRESSURE_TOLERANCE_RATIO: f64 = 1e-3;
/// `2^p − 1` for the observed order `p = 2` of the discretisation: the attitude of the next
/// grid is extrapolated as `q + (q − q_coarser) / 3`.
const EXTRAPOLATION: f64 = 3.0;
/// Floor of the extrapolated start pressure, `p/p_a`.
const MIN_START_PRESSURE: f64 = 0.05;

/// Options of the attitude solve.
///
/// ```
/// use hdi_tribology::bearing::AttitudeOptions;
/// let o = AttitudeOptions::default();
/// assert!(o.tolerance < 1e-6);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct AttitudeOptions {
    /// Where Newton starts on the coarsest grid.
    pub start: Attitude,
    /// Relative tolerance of the balances (force over the preload; moments over preload × L).
    pub tolerance: f64,
    /// Newton steps allowed per grid.
    pub max_iterations: usize,
    /// Solve on coarser grids first.
    pub coarse_to_fine: bool,
    /// Asked between the linear solves whether to stop; kept by the [`Equilibrium`]'s
    /// equation, so that its damping and curves stop too.
    pub interrupt: Option<Interrupt>,
}

impl Default for AttitudeOptions {
    fn default() -> Self {
        AttitudeOptions {
            start: Attitude {
                fly_height: 15e-9,
                pitch: 150e-6,
                roll: 0.0,
            },
            tolerance: 1e-9,
            max_iterations: 40,
            coarse_to_fine: true,
            interrupt: None,
        }
    }
}

/// How the solve went on one grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LevelReport {
    /// Control volumes `(nx, ny)`.
    pub cells: (usize, usize),
    /// Newton steps of the attitude.
    pub iterations: usize,
    /// Newton steps of the pressure, summed over the attitude's steps.
    pub pressure_iterations: usize,
    /// GMRES iterations, summed (pressure and sensitivities).
    pub krylov_iterations: usize,
    /// Largest relative imbalance at the end.
    pub imbalance: f64,
}

/// The equilibrium attitude and what follows from it.
#[derive(Clone, Debug)]
pub struct Equilibrium {
    /// The attitude.
    pub attitude: Attitude,
    /// The bearing's force (N) and moments about the pivot (N m), pitch and roll.
    pub loads: [f64; 3],
    /// Pressure `p/p_a` per control volume, index `j nx + i`.
    pub pressure: Vec<f64>,
    /// The equation on the final grid.
    pub reynolds: Reynolds,
    /// The solve on each grid, coarse to fine.
    pub levels: Vec<LevelReport>,
    /// Jacobian of the loads in the attitude at the equilibrium: `[i][j] = ∂load_i/∂q_j`.
    pub load_jacobian: [[f64; 3]; 3],
    spacing: Vec<f64>,
    factored: Factored,
    dps: [Vec<f64>; 3],
}

fn imbalance(b: &Bearing, loads: [f64; 3]) -> Vector3<f64> {
    let f = b.preload;
    Vector3::new(
        (loads[0] - f) / f,
        (loads[1] - b.pitch_torque) / (f * b.length),
        (loads[2] - b.roll_torque) / (f * b.length),
    )
}

/// What one grid's solve hands on.
struct LevelResult {
    attitude: Attitude,
    report: LevelReport,
    factored: Factored,
    dps: [Vec<f64>; 3],
    jacobian: [[f64; 3]; 3],
    spacing: Vec<f64>,
}

/// What a coarser grid hands to the next: its load Jacobian, and its pressure derivatives
/// interpolated onto the next grid.
struct Coarser {
    jacobian: [[f64; 3]; 3],
    dps: [Vec<f64>; 3],
}

/// One Newton solve of the attitude on one grid; `p` is the start and the result. The load
/// Jacobian of a coarser grid, if any, steers the steps until they stop converging fast, when
/// the sensitivities on this grid replace it; their linear solves start from the coarser grid's
/// pressure derivatives.
fn solve_level(
    r: &Reynolds,
    start: Attitude,
    p: &mut [f64],
    tol: f64,
    max_iterations: usize,
    final_level: bool,
    coarser: Option<Coarser>,
) -> Result<LevelResult> {
    let b = &r.bearing;
    let mut att = start;
    let mut report = LevelReport {
        cells: r.size(),
        iterations: 0,
        pressure_iterations: 0,
        krylov_iterations: 0,
        imbalance: f64::INFINITY,
    };
    let (mut jac, guess) = match coarser {
        Some(c) => (Some(c.jacobian), Some(c.dps)),
        None => (None, None),
    };
    let mut dps: Option<[Vec<f64>; 3]> = None;
    // Where the linear solves of the sensitivities start: the last ones on this grid, or the
    // coarser grid's interpolated.
    let n = p.len();
    let mut guess = guess
        .filter(|g| g.iter().all(|d| d.len() == n))
        .unwrap_or_else(|| [vec![0.0; n], vec![0.0; n], vec![0.0; n]]);
    let mut last = f64::INFINITY;
    loop {
        let h = r.spacing(&att);
        // Far from the balance the pressure need not be exact: solve it to a tolerance that
        // follows the imbalance, and to the full tolerance once the balance is near.
        let ptol = (PRESSURE_TOLERANCE_RATIO * last.min(1.0)).clamp(r.tolerance, COARSE_TOLERANCE);
        let (mut stats, mut fac) = r.solve_spacing_to(&h, p, ptol)?;
        let mut loads = r.loads(p);
        let mut f = imbalance(b, loads);
        report.imbalance = f.amax();
        if report.imbalance <= tol.max(ptol) && ptol > r.tolerance {
            // Balanced within the pressure's own tolerance: finish the pressure, then judge.
            let (s2, f2) = r.solve_spacing(&h, p)?;
            stats.iterations += s2.iterations;
            stats.krylov_iterations += s2.krylov_iterations;
            fac = f2;
            loads = r.loads(p);
            f = imbalance(b, loads);
            report.imbalance = f.amax();
        }
        report.pressure_iterations += stats.iterations;
        report.krylov_iterations += stats.krylov_iterations;
        if report.imbalance <= tol {
            let rtol = if final_level {
                FINAL_SENSITIVITY_RTOL
            } else {
                STEP_SENSITIVITY_RTOL
            };
            let start = dps.unwrap_or(guess);
            let (k, d, its) = r.sensitivities_from(p, &h, &fac, rtol, start)?;
            report.krylov_iterations += its;
            return Ok(LevelResult {
                attitude: att,
                report,
                factored: fac,
                dps: d,
                jacobian: k,
                spacing: h,
            });
        }
        if report.iterations >= max_iterations {
            return Err(BearingError::AttitudeNewton {
                iterations: report.iterations,
                nx: report.cells.0,
                ny: report.cells.1,
                imbalance: report.imbalance,
            }
            .into());
        }
        if jac.is_none() || report.imbalance > FAST_CONVERGENCE * last {
            let start = match dps.take() {
                Some(d) => d,
                None => std::mem::take(&mut guess),
            };
            let (k, d, its) = r.sensitivities_from(p, &h, &fac, STEP_SENSITIVITY_RTOL, start)?;
            report.krylov_iterations += its;
            jac = Some(k);
            dps = Some(d);
        }
        last = report.imbalance;
        let k = jac.expect("the Jacobian is set above");
        report.iterations += 1;
        // Jacobian of the scaled imbalance.
        let fl = b.preload * b.length;
        let jm = Matrix3::from_fn(|i, j| k[i][j] / if i == 0 { b.preload } else { fl });
        let step = jm
            .lu()
            .solve(&(-f))
            .ok_or_else(|| Error::from(BearingError::SingularStiffness))?;
        let q = att.to_array();
        let at = |t: f64| {
            Attitude::from_array([q[0] + t * step[0], q[1] + t * step[1], q[2] + t * step[2]])
        };
        let hmin = r.min_spacing(&att);
        let mut t = 1.0;
        let mut next = at(t);
        for _ in 0..60 {
            next = at(t);
            let m = r.min_spacing(&next);
            if m >= (1.0 - MAX_CLOSING) * hmin && m >= SPACING_FLOOR {
                break;
            }
            if hmin <= SPACING_FLOOR * (1.0 + 1e-6) && loads[0] < b.preload {
                return Err(BearingError::DoesNotFly {
                    preload_mn: b.preload * 1e3,
                    load_mn: loads[0] * 1e3,
                    min_spacing_nm: hmin * 1e9,
                }
                .into());
            }
            t *= 0.5;
            if r.min_spacing(&at(t)) < SPACING_FLOOR && t < 1e-3 {
                // Close in on the floor along the step.
                let (mut lo, mut hi) = (0.0, t);
                for _ in 0..50 {
                    let mid = 0.5 * (lo + hi);
                    if r.min_spacing(&at(mid)) >= SPACING_FLOOR {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                next = at(lo);
                break;
            }
        }
        // First-order predictor of the pressure at the new attitude.
        if let Some(d) = &dps {
            let dq = [
                next.fly_height - att.fly_height,
                next.pitch - att.pitch,
                next.roll - att.roll,
            ];
            for c in 0..p.len() {
                let v = p[c] + d[0][c] * dq[0] + d[1][c] * dq[1] + d[2][c] * dq[2];
                p[c] = v.max(0.5 * p[c]);
            }
        }
        att = next;
    }
}

/// Solves for the equilibrium attitude of `bearing` on its grid (`bearing.grid`).
///
/// A bearing that cannot carry the preload above [`SPACING_FLOOR`] gives
/// [`BearingError::DoesNotFly`].
///
/// ```
/// use hdi_tribology::bearing::{solve_attitude, AttitudeOptions, BearingSpec};
/// let spec = BearingSpec::from_path(concat!(
///     env!("CARGO_MANIFEST_DIR"),
///     "/scenes/bearing/two_rail_taper_flat.toml"
/// ))?;
/// let mut spec = spec;
/// spec.grid.nx = 65;
/// spec.grid.ny = 65;
/// let eq = solve_attitude(&spec.build()?, &AttitudeOptions::default())?;
/// assert!(eq.attitude.fly_height > 1e-9 && eq.attitude.pitch > 0.0);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn solve_attitude(bearing: &Bearing, opts: &AttitudeOptions) -> Result<Equilibrium> {
    let (nx, ny) = (bearing.grid.nx, bearing.grid.ny);
    let mut sizes = vec![(nx, ny)];
    if opts.coarse_to_fine {
        let (mut a, mut c) = (nx, ny);
        while a.min(c) / 2 >= COARSEST {
            a = a / 2 + 1;
            c = c / 2 + 1;
            sizes.push((a, c));
        }
    }
    sizes.reverse();
    let mut att = opts.start;
    let mut prev: Option<(Reynolds, Vec<f64>, [Vec<f64>; 3])> = None;
    let mut before: Option<Attitude> = None;
    let mut jac = None;
    let mut levels = Vec::new();
    let last = sizes.len() - 1;
    for (k, &(a, c)) in sizes.iter().enumerate() {
        let mut r = Reynolds::new(bearing, a, c);
        r.interrupt = opts.interrupt.clone();
        let mut p = match &prev {
            Some((rc, pc, _)) => r.interpolate_from(rc, pc),
            None => r.ambient(),
        };
        // The coarser grid's pressure derivatives on this grid: where the sensitivities' linear
        // solves start, and the first-order move of the pressure below.
        let coarse_dps: Option<[Vec<f64>; 3]> = prev
            .as_ref()
            .map(|(rc, _, d)| std::array::from_fn(|i| r.interpolate_from(rc, &d[i])));
        // From the third grid on, start from the attitude extrapolated from the two coarser
        // grids (second-order convergence: the error falls fourfold per halving), and move the
        // interpolated pressure there to first order.
        let mut start = att;
        if let (Some(b0), Some(dps)) = (before, &coarse_dps) {
            let q = att.to_array();
            let q0 = b0.to_array();
            let ext: [f64; 3] = std::array::from_fn(|i| q[i] + (q[i] - q0[i]) / EXTRAPOLATION);
            let moved = Attitude::from_array(ext);
            if r.min_spacing(&moved) > 0.5 * r.min_spacing(&att) {
                for (i, di) in dps.iter().enumerate() {
                    let dq = ext[i] - q[i];
                    for (pc, dc) in p.iter_mut().zip(di) {
                        *pc += dc * dq;
                    }
                }
                for pc in p.iter_mut() {
                    *pc = pc.max(MIN_START_PRESSURE);
                }
                start = moved;
            }
        }
        let tol = if k == last {
            opts.tolerance
        } else {
            COARSE_TOLERANCE.max(opts.tolerance)
        };
        let res = solve_level(
            &r,
            start,
            &mut p,
            tol,
            opts.max_iterations,
            k == last,
            jac.zip(coarse_dps)
                .map(|(jacobian, dps)| Coarser { jacobian, dps }),
        )?;
        before = Some(att);
        att = res.attitude;
        jac = Some(res.jacobian);
        levels.push(res.report);
        if k == last {
            let loads = r.loads(&p);
            return Ok(Equilibrium {
                attitude: att,
                loads,
                pressure: p,
                reynolds: r,
                levels,
                load_jacobian: res.jacobian,
                spacing: res.spacing,
                factored: res.factored,
                dps: res.dps,
            });
        }
        prev = Some((r, p, res.dps));
    }
    unreachable!("the grid sequence is never empty")
}

impl Equilibrium {
    /// Spacing at a point `(x, y)` (m), the surface's depth included.
    pub fn spacing_at(&self, x: f64, y: f64) -> f64 {
        let b = &self.reynolds.bearing;
        let (xi, yi) = nudged(b, x, y);
        self.attitude.spacing_at(x, y, b.length, b.width) + b.depth_at(xi, yi)
    }

    /// Spacing at the trailing edge's centre (m).
    pub fn trailing_edge_spacing(&self) -> f64 {
        let b = &self.reynolds.bearing;
        self.spacing_at(b.length, 0.5 * b.width)
    }

    /// Spacing at the bulge (m).
    ///
    /// ```
    /// # use hdi_tribology::bearing::{solve_attitude, AttitudeOptions, BearingSpec};
    /// # let mut spec = BearingSpec::from_path(concat!(
    /// #     env!("CARGO_MANIFEST_DIR"), "/scenes/bearing/two_rail_taper_flat.toml"))?;
    /// # spec.grid.nx = 33;
    /// # spec.grid.ny = 33;
    /// # let eq = solve_attitude(&spec.build()?, &AttitudeOptions::default())?;
    /// // The example's bulge is the left rail's trailing edge: no roll, so the fly height.
    /// assert!((eq.bulge_spacing() - eq.attitude.fly_height).abs() < 1e-15);
    /// assert!(eq.min_spacing() <= eq.bulge_spacing());
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn bulge_spacing(&self) -> f64 {
        let [x, y] = self.reynolds.bearing.bulge;
        self.spacing_at(x, y)
    }

    /// Smallest spacing over the grid's nodes (m).
    pub fn min_spacing(&self) -> f64 {
        self.reynolds.min_spacing(&self.attitude)
    }

    /// ```
    /// # use hdi_tribology::bearing::{solve_attitude, AttitudeOptions, BearingSpec};
    /// # let mut spec = BearingSpec::from_path(concat!(
    /// #     env!("CARGO_MANIFEST_DIR"), "/scenes/bearing/two_rail_taper_flat.toml"))?;
    /// # spec.grid.nx = 33;
    /// # spec.grid.ny = 33;
    /// # let eq = solve_attitude(&spec.build()?, &AttitudeOptions::default())?;
    /// let k = eq.stiffness();
    /// assert!(k[0][0] > 0.0 && k[1][1] > 0.0 && k[2][2] > 0.0);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    ///
    /// Stiffness matrix about the equilibrium, `K = −∂(force, pitch moment, roll moment) /
    /// ∂(fly height, pitch, roll)`: N/m, N/rad; N m/m, N m/rad. The moments are positive in the
    /// sense that raises their angle, so a stable bearing has a positive diagonal.
    pub fn stiffness(&self) -> [[f64; 3]; 3] {
        let mut k = self.load_jacobian;
        for row in k.iter_mut() {
            for v in row.iter_mut() {
                *v = -*v;
            }
        }
        k
    }

    /// ```
    /// # use hdi_tribology::bearing::{solve_attitude, AttitudeOptions, BearingSpec};
    /// # let mut spec = BearingSpec::from_path(concat!(
    /// #     env!("CARGO_MANIFEST_DIR"), "/scenes/bearing/two_rail_taper_flat.toml"))?;
    /// # spec.grid.nx = 33;
    /// # spec.grid.ny = 33;
    /// # let eq = solve_attitude(&spec.build()?, &AttitudeOptions::default())?;
    /// let c = eq.damping()?;
    /// assert!(c[0][0] > 0.0);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    ///
    /// Low-frequency squeeze-film damping matrix about the equilibrium (same units as
    /// [`Equilibrium::stiffness`] times s).
    pub fn damping(&self) -> Result<[[f64; 3]; 3]> {
        self.reynolds
            .damping(&self.pressure, &self.spacing, &self.factored, &self.dps)
    }

    /// Pressure `p` (Pa) per control volume.
    pub fn pressure_pa(&self) -> Vec<f64> {
        let pa = self.reynolds.bearing.ambient_pressure;
        self.pressure.iter().map(|v| v * pa).collect()
    }

    /// ```
    /// # use hdi_tribology::bearing::{solve_attitude, AttitudeOptions, BearingSpec};
    /// # let mut spec = BearingSpec::from_path(concat!(
    /// #     env!("CARGO_MANIFEST_DIR"), "/scenes/bearing/two_rail_taper_flat.toml"))?;
    /// # spec.grid.nx = 33;
    /// # spec.grid.ny = 33;
    /// # let eq = solve_attitude(&spec.build()?, &AttitudeOptions::default())?;
    /// let curve = eq.force_spacing(&[-20e-9, 0.0, 50e-9])?;
    /// assert!(curve[0].1 > curve[1].1 && curve[1].1 > curve[2].1);
    /// assert!((curve[1].1 - 49e-3).abs() < 1e-9);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    ///
    /// The bearing's force (N) against the bulge's spacing (m), with pitch and roll held at
    /// the equilibrium's and the fly height moved by each of `offsets` (m).
    pub fn force_spacing(&self, offsets: &[f64]) -> Result<Vec<(f64, f64)>> {
        let r = &self.reynolds;
        let mut out = Vec::with_capacity(offsets.len());
        let mut sorted: Vec<f64> = offsets.to_vec();
        sorted.sort_by(f64::total_cmp);
        for &d in &sorted {
            let mut att = self.attitude;
            att.fly_height += d;
            let mut p = self.pressure.clone();
            for (pc, dc) in p.iter_mut().zip(&self.dps[0]) {
                *pc = (*pc + dc * d).max(0.5 * *pc);
            }
            r.solve(&att, &mut p)?;
            out.push((self.bulge_spacing() + d, r.loads(&p)[0]));
        }
        Ok(out)
    }

    /// ```
    /// # use hdi_tribology::bearing::{solve_attitude, AttitudeOptions, BearingSpec};
    /// # let mut spec = BearingSpec::from_path(concat!(
    /// #     env!("CARGO_MANIFEST_DIR"), "/scenes/bearing/two_rail_taper_flat.toml"))?;
    /// # spec.grid.nx = 33;
    /// # spec.grid.ny = 33;
    /// # let eq = solve_attitude(&spec.build()?, &AttitudeOptions::default())?;
    /// let curve = eq.heave_curve(&[0.0, 20e-9])?;
    /// assert!((curve[0].1 - 49e-3).abs() < 1e-9);
    /// assert_eq!(curve[0].2, -eq.stiffness()[0][0]);
    /// assert!(curve[1].1 < curve[0].1 && curve[1].2 < 0.0);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    ///
    /// The bearing's force along a heave: for each of `offsets` (m, added to the fly height
    /// with pitch and roll held), `(offset, force (N), ∂force/∂fly height (N/m))`, the
    /// derivative from the pressure's sensitivity (one linear solve), not from differences. At
    /// offset 0 it is the equilibrium's own: the preload balanced and `−K[0][0]`.
    pub fn heave_curve(&self, offsets: &[f64]) -> Result<Vec<(f64, f64, f64)>> {
        let r = &self.reynolds;
        let mut out = Vec::with_capacity(offsets.len());
        for &d in offsets {
            if d == 0.0 {
                out.push((0.0, self.loads[0], self.load_jacobian[0][0]));
                continue;
            }
            let mut att = self.attitude;
            att.fly_height += d;
            if r.min_spacing(&att) < SPACING_FLOOR {
                return Err(Error::invalid(
                    "heave offset",
                    format!(
                        "{:.3} nm brings the slider below the {:.1} nm the bearing solve reaches",
                        d * 1e9,
                        SPACING_FLOOR * 1e9
                    ),
                ));
            }
            let mut p = self.pressure.clone();
            for (pc, dc) in p.iter_mut().zip(&self.dps[0]) {
                *pc = (*pc + dc * d).max(0.5 * *pc);
            }
            let h = r.spacing(&att);
            let (_, f) = r.solve_spacing(&h, &mut p)?;
            let (k, _, _) = r.sensitivities(&p, &h, &f, FINAL_SENSITIVITY_RTOL)?;
            out.push((d, r.loads(&p)[0], k[0][0]));
        }
        Ok(out)
    }

    /// The bearing number at the reference spacing (10 nm).
    pub fn bearing_number(&self) -> f64 {
        self.reynolds.bearing_number()
    }

    /// The reference spacing of the bearing number, m.
    pub fn reference_spacing(&self) -> f64 {
        REFERENCE_SPACING
    }
}
