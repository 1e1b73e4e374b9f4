//! Does lubricant adhesion with memory let the AC voltage advance take-off? Maps of the dynamic
//! hysteresis `ΔP`, the touchdown power `P_TD` and the take-off power `P_TO` of the paper scene
//! with lubricant menisci (`force::Meniscus`), over the AC amplitude and
//! - `thickness`: the mobile lubricant thickness t_m (log scale), at the healing time τ_h below;
//! - `healing`: the healing time τ_h (log scale), at the mobile thickness below;
//! - `rupture`: the rupture distance s_r given outright (log scale) in place of Lian's law,
//!   at both of the others below (`--maps rupture`; not in the default set);
//! - `formation`: the formation time τ_f (log scale, 10 ns – 1 ms), at the others below
//!   (`--maps formation`; not in the default set).
//!
//! Every point runs the scene's fixed programme at the scene's tolerance; where that run gives
//! touchdown and take-off, it counts as converged when the other stiff method (Radau5) at the
//! same tolerance and then a run at a tolerance ten times tighter both agree with it to 0.05 mW
//! in touchdown and take-off (the checks of `mechanism_maps`, `common/checks.rs`). The row
//! without menisci (the plain paper scene) is run alike and written beside each map.
//!
//! `cargo run --release --all-features --example meniscus_map -- --grid 12` writes
//! `out/meniscus/{thickness,healing}.csv` and `.svg` (three heat maps each, converged points
//! coloured, others grey), and prints the CPU time of each map and of one cycle with and without
//! menisci (median of seven). `--maps thickness` picks one (`--maps none`: the timing alone); `--out DIR` writes elsewhere; without `--grid` a 4 × 4
//! grid runs. `--formation-us T` sets the formation time where it is not the axis (default
//! 0.1 µs; 0: bridges that form at once).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use hdi_tribology::analysis::cycle::{simulate_cycle, CycleOptions, CycleResult, HeaterProgramme};
use hdi_tribology::force::{Meniscus, MeniscusParams, Wetting};
use hdi_tribology::model::SliderModel;
use hdi_tribology::quadrature::TableOptions;
use hdi_tribology::scene::Scene;
use rayon::prelude::*;

#[path = "common/checks.rs"]
mod checks;
#[path = "common/colour.rs"]
mod colour;
use colour::viridis;

type Res<T> = Result<T, Box<dyn std::error::Error + Send + Sync>>;

/// Step limit of one cycle.
const MAX_STEPS: usize = 300_000;

/// The lubricant of the maps where it is not the axis: PFPE (γ = 24 mN/m) wetting the disk, at
/// 30° on the head, 0.3 nm mobile, healing in 20 µs (see docs/analyses.md).
const GAMMA: f64 = 0.024;
const THETA_DEG: f64 = 30.0;
const MOBILE_M: f64 = 0.3e-9;
const HEALING_S: f64 = 2e-5;
const FORMATION_S: f64 = 1e-7;

/// The AC amplitudes of the maps, V.
const V_AC_MAX: f64 = 1.0;

#[derive(Clone, Copy, Debug)]
enum Axis {
    Thickness,
    Healing,
    Rupture,
    Formation,
}

impl Axis {
    fn name(self) -> &'static str {
        match self {
            Axis::Thickness => "thickness",
            Axis::Healing => "healing",
            Axis::Rupture => "rupture",
            Axis::Formation => "formation",
        }
    }
    fn label(self) -> &'static str {
        match self {
            Axis::Thickness => "mobile thickness t_m (nm)",
            Axis::Healing => "healing time τ_h (µs)",
            Axis::Rupture => "rupture distance s_r (nm)",
            Axis::Formation => "formation time τ_f (µs)",
        }
    }
    /// Range (SI) and the factor to the unit of the label.
    fn range(self) -> ((f64, f64), f64) {
        match self {
            Axis::Thickness => ((0.05e-9, 1.5e-9), 1e9),
            Axis::Healing => ((1e-7, 1e-2), 1e6),
            Axis::Rupture => ((0.02e-9, 3e-9), 1e9),
            Axis::Formation => ((1e-8, 1e-3), 1e6),
        }
    }
    /// The lubricant at `value` of the axis, formed in `formation` (s) where that is not it.
    fn params(self, value: f64, formation: f64) -> MeniscusParams {
        let (t_m, tau_h, s_r, tau_f) = match self {
            Axis::Thickness => (value, HEALING_S, None, formation),
            Axis::Healing => (MOBILE_M, value, None, formation),
            Axis::Rupture => (MOBILE_M, HEALING_S, Some(value), formation),
            Axis::Formation => (MOBILE_M, HEALING_S, None, value),
        };
        MeniscusParams {
            surface_tension: GAMMA,
            contact_angle: THETA_DEG.to_radians(),
            wetting: Wetting::Disk,
            mobile_thickness: t_m,
            rupture_distance: s_r,
            healing_time: tau_h,
            formation_time: tau_f,
            pickup: None,
        }
    }
}

/// One map point.
#[derive(Clone, Debug)]
struct Point {
    v_ac: f64,
    /// The axis value (SI); NaN for the row without menisci.
    param: f64,
    td: Option<f64>,
    to: Option<f64>,
    converged: bool,
    error: Option<String>,
    cpu_s: f64,
}

impl Point {
    fn dp(&self) -> Option<f64> {
        Some(self.td? - self.to?)
    }
}

struct Setup {
    scene: Scene,
    plain: SliderModel,
    programme: HeaterProgramme,
    opts: CycleOptions,
    /// The formation time where it is not the axis (s).
    formation: f64,
}

impl Setup {
    fn new(formation: f64) -> Res<Self> {
        let scene = Scene::paper();
        let mut opts = CycleOptions::from_scene(&scene)?;
        opts.solver.max_steps = MAX_STEPS;
        opts.stop_outside_tables = true;
        Ok(Setup {
            plain: SliderModel::from_scene(&scene)?,
            programme: HeaterProgramme::fixed_from_scene(&scene)?,
            opts,
            scene,
            formation,
        })
    }

    /// The paper model with menisci of `params` (`None`: without).
    fn model(&self, params: Option<MeniscusParams>, v_ac: f64) -> Res<SliderModel> {
        let base = self.plain.with_ac_amplitude(v_ac);
        let Some(p) = params else {
            return Ok(base);
        };
        let c = self
            .scene
            .contact
            .as_ref()
            .ok_or("the paper scene has contact")?;
        let m = Meniscus::new(
            p,
            c.asperity_radius_m,
            c.asperity_density_per_m2,
            self.scene.peaks()?,
            c.footprint,
        )?
        .tabulated(self.scene.table_range(), &TableOptions::default())?;
        Ok(base.with_stateful_term(m)?)
    }

    /// One cycle of the scene's programme at its settings.
    fn cycle(&self, model: &SliderModel) -> hdi_tribology::Result<CycleResult> {
        simulate_cycle(model, &self.programme, &self.opts)
    }

    fn run(&self, params: Option<MeniscusParams>, param: f64, v_ac: f64) -> Point {
        let t0 = Instant::now();
        let mut p = Point {
            v_ac,
            param,
            td: None,
            to: None,
            converged: false,
            error: None,
            cpu_s: 0.0,
        };
        let outcome = (|| -> Res<()> {
            let model = self.model(params, v_ac)?;
            let first = self.cycle(&model)?;
            let shown = checks::powers(&first);
            (p.td, p.to) = shown;
            if p.td.is_some() && p.to.is_some() {
                let (mut runs, mut steps) = (1, 0);
                p.converged = checks::both_checks(
                    &model,
                    &self.programme,
                    &self.opts,
                    &first,
                    true,
                    &mut runs,
                    &mut steps,
                )?;
            }
            Ok(())
        })();
        if let Err(e) = outcome {
            p.error = Some(e.to_string());
        }
        p.cpu_s = t0.elapsed().as_secs_f64();
        p
    }
}

fn grid((lo, hi): (f64, f64), n: usize, log: bool) -> Vec<f64> {
    (0..n)
        .map(|j| {
            let f = j as f64 / (n.max(2) - 1) as f64;
            if log {
                (lo.ln() + (hi.ln() - lo.ln()) * f).exp()
            } else {
                lo + (hi - lo) * f
            }
        })
        .collect()
}

fn fmt_mw(x: Option<f64>) -> String {
    x.map_or_else(|| "".into(), |x| format!("{:.4}", x * 1e3))
}

fn write_csv(path: &Path, axis: Axis, points: &[Point]) -> Res<()> {
    let (_, unit) = axis.range();
    let mut s = format!(
        "v_ac_v,{},p_td_mw,p_to_mw,dp_mw,converged,cpu_s,error\n",
        match axis {
            Axis::Thickness => "mobile_thickness_nm",
            Axis::Healing => "healing_time_us",
            Axis::Rupture => "rupture_distance_nm",
            Axis::Formation => "formation_time_us",
        }
    );
    for p in points {
        writeln!(
            s,
            "{},{},{},{},{},{},{:.3},{}",
            p.v_ac,
            if p.param.is_nan() {
                // the row without menisci: no value, an empty field
                String::new()
            } else {
                format!("{:.6}", p.param * unit)
            },
            fmt_mw(p.td),
            fmt_mw(p.to),
            fmt_mw(p.dp()),
            p.converged,
            p.cpu_s,
            p.error.as_deref().unwrap_or("").replace(',', ";")
        )?;
    }
    std::fs::write(path, s)?;
    Ok(())
}

type Quantity = (&'static str, fn(&Point) -> Option<f64>);

const QUANTITIES: [Quantity; 3] = [
    ("ΔP (mW)", |p| p.dp().map(|d| d * 1e3)),
    ("P_TD (mW)", |p| p.td.map(|x| x * 1e3)),
    ("P_TO (mW)", |p| p.to.map(|x| x * 1e3)),
];

/// Three heat maps side by side (rows: the axis, bottom row without menisci; columns: V_ac),
/// converged points coloured on each panel's own scale, unconverged grey, undetected light grey.
fn write_svg(path: &Path, axis: Axis, values: &[f64], v: &[f64], points: &[Point]) -> Res<()> {
    let (_, unit) = axis.range();
    let (cell_w, cell_h) = (22.0, 18.0);
    let rows = values.len() + 1;
    let (pw, ph) = (cell_w * v.len() as f64, cell_h * rows as f64);
    let (left, top, gap) = (70.0, 40.0, 70.0);
    let width = left + 3.0 * (pw + gap);
    let height = top + ph + 84.0;
    let mut s = format!(
        "<svg xmlns='http://www.w3.org/2000/svg' width='{width}' height='{height}' \
         font-family='sans-serif' font-size='10'>\n<rect width='100%' height='100%' fill='white'/>\n"
    );
    let at = |row: usize, col: usize| -> Option<&Point> {
        points.iter().find(|p| {
            (p.v_ac - v[col]).abs() < 1e-12
                && if row == values.len() {
                    p.param.is_nan()
                } else {
                    (p.param - values[row]).abs() <= 1e-9 * values[row]
                }
        })
    };
    for (k, (name, q)) in QUANTITIES.iter().enumerate() {
        let x0 = left + k as f64 * (pw + gap);
        let shown: Vec<f64> = points
            .iter()
            .filter(|p| p.converged)
            .filter_map(q)
            .collect();
        let lo = shown.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = shown.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        writeln!(
            s,
            "<text x='{}' y='{}' font-size='12'>{name}: {lo:.2} … {hi:.2}</text>",
            x0,
            top - 12.0
        )?;
        for row in 0..rows {
            // top row: the largest axis value; the bottom row: no menisci
            let r = if row == values.len() {
                values.len()
            } else {
                values.len() - 1 - row
            };
            let y = top + row as f64 * cell_h + if row == values.len() { 4.0 } else { 0.0 };
            for col in 0..v.len() {
                let fill = match at(r, col) {
                    Some(p) if p.converged => match q(p) {
                        Some(x) if hi > lo => {
                            let (a, b, c) = viridis((x - lo) / (hi - lo));
                            format!("rgb({a},{b},{c})")
                        }
                        Some(_) => "rgb(33,144,141)".into(),
                        None => "rgb(225,225,225)".into(),
                    },
                    Some(p) if p.td.is_some() && p.to.is_some() => "rgb(150,150,150)".into(),
                    _ => "rgb(225,225,225)".into(),
                };
                writeln!(
                    s,
                    "<rect x='{}' y='{y}' width='{cell_w}' height='{cell_h}' fill='{fill}' \
                     stroke='white' stroke-width='0.5'/>",
                    x0 + col as f64 * cell_w
                )?;
            }
        }
        for (i, &val) in values.iter().enumerate().rev() {
            if k == 0 && (i % 2 == 0 || values.len() <= 6) {
                let y = top + (values.len() - 1 - i) as f64 * cell_h + 0.7 * cell_h;
                writeln!(
                    s,
                    "<text x='{}' y='{y}' text-anchor='end'>{:.3}</text>",
                    x0 - 4.0,
                    val * unit
                )?;
            }
        }
        if k == 0 {
            writeln!(
                s,
                "<text x='{}' y='{}' text-anchor='end'>none</text>",
                x0 - 4.0,
                top + ph + 4.0 - 0.3 * cell_h
            )?;
        }
        for (col, &va) in v.iter().enumerate() {
            if col % 2 == 0 || v.len() <= 6 {
                writeln!(
                    s,
                    "<text x='{}' y='{}' text-anchor='middle'>{va:.2}</text>",
                    x0 + (col as f64 + 0.5) * cell_w,
                    top + ph + 18.0
                )?;
            }
        }
        writeln!(
            s,
            "<text x='{}' y='{}' text-anchor='middle'>V_ac (V)</text>",
            x0 + 0.5 * pw,
            top + ph + 34.0
        )?;
    }
    writeln!(
        s,
        "<text x='4' y='{}'>rows: {}; bottom row: no menisci.</text>\n\
         <text x='4' y='{}'>Grey: moves &gt; 0.05 mW with Radau5 or at 10× tighter tolerance; \
         light grey: touchdown or take-off not detected (no take-off before the programme \
         returns to 60 mW).</text>",
        top + ph + 55.0,
        axis.label(),
        top + ph + 69.0
    )?;
    s.push_str("</svg>\n");
    std::fs::write(path, s)?;
    Ok(())
}

fn run_map(setup: &Setup, axis: Axis, n: usize, out: &Path) -> Res<()> {
    let ((lo, hi), _) = axis.range();
    let values = grid((lo, hi), n, true);
    let v = grid((0.0, V_AC_MAX), n, false);
    let mut jobs: Vec<(Option<f64>, f64)> = Vec::new();
    for &va in &v {
        jobs.push((None, va));
        for &x in &values {
            jobs.push((Some(x), va));
        }
    }
    let t0 = Instant::now();
    let points: Vec<Point> = jobs
        .par_iter()
        .map(|&(x, va)| match x {
            Some(x) => setup.run(Some(axis.params(x, setup.formation)), x, va),
            None => setup.run(None, f64::NAN, va),
        })
        .collect();
    let wall = t0.elapsed().as_secs_f64();
    let cpu: f64 = points.iter().map(|p| p.cpu_s).sum();
    let conv = points.iter().filter(|p| p.converged).count();
    println!(
        "{}: {n} × {n} (+ {n} without menisci) in {wall:.1} s wall, {cpu:.1} s summed over \
         points; {conv} of {} converged",
        axis.name(),
        points.len()
    );
    for p in &points {
        if let Some(e) = &p.error {
            println!("  {:.2} V, {:.3e}: {e}", p.v_ac, p.param);
        }
    }
    write_csv(&out.join(format!("{}.csv", axis.name())), axis, &points)?;
    write_svg(
        &out.join(format!("{}.svg", axis.name())),
        axis,
        &values,
        &v,
        &points,
    )?;
    Ok(())
}

/// One cycle with and without menisci, each timed over `reps` runs (median).
fn timing(setup: &Setup, reps: usize) -> Res<()> {
    let time = |m: &SliderModel| -> Res<f64> {
        let mut t: Vec<f64> = (0..reps)
            .map(|_| {
                let t0 = Instant::now();
                setup.cycle(m).map(|_| t0.elapsed().as_secs_f64())
            })
            .collect::<hdi_tribology::Result<_>>()?;
        t.sort_by(f64::total_cmp);
        Ok(t[reps / 2])
    };
    for va in [0.0, 0.6] {
        let plain = setup.model(None, va)?;
        let with = setup.model(Some(Axis::Thickness.params(MOBILE_M, setup.formation)), va)?;
        let (a, b) = (time(&plain)?, time(&with)?);
        let (ra, rb) = (setup.cycle(&plain)?, setup.cycle(&with)?);
        let statics = |m: &SliderModel| -> Res<f64> {
            let t0 = Instant::now();
            for _ in 0..10 {
                hdi_tribology::analysis::flying_equilibrium(
                    m,
                    0.06,
                    0.0,
                    &hdi_tribology::analysis::ScanGrid::default(),
                )?;
            }
            Ok(t0.elapsed().as_secs_f64() / 10.0)
        };
        println!(
            "  flying equilibrium: {:.2} ms without, {:.2} ms with; stats without {:?}\n  with {:?}",
            statics(&plain)? * 1e3,
            statics(&with)? * 1e3,
            ra.stats,
            rb.stats
        );
        println!(
            "one cycle at {va} V: {:.1} ms without menisci ({} steps), {:.1} ms with ({} steps): \
             {:.2}×; TD {} / {} mW, TO {} / {} mW",
            a * 1e3,
            ra.stats.accepted,
            b * 1e3,
            rb.stats.accepted,
            b / a,
            fmt_mw(ra.touchdown.map(|d| d.power)),
            fmt_mw(rb.touchdown.map(|d| d.power)),
            fmt_mw(ra.takeoff.map(|d| d.power)),
            fmt_mw(rb.takeoff.map(|d| d.power)),
        );
    }
    Ok(())
}

fn main() -> Res<()> {
    let mut n = 4;
    let mut out = PathBuf::from("out/meniscus");
    let mut maps = vec![Axis::Thickness, Axis::Healing];
    let mut formation = FORMATION_S;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--grid" => n = args.next().ok_or("--grid needs a number")?.parse()?,
            "--out" => out = args.next().ok_or("--out needs a directory")?.into(),
            "--formation-us" => {
                let us: f64 = args.next().ok_or("--formation-us needs a time")?.parse()?;
                if !(us.is_finite() && us >= 0.0) {
                    return Err(
                        format!("--formation-us must be finite and >= 0, got {us} µs").into(),
                    );
                }
                formation = us * 1e-6;
            }
            "--maps" => {
                maps = args
                    .next()
                    .ok_or("--maps needs names")?
                    .split(',')
                    .filter(|m| *m != "none")
                    .map(|m| match m {
                        "thickness" => Ok(Axis::Thickness),
                        "healing" => Ok(Axis::Healing),
                        "rupture" => Ok(Axis::Rupture),
                        "formation" => Ok(Axis::Formation),
                        other => Err(format!("unknown map {other:?}")),
                    })
                    .collect::<Result<_, _>>()?
            }
            other => return Err(format!("unknown argument {other:?}").into()),
        }
    }
    if !(2..=64).contains(&n) {
        return Err(format!("--grid must lie in [2, 64], got {n}").into());
    }
    std::fs::create_dir_all(&out)?;
    let setup = Setup::new(formation)?;
    timing(&setup, 7)?;
    for axis in maps {
        run_map(&setup, axis, n, &out)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2 × 2 thickness map runs, writes its files, and its row without menisci is the plain
    /// paper scene's cycle.
    #[test]
    fn a_small_map_runs_and_writes_its_files() -> Res<()> {
        let dir = tempfile::tempdir()?;
        let setup = Setup::new(FORMATION_S)?;
        run_map(&setup, Axis::Thickness, 2, dir.path())?;
        let csv = std::fs::read_to_string(dir.path().join("thickness.csv"))?;
        assert_eq!(csv.lines().count(), 1 + 2 * 3);
        assert!(std::fs::read_to_string(dir.path().join("thickness.svg"))?.contains("<svg"));
        let plain = setup.cycle(&setup.plain)?;
        let row = csv.lines().find(|l| l.starts_with("0,,")).unwrap();
        assert!(row.contains(&fmt_mw(plain.touchdown.map(|d| d.power))));
        Ok(())
    }
}
