//! The pitching slider on the air bearing solved from its geometry: the heave–pitch stiffness
//! and damping of the Reynolds equation are not symmetric and the pitch damping is negative
//! (the gas film is driven by the disk, not a spring), the structure takes them, and its modes
//! are the roots of the 2 × 2 quadratic eigenproblem `det(λ²M + λC + K) = 0` computed here
//! independently: the undamped frequencies in closed form (a quadratic in ω²), the damped
//! eigenvalues against the quartic's coefficients (Vieta's formulas) and as its roots.

use hdi_tribology::bearing::{solve_attitude, AttitudeOptions, BearingSpec};
use hdi_tribology::force::ReynoldsBearing;
use hdi_tribology::model::Structure;
use num_complex::Complex64;

/// The example slider (2.0 × 1.6 mm) as a block of AlTiC (4250 kg/m³) 0.3 mm thick: its mass,
/// and its pitch inertia about the central pivot, m L²/12.
const MASS: f64 = 4250.0 * 2.0e-3 * 1.6e-3 * 0.3e-3;
const INERTIA: f64 = MASS * 2.0e-3 * 2.0e-3 / 12.0;

fn bearing() -> ([[f64; 2]; 2], [[f64; 2]; 2], f64) {
    let mut spec = BearingSpec::from_path(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/bearing/two_rail_taper_flat.toml"
    ))
    .unwrap();
    spec.grid.nx = 65;
    spec.grid.ny = 65;
    let eq = solve_attitude(&spec.build().unwrap(), &AttitudeOptions::default()).unwrap();
    ReynoldsBearing::from_equilibrium(&eq)
        .unwrap()
        .heave_pitch()
}

/// Coefficients `a₄ … a₀` of `det(λ² diag(m, I) + λ C + K)`, expanded by hand.
fn quartic(k: [[f64; 2]; 2], c: [[f64; 2]; 2], m: f64, i: f64) -> [f64; 5] {
    [
        m * i,
        m * c[1][1] + i * c[0][0],
        m * k[1][1] + i * k[0][0] + c[0][0] * c[1][1] - c[0][1] * c[1][0],
        c[0][0] * k[1][1] + c[1][1] * k[0][0] - c[0][1] * k[1][0] - c[1][0] * k[0][1],
        k[0][0] * k[1][1] - k[0][1] * k[1][0],
    ]
}

#[test]
fn the_pitch_structure_takes_the_bearings_matrices() {
    let (k, c, lever) = bearing();
    // What makes them a film's coefficients, not a structure's: this could fail if the
    // bearing's matrices were symmetric or its pitch damping positive.
    assert!(
        (k[0][1] - k[1][0]).abs() > 0.1 * k[0][1].abs().max(k[1][0].abs()),
        "{k:?}"
    );
    assert!(
        (c[0][1] - c[1][0]).abs() > 0.1 * c[0][1].abs().max(c[1][0].abs()),
        "{c:?}"
    );
    assert!(c[1][1] < 0.0, "{c:?}");
    assert!(
        (lever - 1.0e-3).abs() < 1e-15,
        "the pivot is at the centre: {lever}"
    );

    // A structure built from symmetric springs still refuses them.
    let sym = Structure::general(
        &[vec![MASS, 0.0], vec![0.0, INERTIA]],
        &[vec![0.0, 0.0], vec![0.0, 0.0]],
        &[vec![0.0, k[0][1]], vec![k[1][0], k[1][1]]],
        &[1.0, lever],
    )
    .unwrap_err()
    .to_string();
    assert!(sym.contains("symmetric"), "{sym}");
    // The film's coefficients must still be finite, named as the bearing's.
    let mut bad = k;
    bad[1][0] = f64::NAN;
    let e = Structure::pitch_on_bearing(MASS, INERTIA, bad, c, lever)
        .unwrap_err()
        .to_string();
    assert!(e.contains("air_bearing.stiffness[1][0]"), "{e}");

    let s = Structure::pitch_on_bearing(MASS, INERTIA, k, c, lever).unwrap();
    assert_eq!(s.bulge_influence(), &[1.0, lever][..]);
    assert_eq!(s.stiffness_matrix()[(0, 1)], k[0][1]);
    assert_eq!(s.stiffness_matrix()[(1, 0)], k[1][0]);
    assert_eq!(s.damping_matrix()[(1, 1)], c[1][1]);
    assert_eq!(s.stiffness_matrix()[(0, 0)], 0.0);
}

#[test]
fn the_modes_are_the_roots_of_the_2x2_quadratic_eigenproblem() {
    let (k, c, lever) = bearing();
    let s = Structure::pitch_on_bearing(MASS, INERTIA, k, c, lever).unwrap();

    // Undamped: m I ω⁴ − (m k₁₁ + I k₀₀) ω² + (k₀₀ k₁₁ − k₀₁ k₁₀) = 0.
    let (a, b, cc) = (
        MASS * INERTIA,
        -(MASS * k[1][1] + INERTIA * k[0][0]),
        k[0][0] * k[1][1] - k[0][1] * k[1][0],
    );
    let disc = b * b - 4.0 * a * cc;
    assert!(disc > 0.0, "two real squared frequencies");
    let q = -0.5 * (b - disc.sqrt()); // b < 0: no cancellation
    let mut w2 = [q / a, cc / q];
    w2.sort_by(f64::total_cmp);
    let exact: Vec<f64> = w2
        .iter()
        .map(|x| x.sqrt() / (2.0 * std::f64::consts::PI))
        .collect();
    let f = s.natural_frequencies(k[0][0]);
    for (got, want) in f.iter().zip(&exact) {
        assert!(
            (got - want).abs() <= 1e-10 * want,
            "{f:?} against {exact:?}"
        );
    }

    // Damped: the four eigenvalues against det(λ²M + λC + K) = a₄λ⁴ + … + a₀.
    let l = s.modes(k[0][0], c[0][0]);
    assert_eq!(l.len(), 4);
    let p = quartic(k, c, MASS, INERTIA);
    let big = l.iter().map(|x| x.norm()).fold(0.0, f64::max);
    // Vieta: the elementary symmetric functions of the roots are ±a₃/a₄, a₂/a₄, ∓a₁/a₄, a₀/a₄.
    let e1: Complex64 = l.iter().sum();
    let mut e2 = Complex64::new(0.0, 0.0);
    let mut e3 = Complex64::new(0.0, 0.0);
    for i in 0..4 {
        for j in i + 1..4 {
            e2 += l[i] * l[j];
            for m in j + 1..4 {
                e3 += l[i] * l[j] * l[m];
            }
        }
    }
    let e4: Complex64 = l.iter().product();
    for (got, want, order) in [
        (e1, -p[1] / p[0], 1),
        (e2, p[2] / p[0], 2),
        (e3, -p[3] / p[0], 3),
        (e4, p[4] / p[0], 4),
    ] {
        let tol = 1e-9 * big.powi(order);
        assert!(
            (got - want).norm() <= tol,
            "e{order}: {got} against {want} (roots {l:?})"
        );
    }
    // Each one a root: |det| small against the size of its terms.
    for x in &l {
        let det = (x * x * MASS + x * c[0][0] + k[0][0])
            * (x * x * INERTIA + x * c[1][1] + k[1][1])
            - (x * c[0][1] + k[0][1]) * (x * c[1][0] + k[1][0]);
        let size = (x.norm().powi(2) * MASS + x.norm() * c[0][0].abs() + k[0][0].abs())
            * (x.norm().powi(2) * INERTIA + x.norm() * c[1][1].abs() + k[1][1].abs());
        assert!(
            det.norm() <= 1e-9 * size,
            "λ = {x}: det {det} against {size}"
        );
    }
    // Real eigenvalues and complex pairs: the spectrum is closed under conjugation.
    for x in &l {
        assert!(
            l.iter().any(|y| (y - x.conj()).norm() <= 1e-9 * big),
            "{x} without its conjugate in {l:?}"
        );
    }
    println!("heave-pitch K {k:?}, C {c:?}; modes (1/s): {l:?}");
}
