//! The finite-volume grid: a tensor grid of control volumes, finer at the rails' steps and at
//! the trailing edge, and the surface's depth averaged over each control volume.

use super::geometry::Bearing;

/// Width of the refined band about a step, as a fraction of the slider's length (along `x`) or
/// width (along `y`).
pub const REFINE_WIDTH: f64 = 0.015;
/// Rows per control volume at which the painted regions are sampled across `y` (along `x` the
/// area average is exact).
const SUB_ROWS: usize = 8;
/// Samples of the grid density per final cell when the mapping is inverted.
const MAP_SAMPLES: usize = 16;

/// A tensor grid over the slider and the surface depth on it. The face nearest each vertex
/// coordinate of a region (and the taper's end) is moved onto it, so that rails with edges
/// along the grid lines step exactly at a face.
///
/// ```
/// use hdi_tribology::bearing::{BearingSpec, Grid};
/// let b = BearingSpec::from_toml_str("[slider]\nlength_um = 1000\nwidth_um = 800\n\
///     [operating]\nradius_mm = 20\nrpm = 7200\npreload_mn = 20")?.build()?;
/// let g = Grid::new(&b, 16, 12, 1.0);
/// assert_eq!(g.nx(), 16);
/// assert!((g.xf[16] - 1e-3).abs() < 1e-15);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct Grid {
    /// Faces along `x`, m (`nx + 1`, from 0 to `L`).
    pub xf: Vec<f64>,
    /// Faces along `y`, m (`ny + 1`, from 0 to `W`).
    pub yf: Vec<f64>,
    /// Centres along `x`, m.
    pub xc: Vec<f64>,
    /// Centres along `y`, m.
    pub yc: Vec<f64>,
    /// Depth of the surface averaged over each control volume, m, index `j nx + i`.
    pub depth: Vec<f64>,
    /// Depth at each grid node (cell corner), m, index `j (nx + 1) + i`.
    pub node_depth: Vec<f64>,
}

/// Faces of a 1-D grid of `n` cells on `[0, len]`, finer by `refinement` within `REFINE_WIDTH`
/// of each point in `marks`: the faces are the inverse of the normalised integral of the density
/// `1 + (r − 1) max_k exp(−((s − s_k)/w)²)`, so the grids of one slider differ only in `n`.
fn faces(n: usize, len: f64, marks: &[f64], refinement: f64) -> Vec<f64> {
    if refinement <= 1.0 || marks.is_empty() {
        let mut out: Vec<f64> = (0..=n).map(|i| len * i as f64 / n as f64).collect();
        snap(&mut out, marks);
        return out;
    }
    let m = (n * MAP_SAMPLES).max(4096);
    let density = |s: f64| {
        let near = marks
            .iter()
            .map(|&k| {
                let z = (s - k / len) / REFINE_WIDTH;
                (-z * z).exp()
            })
            .fold(0.0, f64::max);
        1.0 + (refinement - 1.0) * near
    };
    // Cumulative integral by the trapezoidal rule on a fine uniform mesh.
    let mut cum = vec![0.0; m + 1];
    let mut prev = density(0.0);
    for k in 1..=m {
        let cur = density(k as f64 / m as f64);
        cum[k] = cum[k - 1] + 0.5 * (prev + cur) / m as f64;
        prev = cur;
    }
    let total = cum[m];
    let mut out = Vec::with_capacity(n + 1);
    let mut k = 0;
    for i in 0..=n {
        let target = total * i as f64 / n as f64;
        while k < m - 1 && cum[k + 1] < target {
            k += 1;
        }
        let t = ((target - cum[k]) / (cum[k + 1] - cum[k])).clamp(0.0, 1.0);
        out.push(len * (k as f64 + t) / m as f64);
    }
    out[0] = 0.0;
    out[n] = len;
    snap(&mut out, marks);
    out
}

/// Moves the face nearest to each mark onto it, where that keeps the faces in order, so that
/// a step along a grid line falls on a face and no control volume straddles it.
fn snap(faces: &mut [f64], marks: &[f64]) {
    let n = faces.len() - 1;
    for &m in marks {
        let k = faces.partition_point(|&f| f < m);
        if k == 0 || k > n {
            continue;
        }
        let near = if k < n && (faces[k] - m).abs() <= (m - faces[k - 1]).abs() {
            k
        } else {
            k - 1
        };
        if near == 0 || near == n {
            continue;
        }
        // Keep at least a quarter of the neighbouring widths on either side.
        let lo = faces[near - 1] + 0.25 * (faces[near] - faces[near - 1]);
        let hi = faces[near + 1] - 0.25 * (faces[near + 1] - faces[near]);
        if m > lo && m < hi {
            faces[near] = m;
        }
    }
}

/// Paints `[a, b]` at depth `d` over the sorted, disjoint segments `(x0, x1, depth)`.
fn paint(segs: &mut Vec<(f64, f64, f64)>, a: f64, b: f64, d: f64) {
    if b <= a {
        return;
    }
    let mut out = Vec::with_capacity(segs.len() + 2);
    let mut placed = false;
    for &(x0, x1, v) in segs.iter() {
        if x1 <= a || x0 >= b {
            if x0 >= b && !placed {
                out.push((a, b, d));
                placed = true;
            }
            out.push((x0, x1, v));
            continue;
        }
        if x0 < a {
            out.push((x0, a, v));
        }
        if !placed {
            out.push((a, b, d));
            placed = true;
        }
        if x1 > b {
            out.push((b, x1, v));
        }
    }
    if !placed {
        out.push((a, b, d));
    }
    *segs = out;
}

/// Intervals of `x` inside the polygon along the line `y` (even–odd rule).
fn crossings(v: &[[f64; 2]], y: f64, xs: &mut Vec<f64>) {
    xs.clear();
    let n = v.len();
    let mut j = n - 1;
    for i in 0..n {
        let (a, b) = (v[j], v[i]);
        if (a[1] > y) != (b[1] > y) {
            xs.push(a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1]));
        }
        j = i;
    }
    xs.sort_by(f64::total_cmp);
}

/// A point moved a hair towards the slider's centre, so that a point on the outline takes the
/// depth of the region whose edge lies on the outline.
pub(crate) fn nudged(b: &Bearing, x: f64, y: f64) -> (f64, f64) {
    const NUDGE: f64 = 1e-9;
    (
        x + NUDGE * (0.5 * b.length - x),
        y + NUDGE * (0.5 * b.width - y),
    )
}

impl Grid {
    /// The grid of `nx × ny` control volumes for this bearing, `refinement` times finer at the
    /// steps and the trailing edge.
    pub fn new(b: &Bearing, nx: usize, ny: usize, refinement: f64) -> Grid {
        let mut mx: Vec<f64> = vec![b.length];
        let mut my: Vec<f64> = Vec::new();
        for p in &b.polygons {
            for v in &p.vertices {
                mx.push(v[0]);
                my.push(v[1]);
            }
        }
        if let Some((lt, _)) = b.taper {
            mx.push(lt);
        }
        let dedup = |m: &mut Vec<f64>, len: f64| {
            m.sort_by(f64::total_cmp);
            m.dedup_by(|a, b| (*a - *b).abs() < 1e-3 * REFINE_WIDTH * len);
        };
        dedup(&mut mx, b.length);
        dedup(&mut my, b.width);
        let xf = faces(nx, b.length, &mx, refinement);
        let yf = faces(ny, b.width, &my, refinement);
        let xc: Vec<f64> = xf.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
        let yc: Vec<f64> = yf.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
        let mut depth = vec![0.0; nx * ny];
        // Regions: exact along x, SUB_ROWS rows across each cell.
        let mut segs = Vec::new();
        let mut xs = Vec::new();
        for j in 0..ny {
            let row = &mut depth[j * nx..(j + 1) * nx];
            for s in 0..SUB_ROWS {
                let y = yf[j] + (yf[j + 1] - yf[j]) * (s as f64 + 0.5) / SUB_ROWS as f64;
                segs.clear();
                segs.push((0.0, b.length, b.base_depth));
                for p in &b.polygons {
                    crossings(&p.vertices, y, &mut xs);
                    for pair in xs.chunks_exact(2) {
                        paint(&mut segs, pair[0].max(0.0), pair[1].min(b.length), p.depth);
                    }
                }
                let mut k = 0;
                for i in 0..nx {
                    let (a, c) = (xf[i], xf[i + 1]);
                    while k < segs.len() && segs[k].1 <= a {
                        k += 1;
                    }
                    let mut sum = 0.0;
                    let mut q = k;
                    while q < segs.len() && segs[q].0 < c {
                        sum += (segs[q].1.min(c) - segs[q].0.max(a)).max(0.0) * segs[q].2;
                        q += 1;
                    }
                    row[i] += sum / (c - a) / SUB_ROWS as f64;
                }
            }
        }
        // Taper and crown (along x) and camber (along y), averaged exactly.
        let (l, w) = (b.length, b.width);
        let along_x: Vec<f64> = (0..nx)
            .map(|i| {
                let (a, c) = (xf[i], xf[i + 1]);
                let mut v = 0.0;
                if let Some((lt, ht)) = b.taper {
                    let e = c.min(lt);
                    if e > a {
                        v += ht * ((e - a) - (e * e - a * a) / (2.0 * lt));
                    }
                }
                let prim = |x: f64| {
                    let u = 2.0 * x / l - 1.0;
                    0.5 * l * (u - u * u * u / 3.0)
                };
                v -= b.crown * (prim(c) - prim(a));
                v / (c - a)
            })
            .collect();
        let along_y: Vec<f64> = (0..ny)
            .map(|j| {
                let (a, c) = (yf[j], yf[j + 1]);
                let prim = |y: f64| {
                    let u = 2.0 * y / w - 1.0;
                    0.5 * w * (u - u * u * u / 3.0)
                };
                -b.camber * (prim(c) - prim(a)) / (c - a)
            })
            .collect();
        for j in 0..ny {
            for i in 0..nx {
                depth[j * nx + i] += along_x[i] + along_y[j];
            }
        }
        let mut node_depth = Vec::with_capacity((nx + 1) * (ny + 1));
        for &y in &yf {
            for &x in &xf {
                let (xi, yi) = nudged(b, x, y);
                node_depth.push(b.depth_at(xi, yi));
            }
        }
        Grid {
            xf,
            yf,
            xc,
            yc,
            depth,
            node_depth,
        }
    }

    /// Control volumes along `x`.
    pub fn nx(&self) -> usize {
        self.xc.len()
    }

    /// Control volumes along `y`.
    pub fn ny(&self) -> usize {
        self.yc.len()
    }

    /// Area of control volume `(i, j)`, m².
    pub fn area(&self, i: usize, j: usize) -> f64 {
        (self.xf[i + 1] - self.xf[i]) * (self.yf[j + 1] - self.yf[j])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paint_splits_and_overwrites() {
        let mut s = vec![(0.0, 10.0, 1.0)];
        paint(&mut s, 2.0, 4.0, 0.0);
        paint(&mut s, 3.0, 6.0, 5.0);
        assert_eq!(
            s,
            vec![
                (0.0, 2.0, 1.0),
                (2.0, 3.0, 0.0),
                (3.0, 6.0, 5.0),
                (6.0, 10.0, 1.0)
            ]
        );
    }

    #[test]
    fn faces_are_monotone_and_refined() {
        let f = faces(64, 1.0, &[0.5, 1.0], 4.0);
        assert!(f.windows(2).all(|w| w[1] > w[0]));
        let near = f
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(f64::INFINITY, f64::min);
        let far = f.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
        assert!(far / near > 3.0, "{far} {near}");
    }
}
