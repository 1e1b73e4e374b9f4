//! Non-stiff problem with a closed-form solution: accuracy, observed convergence order of the
//! step and of the dense output, for every method; fixed-size and dynamic states agree.

use hdi_tribology::ode::{solve, FnSystem, Method, OdeSystem, Options, SaveAt};
use nalgebra::{allocator::Allocator, DVector, DefaultAllocator, Dim, OVector, Vector3};

/// u' = −2t u², p' = q, q' = −p: u = 1/(1+t²), p = cos t, q = −sin t.
fn rhs<D: Dim>(t: f64, y: &OVector<f64, D>, dy: &mut OVector<f64, D>)
where
    DefaultAllocator: Allocator<D>,
{
    dy[0] = -2.0 * t * y[0] * y[0];
    dy[1] = y[2];
    dy[2] = -y[1];
}

fn exact(t: f64) -> Vector3<f64> {
    Vector3::new(1.0 / (1.0 + t * t), t.cos(), -t.sin())
}

const T_END: f64 = 4.0;

/// Exact solution at `t` through the state `y0` at `t0`.
fn local_exact(t0: f64, y0: &Vector3<f64>, t: f64) -> Vector3<f64> {
    let (s, c) = (t - t0).sin_cos();
    Vector3::new(
        1.0 / (1.0 / y0[0] + t * t - t0 * t0),
        c * y0[1] + s * y0[2],
        -s * y0[1] + c * y0[2],
    )
}

fn max_err(y: &Vector3<f64>, t: f64) -> f64 {
    (y - exact(t)).amax()
}

/// Global error at T_END and max dense-output error at step midpoints, constant step h.
fn fixed_step_errors(method: Method, h: f64) -> (f64, f64) {
    let sys = FnSystem::new(rhs::<nalgebra::U3>);
    // Tight tolerances: with constant steps they only steer Radau5's Newton iteration, which
    // must converge far below the discretisation error.
    let opts = Options::default()
        .adaptive(false)
        .h_init(h)
        .rtol(1e-13)
        .atol(1e-13);
    let sol = solve(
        &sys,
        0.0,
        Vector3::new(1.0, 1.0, 0.0),
        T_END,
        method,
        &opts,
        &mut [],
    )
    .expect("fixed-step run");
    let end = max_err(sol.y_final(), sol.t_final());
    // Dense error within steps minus the error already present at the step ends: sample at
    // θ = 0.37 of each step and compare to the exact solution.
    // Local interpolation error: the dense output against the exact solution through the
    // step's own starting point (closed form for this system), at θ = 0.37 of each step of
    // size h on [1, T_END] (Radau5 may halve its first steps when Newton starts from a zero
    // guess; the same region in both runs keeps the error constants comparable).
    let mut dense = 0.0f64;
    for (k, w) in sol.t.windows(2).enumerate() {
        if w[0] < 1.0 - 1e-9 || (w[1] - w[0] - h).abs() > 1e-12 * h {
            continue;
        }
        let tm = w[0] + 0.37 * (w[1] - w[0]);
        let local = local_exact(w[0], &sol.y[k], tm);
        dense = dense.max((sol.sample(tm).unwrap() - local).amax());
    }
    (end, dense)
}

fn observed_order(method: Method, h: f64) -> (f64, f64) {
    let (e1, d1) = fixed_step_errors(method, h);
    let (e2, d2) = fixed_step_errors(method, h / 2.0);
    ((e1 / e2).log2(), (d1 / d2).log2())
}

/// Observed order within ±0.3 of nominal: step sizes are chosen in the asymptotic range
/// (errors well above rounding, well below O(1)).
/// `dense_local` is the order of the interpolant's local error, one more than the order of the
/// interpolant itself.
fn check_order(method: Method, h: f64, nominal: f64, dense_local: f64) {
    let (p, pd) = observed_order(method, h);
    println!("{method}: observed order {p:.3} (nominal {nominal}), dense local {pd:.3} (nominal {dense_local})");
    assert!((p - nominal).abs() <= 0.3, "{method}: observed order {p}");
    // The interpolant's local error is O(h^(q+1)) with q its order.
    let expect = dense_local;
    assert!(
        (pd - expect).abs() <= 0.3,
        "{method}: dense order {pd}, expected {expect}"
    );
}

#[test]
fn tsit5_order_5_dense_order_4() {
    check_order(Method::Tsit5, 0.05, 5.0, 5.0);
}

#[test]
fn dop853_order_8_dense_order_7() {
    check_order(Method::Dop853, 0.25, 8.0, 8.0);
}

#[test]
fn rodas5p_order_5_dense_order_4() {
    check_order(Method::Rodas5P, 0.1, 5.0, 5.0);
}

#[test]
fn radau5_order_5_dense_order_3() {
    // The collocation polynomial has order 3: local interpolation error O(h^4).
    check_order(Method::Radau5, 0.05, 5.0, 4.0);
}

#[test]
fn adaptive_runs_meet_tolerance() {
    let sys = FnSystem::new(rhs::<nalgebra::U3>);
    for (m, tol) in Method::ALL
        .into_iter()
        .flat_map(|m| [(m, 1e-6), (m, 1e-9)])
        .chain([(Method::Dop853, 1e-12)])
    {
        let opts = Options::default().rtol(tol).atol(tol);
        let sol = solve(
            &sys,
            0.0,
            Vector3::new(1.0, 1.0, 0.0),
            T_END,
            m,
            &opts,
            &mut [],
        )
        .unwrap();
        let e = max_err(sol.y_final(), T_END);
        println!(
            "{m} tol {tol:e}: error {e:.2e}, {} steps",
            sol.stats.accepted
        );
        // Global error of a tolerance-driven integration is a modest multiple of the tolerance.
        assert!(e < 20.0 * tol, "{m} tol {tol}: error {e}");
        assert_eq!(sol.t_final(), T_END);
        for (t, y) in sol.t.iter().zip(&sol.y) {
            assert!(max_err(y, *t) < 20.0 * tol);
        }
    }
}

#[test]
fn fixed_and_dynamic_states_agree() {
    let sys3 = FnSystem::new(rhs::<nalgebra::U3>);
    let sysd = FnSystem::new(rhs::<nalgebra::Dyn>);
    let opts = Options::default()
        .rtol(1e-8)
        .atol(1e-10)
        .save(SaveAt::Times(vec![0.5, 1.0, 3.0]));
    for m in Method::ALL {
        let a = solve(
            &sys3,
            0.0,
            Vector3::new(1.0, 1.0, 0.0),
            T_END,
            m,
            &opts,
            &mut [],
        )
        .unwrap();
        let b = solve(
            &sysd,
            0.0,
            DVector::from_vec(vec![1.0, 1.0, 0.0]),
            T_END,
            m,
            &opts,
            &mut [],
        )
        .unwrap();
        assert_eq!(a.t, b.t);
        assert_eq!(a.stats, b.stats);
        for (ya, yb) in a.y.iter().zip(&b.y) {
            // Same arithmetic in the same order: identical results.
            assert_eq!(ya.as_slice(), yb.as_slice());
        }
    }
}

#[allow(dead_code)]
fn assert_system<D: Dim, S: OdeSystem<D>>(_: &S)
where
    DefaultAllocator: Allocator<D> + Allocator<D, D>,
{
}

#[test]
fn error_shrinks_in_proportion_to_tolerance() {
    let sys = FnSystem::new(rhs::<nalgebra::U3>);
    for m in Method::ALL {
        // DOP853 is the method for tight tolerances; at loose ones it takes a handful of
        // steps whose error is far below the tolerance and not yet controlled by it.
        let tols = if m == Method::Dop853 {
            [1e-8, 1e-10, 1e-12]
        } else {
            [1e-5, 1e-7, 1e-9]
        };
        let errs: Vec<f64> = tols
            .iter()
            .map(|&tol| {
                let opts = Options::default().rtol(tol).atol(tol);
                let sol = solve(
                    &sys,
                    0.0,
                    Vector3::new(1.0, 1.0, 0.0),
                    T_END,
                    m,
                    &opts,
                    &mut [],
                )
                .unwrap();
                max_err(sol.y_final(), T_END)
            })
            .collect();
        println!("{m}: {errs:?}");
        for w in errs.windows(2) {
            // Tolerance down by 100: error down by at least 20 and at most 5000 (roughly
            // proportional; an error-per-step controller of a method of order p with an
            // estimator of order q scales like tol^(p/(q+1)), between 1 and 1.6 here).
            let ratio = w[0] / w[1];
            assert!((20.0..5000.0).contains(&ratio), "{m}: {errs:?}");
        }
    }
}
