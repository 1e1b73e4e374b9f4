//! Physical constants and unit helpers: SI inside, engineering units at the edges.

/// Vacuum permittivity ε₀ in F/m (CODATA 2018).
pub const EPSILON_0: f64 = 8.854_187_812_8e-12;

/// Nanometres to metres. `nm(10.0)` is 1e-8 m.
///
/// ```
/// assert_eq!(hdi_tribology::units::nm(10.0), 1e-8);
/// ```
pub fn nm(x: f64) -> f64 {
    x * 1e-9
}

/// Metres to nanometres.
///
/// ```
/// assert!((hdi_tribology::units::to_nm(1e-8) - 10.0).abs() < 1e-12);
/// ```
pub fn to_nm(x: f64) -> f64 {
    x * 1e9
}

/// Milliwatts to watts.
///
/// ```
/// assert_eq!(hdi_tribology::units::mw(60.0), 0.06);
/// ```
pub fn mw(x: f64) -> f64 {
    x * 1e-3
}

/// Watts to milliwatts.
///
/// ```
/// assert!((hdi_tribology::units::to_mw(0.06) - 60.0).abs() < 1e-12);
/// ```
pub fn to_mw(x: f64) -> f64 {
    x * 1e3
}

/// Kilohertz to hertz.
///
/// ```
/// assert_eq!(hdi_tribology::units::khz(10.5), 10_500.0);
/// ```
pub fn khz(x: f64) -> f64 {
    x * 1e3
}

/// Gigapascals to pascals.
///
/// ```
/// assert_eq!(hdi_tribology::units::gpa(100.0), 1e11);
/// ```
pub fn gpa(x: f64) -> f64 {
    x * 1e9
}

/// Milliseconds to seconds.
///
/// ```
/// assert!((hdi_tribology::units::ms(3.6) - 3.6e-3).abs() < 1e-18);
/// ```
pub fn ms(x: f64) -> f64 {
    x * 1e-3
}

/// Heater efficiency in nm/mW to m/W. `nm_per_mw(0.1)` is 1e-7 m/W.
///
/// ```
/// assert!((hdi_tribology::units::nm_per_mw(0.1) - 1e-7).abs() < 1e-20);
/// ```
pub fn nm_per_mw(x: f64) -> f64 {
    x * 1e-6
}

/// Areal density in µm⁻² to m⁻². `per_um2(150.0)` is 1.5e14 m⁻².
///
/// ```
/// assert_eq!(hdi_tribology::units::per_um2(150.0), 1.5e14);
/// ```
pub fn per_um2(x: f64) -> f64 {
    x * 1e12
}

/// A number for messages: at most seven significant digits, in exponent form when very large or
/// very small (never a 300-digit decimal), `inf` and `NaN` as such.
///
/// ```
/// use hdi_tribology::units::{fmt_short, to_nm};
/// assert_eq!(fmt_short(to_nm(1e-8)), "10");
/// assert_eq!(fmt_short(1e300), "1e300");
/// assert_eq!(fmt_short(2e9), "2e9");
/// assert_eq!(fmt_short(-0.001), "-0.001");
/// assert_eq!(fmt_short(-7e-10), "-7e-10");
/// assert_eq!(fmt_short(1.0 / 3.0), "0.3333333");
/// ```
pub fn fmt_short(x: f64) -> String {
    if !x.is_finite() {
        return format!("{x:?}");
    }
    let r: f64 = format!("{x:.6e}").parse().unwrap_or(x);
    if r != 0.0 && !(1e-4..1e6).contains(&r.abs()) {
        format!("{r:e}")
    } else {
        format!("{r}")
    }
}
