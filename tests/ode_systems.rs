//! Systems without boilerplate: `FnSystem` with a Jacobian closure, autonomous systems and
//! `OdeProblem`, checked against the trait implementation of the same problem.

#[path = "../examples/common/problems.rs"]
mod problems;

use hdi_tribology::nalgebra::{Matrix2, Vector2};
use hdi_tribology::ode::{solve, FnSystem, Method, OdeProblem, Options, SaveAt};

const MU: f64 = 1000.0;

fn vdp_rhs(_t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
    dy[0] = y[1];
    dy[1] = MU * (1.0 - y[0] * y[0]) * y[1] - y[0];
}

fn vdp_jac(_t: f64, y: &Vector2<f64>, j: &mut Matrix2<f64>) {
    *j = Matrix2::new(
        0.0,
        1.0,
        -2.0 * MU * y[0] * y[1] - 1.0,
        MU * (1.0 - y[0] * y[0]),
    );
}

/// rtol = atol = 1e-6, the final state only, no interpolants.
fn final_only() -> Options {
    Options::default()
        .rtol(1e-6)
        .atol(1e-6)
        .save(SaveAt::Final)
        .dense(false)
}

#[test]
fn jacobian_closure_gives_the_trait_implementations_steps() {
    // The problem table's Van der Pol implements `OdeSystem::jacobian` by hand; the closure
    // form must give the same floating-point operations, hence the same result to the bit.
    // Both declare the system autonomous (the problem table does).
    let by_trait = problems::van_der_pol();
    let by_closure = FnSystem::new(vdp_rhs).with_jacobian(vdp_jac).autonomous();
    let opts = final_only();
    for m in [Method::Rodas5P, Method::Radau5, Method::Auto] {
        let a = solve(
            &by_trait,
            0.0,
            by_trait.y0_vector(),
            100.0,
            m,
            &opts,
            &mut [],
        )
        .unwrap();
        let b = solve(
            &by_closure,
            0.0,
            by_trait.y0_vector(),
            100.0,
            m,
            &opts,
            &mut [],
        )
        .unwrap();
        assert_eq!(a.y_final(), b.y_final(), "{m}");
        assert_eq!(a.stats, b.stats, "{m}");
        // Without the Jacobian, differences cost 2 right-hand sides per Jacobian.
        let fd = FnSystem::new(vdp_rhs).autonomous();
        let c = solve(&fd, 0.0, by_trait.y0_vector(), 100.0, m, &opts, &mut []).unwrap();
        assert!(c.stats.rhs_evals > b.stats.rhs_evals, "{m}");
    }
}

#[test]
fn autonomous_declaration_skips_the_time_difference_only() {
    let opts = final_only();
    let plain = FnSystem::new(vdp_rhs).with_jacobian(vdp_jac);
    let auto = FnSystem::new(vdp_rhs).with_jacobian(vdp_jac).autonomous();
    let y0 = Vector2::new(2.0, 0.0);
    let a = solve(&plain, 0.0, y0, 100.0, Method::Rodas5P, &opts, &mut []).unwrap();
    let b = solve(&auto, 0.0, y0, 100.0, Method::Rodas5P, &opts, &mut []).unwrap();
    // f does not depend on t: the difference quotient was exactly zero, so the steps are the
    // same; one right-hand side per Jacobian is saved.
    assert_eq!(a.y_final(), b.y_final());
    assert_eq!(a.stats.accepted, b.stats.accepted);
    assert_eq!(a.stats.rhs_evals - b.stats.rhs_evals, a.stats.jac_evals);
}

#[test]
fn a_problem_value_solves_and_steps_like_solve() {
    let p = OdeProblem::new(
        FnSystem::new(vdp_rhs).with_jacobian(vdp_jac).autonomous(),
        (0.0, 50.0),
        Vector2::new(2.0, 0.0),
    );
    let opts = Options::default().rtol(1e-7).atol(1e-7);
    let direct = solve(&p.system, 0.0, p.y0, 50.0, Method::Radau5, &opts, &mut []).unwrap();
    let held = p.solve(Method::Radau5, &opts).unwrap();
    assert_eq!(direct.y_final(), held.y_final());
    let mut it = p.integrator(Method::Radau5, &opts).unwrap();
    it.advance_to(50.0).unwrap();
    assert_eq!(it.state(), direct.y_final());
    // Bad span: the same typed error as solve.
    let bad = OdeProblem::new(FnSystem::new(vdp_rhs), (1.0, 0.0), Vector2::new(2.0, 0.0));
    assert!(bad.solve(Method::Tsit5, &opts).is_err());
}

/// A non-autonomous Van der Pol (a forcing `sin t` on the second equation) whose Jacobian and
/// `∂f/∂t` come either from the two methods or only from the combined one.
struct Forced {
    combined_only: bool,
}

impl hdi_tribology::ode::OdeSystem<hdi_tribology::nalgebra::U2> for Forced {
    fn rhs(&self, t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
        vdp_rhs(t, y, dy);
        dy[1] += t.sin();
    }
    fn jacobian(&self, t: f64, y: &Vector2<f64>, j: &mut Matrix2<f64>) -> bool {
        vdp_jac(t, y, j);
        !self.combined_only
    }
    fn time_derivative(&self, t: f64, _y: &Vector2<f64>, d: &mut Vector2<f64>) -> bool {
        *d = Vector2::new(0.0, t.cos());
        !self.combined_only
    }
    fn jacobian_and_time_derivative(
        &self,
        t: f64,
        y: &Vector2<f64>,
        j: &mut Matrix2<f64>,
        d: &mut Vector2<f64>,
    ) -> (bool, bool) {
        vdp_jac(t, y, j);
        *d = Vector2::new(0.0, t.cos());
        (true, true)
    }
}

#[test]
fn rodas5p_takes_both_derivatives_from_the_combined_method() {
    let opts = final_only();
    let y0 = Vector2::new(2.0, 0.0);
    let run = |combined_only| {
        solve(
            &Forced { combined_only },
            0.0,
            y0,
            100.0,
            Method::Rodas5P,
            &opts,
            &mut [],
        )
        .unwrap()
    };
    // The separate methods return `false` for the first system: had Rodas5P called them, it
    // would have differenced (more right-hand sides, other rounding).
    let (a, b) = (run(true), run(false));
    assert_eq!(a.y_final(), b.y_final());
    assert_eq!(a.stats, b.stats);
}
