//! The numbers the docs quote that take well under a second to compute: the paper scene's
//! static analyses and its linearised dynamics. `tests/docs_numbers.rs` computes them and checks
//! the docs; `examples/docs_numbers.rs` writes them.

use crate::doc_numbers::Quoted;
use hdi_tribology::analysis::{
    clearance_change, linear_response, pull_in_voltage, static_hysteresis, StaticOptions,
};
use hdi_tribology::model::{SliderModel, Voltage};
use hdi_tribology::scene::Scene;

/// Keys of these numbers start with this.
pub const PREFIX: &str = "static.";

/// The paper scene's static loop, pull-in voltage and clearance change (as `hdi static` and
/// the paper example print them), and its air-bearing mode with and without the interface
/// (docs/analyses.md, README.md, docs/python.md).
pub fn numbers() -> Result<Vec<Quoted>, Box<dyn std::error::Error>> {
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene)?;
    let opts = StaticOptions::from_scene(&scene);
    let stat = static_hysteresis(&model, &opts)?;
    let pull_in = pull_in_voltage(&model, 0.0, &opts)?;
    let volts = [0.5, 1.0];
    let dfh = clearance_change(&model, &volts, &opts)?;
    let (mw, nm) = (1e3, 1e9);
    let mut q = vec![
        Quoted::new("static.paper.td_mw", stat.touchdown.power * mw),
        Quoted::new("static.paper.td_d_nm", stat.touchdown.at.d * nm),
        Quoted::new("static.paper.to_mw", stat.takeoff.power * mw),
        Quoted::new("static.paper.to_d_nm", stat.takeoff.at.d * nm),
        Quoted::new("static.paper.dp_mw", stat.hysteresis * mw),
        Quoted::new("static.paper.pull_in_v", pull_in.voltage),
        Quoted::new("static.paper.dfh_0_5v_nm", dfh[0].clearance_change * nm),
        Quoted::new("static.paper.dfh_1_0v_nm", dfh[1].clearance_change * nm),
    ];
    // The air-bearing mode at the triggered programme's start power and 0.6 V AC, with the
    // interface's stiffness, and the bare bearing's sqrt(k/m)/2π.
    let at = model.with_voltage(Voltage {
        ac_amplitude: 0.6,
        ..model.voltage()
    });
    let lr = linear_response(&at, scene.heater.triggered.start_power_w)?;
    if let Some(mode) = lr.modes.iter().find(|m| m.im > 0.0) {
        q.push(Quoted::new("static.paper.mode_khz", mode.frequency * 1e-3));
    }
    if let hdi_tribology::force::AirBearingModel::Linear {
        stiffness_n_per_m: k,
        ..
    } = scene.air_bearing
    {
        let bare = (k / scene.slider.mass_kg).sqrt() / (2.0 * std::f64::consts::PI);
        q.push(Quoted::new("static.paper.bearing_khz", bare * 1e-3));
    }
    Ok(q)
}
