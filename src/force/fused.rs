//! One table holding the three hot-path sums on a shared grid, so that a full evaluation costs a
//! single index computation and two node reads.

use crate::quadrature::{hermite_bounds, Span, TableOptions};

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

/// Values and slopes of three functions at each node.
#[derive(Clone, Debug)]
pub(crate) struct Fused {
    lo: f64,
    hi: f64,
    inv_panel: f64,
    panels: Vec<Panel>,
    nodes: Vec<[f64; 6]>,
}

#[inline]
fn basis(t: f64, h: f64) -> ([f64; 4], [f64; 4]) {
    let t2 = t * t;
    let t3 = t2 * t;
    (
        [
            2.0 * t3 - 3.0 * t2 + 1.0,
            (t3 - 2.0 * t2 + t) * h,
            3.0 * t2 - 2.0 * t3,
            (t3 - t2) * h,
        ],
        [
            (6.0 * t2 - 6.0 * t) / h,
            3.0 * t2 - 4.0 * t + 1.0,
            (6.0 * t - 6.0 * t2) / h,
            3.0 * t2 - 2.0 * t,
        ],
    )
}

impl Fused {
    /// Tabulates `f` (three (value, slope) pairs) on `[lo, hi]` against `f` itself, which is meant
    /// to be cheap (the separate tables). `None` when the node budget is exceeded or `f` is not
    /// finite.
    pub(crate) fn build(
        f: impl Fn(f64) -> [(f64, f64); 3],
        lo: f64,
        hi: f64,
        opts: &TableOptions,
    ) -> Option<Fused> {
        let width = (hi - lo) / PANELS as f64;
        let mut panels = Vec::with_capacity(PANELS);
        let mut nodes: Vec<[f64; 6]> = Vec::new();
        let pack = |v: [(f64, f64); 3]| [v[0].0, v[0].1, v[1].0, v[1].1, v[2].0, v[2].1];
        for p in 0..PANELS {
            let a = lo + p as f64 * width;
            let b = if p + 1 == PANELS { hi } else { a + width };
            let mut n = 4;
            loop {
                let h = (b - a) / n as f64;
                let xs: Vec<f64> = (0..=n)
                    .map(|i| if i == n { b } else { a + i as f64 * h })
                    .collect();
                let vals: Vec<[f64; 6]> = xs.iter().map(|&x| pack(f(x))).collect();
                if vals.iter().flatten().any(|v| !v.is_finite()) {
                    return None;
                }
                let ok = (0..n).all(|i| {
                    let exact = pack(f(0.5 * (xs[i] + xs[i + 1])));
                    let (w, _) = basis(0.5, xs[i + 1] - xs[i]);
                    (0..3).all(|k| {
                        let (y0, m0, y1, m1) = (
                            vals[i][2 * k],
                            vals[i][2 * k + 1],
                            vals[i + 1][2 * k],
                            vals[i + 1][2 * k + 1],
                        );
                        let v = w[0] * y0 + w[1] * m0 + w[2] * y1 + w[3] * m1;
                        (v - exact[2 * k]).abs()
                            <= (opts.rel_tol * exact[2 * k].abs()).max(opts.abs_tol)
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
        Some(Fused {
            lo,
            hi,
            inv_panel: 1.0 / width,
            panels,
            nodes,
        })
    }

    /// The three (value, slope) pairs at `d`, or `None` outside the range.
    #[inline]
    pub(crate) fn eval(&self, d: f64) -> Option<[(f64, f64); 3]> {
        if !(d >= self.lo && d <= self.hi) {
            return None;
        }
        let p = (((d - self.lo) * self.inv_panel) as usize).min(PANELS - 1);
        let pan = &self.panels[p];
        let s = (d - pan.a) * pan.inv_h;
        let j = (s as usize).min(pan.n - 1);
        let (w, dw) = basis(s - j as f64, pan.h);
        let (n0, n1) = (&self.nodes[pan.start + j], &self.nodes[pan.start + j + 1]);
        let pair = |k: usize| {
            let (y0, m0, y1, m1) = (n0[2 * k], n0[2 * k + 1], n1[2 * k], n1[2 * k + 1]);
            (
                w[0] * y0 + w[1] * m0 + w[2] * y1 + w[3] * m1,
                dw[0] * y0 + dw[1] * m0 + dw[2] * y1 + dw[3] * m1,
            )
        };
        Some([pair(0), pair(1), pair(2)])
    }

    /// Bounds of the first `K` (at most 3) of [`Fused::eval`]'s (value, slope) pairs at every `d`
    /// in `[a, b]`, or `None` unless `lo ≤ a ≤ b ≤ hi`: the hull of the bounds of every interval
    /// a point of `[a, b]` can be given (as [`crate::quadrature::Table`]'s bounds).
    pub(crate) fn bounds<const K: usize>(&self, a: f64, b: f64) -> Option<[(Span, Span); K]> {
        if !(a >= self.lo && b <= self.hi && a <= b) {
            return None;
        }
        let panel = |d: f64| (((d - self.lo) * self.inv_panel) as usize).min(PANELS - 1);
        let interval = |p: &Panel, d: f64| (((d - p.a) * p.inv_h) as usize).min(p.n - 1);
        let (first, last) = (panel(a), panel(b));
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
                    let (v, s) = hermite_bounds(
                        n0[2 * k],
                        p.h * n0[2 * k + 1],
                        n1[2 * k],
                        p.h * n1[2 * k + 1],
                        ext,
                    );
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
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let t = Fused::build(f, 0.0, 3.0, &opts).unwrap();
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
        let t = Fused::build(f, 0.0, 3.0, &TableOptions::default()).unwrap();
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
