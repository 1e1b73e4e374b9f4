#[path = "common/problems.rs"]
#[allow(dead_code)]
mod problems;
use hdi_tribology::ode::{solve, Method};
fn main() {
    let p = problems::hires();
    let m = match std::env::args().nth(1).as_deref() { Some("auto") => Method::Auto, Some("rodas5p") => Method::Rodas5P, _ => Method::Radau5 };
    let rtol: f64 = std::env::args().nth(2).map_or(5.6e-8, |s| s.parse().unwrap());
    let opts = p.options(rtol);
    for _ in 0..50 { let _ = solve(&p, 0.0, p.y0_vector(), p.t_end, m, &opts, &mut []).unwrap(); }
}
