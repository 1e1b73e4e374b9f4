//! The steppable integrator: it reproduces `solve` bit for bit, lands exactly where asked,
//! restarts after jumps, and events that act on the state conserve what they should.

#[path = "../examples/common/problems.rs"]
mod problems;

use hdi_tribology::ode::{
    solve, Direction, Event, FnSystem, Integrator, Method, OdeError, OdeSystem, Options, SaveAt,
    StepStatus, TimeMemo, Tolerance,
};
use nalgebra::{Vector1, Vector2, U1};
use std::cell::Cell;

const G: f64 = 9.81;

fn ball() -> FnSystem<impl Fn(f64, &Vector2<f64>, &mut Vector2<f64>)> {
    FnSystem::new(|_t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>| {
        dy[0] = y[1];
        dy[1] = -G;
    })
}

#[test]
fn stepping_reproduces_solve_bit_for_bit() {
    let vdp = problems::van_der_pol();
    let exact = problems::exact();
    for method in Method::ALL {
        let stiff = !matches!(method, Method::Tsit5 | Method::Dop853);
        let opts = Options::default().rtol(1e-6).atol(1e-6).dense(false);
        // Kinks in the span exercise the restarts; the explicit methods run the non-stiff
        // problem.
        let opts = opts.t_stops(vec![0.5, 3.25]);
        let (sol, steps) = if stiff {
            let sol = solve(&vdp, 0.0, vdp.y0_vector(), 200.0, method, &opts, &mut []).unwrap();
            let mut it = Integrator::new(&vdp, 0.0, vdp.y0_vector(), 200.0, method, &opts).unwrap();
            let mut steps = vec![(it.t(), it.state().as_slice().to_vec())];
            while it.step().unwrap() != StepStatus::ReachedEnd {
                steps.push((it.t(), it.state().as_slice().to_vec()));
            }
            steps.push((it.t(), it.state().as_slice().to_vec()));
            assert_eq!(it.stats(), sol.stats, "{method}");
            let st: Vec<_> = sol
                .t
                .iter()
                .zip(&sol.y)
                .map(|(t, y)| (*t, y.as_slice().to_vec()))
                .collect();
            (st, steps)
        } else {
            let sol = solve(
                &exact,
                0.0,
                exact.y0_vector(),
                exact.t_end,
                method,
                &opts,
                &mut [],
            )
            .unwrap();
            let mut it =
                Integrator::new(&exact, 0.0, exact.y0_vector(), exact.t_end, method, &opts)
                    .unwrap();
            let mut steps = vec![(it.t(), it.state().as_slice().to_vec())];
            while it.step().unwrap() != StepStatus::ReachedEnd {
                steps.push((it.t(), it.state().as_slice().to_vec()));
            }
            steps.push((it.t(), it.state().as_slice().to_vec()));
            assert_eq!(it.stats(), sol.stats, "{method}");
            let st: Vec<_> = sol
                .t
                .iter()
                .zip(&sol.y)
                .map(|(t, y)| (*t, y.as_slice().to_vec()))
                .collect();
            (st, steps)
        };
        assert!(sol.len() > 20, "{method}: {} steps", sol.len());
        // Exact equality: the same floating-point operations in the same order.
        assert_eq!(sol, steps, "{method}");
    }
}

#[test]
fn advance_to_lands_exactly_and_matches_dense_output() {
    let vdp = problems::van_der_pol();
    let opts = Options::default().rtol(1e-8).atol(1e-8);
    let reference = solve(
        &vdp,
        0.0,
        vdp.y0_vector(),
        100.0,
        Method::Radau5,
        &opts,
        &mut [],
    )
    .unwrap();
    let mut it = Integrator::new(&vdp, 0.0, vdp.y0_vector(), 100.0, Method::Radau5, &opts).unwrap();
    for target in [0.1, 0.1, 1.0 / 3.0, 7.0, 50.123, 99.999_999, 100.0] {
        let status = it.advance_to(target).unwrap();
        assert_eq!(it.t(), target);
        if target == 100.0 {
            assert_eq!(status, StepStatus::ReachedEnd);
        }
        // A different step sequence: agreement to the tolerance, not to the bit. The solution
        // is O(1); the global error of these runs is a few hundred times the tolerance.
        let r = reference.sample(target).unwrap();
        assert!((it.state() - r).amax() < 1e-5, "t = {target}");
    }
    // Out of range: a typed error naming the argument.
    assert!(matches!(
        it.advance_to(101.0),
        Err(OdeError::InvalidInput { ref field, .. }) if field == "t"
    ));
    assert!(matches!(it.step(), Err(OdeError::InvalidInput { .. })));
    // Extending the end time goes on from there.
    it.set_tf(120.0).unwrap();
    assert_eq!(it.advance_to(120.0).unwrap(), StepStatus::ReachedEnd);
    assert!(it.set_tf(110.0).is_err());
}

#[test]
fn interpolate_covers_the_last_step_only() {
    let decay = FnSystem::new(|_t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>| dy[0] = -y[0]);
    let opts = Options::default().rtol(1e-10).atol(1e-12);
    let mut it =
        Integrator::new(&decay, 0.0, Vector1::new(1.0), 5.0, Method::Tsit5, &opts).unwrap();
    assert!(it.interpolate(0.0).is_err(), "no step yet");
    it.step().unwrap();
    it.step().unwrap();
    let (a, b) = (it.t_prev(), it.t());
    assert!(a > 0.0 && b > a);
    for k in 0..=10 {
        let t = a + (b - a) * k as f64 / 10.0;
        let y = it.interpolate(t).unwrap()[0];
        // Tsit5's dense output is of order 4: error well below 1e-8 at this tolerance.
        assert!((y - (-t).exp()).abs() < 1e-8, "t = {t}");
    }
    assert!(it.interpolate(a - 1e-9).is_err());
    assert!(it.interpolate(b + 1e-9).is_err());
    let off = Options::default().dense(false);
    let mut it = Integrator::new(&decay, 0.0, Vector1::new(1.0), 5.0, Method::Tsit5, &off).unwrap();
    it.step().unwrap();
    assert!(matches!(
        it.interpolate(it.t()),
        Err(OdeError::InvalidInput { ref field, .. }) if field == "options.dense"
    ));
}

#[test]
fn elastic_bounces_conserve_energy_and_keep_their_period() {
    // A ball dropped from 1 m, reflected elastically at the floor: every bounce returns it to
    // 1 m and the impacts come at (2k + 1)·√(2/g). The state after each action and the
    // impact times are compared with these closed forms. Free flight is a quadratic, which
    // every method integrates exactly: the error control would let a step span several
    // flights, so h_max keeps steps below a flight (0.9 s), as for any event the solution's
    // accuracy does not see.
    let ball = ball();
    let opts = Options::default().rtol(1e-10).atol(1e-12).h_max(0.2);
    let t_fall = (2.0 / G).sqrt();
    let t_end = 20.5 * t_fall;
    for method in [
        Method::Tsit5,
        Method::Dop853,
        Method::Rodas5P,
        Method::Radau5,
    ] {
        let floor = Event::new(|_t, y: &Vector2<f64>| y[0])
            .direction(Direction::Falling)
            .affect(|_t, y| y[1] = -y[1]);
        let mut it = Integrator::new(&ball, 0.0, Vector2::new(1.0, 0.0), t_end, method, &opts)
            .unwrap()
            .events([floor]);
        let mut impacts = Vec::new();
        loop {
            let status = it.step().unwrap();
            // Energy per unit mass g·h + v²/2 = g·1 m at every accepted point.
            let y = it.state();
            let e = G * y[0] + 0.5 * y[1] * y[1];
            assert!(
                (e - G).abs() < 1e-7,
                "{method}: energy {e} at t = {}",
                it.t()
            );
            if let StepStatus::Acted(0) = status {
                impacts.push(it.t());
                assert!(it.state()[1] > 0.0, "moving up after the action");
            }
            if status == StepStatus::ReachedEnd {
                break;
            }
        }
        assert_eq!(impacts.len(), 10, "{method}");
        for (k, t) in impacts.iter().enumerate() {
            let exact = (2 * k + 1) as f64 * t_fall;
            assert!(
                (t - exact).abs() < 1e-8,
                "{method}: impact {k} at {t} vs {exact}"
            );
        }
    }
}

#[test]
fn solve_records_acting_events_and_dense_output_across_the_jump() {
    // Restitution 0.5: each flight is half as long as the one before.
    let ball = ball();
    let opts = Options::default().rtol(1e-10).atol(1e-12);
    let mut ev = [Event::new(|_t, y: &Vector2<f64>| y[0])
        .direction(Direction::Falling)
        .affect(|_t, y| y[1] *= -0.5)];
    let t_fall = (2.0 / G).sqrt();
    let sol = solve(
        &ball,
        0.0,
        Vector2::new(1.0, 0.0),
        2.5 * t_fall,
        Method::Tsit5,
        &opts,
        &mut ev,
    )
    .unwrap();
    let times: Vec<f64> = sol.events.iter().map(|e| e.t).collect();
    // Impacts at t1, t1 + t1, t1 + t1 + t1/2.
    let expect = [t_fall, 2.0 * t_fall, 2.5 * t_fall];
    assert!(times.len() >= 2);
    for (t, e) in times.iter().zip(expect) {
        assert!((t - e).abs() < 1e-8, "{t} vs {e}");
    }
    // The recorded state at an impact is the one before the action; the saved steps hold
    // both.
    assert!(sol.events[0].y[1] < 0.0);
    let i = sol.t.iter().position(|&t| t == times[0]).unwrap();
    assert_eq!(sol.t[i + 1], times[0]);
    assert!((sol.y[i + 1][1] + 0.5 * sol.y[i][1]).abs() < 1e-12);
    // Dense output on either side of the first impact follows the flights.
    let before = sol.sample(0.5 * t_fall).unwrap();
    assert!((before[0] - (1.0 - 0.5 * G * 0.25 * t_fall * t_fall)).abs() < 1e-9);
    let v_up = 0.5 * G * t_fall;
    let s = 0.25 * t_fall;
    let after = sol.sample(t_fall + s).unwrap();
    assert!((after[0] - (v_up * s - 0.5 * G * s * s)).abs() < 1e-9);
}

#[test]
fn an_action_may_change_the_systems_parameters() {
    // A heater switched off when the temperature reaches 0.8: T' = P − T with P = 1 until then
    // (T = 1 − e^{−t}, reached at t* = ln 5), then P = 0 (T = 0.8 e^{−(t − t*)}).
    let power = Cell::new(1.0);
    let heater = FnSystem::new(|_t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>| {
        dy[0] = power.get() - y[0];
    });
    let off = Event::new(|_t, y: &Vector1<f64>| y[0] - 0.8)
        .direction(Direction::Rising)
        .affect(|_t, _y| power.set(0.0));
    let opts = Options::default().rtol(1e-10).atol(1e-12);
    let mut it = Integrator::new(&heater, 0.0, Vector1::new(0.0), 4.0, Method::Rodas5P, &opts)
        .unwrap()
        .events([off]);
    let status = it.advance_to(4.0).unwrap();
    assert_eq!(status, StepStatus::ReachedEnd);
    let t_star = 5f64.ln();
    let exact = 0.8 * (-(4.0 - t_star)).exp();
    assert!(
        (it.state()[0] - exact).abs() < 1e-8,
        "{} vs {exact}",
        it.state()[0]
    );
    assert_eq!(power.get(), 0.0);
}

/// `y' = u cos t` with the input `u` read through the memo of the time's values: a system
/// changed at a time it was already asked at must not be read from the memo.
struct Held {
    u: f64,
}

impl OdeSystem<U1> for Held {
    fn rhs(&self, t: f64, _y: &Vector1<f64>, dy: &mut Vector1<f64>) {
        dy[0] = self.u * t.cos();
    }
    fn rhs_memo(&self, t: f64, _y: &Vector1<f64>, dy: &mut Vector1<f64>, memo: &mut TimeMemo) {
        dy[0] = memo.get_or_insert_with(t, |t| [self.u * t.cos(), 0.0, 0.0, 0.0])[0];
    }
}

#[test]
fn a_changed_system_is_not_read_from_the_memo_of_its_old_inputs() {
    // Fixed steps of 0.25: the last stages of the step that ends at 1 fall on t = 1 exactly,
    // where the system is then changed and the method restarts.
    let opts = Options {
        h_init: Some(0.25),
        adaptive: false,
        ..Options::default()
    };
    for method in [
        Method::Rodas5P,
        Method::Tsit5,
        Method::Dop853,
        Method::Radau5,
    ] {
        let mut it =
            Integrator::new(Held { u: 1.0 }, 0.0, Vector1::new(0.0), 2.0, method, &opts).unwrap();
        it.advance_to(1.0).unwrap();
        let at_one = *it.state();
        it.system_mut().u = -3.0;
        it.advance_to(2.0).unwrap();
        // The same as a new integrator of the changed system started there.
        let mut fresh = Integrator::new(Held { u: -3.0 }, 1.0, at_one, 2.0, method, &opts).unwrap();
        fresh.advance_to(2.0).unwrap();
        assert_eq!(
            it.state()[0].to_bits(),
            fresh.state()[0].to_bits(),
            "{method:?}: {} against {}",
            it.state()[0],
            fresh.state()[0]
        );
    }
}

#[test]
fn reinit_after_a_jump_restarts_from_the_new_state() {
    let decay = FnSystem::new(|_t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>| dy[0] = -y[0]);
    let opts = Options::default().rtol(1e-10).atol(1e-12);
    for method in Method::ALL {
        let mut it = Integrator::new(&decay, 0.0, Vector1::new(1.0), 3.0, method, &opts).unwrap();
        it.advance_to(1.0).unwrap();
        assert!((it.state()[0] - (-1f64).exp()).abs() < 1e-9);
        // A jump of the state at t = 1: y = 5, then y = 5 e^{−(t − 1)}.
        it.reinit(1.0, Vector1::new(5.0)).unwrap();
        assert!(it.interpolate(1.0).is_err(), "no step since the reinit");
        it.advance_to(3.0).unwrap();
        let exact = 5.0 * (-2f64).exp();
        assert!((it.state()[0] - exact).abs() < 1e-8, "{method}");
        // Bad reinit input: typed errors naming the argument.
        assert!(matches!(
            it.reinit(f64::NAN, Vector1::new(1.0)),
            Err(OdeError::InvalidInput { ref field, .. }) if field == "t"
        ));
        assert!(it.reinit(0.0, Vector1::new(f64::INFINITY)).is_err());
    }
}

#[test]
fn tighter_tolerances_between_steps_take_effect() {
    let decay = FnSystem::new(|_t: f64, y: &Vector1<f64>, dy: &mut Vector1<f64>| dy[0] = -y[0]);
    let loose = Options::default().rtol(1e-4).atol(1e-6);
    let run = |tighten: bool| {
        let mut it =
            Integrator::new(&decay, 0.0, Vector1::new(1.0), 10.0, Method::Radau5, &loose).unwrap();
        it.advance_to(1.0).unwrap();
        let before = it.stats().accepted;
        if tighten {
            it.set_tolerances(1e-10, Tolerance::Scalar(1e-12)).unwrap();
        }
        it.advance_to(10.0).unwrap();
        (it.stats().accepted - before, it.state()[0])
    };
    let (n_loose, _) = run(false);
    let (n_tight, _) = run(true);
    assert!(n_tight > 3 * n_loose, "{n_tight} vs {n_loose} steps");
    let mut it =
        Integrator::new(&decay, 0.0, Vector1::new(1.0), 1.0, Method::Tsit5, &loose).unwrap();
    assert!(matches!(
        it.set_tolerances(-1.0, Tolerance::Scalar(1e-8)),
        Err(OdeError::InvalidInput { ref field, .. }) if field == "options.rtol"
    ));
}

#[test]
fn a_terminal_event_stops_a_step_and_stepping_goes_on() {
    let ball = ball();
    let opts = Options::default()
        .rtol(1e-10)
        .atol(1e-12)
        .save(SaveAt::Final);
    let hit = Event::new(|_t, y: &Vector2<f64>| y[0])
        .direction(Direction::Falling)
        .terminal(true);
    let mut it = Integrator::new(
        &ball,
        0.0,
        Vector2::new(1.0, 0.0),
        1.0,
        Method::Tsit5,
        &opts,
    )
    .unwrap()
    .events([hit]);
    let t_fall = (2.0 / G).sqrt();
    assert_eq!(it.advance_to(1.0).unwrap(), StepStatus::Terminated(0));
    assert!((it.t() - t_fall).abs() < 1e-10);
    assert_eq!(it.events_hit().len(), 1);
    // Going on through the floor (nothing acts): free fall continues.
    assert_eq!(it.advance_to(1.0).unwrap(), StepStatus::ReachedEnd);
    assert!((it.state()[0] - (1.0 - 0.5 * G)).abs() < 1e-9);
}
