//! Stiff validation problems against the reference solutions of the Test Set for IVP Solvers
//! (F. Mazzia, C. Magherini et al., Univ. Bari): Van der Pol (μ = 1000), Robertson to 1e11,
//! HIRES; plus tolerance proportionality.

#[path = "../examples/common/problems.rs"]
mod problems;

use hdi_tribology::ode::{solve, Method, Options, Solution, Tolerance};
use nalgebra::{U2, U3, U8};
use problems::Problem;

/// Solves `p` from 0 to its end time and panics with the method and tolerance on failure.
fn run<const N: usize>(
    p: &Problem<N>,
    method: Method,
    tol: f64,
    opts: &Options,
) -> Solution<nalgebra::Const<N>> {
    solve(p, 0.0, p.y0_vector(), p.t_end, method, opts, &mut [])
        .unwrap_or_else(|e| panic!("{} {method} at tol {tol}: {e}", p.name))
}

fn vdp(method: Method, tol: f64) -> Solution<U2> {
    let opts = Options::default().rtol(tol).atol(tol).dense(false);
    run(&problems::van_der_pol(), method, tol, &opts)
}

fn rober(method: Method, rtol: f64) -> Solution<U3> {
    // y2 is ~1e-13 at the end: absolute tolerances far below the component sizes.
    let opts = Options::default()
        .rtol(rtol)
        .atol_per_component(vec![1e-4 * rtol * 1e-8, 1e-4 * rtol * 1e-13, 1e-4 * rtol])
        .dense(false)
        .max_steps(200_000);
    run(&problems::robertson(), method, rtol, &opts)
}

fn hires(method: Method, tol: f64) -> Solution<U8> {
    let opts = Options {
        atol: Tolerance::Scalar(tol * 1e-3),
        ..Options::default().rtol(tol).dense(false)
    };
    run(&problems::hires(), method, tol, &opts)
}

const STIFF: [Method; 3] = [Method::Rodas5P, Method::Radau5, Method::Auto];

#[test]
fn van_der_pol_matches_test_set_reference() {
    for m in STIFF {
        let sol = vdp(m, 1e-8);
        let e = problems::van_der_pol().error(sol.y_final().as_slice());
        println!("vdp {m}: rel err {e:.2e}, {:?}", sol.stats);
        // A relaxation oscillation with sharp fronts: the global error at tol 1e-8 is a few
        // hundred times the tolerance (error growth through the fronts).
        assert!(e < 1e-5, "{m}: relative error {e}");
    }
}

#[test]
fn robertson_to_1e11_conserves_mass_and_matches_reference() {
    for m in STIFF {
        let sol = rober(m, 1e-8);
        let e = problems::robertson().error(sol.y_final().as_slice());
        println!("rober {m}: rel err {e:.2e}, {:?}", sol.stats);
        // Relative error per component (even y2 ~ 1e-13) within 1e-4.
        assert!(e < 1e-4, "{m}: relative error {e}");
        for y in &sol.y {
            // Linear invariant: every linear-implicit/RK step preserves it up to rounding
            // accumulated over the steps.
            assert!((y.sum() - 1.0).abs() < 1e-12, "{m}: mass {}", y.sum());
        }
    }
}

#[test]
fn hires_matches_test_set_reference() {
    for m in STIFF {
        let sol = hires(m, 1e-8);
        let e = problems::hires().error(sol.y_final().as_slice());
        println!("hires {m}: rel err {e:.2e}, {:?}", sol.stats);
        assert!(e < 1e-5, "{m}: relative error {e}");
    }
}

#[test]
fn error_shrinks_with_tolerance() {
    for m in STIFF {
        let errs: Vec<f64> = [1e-5, 1e-7, 1e-9]
            .iter()
            .map(|&tol| problems::hires().error(hires(m, tol).y_final().as_slice()))
            .collect();
        println!("hires {m}: errors {errs:?}");
        for w in errs.windows(2) {
            // Tolerance down by 100: error down by at least 20 (proportionality up to the
            // usual slack of an error-per-step controller).
            assert!(w[1] < w[0] / 20.0, "{m}: {errs:?}");
        }
    }
}

#[test]
fn auto_switches_where_stiffness_changes() {
    // Van der Pol (μ = 1000) alternates slow stiff phases and fast non-stiff jumps: Auto must
    // use both methods and switch both ways; the stiff phases take most of the time.
    let sol = vdp(Method::Auto, 1e-6);
    let s = sol.stats;
    println!("vdp auto: {s:?}");
    assert!(s.stiffness_switches >= 2, "{s:?}");
    assert!(s.stiff_steps > 0 && s.stiff_steps < s.accepted, "{s:?}");
    // Robertson is stiff almost from the start: one switch, and most steps are stiff.
    let s = rober(Method::Auto, 1e-6).stats;
    println!("rober auto: {s:?}");
    assert!(
        s.stiffness_switches >= 1 && 2 * s.stiff_steps > s.accepted,
        "{s:?}"
    );
    // The explicit method alone exhausts the default budget of 100 000 steps early on, where
    // Auto needed a few hundred.
    let opts = Options::default().rtol(1e-6).atol(1e-6).dense(false);
    let p = problems::van_der_pol();
    let r = solve(
        &p,
        0.0,
        p.y0_vector(),
        p.t_end,
        Method::Tsit5,
        &opts,
        &mut [],
    );
    assert!(matches!(r, Err(hdi_tribology::ode::OdeError::TooManySteps { t, .. }) if t < 1000.0));
}
