//! The simulated drive as a plant: steady states against the static model, determinism, the
//! harmonic-ratio clearance change against the true one, typed errors.

use hdi_tribology::analysis::{flying_equilibrium, ScanGrid};
use hdi_tribology::drive::{scene_zone, Command, DiskSpec, Drive, DriveOptions, Plant, Sensors};
use hdi_tribology::scene::Scene;
use hdi_tribology::Error;

const DT: f64 = 50e-6;

fn plant(seed: u64, disk: DiskSpec) -> Plant {
    let scene = Scene::paper();
    let zone = scene_zone(&scene, 0.025).unwrap();
    let opts = DriveOptions {
        disk,
        ..DriveOptions::default()
    };
    Plant::new(&scene, &zone, seed, opts).unwrap()
}

fn hold(d: &mut Drive, p_mw: f64, steps: usize) -> Vec<Sensors> {
    (0..steps)
        .map(|_| d.step(&Command::heater_mw(p_mw), DT).unwrap())
        .collect()
}

#[test]
fn steady_gap_is_the_static_flying_equilibrium() {
    let p = plant(3, DiskSpec::flat());
    let mut d = p.drive().unwrap();
    let model = d.model().clone();
    for p_mw in [60.0, 66.0, 72.0] {
        // 4 ms: 40 heater time constants, ~90 decay times of the air-bearing mode.
        let s = *hold(&mut d, p_mw, 80).last().unwrap();
        let eq = flying_equilibrium(&model, p_mw * 1e-3, 0.0, &ScanGrid::default()).unwrap();
        assert!(
            (s.truth.gap - eq.d).abs() < 1e-13,
            "{p_mw} mW: drive {} nm, static {} nm",
            s.truth.gap * 1e9,
            eq.d * 1e9
        );
    }
}

#[test]
fn same_seed_same_stream_bit_for_bit() {
    let run = |seed| {
        let p = plant(seed, DiskSpec::default());
        let mut d = p.drive().unwrap();
        let mut v = hold(&mut d, 70.0, 30);
        v.extend(hold(&mut d, 75.0, 30));
        v
    };
    let (a, b, c) = (run(11), run(11), run(12));
    let bits = |v: &[Sensors]| -> Vec<u64> {
        v.iter()
            .flat_map(|s| {
                [
                    s.contact_resistance,
                    s.acoustic,
                    s.readback.fundamental,
                    s.readback.third,
                    s.truth.gap,
                ]
            })
            .map(f64::to_bits)
            .collect()
    };
    assert_eq!(bits(&a), bits(&b));
    assert_ne!(bits(&a), bits(&c));
}

#[test]
fn bad_commands_are_typed_errors() {
    let p = plant(1, DiskSpec::flat());
    let mut d = p.drive().unwrap();
    let e = d.step(&Command::heater_mw(-1.0), DT).unwrap_err();
    assert!(
        matches!(e, Error::InvalidInput { ref field, .. } if field == "command.heater_power"),
        "{e}"
    );
    let e = d.step(&Command::heater_mw(60.0), 0.0).unwrap_err();
    assert!(
        matches!(e, Error::InvalidInput { ref field, .. } if field == "dt"),
        "{e}"
    );
    let e = d.step(&Command::heater_mw(60.0), f64::NAN).unwrap_err();
    assert!(
        matches!(e, Error::InvalidInput { ref field, .. } if field == "dt"),
        "{e}"
    );
}
