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

/// The default drive (Rodas5P, 0.01 pm, steps across period ends, restarts only on a new command)
/// against a tight reference (Radau5 at `rtol` 1e-10 and 1e-17 m, steps no longer than a
/// quarter period): a wavy disk, a heater staircase into contact and back, a dither, and runs of
/// unchanged commands. The gap agrees within ten times the default tolerance, and the sensors
/// (same noise) agree within a small fraction of their noise.
#[test]
fn spanning_steps_agree_with_a_tight_reference() {
    let scene = Scene::paper();
    let zone = scene_zone(&scene, 0.025).unwrap();
    let fast = Plant::new(&scene, &zone, 5, DriveOptions::default()).unwrap();
    let tight = Plant::new(
        &scene,
        &zone,
        5,
        DriveOptions {
            method: hdi_tribology::ode::Method::Radau5,
            rtol: 1e-10,
            atol_displacement: 1e-17,
            max_step: Some(DT / 4.0),
            ..DriveOptions::default()
        },
    )
    .unwrap();
    let mut programme: Vec<Command> = Vec::new();
    for mw in [62.0, 68.0, 72.0, 76.0, 78.0, 74.0, 70.0] {
        programme.extend(std::iter::repeat_n(Command::heater_mw(mw), 60));
    }
    let dithered = Command::heater_mw(72.0).with_dither(0.5, 10.5e3);
    programme.extend(std::iter::repeat_n(dithered, 40));
    // A controller that changes the command every period.
    programme.extend((0..40).map(|k| Command::heater_mw(70.0 + 0.05 * k as f64)));
    let (mut a, mut b) = (fast.drive().unwrap(), tight.drive().unwrap());
    let spec = fast.sensor_spec();
    let (mut worst_gap, mut worst_force, mut worst_r) = (0.0f64, 0.0f64, 0.0f64);
    let mut contact = 0;
    let mut ms_r = 0.0;
    let mut worst_at = (0, 0.0);
    for c in &programme {
        let (x, y) = (a.step(c, DT).unwrap(), b.step(c, DT).unwrap());
        if (x.contact_resistance - y.contact_resistance).abs() > worst_r {
            worst_at = (contact, y.truth.mean_contact_force);
        }
        worst_gap = worst_gap.max((x.truth.gap - y.truth.gap).abs());
        worst_force =
            worst_force.max((x.truth.mean_contact_force - y.truth.mean_contact_force).abs());
        worst_r = worst_r.max((x.contact_resistance - y.contact_resistance).abs());
        ms_r += (x.contact_resistance - y.contact_resistance).powi(2) / programme.len() as f64;
        if y.truth.mean_contact_force > 5e-5 {
            contact += 1;
        }
    }
    println!(
        "worst gap {:.3} pm, mean contact force {:.3} µN, contact sensor {:.2e} Ω (rms {:.2e}); {contact} periods in contact; steps {} vs {}",
        worst_gap * 1e12,
        worst_force * 1e6,
        worst_r,
        ms_r.sqrt(),
        a.stats().accepted,
        b.stats().accepted
    );
    assert!(contact > 50, "the programme should reach contact");
    // Ten times the displacement tolerance (0.1 pm); 0.1 µN of period-mean contact force (the
    // contact sensor resolves ~0.2 µN per period in contact, where the force changes by ~4 µN
    // per pm of gap).
    assert!(worst_gap < 1e-13, "gap differs by {worst_gap} m");
    assert!(
        worst_force < 1e-7,
        "mean contact force differs by {worst_force} N"
    );
    // The worst period is the jump into contact, where the mean contact force rises from a few
    // µN to a millinewton within the period; even there the contact sensor differs by a small
    // fraction of its noise, and over the run by a tiny one.
    println!(
        "worst contact-sensor period: after {} periods in contact, mean force {:.1} µN",
        worst_at.0,
        worst_at.1 * 1e6
    );
    assert!(
        worst_r < 0.2 * spec.contact.noise,
        "contact sensor differs by {worst_r} Ω"
    );
    assert!(
        ms_r.sqrt() < 0.01 * spec.contact.noise,
        "contact sensor differs by {} Ω rms",
        ms_r.sqrt()
    );
}

/// A `Drive` owns its plant: no borrow, `'static`, so another language's runtime can hold one.
/// (It is not `Send`: the integrator's events are boxed closures without `Send`.)
#[test]
fn a_drive_is_owned() {
    fn owned<T: 'static>(t: T) -> T {
        t
    }
    let mut d = owned(plant(1, DiskSpec::flat()).into_drive().unwrap());
    assert!(d.step(&Command::heater_mw(60.0), DT).unwrap().truth.gap > 0.0);
}
