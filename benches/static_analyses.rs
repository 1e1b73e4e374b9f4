//! The static analyses (touchdown, take-off, pull-in voltage) per call, on the paper scene with
//! the `rigid`, `bulge` and `pitch` structures and on `scenes/paper_bulge.toml`. Prints a table.
//!
//! `cargo bench --bench static_analyses`. Each call runs repeatedly for at least 1 s; the table
//! gives the mean CPU time of the thread per call (Linux `schedstat`, not inflated by other
//! processes waiting for the cores) and the fastest wall-clock call, with the results, so that a
//! faster path can be checked to give the same numbers.

#[path = "../examples/common/timing.rs"]
mod timing;

use hdi_tribology::analysis::pull_in::pull_in_voltage;
use hdi_tribology::analysis::touchdown::{takeoff_power, touchdown_power, StaticOptions};
use hdi_tribology::model::SliderModel;
use hdi_tribology::scene::{Scene, StructureSpec};
use std::time::Duration;

fn scenes() -> Vec<(&'static str, Scene)> {
    let paper = Scene::paper();
    let mut bulge = paper.clone();
    bulge.structure = StructureSpec::Bulge {
        mass_kg: 5e-13,
        stiffness_n_per_m: 4e5,
        damping_ratio: 0.05,
    };
    // Pitch: a 1 mg slider, 1 mm long, pivot at its middle (L = 0.5 mm), pitch stiffness of the
    // bearing's heave stiffness over the pads (k L²/3) and a small heave–pitch coupling.
    let (k_ab, l) = (3e5, 0.5e-3);
    let mut pitch = paper.clone();
    pitch.structure = StructureSpec::Pitch {
        inertia_kg_m2: paper.slider.mass_kg * l * l / 3.0,
        stiffness_n_m_per_rad: k_ab * l * l / 3.0,
        coupling_stiffness_n_per_rad: 10.0,
        damping_n_m_s_per_rad: 1e-9,
        coupling_damping_n_s_per_rad: 0.0,
        trailing_edge_m: l,
    };
    let mut out = vec![("rigid", paper), ("bulge", bulge), ("pitch", pitch)];
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/paper_bulge.toml");
    match Scene::from_path(file) {
        Ok(s) => out.push(("paper_bulge.toml", s)),
        Err(e) => eprintln!("{file}: {e}"),
    }
    out
}

fn main() {
    let budget = Duration::from_secs(1);
    println!("| scene | analysis | result | CPU ms/call | fastest wall ms |");
    println!("|---|---|---|---|---|");
    for (name, scene) in scenes() {
        let model = match SliderModel::from_scene(&scene) {
            Ok(m) => m,
            Err(e) => {
                eprintln!("{name}: {e}");
                continue;
            }
        };
        let opts = StaticOptions::new(scene.detector.contact_threshold_n);
        let row = |what: &str, result: String, t: timing::Timing| {
            println!(
                "| {name} | {what} | {result} | {:.3} | {:.3} |",
                t.cpu * 1e3,
                t.wall * 1e3
            );
        };
        let (td, t) = timing::measure(3, 10_000, budget, || touchdown_power(&model, &opts));
        let td = match td {
            Ok(td) => td,
            Err(e) => {
                row("touchdown", e.to_string(), t);
                continue;
            }
        };
        row("touchdown", format!("{:.10} mW", td.power_mw()), t);
        let start = td.power + opts.takeoff_start_excess;
        let (to, t) = timing::measure(3, 10_000, budget, || takeoff_power(&model, start, &opts));
        let text = to.map_or_else(|e| e.to_string(), |to| format!("{:.10} mW", to.power_mw()));
        row("take-off", text, t);
        let (pi, t) = timing::measure(3, 10_000, budget, || pull_in_voltage(&model, 0.0, &opts));
        let text = pi.map_or_else(|e| e.to_string(), |p| format!("{:.10} V", p.voltage));
        row("pull-in at 0 mW", text, t);
    }
}
