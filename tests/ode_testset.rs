//! More problems of the Test Set for IVP Solvers (Mazzia, Magherini et al.) against its
//! reference values: OREGO (stiff, 3 states), E5 (stiff and badly scaled, 4 states) and
//! Pleiades (non-stiff, 28 states). Each bound is stated with the reason for its size.

#[path = "../examples/common/problems.rs"]
mod problems;

use hdi_tribology::ode::{solve, Method, OdeSystem};
use nalgebra::Const;
use problems::Problem;

fn error<const N: usize>(p: &Problem<N>, m: Method, rtol: f64) -> f64
where
    Problem<N>: OdeSystem<Const<N>>,
{
    let opts = p.options(rtol).max_steps(200_000);
    let sol = solve(p, 0.0, p.y0_vector(), p.t_end, m, &opts, &mut [])
        .unwrap_or_else(|e| panic!("{} {m} at rtol {rtol}: {e}", p.name));
    let e = p.error(sol.y_final().as_slice());
    println!(
        "{} {m} rtol {rtol:e}: error {e:.2e}, {:?}",
        p.name, sol.stats
    );
    e
}

#[test]
fn orego_meets_its_tolerance() {
    // A relaxation oscillation; with per-step error control the global error at t = 360 is
    // measured at 0.005–0.2 × rtol for these methods: a bound of rtol itself catches any loss
    // of proportionality (an order of magnitude) without depending on rounding.
    let p = problems::orego();
    for m in [Method::Rodas5P, Method::Radau5, Method::Auto] {
        for rtol in [1e-6, 1e-9] {
            let e = error(&p, m, rtol);
            assert!(e < rtol, "{m} at {rtol}: {e}");
        }
    }
}

#[test]
fn pleiades_converges_with_the_tolerance() {
    // Close encounters amplify local errors: the global error at t = 3 is up to ~1e3 × rtol
    // at rtol 1e-6 (the Test Set reports the same loss for DOPRI5). The checks: at rtol 1e-9
    // four correct digits at least, and a thousandfold tighter tolerance gains at least two
    // digits (error proportional to the tolerance, not stuck).
    let p = problems::pleiades();
    for m in Method::ALL {
        let loose = error(&p, m, 1e-6);
        let tight = error(&p, m, 1e-9);
        assert!(tight < 1e-4, "{m}: {tight}");
        assert!(tight < 1e-2 * loose, "{m}: {loose} -> {tight}");
    }
}

#[test]
fn e5_with_radau5_and_tight_auto_keeps_the_invariant_and_three_digits() {
    // y₂ and y₃ end near 8.9e-22 and equal 1/(MCt) only while y₂ − y₃ − y₄ = 0 holds far below
    // that: rounding of y₂ at its peak (1.5e-10) alone is 3e-26, i.e. 3e-4 of the end values,
    // so about three digits is what double precision allows whatever the tolerance. Radau5's
    // Newton residual uses f only, and f keeps the invariant in floating point (see the
    // problem's definition): the invariant holds to 1e-24 and the end values to 1e-2.
    // Auto takes Radau5 as its stiff method below rtol 1e-6 and passes there too.
    let p = problems::e5();
    let opts = |rtol: f64| p.options(rtol).max_steps(200_000);
    let runs = [
        (Method::Radau5, 1e-4),
        (Method::Radau5, 1e-6),
        (Method::Radau5, 1e-8),
        (Method::Auto, 1e-7),
        (Method::Auto, 1e-9),
    ];
    for (m, rtol) in runs {
        let sol = solve(&p, 0.0, p.y0_vector(), p.t_end, m, &opts(rtol), &mut []).unwrap();
        let y = sol.y_final();
        let e = p.error(y.as_slice());
        assert!(e < 1e-2, "{m} rtol {rtol}: error {e}");
        assert!(
            (y[1] - y[2] - y[3]).abs() < 1e-24,
            "{m} rtol {rtol}: invariant"
        );
    }
}
