//! Switching functions of a system (`OdeSystem::switches`): the integrator ends a step on each
//! root, the system changes branch there, and no step crosses the kink. Checked against the
//! closed form of a law with a kink, for every method.

use hdi_tribology::ode::{solve, Integrator, Method, OdeSystem, Options, Stats, StepStatus};
use nalgebra::{Vector2, U2};

/// `y' = 1` while `y ≤ 1`, `y' = y/2` above: from `y(0) = 0`, `y = t` up to `t = 1` and
/// `e^{(t−1)/2}` after. `y[1]` holds the branch (+1 below, −1 above) when `held`; otherwise
/// the law picks it by the sign of `1 − y` at every evaluation (the kink left to the step
/// control).
struct Kink {
    held: bool,
}

impl Kink {
    fn below(&self, y: &Vector2<f64>) -> bool {
        if self.held {
            y[1] > 0.0
        } else {
            y[0] <= 1.0
        }
    }
}

impl OdeSystem<U2> for Kink {
    fn rhs(&self, _t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
        dy[0] = if self.below(y) { 1.0 } else { 0.5 * y[0] };
        dy[1] = 0.0;
    }
    fn switches(&self) -> usize {
        self.held as usize
    }
    fn switching(&self, _i: usize, _t: f64, y: &Vector2<f64>) -> f64 {
        y[1] * (1.0 - y[0])
    }
    fn switch(&self, _i: usize, _t: f64, y: &mut Vector2<f64>) {
        y[1] = -y[1];
    }
}

fn exact(t: f64) -> f64 {
    if t <= 1.0 {
        t
    } else {
        (0.5 * (t - 1.0)).exp()
    }
}

fn run(held: bool, method: Method, y0: f64, flag: f64) -> (f64, Stats) {
    let opts = Options::default().rtol(1e-10).atol(1e-12);
    let sol = solve(
        &Kink { held },
        0.0,
        Vector2::new(y0, flag),
        3.0,
        method,
        &opts,
        &mut [],
    )
    .unwrap();
    (*sol.y.last().unwrap().iter().next().unwrap(), sol.stats)
}

#[test]
fn a_held_branch_meets_the_closed_form_with_no_step_across_the_kink() {
    for method in Method::ALL {
        let (y, held) = run(true, method, 0.0, 1.0);
        let (y_free, free) = run(false, method, 0.0, 1.0);
        let e = exact(3.0);
        println!(
            "{method:?}: held {:.1e} ({} rejected), by sign {:.1e} ({} rejected)",
            (y - e).abs() / e,
            held.rejected,
            (y_free - e).abs() / e,
            free.rejected
        );
        assert!((y - e).abs() <= 1e-8 * e, "{method:?}: {y} against {e}");
        assert_eq!(held.branch_switches, 1, "{method:?}: {held:?}");
        assert_eq!(free.branch_switches, 0);
        // The kink costs the law picked by sign rejected steps; the held branch none.
        assert!(
            held.rejected < free.rejected,
            "{method:?}: {held:?} against {free:?}"
        );
    }
}

#[test]
fn a_step_ends_on_the_switch() {
    let opts = Options::default().rtol(1e-8).atol(1e-10);
    let mut it = Integrator::new(
        Kink { held: true },
        0.0,
        Vector2::new(0.0, 1.0),
        3.0,
        Method::Tsit5,
        &opts,
    )
    .unwrap();
    let mut ends = vec![];
    while it.step().unwrap() != StepStatus::ReachedEnd {
        ends.push((it.t(), it.state()[1]));
    }
    // The flag turns at the first step end at or past t = 1, and that end is the root.
    let at = ends.iter().position(|&(_, flag)| flag < 0.0).unwrap();
    assert!((ends[at].0 - 1.0).abs() < 1e-9, "{:?}", ends[at]);
    assert!(ends[..at].iter().all(|&(t, _)| t < 1.0));
}

#[test]
fn a_start_on_the_wrong_branch_is_switched_before_the_first_step() {
    // From y = 2 > 1 with the flag of the branch below: switched at once, then y = 2 e^{t/2}.
    for method in [Method::Tsit5, Method::Rodas5P] {
        let (y, stats) = run(true, method, 2.0, 1.0);
        let e = 2.0 * 1.5f64.exp();
        assert!((y - e).abs() <= 1e-8 * e, "{method:?}: {y} against {e}");
        assert_eq!(stats.branch_switches, 1);
    }
}
