//! A user-defined interface term: a lubricant meniscus force, added to the paper scene's terms.
//!
//! Model (an illustration, not a validated lubricant model): where the local gap under the
//! paraboloidal bulge is below the meniscus height `h_m` (about the lubricant thickness on both
//! surfaces), capillary bridges pull with the Laplace pressure `2γ/h_m` on a fraction `φ` of that
//! area. On a paraboloid of radius `Rc` the area is `2π Rc (h_m − d)`, so
//! `F(d) = −φ (2γ/h_m) 2π Rc (h_m − d)`, which at `d = 0` is `φ` times the classic meniscus force
//! `4π Rc γ` of a wetted sphere. The edge at `d = h_m` is smoothed over `s` (softplus) so the
//! force and its slope are continuous.
//!
//! The term joins the scene's own terms in `InterfaceForces::build`, and
//! `SliderModel::from_scene_with_forces` makes a model of them, on which every analysis runs: here
//! the static touchdown and take-off and one dynamic cycle, with and without the meniscus.
//!
//! Run with `cargo run --release --example custom_term`.

use hdi_tribology::analysis::{simulate_cycle, static_hysteresis, CycleOptions, StaticOptions};
use hdi_tribology::force::{
    Coupling, GapReference, Gaps, InterfaceForces, InterfaceTerm, TermKind,
};
use hdi_tribology::model::SliderModel;
use hdi_tribology::quadrature::TableOptions;
use hdi_tribology::scene::Scene;
use std::f64::consts::PI;

/// Capillary bridges of a thin lubricant film under a paraboloidal bulge.
#[derive(Debug, Clone)]
struct Meniscus {
    surface_tension: f64, // γ (N/m)
    height: f64,          // h_m (m)
    smoothing: f64,       // s (m)
    radius: f64,          // Rc (m)
    fill: f64,            // φ
}

impl InterfaceTerm for Meniscus {
    fn name(&self) -> &str {
        "lubricant meniscus"
    }
    fn kind(&self) -> TermKind {
        TermKind::Other
    }
    fn coupling(&self) -> Coupling {
        Coupling::Static
    }
    fn gap(&self) -> GapReference {
        GapReference::Bulge
    }
    fn force(&self, d: f64) -> hdi_tribology::Result<(f64, f64)> {
        let scale = self.fill * 2.0 * self.surface_tension / self.height * 2.0 * PI * self.radius;
        let x = (self.height - d) / self.smoothing;
        // softplus(x) = ln(1 + eˣ), written to stay finite for large |x|; its slope is the logistic.
        let softplus = x.max(0.0) + (-x.abs()).exp().ln_1p();
        let logistic = 1.0 / (1.0 + (-x).exp());
        Ok((-scale * self.smoothing * softplus, scale * logistic))
    }
}

fn main() -> hdi_tribology::Result<()> {
    let scene = Scene::paper();
    let meniscus = Meniscus {
        surface_tension: 0.02,
        height: 2e-9,
        smoothing: 0.1e-9,
        radius: 0.02,
        fill: 0.05,
    };

    let base = scene.build_interface()?;
    let mut terms = scene.interface_terms()?;
    terms.push(Box::new(meniscus.clone()));
    let opts = TableOptions {
        rel_tol: scene.table.rel_tol,
        ..TableOptions::default()
    };
    let with = InterfaceForces::build(terms, scene.table_range(), &opts)?;

    println!(
        "{:>7} {:>14} {:>14} {:>14}",
        "d (nm)", "paper (µN)", "meniscus (µN)", "sum (µN)"
    );
    for d_nm in [3.0, 2.0, 1.5, 1.0, 0.5, 0.0] {
        let g = Gaps::same(d_nm * 1e-9);
        let (m, _) = meniscus.force(g.bulge)?;
        let (a, b) = (base.static_part(g).value, with.static_part(g).value);
        println!(
            "{d_nm:>7.2} {:>14.3} {:>14.3} {:>14.3}",
            a * 1e6,
            m * 1e6,
            b * 1e6
        );
        // The table of the sum must reproduce the direct sum (tables are built to 1e-9 relative).
        assert!((b - (a + m)).abs() <= 1e-7 * (a.abs() + m.abs()));
    }

    let programme = hdi_tribology::analysis::HeaterProgramme::fixed_from_scene(&scene)?;
    let cycle_opts = CycleOptions::from_scene(&scene)?;
    let static_opts = StaticOptions::new(scene.detector.contact_threshold_n);
    println!(
        "\n{:<14} {:>10} {:>10} {:>10} {:>12}",
        "", "TD mW", "TO mW", "ΔP mW", "cycle ΔP mW"
    );
    let plain = SliderModel::from_scene(&scene)?;
    let wet = SliderModel::from_scene_with_forces(&scene, with)?;
    for (label, model) in [("paper scene", &plain), ("with meniscus", &wet)] {
        let s = static_hysteresis(model, &static_opts)?;
        let c = simulate_cycle(model, &programme, &cycle_opts)?;
        let dp = c
            .hysteresis
            .map_or("-".into(), |h| format!("{:.3}", h * 1e3));
        println!(
            "{label:<14} {:>10.3} {:>10.3} {:>10.3} {dp:>12}",
            s.touchdown.power * 1e3,
            s.takeoff.power * 1e3,
            s.hysteresis * 1e3
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    /// `cargo test` runs the example, so CI runs every example.
    #[test]
    fn example_runs() {
        super::main().expect("the example runs to completion");
    }
}
