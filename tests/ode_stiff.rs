//! Stiff validation problems against the reference solutions of the Test Set for IVP Solvers
//! (F. Mazzia, C. Magherini et al., Univ. Bari): Van der Pol (μ = 1000), Robertson to 1e11,
//! HIRES; plus tolerance proportionality.

use hdi_tribology::ode::{solve, Method, OdeSystem, Options, Solution, Tolerance};
use nalgebra::{Matrix2, Matrix3, SMatrix, SVector, Vector2, Vector3, U2, U3, U8};

/// Van der Pol in the test-set form: y1' = y2, y2' = μ(1 − y1²)y2 − y1, y(0) = (2, 0).
struct VanDerPol {
    mu: f64,
}

impl OdeSystem<U2> for VanDerPol {
    fn rhs(&self, _t: f64, y: &Vector2<f64>, dy: &mut Vector2<f64>) {
        dy[0] = y[1];
        dy[1] = self.mu * (1.0 - y[0] * y[0]) * y[1] - y[0];
    }
    fn jacobian(&self, _t: f64, y: &Vector2<f64>, j: &mut Matrix2<f64>) -> bool {
        *j = Matrix2::new(
            0.0,
            1.0,
            -2.0 * self.mu * y[0] * y[1] - 1.0,
            self.mu * (1.0 - y[0] * y[0]),
        );
        true
    }
}

/// Reference at t = 2000 (test set, "vdpol").
const VDP_REF: [f64; 2] = [1.706_167_732_170_469, -0.892_809_701_024_812_5e-3];

/// Robertson's chemical kinetics.
struct Robertson;

impl OdeSystem<U3> for Robertson {
    fn rhs(&self, _t: f64, y: &Vector3<f64>, dy: &mut Vector3<f64>) {
        let r1 = 0.04 * y[0];
        let r2 = 1e4 * y[1] * y[2];
        let r3 = 3e7 * y[1] * y[1];
        dy[0] = -r1 + r2;
        dy[1] = r1 - r2 - r3;
        dy[2] = r3;
    }
    fn jacobian(&self, _t: f64, y: &Vector3<f64>, j: &mut Matrix3<f64>) -> bool {
        *j = Matrix3::new(
            -0.04,
            1e4 * y[2],
            1e4 * y[1],
            0.04,
            -1e4 * y[2] - 6e7 * y[1],
            -1e4 * y[1],
            0.0,
            6e7 * y[1],
            0.0,
        );
        true
    }
}

/// Reference at t = 1e11 (test set, "rober").
const ROBER_REF: [f64; 3] = [
    0.208_334_014_970_125_5e-7,
    0.833_336_077_033_471_3e-13,
    0.999_999_979_166_505,
];

/// HIRES (Schäfer 1975), 8 components; finite-difference Jacobian on purpose.
struct Hires;

impl OdeSystem<U8> for Hires {
    fn rhs(&self, _t: f64, y: &SVector<f64, 8>, f: &mut SVector<f64, 8>) {
        f[0] = -1.71 * y[0] + 0.43 * y[1] + 8.32 * y[2] + 0.0007;
        f[1] = 1.71 * y[0] - 8.75 * y[1];
        f[2] = -10.03 * y[2] + 0.43 * y[3] + 0.035 * y[4];
        f[3] = 8.32 * y[1] + 1.71 * y[2] - 1.12 * y[3];
        f[4] = -1.745 * y[4] + 0.43 * y[5] + 0.43 * y[6];
        f[5] = -280.0 * y[5] * y[7] + 0.69 * y[3] + 1.71 * y[4] - 0.43 * y[5] + 0.69 * y[6];
        f[6] = 280.0 * y[5] * y[7] - 1.81 * y[6];
        f[7] = -f[6];
    }
}

/// Reference at t = 321.8122 (test set, "hires").
const HIRES_REF: [f64; 8] = [
    0.737_131_257_332_566_8e-3,
    0.144_248_572_631_618_5e-3,
    0.588_872_974_096_757_5e-4,
    0.117_565_134_328_314_9e-2,
    0.238_635_619_883_133_1e-2,
    0.623_896_825_274_279_6e-2,
    0.284_999_839_518_576_9e-2,
    0.285_000_160_481_423_1e-2,
];

fn max_rel_err<const N: usize>(y: &SVector<f64, N>, r: &[f64; N], floor: f64) -> f64 {
    (0..N)
        .map(|i| (y[i] - r[i]).abs() / r[i].abs().max(floor))
        .fold(0.0, f64::max)
}

fn vdp(method: Method, tol: f64) -> Solution<U2> {
    let opts = Options::default().rtol(tol).atol(tol).dense(false);
    solve(
        &VanDerPol { mu: 1000.0 },
        0.0,
        Vector2::new(2.0, 0.0),
        2000.0,
        method,
        &opts,
        &mut [],
    )
    .unwrap_or_else(|e| panic!("{method} at tol {tol}: {e}"))
}

fn rober(method: Method, rtol: f64) -> Solution<U3> {
    // y2 is ~1e-13 at the end: absolute tolerances far below the component sizes.
    let opts = Options::default()
        .rtol(rtol)
        .atol_per_component(vec![1e-4 * rtol * 1e-8, 1e-4 * rtol * 1e-13, 1e-4 * rtol])
        .dense(false)
        .max_steps(200_000);
    solve(
        &Robertson,
        0.0,
        Vector3::new(1.0, 0.0, 0.0),
        1e11,
        method,
        &opts,
        &mut [],
    )
    .unwrap_or_else(|e| panic!("{method} at rtol {rtol}: {e}"))
}

fn hires(method: Method, tol: f64) -> Solution<U8> {
    let opts = Options {
        atol: Tolerance::Scalar(tol * 1e-3),
        ..Options::default().rtol(tol).dense(false)
    };
    let mut y0 = SVector::<f64, 8>::zeros();
    y0[0] = 1.0;
    y0[7] = 0.0057;
    solve(&Hires, 0.0, y0, 321.8122, method, &opts, &mut [])
        .unwrap_or_else(|e| panic!("{method} at tol {tol}: {e}"))
}

const STIFF: [Method; 3] = [Method::Rodas5P, Method::Radau5, Method::Auto];

#[test]
fn van_der_pol_matches_test_set_reference() {
    for m in STIFF {
        let sol = vdp(m, 1e-8);
        let y = sol.y_final();
        let e = max_rel_err(&SVector::<f64, 2>::from([y[0], y[1]]), &VDP_REF, 1e-3);
        println!("vdp {m}: rel err {e:.2e}, {:?}", sol.stats);
        // A relaxation oscillation with sharp fronts: the global error at tol 1e-8 is a few
        // hundred times the tolerance (error growth through the fronts).
        assert!(e < 1e-5, "{m}: relative error {e}");
    }
}

#[test]
fn robertson_to_1e11_conserves_mass_and_matches_reference() {
    for m in STIFF {
        let sol = rober(m, 1e-8);
        let y = sol.y_final();
        let e = max_rel_err(
            &SVector::<f64, 3>::from([y[0], y[1], y[2]]),
            &ROBER_REF,
            1e-30,
        );
        println!("rober {m}: rel err {e:.2e}, {:?}", sol.stats);
        // Relative error per component (even y2 ~ 1e-13) within 1e-4.
        assert!(e < 1e-4, "{m}: relative error {e}");
        for y in &sol.y {
            // Linear invariant: every linear-implicit/RK step preserves it up to rounding
            // accumulated over the steps.
            assert!((y.sum() - 1.0).abs() < 1e-12, "{m}: mass {}", y.sum());
        }
    }
}

#[test]
fn hires_matches_test_set_reference() {
    for m in STIFF {
        let sol = hires(m, 1e-8);
        let e = max_rel_err(sol.y_final(), &HIRES_REF, 1e-30);
        println!("hires {m}: rel err {e:.2e}, {:?}", sol.stats);
        assert!(e < 1e-5, "{m}: relative error {e}");
    }
}

#[test]
fn error_shrinks_with_tolerance() {
    for m in STIFF {
        let errs: Vec<f64> = [1e-5, 1e-7, 1e-9]
            .iter()
            .map(|&tol| {
                let y = *hires(m, tol).y_final();
                max_rel_err(&y, &HIRES_REF, 1e-30)
            })
            .collect();
        println!("hires {m}: errors {errs:?}");
        for w in errs.windows(2) {
            // Tolerance down by 100: error down by at least 20 (proportionality up to the
            // usual slack of an error-per-step controller).
            assert!(w[1] < w[0] / 20.0, "{m}: {errs:?}");
        }
    }
}

#[allow(dead_code)]
fn _types(_: SMatrix<f64, 2, 2>) {}

#[test]
fn auto_switches_where_stiffness_changes() {
    // Van der Pol (μ = 1000) alternates slow stiff phases and fast non-stiff jumps: Auto must
    // use both methods and switch both ways; the stiff phases take most of the time.
    let sol = vdp(Method::Auto, 1e-6);
    let s = sol.stats;
    println!("vdp auto: {s:?}");
    assert!(s.stiffness_switches >= 2, "{s:?}");
    assert!(s.stiff_steps > 0 && s.stiff_steps < s.accepted, "{s:?}");
    // Robertson is stiff almost from the start: one switch, and most steps are stiff.
    let s = rober(Method::Auto, 1e-6).stats;
    println!("rober auto: {s:?}");
    assert!(
        s.stiffness_switches >= 1 && 2 * s.stiff_steps > s.accepted,
        "{s:?}"
    );
    // The explicit method alone exhausts the default budget of 100 000 steps early on, where
    // Auto needed a few hundred.
    let opts = Options::default().rtol(1e-6).atol(1e-6).dense(false);
    let r = solve(
        &VanDerPol { mu: 1000.0 },
        0.0,
        Vector2::new(2.0, 0.0),
        2000.0,
        Method::Tsit5,
        &opts,
        &mut [],
    );
    assert!(matches!(r, Err(hdi_tribology::ode::OdeError::TooManySteps { t, .. }) if t < 1000.0));
}
