//! Quick start: the paper scene, its static touchdown and take-off, one simulated cycle.
//! Run with `cargo run --release --example quick_start`.
use hdi_tribology::analysis::{simulate_cycle, static_hysteresis, CycleOptions, StaticOptions};
use hdi_tribology::{analysis::HeaterProgramme::Fixed, model::SliderModel, scene::Scene};

fn main() -> hdi_tribology::Result<()> {
    let scene = Scene::paper(); // the built-in scene (PAPER_SCENE parameters)
    let model = SliderModel::from_scene(&scene)?;
    // Static: equilibria along the heater power, contact threshold F_th of the scene.
    let opts = StaticOptions::new(scene.detector.contact_threshold_n);
    let s = static_hysteresis(&model, &opts)?;
    let (td, to) = (s.touchdown.power * 1e3, s.takeoff.power * 1e3);
    println!(
        "static: touchdown {td:.2} mW, take-off {to:.2} mW, ΔP {:.2} mW",
        td - to
    );
    // Dynamic: one cycle under the scene's heater programme (ramp up, hold, ramp down), no AC.
    let programme = Fixed(SliderModel::programme_from_knots(&scene.heater.programme)?);
    let c = simulate_cycle(&model, &programme, &CycleOptions::from_scene(&scene)?)?;
    let mw = |p: Option<f64>| p.map_or("-".into(), |p| format!("{:.2} mW", p * 1e3));
    let (td, to, dp) = (
        mw(c.touchdown.map(|d| d.power)),
        mw(c.takeoff.map(|d| d.power)),
        mw(c.hysteresis),
    );
    println!("cycle:  touchdown {td}, take-off {to}, ΔP {dp}");
    println!(
        "mean flash-temperature rise {:.2} K",
        c.mean_temperature_rise
    );
    Ok(())
}
