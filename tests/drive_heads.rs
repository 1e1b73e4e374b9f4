//! A drive of several heads: each head's sensors equal a one-head drive's to the bit (the heads
//! do not interact), one clock, one spindle, each surface its own; typed errors.

use hdi_tribology::drive::{
    head_seed, scene_zone, Command, DriveError, DriveOptions, MultiPlant, Plant, Sensors,
};
use hdi_tribology::scene::Scene;
use hdi_tribology::Error;

const DT: f64 = 50e-6;

/// Every field of a period's sensors, as text that differs whenever a bit does (shortest
/// round-trip digits, the sign of zero kept).
fn bits(s: &Sensors) -> String {
    format!("{s:?}")
}

/// Head `k`'s command in period `n`: each head its own heater programme, head 1 ramped past
/// touchdown (contact, where the integration is most sensitive), with a dither on head 2.
fn command(k: usize, n: usize) -> Command {
    match k {
        0 => Command::heater_mw(if n < 40 { 60.0 } else { 70.0 }),
        1 => Command::heater_mw(70.0 + 0.2 * n as f64),
        _ => Command::heater_mw(65.0).with_dither(0.5, 10.0),
    }
}

const PERIODS: usize = 120;

/// The sensors of one head run alone on its own one-head drive.
fn alone(plant: &Plant, k: usize) -> Vec<String> {
    let mut d = plant.drive().unwrap();
    (0..PERIODS)
        .map(|n| bits(&d.step(&command(k, n), DT).unwrap()))
        .collect()
}

fn together(plant: &MultiPlant) -> Vec<Vec<Sensors>> {
    let mut d = plant.drive().unwrap();
    let mut per_head = vec![Vec::new(); plant.heads()];
    for n in 0..PERIODS {
        let commands: Vec<Command> = (0..plant.heads()).map(|k| command(k, n)).collect();
        let s = d.step(&commands, DT).unwrap();
        for (k, s) in s.iter().enumerate() {
            assert_eq!(s.time_s.to_bits(), d.time().to_bits(), "one clock");
            per_head[k].push(*s);
        }
    }
    per_head
}

/// Three heads, each its own scene (head 1 flies higher: another slider), heater programme,
/// surface and noise: each head's sensors equal those of a one-head drive of its plant, to the
/// bit, period by period.
#[test]
fn each_head_is_a_one_head_drive_to_the_bit() {
    let paper = Scene::paper();
    let mut low = Scene::paper();
    low.nominal_clearance_m *= 1.05;
    let scenes = [paper.clone(), low, paper];
    let seed = 5;
    let plants: Vec<Plant> = scenes
        .iter()
        .enumerate()
        .map(|(k, s)| {
            let zone = scene_zone(s, 0.025).unwrap();
            Plant::new(s, &zone, head_seed(seed, k), DriveOptions::default()).unwrap()
        })
        .collect();
    let multi = MultiPlant::new(plants.clone()).unwrap();
    let got = together(&multi);
    for (k, p) in plants.iter().enumerate() {
        let text: Vec<String> = got[k].iter().map(bits).collect();
        assert_eq!(text, alone(p, k), "head {k}");
    }
    // Not the same run three times: the heads differ (surface, slider, commands), and head 1
    // was ramped into contact (the static contact force at touchdown is a few µN).
    let gap = |k: usize, n: usize| got[k][n].truth.gap_nm;
    assert_ne!(gap(0, 0), gap(2, 0));
    let force = |k: usize| {
        got[k]
            .iter()
            .map(|s| s.truth.mean_contact_force_un)
            .fold(0.0, f64::max)
    };
    assert!(
        force(1) > 10.0 * force(0).max(1e-3),
        "head 1 {} µN",
        force(1)
    );
}

/// A drive of one scene with several heads: head `k` is the one-head drive seeded
/// `head_seed(seed, k)`; head 0 the one-head drive of the drive's own seed.
#[test]
fn uniform_heads_are_the_one_head_drives_of_their_seeds() {
    let scene = Scene::paper();
    let zone = scene_zone(&scene, 0.025).unwrap();
    let seed = 11;
    let multi = MultiPlant::uniform(&scene, &zone, 3, seed, DriveOptions::default()).unwrap();
    let got = together(&multi);
    for (k, g) in got.iter().enumerate() {
        let one = Plant::new(&scene, &zone, head_seed(seed, k), DriveOptions::default()).unwrap();
        let text: Vec<String> = g.iter().map(bits).collect();
        assert_eq!(text, alone(&one, k), "head {k}");
    }
    assert_eq!(head_seed(seed, 0), seed);
}

/// Each surface has its own run-out and waviness: the disk heights under the heads differ, and
/// each is the one-head drive's surface of the head's seed.
#[test]
fn each_surface_is_its_own() {
    let scene = Scene::paper();
    let zone = scene_zone(&scene, 0.025).unwrap();
    let multi = MultiPlant::uniform(&scene, &zone, 4, 2, DriveOptions::default()).unwrap();
    let mut d = multi.drive().unwrap();
    let s = d.step(&[Command::heater_mw(60.0); 4], DT).unwrap();
    for i in 0..4 {
        for j in 0..i {
            assert_ne!(s[i].truth.disk_height_nm, s[j].truth.disk_height_nm);
        }
    }
}

#[test]
fn one_spindle_one_radius_one_ambient() {
    let scene = Scene::paper();
    let zone = scene_zone(&scene, 0.025).unwrap();
    let opts = DriveOptions::default();
    let head = |zone: &hdi_tribology::drive::Zone, opts: DriveOptions| {
        Plant::new(&scene, zone, 1, opts).unwrap()
    };
    let field = |e: Error| match e {
        Error::InvalidInput { field, .. } => field,
        other => panic!("{other}"),
    };
    let mut fast = zone.clone();
    fast.disk_speed *= 1.5;
    let e = MultiPlant::new(vec![head(&zone, opts.clone()), head(&fast, opts.clone())]);
    assert_eq!(field(e.unwrap_err()), "heads[1].rpm");
    let mut drift = opts.clone();
    drift.ambient.rate = 5.0;
    let e = MultiPlant::new(vec![head(&zone, opts.clone()), head(&zone, drift)]);
    assert_eq!(field(e.unwrap_err()), "heads[1].ambient");
    // A slider of its own may expand differently with temperature.
    let mut expands = opts.clone();
    expands.ambient.clearance_per_kelvin *= 2.0;
    assert!(MultiPlant::new(vec![head(&zone, opts.clone()), head(&zone, expands)]).is_ok());
    let e = MultiPlant::new(vec![]);
    assert_eq!(field(e.unwrap_err()), "heads");
    let e = MultiPlant::uniform(&scene, &zone, 33, 1, opts);
    assert_eq!(field(e.unwrap_err()), "heads");
}

/// A bad command or a wrong count is refused before any head moves; a head whose integration
/// fails leaves the drive refusing further steps with a typed kind.
#[test]
fn bad_steps_are_refused_and_a_failed_head_stops_the_clock() {
    let scene = Scene::paper();
    let zone = scene_zone(&scene, 0.025).unwrap();
    let multi = MultiPlant::uniform(&scene, &zone, 2, 1, DriveOptions::default()).unwrap();
    let mut d = multi.drive().unwrap();
    d.step(&[Command::heater_mw(60.0); 2], DT).unwrap();
    let e = d
        .step(&[Command::heater_mw(60.0), Command::heater_mw(2e3)], DT)
        .unwrap_err();
    assert!(e.to_string().contains("commands[1].heater_power_mw"), "{e}");
    let e = d.step(&[Command::heater_mw(60.0)], DT).unwrap_err();
    assert!(e.to_string().contains("invalid commands"), "{e}");
    let e = d.step(&[Command::heater_mw(60.0); 2], 0.0).unwrap_err();
    assert!(e.to_string().contains("dt"), "{e}");
    assert_eq!(d.time(), DT);
    // Nothing moved: the next period is the one a drive without the refused calls gives.
    let mut clean = multi.drive().unwrap();
    clean.step(&[Command::heater_mw(60.0); 2], DT).unwrap();
    let cmds = [Command::heater_mw(61.0), Command::heater_mw(62.0)];
    let (a, b) = (d.step(&cmds, DT).unwrap(), clean.step(&cmds, DT).unwrap());
    assert_eq!(format!("{a:?}"), format!("{b:?}"));

    // Head 1 with a step budget of one step per period fails at once; head 0 has moved on.
    let mut tight = Scene::paper();
    tight.solver.max_steps = 1;
    let plants = vec![
        Plant::new(&scene, &zone, 1, DriveOptions::default()).unwrap(),
        Plant::new(&tight, &zone, 2, DriveOptions::default()).unwrap(),
    ];
    let mut d = MultiPlant::new(plants).unwrap().drive().unwrap();
    let cmds = [Command::heater_mw(80.0); 2];
    let e = d.step(&cmds, DT).unwrap_err();
    let f = e.failure().expect("a typed failure");
    assert_eq!(
        f.downcast_ref::<DriveError>().map(|k| k.to_string()),
        Some(
            DriveError::PeriodSteps {
                max_steps: 1,
                t0_s: 0.0,
                t1_s: DT
            }
            .to_string()
        )
    );
    let e = d.step(&cmds, DT).unwrap_err();
    let f = e.failure().expect("a typed failure");
    assert_eq!(
        f.downcast_ref::<DriveError>(),
        Some(&DriveError::HeadsOutOfStep { head: 1 })
    );
}
