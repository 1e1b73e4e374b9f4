//! One drive step through the C ABI (`hdi_drive_step`: the handle check, the command's checks
//! and conversion, the sensors' conversion, the panic guard) against the same step in Rust
//! (`Drive::step`), in the same run. Prints a table.
//!
//! `cargo bench --manifest-path capi/Cargo.toml --bench step`. Both drives are the paper scene
//! at 25 mm with the default options and seed 1, so they run the same trajectory to the bit
//! (checked on every period). Each case settles 400 periods, then times rounds of two blocks
//! of 200 periods, one per drive, the order alternating between rounds, on the thread's CPU
//! clock, for at least 2 s; the ratio is the C ABI's total time over Rust's, and the median of
//! the rounds' ratios.

#[path = "../../examples/common/timing.rs"]
mod timing;

use hdi::{
    hdi_drive_free, hdi_drive_new, hdi_drive_step, hdi_scene_free, hdi_scene_paper, HdiCommand,
    HdiDrive, HdiScene, HdiSensors, HdiStatus,
};
use hdi_tribology::drive::{scene_zone, Command, Drive, DriveOptions, Plant};
use hdi_tribology::scene::Scene;
use std::hint::black_box;
use std::ptr::{null, null_mut};
use std::time::{Duration, Instant};

const DT: f64 = 50e-6;
const BLOCK: usize = 200;

/// The heater command of period `k` of a case.
fn heater_mw(base_mw: f64, alternate: bool, k: usize) -> f64 {
    if alternate && k % 2 == 1 {
        base_mw + 0.001
    } else {
        base_mw
    }
}

struct Pair {
    rust: Drive,
    c: *mut HdiDrive,
    k: usize,
}

impl Pair {
    fn rust_block(&mut self, base: f64, alternate: bool, n: usize) -> Vec<f64> {
        (0..n)
            .map(|i| {
                let cmd = Command::heater_mw(heater_mw(base, alternate, self.k + i));
                black_box(self.rust.step(&cmd, DT).expect("step")).truth.gap
            })
            .collect()
    }

    fn c_block(&mut self, base: f64, alternate: bool, n: usize) -> Vec<f64> {
        let mut s = HdiSensors::default();
        (0..n)
            .map(|i| {
                let cmd = HdiCommand {
                    heater_power_mw: heater_mw(base, alternate, self.k + i),
                    ..HdiCommand::default()
                };
                let st = unsafe { hdi_drive_step(self.c, &cmd, DT, &mut s) };
                assert_eq!(st, HdiStatus::Ok);
                black_box(&s);
                s.truth.gap_nm
            })
            .collect()
    }
}

fn cpu_now() -> f64 {
    timing::thread_cpu_seconds().unwrap_or_else(|| {
        static START: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
        START.get_or_init(Instant::now).elapsed().as_secs_f64()
    })
}

fn main() {
    let scene = Scene::paper();
    let zone = scene_zone(&scene, 0.025).expect("zone");
    let plant = Plant::new(&scene, &zone, 1, DriveOptions::default()).expect("plant");
    let mut c_scene: *mut HdiScene = null_mut();
    assert_eq!(unsafe { hdi_scene_paper(&mut c_scene) }, HdiStatus::Ok);
    println!("| case | Rust µs/period | C ABI µs/period | C ABI − Rust (ns/period) | C/Rust (total) | C/Rust (median of rounds) | rounds |");
    println!("|---|---:|---:|---:|---:|---:|---:|");
    let cases = [
        ("flight 70 mW, held command", 70.0, false),
        ("flight 70 mW, command changed every period", 70.0, true),
        ("contact 80 mW, held command", 80.0, false),
        ("contact 80 mW, command changed every period", 80.0, true),
    ];
    for (name, mw, alternate) in cases {
        let mut c: *mut HdiDrive = null_mut();
        assert_eq!(
            unsafe { hdi_drive_new(c_scene, null(), 1, &mut c) },
            HdiStatus::Ok
        );
        let mut p = Pair {
            rust: plant.drive().expect("drive"),
            c,
            k: 0,
        };
        let check = |r: &[f64], c: &[f64]| {
            for (a, b) in r.iter().zip(c) {
                assert_eq!(
                    hdi_tribology::units::to_nm(*a).to_bits(),
                    b.to_bits(),
                    "the two drives diverged"
                );
            }
        };
        let (r, cc) = (
            p.rust_block(mw, alternate, 400),
            p.c_block(mw, alternate, 400),
        );
        check(&r, &cc);
        p.k += 400;
        let (mut total_r, mut total_c, mut ratios) = (0.0, 0.0, Vec::new());
        let start = Instant::now();
        let mut round = 0;
        while start.elapsed() < Duration::from_secs(2) || round < 6 {
            let (tr, tc, r, cc);
            if round % 2 == 0 {
                let t0 = cpu_now();
                r = p.rust_block(mw, alternate, BLOCK);
                let t1 = cpu_now();
                cc = p.c_block(mw, alternate, BLOCK);
                let t2 = cpu_now();
                (tr, tc) = (t1 - t0, t2 - t1);
            } else {
                let t0 = cpu_now();
                cc = p.c_block(mw, alternate, BLOCK);
                let t1 = cpu_now();
                r = p.rust_block(mw, alternate, BLOCK);
                let t2 = cpu_now();
                (tc, tr) = (t1 - t0, t2 - t1);
            }
            check(&r, &cc);
            p.k += BLOCK;
            total_r += tr;
            total_c += tc;
            ratios.push(tc / tr);
            round += 1;
        }
        ratios.sort_by(f64::total_cmp);
        let n = (round * BLOCK) as f64;
        println!(
            "| {name} | {:.2} | {:.2} | {:+.0} | {:.4} | {:.4} | {round} |",
            total_r / n * 1e6,
            total_c / n * 1e6,
            (total_c - total_r) / n * 1e9,
            total_c / total_r,
            ratios[ratios.len() / 2],
        );
        assert_eq!(unsafe { hdi_drive_free(p.c) }, HdiStatus::Ok);
    }
    assert_eq!(unsafe { hdi_scene_free(c_scene) }, HdiStatus::Ok);
}
