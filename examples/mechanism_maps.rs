//! Does the AC voltage advance take-off? Maps of the dynamic hysteresis `ΔP`, the touchdown power
//! `P_TD` and the take-off power `P_TO` over the AC amplitude and one structural parameter, for
//! the few-peak deformable-slider scene `scenes/paper_bulge.toml`:
//! - `freq`: V_ac × the bulge's natural frequency on a fixed body (`bulge`);
//! - `zeta`: V_ac × the bulge's damping ratio (`bulge`);
//! - `lag_rigid`, `lag_bulge`: V_ac × the interface lag τ, on `rigid` and on `bulge`;
//! - `lag_paper` (only when named in `--maps`): V_ac × the interface lag τ = 1 – 320 ns on the
//!   paper scene itself, `scenes/paper.toml` (Greenwood–Williamson contact, rigid slider), whose
//!   c/K_contact (≈ 27 ns) lies inside the plausible lags.
//!
//! Every point runs the scene's fixed programme at the scene's tolerance, and where that run
//! gives touchdown and take-off, two checks must pass before the point counts as converged, each
//! to 0.05 mW in touchdown and take-off:
//! - the method check: the other stiff method (Radau5, or Rodas5P if the scene asks for Radau5)
//!   at the scene's tolerance must agree with the values shown (`--no-method-check` leaves it
//!   out). With AC the detected take-off can be a whole period of `V²` early or late in both runs
//!   of a tolerance check alike;
//! - the tolerance check: a run at a tolerance ten times tighter by the method the first run
//!   took (`CycleResult::method`: Rodas5P where `Auto` started stiff, not the Radau5 that `Auto`
//!   takes below rtol 1e-6).
//!
//! The method check runs first and the tighter run only where it agrees: where it disagrees the
//! point is unconverged whatever the tighter run gives, and the map saves that run (a 100 × 100
//! `freq` map 13–15 % of its time; docs/benchmarks.md, "The method check first"). (`--full-check`: the tolerance check at every point and the tighter
//! run shown, `ac_sweep_refined` with two runs, as the maps in docs/analyses.md were made; the
//! method check then follows it.) A cycle that bounces below the force
//! tables at more than twice the even step pace stops there (`CycleOptions::stop_outside_tables`),
//! and every run ends at its take-off (`CycleOptions::stop_at_takeoff`: the same powers) without
//! the mean flash temperature (`CycleOptions::mean_temperature`: the powers within the tolerance).
//! The output gives each map's CPU time per status, and for the runaways per cause (also in the
//! CSV's `cause` column). The heatmaps colour only converged
//! points with both detections (and, for `ΔP`, a non-negative value); the others are drawn in
//! grey or black and named in the legend. A white dot marks a point whose contact force drops to
//! zero during the hold at the highest power (the contact bounces). The outlined band is the
//! physically plausible range estimated in docs/analyses.md.
//!
//! `cargo run --release --example mechanism_maps -- --grid 12 --out docs/img/maps` draws the
//! maps of docs/analyses.md; `--maps freq,zeta` picks maps, `--check` reruns a few points with
//! Radau5 at a hundredfold tighter tolerance, `--probe` reruns the unconverged points of the
//! plausible band with both stiff methods at rtol 1e-6 … 1e-9 and compares their take-off with
//! the row's at `V_ac = 0`. Without `--grid` a 6 × 6 grid runs (a few minutes
//! for all four maps on two cores; the test runs a 3 × 3 map in seconds).

use hdi_tribology::analysis::cycle::{CycleOptions, HeaterProgramme};
use hdi_tribology::analysis::{ac_sweep_refined, simulate_cycle, Refinement};
use hdi_tribology::model::{ForceSlopes, SliderModel, Structure};
use hdi_tribology::ode::Method;
use hdi_tribology::report::write_csv;
use hdi_tribology::scene::{Scene, StructureSpec};
use plotters::prelude::*;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::path::Path;
use std::time::Instant;

#[path = "common/checks.rs"]
mod checks;
#[path = "common/colour.rs"]
mod colour;
use checks::POWER_TOL;

type Res<T> = Result<T, Box<dyn std::error::Error>>;

/// Step limit of one cycle of a map.
const MAX_STEPS: usize = 300_000;

/// The scene's bulge: mass (kg), stiffness (N/m), damping ratio.
#[derive(Clone, Copy, Debug)]
struct Bulge {
    mass: f64,
    stiffness: f64,
    zeta: f64,
}

impl Bulge {
    fn frequency(&self) -> f64 {
        (self.stiffness / self.mass).sqrt() / (2.0 * PI)
    }
}

/// How a map point's values are checked.
#[derive(Clone, Copy, Debug)]
struct Checks {
    /// Both runs at every point, the tighter one shown (`--full-check`).
    full: bool,
    /// A run with the other stiff method at the scene's tolerance, before the tighter one (on
    /// unless `--no-method-check`).
    method: bool,
    /// The bulge mode condensed to its quasi-static equilibrium where
    /// `QuasiStaticBulge::check` passes (`--quasi-static`).
    quasi_static: bool,
}

/// What a map varies along its vertical axis (log scale).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Axis {
    /// Bulge natural frequency on a fixed body (Hz), at the scene's bulge mass and damping ratio.
    Frequency,
    /// Bulge damping ratio, at the scene's bulge mass and stiffness.
    Damping,
    /// Interface lag τ (s), on the given structure.
    Lag { bulge: bool },
}

#[derive(Clone, Copy, Debug)]
struct MapSpec {
    name: &'static str,
    title: &'static str,
    axis: Axis,
    /// log10 of the axis range.
    range: (f64, f64),
    /// log10 of the physically plausible band.
    plausible: (f64, f64),
    label: &'static str,
    /// The scene the map runs on, where it is not the one given by `--scene`.
    scene: Option<&'static str>,
}

const MAPS: [MapSpec; 5] = [
    MapSpec {
        name: "freq",
        title: "bulge: V_ac × bulge natural frequency",
        axis: Axis::Frequency,
        range: (6.5, 9.5),
        // 10 MHz – 1.3 GHz: k = 2E*a = 4e5 … 2e6 N/m, m = ρL³ with L = 2 … 30 µm.
        plausible: (7.0, 9.11),
        label: "f_{b} (Hz)",
        scene: None,
    },
    MapSpec {
        name: "zeta",
        title: "bulge: V_ac × bulge damping ratio",
        axis: Axis::Damping,
        range: (-4.0, 0.0),
        // radiation into the body, ζ ≈ 0.43/√B for B = m/(ρa³) = 1 … 1000, plus material loss.
        plausible: (-1.9, -0.37),
        label: "ζ_{b}",
        scene: None,
    },
    MapSpec {
        name: "lag_rigid",
        title: "rigid: V_ac × interface lag",
        axis: Axis::Lag { bulge: false },
        range: (-10.0, -5.0),
        // a wave crossing 10 µm … 1.2 mm at 8.7 km/s: 1 ns … 140 ns.
        plausible: (-9.0, -6.854),
        label: "τ (s)",
        scene: None,
    },
    MapSpec {
        name: "lag_bulge",
        title: "bulge: V_ac × interface lag",
        axis: Axis::Lag { bulge: true },
        range: (-10.0, -5.0),
        plausible: (-9.0, -6.854),
        label: "τ (s)",
        scene: None,
    },
    MapSpec {
        name: "lag_paper",
        title: "paper scene (GW, rigid): V_ac × interface lag",
        axis: Axis::Lag { bulge: false },
        range: (-9.0, -6.5),
        plausible: (-9.0, -6.854),
        label: "τ (s)",
        scene: Some("scenes/paper.toml"),
    },
];

/// Which model gave a map point's values.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Model {
    /// The full structure.
    Full,
    /// The quasi-static bulge, run for this point.
    QuasiStatic,
    /// The quasi-static bulge, the run of another point with the same reduced model (on the
    /// `zeta` map the condensation drops the damping, so every row where it holds shares it).
    Shared,
}

impl Model {
    fn code(self) -> f64 {
        match self {
            Model::Full => 0.0,
            Model::QuasiStatic => 1.0,
            Model::Shared => 2.0,
        }
    }
}

/// How a map point ended.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Status {
    /// Both detections, converged.
    Fine,
    /// Both detections, but touchdown or take-off moved by more than `POWER_TOL` at 10× rtol.
    Unconverged,
    /// No touchdown, or no take-off, under the programme.
    Undetected,
    /// The cycle failed: the slider ran into the disk, bounced below the force tables, or the
    /// solver gave up.
    Runaway,
}

/// Why a runaway point's cycle failed.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Cause {
    /// The pad gap reached zero (`LeftTheModel`).
    HitTheDisk,
    /// A bounce below the force tables at more than twice the even step pace (`LeftTheTables`).
    LeftTheTables,
    /// The steps were spent too fast (`StepPace`).
    StepPace,
    /// Anything else: the step limit, a non-finite state, no flying equilibrium at the start.
    Other,
}

impl Cause {
    fn of(e: &hdi_tribology::Error) -> Self {
        use hdi_tribology::analysis::cycle::CycleError as C;
        match e.failure().and_then(|f| f.downcast_ref::<C>()) {
            Some(C::LeftTheModel { .. }) => Cause::HitTheDisk,
            Some(C::LeftTheTables { .. }) => Cause::LeftTheTables,
            Some(C::StepPace { .. }) => Cause::StepPace,
            _ => Cause::Other,
        }
    }

    fn code(self) -> f64 {
        match self {
            Cause::HitTheDisk => 1.0,
            Cause::LeftTheTables => 2.0,
            Cause::StepPace => 3.0,
            Cause::Other => 4.0,
        }
    }
}

impl Status {
    fn code(self) -> f64 {
        match self {
            Status::Fine => 0.0,
            Status::Unconverged => 1.0,
            Status::Undetected => 2.0,
            Status::Runaway => 3.0,
        }
    }
}

#[derive(Clone, Copy, Debug)]
struct Point {
    v_ac: f64,
    param: f64,
    td: Option<f64>,
    to: Option<f64>,
    status: Status,
    /// Why the cycle failed, for a runaway.
    cause: Option<Cause>,
    bounce: bool,
    /// CPU time of the point's cycles (s) and their accepted steps.
    cpu: f64,
    steps: usize,
    /// Cycles run for the point (1 without a check run, 2 with one).
    runs: usize,
    /// Which model gave the values.
    model: Model,
}

impl Point {
    fn dp(&self) -> Option<f64> {
        Some(self.td? - self.to?)
    }
}

struct Setup {
    base: SliderModel,
    programme: HeaterProgramme,
    opts: CycleOptions,
    /// The scene's bulge; `None` on a rigid scene (lag maps on `rigid` only).
    bulge: Option<Bulge>,
    body_mass: f64,
    /// The interface force's slopes, for the quasi-static bulge's check at every point.
    slopes: ForceSlopes,
}

impl Setup {
    fn from_scene(scene: &Scene) -> Res<Self> {
        let bulge = match scene.structure {
            StructureSpec::Bulge {
                mass_kg,
                stiffness_n_per_m,
                damping_ratio,
            } => Some(Bulge {
                mass: mass_kg,
                stiffness: stiffness_n_per_m,
                zeta: damping_ratio,
            }),
            _ => None,
        };
        let knots = &scene.heater.programme;
        let top = knots.iter().map(|k| k[1]).fold(f64::MIN, f64::max);
        let at_top: Vec<f64> = knots.iter().filter(|k| k[1] == top).map(|k| k[0]).collect();
        let mut opts = CycleOptions::from_scene(scene)?;
        opts.keep_series = true;
        // A cycle of this scene takes 1e3 … 5e4 steps; one that needs more is bouncing without
        // bound and is marked as a runaway instead of running for minutes.
        opts.solver.max_steps = opts.solver.max_steps.min(MAX_STEPS);
        // A bounce below the force tables at more than twice the even step pace stops at once,
        // not after the step pace's start allowance of exact-quadrature steps.
        opts.stop_outside_tables = true;
        // The maps show powers, not the lag's energy audit, which would cost a tenth more.
        opts.energy_audit = false;
        // A point shows the two powers and whether the contact bounces during the hold: its
        // runs end at the take-off (the same powers to the bit, a tenth fewer steps).
        opts.stop_at_takeoff = true;
        // Nor the mean flash temperature: its integral left out of the state, about 13 % fewer
        // instructions per cycle (the powers move within the tolerance).
        opts.mean_temperature = false;
        // The bounce flag reads the contact force over the hold at the highest power alone: the
        // series covers that stretch and no more (the same values to the bit, a sixth fewer
        // instructions in a point's first run).
        opts.series_window = Some((at_top[0], at_top[at_top.len() - 1]));
        let base = SliderModel::from_scene(scene)?;
        Ok(Setup {
            slopes: ForceSlopes::of(base.forces()),
            base,
            programme: HeaterProgramme::Fixed(SliderModel::programme_from_knots(knots)?),
            opts,
            bulge,
            body_mass: scene.slider.mass_kg,
        })
    }

    /// The model of one map point.
    fn model(&self, axis: Axis, param: f64, v_ac: f64) -> Res<SliderModel> {
        let mut m = self.base.clone();
        let bulge = || {
            self.bulge
                .ok_or("this map needs a scene with a bulge structure")
        };
        let structure = match axis {
            Axis::Frequency => {
                let b = bulge()?;
                Structure::bulge(
                    self.body_mass,
                    b.mass,
                    b.mass * (2.0 * PI * param).powi(2),
                    b.zeta,
                )?
            }
            Axis::Damping => {
                let b = bulge()?;
                Structure::bulge(self.body_mass, b.mass, b.stiffness, param)?
            }
            Axis::Lag { bulge: true } => {
                let b = bulge()?;
                m = m.with_interface_lag(param);
                Structure::bulge(self.body_mass, b.mass, b.stiffness, b.zeta)?
            }
            Axis::Lag { bulge: false } => {
                m = m.with_interface_lag(param);
                Structure::rigid(self.body_mass)?
            }
        };
        Ok(m.with_structure(structure).with_ac_amplitude(v_ac))
    }

    /// Where the quasi-static bulge holds at a point (`QuasiStaticBulge::check`), what its reduced
    /// model is made of: the bulge spring, the interface lag and the AC amplitude (the bulge's
    /// mass and damping enter only the check). `None` where it does not hold, or on `rigid`.
    fn quasi_static_key(&self, axis: Axis, param: f64, v_ac: f64) -> Res<Option<[u64; 3]>> {
        if axis == (Axis::Lag { bulge: false }) {
            return Ok(None);
        }
        let m = self.model(axis, param, v_ac)?;
        let q = m
            .structure()
            .quasi_static_bulge()
            .ok_or("the bulge maps need a bulge structure")?;
        Ok(q.check_on(&m, &self.slopes).passes().then(|| {
            [
                q.stiffness().to_bits(),
                m.interface_lag().to_bits(),
                v_ac.to_bits(),
            ]
        }))
    }

    /// One map point. The cycle at the scene's tolerance gives the values; the method check,
    /// then a cycle at a tenfold tighter tolerance check them (`checks::both_checks`: converged
    /// when both agree within `POWER_TOL`). Where the first cycle already fails (the slider runs
    /// into the disk or the stepper gives up) or misses touchdown or take-off, the point is marked
    /// as such without the checks: no value is shown there, so there is nothing to check.
    /// `checks.full` runs the tighter cycle everywhere and reports it instead (the earlier
    /// scheme, for comparison), the method check after it. A check cycle that fails marks the
    /// point: the tighter one as the cause of a runaway, the method check's as a disagreement.
    fn run(&self, axis: Axis, param: f64, v_ac: f64, checks: Checks, quasi: bool) -> Res<Point> {
        let mut m = self.model(axis, param, v_ac)?;
        if quasi {
            m = m.with_quasi_static_bulge()?;
        }
        let cpu0 = thread_cpu_seconds();
        let mut p = Point {
            v_ac,
            param,
            td: None,
            to: None,
            status: Status::Runaway,
            cause: None,
            bounce: false,
            cpu: 0.0,
            steps: 0,
            runs: 1,
            model: if quasi {
                Model::QuasiStatic
            } else {
                Model::Full
            },
        };
        let outcome = if checks.full {
            let refine = Refinement {
                power_tol: POWER_TOL,
                // The maps show powers only: the mean temperature rise is not checked.
                temperature_tol: f64::MAX,
                factor: 0.1,
                max_runs: 2,
                agreeing_runs: 2,
            };
            ac_sweep_refined(&m, &self.programme, &self.opts, &[v_ac], &refine).map(|mut r| {
                let r = r.remove(0);
                p.runs = r.runs;
                p.steps = r.stats.accepted;
                (r.cycle, Some(r.converged))
            })
        } else {
            simulate_cycle(&m, &self.programme, &self.opts).and_then(|first| {
                p.steps = first.stats.accepted;
                let shown = checks::powers(&first);
                if shown.0.is_none() || shown.1.is_none() {
                    return Ok((first, None));
                }
                let converged = checks::both_checks(
                    &m,
                    &self.programme,
                    &self.opts,
                    &first,
                    checks.method,
                    &mut p.runs,
                    &mut p.steps,
                )?;
                Ok((first, Some(converged)))
            })
        };
        p.cpu = thread_cpu_seconds() - cpu0;
        // The slider entering the disk, or the stepper giving up, is a property of this point:
        // mark it, do not stop the map.
        let (r, mut converged) = match outcome {
            Ok(x) => x,
            Err(e) => {
                p.cause = Some(Cause::of(&e));
                return Ok(p);
            }
        };
        (p.td, p.to) = checks::powers(&r);
        if checks.full && converged == Some(true) && checks.method {
            // With the full check the values shown are the tighter run's, so the method check
            // follows it: the other stiff method than the one asked for, at the scene's
            // tolerance, as the maps of docs/analyses.md were checked.
            p.runs += 1;
            converged = Some(checks::method_check(
                &m,
                &self.programme,
                &self.opts,
                ((p.td, p.to), self.opts.solver.method),
                &mut p.steps,
            ));
            p.cpu = thread_cpu_seconds() - cpu0;
        }
        p.status = match (p.td, p.to, converged) {
            (Some(_), Some(_), Some(true)) => Status::Fine,
            (Some(_), Some(_), _) => Status::Unconverged,
            _ => Status::Undetected,
        };
        // The series holds the hold's steps alone (`CycleOptions::series_window`).
        if let Some(s) = &r.series {
            p.bounce = p.td.is_some() && s.contact.iter().any(|&f| f <= 0.0);
        }
        Ok(p)
    }
}

/// CPU time of the calling thread (s), from `/proc/thread-self/schedstat` (0 where the kernel
/// does not report it).
fn thread_cpu_seconds() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(0.0, |ns| ns * 1e-9)
}

fn log_grid((lo, hi): (f64, f64), n: usize) -> Vec<f64> {
    (0..n)
        .map(|j| lo + (hi - lo) * j as f64 / (n.max(2) - 1) as f64)
        .collect()
}

/// Every point of a map, on rayon's pool. Each point's values are those of its own runs, which
/// depend on nothing but the point: the map is the same to the bit on any number of threads.
/// With `checks.quasi_static` the points where the quasi-static bulge holds run on it, each
/// reduced model once (points that share one take its values, `Model::Shared`), and a point
/// whose reduced run fails runs again on the full model.
fn run_map(setup: &Setup, spec: &MapSpec, n: usize, checks: Checks) -> Res<Vec<Point>> {
    let volts = log_grid((0.0, 1.0), n);
    let params = log_grid(spec.range, n);
    let cells: Vec<(f64, f64)> = params
        .iter()
        .flat_map(|&y| volts.iter().map(move |&v| (v, 10f64.powf(y))))
        .collect();
    let keys: Vec<Option<[u64; 3]>> = if checks.quasi_static {
        cells
            .par_iter()
            .map(|&(v, p)| {
                setup
                    .quasi_static_key(spec.axis, p, v)
                    .map_err(|e| e.to_string())
            })
            .collect::<Result<_, String>>()?
    } else {
        vec![None; cells.len()]
    };
    // One job per cell, except that cells with the same reduced model share the first one's.
    let mut jobs: Vec<(usize, bool)> = Vec::new();
    let mut job_of = Vec::with_capacity(cells.len());
    let mut first = std::collections::HashMap::new();
    for (i, key) in keys.iter().enumerate() {
        let j = match key {
            Some(k) => *first.entry(*k).or_insert_with(|| {
                jobs.push((i, true));
                jobs.len() - 1
            }),
            None => {
                jobs.push((i, false));
                jobs.len() - 1
            }
        };
        job_of.push(j);
    }
    // One task per point: a point costs from a fraction of a millisecond (no flying start) to
    // seconds (a contact that bounces), and the rows differ most, so that sequential stretches
    // of the grid (rayon's default leaves) left one core idle for up to 6 % of a 100 × 100 map.
    let done: Vec<Point> = jobs
        .par_iter()
        .with_max_len(1)
        .map(|&(i, quasi)| {
            let (v, p) = cells[i];
            let run = |quasi| {
                setup
                    .run(spec.axis, p, v, checks, quasi)
                    .map_err(|e| e.to_string())
            };
            let mut point = run(quasi)?;
            if quasi && point.status == Status::Runaway {
                let (cpu, steps, runs) = (point.cpu, point.steps, point.runs);
                point = run(false)?;
                point.cpu += cpu;
                point.steps += steps;
                point.runs += runs;
            }
            Ok(point)
        })
        .collect::<Result<_, String>>()?;
    Ok(cells
        .iter()
        .enumerate()
        .map(|(i, &(v, p))| {
            let (j, mut point) = (job_of[i], done[job_of[i]]);
            if jobs[j].0 != i {
                // The values of the cell that ran this reduced model; its cost is counted there.
                (point.v_ac, point.param, point.model) = (v, p, Model::Shared);
                (point.cpu, point.steps, point.runs) = (0.0, 0, 0);
            }
            point
        })
        .collect())
}

/// Viridis, from its published anchor colours (colour-blind safe, sequential).
fn viridis(x: f64) -> RGBColor {
    let (r, g, b) = colour::viridis(x);
    RGBColor(r, g, b)
}

const UNCONVERGED: RGBColor = RGBColor(150, 150, 150);
const UNDETECTED: RGBColor = RGBColor(225, 225, 225);
const NEGATIVE: RGBColor = RGBColor(90, 90, 90);

/// One quantity of a map: its name and value (mW) at a point, `None` where it is not shown.
type Quantity = (&'static str, fn(&Point) -> Option<f64>);

const QUANTITIES: [Quantity; 3] = [
    ("ΔP (mW)", |p| {
        p.dp().filter(|&d| d >= 0.0).map(|d| d * 1e3)
    }),
    ("P_{TD} (mW)", |p| p.td.map(|x| x * 1e3)),
    ("P_{TO} (mW)", |p| p.to.map(|x| x * 1e3)),
];

/// Size of a map figure (px), set for the two-column width of a journal (7 in).
const MAP_SIZE: (u32, u32) = (1500, 600);

/// A font of `pt` points at the printed width of [`MAP_SIZE`] (plotters sets glyphs at 1/1.24 of
/// the size asked).
fn map_font(pt: f64) -> f64 {
    pt * 1.24 * MAP_SIZE.0 as f64 / (7.0 * 72.0)
}

fn draw_map(path: &Path, spec: &MapSpec, points: &[Point], n: usize) -> Res<()> {
    let mut svg = String::new();
    draw_map_svg(&mut svg, spec, points, n)?;
    hdi_tribology::report::write_file(path, &hdi_tribology::report::typeset_svg(&svg))?;
    Ok(())
}

/// The three panels (ΔP, P_TD, P_TO) of a map with their colour bars and the legend below, for
/// print: no title (the caption is the document's), text at 8–9 pt at 7 in.
fn draw_map_svg(out: &mut String, spec: &MapSpec, points: &[Point], n: usize) -> Res<()> {
    let (tick, axis) = (map_font(8.5), map_font(9.0));
    let root = SVGBackend::with_string(out, MAP_SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let (top, bottom) = root.split_vertically(MAP_SIZE.1 - (4.4 * tick) as u32);
    let panels = top.split_evenly((1, 3));
    let dv = 1.0 / (n.max(2) - 1) as f64;
    let dy = (spec.range.1 - spec.range.0) / (n.max(2) - 1) as f64;
    for (panel, (name, value)) in panels.iter().zip(QUANTITIES) {
        let (plot, bar) = panel.split_horizontally(panel.dim_in_pixel().0 - (3.6 * tick) as u32);
        let shown: Vec<f64> = points
            .iter()
            .filter(|p| p.status == Status::Fine)
            .filter_map(value)
            .collect();
        let lo = shown.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = shown.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let (lo, hi) = if lo.is_finite() && hi > lo {
            (lo, hi)
        } else if lo.is_finite() {
            (lo - 0.5, lo + 0.5)
        } else {
            (0.0, 1.0)
        };
        let mut chart = ChartBuilder::on(&plot)
            .caption(name, ("sans-serif", axis))
            .margin(8)
            .x_label_area_size((2.4 * tick) as u32)
            .y_label_area_size((3.6 * tick) as u32)
            .build_cartesian_2d(
                -dv / 2.0..1.0 + dv / 2.0,
                spec.range.0 - dy / 2.0..spec.range.1 + dy / 2.0,
            )?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("V_{ac} (V)")
            .y_desc(spec.label)
            .x_labels(3)
            .x_label_formatter(&|v| hdi_tribology::report::snapped_tick_label(*v, 1.0))
            .label_style(("sans-serif", tick))
            .axis_desc_style(("sans-serif", axis))
            .y_label_formatter(&|y| format!("10^{{{y:.0}}}"))
            .y_labels((spec.range.1 - spec.range.0).ceil() as usize + 1)
            .draw()?;
        chart.draw_series(points.iter().map(|p| {
            let y = p.param.log10();
            let colour = match (p.status, value(p)) {
                (Status::Fine, Some(v)) => viridis((v - lo) / (hi - lo)),
                (Status::Fine, None) => NEGATIVE,
                (Status::Unconverged, _) => UNCONVERGED,
                (Status::Undetected, _) => UNDETECTED,
                (Status::Runaway, _) => BLACK,
            };
            Rectangle::new(
                [
                    (p.v_ac - dv / 2.0, y - dy / 2.0),
                    (p.v_ac + dv / 2.0, y + dy / 2.0),
                ],
                colour.filled(),
            )
        }))?;
        let r = (300.0 / n as f64 / 4.0).clamp(1.0, 6.0) as i32;
        chart.draw_series(
            points
                .iter()
                .filter(|p| p.bounce)
                .map(|p| Circle::new((p.v_ac, p.param.log10()), r, WHITE.filled())),
        )?;
        for (w, c) in [(4, WHITE), (2, BLACK)] {
            chart.draw_series(std::iter::once(Rectangle::new(
                [
                    (-dv / 2.0, spec.plausible.0),
                    (1.0 + dv / 2.0, spec.plausible.1),
                ],
                c.stroke_width(w),
            )))?;
        }
        // Colour bar, level with the plot, its labels on the right.
        let mut cb = ChartBuilder::on(&bar)
            .margin_top((axis * 1.1) as u32 + 8)
            .margin_bottom((2.4 * tick) as u32 + 8)
            .margin_left(6)
            .right_y_label_area_size((2.2 * tick) as u32)
            .build_cartesian_2d(0.0..1.0, lo..hi)?;
        cb.configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_labels(5)
            .label_style(("sans-serif", tick))
            .y_label_formatter(&|v| format!("{v:.1}"))
            .draw()?;
        let steps = 100;
        cb.draw_series((0..steps).map(|i| {
            let a = lo + (hi - lo) * i as f64 / steps as f64;
            let b = lo + (hi - lo) * (i + 1) as f64 / steps as f64;
            Rectangle::new(
                [(0.0, a), (1.0, b)],
                viridis(i as f64 / (steps - 1) as f64).filled(),
            )
        }))?;
    }
    // The legend in two rows under the panels: swatches of the statuses, then the outline and
    // the dot.
    let legend = [
        (UNCONVERGED, "not converged"),
        (UNDETECTED, "no touchdown or take-off"),
        (BLACK, "runaway"),
        (NEGATIVE, "ΔP < 0 (ΔP panel)"),
    ];
    let style = ("sans-serif", tick).into_font();
    let h = (tick / 1.24) as i32;
    let (row1, row2) = ((0.6 * tick) as i32, (2.2 * tick) as i32);
    let mut x = 20;
    for (c, text) in legend {
        bottom.draw(&Rectangle::new([(x, row1), (x + h, row1 + h)], c.filled()))?;
        bottom.draw(&Rectangle::new(
            [(x, row1), (x + h, row1 + h)],
            BLACK.stroke_width(1),
        ))?;
        bottom.draw(&Text::new(text, (x + h + 8, row1), style.clone()))?;
        x += h + 8 + (text.chars().count() as f64 * 0.46 * tick) as i32 + 40;
    }
    let outlined = "outlined: physically plausible band";
    bottom.draw(&Text::new(outlined, (20, row2), style.clone()))?;
    let x = 20 + (outlined.chars().count() as f64 * 0.46 * tick) as i32 + 40;
    bottom.draw(&Circle::new(
        (x + h / 2, row2 + h / 2),
        h / 3,
        WHITE.filled(),
    ))?;
    bottom.draw(&Circle::new(
        (x + h / 2, row2 + h / 2),
        h / 3,
        BLACK.stroke_width(1),
    ))?;
    bottom.draw(&Text::new("bounces in the hold", (x + h + 8, row2), style))?;
    root.present()?;
    Ok(())
}

/// The points of a map as [`write_points`] wrote them, to draw again without computing
/// (`--replot DIR`).
fn read_points(path: &Path) -> Res<Vec<Point>> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out = Vec::new();
    for line in text.lines().skip(1) {
        // A missing value is an empty field (maps written before that: `NaN`).
        let v: Vec<f64> = line
            .split(',')
            .map(|c| {
                if c.is_empty() {
                    Ok(f64::NAN)
                } else {
                    c.parse::<f64>()
                }
            })
            .collect::<Result<_, _>>()?;
        // Maps written before the `model` column have 11 fields: every point the full model's.
        let (v, model) = match v.len() {
            11 => (&v[..], 0.0),
            _ => (&v[..v.len().saturating_sub(1)], v[v.len() - 1]),
        };
        let [v_ac, param, td, to, _, status, bounce, cpu, steps, runs, cause] = v[..] else {
            return Err(format!("{}: a row of {} fields", path.display(), v.len()).into());
        };
        let model = [Model::Full, Model::QuasiStatic, Model::Shared]
            .into_iter()
            .find(|m| m.code() == model)
            .ok_or("unknown model")?;
        let status = [
            Status::Fine,
            Status::Unconverged,
            Status::Undetected,
            Status::Runaway,
        ]
        .into_iter()
        .find(|s| s.code() == status)
        .ok_or("unknown status")?;
        let cause = [
            Cause::HitTheDisk,
            Cause::LeftTheTables,
            Cause::StepPace,
            Cause::Other,
        ]
        .into_iter()
        .find(|c| c.code() == cause);
        out.push(Point {
            v_ac,
            param,
            td: td.is_finite().then_some(td),
            to: to.is_finite().then_some(to),
            status,
            cause,
            bounce: bounce != 0.0,
            cpu,
            steps: steps as usize,
            runs: runs as usize,
            model,
        });
    }
    Ok(out)
}

fn write_points(path: &Path, points: &[Point]) -> Res<()> {
    let col = |f: &dyn Fn(&Point) -> f64| points.iter().map(f).collect::<Vec<f64>>();
    let nan = f64::NAN;
    write_csv(
        path,
        &[
            "v_ac_v",
            "parameter",
            "touchdown_w",
            "takeoff_w",
            "hysteresis_w",
            "status",
            "bounce",
            "cpu_s",
            "steps",
            "runs",
            "cause",
            "model",
        ],
        &[
            &col(&|p| p.v_ac),
            &col(&|p| p.param),
            &col(&|p| p.td.unwrap_or(nan)),
            &col(&|p| p.to.unwrap_or(nan)),
            &col(&|p| p.dp().unwrap_or(nan)),
            &col(&|p| p.status.code()),
            &col(&|p| p.bounce as u8 as f64),
            &col(&|p| p.cpu),
            &col(&|p| p.steps as f64),
            &col(&|p| p.runs as f64),
            &col(&|p| p.cause.map_or(0.0, Cause::code)),
            &col(&|p| p.model.code()),
        ],
    )?;
    Ok(())
}

/// Where a map's time goes: CPU time and steps per status, and the whole map's CPU time scaled
/// to 100 × 100 points on two cores.
fn cost(spec: &MapSpec, points: &[Point], wall: f64) {
    let total: f64 = points.iter().map(|p| p.cpu).sum();
    println!(
        "{:<10} cost: {} points, wall {wall:.1} s, CPU {total:.1} s ({:.1} ms per point); \
         100 × 100 at this CPU per point on 2 cores: {:.1} min",
        spec.name,
        points.len(),
        1e3 * total / points.len() as f64,
        total / points.len() as f64 * 1e4 / 2.0 / 60.0
    );
    for s in [
        Status::Fine,
        Status::Unconverged,
        Status::Undetected,
        Status::Runaway,
    ] {
        let these: Vec<&Point> = points.iter().filter(|p| p.status == s).collect();
        if these.is_empty() {
            continue;
        }
        let cpu: f64 = these.iter().map(|p| p.cpu).sum();
        let steps: usize = these.iter().map(|p| p.steps).sum();
        let runs: usize = these.iter().map(|p| p.runs).sum();
        println!(
            "{:<10}   {s:?}: {} points, CPU {cpu:.1} s ({:.0} % of the map), {:.0} steps per \
             cycle, {:.2} cycles per point",
            "",
            these.len(),
            100.0 * cpu / total.max(1e-300),
            steps as f64 / runs.max(1) as f64,
            runs as f64 / these.len() as f64
        );
    }
    for c in [
        Cause::HitTheDisk,
        Cause::LeftTheTables,
        Cause::StepPace,
        Cause::Other,
    ] {
        let these: Vec<&Point> = points.iter().filter(|p| p.cause == Some(c)).collect();
        if !these.is_empty() {
            println!(
                "{:<10}     runaway, {c:?}: {} points, CPU {:.1} s",
                "",
                these.len(),
                these.iter().map(|p| p.cpu).sum::<f64>()
            );
        }
    }
}

/// Which model gave the points, with their CPU time.
fn models(spec: &MapSpec, points: &[Point]) {
    for m in [Model::Full, Model::QuasiStatic, Model::Shared] {
        let these: Vec<&Point> = points.iter().filter(|p| p.model == m).collect();
        if !these.is_empty() {
            println!(
                "{:<10}   model {m:?}: {} points, CPU {:.1} s",
                spec.name,
                these.len(),
                these.iter().map(|p| p.cpu).sum::<f64>()
            );
        }
    }
}

/// Per map: inside the plausible band, the largest shift of `P_TO` and `P_TD` from their value
/// at `V_ac = 0` on the same row, over converged points (mW).
fn summarise(spec: &MapSpec, points: &[Point]) {
    let inside = |p: &Point| {
        let y = p.param.log10();
        y >= spec.plausible.0 - 1e-9 && y <= spec.plausible.1 + 1e-9
    };
    let fine: Vec<&Point> = points
        .iter()
        .filter(|p| p.status == Status::Fine && inside(p))
        .collect();
    let row0 = |p: &Point| {
        fine.iter()
            .find(|q| q.param == p.param && q.v_ac == 0.0)
            .copied()
    };
    let (mut to_up, mut td_down) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
    for p in &fine {
        if let Some(z) = row0(p) {
            to_up = to_up.max((p.to.unwrap_or(f64::NAN) - z.to.unwrap_or(f64::NAN)) * 1e3);
            td_down = td_down.max((z.td.unwrap_or(f64::NAN) - p.td.unwrap_or(f64::NAN)) * 1e3);
        }
    }
    let count = |s: Status| points.iter().filter(|p| inside(p) && p.status == s).count();
    println!(
        "{:<10} plausible band: {} fine, {} unconverged, {} undetected, {} runaway, {} bounce; \
         largest P_TO rise {:+.3} mW, largest P_TD fall {:+.3} mW (vs V_ac = 0)",
        spec.name,
        fine.len(),
        count(Status::Unconverged),
        count(Status::Undetected),
        count(Status::Runaway),
        points.iter().filter(|p| inside(p) && p.bounce).count(),
        to_up,
        td_down
    );
}

/// A few points again with Radau5 at a hundredfold tighter tolerance than the map's first run.
fn check(setup: &Setup, spec: &MapSpec, points: &[Point]) -> Res<()> {
    let mid = 10f64.powf(0.5 * (spec.plausible.0 + spec.plausible.1));
    for v in [0.0, 0.4, 0.8] {
        let full = Checks {
            full: true,
            method: false,
            quasi_static: false,
        };
        let p = setup.run(spec.axis, mid, v, full, false)?;
        let m = setup.model(spec.axis, mid, v)?;
        let mut o = setup.opts;
        o.keep_series = false;
        o.solver.method = Method::Radau5;
        o.solver = o.solver.with_rtol(o.solver.rtol / 100.0);
        let r = simulate_cycle(&m, &setup.programme, &o);
        let show = |x: Option<f64>| x.map_or("—".to_string(), |x| format!("{:.3}", x * 1e3));
        let (td, to) = match &r {
            Ok(r) => (r.touchdown.map(|d| d.power), r.takeoff.map(|d| d.power)),
            Err(_) => (None, None),
        };
        println!(
            "  check {:<10} {:.3e} at {v:.1} V: map (Auto, rtol 1e-7) TD {} TO {} mW [{:?}]; \
             Radau5 rtol {:.0e}: TD {} TO {} mW{}",
            spec.name,
            mid,
            show(p.td),
            show(p.to),
            p.status,
            o.solver.rtol,
            show(td),
            show(to),
            if r.is_err() { " (failed)" } else { "" }
        );
    }
    let _ = points;
    Ok(())
}

/// Inside the plausible band, the points that did not converge, rerun with Auto and Radau5 at
/// rtol 1e-6 … 1e-9 (displacement tolerance scaled alike): the spread of their take-off against
/// the converged take-off at `V_ac = 0` on the same row. An unconverged point is not counted
/// either way on the map; this says whether any of its runs takes off above `V_ac = 0`.
fn probe(setup: &Setup, spec: &MapSpec, points: &[Point]) -> Res<()> {
    let inside = |p: &Point| {
        let y = p.param.log10();
        y >= spec.plausible.0 - 1e-9 && y <= spec.plausible.1 + 1e-9
    };
    let row0 = |p: &Point| {
        points
            .iter()
            .find(|q| q.param == p.param && q.v_ac == 0.0 && q.status == Status::Fine)
            .and_then(|q| q.to)
    };
    let targets: Vec<&Point> = points
        .iter()
        .filter(|p| p.status == Status::Unconverged && inside(p))
        .collect();
    let methods = [setup.opts.solver.method, Method::Radau5];
    let rtols = [1e-6, 1e-7, 1e-8, 1e-9];
    let mut jobs: Vec<(usize, Method, f64)> = Vec::new();
    for i in 0..targets.len() {
        for m in methods {
            for r in rtols {
                jobs.push((i, m, r));
            }
        }
    }
    let runs: Vec<(usize, Result<Option<f64>, String>)> = jobs
        .par_iter()
        .map(|&(i, method, rtol)| {
            let p = targets[i];
            let mut o = setup.opts;
            o.keep_series = false;
            o.solver.method = method;
            o.solver = o.solver.with_rtol(rtol);
            let r = setup
                .model(spec.axis, p.param, p.v_ac)
                .map_err(|e| e.to_string())
                .and_then(|m| {
                    simulate_cycle(&m, &setup.programme, &o)
                        .map_err(|e| format!("{method:?} at rtol {rtol:.0e}: {:?}", Cause::of(&e)))
                });
            (i, r.map(|c| c.takeoff.map(|d| d.power)))
        })
        .collect();
    let mut largest = f64::NEG_INFINITY;
    for (i, p) in targets.iter().enumerate() {
        let mine: Vec<&Result<Option<f64>, String>> = runs
            .iter()
            .filter(|(j, _)| *j == i)
            .map(|(_, r)| r)
            .collect();
        let to: Vec<f64> = mine
            .iter()
            .filter_map(|r| r.as_ref().ok().copied().flatten())
            .collect();
        let none = mine.iter().filter(|r| matches!(r, Ok(None))).count();
        let failed: Vec<&str> = mine
            .iter()
            .filter_map(|r| r.as_ref().err().map(String::as_str))
            .collect();
        let lo = to.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = to.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let zero = row0(p);
        let rise = zero.map(|z| hi - z);
        if let Some(r) = rise.filter(|r| r.is_finite()) {
            largest = largest.max(r);
        }
        println!(
            "  probe {:<10} {:.3e} at {:.3} V: P_TO {}…{} mW over {} runs ({} without take-off, \
             {} failed{}); V = 0: {} mW; highest minus V = 0: {} mW",
            spec.name,
            p.param,
            p.v_ac,
            fmt_mw(lo),
            fmt_mw(hi),
            to.len(),
            none,
            failed.len(),
            if failed.is_empty() {
                String::new()
            } else {
                format!(": {}", failed.join("; "))
            },
            zero.map_or("—".into(), fmt_mw),
            rise.map_or("—".into(), |r| format!("{:+.3}", r * 1e3)),
        );
    }
    println!(
        "{:<10} probe: {} unconverged points in the plausible band, {} runs; largest P_TO rise \
         over V = 0 in any run: {} mW",
        spec.name,
        targets.len(),
        runs.len(),
        if largest.is_finite() {
            format!("{:+.3}", largest * 1e3)
        } else {
            "—".into()
        }
    );
    Ok(())
}

fn fmt_mw(x: f64) -> String {
    if x.is_finite() {
        format!("{:.3}", x * 1e3)
    } else {
        "—".into()
    }
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().collect();
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let n: usize = value("--grid").map_or(Ok(6), |s| s.parse())?;
    if !(2..=400).contains(&n) {
        return Err("--grid must be between 2 and 400".into());
    }
    let out = value("--out").unwrap_or_else(|| "out/maps".into());
    let out = Path::new(&out);
    std::fs::create_dir_all(out)?;
    let names = value("--maps").unwrap_or_else(|| "freq,zeta,lag_rigid,lag_bulge".into());
    // `--replot DIR`: draw the maps again from the CSV files of an earlier run, computing
    // nothing.
    if let Some(dir) = value("--replot") {
        for spec in MAPS
            .iter()
            .filter(|s| names.split(',').any(|x| x == s.name))
        {
            let points = read_points(&Path::new(&dir).join(format!("{}.csv", spec.name)))?;
            let n = (points.len() as f64).sqrt().round() as usize;
            if n * n != points.len() {
                return Err(format!("{}: not a square map", spec.name).into());
            }
            draw_map(&out.join(format!("{}.svg", spec.name)), spec, &points, n)?;
            println!("{}: {} ({n} × {n}), drawn again", spec.name, spec.title);
        }
        return Ok(());
    }
    let scene =
        Scene::from_path(value("--scene").unwrap_or_else(|| "scenes/paper_bulge.toml".into()))?;
    let setup = Setup::from_scene(&scene)?;
    let checks = Checks {
        full: args.iter().any(|a| a == "--full-check"),
        method: !args.iter().any(|a| a == "--no-method-check"),
        quasi_static: args.iter().any(|a| a == "--quasi-static"),
    };
    let head = format!(
        "# {} ({} × {} grid, {} threads)",
        scene.name,
        n,
        n,
        rayon::current_num_threads()
    );
    match setup.bulge {
        Some(b) => println!(
            "{head}; scene bulge {:.3e} kg, {:.3e} N/m ({:.1} MHz), ζ = {}",
            b.mass,
            b.stiffness,
            b.frequency() * 1e-6,
            b.zeta
        ),
        None => println!("{head}; rigid scene"),
    }
    for spec in MAPS
        .iter()
        .filter(|s| names.split(',').any(|x| x == s.name))
    {
        // A map on a scene of its own (`lag_paper`) loads it; the others share `--scene`'s.
        let own = match spec.scene {
            Some(path) => {
                let scene = Scene::from_path(path)?;
                println!("{:<10} scene {} ({path})", spec.name, scene.name);
                Some(Setup::from_scene(&scene)?)
            }
            None => None,
        };
        let setup = own.as_ref().unwrap_or(&setup);
        let clock = Instant::now();
        let points = run_map(setup, spec, n, checks)?;
        let wall = clock.elapsed().as_secs_f64();
        cost(spec, &points, wall);
        models(spec, &points);
        draw_map(&out.join(format!("{}.svg", spec.name)), spec, &points, n)?;
        write_points(&out.join(format!("{}.csv", spec.name)), &points)?;
        println!(
            "{:<10} {} cycles pairs in {wall:.1} s",
            spec.name,
            points.len()
        );
        summarise(spec, &points);
        if args.iter().any(|a| a == "--check") {
            check(setup, spec, &points)?;
        }
        if args.iter().any(|a| a == "--probe") {
            probe(setup, spec, &points)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a 3 × 3 lag map of the rigid structure, the shortest lag at zero AC touches down within
    /// the detector's delay (2 × ramp × window) above the static touchdown power.
    #[test]
    fn tiny_rigid_lag_map_matches_statics() -> Res<()> {
        use hdi_tribology::analysis::{touchdown_power, StaticOptions};
        let scene = Scene::from_path(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenes/paper_bulge.toml"
        ))?;
        let setup = Setup::from_scene(&scene)?;
        let spec = MAPS[2];
        let checks = Checks {
            full: false,
            method: true,
            quasi_static: false,
        };
        let points = run_map(&setup, &spec, 3, checks)?;
        assert_eq!(points.len(), 9);
        // A converged point had all three runs: the method check ran and agreed.
        assert!(points
            .iter()
            .filter(|p| p.status == Status::Fine)
            .all(|p| p.runs == 3));
        let p = points[0];
        assert_eq!((p.v_ac, p.param), (0.0, 1e-10));
        let m = setup.model(spec.axis, p.param, 0.0)?;
        let stat = touchdown_power(&m, &StaticOptions::new(scene.detector.contact_threshold_n))?;
        let td = p.td.ok_or("no touchdown")?;
        let bias = 2.0 * 5e-3 / 1e-3 * scene.detector.window_s;
        assert!(
            td >= stat.power - 1e-6 && td <= stat.power + bias,
            "{td} vs {}",
            stat.power
        );
        let dir = tempfile::tempdir()?;
        let svg = dir.path().join("m.svg");
        draw_map(&svg, &spec, &points, 3)?;
        assert!(std::fs::metadata(&svg)?.len() > 1000);
        Ok(())
    }

    /// A map is the same to the bit on one thread and on two: every point's values come from
    /// its own runs (here the `freq` map with the quasi-static bulge where it holds, so both
    /// models and the fallback run).
    #[test]
    fn the_map_does_not_depend_on_the_thread_count() -> Res<()> {
        let scene = Scene::from_path(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenes/paper_bulge.toml"
        ))?;
        let setup = Setup::from_scene(&scene)?;
        let spec = MAPS[0];
        let checks = Checks {
            full: false,
            method: true,
            quasi_static: true,
        };
        let on = |threads: usize| -> Res<Vec<Point>> {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()?;
            pool.install(|| run_map(&setup, &spec, 3, checks).map_err(|e| e.to_string()))
                .map_err(Into::into)
        };
        let (one, two) = (on(1)?, on(2)?);
        // Everything but the CPU time.
        let key = |p: &Point| {
            (
                (p.v_ac.to_bits(), p.param.to_bits()),
                (p.td.map(f64::to_bits), p.to.map(f64::to_bits)),
                (p.status, p.cause, p.bounce),
                (p.steps, p.runs, p.model),
            )
        };
        let (a, b): (Vec<_>, Vec<_>) =
            (one.iter().map(key).collect(), two.iter().map(key).collect());
        assert_eq!(a, b);
        assert!(one.iter().any(|p| p.model == Model::QuasiStatic));
        assert!(one.iter().any(|p| p.model == Model::Full));
        Ok(())
    }
}
