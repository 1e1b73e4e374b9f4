//! The drive's bounded mode (`DriveOptions::steps_per_period`): at most `n` steps a period,
//! the error estimate as a flag, and what it costs in accuracy against a tight reference.

use hdi_tribology::drive::{
    scene_zone, Command, DiskSpec, Drive, DriveError, DriveOptions, Plant, SensorSpec, Sensors,
};
use hdi_tribology::ode::Method;
use hdi_tribology::scene::Scene;
use hdi_tribology::Error;

const DT: f64 = 50e-6;

fn plant(disk: DiskSpec, opts: DriveOptions) -> Plant {
    let scene = Scene::paper();
    let zone = scene_zone(&scene, 0.025).unwrap();
    Plant::new(&scene, &zone, 3, DriveOptions { disk, ..opts }).unwrap()
}

fn bounded(n: usize) -> DriveOptions {
    DriveOptions::default().bounded(n)
}

/// A tight reference: Radau5 at `rtol` 1e-10 and 1e-17 m, steps of at most a quarter period.
fn tight() -> DriveOptions {
    DriveOptions {
        method: Method::Radau5,
        rtol: 1e-10,
        atol_displacement: 1e-17,
        atol_displacement_flight: 1e-17,
        max_step: Some(DT / 4.0),
        ..DriveOptions::default()
    }
}

/// A programme: a heater staircase in flight, a 0.5 V dither, a command changed every period.
fn flight_programme() -> Vec<Command> {
    let mut p = Vec::new();
    for mw in [62.0, 66.0, 70.0, 68.0] {
        p.extend(std::iter::repeat_n(Command::heater_mw(mw), 40));
    }
    p.extend(std::iter::repeat_n(
        Command::heater_mw(68.0).with_dither(0.5, 10.5),
        60,
    ));
    p.extend((0..40).map(|k| Command::heater_mw(66.0 + 0.05 * k as f64)));
    p
}

/// Runs `commands`; the sensors and the per-period steps and error estimates.
fn run(d: &mut Drive, commands: &[Command]) -> (Vec<Sensors>, Vec<(usize, f64)>) {
    let mut s = Vec::new();
    let mut flags = Vec::new();
    for c in commands {
        s.push(d.step(c, DT).unwrap());
        let p = d.last_period();
        flags.push((p.steps, p.error_estimate));
    }
    (s, flags)
}

/// The largest contact-sensor and read-back log-ratio differences, in units of their noise
/// per period.
fn stray(a: &[Sensors], b: &[Sensors]) -> (f64, f64) {
    let spec = SensorSpec::default();
    let rb_noise = 2f64.sqrt() * spec.readback.noise;
    a.iter().zip(b).fold((0.0f64, 0.0f64), |(r, l), (x, y)| {
        (
            r.max((x.contact_resistance_ohm - y.contact_resistance_ohm).abs() / spec.contact.noise),
            l.max((x.readback.log_ratio() - y.readback.log_ratio()).abs() / rb_noise),
        )
    })
}

/// Every period ends in at most `n` steps (one more when a step shortened onto the period's
/// end ends in it too), on the wavy disk with the dither, where the adaptive drive takes up to
/// 20 a period; the flag says where the tolerance was missed, and the drive reports it.
#[test]
fn at_most_n_steps_a_period_and_the_misses_are_flagged() {
    let programme = flight_programme();
    let n = 4;
    let mut d = plant(DiskSpec::default(), bounded(n)).drive().unwrap();
    let (_, flags) = run(&mut d, &programme);
    let most = flags.iter().map(|f| f.0).max().unwrap();
    assert!(most <= n + 1, "{most} steps in a period");
    // The dither at 4 steps a period misses the tolerance (the adaptive drive needs ~20).
    let dithered = &flags[160..220];
    assert!(dithered.iter().all(|f| f.0 >= n - 1));
    assert!(dithered.iter().any(|f| f.1 > 1.0), "{dithered:?}");
    // Without the bound, the same periods take more steps, all within the tolerance.
    let mut free = plant(DiskSpec::default(), DriveOptions::default())
        .drive()
        .unwrap();
    let (_, free_flags) = run(&mut free, &programme);
    assert!(free_flags.iter().all(|f| f.1 <= 1.0));
    assert!(free_flags[160..220].iter().map(|f| f.0).max().unwrap() > 2 * n);
}

/// In flight on the wavy disk, with the dither and a command changed every period, eight steps
/// a period keep every sensor within a small fraction of its noise of a tight reference,
/// although the flag says the tolerance was missed in the dither.
#[test]
fn eight_steps_a_period_keep_the_sensors_within_their_noise_in_flight() {
    let programme = flight_programme();
    let mut reference = plant(DiskSpec::default(), tight()).drive().unwrap();
    let (truth, _) = run(&mut reference, &programme);
    let mut d = plant(DiskSpec::default(), bounded(8)).drive().unwrap();
    let (s, flags) = run(&mut d, &programme);
    let (sensor, readback) = stray(&s, &truth);
    println!("contact sensor {sensor:.4} and read-back {readback:.4} of their noise");
    assert!(sensor < 0.05, "contact sensor strays {sensor} of its noise");
    assert!(readback < 0.05, "read-back strays {readback} of its noise");
    assert!(flags.iter().any(|f| f.1 > 1.0));
}

/// In contact, Rodas5P at a bounded step fails (the contact force's curvature throws a
/// linearly implicit step far into the asperities); Radau5, the bounded mode's method, whose
/// Newton iteration copes with it, runs the snap into contact and a held contact on the wavy
/// disk. Where its Newton iteration fails at the floor (in the snap's periods), the floor's
/// backward Euler step takes the trial instead of shorter ones: every period, the snap's
/// included, ends in at most `2n` steps (the shortened trials took up to 62–63 at `n` = 8
/// and 16).
/// Once in contact, every period takes at most `n` steps and the contact sensor stays within
/// a fifth of its noise of the tight reference; where it strays further (in the snap), the
/// flag said so within the three periods before.
#[test]
fn radau5_with_the_bound_runs_in_contact() {
    let mut programme = vec![Command::heater_mw(70.0); 20];
    programme.extend(std::iter::repeat_n(Command::heater_mw(80.0), 200));
    let mut reference = plant(DiskSpec::default(), tight()).drive().unwrap();
    let (truth, _) = run(&mut reference, &programme);
    assert!(truth.last().unwrap().truth.mean_contact_force_un > 50.0);
    let noise = SensorSpec::default().contact.noise;
    for n in [8, 16] {
        let mut d = plant(DiskSpec::default(), bounded(n)).drive().unwrap();
        let (s, flags) = run(&mut d, &programme);
        let stray: Vec<f64> = s
            .iter()
            .zip(&truth)
            .map(|(a, b)| (a.contact_resistance_ohm - b.contact_resistance_ohm).abs() / noise)
            .collect();
        let settled = 40;
        assert!(d.stats().floor_steps > 0, "{:?}", d.stats());
        assert!(flags.iter().all(|f| f.0 <= 2 * n), "{flags:?}");
        assert!(flags[settled..].iter().all(|f| f.0 <= n + 1), "{flags:?}");
        let late = stray[settled..].iter().cloned().fold(0.0f64, f64::max);
        assert!(
            late < 0.2,
            "{n} steps: the contact sensor strays {late} of its noise"
        );
        for (i, &x) in stray.iter().enumerate() {
            let warned = flags[i.saturating_sub(3)..=i].iter().any(|f| f.1 > 1.0);
            assert!(x < 0.5 || warned, "period {i}: {x} of the noise, no flag");
        }
    }
}

/// Where the tolerance allows long steps (a held command on a flat disk, whose steps span
/// periods), the bound binds only in the start's transient: after it no step is forced, steps
/// span periods, and the drive reads the same as without the bound.
#[test]
fn where_the_bound_does_not_bind_nothing_is_forced() {
    let programme = vec![Command::heater_mw(66.0); 100];
    let mut a = plant(DiskSpec::flat(), DriveOptions::default())
        .drive()
        .unwrap();
    let mut b = plant(DiskSpec::flat(), bounded(2)).drive().unwrap();
    let (sa, _) = run(&mut a, &programme);
    let (sb, fb) = run(&mut b, &programme);
    assert!(fb[10..].iter().all(|f| f.1 <= 1.0 && f.0 <= 1), "{fb:?}");
    let spanned = fb[10..].iter().filter(|f| f.0 == 0).count();
    assert!(spanned > 30, "{spanned} periods spanned by one step");
    let (sensor, readback) = stray(&sa[10..], &sb[10..]);
    assert!(sensor < 1e-3 && readback < 1e-3, "{sensor}, {readback}");
}

#[test]
fn bad_bounds_are_typed_errors() {
    let scene = Scene::paper();
    let zone = scene_zone(&scene, 0.025).unwrap();
    for (opts, field) in [
        (bounded(0), "steps_per_period"),
        (bounded(65), "steps_per_period"),
        (
            DriveOptions {
                method: Method::Rodas5P,
                ..bounded(4)
            },
            "method",
        ),
    ] {
        let e = Plant::new(&scene, &zone, 1, opts).unwrap_err();
        assert!(
            matches!(e, Error::InvalidInput { field: ref f, .. } if f == field),
            "{e}"
        );
    }
}

/// The bounded mode reads the interface forces from their tables alone: a trial state outside
/// them fails its step instead of paying for direct quadrature (in the snap into contact,
/// Radau5's diverging Newton iterates reach micrometres into the disk, about 0.2 ms an
/// evaluation). With tables cut off at 0.62 nm (they must reach the mean peak height,
/// 0.627 nm) and a heater at 120 mW, whose contact sits below that, the adaptive drive runs on
/// with the exact forces there, and the bounded one stops with an error that names the tables.
#[test]
fn the_bounded_mode_reads_the_forces_from_the_tables_alone() {
    let mut scene = Scene::paper();
    scene.table.d_min_m = Some(6.2e-10);
    let zone = scene_zone(&scene, 0.025).unwrap();
    let drive = |opts: DriveOptions| Plant::new(&scene, &zone, 3, opts).unwrap().drive().unwrap();
    let to_contact = |d: &mut Drive| -> Result<Sensors, Error> {
        let mut last = d.step(&Command::heater_mw(120.0), DT)?;
        for _ in 1..60 {
            last = d.step(&Command::heater_mw(120.0), DT)?;
        }
        Ok(last)
    };
    let adaptive = to_contact(&mut drive(DriveOptions::default())).unwrap();
    assert!(adaptive.truth.gap_nm < 0.6, "{adaptive:?}");
    let e = to_contact(&mut drive(bounded(8))).unwrap_err();
    let Error::Analysis(a) = &e else {
        panic!("{e:?}")
    };
    let Some(DriveError::LeftTheTables { table_low_nm, .. }) = a.downcast_ref() else {
        panic!("{e}")
    };
    assert!((table_low_nm - 0.62).abs() < 1e-9, "{e}");
    assert!(e.to_string().contains("table.d_min_m"), "{e}");
}
