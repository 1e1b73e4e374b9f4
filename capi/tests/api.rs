//! The C ABI's calls against the Rust API they wrap: the same numbers to the bit, and the
//! handle rules under threads.

use hdi::*;
use hdi_tribology::analysis::{self, Protocol};
use hdi_tribology::drive::{
    head_seed, spec_zone, zone_at, Ambient, Command, DiskSpec, DriveOptions, DriveScheme, Harmonic,
    MultiPlant, Plant, Sensors,
};
use hdi_tribology::model::SliderModel;
use hdi_tribology::scene::Scene;
use hdi_tribology::units;
use std::ffi::CStr;
use std::ptr::{null, null_mut};

fn ok(s: HdiStatus) {
    assert_eq!(s, HdiStatus::Ok, "{}", unsafe {
        CStr::from_ptr(hdi_last_error()).to_string_lossy()
    });
}

fn last_error() -> String {
    unsafe { CStr::from_ptr(hdi_last_error()) }
        .to_string_lossy()
        .into_owned()
}

fn paper() -> *mut HdiScene {
    let mut s = null_mut();
    ok(unsafe { hdi_scene_paper(&mut s) });
    s
}

fn same(what: &str, c: f64, rust: f64) {
    assert_eq!(c.to_bits(), rust.to_bits(), "{what}: C {c}, Rust {rust}");
}

/// The C sensors equal the Rust sensors, field by field: the same names and units.
fn same_sensors(k: usize, c: &HdiSensors, r: &Sensors) {
    let t = &r.truth;
    let pairs = [
        ("time_s", c.time_s, r.time_s),
        ("heater_power_mw", c.heater_power_mw, r.heater_power_mw),
        (
            "contact_resistance_ohm",
            c.contact_resistance_ohm,
            r.contact_resistance_ohm,
        ),
        ("acoustic_v", c.acoustic_v, r.acoustic_v),
        (
            "readback_fundamental_v",
            c.readback_fundamental_v,
            r.readback.fundamental_v,
        ),
        ("readback_third_v", c.readback_third_v, r.readback.third_v),
        ("gap_nm", c.truth.gap_nm, t.gap_nm),
        ("pad_gap_nm", c.truth.pad_gap_nm, t.pad_gap_nm),
        (
            "displacement_nm",
            c.truth.displacement_nm,
            t.displacement_nm,
        ),
        (
            "velocity_mm_per_s",
            c.truth.velocity_mm_per_s,
            t.velocity_mm_per_s,
        ),
        ("protrusion_nm", c.truth.protrusion_nm, t.protrusion_nm),
        (
            "mean_contact_force_un",
            c.truth.mean_contact_force_un,
            t.mean_contact_force_un,
        ),
        (
            "contact_force_un",
            c.truth.contact_force_un,
            t.contact_force_un,
        ),
        (
            "interface_force_un",
            c.truth.interface_force_un,
            t.interface_force_un,
        ),
        (
            "mean_flash_temperature_k",
            c.truth.mean_flash_temperature_k,
            t.mean_flash_temperature_k,
        ),
        (
            "friction_power_mw",
            c.truth.friction_power_mw,
            t.friction_power_mw,
        ),
        (
            "sensor_temperature_k",
            c.truth.sensor_temperature_k,
            t.sensor_temperature_k,
        ),
        ("disk_height_nm", c.truth.disk_height_nm, t.disk_height_nm),
        ("ambient_k", c.truth.ambient_k, t.ambient_k),
    ];
    for (name, a, b) in pairs {
        same(&format!("period {k}: {name}"), a, b);
    }
}

#[test]
fn versions() {
    let v = unsafe { CStr::from_ptr(hdi_version()) }.to_str().unwrap();
    let root = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../Cargo.toml"))
        .expect("the library's Cargo.toml");
    assert!(
        root.contains(&format!("\nversion = \"{v}\"\n")),
        "hdi_version {v} is not the library's version"
    );
    assert_eq!(hdi_abi_version(), HDI_ABI_VERSION);
    let name = unsafe { CStr::from_ptr(hdi_status_name(HdiStatus::InvalidInput as i32)) };
    assert_eq!(name.to_str().unwrap(), "HDI_STATUS_INVALID_INPUT");
    let all = [
        (HdiStatus::Ok, "OK"),
        (HdiStatus::NullPointer, "NULL_POINTER"),
        (HdiStatus::InvalidHandle, "INVALID_HANDLE"),
        (HdiStatus::WrongHandleType, "WRONG_HANDLE_TYPE"),
        (HdiStatus::Busy, "BUSY"),
        (HdiStatus::InvalidInput, "INVALID_INPUT"),
        (HdiStatus::Scene, "SCENE"),
        (HdiStatus::Io, "IO"),
        (HdiStatus::NoConvergence, "NO_CONVERGENCE"),
        (HdiStatus::Analysis, "ANALYSIS"),
        (HdiStatus::Integration, "INTEGRATION"),
        (HdiStatus::Other, "OTHER"),
        (HdiStatus::Panic, "PANIC"),
    ];
    let name = |i: i32| {
        unsafe { CStr::from_ptr(hdi_status_name(i)) }
            .to_str()
            .unwrap()
    };
    for (s, n) in all {
        assert_eq!(name(s as i32), format!("HDI_STATUS_{n}"));
    }
    for i in [-1, all.len() as i32, i32::MAX] {
        assert_eq!(name(i), "HDI_STATUS_UNKNOWN");
    }
}

/// A drive with a changed zone, disk, ambient drift and step and sensors, under a ramp with a
/// dither and a DC voltage, steps as the Rust drive with the same options, to the bit.
#[test]
fn configured_drive_steps_as_the_rust_drive() {
    let harmonics = [
        HdiHarmonic {
            order: 1,
            amplitude_nm: 500.0,
            phase_rad: 0.25,
        },
        HdiHarmonic {
            order: 30,
            amplitude_nm: 0.2,
            phase_rad: 1.0,
        },
    ];
    let mut config = std::mem::MaybeUninit::uninit();
    ok(unsafe { hdi_drive_config_default(config.as_mut_ptr()) });
    let mut config: HdiDriveConfig = unsafe { config.assume_init() };
    config.radius_mm = 30.0;
    config.rpm = 7200.0;
    config.initial_heater_power_mw = 62.0;
    config.heater_time_constant_us = 50.0;
    // The run-out of phase 0.25 among the harmonics, not the phase-0 one.
    config.disk.runout_nm = 0.0;
    config.disk.harmonics = harmonics.as_ptr();
    config.disk.harmonic_count = harmonics.len();
    config.disk.random_rms_nm = 0.1;
    config.disk.random_order_min = 10;
    config.disk.random_order_max = 100;
    config.ambient = HdiAmbient {
        rate_k_per_s: 200.0,
        amplitude_k: 0.5,
        period_s: 0.004,
        clearance_per_kelvin_nm: 0.05,
        step_k: 2.0,
        step_time_s: 0.01,
    };
    config.sensors.contact.noise_ohm = 0.01;
    config.sensors.contact.bandwidth_khz = 20.0;
    config.sensors.acoustic.noise_v = 1e-3;
    config.sensors.readback.wavelength_nm = 80.0;
    config.atol_flight_pm = 1.0;
    let scene = paper();
    let mut drive = null_mut();
    ok(unsafe { hdi_drive_new(scene, &config, 42, &mut drive) });

    let s = Scene::paper();
    let mut sensors = hdi_tribology::drive::SensorSpec::default();
    sensors.contact.noise = 0.01;
    sensors.contact.bandwidth = units::khz(20.0);
    sensors.acoustic.noise = 1e-3;
    sensors.readback.wavelength = units::nm(80.0);
    let opts = DriveOptions {
        initial_power: units::mw(62.0),
        heater_time_constant: 50.0 * 1e-6,
        disk: DiskSpec {
            harmonics: vec![
                Harmonic {
                    order: 1,
                    amplitude: units::nm(500.0),
                    phase: 0.25,
                },
                Harmonic {
                    order: 30,
                    amplitude: units::nm(0.2),
                    phase: 1.0,
                },
            ],
            random_rms: units::nm(0.1),
            random_orders: (10, 100),
        },
        ambient: Ambient {
            rate: 200.0,
            amplitude: 0.5,
            period: 0.004,
            clearance_per_kelvin: units::nm(0.05),
            step: 2.0,
            step_time: 0.01,
        },
        sensors,
        atol_displacement_flight: 1.0 * 1e-12,
        ..DriveOptions::default()
    };
    let zone = zone_at(&s, 30.0 * 1e-3, Some(7200.0)).unwrap();
    let plant = Plant::new(&s, &zone, 42, opts).unwrap();
    let mut rust = plant.into_drive().unwrap();
    let mut c = HdiSensors::default();
    for k in 0..300 {
        let cmd = HdiCommand {
            heater_power_mw: 62.0 + 0.05 * k as f64,
            dc_voltage_v: 0.3,
            ac_amplitude_v: if k > 150 { 0.2 } else { 0.0 },
            ac_frequency_khz: 10.5,
        };
        ok(unsafe { hdi_drive_step(drive, &cmd, 50e-6, &mut c) });
        let r = rust
            .step(
                &Command {
                    dc_voltage_v: 0.3,
                    ..Command::heater_mw(cmd.heater_power_mw)
                }
                .with_dither(cmd.ac_amplitude_v, 10.5),
                50e-6,
            )
            .unwrap();
        same_sensors(k, &c, &r);
    }
    // The drift and the step are in: ΔT = rate·t + amplitude·sin(2πt/period) + step at the
    // last period's start (past the step's time).
    let t0 = 299.0 * 50e-6;
    let want = 200.0 * t0 + 0.5 * (2.0 * std::f64::consts::PI * t0 / 0.004).sin() + 2.0;
    assert!(
        (c.truth.ambient_k - want).abs() < 1e-9,
        "{} K, expected {want} K",
        c.truth.ambient_k
    );
    assert!(c.truth.disk_height_nm.abs() > 1.0);
    let mut t = 0.0;
    ok(unsafe { hdi_drive_time(drive, &mut t) });
    same("time", t, rust.time());
    ok(unsafe { hdi_drive_free(drive) });
    ok(unsafe { hdi_scene_free(scene) });
}

#[test]
fn analyses_equal_the_rust_analyses() {
    let scene = paper();
    let mut model = null_mut();
    ok(unsafe { hdi_model_new(scene, &mut model) });
    ok(unsafe { hdi_scene_free(scene) });
    let s = Scene::paper();
    let m = SliderModel::from_scene(&s).unwrap();
    let p = Protocol::from_scene(&s).unwrap();

    let mut h = std::mem::MaybeUninit::uninit();
    ok(unsafe { hdi_model_hysteresis(model, null(), h.as_mut_ptr()) });
    let h: HdiHysteresis = unsafe { h.assume_init() };
    let r = analysis::static_hysteresis(&m, &p.statics).unwrap();
    same("touchdown", h.touchdown.power_mw, r.touchdown.power_mw());
    same(
        "touchdown gap",
        h.touchdown.gap_nm,
        units::to_nm(r.touchdown.at.d),
    );
    same("take-off", h.takeoff.power_mw, r.takeoff.power_mw());
    same("hysteresis", h.hysteresis_mw, r.hysteresis_mw());
    assert_eq!(h.touchdown.cause, HdiCause::Fold);

    // Take-off from where the hysteresis starts it: the same transition.
    let mut t = std::mem::MaybeUninit::uninit();
    let start = h.touchdown.power_mw + 30.0;
    ok(unsafe { hdi_model_takeoff(model, null(), start, t.as_mut_ptr()) });
    let t: HdiTransition = unsafe { t.assume_init() };
    let rt = analysis::takeoff_power(&m, units::mw(start), &p.statics).unwrap();
    same("take-off from start", t.power_mw, rt.power_mw());

    // A threshold of 10 µN: given in µN, used in N.
    let opts = HdiStaticOptions {
        contact_threshold_un: 10.0,
        takeoff_start_excess_mw: 30.0,
    };
    let mut td = std::mem::MaybeUninit::uninit();
    ok(unsafe { hdi_model_touchdown(model, &opts, td.as_mut_ptr()) });
    let td: HdiTransition = unsafe { td.assume_init() };
    let rtd = analysis::touchdown_power(&m, &analysis::StaticOptions::new(10.0 * 1e-6)).unwrap();
    same("touchdown at 10 µN", td.power_mw, rtd.power_mw());

    let mut pi = std::mem::MaybeUninit::uninit();
    ok(unsafe { hdi_model_pull_in(model, null(), 20.0, pi.as_mut_ptr()) });
    let pi: HdiPullIn = unsafe { pi.assume_init() };
    let rpi = analysis::pull_in_voltage(&m, units::mw(20.0), &p.statics).unwrap();
    same("pull-in", pi.voltage_v, rpi.voltage);
    same("pull-in gap", pi.gap_nm, units::to_nm(rpi.d));

    // One cycle at 0.3 V.
    let mut c = HdiCycle::default();
    let copts = HdiCycleOptions {
        ac_amplitude_v: 0.3,
        triggered: 0,
    };
    ok(unsafe { hdi_model_cycle(model, &copts, &mut c) });
    let with_ac = m.with_voltage(hdi_tribology::model::Voltage {
        ac_amplitude: 0.3,
        ..m.voltage()
    });
    let rc = analysis::simulate_cycle(&with_ac, &p.fixed, &p.cycle).unwrap();
    assert!(c.touchdown_detected && c.takeoff_detected);
    same(
        "cycle touchdown",
        c.touchdown_power_mw,
        rc.touchdown.unwrap().power_mw(),
    );
    same(
        "cycle take-off time",
        c.takeoff_time_s,
        rc.takeoff.unwrap().time,
    );
    same(
        "cycle hysteresis",
        c.hysteresis_mw,
        rc.hysteresis_mw().unwrap(),
    );
    assert_eq!(c.accepted_steps, rc.stats.accepted as u64);
    ok(unsafe { hdi_model_free(model) });
}

/// Two threads stepping one drive: each call either runs alone or is refused as busy, and the
/// drive's time counts exactly the calls that ran.
#[test]
fn a_drive_takes_one_call_at_a_time() {
    let scene = paper();
    let mut drive = null_mut();
    ok(unsafe { hdi_drive_new(scene, null(), 1, &mut drive) });
    ok(unsafe { hdi_scene_free(scene) });
    let addr = drive as usize;
    let worker = move || {
        let drive = addr as *mut HdiDrive;
        let (mut ran, mut busy) = (0u64, 0u64);
        let mut s = HdiSensors::default();
        let cmd = HdiCommand {
            heater_power_mw: 65.0,
            ..HdiCommand::default()
        };
        for _ in 0..400 {
            match unsafe { hdi_drive_step(drive, &cmd, 50e-6, &mut s) } {
                HdiStatus::Ok => ran += 1,
                HdiStatus::Busy => {
                    assert!(last_error().contains("in use by a call on another thread"));
                    busy += 1
                }
                other => panic!("{other:?}: {}", last_error()),
            }
        }
        (ran, busy)
    };
    let a = std::thread::spawn(worker);
    let b = std::thread::spawn(worker);
    let (ra, ba) = a.join().unwrap();
    let (rb, bb) = b.join().unwrap();
    assert_eq!(ra + ba + rb + bb, 800);
    let mut t = 0.0;
    ok(unsafe { hdi_drive_time(drive, &mut t) });
    let ran = (ra + rb) as f64;
    assert!(
        (t - ran * 50e-6).abs() < 1e-12,
        "time {t} s after {ran} periods"
    );
    ok(unsafe { hdi_drive_free(drive) });
}

/// A model cannot be freed while a call on another thread reads it.
#[test]
fn a_handle_in_use_is_not_freed() {
    let mut seen_busy = false;
    for _ in 0..20 {
        let scene = paper();
        let mut model = null_mut();
        ok(unsafe { hdi_model_new(scene, &mut model) });
        ok(unsafe { hdi_scene_free(scene) });
        let addr = model as usize;
        let (tx, rx) = std::sync::mpsc::channel();
        // A slow call: a cycle at 0.6 V (tens of milliseconds).
        let reader = std::thread::spawn(move || {
            tx.send(()).unwrap();
            let opts = HdiCycleOptions {
                ac_amplitude_v: 0.6,
                triggered: 0,
            };
            let mut c = HdiCycle::default();
            unsafe { hdi_model_cycle(addr as *const HdiModel, &opts, &mut c) }
        });
        rx.recv().unwrap();
        std::thread::sleep(std::time::Duration::from_millis(2));
        let freed = match unsafe { hdi_model_free(model) } {
            HdiStatus::Busy => {
                assert!(last_error().contains("in use"), "{}", last_error());
                seen_busy = true;
                false
            }
            HdiStatus::Ok => true,
            other => panic!("{other:?}: {}", last_error()),
        };
        let read = reader.join().unwrap();
        if freed {
            // Freed before the reader took it: the reader was refused, not let in.
            assert!(matches!(read, HdiStatus::Ok | HdiStatus::InvalidHandle));
            continue;
        }
        assert_eq!(read, HdiStatus::Ok);
        ok(unsafe { hdi_model_free(model) });
        break;
    }
    assert!(seen_busy, "no free was refused in 20 tries");
}

fn scene_toml(extra: &str) -> *mut HdiScene {
    let text = format!("{}\n{extra}", Scene::paper().to_toml_string().unwrap());
    let c = std::ffi::CString::new(text).unwrap();
    let mut s = null_mut();
    ok(unsafe { hdi_scene_from_toml(c.as_ptr(), &mut s) });
    s
}

const DRIVE_SECTION: &str = "[drive]\nheads = 3\nrpm = 7200\ninitial_heater_power_mw = 62\n\
    [drive.disk]\nrunout_nm = 500\nwaviness_rms_nm = 0.2\n\
    [drive.ambient]\nrate_k_per_s = 50\nstep_k = 1.5\nstep_time_s = 0.002\n\
    [drive.sensors]\nreadback_wavelength_nm = 80\ncontact_noise_ohm = 0.01\n";

/// A scene's `[drive]` section builds, through the C ABI (with a `NULL` config or the config
/// `hdi_drive_config_from_scene` gives), the drive `hdi drive` builds on the scene: three heads
/// stepped together, each equal to the Rust drive's head to the bit.
#[test]
fn the_scene_drive_section_builds_the_rust_drive_of_several_heads() {
    let scene = scene_toml(DRIVE_SECTION);
    let mut config = std::mem::MaybeUninit::uninit();
    ok(unsafe { hdi_drive_config_from_scene(scene, config.as_mut_ptr()) });
    let config: HdiDriveConfig = unsafe { config.assume_init() };
    assert_eq!((config.heads, config.rpm), (3, 7200.0));
    assert_eq!(config.initial_heater_power_mw, 62.0);
    assert_eq!(
        (config.ambient.step_k, config.ambient.step_time_s),
        (1.5, 0.002)
    );
    assert!((config.disk.runout_nm - 500.0).abs() < 1e-9);
    let (mut a, mut b) = (null_mut(), null_mut());
    ok(unsafe { hdi_drive_new(scene, null(), 9, &mut a) });
    ok(unsafe { hdi_drive_new(scene, &config, 9, &mut b) });
    let mut heads = 0;
    ok(unsafe { hdi_drive_heads(a, &mut heads) });
    assert_eq!(heads, 3);

    let s = Scene::from_toml_str(&format!(
        "{}\n{DRIVE_SECTION}",
        Scene::paper().to_toml_string().unwrap()
    ))
    .unwrap();
    let spec = s.drive.clone().unwrap();
    let zone = spec_zone(&s, &spec).unwrap();
    let plant = MultiPlant::uniform(&s, &zone, 3, 9, DriveOptions::from_spec(&spec)).unwrap();
    let mut rust = plant.drive().unwrap();
    let mut ca = [HdiSensors::default(); 3];
    let mut cb = [HdiSensors::default(); 3];
    for n in 0..120 {
        let cmds: Vec<HdiCommand> = (0..3)
            .map(|k| HdiCommand {
                heater_power_mw: 62.0 + 0.1 * (n * (k + 1)) as f64,
                ..HdiCommand::default()
            })
            .collect();
        ok(unsafe { hdi_drive_step_heads(a, cmds.as_ptr(), 3, 50e-6, ca.as_mut_ptr()) });
        ok(unsafe { hdi_drive_step_heads(b, cmds.as_ptr(), 3, 50e-6, cb.as_mut_ptr()) });
        let rc: Vec<Command> = cmds
            .iter()
            .map(|c| Command::heater_mw(c.heater_power_mw))
            .collect();
        let r = rust.step(&rc, 50e-6).unwrap();
        for k in 0..3 {
            same_sensors(n, &ca[k], &r[k]);
            same_sensors(n, &cb[k], &r[k]);
        }
    }
    // Head 2 alone is the one-head drive of its seed.
    let one = Plant::new(&s, &zone, head_seed(9, 2), DriveOptions::from_spec(&spec)).unwrap();
    assert_eq!(rust.head(2).unwrap().plant().seed(), one.seed());
    // The ambient step is in.
    assert!(ca[0].truth.ambient_k > 1.5);
    ok(unsafe { hdi_drive_free(a) });
    ok(unsafe { hdi_drive_free(b) });
    ok(unsafe { hdi_scene_free(scene) });
}

/// The misuses of a drive of several heads get a status and a message naming the argument.
#[test]
fn several_heads_are_stepped_together() {
    let scene = paper();
    let mut config = std::mem::MaybeUninit::uninit();
    ok(unsafe { hdi_drive_config_default(config.as_mut_ptr()) });
    let mut config: HdiDriveConfig = unsafe { config.assume_init() };
    assert_eq!(config.heads, 1);
    let mut drive = null_mut();
    config.heads = 0;
    let st = unsafe { hdi_drive_new(scene, &config, 1, &mut drive) };
    assert_eq!(st, HdiStatus::InvalidInput);
    assert!(last_error().contains("config.heads"), "{}", last_error());
    assert!(drive.is_null());
    config.heads = 2;
    ok(unsafe { hdi_drive_new(scene, &config, 1, &mut drive) });
    let cmd = HdiCommand {
        heater_power_mw: 60.0,
        ..HdiCommand::default()
    };
    let mut s = [HdiSensors::default(); 2];
    let st = unsafe { hdi_drive_step(drive, &cmd, 50e-6, s.as_mut_ptr()) };
    assert_eq!(st, HdiStatus::InvalidInput);
    assert!(
        last_error().contains("hdi_drive_step_heads"),
        "{}",
        last_error()
    );
    let st = unsafe { hdi_drive_step_heads(drive, &cmd, 1, 50e-6, s.as_mut_ptr()) };
    assert_eq!(st, HdiStatus::InvalidInput);
    assert!(last_error().contains("count"), "{}", last_error());
    let bad = [
        cmd,
        HdiCommand {
            heater_power_mw: -1.0,
            ..cmd
        },
    ];
    let st = unsafe { hdi_drive_step_heads(drive, bad.as_ptr(), 2, 50e-6, s.as_mut_ptr()) };
    assert_eq!(st, HdiStatus::InvalidInput);
    assert!(
        last_error().contains("commands[1].heater_power_mw"),
        "{}",
        last_error()
    );
    let big = [
        HdiCommand {
            heater_power_mw: 2000.0,
            ..cmd
        },
        cmd,
    ];
    let st = unsafe { hdi_drive_step_heads(drive, big.as_ptr(), 2, 50e-6, s.as_mut_ptr()) };
    assert_eq!(st, HdiStatus::InvalidInput);
    assert!(
        last_error().contains("commands[0].heater_power_mw"),
        "{}",
        last_error()
    );
    let st = unsafe { hdi_drive_step_heads(drive, [cmd, cmd].as_ptr(), 2, 0.0, s.as_mut_ptr()) };
    assert_eq!(st, HdiStatus::InvalidInput);
    assert!(last_error().contains("period_s"), "{}", last_error());
    let st = unsafe { hdi_drive_step_heads(drive, null(), 2, 50e-6, s.as_mut_ptr()) };
    assert_eq!(st, HdiStatus::NullPointer);
    let mut t = -1.0;
    ok(unsafe { hdi_drive_time(drive, &mut t) });
    assert_eq!(t, 0.0, "nothing moved");
    ok(unsafe { hdi_drive_step_heads(drive, [cmd, cmd].as_ptr(), 2, 50e-6, s.as_mut_ptr()) });
    assert_eq!(s[0].time_s, s[1].time_s);
    assert_ne!(s[0].truth.disk_height_nm, s[1].truth.disk_height_nm);
    let mut model = null_mut();
    assert_eq!(
        unsafe { hdi_drive_head_model(drive, 2, &mut model) },
        HdiStatus::InvalidInput
    );
    assert!(last_error().contains("head"), "{}", last_error());
    ok(unsafe { hdi_drive_head_model(drive, 1, &mut model) });
    ok(unsafe { hdi_model_free(model) });
    ok(unsafe { hdi_drive_free(drive) });
    // A one-head step names its command as `command`.
    let mut one = null_mut();
    ok(unsafe { hdi_drive_new(scene, null(), 1, &mut one) });
    let big = HdiCommand {
        heater_power_mw: 2000.0,
        ..cmd
    };
    let st = unsafe { hdi_drive_step(one, &big, 50e-6, s.as_mut_ptr()) };
    assert_eq!(st, HdiStatus::InvalidInput);
    assert!(
        last_error().contains("command.heater_power_mw"),
        "{}",
        last_error()
    );
    ok(unsafe { hdi_drive_free(one) });
    ok(unsafe { hdi_scene_free(scene) });
}

/// The bounded mode through the C ABI: the same drive as the Rust `DriveOptions::bounded`, to
/// the bit; each period's steps and error estimate from `hdi_drive_last_period`; a bound out of
/// range and a head out of range are named.
#[test]
fn the_bounded_mode_reports_its_flag() {
    let scene = paper();
    let mut config = std::mem::MaybeUninit::uninit();
    ok(unsafe { hdi_drive_config_default(config.as_mut_ptr()) });
    let mut config: HdiDriveConfig = unsafe { config.assume_init() };
    assert_eq!(config.steps_per_period, 0);
    let mut drive = null_mut();
    config.steps_per_period = 65;
    let st = unsafe { hdi_drive_new(scene, &config, 1, &mut drive) };
    assert_eq!(st, HdiStatus::InvalidInput);
    assert!(
        last_error().contains("config.steps_per_period"),
        "{}",
        last_error()
    );
    config.steps_per_period = 4;
    ok(unsafe { hdi_drive_new(scene, &config, 1, &mut drive) });
    let s = Scene::paper();
    let plant = Plant::new(
        &s,
        &zone_at(&s, 0.025, None).unwrap(),
        1,
        DriveOptions::default().bounded(4),
    )
    .unwrap();
    let mut rust = plant.drive().unwrap();
    let cmd = HdiCommand {
        heater_power_mw: 68.0,
        ac_amplitude_v: 0.5,
        ac_frequency_khz: 10.5,
        ..HdiCommand::default()
    };
    let rcmd = Command::heater_mw(68.0).with_dither(0.5, 10.5);
    let mut missed = 0;
    for k in 0..40 {
        let mut out = HdiSensors::default();
        ok(unsafe { hdi_drive_step(drive, &cmd, 50e-6, &mut out) });
        let r = rust.step(&rcmd, 50e-6).unwrap();
        same_sensors(k, &out, &r);
        let mut p = HdiPeriod::default();
        ok(unsafe { hdi_drive_last_period(drive, 0, &mut p) });
        let q = rust.last_period();
        assert_eq!(
            (p.steps as usize, p.error_estimate),
            (q.steps, q.error_estimate)
        );
        assert!(p.steps <= 5);
        missed += usize::from(p.error_estimate > 1.0);
    }
    assert!(
        missed > 0,
        "the dither at 4 steps a period misses the tolerances"
    );
    let mut p = HdiPeriod::default();
    let st = unsafe { hdi_drive_last_period(drive, 1, &mut p) };
    assert_eq!(st, HdiStatus::InvalidInput);
    assert!(last_error().contains("head"), "{}", last_error());
    ok(unsafe { hdi_drive_free(drive) });
    ok(unsafe { hdi_scene_free(scene) });
}

/// A bounded drive whose path leaves the force tables stops with `HDI_STATUS_ANALYSIS` and a
/// message that names the tables (docs/firmware.md): the paper scene's tables cut off at
/// 0.62 nm, above the contact a heater at 120 mW settles into.
#[test]
fn a_bounded_drive_that_leaves_the_tables_says_so() {
    let mut s = Scene::paper();
    s.table.d_min_m = Some(6.2e-10);
    let text = std::ffi::CString::new(s.to_toml_string().unwrap()).unwrap();
    let mut scene = null_mut();
    ok(unsafe { hdi_scene_from_toml(text.as_ptr(), &mut scene) });
    let mut config = std::mem::MaybeUninit::uninit();
    ok(unsafe { hdi_drive_config_default(config.as_mut_ptr()) });
    let mut config: HdiDriveConfig = unsafe { config.assume_init() };
    config.steps_per_period = 8;
    let mut drive = null_mut();
    ok(unsafe { hdi_drive_new(scene, &config, 1, &mut drive) });
    let cmd = HdiCommand {
        heater_power_mw: 120.0,
        ..HdiCommand::default()
    };
    let mut status = HdiStatus::Ok;
    for _ in 0..60 {
        let mut out = HdiSensors::default();
        status = unsafe { hdi_drive_step(drive, &cmd, 50e-6, &mut out) };
        if status != HdiStatus::Ok {
            break;
        }
    }
    assert_eq!(status, HdiStatus::Analysis, "{}", last_error());
    let e = last_error();
    assert!(e.contains("0.620 to") && e.contains("table.d_min_m"), "{e}");
    ok(unsafe { hdi_drive_free(drive) });
    ok(unsafe { hdi_scene_free(scene) });
}

/// The exponential scheme through the C ABI: the same drive as the Rust one with
/// `DriveScheme::Exponential`, to the bit, each period's scheme in `HdiPeriod::exponential`,
/// most of 80 periods the scheme's (the start's transient replaces its first tables within a
/// few periods, and the periods after them go to the integrator); a scheme that does not exist
/// is named.
#[test]
fn the_exponential_scheme_is_the_rust_one() {
    let scene = paper();
    let mut config = std::mem::MaybeUninit::uninit();
    ok(unsafe { hdi_drive_config_default(config.as_mut_ptr()) });
    let mut config: HdiDriveConfig = unsafe { config.assume_init() };
    assert_eq!(config.scheme, HDI_SCHEME_INTEGRATOR);
    let mut drive = null_mut();
    config.scheme = 7;
    let st = unsafe { hdi_drive_new(scene, &config, 1, &mut drive) };
    assert_eq!(st, HdiStatus::InvalidInput);
    assert!(last_error().contains("config.scheme"), "{}", last_error());
    config.scheme = HDI_SCHEME_EXPONENTIAL;
    ok(unsafe { hdi_drive_new(scene, &config, 1, &mut drive) });
    let s = Scene::paper();
    let opts = DriveOptions {
        scheme: DriveScheme::Exponential,
        ..DriveOptions::default()
    };
    let plant = Plant::new(&s, &zone_at(&s, 0.025, None).unwrap(), 1, opts).unwrap();
    let mut rust = plant.drive().unwrap();
    let mut own = 0;
    let periods = 80;
    for k in 0..periods {
        // A command changed every period: the case the scheme is for.
        let p = 66.0 + if k % 2 == 1 { 0.001 } else { 0.0 };
        let cmd = HdiCommand {
            heater_power_mw: p,
            ..HdiCommand::default()
        };
        let mut out = HdiSensors::default();
        ok(unsafe { hdi_drive_step(drive, &cmd, 50e-6, &mut out) });
        let r = rust.step(&Command::heater_mw(p), 50e-6).unwrap();
        same_sensors(k, &out, &r);
        let mut q = HdiPeriod::default();
        ok(unsafe { hdi_drive_last_period(drive, 0, &mut q) });
        assert_eq!(q.exponential, rust.last_period().exponential);
        own += usize::from(q.exponential);
    }
    assert!(
        own > periods / 2,
        "{own} of {periods} periods by the exponential scheme"
    );
    ok(unsafe { hdi_drive_free(drive) });
    ok(unsafe { hdi_scene_free(scene) });
}
