//! Clearance calibration against the static model: the touchdown found by stepping the heater on
//! the simulated drive, the take-off found stepping back, the clearance set after the back-off,
//! zone scaling, and typed errors for bad options.

use hdi_tribology::analysis::{
    flying_equilibrium, static_hysteresis, touchdown_power, ScanGrid, StaticOptions,
};
use hdi_tribology::calibration::CalibrationError;
use hdi_tribology::calibration::{
    calibrate, CalibrationOptions, ContactForceRms, MeanContactForce, Zone,
};
use hdi_tribology::model::{SliderModel, Voltage};
use hdi_tribology::scene::Scene;
use hdi_tribology::Error;

const STEP: f64 = 0.5e-3;
const MARGIN: f64 = 10e-3;

fn reference_detector(scene: &Scene) -> MeanContactForce {
    MeanContactForce::new(scene.detector.contact_threshold_n, scene.detector.window_s).unwrap()
}

/// Options whose staircase starts 6 mW under `p_td` (on the step grid anchored at 0).
fn options_near(p_td: f64, find_takeoff: bool) -> CalibrationOptions {
    let start = ((p_td - 6e-3) / STEP).floor() * STEP;
    let mut o = CalibrationOptions::new(start, STEP, start + 0.03, MARGIN);
    o.find_takeoff = find_takeoff;
    o
}

#[test]
fn calibrated_touchdown_and_clearance_match_the_static_model() {
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene).unwrap();
    let th = scene.detector.contact_threshold_n;
    let td = touchdown_power(&model, &StaticOptions::new(th)).unwrap();
    let cal = calibrate(
        &model,
        &mut reference_detector(&scene),
        &options_near(td.power, false),
    )
    .unwrap();
    // The staircase can only land on its grid: the first level at or past the static touchdown,
    // one step at most away from it.
    assert!(
        (cal.touchdown_power - td.power).abs() <= STEP,
        "calibrated {} W vs static {} W",
        cal.touchdown_power,
        td.power
    );
    // Same margin on both: the clearances differ by the slope of the flying branch times the power
    // difference. Along the branch |dd/dP| = η k/k_tot ≥ η, with k_tot the total stiffness, which
    // falls towards the fold; so the bound is η·step·k/min(k_tot) at the two set points.
    let eta = model.efficiency();
    let k = model.bearing().stiffness(0.0);
    let dc2 = model.voltage().effective_dc().powi(2);
    let grid = ScanGrid::default();
    let at_cal = flying_equilibrium(&model, cal.set_power, dc2, &grid).unwrap();
    let at_static = flying_equilibrium(&model, td.power - MARGIN, dc2, &grid).unwrap();
    let softening = k / at_cal.stiffness.min(at_static.stiffness);
    // The slope the bound rests on: a central difference over ±0.1 mW (curvature error ~1e-4
    // relative here; 1e-3 leaves room for the 1e-12 root tolerance of the equilibria).
    let h = 1e-4;
    let up = flying_equilibrium(&model, cal.set_power + h, dc2, &grid).unwrap();
    let down = flying_equilibrium(&model, cal.set_power - h, dc2, &grid).unwrap();
    let slope = (down.d - up.d) / (2.0 * h);
    assert!(
        (slope / (eta * k / at_cal.stiffness) - 1.0).abs() < 1e-3,
        "slope {slope} m/W vs η k/k_tot = {}",
        eta * k / at_cal.stiffness
    );
    // About 1.08 for the paper scene 10 mW below touchdown.
    assert!((1.0..1.5).contains(&softening), "k/k_tot = {softening}");
    assert_eq!(cal.clearance, at_cal.d);
    assert!(
        (cal.clearance - at_static.d).abs() <= eta * STEP * softening,
        "clearance {} m vs static {} m",
        cal.clearance,
        at_static.d
    );
    assert!(cal.clearance > 0.0 && cal.clearance < model.nominal_clearance());
    // Every level below touchdown was judged flying.
    let n = cal.steps.len();
    assert!(cal.steps[..n - 1].iter().all(|s| !s.contact));
    assert!(cal.steps[n - 1].contact);
}

#[test]
fn calibrated_takeoff_matches_the_static_model() {
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene).unwrap();
    let th = scene.detector.contact_threshold_n;
    let stat = static_hysteresis(&model, &StaticOptions::new(th)).unwrap();
    let cal = calibrate(
        &model,
        &mut reference_detector(&scene),
        &options_near(stat.touchdown.power, true),
    )
    .unwrap();
    let to = cal.takeoff_power.expect("take-off found");
    // Stepping down, the first level without contact lies at most one step past the static
    // take-off.
    assert!(
        (to - stat.takeoff.power).abs() <= STEP,
        "calibrated take-off {to} W vs static {} W",
        stat.takeoff.power
    );
    let h = cal.hysteresis().unwrap();
    assert!(
        (h - stat.hysteresis).abs() <= 2.0 * STEP,
        "hysteresis {h} W vs static {} W",
        stat.hysteresis
    );
}

#[test]
fn zone_with_more_clearance_moves_touchdown_by_clearance_over_efficiency() {
    let base = Scene::paper();
    let zone = Zone::at_rpm("MD", 0.03, 5400.0, base.nominal_clearance_m + 1e-9, 3.0e5);
    let scene = zone.scene(&base).unwrap();
    let (m0, m1) = (
        SliderModel::from_scene(&base).unwrap(),
        SliderModel::from_scene(&scene).unwrap(),
    );
    let th = base.detector.contact_threshold_n;
    let o = StaticOptions::new(th);
    let (p0, p1) = (
        touchdown_power(&m0, &o).unwrap().power,
        touchdown_power(&m1, &o).unwrap().power,
    );
    // With a linear bearing and every term on the bulge gap, the S-curve δ(d) = h0 − d + F(d)/k
    // shifts by exactly Δh0: the fold moves by Δh0/η = 10 mW. Folds are refined to 1e-12 in d on
    // exact forces, hence 1e-9 relative here.
    let shift = 1e-9 / m0.efficiency();
    assert!(
        ((p1 - p0) / shift - 1.0).abs() < 1e-9,
        "shift {} W",
        p1 - p0
    );
    // The calibration sees the same shift, to within one step each.
    let c0 = calibrate(
        &m0,
        &mut reference_detector(&base),
        &options_near(p0, false),
    )
    .unwrap();
    let c1 = calibrate(
        &m1,
        &mut reference_detector(&scene),
        &options_near(p1, false),
    )
    .unwrap();
    assert!(((c1.touchdown_power - c0.touchdown_power) - shift).abs() <= 2.0 * STEP);
    // Same stiffness and mass: the damping ratio, hence the damping, is unchanged.
    assert_eq!(
        m1.bearing().damping(0.0),
        m0.bearing().damping(0.0),
        "damping"
    );
    assert_eq!(m1.friction().disk_speed, zone.disk_speed);
}

#[test]
fn stiffer_zone_keeps_the_damping_ratio() {
    let base = Scene::paper();
    let scene = Zone::at_rpm("OD", 0.045, 5400.0, 12e-9, 4.8e5)
        .scene(&base)
        .unwrap();
    let (b0, b1) = (
        base.build_air_bearing().unwrap(),
        scene.build_air_bearing().unwrap(),
    );
    let m = base.slider.mass_kg;
    let zeta = |b: &dyn hdi_tribology::force::AirBearing| {
        b.damping(0.0) / (2.0 * (b.stiffness(0.0) * m).sqrt())
    };
    assert!((zeta(&*b1) / zeta(&*b0) - 1.0).abs() < 1e-14);
    assert_eq!(b1.stiffness(0.0), 4.8e5);
}

#[test]
fn dither_brings_touchdown_earlier() {
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene).unwrap();
    let th = scene.detector.contact_threshold_n;
    let td = touchdown_power(&model, &StaticOptions::new(th))
        .unwrap()
        .power;
    let v_ac = 0.5;
    let dithered = model.with_voltage(Voltage {
        ac_amplitude: v_ac,
        frequency: 10.5e3,
        ..model.voltage()
    });
    // Quasi-static bounds: the head follows V² (2f = 21 kHz is far below the 87 kHz air-bearing
    // mode), so it cannot touch down later than the static touchdown at the mean V² = V_ac²/2.
    let at = |v: f64| {
        let m = model.with_voltage(Voltage {
            dc: v,
            ..model.voltage()
        });
        touchdown_power(&m, &StaticOptions::new(th)).unwrap().power
    };
    let (p_mean, p_peak) = (at(v_ac / 2f64.sqrt()), at(v_ac));
    assert!(p_peak < p_mean && p_mean < td);
    let mut opts = options_near(p_peak, false);
    opts.staircase.start_power -= 0.01;
    let cal = calibrate(
        &dithered,
        &mut ContactForceRms::new(1e-5, 5e3, 5e-5).unwrap(),
        &opts,
    )
    .unwrap();
    assert!(
        cal.touchdown_power <= p_mean + STEP && cal.touchdown_power < td,
        "dithered touchdown {} W, static at mean V² {p_mean} W, at peak V² {p_peak} W",
        cal.touchdown_power
    );
    // The set clearance is evaluated with the dither off: more clearance than without dither.
    let plain = flying_equilibrium(&model, td - MARGIN, 0.0, &ScanGrid::default()).unwrap();
    assert!(cal.clearance > plain.d);
}

#[test]
fn bad_options_are_typed_errors_naming_the_field() {
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene).unwrap();
    let mut det = reference_detector(&scene);
    let field_of = |e: Error| match e {
        Error::InvalidInput { field, .. } => field,
        other => panic!("not an input error: {other}"),
    };
    let mut o = CalibrationOptions::new(0.06, 0.0, 0.1, 0.01);
    assert_eq!(
        field_of(calibrate(&model, &mut det, &o).unwrap_err()),
        "staircase.step"
    );
    o = CalibrationOptions::new(0.06, 1e-3, 0.05, 0.01);
    assert_eq!(
        field_of(calibrate(&model, &mut det, &o).unwrap_err()),
        "staircase.max_power"
    );
    o = CalibrationOptions::new(0.06, 1e-3, 0.1, 0.01);
    o.staircase.rise_time = 1e-3;
    assert_eq!(
        field_of(calibrate(&model, &mut det, &o).unwrap_err()),
        "staircase.rise_time"
    );
    o = CalibrationOptions::new(0.06, 1e-3, 0.1, f64::NAN);
    assert_eq!(
        field_of(calibrate(&model, &mut det, &o).unwrap_err()),
        "margin"
    );
    o = CalibrationOptions::new(0.06, 1e-12, 0.1, 0.01);
    assert_eq!(
        field_of(calibrate(&model, &mut det, &o).unwrap_err()),
        "staircase.step"
    );
    assert!(MeanContactForce::new(-1.0, 1e-5).is_err());
    assert!(ContactForceRms::new(1e-5, 0.0, 1e-5).is_err());
    // No contact below max_power: an analysis error, not a panic or an endless search.
    o = CalibrationOptions::new(0.0, 5e-3, 0.01, 0.0);
    let e = calibrate(&model, &mut det, &o).unwrap_err();
    let Error::Analysis(f) = &e else {
        panic!("unexpected {e}")
    };
    match f.downcast_ref() {
        Some(CalibrationError::NoTouchdown { max_power_mw, .. }) => {
            assert_eq!(*max_power_mw, 10.0)
        }
        _ => panic!("unexpected {e}"),
    }
}
