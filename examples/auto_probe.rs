#[path = "common/problems.rs"]
mod problems;
#[path = "common/timing.rs"]
mod timing;
use hdi_tribology::ode::{solve, Method};
use std::time::Duration;
fn go<const N: usize>(p: &problems::Problem<N>) {
    for rtol in [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10] {
        let mut line = format!("{:<10} {rtol:.0e}", p.name);
        for m in [Method::Rodas5P, Method::Radau5, Method::Auto] {
            let o = p.options(rtol).max_steps(2_000_000);
            let (r, t) = timing::measure(3, 10000, Duration::from_millis(60), || {
                solve(p, 0.0, p.y0_vector(), p.t_end, m, &o, &mut [])
            });
            match r {
                Ok(s) => {
                    line += &format!(
                        " | {m} err {:.1e} cpu {:.3} ms",
                        p.error(s.y_final().as_slice()),
                        t.cpu * 1e3
                    )
                }
                Err(_) => line += " | fail",
            }
        }
        println!("{line}");
    }
}
fn main() {
    go(&problems::van_der_pol());
    go(&problems::robertson());
    go(&problems::hires());
    go(&problems::orego());
    go(&problems::e5());
}
