//! Detector statistics over noise seeds: false alarms, missed touchdowns and the clearance error
//! a detector leaves.

use super::controller::{run, LevelDetector, Staircase, StaircaseSettings};
use super::plant::Plant;
use crate::analysis::{flying_equilibrium, touchdown_power, ScanGrid, StaticOptions};
use crate::error::{check_positive, Error, Result};
use serde::Serialize;

/// One point of a detector's ROC: its outcome over many seeds at one setting.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RocPoint {
    /// Detector name.
    pub detector: String,
    /// Runs (seeds).
    pub runs: usize,
    /// Runs where the detector fired at a level where the true period-mean contact force was
    /// still below `F_th` and more than one heater step below the static touchdown power: a
    /// touchdown declared while the head clearly flies.
    pub false_alarms: usize,
    /// Runs where it fired on the last level below the static touchdown (within one step), the
    /// true contact force still below `F_th`: the approach heard, one step early.
    pub early: usize,
    /// Runs where the detector did not fire at the first level in true contact (it fired later,
    /// or never up to the maximum power).
    pub missed: usize,
    /// Mean of `P_detected − P_TD,static` over the runs that fired (mW).
    pub mean_error_mw: f64,
    /// Root-mean-square clearance error at the operating power (`P_detected − margin`) against
    /// that at `P_TD,static − margin`, from the static flying branch, over the runs that fired
    /// (nm).
    pub rms_clearance_error_nm: f64,
    /// The static touchdown power the errors are taken against (mW).
    pub static_touchdown_mw: f64,
}

impl RocPoint {
    /// False-alarm rate.
    pub fn false_alarm_rate(&self) -> f64 {
        self.false_alarms as f64 / self.runs.max(1) as f64
    }

    /// Rate of one-step-early detections.
    pub fn early_rate(&self) -> f64 {
        self.early as f64 / self.runs.max(1) as f64
    }

    /// Missed-touchdown rate.
    pub fn missed_rate(&self) -> f64 {
        self.missed as f64 / self.runs.max(1) as f64
    }
}

/// Runs the staircase `settings` (take-off search off) on `plant` with seeds `seeds`, a fresh
/// detector from `detector` per run, judging each against the truth with contact threshold
/// `threshold_un` (µN).
///
/// # Errors
/// Invalid settings or threshold (named field); no static touchdown; drive failures.
pub fn touchdown_roc<D: LevelDetector>(
    plant: &Plant,
    settings: StaircaseSettings,
    threshold_un: f64,
    seeds: std::ops::Range<u64>,
    detector: impl Fn() -> Result<D>,
) -> Result<RocPoint> {
    check_positive("threshold_un", threshold_un)?;
    if seeds.is_empty() {
        return Err(Error::invalid("seeds", "needs at least one seed"));
    }
    let mut st = settings;
    st.find_takeoff = false;
    let dt = 50e-6;
    let model = plant.model();
    let threshold = threshold_un * 1e-6;
    let p_td = touchdown_power(model, &StaticOptions::new(threshold))?.power;
    let grid = ScanGrid::default();
    let dc2 = model.voltage().dc_squared();
    let clearance = |p: f64| flying_equilibrium(model, p.max(0.0), dc2, &grid).map(|e| e.d);
    let (margin, step) = (st.margin_mw * 1e-3, st.step_mw * 1e-3);
    let d_ref = clearance(p_td - margin)?;
    let (mut runs, mut fa, mut early, mut missed, mut fired) = (0, 0, 0, 0, 0);
    let (mut err_sum, mut cl_sum2) = (0.0, 0.0);
    let mut name = String::new();
    let levels = ((st.max_power_mw - st.start_power_mw) / st.step_mw).ceil() as usize + 2;
    let periods = levels * ((st.settle_time_s + st.measure_time_s) / dt).ceil() as usize + 10;
    for seed in seeds {
        let p = plant.with_seed(seed)?;
        let mut drive = p.drive()?;
        let mut sc = Staircase::new(st, detector()?, dt)?;
        name = sc.outcome().detector.clone();
        run(&mut drive, &mut sc, dt, periods)?;
        let out = sc.outcome();
        runs += 1;
        let first_true = out
            .levels
            .iter()
            .position(|l| l.true_contact_force_un.mean >= threshold_un);
        match out.levels.iter().position(|l| l.contact) {
            Some(i) => {
                fired += 1;
                let p_det = out.levels[i].heater_power_mw * 1e-3;
                if out.levels[i].true_contact_force_un.mean < threshold_un {
                    if p_det < p_td - step * (1.0 + 1e-9) {
                        fa += 1;
                    } else {
                        early += 1;
                    }
                } else if first_true != Some(i) {
                    missed += 1;
                }
                err_sum += (p_det - p_td) * 1e3;
                cl_sum2 += ((clearance(p_det - margin)? - d_ref) * 1e9).powi(2);
            }
            None => missed += 1,
        }
    }
    let f = fired.max(1) as f64;
    Ok(RocPoint {
        detector: name,
        runs,
        false_alarms: fa,
        early,
        missed,
        mean_error_mw: if fired > 0 { err_sum / f } else { f64::NAN },
        rms_clearance_error_nm: if fired > 0 {
            (cl_sum2 / f).sqrt()
        } else {
            f64::NAN
        },
        static_touchdown_mw: p_td * 1e3,
    })
}
