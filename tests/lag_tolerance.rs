//! The lagged force's absolute tolerance (`SliderSystem::tolerances`): the force that moves the
//! slider by the displacement tolerance at rest, times `max(1, 1/(ω τ))`, since a local error in
//! a lag much faster than the structure's fastest mode acts as a short impulse. Checked against
//! its formula, and against a reference run 10⁴ times tighter: a lagged cycle at the scene's
//! tolerance finds touchdown and take-off within the heater power that moves the clearance by
//! the displacement tolerance.

use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, HeaterProgramme, TimeSeries};
use hdi_tribology::heater::Programme;
use hdi_tribology::model::{SliderModel, SliderSystem, Structure};
use hdi_tribology::ode::Method;
use hdi_tribology::scene::Scene;

#[path = "common/scenes.rs"]
mod scenes;

const DISPLACEMENT: f64 = 1e-14;

fn few_peak() -> Scene {
    scenes::paper_bulge()
}

/// The lagged force's absolute tolerance of `model`.
fn lag_atol(model: &SliderModel) -> f64 {
    let sys = SliderSystem::new(
        model,
        model.inputs(Programme::constant(0.06, 1e-3).unwrap()),
        true,
    );
    let i = sys.layout().lagged_force.expect("a lagged model");
    sys.tolerances(DISPLACEMENT, 1e-12, 1e-10)[i]
}

#[test]
fn the_lagged_force_tolerance_follows_the_impulse_of_its_error() {
    let scene = few_peak();
    let base = SliderModel::from_scene(&scene).unwrap();
    let m = scene.slider.mass_kg;
    // The scene's linear bearing: k = 3e5 N/m on the 1 mg body, ω = √(k/m) = 5.48e5 rad/s.
    let k = 3e5;
    let w = (k / m).sqrt();
    let rigid = |tau: f64| {
        base.clone()
            .with_interface_lag(tau)
            .with_structure(Structure::rigid(m).unwrap())
    };
    // A 10 ns lag is far faster than the body's mode: the tolerance is k/(ωτ) ≈ 183 times the
    // static one.
    let fast = lag_atol(&rigid(1e-8));
    let expected = DISPLACEMENT * k / (w * 1e-8);
    assert!(
        (fast / expected - 1.0).abs() < 1e-12,
        "{fast:e} against {expected:e}"
    );
    // A lag slower than the mode acts as a static load: the force that moves the body by the
    // displacement tolerance.
    let slow = lag_atol(&rigid(1e-5));
    assert!((slow / (DISPLACEMENT * k) - 1.0).abs() < 1e-12, "{slow:e}");
    // On the bulge (142 MHz, ω = 8.9e8 rad/s) a 10 ns lag is slower than the fastest mode: the
    // static tolerance at the bulge; a 0.1 ns lag is faster again.
    let bulge = |tau: f64| base.clone().with_interface_lag(tau);
    let static_bulge = lag_atol(&bulge(1e-5));
    assert_eq!(lag_atol(&bulge(1e-8)), static_bulge);
    let w_b = (4e5f64 / 5e-13).sqrt();
    let faster = lag_atol(&bulge(1e-10));
    assert!(
        (faster / (static_bulge / (w_b * 1e-10)) - 1.0).abs() < 1e-9,
        "{faster:e} against {:e}",
        static_bulge / (w_b * 1e-10)
    );
}

/// Largest distance between the gaps of `run` and of `reference` (linear between the reference's
/// steps, which are 10–20 times shorter), over the times both cover.
fn largest_gap_difference(run: &TimeSeries, reference: &TimeSeries) -> f64 {
    let end = run.t.last().unwrap().min(*reference.t.last().unwrap());
    let mut j = 0;
    let mut largest = 0.0f64;
    for (&t, &d) in run.t.iter().zip(&run.d).take_while(|(&t, _)| t <= end) {
        while reference.t[j + 1] < t {
            j += 1;
        }
        let th = (t - reference.t[j]) / (reference.t[j + 1] - reference.t[j]);
        let r = reference.d[j] + th * (reference.d[j + 1] - reference.d[j]);
        largest = largest.max((d - r).abs());
    }
    largest
}

/// The few-peak rigid slider with a 10 ns lag under 0.55 V AC (intermittent contact on five
/// Hertz peaks for 4 ms) and with a 1 µs lag under 0.27 V, at the scene's tolerance against
/// Radau5 at 10⁻⁴ of it:
/// - touchdown and take-off within the heater power that moves the clearance by the
///   displacement tolerance (1e-14 m at 1e-7 m/W: 1e-7 W);
/// - the gap along the run within 2.5 times the distance measured with the static tolerance for
///   the lagged force (`k` times the displacement tolerance, before the impulse's factor):
///   1.30e-12 m at 10 ns and 7.39e-12 m at 1 µs. The factors are 183 and 1.8 here; ten times the
///   first (1 830) left the gap 5.1e-12 m off at 10 ns.
#[test]
fn a_lagged_cycle_keeps_the_accuracy_of_the_displacement_tolerance() {
    let scene = few_peak();
    let base = SliderModel::from_scene(&scene).unwrap();
    let programme =
        HeaterProgramme::Fixed(SliderModel::programme_from_knots(&scene.heater.programme).unwrap());
    let mut opts = CycleOptions::from_scene(&scene).unwrap();
    opts.energy_audit = false;
    opts.stop_at_takeoff = true;
    assert_eq!(opts.solver.atol_displacement, DISPLACEMENT);
    let bound = DISPLACEMENT / scene.heater.efficiency_m_per_w;
    opts.keep_series = true;
    for (v_ac, tau, static_gap) in [(0.55, 1e-8, 1.30e-12), (0.27, 1e-6, 7.39e-12)] {
        let model = base
            .clone()
            .with_interface_lag(tau)
            .with_structure(Structure::rigid(scene.slider.mass_kg).unwrap())
            .with_ac_amplitude(v_ac);
        let run = simulate_cycle(&model, &programme, &opts).unwrap();
        let mut tight = opts;
        tight.solver.method = Method::Radau5;
        tight.solver = tight.solver.with_rtol(tight.solver.rtol * 1e-4);
        let reference = simulate_cycle(&model, &programme, &tight).unwrap();
        for (what, a, b) in [
            ("touchdown", run.touchdown, reference.touchdown),
            ("take-off", run.takeoff, reference.takeoff),
        ] {
            let (a, b) = (a.unwrap().power, b.unwrap().power);
            assert!(
                (a - b).abs() <= bound,
                "{v_ac} V, τ = {tau:e} s: {what} {a} W against {b} W (bound {bound:e} W)"
            );
        }
        let gap = largest_gap_difference(
            run.series.as_ref().unwrap(),
            reference.series.as_ref().unwrap(),
        );
        assert!(
            gap <= 2.5 * static_gap,
            "{v_ac} V, τ = {tau:e} s: the gap {gap:e} m off the reference"
        );
    }
}
