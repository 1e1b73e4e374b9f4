//! Options and bookkeeping: t_stops at kinks, h_max, output at given times, statistics that
//! count what really happened, and Jacobian sources (analytic, finite-difference, complex-step).

use hdi_tribology::ode::{
    complex_step_jacobian, solve, FnSystem, Method, OdeSystem, Options, SaveAt,
};
use nalgebra::{Matrix2, Vector1, Vector2, U2};
use num_complex::Complex64;
use std::cell::Cell;

/// Van der Pol (μ = 10) that counts its right-hand-side and Jacobian calls.
struct Counted {
    rhs: Cell<usize>,
    jac: Cell<usize>,
    jacobian: JacobianKind,
}

#[derive(Clone, Copy, PartialEq)]
enum JacobianKind {
    Analytic,
    FiniteDifference,
    ComplexStep,
}

const MU: f64 = 10.0;

fn vdp_c(_t: f64, y: &Vector2<Complex64>, dy: &mut Vector2<Complex64>) {
    dy[0] = y[1];
    dy[1] = (Complex64::new(1.0, 0.0) - y[0] * y[0]) * y[1] * MU - y[0];
}

impl OdeSystem<U2> for Counted {
    fn rhs(&self, _t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
        self.rhs.set(self.rhs.get() + 1);
        dy[0] = y[1];
        dy[1] = MU * (1.0 - y[0] * y[0]) * y[1] - y[0];
    }
    fn jacobian(&self, t: f64, y: &Vector2<f64>, j: &mut Matrix2<f64>) -> bool {
        match self.jacobian {
            JacobianKind::Analytic => {
                self.jac.set(self.jac.get() + 1);
                *j = Matrix2::new(
                    0.0,
                    1.0,
                    -2.0 * MU * y[0] * y[1] - 1.0,
                    MU * (1.0 - y[0] * y[0]),
                );
                true
            }
            JacobianKind::ComplexStep => {
                self.jac.set(self.jac.get() + 1);
                complex_step_jacobian(vdp_c, t, y, j);
                true
            }
            JacobianKind::FiniteDifference => false,
        }
    }
    fn time_derivative(&self, _t: f64, _y: &Vector2<f64>, dfdt: &mut Vector2<f64>) -> bool {
        dfdt.fill(0.0);
        true
    }
}

fn counted(jacobian: JacobianKind) -> Counted {
    Counted {
        rhs: Cell::new(0),
        jac: Cell::new(0),
        jacobian,
    }
}

#[test]
fn stats_count_every_evaluation() {
    for m in Method::ALL {
        for kind in [JacobianKind::Analytic, JacobianKind::FiniteDifference] {
            let sys = counted(kind);
            let opts = Options::default().rtol(1e-7).atol(1e-9);
            let sol = solve(&sys, 0.0, Vector2::new(2.0, 0.0), 30.0, m, &opts, &mut []).unwrap();
            let s = sol.stats;
            assert_eq!(s.rhs_evals, sys.rhs.get(), "{m}: rhs count");
            if kind == JacobianKind::Analytic {
                assert_eq!(s.jac_evals, sys.jac.get(), "{m}: Jacobian count");
            }
            assert_eq!(s.accepted + 1, sol.t.len(), "{m}: one saved point per step");
            match m {
                Method::Tsit5 | Method::Dop853 => {
                    assert_eq!((s.jac_evals, s.lu_decomps, s.stiff_steps), (0, 0, 0));
                }
                Method::Rodas5P => {
                    // One Jacobian per accepted step (reused by rejected retries), one LU per
                    // attempt.
                    assert_eq!(s.jac_evals, s.accepted);
                    assert_eq!(s.lu_decomps, s.accepted + s.rejected);
                    assert_eq!(s.stiff_steps, s.accepted);
                }
                Method::Radau5 => {
                    // Jacobians and LU factors are reused across steps.
                    assert!(s.jac_evals < s.accepted, "{m}: {s:?}");
                    assert!(s.newton_iters >= s.accepted);
                }
                Method::Auto => assert!(s.stiff_steps <= s.accepted),
            }
        }
    }
}

#[test]
fn jacobian_sources_agree() {
    // Analytic, finite-difference and complex-step Jacobians give the same solution to well
    // within the tolerance (the Jacobian only steers the linear algebra of Rodas5P's stages to
    // order-preserving accuracy; differences enter at the level of the FD error ~1e-8).
    let opts = Options::default().rtol(1e-9).atol(1e-11);
    let run = |k| {
        *solve(
            &counted(k),
            0.0,
            Vector2::new(2.0, 0.0),
            30.0,
            Method::Rodas5P,
            &opts,
            &mut [],
        )
        .unwrap()
        .y_final()
    };
    let a = run(JacobianKind::Analytic);
    let f = run(JacobianKind::FiniteDifference);
    let c = run(JacobianKind::ComplexStep);
    assert!((a - c).amax() < 1e-12, "complex step: {}", (a - c).amax());
    assert!(
        (a - f).amax() < 1e-6,
        "finite difference: {}",
        (a - f).amax()
    );
}

#[test]
fn t_stops_and_h_max_shape_the_steps() {
    // A right-hand side with a kink at t = 1 (like a knot of a heater programme):
    // y' = t before, y' = 1 − 2(t − 1) after; exact y = t²/2, then 1/2 + (t−1) − (t−1)².
    let exact = |t: f64| {
        if t < 1.0 {
            0.5 * t * t
        } else {
            0.5 + (t - 1.0) - (t - 1.0).powi(2)
        }
    };
    let sys = FnSystem::new(|t: f64, _y: &Vector1<f64>, dy: &mut Vector1<f64>| {
        dy[0] = if t < 1.0 { t } else { 1.0 - 2.0 * (t - 1.0) };
    });
    for m in Method::ALL {
        let opts = Options::default().t_stops(vec![1.0, 5.0]).h_max(0.25);
        let sol = solve(&sys, 0.0, Vector1::new(0.0), 3.0, m, &opts, &mut []).unwrap();
        assert!(sol.t.contains(&1.0), "{m}: kink not a step end");
        assert!(!sol.t.contains(&5.0));
        assert!(
            sol.t
                .windows(2)
                .all(|w| w[1] - w[0] <= 0.25 * (1.0 + 1e-12)),
            "{m}: h_max"
        );
        // Quadratic pieces: every method integrates them exactly when no step straddles the
        // kink, up to rounding and, for Rodas5P, the finite-difference ∂f/∂t (relative
        // error ~√ε entering at O(h²)): 1e-9.
        assert!(
            (sol.y_final()[0] - exact(3.0)).abs() < 1e-9,
            "{m}: {}",
            sol.y_final()[0]
        );
        for t in [0.3, 0.999, 1.0, 1.7] {
            let e = (sol.sample(t).unwrap()[0] - exact(t)).abs();
            assert!(e < 1e-9, "{m} at {t}: {e}");
        }
    }
}

#[test]
fn save_at_times_interpolates_requested_points() {
    // Harmonic oscillator; output exactly at the requested times (dense off too).
    let sys = FnSystem::new(|_t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>| {
        dy[0] = y[1];
        dy[1] = -y[0];
    });
    let times = vec![0.0, 0.1, 1.0, 2.5, 7.0];
    for m in Method::ALL {
        let opts = Options::default()
            .rtol(1e-10)
            .atol(1e-10)
            .dense(false)
            .save(SaveAt::Times(times.clone()));
        let sol = solve(&sys, 0.0, Vector2::new(1.0, 0.0), 7.0, m, &opts, &mut []).unwrap();
        assert_eq!(sol.t, times);
        assert!(sol.sample(1.0).is_none(), "dense output was off");
        for (t, y) in sol.t.iter().zip(&sol.y) {
            // Interpolation error of the lowest-order interpolant (Radau5, order 3) at
            // tol 1e-10 stays below 1e-8.
            assert!(
                (y[0] - t.cos()).abs() < 1e-8,
                "{m} at {t}: {}",
                y[0] - t.cos()
            );
        }
        let fin = Options::default().save(SaveAt::Final);
        let sol = solve(&sys, 0.0, Vector2::new(1.0, 0.0), 7.0, m, &fin, &mut []).unwrap();
        assert_eq!(sol.t, vec![7.0]);
    }
}
