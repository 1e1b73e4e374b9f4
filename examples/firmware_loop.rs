//! A controller written by a user, driving the simulated drive in a loop, as drive firmware
//! does: read the sensors at 20 kHz, decide the heater command, repeat.
//!
//! The controller ramps the heater slowly and watches the acoustic emission: it learns the
//! AE baseline and its scatter over the first 2 ms, declares touchdown once a 1 ms running mean
//! of the AE is six standard errors above that baseline, then backs off 10 mW and holds there.
//! The run prints what the controller saw and compares its touchdown with the static model's.
//! Then it runs the crate's own staircase detectors over 20 noise seeds and prints their ROC
//! points (false alarms, missed touchdowns, the clearance error left), and the contact-sensor
//! slope's alarms on noise alone.
//!
//! `cargo run --release --example firmware_loop [SEED] [--trace FILE]`
//!
//! `--trace` writes every period of the user's loop (the command held and the sensors read) to
//! FILE as CSV and stops after the loop. The C example `capi/examples/firmware_loop.c` runs the
//! same controller through the C ABI and writes the same file; `capi/tests/c_example.rs`
//! checks that the two agree to the bit.

use hdi_tribology::analysis::{static_hysteresis, StaticOptions};
use hdi_tribology::drive::{
    run, scene_zone, touchdown_roc, AcousticLevel, Action, Command, ContactSensorSlope, Controller,
    DriveOptions, LevelDetector, Plant, RocPoint, Sensors, Staircase, StaircaseSettings,
    TrueContact,
};
use hdi_tribology::scene::Scene;

/// The user's controller: ramp, watch the AE, back off, hold.
struct RampAndWatch {
    /// Heater now (mW).
    power_mw: f64,
    /// Ramp per period (mW).
    ramp_mw: f64,
    /// Periods seen.
    n: usize,
    /// Baseline sums over the first periods.
    base: (f64, f64, usize),
    /// Running mean of the AE (exponential, 1 ms).
    mean: f64,
    touchdown_mw: Option<f64>,
    hold_left: usize,
}

/// Writes every period's sensors to a CSV text before the controller sees them.
struct Traced<C> {
    inner: C,
    csv: Option<String>,
    n: usize,
}

impl<C: Controller> Controller for Traced<C> {
    fn start(&mut self) -> Command {
        self.inner.start()
    }

    fn update(&mut self, s: &Sensors) -> Action {
        self.n += 1;
        if let Some(csv) = &mut self.csv {
            use std::fmt::Write;
            let t = &s.truth;
            // The units of the C ABI's `HdiSensors`, the same as the Rust `Sensors`.
            let _ = writeln!(
                csv,
                "{},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?}",
                self.n,
                s.time_s,
                s.heater_power_mw,
                s.contact_resistance_ohm,
                s.acoustic_v,
                s.readback.fundamental_v,
                s.readback.third_v,
                t.gap_nm,
                t.mean_contact_force_un,
                t.sensor_temperature_k,
                t.disk_height_nm
            );
        }
        self.inner.update(s)
    }
}

const DT: f64 = 50e-6;
const BASELINE_PERIODS: usize = 40;
const MEAN_PERIODS: f64 = 20.0;

impl Controller for RampAndWatch {
    fn start(&mut self) -> Command {
        Command::heater_mw(self.power_mw)
    }

    fn update(&mut self, s: &Sensors) -> Action {
        self.n += 1;
        if let Some(td) = self.touchdown_mw {
            // Backed off: hold for a while, then stop.
            self.hold_left = self.hold_left.saturating_sub(1);
            if self.hold_left == 0 {
                return Action::Stop;
            }
            return Action::Continue(Command::heater_mw(td - 10.0));
        }
        if self.n <= BASELINE_PERIODS {
            self.base.0 += s.acoustic_v;
            self.base.1 += s.acoustic_v * s.acoustic_v;
            self.base.2 += 1;
            self.mean = s.acoustic_v;
            return Action::Continue(Command::heater_mw(self.power_mw));
        }
        let a = 1.0 / MEAN_PERIODS;
        self.mean += a * (s.acoustic_v - self.mean);
        let k = self.base.2 as f64;
        let m = self.base.0 / k;
        let sd = (self.base.1 / k - m * m).max(0.0).sqrt();
        // Standard error of an exponential mean of white samples: sd·√(a/(2−a)).
        let se = sd * (a / (2.0 - a)).sqrt();
        if self.mean > m + 6.0 * se {
            self.touchdown_mw = Some(self.power_mw);
            self.hold_left = 200;
            return Action::Continue(Command::heater_mw(self.power_mw - 10.0));
        }
        self.power_mw += self.ramp_mw;
        Action::Continue(Command::heater_mw(self.power_mw))
    }
}

fn main() -> Result<(), hdi_tribology::Error> {
    let mut seed: u64 = 1;
    let mut trace = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--trace" => trace = args.next(),
            s => seed = s.parse().unwrap_or(1),
        }
    }
    let scene = Scene::paper();
    let zone = scene_zone(&scene, 0.025)?;
    let plant = Plant::new(&scene, &zone, seed, DriveOptions::default())?;
    let mut drive = plant.drive()?;
    let mut traced = Traced {
        inner: RampAndWatch {
            power_mw: 70.0,
            // 1 mW/ms: 0.05 mW per 50 µs period.
            ramp_mw: 0.05,
            n: 0,
            base: (0.0, 0.0, 0),
            mean: 0.0,
            touchdown_mw: None,
            hold_left: 0,
        },
        csv: trace.as_ref().map(|_| {
            "period,time_s,heater_power_mw,contact_resistance_ohm,acoustic_v,\
             readback_fundamental_v,readback_third_v,true_gap_nm,true_mean_contact_force_un,\
             true_sensor_temperature_k,true_disk_height_nm\n"
                .to_string()
        }),
        n: 0,
    };
    let clock = std::time::Instant::now();
    let periods = run(&mut drive, &mut traced, DT, 1_000_000)?;
    let ctrl = &traced.inner;
    let wall = clock.elapsed().as_secs_f64();
    let h = static_hysteresis(
        plant.model(),
        &StaticOptions::new(scene.detector.contact_threshold_n),
    )?;
    println!(
        "seed {seed}: {periods} periods ({:.1} ms of drive time) in {:.1} ms",
        drive.time() * 1e3,
        wall * 1e3
    );
    match ctrl.touchdown_mw {
        Some(td) => println!(
            "AE touchdown at {td:.2} mW (static touchdown {:.3} mW: {:+.2} mW); holding {:.2} mW",
            h.touchdown.power_mw(),
            td - h.touchdown.power_mw(),
            td - 10.0
        ),
        None => println!("no touchdown seen"),
    }
    if let (Some(path), Some(csv)) = (&trace, &traced.csv) {
        std::fs::write(path, csv).map_err(|source| hdi_tribology::Error::Io {
            path: path.clone(),
            source,
        })?;
        return Ok(());
    }

    // The crate's detectors on the 0.25 mW staircase from 70 mW, 20 seeds per point.
    let settings = StaircaseSettings::from_mw(70.0, 0.25, 80.0, 10.0);
    let th = scene.detector.contact_threshold_n * 1e6; // µN
    let seeds = 1..21;
    println!("\n| detector | n_sigma | runs | false alarm | one step early | missed | mean P_det − P_TD (mW) | rms clearance error (nm) |");
    println!("|---|---|---|---|---|---|---|---|");
    let clock = std::time::Instant::now();
    let row = |r: &RocPoint, n: f64| {
        println!(
            "| {} | {n} | {} | {:.2} | {:.2} | {:.2} | {:+.3} | {:.4} |",
            r.detector,
            r.runs,
            r.false_alarm_rate(),
            r.early_rate(),
            r.missed_rate(),
            r.mean_error_mw,
            r.rms_clearance_error_nm
        )
    };
    for n in [2.0, 3.0, 5.0, 8.0] {
        let r = touchdown_roc(&plant, settings, th, seeds.clone(), || {
            ContactSensorSlope::new(n, 6)
        })?;
        row(&r, n);
    }
    for n in [2.0, 3.0, 5.0, 8.0] {
        let r = touchdown_roc(&plant, settings, th, seeds.clone(), || {
            AcousticLevel::new(n, 3)
        })?;
        row(&r, n);
    }
    println!(
        "(static touchdown {:.3} mW; ROC runs took {:.1} s)",
        h.touchdown.power_mw(),
        clock.elapsed().as_secs_f64()
    );

    // Noise alone: the contact-sensor slope judged on flying levels far below touchdown
    // (50–66 mW), where the asperity tail carries well under 1 µN, for the same seeds, each run
    // up to its first alarm (where a staircase stops): alarms per level judged.
    let mut flying = StaircaseSettings::from_mw(50.0, 0.25, 66.0, 10.0);
    flying.find_takeoff = false;
    let mut levels = Vec::new();
    for seed in seeds.clone() {
        let mut d = plant.with_seed(seed)?.drive()?;
        let mut st = Staircase::new(flying, TrueContact::new(th)?, DT)?;
        run(&mut d, &mut st, DT, 1_000_000)?;
        levels.push(st.outcome().levels.clone());
    }
    println!("\n| n_sigma | flying levels judged | alarms per level on noise | one-sided Gaussian tail |");
    println!("|---|---|---|---|");
    for n in [2.0, 3.0, 5.0, 8.0] {
        let (mut judged, mut fired) = (0usize, 0usize);
        for run_levels in &levels {
            let mut det = ContactSensorSlope::new(n, 6)?;
            // As the staircase does: up to the first alarm.
            for l in run_levels {
                judged += det.excess(l).is_some() as usize;
                if det.judge(l) {
                    fired += 1;
                    break;
                }
            }
        }
        println!(
            "| {n} | {judged} | {:.2} % | {:.2} % |",
            100.0 * fired as f64 / judged as f64,
            50.0 * erfc(n / std::f64::consts::SQRT_2)
        );
    }
    Ok(())
}

/// Complementary error function (Numerical Recipes' Chebyshev fit, relative error < 1.2e-7).
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let r = t
        * (-z * z - 1.26551223
            + t * (1.00002368
                + t * (0.37409196
                    + t * (0.09678418
                        + t * (-0.18628806
                            + t * (0.27886807
                                + t * (-1.13520398
                                    + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277)))))))))
            .exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}
