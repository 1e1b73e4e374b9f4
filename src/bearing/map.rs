//! The pressure field as a map: an SVG sized for a 3.5 in column (fonts of 8 pt and more, real
//! minus signs, no title inside the figure), the slider's length across and its width up, the
//! pressure over ambient in colour, the regions' outlines on top.

use std::fmt::Write;

use super::attitude::Equilibrium;
use super::geometry::Bearing;

/// Width of the figure, pt (3.5 in).
const WIDTH_PT: f64 = 252.0;
/// Margins of the plot area, pt: left (tick labels and axis label), right (colour bar), top,
/// bottom.
const MARGIN: [f64; 4] = [36.0, 54.0, 8.0, 30.0];
/// Font size of tick labels and axis labels, pt.
const FONT_PT: f64 = 8.5;
/// Colour levels of the map.
const LEVELS: usize = 96;
/// The viridis colour map at nine evenly spaced stops (van der Walt & Smith, 2015).
const VIRIDIS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 81, 139],
    [44, 113, 142],
    [33, 144, 141],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

fn colour(t: f64) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0) * (VIRIDIS.len() - 1) as f64;
    let k = (t.floor() as usize).min(VIRIDIS.len() - 2);
    let f = t - k as f64;
    let (a, b) = (VIRIDIS[k], VIRIDIS[k + 1]);
    let mix = |i: usize| (a[i] as f64 + f * (b[i] as f64 - a[i] as f64)).round() as u8;
    [mix(0), mix(1), mix(2)]
}

/// A number with a real minus sign.
fn label(v: f64, decimals: usize) -> String {
    let s = format!("{:.*}", decimals, v);
    let s = if s
        .trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        s.trim_start_matches('-').to_string()
    } else {
        s
    };
    s.replace('-', "\u{2212}")
}

/// Ticks at a "nice" step (1, 2 or 5 × 10ᵏ) over `[lo, hi]`, and the decimals they need.
fn ticks(lo: f64, hi: f64, target: usize) -> (Vec<f64>, usize) {
    let span = (hi - lo).max(1e-12);
    let raw = span / target as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step + 1e-9).floor() as i64;
    let decimals = if step >= 1.0 {
        0
    } else {
        (-step.log10().floor()) as usize
    };
    ((first..=last).map(|k| k as f64 * step).collect(), decimals)
}

impl Equilibrium {
    /// The pressure map as SVG text.
    ///
    /// ```
    /// use hdi_tribology::bearing::{solve_attitude, AttitudeOptions, BearingSpec};
    /// let mut spec = BearingSpec::from_path(concat!(
    ///     env!("CARGO_MANIFEST_DIR"),
    ///     "/scenes/bearing/two_rail_taper_flat.toml"
    /// ))?;
    /// spec.grid.nx = 33;
    /// spec.grid.ny = 33;
    /// let eq = solve_attitude(&spec.build()?, &AttitudeOptions::default())?;
    /// let svg = eq.pressure_map_svg();
    /// assert!(svg.starts_with("<svg") && svg.contains("3.5in"));
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    pub fn pressure_map_svg(&self) -> String {
        let b = &self.reynolds.bearing;
        let pw = WIDTH_PT - MARGIN[0] - MARGIN[1];
        let ph = pw * b.width / b.length;
        let frame = Frame {
            x0: MARGIN[0],
            y0: MARGIN[2],
            pw,
            ph,
            height: ph + MARGIN[2] + MARGIN[3],
        };
        let lo = self.pressure.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = self
            .pressure
            .iter()
            .cloned()
            .fold(f64::NEG_INFINITY, f64::max);
        let height = frame.height;
        let mut s = String::new();
        let _ = write!(
            s,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"3.5in\" height=\"{:.3}in\" \
             viewBox=\"0 0 {WIDTH_PT} {height:.2}\" font-family=\"DejaVu Sans, Arial, sans-serif\" \
             font-size=\"{FONT_PT}\" shape-rendering=\"crispEdges\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n",
            height / 72.0
        );
        self.write_raster(&mut s, &frame, lo, hi);
        frame.write_outlines(&mut s, b);
        frame.write_axes(&mut s, b.length * 1e3, b.width * 1e3);
        frame.write_colour_bar(&mut s, lo, hi);
        s.push_str("</svg>\n");
        s
    }

    /// The map: a raster of 0.5 pt, each pixel the pressure of the control volume at its
    /// centre in the colour of its level between `lo` and `hi`, runs of one colour level merged.
    /// y up: row 0 at the bottom.
    fn write_raster(&self, s: &mut String, frame: &Frame, lo: f64, hi: f64) {
        let r = &self.reynolds;
        let (b, g) = (&r.bearing, &r.grid);
        let (nx, _) = r.size();
        let Frame { x0, y0, pw, ph, .. } = *frame;
        let span = (hi - lo).max(1e-12);
        let level = |p: f64| (((p - lo) / span) * (LEVELS - 1) as f64).round() as usize;
        let px = 0.5;
        let cols = (pw / px).round() as usize;
        let rows = (ph / px).round() as usize;
        let cell = |faces: &[f64], v: f64| {
            faces.partition_point(|&f| f <= v).clamp(1, faces.len() - 1) - 1
        };
        let ix: Vec<usize> = (0..cols)
            .map(|c| cell(&g.xf, (c as f64 + 0.5) / cols as f64 * b.length))
            .collect();
        for row in 0..rows {
            let y = (row as f64 + 0.5) / rows as f64 * b.width;
            let j = cell(&g.yf, y);
            let top = y0 + ph - (row + 1) as f64 * px;
            let mut c = 0;
            while c < cols {
                let lv = level(self.pressure[j * nx + ix[c]]);
                let mut e = c + 1;
                while e < cols && level(self.pressure[j * nx + ix[e]]) == lv {
                    e += 1;
                }
                let [cr, cg, cb] = colour(lv as f64 / (LEVELS - 1) as f64);
                let _ = writeln!(
                    s,
                    "<rect x=\"{:.2}\" y=\"{:.2}\" width=\"{:.2}\" height=\"{:.2}\" \
                     fill=\"#{cr:02x}{cg:02x}{cb:02x}\"/>",
                    x0 + c as f64 * px,
                    top,
                    (e - c) as f64 * px + 0.3,
                    px + 0.3
                );
                c = e;
            }
        }
    }
}

/// Where the plot area sits in the figure (pt): its top-left corner, width and height, and the
/// height of the whole figure.
#[derive(Clone, Copy)]
struct Frame {
    x0: f64,
    y0: f64,
    pw: f64,
    ph: f64,
    height: f64,
}

impl Frame {
    /// The regions' outlines, then the frame of the plot area.
    fn write_outlines(&self, s: &mut String, b: &Bearing) {
        let Frame { x0, y0, pw, ph, .. } = *self;
        let to_x = |x: f64| x0 + x / b.length * pw;
        let to_y = |y: f64| y0 + ph - y / b.width * ph;
        for p in &b.polygons {
            let pts: Vec<String> = p
                .vertices
                .iter()
                .map(|v| format!("{:.2},{:.2}", to_x(v[0]), to_y(v[1])))
                .collect();
            let _ = writeln!(
                s,
                "<polygon points=\"{}\" fill=\"none\" stroke=\"white\" stroke-width=\"0.6\" \
                 stroke-opacity=\"0.8\"/>",
                pts.join(" ")
            );
        }
        let _ = writeln!(
            s,
            "<rect x=\"{x0}\" y=\"{y0}\" width=\"{pw:.2}\" height=\"{ph:.2}\" fill=\"none\" \
             stroke=\"black\" stroke-width=\"0.6\"/>"
        );
    }

    /// The axes: the slider's length `l_mm` across, its width `w_mm` up, with ticks and labels.
    fn write_axes(&self, s: &mut String, l_mm: f64, w_mm: f64) {
        let Frame {
            x0,
            y0,
            pw,
            ph,
            height,
        } = *self;
        let (xt, xd) = ticks(0.0, l_mm, 4);
        for t in xt {
            let x = x0 + t / l_mm * pw;
            let _ = writeln!(
                s,
                "<line x1=\"{x:.2}\" y1=\"{:.2}\" x2=\"{x:.2}\" y2=\"{:.2}\" stroke=\"black\" \
                 stroke-width=\"0.6\"/>\n<text x=\"{x:.2}\" y=\"{:.2}\" text-anchor=\"middle\">{}</text>",
                y0 + ph,
                y0 + ph + 3.0,
                y0 + ph + 3.0 + FONT_PT,
                label(t, xd)
            );
        }
        let _ = writeln!(
            s,
            "<text x=\"{:.2}\" y=\"{:.2}\" text-anchor=\"middle\">x from the leading edge (mm)</text>",
            x0 + 0.5 * pw,
            height - 3.0
        );
        let (yt, yd) = ticks(0.0, w_mm, 4);
        for t in yt {
            let y = y0 + ph - t / w_mm * ph;
            let _ = writeln!(
                s,
                "<line x1=\"{:.2}\" y1=\"{y:.2}\" x2=\"{x0:.2}\" y2=\"{y:.2}\" stroke=\"black\" \
                 stroke-width=\"0.6\"/>\n<text x=\"{:.2}\" y=\"{:.2}\" text-anchor=\"end\">{}</text>",
                x0 - 3.0,
                x0 - 4.5,
                y + 0.35 * FONT_PT,
                label(t, yd)
            );
        }
        let _ = writeln!(
            s,
            "<text transform=\"translate({:.2},{:.2}) rotate(-90)\" text-anchor=\"middle\">y (mm)</text>",
            x0 - 24.0,
            y0 + 0.5 * ph
        );
    }

    /// The colour bar right of the plot, from the pressure `lo` to `hi`, with ticks and label.
    fn write_colour_bar(&self, s: &mut String, lo: f64, hi: f64) {
        let Frame { x0, y0, pw, ph, .. } = *self;
        let span = (hi - lo).max(1e-12);
        let (bx, bw) = (x0 + pw + 8.0, 7.0);
        let steps = 96;
        for k in 0..steps {
            let t = (k as f64 + 0.5) / steps as f64;
            let [cr, cg, cb] = colour(t);
            let _ = writeln!(
                s,
                "<rect x=\"{bx:.2}\" y=\"{:.2}\" width=\"{bw}\" height=\"{:.3}\" \
                 fill=\"#{cr:02x}{cg:02x}{cb:02x}\"/>",
                y0 + ph - (k + 1) as f64 / steps as f64 * ph,
                ph / steps as f64 + 0.05
            );
        }
        let _ = writeln!(
            s,
            "<rect x=\"{bx:.2}\" y=\"{y0}\" width=\"{bw}\" height=\"{ph:.2}\" fill=\"none\" \
             stroke=\"black\" stroke-width=\"0.6\"/>"
        );
        let (pt, pd) = ticks(lo, hi, 4);
        for t in pt {
            let y = y0 + ph - (t - lo) / span * ph;
            let _ = writeln!(
                s,
                "<line x1=\"{:.2}\" y1=\"{y:.2}\" x2=\"{:.2}\" y2=\"{y:.2}\" stroke=\"black\" \
                 stroke-width=\"0.6\"/>\n<text x=\"{:.2}\" y=\"{:.2}\">{}</text>",
                bx + bw,
                bx + bw + 2.5,
                bx + bw + 4.0,
                y + 0.35 * FONT_PT,
                label(t, pd)
            );
        }
        let _ = writeln!(
            s,
            "<text transform=\"translate({:.2},{:.2}) rotate(-90)\" text-anchor=\"middle\">\
             pressure / ambient</text>",
            WIDTH_PT - 4.0,
            y0 + 0.5 * ph
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_use_real_minus_signs() {
        assert_eq!(label(-0.5, 1), "\u{2212}0.5");
        assert_eq!(label(-0.0, 1), "0.0");
        let (t, d) = ticks(0.0, 2.0, 4);
        assert_eq!((t, d), (vec![0.0, 0.5, 1.0, 1.5, 2.0], 1));
    }
}
