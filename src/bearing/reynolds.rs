//! The steady compressible Reynolds equation with rarefaction, discretised by control volumes
//! and solved by Newton's method.
//!
//! In the variables `X = x/L`, `Y = y/L`, `P = p/p_a`, `H = h/h_m` the mass flux per unit width
//! is `J = Λ e P H − Q P H³ ∇P` (`e` the unit vector of the disk's velocity, `Λ = 6 μ U L /
//! (p_a h_m²)` the bearing number, `Q(Kn)` the Poiseuille flow factor at `Kn = λ_a/(P H h_m)`),
//! and the steady equation is `∇·J = 0`, with `P = 1` on the slider's edges.
//!
//! Each control volume balances the fluxes through its four faces. Across a face, the
//! conductance `Q P H³` of the two neighbours is combined in series (the harmonic mean, which
//! keeps the flux continuous where a rail steps), the convected mass `P H` takes the spacing on
//! the face (interpolated where the surface is smooth, the upstream cell's across a step), and
//! Patankar's power-law scheme weighs the two by the face's Péclet number:
//! central differences where diffusion dominates, upwinding where convection does, stable at
//! any bearing number. The Jacobian of the residual is exact (analytic), and each Newton step
//! is a GMRES solve preconditioned by the incomplete LU factors of that Jacobian.

use super::error::{BearingError, Solve};
use super::flow_factor::FlowModel;
use super::geometry::Bearing;
use super::grid::Grid;
use super::linear::{gmres, FivePoint, KrylovStats, Multigrid};
use crate::Result;

/// The reference spacing `h_m` of the non-dimensional variables, m.
pub const REFERENCE_SPACING: f64 = 10e-9;
/// Restart length of GMRES.
const RESTART: usize = 30;
/// Iteration budget of one GMRES solve.
const MAX_KRYLOV: usize = 3000;
/// Smallest fraction of the current pressure a Newton step may leave.
const MIN_PRESSURE_FRACTION: f64 = 0.2;
/// A Newton step this small (in `p/p_a`) that no longer lowers the residual has met the
/// residual's round-off floor.
const ROUND_OFF_UPDATE: f64 = 1e-7;
/// Relative tolerance of the linear solves of the damping.
const DAMPING_RTOL: f64 = 1e-8;

/// The slider's attitude: spacing at the trailing edge's centre, pitch and roll.
///
/// The spacing of the air-bearing surface (depth 0) at `(x, y)` is
/// `h = fly_height + pitch (L − x) + roll (y − W/2)`; positive pitch raises the leading edge,
/// positive roll the `+y` side. The surface's depth adds to it.
///
/// ```
/// use hdi_tribology::bearing::Attitude;
/// let a = Attitude { fly_height: 10e-9, pitch: 100e-6, roll: 0.0 };
/// assert!((a.spacing_at(0.0, 0.5e-3, 1e-3, 1e-3) - 110e-9).abs() < 1e-18);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attitude {
    /// Spacing at the trailing edge's centre (surface depth 0), m.
    pub fly_height: f64,
    /// Pitch, rad.
    pub pitch: f64,
    /// Roll, rad.
    pub roll: f64,
}

impl Attitude {
    /// Spacing of the plane of depth 0 at `(x, y)` on a slider of length `l` and width `w`, m.
    pub fn spacing_at(&self, x: f64, y: f64, l: f64, w: f64) -> f64 {
        self.fly_height + self.pitch * (l - x) + self.roll * (y - 0.5 * w)
    }

    /// As an array `[fly_height, pitch, roll]`.
    pub fn to_array(self) -> [f64; 3] {
        [self.fly_height, self.pitch, self.roll]
    }

    /// From an array `[fly_height, pitch, roll]`.
    pub fn from_array(a: [f64; 3]) -> Self {
        Attitude {
            fly_height: a[0],
            pitch: a[1],
            roll: a[2],
        }
    }
}

/// What happens at the slider's sides `y = 0` and `y = W`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Sides {
    /// Ambient pressure (a real slider).
    #[default]
    Ambient,
    /// No flux through the sides: with no skew, the infinitely wide slider.
    Closed,
}

/// How a Newton solve of the pressure went.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NewtonStats {
    /// Newton steps.
    pub iterations: usize,
    /// GMRES iterations over all steps.
    pub krylov_iterations: usize,
    /// Largest change of `P` in the last step.
    pub last_update: f64,
    /// 2-norm of the residual at the solution, relative to the convective flux scale `Λ`
    /// times the slider's width over its length.
    pub residual: f64,
}

/// The Reynolds equation of one bearing on one grid.
///
/// ```
/// use hdi_tribology::bearing::{Attitude, BearingSpec, Reynolds};
/// let b = BearingSpec::from_toml_str("[slider]\nlength_um = 1000\nwidth_um = 800\n\
///     [operating]\nradius_mm = 20\nrpm = 7200\npreload_mn = 20")?.build()?;
/// let r = Reynolds::new(&b, 32, 32);
/// let att = Attitude { fly_height: 20e-9, pitch: 100e-6, roll: 0.0 };
/// let mut p = r.ambient();
/// r.solve(&att, &mut p)?;
/// let [load, _, _] = r.loads(&p);
/// assert!(load > 0.0);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct Reynolds {
    /// The bearing.
    pub bearing: Bearing,
    /// The grid.
    pub grid: Grid,
    /// Side boundaries.
    pub sides: Sides,
    /// Bearing number components along `x` and `y`.
    lambda: [f64; 2],
    /// `λ_a / h_m`.
    kn0: f64,
    model: FlowModel,
    /// Non-dimensional cell widths.
    dx: Vec<f64>,
    dy: Vec<f64>,
    /// Non-dimensional cell centres.
    xc: Vec<f64>,
    yc: Vec<f64>,
    /// Tolerance on the largest change of `P` in a Newton step.
    pub tolerance: f64,
    /// Newton steps allowed.
    pub max_newton: usize,
    /// Asked between the linear solves whether to stop (see [`Interrupt`]).
    pub interrupt: Option<Interrupt>,
}

/// A check the solver asks between its linear solves (each Newton step of the pressure, each
/// sensitivity and damping solve): when it says so, the solve stops with an error
/// ([`BearingError::Interrupted`]). How a caller that watches for Ctrl-C, or a deadline, stops
/// a long solve; a solve on the finest grids asks it every few tenths of a
/// second.
///
/// ```
/// use std::sync::atomic::{AtomicBool, Ordering};
/// use std::sync::Arc;
/// use hdi_tribology::bearing::{solve_attitude, AttitudeOptions, BearingSpec, Interrupt};
/// let b = BearingSpec::from_path(concat!(
///     env!("CARGO_MANIFEST_DIR"),
///     "/scenes/bearing/two_rail_taper_flat.toml"
/// ))?
/// .build()?;
/// let stop = Arc::new(AtomicBool::new(true));
/// let flag = stop.clone();
/// let opts = AttitudeOptions {
///     interrupt: Some(Interrupt::new(move || flag.load(Ordering::Relaxed))),
///     ..AttitudeOptions::default()
/// };
/// let e = solve_attitude(&b, &opts).unwrap_err().to_string();
/// assert!(e.contains("stopped on request"), "{e}");
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone)]
pub struct Interrupt(std::sync::Arc<dyn Fn() -> bool + Send + Sync>);

impl Interrupt {
    /// A check that stops the solve when `stop` returns `true`.
    pub fn new(stop: impl Fn() -> bool + Send + Sync + 'static) -> Self {
        Interrupt(std::sync::Arc::new(stop))
    }

    /// Whether the check asks to stop.
    pub fn requested(&self) -> bool {
        (self.0)()
    }
}

impl std::fmt::Debug for Interrupt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Interrupt")
    }
}

impl PartialEq for Interrupt {
    /// The same check (clones of one).
    fn eq(&self, other: &Self) -> bool {
        std::sync::Arc::ptr_eq(&self.0, &other.0)
    }
}

/// Patankar's power-law weight `A(|Pe|) = max(0, (1 − 0.1 |Pe|)⁵)` and its derivative.
#[inline]
fn power_law(z: f64) -> (f64, f64) {
    if z >= 10.0 {
        (0.0, 0.0)
    } else {
        let t = 1.0 - 0.1 * z;
        let t2 = t * t;
        (t2 * t2 * t, -0.5 * t2 * t2)
    }
}

/// Two neighbouring spacings differing by more than this fraction of the smaller one are a
/// step, not a smooth variation.
const STEP_RATIO: f64 = 0.5;

/// Spacing on face `k` of a line of cells (`h[m · stride]` the spacing of cell `m`, `w[m]` its
/// width) for the convected mass `Λ P H`: linear interpolation between the two cells where the
/// spacing varies smoothly (second order), linear extrapolation from the first two cells on the
/// slider's edge, and the upstream cell's spacing across a step, where the surface jumps.
fn face_spacing(h: &[f64], w: &[f64], k: usize, stride: usize, lambda: f64) -> f64 {
    let n = w.len();
    let at = |m: usize| h[m * stride];
    let smooth = |a: f64, b: f64| (a - b).abs() <= STEP_RATIO * a.min(b);
    if k == 0 || k == n {
        let (c0, c1) = if k == 0 { (0, 1) } else { (n - 1, n - 2) };
        let (h0, h1) = (at(c0), at(c1));
        if n < 2 || !smooth(h0, h1) {
            return h0;
        }
        let t = 0.5 * w[c0] / (0.5 * (w[c0] + w[c1]));
        return (h0 - t * (h1 - h0)).max(0.5 * h0);
    }
    let (hl, hr) = (at(k - 1), at(k));
    if smooth(hl, hr) {
        let (wl, wr) = (w[k - 1], w[k]);
        (hl * wr + hr * wl) / (wl + wr)
    } else if lambda >= 0.0 {
        hl
    } else {
        hr
    }
}

/// One face: flux from the left cell to the right one and its derivatives with respect to the
/// two pressures. `a_l`, `a_r`: distances of the centres from the face (0 for a boundary);
/// `gl`, `gr`: conductances `Q P H³`, `dgl`, `dgr` their derivatives in `P`; `f`: convective
/// strength `Λ_d × face length × H_upwind`; `area`: face length.
#[allow(clippy::too_many_arguments)]
#[inline]
fn face(
    pl: f64,
    pr: f64,
    a_l: f64,
    a_r: f64,
    gl: f64,
    gr: f64,
    dgl: f64,
    dgr: f64,
    f: f64,
    area: f64,
) -> (f64, f64, f64) {
    let rl = a_l / gl;
    let rr = a_r / gr;
    let g = 1.0 / (rl + rr);
    let d = g * area;
    let pe = (f / d).abs();
    let (a, da) = power_law(pe);
    let j = d * a * (pl - pr) + f.max(0.0) * pl - (-f).max(0.0) * pr;
    let djdd = (pl - pr) * (a - da * pe);
    let ddl = area * g * g * rl / gl * dgl;
    let ddr = area * g * g * rr / gr * dgr;
    let jl = djdd * ddl + d * a + f.max(0.0);
    let jr = djdd * ddr - d * a - (-f).max(0.0);
    (j, jl, jr)
}

/// The direction a face is normal to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Axis {
    X,
    Y,
}

/// The flux through one face ([`Reynolds::face_flux`]): the cells below and above it (none on
/// the slider's edge), the flux from below to above, and its derivatives in the two pressures.
struct FaceFlux {
    low: Option<usize>,
    high: Option<usize>,
    flux: f64,
    d_low: f64,
    d_high: f64,
}

impl Reynolds {
    /// The equation of `bearing` on the grid of `nx × ny` control volumes at the bearing's
    /// refinement.
    pub fn new(bearing: &Bearing, nx: usize, ny: usize) -> Reynolds {
        let grid = Grid::new(bearing, nx, ny, bearing.grid.refinement);
        Self::on_grid(bearing, grid)
    }

    /// The equation on a given grid.
    pub fn on_grid(bearing: &Bearing, grid: Grid) -> Reynolds {
        let l = bearing.length;
        let lam = bearing.bearing_number(REFERENCE_SPACING);
        let dx = grid.xf.windows(2).map(|w| (w[1] - w[0]) / l).collect();
        let dy = grid.yf.windows(2).map(|w| (w[1] - w[0]) / l).collect();
        let xc = grid.xc.iter().map(|x| x / l).collect();
        let yc = grid.yc.iter().map(|y| y / l).collect();
        Reynolds {
            lambda: [lam * bearing.skew.cos(), lam * bearing.skew.sin()],
            kn0: bearing.mean_free_path / REFERENCE_SPACING,
            model: bearing.flow_model,
            bearing: bearing.clone(),
            grid,
            sides: Sides::Ambient,
            dx,
            dy,
            xc,
            yc,
            tolerance: 1e-10,
            max_newton: 60,
            interrupt: None,
        }
    }

    /// An error if the [`Interrupt`] asks to stop `what`.
    fn check_interrupt(&self, what: Solve) -> Result<()> {
        match &self.interrupt {
            Some(i) if i.requested() => Err(BearingError::Interrupted { during: what }.into()),
            _ => Ok(()),
        }
    }

    /// Control volumes `(nx, ny)`.
    pub fn size(&self) -> (usize, usize) {
        (self.grid.nx(), self.grid.ny())
    }

    /// The bearing number `Λ` at the reference spacing.
    pub fn bearing_number(&self) -> f64 {
        self.lambda[0].hypot(self.lambda[1])
    }

    /// Ambient pressure everywhere (`P = 1`), a start for [`Reynolds::solve`].
    pub fn ambient(&self) -> Vec<f64> {
        vec![1.0; self.grid.depth.len()]
    }

    /// Spacing of each control volume (area average), non-dimensional (`h / h_m`).
    pub fn spacing(&self, att: &Attitude) -> Vec<f64> {
        let (nx, ny) = self.size();
        let (l, w) = (self.bearing.length, self.bearing.width);
        let mut h = Vec::with_capacity(nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                let s = att.spacing_at(self.grid.xc[i], self.grid.yc[j], l, w)
                    + self.grid.depth[j * nx + i];
                h.push(s / REFERENCE_SPACING);
            }
        }
        h
    }

    /// How the non-dimensional spacing of each control volume changes with the attitude's
    /// fly height (per m), pitch and roll (per rad).
    pub fn spacing_derivatives(&self) -> [Vec<f64>; 3] {
        let (l, w) = (self.bearing.length, self.bearing.width);
        self.per_cell(|i, j| {
            [
                1.0 / REFERENCE_SPACING,
                (l - self.grid.xc[i]) / REFERENCE_SPACING,
                (self.grid.yc[j] - 0.5 * w) / REFERENCE_SPACING,
            ]
        })
    }

    /// Smallest spacing over the grid's nodes (surface depth included), m.
    pub fn min_spacing(&self, att: &Attitude) -> f64 {
        let (l, w) = (self.bearing.length, self.bearing.width);
        let nxn = self.grid.xf.len();
        let mut m = f64::INFINITY;
        for (j, &y) in self.grid.yf.iter().enumerate() {
            for (i, &x) in self.grid.xf.iter().enumerate() {
                m = m.min(att.spacing_at(x, y, l, w) + self.grid.node_depth[j * nxn + i]);
            }
        }
        m
    }

    /// Conductance `Q P H³` of each cell and its derivative in `P`.
    fn conductances(&self, p: &[f64], h: &[f64], g: &mut [f64], dg: &mut [f64]) {
        for c in 0..p.len() {
            let (pc, hc) = (p[c], h[c]);
            let h3 = hc * hc * hc;
            if self.kn0 == 0.0 || self.model == FlowModel::Continuum {
                g[c] = pc * h3;
                dg[c] = h3;
            } else {
                let kn = self.kn0 / (pc * hc);
                let (q, dq) = self.model.factor_and_derivative(kn);
                g[c] = q * pc * h3;
                dg[c] = h3 * (q - dq * kn);
            }
        }
    }

    /// The residual `r` (net mass outflow of each control volume) and, if asked, its Jacobian.
    pub fn residual(&self, p: &[f64], h: &[f64], r: &mut [f64], mut jac: Option<&mut FivePoint>) {
        let (nx, ny) = self.size();
        let n = nx * ny;
        let mut g = vec![0.0; n];
        let mut dg = vec![0.0; n];
        self.conductances(p, h, &mut g, &mut dg);
        r.iter_mut().for_each(|x| *x = 0.0);
        if let Some(a) = jac.as_deref_mut() {
            a.clear();
        }
        let closed = self.sides == Sides::Closed;
        for axis in [Axis::X, Axis::Y] {
            // Faces in storage order: rows of faces normal to x, then rows of faces normal to y.
            let (outer, inner) = match axis {
                Axis::X => (ny, nx + 1),
                Axis::Y => (ny + 1, nx),
            };
            for o in 0..outer {
                if axis == Axis::Y && closed && (o == 0 || o == ny) {
                    continue;
                }
                for q in 0..inner {
                    let (k, m) = match axis {
                        Axis::X => (q, o),
                        Axis::Y => (o, q),
                    };
                    let f = self.face_flux(axis, k, m, p, h, &g, &dg);
                    if let Some(l) = f.low {
                        r[l] += f.flux;
                    }
                    if let Some(u) = f.high {
                        r[u] -= f.flux;
                    }
                    if let Some(a) = jac.as_deref_mut() {
                        if let Some(l) = f.low {
                            a.diag[l] += f.d_low;
                            if let Some(u) = f.high {
                                let (up, down) = match axis {
                                    Axis::X => (&mut a.east, &mut a.west),
                                    Axis::Y => (&mut a.north, &mut a.south),
                                };
                                up[l] += f.d_high;
                                down[u] -= f.d_low;
                            }
                        }
                        if let Some(u) = f.high {
                            a.diag[u] -= f.d_high;
                        }
                    }
                }
            }
        }
    }

    /// The flux through one face and its derivatives in the pressures on its two sides: the
    /// face `k` (of `0..=n` along the axis) of line `m` (the row `j` for faces normal to `x`,
    /// the column `i` for faces normal to `y`), positive from the cell below `k` to the one
    /// above. A face on the slider's edge has ambient pressure on its outer side, half a
    /// volume closer than a centre.
    #[allow(clippy::too_many_arguments)]
    fn face_flux(
        &self,
        axis: Axis,
        k: usize,
        m: usize,
        p: &[f64],
        h: &[f64],
        g: &[f64],
        dg: &[f64],
    ) -> FaceFlux {
        let nx = self.grid.nx();
        let (n, widths, lambda, area, first, stride) = match axis {
            Axis::X => (nx, &self.dx, self.lambda[0], self.dy[m], m * nx, 1),
            Axis::Y => (self.grid.ny(), &self.dy, self.lambda[1], self.dx[m], m, nx),
        };
        let low = (k > 0).then(|| first + (k - 1) * stride);
        let high = (k < n).then(|| first + k * stride);
        let side = |c: Option<usize>, w: usize| match c {
            Some(c) => (p[c], g[c], dg[c], 0.5 * widths[w]),
            None => (1.0, 1.0, 0.0, 0.0),
        };
        let (pl, gl, dgl, al) = side(low, k.saturating_sub(1));
        let (pr, gr, dgr, ar) = side(high, k.min(n - 1));
        let hf = face_spacing(&h[first..], widths, k, stride, lambda);
        let (flux, d_low, d_high) =
            face(pl, pr, al, ar, gl, gr, dgl, dgr, lambda * area * hf, area);
        FaceFlux {
            low,
            high,
            flux,
            d_low,
            d_high,
        }
    }

    /// ```
    /// # use hdi_tribology::bearing::{Attitude, BearingSpec, Reynolds};
    /// # let b = BearingSpec::from_toml_str("[slider]\nlength_um = 1000\nwidth_um = 800\n\
    /// #     [operating]\nradius_mm = 20\nrpm = 7200\npreload_mn = 20")?.build()?;
    /// # let r = Reynolds::new(&b, 24, 24);
    /// # let att = Attitude { fly_height: 20e-9, pitch: 100e-6, roll: 0.0 };
    /// let mut p = r.ambient();
    /// r.solve(&att, &mut p)?;
    /// let (inflow, outflow) = r.boundary_flux(&p, &r.spacing(&att));
    /// assert!((inflow - outflow).abs() < 1e-8 * inflow);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    ///
    /// Total mass flux into and out of the slider through its edges (non-dimensional, per the
    /// scale `p_a h_m L`), at the pressure `p` and spacing `h`.
    pub fn boundary_flux(&self, p: &[f64], h: &[f64]) -> (f64, f64) {
        let (nx, ny) = self.size();
        let n = nx * ny;
        let mut g = vec![0.0; n];
        let mut dg = vec![0.0; n];
        self.conductances(p, h, &mut g, &mut dg);
        let (mut inflow, mut outflow) = (0.0, 0.0);
        let mut edges = vec![(Axis::X, nx, ny)];
        if self.sides == Sides::Ambient {
            edges.push((Axis::Y, ny, nx));
        }
        for (axis, n_faces, lines) in edges {
            for m in 0..lines {
                // Outward flux through the low edge (k = 0) and the high edge (k = n).
                let out_low = -self.face_flux(axis, 0, m, p, h, &g, &dg).flux;
                let out_high = self.face_flux(axis, n_faces, m, p, h, &g, &dg).flux;
                for f in [out_low, out_high] {
                    if f > 0.0 {
                        outflow += f;
                    } else {
                        inflow -= f;
                    }
                }
            }
        }
        (inflow, outflow)
    }

    /// Scale of the residual: the convective flux `Λ` across the slider's width.
    fn residual_scale(&self) -> f64 {
        self.bearing_number().max(1.0) * self.dy.iter().sum::<f64>()
    }

    /// Solves for the pressure at the attitude `att`, from the start `p` (non-dimensional), by
    /// Newton's method; `p` holds the solution.
    pub fn solve(&self, att: &Attitude, p: &mut [f64]) -> Result<NewtonStats> {
        let h = self.spacing(att);
        if let Some(c) = h.iter().position(|&v| v.is_nan() || v <= 0.0) {
            return Err(BearingError::Touches {
                cell: c,
                spacing_nm: h[c] * REFERENCE_SPACING * 1e9,
            }
            .into());
        }
        self.solve_spacing(&h, p).map(|(s, _)| s)
    }

    /// [`Reynolds::solve`] at a given non-dimensional spacing per cell; also returns the
    /// Jacobian at the solution and its multigrid preconditioner, for sensitivities.
    pub fn solve_spacing(&self, h: &[f64], p: &mut [f64]) -> Result<(NewtonStats, Factored)> {
        self.solve_spacing_to(h, p, self.tolerance)
    }

    /// [`Reynolds::solve_spacing`] to the tolerance `tol` on the largest change of `P` in a
    /// Newton step instead of [`Reynolds::tolerance`].
    pub fn solve_spacing_to(
        &self,
        h: &[f64],
        p: &mut [f64],
        tol: f64,
    ) -> Result<(NewtonStats, Factored)> {
        let (nx, ny) = self.size();
        let n = nx * ny;
        let mut r = vec![0.0; n];
        let mut trial_r = vec![0.0; n];
        let mut a = FivePoint::zeros(nx, ny);
        let mut dp = vec![0.0; n];
        let mut trial = vec![0.0; n];
        let scale = self.residual_scale();
        let mut stats = NewtonStats::default();
        self.residual(p, h, &mut r, Some(&mut a));
        let mut rnorm = norm(&r);
        let mut forcing = Forcing::new(tol);
        let mut mg: Option<Multigrid> = None;
        loop {
            if stats.iterations >= self.max_newton {
                return Err(BearingError::PressureNewton {
                    iterations: stats.iterations,
                    last_change: stats.last_update,
                    residual: rnorm / scale,
                }
                .into());
            }
            self.check_interrupt(Solve::Pressure)?;
            let ilu = refreshed(&mut mg, &a);
            let eta = forcing.next(rnorm);
            dp.iter_mut().for_each(|x| *x = 0.0);
            let neg: Vec<f64> = r.iter().map(|v| -v).collect();
            let ks: KrylovStats = gmres(&a, ilu, &neg, &mut dp, eta, RESTART, MAX_KRYLOV);
            stats.krylov_iterations += ks.iterations;
            stats.iterations += 1;
            let full = dp.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let (accepted, tnorm) = if full <= tol {
                (false, rnorm)
            } else {
                // Keep the pressure positive, then backtrack on the residual's norm.
                let mut t: f64 = 1.0;
                for c in 0..n {
                    if dp[c] < 0.0 {
                        t = t.min((MIN_PRESSURE_FRACTION - 1.0) * p[c] / dp[c]);
                    }
                }
                let mut accepted = false;
                let mut tnorm = rnorm;
                for _ in 0..12 {
                    for c in 0..n {
                        trial[c] = p[c] + t * dp[c];
                    }
                    self.residual(&trial, h, &mut trial_r, None);
                    tnorm = norm(&trial_r);
                    if tnorm.is_finite() && tnorm <= (1.0 - 1e-4 * t) * rnorm {
                        accepted = true;
                        break;
                    }
                    t *= 0.5;
                }
                (accepted, tnorm)
            };
            // Converged, or the residual is at its round-off floor (the backtracking found no
            // descent): the full step is the answer.
            if full <= tol || (!accepted && full <= ROUND_OFF_UPDATE) {
                for c in 0..n {
                    p[c] += dp[c];
                }
                stats.last_update = full;
                self.residual(p, h, &mut r, Some(&mut a));
                rnorm = norm(&r);
                break;
            }
            if !accepted && !tnorm.is_finite() {
                return Err(BearingError::NonFiniteResidual.into());
            }
            let mut upd: f64 = 0.0;
            for c in 0..n {
                upd = upd.max((trial[c] - p[c]).abs());
            }
            p.copy_from_slice(&trial);
            stats.last_update = upd;
            forcing.stepped(full, rnorm, tnorm);
            rnorm = tnorm;
            self.residual(p, h, &mut r, Some(&mut a));
        }
        stats.residual = rnorm / scale;
        refreshed(&mut mg, &a);
        let ilu = mg.expect("the preconditioner is built above");
        Ok((stats, Factored { jacobian: a, ilu }))
    }

    /// Loads of the pressure `p` (non-dimensional): the force (N, positive away from the disk)
    /// and its moments about the pivot (N m), each positive in the sense that raises its angle
    /// of [`Attitude`]: pitch (positive when the pressure's centre lies ahead of the pivot,
    /// towards the leading edge) and roll (positive when it lies on the `+y` side).
    pub fn loads(&self, p: &[f64]) -> [f64; 3] {
        let w = self.weights();
        let l = self.bearing.length;
        let pa = self.bearing.ambient_pressure;
        let mut out = [0.0; 3];
        for (c, &pc) in p.iter().enumerate() {
            let e = pc - 1.0;
            out[0] += e * w[0][c];
            out[1] += e * w[1][c];
            out[2] += e * w[2][c];
        }
        [
            out[0] * pa * l * l,
            out[1] * pa * l * l,
            out[2] * pa * l * l,
        ]
    }

    /// The loads (N, N m, N m) of a non-dimensional pressure field `x` with the weights `w`
    /// ([`Reynolds::weights`]): each weighted sum times the ambient pressure and the length
    /// squared.
    fn weighted_loads(&self, w: &[Vec<f64>; 3], x: &[f64]) -> [f64; 3] {
        let (l, pa) = (self.bearing.length, self.bearing.ambient_pressure);
        w.each_ref()
            .map(|wi| x.iter().zip(wi).map(|(a, b)| a * b).sum::<f64>() * pa * l * l)
    }

    /// Weights of the loads: area, area × lever arm ahead of the pivot (m), area × lever arm to
    /// its `+y` side.
    fn weights(&self) -> [Vec<f64>; 3] {
        let [px, py] = self.bearing.pivot;
        self.per_cell(|i, j| {
            let a = self.dx[i] * self.dy[j];
            [a, a * (px - self.grid.xc[i]), a * (self.grid.yc[j] - py)]
        })
    }

    /// Three quantities of every control volume, row by row: `f(i, j)` of the volume in column
    /// `i` and row `j`.
    fn per_cell(&self, f: impl Fn(usize, usize) -> [f64; 3]) -> [Vec<f64>; 3] {
        let (nx, ny) = self.size();
        let mut out = [
            Vec::with_capacity(nx * ny),
            Vec::with_capacity(nx * ny),
            Vec::with_capacity(nx * ny),
        ];
        for j in 0..ny {
            for i in 0..nx {
                for (v, o) in f(i, j).into_iter().zip(&mut out) {
                    o.push(v);
                }
            }
        }
        out
    }

    /// ```
    /// # use hdi_tribology::bearing::{Attitude, BearingSpec, Reynolds};
    /// # let b = BearingSpec::from_toml_str("[slider]\nlength_um = 1000\nwidth_um = 800\n\
    /// #     [operating]\nradius_mm = 20\nrpm = 7200\npreload_mn = 20")?.build()?;
    /// # let r = Reynolds::new(&b, 24, 24);
    /// # let att = Attitude { fly_height: 20e-9, pitch: 100e-6, roll: 0.0 };
    /// let h = r.spacing(&att);
    /// let mut p = r.ambient();
    /// let (_, f) = r.solve_spacing(&h, &mut p)?;
    /// let (k, _, _) = r.sensitivities(&p, &h, &f, 1e-8)?;
    /// assert!(k[0][0] < 0.0); // the load falls as the slider rises
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    ///
    /// Derivatives of the loads ([`Reynolds::loads`]) with respect to the attitude, at the
    /// converged pressure `p` and spacing `h` with the factored Jacobian `f`: `k[i][j] =
    /// ∂load_i/∂attitude_j` (N/m, N, N m/m, N m), the pressure's derivatives
    /// `∂P/∂attitude_j`, and the GMRES iterations spent; each linear solve to the relative
    /// tolerance `rtol`.
    pub fn sensitivities(
        &self,
        p: &[f64],
        h: &[f64],
        f: &Factored,
        rtol: f64,
    ) -> Result<Sensitivities> {
        let n = p.len();
        self.sensitivities_from(p, h, f, rtol, [vec![0.0; n], vec![0.0; n], vec![0.0; n]])
    }

    /// [`Reynolds::sensitivities`] with the linear solves started from `start`, a guess of
    /// the pressure's derivatives (those of a nearby attitude, or of a coarser grid
    /// interpolated onto this one); a start of another length than the grid's is zero.
    pub fn sensitivities_from(
        &self,
        p: &[f64],
        h: &[f64],
        f: &Factored,
        rtol: f64,
        start: [Vec<f64>; 3],
    ) -> Result<Sensitivities> {
        let dh = self.spacing_derivatives();
        let n = p.len();
        let mut start = start;
        for s in start.iter_mut().filter(|s| s.len() != n) {
            *s = vec![0.0; n];
        }
        let mut rp = vec![0.0; n];
        let mut rm = vec![0.0; n];
        let mut hs = h.to_vec();
        let hmax = h.iter().cloned().fold(0.0, f64::max);
        let mut dps = start;
        let mut k = [[0.0; 3]; 3];
        let mut iterations = 0;
        let w = self.weights();
        for q in 0..3 {
            self.check_interrupt(Solve::Sensitivity)?;
            let dmax = dh[q].iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let eps = 1e-6 * hmax / dmax;
            for c in 0..n {
                hs[c] = h[c] + eps * dh[q][c];
            }
            self.residual(p, &hs, &mut rp, None);
            for c in 0..n {
                hs[c] = h[c] - eps * dh[q][c];
            }
            self.residual(p, &hs, &mut rm, None);
            let rhs: Vec<f64> = (0..n).map(|c| -(rp[c] - rm[c]) / (2.0 * eps)).collect();
            iterations += f.solve(&rhs, &mut dps[q], rtol, Solve::Sensitivity)?;
            let loads = self.weighted_loads(&w, &dps[q]);
            for i in 0..3 {
                k[i][q] = loads[i];
            }
        }
        Ok((k, dps, iterations))
    }

    /// Low-frequency squeeze-film damping (the term of first order in the frequency of a
    /// small harmonic motion of the attitude): `c[i][j] = −∂load_i/∂(d attitude_j/dt)`.
    /// `dps` are the pressure's derivatives from [`Reynolds::sensitivities`].
    pub fn damping(
        &self,
        p: &[f64],
        h: &[f64],
        f: &Factored,
        dps: &[Vec<f64>; 3],
    ) -> Result<[[f64; 3]; 3]> {
        let b = &self.bearing;
        let sigma = 12.0 * b.viscosity * b.length * b.length
            / (b.ambient_pressure * REFERENCE_SPACING.powi(2));
        let dh = self.spacing_derivatives();
        let w = self.weights();
        let (nx, ny) = self.size();
        let n = p.len();
        let mut c = [[0.0; 3]; 3];
        for q in 0..3 {
            self.check_interrupt(Solve::Damping)?;
            let mut rhs = vec![0.0; n];
            for j in 0..ny {
                for i in 0..nx {
                    let k = j * nx + i;
                    let area = self.dx[i] * self.dy[j];
                    rhs[k] = -sigma * area * (h[k] * dps[q][k] + p[k] * dh[q][k]);
                }
            }
            let mut x = vec![0.0; n];
            f.solve(&rhs, &mut x, DAMPING_RTOL, Solve::Damping)?;
            let loads = self.weighted_loads(&w, &x);
            for i in 0..3 {
                c[i][q] = -loads[i];
            }
        }
        Ok(c)
    }

    /// ```
    /// # use hdi_tribology::bearing::{Attitude, BearingSpec, Reynolds};
    /// # let b = BearingSpec::from_toml_str("[slider]\nlength_um = 1000\nwidth_um = 800\n\
    /// #     [operating]\nradius_mm = 20\nrpm = 7200\npreload_mn = 20")?.build()?;
    /// # let r = Reynolds::new(&b, 24, 24);
    /// # let att = Attitude { fly_height: 20e-9, pitch: 100e-6, roll: 0.0 };
    /// let mut p = r.ambient();
    /// r.solve(&att, &mut p)?;
    /// let fine = Reynolds::new(&b, 48, 48);
    /// let q = fine.interpolate_from(&r, &p);
    /// assert_eq!(q.len(), 48 * 48);
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    ///
    /// Interpolates a pressure field of another grid of the same bearing onto this one
    /// (bilinear between cell centres, constant beyond the outermost centres).
    pub fn interpolate_from(&self, other: &Reynolds, p: &[f64]) -> Vec<f64> {
        let (nx, ny) = self.size();
        let (mx, _) = other.size();
        let locate = |centres: &[f64], x: f64| -> (usize, f64) {
            let m = centres.len();
            if x <= centres[0] {
                return (0, 0.0);
            }
            if x >= centres[m - 1] {
                return (m - 2, 1.0);
            }
            let k = centres.partition_point(|&c| c <= x) - 1;
            (k, (x - centres[k]) / (centres[k + 1] - centres[k]))
        };
        let ix: Vec<(usize, f64)> = self.xc.iter().map(|&x| locate(&other.xc, x)).collect();
        let mut out = Vec::with_capacity(nx * ny);
        for &y in &self.yc {
            let (j, ty) = locate(&other.yc, y);
            for &(i, tx) in &ix {
                let v00 = p[j * mx + i];
                let v10 = p[j * mx + i + 1];
                let v01 = p[(j + 1) * mx + i];
                let v11 = p[(j + 1) * mx + i + 1];
                out.push(
                    (1.0 - ty) * ((1.0 - tx) * v00 + tx * v10) + ty * ((1.0 - tx) * v01 + tx * v11),
                );
            }
        }
        out
    }
}

/// What [`Reynolds::sensitivities`] gives: `∂load_i/∂attitude_j`, the pressure's derivatives
/// `∂P/∂attitude_j`, and the GMRES iterations spent.
pub type Sensitivities = ([[f64; 3]; 3], [Vec<f64>; 3], usize);

/// The Jacobian at a converged pressure and its multigrid preconditioner, reused for sensitivities.
#[derive(Clone, Debug)]
pub struct Factored {
    /// The Jacobian.
    pub jacobian: FivePoint,
    /// Its multigrid preconditioner.
    pub ilu: Multigrid,
}

impl Factored {
    /// Solves `J x = rhs` by GMRES from the start in `x` to the relative tolerance `rtol`, and
    /// returns the iterations; a residual left above ten times `rtol` is a
    /// [`BearingError::Krylov`] of `solve`.
    fn solve(&self, rhs: &[f64], x: &mut [f64], rtol: f64, solve: Solve) -> Result<usize> {
        let stats = gmres(&self.jacobian, &self.ilu, rhs, x, rtol, RESTART, MAX_KRYLOV);
        if stats.relative_residual > 10.0 * rtol {
            return Err(BearingError::Krylov {
                solve,
                relative_residual: stats.relative_residual,
                iterations: stats.iterations,
            }
            .into());
        }
        Ok(stats.iterations)
    }
}

/// The multigrid preconditioner of `a`: the hierarchy of the last Newton step given the new
/// Jacobian's values (its levels and work vectors are kept), or a new one.
fn refreshed<'a>(mg: &'a mut Option<Multigrid>, a: &FivePoint) -> &'a Multigrid {
    match mg {
        Some(m) => {
            m.refresh(a);
            m
        }
        None => mg.insert(Multigrid::new(a)),
    }
}

/// The forcing terms of the inexact Newton iteration of the pressure: the relative residual
/// `η` to which each step's linear system is solved.
///
/// Eisenstat & Walker's (1996) second choice, `η_k = γ (‖r_k‖/‖r_{k−1}‖)²` with `γ = 0.9`,
/// kept from falling faster than `γ η_{k−1}²` while that is above 0.1, between [`FORCING_MIN`]
/// and [`FORCING_MAX`]: loose far from the solution, tighter as Newton converges. And, after
/// Kelley (1995, §6.3), no tighter than the tolerance needs: Newton stops on the size of a step
/// (`tol`), and a step is about the previous one times the residual's last reduction, so
/// solving it to a relative `FORCING_SAFEGUARD × tol / (expected step)` is enough.
struct Forcing {
    tol: f64,
    eta: f64,
    /// `‖r_k‖/‖r_{k−1}‖`, the size of the last Newton step and the residual it started from.
    ratio: Option<f64>,
    step: f64,
    rnorm: f64,
}

/// `γ` of the forcing terms.
const FORCING_GAMMA: f64 = 0.9;
/// The loosest relative residual of a Newton step's linear solve. On the example slider 3 × 10⁻³
/// (against 10⁻² and 3 × 10⁻²) took the fewest Newton steps at the same GMRES iterations.
const FORCING_MAX: f64 = 3e-3;
/// The tightest.
const FORCING_MIN: f64 = 1e-10;
/// Fraction of the tolerance on the step that the linear solve's error may take.
const FORCING_SAFEGUARD: f64 = 0.1;

impl Forcing {
    fn new(tol: f64) -> Self {
        Forcing {
            tol,
            eta: FORCING_MAX,
            ratio: None,
            step: f64::INFINITY,
            rnorm: f64::INFINITY,
        }
    }

    /// The forcing term of the step from a residual of norm `rnorm`.
    fn next(&mut self, rnorm: f64) -> f64 {
        let Some(ratio) = self.ratio else {
            return self.eta;
        };
        let mut eta = FORCING_GAMMA * ratio * ratio;
        let kept = FORCING_GAMMA * self.eta * self.eta;
        if kept > 0.1 {
            eta = eta.max(kept);
        }
        let expected = self.step * rnorm / self.rnorm;
        if expected > 0.0 {
            eta = eta.max(FORCING_SAFEGUARD * self.tol / expected);
        }
        self.eta = eta.clamp(FORCING_MIN, FORCING_MAX);
        self.eta
    }

    /// Records a step of size `step` (largest change of `P`) that took the residual's norm from
    /// `before` to `after`.
    fn stepped(&mut self, step: f64, before: f64, after: f64) {
        self.ratio = Some((after / before).min(1.0));
        self.step = step;
        self.rnorm = before;
    }
}

fn norm(a: &[f64]) -> f64 {
    a.iter().map(|x| x * x).sum::<f64>().sqrt()
}
