//! The static analyses (touchdown, take-off, pull-in voltage) per call, on the paper scene with
//! the `rigid`, `bulge` and `pitch` structures and on `scenes/paper_bulge.toml`. Prints a table.
//!
//! `cargo bench --bench static_analyses`. Each call runs repeatedly for at least 1 s; the table
//! gives the mean CPU time of the thread per call (Linux `schedstat`, not inflated by other
//! processes waiting for the cores) and the fastest wall-clock call, with the results, so that a
//! faster path can be checked to give the same numbers.

#[path = "../tests/common/scenes.rs"]
mod scenes;
#[path = "../examples/common/timing.rs"]
mod timing;

use hdi_tribology::analysis::pull_in::pull_in_voltage;
use hdi_tribology::analysis::touchdown::{takeoff_power, touchdown_power, StaticOptions};
use hdi_tribology::model::SliderModel;
use hdi_tribology::scene::Scene;
use std::time::Duration;

fn scenes() -> Vec<(&'static str, Scene)> {
    let mut out: Vec<(&'static str, Scene)> = scenes::bench_structures()
        .into_iter()
        .map(|(name, structure)| {
            let mut s = Scene::paper();
            s.structure = structure;
            (name, s)
        })
        .collect();
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/paper_bulge.toml");
    match Scene::from_path(file) {
        Ok(s) => out.push(("paper_bulge.toml", s)),
        Err(e) => eprintln!("{file}: {e}"),
    }
    out
}

/// One analysis's result as a number (mW or V) or its error.
type Outcome = Result<f64, String>;

/// An analysis under given options.
type Analysis<'a> = &'a dyn Fn(&StaticOptions) -> Outcome;

fn main() {
    let budget = Duration::from_secs(1);
    println!(
        "| scene | analysis | result | direct refinement CPU ms | polished from tables CPU ms | \
         ratio | relative difference |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (name, scene) in scenes() {
        let model = match SliderModel::from_scene(&scene) {
            Ok(m) => m,
            Err(e) => {
                eprintln!("{name}: {e}");
                continue;
            }
        };
        let opts = |polish: bool| {
            let mut o = StaticOptions::new(scene.detector.contact_threshold_n);
            o.grid.polish_from_tables = polish;
            o
        };
        // The take-off starts 30 mW above the touchdown of the default path.
        let start = touchdown_power(&model, &opts(true))
            .map(|t| t.power + opts(true).takeoff_start_excess)
            .unwrap_or(0.1);
        let analyses: [(&str, &str, Analysis); 3] = [
            ("touchdown", "mW", &|o| {
                touchdown_power(&model, o)
                    .map(|t| t.power_mw())
                    .map_err(|e| e.to_string())
            }),
            ("take-off", "mW", &|o| {
                takeoff_power(&model, start, o)
                    .map(|t| t.power_mw())
                    .map_err(|e| e.to_string())
            }),
            ("pull-in at 0 mW", "V", &|o| {
                pull_in_voltage(&model, 0.0, o)
                    .map(|p| p.voltage)
                    .map_err(|e| e.to_string())
            }),
        ];
        for (what, unit, run) in analyses {
            // Interleaved, so that both see the same load.
            let (mut cpu_direct, mut cpu_polished) = (0.0, 0.0);
            let (mut direct, mut polished) = (Err(String::new()), Err(String::new()));
            for _ in 0..2 {
                let (r, t) = timing::measure(3, 10_000, budget / 2, || run(&opts(false)));
                (direct, cpu_direct) = (r, cpu_direct + 0.5 * t.cpu);
                let (r, t) = timing::measure(3, 10_000, budget / 2, || run(&opts(true)));
                (polished, cpu_polished) = (r, cpu_polished + 0.5 * t.cpu);
            }
            let (result, diff) = match (&direct, &polished) {
                (Ok(a), Ok(b)) => (
                    format!("{b:.10} {unit}"),
                    format!("{:.1e}", (a - b).abs() / a.abs()),
                ),
                (Err(a), Err(b)) if a == b => (a.clone(), "same error".into()),
                _ => (format!("{direct:?} vs {polished:?}"), "DIFFERENT".into()),
            };
            println!(
                "| {name} | {what} | {result} | {:.3} | {:.3} | {:.2}× | {diff} |",
                cpu_direct * 1e3,
                cpu_polished * 1e3,
                cpu_direct / cpu_polished
            );
        }
    }
}
