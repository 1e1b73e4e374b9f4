//! Test problems for the work–precision report and the peer comparison, with their reference
//! solutions: one non-stiff problem with a closed-form solution, the non-stiff Pleiades (28
//! states), and five stiff problems of the Test Set for IVP Solvers (F. Mazzia, C. Magherini et
//! al., Univ. Bari): Van der Pol (μ = 1000), Robertson to t = 1e11, HIRES, OREGO and the badly
//! scaled E5. The reference values are those of the test set; the crate's validation tests
//! (`tests/ode_stiff.rs`, `tests/ode_testset.rs`) use these same definitions.
//!
//! Right-hand sides and Jacobians work on plain slices so that any solver can call them.
#![allow(dead_code)]

use hdi_tribology::ode::{OdeSystem, Options, Tolerance};
use nalgebra::{Const, SMatrix, SVector};

/// One initial-value problem on `N` components with a reference value at its end time.
pub struct Problem<const N: usize> {
    /// Short name used in tables and file names.
    pub name: &'static str,
    /// Whether explicit methods are expected to fail on it.
    pub stiff: bool,
    /// Whether `f` does not depend on `t` (declared to the solvers, as a user would: Rodas5P
    /// then needs no difference quotient for ∂f/∂t).
    pub autonomous: bool,
    /// `dy = f(t, y)`.
    pub rhs: fn(f64, &[f64], &mut [f64]),
    /// Row-major Jacobian `j[i·N + k] = ∂f_i/∂y_k`.
    pub jac: fn(f64, &[f64], &mut [f64]),
    /// Initial state at `t = 0`.
    pub y0: [f64; N],
    /// End time.
    pub t_end: f64,
    /// Reference solution at `t_end`.
    pub reference: [f64; N],
    /// Error measure: `max_i |y_i − ref_i| / max(|ref_i|, floor)`.
    pub floor: f64,
    /// Absolute tolerance per component for a given relative tolerance.
    pub atol: fn(f64) -> [f64; N],
}

impl<const N: usize> Problem<N> {
    /// Error of a final state against the reference.
    pub fn error(&self, y: &[f64]) -> f64 {
        (0..N)
            .map(|i| (y[i] - self.reference[i]).abs() / self.reference[i].abs().max(self.floor))
            .fold(0.0, f64::max)
    }

    /// The crate's options for relative tolerance `rtol` (no saved steps, no dense output).
    pub fn options(&self, rtol: f64) -> Options {
        Options {
            atol: Tolerance::PerComponent((self.atol)(rtol).to_vec()),
            ..Options::default()
                .rtol(rtol)
                .dense(false)
                .save(hdi_tribology::ode::SaveAt::Final)
        }
    }

    /// The initial state as a nalgebra vector.
    pub fn y0_vector(&self) -> SVector<f64, N> {
        SVector::from(self.y0)
    }

    /// `J·v` from the row-major Jacobian (for solvers that ask for Jacobian–vector products).
    pub fn jac_times(&self, t: f64, y: &[f64], v: &[f64], out: &mut [f64]) {
        let mut j = vec![0.0; N * N];
        (self.jac)(t, y, &mut j);
        for i in 0..N {
            out[i] = (0..N).map(|k| j[i * N + k] * v[k]).sum();
        }
    }
}

impl<const N: usize> OdeSystem<Const<N>> for Problem<N> {
    fn rhs(&self, t: f64, y: &SVector<f64, N>, dy: &mut SVector<f64, N>) {
        (self.rhs)(t, y.as_slice(), dy.as_mut_slice());
    }
    fn jacobian(&self, t: f64, y: &SVector<f64, N>, j: &mut SMatrix<f64, N, N>) -> bool {
        let mut buf = [[0.0; N]; N];
        (self.jac)(t, y.as_slice(), buf.as_flattened_mut());
        for (i, row) in buf.iter().enumerate() {
            for (k, v) in row.iter().enumerate() {
                j[(i, k)] = *v;
            }
        }
        true
    }
    fn is_autonomous(&self) -> bool {
        self.autonomous
    }
}

/// End time of the non-stiff problem.
const EXACT_T_END: f64 = 10.0;

/// Non-stiff, closed form: `u' = −2t u²`, `p' = q`, `q' = −p` with `u = 1/(1+t²)`,
/// `p = cos t`, `q = −sin t`. The error is absolute (floor 1).
pub fn exact() -> Problem<3> {
    Problem {
        name: "exact",
        autonomous: false,
        stiff: false,
        rhs: |t, y, dy| {
            dy[0] = -2.0 * t * y[0] * y[0];
            dy[1] = y[2];
            dy[2] = -y[1];
        },
        jac: |t, y, j| {
            j.fill(0.0);
            j[0] = -4.0 * t * y[0];
            j[5] = 1.0;
            j[7] = -1.0;
        },
        y0: [1.0, 1.0, 0.0],
        t_end: EXACT_T_END,
        reference: [
            1.0 / (1.0 + EXACT_T_END * EXACT_T_END),
            EXACT_T_END.cos(),
            -EXACT_T_END.sin(),
        ],
        floor: 1.0,
        atol: |rtol| [rtol; 3],
    }
}

const MU: f64 = 1000.0;

/// Van der Pol, μ = 1000, `y(0) = (2, 0)`, to t = 2000 (test set "vdpol"); relative error with
/// floor 1e-3 (y₂ ends near −9e-4).
pub fn van_der_pol() -> Problem<2> {
    Problem {
        name: "vdp",
        autonomous: true,
        stiff: true,
        rhs: |_, y, dy| {
            dy[0] = y[1];
            dy[1] = MU * (1.0 - y[0] * y[0]) * y[1] - y[0];
        },
        jac: |_, y, j| {
            j[0] = 0.0;
            j[1] = 1.0;
            j[2] = -2.0 * MU * y[0] * y[1] - 1.0;
            j[3] = MU * (1.0 - y[0] * y[0]);
        },
        y0: [2.0, 0.0],
        t_end: 2000.0,
        reference: [1.706_167_732_170_469, -0.892_809_701_024_812_5e-3],
        floor: 1e-3,
        atol: |rtol| [rtol; 2],
    }
}

/// Robertson's kinetics to t = 1e11 (test set "rober"); relative error on every component,
/// even y₂ ≈ 8e-14, hence absolute tolerances far below each component's size.
pub fn robertson() -> Problem<3> {
    Problem {
        name: "robertson",
        autonomous: true,
        stiff: true,
        rhs: |_, y, dy| {
            let r1 = 0.04 * y[0];
            let r2 = 1e4 * y[1] * y[2];
            let r3 = 3e7 * y[1] * y[1];
            dy[0] = -r1 + r2;
            dy[1] = r1 - r2 - r3;
            dy[2] = r3;
        },
        jac: |_, y, j| {
            j.copy_from_slice(&[
                -0.04,
                1e4 * y[2],
                1e4 * y[1],
                0.04,
                -1e4 * y[2] - 6e7 * y[1],
                -1e4 * y[1],
                0.0,
                6e7 * y[1],
                0.0,
            ]);
        },
        y0: [1.0, 0.0, 0.0],
        t_end: 1e11,
        reference: [
            0.208_334_014_970_125_5e-7,
            0.833_336_077_033_471_3e-13,
            0.999_999_979_166_505,
        ],
        floor: 1e-30,
        atol: |rtol| [1e-4 * rtol * 1e-8, 1e-4 * rtol * 1e-13, 1e-4 * rtol],
    }
}

/// HIRES (Schäfer 1975), 8 components, to t = 321.8122 (test set "hires"); relative error.
pub fn hires() -> Problem<8> {
    Problem {
        name: "hires",
        autonomous: true,
        stiff: true,
        rhs: |_, y, f| {
            f[0] = -1.71 * y[0] + 0.43 * y[1] + 8.32 * y[2] + 0.0007;
            f[1] = 1.71 * y[0] - 8.75 * y[1];
            f[2] = -10.03 * y[2] + 0.43 * y[3] + 0.035 * y[4];
            f[3] = 8.32 * y[1] + 1.71 * y[2] - 1.12 * y[3];
            f[4] = -1.745 * y[4] + 0.43 * y[5] + 0.43 * y[6];
            f[5] = -280.0 * y[5] * y[7] + 0.69 * y[3] + 1.71 * y[4] - 0.43 * y[5] + 0.69 * y[6];
            f[6] = 280.0 * y[5] * y[7] - 1.81 * y[6];
            f[7] = -f[6];
        },
        jac: |_, y, j| {
            j.fill(0.0);
            let mut set = |i: usize, k: usize, v: f64| j[i * 8 + k] = v;
            set(0, 0, -1.71);
            set(0, 1, 0.43);
            set(0, 2, 8.32);
            set(1, 0, 1.71);
            set(1, 1, -8.75);
            set(2, 2, -10.03);
            set(2, 3, 0.43);
            set(2, 4, 0.035);
            set(3, 1, 8.32);
            set(3, 2, 1.71);
            set(3, 3, -1.12);
            set(4, 4, -1.745);
            set(4, 5, 0.43);
            set(4, 6, 0.43);
            set(5, 3, 0.69);
            set(5, 4, 1.71);
            set(5, 5, -280.0 * y[7] - 0.43);
            set(5, 6, 0.69);
            set(5, 7, -280.0 * y[5]);
            set(6, 5, 280.0 * y[7]);
            set(6, 6, -1.81);
            set(6, 7, 280.0 * y[5]);
            set(7, 5, -280.0 * y[7]);
            set(7, 6, 1.81);
            set(7, 7, -280.0 * y[5]);
        },
        y0: [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0057],
        t_end: 321.8122,
        reference: [
            0.737_131_257_332_566_8e-3,
            0.144_248_572_631_618_5e-3,
            0.588_872_974_096_757_5e-4,
            0.117_565_134_328_314_9e-2,
            0.238_635_619_883_133_1e-2,
            0.623_896_825_274_279_6e-2,
            0.284_999_839_518_576_9e-2,
            0.285_000_160_481_423_1e-2,
        ],
        floor: 1e-30,
        atol: |rtol| [rtol * 1e-3; 8],
    }
}

/// OREGO, the Oregonator (Field & Noyes), to t = 360 (test set "orego"); relative error.
pub fn orego() -> Problem<3> {
    const S: f64 = 77.27;
    const W: f64 = 0.161;
    const Q: f64 = 8.375e-6;
    Problem {
        name: "orego",
        autonomous: true,
        stiff: true,
        rhs: |_, y, f| {
            f[0] = S * (y[1] + y[0] * (1.0 - Q * y[0] - y[1]));
            f[1] = (y[2] - (1.0 + y[0]) * y[1]) / S;
            f[2] = W * (y[0] - y[2]);
        },
        jac: |_, y, j| {
            j.copy_from_slice(&[
                S * (1.0 - 2.0 * Q * y[0] - y[1]),
                S * (1.0 - y[0]),
                0.0,
                -y[1] / S,
                -(1.0 + y[0]) / S,
                1.0 / S,
                W,
                0.0,
                -W,
            ]);
        },
        y0: [1.0, 2.0, 3.0],
        t_end: 360.0,
        reference: [
            0.100_081_487_031_852_3e1,
            0.122_817_852_154_991_7e4,
            0.132_055_494_284_670_6e3,
        ],
        floor: 1e-30,
        // Components range over 1 … 1e5: the tolerance is relative, with a small floor.
        atol: |rtol| [rtol * 1e-2; 3],
    }
}

/// E5 rate constants (test set "e5", a chemical pyrolysis).
const E5_A: f64 = 7.89e-10;
const E5_B: f64 = 1.1e7;
const E5_C: f64 = 1.13e3;
const E5_M: f64 = 1e6;

/// E5 to t = 1e13 (test set "e5"): badly scaled (y₁ starts at 1.76e-3 and ends near 1e-291,
/// the others never exceed ~1.5e-10 and end near 1e-22), with the linear invariant
/// y₂ − y₃ − y₄ = 0. The end values y₂ ≈ y₃ ≈ 1/(MCt) are right only while the invariant holds
/// to well below 1e-22, i.e. to 1e-12 of y₂'s peak: the right-hand side is written so that
/// f₂ − f₃ − f₄ = 0 holds in floating point too (f₃ = f₂ − f₄, algebraically the test set's
/// f₃ = Ay₁ − By₁y₃ − MCy₂y₃ + Cy₄, whose rounding of the nearly cancelling ±1.5e-7 terms alone
/// breaks the invariant by ~1e-20 over the run). Error: relative, with floor 1e-24 (the test
/// set's absolute tolerance for E5), so y₁ ≈ 1e-291 and y₄ = 0 only have to be tiny.
/// Absolute tolerance 1e-20·rtol, as in the test set's runs.
pub fn e5() -> Problem<4> {
    Problem {
        name: "e5",
        autonomous: true,
        stiff: true,
        rhs: |_, y, f| {
            let (a, b, mc) = (E5_A * y[0], E5_B * y[0] * y[2], E5_M * E5_C * y[1] * y[2]);
            let c = E5_C * y[3];
            f[0] = -a - b;
            f[1] = a - mc;
            f[3] = b - c;
            f[2] = f[1] - f[3];
        },
        jac: |_, y, j| {
            let mc = E5_M * E5_C;
            j.copy_from_slice(&[
                -E5_A - E5_B * y[2],
                0.0,
                -E5_B * y[0],
                0.0,
                E5_A,
                -mc * y[2],
                -mc * y[1],
                0.0,
                E5_A - E5_B * y[2],
                -mc * y[2],
                -E5_B * y[0] - mc * y[1],
                E5_C,
                E5_B * y[2],
                0.0,
                E5_B * y[0],
                -E5_C,
            ]);
        },
        y0: [1.76e-3, 0.0, 0.0, 0.0],
        t_end: 1e13,
        reference: [
            0.115_290_327_871_182_9e-290,
            0.886_765_551_764_212e-22,
            0.885_481_462_626_883_8e-22,
            0.0,
        ],
        floor: 1e-24,
        atol: |rtol| [1e-20 * rtol; 4],
    }
}

/// Pleiades (test set "plei"): seven bodies in the plane with masses 1 … 7 under gravity,
/// 28 states (x, y, x', y'), to t = 3. Non-stiff; close encounters make the step size vary by
/// orders of magnitude. Relative error (all end components are 0.24 … 5.3 in size).
pub fn pleiades() -> Problem<28> {
    Problem {
        name: "pleiades",
        autonomous: true,
        stiff: false,
        rhs: |_, y, f| {
            for i in 0..7 {
                let (mut ax, mut ay) = (0.0, 0.0);
                for j in 0..7 {
                    if j != i {
                        let (dx, dy) = (y[j] - y[i], y[j + 7] - y[i + 7]);
                        let r2 = dx * dx + dy * dy;
                        let r3 = r2 * r2.sqrt();
                        let m = (j + 1) as f64;
                        ax += m * dx / r3;
                        ay += m * dy / r3;
                    }
                }
                f[i + 14] = ax;
                f[i + 21] = ay;
            }
            f[..14].copy_from_slice(&y[14..28]);
        },
        jac: |_, y, jac| {
            jac.fill(0.0);
            let mut set = |i: usize, k: usize, v: f64| jac[i * 28 + k] = v;
            for i in 0..14 {
                set(i, 14 + i, 1.0);
            }
            // ∂a_i/∂r_j for j ≠ i, and the diagonal blocks as minus their row sums.
            let mut diag = [[0.0; 3]; 7];
            for i in 0..7 {
                for j in 0..7 {
                    if j == i {
                        continue;
                    }
                    let (dx, dy) = (y[j] - y[i], y[j + 7] - y[i + 7]);
                    let r2 = dx * dx + dy * dy;
                    let r = r2.sqrt();
                    let (r3, r5) = (r2 * r, r2 * r2 * r);
                    let m = (j + 1) as f64;
                    let xx = m * (1.0 / r3 - 3.0 * dx * dx / r5);
                    let yy = m * (1.0 / r3 - 3.0 * dy * dy / r5);
                    let xy = -m * 3.0 * dx * dy / r5;
                    set(14 + i, j, xx);
                    set(14 + i, 7 + j, xy);
                    set(21 + i, j, xy);
                    set(21 + i, 7 + j, yy);
                    diag[i][0] += xx;
                    diag[i][1] += xy;
                    diag[i][2] += yy;
                }
                set(14 + i, i, -diag[i][0]);
                set(14 + i, 7 + i, -diag[i][1]);
                set(21 + i, i, -diag[i][1]);
                set(21 + i, 7 + i, -diag[i][2]);
            }
        },
        y0: [
            3.0, 3.0, -1.0, -3.0, 2.0, -2.0, 2.0, // x
            3.0, -3.0, 2.0, 0.0, 0.0, -4.0, 4.0, // y
            0.0, 0.0, 0.0, 0.0, 0.0, 1.75, -1.5, // x'
            0.0, 0.0, 0.0, -1.25, 1.0, 0.0, 0.0, // y'
        ],
        t_end: 3.0,
        reference: [
            0.370_613_914_397_050_2,
            0.323_728_409_205_723_3e1,
            -0.322_255_903_241_832_4e1,
            0.659_709_145_577_531,
            0.342_558_170_715_658_4,
            0.156_217_210_140_063_1e1,
            -0.700_309_292_221_249_5,
            -0.394_343_758_551_739_2e1,
            -0.327_138_097_397_255e1,
            0.522_508_184_345_654_3e1,
            -0.259_061_243_497_747e1,
            0.119_821_369_339_227_5e1,
            -0.242_968_234_493_582_4,
            0.109_144_924_042_898e1,
            0.341_700_380_631_431_3e1,
            0.135_458_450_162_550_1e1,
            -0.259_006_559_781_077_5e1,
            0.202_505_373_471_424_2e1,
            -0.115_581_510_016_044_8e1,
            -0.807_298_817_022_302_1,
            0.595_239_635_420_871,
            -0.374_124_496_123_401e1,
            0.377_345_968_575_063,
            0.938_685_886_955_107_3,
            0.366_792_222_720_057_1,
            -0.347_404_635_380_849,
            0.234_491_544_818_093_7e1,
            -0.194_702_043_426_329_2e1,
        ],
        floor: 1e-30,
        atol: |rtol| [rtol; 28],
    }
}
