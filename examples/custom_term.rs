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
//! `SliderModel` is built only from a `Scene` (its force tables are private), so the term cannot
//! yet be put into the dynamic model; the example builds the tables with `InterfaceForces::build`
//! and finds the folds of the static S-curve (linear air bearing) directly from them.
//!
//! Run with `cargo run --release --example custom_term`.

use hdi_tribology::analysis::{touchdown_power, StaticOptions};
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

/// Folds of the S-curve of a linear air bearing `k`: scanning `d` down, where `k − F'(d)` changes
/// sign. Returns (d, P) with `P = (h0 − d + F(d)/k)/η`.
fn folds(f: &InterfaceForces, k: f64, h0: f64, eta: f64, lo: f64, hi: f64) -> Vec<(f64, f64)> {
    let n = ((hi - lo) / 1e-12) as usize;
    // Every term of the paper scene sees the bulge gap, so the pad gap does not matter.
    let eval = |d: f64| f.static_part(Gaps::same(d));
    let mut out = Vec::new();
    let mut prev = k - eval(hi).d_bulge;
    for i in 1..=n {
        let d = hi - i as f64 * (hi - lo) / n as f64;
        let e = eval(d);
        let stiff = k - e.d_bulge;
        if (stiff > 0.0) != (prev > 0.0) {
            out.push((d, (h0 - d + e.value / k) / eta));
        }
        prev = stiff;
    }
    out
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

    let (k, h0, eta) = (
        3.0e5,
        scene.nominal_clearance_m,
        scene.heater.efficiency_m_per_w,
    );
    let (lo, _) = scene.table_range();
    let model = SliderModel::from_scene(&scene)?;
    let td = touchdown_power(
        &model,
        &StaticOptions::new(scene.detector.contact_threshold_n),
    )?;
    println!(
        "\nstatic touchdown of the paper scene (analysis): {:.3} mW ({:?})",
        td.power * 1e3,
        td.cause
    );
    for (label, f) in [("paper scene", &base), ("with meniscus", &with)] {
        let fs = folds(f, k, h0, eta, lo, 3e-9);
        let list: Vec<String> = fs
            .iter()
            .map(|(d, p)| format!("{:.3} mW at d = {:.3} nm", p * 1e3, d * 1e9))
            .collect();
        println!("{label:<14} S-curve folds: {}", list.join("; "));
        if let [(_, p_in), (_, p_out), ..] = fs.as_slice() {
            println!(
                "{:<14} fold-to-fold hysteresis {:.3} mW",
                "",
                (p_in - p_out) * 1e3
            );
        }
    }
    Ok(())
}
