//! What a drive does at clearance calibration, on the simulated head–disk interface.
//!
//! In each zone (radius and disk speed) the heater steps up in small increments until a touchdown
//! detector fires, then back down until it stops firing (take-off); the operating power is the
//! touchdown power minus a margin, and the clearance there comes from the static model. This is
//! done without dither and with a 10.5 kHz AC dither on the head–disk voltage, with three
//! detectors, and compared with the static touchdown of the model.
//!
//! The crate has no air-bearing solver: the clearance and stiffness of each zone below are
//! illustrative inputs (what an air-bearing simulation of the slider would supply).
//!
//! Run with `cargo run --release --example firmware_clearance`.

use hdi_tribology::analysis::{
    flying_equilibrium, static_hysteresis, touchdown_power, ScanGrid, StaticOptions,
};
use hdi_tribology::calibration::{
    calibrate, Calibration, CalibrationOptions, ContactForceRms, MeanContactForce, Relative,
    TouchdownDetector, VibrationRms, Zone,
};
use hdi_tribology::model::{SliderModel, Voltage};
use hdi_tribology::scene::Scene;
use hdi_tribology::units::{mw, to_mw};
use std::time::Instant;

#[path = "common/doc_numbers.rs"]
#[allow(dead_code)]
pub mod doc_numbers;

type Res<T> = Result<T, Box<dyn std::error::Error>>;

const STEP_MW: f64 = 0.5; // heater increment: 0.05 nm of protrusion at 0.1 nm/mW
const MARGIN_MW: f64 = 15.0; // back-off: 1.5 nm of clearance at 0.1 nm/mW
const DITHER_V: f64 = 0.5; // AC dither amplitude (V)
const DITHER_HZ: f64 = 10.5e3; // dither frequency (Hz): the force acts at 21 kHz

fn main() -> Res<()> {
    run().map(|_| ())
}

/// One calibration of a zone: the zone, the detector's short name (`mean`, `ae`, `ae_slow`,
/// `vibration`), whether the dither was on, and the result (`None`: no contact seen).
pub struct Row {
    /// The zone's name.
    pub zone: String,
    /// The detector's short name.
    pub detector: &'static str,
    /// With the AC dither.
    pub dither: bool,
    /// The calibration, `None` when the detector saw no contact.
    pub calibration: Option<Calibration>,
}

/// A zone's static model: touchdown, take-off, the clearance at touchdown − margin and the
/// touchdown at the dither's peak `V²` (W, W, m, W).
pub struct ZoneStatics {
    /// The zone's name.
    pub zone: String,
    /// Static touchdown, take-off (W).
    pub touchdown: f64,
    /// Static take-off (W).
    pub takeoff: f64,
    /// Clearance at the static touchdown minus the margin (m).
    pub clearance: f64,
    /// Static touchdown at the dither's peak `V²` (W).
    pub touchdown_peak: f64,
}

/// Runs every zone with every detector, printing the tables; returns the statics and the rows.
pub fn run() -> Res<(Vec<ZoneStatics>, Vec<Row>)> {
    let clock = Instant::now();
    let mut statics = Vec::new();
    let mut rows = Vec::new();
    let base = Scene::paper();
    let zones = [
        Zone::at_rpm("ID", 0.018, 5400.0, 10e-9, 3.0e5),
        Zone::at_rpm("MD", 0.030, 5400.0, 11e-9, 3.6e5),
        Zone::at_rpm("OD", 0.045, 5400.0, 12e-9, 4.2e5),
    ];
    println!(
        "step {:.2} mW, margin {:.1} mW, dither {DITHER_V} V at {:.1} kHz",
        STEP_MW,
        MARGIN_MW,
        DITHER_HZ * 1e-3
    );
    for zone in &zones {
        let scene = zone.scene(&base)?;
        let model = SliderModel::from_scene(&scene)?;
        let th = scene.detector.contact_threshold_n;
        let stat = static_hysteresis(&model, &StaticOptions::new(th))?;
        let dithered = model.with_voltage(Voltage {
            ac_amplitude: DITHER_V,
            frequency: DITHER_HZ,
            ..model.voltage()
        });
        // Quasi-static estimate with dither: touchdown at the pull-in of the peak V².
        let peak = model.with_voltage(Voltage {
            dc: model.voltage().dc + DITHER_V,
            ..model.voltage()
        });
        let td_peak = touchdown_power(&peak, &StaticOptions::new(th))?;
        // What the static model says the margin leaves (dither off, as in operation).
        let dc2 = model.voltage().effective_dc().powi(2);
        let set = stat.touchdown.power - mw(MARGIN_MW);
        let target = flying_equilibrium(&model, set, dc2, &ScanGrid::default())?.d;
        println!(
            "\n## zone {} (r = {:.0} mm, v = {:.1} m/s, h0 = {:.1} nm, k = {:.2e} N/m)",
            zone.name,
            zone.radius * 1e3,
            zone.disk_speed,
            zone.nominal_clearance * 1e9,
            zone.bearing_stiffness
        );
        println!(
            "static model: touchdown {:.2} mW ({:?}), take-off {:.2} mW, hysteresis {:.2} mW; \
             touchdown at peak V² of the dither {:.2} mW",
            stat.touchdown.power * 1e3,
            stat.touchdown.cause,
            stat.takeoff.power * 1e3,
            stat.hysteresis * 1e3,
            td_peak.power * 1e3
        );
        println!(
            "static model at touchdown − margin = {:.2} mW: clearance {:.3} nm",
            set * 1e3,
            target * 1e9
        );
        statics.push(ZoneStatics {
            zone: zone.name.clone(),
            touchdown: stat.touchdown.power,
            takeoff: stat.takeoff.power,
            clearance: target,
            touchdown_peak: td_peak.power,
        });
        // The search starts where the nominal clearance minus the protrusion would leave 5 nm,
        // a power the drive knows from its characterisation, not from the model.
        let start_mw = to_mw((zone.nominal_clearance - 5e-9) / scene.heater.efficiency_m_per_w);
        let opts = CalibrationOptions::from_mw(start_mw, STEP_MW, start_mw + 60.0, MARGIN_MW);
        println!(
            "{:<46} {:>9} {:>9} {:>9} {:>8} {:>9} {:>9} {:>9} {:>6}",
            "detector",
            "dither",
            "TD mW",
            "TO mW",
            "ΔP mW",
            "contrast",
            "set mW",
            "clear nm",
            "wall s"
        );
        // Settling 0.5 ms instead of 0.2 ms before judging a level: only a steady contact signal
        // is still there.
        let mut slow = opts;
        slow.staircase.settle_time = 5e-4;
        let mut run = |m: &SliderModel,
                       label: &str,
                       detector: &'static str,
                       det: &mut dyn TouchdownDetector,
                       opts: &CalibrationOptions|
         -> Res<()> {
            let c = Instant::now();
            let calibration = match calibrate(m, det, opts) {
                Ok(cal) => {
                    print_row(&cal, label, c.elapsed().as_secs_f64());
                    Some(cal)
                }
                Err(e) => {
                    println!("{:<46} {:>9}  no result: {e}", det.name(), label);
                    None
                }
            };
            rows.push(Row {
                zone: zone.name.clone(),
                detector,
                dither: label.starts_with("on"),
                calibration,
            });
            Ok(())
        };
        let window = scene.detector.window_s;
        let ae = || ContactForceRms::new(1e-5, 5e3, 5e-5);
        for (m, dither) in [(&model, "off"), (&dithered, "on")] {
            run(
                m,
                dither,
                "mean",
                &mut MeanContactForce::new(th, window)?,
                &opts,
            )?;
            run(m, dither, "ae", &mut ae()?, &opts)?;
            run(m, &format!("{dither}, slow"), "ae_slow", &mut ae()?, &slow)?;
            run(m, dither, "vibration", &mut vibration()?, &opts)?;
        }
    }
    println!("\ntotal wall time {:.2} s", clock.elapsed().as_secs_f64());
    Ok((statics, rows))
}

// Used by this example's test and by examples/docs_numbers.rs, which includes this file.
#[allow(dead_code)]
/// The numbers of this run that docs/clearance.md quotes, keyed
/// `clearance.<zone>.<detector>.<on|off>.<td_mw|to_mw|dp_mw|clearance_nm>` and
/// `clearance.<zone>.static.<td_mw|to_mw|clearance_nm|td_peak_mw>` (zones `id`, `md`, `od`).
pub fn doc_numbers(statics: &[ZoneStatics], rows: &[Row]) -> Vec<doc_numbers::Quoted> {
    use doc_numbers::Quoted;
    let mut q = Vec::new();
    for s in statics {
        let at = format!("clearance.{}.static", s.zone.to_lowercase());
        q.extend([
            Quoted::new(&format!("{at}.td_mw"), s.touchdown * 1e3),
            Quoted::new(&format!("{at}.to_mw"), s.takeoff * 1e3),
            Quoted::new(&format!("{at}.clearance_nm"), s.clearance * 1e9),
            Quoted::new(&format!("{at}.td_peak_mw"), s.touchdown_peak * 1e3),
        ]);
    }
    for r in rows {
        let Some(c) = &r.calibration else { continue };
        let at = format!(
            "clearance.{}.{}.{}",
            r.zone.to_lowercase(),
            r.detector,
            if r.dither { "on" } else { "off" }
        );
        q.push(Quoted::new(&format!("{at}.td_mw"), c.touchdown_power * 1e3));
        q.push(Quoted::new(
            &format!("{at}.clearance_nm"),
            c.clearance * 1e9,
        ));
        if let Some(to) = c.takeoff_power {
            q.push(Quoted::new(&format!("{at}.to_mw"), to * 1e3));
        }
        if let Some(h) = c.hysteresis() {
            q.push(Quoted::new(&format!("{at}.dp_mw"), h * 1e3));
        }
    }
    q
}

/// High-pass displacement RMS above 0.02 nm and above 3 times its level at the start power
/// (baseline over 100–300 µs, the first level of the staircase): the dither's modulation is not
/// small.
fn vibration() -> hdi_tribology::Result<Relative<VibrationRms>> {
    Relative::new(VibrationRms::new(2e-11, 5e3, 5e-5)?, 3.0, 1e-4, 2e-4)
}

fn print_row(c: &Calibration, dither: &str, wall: f64) {
    let opt = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{:.2}", v * 1e3));
    println!(
        "{:<46} {:>9} {:>9.2} {:>9} {:>8} {:>9.2e} {:>9.2} {:>9.3} {:>6.2}",
        c.detector,
        dither,
        c.touchdown_power * 1e3,
        opt(c.takeoff_power),
        opt(c.hysteresis()),
        c.contrast,
        c.set_power * 1e3,
        c.clearance * 1e9,
        wall
    );
}

#[cfg(test)]
mod tests {
    /// `cargo test` runs the example, so CI runs every example.
    #[test]
    fn example_runs() {
        let (statics, rows) = super::run().expect("the example runs to completion");
        // The numbers docs/clearance.md quotes from this run are the run's.
        let root = super::doc_numbers::repository_root();
        let numbers = super::doc_numbers(&statics, &rows);
        assert!(super::doc_numbers::assert_quoted(&root, &numbers) > 0);
    }
}
