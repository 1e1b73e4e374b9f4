//! The `[drive]` section of a scene: the simulated drive the scene's slider flies in (heads,
//! zone, heater start and lag, disk, ambient drift, sensors), so that one file describes a
//! drive. Every field is optional; an absent one keeps the library's default
//! (`drive::DriveOptions::default()`).

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Most heads (disk surfaces) one drive may have.
pub const MAX_HEADS: u32 = 32;

/// The `[drive]` section: see the module documentation and docs/scene_format.md.
///
/// ```
/// use hdi_tribology::scene::Scene;
/// let text = format!("{}\n[drive]\nheads = 2\nrpm = 7200\ninitial_heater_power_mw = 65\n\
///     [drive.ambient]\nrate_k_per_s = 20\n[drive.sensors]\nreadback_wavelength_nm = 80\n",
///     Scene::paper().to_toml_string()?);
/// let scene = Scene::from_toml_str(&text)?;
/// let d = scene.drive.unwrap();
/// assert_eq!((d.heads, d.rpm), (2, Some(7200.0)));
/// assert_eq!(d.initial_heater_power_w, Some(0.065));
/// assert_eq!(d.sensors.readback_wavelength_m, Some(80e-9));
/// // A bad value is named as written, in the unit written.
/// let bad = text.replace("initial_heater_power_mw = 65", "initial_heater_power_mw = -5");
/// let e = Scene::from_toml_str(&bad).unwrap_err().to_string();
/// assert!(e.contains("drive.initial_heater_power_mw") && e.contains("-5 mW"), "{e}");
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveSpec {
    /// Heads, one per disk surface (1 to [`MAX_HEADS`]; default 1).
    #[serde(default = "one_head", skip_serializing_if = "is_one")]
    pub heads: u32,
    /// Radius of the zone (m; default 25 mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius_m: Option<f64>,
    /// Spindle speed (rpm); default: the scene's disk speed at the radius.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rpm: Option<f64>,
    /// Heater power at the start (W; default 60 mW).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_heater_power_w: Option<f64>,
    /// Heater time constant where the scene's heater has none (s; default 100 µs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub heater_time_constant_s: Option<f64>,
    /// The disk surface.
    #[serde(default, skip_serializing_if = "DriveDiskSpec::is_default")]
    pub disk: DriveDiskSpec,
    /// The ambient drift.
    #[serde(default, skip_serializing_if = "DriveAmbientSpec::is_default")]
    pub ambient: DriveAmbientSpec,
    /// The sensors.
    #[serde(default, skip_serializing_if = "DriveSensorsSpec::is_default")]
    pub sensors: DriveSensorsSpec,
}

/// `[drive.disk]`: each surface's run-out and waviness (each surface draws its own random
/// waviness from its seed).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveDiskSpec {
    /// Once-around axial run-out amplitude (m, ≥ 0; default 1 µm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub runout_m: Option<f64>,
    /// Root-mean-square height of the random waviness (m, ≥ 0; default 0.3 nm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub waviness_rms_m: Option<f64>,
    /// Lowest and highest order of the random waviness per revolution (default 20 to 400).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub waviness_orders: Option<[u32; 2]>,
}

/// `[drive.ambient]`: `ΔT(t) = rate · t + amplitude · sin(2π t / period) + step · H(t − step_time)`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveAmbientSpec {
    /// Linear drift (K/s; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate_k_per_s: Option<f64>,
    /// Amplitude of the periodic part (K; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitude_k: Option<f64>,
    /// Its period (s, > 0; default 1 s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub period_s: Option<f64>,
    /// Clearance change per kelvin (m/K; default 0.03 nm/K).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clearance_per_kelvin_m: Option<f64>,
    /// A step of the ambient temperature (K; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step_k: Option<f64>,
    /// When it comes (s, ≥ 0; default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step_time_s: Option<f64>,
}

/// `[drive.sensors]`: the options a test bench changes most.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveSensorsSpec {
    /// Acoustic-emission gain `G` (V/√W, ≥ 0; default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ae_gain_v_per_sqrt_w: Option<f64>,
    /// Bandwidth of the acoustic-emission RMS detector (Hz, > 0; default 5 kHz).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ae_bandwidth_hz: Option<f64>,
    /// Acoustic-emission amplifier noise per quadrature (V, ≥ 0; default 2 mV).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ae_noise_v: Option<f64>,
    /// Contact-sensor noise per sample (Ω, ≥ 0; default 5 mΩ).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact_noise_ohm: Option<f64>,
    /// Read-back wavelength (m, > 0; default 100 nm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub readback_wavelength_m: Option<f64>,
}

impl Default for DriveSpec {
    /// One head; every other setting the library's default.
    ///
    /// ```
    /// use hdi_tribology::scene::DriveSpec;
    /// assert_eq!(DriveSpec::default().heads, 1);
    /// ```
    fn default() -> Self {
        DriveSpec {
            heads: one_head(),
            radius_m: None,
            rpm: None,
            initial_heater_power_w: None,
            heater_time_constant_s: None,
            disk: DriveDiskSpec::default(),
            ambient: DriveAmbientSpec::default(),
            sensors: DriveSensorsSpec::default(),
        }
    }
}

fn one_head() -> u32 {
    1
}

fn is_one(n: &u32) -> bool {
    *n == 1
}

impl DriveDiskSpec {
    fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

impl DriveAmbientSpec {
    fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

impl DriveSensorsSpec {
    fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

/// How a value is checked.
#[derive(Clone, Copy)]
enum Rule {
    Finite,
    NonNegative,
    Positive,
    /// In `(0, max]`.
    UpTo(f64),
    /// In `[0, max]`.
    ZeroTo(f64),
}

/// One field of the section: its path below `drive.`, the name with its engineering unit (the
/// CLI flag's and the Python argument's), the factor from that unit to SI, the unit, and the
/// rule.
struct Field {
    path: &'static str,
    eng: &'static str,
    factor: f64,
    unit: &'static str,
    rule: Rule,
}

const fn field(
    path: &'static str,
    eng: &'static str,
    factor: f64,
    unit: &'static str,
    rule: Rule,
) -> Field {
    Field {
        path,
        eng,
        factor,
        unit,
        rule,
    }
}

/// The numeric fields of the section (the heads and the waviness orders are integers, checked
/// on their own).
const FIELDS: &[Field] = &[
    field("radius_m", "radius_mm", 1e-3, "mm", Rule::UpTo(0.1)),
    field("rpm", "rpm", 1.0, "rpm", Rule::UpTo(100_000.0)),
    field(
        "initial_heater_power_w",
        "initial_heater_power_mw",
        1e-3,
        "mW",
        Rule::ZeroTo(1.0),
    ),
    field(
        "heater_time_constant_s",
        "heater_time_constant_us",
        1e-6,
        "µs",
        Rule::ZeroTo(1.0),
    ),
    field("disk.runout_m", "runout_nm", 1e-9, "nm", Rule::ZeroTo(1e-3)),
    field(
        "disk.waviness_rms_m",
        "waviness_rms_nm",
        1e-9,
        "nm",
        Rule::ZeroTo(1e-6),
    ),
    field(
        "ambient.rate_k_per_s",
        "ambient_rate_k_per_s",
        1.0,
        "K/s",
        Rule::Finite,
    ),
    field(
        "ambient.amplitude_k",
        "ambient_amplitude_k",
        1.0,
        "K",
        Rule::Finite,
    ),
    field(
        "ambient.period_s",
        "ambient_period_s",
        1.0,
        "s",
        Rule::Positive,
    ),
    field(
        "ambient.clearance_per_kelvin_m",
        "ambient_clearance_per_kelvin_nm",
        1e-9,
        "nm/K",
        Rule::Finite,
    ),
    field("ambient.step_k", "ambient_step_k", 1.0, "K", Rule::Finite),
    field(
        "ambient.step_time_s",
        "ambient_step_time_s",
        1.0,
        "s",
        Rule::NonNegative,
    ),
    field(
        "sensors.ae_gain_v_per_sqrt_w",
        "ae_gain_v_per_sqrt_w",
        1.0,
        "V/√W",
        Rule::NonNegative,
    ),
    field(
        "sensors.ae_bandwidth_hz",
        "ae_bandwidth_khz",
        1e3,
        "kHz",
        Rule::Positive,
    ),
    field(
        "sensors.ae_noise_v",
        "ae_noise_v",
        1.0,
        "V",
        Rule::NonNegative,
    ),
    field(
        "sensors.contact_noise_ohm",
        "contact_noise_ohm",
        1.0,
        "Ω",
        Rule::NonNegative,
    ),
    field(
        "sensors.readback_wavelength_m",
        "readback_wavelength_nm",
        1e-9,
        "nm",
        Rule::Positive,
    ),
];

impl DriveSpec {
    /// The names of the section's settings in engineering units, as the `hdi drive` flags
    /// (`--` and dashes) and the Python arguments spell them, with their units.
    ///
    /// ```
    /// use hdi_tribology::scene::DriveSpec;
    /// let names: Vec<_> = DriveSpec::settings().map(|(n, _)| n).collect();
    /// assert!(names.contains(&"readback_wavelength_nm") && names.contains(&"heads"));
    /// ```
    pub fn settings() -> impl Iterator<Item = (&'static str, &'static str)> {
        std::iter::once(("heads", ""))
            .chain(FIELDS.iter().map(|f| (f.eng, f.unit)))
            .chain(std::iter::once(("waviness_orders", "")))
    }

    fn slot(&mut self, path: &str) -> Option<&mut Option<f64>> {
        Some(match path {
            "radius_m" => &mut self.radius_m,
            "rpm" => &mut self.rpm,
            "initial_heater_power_w" => &mut self.initial_heater_power_w,
            "heater_time_constant_s" => &mut self.heater_time_constant_s,
            "disk.runout_m" => &mut self.disk.runout_m,
            "disk.waviness_rms_m" => &mut self.disk.waviness_rms_m,
            "ambient.rate_k_per_s" => &mut self.ambient.rate_k_per_s,
            "ambient.amplitude_k" => &mut self.ambient.amplitude_k,
            "ambient.period_s" => &mut self.ambient.period_s,
            "ambient.clearance_per_kelvin_m" => &mut self.ambient.clearance_per_kelvin_m,
            "ambient.step_k" => &mut self.ambient.step_k,
            "ambient.step_time_s" => &mut self.ambient.step_time_s,
            "sensors.ae_gain_v_per_sqrt_w" => &mut self.sensors.ae_gain_v_per_sqrt_w,
            "sensors.ae_bandwidth_hz" => &mut self.sensors.ae_bandwidth_hz,
            "sensors.ae_noise_v" => &mut self.sensors.ae_noise_v,
            "sensors.contact_noise_ohm" => &mut self.sensors.contact_noise_ohm,
            "sensors.readback_wavelength_m" => &mut self.sensors.readback_wavelength_m,
            _ => return None,
        })
    }

    /// Sets the setting `eng` (a name of [`DriveSpec::settings`]) to `value`, given in its
    /// engineering unit, checked; `shown` names it in errors as the caller's user wrote it (a
    /// flag, an argument), with the value in that unit.
    ///
    /// ```
    /// use hdi_tribology::scene::DriveSpec;
    /// let mut d = DriveSpec::default();
    /// d.set("readback_wavelength_nm", 80.0, "--readback-wavelength-nm")?;
    /// assert_eq!(d.sensors.readback_wavelength_m, Some(80e-9));
    /// let e = d.set("ae_bandwidth_khz", -1.0, "--ae-bandwidth-khz").unwrap_err();
    /// assert!(e.to_string().contains("--ae-bandwidth-khz") && e.to_string().contains("-1 kHz"), "{e}");
    /// # Ok::<(), hdi_tribology::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::InvalidInput`] naming `shown`: a value out of range, an unknown setting.
    pub fn set(&mut self, eng: &str, value: f64, shown: &str) -> Result<()> {
        if eng == "heads" {
            if !(value.fract() == 0.0 && value >= 1.0 && value <= MAX_HEADS as f64) {
                return Err(Error::invalid(
                    shown,
                    format!("must be a whole number of heads from 1 to {MAX_HEADS}, got {value}"),
                ));
            }
            self.heads = value as u32;
            return Ok(());
        }
        let Some(f) = FIELDS.iter().find(|f| f.eng == eng) else {
            return Err(Error::invalid(shown, "is not a drive setting"));
        };
        check(f, value, shown, f.unit, 1.0)?;
        if let Some(slot) = self.slot(f.path) {
            // On the decimal given, as the scene reader converts the same field written in the
            // file (`--runout-nm 500` and `runout_nm = 500` are both 5e-7 m).
            *slot = Some(crate::units::rescale(value, f.factor));
        }
        Ok(())
    }

    /// Sets the random waviness's orders, checked (1 ≤ lowest ≤ highest ≤ 512); `shown` names
    /// them in errors.
    ///
    /// # Errors
    /// [`Error::InvalidInput`] naming `shown`.
    pub fn set_waviness_orders(&mut self, orders: [u32; 2], shown: &str) -> Result<()> {
        check_orders(orders, shown)?;
        self.disk.waviness_orders = Some(orders);
        Ok(())
    }

    /// Checks every field; errors name `drive.` and the field's path, in SI (a scene read from
    /// a file names it as written, in the unit written).
    ///
    /// # Errors
    /// [`Error::InvalidInput`] naming the field.
    pub fn validate(&self) -> Result<()> {
        if !(1..=MAX_HEADS).contains(&self.heads) {
            return Err(Error::invalid(
                "drive.heads",
                format!("must be from 1 to {MAX_HEADS}, got {}", self.heads),
            ));
        }
        let mut me = self.clone();
        for f in FIELDS {
            if let Some(v) = me.slot(f.path).and_then(|s| *s) {
                check(f, v, &format!("drive.{}", f.path), si_unit(f), f.factor)?;
            }
        }
        if let Some(o) = self.disk.waviness_orders {
            check_orders(o, "drive.disk.waviness_orders")?;
        }
        Ok(())
    }
}

/// The SI unit of a field, as error messages write it (so a scene's reader can rewrite it).
fn si_unit(f: &Field) -> &'static str {
    match f.unit {
        "mm" | "nm" => "m",
        "mW" => "W",
        "µs" => "s",
        "kHz" => "Hz",
        "nm/K" => "m/K",
        other => other,
    }
}

/// Checks `v` (in the unit `unit`; `factor` is the field's factor to SI when `v` is in SI, else
/// 1) against the field's rule.
fn check(f: &Field, v: f64, name: &str, unit: &str, factor: f64) -> Result<()> {
    let bound = |max: f64| crate::units::fmt_short(max / f.factor * factor);
    let scale = f.factor / factor;
    let (ok, want) = match f.rule {
        Rule::Finite => (v.is_finite(), "finite".to_string()),
        Rule::NonNegative => (v.is_finite() && v >= 0.0, "finite and ≥ 0".to_string()),
        Rule::Positive => (v.is_finite() && v > 0.0, "finite and > 0".to_string()),
        Rule::UpTo(max) => (
            v > 0.0 && v * scale <= max,
            format!("above 0 and at most {} {unit}", bound(max)),
        ),
        Rule::ZeroTo(max) => (
            v >= 0.0 && v * scale <= max,
            format!("from 0 to {} {unit}", bound(max)),
        ),
    };
    if ok {
        Ok(())
    } else {
        Err(Error::invalid(
            name,
            format!("must be {want}, got {v} {unit}"),
        ))
    }
}

fn check_orders(o: [u32; 2], name: &str) -> Result<()> {
    if o[0] == 0 || o[1] < o[0] || o[1] > 512 {
        return Err(Error::invalid(
            name,
            format!("needs 1 ≤ lowest ≤ highest ≤ 512, got [{}, {}]", o[0], o[1]),
        ));
    }
    Ok(())
}
