//! The sensors firmware reads, each with its own bandwidth and seeded noise, and the true values
//! behind them.

use super::rng::Rng;
use crate::error::{check_finite, check_non_negative, check_positive, Result};
use serde::Serialize;
use std::f64::consts::PI;

/// Embedded contact sensor: a thermal resistor at the air-bearing surface.
///
/// Its temperature is that of one lumped thermal node fed by the heater and by frictional
/// heating, and drained to the slider body and, across the head–disk gap, to the disk:
///
/// `T = T_amb + (c_h P + c_f μ F̄_c v) / (1 + g_0 · L / (d + L))`
///
/// `c_h` and `c_f` are the node's temperature rise per watt of heater and of frictional power
/// with the gap closed off; the gap conductance relative to the conductance to the body is
/// `g_0 L/(d + L)`, the continuum conductance `k_air/(d + L)` of a gap of width `d` with the
/// temperature-jump distances of both walls summed in `L` (rarefied-gas heat conduction, the
/// Smoluchowski jump), normalised to `g_0` at `d = 0`. The resistance is
/// `R = R_0 (1 + α (T − T_ref))`, read through a first-order low pass of bandwidth
/// `bandwidth` with white Gaussian noise of standard deviation `noise` per sample. As the
/// heater closes the gap the cooling grows and `dR/dP` falls; in contact the frictional heat
/// makes it rise again: drives detect touchdown from that change of slope.
///
/// The default values are illustrative (a nickel–iron sensor, ≈ 1 K/mW from the heater), not a
/// particular product.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ContactSensorSpec {
    /// `R_0`, the resistance at the reference temperature (Ω).
    pub resistance: f64,
    /// Temperature coefficient `α` (1/K).
    pub tcr: f64,
    /// `c_h`: temperature rise per heater watt with no gap cooling (K/W).
    pub heater_coupling: f64,
    /// `c_f`: temperature rise per watt of frictional heat with no gap cooling (K/W).
    pub friction_coupling: f64,
    /// `g_0`: gap conductance at zero gap over the conductance to the slider body.
    pub gap_cooling: f64,
    /// `L`: summed temperature-jump distance of the gap (m).
    pub jump_length: f64,
    /// Read-out bandwidth (Hz).
    pub bandwidth: f64,
    /// Noise per sample, standard deviation (Ω).
    pub noise: f64,
}

impl Default for ContactSensorSpec {
    fn default() -> Self {
        ContactSensorSpec {
            resistance: 100.0,
            tcr: 2.5e-3,
            heater_coupling: 1.2e3,
            friction_coupling: 5.0e4,
            gap_cooling: 0.5,
            jump_length: 100e-9,
            bandwidth: 10e3,
            noise: 5e-3,
        }
    }
}

/// Acoustic-emission sensor: the RMS of the band-passed (hundreds of kHz) elastic waves.
///
/// Asperity contact radiates elastic waves whose energy is a fraction of the frictional work,
/// so the band-passed signal's mean square grows with the frictional power `μ F̄_c v`:
/// `AE = √(G² μ F̄_c v + n²)`, with `n` the amplifier's noise (Rayleigh-distributed RMS of
/// Gaussian noise of standard deviation `noise` per quadrature) and the power seen through
/// the RMS detector's first-order low pass of bandwidth `bandwidth`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AcousticSpec {
    /// `G` (V/√W).
    pub gain: f64,
    /// Noise per quadrature, standard deviation (V).
    pub noise: f64,
    /// Bandwidth of the RMS detector (Hz).
    pub bandwidth: f64,
}

impl Default for AcousticSpec {
    fn default() -> Self {
        AcousticSpec {
            gain: 1.0,
            noise: 2e-3,
            bandwidth: 5e3,
        }
    }
}

/// Readback of a written pattern of wavelength `λ`: the amplitudes of its fundamental and
/// third harmonic, with the Wallace spacing loss `A_k = A_{k,0} exp(−2π k d_m / λ)`.
///
/// `d_m = d + magnetic_offset` is the magnetic spacing (the bulge gap plus overcoats and
/// lubricant), low-passed over the read-back `bandwidth`. Each amplitude carries a relative
/// Gaussian noise `noise` and a common gain `g(t)` (preamplifier drift) that the harmonic
/// ratio cancels: `ln(A_1/A_3) = const + 4π d_m/λ`, so the clearance change is
/// `Δd = λ/(4π) Δln(A_1/A_3)` ([`Readback::clearance_change_nm`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ReadbackSpec {
    /// Wavelength of the fundamental `λ` (m).
    pub wavelength: f64,
    /// Magnetic spacing beyond the bulge gap (m).
    pub magnetic_offset: f64,
    /// Amplitude of the fundamental at zero magnetic spacing (V); the third harmonic's is a
    /// third of it (square-wave pattern).
    pub amplitude: f64,
    /// Relative noise of each amplitude per sample (standard deviation).
    pub noise: f64,
    /// Relative amplitude of the slow common gain drift (a sine of period 1 s).
    pub gain_drift: f64,
    /// Bandwidth (Hz).
    pub bandwidth: f64,
}

impl Default for ReadbackSpec {
    fn default() -> Self {
        ReadbackSpec {
            wavelength: 100e-9,
            magnetic_offset: 4e-9,
            amplitude: 1e-3,
            noise: 2e-3,
            gain_drift: 0.05,
            bandwidth: 10e3,
        }
    }
}

/// All sensor models of a drive.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct SensorSpec {
    /// The embedded contact sensor.
    pub contact: ContactSensorSpec,
    /// The acoustic-emission sensor.
    pub acoustic: AcousticSpec,
    /// The read-back channel.
    pub readback: ReadbackSpec,
}

impl SensorSpec {
    pub(crate) fn validate(&self) -> Result<()> {
        let c = &self.contact;
        check_positive("sensors.contact.resistance", c.resistance)?;
        check_finite("sensors.contact.tcr", c.tcr)?;
        check_non_negative("sensors.contact.heater_coupling", c.heater_coupling)?;
        check_non_negative("sensors.contact.friction_coupling", c.friction_coupling)?;
        check_non_negative("sensors.contact.gap_cooling", c.gap_cooling)?;
        check_positive("sensors.contact.jump_length", c.jump_length)?;
        check_positive("sensors.contact.bandwidth", c.bandwidth)?;
        check_non_negative("sensors.contact.noise", c.noise)?;
        let a = &self.acoustic;
        check_non_negative("sensors.acoustic.gain", a.gain)?;
        check_non_negative("sensors.acoustic.noise", a.noise)?;
        check_positive("sensors.acoustic.bandwidth", a.bandwidth)?;
        let r = &self.readback;
        check_positive("sensors.readback.wavelength", r.wavelength)?;
        check_non_negative("sensors.readback.magnetic_offset", r.magnetic_offset)?;
        check_positive("sensors.readback.amplitude", r.amplitude)?;
        check_non_negative("sensors.readback.noise", r.noise)?;
        check_non_negative("sensors.readback.gain_drift", r.gain_drift)?;
        if r.gain_drift >= 1.0 {
            return Err(crate::Error::invalid(
                "sensors.readback.gain_drift",
                format!("must be below 1, got {}", r.gain_drift),
            ));
        }
        check_positive("sensors.readback.bandwidth", r.bandwidth)?;
        Ok(())
    }
}

/// Read-back amplitudes of one sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Readback {
    /// Fundamental (V).
    pub fundamental_v: f64,
    /// Third harmonic (V).
    pub third_v: f64,
}

impl Readback {
    /// `ln(A_1/A_3)`.
    pub fn log_ratio(&self) -> f64 {
        (self.fundamental_v / self.third_v).ln()
    }

    /// Magnetic-spacing change from a reference log ratio to `log_ratio` (nm), for a pattern of
    /// wavelength `wavelength_nm`: `Δd = λ/(4π) (ln(A_1/A_3) − ln(A_1/A_3)_ref)`.
    ///
    /// ```
    /// use hdi_tribology::drive::Readback;
    /// let lambda_nm = 100.0;
    /// let at = |d_nm: f64| Readback {
    ///     fundamental_v: (-2.0 * std::f64::consts::PI * d_nm / lambda_nm).exp(),
    ///     third_v: (-6.0 * std::f64::consts::PI * d_nm / lambda_nm).exp() / 3.0,
    /// };
    /// let dd = Readback::clearance_change_nm(at(5.0).log_ratio(), at(6.0).log_ratio(), lambda_nm);
    /// assert!((dd - 1.0).abs() < 1e-9);
    /// ```
    pub fn clearance_change_nm(reference: f64, log_ratio: f64, wavelength_nm: f64) -> f64 {
        clearance_change(reference, log_ratio, wavelength_nm)
    }
}

/// `λ/(4π) (log_ratio − reference)`, in the unit of `wavelength`.
pub(crate) fn clearance_change(reference: f64, log_ratio: f64, wavelength: f64) -> f64 {
    wavelength / (4.0 * PI) * (log_ratio - reference)
}

/// The true state behind the sensors, in SI: what the drive computes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct TrueState {
    pub gap: f64,
    pub pad_gap: f64,
    pub displacement: f64,
    pub velocity: f64,
    pub protrusion: f64,
    pub mean_contact_force: f64,
    pub contact_force: f64,
    pub interface_force: f64,
    pub mean_flash_temperature: f64,
    pub friction_power: f64,
    pub sensor_temperature: f64,
    pub disk_height: f64,
    pub ambient: f64,
}

impl TrueState {
    /// In the firmware-facing units of [`Truth`] (each value times a power of ten).
    pub(crate) fn truth(&self) -> Truth {
        Truth {
            gap_nm: self.gap * 1e9,
            pad_gap_nm: self.pad_gap * 1e9,
            displacement_nm: self.displacement * 1e9,
            velocity_mm_per_s: self.velocity * 1e3,
            protrusion_nm: self.protrusion * 1e9,
            mean_contact_force_un: self.mean_contact_force * 1e6,
            contact_force_un: self.contact_force * 1e6,
            interface_force_un: self.interface_force * 1e6,
            mean_flash_temperature_k: self.mean_flash_temperature,
            friction_power_mw: self.friction_power * 1e3,
            sensor_temperature_k: self.sensor_temperature,
            disk_height_nm: self.disk_height * 1e9,
            ambient_k: self.ambient,
        }
    }
}

/// The true state behind the sensors, for test oracles, in engineering units (the unit in each
/// name, as in the C ABI's `HdiTruth`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Truth {
    /// Bulge gap `d` at the end of the period (nm).
    pub gap_nm: f64,
    /// Pad gap at the end of the period (nm).
    pub pad_gap_nm: f64,
    /// Slider displacement relative to the disk surface (nm).
    pub displacement_nm: f64,
    /// Its rate (mm/s).
    pub velocity_mm_per_s: f64,
    /// Protrusion `δ` (nm).
    pub protrusion_nm: f64,
    /// Contact force averaged over the period (µN).
    pub mean_contact_force_un: f64,
    /// Contact force at the end of the period (µN).
    pub contact_force_un: f64,
    /// Interface force at the end of the period (µN, positive pushes the head away).
    pub interface_force_un: f64,
    /// Flash temperature rise averaged over the period (K).
    pub mean_flash_temperature_k: f64,
    /// Frictional power `μ F̄_c v` over the period (mW).
    pub friction_power_mw: f64,
    /// Contact-sensor temperature (K above the reference).
    pub sensor_temperature_k: f64,
    /// Disk surface height under the head (nm).
    pub disk_height_nm: f64,
    /// Ambient temperature change since the start (K).
    pub ambient_k: f64,
}

/// What the drive reports after one controller period, in engineering units (the unit in each
/// name, as in the C ABI's `HdiSensors`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Sensors {
    /// Time at the end of the period (s).
    pub time_s: f64,
    /// Contact-sensor resistance (Ω).
    pub contact_resistance_ohm: f64,
    /// Acoustic-emission RMS (V).
    pub acoustic_v: f64,
    /// Read-back amplitudes.
    pub readback: Readback,
    /// The heater power in effect over the period (mW).
    pub heater_power_mw: f64,
    /// The true values.
    pub truth: Truth,
}

/// The physical inputs of the sensors at the end of one period.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Physical {
    pub gap: f64,
    pub heater_power: f64,
    pub friction_power: f64,
    pub ambient: f64,
}

/// Filter states and noise sources of the sensors.
#[derive(Clone, Debug)]
pub(crate) struct SensorState {
    spec: SensorSpec,
    temperature: f64,
    friction_power: f64,
    spacing: f64,
    ecs_noise: Rng,
    ae_noise: Rng,
    rb_noise: Rng,
    /// The low-pass factors of the last period length `(dt, [contact, acoustic, read-back])`.
    lp: (f64, [f64; 3]),
}

impl SensorState {
    pub(crate) fn new(spec: SensorSpec, seed: u64, start: &Physical) -> Self {
        let mut s = SensorState {
            spec,
            temperature: 0.0,
            friction_power: start.friction_power,
            spacing: start.gap,
            ecs_noise: Rng::new(seed, 0xEC5),
            ae_noise: Rng::new(seed, 0xAE),
            rb_noise: Rng::new(seed, 0xB7),
            lp: (f64::NAN, [0.0; 3]),
        };
        s.temperature = s.steady_temperature(start);
        s
    }

    fn steady_temperature(&self, p: &Physical) -> f64 {
        let c = &self.spec.contact;
        let cooling = c.gap_cooling * c.jump_length / (p.gap.max(0.0) + c.jump_length);
        p.ambient
            + (c.heater_coupling * p.heater_power + c.friction_coupling * p.friction_power)
                / (1.0 + cooling)
    }

    /// Advances the filters by `dt` with the physical inputs held over the period, then samples.
    /// Returns (resistance, AE, readback, sensor temperature).
    pub(crate) fn sample(&mut self, t: f64, dt: f64, p: &Physical) -> (f64, f64, Readback, f64) {
        let spec = self.spec;
        if self.lp.0 != dt {
            let lp = |bw: f64| 1.0 - (-2.0 * PI * bw * dt).exp();
            self.lp = (
                dt,
                [
                    lp(spec.contact.bandwidth),
                    lp(spec.acoustic.bandwidth),
                    lp(spec.readback.bandwidth),
                ],
            );
        }
        let [lp_c, lp_a, lp_r] = self.lp.1;
        let target = self.steady_temperature(p);
        self.temperature += lp_c * (target - self.temperature);
        self.friction_power += lp_a * (p.friction_power - self.friction_power);
        self.spacing += lp_r * (p.gap - self.spacing);

        let c = &spec.contact;
        let r = c.resistance * (1.0 + c.tcr * self.temperature) + c.noise * self.ecs_noise.normal();

        let a = &spec.acoustic;
        let (n1, n2) = (self.ae_noise.normal(), self.ae_noise.normal());
        let ae = (a.gain * a.gain * self.friction_power.max(0.0)
            + 0.5 * a.noise * a.noise * (n1 * n1 + n2 * n2))
            .sqrt();

        let rb = &spec.readback;
        let gain = 1.0 + rb.gain_drift * (2.0 * PI * t).sin();
        let dm = self.spacing + rb.magnetic_offset;
        let k = 2.0 * PI * dm / rb.wavelength;
        let readback = Readback {
            fundamental_v: gain
                * rb.amplitude
                * (-k).exp()
                * (1.0 + rb.noise * self.rb_noise.normal()),
            third_v: gain * rb.amplitude / 3.0
                * (-3.0 * k).exp()
                * (1.0 + rb.noise * self.rb_noise.normal()),
        };
        (r, ae, readback, self.temperature)
    }
}
