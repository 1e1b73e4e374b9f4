//! One attitude solve of the example slider's air bearing, timed: the fly height, pitch, roll
//! and loads at the equilibrium, the stiffness and damping, how the solve went on each grid,
//! and the CPU time of the solving thread.
//!
//! ```text
//! cargo run --release --example bearing_attitude -- 257 [BEARING_FILE]
//! ```
//!
//! The first argument is the control volumes a side (default 257), the second a bearing file
//! (default `scenes/bearing/two_rail_taper_flat.toml`). This is the program that the air
//! bearing's section of docs/benchmarks.md times with `farm-bench`.

#[path = "common/timing.rs"]
mod timing;

use hdi_tribology::bearing::{solve_attitude, AttitudeOptions, BearingSpec};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let cells: usize = match args.next() {
        Some(a) => a.parse().map_err(|e| format!("cells {a:?}: {e}"))?,
        None => 257,
    };
    let path = args.next().unwrap_or_else(|| {
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenes/bearing/two_rail_taper_flat.toml"
        )
        .to_string()
    });
    let mut spec = BearingSpec::from_path(&path)?;
    spec.grid.nx = cells;
    spec.grid.ny = cells;
    let bearing = spec.build()?;

    let cpu0 = timing::thread_cpu_seconds();
    let eq = solve_attitude(&bearing, &AttitudeOptions::default())?;
    let cpu1 = timing::thread_cpu_seconds();
    let c = eq.damping()?;
    let cpu2 = timing::thread_cpu_seconds();

    let a = eq.attitude;
    println!("cells {cells}x{cells}");
    println!("fly_height_nm {:.6}", a.fly_height * 1e9);
    println!("pitch_urad {:.6}", a.pitch * 1e6);
    println!("roll_urad {:.6e}", a.roll * 1e6);
    println!("load_mn {:.9}", eq.loads[0] * 1e3);
    println!("pitch_moment_un_m {:.6e}", eq.loads[1] * 1e6);
    println!("roll_moment_un_m {:.6e}", eq.loads[2] * 1e6);
    let k = eq.stiffness();
    for (name, m) in [("stiffness", k), ("damping", c)] {
        for (i, row) in m.iter().enumerate() {
            println!("{name}[{i}] {:.7e} {:.7e} {:.7e}", row[0], row[1], row[2]);
        }
    }
    for l in &eq.levels {
        println!(
            "level {}x{}: attitude steps {}, pressure Newton steps {}, GMRES iterations {}, \
             imbalance {:.2e}",
            l.cells.0,
            l.cells.1,
            l.iterations,
            l.pressure_iterations,
            l.krylov_iterations,
            l.imbalance
        );
    }
    if let (Some(t0), Some(t1), Some(t2)) = (cpu0, cpu1, cpu2) {
        println!("attitude_cpu_s {:.4}", t1 - t0);
        println!("damping_cpu_s {:.4}", t2 - t1);
    }
    Ok(())
}
