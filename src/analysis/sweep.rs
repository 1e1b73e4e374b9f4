//! Hysteresis against AC amplitude (paper Fig. 3d): one cycle per amplitude, in parallel.
//!
//! Each cycle is independent and deterministic, and results are returned in the order of the
//! amplitudes, so the sweep gives the same numbers whatever the thread count.

use super::cycle::{simulate_cycle, CycleOptions, CycleResult, HeaterProgramme};
use crate::error::{check_finite, Result};
use crate::model::{SliderModel, Voltage};

/// Runs `programme` once per AC amplitude (V), at the model's frequency and DC voltage.
///
/// With the `parallel` feature the cycles run on rayon's thread pool.
///
/// ```no_run
/// use hdi_tribology::analysis::{ac_sweep, CycleOptions, HeaterProgramme};
/// use hdi_tribology::{model::SliderModel, scene::Scene};
/// let scene = Scene::paper();
/// let model = SliderModel::from_scene(&scene)?;
/// let programme = HeaterProgramme::Fixed(SliderModel::programme_from_knots(&scene.heater.programme)?);
/// let opts = CycleOptions::from_scene(&scene)?;
/// for r in ac_sweep(&model, &programme, &opts, &[0.0, 0.5, 1.0])? {
///     println!("{} V: {:?}", r.v_ac, r.hysteresis);
/// }
/// # Ok::<(), hdi_tribology::Error>(())
/// ```
pub fn ac_sweep(
    model: &SliderModel,
    programme: &HeaterProgramme,
    opts: &CycleOptions,
    amplitudes: &[f64],
) -> Result<Vec<CycleResult>> {
    for (i, &a) in amplitudes.iter().enumerate() {
        check_finite(&format!("amplitudes[{i}]"), a)?;
    }
    let one = |&v_ac: &f64| {
        let m = model.with_voltage(Voltage {
            ac_amplitude: v_ac,
            ..model.voltage
        });
        simulate_cycle(&m, programme, opts)
    };
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        amplitudes.par_iter().map(one).collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        amplitudes.iter().map(one).collect()
    }
}
