//! Chart pieces shared by the examples that draw a cycle: the force and spacing series of a
//! time series, in the letter's colours (total purple, electrostatic blue, air bearing green,
//! spacing red), so that every figure colours each quantity the same way.

use hdi_tribology::analysis::TimeSeries;
use hdi_tribology::report::{palette, Chart, Colour, Series};

/// Total force (the letter's purple).
pub const TOTAL: Colour = palette::PURPLE;
/// Electrostatic force (blue).
pub const ELECTROSTATIC: Colour = palette::BLUE;
/// Air-bearing force (green).
pub const AIR_BEARING: Colour = palette::GREEN;
/// Spacing (red).
pub const SPACING: Colour = palette::VERMILION;
/// Intermolecular force.
pub const INTERMOLECULAR: Colour = palette::ORANGE;
/// Contact force.
pub const CONTACT: Colour = palette::BLACK;

/// `(t in ms, f(s, i))` for the steps with `t0 ≤ t ≤ t1` (s).
pub fn window(
    s: &TimeSeries,
    (t0, t1): (f64, f64),
    f: impl Fn(&TimeSeries, usize) -> f64,
) -> Vec<(f64, f64)> {
    (0..s.t.len())
        .filter(|&i| s.t[i] >= t0 && s.t[i] <= t1)
        .map(|i| (s.t[i] * 1e3, f(s, i)))
        .collect()
}

/// Every force (mN) against time over `span` (s): the components first, the total last and
/// thickest, so that it stays visible where it runs along another curve.
pub fn force_series<'a>(s: &TimeSeries, span: (f64, f64)) -> Vec<Series<'a>> {
    let mn = |f: fn(&TimeSeries, usize) -> f64| window(s, span, move |s, i| f(s, i) * 1e3);
    vec![
        Series::line("air bearing", mn(|s, i| s.air_bearing[i])).colour(AIR_BEARING),
        Series::line("intermolecular", mn(|s, i| s.intermolecular[i])).colour(INTERMOLECULAR),
        Series::line("electrostatic", mn(|s, i| s.electrostatic[i])).colour(ELECTROSTATIC),
        Series::line("contact", mn(|s, i| s.contact[i])).colour(CONTACT),
        Series::line("total", mn(|s, i| s.total[i]))
            .colour(TOTAL)
            .width(3),
    ]
}

/// `f(s, i)` over `span` (s) in bins of `period` (s): per bin its centre (ms), the
/// time-weighted mean (each sample holds until the next), the least and the largest sample.
pub fn binned(
    s: &TimeSeries,
    (t0, t1): (f64, f64),
    period: f64,
    f: impl Fn(&TimeSeries, usize) -> f64,
) -> Vec<(f64, f64, f64, f64)> {
    let idx: Vec<usize> = (0..s.t.len())
        .filter(|&i| s.t[i] >= t0 && s.t[i] <= t1)
        .collect();
    let Some(&first) = idx.first() else {
        return Vec::new();
    };
    let start = s.t[first];
    let mut out = Vec::new();
    let mut bin = (0usize, 0.0, 0.0, f64::INFINITY, f64::NEG_INFINITY);
    for (n, &i) in idx.iter().enumerate() {
        let k = ((s.t[i] - start) / period).floor() as usize;
        if k != bin.0 && bin.2 > 0.0 {
            let centre = start + (bin.0 as f64 + 0.5) * period;
            out.push((centre * 1e3, bin.1 / bin.2, bin.3, bin.4));
            bin = (k, 0.0, 0.0, f64::INFINITY, f64::NEG_INFINITY);
        }
        bin.0 = k;
        let v = f(s, i);
        let dt = idx.get(n + 1).map_or(0.0, |&j| s.t[j] - s.t[i]);
        // The last sample of the span weighs as little as the bin allows, but counts.
        let w = if dt > 0.0 { dt } else { 1e-300 };
        bin.1 += v * w;
        bin.2 += w;
        bin.3 = bin.3.min(v);
        bin.4 = bin.4.max(v);
    }
    if bin.2 > 0.0 {
        let centre = start + (bin.0 as f64 + 0.5) * period;
        out.push((centre * 1e3, bin.1 / bin.2, bin.3, bin.4));
    }
    out
}

/// Every force (mN) against time over `span` (s) as in [`force_series`], binned by `period`
/// (s, one period of `V²`): each force's mean over a period as a line, its range over the
/// period shaded beneath. A drive at `2f` sampled at one pixel per period would otherwise
/// draw a moiré instead of the signal. A force that is zero throughout is left out (a line
/// hidden under the others would be listed in the legend but not seen); its name is returned
/// beside the series.
pub fn force_envelopes<'a>(
    s: &TimeSeries,
    span: (f64, f64),
    period: f64,
) -> (Vec<Series<'a>>, Vec<&'static str>) {
    type Force = fn(&TimeSeries, usize) -> f64;
    let forces: [(&'static str, Force, Colour, u32); 5] = [
        ("air bearing", |s, i| s.air_bearing[i], AIR_BEARING, 2),
        (
            "intermolecular",
            |s, i| s.intermolecular[i],
            INTERMOLECULAR,
            2,
        ),
        ("electrostatic", |s, i| s.electrostatic[i], ELECTROSTATIC, 2),
        ("contact", |s, i| s.contact[i], CONTACT, 2),
        ("total", |s, i| s.total[i], TOTAL, 3),
    ];
    let mut bands = Vec::new();
    let mut lines = Vec::new();
    let mut zero = Vec::new();
    for (label, f, colour, width) in forces {
        let b = binned(s, span, period, move |s, i| f(s, i) * 1e3);
        if b.iter().all(|&(_, _, lo, hi)| lo == 0.0 && hi == 0.0) {
            zero.push(label);
            continue;
        }
        bands.push(
            Series::band(
                "",
                b.iter().map(|&(t, _, lo, _)| (t, lo)).collect(),
                b.iter().map(|&(_, _, _, hi)| hi).collect(),
            )
            .colour(colour),
        );
        lines.push(
            Series::line(label, b.iter().map(|&(t, m, _, _)| (t, m)).collect())
                .colour(colour)
                .width(width),
        );
    }
    bands.extend(lines);
    (bands, zero)
}

/// Forces against time over `span` (s), on fixed y range `y_range` if given (mN).
pub fn forces_chart<'a>(
    title: &'a str,
    s: &TimeSeries,
    span: (f64, f64),
    y_range: Option<(f64, f64)>,
) -> Chart<'a> {
    Chart {
        title,
        x_label: "t (ms)",
        y_label: "force (mN)",
        series: force_series(s, span),
        y_range,
        ..Chart::default()
    }
}

/// Total, electrostatic and air-bearing force (mN, left axis) with the bulge spacing (nm, right
/// axis) over `span` (s): the letter's Fig. 3(b).
pub fn zoom_chart<'a>(title: &'a str, s: &TimeSeries, span: (f64, f64)) -> Chart<'a> {
    let mn = |f: fn(&TimeSeries, usize) -> f64| window(s, span, move |s, i| f(s, i) * 1e3);
    Chart {
        title,
        x_label: "t (ms)",
        y_label: "force (mN)",
        y2_label: "bulge spacing d (nm)",
        series: vec![
            Series::line("air bearing", mn(|s, i| s.air_bearing[i])).colour(AIR_BEARING),
            Series::line("electrostatic", mn(|s, i| s.electrostatic[i])).colour(ELECTROSTATIC),
            Series::line("total", mn(|s, i| s.total[i]))
                .colour(TOTAL)
                .width(3),
            Series::line(
                "spacing d (right axis)",
                window(s, span, |s, i| s.d[i] * 1e9),
            )
            .colour(SPACING)
            .on_secondary(),
        ],
        ..Chart::default()
    }
}
