//! A drive of several heads stepped all at once (`MultiDrive::step_into`) against the same
//! heads stepped one by one (one `Drive` per head, each stepped in turn every period): the
//! same plants, the same commands, the same trajectories. Meant to be timed as a whole process,
//! the two modes paired run by run (docs/benchmarks.md, "Drive: several heads").
//!
//! `cargo bench --bench drive_heads -- MODE [HEADS] [PERIODS] [DISK]`: `MODE` is `together`
//! or `apart`, `HEADS` (default 4) heads of the paper scene at 25 mm, `PERIODS` (default
//! 4000) periods of 50 µs, each head's heater moving by ±1 µW every period about its own
//! level from 66 mW up, on the default wavy disk or, with `DISK` = `flat`, a flat one.
//! `check` runs both modes and requires the same sensors to the bit. Prints a checksum.

use hdi_tribology::drive::{scene_zone, Command, DiskSpec, DriveOptions, MultiPlant, Sensors};
use hdi_tribology::scene::Scene;

const DT: f64 = 50e-6;

fn command(head: usize, n: usize) -> Command {
    Command::heater_mw(66.0 + 2.0 * head as f64 + if n % 2 == 1 { 0.001 } else { 0.0 })
}

/// Every head's sensors of every period, in the mode asked for.
fn run(plant: &MultiPlant, together: bool, periods: usize, mut each: impl FnMut(&[Sensors])) {
    let heads = plant.heads();
    let mut out = vec![Sensors::default(); heads];
    let mut commands = vec![Command::default(); heads];
    if together {
        let mut drive = plant.drive().expect("drive");
        for n in 0..periods {
            for (k, c) in commands.iter_mut().enumerate() {
                *c = command(k, n);
            }
            drive.step_into(&commands, DT, &mut out).expect("step");
            each(&out);
        }
    } else {
        let mut drives: Vec<_> = (0..heads)
            .map(|k| plant.head(k).expect("head").drive().expect("drive"))
            .collect();
        for n in 0..periods {
            for (k, d) in drives.iter_mut().enumerate() {
                out[k] = d.step(&command(k, n), DT).expect("step");
            }
            each(&out);
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    let mode = args.first().map_or("together", String::as_str);
    let heads: usize = args.get(1).map_or(4, |s| s.parse().expect("HEADS"));
    let periods: usize = args.get(2).map_or(4000, |s| s.parse().expect("PERIODS"));
    let disk = match args.get(3).map(String::as_str) {
        Some("flat") => DiskSpec::flat(),
        _ => DiskSpec::default(),
    };
    let scene = Scene::paper();
    let zone = scene_zone(&scene, 0.025).expect("zone");
    let opts = DriveOptions {
        disk,
        ..DriveOptions::default()
    };
    let plant = MultiPlant::uniform(&scene, &zone, heads, 1, opts).expect("plant");
    let checksum = |together: bool| {
        let mut sum = 0.0;
        let mut bits = Vec::new();
        run(&plant, together, periods, |s| {
            for x in s {
                sum += x.truth.gap_nm;
                if mode == "check" {
                    bits.push(format!("{x:?}"));
                }
            }
        });
        (sum, bits)
    };
    match mode {
        "together" | "apart" => {
            let (sum, _) = checksum(mode == "together");
            println!("{mode}: {heads} heads, {periods} periods, sum of gaps {sum:.9} nm");
        }
        "check" => {
            let (a, b) = (checksum(true), checksum(false));
            assert_eq!(a.1, b.1, "the two modes differ");
            println!(
                "same sensors to the bit: {heads} heads, {periods} periods, {} nm",
                a.0
            );
        }
        other => panic!("MODE is together, apart or check, got {other}"),
    }
}
