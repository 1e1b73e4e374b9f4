//! Linear algebra of the five-point finite-volume stencil: the matrix in diagonal storage, its
//! incomplete LU factorisation without fill (ILU(0)), an additive-correction multigrid built on
//! it, and restarted GMRES.
//!
//! The multigrid merges 2 × 2 control volumes into one on each coarser level, and its coarse
//! matrices are the sums of the fine couplings between the merged volumes (the Galerkin product
//! with piecewise-constant prolongation: additive-correction multigrid after Hutchinson &
//! Raithby 1986). Merging keeps the five-point structure and the flux balance of each merged
//! volume, so it copes with the jumps of the conductance `Q P H³` by many orders of magnitude
//! between a rail and a deep recess, where a single-level preconditioner stalls. ILU(0) smooths
//! on every level, each coarser level is visited twice (a W-cycle), and the coarsest is solved
//! by dense LU.

use std::cell::RefCell;

use nalgebra::DMatrix;

/// A preconditioner: `x ← M⁻¹ x`.
///
/// ```
/// use hdi_tribology::bearing::linear::Preconditioner;
/// struct Jacobi(Vec<f64>);
/// impl Preconditioner for Jacobi {
///     fn apply(&self, x: &mut [f64]) {
///         x.iter_mut().zip(&self.0).for_each(|(v, d)| *v /= d);
///     }
/// }
/// let mut x = vec![2.0, 6.0];
/// Jacobi(vec![2.0, 3.0]).apply(&mut x);
/// assert_eq!(x, vec![1.0, 2.0]);
/// ```
pub trait Preconditioner {
    /// Applies `M⁻¹` in place.
    fn apply(&self, x: &mut [f64]);
}

/// A matrix on an `nx × ny` tensor grid with the five-point stencil, unknown `c = j nx + i`:
/// row `c` holds `diag[c]` and the coefficients of its west (`c − 1`), east (`c + 1`), south
/// (`c − nx`) and north (`c + nx`) neighbours, zero where the neighbour is outside the grid.
///
/// ```
/// use hdi_tribology::bearing::linear::FivePoint;
/// let mut a = FivePoint::zeros(2, 1);
/// a.diag = vec![2.0, 2.0];
/// a.east[0] = -1.0;
/// let mut y = vec![0.0; 2];
/// a.apply(&[1.0, 1.0], &mut y);
/// assert_eq!(y, vec![1.0, 2.0]);
/// ```
#[derive(Clone, Debug)]
pub struct FivePoint {
    /// Cells along `x`.
    pub nx: usize,
    /// Cells along `y`.
    pub ny: usize,
    /// Diagonal.
    pub diag: Vec<f64>,
    /// West neighbour.
    pub west: Vec<f64>,
    /// East neighbour.
    pub east: Vec<f64>,
    /// South neighbour.
    pub south: Vec<f64>,
    /// North neighbour.
    pub north: Vec<f64>,
}

impl FivePoint {
    /// The zero matrix.
    pub fn zeros(nx: usize, ny: usize) -> Self {
        let n = nx * ny;
        FivePoint {
            nx,
            ny,
            diag: vec![0.0; n],
            west: vec![0.0; n],
            east: vec![0.0; n],
            south: vec![0.0; n],
            north: vec![0.0; n],
        }
    }

    /// Sets every coefficient to zero.
    pub fn clear(&mut self) {
        for v in [
            &mut self.diag,
            &mut self.west,
            &mut self.east,
            &mut self.south,
            &mut self.north,
        ] {
            v.iter_mut().for_each(|x| *x = 0.0);
        }
    }

    /// `y = A x`.
    pub fn apply(&self, x: &[f64], y: &mut [f64]) {
        let nx = self.nx;
        let n = x.len();
        // One pass over the interior rows (all four neighbours inside the storage; a missing
        // neighbour has a zero coefficient), the first and last rows term by term.
        let row = |c: usize| {
            let mut v = self.diag[c] * x[c];
            if c >= 1 {
                v += self.west[c] * x[c - 1];
            }
            if c + 1 < n {
                v += self.east[c] * x[c + 1];
            }
            if c >= nx {
                v += self.south[c] * x[c - nx];
            }
            if c + nx < n {
                v += self.north[c] * x[c + nx];
            }
            v
        };
        if n <= 2 * nx {
            for (c, yc) in y.iter_mut().enumerate().take(n) {
                *yc = row(c);
            }
            return;
        }
        for c in (0..nx).chain(n - nx..n) {
            y[c] = row(c);
        }
        let (lo, hi) = (nx, n - nx);
        let ys = &mut y[lo..hi];
        let d = &self.diag[lo..hi];
        let w = &self.west[lo..hi];
        let e = &self.east[lo..hi];
        let so = &self.south[lo..hi];
        let no = &self.north[lo..hi];
        let xc = &x[lo..hi];
        let xw = &x[lo - 1..hi - 1];
        let xe = &x[lo + 1..hi + 1];
        let xs = &x[..hi - nx];
        let xn = &x[lo + nx..];
        for k in 0..ys.len() {
            ys[k] = d[k] * xc[k] + w[k] * xw[k] + e[k] * xe[k] + so[k] * xs[k] + no[k] * xn[k];
        }
    }
}

/// ILU(0) of a [`FivePoint`] matrix: `L U` with the sparsity of `A`, `L` unit lower triangular.
/// On a tridiagonal matrix (one row of cells) it is the exact LU.
///
/// ```
/// use hdi_tribology::bearing::linear::{FivePoint, Ilu0};
/// let mut a = FivePoint::zeros(3, 1);
/// a.diag = vec![2.0, 2.0, 2.0];
/// a.west = vec![0.0, -1.0, -1.0];
/// a.east = vec![-1.0, -1.0, 0.0];
/// let mut x = vec![1.0, 0.0, 1.0];
/// Ilu0::new(&a).solve(&mut x);
/// assert!(x.iter().all(|v| (v - 1.0).abs() < 1e-15));
/// ```
#[derive(Clone, Debug)]
pub struct Ilu0 {
    nx: usize,
    /// Multipliers of `L` (west, south), what the forward sweep reads, side by side.
    lower: Vec<[f64; 2]>,
    /// Off-diagonals of `U` (east, north; those of `A`) and the reciprocal of its pivot (the
    /// backward sweep multiplies: a division would lengthen its chain of dependent operations),
    /// what the backward sweep reads, side by side.
    upper: Vec<[f64; 3]>,
}

impl Ilu0 {
    /// Factorises `a`; a vanishing pivot is replaced by a small one of the row's scale.
    pub fn new(a: &FivePoint) -> Self {
        let mut f = Ilu0 {
            nx: a.nx,
            lower: Vec::new(),
            upper: Vec::new(),
        };
        f.refactor(a);
        f
    }

    /// Factorises `a` in place of the factors held (their storage is reused).
    pub fn refactor(&mut self, a: &FivePoint) {
        let nx = a.nx;
        let n = a.diag.len();
        self.nx = nx;
        self.lower.clear();
        self.lower.resize(n, [0.0; 2]);
        self.upper.clear();
        self.upper.resize(n, [0.0; 3]);
        // The pivots of the row below (by column) and of the west neighbour.
        let mut pivot_prev_row = vec![0.0; nx.min(n)];
        let mut west_pivot = 0.0;
        for c in 0..n {
            let i = c % nx;
            let mut d = a.diag[c];
            if c >= 1 && a.west[c] != 0.0 {
                let lw = a.west[c] / west_pivot;
                d -= lw * a.east[c - 1];
                self.lower[c][0] = lw;
            }
            if c >= nx && a.south[c] != 0.0 {
                let ls = a.south[c] / pivot_prev_row[i];
                d -= ls * a.north[c - nx];
                self.lower[c][1] = ls;
            }
            if d.abs() < 1e-14 * a.diag[c].abs().max(f64::MIN_POSITIVE) {
                d = 1e-14 * a.diag[c].abs().max(1.0);
            }
            pivot_prev_row[i] = d;
            west_pivot = d;
            self.upper[c] = [a.east[c], a.north[c], 1.0 / d];
        }
    }

    /// `x = (L U)⁻¹ x`, in place.
    ///
    /// Each sweep is a chain of dependent operations along a row (a cell needs its west or
    /// east neighbour's result) and across rows (its south or north neighbour's). Rows are
    /// swept four at a time, each a cell behind the one before it, so that the
    /// processor works on that many independent chains at once; every cell still sees its
    /// neighbours' final values, so the result is the row-by-row sweep's to the bit.
    pub fn solve(&self, x: &mut [f64]) {
        let nx = self.nx;
        let n = x.len();
        if nx == 0 || n == 0 {
            return;
        }
        let ny = n / nx;
        let (lo, up) = (&self.lower[..n], &self.upper[..n]);
        // Forward: the first row has west neighbours only, the rest south ones too.
        for c in 1..nx.min(n) {
            x[c] -= lo[c][0] * x[c - 1];
        }
        let mut j0 = 1;
        while j0 < ny {
            let rows = WAVEFRONT.min(ny - j0);
            for t in 0..nx + rows - 1 {
                for r in 0..rows {
                    if t < r || t - r >= nx {
                        continue;
                    }
                    let i = t - r;
                    let c = (j0 + r) * nx + i;
                    let [w, s] = lo[c];
                    let west = if i > 0 { w * x[c - 1] } else { 0.0 };
                    x[c] -= west + s * x[c - nx];
                }
            }
            j0 += rows;
        }
        // Backward: the last row has east neighbours only.
        let top = n.saturating_sub(nx);
        for c in (top..n).rev() {
            let [e, _, inv] = up[c];
            let east = if c + 1 < n { e * x[c + 1] } else { 0.0 };
            x[c] = (x[c] - east) * inv;
        }
        // Rows ny − 2 down to 0, in blocks whose top row is `j1`.
        let mut done = 1;
        while done < ny {
            let rows = WAVEFRONT.min(ny - done);
            let j1 = ny - 1 - done;
            for t in 0..nx + rows - 1 {
                for r in 0..rows {
                    if t < r || t - r >= nx {
                        continue;
                    }
                    let i = nx - 1 - (t - r);
                    let c = (j1 - r) * nx + i;
                    let [e, no, inv] = up[c];
                    let east = if i + 1 < nx { e * x[c + 1] } else { 0.0 };
                    x[c] = (x[c] - no * x[c + nx] - east) * inv;
                }
            }
            done += rows;
        }
    }
}

/// Rows an [`Ilu0`] sweep works on at once (eight were no faster on the example slider).
const WAVEFRONT: usize = 4;

impl Preconditioner for Ilu0 {
    fn apply(&self, x: &mut [f64]) {
        self.solve(x);
    }
}

/// The coarsest level of the multigrid has fewer control volumes than this along a side.
const COARSEST_SIDE: usize = 12;
/// Factor on the coarse-level correction. A piecewise-constant prolongation represents smooth
/// errors by steps and its Galerkin coarse matrix is too stiff for them, so the plain correction
/// falls short; over-correcting by a factor near 2 makes up for it (Braess 1995). On the example
/// slider's Jacobians (257² volumes) 1.8 cuts the GMRES iterations to a 10⁻⁸ relative residual
/// from 18–24 to 13–18.
const OVER_CORRECTION: f64 = 1.8;

/// One level of the multigrid: the matrix, its ILU(0) smoother, and the cycle's work vectors
/// (allocated once).
#[derive(Clone, Debug)]
struct Level {
    a: FivePoint,
    ilu: Ilu0,
    work: RefCell<Work>,
}

/// Work vectors of one level: its residual, and the coarser level's residual, correction,
/// second residual and second correction.
#[derive(Clone, Debug, Default)]
struct Work {
    r: Vec<f64>,
    rc: Vec<f64>,
    ec: Vec<f64>,
    rr: Vec<f64>,
    e2: Vec<f64>,
}

/// Additive-correction multigrid W-cycle on a [`FivePoint`] matrix, a preconditioner for
/// [`gmres`].
///
/// ```
/// use hdi_tribology::bearing::linear::{gmres, FivePoint, Multigrid};
/// let (nx, ny) = (64, 64);
/// let mut a = FivePoint::zeros(nx, ny);
/// for c in 0..nx * ny {
///     a.diag[c] = 4.0;
///     if c % nx > 0 { a.west[c] = -1.0; }
///     if c % nx + 1 < nx { a.east[c] = -1.0; }
///     if c >= nx { a.south[c] = -1.0; }
///     if c + nx < nx * ny { a.north[c] = -1.0; }
/// }
/// let b = vec![1.0; nx * ny];
/// let mut x = vec![0.0; nx * ny];
/// let stats = gmres(&a, &Multigrid::new(&a), &b, &mut x, 1e-10, 30, 200);
/// assert!(stats.relative_residual <= 1e-10 && stats.iterations < 40);
/// ```
#[derive(Clone, Debug)]
pub struct Multigrid {
    levels: Vec<Level>,
    /// The right-hand side of the cycle being applied.
    rhs: RefCell<Vec<f64>>,
    coarsest: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
}

/// Aggregate of fine index `i` on a side of `n` cells coarsened to `n / 2`.
#[inline]
fn agg(i: usize, nc: usize) -> usize {
    (i / 2).min(nc - 1)
}

fn coarsen(a: &FivePoint) -> FivePoint {
    let mut c = FivePoint::zeros(a.nx / 2, a.ny / 2);
    coarsen_into(a, &mut c);
    c
}

/// The coarse matrix of `a` into `c` (of `a`'s sides halved).
fn coarsen_into(a: &FivePoint, c: &mut FivePoint) {
    let (nx, ny) = (a.nx, a.ny);
    let (mx, my) = (nx / 2, ny / 2);
    debug_assert_eq!((c.nx, c.ny), (mx, my));
    c.clear();
    for j in 0..ny {
        let jc = agg(j, my);
        for i in 0..nx {
            let ic = agg(i, mx);
            let k = j * nx + i;
            let kc = jc * mx + ic;
            c.diag[kc] += a.diag[k];
            // A link within the aggregate adds to the coarse diagonal, one out of it to the
            // coarse link.
            let mut link = |coarse: &mut Vec<f64>, a: f64, within: bool| {
                if within {
                    c.diag[kc] += a;
                } else {
                    coarse[kc] += a;
                }
            };
            if i > 0 {
                link(&mut c.west, a.west[k], agg(i - 1, mx) == ic);
            }
            if i + 1 < nx {
                link(&mut c.east, a.east[k], agg(i + 1, mx) == ic);
            }
            if j > 0 {
                link(&mut c.south, a.south[k], agg(j - 1, my) == jc);
            }
            if j + 1 < ny {
                link(&mut c.north, a.north[k], agg(j + 1, my) == jc);
            }
        }
    }
}

impl Multigrid {
    /// Builds the levels of `a`.
    pub fn new(a: &FivePoint) -> Multigrid {
        let mut levels = vec![Level {
            a: a.clone(),
            ilu: Ilu0::new(a),
            work: RefCell::default(),
        }];
        loop {
            let last = &levels[levels.len() - 1].a;
            if last.nx.min(last.ny) < COARSEST_SIDE || last.nx < 2 || last.ny < 2 {
                break;
            }
            let c = coarsen(last);
            let ilu = Ilu0::new(&c);
            levels.push(Level {
                a: c,
                ilu,
                work: RefCell::default(),
            });
        }
        for k in 0..levels.len() {
            let n = levels[k].a.diag.len();
            let m = levels.get(k + 1).map_or(0, |c| c.a.diag.len());
            levels[k].work = RefCell::new(Work {
                r: vec![0.0; n],
                rc: vec![0.0; m],
                ec: vec![0.0; m],
                rr: vec![0.0; m],
                e2: vec![0.0; m],
            });
        }
        let coarsest = Self::coarsest_lu(&levels);
        Multigrid {
            rhs: RefCell::new(Vec::with_capacity(a.diag.len())),
            levels,
            coarsest,
        }
    }

    /// The multigrid of `a`, a matrix of the same size as the one it was built for, in place:
    /// the levels' matrices and smoothers are recomputed in their storage (a Newton iteration
    /// builds one per step). A matrix of another size builds a new hierarchy.
    ///
    /// ```
    /// use hdi_tribology::bearing::linear::{gmres, FivePoint, Multigrid};
    /// let (nx, ny) = (32, 32);
    /// let laplace = |d: f64| {
    ///     let mut a = FivePoint::zeros(nx, ny);
    ///     for c in 0..nx * ny {
    ///         a.diag[c] = d;
    ///         if c % nx > 0 { a.west[c] = -1.0; }
    ///         if c % nx + 1 < nx { a.east[c] = -1.0; }
    ///         if c >= nx { a.south[c] = -1.0; }
    ///         if c + nx < nx * ny { a.north[c] = -1.0; }
    ///     }
    ///     a
    /// };
    /// let mut mg = Multigrid::new(&laplace(4.0));
    /// let a = laplace(4.5);
    /// mg.refresh(&a);
    /// let mut x = vec![0.0; nx * ny];
    /// let stats = gmres(&a, &mg, &vec![1.0; nx * ny], &mut x, 1e-10, 30, 200);
    /// assert!(stats.relative_residual <= 1e-10);
    /// ```
    pub fn refresh(&mut self, a: &FivePoint) {
        let l0 = &self.levels[0].a;
        if (l0.nx, l0.ny) != (a.nx, a.ny) {
            *self = Multigrid::new(a);
            return;
        }
        for k in 0..self.levels.len() {
            let (done, rest) = self.levels.split_at_mut(k);
            let level = &mut rest[0];
            match done.last() {
                None => {
                    for (dst, src) in [
                        (&mut level.a.diag, &a.diag),
                        (&mut level.a.west, &a.west),
                        (&mut level.a.east, &a.east),
                        (&mut level.a.south, &a.south),
                        (&mut level.a.north, &a.north),
                    ] {
                        dst.copy_from_slice(src);
                    }
                }
                Some(finer) => coarsen_into(&finer.a, &mut level.a),
            }
            level.ilu.refactor(&level.a);
        }
        self.coarsest = Self::coarsest_lu(&self.levels);
    }

    /// Dense LU of the coarsest level (none with a single level).
    fn coarsest_lu(levels: &[Level]) -> Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>> {
        if levels.len() < 2 {
            return None;
        }
        let a = &levels[levels.len() - 1].a;
        let n = a.nx * a.ny;
        let mut m = DMatrix::<f64>::zeros(n, n);
        for k in 0..n {
            m[(k, k)] = a.diag[k];
            if k >= 1 {
                m[(k, k - 1)] = a.west[k];
            }
            if k + 1 < n {
                m[(k, k + 1)] = a.east[k];
            }
            if k >= a.nx {
                m[(k, k - a.nx)] = a.south[k];
            }
            if k + a.nx < n {
                m[(k, k + a.nx)] = a.north[k];
            }
        }
        Some(m.lu())
    }

    fn cycle(&self, l: usize, b: &[f64], x: &mut [f64]) {
        let lev = &self.levels[l];
        if l + 1 == self.levels.len() {
            match &self.coarsest {
                Some(lu) => {
                    let v = nalgebra::DVector::from_column_slice(b);
                    match lu.solve(&v) {
                        Some(s) => x.copy_from_slice(s.as_slice()),
                        None => {
                            x.copy_from_slice(b);
                            lev.ilu.solve(x);
                        }
                    }
                }
                None => {
                    x.copy_from_slice(b);
                    lev.ilu.solve(x);
                }
            }
            return;
        }
        let a = &lev.a;
        let n = b.len();
        let mut guard = lev.work.borrow_mut();
        let Work { r, rc, ec, rr, e2 } = &mut *guard;
        // Pre-smoothing from zero.
        x.copy_from_slice(b);
        lev.ilu.solve(x);
        a.apply(x, r);
        for k in 0..n {
            r[k] = b[k] - r[k];
        }
        // Restriction: sums over the merged volumes.
        let c = &self.levels[l + 1].a;
        let (mx, my) = (c.nx, c.ny);
        rc.iter_mut().for_each(|v| *v = 0.0);
        for j in 0..a.ny {
            let jc = agg(j, my);
            for i in 0..a.nx {
                rc[jc * mx + agg(i, mx)] += r[j * a.nx + i];
            }
        }
        self.cycle(l + 1, rc, ec);
        if l + 2 < self.levels.len() {
            // Second visit of the coarse level (W-cycle) on its own residual.
            c.apply(ec, rr);
            for k in 0..mx * my {
                rr[k] = rc[k] - rr[k];
            }
            self.cycle(l + 1, rr, e2);
            for k in 0..mx * my {
                ec[k] += e2[k];
            }
        }
        // Prolongation: each merged volume's correction to all its volumes, over-corrected.
        for j in 0..a.ny {
            let jc = agg(j, my);
            for i in 0..a.nx {
                x[j * a.nx + i] += OVER_CORRECTION * ec[jc * mx + agg(i, mx)];
            }
        }
        // Post-smoothing.
        a.apply(x, r);
        for k in 0..n {
            r[k] = b[k] - r[k];
        }
        lev.ilu.solve(r);
        for k in 0..n {
            x[k] += r[k];
        }
    }
}

impl Preconditioner for Multigrid {
    fn apply(&self, x: &mut [f64]) {
        let mut b = self.rhs.borrow_mut();
        b.clear();
        b.extend_from_slice(x);
        self.cycle(0, &b, x);
    }
}

/// What a GMRES solve did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KrylovStats {
    /// Iterations (matrix–vector products).
    pub iterations: usize,
    /// Final residual norm relative to the right-hand side's.
    pub relative_residual: f64,
}

/// `aᵀb`, summed in four interleaved partial sums: one running sum is a chain of dependent
/// additions, four keep the processor's adders busy.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut s = [0.0; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in ca.zip(cb) {
        for k in 0..4 {
            s[k] += x[k] * y[k];
        }
    }
    (s[0] + s[1]) + (s[2] + s[3]) + tail
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// Solves `A x = b` by flexible GMRES(`restart`) with `m` as right preconditioner (which may
/// vary from one application to the next), from the start `x`, until `‖b − A x‖ ≤ rtol ‖b‖`
/// or `max_iter` iterations.
///
/// ```
/// use hdi_tribology::bearing::linear::{gmres, FivePoint, Ilu0};
/// let (nx, ny) = (8, 8);
/// let mut a = FivePoint::zeros(nx, ny);
/// for c in 0..nx * ny {
///     a.diag[c] = 4.0;
///     if c % nx > 0 { a.west[c] = -1.0; }
///     if c % nx + 1 < nx { a.east[c] = -1.0; }
///     if c >= nx { a.south[c] = -1.0; }
///     if c + nx < nx * ny { a.north[c] = -1.0; }
/// }
/// let b = vec![1.0; nx * ny];
/// let mut x = vec![0.0; nx * ny];
/// let stats = gmres(&a, &Ilu0::new(&a), &b, &mut x, 1e-10, 30, 200);
/// assert!(stats.relative_residual <= 1e-10);
/// ```
pub fn gmres(
    a: &FivePoint,
    m: &impl Preconditioner,
    b: &[f64],
    x: &mut [f64],
    rtol: f64,
    restart: usize,
    max_iter: usize,
) -> KrylovStats {
    let n = b.len();
    let bnorm = norm(b).max(f64::MIN_POSITIVE);
    let ilu = m;
    let m = restart.max(1);
    // The Krylov basis and its preconditioned vectors are this thread's, kept from one call to
    // the next: allocating 2 × restart vectors per call cost more than the orthogonalisation
    // (fresh pages each time).
    let mut guard = KRYLOV_WORK.with(|w| w.take());
    let KrylovWork { v, zs, w } = &mut guard;
    v.resize_with(m + 1, Vec::new);
    zs.resize_with(m, Vec::new);
    for x in v
        .iter_mut()
        .chain(zs.iter_mut())
        .chain(std::iter::once(&mut *w))
    {
        x.resize(n, 0.0);
    }
    let mut h = vec![vec![0.0; m]; m + 1];
    let (mut cs, mut sn, mut g) = (vec![0.0; m], vec![0.0; m], vec![0.0; m + 1]);
    let mut iters = 0;
    let mut rel;
    loop {
        a.apply(x, w);
        for k in 0..n {
            w[k] = b[k] - w[k];
        }
        let beta = norm(w);
        rel = beta / bnorm;
        if rel <= rtol || iters >= max_iter {
            break;
        }
        for k in 0..n {
            v[0][k] = w[k] / beta;
        }
        g.iter_mut().for_each(|x| *x = 0.0);
        g[0] = beta;
        let mut used = 0;
        for j in 0..m {
            zs[j].copy_from_slice(&v[j]);
            ilu.apply(&mut zs[j]);
            a.apply(&zs[j], w);
            iters += 1;
            // Modified Gram–Schmidt.
            for i in 0..=j {
                let hij = dot(w, &v[i]);
                h[i][j] = hij;
                for (wk, vk) in w.iter_mut().zip(&v[i]) {
                    *wk -= hij * vk;
                }
            }
            let hn = norm(w);
            h[j + 1][j] = hn;
            if hn > 0.0 {
                for k in 0..n {
                    v[j + 1][k] = w[k] / hn;
                }
            }
            for i in 0..j {
                let t = cs[i] * h[i][j] + sn[i] * h[i + 1][j];
                h[i + 1][j] = -sn[i] * h[i][j] + cs[i] * h[i + 1][j];
                h[i][j] = t;
            }
            let r = h[j][j].hypot(h[j + 1][j]);
            if r == 0.0 {
                cs[j] = 1.0;
                sn[j] = 0.0;
            } else {
                cs[j] = h[j][j] / r;
                sn[j] = h[j + 1][j] / r;
            }
            h[j][j] = r;
            h[j + 1][j] = 0.0;
            g[j + 1] = -sn[j] * g[j];
            g[j] *= cs[j];
            used = j + 1;
            if g[j + 1].abs() / bnorm <= rtol || iters >= max_iter || hn == 0.0 {
                break;
            }
        }
        // Back substitution for y, then x += M⁻¹ V y.
        let mut y = vec![0.0; used];
        for i in (0..used).rev() {
            let mut s = g[i];
            for k in i + 1..used {
                s -= h[i][k] * y[k];
            }
            y[i] = s / h[i][i];
        }
        for (i, yi) in y.iter().enumerate() {
            for (xk, zk) in x.iter_mut().zip(&zs[i]) {
                *xk += yi * zk;
            }
        }
    }
    KRYLOV_WORK.with(|w| w.replace(guard));
    KrylovStats {
        iterations: iters,
        relative_residual: rel,
    }
}

/// The work vectors of [`gmres`]: the Krylov basis `v`, its preconditioned vectors `zs`, and
/// one vector for the products.
#[derive(Default)]
struct KrylovWork {
    v: Vec<Vec<f64>>,
    zs: Vec<Vec<f64>>,
    w: Vec<f64>,
}

thread_local! {
    static KRYLOV_WORK: RefCell<KrylovWork> = RefCell::default();
}
