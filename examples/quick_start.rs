//! Quick start: the paper scene, its static touchdown and take-off, one simulated cycle.
//! Run with `cargo run --release --example quick_start`.
use hdi_tribology::analysis::{simulate_cycle, static_hysteresis, Protocol};
use hdi_tribology::{model::SliderModel, scene::Scene};

fn main() -> hdi_tribology::Result<()> {
    let scene = Scene::paper(); // the built-in scene of the paper
    let model = SliderModel::from_scene(&scene)?;
    let mw = |p: f64| format!("{:.2} mW", p * 1e3);
    // Static: equilibria along the heater power, contact threshold F_th of the scene.
    let protocol = Protocol::from_scene(&scene)?;
    let s = static_hysteresis(&model, &protocol.statics)?;
    let (td, to, dp) = (mw(s.touchdown.power), mw(s.takeoff.power), mw(s.hysteresis));
    println!("static: touchdown {td}, take-off {to}, ΔP {dp}");
    // Dynamic: one cycle under the scene's heater programme (ramp up, hold, ramp down), no AC.
    let c = simulate_cycle(&model, &protocol.fixed, &protocol.cycle)?;
    let opt = |p: Option<f64>| p.map_or("-".into(), mw);
    let (td, to) = (c.touchdown.map(|d| d.power), c.takeoff.map(|d| d.power));
    let (td, to, dp) = (opt(td), opt(to), opt(c.hysteresis));
    println!("cycle:  touchdown {td}, take-off {to}, ΔP {dp}");
    let dt = c.mean_temperature_rise;
    println!("mean flash-temperature rise {dt:.2} K");
    Ok(())
}

#[cfg(test)]
mod tests {
    /// `cargo test` runs the example, so CI runs every example.
    #[test]
    fn example_runs() {
        super::main().expect("the example runs to completion");
    }
}
