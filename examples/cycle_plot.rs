//! One touchdown/take-off cycle of any scene, plotted.
//!
//! `cargo run --release --example cycle_plot -- my_scene.toml [--v-ac 0.6] [--triggered]`
//! writes `out/cycle_plot/` with the time series as CSV and three SVG charts: forces against
//! time, spacing against time, and the contact indicator against heater power. Without a scene
//! file it uses the built-in paper scene. Start a scene of your own from
//! `cargo run --features cli --bin hdi -- scene --paper > my_scene.toml`.

use hdi_tribology::analysis::{simulate_cycle, CycleOptions, HeaterProgramme};
use hdi_tribology::model::{SliderModel, Voltage};
use hdi_tribology::report::{Chart, Series};
use hdi_tribology::scene::Scene;
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let flag = |name: &str| args.iter().position(|a| a == name);
    let value = |name: &str| flag(name).and_then(|i| args.get(i + 1));
    let scene = match args.first().filter(|a| !a.starts_with("--")) {
        Some(path) => Scene::from_path(path)?,
        None => Scene::paper(),
    };
    let mut model = SliderModel::from_scene(&scene)?;
    if let Some(v) = value("--v-ac") {
        model = model.with_voltage(Voltage {
            ac_amplitude: v.parse()?,
            ..model.voltage
        });
    }
    let programme = if flag("--triggered").is_some() {
        HeaterProgramme::triggered_from_scene(&scene)
    } else {
        HeaterProgramme::fixed_from_scene(&scene)?
    };
    let mut opts = CycleOptions::from_scene(&scene)?;
    opts.keep_series = true;
    let r = simulate_cycle(&model, &programme, &opts)?;
    let s = r.series.as_ref().ok_or("no time series")?;

    let out = Path::new("out/cycle_plot");
    std::fs::create_dir_all(out)?;
    s.write_csv(&out.join("series.csv"))?;
    let ms = |f: &dyn Fn(usize) -> f64| -> Vec<(f64, f64)> {
        (0..s.t.len()).map(|i| (s.t[i] * 1e3, f(i))).collect()
    };
    let line = |label, points| Series {
        label,
        points,
        markers: false,
    };
    Chart {
        title: &scene.name,
        x_label: "t (ms)",
        y_label: "force (mN)",
        series: vec![
            line("air bearing", ms(&|i| s.air_bearing[i] * 1e3)),
            line("intermolecular", ms(&|i| s.intermolecular[i] * 1e3)),
            line("electrostatic", ms(&|i| s.electrostatic[i] * 1e3)),
            line("contact", ms(&|i| s.contact[i] * 1e3)),
            line("total", ms(&|i| s.total[i] * 1e3)),
        ],
        log: (false, false),
    }
    .to_svg(&out.join("forces.svg"), 1000, 550)?;
    Chart {
        title: &scene.name,
        x_label: "t (ms)",
        y_label: "bulge gap d (nm)",
        series: vec![line("d", ms(&|i| s.d[i] * 1e9))],
        log: (false, false),
    }
    .to_svg(&out.join("spacing.svg"), 1000, 400)?;
    let indicator = (0..s.t.len())
        .filter(|&i| s.indicator[i].is_finite())
        .map(|i| (s.power[i] * 1e3, s.indicator[i] * 1e6))
        .collect();
    Chart {
        title: &scene.name,
        x_label: "heater power (mW)",
        y_label: "running mean of F_c (µN)",
        series: vec![line("contact indicator", indicator)],
        log: (false, false),
    }
    .to_svg(&out.join("indicator.svg"), 900, 500)?;

    let mw = |p: Option<f64>| p.map_or("none".to_string(), |p| format!("{:.3} mW", p * 1e3));
    println!(
        "scene {}: V_ac = {} V",
        scene.name, model.voltage.ac_amplitude
    );
    println!(
        "touchdown {}, take-off {}, hysteresis {}",
        mw(r.touchdown.map(|d| d.power)),
        mw(r.takeoff.map(|d| d.power)),
        mw(r.hysteresis)
    );
    println!(
        "mean flash-temperature rise {:.2} K; {} steps in {:.1} ms",
        r.mean_temperature_rise,
        r.stats.accepted,
        r.wall_seconds * 1e3
    );
    println!(
        "wrote {}/series.csv, forces.svg, spacing.svg, indicator.svg",
        out.display()
    );
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
