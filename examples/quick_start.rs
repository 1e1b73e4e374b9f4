//! Quick start: the paper scene, its static touchdown and take-off, and one simulated cycle.
//! Run with `cargo run --release --example quick_start`.

use hdi_tribology::analysis::{
    simulate_cycle, static_hysteresis, CycleOptions, HeaterProgramme, StaticOptions,
};
use hdi_tribology::{model::SliderModel, scene::Scene};

fn main() -> hdi_tribology::Result<()> {
    // The built-in scene of the paper (PAPER_SCENE parameters), and the slider model built from it.
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene)?;

    // Static analysis: equilibria along the heater power, detector threshold F_th of the scene.
    let stat = static_hysteresis(
        &model,
        &StaticOptions::new(scene.detector.contact_threshold_n),
    )?;
    println!(
        "static: touchdown {:.2} mW ({:?}), take-off {:.2} mW ({:?}), hysteresis {:.2} mW",
        stat.touchdown.power * 1e3,
        stat.touchdown.cause,
        stat.takeoff.power * 1e3,
        stat.takeoff.cause,
        stat.hysteresis * 1e3
    );

    // One dynamic cycle under the scene's fixed heater programme (ramp up, hold, ramp down), no AC.
    let programme =
        HeaterProgramme::Fixed(SliderModel::programme_from_knots(&scene.heater.programme)?);
    let cycle = simulate_cycle(&model, &programme, &CycleOptions::from_scene(&scene)?)?;
    let mw =
        |p: Option<f64>| p.map_or("not detected".to_string(), |p| format!("{:.2} mW", p * 1e3));
    println!(
        "cycle:  touchdown {}, take-off {}, hysteresis {}",
        mw(cycle.touchdown.map(|d| d.power)),
        mw(cycle.takeoff.map(|d| d.power)),
        mw(cycle.hysteresis)
    );
    println!(
        "        mean flash-temperature rise {:.3} K over {:.1} ms ({} steps, {:.2} s)",
        cycle.mean_temperature_rise,
        cycle.duration * 1e3,
        cycle.stats.accepted,
        cycle.wall_seconds
    );
    Ok(())
}
