//! The C ABI of `hdi-tribology`: opaque handles for a scene, a slider model and a simulated
//! drive; the drive's step with its sensors; the static analyses and one dynamic cycle; version
//! queries. The header `include/hdi.h` is generated from this file by cbindgen
//! (`tests/header.rs` fails when the committed header differs); `docs/firmware.md` walks from
//! the header to a closed loop.
//!
//! # Conventions
//!
//! - **Units.** Engineering units at the edge, the unit in every field name: `heater_power_mw`,
//!   `gap_nm`, `contact_force_un` (µN), `ac_frequency_khz`, `time_s`. Times are in seconds
//!   (`period_s`, `time_s`), as the drive's command files write them.
//! - **Status.** Every call that can fail returns an [`HdiStatus`]; [`hdi_last_error`] gives the
//!   message of the calling thread's last failed call, naming the argument or field as the C
//!   caller wrote it (`command.heater_power_mw`, `config.sensors.contact.noise_ohm`) or, for a
//!   scene, as the scene file wrote it. No Rust panic crosses the boundary: it becomes
//!   [`HdiStatus::Panic`]. On failure, output structs are left unspecified and output handles
//!   are set to `NULL`.
//! - **Handles.** `hdi_*_new`/`hdi_scene_*` return a handle the caller owns and frees with the
//!   one free function of its type. A handle owns copies of what it was made from: a model or
//!   a drive does not borrow the scene it was made from, which may be freed at once. Handles
//!   are checked against a registry of live handles before use: `NULL`, a freed handle, a
//!   pointer this library did not make or a handle of another type is refused with a status,
//!   never dereferenced.
//! - **Threads.** Scenes and models are read-only: any number of calls may read one at once, on
//!   any threads. A drive takes one call at a time (it may move between threads between
//!   calls); a second concurrent call on the same drive is refused with [`HdiStatus::Busy`],
//!   as is freeing a handle while a call uses it. Different drives run in parallel freely.
//!   The last-error message is per thread.
//! - **Memory.** Structs passed in are read during the call only (including the disk's
//!   harmonics array of [`HdiDriveConfig`]); the library keeps no pointer to caller memory.
//!   Strings returned by the library are static or thread-local, never freed by the caller.

mod error;
mod handle;

use error::{call, renamed, Failure};
use handle::{acquire, free, register, Access, Handle, Header, Kind};
use hdi_tribology::analysis::{
    self, static_hysteresis, takeoff_power, touchdown_power, Cause, Protocol, StaticOptions,
    Transition,
};
use hdi_tribology::drive::{
    zone_at, Ambient, Command, DiskSpec, DriveOptions, DriveScheme, Harmonic, MultiDrive,
    MultiPlant, SensorSpec, Sensors, DEFAULT_RADIUS,
};
use hdi_tribology::model::{SliderModel, Voltage};
use hdi_tribology::scene::DriveSpec;
use hdi_tribology::scene::Scene;
use hdi_tribology::units;
use std::cell::UnsafeCell;
use std::ffi::{c_char, CStr};

/// The version of the ABI this header describes: a program built against one version must be
/// run with a library of the same version (check [`hdi_abi_version`] at start-up).
pub const HDI_ABI_VERSION: u32 = 4;

/// [`HdiDriveConfig::scheme`]: the adaptive integrator (the default).
pub const HDI_SCHEME_INTEGRATOR: u32 = 0;
/// [`HdiDriveConfig::scheme`]: one exponential step a period with the Jacobian held, the
/// integrator where it misses (docs/clearance.md, "The exponential scheme").
pub const HDI_SCHEME_EXPONENTIAL: u32 = 1;

/// What a call did. `HDI_STATUS_OK` is 0; every other value is a failure, with its message
/// from [`hdi_last_error`].
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HdiStatus {
    /// Success.
    Ok = 0,
    /// A required pointer argument was `NULL`.
    NullPointer = 1,
    /// A handle that is not live: already freed, or not made by this library.
    InvalidHandle = 2,
    /// A live handle of another type (a model where a drive is expected, ...).
    WrongHandleType = 3,
    /// The handle is in use by a call on another thread.
    Busy = 4,
    /// A value out of its range; the message names the field and gives the value in its unit.
    InvalidInput = 5,
    /// A scene could not be parsed or is invalid; the message names the field as written.
    Scene = 6,
    /// A file could not be read.
    Io = 7,
    /// A numerical procedure did not reach its tolerance.
    NoConvergence = 8,
    /// An analysis has no result for this model (no touchdown in range, ...).
    Analysis = 9,
    /// The time integration failed.
    Integration = 10,
    /// Any other error of the library.
    Other = 11,
    /// An internal error (a bug) was caught; a drive it happened in is refused from then on.
    Panic = 12,
}

// ---------------------------------------------------------------------------------------------
// Handles

/// A scene: the parameters of a head–disk interface (TOML or JSON, as `hdi` reads them).
pub struct HdiScene {
    header: Header,
    scene: Scene,
}

/// A slider model of a scene, with the scene's analysis protocol (detector threshold, heater
/// programmes, solver settings).
pub struct HdiModel {
    header: Header,
    model: SliderModel,
    protocol: Protocol,
}

/// A simulated drive: the slider of a scene in its zone over a disk, with a heater, a voltage
/// and the sensors firmware reads, stepped one controller period at a time; one head or
/// several on one spindle and one clock (`HdiDriveConfig.heads`).
pub struct HdiDrive {
    header: Header,
    /// Reached only under the handle's exclusive access.
    drive: UnsafeCell<MultiDrive>,
    /// The library's sensors of the heads' last step (no allocation per step).
    scratch: UnsafeCell<Vec<Sensors>>,
    protocol: Protocol,
}

impl Handle for HdiScene {
    const KIND: Kind = Kind::Scene;
    fn header(&self) -> &Header {
        &self.header
    }
}

impl Handle for HdiModel {
    const KIND: Kind = Kind::Model;
    fn header(&self) -> &Header {
        &self.header
    }
}

impl Handle for HdiDrive {
    const KIND: Kind = Kind::Drive;
    fn header(&self) -> &Header {
        &self.header
    }
}

// Scenes and models are read from several threads at once.
const _: () = {
    const fn shared<T: Send + Sync>() {}
    shared::<Scene>();
    shared::<SliderModel>();
    shared::<Protocol>();
};

// ---------------------------------------------------------------------------------------------
// Plain structs

/// One controller period's command.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HdiCommand {
    /// Heater power (mW, 0 to 1000); the protrusion follows through the heater's thermal lag.
    pub heater_power_mw: f64,
    /// DC head–disk voltage (V).
    pub dc_voltage_v: f64,
    /// AC dither amplitude (V).
    pub ac_amplitude_v: f64,
    /// AC dither frequency (kHz, ≥ 0).
    pub ac_frequency_khz: f64,
}

/// The true state behind the sensors at the end of a period (for test oracles: firmware
/// cannot read these).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HdiTruth {
    /// Bulge gap (nm).
    pub gap_nm: f64,
    /// Pad gap (nm).
    pub pad_gap_nm: f64,
    /// Slider displacement relative to the disk surface (nm).
    pub displacement_nm: f64,
    /// Its rate (mm/s).
    pub velocity_mm_per_s: f64,
    /// Thermal protrusion (nm).
    pub protrusion_nm: f64,
    /// Contact force, mean over the period (µN).
    pub mean_contact_force_un: f64,
    /// Contact force at the end of the period (µN).
    pub contact_force_un: f64,
    /// Interface force at the end of the period (µN, positive pushes the head away).
    pub interface_force_un: f64,
    /// Flash temperature rise, mean over the period (K).
    pub mean_flash_temperature_k: f64,
    /// Frictional power over the period (mW).
    pub friction_power_mw: f64,
    /// Contact-sensor temperature (K above its reference).
    pub sensor_temperature_k: f64,
    /// Disk surface height under the head (nm).
    pub disk_height_nm: f64,
    /// Ambient temperature change since the start (K).
    pub ambient_k: f64,
}

/// What the drive reports after one controller period: the sensors firmware reads, and the
/// truth.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HdiSensors {
    /// Time at the end of the period (s).
    pub time_s: f64,
    /// Heater power held over the period (mW).
    pub heater_power_mw: f64,
    /// Embedded contact sensor's resistance (Ω).
    pub contact_resistance_ohm: f64,
    /// Acoustic-emission RMS (V).
    pub acoustic_v: f64,
    /// Read-back amplitude of the fundamental (V).
    pub readback_fundamental_v: f64,
    /// Read-back amplitude of the third harmonic (V).
    pub readback_third_v: f64,
    /// The true values.
    pub truth: HdiTruth,
}

/// One fixed harmonic of the disk surface per revolution, `a sin(n θ + φ)`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HdiHarmonic {
    /// Order `n` (cycles per revolution, 1 to 512).
    pub order: u32,
    /// Amplitude `a` (nm).
    pub amplitude_nm: f64,
    /// Phase `φ` (rad).
    pub phase_rad: f64,
}

/// The disk surface (each head's surface its own, drawn from its seed): a once-around run-out,
/// fixed harmonics (known waviness) and seeded random waviness with a `1/n` amplitude
/// spectrum.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HdiDisk {
    /// Once-around axial run-out amplitude (nm, ≥ 0; phase 0; 0 for none): the harmonic of
    /// order 1 the scene's `drive.disk.runout_nm` sets.
    pub runout_nm: f64,
    /// More fixed harmonics (`harmonic_count` of them; read during `hdi_drive_new` only; may
    /// be `NULL` when the count is 0).
    pub harmonics: *const HdiHarmonic,
    /// Number of fixed harmonics (at most 4096).
    pub harmonic_count: usize,
    /// Root-mean-square height of the random waviness (nm, ≥ 0; 0 for none).
    pub random_rms_nm: f64,
    /// Lowest order of the random waviness (≥ 1).
    pub random_order_min: u32,
    /// Highest order of the random waviness (≥ the lowest, ≤ 512).
    pub random_order_max: u32,
}

/// Ambient temperature drift
/// `ΔT(t) = rate · t + amplitude · sin(2π t / period) + step · H(t − step_time)`; the nominal
/// clearance moves by `clearance_per_kelvin_nm · ΔT` and the contact sensor reads `ΔT`. One
/// drive has one ambient: every head sees it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HdiAmbient {
    /// Linear drift (K/s).
    pub rate_k_per_s: f64,
    /// Amplitude of the periodic part (K).
    pub amplitude_k: f64,
    /// Its period (s, > 0).
    pub period_s: f64,
    /// Clearance change per kelvin (nm/K).
    pub clearance_per_kelvin_nm: f64,
    /// A step of the ambient temperature (K; 0 for none): a disturbance to test a clearance
    /// loop against.
    pub step_k: f64,
    /// When the step comes (s, ≥ 0).
    pub step_time_s: f64,
}

/// The embedded contact sensor (a thermal resistor at the air-bearing surface).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HdiContactSensorOptions {
    /// Resistance at the reference temperature (Ω, > 0).
    pub resistance_ohm: f64,
    /// Temperature coefficient of resistance (1/K).
    pub tcr_per_k: f64,
    /// Temperature rise per heater milliwatt with no gap cooling (K/mW, ≥ 0).
    pub heater_coupling_k_per_mw: f64,
    /// Temperature rise per milliwatt of frictional heat with no gap cooling (K/mW, ≥ 0).
    pub friction_coupling_k_per_mw: f64,
    /// Gap conductance at zero gap over the conductance to the slider body (≥ 0).
    pub gap_cooling: f64,
    /// Summed temperature-jump distance of the gap (nm, > 0).
    pub jump_length_nm: f64,
    /// Read-out bandwidth (kHz, > 0).
    pub bandwidth_khz: f64,
    /// Noise per sample, standard deviation (Ω, ≥ 0).
    pub noise_ohm: f64,
}

/// The acoustic-emission sensor: `AE = √(G² μ F̄_c v + n²)`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HdiAcousticSensorOptions {
    /// Gain `G` (V/√W, ≥ 0).
    pub gain_v_per_sqrt_w: f64,
    /// Noise per quadrature, standard deviation (V, ≥ 0).
    pub noise_v: f64,
    /// Bandwidth of the RMS detector (kHz, > 0).
    pub bandwidth_khz: f64,
}

/// The read-back channel: fundamental and third harmonic of a written pattern, with the
/// Wallace spacing loss.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HdiReadbackOptions {
    /// Wavelength of the fundamental (nm, > 0).
    pub wavelength_nm: f64,
    /// Magnetic spacing beyond the bulge gap (nm, ≥ 0).
    pub magnetic_offset_nm: f64,
    /// Amplitude of the fundamental at zero magnetic spacing (V, > 0).
    pub amplitude_v: f64,
    /// Noise of each amplitude per sample, relative (≥ 0).
    pub noise_relative: f64,
    /// Amplitude of the slow common gain drift, relative (0 to below 1).
    pub gain_drift_relative: f64,
    /// Bandwidth (kHz, > 0).
    pub bandwidth_khz: f64,
}

/// All sensor options.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HdiSensorOptions {
    /// The embedded contact sensor.
    pub contact: HdiContactSensorOptions,
    /// The acoustic-emission sensor.
    pub acoustic: HdiAcousticSensorOptions,
    /// The read-back channel.
    pub readback: HdiReadbackOptions,
}

/// How a drive is built: fill it with [`hdi_drive_config_default`] (the library's defaults) or
/// [`hdi_drive_config_from_scene`] (a scene's `[drive]` section), change what you need, pass it
/// to [`hdi_drive_new`].
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HdiDriveConfig {
    /// Heads, one per disk surface (1 to 32): one spindle and one clock, each head its own
    /// surface and sensor noise, stepped together by [`hdi_drive_step_heads`].
    pub heads: u32,
    /// Radius of the zone (mm, > 0): every head sits there (one actuator).
    pub radius_mm: f64,
    /// Spindle speed (rpm, > 0), or 0 for the scene's disk speed at the radius.
    pub rpm: f64,
    /// Heater power at the start (mW, ≥ 0): the slider starts at rest in its flying
    /// equilibrium there.
    pub initial_heater_power_mw: f64,
    /// Thermal time constant of the heater (µs, ≥ 0), used when the scene has none.
    pub heater_time_constant_us: f64,
    /// The disk surface.
    pub disk: HdiDisk,
    /// Ambient drift.
    pub ambient: HdiAmbient,
    /// The sensors.
    pub sensors: HdiSensorOptions,
    /// Relative tolerance of the slider integration (> 0).
    pub rtol: f64,
    /// Absolute displacement tolerance near contact (pm, > 0).
    pub atol_pm: f64,
    /// Absolute displacement tolerance in flight (pm, ≥ `atol_pm`; equal for one tolerance
    /// throughout, the default).
    pub atol_flight_pm: f64,
    /// Contact-force error the displacement tolerance is sized for (µN, > 0).
    pub contact_force_tolerance_un: f64,
    /// Largest integration step (µs, > 0), or 0 for no limit (the default).
    pub max_step_us: f64,
    /// The bounded mode for firmware in the loop: at most this many Radau5 steps a period (1
    /// to 64), a step at the bound accepted whatever its error, the error estimate returned by
    /// [`hdi_drive_last_period`] as a flag; 0 for adaptive steps (the default).
    pub steps_per_period: u32,
    /// How each period is advanced: [`HDI_SCHEME_INTEGRATOR`] (the default) or
    /// [`HDI_SCHEME_EXPONENTIAL`]; [`HdiPeriod::exponential`] tells which advanced a period.
    pub scheme: u32,
}

/// How the solver advanced a head's last period ([`hdi_drive_last_period`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HdiPeriod {
    /// Steps that ended within the period (0 when one step spans it).
    pub steps: u32,
    /// The largest weighted error estimate of those steps against the tolerances: at most 1
    /// under adaptive control; in the bounded mode, above 1 where a step missed them.
    pub error_estimate: f64,
    /// Whether one exponential step advanced the period ([`HDI_SCHEME_EXPONENTIAL`]); false
    /// under the integrator, and in a period the exponential scheme left to it.
    pub exponential: bool,
}

/// Options of the static analyses.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HdiStaticOptions {
    /// Contact-force threshold `F_th` standing in for the touchdown detector (µN, > 0).
    pub contact_threshold_un: f64,
    /// How far above the touchdown power the take-off search of `hdi_model_hysteresis` starts
    /// on the contact branch (mW, > 0).
    pub takeoff_start_excess_mw: f64,
}

/// Why a static transition happened.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HdiCause {
    /// The contact force crossed the threshold on a stable branch.
    Threshold = 0,
    /// The stable branch ended at a fold (a jump).
    Fold = 1,
}

/// A static touchdown or take-off, and the equilibrium where it happens.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HdiTransition {
    /// Heater power (mW).
    pub power_mw: f64,
    /// Bulge gap (nm).
    pub gap_nm: f64,
    /// Air-bearing displacement of the slider body (nm).
    pub displacement_nm: f64,
    /// Protrusion (nm).
    pub protrusion_nm: f64,
    /// Total stiffness (N/m; positive is stable).
    pub stiffness_n_per_m: f64,
    /// Interface force (µN).
    pub interface_force_un: f64,
    /// Contact force (µN).
    pub contact_force_un: f64,
    /// Threshold crossing or fold.
    pub cause: HdiCause,
}

/// Static touchdown and take-off at the model's DC voltage.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HdiHysteresis {
    /// Touchdown.
    pub touchdown: HdiTransition,
    /// Take-off.
    pub takeoff: HdiTransition,
    /// Touchdown power minus take-off power (mW).
    pub hysteresis_mw: f64,
}

/// The static pull-in voltage at one heater power.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HdiPullIn {
    /// `|V_dc − φ|` at pull-in (V).
    pub voltage_v: f64,
    /// Bulge gap just before the jump (nm).
    pub gap_nm: f64,
    /// Fold of the flying branch or contact threshold.
    pub cause: HdiCause,
}

/// Options of one dynamic cycle.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HdiCycleOptions {
    /// AC amplitude of the head–disk voltage (V, ≥ 0; the scene's by default).
    pub ac_amplitude_v: f64,
    /// 0: the scene's fixed heater programme; any other value: its touchdown-triggered ramp
    /// (an integer, so that any value C may hold is valid).
    pub triggered: i32,
}

/// One dynamic touchdown/take-off cycle.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HdiCycle {
    /// AC amplitude of the cycle (V).
    pub ac_amplitude_v: f64,
    /// Whether touchdown was detected.
    pub touchdown_detected: bool,
    /// Time of touchdown (s; NaN when not detected).
    pub touchdown_time_s: f64,
    /// Programme power at touchdown (mW; NaN when not detected).
    pub touchdown_power_mw: f64,
    /// Whether take-off was detected.
    pub takeoff_detected: bool,
    /// Time of take-off (s; NaN when not detected).
    pub takeoff_time_s: f64,
    /// Programme power at take-off (mW; NaN when not detected).
    pub takeoff_power_mw: f64,
    /// Touchdown power minus take-off power (mW; NaN unless both were detected).
    pub hysteresis_mw: f64,
    /// Time mean of the flash temperature rise over the programme (K).
    pub mean_temperature_rise_k: f64,
    /// Length of the programme (s).
    pub duration_s: f64,
    /// Accepted integration steps.
    pub accepted_steps: u64,
    /// Rejected integration steps.
    pub rejected_steps: u64,
}

// ---------------------------------------------------------------------------------------------
// Versions and errors (these four cannot fail and return their value directly)

/// The library's version, e.g. `"0.1.0"` (a static string).
#[no_mangle]
pub extern "C" fn hdi_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// The ABI version of the library: compare with `HDI_ABI_VERSION` of the header you built
/// against.
#[no_mangle]
pub extern "C" fn hdi_abi_version() -> u32 {
    HDI_ABI_VERSION
}

/// The message of the calling thread's last failed call, or `""` when its last call
/// succeeded. The string belongs to the library and stays valid until the thread's next call.
#[no_mangle]
pub extern "C" fn hdi_last_error() -> *const c_char {
    error::last_error_ptr()
}

/// The name of a status (an `HdiStatus` value), e.g. `"HDI_STATUS_INVALID_INPUT"`, or
/// `"HDI_STATUS_UNKNOWN"` for a value that is none (a static string).
#[no_mangle]
pub extern "C" fn hdi_status_name(status: i32) -> *const c_char {
    // An integer, not the enum: a value from C outside the enum is answered, not undefined.
    const NAMES: [&str; 13] = [
        "HDI_STATUS_OK\0",
        "HDI_STATUS_NULL_POINTER\0",
        "HDI_STATUS_INVALID_HANDLE\0",
        "HDI_STATUS_WRONG_HANDLE_TYPE\0",
        "HDI_STATUS_BUSY\0",
        "HDI_STATUS_INVALID_INPUT\0",
        "HDI_STATUS_SCENE\0",
        "HDI_STATUS_IO\0",
        "HDI_STATUS_NO_CONVERGENCE\0",
        "HDI_STATUS_ANALYSIS\0",
        "HDI_STATUS_INTEGRATION\0",
        "HDI_STATUS_OTHER\0",
        "HDI_STATUS_PANIC\0",
    ];
    let s = usize::try_from(status)
        .ok()
        .and_then(|i| NAMES.get(i))
        .copied()
        .unwrap_or("HDI_STATUS_UNKNOWN\0");
    s.as_ptr().cast()
}

// ---------------------------------------------------------------------------------------------
// Helpers

/// `*out`, checked for `NULL`.
///
/// # Safety
/// `out` is `NULL` or valid for writes.
unsafe fn out_ref<'a, T>(out: *mut T, arg: &str) -> Result<&'a mut T, Failure> {
    // SAFETY: the caller's contract.
    unsafe { out.as_mut() }.ok_or_else(|| Failure::null(arg))
}

/// `*p`, checked for `NULL`.
///
/// # Safety
/// `p` is `NULL` or valid for reads.
unsafe fn in_ref<'a, T>(p: *const T, arg: &str) -> Result<&'a T, Failure> {
    // SAFETY: the caller's contract.
    unsafe { p.as_ref() }.ok_or_else(|| Failure::null(arg))
}

/// A C string argument as UTF-8.
///
/// # Safety
/// `p` is `NULL` or a NUL-terminated string.
unsafe fn text<'a>(p: *const c_char, arg: &str) -> Result<&'a str, Failure> {
    if p.is_null() {
        return Err(Failure::null(arg));
    }
    // SAFETY: the caller's contract.
    unsafe { CStr::from_ptr(p) }
        .to_str()
        .map_err(|e| Failure::invalid(arg, format!("not UTF-8 (at byte {})", e.valid_up_to())))
}

/// Makes a handle and stores it in `*out` (`NULL` first, so a failure leaves `NULL`).
///
/// # Safety
/// `out` is `NULL` or valid for writes.
unsafe fn make<H: Handle>(out: *mut *mut H, f: impl FnOnce() -> Result<H, Failure>) -> HdiStatus {
    call(|| {
        // SAFETY: the caller's contract.
        let out = unsafe { out_ref(out, "out") }?;
        *out = std::ptr::null_mut();
        *out = register(f()?);
        Ok(())
    })
}

fn finite(field: &str, v: f64, unit: &str) -> Result<f64, Failure> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(Failure::invalid(
            field,
            format!("must be finite, got {v} {unit}"),
        ))
    }
}

fn positive(field: &str, v: f64, unit: &str) -> Result<f64, Failure> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(Failure::invalid(
            field,
            format!("must be finite and > 0 {unit}, got {v} {unit}"),
        ))
    }
}

fn non_negative(field: &str, v: f64, unit: &str) -> Result<f64, Failure> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(Failure::invalid(
            field,
            format!("must be finite and ≥ 0 {unit}, got {v} {unit}"),
        ))
    }
}

/// Micrometres, microseconds, ... to the SI unit.
fn micro(x: f64) -> f64 {
    x * 1e-6
}

fn to_micro(x: f64) -> f64 {
    x * 1e6
}

/// Picometres to metres.
fn pm(x: f64) -> f64 {
    x * 1e-12
}

/// µN to N.
fn un(x: f64) -> f64 {
    micro(x)
}

// ---------------------------------------------------------------------------------------------
// Scenes

/// The built-in scene of the letter the crate reproduces (`hdi` calls it `paper`).
///
/// # Safety
/// `out` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_scene_paper(out: *mut *mut HdiScene) -> HdiStatus {
    // SAFETY: the caller's contract.
    unsafe {
        make(out, || {
            Ok(HdiScene {
                header: Header::default(),
                scene: Scene::paper(),
            })
        })
    }
}

fn scene_handle(scene: Result<Scene, hdi_tribology::Error>) -> Result<HdiScene, Failure> {
    Ok(HdiScene {
        header: Header::default(),
        scene: scene?,
    })
}

/// A scene from TOML text (fields may be given in engineering units, as in scene files).
///
/// # Safety
/// `toml` is `NULL` or a NUL-terminated string; `out` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_scene_from_toml(
    toml: *const c_char,
    out: *mut *mut HdiScene,
) -> HdiStatus {
    // SAFETY: the caller's contract.
    unsafe {
        make(out, || {
            scene_handle(Scene::from_toml_str(text(toml, "toml")?))
        })
    }
}

/// A scene from JSON text.
///
/// # Safety
/// `json` is `NULL` or a NUL-terminated string; `out` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_scene_from_json(
    json: *const c_char,
    out: *mut *mut HdiScene,
) -> HdiStatus {
    // SAFETY: the caller's contract.
    unsafe {
        make(out, || {
            scene_handle(Scene::from_json_str(text(json, "json")?))
        })
    }
}

/// A scene from a `.toml` or `.json` file.
///
/// # Safety
/// `path` is `NULL` or a NUL-terminated string; `out` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_scene_from_file(
    path: *const c_char,
    out: *mut *mut HdiScene,
) -> HdiStatus {
    // SAFETY: the caller's contract.
    unsafe { make(out, || scene_handle(Scene::from_path(text(path, "path")?))) }
}

/// Frees a scene (`NULL`: nothing to do). Models and drives made from it stay valid.
///
/// # Safety
/// `scene` is `NULL` or any pointer: one not made by this library is refused, not freed.
#[no_mangle]
pub unsafe extern "C" fn hdi_scene_free(scene: *mut HdiScene) -> HdiStatus {
    call(|| free(scene, "scene"))
}

// ---------------------------------------------------------------------------------------------
// Models and the static analyses

/// The slider model of a scene.
///
/// # Safety
/// `out` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_model_new(
    scene: *const HdiScene,
    out: *mut *mut HdiModel,
) -> HdiStatus {
    // SAFETY: the caller's contract.
    unsafe {
        make(out, || {
            let s = acquire(scene, "scene", Access::Shared)?;
            let scene = &s.get().scene;
            Ok(HdiModel {
                header: Header::default(),
                model: SliderModel::from_scene(scene)?,
                protocol: Protocol::from_scene(scene)?,
            })
        })
    }
}

/// Frees a model (`NULL`: nothing to do).
///
/// # Safety
/// `model` is `NULL` or any pointer: one not made by this library is refused, not freed.
#[no_mangle]
pub unsafe extern "C" fn hdi_model_free(model: *mut HdiModel) -> HdiStatus {
    call(|| free(model, "model"))
}

/// The default static options of a model: its scene's detector threshold, take-off search
/// from 30 mW above touchdown.
///
/// # Safety
/// `out` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_static_options_default(
    model: *const HdiModel,
    out: *mut HdiStaticOptions,
) -> HdiStatus {
    call(|| {
        let m = acquire(model, "model", Access::Shared)?;
        // SAFETY: the caller's contract.
        let out = unsafe { out_ref(out, "out") }?;
        let s = &m.get().protocol.statics;
        *out = HdiStaticOptions {
            contact_threshold_un: to_micro(s.contact_threshold),
            takeoff_start_excess_mw: units::to_mw(s.takeoff_start_excess),
        };
        Ok(())
    })
}

/// The static options in SI: the model's own when `options` is `NULL`.
///
/// # Safety
/// `options` is `NULL` or valid for reads.
unsafe fn static_options(
    m: &HdiModel,
    options: *const HdiStaticOptions,
) -> Result<StaticOptions, Failure> {
    // SAFETY: the caller's contract.
    let Some(o) = (unsafe { options.as_ref() }) else {
        return Ok(m.protocol.statics);
    };
    let mut s = m.protocol.statics;
    // The model's own values exactly when given back unchanged.
    let d = HdiStaticOptions {
        contact_threshold_un: to_micro(s.contact_threshold),
        takeoff_start_excess_mw: units::to_mw(s.takeoff_start_excess),
    };
    if o.contact_threshold_un != d.contact_threshold_un {
        s.contact_threshold = un(positive(
            "options.contact_threshold_un",
            o.contact_threshold_un,
            "µN",
        )?);
    }
    if o.takeoff_start_excess_mw != d.takeoff_start_excess_mw {
        s.takeoff_start_excess = units::mw(positive(
            "options.takeoff_start_excess_mw",
            o.takeoff_start_excess_mw,
            "mW",
        )?);
    }
    Ok(s)
}

fn cause(c: Cause) -> HdiCause {
    match c {
        Cause::Threshold => HdiCause::Threshold,
        Cause::Fold => HdiCause::Fold,
    }
}

fn transition(t: &Transition) -> HdiTransition {
    HdiTransition {
        power_mw: t.power_mw(),
        gap_nm: units::to_nm(t.at.d),
        displacement_nm: units::to_nm(t.at.y),
        protrusion_nm: units::to_nm(t.at.protrusion),
        stiffness_n_per_m: t.at.stiffness,
        interface_force_un: to_micro(t.at.interface_force),
        contact_force_un: to_micro(t.at.contact_force),
        cause: cause(t.cause),
    }
}

/// One static analysis: the model taken, its options in SI, the result written to `out`.
///
/// # Safety
/// `options` is `NULL` or valid for reads; `out` is `NULL` or valid for writes.
unsafe fn static_analysis<T>(
    model: *const HdiModel,
    options: *const HdiStaticOptions,
    out: *mut T,
    f: impl FnOnce(&SliderModel, &StaticOptions) -> Result<T, Failure>,
) -> HdiStatus {
    call(|| {
        let m = acquire(model, "model", Access::Shared)?;
        // SAFETY: the caller's contract.
        let (opts, out) = unsafe { (static_options(m.get(), options)?, out_ref(out, "out")?) };
        *out = f(&m.get().model, &opts)?;
        Ok(())
    })
}

/// Static touchdown at the model's DC voltage. `options`: `NULL` for the model's defaults.
///
/// # Safety
/// `options` is `NULL` or valid for reads; `out` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_model_touchdown(
    model: *const HdiModel,
    options: *const HdiStaticOptions,
    out: *mut HdiTransition,
) -> HdiStatus {
    // SAFETY: the caller's contract.
    unsafe {
        static_analysis(model, options, out, |m, o| {
            Ok(transition(&touchdown_power(m, o)?))
        })
    }
}

/// Static take-off at the model's DC voltage, following the contact branch down from
/// `start_power_mw` (on the contact branch: above touchdown).
///
/// # Safety
/// `options` is `NULL` or valid for reads; `out` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_model_takeoff(
    model: *const HdiModel,
    options: *const HdiStaticOptions,
    start_power_mw: f64,
    out: *mut HdiTransition,
) -> HdiStatus {
    // SAFETY: the caller's contract.
    unsafe {
        static_analysis(model, options, out, |m, o| {
            let start = units::mw(finite("start_power_mw", start_power_mw, "mW")?);
            Ok(transition(&takeoff_power(m, start, o)?))
        })
    }
}

/// Static touchdown and take-off (the take-off search starts `takeoff_start_excess_mw` above
/// touchdown).
///
/// # Safety
/// `options` is `NULL` or valid for reads; `out` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_model_hysteresis(
    model: *const HdiModel,
    options: *const HdiStaticOptions,
    out: *mut HdiHysteresis,
) -> HdiStatus {
    // SAFETY: the caller's contract.
    unsafe {
        static_analysis(model, options, out, |m, o| {
            let h = static_hysteresis(m, o)?;
            Ok(HdiHysteresis {
                touchdown: transition(&h.touchdown),
                takeoff: transition(&h.takeoff),
                hysteresis_mw: h.hysteresis_mw(),
            })
        })
    }
}

/// The static pull-in voltage `|V_dc − φ|` at heater power `heater_power_mw` (0 V when the head
/// is past touchdown there without voltage).
///
/// # Safety
/// `options` is `NULL` or valid for reads; `out` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_model_pull_in(
    model: *const HdiModel,
    options: *const HdiStaticOptions,
    heater_power_mw: f64,
    out: *mut HdiPullIn,
) -> HdiStatus {
    // SAFETY: the caller's contract.
    unsafe {
        static_analysis(model, options, out, |m, o| {
            let p = units::mw(finite("heater_power_mw", heater_power_mw, "mW")?);
            let r = analysis::pull_in_voltage(m, p, o)?;
            Ok(HdiPullIn {
                voltage_v: r.voltage,
                gap_nm: units::to_nm(r.d),
                cause: cause(r.cause),
            })
        })
    }
}

/// The default cycle options of a model: its scene's AC amplitude, the fixed programme.
///
/// # Safety
/// `out` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_cycle_options_default(
    model: *const HdiModel,
    out: *mut HdiCycleOptions,
) -> HdiStatus {
    call(|| {
        let m = acquire(model, "model", Access::Shared)?;
        // SAFETY: the caller's contract.
        let out = unsafe { out_ref(out, "out") }?;
        *out = HdiCycleOptions {
            ac_amplitude_v: m.get().model.voltage().ac_amplitude,
            triggered: 0,
        };
        Ok(())
    })
}

/// One dynamic touchdown/take-off cycle under the scene's heater programme, with the scene's
/// detector and solver settings. `options`: `NULL` for [`hdi_cycle_options_default`].
///
/// # Safety
/// `options` is `NULL` or valid for reads; `out` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_model_cycle(
    model: *const HdiModel,
    options: *const HdiCycleOptions,
    out: *mut HdiCycle,
) -> HdiStatus {
    call(|| {
        let m = acquire(model, "model", Access::Shared)?;
        let m = m.get();
        // SAFETY: the caller's contract.
        let (options, out) = unsafe { (options.as_ref(), out_ref(out, "out")?) };
        let v = m.model.voltage();
        let (ac, triggered) = match options {
            Some(o) => (
                non_negative("options.ac_amplitude_v", o.ac_amplitude_v, "V")?,
                o.triggered != 0,
            ),
            None => (v.ac_amplitude, false),
        };
        let programme = if triggered {
            &m.protocol.triggered
        } else {
            &m.protocol.fixed
        };
        let r = if ac == v.ac_amplitude {
            analysis::simulate_cycle(&m.model, programme, &m.protocol.cycle)?
        } else {
            let with_ac = m.model.with_voltage(Voltage {
                ac_amplitude: ac,
                ..v
            });
            analysis::simulate_cycle(&with_ac, programme, &m.protocol.cycle)?
        };
        let nan = f64::NAN;
        *out = HdiCycle {
            ac_amplitude_v: r.v_ac,
            touchdown_detected: r.touchdown.is_some(),
            touchdown_time_s: r.touchdown.map_or(nan, |d| d.time),
            touchdown_power_mw: r.touchdown.map_or(nan, |d| d.power_mw()),
            takeoff_detected: r.takeoff.is_some(),
            takeoff_time_s: r.takeoff.map_or(nan, |d| d.time),
            takeoff_power_mw: r.takeoff.map_or(nan, |d| d.power_mw()),
            hysteresis_mw: r.hysteresis_mw().unwrap_or(nan),
            mean_temperature_rise_k: r.mean_temperature_rise,
            duration_s: r.duration,
            accepted_steps: r.stats.accepted as u64,
            rejected_steps: r.stats.rejected as u64,
        };
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------------
// Drives

/// The scene's drive: its `[drive]` section (the library's defaults without one), the options
/// it sets and its zone's radius (m) and spindle speed (rpm; `None`: the scene's disk speed).
fn scene_drive(scene: &Scene) -> (DriveSpec, DriveOptions, f64, Option<f64>) {
    let spec = scene.drive.clone().unwrap_or_default();
    let opts = DriveOptions::from_spec(&spec);
    let radius = spec.radius_m.unwrap_or(DEFAULT_RADIUS);
    let rpm = spec.rpm;
    (spec, opts, radius, rpm)
}

/// The library's drive options in the units of [`HdiDriveConfig`]: the run-out is the first
/// harmonic of order 1 and phase 0 (as the scene and the defaults set it), and there are no
/// other fixed harmonics (`harmonics` is `NULL`).
fn config_of(o: &DriveOptions, heads: u32, radius: f64, rpm: Option<f64>) -> HdiDriveConfig {
    let (c, a, r) = (&o.sensors.contact, &o.sensors.acoustic, &o.sensors.readback);
    let runout = o
        .disk
        .harmonics
        .iter()
        .find(|h| h.order == 1 && h.phase == 0.0)
        .map_or(0.0, |h| h.amplitude);
    HdiDriveConfig {
        heads,
        radius_mm: radius * 1e3,
        rpm: rpm.unwrap_or(0.0),
        initial_heater_power_mw: units::to_mw(o.initial_power),
        heater_time_constant_us: to_micro(o.heater_time_constant),
        disk: HdiDisk {
            runout_nm: units::to_nm(runout),
            harmonics: std::ptr::null(),
            harmonic_count: 0,
            random_rms_nm: units::to_nm(o.disk.random_rms),
            random_order_min: o.disk.random_orders.0,
            random_order_max: o.disk.random_orders.1,
        },
        ambient: HdiAmbient {
            rate_k_per_s: o.ambient.rate,
            amplitude_k: o.ambient.amplitude,
            period_s: o.ambient.period,
            clearance_per_kelvin_nm: units::to_nm(o.ambient.clearance_per_kelvin),
            step_k: o.ambient.step,
            step_time_s: o.ambient.step_time,
        },
        sensors: HdiSensorOptions {
            contact: HdiContactSensorOptions {
                resistance_ohm: c.resistance,
                tcr_per_k: c.tcr,
                heater_coupling_k_per_mw: c.heater_coupling * 1e-3,
                friction_coupling_k_per_mw: c.friction_coupling * 1e-3,
                gap_cooling: c.gap_cooling,
                jump_length_nm: units::to_nm(c.jump_length),
                bandwidth_khz: c.bandwidth * 1e-3,
                noise_ohm: c.noise,
            },
            acoustic: HdiAcousticSensorOptions {
                gain_v_per_sqrt_w: a.gain,
                noise_v: a.noise,
                bandwidth_khz: a.bandwidth * 1e-3,
            },
            readback: HdiReadbackOptions {
                wavelength_nm: units::to_nm(r.wavelength),
                magnetic_offset_nm: units::to_nm(r.magnetic_offset),
                amplitude_v: r.amplitude,
                noise_relative: r.noise,
                gain_drift_relative: r.gain_drift,
                bandwidth_khz: r.bandwidth * 1e-3,
            },
        },
        rtol: o.rtol,
        atol_pm: o.atol_displacement * 1e12,
        atol_flight_pm: o.atol_displacement_flight * 1e12,
        contact_force_tolerance_un: to_micro(o.contact_force_tolerance),
        max_step_us: o.max_step.map_or(0.0, to_micro),
        steps_per_period: o.steps_per_period.map_or(0, |n| n as u32),
        scheme: match o.scheme {
            DriveScheme::Integrator => HDI_SCHEME_INTEGRATOR,
            DriveScheme::Exponential => HDI_SCHEME_EXPONENTIAL,
        },
    }
}

/// Most fixed harmonics a disk may list.
const MAX_HARMONICS: usize = 4096;

/// A drive built from a config: the heads, the zone's radius (m) and spindle speed (rpm), and
/// the options of every head.
struct Built {
    heads: usize,
    radius: f64,
    rpm: Option<f64>,
    opts: DriveOptions,
}

/// The library's drive of a config on `scene`, checked field by field in the config's names
/// and units. A value equal to the scene's (as [`hdi_drive_config_from_scene`] gives it; the
/// library's default where the scene's `[drive]` section has none) stands for the scene's value
/// exactly, so the scene's config builds the very drive `hdi drive` builds on the scene, and
/// the default config on a scene without a `[drive]` section the drive of
/// `DriveOptions::default()`.
///
/// # Safety
/// `c.disk.harmonics` is `NULL` or valid for `c.disk.harmonic_count` reads.
unsafe fn drive_options(scene: &Scene, c: &HdiDriveConfig) -> Result<Built, Failure> {
    let (spec, lib, lib_radius, lib_rpm) = scene_drive(scene);
    let d = config_of(&lib, spec.heads, lib_radius, lib_rpm);
    // The scene's value when `v` is the scene config's, else `v` converted by `si`.
    let pick = |v: f64, dv: f64, lib: f64, si: fn(f64) -> f64| if v == dv { lib } else { si(v) };
    let heads = c.heads;
    if !(1..=hdi_tribology::scene::MAX_HEADS).contains(&heads) {
        return Err(Failure::invalid(
            "config.heads",
            format!(
                "must be from 1 to {} heads, got {heads}",
                hdi_tribology::scene::MAX_HEADS
            ),
        ));
    }
    let radius = pick(
        positive("config.radius_mm", c.radius_mm, "mm")?,
        d.radius_mm,
        lib_radius,
        |x| x * 1e-3,
    );
    let rpm = match non_negative("config.rpm", c.rpm, "rpm")? {
        v if v == d.rpm => lib_rpm,
        0.0 => None,
        v => Some(v),
    };
    let harmonics: &[HdiHarmonic] = match c.disk.harmonic_count {
        0 => &[],
        n if n > MAX_HARMONICS => {
            return Err(Failure::invalid(
                "config.disk.harmonic_count",
                format!("at most {MAX_HARMONICS} harmonics, got {n}"),
            ))
        }
        // SAFETY: the caller's contract.
        n => unsafe {
            in_ref(c.disk.harmonics, "config.disk.harmonics")
                .map(|h| std::slice::from_raw_parts(h, n))
        }?,
    };
    let runout = non_negative("config.disk.runout_nm", c.disk.runout_nm, "nm")?;
    let disk = if harmonics.is_empty()
        && runout == d.disk.runout_nm
        && c.disk.random_rms_nm == d.disk.random_rms_nm
        && (c.disk.random_order_min, c.disk.random_order_max)
            == (d.disk.random_order_min, d.disk.random_order_max)
    {
        lib.disk.clone()
    } else {
        let mut h = Vec::with_capacity(harmonics.len() + 1);
        if runout != 0.0 {
            h.push(Harmonic {
                order: 1,
                amplitude: units::nm(runout),
                phase: 0.0,
            });
        }
        for (i, x) in harmonics.iter().enumerate() {
            if x.order == 0 {
                return Err(Failure::invalid(
                    &format!("config.disk.harmonics[{i}].order"),
                    "must be at least 1, got 0",
                ));
            }
            h.push(Harmonic {
                order: x.order,
                amplitude: units::nm(finite(
                    &format!("config.disk.harmonics[{i}].amplitude_nm"),
                    x.amplitude_nm,
                    "nm",
                )?),
                phase: finite(
                    &format!("config.disk.harmonics[{i}].phase_rad"),
                    x.phase_rad,
                    "rad",
                )?,
            });
        }
        DiskSpec {
            harmonics: h,
            random_rms: units::nm(non_negative(
                "config.disk.random_rms_nm",
                c.disk.random_rms_nm,
                "nm",
            )?),
            random_orders: (c.disk.random_order_min, c.disk.random_order_max),
        }
    };
    let (la, da, ca) = (&lib.ambient, &d.ambient, &c.ambient);
    let ambient = Ambient {
        rate: finite("config.ambient.rate_k_per_s", ca.rate_k_per_s, "K/s")?,
        amplitude: finite("config.ambient.amplitude_k", ca.amplitude_k, "K")?,
        period: positive("config.ambient.period_s", ca.period_s, "s")?,
        clearance_per_kelvin: pick(
            finite(
                "config.ambient.clearance_per_kelvin_nm",
                ca.clearance_per_kelvin_nm,
                "nm/K",
            )?,
            da.clearance_per_kelvin_nm,
            la.clearance_per_kelvin,
            units::nm,
        ),
        step: finite("config.ambient.step_k", ca.step_k, "K")?,
        step_time: non_negative("config.ambient.step_time_s", ca.step_time_s, "s")?,
    };
    let (ls, ds, cs) = (&lib.sensors, &d.sensors, &c.sensors);
    let kilo = |x: f64| x * 1e3;
    let mut sensors: SensorSpec = lib.sensors;
    {
        let (l, d, c, s) = (&ls.contact, &ds.contact, &cs.contact, &mut sensors.contact);
        let f = "config.sensors.contact.";
        s.resistance = positive(&format!("{f}resistance_ohm"), c.resistance_ohm, "Ω")?;
        s.tcr = finite(&format!("{f}tcr_per_k"), c.tcr_per_k, "1/K")?;
        s.heater_coupling = pick(
            non_negative(
                &format!("{f}heater_coupling_k_per_mw"),
                c.heater_coupling_k_per_mw,
                "K/mW",
            )?,
            d.heater_coupling_k_per_mw,
            l.heater_coupling,
            kilo,
        );
        s.friction_coupling = pick(
            non_negative(
                &format!("{f}friction_coupling_k_per_mw"),
                c.friction_coupling_k_per_mw,
                "K/mW",
            )?,
            d.friction_coupling_k_per_mw,
            l.friction_coupling,
            kilo,
        );
        s.gap_cooling = non_negative(&format!("{f}gap_cooling"), c.gap_cooling, "")?;
        s.jump_length = pick(
            positive(&format!("{f}jump_length_nm"), c.jump_length_nm, "nm")?,
            d.jump_length_nm,
            l.jump_length,
            units::nm,
        );
        s.bandwidth = pick(
            positive(&format!("{f}bandwidth_khz"), c.bandwidth_khz, "kHz")?,
            d.bandwidth_khz,
            l.bandwidth,
            units::khz,
        );
        s.noise = non_negative(&format!("{f}noise_ohm"), c.noise_ohm, "Ω")?;
    }
    {
        let (l, d, c, s) = (
            &ls.acoustic,
            &ds.acoustic,
            &cs.acoustic,
            &mut sensors.acoustic,
        );
        let f = "config.sensors.acoustic.";
        s.gain = non_negative(
            &format!("{f}gain_v_per_sqrt_w"),
            c.gain_v_per_sqrt_w,
            "V/√W",
        )?;
        s.noise = non_negative(&format!("{f}noise_v"), c.noise_v, "V")?;
        s.bandwidth = pick(
            positive(&format!("{f}bandwidth_khz"), c.bandwidth_khz, "kHz")?,
            d.bandwidth_khz,
            l.bandwidth,
            units::khz,
        );
    }
    {
        let (l, d, c, s) = (
            &ls.readback,
            &ds.readback,
            &cs.readback,
            &mut sensors.readback,
        );
        let f = "config.sensors.readback.";
        s.wavelength = pick(
            positive(&format!("{f}wavelength_nm"), c.wavelength_nm, "nm")?,
            d.wavelength_nm,
            l.wavelength,
            units::nm,
        );
        s.magnetic_offset = pick(
            non_negative(
                &format!("{f}magnetic_offset_nm"),
                c.magnetic_offset_nm,
                "nm",
            )?,
            d.magnetic_offset_nm,
            l.magnetic_offset,
            units::nm,
        );
        s.amplitude = positive(&format!("{f}amplitude_v"), c.amplitude_v, "V")?;
        s.noise = non_negative(&format!("{f}noise_relative"), c.noise_relative, "")?;
        s.gain_drift = non_negative(
            &format!("{f}gain_drift_relative"),
            c.gain_drift_relative,
            "",
        )?;
        if s.gain_drift >= 1.0 {
            return Err(Failure::invalid(
                &format!("{f}gain_drift_relative"),
                format!("must be below 1, got {}", s.gain_drift),
            ));
        }
        s.bandwidth = pick(
            positive(&format!("{f}bandwidth_khz"), c.bandwidth_khz, "kHz")?,
            d.bandwidth_khz,
            l.bandwidth,
            units::khz,
        );
    }
    let max_step = match non_negative("config.max_step_us", c.max_step_us, "µs")? {
        0.0 => None,
        h => Some(micro(h)),
    };
    let opts = DriveOptions {
        initial_power: pick(
            non_negative(
                "config.initial_heater_power_mw",
                c.initial_heater_power_mw,
                "mW",
            )?,
            d.initial_heater_power_mw,
            lib.initial_power,
            units::mw,
        ),
        heater_time_constant: pick(
            non_negative(
                "config.heater_time_constant_us",
                c.heater_time_constant_us,
                "µs",
            )?,
            d.heater_time_constant_us,
            lib.heater_time_constant,
            micro,
        ),
        disk,
        ambient,
        sensors,
        rtol: positive("config.rtol", c.rtol, "")?,
        atol_displacement: pick(
            positive("config.atol_pm", c.atol_pm, "pm")?,
            d.atol_pm,
            lib.atol_displacement,
            pm,
        ),
        atol_displacement_flight: pick(
            positive("config.atol_flight_pm", c.atol_flight_pm, "pm")?,
            d.atol_flight_pm,
            lib.atol_displacement_flight,
            pm,
        ),
        contact_force_tolerance: pick(
            positive(
                "config.contact_force_tolerance_un",
                c.contact_force_tolerance_un,
                "µN",
            )?,
            d.contact_force_tolerance_un,
            lib.contact_force_tolerance,
            un,
        ),
        max_step,
        ..lib
    };
    // The plant checks the range (`config_field` names it as the config does).
    let mut opts = match c.steps_per_period {
        0 => opts,
        n => opts.bounded(n as usize),
    };
    opts.scheme = match c.scheme {
        HDI_SCHEME_INTEGRATOR => DriveScheme::Integrator,
        HDI_SCHEME_EXPONENTIAL => DriveScheme::Exponential,
        other => {
            return Err(Failure::invalid(
                "config.scheme",
                format!(
                    "must be HDI_SCHEME_INTEGRATOR ({HDI_SCHEME_INTEGRATOR}) or \
                     HDI_SCHEME_EXPONENTIAL ({HDI_SCHEME_EXPONENTIAL}), got {other}"
                ),
            ))
        }
    };
    Ok(Built {
        heads: heads as usize,
        radius,
        rpm,
        opts,
    })
}

/// The library's name of a drive option to the config's (`None`: not a drive option, such as a
/// field of the scene, which keeps the scene's name).
fn config_field(field: &str) -> Option<String> {
    let f = match field {
        "radius" => "config.radius_mm",
        "zone rpm" | "rpm" => "config.rpm",
        "heads" => "config.heads",
        "initial_power" => "config.initial_heater_power_mw",
        "heater_time_constant" => "config.heater_time_constant_us",
        "rtol" => "config.rtol",
        "atol_displacement" => "config.atol_pm",
        "atol_displacement_flight" => "config.atol_flight_pm",
        "contact_force_tolerance" => "config.contact_force_tolerance_un",
        "max_step" => "config.max_step_us",
        "steps_per_period" => "config.steps_per_period",
        "disk.random_orders" => "config.disk.random_order_min, config.disk.random_order_max",
        "disk.harmonics" => "config.disk.harmonics[].order",
        other
            if ["disk.", "ambient.", "sensors."]
                .iter()
                .any(|p| other.starts_with(p)) =>
        {
            return Some(format!("config.{other}"))
        }
        _ => return None,
    };
    Some(f.into())
}

/// Fills `out` with the default drive: one head, a 25 mm zone at the scene's disk speed, 60 mW
/// at the start, a 100 µs heater lag, 1 µm once-around run-out and 0.3 nm of random waviness
/// (orders 20–400), no ambient drift, the default sensors and solver.
///
/// # Safety
/// `out` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_drive_config_default(out: *mut HdiDriveConfig) -> HdiStatus {
    call(|| {
        // SAFETY: the caller's contract.
        let out = unsafe { out_ref(out, "out") }?;
        *out = config_of(&DriveOptions::default(), 1, DEFAULT_RADIUS, None);
        Ok(())
    })
}

/// Fills `out` with the drive of `scene`'s `[drive]` section (docs/scene_format.md: heads,
/// radius, rpm, start power, heater lag, run-out, waviness, ambient drift and step, sensor
/// options), the library's defaults where it has none (all of them without the section).
///
/// # Safety
/// `out` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_drive_config_from_scene(
    scene: *const HdiScene,
    out: *mut HdiDriveConfig,
) -> HdiStatus {
    call(|| {
        let s = acquire(scene, "scene", Access::Shared)?;
        // SAFETY: the caller's contract.
        let out = unsafe { out_ref(out, "out") }?;
        let (spec, opts, radius, rpm) = scene_drive(&s.get().scene);
        *out = config_of(&opts, spec.heads, radius, rpm);
        Ok(())
    })
}

/// A drive of `scene` as `config` sets it: `config->heads` heads in the zone at
/// `config->radius_mm`, head `k`'s surface and sensor noise seeded `head_seed(seed, k)` (head 0
/// by `seed` itself: a one-head drive is head 0 of a drive of several); `config`: `NULL` for
/// [`hdi_drive_config_from_scene`] (the scene's `[drive]` section, or the defaults). Every head
/// starts at time 0, at rest in its flying equilibrium at the initial heater power, with no
/// voltage.
///
/// # Safety
/// `config` is `NULL` or valid for reads (and its `disk.harmonics` for `disk.harmonic_count`
/// reads); `out` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_drive_new(
    scene: *const HdiScene,
    config: *const HdiDriveConfig,
    seed: u64,
    out: *mut *mut HdiDrive,
) -> HdiStatus {
    // SAFETY: the caller's contract.
    unsafe {
        make(out, || {
            let s = acquire(scene, "scene", Access::Shared)?;
            let scene = &s.get().scene;
            let b = match config.as_ref() {
                Some(c) => drive_options(scene, c)?,
                None => {
                    let (spec, opts, radius, rpm) = scene_drive(scene);
                    Built {
                        heads: spec.heads as usize,
                        radius,
                        rpm,
                        opts,
                    }
                }
            };
            let zone = zone_at(scene, b.radius, b.rpm).map_err(|e| renamed(e, config_field))?;
            let plant = MultiPlant::uniform(scene, &zone, b.heads, seed, b.opts)
                .map_err(|e| renamed(e, config_field))?;
            Ok(HdiDrive {
                header: Header::default(),
                drive: UnsafeCell::new(plant.drive()?),
                scratch: UnsafeCell::new(vec![Sensors::default(); b.heads]),
                protocol: Protocol::from_scene(scene)?,
            })
        })
    }
}

/// Frees a drive (`NULL`: nothing to do).
///
/// # Safety
/// `drive` is `NULL` or any pointer: one not made by this library is refused, not freed.
#[no_mangle]
pub unsafe extern "C" fn hdi_drive_free(drive: *mut HdiDrive) -> HdiStatus {
    call(|| free(drive, "drive"))
}

/// The library's sensors, field by field: the same units and names.
fn sensors_of(s: &Sensors) -> HdiSensors {
    let t = &s.truth;
    HdiSensors {
        time_s: s.time_s,
        heater_power_mw: s.heater_power_mw,
        contact_resistance_ohm: s.contact_resistance_ohm,
        acoustic_v: s.acoustic_v,
        readback_fundamental_v: s.readback.fundamental_v,
        readback_third_v: s.readback.third_v,
        truth: HdiTruth {
            gap_nm: t.gap_nm,
            pad_gap_nm: t.pad_gap_nm,
            displacement_nm: t.displacement_nm,
            velocity_mm_per_s: t.velocity_mm_per_s,
            protrusion_nm: t.protrusion_nm,
            mean_contact_force_un: t.mean_contact_force_un,
            contact_force_un: t.contact_force_un,
            interface_force_un: t.interface_force_un,
            mean_flash_temperature_k: t.mean_flash_temperature_k,
            friction_power_mw: t.friction_power_mw,
            sensor_temperature_k: t.sensor_temperature_k,
            disk_height_nm: t.disk_height_nm,
            ambient_k: t.ambient_k,
        },
    }
}

/// One C command, checked in the C call's names (`name()` is `command` or `commands[k]`,
/// made only for an error: a step that succeeds formats nothing).
fn command_of(c: &HdiCommand, name: impl Fn() -> String) -> Result<Command, Failure> {
    let valid = |v: f64, at_least_zero: bool| v.is_finite() && (!at_least_zero || v >= 0.0);
    if !(valid(c.heater_power_mw, true)
        && valid(c.dc_voltage_v, false)
        && valid(c.ac_amplitude_v, false)
        && valid(c.ac_frequency_khz, true))
    {
        let name = name();
        non_negative(&format!("{name}.heater_power_mw"), c.heater_power_mw, "mW")?;
        finite(&format!("{name}.dc_voltage_v"), c.dc_voltage_v, "V")?;
        finite(&format!("{name}.ac_amplitude_v"), c.ac_amplitude_v, "V")?;
        non_negative(
            &format!("{name}.ac_frequency_khz"),
            c.ac_frequency_khz,
            "kHz",
        )?;
    }
    Ok(Command {
        heater_power_mw: c.heater_power_mw,
        dc_voltage_v: c.dc_voltage_v,
        ac_amplitude_v: c.ac_amplitude_v,
        ac_frequency_khz: c.ac_frequency_khz,
    })
}

/// Holds `command` for `period_s` seconds (0 < period ≤ 1 s), advances the drive and fills
/// `sensors` with the sensors and the truth at the period's end. A drive of several heads is
/// stepped by [`hdi_drive_step_heads`].
///
/// # Safety
/// `command` is `NULL` or valid for reads; `sensors` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_drive_step(
    drive: *mut HdiDrive,
    command: *const HdiCommand,
    period_s: f64,
    sensors: *mut HdiSensors,
) -> HdiStatus {
    call(|| {
        let d = acquire(drive.cast_const(), "drive", Access::Exclusive)?;
        // SAFETY: the caller's contract.
        let (c, out) = unsafe { (in_ref(command, "command")?, out_ref(sensors, "sensors")?) };
        let cmd = command_of(c, || "command".into())?;
        positive("period_s", period_s, "s")?;
        // SAFETY: the guard holds the handle exclusively: no other reference to the drive.
        let (drive, scratch) = unsafe { (&mut *d.get().drive.get(), &mut *d.get().scratch.get()) };
        if drive.heads() != 1 {
            return Err(Failure::invalid(
                "drive",
                format!(
                    "has {} heads: step them together with hdi_drive_step_heads",
                    drive.heads()
                ),
            ));
        }
        drive
            .step_into(std::slice::from_ref(&cmd), period_s, scratch)
            .map_err(|e| renamed(e, |f| step_field(f, "command")))?;
        *out = sensors_of(&scratch[0]);
        Ok(())
    })
}

/// The library's name of a step argument to the C call's: `dt` is `period_s`, head 0's
/// command `one` (`command` for [`hdi_drive_step`]).
fn step_field(field: &str, one: &str) -> Option<String> {
    if field == "dt" {
        return Some("period_s".into());
    }
    field
        .strip_prefix("commands[0].")
        .filter(|_| one == "command")
        .map(|rest| format!("{one}.{rest}"))
}

/// Holds `commands[k]` on head `k` for `period_s` seconds (0 < period ≤ 1 s), advances every
/// head (one clock) and fills `sensors[k]` with head `k`'s sensors and truth at the period's
/// end. `count` is the number of heads ([`hdi_drive_heads`]), of commands and of sensors. Every
/// command is checked before any head moves; a head whose integration fails leaves the drive
/// refusing further steps (the heads before it had moved on): free it and start again.
///
/// # Safety
/// `commands` is `NULL` or valid for `count` reads; `sensors` is `NULL` or valid for `count`
/// writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_drive_step_heads(
    drive: *mut HdiDrive,
    commands: *const HdiCommand,
    count: usize,
    period_s: f64,
    sensors: *mut HdiSensors,
) -> HdiStatus {
    call(|| {
        let d = acquire(drive.cast_const(), "drive", Access::Exclusive)?;
        // SAFETY: the guard holds the handle exclusively: no other reference to the drive.
        let (drive, scratch) = unsafe { (&mut *d.get().drive.get(), &mut *d.get().scratch.get()) };
        let n = drive.heads();
        if count != n {
            return Err(Failure::invalid(
                "count",
                format!("one command and one sensors struct per head: the drive has {n} heads, got {count}"),
            ));
        }
        // SAFETY: the caller's contract (both checked for `NULL`, `count` elements each).
        let (cs, out) = unsafe {
            (
                std::slice::from_raw_parts(in_ref(commands, "commands")?, n),
                std::slice::from_raw_parts_mut(out_ref(sensors, "sensors")?, n),
            )
        };
        let mut cmds = [Command::default(); hdi_tribology::scene::MAX_HEADS as usize];
        for (k, c) in cs.iter().enumerate() {
            cmds[k] = command_of(c, || format!("commands[{k}]"))?;
        }
        positive("period_s", period_s, "s")?;
        drive
            .step_into(&cmds[..n], period_s, scratch)
            .map_err(|e| renamed(e, |f| step_field(f, "commands")))?;
        for (o, s) in out.iter_mut().zip(scratch.iter()) {
            *o = sensors_of(s);
        }
        Ok(())
    })
}

/// The number of heads of the drive.
///
/// # Safety
/// `heads` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_drive_heads(drive: *mut HdiDrive, heads: *mut u32) -> HdiStatus {
    call(|| {
        let d = acquire(drive.cast_const(), "drive", Access::Exclusive)?;
        // SAFETY: the caller's contract.
        let out = unsafe { out_ref(heads, "heads") }?;
        // SAFETY: held exclusively.
        *out = unsafe { &*d.get().drive.get() }.heads() as u32;
        Ok(())
    })
}

/// The drive's time (s): the end of its last period (one clock for every head).
///
/// # Safety
/// `time_s` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_drive_time(drive: *mut HdiDrive, time_s: *mut f64) -> HdiStatus {
    call(|| {
        let d = acquire(drive.cast_const(), "drive", Access::Exclusive)?;
        // SAFETY: the caller's contract.
        let out = unsafe { out_ref(time_s, "time_s") }?;
        // SAFETY: held exclusively.
        *out = unsafe { &*d.get().drive.get() }.time();
        Ok(())
    })
}

/// How the solver advanced the last period of head `head` (0 to heads − 1): its steps and error
/// estimate, the flag of the bounded mode (`config.steps_per_period`).
///
/// # Safety
/// `out` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_drive_last_period(
    drive: *mut HdiDrive,
    head: u32,
    out: *mut HdiPeriod,
) -> HdiStatus {
    call(|| {
        let d = acquire(drive.cast_const(), "drive", Access::Exclusive)?;
        // SAFETY: the caller's contract.
        let out = unsafe { out_ref(out, "out") }?;
        // SAFETY: held exclusively.
        let drive = unsafe { &*d.get().drive.get() };
        let Some(h) = drive.head(head as usize) else {
            return Err(Failure::invalid(
                "head",
                format!("the drive has heads 0 to {}, got {head}", drive.heads() - 1),
            ));
        };
        let p = h.last_period();
        *out = HdiPeriod {
            steps: p.steps as u32,
            error_estimate: p.error_estimate,
            exponential: p.exponential,
        };
        Ok(())
    })
}

/// The slider model of the drive's zone (with the heater lag the drive uses) as a new model
/// handle, with the scene's analysis protocol: its static touchdown is the one the drive's
/// heater meets. Head 0's, for a drive of several heads (see [`hdi_drive_head_model`]).
///
/// # Safety
/// `out` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_drive_model(
    drive: *mut HdiDrive,
    out: *mut *mut HdiModel,
) -> HdiStatus {
    // SAFETY: the caller's contract.
    unsafe { hdi_drive_head_model(drive, 0, out) }
}

/// [`hdi_drive_model`] of head `head` (0 to heads − 1).
///
/// # Safety
/// `out` is `NULL` or valid for writes.
#[no_mangle]
pub unsafe extern "C" fn hdi_drive_head_model(
    drive: *mut HdiDrive,
    head: u32,
    out: *mut *mut HdiModel,
) -> HdiStatus {
    // SAFETY: the caller's contract.
    unsafe {
        make(out, || {
            let d = acquire(drive.cast_const(), "drive", Access::Exclusive)?;
            // SAFETY: held exclusively.
            let drive = &*d.get().drive.get();
            let Some(h) = drive.head(head as usize) else {
                return Err(Failure::invalid(
                    "head",
                    format!("the drive has heads 0 to {}, got {head}", drive.heads() - 1),
                ));
            };
            Ok(HdiModel {
                header: Header::default(),
                model: h.model().clone(),
                protocol: d.get().protocol.clone(),
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The default config builds exactly the library's default options.
    #[test]
    fn default_config_is_the_library_default() {
        let mut c = std::mem::MaybeUninit::<HdiDriveConfig>::uninit();
        assert_eq!(
            unsafe { hdi_drive_config_default(c.as_mut_ptr()) },
            HdiStatus::Ok
        );
        let c = unsafe { c.assume_init() };
        let b = unsafe { drive_options(&Scene::paper(), &c) }.unwrap();
        assert_eq!(b.radius.to_bits(), 0.025f64.to_bits());
        assert_eq!((b.heads, b.rpm), (1, None));
        assert_eq!(b.opts, DriveOptions::default());
    }

    fn message() -> String {
        unsafe { CStr::from_ptr(hdi_last_error()) }
            .to_string_lossy()
            .into_owned()
    }

    /// A panic inside a call becomes a status with the panic's message; a drive that a panic
    /// left half-stepped is refused from then on, and can still be freed.
    #[test]
    fn a_panic_becomes_a_status_and_retires_the_drive() {
        assert_eq!(call(|| panic!("boom")), HdiStatus::Panic);
        assert!(message().contains("internal error") && message().contains("boom"));
        assert_eq!(call(|| Ok(())), HdiStatus::Ok);
        assert_eq!(message(), "");

        let (mut scene, mut drive) = (std::ptr::null_mut(), std::ptr::null_mut());
        unsafe {
            assert_eq!(hdi_scene_paper(&mut scene), HdiStatus::Ok);
            assert_eq!(
                hdi_drive_new(scene, std::ptr::null(), 1, &mut drive),
                HdiStatus::Ok
            );
            assert_eq!(hdi_scene_free(scene), HdiStatus::Ok);
        }
        let status = call(|| {
            let _held = acquire(drive.cast_const(), "drive", Access::Exclusive)?;
            panic!("inside a step")
        });
        assert_eq!(status, HdiStatus::Panic);
        let cmd = HdiCommand {
            heater_power_mw: 60.0,
            ..HdiCommand::default()
        };
        let mut s = HdiSensors::default();
        assert_eq!(
            unsafe { hdi_drive_step(drive, &cmd, 50e-6, &mut s) },
            HdiStatus::Panic
        );
        assert!(message().contains("free it"), "{}", message());
        assert_eq!(unsafe { hdi_drive_free(drive) }, HdiStatus::Ok);
        assert_eq!(
            unsafe { hdi_drive_step(drive, &cmd, 50e-6, &mut s) },
            HdiStatus::InvalidHandle
        );
    }
}
