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
