//! The paper scene's fixed-programme cycle at the accuracy of an independent reference: ΔP within
//! 1e-8 mW (1e-11 W) of a Tsit5 run at rtol 1e-11 (checked against Radau5 at the same rtol), at
//! 0 V and at 0.6 V AC. Prints, per method and tolerance, the error of ΔP and P_TD, the steps,
//! and the mean CPU time of the thread per cycle (Linux `schedstat`: not inflated by other
//! processes waiting for the cores) over at least 1 s of repetitions.
//!
//! `cargo bench --bench cycle_reference`; `-- --quick` times each row for 0.3 s.

#[path = "../examples/common/slider_reference.rs"]
mod slider_reference;
#[path = "../examples/common/timing.rs"]
mod timing;

use slider_reference::{SLIDER_ATOL_PER_RTOL as ATOL_PER_RTOL, SLIDER_REF_RTOL as REF_RTOL};

use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, CycleResult, HeaterProgramme};
use hdi_tribology::model::{SliderModel, Voltage};
use hdi_tribology::ode::Method;
use hdi_tribology::scene::Scene;
use std::time::Duration;

/// The accuracy asked for: ΔP within 1e-8 mW.
const TARGET_W: f64 = 1e-11;

/// The paper scene's model (tables built once), fixed programme and cycle options.
struct Setup {
    model: SliderModel,
    programme: HeaterProgramme,
    opts: CycleOptions,
}

impl Setup {
    fn new(scene: &Scene) -> hdi_tribology::Result<Self> {
        Ok(Setup {
            model: SliderModel::from_scene(scene)?,
            programme: HeaterProgramme::fixed_from_scene(scene)?,
            opts: CycleOptions::from_scene(scene)?,
        })
    }

    /// The paper scene at `v_ac` as a model (its tables shared, not rebuilt).
    fn at(&self, v_ac: f64) -> SliderModel {
        self.model.with_voltage(Voltage {
            ac_amplitude: v_ac,
            ..self.model.voltage()
        })
    }

    fn cycle(
        &self,
        model: &SliderModel,
        method: Method,
        rtol: f64,
    ) -> hdi_tribology::Result<CycleResult> {
        let mut opts = self.opts;
        opts.solver.method = method;
        opts.solver.rtol = rtol;
        opts.solver.atol_displacement = rtol * ATOL_PER_RTOL;
        simulate_cycle(model, &self.programme, &opts)
    }
}

fn outputs(r: &CycleResult) -> Option<(f64, f64)> {
    Some((r.hysteresis?, r.touchdown?.power))
}

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let budget = Duration::from_millis(if quick { 300 } else { 1000 });
    let setup = match Setup::new(&Scene::paper()) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("the paper scene: {e}");
            return;
        }
    };
    let rows: [(Method, f64); 7] = [
        (Method::Auto, 1e-9),
        (Method::Dop853, 1e-8),
        (Method::Dop853, 3e-9),
        (Method::Dop853, 1e-9),
        (Method::Tsit5, 1e-9),
        (Method::Radau5, 1e-9),
        (Method::Rodas5P, 1e-9),
    ];
    println!("| V_ac (V) | method | rtol | error ΔP (W) | error P_TD (W) | within 1e-11 W | steps | rhs evals | CPU ms |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for v_ac in [0.0, 0.6] {
        let model = setup.at(v_ac);
        let reference = setup
            .cycle(&model, Method::Tsit5, REF_RTOL)
            .map(|r| outputs(&r));
        let check = setup
            .cycle(&model, Method::Radau5, REF_RTOL)
            .map(|r| outputs(&r));
        let ((dp_ref, ptd_ref), (dp_chk, _)) = match (reference, check) {
            (Ok(Some(a)), Ok(Some(b))) => (a, b),
            other => {
                eprintln!("{v_ac} V: no reference cycle: {other:?}");
                continue;
            }
        };
        eprintln!(
            "# {v_ac} V: reference ΔP {dp_ref:.12e} W; Radau5 at rtol {REF_RTOL:e} differs by {:.1e} W",
            (dp_chk - dp_ref).abs()
        );
        for (method, rtol) in rows {
            let (res, t) = timing::measure(3, 10_000, budget, || setup.cycle(&model, method, rtol));
            match res {
                Ok(r) => match outputs(&r) {
                    Some((dp, ptd)) => {
                        let e = (dp - dp_ref).abs();
                        println!(
                            "| {v_ac:.1} | {method:?} | {rtol:.0e} | {e:.1e} | {:.1e} | {} | {} | {} | {:.2} |",
                            (ptd - ptd_ref).abs(),
                            if e <= TARGET_W { "yes" } else { "no" },
                            r.stats.accepted,
                            r.stats.rhs_evals,
                            t.cpu * 1e3
                        );
                    }
                    None => {
                        println!("| {v_ac:.1} | {method:?} | {rtol:.0e} | no take-off | | no | | |")
                    }
                },
                Err(e) => {
                    println!("| {v_ac:.1} | {method:?} | {rtol:.0e} | failed: {e} | | no | | |")
                }
            }
        }
    }
}
