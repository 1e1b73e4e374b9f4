//! `hdi bearing`: the air bearing of a slider's geometry: attitude, stiffness, damping, the
//! force–spacing curve, and the pressure map.

use std::path::PathBuf;

use hdi_tribology::bearing::{solve_attitude, AttitudeOptions, BearingSpec, Equilibrium};
use hdi_tribology::report::CsvTable;
use serde::Serialize;

use crate::common::{self, CliError, Output};

/// The slider's attitude on its air bearing (fly height, pitch, roll) and what follows from it,
/// JSON on standard output, each key with its unit. GEOMETRY is a bearing file: TOML, JSON or
/// the text format (any other extension).
#[derive(clap::Args)]
pub struct Args {
    /// The bearing file.
    #[arg(value_name = "GEOMETRY")]
    geometry: PathBuf,
    /// Directory to write the pressure map (pressure_map.svg) and the pressure field
    /// (pressure.csv) into.
    #[arg(long, value_name = "DIR", conflicts_with = "svg")]
    out: Option<PathBuf>,
    /// Write only the pressure map, as SVG, to this file.
    #[arg(long, value_name = "FILE")]
    svg: Option<PathBuf>,
    /// Control volumes along each side, instead of the file's grid.
    #[arg(long, value_name = "N")]
    cells: Option<usize>,
}

#[derive(Serialize)]
struct Level {
    cells: [usize; 2],
    newton_steps: usize,
    pressure_newton_steps: usize,
    krylov_iterations: usize,
    relative_imbalance: f64,
}

#[derive(Serialize)]
struct Matrix {
    force_per_fly_height: f64,
    force_per_pitch: f64,
    force_per_roll: f64,
    pitch_moment_per_fly_height: f64,
    pitch_moment_per_pitch: f64,
    pitch_moment_per_roll: f64,
    roll_moment_per_fly_height: f64,
    roll_moment_per_pitch: f64,
    roll_moment_per_roll: f64,
}

impl Matrix {
    fn new(m: [[f64; 3]; 3]) -> Self {
        Matrix {
            force_per_fly_height: m[0][0],
            force_per_pitch: m[0][1],
            force_per_roll: m[0][2],
            pitch_moment_per_fly_height: m[1][0],
            pitch_moment_per_pitch: m[1][1],
            pitch_moment_per_roll: m[1][2],
            roll_moment_per_fly_height: m[2][0],
            roll_moment_per_pitch: m[2][1],
            roll_moment_per_roll: m[2][2],
        }
    }
}

#[derive(Serialize)]
struct Point {
    bulge_spacing_nm: f64,
    load_mn: f64,
}

#[derive(Serialize)]
struct Report {
    fly_height_nm: f64,
    pitch_urad: f64,
    roll_urad: f64,
    trailing_edge_spacing_nm: f64,
    bulge_spacing_nm: f64,
    min_spacing_nm: f64,
    load_mn: f64,
    pitch_moment_un_m: f64,
    roll_moment_un_m: f64,
    bearing_number_at_10_nm: f64,
    /// SI: N/m, N/rad; N m/m, N m/rad.
    stiffness_si: Matrix,
    /// SI: N s/m, N s/rad; N m s/m, N m s/rad.
    damping_si: Matrix,
    force_spacing: Vec<Point>,
    convergence: Vec<Level>,
}

/// Offsets of the fly height for the force–spacing curve, as fractions of the smallest spacing
/// (below) and of the bulge's spacing (above).
const BELOW: [f64; 3] = [-0.5, -0.3, -0.15];
const ABOVE: [f64; 5] = [0.0, 0.15, 0.3, 0.6, 1.0];

fn report(eq: &Equilibrium) -> Result<Report, CliError> {
    let a = eq.attitude;
    let min = eq.min_spacing();
    let bulge = eq.bulge_spacing();
    let offsets: Vec<f64> = BELOW
        .iter()
        .map(|f| f * min)
        .chain(ABOVE.iter().map(|f| f * bulge))
        .collect();
    let curve = eq.force_spacing(&offsets)?;
    Ok(Report {
        fly_height_nm: a.fly_height * 1e9,
        pitch_urad: a.pitch * 1e6,
        roll_urad: a.roll * 1e6,
        trailing_edge_spacing_nm: eq.trailing_edge_spacing() * 1e9,
        bulge_spacing_nm: bulge * 1e9,
        min_spacing_nm: min * 1e9,
        load_mn: eq.loads[0] * 1e3,
        pitch_moment_un_m: eq.loads[1] * 1e6,
        roll_moment_un_m: eq.loads[2] * 1e6,
        bearing_number_at_10_nm: eq.bearing_number(),
        stiffness_si: Matrix::new(eq.stiffness()),
        damping_si: Matrix::new(eq.damping()?),
        force_spacing: curve
            .iter()
            .map(|&(s, f)| Point {
                bulge_spacing_nm: s * 1e9,
                load_mn: f * 1e3,
            })
            .collect(),
        convergence: eq
            .levels
            .iter()
            .map(|l| Level {
                cells: [l.cells.0, l.cells.1],
                newton_steps: l.iterations,
                pressure_newton_steps: l.pressure_iterations,
                krylov_iterations: l.krylov_iterations,
                relative_imbalance: l.imbalance,
            })
            .collect(),
    })
}

/// The pressure field as CSV, one row per control volume, through the crate's one CSV writer
/// (a missing value an empty field).
fn pressure_csv(eq: &Equilibrium) -> Result<String, CliError> {
    let r = &eq.reynolds;
    let (nx, _) = r.size();
    let cells = || {
        r.grid.yc.iter().enumerate().flat_map(move |(j, &y)| {
            r.grid
                .xc
                .iter()
                .enumerate()
                .map(move |(i, &x)| (i, j, x, y))
        })
    };
    Ok(CsvTable::new()
        .real("x_um", cells().map(|(_, _, x, _)| x * 1e6))
        .real("y_um", cells().map(|(_, _, _, y)| y * 1e6))
        .real(
            "pressure_over_ambient",
            cells().map(|(i, j, _, _)| eq.pressure[j * nx + i]),
        )
        .to_csv_string()?)
}

pub fn run(a: Args) -> Result<(), CliError> {
    let mut spec = BearingSpec::from_path(&a.geometry)?;
    if let Some(n) = a.cells {
        spec.grid.nx = n;
        spec.grid.ny = n;
    }
    let bearing = spec.build()?;
    // Check the outputs before the computation.
    let files = match (&a.out, &a.svg) {
        (Some(dir), _) => {
            if !dir.is_dir() {
                return Err(CliError::Failed(format!(
                    "--out {}: not a directory",
                    dir.display()
                )));
            }
            Some((
                Output::prepare(&dir.join("pressure_map.svg"), "--out")?,
                Some(Output::prepare(&dir.join("pressure.csv"), "--out")?),
            ))
        }
        (None, Some(f)) => Some((Output::prepare(f, "--svg")?, None)),
        (None, None) => None,
    };
    let progress = common::Progress::spinner("bearing: attitude, stiffness and damping");
    let eq = solve_attitude(&bearing, &AttitudeOptions::default())?;
    let rep = report(&eq)?;
    drop(progress);
    if let Some((svg, csv)) = files {
        svg.write(eq.pressure_map_svg().as_bytes())?;
        if let Some(csv) = csv {
            csv.write(pressure_csv(&eq)?.as_bytes())?;
        }
    }
    common::print_json(&rep)
}
