//! Detector building blocks against closed forms, and a user-defined detector plugged into the
//! calibration loop.

use hdi_tribology::analysis::equilibrium::EquilibriumSolver;
use hdi_tribology::calibration::{
    calibrate, CalibrationOptions, HighPass, MeanContactForce, MeanSquare, Relative, Sample,
    TouchdownDetector, VibrationRms,
};
use hdi_tribology::model::SliderModel;
use hdi_tribology::scene::Scene;
use std::f64::consts::PI;

#[test]
fn high_pass_gain_and_phase_on_a_sine() {
    let (fc, f, dt) = (5e3, 2.1e4, 1e-7);
    let mut hp = HighPass::new(fc).unwrap();
    let (w, tau) = (2.0 * PI * f, 1.0 / (2.0 * PI * fc));
    // Steady state of s τ/(1 + s τ): gain ωτ/√(1 + ω²τ²), phase lead atan(1/(ωτ)).
    let gain = w * tau / (1.0 + (w * tau).powi(2)).sqrt();
    let lead = (1.0 / (w * tau)).atan();
    let mut worst: f64 = 0.0;
    for i in 0..200_000 {
        let t = i as f64 * dt;
        let y = hp.filter(t, (w * t).sin());
        // After 20 ms the start transient (time constant τ ≈ 32 µs) is gone.
        if t > 0.018 {
            worst = worst.max((y - gain * (w * t + lead).sin()).abs());
        }
    }
    // The filter is exact for piecewise-linear input; a sampled sine differs from its chords by
    // up to (ω dt)²/8 ≈ 2e-5 of the amplitude.
    assert!(worst < 1e-4, "worst deviation {worst}");
}

#[test]
fn mean_square_of_a_constant_converges_exponentially() {
    let tau = 1e-4;
    let mut ms = MeanSquare::new(tau).unwrap();
    let mut v = 0.0;
    for i in 0..=1000 {
        v = ms.update(i as f64 * 1e-6, 3.0);
    }
    // Starting from 0: 9 (1 − e^{−t/τ}) at t = 1 ms, exact for any spacing.
    assert!((v - 9.0 * (1.0 - (-1e-3 / tau).exp())).abs() < 1e-12);
}

#[test]
fn mean_contact_force_is_the_mean_over_the_trailing_window() {
    let (w, dt) = (4.7619e-5, 1e-6);
    let mut d = MeanContactForce::new(1.0, w).unwrap();
    let fc = |t: f64| 1e-4 + 2.0 * t; // a ramp: the mean is the value at the mean sample time
    for i in 0..200 {
        let t = i as f64 * dt;
        let fired = d.update(&Sample {
            t,
            contact_force: fc(t),
            ..Sample::default()
        });
        assert!(!fired);
        if t >= w {
            // Samples in [t − w, t]: i − 47 ..= i.
            let n = (w / dt).floor() as usize;
            let t_mid = (i as f64 - n as f64 / 2.0) * dt;
            assert!((d.level() - fc(t_mid)).abs() < 1e-15, "at {t}");
        }
    }
}

#[test]
fn relative_detector_waits_for_its_baseline() {
    let inner = VibrationRms::new(1e-12, 5e3, 2e-5).unwrap();
    let mut d = Relative::new(inner, 2.0, 5e-5, 5e-5).unwrap();
    let mut first_fire = None;
    for i in 0..400 {
        let t = i as f64 * 1e-6;
        // Vibration amplitude 0.1 nm, tripled from 250 µs on.
        let a = if i < 250 { 1e-10 } else { 3e-10 };
        let s = Sample {
            t,
            displacement: a * (2.0 * PI * 5e4 * t).sin(),
            ..Sample::default()
        };
        if d.update(&s) && first_fire.is_none() {
            first_fire = Some(t);
        }
    }
    let b = d.baseline().unwrap();
    // Baseline: RMS of a 0.1 nm sine after the high-pass (gain 0.995 at 50 kHz) ≈ 0.0704 nm,
    // with the ripple of the 20 µs mean-square window.
    assert!(
        (b / (1e-10 * 0.995 / 2f64.sqrt()) - 1.0).abs() < 0.1,
        "baseline {b}"
    );
    let t = first_fire.expect("fires after the amplitude triples");
    assert!(t > 250e-6 && t < 300e-6, "fired at {t}");
    assert!(Relative::new(VibrationRms::new(1e-12, 5e3, 2e-5).unwrap(), 1.0, 0.0, 1e-5).is_err());
}

/// A detector no drive has: contact when the bulge gap is below a set value.
#[derive(Debug)]
struct GapBelow(f64);

impl TouchdownDetector for GapBelow {
    fn name(&self) -> &str {
        "gap below"
    }
    fn reset(&mut self) {}
    fn update(&mut self, s: &Sample) -> bool {
        s.gap < self.0
    }
    fn level(&self) -> f64 {
        0.0
    }
}

#[test]
fn a_user_detector_plugs_into_the_loop() {
    let scene = Scene::paper();
    let model = SliderModel::from_scene(&scene).unwrap();
    let d_star = 3e-9;
    // Static power at which the flying equilibrium reaches d*.
    let p_star = EquilibriumSolver::new(&model, 0.0)
        .at_gap(d_star)
        .unwrap()
        .power;
    let step = 0.5e-3;
    let start = ((p_star - 5e-3) / step).floor() * step;
    let mut o = CalibrationOptions::new(start, step, start + 0.02, 0.0);
    o.find_takeoff = false;
    let cal = calibrate(&model, &mut GapBelow(d_star), &o).unwrap();
    // Far from the fold the flying branch follows the heater quasi-statically (20 µs ramps, an
    // 11 µs air-bearing period): the first level past P* is the one detected.
    assert!(
        cal.touchdown_power >= p_star && cal.touchdown_power < p_star + step,
        "{} W vs P* = {p_star} W",
        cal.touchdown_power
    );
    // Zero margin: the clearance is the static gap at that level, just under d*: by at most
    // η·step·k/k_tot, with k_tot the total stiffness at the lower end (the branch softens as d falls).
    let below = EquilibriumSolver::new(&model, 0.0)
        .at_gap(cal.clearance)
        .unwrap();
    let softening = model.bearing().stiffness(0.0) / below.stiffness;
    assert!(cal.clearance < d_star);
    assert!(d_star - cal.clearance <= model.efficiency() * step * softening);
}
