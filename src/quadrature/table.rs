//! Adaptive piecewise cubic Hermite tables with O(1) look-up.
//!
//! The range is split by bisection into panels (at most 2^10); each panel holds
//! uniformly spaced nodes, so a look-up is one index-grid read, one panel read
//! and two node reads, without search, allocation or branching on errors.

use super::QuadratureError;
use crate::cache::codec::{malformed, Reader, Writer};
use crate::{Error, Result};

/// Largest bisection depth of the panel tree; deeper refinement doubles the
/// node count inside a panel instead.
const MAX_DEPTH: u32 = 10;
/// Depth of the initial uniform split (2^INITIAL_DEPTH panels), so that features
/// narrower than the whole range are sampled from the start.
const INITIAL_DEPTH: u32 = 3;
/// Largest node budget a table may be given: 10⁷ nodes take about 400 MB while building. A larger
/// budget with an unreachable tolerance would exhaust memory before failing.
pub const MAX_NODES: usize = 10_000_000;
/// Intervals per panel before any doubling (even, so panels split on nodes).
const INITIAL_INTERVALS: usize = 4;

/// A closed interval `[lo, hi]` of real numbers: bounds of a table's values or slopes over a
/// stretch of its argument.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Span {
    /// Lower bound.
    pub lo: f64,
    /// Upper bound.
    pub hi: f64,
}

impl Span {
    /// The one point `x`.
    pub(crate) fn point(x: f64) -> Self {
        Span { lo: x, hi: x }
    }

    /// The smallest span holding both.
    pub(crate) fn hull(self, o: Span) -> Self {
        Span {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }

    /// Widened by `m ≥ 0` on both sides.
    pub(crate) fn widen(self, m: f64) -> Self {
        Span {
            lo: self.lo - m,
            hi: self.hi + m,
        }
    }

    /// `{x + y}`, widened by the rounding of the sum.
    pub(crate) fn add(self, o: Span) -> Self {
        Span {
            lo: self.lo + o.lo,
            hi: self.hi + o.hi,
        }
        .widen(ROUNDING * (self.magnitude() + o.magnitude()))
    }

    /// `{c x}` for a constant `c`, widened by the rounding of the product.
    pub(crate) fn scale(self, c: f64) -> Self {
        let (a, b) = (c * self.lo, c * self.hi);
        Span {
            lo: a.min(b),
            hi: a.max(b),
        }
        .widen(ROUNDING * a.abs().max(b.abs()))
    }

    /// The largest magnitude in the span.
    pub(crate) fn magnitude(self) -> f64 {
        self.lo.abs().max(self.hi.abs())
    }

    /// Whether both ends are finite.
    pub(crate) fn is_finite(self) -> bool {
        self.lo.is_finite() && self.hi.is_finite()
    }
}

/// Relative allowance for the rounding of a table look-up (a few operations of relative error
/// 1.1e-16 each on numbers no larger than the magnitudes involved), with a wide safety factor.
const ROUNDING: f64 = 1e-12;

/// Bounds of the cubic Hermite interpolant of one interval (values `y0`, `y1`, slopes times the
/// spacing `hm0`, `hm1`) for `t` in `[−ext, 1 + ext]`: the value and the `t`-derivative (divide by
/// the spacing for the slope), each widened by the rounding of an evaluation. On `[0, 1]` both
/// lie within their Bernstein coefficients: `y0, y0 + hm0/3, y1 − hm1/3, y1` for the value and
/// `hm0, 3(y1 − y0) − hm0 − hm1, hm1` for the derivative; `ext` adds the largest derivative (of
/// the value, and of the derivative) times `ext`.
pub(crate) fn hermite_bounds(y0: f64, hm0: f64, y1: f64, hm1: f64, ext: f64) -> (Span, Span) {
    let c = [y0, y0 + hm0 / 3.0, y1 - hm1 / 3.0, y1];
    let g = [hm0, 3.0 * (y1 - y0) - hm0 - hm1, hm1];
    let hull = |x: &[f64]| {
        x.iter().fold(Span::point(x[0]), |s, &v| Span {
            lo: s.lo.min(v),
            hi: s.hi.max(v),
        })
    };
    let (value, slope) = (hull(&c), hull(&g));
    let curvature = 2.0 * (g[1] - g[0]).abs().max((g[2] - g[1]).abs());
    let size = y0.abs() + y1.abs() + hm0.abs() + hm1.abs();
    (
        value.widen(ext * slope.magnitude() + ROUNDING * size),
        slope.widen(ext * curvature + 4.0 * ROUNDING * size),
    )
}

/// Accuracy and size limits of [`Table::build`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TableOptions {
    /// Relative tolerance of interpolated values.
    pub rel_tol: f64,
    /// Absolute tolerance of interpolated values (for values near zero).
    pub abs_tol: f64,
    /// Largest number of stored nodes before the build fails.
    pub max_nodes: usize,
}

impl Default for TableOptions {
    /// `rel_tol = 1e-9`, `abs_tol = 1e-16`, `max_nodes = 200_000`.
    fn default() -> Self {
        TableOptions {
            rel_tol: 1e-9,
            abs_tol: 1e-16,
            max_nodes: 200_000,
        }
    }
}

/// A panel of uniformly spaced nodes (32 bytes, copied into every index cell it
/// covers so that a look-up needs one cell read and one node read).
#[derive(Clone, Copy, Debug)]
struct Panel {
    /// Left end.
    a: f64,
    /// 1/h.
    inv_h: f64,
    /// Node spacing h.
    h: f64,
    /// Index of the first node of this panel in `Table::nodes`.
    start: u32,
    /// Index of the last interval (intervals − 1).
    last: u32,
}

/// Piecewise cubic Hermite table of a smooth function and its derivative.
///
/// Built once by [`Table::build`] with adaptive node placement; evaluated in
/// O(1) by [`Table::eval`].
///
/// ```
/// use hdi_tribology::quadrature::{Table, TableOptions};
/// let t = Table::build(|x: f64| Ok((x.sin(), x.cos())), 0.0, 3.0, &TableOptions::default())
///     .unwrap();
/// let (v, dv) = t.eval(1.234).unwrap();
/// assert!((v - 1.234f64.sin()).abs() <= 1e-9 * 1.234f64.sin().abs() + 1e-16);
/// assert!((dv - 1.234f64.cos()).abs() < 1e-6);
/// assert!(t.eval(3.5).is_none());
/// ```
#[derive(Clone, Debug)]
pub struct Table {
    lo: f64,
    hi: f64,
    /// Number of index cells per unit length.
    inv_cell: f64,
    /// For each cell of the finest panel grid, the panel covering it.
    cells: Vec<Panel>,
    /// Number of distinct panels.
    panel_count: usize,
    /// (value, h·derivative) at every node, panel after panel, with h the
    /// spacing of the node's panel.
    nodes: Vec<[f64; 2]>,
}

/// A panel under construction: its place in the bisection tree, its nodes and
/// the exact values at the midpoints of its intervals.
struct Pending {
    depth: u32,
    /// Position among the 2^depth panels of its depth.
    pos: u64,
    a: f64,
    b: f64,
    xs: Vec<f64>,
    nodes: Vec<[f64; 2]>,
    mids: Vec<[f64; 2]>,
}

impl Pending {
    /// Whether the cubic Hermite interpolant meets the tolerance at every interval's
    /// midpoint, relative to the largest magnitude on the interval (so that a sign change
    /// inside it does not demand absolute accuracy near zero).
    fn accurate(&self, opts: &TableOptions) -> bool {
        (0..self.xs.len() - 1).all(|i| {
            let h = self.xs[i + 1] - self.xs[i];
            let [y0, m0] = self.nodes[i];
            let [y1, m1] = self.nodes[i + 1];
            let (v, _) = cubic(y0, h * m0, y1, h * m1, 0.5);
            let exact = self.mids[i][0];
            let scale = exact.abs().max(y0.abs()).max(y1.abs());
            (v - exact).abs() <= (opts.rel_tol * scale).max(opts.abs_tol)
        })
    }
}

/// The checks of [`Table::build`]'s range and options.
fn check_build(lo: f64, hi: f64, opts: &TableOptions) -> Result<()> {
    crate::error::check_finite("table.lo", lo)?;
    crate::error::check_finite("table.hi", hi)?;
    // Both are finite here, so the comparison is total.
    if hi <= lo {
        return Err(Error::invalid(
            "table.hi",
            format!("must be > table.lo = {lo}, got {hi}"),
        ));
    }
    crate::error::check_non_negative("table.rel_tol", opts.rel_tol)?;
    crate::error::check_non_negative("table.abs_tol", opts.abs_tol)?;
    if opts.rel_tol == 0.0 && opts.abs_tol == 0.0 {
        // Refinement would go on down to rounding-level spacing: ~1e16 nodes.
        return Err(Error::invalid(
            "table.rel_tol",
            "rel_tol and abs_tol are both 0; at least one must be > 0",
        ));
    }
    if opts.max_nodes > MAX_NODES {
        return Err(Error::invalid(
            "table.max_nodes",
            format!(
                "must be at most {MAX_NODES} (about 40 bytes each while building), got {}",
                opts.max_nodes
            ),
        ));
    }
    Ok(())
}

/// Cubic Hermite interpolant on one interval in the local variable t ∈ [0, 1],
/// from values y and scaled slopes hm = h·f' at both ends: returns the value and
/// the t-derivative (divide by h for d/dx). Written as linear interpolation plus
/// a correction that vanishes at both ends, so node values are reproduced exactly.
#[inline(always)]
fn cubic(y0: f64, hm0: f64, y1: f64, hm1: f64, t: f64) -> (f64, f64) {
    let (v, [delta, a, b, u, bracket]) = cubic_value(y0, hm0, y1, hm1, t);
    let dv = delta + (u - t) * bracket - t * u * (a + b);
    (v, dv)
}

/// The value of [`cubic`] alone (the same operations), with the intermediates its derivative
/// reuses.
#[inline(always)]
fn cubic_value(y0: f64, hm0: f64, y1: f64, hm1: f64, t: f64) -> (f64, [f64; 5]) {
    let delta = y1 - y0;
    let a = hm0 - delta;
    let b = hm1 - delta;
    let u = 1.0 - t;
    let bracket = u * a - t * b;
    let v = u * y0 + t * y1 + t * u * bracket;
    (v, [delta, a, b, u, bracket])
}

impl Table {
    /// Tabulates `f` on `[lo, hi]`; `f(d)` must return the exact `(value, derivative)`.
    ///
    /// Nodes are refined until the interpolated value at the midpoint of every
    /// interval agrees with `f` there to `max(rel_tol·|f|, abs_tol)`, with `|f|`
    /// the largest magnitude among the interval's ends and midpoint (the cubic
    /// Hermite error peaks at the midpoint, so this bounds the error on the whole
    /// interval; near a sign change it is relative to the neighbouring values). The
    /// derivative is the derivative of the interpolant: its error is of order
    /// `tolerance / spacing` (it is exact at the nodes).
    ///
    /// Errors: invalid range or options, a non-finite value or derivative from `f`
    /// (or an error returned by `f`), or more than `max_nodes` nodes needed.
    pub fn build<F: FnMut(f64) -> Result<(f64, f64)>>(
        mut f: F,
        lo: f64,
        hi: f64,
        opts: &TableOptions,
    ) -> Result<Table> {
        check_build(lo, hi, opts)?;

        let mut eval = |x: f64| -> Result<[f64; 2]> {
            let (v, d) = f(x)?;
            if !v.is_finite() || !d.is_finite() {
                return Err(Error::invalid(
                    "table.f",
                    format!("tabulated function is not finite at {x}: ({v}, {d})"),
                ));
            }
            Ok([v, d])
        };
        let too_many = |count: usize| {
            Error::from(QuadratureError::TableNodes {
                max_nodes: opts.max_nodes,
                reached: count,
                rel_tol: opts.rel_tol,
                abs_tol: opts.abs_tol,
                lo,
                hi,
            })
        };

        let n0 = INITIAL_INTERVALS;
        let np0 = 1usize << INITIAL_DEPTH;
        let mut node_count = np0 * (n0 + 1);
        if node_count > opts.max_nodes {
            return Err(too_many(node_count));
        }
        let width = hi - lo;
        let edge = |depth: u32, k: u64| -> f64 {
            if k == 1u64 << depth {
                hi
            } else {
                lo + width * (k as f64) / ((1u64 << depth) as f64)
            }
        };
        let grid = |a: f64, b: f64, n: usize| -> Vec<f64> {
            (0..=n)
                .map(|i| {
                    if i == n {
                        b
                    } else {
                        a + (b - a) * (i as f64) / (n as f64)
                    }
                })
                .collect()
        };

        let mut stack: Vec<Pending> = Vec::new();
        for k in (0..np0 as u64).rev() {
            let (a, b) = (edge(INITIAL_DEPTH, k), edge(INITIAL_DEPTH, k + 1));
            let xs = grid(a, b, n0);
            let nodes = xs.iter().map(|&x| eval(x)).collect::<Result<Vec<_>>>()?;
            let mids = xs
                .windows(2)
                .map(|w| eval(0.5 * (w[0] + w[1])))
                .collect::<Result<Vec<_>>>()?;
            stack.push(Pending {
                depth: INITIAL_DEPTH,
                pos: k,
                a,
                b,
                xs,
                nodes,
                mids,
            });
        }

        let mut done: Vec<Pending> = Vec::new();
        while let Some(p) = stack.pop() {
            let n = p.xs.len() - 1;
            if p.accurate(opts) {
                done.push(p);
                continue;
            }
            // Old nodes and old midpoints interleaved become the refined nodes
            // (their abscissae agree with the refined uniform grid up to rounding).
            let mut nodes = Vec::with_capacity(2 * n + 1);
            for i in 0..n {
                nodes.push(p.nodes[i]);
                nodes.push(p.mids[i]);
            }
            nodes.push(p.nodes[n]);
            if (p.b - p.a) / (2 * n) as f64 <= f64::EPSILON * p.a.abs().max(p.b.abs()) {
                return Err(QuadratureError::TableSpacing { x: p.a }.into());
            }
            if p.depth < MAX_DEPTH {
                // Split the panel in two, each keeping n intervals.
                node_count += n + 1;
                if node_count > opts.max_nodes {
                    return Err(too_many(node_count));
                }
                let depth = p.depth + 1;
                let mid_edge = edge(depth, 2 * p.pos + 1);
                let halves = [
                    (2 * p.pos, p.a, mid_edge, 0..=n),
                    (2 * p.pos + 1, mid_edge, p.b, n..=2 * n),
                ];
                // Push the right half first so panels come off the stack left to right.
                for (pos, a, b, range) in halves.into_iter().rev() {
                    let xs = grid(a, b, n);
                    let mids = xs
                        .windows(2)
                        .map(|w| eval(0.5 * (w[0] + w[1])))
                        .collect::<Result<Vec<_>>>()?;
                    stack.push(Pending {
                        depth,
                        pos,
                        a,
                        b,
                        xs,
                        nodes: nodes[range].to_vec(),
                        mids,
                    });
                }
            } else {
                node_count += n;
                if node_count > opts.max_nodes {
                    return Err(too_many(node_count));
                }
                let xs = grid(p.a, p.b, 2 * n);
                let mids = xs
                    .windows(2)
                    .map(|w| eval(0.5 * (w[0] + w[1])))
                    .collect::<Result<Vec<_>>>()?;
                stack.push(Pending {
                    depth: p.depth,
                    pos: p.pos,
                    a: p.a,
                    b: p.b,
                    xs,
                    nodes,
                    mids,
                });
            }
        }

        if node_count > u32::MAX as usize {
            return Err(too_many(node_count));
        }
        Ok(Table::assemble(lo, hi, done, node_count))
    }

    /// The table of the accepted panels `done` (which tile `[lo, hi]`), holding `node_count`
    /// nodes: cells of the finest panel width, each pointing at its panel.
    fn assemble(lo: f64, hi: f64, mut done: Vec<Pending>, node_count: usize) -> Table {
        let max_depth = done.iter().map(|p| p.depth).max().unwrap_or(INITIAL_DEPTH);
        // Order by first covered cell of the finest grid (panels tile the range).
        done.sort_by_key(|p| p.pos << (max_depth - p.depth));
        let ncells = 1usize << max_depth;
        let mut cells = Vec::with_capacity(ncells);
        let mut nodes = Vec::with_capacity(node_count);
        for p in &done {
            let n = p.xs.len() - 1;
            let h = (p.b - p.a) / n as f64;
            let panel = Panel {
                a: p.a,
                inv_h: 1.0 / h,
                h,
                start: nodes.len() as u32,
                last: (n - 1) as u32,
            };
            nodes.extend(p.nodes.iter().map(|&[y, m]| [y, h * m]));
            // Panels are sorted by position, so cells are filled in order.
            let span = 1usize << (max_depth - p.depth);
            cells.extend(std::iter::repeat_n(panel, span));
        }
        Table {
            lo,
            hi,
            inv_cell: ncells as f64 / (hi - lo),
            cells,
            panel_count: done.len(),
            nodes,
        }
    }

    /// `(value, derivative)` at `d`, or `None` outside `[lo, hi]` (or for NaN).
    #[inline]
    pub fn eval(&self, d: f64) -> Option<(f64, f64)> {
        let (pair, t, inv_h) = self.locate(d)?;
        let (v, dt) = cubic(pair[0][0], pair[0][1], pair[1][0], pair[1][1], t);
        Some((v, dt * inv_h))
    }

    /// The value of [`Table::eval`] alone (the same number), or `None` outside `[lo, hi]`.
    ///
    /// ```
    /// use hdi_tribology::quadrature::{Table, TableOptions};
    /// let t = Table::build(|x: f64| Ok((x.sin(), x.cos())), 0.0, 3.0, &TableOptions::default())
    ///     .unwrap();
    /// assert_eq!(t.value(1.3), t.eval(1.3).map(|(v, _)| v));
    /// assert_eq!(t.value(3.5), None);
    /// ```
    #[inline]
    pub fn value(&self, d: f64) -> Option<f64> {
        let (pair, t, _) = self.locate(d)?;
        Some(cubic_value(pair[0][0], pair[0][1], pair[1][0], pair[1][1], t).0)
    }

    /// The two nodes of the interval holding `d`, the local coordinate in it and the inverse
    /// of its width; `None` outside `[lo, hi]` (or for NaN).
    #[inline(always)]
    fn locate(&self, d: f64) -> Option<(&[[f64; 2]], f64, f64)> {
        if !(d >= self.lo && d <= self.hi) {
            return None;
        }
        let p = self.panel(d);
        let s = (d - p.a) * p.inv_h;
        // Clamp in floating point (a negative `s` from rounding at a panel edge
        // goes to interval 0); the i32 conversion is then a single instruction.
        let j = s.clamp(0.0, f64::from(p.last)) as i32;
        let t = s - f64::from(j);
        let j = j as usize;
        let k = p.start as usize + j;
        Some((&self.nodes[k..k + 2], t, p.inv_h))
    }

    /// Bounds of [`Table::eval`]'s value and derivative at every `d` in `[a, b]`, or `None`
    /// unless `lo ≤ a ≤ b ≤ hi`. Follows the look-up: every panel and interval that a point of
    /// `[a, b]` can be given (the index computations are monotone in `d`), the intervals at a
    /// panel's ends a little beyond `[0, 1]` in `t` (a point within rounding of a panel edge may
    /// be given the neighbouring panel).
    pub(crate) fn bounds(&self, a: f64, b: f64) -> Option<(Span, Span)> {
        if !(a >= self.lo && b <= self.hi && a <= b) {
            return None;
        }
        let cell =
            |d: f64| (((d - self.lo) * self.inv_cell) as i32 as usize).min(self.cells.len() - 1);
        let interval =
            |p: &Panel, d: f64| ((d - p.a) * p.inv_h).clamp(0.0, f64::from(p.last)) as i32 as u32;
        let (first, last) = (cell(a), cell(b));
        let mut out: Option<(Span, Span)> = None;
        let mut c = first;
        while c <= last {
            let p = &self.cells[c];
            let mut end = c;
            while end < last && self.cells[end + 1].start == p.start {
                end += 1;
            }
            let j0 = if c == first { interval(p, a) } else { 0 };
            let j1 = if end == last { interval(p, b) } else { p.last };
            let ext = 1e-12 * f64::from(p.last + 2);
            for j in j0..=j1 {
                let k = (p.start + j) as usize;
                let ([y0, hm0], [y1, hm1]) = (self.nodes[k], self.nodes[k + 1]);
                let (v, s) = hermite_bounds(y0, hm0, y1, hm1, ext);
                let s = Span {
                    lo: s.lo * p.inv_h,
                    hi: s.hi * p.inv_h,
                }
                .widen(ROUNDING * s.magnitude() * p.inv_h);
                out = Some(match out {
                    Some((ov, os)) => (ov.hull(v), os.hull(s)),
                    None => (v, s),
                });
            }
            c = end + 1;
        }
        out
    }

    /// The panel covering `d` (which must be inside the range).
    #[inline(always)]
    fn panel(&self, d: f64) -> &Panel {
        // d is inside [lo, hi], so the index is in 0..=cells (cells ≤ 2^10).
        let cell = ((d - self.lo) * self.inv_cell) as i32 as usize;
        &self.cells[cell.min(self.cells.len() - 1)]
    }

    /// The tabulated range `(lo, hi)`.
    pub fn range(&self) -> (f64, f64) {
        (self.lo, self.hi)
    }

    /// Number of stored nodes (panel edges are stored once per panel).
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// True when the table holds no node (never the case for a built table).
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Node spacing of the interval containing `d`, or `None` outside the range.
    pub fn spacing_at(&self, d: f64) -> Option<f64> {
        if !(d >= self.lo && d <= self.hi) {
            return None;
        }
        Some(self.panel(d).h)
    }

    /// Number of index cells (a power of two: the cells of the finest panel width, each inside
    /// one panel).
    pub(crate) fn cell_count(&self) -> usize {
        self.cells.len()
    }

    /// Node spacing of the panel holding index cell `c` (`c < cell_count()`).
    pub(crate) fn cell_spacing(&self, c: usize) -> f64 {
        self.cells[c].h
    }

    /// Number of panels of uniform spacing.
    pub fn panels(&self) -> usize {
        self.panel_count
    }

    /// Appends the table to a cache payload: every stored number as its bits, each panel once
    /// with the number of index cells it covers.
    pub(crate) fn encode(&self, w: &mut Writer) {
        w.f64(self.lo);
        w.f64(self.hi);
        w.f64(self.inv_cell);
        w.usize(self.panel_count);
        for run in self.cells.chunk_by(|x, y| x.start == y.start) {
            let p = run[0];
            w.f64(p.a);
            w.f64(p.inv_h);
            w.f64(p.h);
            w.usize(p.start as usize);
            w.usize(p.last as usize);
            w.usize(run.len());
        }
        w.usize(self.nodes.len());
        for &[y, m] in &self.nodes {
            w.f64(y);
            w.f64(m);
        }
    }

    /// A table written by [`Table::encode`], checked so that every look-up stays inside it.
    pub(crate) fn decode(r: &mut Reader<'_>) -> Result<Table> {
        let (lo, hi, inv_cell) = (r.finite()?, r.finite()?, r.finite()?);
        if !(lo < hi && inv_cell > 0.0) {
            return Err(malformed(format!(
                "a table on [{lo:e}, {hi:e}] with {inv_cell:e} cells per unit"
            )));
        }
        let panel_count = r.count(48)?;
        let mut panels = Vec::with_capacity(panel_count);
        for _ in 0..panel_count {
            let (a, inv_h, h) = (r.finite()?, r.finite()?, r.finite()?);
            let (start, last) = (r.usize()?, r.usize()?);
            let span = r.usize()?;
            panels.push((a, inv_h, h, start, last, span));
        }
        let n = r.count(16)?;
        let nodes = (0..n)
            .map(|_| Ok([r.finite()?, r.finite()?]))
            .collect::<Result<Vec<[f64; 2]>>>()?;
        let mut cells = Vec::new();
        for (a, inv_h, h, start, last, span) in panels {
            // A look-up reads nodes start + j and start + j + 1 for j ≤ last.
            let fits = start
                .checked_add(last)
                .and_then(|e| e.checked_add(1))
                .is_some_and(|e| e < n && e <= u32::MAX as usize);
            if !fits || span == 0 || cells.len() + span > 1 << MAX_DEPTH {
                return Err(malformed(format!(
                    "a panel of nodes {start}..={start}+{last}+1 over {span} cells, {n} nodes"
                )));
            }
            let panel = Panel {
                a,
                inv_h,
                h,
                start: start as u32,
                last: last as u32,
            };
            cells.extend(std::iter::repeat_n(panel, span));
        }
        if !cells.len().is_power_of_two() {
            return Err(malformed(format!("a table of {} cells", cells.len())));
        }
        Ok(Table {
            lo,
            hi,
            inv_cell,
            cells,
            panel_count,
            nodes,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounds_hold_every_look_up_of_the_stretch() {
        // A function with a narrow feature, so that the panels differ in spacing.
        let f = |x: f64| {
            Ok(((5.0 * x).sin() + (-(x - 1.0).powi(2) * 400.0).exp(), {
                5.0 * (5.0 * x).cos() - 800.0 * (x - 1.0) * (-(x - 1.0).powi(2) * 400.0).exp()
            }))
        };
        let t = Table::build(f, 0.0, 3.0, &TableOptions::default()).unwrap();
        assert!(t.panels() > 1);
        let mut x = 0.123_f64;
        for _ in 0..300 {
            let a = 3.0 * ((x * 7.77) % 1.0);
            let b = (a + 3.0 * (x % 1.0).powi(3)).min(3.0);
            x = (x + 0.618_033_988_749_895) % 1.0 + 0.01;
            let (v, s) = t.bounds(a, b).unwrap();
            for i in 0..=50 {
                let d = if i == 50 {
                    b
                } else {
                    a + (b - a) * i as f64 / 50.0
                };
                let (y, dy) = t.eval(d).unwrap();
                assert!(v.lo <= y && y <= v.hi, "value at {d} in [{a}, {b}]");
                assert!(s.lo <= dy && dy <= s.hi, "slope at {d} in [{a}, {b}]");
            }
        }
        // Tight where the function is simple: a cubic is its own interpolant.
        let c = Table::build(
            |x| Ok((x * x * x, 3.0 * x * x)),
            0.0,
            1.0,
            &TableOptions::default(),
        )
        .unwrap();
        let (v, _) = c.bounds(0.5, 0.5).unwrap();
        assert!(v.lo <= 0.125 && v.hi >= 0.125 && v.hi - v.lo < 0.1);
        assert!(t.bounds(-0.1, 1.0).is_none() && t.bounds(1.0, 3.5).is_none());
    }
}
