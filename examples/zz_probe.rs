use hdi_tribology::analysis::{ac_sweep_refined, sweep::Refinement, CycleOptions, HeaterProgramme};
use hdi_tribology::model::SliderModel;
use hdi_tribology::scene::Scene;
fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().unwrap())
        .collect();
    let mut scene = Scene::paper();
    if args.len() >= 3 {
        scene.surface.height_sigma_m = args[0] * 1e-9;
        if let hdi_tribology::surface::PeakModel::RiceMaxima { sigma_m, .. } =
            &mut scene.surface.peaks
        {
            *sigma_m = args[0] * 1e-9;
        }
        scene.intermolecular.as_mut().unwrap().hamaker_attractive_j = args[1];
        scene.heater.efficiency_m_per_w = args[2] * 1e-6;
    }
    let ptol = args.get(3).copied().unwrap_or(1e-6);
    let m = SliderModel::from_scene(&scene).unwrap();
    let prog =
        HeaterProgramme::Fixed(SliderModel::programme_from_knots(&scene.heater.programme).unwrap());
    let opts = CycleOptions::from_scene(&scene).unwrap();
    let mut r = Refinement::new(ptol);
    r.max_runs = 5;
    let t = std::time::Instant::now();
    for c in ac_sweep_refined(&m, &prog, &opts, &[0.0, 0.2, 0.4, 0.6, 0.8, 1.0], &r).unwrap() {
        println!(
            "vac {:.1} td {:?} to {:?} conv {} change {:.3e} rtol {:e} runs {} wall {:.3}",
            c.cycle.v_ac,
            c.cycle.touchdown.map(|d| d.power * 1e3),
            c.cycle.takeoff.map(|d| d.power * 1e3),
            c.converged,
            c.change * 1e3,
            c.rtol,
            c.runs,
            c.wall_seconds
        );
    }
    println!("total {:.2}", t.elapsed().as_secs_f64());
}
