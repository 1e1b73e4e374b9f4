//! Adaptive piecewise cubic Hermite tables with O(1) look-up.
//!
//! The range is split by bisection into panels (at most 2^10); each panel holds
//! uniformly spaced nodes, so a look-up is one index-grid read, one panel read
//! and two node reads, without search, allocation or branching on errors.

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

/// Cubic Hermite interpolant on one interval in the local variable t ∈ [0, 1],
/// from values y and scaled slopes hm = h·f' at both ends: returns the value and
/// the t-derivative (divide by h for d/dx). Written as linear interpolation plus
/// a correction that vanishes at both ends, so node values are reproduced exactly.
#[inline(always)]
fn cubic(y0: f64, hm0: f64, y1: f64, hm1: f64, t: f64) -> (f64, f64) {
    let delta = y1 - y0;
    let a = hm0 - delta;
    let b = hm1 - delta;
    let u = 1.0 - t;
    let bracket = u * a - t * b;
    let v = u * y0 + t * y1 + t * u * bracket;
    let dv = delta + (u - t) * bracket - t * u * (a + b);
    (v, dv)
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
            Error::no_convergence(
                "table build",
                format!(
                    "needs more than max_nodes = {} nodes (reached {count}) for rel_tol = {:e}, \
                     abs_tol = {:e} on [{lo:e}, {hi:e}]",
                    opts.max_nodes, opts.rel_tol, opts.abs_tol
                ),
            )
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
            let ok = (0..n).all(|i| {
                let h = p.xs[i + 1] - p.xs[i];
                let [y0, m0] = p.nodes[i];
                let [y1, m1] = p.nodes[i + 1];
                let (v, _) = cubic(y0, h * m0, y1, h * m1, 0.5);
                let exact = p.mids[i][0];
                // Relative to the largest magnitude on the interval, so that a sign
                // change inside it does not demand absolute accuracy near zero.
                let scale = exact.abs().max(y0.abs()).max(y1.abs());
                (v - exact).abs() <= (opts.rel_tol * scale).max(opts.abs_tol)
            });
            if ok {
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
                return Err(Error::no_convergence(
                    "table build",
                    format!("node spacing reaches rounding level near {}", p.a),
                ));
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

        let max_depth = done.iter().map(|p| p.depth).max().unwrap_or(INITIAL_DEPTH);
        // Order by first covered cell of the finest grid (panels tile the range).
        done.sort_by_key(|p| p.pos << (max_depth - p.depth));
        let ncells = 1usize << max_depth;
        if node_count > u32::MAX as usize {
            return Err(too_many(node_count));
        }
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
        Ok(Table {
            lo,
            hi,
            inv_cell: ncells as f64 / width,
            cells,
            panel_count: done.len(),
            nodes,
        })
    }

    /// `(value, derivative)` at `d`, or `None` outside `[lo, hi]` (or for NaN).
    #[inline]
    pub fn eval(&self, d: f64) -> Option<(f64, f64)> {
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
        let pair = &self.nodes[k..k + 2];
        let (v, dt) = cubic(pair[0][0], pair[0][1], pair[1][0], pair[1][1], t);
        Some((v, dt * p.inv_h))
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

    /// Number of panels of uniform spacing.
    pub fn panels(&self) -> usize {
        self.panel_count
    }
}
