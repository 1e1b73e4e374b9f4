//! Test problems for the work–precision report and the peer comparison, with their reference
//! solutions: one non-stiff problem with a closed-form solution, and three stiff problems of the
//! Test Set for IVP Solvers (F. Mazzia, C. Magherini et al., Univ. Bari): Van der Pol (μ = 1000),
//! Robertson to t = 1e11 and HIRES. The reference values are those of the test set; the crate's
//! stiff validation tests (`tests/ode_stiff.rs`) use these same definitions.
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
        // Stack buffer: every problem here has at most 8 components.
        let mut buf = [0.0; 64];
        let j = &mut buf[..N * N];
        (self.jac)(t, y, j);
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
}

/// End time of the non-stiff problem.
const EXACT_T_END: f64 = 10.0;

/// Non-stiff, closed form: `u' = −2t u²`, `p' = q`, `q' = −p` with `u = 1/(1+t²)`,
/// `p = cos t`, `q = −sin t`. The error is absolute (floor 1).
pub fn exact() -> Problem<3> {
    Problem {
        name: "exact",
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
