//! Failure is an answer: typed errors naming the field, or the time and the reason.

use hdi_tribology::ode::{solve, FnSystem, Method, OdeError, Options, SaveAt};
use nalgebra::{DVector, Vector1, Vector2};

fn vdp(mu: f64) -> FnSystem<impl Fn(f64, &Vector2<f64>, &mut Vector2<f64>)> {
    FnSystem::new(move |_t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>| {
        dy[0] = y[1];
        dy[1] = mu * (1.0 - y[0] * y[0]) * y[1] - y[0];
    })
}

#[test]
fn explicit_method_on_stiff_problem_exhausts_step_budget() {
    let opts = Options::default().max_steps(2000);
    let err = solve(
        &vdp(1e6),
        0.0,
        Vector2::new(2.0, 0.0),
        2e6,
        Method::Tsit5,
        &opts,
        &mut [],
    )
    .unwrap_err();
    match err {
        OdeError::TooManySteps { t, max_steps } => {
            assert_eq!(max_steps, 2000);
            assert!(t > 0.0 && t < 2e6);
        }
        other => panic!("expected TooManySteps, got {other}"),
    }
    // The stiff methods finish the same problem within the same budget.
    for m in [Method::Rodas5P, Method::Radau5, Method::Auto] {
        let sol = solve(
            &vdp(1e6),
            0.0,
            Vector2::new(2.0, 0.0),
            2e6,
            m,
            &opts,
            &mut [],
        );
        assert!(sol.is_ok(), "{m}: {:?}", sol.err());
    }
}

#[test]
fn nan_right_hand_side_is_reported_with_its_time() {
    let sys = FnSystem::new(|t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>| {
        dy[0] = if t > 1.0 { f64::NAN } else { -y[0] };
    });
    for m in Method::ALL {
        let err = solve(
            &sys,
            0.0,
            Vector1::new(1.0),
            2.0,
            m,
            &Options::default(),
            &mut [],
        )
        .unwrap_err();
        match err {
            OdeError::NonFinite { t, .. } => assert!((t - 1.0).abs() < 1e-6, "{m}: t = {t}"),
            other => panic!("{m}: expected NonFinite, got {other}"),
        }
    }
    // Non-finite at the very start.
    let bad =
        FnSystem::new(|_t: f64, _y: &Vector1<f64>, dy: &mut Vector1<f64>| dy[0] = f64::INFINITY);
    let err = solve(
        &bad,
        0.0,
        Vector1::new(1.0),
        1.0,
        Method::Tsit5,
        &Options::default(),
        &mut [],
    )
    .unwrap_err();
    assert!(
        matches!(err, OdeError::NonFinite { t, .. } if t == 0.0),
        "{err}"
    );
}

#[test]
fn blow_up_hits_the_step_floor() {
    // y' = y², y(0) = 1: y = 1/(1 − t) blows up at t = 1.
    let sys = FnSystem::new(|_t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>| dy[0] = y[0] * y[0]);
    for m in [
        Method::Tsit5,
        Method::Dop853,
        Method::Rodas5P,
        Method::Radau5,
    ] {
        let opts = Options::default().h_min(1e-9);
        let err = solve(&sys, 0.0, Vector1::new(1.0), 2.0, m, &opts, &mut []).unwrap_err();
        match err {
            OdeError::StepTooSmall { t, h, h_min } => {
                assert_eq!(h_min, 1e-9);
                assert!(h < h_min);
                // Stuck at the singularity (a discrete solution may step a hair past the pole,
                // where it is still finite, before the floor is hit).
                assert!((t - 1.0).abs() < 1e-3, "{m}: t = {t}");
            }
            other => panic!("{m}: expected StepTooSmall, got {other}"),
        }
    }
}

#[test]
fn bad_input_names_the_field() {
    let sys = vdp(1.0);
    let y0 = Vector2::new(2.0, 0.0);
    let field = |r: Result<_, OdeError>| match r {
        Err(OdeError::InvalidInput { field, .. }) => field,
        Err(other) => panic!("expected InvalidInput, got {other}"),
        Ok(_) => panic!("expected an error"),
    };
    let run = |t0: f64, y0: Vector2<f64>, tf: f64, o: &Options| {
        solve(&sys, t0, y0, tf, Method::Tsit5, o, &mut []).map(|_| ())
    };
    let d = Options::default();
    assert_eq!(field(run(1.0, y0, 0.0, &d)), "tf");
    assert_eq!(field(run(0.0, y0, f64::NAN, &d)), "t0, tf");
    assert_eq!(
        field(run(0.0, Vector2::new(f64::NAN, 0.0), 1.0, &d)),
        "y0[0]"
    );
    assert_eq!(
        field(run(0.0, y0, 1.0, &d.clone().rtol(0.0))),
        "options.rtol"
    );
    assert_eq!(
        field(run(0.0, y0, 1.0, &d.clone().atol(-1.0))),
        "options.atol"
    );
    assert_eq!(
        field(run(0.0, y0, 1.0, &d.clone().atol_per_component(vec![1e-6]))),
        "options.atol"
    );
    assert_eq!(
        field(run(
            0.0,
            y0,
            1.0,
            &d.clone().atol_per_component(vec![1e-6, f64::NAN])
        )),
        "options.atol[1]"
    );
    assert_eq!(
        field(run(0.0, y0, 1.0, &d.clone().h_max(0.0))),
        "options.h_max"
    );
    assert_eq!(
        field(run(0.0, y0, 1.0, &d.clone().max_steps(0))),
        "options.max_steps"
    );
    assert_eq!(
        field(run(0.0, y0, 1.0, &d.clone().adaptive(false))),
        "options.h_init"
    );
    assert_eq!(
        field(run(
            0.0,
            y0,
            1.0,
            &d.clone().save(SaveAt::Times(vec![0.5, 2.0]))
        )),
        "options.save"
    );
    assert_eq!(
        field(run(
            0.0,
            y0,
            1.0,
            &d.clone().save(SaveAt::Times(vec![0.5, 0.2]))
        )),
        "options.save"
    );
    // Empty dynamic state.
    let dsys = FnSystem::new(|_t: f64, _y: &DVector<f64>, _dy: &mut DVector<f64>| {});
    let r = solve(
        &dsys,
        0.0,
        DVector::zeros(0),
        1.0,
        Method::Tsit5,
        &d,
        &mut [],
    );
    assert!(matches!(r, Err(OdeError::InvalidInput { .. })));
    // Unknown method name.
    assert!(matches!(
        "rk4".parse::<Method>(),
        Err(OdeError::InvalidInput { .. })
    ));
}

#[test]
fn newton_divergence_is_reported() {
    // y' = −1e8·sign(y − 1) from y = 1: the state sits on a jump of the right-hand side and
    // the stage equations have no solution at any step size; the Newton iterates of Radau5
    // bounce between the two branches (contraction rate ≈ 1). After a bounded number of
    // halvings the solver gives up with a typed error at t = 0.
    let sys = FnSystem::new(|_t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>| {
        dy[0] = -1e8 * (y[0] - 1.0).signum();
    });
    let err = solve(
        &sys,
        0.0,
        Vector1::new(1.0),
        1.0,
        Method::Radau5,
        &Options::default(),
        &mut [],
    )
    .unwrap_err();
    assert!(
        matches!(err, OdeError::NewtonDivergence { t, .. } if t == 0.0),
        "{err}"
    );
}

#[test]
fn chattering_right_hand_side_ends_with_an_error_not_a_hang() {
    // y' = −sign(y): after t = 1 the solution chatters around 0 and the implicit stage
    // equations have no solution. Whatever the solver does there, it must stop with a typed
    // error at t ≈ 1 within its step budget.
    let sys = FnSystem::new(|_t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>| {
        dy[0] = -y[0].signum();
    });
    let opts = Options::default().max_steps(20_000);
    let err = solve(
        &sys,
        0.0,
        Vector1::new(1.0),
        3.0,
        Method::Radau5,
        &opts,
        &mut [],
    )
    .unwrap_err();
    let t = match err {
        OdeError::NewtonDivergence { t, .. }
        | OdeError::StepTooSmall { t, .. }
        | OdeError::TooManySteps { t, .. } => t,
        other => panic!("unexpected error {other}"),
    };
    assert!((t - 1.0).abs() < 1e-3, "t = {t}");
}
