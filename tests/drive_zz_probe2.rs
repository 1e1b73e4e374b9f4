use hdi_tribology::drive::{scene_zone, Command, DiskSpec, DriveOptions, DriveScheme, Plant};
use hdi_tribology::scene::Scene;
const DT: f64 = 50e-6;
#[test]
fn probe2() {
    let scene = Scene::paper();
    let zone = scene_zone(&scene, 0.025).unwrap();
    let disk = if std::env::var("WAVY").is_ok() { DiskSpec::default() } else { DiskSpec::flat() };
    let fast = Plant::new(&scene, &zone, 1, DriveOptions { disk, scheme: DriveScheme::Exponential, ..DriveOptions::default() }).unwrap();
    let mut a = fast.drive().unwrap();
    let c = if std::env::var("NODITHER").is_ok() { Command::heater_mw(70.0) } else { Command::heater_mw(70.0).with_dither(0.5, 10.5) };
    for k in 0..200 { let _ = a.step(&c, DT).unwrap(); if k > 150 { eprintln!("{k} {:?}", a.last_period()); } }
    eprintln!("{:?}", a.scheme_counts());
}
