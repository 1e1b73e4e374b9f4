//! One table holding the hot-path sums on a shared grid (the static, per-V² and contact forces,
//! and the real contact area), so that an evaluation costs a single index computation and two
//! node reads, and the values alone (an ODE's right-hand side) skip the slopes.
//!
//! Two kinds: smooth sums are tabulated afresh on equal panels to their tolerance
//! ([`Fused::build`]); sums with kinks (a contact onset at each peak of a few-peak scene) are
//! split at the kinks like their separate tables, and on each stretch the shared grid is the
//! union of the separate tables' grids, so that every function's piecewise cubic is the
//! separate table's own, to rounding ([`Fused::from_tables`]).

use crate::cache::codec::{malformed, Reader, Writer};
use crate::quadrature::{hermite_bounds, Span, Table};
use crate::Result;

/// Panels of equal width; each holds a uniform grid refined until every function agrees with its
/// source at every interval midpoint.
const PANELS: usize = 256;
/// Node budget of the fused table; beyond it the fused table is not built (the separate tables
/// remain).
const MAX_NODES: usize = 400_000;

#[derive(Clone, Copy, Debug)]
struct Panel {
    a: f64,
    h: f64,
    inv_h: f64,
    start: usize,
    n: usize,
}

/// A stretch between two cuts (or the whole range): `count` panels of equal width from panel
/// `first`.
#[derive(Clone, Copy, Debug)]
struct Segment {
    lo: f64,
    inv_panel: f64,
    first: usize,
    count: usize,
}

/// Values and slopes of `N` functions at each node. `CUT`: split at kinks into segments
/// ([`Fused::from_tables`]); without, [`PANELS`] equal panels over the whole range
/// ([`Fused::build`]), whose look-up reads no segment (a constant, not a branch, tells them apart).
#[derive(Clone, Debug)]
pub(crate) struct Fused<const N: usize, const CUT: bool = false> {
    lo: f64,
    hi: f64,
    /// The first segment's `inv_panel` (the only one's, without cuts).
    inv_panel: f64,
    /// Interior cuts, ascending: segment `k` covers `[cuts[k-1], cuts[k])` (right-continuous, as
    /// the separate tables).
    cuts: Vec<f64>,
    segments: Vec<Segment>,
    panels: Vec<Panel>,
    nodes: Vec<[(f64, f64); N]>,
}

/// The interval of a panel holding the local coordinate `s` (in interval widths from the panel's
/// start), clamped to the panel.
#[inline]
fn interval_index(p: &Panel, s: f64) -> usize {
    s.clamp(0.0, (p.n - 1) as f64) as u32 as usize
}

/// An interval's two end nodes, the local coordinate `t ∈ [0, 1]` in it and its width.
type Interval<'a, const N: usize> = (&'a [(f64, f64); N], &'a [(f64, f64); N], f64, f64);

/// The cubic Hermite weights of the two values and two slopes at `t` in an interval of width `h`.
#[inline]
fn weights(t: f64, h: f64) -> [f64; 4] {
    let t2 = t * t;
    let t3 = t2 * t;
    [
        2.0 * t3 - 3.0 * t2 + 1.0,
        (t3 - 2.0 * t2 + t) * h,
        3.0 * t2 - 2.0 * t3,
        (t3 - t2) * h,
    ]
}

/// The weights of the same cubic's derivative.
#[inline]
fn slope_weights(t: f64, h: f64) -> [f64; 4] {
    let t2 = t * t;
    [
        (6.0 * t2 - 6.0 * t) / h,
        3.0 * t2 - 4.0 * t + 1.0,
        (6.0 * t - 6.0 * t2) / h,
        3.0 * t2 - 2.0 * t,
    ]
}

/// `w · (y0, m0, y1, m1)`.
#[inline]
fn combine(w: &[f64; 4], (y0, m0): (f64, f64), (y1, m1): (f64, f64)) -> f64 {
    w[0] * y0 + w[1] * m0 + w[2] * y1 + w[3] * m1
}

impl<const N: usize> Fused<N> {
    /// Tabulates `f` (`N` (value, slope) pairs) on `[lo, hi]` against `f` itself, which is meant
    /// to be cheap (the separate tables), to the tolerance `(rel, abs)` of each function. `None`
    /// when the node budget is exceeded or `f` is not finite.
    pub(crate) fn build(
        f: impl Fn(f64) -> [(f64, f64); N],
        lo: f64,
        hi: f64,
        tols: [(f64, f64); N],
    ) -> Option<Self> {
        let width = (hi - lo) / PANELS as f64;
        let mut panels = Vec::with_capacity(PANELS);
        let mut nodes: Vec<[(f64, f64); N]> = Vec::new();
        for p in 0..PANELS {
            let a = lo + p as f64 * width;
            let b = if p + 1 == PANELS { hi } else { a + width };
            let mut n = 4;
            loop {
                let h = (b - a) / n as f64;
                let xs: Vec<f64> = (0..=n)
                    .map(|i| if i == n { b } else { a + i as f64 * h })
                    .collect();
                let vals: Vec<[(f64, f64); N]> = xs.iter().map(|&x| f(x)).collect();
                if vals
                    .iter()
                    .flatten()
                    .any(|&(v, m)| !(v.is_finite() && m.is_finite()))
                {
                    return None;
                }
                let ok = (0..n).all(|i| {
                    let exact = f(0.5 * (xs[i] + xs[i + 1]));
                    let w = weights(0.5, xs[i + 1] - xs[i]);
                    (0..N).all(|k| {
                        let v = combine(&w, vals[i][k], vals[i + 1][k]);
                        let (rel, abs) = tols[k];
                        (v - exact[k].0).abs() <= (rel * exact[k].0.abs()).max(abs)
                    })
                });
                if ok {
                    panels.push(Panel {
                        a,
                        h,
                        inv_h: 1.0 / h,
                        start: nodes.len(),
                        n,
                    });
                    nodes.extend(vals);
                    break;
                }
                n *= 2;
                if nodes.len() + n > MAX_NODES {
                    return None;
                }
            }
        }
        let whole = Segment {
            lo,
            inv_panel: 1.0 / width,
            first: 0,
            count: PANELS,
        };
        Some(Fused::assemble(
            lo,
            hi,
            Vec::new(),
            vec![whole],
            panels,
            nodes,
        ))
    }
}

impl<const N: usize> Fused<N, true> {
    /// The `N` functions whose separate tables are `parts` (function `k`'s tables on the
    /// segments between `lo`, the `cuts` and `hi`; `None` for a function that is zero) on one
    /// grid per segment: the union of the separate tables' grids there. Each separate table's
    /// nodes are nodes of the union, and a cubic is its own Hermite interpolant, so the fused
    /// look-up gives each function's separate look-up to rounding. `None` when a table does
    /// not cover its segment, a value is not finite or the node budget is exceeded.
    pub(crate) fn from_tables(
        lo: f64,
        hi: f64,
        cuts: &[f64],
        parts: [Option<&[Table]>; N],
    ) -> Option<Self> {
        let count = cuts.len() + 1;
        if parts.iter().all(Option::is_none) || parts.iter().flatten().any(|p| p.len() != count) {
            return None;
        }
        let mut edges = Vec::with_capacity(count + 1);
        edges.push(lo);
        edges.extend_from_slice(cuts);
        edges.push(hi);
        let (mut segments, mut panels, mut nodes) = (Vec::new(), Vec::new(), Vec::new());
        for (s, w) in edges.windows(2).enumerate() {
            let (a, b) = (w[0], w[1]);
            let tables: Vec<&Table> = parts.iter().flatten().map(|p| &p[s]).collect();
            if tables.iter().any(|t| t.range() != (a, b)) {
                return None;
            }
            // Cells of the finest index grid among the tables (powers of two, so each table's
            // cell holds a whole number of these).
            let cells = tables.iter().map(|t| t.cell_count()).max()?;
            segments.push(Segment {
                lo: a,
                inv_panel: cells as f64 / (b - a),
                first: panels.len(),
                count: cells,
            });
            let edge = |c: usize| {
                if c == cells {
                    b
                } else {
                    a + (b - a) * c as f64 / cells as f64
                }
            };
            for c in 0..cells {
                let (ca, cb) = (edge(c), edge(c + 1));
                // The finest spacing of any table here; its intervals per cell are a power of two.
                let n = tables
                    .iter()
                    .map(|t| {
                        let h = t.cell_spacing(c / (cells / t.cell_count()));
                        ((cb - ca) / h).round().max(1.0) as usize
                    })
                    .max()?
                    .next_power_of_two();
                // The budget before the nodes are made, not after.
                if nodes.len() + n + 1 > MAX_NODES {
                    return None;
                }
                let h = (cb - ca) / n as f64;
                panels.push(Panel {
                    a: ca,
                    h,
                    inv_h: 1.0 / h,
                    start: nodes.len(),
                    n,
                });
                for i in 0..=n {
                    let x = if i == n { cb } else { ca + i as f64 * h };
                    let mut node = [(0.0, 0.0); N];
                    for (k, p) in parts.iter().enumerate() {
                        if let Some(p) = p {
                            let (v, m) = p[s].eval(x)?;
                            if !(v.is_finite() && m.is_finite()) {
                                return None;
                            }
                            node[k] = (v, m);
                        }
                    }
                    nodes.push(node);
                }
            }
        }
        Some(Fused::assemble(
            lo,
            hi,
            cuts.to_vec(),
            segments,
            panels,
            nodes,
        ))
    }
}

impl<const N: usize, const CUT: bool> Fused<N, CUT> {
    /// The table of its parts.
    fn assemble(
        lo: f64,
        hi: f64,
        cuts: Vec<f64>,
        segments: Vec<Segment>,
        panels: Vec<Panel>,
        nodes: Vec<[(f64, f64); N]>,
    ) -> Self {
        Fused {
            lo,
            hi,
            inv_panel: segments[0].inv_panel,
            cuts,
            segments,
            panels,
            nodes,
        }
    }

    /// The interval holding `d`: its two end nodes, the local coordinate in it and its width;
    /// `None` outside the range.
    #[inline]
    fn locate(&self, d: f64) -> Option<Interval<'_, N>> {
        if !(d >= self.lo && d <= self.hi) {
            return None;
        }
        let p = if CUT {
            self.panel_index(self.segment(d), d)
        } else {
            // The one segment of `PANELS` panels from `lo`: `panel_index` of it, without reading
            // it.
            ((d - self.lo) * self.inv_panel).min((PANELS - 1) as f64) as u32 as usize
        };
        let pan = &self.panels[p];
        let s = (d - pan.a) * pan.inv_h;
        let j = interval_index(pan, s);
        let k = pan.start + j;
        Some((&self.nodes[k], &self.nodes[k + 1], s - j as f64, pan.h))
    }

    /// The segment holding `d` (inside the range): right-continuous at the cuts.
    #[inline]
    fn segment(&self, d: f64) -> &Segment {
        if self.cuts.is_empty() {
            &self.segments[0]
        } else {
            &self.segments[self.cuts.partition_point(|&c| c <= d)]
        }
    }

    /// The panel of `d` in its segment `seg`. `d` is inside the segment, so the index is small
    /// and non-negative up to rounding: clamped in floating point, the conversion is one
    /// instruction.
    #[inline]
    fn panel_index(&self, seg: &Segment, d: f64) -> usize {
        seg.first + ((d - seg.lo) * seg.inv_panel).min((seg.count - 1) as f64) as u32 as usize
    }

    /// The `N` (value, slope) pairs at `d`, or `None` outside the range.
    #[inline]
    pub(crate) fn eval(&self, d: f64) -> Option<[(f64, f64); N]> {
        let (n0, n1, t, h) = self.locate(d)?;
        let (w, dw) = (weights(t, h), slope_weights(t, h));
        Some(std::array::from_fn(|k| {
            (combine(&w, n0[k], n1[k]), combine(&dw, n0[k], n1[k]))
        }))
    }

    /// The `N` values alone at `d` (the same numbers as [`Fused::eval`]'s), or `None` outside
    /// the range: the right-hand side of an ODE needs no slope.
    #[inline]
    pub(crate) fn values(&self, d: f64) -> Option<[f64; N]> {
        let (n0, n1, t, h) = self.locate(d)?;
        let w = weights(t, h);
        Some(std::array::from_fn(|k| combine(&w, n0[k], n1[k])))
    }

    /// Bounds of the first `K` (at most `N`) of [`Fused::eval`]'s (value, slope) pairs at every `d`
    /// in `[a, b]`, or `None` unless `lo ≤ a ≤ b ≤ hi`: the hull of the bounds of every interval
    /// a point of `[a, b]` can be given (as [`crate::quadrature::Table`]'s bounds).
    pub(crate) fn bounds<const K: usize>(&self, a: f64, b: f64) -> Option<[(Span, Span); K]> {
        if !(a >= self.lo && b <= self.hi && a <= b) {
            return None;
        }
        // The same intervals as `locate` gives the points of [a, b]; the panels are in order
        // along the range, across the segments.
        let interval = |p: &Panel, d: f64| interval_index(p, (d - p.a) * p.inv_h);
        let (first, last) = (
            self.panel_index(self.segment(a), a),
            self.panel_index(self.segment(b), b),
        );
        let mut out: Option<[(Span, Span); K]> = None;
        for (i, p) in self.panels[first..=last].iter().enumerate() {
            let j0 = if i == 0 { interval(p, a) } else { 0 };
            let j1 = if first + i == last {
                interval(p, b)
            } else {
                p.n - 1
            };
            let ext = 1e-12 * (p.n + 1) as f64;
            for j in j0..=j1 {
                let (n0, n1) = (&self.nodes[p.start + j], &self.nodes[p.start + j + 1]);
                let each = |k: usize| {
                    let (v, s) =
                        hermite_bounds(n0[k].0, p.h * n0[k].1, n1[k].0, p.h * n1[k].1, ext);
                    let s = Span {
                        lo: s.lo * p.inv_h,
                        hi: s.hi * p.inv_h,
                    };
                    (v, s.widen(1e-12 * s.magnitude()))
                };
                let here: [(Span, Span); K] = std::array::from_fn(each);
                out = Some(match out {
                    Some(o) => {
                        std::array::from_fn(|k| (o[k].0.hull(here[k].0), o[k].1.hull(here[k].1)))
                    }
                    None => here,
                });
            }
        }
        out
    }

    /// Number of nodes.
    pub(crate) fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Appends the table to a cache payload, every number as its bits.
    pub(crate) fn encode(&self, w: &mut Writer) {
        w.f64(self.lo);
        w.f64(self.hi);
        w.f64s(&self.cuts);
        w.usize(self.segments.len());
        for s in &self.segments {
            w.f64(s.lo);
            w.f64(s.inv_panel);
            w.usize(s.first);
            w.usize(s.count);
        }
        w.usize(self.panels.len());
        for p in &self.panels {
            w.f64(p.a);
            w.f64(p.h);
            w.f64(p.inv_h);
            w.usize(p.start);
            w.usize(p.n);
        }
        w.usize(self.nodes.len());
        for node in &self.nodes {
            for &(v, m) in node {
                w.f64(v);
                w.f64(m);
            }
        }
    }

    /// A table written by [`Fused::encode`], checked so that every look-up stays inside it.
    pub(crate) fn decode(r: &mut Reader<'_>) -> Result<Self> {
        let (lo, hi) = (r.finite()?, r.finite()?);
        if lo >= hi {
            return Err(malformed(format!("a fused table on [{lo:e}, {hi:e}]")));
        }
        let cuts = r.finite_f64s()?;
        if !cuts.windows(2).all(|w| w[0] < w[1]) || cuts.iter().any(|&c| !(c > lo && c < hi)) {
            return Err(malformed("a fused table's cuts".to_string()));
        }
        let nseg = r.count(32)?;
        if nseg != cuts.len() + 1 {
            return Err(malformed(format!(
                "a fused table of {nseg} segments between {} cuts",
                cuts.len()
            )));
        }
        let segments = (0..nseg)
            .map(|_| {
                Ok(Segment {
                    lo: r.finite()?,
                    inv_panel: r.finite()?,
                    first: r.usize()?,
                    count: r.usize()?,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let whole = |s: &Segment| s.lo == lo && s.first == 0 && s.count == PANELS;
        if !(CUT || (cuts.is_empty() && whole(&segments[0]))) {
            return Err(malformed(format!(
                "a fused table of {nseg} segments where one of {PANELS} panels was expected"
            )));
        }
        let count = r.count(40)?;
        // A look-up reads panels first..first + count of its segment.
        for s in &segments {
            if s.inv_panel <= 0.0
                || s.count == 0
                || s.first.checked_add(s.count).is_none_or(|e| e > count)
            {
                return Err(malformed(format!(
                    "a fused segment of panels {}+{}, {count} panels",
                    s.first, s.count
                )));
            }
        }
        let panels = (0..count)
            .map(|_| {
                Ok(Panel {
                    a: r.finite()?,
                    h: r.finite()?,
                    inv_h: r.finite()?,
                    start: r.usize()?,
                    n: r.usize()?,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let len = r.count(16 * N)?;
        let mut nodes = Vec::with_capacity(len);
        for _ in 0..len {
            let mut node = [(0.0, 0.0); N];
            for x in &mut node {
                *x = (r.finite()?, r.finite()?);
            }
            nodes.push(node);
        }
        // A look-up reads nodes start + j and start + j + 1 for j < n.
        for p in &panels {
            if p.n == 0 || p.start.checked_add(p.n).is_none_or(|e| e >= len) {
                return Err(malformed(format!(
                    "a fused panel of nodes {}..={}+{}, {len} nodes",
                    p.start, p.start, p.n
                )));
            }
        }
        Ok(Fused::assemble(lo, hi, cuts, segments, panels, nodes))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cache::codec::{Reader, Writer};
    use crate::quadrature::TableOptions;

    #[test]
    fn fused_table_meets_its_tolerance_for_each_function() {
        let f = |x: f64| {
            [
                (x.sin(), x.cos()),
                ((-x).exp(), -(-x).exp()),
                (x.powi(3), 3.0 * x * x),
            ]
        };
        let opts = TableOptions::default();
        let tol = (opts.rel_tol, opts.abs_tol);
        let t = Fused::build(f, 0.0, 3.0, [tol; 3]).unwrap();
        for i in 0..1000 {
            let x = 3.0 * ((0.5 + i as f64 * 0.618_033_988_749_895) % 1.0);
            let got = t.eval(x).unwrap();
            for (k, (v, _)) in f(x).into_iter().enumerate() {
                // the builder checks midpoints; elsewhere the cubic error is smaller or similar
                assert!(
                    (got[k].0 - v).abs() <= 2.0 * (opts.rel_tol * v.abs()).max(opts.abs_tol),
                    "{k} at {x}"
                );
            }
        }
        // a cubic is reproduced exactly, slope included
        let (v, s) = t.eval(1.234).unwrap()[2];
        assert!((v - 1.234f64.powi(3)).abs() < 1e-14 && (s - 3.0 * 1.234 * 1.234).abs() < 1e-13);
        assert!(t.eval(3.1).is_none() && t.eval(f64::NAN).is_none());
        // the values alone are the same numbers, to the bit
        for x in [0.0, 0.37, 1.234, 2.999, 3.0] {
            let (all, values) = (t.eval(x).unwrap(), t.values(x).unwrap());
            assert_eq!(all.map(|p| p.0), values);
        }
        assert!(t.values(-0.1).is_none());
    }

    /// Three functions with Hertz-like onsets `(z − x)^{3/2}` at two of the cuts, tabulated
    /// separately per segment as the interface tables are, and fused on the union grid.
    fn kinked() -> (Vec<Vec<Table>>, Fused<3, true>, Vec<f64>) {
        let cuts = vec![0.9, 1.7];
        let onset = |x: f64, z: f64, c: f64| {
            let u = (z - x).max(0.0);
            (c * u.powf(1.5), -1.5 * c * u.sqrt())
        };
        let fs: [&dyn Fn(f64) -> (f64, f64); 3] = [
            &|x| {
                let (a, da) = onset(x, 0.9, 2.0);
                let (b, db) = onset(x, 1.7, 0.5);
                (a + b + (-x).exp(), da + db - (-x).exp())
            },
            &|x| ((3.0 * x).sin() * 1e-3, 3e-3 * (3.0 * x).cos()),
            &|x| onset(x, 1.7, 1e-6),
        ];
        let mut edges = vec![0.0];
        edges.extend(&cuts);
        edges.push(3.0);
        let opts = TableOptions::default();
        let tables: Vec<Vec<Table>> = fs
            .iter()
            .map(|f| {
                edges
                    .windows(2)
                    .map(|w| Table::build(|x| Ok(f(x)), w[0], w[1], &opts).unwrap())
                    .collect()
            })
            .collect();
        let parts = std::array::from_fn(|k| Some(tables[k].as_slice()));
        let fused = Fused::from_tables(0.0, 3.0, &cuts, parts).unwrap();
        (tables, fused, cuts)
    }

    #[test]
    fn a_fused_kinked_table_gives_each_separate_look_up_to_rounding() {
        let (tables, fused, cuts) = kinked();
        let segment = |x: f64| cuts.partition_point(|&c| c <= x);
        let mut xs: Vec<f64> = (0..=3000).map(|i| 3.0 * i as f64 / 3000.0).collect();
        // the cuts themselves and their neighbours, where the segment changes
        for &c in &cuts {
            xs.extend([c, c.next_down(), c.next_up(), c - 1e-9, c + 1e-9]);
        }
        let (mut worst_v, mut worst_s) = (0.0f64, 0.0f64);
        for &x in &xs {
            let got = fused.eval(x).unwrap();
            assert_eq!(
                got.map(|p| p.0),
                fused.values(x).unwrap(),
                "values alone at {x}"
            );
            for (k, t) in tables.iter().enumerate() {
                let (v, s) = t[segment(x)].eval(x).unwrap();
                // Relative to the function's scale on the segment (a cubic's rounding).
                let (scale, slope_scale) = (0..=20).fold((0.0f64, 0.0f64), |(a, b), i| {
                    let seg = &t[segment(x)];
                    let (lo, hi) = seg.range();
                    let (v, s) = seg.eval(lo + (hi - lo) * i as f64 / 20.0).unwrap();
                    (a.max(v.abs()), b.max(s.abs()))
                });
                worst_v = worst_v.max((got[k].0 - v).abs() / scale);
                worst_s = worst_s.max((got[k].1 - s).abs() / slope_scale);
            }
        }
        // The separate tables meet 1e-9; the fused one reproduces their cubics, not just
        // their tolerance.
        assert!(worst_v < 1e-13, "values off by {worst_v:e} of their scale");
        assert!(worst_s < 1e-10, "slopes off by {worst_s:e} of their scale");
        assert!(fused.eval(3.1).is_none() && fused.eval(-0.1).is_none());
        // A missing table is refused, and so is one that does not cover its segment.
        let parts = [Some(&tables[0][..1]), Some(&tables[1][..]), None];
        assert!(Fused::from_tables(0.0, 3.0, &cuts, parts).is_none());
        let parts = [Some(&tables[0][..]), None, None];
        assert!(Fused::<3, true>::from_tables(0.0, 3.0, &[0.8, 1.7], parts).is_none());
    }

    #[test]
    fn a_fused_kinked_table_reads_back_from_its_encoding_to_the_bit() {
        let (_, fused, _) = kinked();
        let mut w = Writer::new();
        fused.encode(&mut w);
        let bytes = w.into_bytes();
        let back = Fused::<3, true>::decode(&mut Reader::new(&bytes)).unwrap();
        // A smooth table's reader refuses it: its look-up reads no segment.
        assert!(Fused::<3>::decode(&mut Reader::new(&bytes)).is_err());
        for i in 0..=1000 {
            let x = 3.0 * i as f64 / 1000.0;
            let (a, b) = (fused.eval(x).unwrap(), back.eval(x).unwrap());
            assert!(a
                .iter()
                .zip(&b)
                .all(|(p, q)| p.0.to_bits() == q.0.to_bits() && p.1.to_bits() == q.1.to_bits()));
        }
        // A segment pointing past the panels is refused.
        let mut cut = bytes.clone();
        cut.truncate(bytes.len() / 2);
        assert!(Fused::<3, true>::decode(&mut Reader::new(&cut)).is_err());
    }

    #[test]
    fn bounds_hold_every_look_up_of_a_kinked_stretch() {
        let (_, t, _) = kinked();
        let mut x = 0.123_f64;
        for _ in 0..200 {
            let a = 3.0 * ((x * 7.77) % 1.0);
            let b = (a + 3.0 * (x % 1.0).powi(3)).min(3.0);
            x = (x + 0.618_033_988_749_895) % 1.0 + 0.01;
            let bounds: [(Span, Span); 3] = t.bounds(a, b).unwrap();
            let mut ds: Vec<f64> = (0..=50).map(|i| a + (b - a) * i as f64 / 50.0).collect();
            ds.push(b);
            ds.extend([0.9, 1.7].into_iter().filter(|&c| a <= c && c <= b));
            for d in ds.into_iter().filter(|&d| a <= d && d <= b) {
                let got = t.eval(d).unwrap();
                for k in 0..3 {
                    let (v, s) = bounds[k];
                    assert!(v.lo <= got[k].0 && got[k].0 <= v.hi, "{k} value at {d}");
                    assert!(s.lo <= got[k].1 && got[k].1 <= s.hi, "{k} slope at {d}");
                }
            }
        }
    }

    #[test]
    fn bounds_hold_every_look_up_of_the_stretch() {
        let f = |x: f64| {
            [
                ((3.0 * x).sin(), 3.0 * (3.0 * x).cos()),
                ((-x).exp(), -(-x).exp()),
                (x.powi(3), 3.0 * x * x),
            ]
        };
        let opts = TableOptions::default();
        let t = Fused::build(f, 0.0, 3.0, [(opts.rel_tol, opts.abs_tol); 3]).unwrap();
        let mut x = 0.123_f64;
        for _ in 0..200 {
            // stretches of every width, edges included
            let a = 3.0 * ((x * 7.77) % 1.0);
            let b = (a + 3.0 * (x % 1.0).powi(3)).min(3.0);
            x = (x + 0.618_033_988_749_895) % 1.0 + 0.01;
            let bounds: [(Span, Span); 3] = t.bounds(a, b).unwrap();
            for i in 0..=50 {
                let d = if i == 50 {
                    b
                } else {
                    a + (b - a) * i as f64 / 50.0
                };
                let got = t.eval(d).unwrap();
                for k in 0..3 {
                    let (v, s) = bounds[k];
                    assert!(v.lo <= got[k].0 && got[k].0 <= v.hi, "{k} value at {d}");
                    assert!(s.lo <= got[k].1 && got[k].1 <= s.hi, "{k} slope at {d}");
                }
            }
        }
        assert!(t.bounds::<3>(-0.1, 1.0).is_none() && t.bounds::<3>(1.0, 0.5).is_none());
    }
}
