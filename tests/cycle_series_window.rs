//! `CycleOptions::series_window`: the series over a window holds exactly the whole series's
//! steps within it, every field to the bit, and the run itself (its detections and steps) does
//! not change.

use hdi_tribology::analysis::cycle::{
    simulate_cycle, CycleOptions, CycleResult, HeaterProgramme, TimeSeries,
};
use hdi_tribology::model::SliderModel;
use hdi_tribology::scene::Scene;

#[path = "common/scenes.rs"]
mod scenes;

/// Every field of `s` at the indices `keep`, as bits (NaN indicators compare by their bits).
fn fields(s: &TimeSeries, keep: &[usize]) -> Vec<Vec<u64>> {
    let mut all = vec![
        &s.t,
        &s.power,
        &s.d,
        &s.air_bearing,
        &s.intermolecular,
        &s.electrostatic,
        &s.contact,
        &s.total,
        &s.temperature_rise,
        &s.indicator,
    ];
    all.extend(s.term_states.iter());
    all.iter()
        .map(|v| keep.iter().map(|&i| v[i].to_bits()).collect())
        .collect()
}

/// Runs `model` with the whole series and with the series over `window`, and compares them.
fn compare(model: &SliderModel, scene: &Scene, stop_at_takeoff: bool, window: (f64, f64)) {
    let programme = HeaterProgramme::fixed_from_scene(scene).unwrap();
    let mut opts = CycleOptions::from_scene(scene).unwrap();
    opts.keep_series = true;
    opts.stop_at_takeoff = stop_at_takeoff;
    let run = |o: &CycleOptions| -> CycleResult { simulate_cycle(model, &programme, o).unwrap() };
    let whole = run(&opts);
    opts.series_window = Some(window);
    let part = run(&opts);
    assert_eq!(part.touchdown, whole.touchdown);
    assert_eq!(part.takeoff, whole.takeoff);
    assert_eq!(part.stats, whole.stats);
    let (ws, ps) = (whole.series.unwrap(), part.series.unwrap());
    let inside: Vec<usize> = (0..ws.t.len())
        .filter(|&i| ws.t[i] >= window.0 && ws.t[i] <= window.1)
        .collect();
    assert!(
        inside.len() > 10 && inside.len() < ws.t.len(),
        "{} of {} steps in the window",
        inside.len(),
        ws.t.len()
    );
    let every: Vec<usize> = (0..ps.t.len()).collect();
    assert_eq!(fields(&ps, &every), fields(&ws, &inside));
    assert_eq!(ps.term_states.len(), ws.term_states.len());
}

#[test]
fn the_windowed_series_is_the_whole_series_within_the_window() {
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene)
        .unwrap()
        .with_ac_amplitude(0.6);
    compare(&model, &scene, false, (4.0e-3, 6.0e-3));
    // The window's ends on step times: both included.
    let mut opts = CycleOptions::from_scene(&scene).unwrap();
    opts.keep_series = true;
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    let t = simulate_cycle(&model, &programme, &opts)
        .unwrap()
        .series
        .unwrap()
        .t;
    let (a, b) = (t[100], t[400]);
    opts.series_window = Some((a, b));
    let part = simulate_cycle(&model, &programme, &opts)
        .unwrap()
        .series
        .unwrap();
    assert_eq!(part.t, t[100..=400]);
}

/// The mechanism maps' case: the few-peak bulge with an interface lag (a lag state in the
/// series' run), ended at the take-off, the window over the hold.
#[test]
fn the_maps_window_over_the_hold_holds_for_a_lagged_few_peak_cycle() {
    let scene = scenes::paper_bulge();
    let model = SliderModel::from_scene(&scene)
        .unwrap()
        .with_interface_lag(1e-8)
        .with_ac_amplitude(0.55);
    compare(&model, &scene, true, (4.8e-3, 5.2e-3));
}
