//! Lubricant menisci with memory: the single-sphere limits against Israelachvili's closed forms,
//! the rupture distance against Lian's law, the adhesion pressure against the sub-boundary
//! lubrication band for the head–disk interface, Ono's trends, and the term off to the bit.

use std::f64::consts::PI;
use std::sync::Arc;

use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, HeaterProgramme};
use hdi_tribology::force::{
    lian_rupture_distance, Footprint, Gaps, Meniscus, MeniscusParams, StatefulTerm, Wetting,
};
use hdi_tribology::model::SliderModel;
use hdi_tribology::scene::{LubricantSpec, Scene, WettingSpec};
use hdi_tribology::surface::{Discrete, RiceMaxima};
use hdi_tribology::Error;

const GAMMA: f64 = 0.024; // N/m, PFPE (Zdol) at room temperature
const R: f64 = 1e-7; // asperity radius of the paper scene, m

fn params(t_m: f64, theta: f64, wetting: Wetting, rupture: Option<f64>) -> MeniscusParams {
    MeniscusParams {
        surface_tension: GAMMA,
        contact_angle: theta,
        wetting,
        mobile_thickness: t_m,
        rupture_distance: rupture,
        healing_time: 1e-5,
        formation_time: 1e-7,
    }
}

/// One asperity at height 0 under a flat footprint holding exactly one (η A = 1).
fn one_sphere(p: MeniscusParams) -> Meniscus {
    let peak = Arc::new(Discrete::from_heights(vec![0.0]).unwrap());
    Meniscus::new(p, R, 1e12, peak, Footprint::Flat { area_m2: 1e-12 }).unwrap()
}

/// Israelachvili's sphere on a flat: `2πRγ(1 + cos θ)` with the disk fully wetted, `4πRγ cos θ`
/// with both surfaces at θ; formed when the gap falls below `t_m`, held until it exceeds
/// `t_m + s_r`.
#[test]
fn one_sphere_gives_the_closed_form_force_between_formation_and_rupture() {
    let t_m = 1.2e-9;
    for theta_deg in [0.0_f64, 30.0, 60.0, 90.0] {
        let theta = theta_deg.to_radians();
        for (wetting, exact) in [
            (Wetting::Disk, 2.0 * PI * R * GAMMA * (1.0 + theta.cos())),
            (Wetting::Both, 4.0 * PI * R * GAMMA * theta.cos()),
        ] {
            let m = one_sphere(params(t_m, theta, wetting, None));
            let s_r = m.rupture_distance();
            let f = |d: f64, d_star: f64| m.force(Gaps::same(d), &[d_star]).force.value;
            // approach: nothing above t_m, the full bridge below
            assert_eq!(f(t_m * 1.01, t_m * 1.01), 0.0);
            let at = f(0.5 * t_m, 0.5 * t_m);
            assert!((at + exact).abs() <= 1e-14 * exact, "{at} vs −{exact}");
            // separation after the approach to 0.5 t_m: held to t_m + s_r, gone beyond
            let d_star = 0.5 * t_m;
            let held = f(t_m + 0.99 * s_r, d_star);
            assert!((held + exact).abs() <= 1e-14 * exact, "{held}");
            assert_eq!(f(t_m + 1.01 * s_r, d_star), 0.0);
        }
    }
}

/// Lian, Thornton & Adams (1993): `s_r = (1 + θ/2) V^{1/3}`, here with the bridge volume
/// `V = π R t_m²`; a given rupture distance overrides it; and the single bridge of the previous
/// test breaks there to within 1 % of s_r.
#[test]
fn the_rupture_distance_follows_lians_law() {
    for (t_m, theta_deg) in [(0.5e-9, 0.0_f64), (1e-9, 20.0), (2e-9, 60.0)] {
        let theta = theta_deg.to_radians();
        let v = PI * R * t_m * t_m;
        let law = (1.0 + 0.5 * theta) * v.cbrt();
        assert!((lian_rupture_distance(v, theta) - law).abs() <= 1e-15 * law);
        let m = one_sphere(params(t_m, theta, Wetting::Disk, None));
        assert!((m.rupture_distance() - law).abs() <= 1e-15 * law);
        // the breaking gap, by bisection on the force along a separation from contact
        let (mut lo, mut hi) = (t_m, t_m + 3.0 * law);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if m.force(Gaps::same(mid), &[0.0]).force.value < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        assert!(
            (lo - (t_m + law)).abs() <= 0.01 * law,
            "{lo} vs {}",
            t_m + law
        );
    }
    let m = one_sphere(params(1e-9, 0.0, Wetting::Disk, Some(4e-9)));
    assert_eq!(m.rupture_distance(), 4e-9);
}

/// The paper surface: Rice maxima, σ = 0.7 nm, ε = 0.7, η_s = 150 µm⁻², R = 100 nm.
fn paper_surface(p: MeniscusParams) -> Meniscus {
    let peaks = Arc::new(RiceMaxima::new(0.7e-9, 0.7).unwrap());
    Meniscus::new(p, R, 1.5e14, peaks, Footprint::Flat { area_m2: 1e-12 }).unwrap()
}

/// The adhesion pressure on approach. The sub-boundary-lubrication tables for the head–disk
/// interface give about 20–60 MPa at 1–2 nm of lubricant. Under one bridge the Laplace pressure
/// over its wetted cap (area `2πR t_m`) is `f_b/(2πR t_m) = γ(1 + cos θ)/t_m`: 24–48 MPa at
/// t_m = 1–2 nm with γ = 24 mN/m, θ = 0, inside the band. Spread over the nominal area of the
/// paper surface, with a fraction of the peaks wet, the pressure is an order of magnitude lower:
/// below 5 MPa at every gap, at most `f_b η_s` = 4.5 MPa with every peak wet.
#[test]
fn the_adhesion_pressure_on_approach_against_the_sub_boundary_band() {
    for t_m in [1e-9, 2e-9] {
        let m = paper_surface(params(t_m, 0.0, Wetting::Disk, None));
        let laplace = m.bridge_force() / (2.0 * PI * R * t_m);
        assert!((20e6..=60e6).contains(&laplace), "{laplace} Pa");
        let peaks = RiceMaxima::new(0.7e-9, 0.7).unwrap();
        for d in [-2e-9, 0.0, 1e-9, 2e-9] {
            let p = -m.force(Gaps::same(d), &[d]).force.value / 1e-12;
            // the closed form over a flat footprint: f_b η_s M_0(d − t_m)
            use hdi_tribology::surface::PeakDistribution;
            let exact = m.bridge_force() * 1.5e14 * peaks.partial_moment(d - t_m, 0.0);
            assert!((p - exact).abs() <= 1e-12 * exact, "{p} vs {exact}");
            assert!(p > 0.0 && p < 5e6, "t_m {t_m}, d {d}: {p} Pa");
        }
    }
}

/// The force along an approach to `d_min` and back, with the formation instant (τ_f → 0) and no
/// healing (τ_h → ∞): `d*` is the running minimum.
fn loop_forces(m: &Meniscus, d_min: f64, d_max: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let n = 400;
    let ds: Vec<f64> = (0..=n)
        .map(|i| d_max - (d_max - d_min) * i as f64 / n as f64)
        .collect();
    let approach = ds
        .iter()
        .map(|&d| m.force(Gaps::same(d), &[d]).force.value)
        .collect();
    let separation = ds
        .iter()
        .map(|&d| m.force(Gaps::same(d), &[d_min]).force.value)
        .collect();
    (ds, approach, separation)
}

/// Ono's impact tests: the adhesion shows at separation (the force on the way out is at least
/// as attractive as on the way in at every gap, and strictly more at some); it grows with the
/// mobile thickness; and a lubricant that is all bonded forms no bridges at all.
#[test]
fn ono_trends_separation_only_growing_with_mobile_thickness_none_when_bonded() {
    let mut pull_off = Vec::new();
    for t_m in [0.3e-9, 0.6e-9, 1.2e-9] {
        let m = paper_surface(params(t_m, 0.0, Wetting::Disk, None));
        // out past the rupture of the last bridge
        let d_max = t_m + m.rupture_distance() + 8e-9;
        let (ds, approach, separation) = loop_forces(&m, 0.0, d_max);
        let mut stronger_somewhere = false;
        for ((d, a), s) in ds.iter().zip(&approach).zip(&separation) {
            assert!(*s <= *a, "d = {d}: separation {s} N above approach {a} N");
            stronger_somewhere |= *s < *a * 1.5;
        }
        assert!(stronger_somewhere);
        // the work of adhesion: the area between the two branches, positive
        let work: f64 = ds
            .windows(2)
            .zip(approach.windows(2).zip(separation.windows(2)))
            .map(|(d, (a, s))| (d[0] - d[1]) * 0.5 * ((a[0] - s[0]) + (a[1] - s[1])))
            .sum();
        assert!(work > 0.0);
        pull_off.push((work, separation.iter().copied().fold(0.0, f64::min)));
    }
    for w in pull_off.windows(2) {
        assert!(w[1].0 > w[0].0 && w[1].1 < w[0].1, "{pull_off:?}");
    }
    // all bonded: no term in the model
    let mut scene = Scene::paper();
    scene.lubricant = Some(lubricant(1.2e-9, 1.2e-9, 1e-5));
    assert!(scene.meniscus().unwrap().is_none());
    let model = SliderModel::from_scene(&scene).unwrap();
    assert!(model.stateful_terms().is_empty());
}

fn lubricant(total: f64, bonded: f64, tau_h: f64) -> LubricantSpec {
    LubricantSpec {
        total_thickness_m: total,
        bonded_thickness_m: bonded,
        surface_tension_n_per_m: GAMMA,
        contact_angle_deg: 0.0,
        wetting: WettingSpec::Disk,
        healing_time_s: tau_h,
        formation_time_s: 1e-7,
        rupture_distance_m: None,
    }
}

/// With no lubricant section, or no mobile lubricant, a cycle of the paper scene (the values of
/// the paper example's cycle CSVs: every step of the series) is the same to the bit, at 0 V and
/// at 0.6 V AC.
#[test]
fn no_mobile_lubricant_changes_no_bit_of_a_cycle() {
    let plain = Scene::paper();
    let mut bonded = plain.clone();
    bonded.lubricant = Some(lubricant(1.0e-9, 1.0e-9, 1e-5));
    let mut empty = plain.clone();
    empty.lubricant = Some(lubricant(0.0, 0.0, 1e-5));
    let programme = HeaterProgramme::fixed_from_scene(&plain).unwrap();
    let mut opts = CycleOptions::from_scene(&plain).unwrap();
    opts.keep_series = true;
    for v_ac in [0.0, 0.6] {
        let run = |s: &Scene| {
            let m = SliderModel::from_scene(s).unwrap().with_ac_amplitude(v_ac);
            simulate_cycle(&m, &programme, &opts).unwrap()
        };
        let base = run(&plain);
        for other in [&bonded, &empty] {
            let r = run(other);
            assert_eq!(base.touchdown, r.touchdown);
            assert_eq!(base.takeoff, r.takeoff);
            assert_eq!(base.hysteresis, r.hysteresis);
            assert_eq!(
                base.mean_temperature_rise.to_bits(),
                r.mean_temperature_rise.to_bits()
            );
            assert_eq!(format!("{:?}", base.stats), format!("{:?}", r.stats));
            let (a, b) = (base.series.as_ref().unwrap(), r.series.as_ref().unwrap());
            // every column at every step: `{:?}` writes the shortest decimal that reads back
            // to the same bits, so equal text is equal bits (NaN included)
            assert_eq!(format!("{a:?}"), format!("{b:?}"));
        }
    }
}

/// Bad lubricant parameters are refused by the field as written, with the value in its unit.
#[test]
fn bad_lubricant_parameters_are_named_with_their_unit() {
    let base = Scene::paper().to_toml_string().unwrap();
    let with = |section: &str| format!("{base}\n[lubricant]\n{section}\n");
    let ok = "surface_tension_n_per_m = 0.024\ncontact_angle_deg = 20\nhealing_time_us = 10\n";
    let cases = [
        (
            format!("total_thickness_nm = -1\nbonded_thickness_nm = 0\n{ok}"),
            "lubricant.total_thickness_nm: must be finite and >= 0, got -1 nm",
        ),
        (
            format!("total_thickness_nm = 1\nbonded_thickness_nm = 1.5\n{ok}"),
            "lubricant.bonded_thickness_nm: must not exceed the total thickness of 1 nm, got 1.5 nm",
        ),
        (
            format!(
                "total_thickness_nm = 1.5\nbonded_thickness_nm = 0.5\n{}",
                ok.replace("contact_angle_deg = 20", "contact_angle_deg = 95")
            ),
            "lubricant.contact_angle_deg: must lie in [0, 90] deg, got 95 deg",
        ),
        (
            format!(
                "total_thickness_nm = 1.5\nbonded_thickness_nm = 0.5\n{}",
                ok.replace("0.024", "0")
            ),
            "lubricant.surface_tension_n_per_m: must be finite and > 0, got 0.0",
        ),
    ];
    for (text, want) in cases {
        let err = Scene::from_toml_str(&with(&text)).unwrap_err();
        assert!(matches!(err, Error::InvalidInput { .. }), "{err:?}");
        let msg = err.to_string();
        assert!(msg.contains(want), "{msg}\n wanted: {want}");
    }
    // a good section reads, and builds a term with one state
    let s = Scene::from_toml_str(&with(&format!(
        "total_thickness_nm = 1.5\nbonded_thickness_nm = 0.5\n{ok}"
    )))
    .unwrap();
    let l = s.lubricant.as_ref().unwrap();
    assert!((l.mobile_thickness_m() - 1e-9).abs() < 1e-24);
    assert!((l.healing_time_s - 1e-5).abs() < 1e-20);
    let model = SliderModel::from_scene(&s).unwrap();
    assert_eq!(model.term_states(), 1);
}
