//! Every public constructor rejects non-finite, impossible and inconsistent input with a typed
//! error that names the field; none panics.

use hdi_tribology::analysis::cycle::CycleError;
use hdi_tribology::analysis::cycle::{
    simulate_cycle, CycleOptions, Detector, HeaterProgramme, SolverSettings,
};
use hdi_tribology::analysis::{
    flying_equilibrium, pull_in_voltage, s_curve, static_hysteresis, ScanGrid, StaticOptions,
};
use hdi_tribology::force::{
    composite_modulus, AirBearingModel, Coulomb, CubicBearing, Electrostatic, Footprint,
    GapReference, GreenwoodWilliamson, InterfaceForces, Intermolecular, LennardJones39,
    LinearBearing, PowerLawBearing,
};
use hdi_tribology::heater::Programme;
use hdi_tribology::model::SliderModel;
use hdi_tribology::ode::{self, Method, Options};
use hdi_tribology::quadrature::{Table, TableOptions};
use hdi_tribology::scene::Scene;
use hdi_tribology::surface::{
    Discrete, Empirical, Gaussian, GaussianHeights, PeakModel, RiceMaxima, Rician,
};
use hdi_tribology::Error;
use std::sync::Arc;

const BAD: [f64; 4] = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -1.0];

/// The field an input error names; panics (fails the test) on any other outcome.
fn field<T: std::fmt::Debug>(r: hdi_tribology::Result<T>) -> String {
    match r {
        Err(Error::InvalidInput { field, reason }) => {
            assert!(!reason.is_empty(), "{field}: empty reason");
            field
        }
        other => panic!("expected an input error, got {other:?}"),
    }
}

fn sphere() -> Footprint {
    Footprint::Paraboloid {
        radius_of_curvature_m: 0.02,
        max_radius_m: None,
    }
}

fn smooth() -> GaussianHeights {
    GaussianHeights::new(0.0).unwrap()
}

#[test]
fn peak_laws_and_heights_name_their_fields() {
    for x in BAD {
        assert_eq!(field(Gaussian::new(0.0, x)), "peaks.std");
        assert_eq!(field(RiceMaxima::new(x, 0.7)), "peaks.sigma");
        assert_eq!(field(Rician::new(0.0, x)), "peaks.s");
        assert_eq!(field(GaussianHeights::new(x)), "surface.sigma");
    }
    // The engineering-unit constructors check the same fields.
    for x in BAD {
        assert_eq!(field(Gaussian::from_nm(0.0, x)), "peaks.std");
        assert_eq!(field(RiceMaxima::from_nm(x, 0.7)), "peaks.sigma");
        assert_eq!(field(Rician::from_nm(0.0, x)), "peaks.s");
        assert_eq!(field(GaussianHeights::from_nm(x)), "surface.sigma");
    }
    assert_eq!(field(Discrete::from_heights_nm(&[])), "peaks.heights");
    assert_eq!(
        field(Empirical::from_sample_nm(&[1.0, f64::NAN])),
        "peaks.sample"
    );
    assert_eq!(field(Gaussian::new(f64::NAN, 1e-9)), "peaks.mean");
    assert_eq!(field(Gaussian::new(0.0, 0.0)), "peaks.std");
    for eps in [0.0, -0.1, 1.0 + 1e-12, f64::NAN] {
        assert_eq!(field(RiceMaxima::new(1e-9, eps)), "peaks.epsilon");
    }
    assert_eq!(field(Rician::new(-1e-9, 1e-9)), "peaks.nu");
}

#[test]
fn histograms_and_samples_reject_inconsistent_and_oversized_input() {
    // Edges out of order, counts negative or all zero, lengths that do not match, empty input.
    assert_eq!(
        field(Empirical::from_histogram(&[0.0, 2.0, 1.0], &[1.0, 1.0])),
        "peaks.edges"
    );
    assert_eq!(
        field(Empirical::from_histogram(&[0.0, 1.0, 1.0], &[1.0, 1.0])),
        "peaks.edges"
    );
    assert_eq!(
        field(Empirical::from_histogram(&[0.0, f64::NAN], &[1.0])),
        "peaks.edges"
    );
    assert_eq!(
        field(Empirical::from_histogram(&[0.0, 1.0], &[1.0, 1.0])),
        "peaks.edges"
    );
    assert_eq!(
        field(Empirical::from_histogram(&[0.0, 1.0], &[-1.0])),
        "peaks.counts"
    );
    assert_eq!(
        field(Empirical::from_histogram(&[0.0, 1.0], &[0.0])),
        "peaks.counts"
    );
    assert_eq!(
        field(Empirical::from_histogram(&[0.0, 1.0], &[f64::INFINITY])),
        "peaks.counts"
    );
    assert_eq!(
        field(Empirical::from_histogram(&[0.0], &[])),
        "peaks.counts"
    );
    // Counts whose total overflows.
    assert_eq!(
        field(Empirical::from_histogram(
            &[0.0, 1.0, 2.0],
            &[f64::MAX, f64::MAX]
        )),
        "peaks.counts"
    );
    assert_eq!(field(Empirical::from_sample(&[1.0])), "peaks.sample");
    assert_eq!(field(Empirical::from_sample(&[1.0, 1.0])), "peaks.sample");
    assert_eq!(
        field(Empirical::from_sample(&[0.0, f64::NAN])),
        "peaks.sample"
    );
    assert_eq!(field(Discrete::from_heights(vec![])), "peaks.heights");
    assert_eq!(
        field(Discrete::from_heights(vec![0.0, f64::INFINITY])),
        "peaks.heights"
    );
    // Oversized: a sampled ensemble so large it would exhaust memory is refused before any
    // allocation (the limit is 10⁷ peaks).
    let parent = Gaussian::new(0.0, 1e-9).unwrap();
    assert_eq!(field(Discrete::sample(&parent, usize::MAX, 1)), "peaks.n");
    assert_eq!(field(Discrete::sample(&parent, 0, 1)), "peaks.n");
    let huge = PeakModel::DiscreteSampled {
        from: Box::new(PeakModel::Gaussian {
            mean_m: 0.0,
            std_m: 1e-9,
        }),
        n: 1 << 60,
        seed: 3,
    };
    assert_eq!(field(huge.build()), "peaks.n");
    let nested = PeakModel::DiscreteSampled {
        from: Box::new(PeakModel::Rician {
            nu_m: 0.0,
            s_m: -1.0,
        }),
        n: 10,
        seed: 3,
    };
    assert_eq!(field(nested.build()), "peaks.from.s_m");
}

#[test]
fn pressure_laws_terms_and_footprints_name_their_fields() {
    for x in BAD {
        assert_eq!(field(LennardJones39::new(x, 1e-76)), "hamaker_attractive_j");
        assert_eq!(
            field(LennardJones39::new(1e-19, x)),
            "hamaker_repulsive_j_m6"
        );
        assert_eq!(field(Coulomb::new(x)), "dielectric_thickness_m");
        let flat = Footprint::Flat { area_m2: x };
        assert_eq!(field(flat.validate("fp")), "fp.area_m2");
        let p = Footprint::Paraboloid {
            radius_of_curvature_m: x,
            max_radius_m: None,
        };
        assert_eq!(field(p.validate("fp")), "fp.radius_of_curvature_m");
        let cut = Footprint::Paraboloid {
            radius_of_curvature_m: 0.02,
            max_radius_m: Some(x),
        };
        assert_eq!(field(cut.validate("fp")), "fp.max_radius_m");
        assert_eq!(
            field(Electrostatic::new(
                0.0,
                x,
                smooth(),
                sphere(),
                GapReference::Bulge
            )),
            "cutoff_m"
        );
        let peaks = Arc::new(Gaussian::new(0.0, 1e-9).unwrap());
        assert_eq!(
            field(GreenwoodWilliamson::new(
                x,
                1e-7,
                1.5e14,
                peaks.clone(),
                sphere(),
                GapReference::Bulge
            )),
            "composite_modulus_pa"
        );
        assert_eq!(
            field(GreenwoodWilliamson::new(
                1e11,
                x,
                1.5e14,
                peaks.clone(),
                sphere(),
                GapReference::Bulge
            )),
            "asperity_radius_m"
        );
        assert_eq!(
            field(GreenwoodWilliamson::new(
                1e11,
                1e-7,
                x,
                peaks,
                sphere(),
                GapReference::Bulge
            )),
            "asperity_density_per_m2"
        );
    }
    // max_radius = 0 is "max_radius ≤ 0".
    let zero = Footprint::Paraboloid {
        radius_of_curvature_m: 0.02,
        max_radius_m: Some(0.0),
    };
    assert_eq!(field(zero.validate("fp")), "fp.max_radius_m");
    assert_eq!(
        field(Intermolecular::new(
            1e-19,
            1e-76,
            Some(0.0),
            smooth(),
            sphere(),
            GapReference::Bulge
        )),
        "cutoff_m"
    );
    for (nu, name) in [(0.6, "nu1"), (-1.0, "nu1"), (f64::NAN, "nu1")] {
        assert_eq!(field(composite_modulus(1e11, nu, 1e11, 0.3)), name);
    }
    assert_eq!(field(composite_modulus(1e11, 0.3, -1.0, 0.3)), "e2");
}

#[test]
fn air_bearings_name_their_fields() {
    for x in BAD {
        assert_eq!(
            field(LinearBearing::new(x, 0.05)),
            "air_bearing.stiffness_n_per_m"
        );
        assert_eq!(
            field(LinearBearing::new(3e5, x)),
            "air_bearing.damping_n_s_per_m"
        );
        assert_eq!(
            field(PowerLawBearing::new(x, 3.0, 1e-8, 0.05)),
            "air_bearing.preload_n"
        );
        assert_eq!(
            field(PowerLawBearing::new(1.0, x, 1e-8, 0.05)),
            "air_bearing.exponent"
        );
        assert_eq!(
            field(PowerLawBearing::new(1.0, 3.0, x, 0.05)),
            "air_bearing.reference_gap_m"
        );
    }
    assert_eq!(
        field(CubicBearing::new(3e5, f64::NAN, 0.05)),
        "air_bearing.cubic_stiffness_n_per_m3"
    );
    let m = AirBearingModel::Linear {
        stiffness_n_per_m: 0.0,
        damping_n_s_per_m: 0.0,
    };
    assert_eq!(field(m.build()), "air_bearing.stiffness_n_per_m");
}

#[test]
fn heater_programmes_reject_empty_unordered_and_non_finite_knots() {
    assert_eq!(field(Programme::new(vec![])), "heater.programme");
    assert_eq!(
        field(Programme::from_ms_mw(&[(0.0, 60.0)])),
        "heater.programme"
    );
    assert_eq!(field(Programme::new(vec![(0.0, 0.06)])), "heater.programme");
    assert_eq!(
        field(Programme::new(vec![(0.0, 0.06), (0.0, 0.07)])),
        "heater.programme[1].time"
    );
    assert_eq!(
        field(Programme::new(vec![(1.0, 0.06), (0.5, 0.07)])),
        "heater.programme[1].time"
    );
    assert_eq!(
        field(Programme::new(vec![(0.0, 0.06), (f64::NAN, 0.07)])),
        "heater.programme[1].time"
    );
    for p in BAD {
        assert_eq!(
            field(Programme::new(vec![(0.0, 0.06), (1.0, p)])),
            "heater.programme[1].power"
        );
    }
    assert_eq!(
        field(Programme::constant(0.06, 0.0)),
        "heater.programme[1].time"
    );
}

#[test]
fn tables_reject_bad_ranges_and_tolerances() {
    let f = |x: f64| Ok((x, 1.0));
    assert_eq!(
        field(Table::build(f, 1.0, 0.0, &TableOptions::default())),
        "table.hi"
    );
    assert_eq!(
        field(Table::build(f, f64::NAN, 1.0, &TableOptions::default())),
        "table.lo"
    );
    for x in BAD {
        let o = TableOptions {
            rel_tol: x,
            ..TableOptions::default()
        };
        assert_eq!(field(Table::build(f, 0.0, 1.0, &o)), "table.rel_tol");
    }
    // A table that would need more nodes than allowed stops with a typed error instead of
    // growing without bound.
    let tiny = TableOptions {
        rel_tol: 1e-15,
        abs_tol: 0.0,
        max_nodes: 1000,
    };
    let wiggly = |x: f64| Ok(((1e3 * x).sin(), 1e3 * (1e3 * x).cos()));
    assert!(matches!(
        Table::build(wiggly, 0.0, 1.0, &tiny),
        Err(Error::NoConvergence(_))
    ));
    let scene = Scene::paper();
    for range in [(1e-8, 1e-9), (f64::NAN, 1e-8), (0.0, f64::INFINITY)] {
        let terms = scene.interface_terms().unwrap();
        assert_eq!(
            field(InterfaceForces::build(
                terms,
                range,
                &TableOptions::default()
            )),
            "table range"
        );
    }
}

#[test]
fn ode_options_reject_bad_tolerances_and_limits() {
    let sys = ode::FnSystem::new(
        |_t: f64, y: &nalgebra::Vector1<f64>, dy: &mut nalgebra::Vector1<f64>| {
            dy[0] = -y[0];
        },
    );
    let y0 = nalgebra::Vector1::new(1.0);
    let cases: Vec<(Options, &str)> = vec![
        (Options::default().rtol(0.0), "rtol"),
        (Options::default().rtol(f64::NAN), "rtol"),
        (Options::default().atol(-1.0), "atol"),
        (Options::default().max_steps(0), "max_steps"),
        (Options::default().h_max(0.0), "h_max"),
    ];
    for (o, name) in cases {
        match ode::solve(&sys, 0.0, y0, 1.0, Method::Tsit5, &o, &mut []) {
            Err(ode::OdeError::InvalidInput { field, .. }) => {
                assert!(field.contains(name), "{field} should name {name}")
            }
            other => panic!("{name}: expected an input error, got {other:?}"),
        }
    }
    for (a, b) in [(0.0, f64::NAN), (f64::INFINITY, 1.0)] {
        assert!(matches!(
            ode::solve(&sys, a, y0, b, Method::Tsit5, &Options::default(), &mut []),
            Err(ode::OdeError::InvalidInput { .. })
        ));
    }
}

fn paper_model() -> SliderModel {
    SliderModel::from_scene(&Scene::paper()).unwrap()
}

#[test]
fn analyses_reject_bad_options_and_scan_grids() {
    let model = paper_model();
    for x in [0.0, -1.0, f64::NAN] {
        assert_eq!(
            field(static_hysteresis(&model, &StaticOptions::new(x))),
            "contact_threshold"
        );
    }
    // Scan grids that are non-finite, zero, negative, or so fine that the scan would exhaust
    // memory are refused before any point is made.
    let bad_grids = [
        (0.0, 5e-11, 5e-9),
        (-2e-12, 5e-11, 5e-9),
        (f64::NAN, 5e-11, 5e-9),
        (2e-12, 0.0, 5e-9),
        (2e-12, f64::INFINITY, 5e-9),
        (2e-12, 5e-11, f64::NAN),
        (1e-30, 5e-11, 5e-9),
    ];
    for (fine, coarse, until) in bad_grids {
        let grid = ScanGrid {
            fine_step: fine,
            coarse_step: coarse,
            fine_until: until,
            ..ScanGrid::default()
        };
        let f = field(s_curve(&model, None, &grid));
        assert!(f.starts_with("grid."), "{f}");
        let f = field(flying_equilibrium(&model, 0.06, 0.0, &grid));
        assert!(f.starts_with("grid."), "{f}");
        let mut o = StaticOptions::new(5e-5);
        o.grid = grid;
        assert!(field(static_hysteresis(&model, &o)).starts_with("grid."));
        assert!(field(pull_in_voltage(&model, 0.0, &o)).starts_with("grid."));
    }
    assert_eq!(
        field(flying_equilibrium(
            &model,
            f64::NAN,
            0.0,
            &ScanGrid::default()
        )),
        "power"
    );
    assert_eq!(
        field(flying_equilibrium(&model, 0.06, -1.0, &ScanGrid::default())),
        "volt2"
    );
    assert_eq!(
        field(s_curve(&model, Some((1e-8, 1e-9)), &ScanGrid::default())),
        "range"
    );
}

#[test]
fn cycles_reject_bad_detectors_solvers_and_programmes() {
    let scene = Scene::paper();
    let model = paper_model();
    let base = CycleOptions::from_scene(&scene).unwrap();
    let programme = HeaterProgramme::Fixed(Programme::constant(0.06, 1e-4).unwrap());
    let with = |det: Detector, sol: SolverSettings| CycleOptions {
        detector: det,
        solver: sol,
        keep_series: false,
        series_window: None,
        stop_outside_tables: false,
        energy_audit: true,
        stop_at_takeoff: false,
        mean_temperature: true,
    };
    for x in BAD {
        let mut d = base.detector;
        d.contact_threshold = x;
        assert_eq!(
            field(simulate_cycle(&model, &programme, &with(d, base.solver))),
            "detector.contact_threshold"
        );
        let mut d = base.detector;
        d.window = x;
        assert_eq!(
            field(simulate_cycle(&model, &programme, &with(d, base.solver))),
            "detector.window"
        );
        let mut s = base.solver;
        s.rtol = x;
        assert_eq!(
            field(simulate_cycle(&model, &programme, &with(base.detector, s))),
            "solver.rtol"
        );
        let mut s = base.solver;
        s.atol_displacement = x;
        assert_eq!(
            field(simulate_cycle(&model, &programme, &with(base.detector, s))),
            "solver.atol_displacement"
        );
        let triggered = HeaterProgramme::Triggered {
            start_power: 0.06,
            ramp_rate: x,
            overshoot: 1e-3,
        };
        assert_eq!(
            field(simulate_cycle(&model, &triggered, &base)),
            "programme.ramp_rate"
        );
    }
    let mut s = base.solver;
    s.max_steps = 0;
    assert_eq!(
        field(simulate_cycle(&model, &programme, &with(base.detector, s))),
        "solver.max_steps"
    );
    // A series window that ends before it starts, or is not finite.
    for window in [(2e-3, 1e-3), (f64::NAN, 1e-3), (0.0, f64::INFINITY)] {
        let mut o = base;
        o.keep_series = true;
        o.series_window = Some(window);
        assert_eq!(
            field(simulate_cycle(&model, &programme, &o)),
            "series_window"
        );
    }
}

/// Analyses in heater power need `η > 0`; a heater too weak to reach touchdown fails the
/// triggered protocol at once instead of ramping for ever.
#[test]
fn analyses_in_power_need_a_working_heater() {
    let mut scene = Scene::paper();
    scene.heater.efficiency_m_per_w = 0.0;
    let model = SliderModel::from_scene(&scene).unwrap();
    let opts = StaticOptions::new(5e-5);
    assert_eq!(
        field(static_hysteresis(&model, &opts)),
        "heater.efficiency_m_per_w"
    );
    assert_eq!(
        field(s_curve(&model, None, &ScanGrid::default())),
        "heater.efficiency_m_per_w"
    );
    let programme = HeaterProgramme::Fixed(Programme::constant(0.06, 1e-4).unwrap());
    let copts = CycleOptions::from_scene(&scene).unwrap();
    assert_eq!(
        field(simulate_cycle(&model, &programme, &copts)),
        "heater.efficiency_m_per_w"
    );
    // Pull-in at zero power needs no heater.
    assert!(pull_in_voltage(&model, 0.0, &opts).is_ok());
    scene.heater.efficiency_m_per_w = 1e-30;
    let weak = SliderModel::from_scene(&scene).unwrap();
    let triggered = HeaterProgramme::Triggered {
        start_power: 0.06,
        ramp_rate: 5.0,
        overshoot: 1e-3,
    };
    let e = simulate_cycle(&weak, &triggered, &copts).unwrap_err();
    match e.failure().and_then(|f| f.downcast_ref()) {
        Some(CycleError::TooManySegments {
            segments,
            max_segments,
            ..
        }) => assert!(segments > max_segments, "{segments} {max_segments}"),
        _ => panic!("expected the segment bound, got {e:?}"),
    }
}

/// A table budget so large that refinement to an unreachable tolerance would exhaust memory, and
/// a tolerance of exactly zero, are refused before any node is made (a build with both once
/// grew past 24 GB).
#[test]
fn oversized_tables_and_zero_tolerances_are_refused() {
    let f = |x: f64| Ok((x.sin(), x.cos()));
    let huge = TableOptions {
        max_nodes: usize::MAX,
        ..TableOptions::default()
    };
    assert_eq!(field(Table::build(f, 0.0, 10.0, &huge)), "table.max_nodes");
    let zero = TableOptions {
        rel_tol: 0.0,
        abs_tol: 0.0,
        max_nodes: 1000,
    };
    assert_eq!(field(Table::build(f, 0.0, 10.0, &zero)), "table.rel_tol");
    // The largest allowed budget with a tolerance that cannot be met stops at the budget.
    let tight = TableOptions {
        rel_tol: 1e-300,
        abs_tol: 0.0,
        max_nodes: 100_000,
    };
    assert!(matches!(
        Table::build(f, 0.0, 10.0, &tight),
        Err(Error::NoConvergence(_))
    ));
}
