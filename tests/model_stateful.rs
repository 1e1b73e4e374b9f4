//! A term with a state of its own ([`RelaxingState`]) rides along in every analysis: its
//! closed-form relaxation comes out of a cycle and of the drive, and its equilibrium enters the
//! static balance.

use hdi_tribology::analysis::{
    flying_equilibrium, simulate_cycle, CycleOptions, HeaterProgramme, ScanGrid,
};
use hdi_tribology::drive::{Command, DiskSpec, DriveOptions, Plant};
use hdi_tribology::force::{Gaps, RelaxingState};
use hdi_tribology::model::{SliderModel, StateLayout};
use hdi_tribology::scene::Scene;

const TAU: f64 = 2e-4;

fn paper() -> SliderModel {
    SliderModel::from_scene(&Scene::paper()).unwrap()
}

/// `x(t) = e^{−(t−t₀)/τ}` at every step of a cycle, to the integration's accuracy; and the
/// state, which adds no force, leaves touchdown and take-off where they were (within the
/// detector's interpolation, since the state joins the error norm and moves the steps).
#[test]
fn a_relaxing_state_decays_in_closed_form_through_a_cycle() {
    let scene = Scene::paper();
    let plain = paper();
    let model = plain
        .with_stateful_term(RelaxingState::relaxation(TAU, 1.0).unwrap())
        .unwrap();
    let layout = StateLayout::of(&model, true);
    assert_eq!(layout.term_states, (2, 1));
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    let mut opts = CycleOptions::from_scene(&scene).unwrap();
    opts.keep_series = true;
    let with = simulate_cycle(&model, &programme, &opts).unwrap();
    let series = with.series.as_ref().unwrap();
    assert_eq!(series.term_states.len(), 1);
    let t0 = series.t[0];
    let rtol = opts.solver.rtol;
    let mut worst: f64 = 0.0;
    for (t, x) in series.t.iter().zip(&series.term_states[0]) {
        let exact = (-(t - t0) / TAU).exp();
        // Mixed error control: the state's absolute tolerance is 1e9 per metre of the
        // displacement tolerance (|x₀| = 1 per nanometre), its relative one the solver's.
        let allowed = 100.0 * (opts.solver.atol_displacement * 1e9 + rtol * exact);
        worst = worst.max((x - exact).abs() / allowed);
    }
    assert!(worst <= 1.0, "worst error {worst} of the allowance");
    // Far past a few τ it is gone, and it decayed, not grew, all along.
    assert!(series.term_states[0].last().unwrap().abs() < 1e-6);
    let without = simulate_cycle(&plain, &programme, &opts).unwrap();
    let (a, b) = (with.touchdown.unwrap(), without.touchdown.unwrap());
    assert!((a.power - b.power).abs() < 1e-5, "{a:?} vs {b:?}");
    let (a, b) = (with.takeoff.unwrap(), without.takeoff.unwrap());
    assert!((a.power - b.power).abs() < 1e-5, "{a:?} vs {b:?}");
}

/// The drive carries the state across periods and across command changes (each a restart of
/// the integrator): `x(t) = e^{−t/τ}` at every period end.
#[test]
fn a_relaxing_state_decays_in_closed_form_through_the_drive() {
    let model = paper()
        .with_stateful_term(RelaxingState::relaxation(TAU, 1.0).unwrap())
        .unwrap();
    let opts = DriveOptions {
        disk: DiskSpec::flat(),
        ..DriveOptions::default()
    };
    let mut drive = Plant::from_model(&model, 0.025, 3, opts)
        .unwrap()
        .into_drive()
        .unwrap();
    assert_eq!(drive.term_states(), &[1.0]);
    let dt = 50e-6;
    let mut worst: f64 = 0.0;
    for k in 0..40 {
        // A new command every fifth period: restarts must carry the state as it is.
        let p = if (k / 5) % 2 == 0 { 60.0 } else { 62.0 };
        let s = drive.step(&Command::heater_mw(p), dt).unwrap();
        let exact = (-s.time_s / TAU).exp();
        let x = drive.term_states()[0];
        worst = worst.max((x - exact).abs() / (1e-5 + 1e-6 * exact));
    }
    assert!(worst <= 100.0, "worst error {worst} × (1e-5 + 1e-6 x)");
}

/// With a force, the state's equilibrium enters the static balance: the interface force gains
/// `k a d` and its slope `k a`, and a drive held at one power settles on the static flying
/// equilibrium of the model with the term.
#[test]
fn a_stateful_force_enters_the_statics_at_its_equilibrium() {
    let plain = paper();
    let (a, k) = (1e9, -2e-5); // x → d / 1 nm; F = −20 µN per unit of x: an attraction
    let model = plain
        .with_stateful_term(RelaxingState::new(1e-6, a, k, None).unwrap())
        .unwrap();
    let g = Gaps::same(3e-9);
    let (f0, f1) = (plain.interface_force(g, 0.0), model.interface_force(g, 0.0));
    assert!((f1.value - f0.value - k * a * 3e-9).abs() <= 1e-12 * f0.value.abs().max(1e-9));
    assert!((f1.d_bulge - f0.d_bulge - k * a).abs() <= 1e-9 * (k * a).abs());
    let p = 0.06;
    let eq = flying_equilibrium(&model, p, 0.0, &ScanGrid::default()).unwrap();
    let eq0 = flying_equilibrium(&plain, p, 0.0, &ScanGrid::default()).unwrap();
    assert!(
        eq.d < eq0.d - 1e-11,
        "the attraction closes the gap: {} vs {}",
        eq.d,
        eq0.d
    );
    let opts = DriveOptions {
        disk: DiskSpec::flat(),
        initial_power: p,
        ..DriveOptions::default()
    };
    let mut drive = Plant::from_model(&model, 0.025, 3, opts)
        .unwrap()
        .into_drive()
        .unwrap();
    let mut s = drive.step(&Command::heater_mw(60.0), 50e-6).unwrap();
    for _ in 0..20 {
        s = drive.step(&Command::heater_mw(60.0), 50e-6).unwrap();
    }
    assert!(
        ((s.truth.gap_nm * 1e-9) - eq.d).abs() < 1e-13,
        "drive {} m, static {} m",
        (s.truth.gap_nm * 1e-9),
        eq.d
    );
    assert!((drive.term_states()[0] - a * eq.d).abs() < 1e-4 * a * eq.d);
}

/// Pull-in sees a stateful term at its equilibrium too: at the pull-in voltage and gap of a
/// model with an attracting term, the interface force (the term's included) balances the load
/// on the bulge and the total stiffness vanishes; the attraction lowers the pull-in voltage.
#[test]
fn pull_in_sees_a_stateful_force_at_its_equilibrium() {
    use hdi_tribology::analysis::{pull_in_voltage, StaticOptions};
    let plain = paper();
    let (a, k) = (1e9, -2e-5);
    let model = plain
        .with_stateful_term(RelaxingState::new(1e-6, a, k, None).unwrap())
        .unwrap();
    let (p, opts) = (0.03, StaticOptions::new(5e-5));
    let pi = pull_in_voltage(&model, p, &opts).unwrap();
    let pi0 = pull_in_voltage(&plain, p, &opts).unwrap();
    assert!(
        pi.voltage < pi0.voltage - 1e-3,
        "{} V vs {} V",
        pi.voltage,
        pi0.voltage
    );
    let delta = model.protrusion(p);
    let (q, load, k_structure) = model
        .bulge_load(pi.d - model.nominal_clearance() + delta)
        .unwrap();
    let f = model.interface_force(model.gaps(&q, delta), pi.voltage * pi.voltage);
    assert!(
        (f.value - load).abs() <= 1e-6 * load.abs(),
        "balance: {} N vs {} N",
        f.value,
        load
    );
    let k_total = k_structure - (f.d_bulge + f.d_pad);
    assert!(
        k_total.abs() <= 1e-3 * k_structure,
        "stiffness at pull-in {k_total} N/m of {k_structure} N/m"
    );
}
