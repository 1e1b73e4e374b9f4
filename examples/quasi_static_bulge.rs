//! The quasi-static bulge against the full structure on `scenes/paper_bulge.toml`: for each AC
//! amplitude, the fixed programme's cycle on both models at the scene's tolerance and at a
//! hundredfold tighter one, with touchdown, take-off, hysteresis, steps and CPU time, and the
//! condensation's check (`QuasiStaticBulge::check`).
//!
//! `cargo run --release --example quasi_static_bulge -- [--scene PATH] [--ac 0,0.2,…]
//! [--zeta Z] [--stiffness K]` (the last two change the scene's bulge).

use hdi_tribology::analysis::{simulate_cycle, CycleOptions, CycleResult, HeaterProgramme};
use hdi_tribology::model::{SliderModel, Structure};
use hdi_tribology::scene::{Scene, StructureSpec};
use std::time::Instant;

type Res<T> = Result<T, Box<dyn std::error::Error>>;

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let scene =
        Scene::from_path(value("--scene").unwrap_or_else(|| "scenes/paper_bulge.toml".into()))?;
    let StructureSpec::Bulge {
        mass_kg,
        stiffness_n_per_m,
        damping_ratio,
    } = scene.structure
    else {
        return Err("the comparison needs a scene with a bulge structure".into());
    };
    let zeta: f64 = value("--zeta").map_or(Ok(damping_ratio), |s| s.parse())?;
    let k: f64 = value("--stiffness").map_or(Ok(stiffness_n_per_m), |s| s.parse())?;
    let amplitudes: Vec<f64> = value("--ac")
        .unwrap_or_else(|| "0,0.2,0.4,0.6,0.8,1.0".into())
        .split(',')
        .map(str::parse)
        .collect::<Result<_, _>>()?;
    let structure = Structure::bulge(scene.slider.mass_kg, mass_kg, k, zeta)?;
    let base = SliderModel::from_scene(&scene)?.with_structure(structure);
    let programme =
        HeaterProgramme::Fixed(SliderModel::programme_from_knots(&scene.heater.programme)?);
    let mut opts = CycleOptions::from_scene(&scene)?;
    opts.solver.max_steps = 300_000;
    println!(
        "# {}: bulge {mass_kg:.3e} kg, {k:.3e} N/m, zeta {zeta}; rtol {:.0e} and {:.0e}",
        scene.name,
        opts.solver.rtol,
        opts.solver.rtol * 0.01
    );
    println!(
        "v_ac_v,rtol,model,touchdown_mw,takeoff_mw,hysteresis_mw,steps,cpu_ms,\
         d_touchdown_mw,d_takeoff_mw,d_hysteresis_mw"
    );
    for &v in &amplitudes {
        let full = base.with_ac_amplitude(v);
        let check = full.quasi_static_check()?;
        eprintln!(
            "{v} V: check {} (fast {:.3e} rad/s, decay {:.3e} 1/s, slow {:.3e} rad/s, k_f {:.3e} N/m){}",
            if check.passes() { "passes" } else { "refused" },
            check.fast_rate,
            check.decay_rate,
            check.slow_rate,
            check.fast_stiffness,
            if check.passes() {
                String::new()
            } else {
                format!(": {}", check.refused.join("; "))
            }
        );
        let reduced = full.with_quasi_static_bulge()?;
        for factor in [1.0, 0.01] {
            let mut o = opts;
            o.solver = o.solver.with_rtol(o.solver.rtol * factor);
            let run = |m: &SliderModel| -> (Option<CycleResult>, f64) {
                let clock = Instant::now();
                let r = simulate_cycle(m, &programme, &o).ok();
                (r, clock.elapsed().as_secs_f64())
            };
            let (a, ta) = run(&full);
            let (b, tb) = run(&reduced);
            let mw = |r: &Option<CycleResult>| {
                let td = r.as_ref().and_then(|r| r.touchdown.map(|d| d.power * 1e3));
                let to = r.as_ref().and_then(|r| r.takeoff.map(|d| d.power * 1e3));
                (td, to, td.zip(to).map(|(a, b)| a - b))
            };
            let show = |x: Option<f64>| x.map_or("nan".to_string(), |x| format!("{x:.4}"));
            let (fa, fb) = (mw(&a), mw(&b));
            let diff = |x: Option<f64>, y: Option<f64>| show(x.zip(y).map(|(x, y)| y - x));
            for (name, r, m, t) in [("full", &a, fa, ta), ("quasi_static", &b, fb, tb)] {
                let d = if name == "full" {
                    ["".to_string(), "".to_string(), "".to_string()]
                } else {
                    [diff(fa.0, fb.0), diff(fa.1, fb.1), diff(fa.2, fb.2)]
                };
                println!(
                    "{v},{:.0e},{name},{},{},{},{},{:.1},{},{},{}",
                    o.solver.rtol,
                    show(m.0),
                    show(m.1),
                    show(m.2),
                    r.as_ref().map_or(0, |r| r.stats.accepted),
                    t * 1e3,
                    d[0],
                    d[1],
                    d[2]
                );
            }
        }
    }
    Ok(())
}
