//! Controllers driving the simulated drive: the staircase calibration against the static model,
//! the contact-sensor and acoustic touchdown detectors, the harmonic-ratio clearance change
//! against the true one, and the closed-loop clearance hold.

use hdi_tribology::analysis::{static_hysteresis, StaticOptions};
use hdi_tribology::drive::{
    run, scene_zone, touchdown_roc, AcousticLevel, Command, ContactSensorSlope, Drive,
    DriveOptions, LevelDetector, Plant, Readback, Staircase, StaircaseSettings, TrueContact,
};
use hdi_tribology::scene::Scene;

const DT: f64 = 50e-6;

fn plant(seed: u64, opts: DriveOptions) -> Plant {
    let scene = Scene::paper();
    Plant::new(&scene, &scene_zone(&scene, 0.025).unwrap(), seed, opts).unwrap()
}

fn calibrate<D: LevelDetector>(d: &mut Drive, settings: StaircaseSettings, det: D) -> Staircase<D> {
    let mut st = Staircase::new(settings, det, DT).unwrap();
    run(d, &mut st, DT, 1_000_000).unwrap();
    assert!(st.is_done());
    st
}

/// Static touchdown and take-off of the drive's model (mW; the paper scene: 74.324 / 68.317 mW).
fn static_td_to(d: &Drive) -> (f64, f64) {
    let h = static_hysteresis(d.model(), &StaticOptions::new(5e-5)).unwrap();
    (h.touchdown.power * 1e3, h.takeoff.power * 1e3)
}

#[test]
fn staircase_through_the_drive_agrees_with_the_static_model() {
    let p = plant(5, DriveOptions::default());
    let mut d = p.drive().unwrap();
    let (td, to) = static_td_to(&d);
    assert!((td - 74.324).abs() < 1e-3, "static touchdown {td}");
    let step = 0.25;
    let st = calibrate(
        &mut d,
        StaircaseSettings::from_mw(66.0, 0.25, 80.0, 10.0),
        TrueContact::new(50.0).unwrap(),
    );
    let out = st.outcome();
    let cal_td = out.touchdown_power_mw.unwrap();
    // The first level at or above the static touchdown.
    assert!(
        cal_td >= td - 1e-6 && cal_td < td + step,
        "touchdown {cal_td} vs static {td}"
    );
    let cal_to = out.takeoff_power_mw.unwrap();
    // Stepping down, the first level below the static take-off flies.
    assert!(
        cal_to <= to + 1e-6 && cal_to > to - step,
        "take-off {cal_to} vs static {to}"
    );
    assert!((out.set_power_mw.unwrap() - (cal_td - 10.0)).abs() < 1e-12);
}

#[test]
fn contact_sensor_touchdown_within_1_mw_of_static() {
    for seed in [1, 2, 3] {
        let p = plant(seed, DriveOptions::default());
        let mut d = p.drive().unwrap();
        let (td, _) = static_td_to(&d);
        let mut s = StaircaseSettings::from_mw(70.0, 0.25, 80.0, 10.0);
        s.find_takeoff = false;
        let st = calibrate(&mut d, s, ContactSensorSlope::new(5.0, 6).unwrap());
        let p = st
            .outcome()
            .touchdown_power_mw
            .expect("contact sensor saw no touchdown");
        assert!(
            st.outcome().levels.len() > 8,
            "the line was fitted before touchdown"
        );
        assert!(
            (p - td).abs() <= 1.0,
            "seed {seed}: {p} mW vs static {td} mW"
        );
    }
}

/// The contact-sensor slope's statistic is honest on noise alone: on flying levels far below
/// touchdown (50–66 mW, the asperity tail carries well under 1 µN), each run up to its first
/// alarm as a staircase runs, it fires on no more levels than the one-sided Gaussian tail
/// allows (3σ: 0.13 % of levels, checked against 1 %; 5σ: none). On the approach to the fold it does not fire on the smooth rise of frictional heat
/// from the asperity tail: over ten seeds at 5σ no touchdown is declared more than one step
/// below the static one, and none is missed.
#[test]
fn contact_sensor_slope_false_alarms_are_rare() {
    let base = plant(1, DriveOptions::default());
    let mut flying = StaircaseSettings::from_mw(50.0, 0.25, 66.0, 10.0);
    flying.find_takeoff = false;
    let (mut judged, mut fired3, mut fired5) = (0usize, 0usize, 0usize);
    for seed in 1..=10 {
        let mut d = base.with_seed(seed).unwrap().drive().unwrap();
        let st = calibrate(&mut d, flying, TrueContact::new(50.0).unwrap());
        let levels = &st.outcome().levels;
        assert!(levels.iter().all(|l| l.true_contact_force_un.mean < 1.0));
        let (mut d3, mut d5) = (
            ContactSensorSlope::new(3.0, 6).unwrap(),
            ContactSensorSlope::new(5.0, 6).unwrap(),
        );
        // Each up to its first alarm, as a staircase runs.
        let (mut on3, mut on5) = (true, true);
        for l in levels {
            if on3 && d3.excess(l).is_some() {
                judged += 1;
            }
            if on3 && d3.judge(l) {
                fired3 += 1;
                on3 = false;
            }
            if on5 && d5.judge(l) {
                fired5 += 1;
                on5 = false;
            }
        }
    }
    println!("{fired3} (3σ) and {fired5} (5σ) of {judged} flying levels fired");
    assert!(judged > 500);
    assert!(
        (fired3 as f64) < 0.01 * judged as f64,
        "3σ: {fired3} of {judged}"
    );
    assert_eq!(fired5, 0, "5σ fired on noise");

    let scene = Scene::paper();
    let roc = touchdown_roc(
        &base,
        StaircaseSettings::from_mw(70.0, 0.25, 80.0, 10.0),
        scene.detector.contact_threshold_n * 1e6,
        1..11,
        || ContactSensorSlope::new(5.0, 6),
    )
    .unwrap();
    println!("{roc:?}");
    assert_eq!(roc.false_alarms, 0, "{roc:?}");
    assert_eq!(roc.missed, 0, "{roc:?}");
}

#[test]
fn acoustic_touchdown_within_1_mw_of_static() {
    for seed in [1, 2, 3] {
        let p = plant(seed, DriveOptions::default());
        let mut d = p.drive().unwrap();
        let (td, _) = static_td_to(&d);
        let mut s = StaircaseSettings::from_mw(70.0, 0.25, 80.0, 10.0);
        s.find_takeoff = false;
        let st = calibrate(&mut d, s, AcousticLevel::new(5.0, 3).unwrap());
        let p = st
            .outcome()
            .touchdown_power_mw
            .expect("AE saw no touchdown");
        assert!(
            (p - td).abs() <= 1.0,
            "seed {seed}: {p} mW vs static {td} mW"
        );
    }
}

#[test]
fn harmonic_ratio_clearance_change_matches_the_true_one_within_the_noise() {
    let opts = DriveOptions::default();
    let rb = opts.sensors.readback;
    let p = plant(9, opts);
    let mut d = p.drive().unwrap();
    let n = 400;
    let window = |d: &mut Drive, mw: f64| {
        // Settle 2 ms, then average.
        for _ in 0..40 {
            d.step(&Command::heater_mw(mw), DT).unwrap();
        }
        let (mut lr, mut gap) = (0.0, 0.0);
        for _ in 0..n {
            let s = d.step(&Command::heater_mw(mw), DT).unwrap();
            lr += s.readback.log_ratio();
            gap += s.truth.gap_nm;
        }
        (lr / n as f64, gap / n as f64)
    };
    let (lr0, g0) = window(&mut d, 62.0);
    let (lr1, g1) = window(&mut d, 70.0);
    let est = Readback::clearance_change_nm(lr0, lr1, rb.wavelength * 1e9);
    let truth = g1 - g0;
    // Each log ratio carries √2·noise per sample; a difference of two means of n samples has
    // standard deviation λ/(4π)·2·noise/√n.
    let sigma =
        rb.wavelength * 1e9 / (4.0 * std::f64::consts::PI) * 2.0 * rb.noise / (n as f64).sqrt();
    assert!(truth < -0.5, "the heater closed the gap: {truth} nm");
    assert!(
        (est - truth).abs() < 4.0 * sigma,
        "HR {est:e} vs true {truth:e} (σ {sigma:e})"
    );
}

#[test]
fn clearance_hold_follows_an_ambient_drift() {
    use hdi_tribology::drive::{
        Action, Ambient, ClearanceHold, Controller, HoldPhase, HoldSettings, HoldTarget,
    };
    // A fast drift (200 K/s at 0.03 nm/K: 6 nm/s) so that a 60 ms run moves the clearance by
    // about 0.3 nm.
    let opts = DriveOptions {
        ambient: Ambient {
            rate: 200.0,
            ..Ambient::default()
        },
        ..DriveOptions::default()
    };
    let wavelength_nm = opts.sensors.readback.wavelength * 1e9;
    let p = plant(4, opts);
    let eta = p.model().efficiency() * 1e6; // nm/mW
    let mut stair = StaircaseSettings::from_mw(70.0, 0.25, 80.0, 10.0);
    stair.find_takeoff = false;
    // The integral correction around the calibrated operating power.
    let settings = HoldSettings {
        staircase: stair,
        target: HoldTarget::SetPower,
        wavelength_nm,
        efficiency_nm_per_mw: eta,
        average: 20,
        integral_gain: 0.5,
        proportional_gain: 0.0,
        recalibrate_after_mw: 20.0,
    };
    let mut hold =
        ClearanceHold::new(settings, ContactSensorSlope::new(5.0, 4).unwrap(), DT).unwrap();
    let mut d = p.drive().unwrap();
    let mut cmd = hold.start();
    let (mut ref_gap, mut n_ref) = (0.0, 0);
    let mut errors = Vec::new();
    let mut hold_start = None;
    for _ in 0..4000 {
        let s = d.step(&cmd, DT).unwrap();
        let phase = hold.phase();
        match phase {
            HoldPhase::Referencing => {
                ref_gap += s.truth.gap_nm;
                n_ref += 1;
            }
            HoldPhase::Holding => {
                hold_start.get_or_insert(s.time_s);
                errors.push((s.time_s, s.truth.gap_nm - ref_gap / n_ref as f64));
            }
            HoldPhase::Calibrating => {}
        }
        match hold.update(&s) {
            Action::Continue(c) => cmd = c,
            Action::Stop => panic!("the hold stopped"),
        }
    }
    assert_eq!(hold.calibrations(), 1);
    let t0 = hold_start.expect("never held");
    let span = d.time() - t0;
    assert!(span > 0.05, "held for {span} s");
    // Open loop the clearance would have grown by the drift over the span (nm).
    let drift = 200.0 * 0.03 * span;
    // Closed loop: after the first 5 ms the error stays within 10 % of that drift.
    let late: Vec<f64> = errors
        .iter()
        .filter(|e| e.0 > t0 + 5e-3)
        .map(|e| e.1)
        .collect();
    let rms = (late.iter().map(|e| e * e).sum::<f64>() / late.len() as f64).sqrt();
    assert!(
        rms < 0.1 * drift,
        "rms clearance error {rms} nm against a drift of {drift} nm"
    );
    // The heater took up the drift: about drift/η more power.
    assert!(hold.power_mw() - hold.set_power_mw() > 0.5 * drift / eta);
}

/// A PI hold on a clearance above touchdown, on the default wavy disk, with an ambient step of
/// `step_k` at `step_time_s`; returns the hold and, per period held, (time, true clearance above
/// the touchdown level's mean gap, heater mW).
fn pi_hold(
    step_k: f64,
    step_time_s: f64,
    target_nm: f64,
    periods: usize,
) -> (
    hdi_tribology::drive::ClearanceHold<ContactSensorSlope>,
    Vec<(f64, f64, f64)>,
) {
    use hdi_tribology::drive::{
        Action, Ambient, ClearanceHold, Controller, HoldPhase, HoldSettings, HoldTarget,
    };
    let opts = DriveOptions {
        ambient: Ambient {
            step: step_k,
            step_time: step_time_s,
            ..Ambient::default()
        },
        ..DriveOptions::default()
    };
    let wavelength_nm = opts.sensors.readback.wavelength * 1e9;
    let p = plant(6, opts);
    let eta = p.model().efficiency() * 1e6;
    let mut stair = StaircaseSettings::from_mw(70.0, 0.25, 80.0, 10.0);
    stair.find_takeoff = false;
    let settings = HoldSettings {
        staircase: stair,
        target: HoldTarget::AboveTouchdownNm(target_nm),
        wavelength_nm,
        efficiency_nm_per_mw: eta,
        average: 20,
        integral_gain: 0.3,
        proportional_gain: 0.5,
        recalibrate_after_mw: 20.0,
    };
    let mut hold =
        ClearanceHold::new(settings, ContactSensorSlope::new(5.0, 4).unwrap(), DT).unwrap();
    let mut d = p.drive().unwrap();
    let mut cmd = hold.start();
    let mut held = Vec::new();
    for _ in 0..periods {
        let s = d.step(&cmd, DT).unwrap();
        if hold.phase() == HoldPhase::Holding {
            let td = hold.calibration().touchdown_power_mw.unwrap();
            let level = hold
                .calibration()
                .levels
                .iter()
                .find(|l| l.heater_power_mw == td)
                .unwrap();
            held.push((
                s.time_s,
                s.truth.gap_nm - level.true_gap_nm.mean,
                s.heater_power_mw,
            ));
        }
        match hold.update(&s) {
            Action::Continue(c) => cmd = c,
            Action::Stop => panic!("the hold stopped"),
        }
    }
    assert_eq!(hold.calibrations(), 1);
    (hold, held)
}

/// Mean of the true clearance over `[t0, t1)`.
fn mean_clearance(held: &[(f64, f64, f64)], t0: f64, t1: f64) -> f64 {
    let w: Vec<f64> = held
        .iter()
        .filter(|h| h.0 >= t0 && h.0 < t1)
        .map(|h| h.1)
        .collect();
    assert!(w.len() > 50, "{} periods in [{t0}, {t1})", w.len());
    w.iter().sum::<f64>() / w.len() as f64
}

/// The PI hold brings the true clearance above touchdown (the true gap less the touchdown
/// level's mean gap) to its target: within 0.1 nm over 10 ms once settled, from a feed-forward
/// start that the heater-efficiency estimate alone would leave off by more.
#[test]
fn pi_hold_settles_to_its_clearance_target() {
    let target = 1.5;
    let (hold, held) = pi_hold(0.0, 0.0, target, 1400);
    let t0 = held.first().expect("never held").0;
    let end = held.last().unwrap().0;
    assert!(end - t0 > 0.03, "held for {} s", end - t0);
    let settled = mean_clearance(&held, end - 0.01, end + 1.0);
    println!(
        "target {target} nm: true clearance {settled:.4} nm, estimate {:.4} nm, heater {:.3} mW (feed-forward {:.3} mW)",
        hold.estimate_nm(),
        hold.power_mw(),
        hold.set_power_mw()
    );
    assert!(
        (settled - target).abs() < 0.1,
        "clearance {settled} nm against a target of {target} nm"
    );
    assert!((hold.estimate_nm() - target).abs() < 0.1);
}

/// An ambient step of 10 K (0.3 nm of clearance at 0.03 nm/K) after the hold has settled: open
/// loop the clearance would stay 0.3 nm off; the PI hold brings it back within 0.1 nm of the
/// target within 10 ms, by about 0.3 nm/η more heater.
#[test]
fn pi_hold_rejects_an_ambient_step() {
    let target = 1.5;
    let step_time = 0.045;
    let (hold, held) = pi_hold(10.0, step_time, target, 1600);
    let before = mean_clearance(&held, step_time - 0.01, step_time);
    let just_after = held
        .iter()
        .find(|h| h.0 > step_time + 1e-3)
        .map(|h| h.1)
        .unwrap();
    let after = mean_clearance(&held, step_time + 0.01, step_time + 0.04);
    let p_before = held.iter().rev().find(|h| h.0 < step_time).unwrap().2;
    let p_after = held.last().unwrap().2;
    println!(
        "clearance {before:.4} nm before the step, {just_after:.4} nm 1 ms after, {after:.4} nm          10–40 ms after; heater {p_before:.3} → {p_after:.3} mW"
    );
    assert!(
        (before - target).abs() < 0.1,
        "before the step: {before} nm"
    );
    // The step reached the head: the clearance jumped by most of 0.3 nm.
    assert!(
        just_after - before > 0.2,
        "the step did not act: {just_after} nm"
    );
    assert!((after - target).abs() < 0.1, "after the step: {after} nm");
    // About 0.3 nm/η ≈ 3 mW more heater (η ≈ 0.1 nm/mW).
    assert!(
        p_after - p_before > 0.5 * 0.3 / hold.efficiency_nm_per_mw(),
        "heater {p_before} → {p_after} mW"
    );
}
