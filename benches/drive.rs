//! `Drive::step` at a 20 kHz controller rate against real time: in flight (70 mW), in contact
//! (80 mW) and in a flight clear of the peaks (60 mW), on a flat and on the default wavy disk,
//! with and without an AC dither, and with a command that changes every period, without and
//! under the dither; at the default
//! tolerance (0.01 pm throughout), with the exponential scheme (`DriveScheme::Exponential`, right
//! after the default on the same case) and with 1 pm in flight
//! (`DriveOptions::atol_displacement_flight`). Prints a table; the last column gives the shares
//! of the timed periods the exponential scheme advanced itself (in brackets those that continued
//! the period before by the two-step method), left to the integrator's
//! spanning steps (a held command on a flat disk) and read from a dither's settled orbit (a
//! dither on a flat disk, held or under a heater changed within the orbit's linearised map);
//! the rest it left to the integrator after misses.
//!
//! `cargo bench --bench drive`. Each case settles 20 ms at its heater power, then times blocks
//! of 200 periods (10 ms of drive time) for at least 1 s; the table gives the fastest block's
//! wall-clock time and the mean CPU time of the thread per period, and the ratio of the period
//! (50 µs) to each: how many times faster than real time the drive runs on one core.
//!
//! Then three programmes on the wavy disk from a fresh drive, each run timed whole, default and
//! exponential scheme (`ramps`): the heater ramped into contact and back, ramped slowly, and
//! stepped; here the table rebuilds of the exponential scheme count.

#[path = "../examples/common/timing.rs"]
mod timing;

use hdi_tribology::drive::{scene_zone, Command, DiskSpec, DriveOptions, DriveScheme, Plant};
use hdi_tribology::scene::Scene;
use std::time::Duration;

const DT: f64 = 50e-6;
const BLOCK: usize = 200;

fn main() {
    let scene = Scene::paper();
    let zone = scene_zone(&scene, 0.025).expect("zone");
    println!("| scheme | disk | state | heater (mW) | dither | wall µs/period | CPU µs/period | × real time (wall) | × real time (CPU) | steps/period | exponential (two-step) / spanned / orbit periods |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    let configs = [
        ("0.01 pm", DriveOptions::default()),
        (
            "exponential",
            DriveOptions {
                scheme: DriveScheme::Exponential,
                ..DriveOptions::default()
            },
        ),
        (
            "1 pm flight",
            DriveOptions {
                atol_displacement_flight: 1e-12,
                ..DriveOptions::default()
            },
        ),
    ];
    for (disk_name, disk) in [("flat", DiskSpec::flat()), ("wavy", DiskSpec::default())] {
        let plants: Vec<(&str, Plant)> = configs
            .iter()
            .map(|(name, o)| {
                let o = DriveOptions {
                    disk: disk.clone(),
                    ..o.clone()
                };
                (*name, Plant::new(&scene, &zone, 1, o).expect("plant"))
            })
            .collect();
        {
            // "clear": 60 mW, a 3.9 nm gap with the peaks clear of the head (at 70 mW, 2.8 nm,
            // the highest peaks already touch it: 0.07 µN of contact force).
            for (state, mw) in [("flight", 70.0), ("contact", 80.0), ("clear", 60.0)] {
                // Held commands, with and without dither; then a command that changes every period
                // (a heater dithered by ±1 µW, alternating): the worst case, a restart per period;
                // then the same under the AC dither.
                for (dither, alternate) in [
                    (None, false),
                    (Some((0.5, 10.5)), false),
                    (None, true),
                    (Some((0.5, 10.5)), true),
                ] {
                    for (atol_name, plant) in &plants {
                        // `DRIVE_BENCH_ONLY=exponential/flat/flight/held` runs the cases whose
                        // label contains the value (a profile of one case).
                        let label = format!(
                            "{atol_name}/{disk_name}/{state}/{}",
                            match (dither, alternate) {
                                (Some(_), false) => "dither",
                                (Some(_), true) => "dither-changed",
                                (None, true) => "changed",
                                (None, false) => "held",
                            }
                        );
                        if std::env::var("DRIVE_BENCH_ONLY").is_ok_and(|o| !label.contains(&o)) {
                            continue;
                        }
                        let mut d = plant.drive().expect("drive");
                        let mut cmd = Command::heater_mw(mw);
                        if let Some((a, f)) = dither {
                            cmd = cmd.with_dither(a, f);
                        }
                        for _ in 0..400 {
                            d.step(&cmd, DT).expect("settle");
                        }
                        let s0 = d.stats().accepted;
                        let c0 = d.scheme_counts();
                        let t0 = d.time();
                        let mut k = 0usize;
                        let (last, t) = timing::measure(5, 100_000, Duration::from_secs(1), || {
                            let mut s = None;
                            for _ in 0..BLOCK {
                                let mut c = cmd;
                                if alternate {
                                    k += 1;
                                    c.heater_power_mw +=
                                        if k.is_multiple_of(2) { 1e-3 } else { -1e-3 };
                                }
                                s = Some(d.step(&c, DT).expect("step"));
                            }
                            s
                        });
                        let periods = (d.time() - t0) / DT;
                        let steps = (d.stats().accepted - s0) as f64 / periods;
                        let c1 = d.scheme_counts();
                        let exp_share = (c1.exponential - c0.exponential) as f64 / periods;
                        let two_share = (c1.two_step - c0.two_step) as f64 / periods;
                        let spanned = (c1.spanned - c0.spanned) as f64 / periods;
                        let orbit = (c1.orbit - c0.orbit) as f64 / periods;
                        let last = last.expect("ran");
                        // The state the case claims: in contact the true contact force is far above F_th.
                        let in_contact = (last.truth.mean_contact_force_un * 1e-6) > 5e-5;
                        assert_eq!(in_contact, state == "contact", "{state} at {mw} mW");
                        let (wall, cpu) = (t.wall / BLOCK as f64, t.cpu / BLOCK as f64);
                        println!(
                    "| {atol_name} | {disk_name} | {state} | {mw} | {} | {:.2} | {:.2} | {:.0} | {:.0} | {:.2} | {:.2} ({:.2}) / {:.2} / {:.2} |",
                    match (dither, alternate) {
                        (Some((a, f)), false) => format!("{a} V, {f:.1} kHz"),
                        (Some((a, f)), true) => format!("{a} V, {f:.1} kHz, ±1 µW every period"),
                        (None, true) => "off, ±1 µW every period".to_string(),
                        (None, false) => "off".to_string(),
                    },
                    wall * 1e6,
                    cpu * 1e6,
                    DT / wall,
                    DT / cpu,
                    steps,
                    exp_share,
                    two_share,
                    spanned,
                    orbit
                );
                    }
                }
            }
        }
    }
    ramps(&scene, &zone, &configs);
}

/// A heater ramped on the wavy disk, the command changed every period: `60 + 22 sin²(π t / T)`
/// mW over `T` (into contact and back for `T` = 0.2 s; up to 62 mW over the first 0.2 s for
/// `T` = 2 s), and a step from 70 to 80 mW held 0.1 s each: 4 000 periods from a fresh drive,
/// each run timed whole, its table rebuilds included (median of three).
fn ramps(scene: &Scene, zone: &hdi_tribology::drive::Zone, configs: &[(&str, DriveOptions)]) {
    println!();
    println!("| scheme | programme | wall ms (4 000 periods) | CPU ms | refreshes | rebuilds |");
    println!("|---|---|---|---|---|---|");
    for (name, period) in [
        ("ramp 0.2 s", Some(0.2)),
        ("ramp 2 s", Some(2.0)),
        ("step 70 → 80 mW", None),
    ] {
        for (atol_name, o) in configs.iter().take(2) {
            let label = format!("{atol_name}/wavy/{name}");
            if std::env::var("DRIVE_BENCH_ONLY").is_ok_and(|o| !label.contains(&o)) {
                continue;
            }
            let o = DriveOptions {
                disk: DiskSpec::default(),
                ..o.clone()
            };
            let plant = Plant::new(scene, zone, 1, o).expect("plant");
            let mut runs = Vec::new();
            let mut counts = None;
            for _ in 0..3 {
                let mut d = plant.drive().expect("drive");
                let (_, t) = timing::measure(1, 1, Duration::ZERO, || {
                    for k in 0..4000 {
                        let t = k as f64 * DT;
                        let mw = match period {
                            Some(p) => 60.0 + 22.0 * (std::f64::consts::PI * t / p).sin().powi(2),
                            None if k < 2000 => 70.0,
                            None => 80.0,
                        };
                        d.step(&Command::heater_mw(mw), DT).expect("step");
                    }
                });
                runs.push((t.wall, t.cpu));
                counts = Some(d.scheme_counts());
            }
            runs.sort_by(|a, b| a.0.total_cmp(&b.0));
            let (wall, cpu) = runs[1];
            let c = counts.expect("ran");
            println!(
                "| {atol_name} | {name} | {:.1} | {:.1} | {} | {} |",
                wall * 1e3,
                cpu * 1e3,
                c.refreshes,
                c.rebuilds
            );
        }
    }
}
