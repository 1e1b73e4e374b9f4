//! One drive step through the C ABI (`hdi_drive_step`: the handle check, the command's checks
//! and conversion, the sensors' conversion, the panic guard) against the same step in Rust
//! (`Drive::step`), in the same run. Prints a table.
//!
//! `cargo bench --manifest-path capi/Cargo.toml --bench step`. Both drives are the paper scene
//! at 25 mm with the default options and seed 1, so they run the same trajectory to the bit
//! (checked on every period). Each case settles 400 periods, then times rounds of two blocks
//! of 1000 periods, one per drive, the order alternating between rounds, for at least 4 s. The
//! CPU ratio is the C ABI's total thread CPU time over Rust's (the kernel's clock ticks every
//! few ms: totals only); the wall ratio is the median of the rounds' wall-clock ratios.

#[path = "../../examples/common/timing.rs"]
mod timing;

use hdi::{
    hdi_drive_free, hdi_drive_new, hdi_drive_step, hdi_drive_time, hdi_scene_free, hdi_scene_paper,
    HdiCommand, HdiDrive, HdiScene, HdiSensors, HdiStatus,
};
use hdi_tribology::drive::{scene_zone, Command, Drive, DriveOptions, Plant};
use hdi_tribology::scene::Scene;
use std::hint::black_box;
use std::ptr::{null, null_mut};
use std::time::{Duration, Instant};

const DT: f64 = 50e-6;
const BLOCK: usize = 1000;

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
                black_box(self.rust.step(&cmd, DT).expect("step"))
                    .truth
                    .gap_nm
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
    println!("| case | Rust µs/period (CPU) | C ABI µs/period (CPU) | C ABI − Rust (ns/period, CPU) | C/Rust (CPU, total) | C/Rust (wall, median of rounds) | rounds |");
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
                assert_eq!(a.to_bits(), b.to_bits(), "the two drives diverged");
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
        // One block: (wall s, CPU s, the gaps).
        let time = |f: &mut dyn FnMut() -> Vec<f64>| {
            let (w0, c0) = (Instant::now(), cpu_now());
            let r = f();
            (w0.elapsed().as_secs_f64(), cpu_now() - c0, r)
        };
        while start.elapsed() < Duration::from_secs(4) || round < 6 {
            let ((wr, tr, r), (wc, tc, cc));
            if round % 2 == 0 {
                (wr, tr, r) = time(&mut || p.rust_block(mw, alternate, BLOCK));
                (wc, tc, cc) = time(&mut || p.c_block(mw, alternate, BLOCK));
            } else {
                (wc, tc, cc) = time(&mut || p.c_block(mw, alternate, BLOCK));
                (wr, tr, r) = time(&mut || p.rust_block(mw, alternate, BLOCK));
            }
            check(&r, &cc);
            p.k += BLOCK;
            total_r += tr;
            total_c += tc;
            ratios.push(wc / wr);
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
    // The crossing alone: `hdi_drive_time` does nothing but the handle check, the exclusive
    // access, the panic guard and one read.
    let mut c: *mut HdiDrive = null_mut();
    assert_eq!(
        unsafe { hdi_drive_new(c_scene, null(), 1, &mut c) },
        HdiStatus::Ok
    );
    let mut t = 0.0;
    let n = 2_000_000;
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let w0 = Instant::now();
        for _ in 0..n {
            assert_eq!(
                unsafe { hdi_drive_time(black_box(c), &mut t) },
                HdiStatus::Ok
            );
        }
        best = best.min(w0.elapsed().as_secs_f64() / n as f64);
    }
    println!(
        "\nThe crossing alone (`hdi_drive_time`: handle check, exclusive access, panic guard): {:.1} ns per call (fastest of 5 × {n} calls, wall).",
        best * 1e9
    );
    assert_eq!(unsafe { hdi_drive_free(c) }, HdiStatus::Ok);
    assert_eq!(unsafe { hdi_scene_free(c_scene) }, HdiStatus::Ok);
}
