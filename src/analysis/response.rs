//! Linear response about a stable equilibrium: modes (frequency, damping ratio, shape), frequency
//! response, and the dither that an AC voltage drives at twice its frequency (MODEL.md section 6).
//!
//! The state-space matrix `A` is the slider's own Jacobian (every coordinate of its structure,
//! with lags if the scene has them) at the equilibrium under the mean `V²`;
//! `H(iω) = cᵀ (iω − A)⁻¹ u` with `u` the input of a unit interface force and `cᵀx = bᵀq` the
//! bulge displacement.

use super::equilibrium::{flying_equilibrium, Equilibrium, ScanGrid};
use crate::error::{failure_kind, Error, Result, Stage};
use crate::model::{Heater, SliderModel, SliderSystem, Voltage};
use crate::ode::OdeSystem;
use crate::scene::MAX_DOF;
use crate::sim::Problem;
use nalgebra::{DMatrix, DVector, Dyn};
use num_complex::Complex64;
use serde::Serialize;
use std::f64::consts::PI;

impl Stage {
    /// The linear response about an equilibrium.
    pub const LINEAR_RESPONSE: Stage = Stage::named("linear response");
    /// The simulated response to the AC dither.
    pub const SIMULATED_DITHER: Stage = Stage::named("simulated dither");
}

/// Why the linear or simulated response could not be given.
///
/// ```
/// use hdi_tribology::analysis::response::ResponseError;
/// let e: hdi_tribology::Error = ResponseError::NoAcVoltage.into();
/// assert_eq!(e.to_string(), "simulated dither: the voltage has no AC part");
/// ```
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ResponseError {
    /// An eigenvalue of the linearised system is not finite.
    #[error("non-finite eigenvalue")]
    NonFiniteEigenvalue,
    /// The simulated dither needs an AC voltage.
    #[error("the voltage has no AC part")]
    NoAcVoltage,
}

failure_kind!(ResponseError, convergence = |_| false, {
        NonFiniteEigenvalue => Stage::LINEAR_RESPONSE,
        NoAcVoltage => Stage::SIMULATED_DITHER,
});

/// One mode of the linearised slider.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Mode {
    /// Eigenvalue real part (1/s).
    #[serde(rename = "re_per_s")]
    pub re: f64,
    /// Eigenvalue imaginary part (1/s).
    #[serde(rename = "im_per_s")]
    pub im: f64,
    /// `|Im λ| / 2π` (Hz).
    #[serde(rename = "frequency_hz")]
    pub frequency: f64,
    /// Damping ratio `−Re λ / |λ|`.
    pub damping_ratio: f64,
    /// Mode shape over the structure's coordinates: the eigenvector's displacement part, scaled
    /// so that its largest entry is 1 and rotated to be real there (signed real parts; entries
    /// beyond the structure's coordinates are 0). All zero for a mode of the lags alone.
    pub shape: [f64; MAX_DOF],
}

/// The linearised slider `ẋ = A x + u f`, with the bulge displacement `cᵀ x`: what
/// [`LinearResponse::transfer`] evaluates, `H(iω) = cᵀ (iω − A)⁻¹ u`. The state is the
/// slider's own (every coordinate of its structure, their velocities, and the lags of the scene
/// if it has them), in SI units.
///
/// ```
/// use hdi_tribology::{analysis::linear_response, model::SliderModel, scene::Scene};
/// let r = linear_response(&SliderModel::from_scene(&Scene::paper())?, 0.06)?;
/// let ss = &r.state_space;
/// // At ω = 0, H is the static compliance cᵀ(−A)⁻¹u.
/// let static_compliance = ss.output.dot(&ss.a.clone().lu().solve(&ss.input).unwrap());
/// assert!((r.transfer(0.0).re + static_compliance).abs() <= 1e-9 * static_compliance.abs());
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct StateSpace {
    /// `A`: the Jacobian of the slider's equations of motion at the equilibrium.
    pub a: DMatrix<f64>,
    /// `u`: the state's rate per unit interface force (per N).
    pub input: DVector<f64>,
    /// `c`: the bulge displacement of a state (m per unit of each state).
    pub output: DVector<f64>,
}

/// The linear response about the flying equilibrium at one heater power.
///
/// Compares by value (`==`), the state-space matrices included; every field is public, so a
/// response saved field by field (as the Python package pickles it) is rebuilt to the bit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LinearResponse {
    /// The equilibrium (under the mean `V²`).
    pub equilibrium: Equilibrium,
    /// Eigenvalues of the linearised system, with shapes, by ascending frequency.
    pub modes: Vec<Mode>,
    /// Whether every eigenvalue has a negative real part.
    pub stable: bool,
    /// `|H(i·2π·2f)|` (m/N).
    #[serde(rename = "gain_at_2f_m_per_n")]
    pub gain_at_2f: f64,
    /// Amplitude of the force at `2f`: `|G_e| V_ac²/2` (N).
    #[serde(rename = "force_at_2f_n")]
    pub force_at_2f: f64,
    /// Predicted dither amplitude of the bulge at `2f` (m).
    #[serde(rename = "dither_amplitude_m")]
    pub dither_amplitude: f64,
    /// The linearised system behind [`LinearResponse::transfer`] (not serialized).
    #[serde(skip)]
    pub state_space: StateSpace,
}

/// `(iω − A)⁻¹ u`, or NaN where singular.
fn resolvent(
    a: &DMatrix<f64>,
    omega: Complex64,
    u: &DVector<Complex64>,
) -> Option<DVector<Complex64>> {
    let n = a.nrows();
    let m = DMatrix::<Complex64>::from_fn(n, n, |i, j| {
        let diag = if i == j {
            omega
        } else {
            Complex64::new(0.0, 0.0)
        };
        diag - Complex64::new(a[(i, j)], 0.0)
    });
    m.lu().solve(u)
}

impl LinearResponse {
    /// `H(iω)` (m/N): bulge displacement per unit interface force at angular frequency `omega`.
    pub fn transfer(&self, omega: f64) -> Complex64 {
        let ss = &self.state_space;
        let u = ss.input.map(|x| Complex64::new(x, 0.0));
        resolvent(&ss.a, Complex64::new(0.0, omega), &u)
            .map_or(Complex64::new(f64::NAN, f64::NAN), |x| {
                x.iter().zip(ss.output.iter()).map(|(x, c)| x * c).sum()
            })
    }
}

/// Diagonal similarity `B = D⁻¹ A D` with powers of two that makes row and column norms alike
/// (Parlett–Reinsch balancing): a stiff bulge puts entries of 10¹⁸ beside entries of 1, and
/// without it the eigenvalues of the slow modes drown in rounding. Returns `B` and `D`.
fn balanced(a: &DMatrix<f64>) -> (DMatrix<f64>, DVector<f64>) {
    let n = a.nrows();
    let mut b = a.clone();
    let mut d = DVector::<f64>::from_element(n, 1.0);
    for _ in 0..200 {
        let mut done = true;
        for i in 0..n {
            let c: f64 = (0..n).filter(|&j| j != i).map(|j| b[(j, i)].abs()).sum();
            let r: f64 = (0..n).filter(|&j| j != i).map(|j| b[(i, j)].abs()).sum();
            if c == 0.0 || r == 0.0 || !c.is_finite() || !r.is_finite() {
                continue;
            }
            let (mut cc, mut rr, mut f) = (c, r, 1.0);
            while cc < rr / 2.0 {
                cc *= 2.0;
                rr /= 2.0;
                f *= 2.0;
            }
            while cc >= rr * 2.0 {
                cc /= 2.0;
                rr *= 2.0;
                f /= 2.0;
            }
            if (cc + rr) / f < 0.95 * (c + r) {
                done = false;
                d[i] *= f;
                for j in 0..n {
                    b[(i, j)] /= f;
                    b[(j, i)] *= f;
                }
            }
        }
        if done {
            break;
        }
    }
    (b, d)
}

/// The shape of the mode of eigenvalue `l` of `A = D B D⁻¹` (`B` balanced, `D = diag(scale)`):
/// two steps of inverse iteration on `B` from a uniform vector, back-scaled by `D`, displacement
/// part normalised.
fn mode_shape(b: &DMatrix<f64>, scale: &DVector<f64>, l: Complex64, dofs: usize) -> [f64; MAX_DOF] {
    let n = b.nrows();
    let eps = 1e-10 * l.norm().max(1.0);
    let shift = l + Complex64::new(eps, eps);
    let mut shape = [0.0; MAX_DOF];
    // (B − s)⁻¹ v = −(s − B)⁻¹ v.
    let step = |v: &DVector<Complex64>| resolvent(b, shift, &v.map(|x| -x));
    let u = DVector::<Complex64>::from_element(n, Complex64::new(1.0, 0.0));
    let Some(xb) = step(&u).and_then(|x| step(&x)) else {
        return shape;
    };
    let x = DVector::<Complex64>::from_fn(n, |i, _| xb[i] * scale[i]);
    let Some(big) = x
        .iter()
        .take(dofs)
        .copied()
        .max_by(|p, q| p.norm().total_cmp(&q.norm()))
    else {
        return shape;
    };
    // A mode of the lag states alone moves no coordinate (velocities are |λ| × positions).
    let total = x.iter().map(|v| v.norm()).fold(0.0, f64::max);
    if big.norm() * l.norm().max(1.0) <= 1e-9 * total {
        return shape;
    }
    for (i, v) in x.iter().take(dofs).enumerate() {
        shape[i] = (v / big).re;
    }
    shape
}

/// Linear response about the flying equilibrium at heater power `power` (W).
///
/// ```no_run
/// use hdi_tribology::{analysis::linear_response, model::SliderModel, scene::Scene};
/// let mut scene = Scene::paper();
/// scene.voltage.ac_amplitude_v = 0.6;
/// let model = SliderModel::from_scene(&scene)?;
/// let r = linear_response(&model, 0.06)?;
/// println!("mode at {:.1} kHz, dither {:.3} nm", r.modes[0].frequency / 1e3, r.dither_amplitude * 1e9);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn linear_response(model: &SliderModel, power: f64) -> Result<LinearResponse> {
    model.require_full_structure("the linear response")?;
    let v = model.voltage();
    let mean_volt2 = v.mean_squared();
    let eq = flying_equilibrium(model, power, mean_volt2, &ScanGrid::default())?;
    // Freeze the voltage at its mean square: a DC voltage with the same V².
    let mut inputs = model.inputs(Heater::Power(power));
    inputs.voltage = Voltage {
        dc: v.contact_potential + mean_volt2.sqrt(),
        ac_amplitude: 0.0,
        ..v
    };
    let sys = SliderSystem::new(model, inputs, false);
    let layout = sys.layout();
    let n = layout.len();
    let state = sys.initial_state(Dyn(n), &eq.rest());
    let mut a = DMatrix::<f64>::zeros(n, n);
    OdeSystem::<Dyn>::jacobian(&sys, 0.0, &state, &mut a);
    // A unit interface force enters through the lag, or through M⁻¹b on the accelerations.
    let st = &model.structure();
    let mut input = DVector::<f64>::zeros(n);
    match layout.lagged_force {
        Some(i) => input[i] = 1.0 / model.interface_lag(),
        None => {
            let per_force = st.mass_solve(&st.bulge_vector());
            for r in 0..layout.dofs {
                input[layout.velocity(r)] = per_force[r];
            }
        }
    }
    let mut output = DVector::<f64>::zeros(n);
    for (r, b) in st.bulge_influence().iter().enumerate() {
        output[r] = *b;
    }
    let (bal, scale) = balanced(&a);
    let mut modes: Vec<Mode> = bal
        .complex_eigenvalues()
        .iter()
        .map(|l| {
            let norm = l.norm();
            Mode {
                re: l.re,
                im: l.im,
                frequency: l.im.abs() / (2.0 * PI),
                damping_ratio: if norm > 0.0 { -l.re / norm } else { 0.0 },
                shape: mode_shape(&bal, &scale, *l, layout.dofs),
            }
        })
        .collect();
    modes.sort_by(|p, q| {
        p.frequency
            .total_cmp(&q.frequency)
            .then(q.re.total_cmp(&p.re))
    });
    if modes.iter().any(|m| !m.re.is_finite()) {
        return Err(ResponseError::NonFiniteEigenvalue.into());
    }
    let stable = modes.iter().all(|m| m.re < 0.0);
    let g = model.gaps(&eq.q, eq.protrusion);
    let ge = if model.forces().has_voltage_terms() {
        model.forces().per_volt2_part(g).value
    } else {
        0.0
    };
    let force_at_2f = ge.abs() * 0.5 * v.ac_amplitude * v.ac_amplitude;
    let mut r = LinearResponse {
        equilibrium: eq,
        modes,
        stable,
        gain_at_2f: 0.0,
        force_at_2f,
        dither_amplitude: 0.0,
        state_space: StateSpace { a, input, output },
    };
    r.gain_at_2f = r.transfer(2.0 * PI * 2.0 * v.frequency).norm();
    r.dither_amplitude = r.gain_at_2f * force_at_2f;
    Ok(r)
}

/// Dither amplitude of the bulge at `2f` from a simulation at constant heater power `power` (W): half
/// the peak-to-peak displacement over the last `periods` periods of `V²`, after `settle` periods
/// for the start-up transient to decay.
///
/// ```no_run
/// use hdi_tribology::analysis::{cycle::CycleOptions, response::simulated_dither};
/// use hdi_tribology::{model::SliderModel, scene::Scene};
/// let mut scene = Scene::paper();
/// scene.voltage.ac_amplitude_v = 0.6;
/// let model = SliderModel::from_scene(&scene)?;
/// let a = simulated_dither(&model, 0.06, &CycleOptions::from_scene(&scene)?, 40, 10)?;
/// println!("{:.4} nm", a * 1e9);
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn simulated_dither(
    model: &SliderModel,
    power: f64,
    opts: &super::cycle::CycleOptions,
    settle: usize,
    periods: usize,
) -> Result<f64> {
    use crate::ode::SaveAt;
    model.require_full_structure("the simulated dither")?;
    let v = model.voltage();
    if !v.is_time_dependent() {
        return Err(ResponseError::NoAcVoltage.into());
    }
    if periods == 0 {
        return Err(Error::invalid("periods", "must be at least 1"));
    }
    let period = 1.0 / (2.0 * v.frequency.abs());
    let t_end = (settle + periods) as f64 * period;
    let eq = flying_equilibrium(model, power, v.squared(0.0), &ScanGrid::default())?;
    let t_start = settle as f64 * period;
    let samples = 400 * periods;
    let times: Vec<f64> = (0..=samples)
        .map(|i| t_start + (t_end - t_start) * i as f64 / samples as f64)
        .collect();
    let s = opts.solver;
    let problem = Problem::builder(model, model.inputs(Heater::Power(power)), false)
        .rtol(s.rtol)
        .tolerances(s.atol_displacement, 0.0, 0.0)
        .max_step(None)
        .max_steps(s.max_steps)
        .save(SaveAt::Times(times))
        .method(s.method)
        .build()?;
    let sys = problem.system();
    let y0 = problem.initial_state(Dyn(sys.layout().len()), &eq.rest());
    let sol = problem.solve(0.0, y0, t_end)?;
    let (lo, hi) = sol
        .y
        .iter()
        .map(|x| model.structure().bulge_displacement(&sys.coordinates(x)))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
            (a.min(y), b.max(y))
        });
    Ok(0.5 * (hi - lo))
}
