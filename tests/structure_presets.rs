//! The slider structures: modal frequencies, shapes and static deflections of the two-coordinate
//! presets against closed forms, pull-in through the condensed stiffness, the rigid preset
//! against the one-mass slider, the energy balance of a bulge cycle, and random structures.

use hdi_tribology::analysis::equilibrium::EquilibriumSolver;
use hdi_tribology::analysis::*;
use hdi_tribology::force::{AirBearingModel, Footprint};
use hdi_tribology::heater::Programme;
use hdi_tribology::model::{SliderModel, SliderSystem, Structure};
use hdi_tribology::ode::{self, Method, Options, SaveAt};
use hdi_tribology::scene::{Scene, StructureSpec};
use hdi_tribology::units::EPSILON_0;
use hdi_tribology::Error;
use nalgebra::U4;
use proptest::prelude::*;
use std::f64::consts::PI;

#[path = "common/scenes.rs"]
mod scenes;

const K_AB: f64 = 3e5;
const M: f64 = 1e-6;

/// The paper scene without damping and with contact alone: at the nominal clearance the contact
/// force and its stiffness are nil, so the modes are those of the structure on the bearing.
fn undamped_free(structure: StructureSpec) -> Scene {
    let mut s = Scene::paper();
    s.intermolecular = None;
    s.electrostatic = None;
    s.air_bearing = AirBearingModel::Linear {
        stiffness_n_per_m: K_AB,
        damping_n_s_per_m: 0.0,
    };
    s.structure = structure;
    s
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Roots `ω²` of `a ω⁴ − b ω² + c = 0`, ascending.
fn quadratic_roots(a: f64, b: f64, c: f64) -> [f64; 2] {
    let disc = (b * b - 4.0 * a * c).sqrt();
    // The stable form for the small root.
    let big = (b + disc) / (2.0 * a);
    [c / (a * big), big]
}

#[test]
fn bulge_modes_match_the_two_mass_closed_form() {
    let (mb, kb) = (1e-10, 1e6);
    let scene = undamped_free(StructureSpec::Bulge {
        mass_kg: mb,
        stiffness_n_per_m: kb,
        damping_ratio: 0.0,
    });
    let model = SliderModel::from_scene(&scene).unwrap();
    // det(K − ω² M) = 0 with K = [[k_ab + k_b, −k_b], [−k_b, k_b]], M = diag(m, m_b).
    let w2 = quadratic_roots(M * mb, M * kb + mb * (K_AB + kb), K_AB * kb);
    let exact = w2.map(|w| w.sqrt() / (2.0 * PI));
    let nat = model.structure().natural_frequencies(K_AB);
    for i in 0..2 {
        assert!(rel(nat[i], exact[i]) < 1e-9, "{nat:?} vs {exact:?}");
    }
    // The linearised slider (interface, Jacobian and balancing included) at rest far from the
    // disk: the same frequencies, no damping, and the shapes z/y = k_b/(k_b − m_b ω²).
    let r = linear_response(&model, 0.0).unwrap();
    let modes: Vec<_> = r.modes.iter().filter(|m| m.im > 0.0).collect();
    assert_eq!(modes.len(), 2, "{:?}", r.modes);
    for (m, (&f, &w2)) in modes.iter().zip(exact.iter().zip(&w2)) {
        assert!(rel(m.frequency, f) < 1e-7, "{} vs {f}", m.frequency);
        assert!(m.damping_ratio.abs() < 1e-7, "{}", m.damping_ratio);
        let ratio = kb / (kb - mb * w2);
        let got = m.shape[1] / m.shape[0];
        assert!(
            rel(got, ratio) < 1e-6,
            "shape {:?}: {got} vs {ratio}",
            m.shape
        );
        assert_eq!(m.shape[2], 0.0);
    }
}

#[test]
fn pitch_modes_match_the_heave_pitch_closed_form() {
    let l = 0.5e-3;
    let (inertia, kp, kc) = (M * l * l / 3.0, K_AB * l * l / 3.0, 12.0);
    let scene = undamped_free(StructureSpec::Pitch {
        inertia_kg_m2: inertia,
        stiffness_n_m_per_rad: Some(kp),
        coupling_stiffness_n_per_rad: Some(kc),
        damping_n_m_s_per_rad: Some(0.0),
        coupling_damping_n_s_per_rad: Some(0.0),
        trailing_edge_m: Some(l),
        from_bearing: false,
    });
    let model = SliderModel::from_scene(&scene).unwrap();
    // det(K − ω² M) = 0 with K = [[k_ab, k_c], [k_c, k_θθ]], M = diag(m, I).
    let w2 = quadratic_roots(M * inertia, M * kp + inertia * K_AB, K_AB * kp - kc * kc);
    let r = linear_response(&model, 0.0).unwrap();
    let modes: Vec<_> = r.modes.iter().filter(|m| m.im > 0.0).collect();
    assert_eq!(modes.len(), 2, "{:?}", r.modes);
    for (m, &w2) in modes.iter().zip(&w2) {
        let f = w2.sqrt() / (2.0 * PI);
        assert!(rel(m.frequency, f) < 1e-7, "{} vs {f}", m.frequency);
        // Heave row: (k_ab − m ω²) y + k_c θ = 0.
        let ratio = -(K_AB - M * w2) / kc;
        let got = m.shape[1] / m.shape[0];
        assert!(
            rel(got, ratio) < 1e-6,
            "shape {:?}: {got} vs {ratio}",
            m.shape
        );
    }
}

#[test]
fn static_deflection_of_the_presets_matches_closed_forms() {
    let base = Scene::paper();
    let rigid = SliderModel::from_scene(&base).unwrap();
    let (mb, kb) = (1e-13, 4e5);
    let bulge = rigid.with_structure(Structure::bulge(M, mb, kb, 0.05).unwrap());
    let l = 0.5e-3;
    let (kp, kc) = (K_AB * l * l / 3.0, 12.0);
    let pitch = rigid
        .with_structure(Structure::pitch(M, M * l * l / 3.0, [kp, kc], [0.0, 0.0], l).unwrap());
    let volt2 = 1.0;
    for d in [8e-9, 4e-9, 2e-9, 1e-9, 0.3e-9] {
        let r = EquilibriumSolver::new(&rigid, volt2).at_gap(d).unwrap();
        let b = EquilibriumSolver::new(&bulge, volt2).at_gap(d).unwrap();
        let p = EquilibriumSolver::new(&pitch, volt2).at_gap(d).unwrap();
        let f = r.interface_force;
        // Bulge: the body balances the whole force on the bearing as the rigid slider does,
        // the bulge sits F/k_b off the body, and that deflection is protrusion the heater
        // must make: P_bulge − P_rigid = F/(η k_b).
        assert!((b.y - r.y).abs() <= 1e-12 * r.y.abs(), "{} {}", b.y, r.y);
        assert!(rel(b.q[1] - b.q[0], f / kb) < 1e-9, "d = {d:e}");
        let dp = f / (rigid.efficiency() * kb);
        assert!(
            rel(b.power - r.power, dp) < 1e-6,
            "d = {d:e}: {}",
            b.power - r.power
        );
        // Pitch with a linear bearing: q = K⁻¹ b F, the bulge at bᵀK⁻¹b F.
        let det = K_AB * kp - kc * kc;
        let (y, th) = ((kp - kc * l) * f / det, (K_AB * l - kc) * f / det);
        assert!(rel(p.q[0], y) < 1e-9, "d = {d:e}: {} vs {y}", p.q[0]);
        assert!(rel(p.q[1], th) < 1e-9, "d = {d:e}: {} vs {th}", p.q[1]);
        assert!(rel(p.protrusion, base.nominal_clearance_m + y + l * th - d) < 1e-12);
    }
}

#[test]
fn pull_in_uses_the_stiffness_condensed_onto_the_bulge() {
    // A flat plate on the bulge: the bulge spring and the bearing in series hold it.
    let area = 1e-11;
    let mut s = scenes::electrostatic_only(Footprint::Flat { area_m2: area });
    let kb = 2e5;
    s.structure = StructureSpec::Bulge {
        mass_kg: 1e-12,
        stiffness_n_per_m: kb,
        damping_ratio: 0.1,
    };
    let model = SliderModel::from_scene(&s).unwrap();
    let pi = pull_in_voltage(&model, 0.0, &StaticOptions::new(1.0)).unwrap();
    let k = K_AB * kb / (K_AB + kb);
    let g = s.nominal_clearance_m;
    let exact = (8.0 * k * g.powi(3) / (27.0 * EPSILON_0 * area)).sqrt();
    assert!(rel(pi.voltage, exact) < 1e-8, "{} vs {exact}", pi.voltage);
    assert!(rel(pi.d, 2.0 * g / 3.0) < 1e-8, "{}", pi.d);
}

#[test]
fn rigid_spelled_out_equals_the_default_and_the_general_form() {
    let paper = Scene::paper();
    let text = paper.to_toml_string().unwrap() + "\n[structure]\npreset = \"rigid\"\n";
    let spelled = Scene::from_toml_str(&text).unwrap();
    assert_eq!(spelled, paper);
    let opts = StaticOptions::new(paper.detector.contact_threshold_n);
    let rigid = SliderModel::from_scene(&paper).unwrap();
    let h = static_hysteresis(&rigid, &opts).unwrap();
    // The letter's numbers.
    assert!((h.touchdown.power_mw() - 74.324).abs() < 5e-4, "{h:?}");
    assert!((h.takeoff.power_mw() - 68.317).abs() < 5e-4, "{h:?}");
    let pi = pull_in_voltage(&rigid, 0.0, &opts).unwrap();
    assert!((pi.voltage - 3.618).abs() < 5e-4, "{pi:?}");
    // The same slider as a general one-coordinate structure.
    let mut general = paper.clone();
    general.structure = StructureSpec::General {
        mass: vec![vec![paper.slider.mass_kg]],
        damping: vec![vec![0.0]],
        stiffness: vec![vec![0.0]],
        bulge_influence: vec![1.0],
    };
    let g = SliderModel::from_scene(&general).unwrap();
    let hg = static_hysteresis(&g, &opts).unwrap();
    assert!(rel(hg.touchdown.power, h.touchdown.power) < 1e-9);
    assert!(rel(hg.takeoff.power, h.takeoff.power) < 1e-9);
    assert!(rel(pull_in_voltage(&g, 0.0, &opts).unwrap().voltage, pi.voltage) < 1e-9);
    // A very stiff bulge is the rigid slider.
    let stiff =
        rigid.with_structure(Structure::bulge(paper.slider.mass_kg, 1e-12, 1e13, 0.05).unwrap());
    let hs = static_hysteresis(&stiff, &opts).unwrap();
    assert!(rel(hs.touchdown.power, h.touchdown.power) < 1e-6, "{hs:?}");
    assert!(rel(hs.takeoff.power, h.takeoff.power) < 1e-6, "{hs:?}");
}

#[test]
fn energy_balance_of_a_bulge_cycle() {
    // Mechanical energy plus damping losses equal the work of the interface force, over a ramp
    // into contact and back: E(T) − E(0) + ∫(c_ab ẏ² + c_b (ż − ẏ)²) dt = ∫ F_if ż dt.
    let (mb, kb, zeta) = (1e-10, 1e6, 0.1);
    let mut scene = Scene::paper();
    scene.structure = StructureSpec::Bulge {
        mass_kg: mb,
        stiffness_n_per_m: kb,
        damping_ratio: zeta,
    };
    scene.voltage.dc_v = 1.0;
    let c_ab = match scene.air_bearing {
        AirBearingModel::Linear {
            damping_n_s_per_m, ..
        } => damping_n_s_per_m,
        _ => unreachable!(),
    };
    let cb = 2.0 * zeta * (kb * mb).sqrt();
    let model = SliderModel::from_scene(&scene).unwrap();
    let programme = Programme::new(vec![(0.0, 0.06), (1e-3, 0.08), (2e-3, 0.06)]).unwrap();
    let eq = equilibrium::flying_equilibrium(&model, 0.06, 1.0, &equilibrium::ScanGrid::default())
        .unwrap();
    let sys = SliderSystem::new(&model, model.inputs(programme.clone()), false);
    let y0 = sys.initial_state(U4, &eq.rest());
    let o = Options::default()
        .rtol(1e-11)
        .atol_per_component(sys.tolerances(1e-19, 0.0, 0.0))
        .t_stops(vec![1e-3])
        .save(SaveAt::Steps)
        .dense(true);
    let sol = ode::solve(&sys, 0.0, y0, 2e-3, Method::Radau5, &o, &mut []).unwrap();
    let energy = |s: &nalgebra::Vector4<f64>| {
        let (y, z, vy, vz) = (s[0], s[1], s[2], s[3]);
        0.5 * M * vy * vy + 0.5 * mb * vz * vz + 0.5 * kb * (z - y).powi(2) + 0.5 * K_AB * y * y
    };
    // 5-point Gauss–Legendre on every step, on the dense output.
    let nodes = [
        (0.0, 128.0 / 225.0),
        (0.538_469_310_105_683, 0.478_628_670_499_366_5),
        (-0.538_469_310_105_683, 0.478_628_670_499_366_5),
        (0.906_179_845_938_664, 0.236_926_885_056_189_1),
        (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    ];
    let (mut work, mut loss) = (0.0, 0.0);
    for w in sol.t.windows(2) {
        let (a, b) = (w[0], w[1]);
        for (x, wt) in nodes {
            let t = 0.5 * (a + b) + 0.5 * (b - a) * x;
            let s = sol.sample(t).unwrap();
            let f = model
                .interface_force(sys.gaps(t, &s), model.voltage().squared(t))
                .value;
            work += 0.5 * (b - a) * wt * f * s[3];
            loss += 0.5 * (b - a) * wt * (c_ab * s[2] * s[2] + cb * (s[3] - s[2]).powi(2));
        }
    }
    let de = energy(sol.y_final()) - energy(&sol.y[0]);
    let scale = work.abs().max(loss);
    assert!(loss > 0.0 && scale > 0.0);
    let residual = de + loss - work;
    assert!(
        residual.abs() <= 1e-6 * scale,
        "ΔE {de:e} + losses {loss:e} − work {work:e} = {residual:e}"
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    /// Any bulge or pitch structure gives finite static results or a typed error.
    #[test]
    fn random_structures_give_finite_results_or_typed_errors(
        log_mb in -14.0f64..-8.0,
        log_kb in 4.0f64..8.0,
        zeta in 0.0f64..1.0,
        pitch in any::<bool>(),
        kc in -50.0f64..50.0,
    ) {
        let rigid = SliderModel::from_scene(&Scene::paper()).unwrap();
        let l = 0.5e-3;
        let structure = if pitch {
            Structure::pitch(M, M * l * l / 3.0, [K_AB * l * l / 3.0, kc], [1e-9, 0.0], l)
        } else {
            Structure::bulge(M, 10f64.powf(log_mb), 10f64.powf(log_kb), zeta)
        }
        .unwrap();
        let model = rigid.with_structure(structure);
        match static_hysteresis(&model, &StaticOptions::new(5e-5)) {
            Ok(h) => {
                prop_assert!(h.touchdown.power.is_finite() && h.takeoff.power.is_finite());
                prop_assert!(h.hysteresis.is_finite());
            }
            Err(e) => prop_assert!(
                matches!(e, Error::Analysis(_) | Error::NoConvergence { .. }),
                "{e:?}"
            ),
        }
        match linear_response(&model, 0.03) {
            Ok(r) => prop_assert!(r.modes.iter().all(|m| m.frequency.is_finite())),
            Err(e) => prop_assert!(matches!(e, Error::Analysis(_) | Error::NoConvergence { .. }), "{e:?}"),
        }
    }
}
