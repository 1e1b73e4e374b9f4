use hdi_tribology::drive::{scene_zone, Command, DriveOptions, DriveScheme, Plant};
use hdi_tribology::scene::Scene;
const DT: f64 = 50e-6;
#[test]
fn probe() {
    let scene = Scene::paper();
    let zone = scene_zone(&scene, 0.025).unwrap();
    let fast = Plant::new(&scene, &zone, 5, DriveOptions { scheme: DriveScheme::Exponential, ..DriveOptions::default() }).unwrap();
    let tight = Plant::new(&scene, &zone, 5, DriveOptions {
        method: hdi_tribology::ode::Method::Radau5, rtol: 1e-10, atol_displacement: 1e-17,
        atol_displacement_flight: 1e-17, max_step: Some(DT / 4.0), ..DriveOptions::default() }).unwrap();
    let mut programme: Vec<Command> = Vec::new();
    if std::env::var("FOLD").is_ok() { programme.extend(std::iter::repeat_n(Command::heater_mw(74.3), 600)); }
    for mw in [62.0, 68.0, 72.0, 76.0, 78.0, 74.0, 70.0] {
        programme.extend(std::iter::repeat_n(Command::heater_mw(mw), 60));
    }
    programme.extend(std::iter::repeat_n(Command::heater_mw(72.0).with_dither(0.5, 10.5), 40));
    programme.extend((0..40).map(|k| Command::heater_mw(70.0 + 0.05 * k as f64)));
    let (mut a, mut b) = (fast.drive().unwrap(), tight.drive().unwrap());
    for (k, c) in programme.iter().enumerate() {
        let (x, y) = (a.step(c, DT).unwrap(), b.step(c, DT).unwrap());
        let p = a.last_period();
        println!("{k} {:.2} {} {:.3e} gap {:.4} dgap_pm {:.4} F {:.3} dF_uN {:.4} dR {:.3e}", c.heater_power_mw, p.exponential as u8, p.error_estimate,
            y.truth.gap_nm, (x.truth.gap_nm - y.truth.gap_nm) * 1e3, y.truth.mean_contact_force_un,
            x.truth.mean_contact_force_un - y.truth.mean_contact_force_un, x.contact_resistance_ohm - y.contact_resistance_ohm);
    }
    println!("{:?}", a.scheme_counts());
}
