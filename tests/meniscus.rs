//! Lubricant menisci with memory: the single-sphere limits against Israelachvili's closed forms,
//! the rupture distance against Lian's law, the adhesion pressure against the sub-boundary
//! lubrication band for the head–disk interface, Ono's trends, and the term off to the bit.

use std::f64::consts::PI;
use std::sync::Arc;

use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, HeaterProgramme};
use hdi_tribology::force::{
    lian_rupture_distance, Branch, Footprint, Gaps, Meniscus, MeniscusParams, Pickup, StatefulTerm,
    Wetting,
};
use hdi_tribology::model::SliderModel;
use hdi_tribology::scene::{LubricantSpec, Scene, WettingSpec};
use hdi_tribology::surface::{Discrete, Gaussian, PeakDistribution, RiceMaxima};
use hdi_tribology::Error;

#[path = "common/scenes.rs"]
mod scenes;

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
        pickup: None,
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
        pickup_rate_m_per_s: None,
        pickup_loss_time_s: None,
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
        (
            format!("total_thickness_nm = 1.5\nbonded_thickness_nm = 0.5\n{ok}formation_time_us = -0.1\n"),
            "lubricant.formation_time_us: must be finite and >= 0, got -0.1 µs",
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
    // bridges that form at once: τ_f = 0 is accepted
    let s = Scene::from_toml_str(&with(&format!(
        "total_thickness_nm = 1.5\nbonded_thickness_nm = 0.5\n{ok}formation_time_s = 0\n"
    )))
    .unwrap();
    assert_eq!(s.lubricant.as_ref().unwrap().formation_time_s, 0.0);
    assert_eq!(SliderModel::from_scene(&s).unwrap().term_states(), 1);
    // the head's pick-up: both fields or neither, each > 0; with both, a second state
    let lub = "total_thickness_nm = 1.5\nbonded_thickness_nm = 0.5\n";
    for (extra, want) in [
        (
            "pickup_rate_m_per_s = 1e-5\n",
            "lubricant.pickup_loss_time_s: is required with lubricant.pickup_rate_m_per_s",
        ),
        (
            "pickup_loss_time_us = 50\n",
            "lubricant.pickup_rate_m_per_s: is required with lubricant.pickup_loss_time_s",
        ),
        (
            "pickup_rate_m_per_s = -1e-5\npickup_loss_time_us = 50\n",
            "lubricant.pickup_rate_m_per_s: must be finite and > 0, got -1e-5",
        ),
        (
            "pickup_rate_m_per_s = 1e-5\npickup_loss_time_us = 0\n",
            "lubricant.pickup_loss_time_us: must be finite and > 0, got 0 µs",
        ),
    ] {
        let err = Scene::from_toml_str(&with(&format!("{lub}{ok}{extra}"))).unwrap_err();
        assert!(matches!(err, Error::InvalidInput { .. }), "{err:?}");
        let msg = err.to_string();
        assert!(msg.contains(want), "{msg}\n wanted: {want}");
    }
    let s = Scene::from_toml_str(&with(&format!(
        "{lub}{ok}pickup_rate_m_per_s = 1e-5\npickup_loss_time_us = 50\n"
    )))
    .unwrap();
    assert_eq!(SliderModel::from_scene(&s).unwrap().term_states(), 2);
}

/// A term with the head's pick-up on Gaussian peaks (σ = 0.7 nm) under a flat footprint:
/// `t_m` = 1 nm, `r_p` = 20 µm/s, `τ_p` = 50 µs (saturation 1 nm).
fn with_pickup() -> Meniscus {
    let mut p = params(1e-9, 0.3, Wetting::Disk, None);
    p.pickup = Some(Pickup {
        rate: 2e-5,
        loss_time: 5e-5,
    });
    let peaks = Arc::new(Gaussian::new(0.0, 0.7e-9).unwrap());
    Meniscus::new(p, R, 1.5e14, peaks, Footprint::Flat { area_m2: 1e-9 })
        .unwrap()
        .tabulated((-4e-9, 3e-8), &Default::default())
        .unwrap()
}

/// The head's film, integrated from the term's rates with the crate's stiff solver: held at a
/// gap in contact it grows as `t_h = r_p τ_p S (1 − e^{−t/τ_p})`, with `S` the Gaussian survival
/// `erfc(z/σ√2)/2` of the peak heights at `z = d − t_m`; moved far from the disk it decays as
/// `t_h(t₁) e^{−(t−t₁)/τ_p}`, while `d*` heals towards the gap with τ_h.
#[test]
fn the_head_pickup_grows_and_decays_in_closed_form() {
    use hdi_tribology::ode::{solve, FnSystem, Method, Options};
    use nalgebra::Vector2;
    let m = with_pickup();
    assert_eq!(m.states(), 2);
    let (rate, tau) = (2e-5, 5e-5);
    let run = |d: f64, y0: Vector2<f64>, t_end: f64| {
        let m = &m;
        let sys = FnSystem::new(move |_t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>| {
            let mut r = [0.0; 2];
            m.rates(Gaps::same(d), y.as_slice(), &mut r);
            dy.copy_from_slice(&r);
        });
        let opts = Options::default().rtol(1e-10).atol(1e-22);
        solve(&sys, 0.0, y0, t_end, Method::Radau5, &opts, &mut []).unwrap()
    };
    // in contact: the gap 0.2 nm above t_m; S from the Gaussian's own closed form
    let d1 = 1.2e-9;
    let s = Gaussian::new(0.0, 0.7e-9)
        .unwrap()
        .partial_moment(d1 - 1e-9, 0.0);
    let erfc_half = 0.5 * erfc_series(0.2 / (0.7 * 2f64.sqrt()));
    assert!((s - erfc_half).abs() < 1e-12, "{s} vs {erfc_half}");
    let grow = run(d1, Vector2::new(d1, 0.0), 3.1e-4);
    let mut worst: f64 = 0.0;
    for k in 1..=30 {
        let t = 1e-5 * k as f64;
        let y = grow.sample(t).unwrap();
        let exact = rate * tau * s * (1.0 - (-t / tau).exp());
        worst = worst.max((y[1] - exact).abs() / (rate * tau * s));
        assert_eq!(y[0], d1, "d* rests at the gap held");
    }
    assert!(worst < 1e-6, "growth: worst relative error {worst}");
    // the term's own rest value is the end of the growth
    let at_rest = m.pickup_at_rest(d1).0;
    assert!(
        (at_rest - rate * tau * s).abs() < 1e-8 * at_rest,
        "{at_rest}"
    );
    let t1 = *grow.y_final();
    // far from the disk (S < 1e-300 at 40 σ): pure decay of t_h, d* heals towards 30 nm
    let far = 3e-8;
    let decay = run(far, t1, 3.1e-4);
    worst = 0.0;
    for k in 1..=30 {
        let t = 1e-5 * k as f64;
        let y = decay.sample(t).unwrap();
        let exact = t1[1] * (-t / tau).exp();
        worst = worst.max((y[1] - exact).abs() / t1[1]);
        let healed = far + (t1[0] - far) * (-t / 1e-5).exp();
        assert!(
            (y[0] - healed).abs() < 1e-6 * far,
            "d* at {t}: {} vs {healed}",
            y[0]
        );
    }
    assert!(worst < 1e-6, "decay: worst relative error {worst}");
}

/// `erfc(x) = 1 − erf(x)`, erf from its Taylor series (for small x; independent of the crate's).
fn erfc_series(x: f64) -> f64 {
    let mut sum = 0.0;
    let mut term = x;
    let mut n = 0;
    while term.abs() > 1e-18 {
        sum += term / (2 * n + 1) as f64;
        n += 1;
        term *= -x * x / n as f64;
    }
    1.0 - 2.0 / PI.sqrt() * sum
}

/// With a pick-up, the static force is the term's force at `d* = d` and `t_h` at rest, its slope
/// that of this force along the rest path (central difference), and a picked-up film only adds
/// attraction: at every gap the force with the head's film at rest is at least as attractive
/// as without a pick-up.
#[test]
fn the_pickup_enters_the_statics_at_rest() {
    let with = SliderModel::from_scene(&paper_lubricated(true)).unwrap();
    let without = SliderModel::from_scene(&paper_lubricated(false)).unwrap();
    let plain = SliderModel::from_scene(&Scene::paper()).unwrap();
    let m = paper_lubricated(true).meniscus().unwrap().unwrap();
    let mut compared = 0;
    for d in [0.3e-9, 0.8e-9, 1.2e-9, 1.6e-9, 2.5e-9] {
        let g = Gaps::same(d);
        let base = plain.interface_force(g, 0.0);
        let f = with.interface_force(g, 0.0);
        let mut x = [0.0; 2];
        m.equilibrium(g, &mut x);
        assert_eq!(x[0], d);
        let own = m.force(g, &x).force.value;
        assert!(
            (f.value - base.value - own).abs() <= 1e-12 * base.value.abs().max(own.abs()),
            "{d}: {} vs {own}",
            f.value - base.value
        );
        let h = 1e-13;
        let at = |d: f64| {
            let g = Gaps::same(d);
            let mut x = [0.0; 2];
            m.equilibrium(g, &mut x);
            m.force(g, &x).force.value
        };
        let fd = (at(d + h) - at(d - h)) / (2.0 * h);
        let slope = f.d_bulge - base.d_bulge;
        assert!(
            (slope - fd).abs() <= 1e-4 * fd.abs().max(1.0),
            "{d}: slope {slope} vs {fd}"
        );
        let f0 = without.interface_force(g, 0.0).value;
        assert!(f.value <= f0, "{d}: {} > {f0}", f.value);
        compared += (f.value < f0) as usize;
    }
    assert!(compared >= 3, "the pick-up adds attraction in contact");
}

/// The paper scene with 0.3 nm of mobile lubricant, with or without the head's pick-up
/// (`r_p` = 10 µm/s, `τ_p` = 50 µs: saturation 0.5 nm).
fn paper_lubricated(pickup: bool) -> Scene {
    let mut scene = Scene::paper();
    let mut l = lubricant(1.3e-9, 1.0e-9, 2e-5);
    if pickup {
        l.pickup_rate_m_per_s = Some(1e-5);
        l.pickup_loss_time_s = Some(5e-5);
    }
    scene.lubricant = Some(l);
    scene
}

/// Menisci of 0.3 nm of mobile lubricant at 30° (τ_h = 10 µs) on the paper scene's peaks and
/// footprint, tabulated, forming in `tau_f` (s).
fn on_the_paper_scene(scene: &Scene, tau_f: f64) -> Meniscus {
    let c = scene.contact.as_ref().unwrap();
    let mut p = params(0.3e-9, 30f64.to_radians(), Wetting::Disk, None);
    p.formation_time = tau_f;
    Meniscus::new(
        p,
        c.asperity_radius_m,
        c.asperity_density_per_m2,
        scene.peaks().unwrap(),
        c.footprint,
    )
    .unwrap()
    .tabulated(scene.table_range(), &Default::default())
    .unwrap()
}

/// The meniscus with its branch picked by the sign of `d − d*` at every evaluation: what the
/// term was before the simulations held its branch (the kink left to the step control).
#[derive(Debug)]
struct BySign(Meniscus);

impl StatefulTerm for BySign {
    fn name(&self) -> &str {
        "meniscus by sign"
    }
    fn states(&self) -> usize {
        self.0.states()
    }
    fn equilibrium(&self, g: Gaps, x: &mut [f64]) {
        self.0.equilibrium(g, x)
    }
    fn rates(&self, g: Gaps, x: &[f64], dx: &mut [f64]) {
        self.0.rates(g, x, dx)
    }
    fn rate_partials(&self, g: Gaps, x: &[f64]) -> hdi_tribology::force::RatePartials {
        self.0.rate_partials(g, x)
    }
    fn force(&self, g: Gaps, x: &[f64]) -> hdi_tribology::force::StateForce {
        self.0.force(g, x)
    }
    fn tolerances(&self, displacement: f64, atol: &mut [f64]) {
        self.0.tolerances(displacement, atol)
    }
}

/// Holding the healing or formation branch over each step and switching at the located root
/// integrates the same law as picking the branch by sign: touchdown and take-off agree within
/// 10 nW at the scene's tolerance, with and without the AC dither, and the held branch switches
/// at least once per dither period near contact.
#[test]
fn the_held_branch_integrates_the_law_picked_by_sign() {
    let scene = Scene::paper();
    let m = on_the_paper_scene(&scene, 1e-7);
    assert!(m.switches() && !BySign(m.clone()).switches());
    let plain = SliderModel::from_scene(&scene).unwrap();
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    let opts = CycleOptions::from_scene(&scene).unwrap();
    for v_ac in [0.0, 0.6] {
        let base = plain.with_ac_amplitude(v_ac);
        let held = simulate_cycle(
            &base.with_stateful_term(m.clone()).unwrap(),
            &programme,
            &opts,
        )
        .unwrap();
        let by_sign = simulate_cycle(
            &base.with_stateful_term(BySign(m.clone())).unwrap(),
            &programme,
            &opts,
        )
        .unwrap();
        println!(
            "{v_ac} V: held {:?}\n  by sign {:?}",
            held.stats, by_sign.stats
        );
        let power = |d: Option<hdi_tribology::analysis::cycle::Detection>| d.unwrap().power;
        for (a, b) in [
            (power(held.touchdown), power(by_sign.touchdown)),
            (power(held.takeoff), power(by_sign.takeoff)),
        ] {
            assert!((a - b).abs() <= 1e-8, "{v_ac} V: {a} W against {b} W");
        }
        assert_eq!(by_sign.stats.branch_switches, 0);
        assert!(held.stats.branch_switches >= 10, "{:?}", held.stats);
    }
}

/// The largest layout a lubricated scene can have: the bulge's two coordinates and velocities,
/// the thermal and interface lags, `d*` and the head's film, the branch held for `d*`, and the
/// cycle's two integrals (11 states). A cycle and a drive run on it, and the cycle switches
/// branch.
#[test]
fn the_largest_lubricated_layout_runs() {
    use hdi_tribology::drive::{scene_zone, Command, DiskSpec, DriveOptions, Plant};
    use hdi_tribology::model::StateLayout;
    let mut scene = scenes::paper_bulge();
    scene.heater.thermal_lag_s = 1e-6;
    scene.slider.interface_lag_s = 1e-8;
    scene.lubricant = paper_lubricated(true).lubricant;
    let model = SliderModel::from_scene(&scene).unwrap();
    let layout = StateLayout::of(&model, true);
    assert_eq!(
        (layout.len(), layout.term_states.1, layout.branches.1),
        (11, 2, 1)
    );
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    let mut opts = CycleOptions::from_scene(&scene).unwrap();
    opts.solver.max_steps = 1_000_000;
    let r = simulate_cycle(&model, &programme, &opts).unwrap();
    assert!(r.touchdown.is_some(), "{:?}", r.stats);
    assert!(r.stats.branch_switches > 0, "{:?}", r.stats);
    let opts = DriveOptions {
        disk: DiskSpec::flat(),
        ..DriveOptions::default()
    };
    let mut drive = Plant::new(&scene, &scene_zone(&scene, 0.025).unwrap(), 1, opts)
        .unwrap()
        .into_drive()
        .unwrap();
    for _ in 0..20 {
        drive.step(&Command::heater_mw(70.0), 50e-6).unwrap();
    }
    assert_eq!(drive.term_states().len(), 2);
}

/// Bridges that form at once (`τ_f = 0`) are the limit of a formation time going to zero: at
/// 0 V and 0.6 V touchdown and take-off of τ_f = 10 ns and 100 ns differ from those of
/// instant formation in proportion to τ_f (a first-order approach, the lag `τ_f ḋ` of `d*`),
/// 10 ns within 0.2 µW. Instant formation switches branch where the gap stops closing, and its
/// formation branch is not stiff: the cycle at 0.6 V takes fewer steps on the stiff method.
#[test]
fn instant_formation_is_the_limit_of_a_vanishing_formation_time() {
    let scene = Scene::paper();
    let term = |tau_f: f64| on_the_paper_scene(&scene, tau_f);
    let plain = SliderModel::from_scene(&scene).unwrap();
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    let opts = CycleOptions::from_scene(&scene).unwrap();
    let power = |d: Option<hdi_tribology::analysis::cycle::Detection>| d.unwrap().power;
    for v_ac in [0.0, 0.6] {
        let base = plain.with_ac_amplitude(v_ac);
        let run = |tau_f: f64| {
            simulate_cycle(
                &base.with_stateful_term(term(tau_f)).unwrap(),
                &programme,
                &opts,
            )
            .unwrap()
        };
        let (at_once, r10, r100) = (run(0.0), run(1e-8), run(1e-7));
        println!(
            "{v_ac} V: at once {:?}\n  10 ns {:?}\n  100 ns {:?}",
            at_once.stats, r10.stats, r100.stats
        );
        assert!(at_once.stats.branch_switches >= 10, "{:?}", at_once.stats);
        let mut moved = false;
        for pick in [
            |r: &hdi_tribology::analysis::cycle::CycleResult| r.touchdown,
            |r: &hdi_tribology::analysis::cycle::CycleResult| r.takeoff,
        ] {
            let p0 = power(pick(&at_once));
            let (d10, d100) = (power(pick(&r10)) - p0, power(pick(&r100)) - p0);
            println!("{v_ac} V: {p0} W; 10 ns {d10:e} W, 100 ns {d100:e} W");
            assert!(d10.abs() <= 2e-7, "{v_ac} V: 10 ns moved {d10:e} W");
            // In proportion to τ_f: 10 ns moves the power a tenth as far as 100 ns, within half
            // of that and the tolerance's 10 nW.
            let expected = d100 / 10.0;
            assert!(
                (d10 - expected).abs() <= 0.5 * expected.abs() + 1e-8,
                "{v_ac} V: 10 ns {d10:e} W against a tenth of 100 ns {expected:e} W"
            );
            moved |= d100.abs() > 1e-7;
        }
        if v_ac > 0.0 {
            assert!(moved, "τ_f should matter with the dither");
            assert!(
                at_once.stats.stiff_steps < r100.stats.stiff_steps,
                "{:?} against {:?}",
                at_once.stats,
                r100.stats
            );
        }
    }
}

/// At 0.6 V the formation branch (1/τ_f = 1e7 1/s) holds Tsit5 at its stability bound, and
/// Rodas5P's steps pay there; on the healing branch that follows, the contact alone is not
/// stiff for steps the dither holds. `Auto` goes stiff where the formation branch starts and
/// hands back to Tsit5 where it ends and its stiff step would not count as stiff on the
/// healing branch. It used to keep Rodas5P through both branches: 6 244 of 7 748 steps, and a
/// cycle dearer than either method alone. The powers agree with Tsit5's within the tolerance's
/// reach, and at 0 V, where the contact itself is stiff, Auto still takes fewer steps than
/// Tsit5.
#[test]
fn auto_hands_back_where_a_stiff_branch_ends() {
    let scene = Scene::paper();
    let m = on_the_paper_scene(&scene, 1e-7);
    let plain = SliderModel::from_scene(&scene).unwrap();
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    let mut opts = CycleOptions::from_scene(&scene).unwrap();
    for v_ac in [0.6, 0.0] {
        let model = plain
            .with_ac_amplitude(v_ac)
            .with_stateful_term(m.clone())
            .unwrap();
        opts.solver.method = hdi_tribology::ode::Method::Auto;
        let auto = simulate_cycle(&model, &programme, &opts).unwrap();
        opts.solver.method = hdi_tribology::ode::Method::Tsit5;
        let tsit5 = simulate_cycle(&model, &programme, &opts).unwrap();
        let (a, t) = (auto.stats, tsit5.stats);
        println!("{v_ac} V auto: {a:?}\n{v_ac} V tsit5: {t:?}");
        let power = |d: Option<hdi_tribology::analysis::cycle::Detection>| d.unwrap().power;
        for (x, y) in [
            (power(auto.touchdown), power(tsit5.touchdown)),
            (power(auto.takeoff), power(tsit5.takeoff)),
        ] {
            assert!((x - y).abs() < 1e-8, "{v_ac} V: {x} W against {y} W");
        }
        assert!(
            a.stiff_steps > 0 && a.accepted < t.accepted,
            "{a:?} against {t:?}"
        );
        if v_ac > 0.0 {
            // Runs of another method start and end with the formation branch: many switches,
            // and fewer than 3/5 of the steps stiff (a build before: 23 and 83 %).
            assert!(a.stiffness_switches >= 100, "{a:?}");
            assert!(5 * a.stiff_steps < 3 * a.accepted, "{a:?}");
            // Each entry into the formation branch starts with the first step the last entry
            // accepted: fewer than one rejected step in twenty (the build before that rejected
            // three to five at every entry: 685 in 7 576 steps here).
            assert!(20 * a.rejected < a.accepted, "{a:?}");
            // The formation branch is stepped by the additive pair, its closest approach
            // implicitly by a division: fewer than one factorisation in ten steps (401 in
            // 8 755; with Rodas5P on the branch, the build before: 4 387 in 7 576).
            assert!(10 * a.lu_decomps < a.accepted, "{a:?}");
        } else {
            // In slow contact the formation branch's switching function stays within the
            // integration error of zero: the pair's branches end at their first step, and the
            // entry after such a branch goes to Rodas5P (85 stiffness switches in 1 324 steps;
            // with the pair at every entry, 439 in 2 051).
            assert!(a.stiffness_switches < 150 && a.accepted < 1_600, "{a:?}");
        }
    }
}

/// The meniscus with every law of its own but without saying that its rates are affine in its
/// states row by row: the slider must not declare its rows stiff for the additive pair.
#[derive(Debug)]
struct Undeclared(Meniscus);

impl StatefulTerm for Undeclared {
    fn name(&self) -> &str {
        "undeclared meniscus"
    }
    fn states(&self) -> usize {
        self.0.states()
    }
    fn equilibrium(&self, g: Gaps, x: &mut [f64]) {
        self.0.equilibrium(g, x)
    }
    fn initial(&self, g: Gaps, x: &mut [f64]) {
        self.0.initial(g, x)
    }
    fn rates(&self, g: Gaps, x: &[f64], dx: &mut [f64]) {
        self.0.rates(g, x, dx)
    }
    fn rate_partials(&self, g: Gaps, x: &[f64]) -> hdi_tribology::force::RatePartials {
        self.0.rate_partials(g, x)
    }
    fn force(&self, g: Gaps, x: &[f64]) -> hdi_tribology::force::StateForce {
        self.0.force(g, x)
    }
    fn force_value(&self, g: Gaps, x: &[f64]) -> f64 {
        self.0.force_value(g, x)
    }
    fn tolerances(&self, displacement: f64, atol: &mut [f64]) {
        self.0.tolerances(displacement, atol)
    }
    fn rests_on_bulge_gap(&self) -> bool {
        self.0.rests_on_bulge_gap()
    }
    fn switches(&self) -> bool {
        self.0.switches()
    }
    fn switching(&self, g: Gaps, x: &[f64]) -> f64 {
        self.0.switching(g, x)
    }
    fn rates_on(&self, b: Branch, g: Gaps, x: &[f64], dx: &mut [f64]) {
        self.0.rates_on(b, g, x, dx)
    }
    fn fastest_rate_on(&self, b: Branch) -> Option<f64> {
        self.0.fastest_rate_on(b)
    }
    fn rate_partials_on(
        &self,
        b: Branch,
        g: Gaps,
        x: &[f64],
    ) -> hdi_tribology::force::RatePartials {
        self.0.rate_partials_on(b, g, x)
    }
    fn switching_on(
        &self,
        b: Branch,
        gaps: &dyn Fn() -> Gaps,
        rate: &dyn Fn() -> Gaps,
        x: &[f64],
    ) -> f64 {
        self.0.switching_on(b, gaps, rate, x)
    }
    fn force_on(&self, b: Branch, g: Gaps, x: &[f64]) -> hdi_tribology::force::StateForce {
        self.0.force_on(b, g, x)
    }
    fn force_value_on(&self, b: Branch, g: Gaps, x: &[f64]) -> f64 {
        self.0.force_value_on(b, g, x)
    }
    fn enter(&self, b: Branch, g: Gaps, x: &mut [f64]) {
        self.0.enter(b, g, x)
    }
    fn rates_and_force_value_on(&self, b: Branch, g: Gaps, x: &[f64], dx: &mut [f64]) -> f64 {
        self.0.rates_and_force_value_on(b, g, x, dx)
    }
}

/// Only a term that says its rates are affine in its own states row by row has them stepped
/// implicitly by the additive pair: the same meniscus without saying so runs the formation
/// branch on Rodas5P (many factorisations), and the two cycles agree on touchdown and take-off
/// within 10 nW at 0.6 V.
#[test]
fn only_terms_that_say_so_get_their_rows_stepped_implicitly() {
    let scene = Scene::paper();
    let m = on_the_paper_scene(&scene, 1e-7);
    let plain = SliderModel::from_scene(&scene)
        .unwrap()
        .with_ac_amplitude(0.6);
    let programme = HeaterProgramme::fixed_from_scene(&scene).unwrap();
    let opts = CycleOptions::from_scene(&scene).unwrap();
    let declared = simulate_cycle(
        &plain.with_stateful_term(m.clone()).unwrap(),
        &programme,
        &opts,
    )
    .unwrap();
    let undeclared = simulate_cycle(
        &plain.with_stateful_term(Undeclared(m)).unwrap(),
        &programme,
        &opts,
    )
    .unwrap();
    let (d, u) = (declared.stats, undeclared.stats);
    assert!(10 * d.lu_decomps < d.accepted, "{d:?}");
    assert!(3 * u.lu_decomps > u.accepted, "{u:?}");
    let power = |d: Option<hdi_tribology::analysis::cycle::Detection>| d.unwrap().power;
    for (x, y) in [
        (power(declared.touchdown), power(undeclared.touchdown)),
        (power(declared.takeoff), power(undeclared.takeoff)),
    ] {
        assert!((x - y).abs() < 1e-8, "{x} W against {y} W");
    }
}
