//! Linear response about a stable equilibrium: frequency response, modes and the dither that an
//! AC voltage drives at twice its frequency (MODEL.md section 6).
//!
//! The state-space matrix is the slider's own Jacobian (with lags, if the scene has them) at the
//! equilibrium under the mean `V²`; `H(iω) = e_yᵀ (iω − A)⁻¹ b` with `b` the input of a unit force.

use super::equilibrium::{flying_equilibrium, Equilibrium, ScanGrid};
use crate::error::{Error, Result};
use crate::heater::Programme;
use crate::model::{SliderModel, SliderSystem, Voltage};
use crate::ode::OdeSystem;
use nalgebra::{DMatrix, DVector, Dyn};
use num_complex::Complex64;
use serde::Serialize;
use std::f64::consts::PI;

/// One mode of the linearised slider.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Mode {
    /// Eigenvalue real part (1/s).
    pub re: f64,
    /// Eigenvalue imaginary part (1/s).
    pub im: f64,
    /// `|Im λ| / 2π` (Hz).
    pub frequency: f64,
    /// Damping ratio `−Re λ / |λ|`.
    pub damping_ratio: f64,
}

/// The linear response about the flying equilibrium at one heater power.
#[derive(Clone, Debug, Serialize)]
pub struct LinearResponse {
    /// The equilibrium (under the mean `V²`).
    pub equilibrium: Equilibrium,
    /// Eigenvalues of the linearised system.
    pub modes: Vec<Mode>,
    /// Whether every eigenvalue has a negative real part.
    pub stable: bool,
    /// `|H(i·2π·2f)|` (m/N).
    pub gain_at_2f: f64,
    /// Amplitude of the force at `2f`: `|G_e| V_ac²/2` (N).
    pub force_at_2f: f64,
    /// Predicted dither amplitude of `y` at `2f` (m).
    pub dither_amplitude: f64,
    #[serde(skip)]
    a: DMatrix<f64>,
    #[serde(skip)]
    input: usize,
    #[serde(skip)]
    a_input_gain: f64,
}

impl LinearResponse {
    /// `H(iω)` (m/N): displacement per unit interface force at angular frequency `omega`.
    pub fn transfer(&self, omega: f64) -> Complex64 {
        let n = self.a.nrows();
        let m = DMatrix::<Complex64>::from_fn(n, n, |i, j| {
            let diag = if i == j {
                Complex64::new(0.0, omega)
            } else {
                Complex64::new(0.0, 0.0)
            };
            diag - Complex64::new(self.a[(i, j)], 0.0)
        });
        let mut b = DVector::<Complex64>::zeros(n);
        b[self.input] = Complex64::new(self.a_input_gain, 0.0);
        m.lu()
            .solve(&b)
            .map_or(Complex64::new(f64::NAN, f64::NAN), |x| x[0])
    }
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
    let v = model.voltage;
    let v0 = v.effective_dc();
    let mean_volt2 = v0 * v0 + 0.5 * v.ac_amplitude * v.ac_amplitude;
    let eq = flying_equilibrium(model, power, mean_volt2, &ScanGrid::default())?;
    // Freeze the voltage at its mean square: a DC voltage with the same V².
    let frozen = model.with_voltage(Voltage {
        dc: v.contact_potential + mean_volt2.sqrt(),
        ac_amplitude: 0.0,
        ..v
    });
    let sys = SliderSystem::new(&frozen, Programme::constant(power, 1.0)?, false);
    let layout = sys.layout();
    let n = layout.len();
    let state = sys.initial_state(Dyn(n), eq.y, eq.protrusion, eq.interface_force);
    let mut a = DMatrix::<f64>::zeros(n, n);
    OdeSystem::<Dyn>::jacobian(&sys, 0.0, &state, &mut a);
    let (input, gain) = match layout.lagged_force {
        Some(i) => (i, 1.0 / model.interface_lag),
        None => (1, 1.0 / model.mass),
    };
    let modes: Vec<Mode> = a
        .complex_eigenvalues()
        .iter()
        .map(|l| {
            let norm = l.norm();
            Mode {
                re: l.re,
                im: l.im,
                frequency: l.im.abs() / (2.0 * PI),
                damping_ratio: if norm > 0.0 { -l.re / norm } else { 0.0 },
            }
        })
        .collect();
    if modes.iter().any(|m| !m.re.is_finite()) {
        return Err(Error::analysis("linear response", "non-finite eigenvalue"));
    }
    let stable = modes.iter().all(|m| m.re < 0.0);
    let g = model.gaps(eq.y, eq.protrusion);
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
        a,
        input,
        a_input_gain: gain,
    };
    r.gain_at_2f = r.transfer(2.0 * PI * 2.0 * v.frequency).norm();
    r.dither_amplitude = r.gain_at_2f * force_at_2f;
    Ok(r)
}

/// Dither amplitude of `y` at `2f` from a simulation at constant heater power `power` (W): half
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
    use crate::ode::{solve, Options, SaveAt};
    use nalgebra::U2;
    let v = model.voltage;
    if !v.is_time_dependent() {
        return Err(Error::analysis(
            "simulated dither",
            "the voltage has no AC part",
        ));
    }
    if periods == 0 {
        return Err(Error::invalid("periods", "must be at least 1"));
    }
    let period = 1.0 / (2.0 * v.frequency.abs());
    let t_end = (settle + periods) as f64 * period;
    let eq = flying_equilibrium(model, power, v.squared(0.0), &ScanGrid::default())?;
    let sys = SliderSystem::new(model, Programme::constant(power, t_end)?, false);
    if sys.layout().len() != 2 {
        return Err(Error::analysis(
            "simulated dither",
            "only scenes without thermal or interface lag",
        ));
    }
    let y0 = sys.initial_state(U2, eq.y, eq.protrusion, eq.interface_force);
    let t_start = settle as f64 * period;
    let samples = 400 * periods;
    let times: Vec<f64> = (0..=samples)
        .map(|i| t_start + (t_end - t_start) * i as f64 / samples as f64)
        .collect();
    let s = opts.solver;
    let omega = (model.bearing().stiffness(0.0) / model.mass).sqrt();
    let o = Options::default()
        .rtol(s.rtol)
        .atol_per_component(vec![s.atol_displacement, s.atol_displacement * omega])
        .h_max(period / 20.0)
        .max_steps(s.max_steps)
        .save(SaveAt::Times(times));
    let sol = solve(&sys, 0.0, y0, t_end, s.method, &o, &mut [])?;
    let (lo, hi) = sol
        .y
        .iter()
        .map(|x| x[0])
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
            (a.min(y), b.max(y))
        });
    Ok(0.5 * (hi - lo))
}
