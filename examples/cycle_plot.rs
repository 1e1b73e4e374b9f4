//! One touchdown/take-off cycle of any scene, plotted.
//!
//! `cargo run --release --example cycle_plot -- my_scene.toml [--v-ac 0.6] [--triggered]
//! [--out DIR]` writes `DIR` (default `$HDI_OUT_DIR/cycle_plot`, else `out/cycle_plot`) with the time series as CSV and three SVG charts: forces against
//! time, spacing against time, and the contact indicator against heater power. Without a scene
//! file it uses the built-in paper scene. Start a scene of your own from
//! `cargo run --features cli --bin hdi -- scene --paper > my_scene.toml`.

use hdi_tribology::analysis::{simulate_cycle, CycleOptions, HeaterProgramme};
use hdi_tribology::model::{SliderModel, Voltage};
use hdi_tribology::report::{palette, Chart, Series};
use hdi_tribology::scene::Scene;
use std::path::Path;

#[path = "common/figures.rs"]
#[allow(dead_code)]
mod figures;
#[path = "common/output.rs"]
mod output;

type Res<T> = Result<T, Box<dyn std::error::Error>>;

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = output::out_dir("cycle_plot", &args)?;
    run(&args, &out)
}

/// Runs the cycle the arguments ask for and writes its files into `out`.
fn run(args: &[String], out: &Path) -> Res<()> {
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
            ..model.voltage()
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

    s.write_csv(&out.join("series.csv"))?;
    let all = (f64::NEG_INFINITY, f64::INFINITY);
    let what = format!(
        "{}, V_ac = {} V, {} programme",
        scene.name,
        model.voltage().ac_amplitude,
        if flag("--triggered").is_some() {
            "touchdown-triggered"
        } else {
            "fixed"
        }
    );
    let title = |t: &str| format!("{t}: {what}");
    figures::forces_chart(&title("forces"), s, all, None).to_svg(
        &out.join("forces.svg"),
        1000,
        550,
    )?;
    Chart {
        title: &title("spacing"),
        x_label: "t (ms)",
        y_label: "bulge gap d (nm)",
        series: vec![
            Series::line("", figures::window(s, all, |s, i| s.d[i] * 1e9)).colour(figures::SPACING),
        ],
        ..Chart::default()
    }
    .to_svg(&out.join("spacing.svg"), 1000, 400)?;
    let indicator = (0..s.t.len())
        .filter(|&i| s.indicator[i].is_finite())
        .map(|i| (s.power[i] * 1e3, s.indicator[i] * 1e6))
        .collect();
    let threshold = scene.detector.contact_threshold_n * 1e6;
    let (p0, p1) = s
        .power
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &p| {
            (a.min(p * 1e3), b.max(p * 1e3))
        });
    Chart {
        title: &title("contact indicator"),
        x_label: "heater power (mW)",
        y_label: "running mean of F_{c} (µN)",
        series: vec![
            Series::line("contact indicator", indicator).colour(palette::BLUE),
            Series::line("threshold F_{th}", vec![(p0, threshold), (p1, threshold)])
                .colour(palette::BLACK)
                .width(1)
                .dashed(),
        ],
        ..Chart::default()
    }
    .to_svg(&out.join("indicator.svg"), 900, 500)?;

    let mw = |p: Option<f64>| p.map_or("none".to_string(), |p| format!("{:.3} mW", p * 1e3));
    println!(
        "scene {}: V_ac = {} V",
        scene.name,
        model.voltage().ac_amplitude
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
    /// `cargo test` runs the example (into a temporary directory), so CI runs every example.
    #[test]
    fn example_runs() {
        let dir = tempfile::tempdir().unwrap();
        super::run(&[], dir.path()).expect("the example runs to completion");
        for f in ["series.csv", "forces.svg", "spacing.svg", "indicator.svg"] {
            assert!(dir.path().join(f).is_file(), "{f} written");
        }
    }
}
