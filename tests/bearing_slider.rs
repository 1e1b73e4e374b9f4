//! The attitude solve on the two-rail taper-flat slider: symmetry, mass conservation, the
//! stiffness against finite differences, grid convergence (Richardson), and the typed "does not
//! fly" error.

use hdi_tribology::bearing::BearingError;
use hdi_tribology::bearing::{solve_attitude, AttitudeOptions, BearingSpec, Equilibrium};
use hdi_tribology::Error;

fn example(n: usize) -> BearingSpec {
    let mut s = BearingSpec::from_path(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/bearing/two_rail_taper_flat.toml"
    ))
    .unwrap();
    s.grid.nx = n;
    s.grid.ny = n;
    s
}

fn solve(spec: &BearingSpec) -> Equilibrium {
    solve_attitude(&spec.build().unwrap(), &AttitudeOptions::default()).unwrap()
}

#[test]
fn a_symmetric_slider_without_skew_does_not_roll() {
    let eq = solve(&example(65));
    let b = &eq.reynolds.bearing;
    // Roll over the width: the spacing difference across the slider, against the fly height.
    let tilt = eq.attitude.roll * b.width / eq.attitude.fly_height;
    eprintln!(
        "symmetry: roll {:.3e} rad, roll x width / fly height {tilt:.2e}",
        eq.attitude.roll
    );
    assert!(tilt.abs() < 1e-9, "{tilt:e}");
    assert!(eq.attitude.pitch > 0.0);
    // Balanced: force against preload, moments against the static torques (zero).
    assert!((eq.loads[0] / b.preload - 1.0).abs() < 1e-8);
    assert!(eq.loads[1].abs() < 1e-8 * b.preload * b.length);
}

#[test]
fn skew_rolls_the_slider_and_conserves_mass() {
    let mut spec = example(65);
    spec.operating.skew_deg = 15.0;
    let eq = solve(&spec);
    let tilt = eq.attitude.roll * eq.reynolds.bearing.width / eq.attitude.fly_height;
    assert!(tilt.abs() > 1e-4, "skew should roll the slider: {tilt:e}");
    let r = &eq.reynolds;
    let h = r.spacing(&eq.attitude);
    let (inflow, outflow) = r.boundary_flux(&eq.pressure, &h);
    let imbalance = (inflow - outflow).abs() / inflow;
    eprintln!("conservation: inflow {inflow:.6e}, outflow {outflow:.6e}, relative {imbalance:.2e}");
    assert!(imbalance < 1e-8, "{imbalance:e}");
}

#[test]
fn stiffness_matches_finite_differences_of_the_load() {
    let eq = solve(&example(65));
    let k = eq.stiffness();
    let r = &eq.reynolds;
    let d = 1e-3 * eq.attitude.fly_height;
    let load_at = |dh: f64| {
        let mut att = eq.attitude;
        att.fly_height += dh;
        let mut p = eq.pressure.clone();
        r.solve(&att, &mut p).unwrap();
        r.loads(&p)
    };
    let (lp, lm) = (load_at(d), load_at(-d));
    for i in 0..3 {
        let fd = -(lp[i] - lm[i]) / (2.0 * d);
        let scale = k[0][0].abs() * if i == 0 { 1.0 } else { r.bearing.length };
        let err = (fd - k[i][0]).abs() / scale;
        assert!(err < 1e-5, "row {i}: {fd} against {}: {err:e}", k[i][0]);
    }
    assert!(k[0][0] > 0.0);
    assert!(k[1][1] > 0.0 && k[2][2] > 0.0, "{k:?}");
    // Squeeze damping resists heave and roll; the pitch entry is negative at this low-frequency
    // limit, the transport lag of a high bearing number (checked in closed form in
    // bearing_limits).
    let c = eq.damping().unwrap();
    assert!(c[0][0] > 0.0 && c[2][2] > 0.0 && c[1][1] < 0.0, "{c:?}");
}

/// Pressure along the left rail's centre line, `(x, p/p_a)`.
fn rail_centre_line(r: &hdi_tribology::bearing::Reynolds, p: &[f64]) -> Vec<(f64, f64)> {
    let nx = r.grid.nx();
    let j = r.grid.yc.partition_point(|&y| y < 200e-6);
    (0..nx).map(|i| (r.grid.xc[i], p[j * nx + i])).collect()
}

/// The example flies with a positive pitch: its rails converge towards the trailing edge, and
/// the pressure along a rail has the taper-flat slider's two peaks: one where the taper ends
/// (the taper's own wedge, 100 times steeper than the pitch) and one just ahead of the trailing
/// edge (the converging rail), falling between them as air escapes past the rail's sides.
/// Without the taper, at the same attitude, the pressure rises all the way along the rail to
/// its peak near the trailing edge, as the converging wedge's does.
#[test]
fn the_converging_rails_build_pressure_towards_the_trailing_edge() {
    let eq = solve(&example(65));
    assert!(eq.attitude.pitch > 0.0);
    let b = &eq.reynolds.bearing;
    let line = rail_centre_line(&eq.reynolds, &eq.pressure);
    let at = |x: f64| line.iter().find(|(xc, _)| *xc >= x).unwrap().1;
    let l = b.length;
    let (taper_end, middle, rear) = (at(0.11 * l), at(0.55 * l), at(0.96 * l));
    eprintln!("taper-flat rail: p/p_a {taper_end:.4} behind the taper, {middle:.4} at mid-length, {rear:.4} near the trailing edge");
    assert!(
        taper_end > middle && rear > middle,
        "{taper_end} {middle} {rear}"
    );

    let mut spec = example(65);
    spec.slider.taper = None;
    let flat = spec.build().unwrap();
    let r = hdi_tribology::bearing::Reynolds::new(&flat, 65, 65);
    let mut p = r.ambient();
    r.solve(&eq.attitude, &mut p).unwrap();
    let line = rail_centre_line(&r, &p);
    let (imax, _) = line
        .iter()
        .enumerate()
        .max_by(|a, b| a.1 .1.total_cmp(&b.1 .1))
        .unwrap();
    eprintln!(
        "flat rails: peak p/p_a {:.4} at x = {:.3} L",
        line[imax].1,
        line[imax].0 / l
    );
    assert!(line[imax].0 > 0.9 * l, "peak at {} m", line[imax].0);
    assert!((1..=imax).all(|i| line[i].1 > line[i - 1].1));
}

#[test]
fn grid_convergence_by_richardson_extrapolation() {
    let sizes = [65usize, 129, 257];
    let f: Vec<f64> = sizes
        .iter()
        .map(|&n| solve(&example(n)).bulge_spacing())
        .collect();
    let ratio = (f[0] - f[1]) / (f[1] - f[2]);
    let order = ratio.ln() / 2f64.ln();
    let limit = f[2] + (f[2] - f[1]) / (2f64.powf(order) - 1.0);
    let errors: Vec<f64> = f.iter().map(|v| (v / limit - 1.0).abs()).collect();
    // The grid at which the error falls to 0.1 %, from the observed order.
    let needed = sizes[2] as f64 * (errors[2] / 1e-3).powf(1.0 / order);
    eprintln!(
        "Richardson: bulge spacing {:?} nm, observed order {order:.3}, extrapolated {:.4} nm, \
         errors {errors:?}, 0.1 % at about {needed:.0} cells a side",
        f.iter().map(|v| v * 1e9).collect::<Vec<_>>(),
        limit * 1e9
    );
    assert!(order > 0.8 && order < 3.0, "observed order {order}");
    assert!(errors[2] < 1e-2, "{errors:?}");
}

#[test]
fn a_bearing_that_cannot_carry_the_preload_does_not_fly() {
    let mut spec = example(33);
    spec.operating.preload_mn = 1e6;
    match solve_attitude(&spec.build().unwrap(), &AttitudeOptions::default()) {
        Err(Error::Analysis(e)) if e.is::<BearingError>() && e.kind() == "DoesNotFly" => {
            let msg = e.to_string();
            assert!(
                msg.starts_with("air bearing: the slider does not fly"),
                "{msg}"
            );
            assert!(msg.contains("preload 1.0000e6 mN"), "{msg}");
        }
        Ok(eq) => panic!("expected DoesNotFly, it flies at {:?}", eq.attitude),
        Err(e) => panic!("expected DoesNotFly, got {e}"),
    }
}
