//! The Rust baseline of the Python design of experiments (`python/examples/doe_dask.py`): the
//! same scenes, the same analysis, on rayon, with nothing of Python in the loop.
//!
//! The design varies the surface roughness (rms height and peak-height scale together), the
//! attractive Hamaker constant and the AC amplitude of the paper scene: `N_SIGMA × N_HAMAKER ×
//! N_AC` scenes (10 × 10 × 10 by default). One task is one (roughness, Hamaker) pair: build the
//! model, then `ac_sweep` over the amplitudes. The tasks run on a rayon pool of `--threads`
//! threads (default 2). Each scene's touchdown, take-off, hysteresis, mean temperature rise,
//! steps and flags go to a CSV, every float written so that it reads back bit for bit; a pair
//! whose model or sweep fails keeps the error message instead of numbers. `doe_dask.py` runs the
//! same design on Dask, compares its rows with this CSV and its throughput with the figures this
//! program writes beside it (`<out>.json`).
//!
//!     cargo run --release --example doe_baseline -- --grid 10 10 10 --threads 2 \
//!         --out out/doe/rust.csv
//!
//! The grid: values `start + (stop − start)·i/(n − 1)` rounded to 6 decimals (roughness 0.5 to
//! 0.9 nm; Hamaker constant 0.6 to 1.5 in units of 10⁻¹⁹ J; AC amplitude 0 to 0.9 V), the same
//! rule as `doe_dask.py`'s `design`.

use hdi_tribology::analysis::cycle::{CycleOptions, CycleResult, HeaterProgramme};
use hdi_tribology::analysis::{ac_sweep, sweep};
use hdi_tribology::model::SliderModel;
use hdi_tribology::scene::Scene;
use hdi_tribology::surface::PeakModel;
use hdi_tribology::units;
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

type Res<T> = Result<T, Box<dyn std::error::Error>>;

const HEADER: &str = "height_sigma_nm,hamaker_j,v_ac_v,touchdown_power_w,takeoff_power_w,\
hysteresis_w,mean_temperature_rise_k,steps,status";

/// `n` values from `start` to `stop`, each rounded to 6 decimals (as `doe_dask.py` does).
fn grid(start: f64, stop: f64, n: usize) -> Res<Vec<f64>> {
    (0..n)
        .map(|i| {
            let x = if n == 1 {
                start
            } else {
                start + (stop - start) * i as f64 / (n - 1) as f64
            };
            Ok(format!("{x:.6}").parse()?)
        })
        .collect()
}

/// (roughness in nm, Hamaker constant in J) pairs, and the AC amplitudes (V).
type Design = (Vec<(f64, f64)>, Vec<f64>);

/// The design of `n_sigma × n_hamaker` pairs and `n_ac` amplitudes.
fn design(n_sigma: usize, n_hamaker: usize, n_ac: usize) -> Res<Design> {
    let sigmas = grid(0.5, 0.9, n_sigma)?;
    let hamakers = grid(0.6, 1.5, n_hamaker)?
        .into_iter()
        .map(|a| format!("{a:.6}e-19").parse())
        .collect::<Result<Vec<f64>, _>>()?;
    let pairs = sigmas
        .iter()
        .flat_map(|&s| hamakers.iter().map(move |&a| (s, a)))
        .collect();
    Ok((pairs, grid(0.0, 0.9, n_ac)?))
}

/// The paper scene with roughness `sigma_nm` (nm; heights and peaks) and Hamaker constant
/// `hamaker_j` (J), validated.
fn scene_of(sigma_nm: f64, hamaker_j: f64) -> hdi_tribology::Result<Scene> {
    let mut scene = Scene::paper();
    scene.surface.height_sigma_m = units::nm(sigma_nm);
    if let PeakModel::RiceMaxima { sigma_m, .. } = &mut scene.surface.peaks {
        *sigma_m = units::nm(sigma_nm);
    }
    if let Some(im) = &mut scene.intermolecular {
        im.hamaker_attractive_j = hamaker_j;
    }
    scene.validate()?;
    Ok(scene)
}

/// One task: the cycles of one (roughness, Hamaker) pair, one per amplitude.
fn run_group(
    sigma_nm: f64,
    hamaker_j: f64,
    amplitudes: &[f64],
) -> hdi_tribology::Result<Vec<CycleResult>> {
    let scene = scene_of(sigma_nm, hamaker_j)?;
    let model = SliderModel::from_scene(&scene)?;
    let programme = HeaterProgramme::fixed_from_scene(&scene)?;
    let opts = CycleOptions::from_scene(&scene)?;
    ac_sweep(&model, &programme, &opts, amplitudes)
}

/// CPU time (user + system) of this process so far (s), where Linux's `/proc/self/stat` tells
/// (in clock ticks, assumed 100 per second as on every common Linux build).
fn process_cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    // fields after the command name (which may hold spaces) in parentheses
    let rest = &s[s.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

/// A float as the shortest text that reads back to the same bits; empty for none.
fn num(x: Option<f64>) -> String {
    x.map_or(String::new(), |x| format!("{x:?}"))
}

/// A CSV field, quoted when it holds a comma or a quote.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn rows(
    sigma_nm: f64,
    hamaker_j: f64,
    amplitudes: &[f64],
    r: &hdi_tribology::Result<Vec<CycleResult>>,
) -> String {
    let mut out = String::new();
    match r {
        Ok(cycles) => {
            for c in cycles {
                let flags: Vec<String> = sweep::flags(c)
                    .iter()
                    .map(|f| match serde_json::to_value(f) {
                        Ok(serde_json::Value::String(s)) => s,
                        _ => f.to_string(),
                    })
                    .collect();
                let status = if flags.is_empty() {
                    "ok".to_string()
                } else {
                    flags.join(" ")
                };
                let _ = writeln!(
                    out,
                    "{},{},{},{},{},{},{},{},{}",
                    num(Some(sigma_nm)),
                    num(Some(hamaker_j)),
                    num(Some(c.v_ac)),
                    num(c.touchdown.map(|d| d.power)),
                    num(c.takeoff.map(|d| d.power)),
                    num(c.hysteresis),
                    num(Some(c.mean_temperature_rise)),
                    c.stats.accepted,
                    field(&status)
                );
            }
        }
        Err(e) => {
            for &v in amplitudes {
                let _ = writeln!(
                    out,
                    "{},{},{},,,,,0,{}",
                    num(Some(sigma_nm)),
                    num(Some(hamaker_j)),
                    num(Some(v)),
                    field(&format!("failed: {e}"))
                );
            }
        }
    }
    out
}

fn main() -> Res<()> {
    let mut args = std::env::args().skip(1);
    let (mut n, mut threads, mut out) =
        ([10usize, 10, 10], 2usize, PathBuf::from("out/doe/rust.csv"));
    while let Some(a) = args.next() {
        match a.as_str() {
            "--grid" => {
                for k in &mut n {
                    *k = args
                        .next()
                        .ok_or("--grid needs N_SIGMA N_HAMAKER N_AC")?
                        .parse()?;
                }
            }
            "--threads" => threads = args.next().ok_or("--threads needs a number")?.parse()?,
            "--out" => out = args.next().ok_or("--out needs a path")?.into(),
            other => {
                return Err(format!("unknown argument `{other}` (--grid, --threads, --out)").into())
            }
        }
    }
    if n.contains(&0) || threads == 0 {
        return Err("--grid and --threads need values of at least 1".into());
    }
    let (pairs, amplitudes) = design(n[0], n[1], n[2])?;
    let scenes = pairs.len() * amplitudes.len();
    println!(
        "design: {} (roughness, Hamaker) pairs x {} AC amplitudes = {scenes} scenes, {threads} threads",
        pairs.len(),
        amplitudes.len()
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let t = Instant::now();
    let cpu0 = process_cpu_seconds();
    let results: Vec<String> = pool.install(|| {
        pairs
            .par_iter()
            .map(|&(s, a)| rows(s, a, &amplitudes, &run_group(s, a, &amplitudes)))
            .collect()
    });
    let wall = t.elapsed().as_secs_f64();
    // the main thread sleeps in `install`: the process's CPU time is the pool's
    let cpu = match (cpu0, process_cpu_seconds()) {
        (Some(a), Some(b)) => b - a,
        _ => f64::NAN,
    };

    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let mut text = format!("{HEADER}\n");
    for r in &results {
        text.push_str(r);
    }
    std::fs::write(&out, text)?;
    let summary = out.with_extension("json");
    std::fs::write(
        &summary,
        serde_json::json!({
            "scenes": scenes,
            "threads": threads,
            "wall_s": wall,
            "cpu_s": cpu,
            "scenes_per_s": scenes as f64 / wall,
        })
        .to_string(),
    )?;
    println!(
        "Rust, rayon on {threads} threads: {wall:.2} s wall, {:.1} scenes/s, {:.2} ms/scene; \
         {:.1} ms of CPU per scene",
        scenes as f64 / wall,
        1e3 * wall / scenes as f64,
        1e3 * cpu / scenes as f64
    );
    println!("rows: {}; figures: {}", out.display(), summary.display());
    Ok(())
}
