//! The drive's cost per period, period by period: the adaptive steps (Rodas5P, the default) against
//! the bounded mode (`DriveOptions::bounded`, Radau5), in flight and in contact, on a flat and on
//! the default wavy disk, with a held command, a 0.5 V dither and a command changed every period.
//! Prints the median, the 99.9th percentile and the largest time of one period, and how far each
//! run's sensors stray from a tight reference run, in units of their noise.
//!
//! `cargo bench --bench drive_bounded`. Each case settles 20 ms at its heater power, then runs
//! `PERIODS` periods (the case `snap` settles in flight at 70 mW and is then commanded to 80 mW:
//! its first periods hold the snap into contact); the whole case is run `REPEATS` times from the
//! same start (the same work to the bit: the same seed, the same commands), and a period's time is
//! the least of its repeats: a period the scheduler interrupted in one repeat is not interrupted in
//! all of them, so what is left is the period's own cost. Times are wall-clock (`Instant`) per
//! period on one thread.

use hdi_tribology::drive::{scene_zone, Command, DiskSpec, Drive, DriveOptions, Plant, Sensors};
use hdi_tribology::ode::Method;
use hdi_tribology::scene::Scene;
use std::time::Instant;

const DT: f64 = 50e-6;
const SETTLE: usize = 400;
const PERIODS: usize = 2000;
const REPEATS: usize = 3;

/// The commands of one case, period by period (after the settling ones).
fn command(mw: f64, kind: &str, k: usize) -> Command {
    let c = Command::heater_mw(mw);
    match kind {
        "dither" => c.with_dither(0.5, 10.5),
        // A heater dithered by ±1 µW, alternating: a restart every period.
        "changed" => Command {
            heater_power_mw: mw + if k.is_multiple_of(2) { 1e-3 } else { -1e-3 },
            ..c
        },
        _ => c,
    }
}

/// What one run gives: its sensors, times (s), steps and largest error estimate.
type Run = (Vec<Sensors>, Vec<f64>, usize, f64);

/// Settles a drive at `settle_mw`, then runs the case's periods at `mw`.
fn run(
    plant: &Plant,
    (settle_mw, mw): (f64, f64),
    kind: &str,
) -> Result<Run, hdi_tribology::Error> {
    let mut d: Drive = plant.drive()?;
    for k in 0..SETTLE {
        d.step(&command(settle_mw, kind, k), DT)?;
    }
    let (mut out, mut times) = (Vec::with_capacity(PERIODS), Vec::with_capacity(PERIODS));
    let (s0, mut worst) = (d.stats().accepted, 0.0f64);
    for k in 0..PERIODS {
        let c = command(mw, kind, SETTLE + k);
        let t = Instant::now();
        let s = d.step(&c, DT)?;
        times.push(t.elapsed().as_secs_f64());
        out.push(s);
        worst = worst.max(d.last_period().error_estimate);
    }
    Ok((out, times, d.stats().accepted - s0, worst))
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i]
}

fn main() {
    let scene = Scene::paper();
    let zone = scene_zone(&scene, 0.025).expect("zone");
    let noise = hdi_tribology::drive::SensorSpec::default();
    let rb_noise = 2f64.sqrt() * noise.readback.noise;
    println!("| disk | state | command | mode | p50 µs | p99.9 µs | max µs | × real time (p50) | × real time (max) | steps/period | largest error estimate | contact sensor / noise (max) | read-back ratio / noise (max) | gap (max, pm) |");
    println!("|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (disk_name, disk) in [("flat", DiskSpec::flat()), ("wavy", DiskSpec::default())] {
        let plant = |steps: Option<usize>, tight: bool| {
            let mut base = DriveOptions {
                disk: disk.clone(),
                ..DriveOptions::default()
            };
            if let Some(n) = steps {
                base = base.bounded(n);
            }
            let opts = if tight {
                DriveOptions {
                    method: Method::Radau5,
                    rtol: 1e-10,
                    atol_displacement: 1e-17,
                    atol_displacement_flight: 1e-17,
                    max_step: Some(DT / 4.0),
                    ..base
                }
            } else {
                base
            };
            Plant::new(&scene, &zone, 1, opts).expect("plant")
        };
        let reference = plant(None, true);
        for (state, mw) in [
            ("flight", (70.0, 70.0)),
            ("contact", (80.0, 80.0)),
            ("snap", (70.0, 80.0)),
        ] {
            for kind in ["held", "dither", "changed"] {
                if state == "snap" && kind != "held" {
                    continue;
                }
                // `DRIVE_BOUNDED_CASE=wavy,contact,dither` runs one case only.
                if let Ok(only) = std::env::var("DRIVE_BOUNDED_CASE") {
                    if only != format!("{disk_name},{state},{kind}") {
                        continue;
                    }
                }
                let (truth, ..) = run(&reference, mw, kind).expect("reference");
                for steps in [None, Some(4), Some(8), Some(16), Some(32)] {
                    let p = plant(steps, false);
                    let mut best = vec![f64::INFINITY; PERIODS];
                    let mut last = None;
                    let mode = steps.map_or("adaptive".to_string(), |n| format!("bounded, {n}"));
                    for _ in 0..REPEATS {
                        let (s, times, n, worst) = match run(&p, mw, kind) {
                            Ok(r) => r,
                            Err(e) => {
                                last = None;
                                println!(
                                    "| {disk_name} | {state} | {kind} | {mode} | fails: {e} |"
                                );
                                break;
                            }
                        };
                        for (b, t) in best.iter_mut().zip(&times) {
                            *b = b.min(*t);
                        }
                        last = Some((s, n, worst));
                    }
                    let Some((s, n, worst)) = last else {
                        continue;
                    };
                    let (mut sensor, mut readback, mut gap) = (0.0f64, 0.0f64, 0.0f64);
                    for (a, b) in s.iter().zip(&truth) {
                        sensor =
                            sensor.max((a.contact_resistance_ohm - b.contact_resistance_ohm).abs());
                        readback =
                            readback.max((a.readback.log_ratio() - b.readback.log_ratio()).abs());
                        gap = gap.max((a.truth.gap_nm - b.truth.gap_nm).abs());
                    }
                    best.sort_by(f64::total_cmp);
                    let (p50, p999, max) = (
                        percentile(&best, 0.5),
                        percentile(&best, 0.999),
                        best[PERIODS - 1],
                    );
                    println!(
                        "| {disk_name} | {state} | {kind} | {mode} | {:.2} | {:.2} | {:.2} | {:.0} | {:.0} | {:.2} | {:.3} | {:.3} | {:.3} | {:.4} |",
                        p50 * 1e6,
                        p999 * 1e6,
                        max * 1e6,
                        DT / p50,
                        DT / max,
                        n as f64 / PERIODS as f64,
                        worst,
                        sensor / noise.contact.noise,
                        readback / rb_noise,
                        gap * 1e3,
                    );
                }
            }
        }
    }
}
