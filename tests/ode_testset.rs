//! More problems of the Test Set for IVP Solvers (Mazzia, Magherini et al.) against its
//! reference values: OREGO (stiff, 3 states), E5 (stiff and badly scaled, 4 states) and
//! Pleiades (non-stiff, 28 states). Each bound is stated with the reason for its size.

#[path = "../examples/common/problems.rs"]
mod problems;

use hdi_tribology::ode::{solve, Method, OdeError, OdeSystem};
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
fn e5_every_method_is_right_or_reports_failure() {
    // y₂ and y₃ end near 8.9e-23 and equal 1/(MCt) only while y₂ − y₃ − y₄ = 0 holds far below
    // that: rounding of y₂ at its peak (1.5e-10) alone is 3e-26, i.e. 3e-4 of the end values,
    // so about three digits is what double precision allows whatever the tolerance. The bound
    // 1e-2 is 100 × rtol at the loosest tolerance run and 30× that rounding limit below it.
    // Radau5's Newton residual uses f only, and f keeps the invariant in floating point (see
    // the problem's definition): the invariant holds to 1e-24 and the end values to 1e-2.
    // Rodas5P's stage solves round at ~1e-20 (ε·|J|·|Δy|, times hγ in the conserved
    // direction) where the tolerance declares values from atol/rtol = 1e-20 on significant: it
    // must refuse (and did give 14–550 relative error before it did); Auto must then go on
    // with Radau5. The explicit methods must stop at the step cap (the problem is stiff).
    let p = problems::e5();
    for m in Method::ALL {
        for rtol in [1e-4, 1e-6, 1e-8, 1e-10] {
            let opts = p.options(rtol).max_steps(100_000);
            match solve(&p, 0.0, p.y0_vector(), p.t_end, m, &opts, &mut []) {
                Ok(sol) => {
                    let y = sol.y_final();
                    let e = p.error(y.as_slice());
                    println!("e5 {m} rtol {rtol:e}: error {e:.2e}, {:?}", sol.stats);
                    assert!(e < 1e-2, "{m} rtol {rtol}: error {e}");
                    assert!(
                        (y[1] - y[2] - y[3]).abs() < 1e-24,
                        "{m} rtol {rtol}: invariant {}",
                        y[1] - y[2] - y[3]
                    );
                    assert!(matches!(m, Method::Radau5 | Method::Auto), "{m} completed");
                }
                Err(e) => {
                    println!("e5 {m} rtol {rtol:e}: {e}");
                    match m {
                        Method::Rodas5P => {
                            assert!(matches!(e, OdeError::RoundingFloor { .. }), "{e}")
                        }
                        Method::Tsit5 | Method::Dop853 => {
                            assert!(matches!(e, OdeError::TooManySteps { .. }), "{e}")
                        }
                        _ => panic!("{m} rtol {rtol}: {e}"),
                    }
                }
            }
        }
    }
}

#[test]
fn rodas5p_floor_check_leaves_well_scaled_problems_alone() {
    // The check refuses only where rounding reaches atol/rtol: on Robertson (atol/rtol = 1e-17
    // for y₂, whose end value is 1e-13 of its start) and OREGO it must never fire, and the
    // results keep their accuracy (bounds as in ode_stiff.rs and above).
    let rob = problems::robertson();
    for rtol in [1e-4, 1e-8, 1e-11] {
        assert!(error(&rob, Method::Rodas5P, rtol) < 10.0 * rtol);
    }
    let orego = problems::orego();
    for rtol in [1e-4, 1e-10] {
        assert!(error(&orego, Method::Rodas5P, rtol) < 10.0 * rtol);
    }
}
