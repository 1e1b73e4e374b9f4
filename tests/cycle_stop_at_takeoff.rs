//! `CycleOptions::stop_at_takeoff`: a run that ends at the take-off gives the whole run's
//! touchdown and take-off to the bit, on fewer steps.

use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, HeaterProgramme};
use hdi_tribology::model::{SliderModel, Structure};
use hdi_tribology::scene::Scene;

#[path = "common/scenes.rs"]
mod scenes;

/// Runs `model` under `programme` whole and stopped at the take-off, and compares them.
fn compare(model: &SliderModel, programme: &HeaterProgramme, scene: &Scene, what: &str) {
    let mut opts = CycleOptions::from_scene(scene).unwrap();
    let whole = simulate_cycle(model, programme, &opts).unwrap();
    opts.stop_at_takeoff = true;
    let short = simulate_cycle(model, programme, &opts).unwrap();
    assert_eq!(short.touchdown, whole.touchdown, "{what}");
    assert_eq!(short.takeoff, whole.takeoff, "{what}");
    let to = whole
        .takeoff
        .unwrap_or_else(|| panic!("{what}: no take-off"));
    let end = short.programme.start_time() + short.duration;
    assert!(
        end >= to.time && end < whole.programme.end_time(),
        "{what}: ended at {end} s"
    );
    assert!(
        short.stats.accepted < whole.stats.accepted,
        "{what}: {} against {} steps",
        short.stats.accepted,
        whole.stats.accepted
    );
    // The steps up to the take-off are the same steps.
    assert!(
        short.stats.accepted + 1 >= whole.stats.accepted / 2,
        "{what}"
    );
}

#[test]
fn a_run_stopped_at_the_takeoff_finds_the_whole_runs_powers() {
    let paper = Scene::paper();
    let model = SliderModel::from_scene(&paper).unwrap();
    let fixed = HeaterProgramme::fixed_from_scene(&paper).unwrap();
    for v in [0.0, 0.6] {
        compare(
            &model.clone().with_ac_amplitude(v),
            &fixed,
            &paper,
            &format!("paper, {v} V"),
        );
    }
    // The triggered programme: touchdown on the way up, the take-off watched on the way down.
    let triggered = HeaterProgramme::Triggered {
        start_power: 0.06,
        ramp_rate: 5.0,
        overshoot: 0.001,
    };
    compare(&model, &triggered, &paper, "paper, triggered");
    // The few-peak scene of the maps, rigid with a 10 ns interface lag at 0.27 V, and its
    // bulge at 0.55 V.
    let bulge = scenes::paper_bulge();
    let base = SliderModel::from_scene(&bulge).unwrap();
    let few = HeaterProgramme::fixed_from_scene(&bulge).unwrap();
    let rigid = base
        .clone()
        .with_interface_lag(1e-8)
        .with_structure(Structure::rigid(bulge.slider.mass_kg).unwrap())
        .with_ac_amplitude(0.27);
    compare(&rigid, &few, &bulge, "few peaks, rigid, 10 ns lag, 0.27 V");
    compare(
        &base.with_ac_amplitude(0.55),
        &few,
        &bulge,
        "few peaks, bulge, 0.55 V",
    );
}

#[test]
fn a_run_without_takeoff_runs_to_the_end() {
    let paper = Scene::paper();
    let model = SliderModel::from_scene(&paper).unwrap();
    // 60 → 65 mW and back: the head never touches.
    let programme = HeaterProgramme::Fixed(
        SliderModel::programme_from_knots(&[[0.0, 0.06], [1e-3, 0.065], [2e-3, 0.06]]).unwrap(),
    );
    let mut opts = CycleOptions::from_scene(&paper).unwrap();
    let whole = simulate_cycle(&model, &programme, &opts).unwrap();
    opts.stop_at_takeoff = true;
    let short = simulate_cycle(&model, &programme, &opts).unwrap();
    assert!(whole.touchdown.is_none() && short.touchdown.is_none());
    assert_eq!(short.stats, whole.stats);
    assert_eq!(short.duration, whole.duration);
    assert_eq!(short.mean_temperature_rise, whole.mean_temperature_rise);
}
