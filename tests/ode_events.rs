//! Events located on the dense output: zero crossings of sin t, direction filters, a terminal
//! event (falling ball) and a bouncing ball restarted at each impact, for several methods.

use hdi_tribology::ode::{
    solve, solve_observed, Direction, Event, FnSystem, Method, Options, SaveAt,
};
use nalgebra::Vector2;
use std::f64::consts::PI;

/// y = (sin t, cos t).
fn oscillator() -> FnSystem<impl Fn(f64, &Vector2<f64>, &mut Vector2<f64>)> {
    FnSystem::new(|_t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>| {
        dy[0] = y[1];
        dy[1] = -y[0];
    })
}

const METHODS: [Method; 5] = Method::ALL;

#[test]
fn sine_zero_crossings_located_to_1e_10() {
    for m in METHODS {
        // Solution error ~1e-12 at these tolerances, so the root of the numerical solution is
        // within ~1e-11 of kπ; event_tol 1e-13 adds nothing.
        let opts = Options::default().rtol(1e-12).atol(1e-12).event_tol(1e-13);
        let mut events = [Event::new(|_t, y: &Vector2<f64>| y[0])];
        let sol = solve(
            &oscillator(),
            0.0,
            Vector2::new(0.0, 1.0),
            10.0,
            m,
            &opts,
            &mut events,
        )
        .unwrap();
        let times: Vec<f64> = sol.events.iter().map(|e| e.t).collect();
        assert_eq!(times.len(), 3, "{m}: {times:?}");
        for (k, (&te, hit)) in times.iter().zip(&sol.events).enumerate() {
            let exact = (k + 1) as f64 * PI;
            assert!(
                (te - exact).abs() < 1e-10,
                "{m}: event {k} at {te}, exact {exact}"
            );
            assert!(hit.y[0].abs() < 1e-10);
            // sin falls through zero at π, 3π and rises at 2π.
            assert_eq!(hit.rising, k % 2 == 1);
        }
        assert_eq!(sol.terminated_by_event, None);
        assert_eq!(sol.t_final(), 10.0);
    }
}

#[test]
fn direction_filter_keeps_only_rising_or_falling() {
    let opts = Options::default().rtol(1e-10).atol(1e-10);
    let mut events = [
        Event::new(|_t, y: &Vector2<f64>| y[0]).direction(Direction::Rising),
        Event::new(|_t, y: &Vector2<f64>| y[0]).direction(Direction::Falling),
    ];
    let sol = solve(
        &oscillator(),
        0.0,
        Vector2::new(0.0, 1.0),
        10.0,
        Method::Tsit5,
        &opts,
        &mut events,
    )
    .unwrap();
    let rising: Vec<f64> = sol
        .events
        .iter()
        .filter(|e| e.index == 0)
        .map(|e| e.t)
        .collect();
    let falling: Vec<f64> = sol
        .events
        .iter()
        .filter(|e| e.index == 1)
        .map(|e| e.t)
        .collect();
    assert_eq!(rising.len(), 1);
    assert_eq!(falling.len(), 2);
    assert!((rising[0] - 2.0 * PI).abs() < 1e-8);
    assert!((falling[0] - PI).abs() < 1e-8 && (falling[1] - 3.0 * PI).abs() < 1e-8);
    // Events come out in time order.
    assert!(sol.events.windows(2).all(|w| w[0].t <= w[1].t));
}

const G: f64 = 9.81;

fn ball() -> FnSystem<impl Fn(f64, &Vector2<f64>, &mut Vector2<f64>)> {
    FnSystem::new(|_t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>| {
        dy[0] = y[1];
        dy[1] = -G;
    })
}

#[test]
fn terminal_event_stops_at_impact() {
    for m in METHODS {
        let opts = Options::default().rtol(1e-10).atol(1e-12).event_tol(1e-13);
        let mut events = [Event::new(|_t, y: &Vector2<f64>| y[0])
            .direction(Direction::Falling)
            .terminal(true)];
        let sol = solve(
            &ball(),
            0.0,
            Vector2::new(10.0, 0.0),
            100.0,
            m,
            &opts,
            &mut events,
        )
        .unwrap();
        let t_hit = (2.0 * 10.0 / G).sqrt();
        assert_eq!(sol.terminated_by_event, Some(0));
        // The trajectory is a quadratic: every method of order ≥ 2 reproduces it to rounding,
        // so the event time is limited by event_tol only.
        assert!(
            (sol.t_final() - t_hit).abs() < 1e-12,
            "{m}: {}",
            sol.t_final()
        );
        assert!(sol.y_final()[0].abs() < 1e-11);
        assert_eq!(*sol.t.last().unwrap(), sol.t_final());
        assert!(sol.sample(sol.t_final() + 1e-3).is_none());
        assert!(sol.sample(0.5 * t_hit).is_some());
    }
}

#[test]
fn bouncing_ball_restarts_match_closed_form() {
    // Coefficient of restitution e: the k-th impact happens at
    // t_k = t_1 (1 + 2e + 2e² + … + 2e^(k−1)), with t_1 = √(2 h0 / g).
    let e = 0.8;
    let h0 = 1.0;
    let t1 = (2.0 * h0 / G).sqrt();
    let opts = Options::default()
        .rtol(1e-10)
        .atol(1e-12)
        .save(SaveAt::Final);
    let mut t = 0.0;
    let mut y = Vector2::new(h0, 0.0);
    let mut impacts = Vec::new();
    for _ in 0..5 {
        let mut events = [Event::new(|_t, y: &Vector2<f64>| y[0])
            .direction(Direction::Falling)
            .terminal(true)];
        let sol = solve(&ball(), t, y, 100.0, Method::Tsit5, &opts, &mut events).unwrap();
        assert_eq!(sol.terminated_by_event, Some(0));
        t = sol.t_final();
        impacts.push(t);
        y = Vector2::new(0.0, -e * sol.y_final()[1]);
    }
    let mut expected = t1;
    for (k, &ti) in impacts.iter().enumerate() {
        if k > 0 {
            expected += 2.0 * t1 * e.powi(k as i32);
        }
        assert!(
            (ti - expected).abs() < 1e-9,
            "impact {k}: {ti} vs {expected}"
        );
    }
}

#[test]
fn observer_sees_every_saved_step_bit_for_bit() {
    // A ball bouncing with restitution 0.8 (an acting event): the observer of a run that saves
    // nothing must see the same times and states, bit for bit, as a run that saves every step
    // (after an action, the state after it), for every method.
    for m in METHODS {
        let bounce = || {
            [Event::new(|_t, y: &Vector2<f64>| y[0])
                .direction(Direction::Falling)
                .affect(|_t, y| y[1] *= -0.8)]
        };
        let y0 = Vector2::new(1.0, 0.0);
        let opts = Options::default().rtol(1e-9).atol(1e-12);
        let saved = solve(&ball(), 0.0, y0, 2.0, m, &opts, &mut bounce()).unwrap();
        let mut seen = Vec::new();
        let streamed = solve_observed(
            &ball(),
            0.0,
            y0,
            2.0,
            m,
            &opts.clone().save(SaveAt::Final),
            &mut bounce(),
            |t, y| seen.push((t, *y)),
        )
        .unwrap();
        assert!(saved.events.len() >= 2, "{m}: the ball bounces");
        assert_eq!(seen.len(), streamed.stats.accepted + 1, "{m}");
        // Saved steps hold the state before each action too; the observer sees it after.
        let after_actions: Vec<(f64, Vector2<f64>)> = saved
            .t
            .iter()
            .zip(&saved.y)
            .enumerate()
            .filter(|&(i, (t, _))| saved.t.get(i + 1) != Some(t))
            .map(|(_, (t, y))| (*t, *y))
            .collect();
        assert_eq!(seen.len(), after_actions.len(), "{m}");
        for ((ta, ya), (tb, yb)) in seen.iter().zip(&after_actions) {
            assert_eq!(ta.to_bits(), tb.to_bits(), "{m}");
            assert_eq!(ya, yb, "{m} at t = {ta}");
        }
        assert_eq!(streamed.y_final(), saved.y_final(), "{m}");
    }
}
