//! Physical constants and unit helpers: SI inside, engineering units at the edges.

use std::io::Write;

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

/// A finite `f64` as the decimal its shortest round-trip form writes: `digits · 10^exp`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Decimal {
    digits: i128,
    exp: i32,
}

/// The shortest decimal text of a finite `x` that reads back to it, split into its mantissa
/// (`"-1.25"`, `"0.0011"`) and power of ten.
fn shortest(x: f64, buf: &mut ryu::Buffer) -> (&str, i32) {
    let s = buf.format_finite(x);
    match s.split_once('e') {
        Some((m, e)) => (m, e.parse().unwrap_or(0)),
        None => (s, 0),
    }
}

impl Decimal {
    /// The decimal `x` is written as (`0.1` is 1·10⁻¹, not the binary value nearest to it);
    /// `None` for a value that is not finite.
    fn of(x: f64) -> Option<Self> {
        if !x.is_finite() {
            return None;
        }
        let mut buf = ryu::Buffer::new();
        let (mantissa, exp) = shortest(x, &mut buf);
        let (int, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
        let mut digits: i128 = format!("{int}{frac}").parse().ok()?;
        let mut exp = exp - i32::try_from(frac.len()).ok()?;
        // No trailing zeros (`1.0` is 1·10⁰, `100.0` is 1·10²).
        while digits != 0 && digits % 10 == 0 {
            digits /= 10;
            exp += 1;
        }
        Some(Decimal { digits, exp })
    }

    /// The `f64` nearest to this decimal (correctly rounded by the parser).
    fn value(self) -> f64 {
        format!("{}e{}", self.digits, self.exp)
            .parse()
            .unwrap_or(f64::NAN)
    }

    /// `digits` written with exponent `exp ≤ self.exp`, if it fits.
    fn at(self, exp: i32) -> Option<i128> {
        let shift = u32::try_from(self.exp.checked_sub(exp)?).ok()?;
        self.digits.checked_mul(10i128.checked_pow(shift)?)
    }

    fn add(self, other: Decimal) -> Option<Decimal> {
        let exp = self.exp.min(other.exp);
        Some(Decimal {
            digits: self.at(exp)?.checked_add(other.at(exp)?)?,
            exp,
        })
    }

    fn mul(self, other: Decimal) -> Option<Decimal> {
        Some(Decimal {
            digits: self.digits.checked_mul(other.digits)?,
            exp: self.exp.checked_add(other.exp)?,
        })
    }

    fn times(self, k: i64) -> Option<Decimal> {
        Some(Decimal {
            digits: self.digits.checked_mul(i128::from(k))?,
            exp: self.exp,
        })
    }

    /// `self / other` when it is a decimal of at most 30 digits more than `self`'s.
    fn div(self, other: Decimal) -> Option<Decimal> {
        if other.digits == 0 {
            return None;
        }
        // Scale the dividend until the quotient is a whole number, at most 30 digits further.
        let mut num = self;
        for _ in 0..=30 {
            if num.digits % other.digits == 0 {
                return Some(Decimal {
                    digits: num.digits / other.digits,
                    exp: num.exp.checked_sub(other.exp)?,
                });
            }
            num = Decimal {
                digits: num.digits.checked_mul(10)?,
                exp: num.exp - 1,
            };
        }
        None
    }
}

/// The power of ten that `factor` is (`1e-9` → −9), if it is one.
fn power_of_ten(factor: f64) -> Option<i32> {
    Decimal::of(factor).filter(|d| d.digits == 1).map(|d| d.exp)
}

/// `x · 10^k` taken on the decimal `x` is written as, so a value typed in one unit reads the
/// same in another: 100 nm is `1e-7` m, where `100.0 * 1e-9` is `1.0000000000000001e-7`. The
/// `f64` nearest to the exact decimal; `x` not finite gives `x · 10^k`.
///
/// ```
/// use hdi_tribology::units::shift_decimal;
/// assert_eq!(shift_decimal(100.0, -9), 1e-7);
/// assert_eq!(shift_decimal(1.1, -9), 1.1e-9);
/// assert_eq!(shift_decimal(7e-10, 9), 0.7); // 7e-10 / 1e-9 is 0.7000000000000001
/// assert_eq!(shift_decimal(50.0, -6), 5e-5);
/// assert!(shift_decimal(f64::INFINITY, 3).is_infinite());
/// ```
pub fn shift_decimal(x: f64, k: i32) -> f64 {
    if !x.is_finite() {
        return x * 10f64.powi(k);
    }
    // The shortest decimal with its exponent moved, read back: no allocation (`forces` takes
    // arrays of gaps through here).
    let mut buf = ryu::Buffer::new();
    let (mantissa, exp) = shortest(x, &mut buf);
    let mut text = [0u8; 64];
    let mut w = &mut text[..];
    let room = w.len();
    if write!(w, "{mantissa}e{}", i64::from(exp) + i64::from(k)).is_err() {
        return x * 10f64.powi(k);
    }
    let used = room - w.len();
    std::str::from_utf8(&text[..used])
        .ok()
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| x * 10f64.powi(k))
}

/// `x · factor` for a unit's factor: exact in decimal ([`shift_decimal`]) when `factor` is a
/// power of ten (`1e-9`, `1e3`, `1.0`), the plain product otherwise.
///
/// ```
/// use hdi_tribology::units::rescale;
/// assert_eq!(rescale(3.6, 1e-3), 3.6e-3); // 3.6 * 1e-3 is 0.0036000000000000003
/// assert_eq!(rescale(50.0, 1e-6), 5e-5); // 50.0 * 1e-6 is 4.9999999999999996e-5
/// assert_eq!(rescale(2.0, 0.5), 1.0);
/// ```
pub fn rescale(x: f64, factor: f64) -> f64 {
    match power_of_ten(factor) {
        Some(k) => shift_decimal(x, k),
        None => x * factor,
    }
}

/// `x / factor` for a unit's factor, the inverse of [`rescale`]: exact in decimal when `factor`
/// is a power of ten, the plain quotient otherwise.
///
/// ```
/// use hdi_tribology::units::unscale;
/// assert_eq!(unscale(7e-10, 1e-9), 0.7); // 7e-10 / 1e-9 is 0.7000000000000001
/// assert_eq!(unscale(1.0, 0.5), 2.0);
/// ```
pub fn unscale(x: f64, factor: f64) -> f64 {
    match power_of_ten(factor) {
        Some(k) => shift_decimal(x, -k),
        None => x / factor,
    }
}

/// Point `k` of the grid `start, start + step, start + 2·step, …`, taken on the decimals
/// `start` and `step` are written as and built from the integer `k` (never by adding steps):
/// the point a user who typed `start` and `step` reads, `0.0745` W where `0.06 + 29 * 0.0005`
/// is `0.07450000000000001`. Negative `k` steps back. Falls back to `start + k·step` in floating
/// point when the exact decimal would not fit 38 digits.
///
/// ```
/// use hdi_tribology::units::grid_point;
/// assert_eq!(grid_point(0.06, 0.0005, 29), 0.0745);
/// assert_eq!(grid_point(0.0, 0.1, 3), 0.3);
/// assert_eq!(grid_point(-0.3, 0.1, 3), 0.0);
/// assert_eq!(grid_point(0.0745, 0.015, -1), 0.0595);
/// ```
pub fn grid_point(start: f64, step: f64, k: i64) -> f64 {
    let exact = || {
        Decimal::of(start)?
            .add(Decimal::of(step)?.times(k)?)
            .map(Decimal::value)
    };
    exact().unwrap_or(start + k as f64 * step)
}

/// `x · factor^k`, taken on the decimals `x` and `factor` are written as and built from the
/// integer exponent `k` (never by repeated multiplication): the tolerance `1e-8` tightened
/// twice by `0.1` is `1e-10`, not `1.0000000000000002e-10`. Falls back to `x · factor^k` in
/// floating point when the exact decimal would not fit 38 digits.
///
/// ```
/// use hdi_tribology::units::geometric_point;
/// assert_eq!(geometric_point(1e-8, 0.1, 2), 1e-10);
/// assert_eq!(geometric_point(3e-7, 0.1, 5), 3e-12);
/// assert_eq!(geometric_point(1e-6, 0.5, 3), 1.25e-7);
/// assert_eq!(geometric_point(2.5, 0.1, 0), 2.5);
/// ```
pub fn geometric_point(x: f64, factor: f64, k: u32) -> f64 {
    let exact = || {
        let f = Decimal::of(factor)?;
        let fk = Decimal {
            digits: f.digits.checked_pow(k)?,
            exp: f.exp.checked_mul(i32::try_from(k).ok()?)?,
        };
        Decimal::of(x)?.mul(fk).map(Decimal::value)
    };
    exact().unwrap_or_else(|| x * factor.powi(i32::try_from(k).unwrap_or(i32::MAX)))
}

/// `x · num / den`, taken on the decimals they are written as when the result is a decimal
/// (`1e-15 · 7e-7 / 1e-7` is `7e-15`, not `6.999999999999999e-15`), else `x · (num / den)` in
/// floating point (`1e-15 · 1e-7 / 3e-7`).
///
/// ```
/// use hdi_tribology::units::proportional;
/// assert_eq!(proportional(1e-15, 7e-7, 1e-7), 7e-15);
/// assert_eq!(proportional(1e-15, 1e-7, 3e-7), 1e-15 * (1e-7 / 3e-7));
/// ```
pub fn proportional(x: f64, num: f64, den: f64) -> f64 {
    let exact = || {
        Decimal::of(x)?
            .mul(Decimal::of(num)?)?
            .div(Decimal::of(den)?)
            .map(Decimal::value)
    };
    exact().unwrap_or(x * (num / den))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The f64 nearest to the decimal text `s`: what a user who typed `s` means.
    fn typed(s: &str) -> f64 {
        s.parse().unwrap()
    }

    #[test]
    fn decimals_read_back_as_written() {
        for s in [
            "0.1",
            "-7e-10",
            "1234.5678",
            "1e-300",
            "6.02214076e23",
            "0",
            "-0.0005",
        ] {
            let d = Decimal::of(typed(s)).unwrap();
            assert_eq!(d.value(), typed(s), "{s}");
        }
        assert_eq!(Decimal::of(f64::NAN), None);
        assert_eq!(power_of_ten(1e-9), Some(-9));
        assert_eq!(power_of_ten(1.0), Some(0));
        assert_eq!(power_of_ten(2e3), None);
    }

    #[test]
    fn grids_land_on_the_decimals_a_user_types() {
        // Every point of 0, 0.1, …, 10 and 60, 60.1, …, 80 (mW) against the decimal typed.
        for k in 0..=100 {
            assert_eq!(
                grid_point(0.0, 0.1, k),
                typed(&format!("{}.{}", k / 10, k % 10))
            );
        }
        for k in 0..=200 {
            let text = format!("{}.{}", 60 + k / 10, k % 10);
            assert_eq!(grid_point(60.0, 0.1, k), typed(&text), "{text}");
            assert_eq!(
                grid_point(0.06, 0.0001, k),
                typed(&format!("{}e-3", text)),
                "{text} mW in W"
            );
        }
        // Far beyond 38 digits: the floating-point sum.
        assert_eq!(grid_point(1e300, 1e-300, 1), 1e300 + 1e-300);
    }

    #[test]
    fn ladders_land_on_powers_of_ten() {
        for k in 0..=14u32 {
            assert_eq!(
                geometric_point(1e-6, 0.1, k),
                typed(&format!("1e-{}", 6 + k))
            );
            assert_eq!(
                geometric_point(2e-7, 0.1, k),
                typed(&format!("2e-{}", 7 + k))
            );
        }
        // Repeated multiplication drifts where the ladder does not.
        let mut r = 1e-8;
        for _ in 0..2 {
            r *= 0.1;
        }
        assert_ne!(r, 1e-10);
        assert_eq!(geometric_point(1e-8, 0.1, 2), 1e-10);
    }

    /// Against the standard library's own shortest decimal (`{:e}`), its exponent moved in the
    /// text: random doubles of every magnitude, and decimals of few digits.
    #[test]
    fn shifts_agree_with_the_standard_librarys_shortest_text() {
        let reference = |x: f64, k: i32| -> f64 {
            let s = format!("{x:e}");
            let (m, e) = s.split_once('e').unwrap();
            typed(&format!("{m}e{}", e.parse::<i32>().unwrap() + k))
        };
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for i in 0..20_000 {
            let x = if i % 2 == 0 {
                f64::from_bits(next() >> 2) // positive, below 2, down to the subnormals
            } else {
                typed(&format!(
                    "{}e{}",
                    next() % 100_000,
                    (next() % 40) as i32 - 20
                ))
            };
            for k in [-12, -9, -3, 3, 9] {
                assert_eq!(shift_decimal(x, k), reference(x, k), "{x:e} e{k}");
            }
        }
    }

    #[test]
    fn shifted_decimals_match_the_decimal_in_the_other_unit() {
        for (x, k, s) in [
            (0.7, -9, "0.7e-9"),
            (100.0, -9, "100e-9"),
            (3.6, -3, "3.6e-3"),
            (50.0, -6, "50e-6"),
            (0.1, -6, "0.1e-6"),
            (1e-14, 9, "1e-5"),
        ] {
            assert_eq!(shift_decimal(x, k), typed(s), "{x} e{k}");
        }
    }
}
