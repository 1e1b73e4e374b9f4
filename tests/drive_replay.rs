//! Replaying a command file through the drive: the CSV written, the same bytes for the same seed,
//! and typed errors for bad files.

use hdi_tribology::drive::{
    read_commands, replay, scene_zone, DriveOptions, Plant, SENSOR_COLUMNS,
};
use hdi_tribology::scene::Scene;
use hdi_tribology::Error;

const COMMANDS: &str = "time_s, heater_mw, voltage_dc_v, voltage_ac_v, ac_frequency_khz
0, 60, 0, 0, 0
0.002, 70, 0, 0.5, 10.5
0.004, 80, 0.2, 0, 0
0.006, 80, 0, 0, 0
";

fn run(seed: u64) -> String {
    let scene = Scene::paper();
    let plant = Plant::new(
        &scene,
        &scene_zone(&scene, 0.025).unwrap(),
        seed,
        DriveOptions::default(),
    )
    .unwrap();
    let rows = read_commands(COMMANDS.as_bytes(), "commands.csv").unwrap();
    let mut out = Vec::new();
    let s = replay(&plant, &rows, 50e-6, &mut out).unwrap();
    assert_eq!(s.periods, 120);
    String::from_utf8(out).unwrap()
}

#[test]
fn replay_writes_one_row_per_period_and_repeats_bit_for_bit() {
    let a = run(3);
    assert_eq!(a, run(3));
    assert_ne!(a, run(4));
    let mut lines = a.lines();
    assert_eq!(lines.next().unwrap(), SENSOR_COLUMNS.join(","));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 120);
    // Period 41 starts at 2 ms: the second command is in force.
    assert_eq!(rows[39][1], 60.0);
    assert_eq!(rows[40][1], 70.0);
    // At 80 mW the head is in contact (static touchdown 74.3 mW): a large mean contact force.
    assert!(rows[119][8] > 50.0, "contact force {} µN", rows[119][8]);
    assert!(rows[30][8] < 1.0);
}

#[test]
fn bad_command_files_name_line_and_column() {
    let cases = [
        (
            "time_s,heater_mw,voltage_dc_v\n0.1,60,0\n0.2,60,0\n",
            "line 2, time_s",
        ),
        (
            "time_s,heater_mw,voltage_dc_v\n0,60,0\n0,60,0\n",
            "line 3, time_s",
        ),
        (
            "time_s,heater_mw,voltage_dc_v\n0,60,0\n0.1,abc,0\n",
            "line 3",
        ),
        (
            "time_s,heater_mw,voltage_dc_v\n0,60,0\n0.1,60,0,1,-2\n",
            "line 3",
        ),
        (
            "time_s,heater_mw\n0,60\n0.1,60\n",
            "line 1: the column voltage_dc_v (V) is missing",
        ),
        (
            "time_s,heater_mw,voltage_dc_v\n0,60,0\n",
            "at least two rows",
        ),
    ];
    for (text, want) in cases {
        let e = read_commands(text.as_bytes(), "c.csv").unwrap_err();
        assert!(matches!(e, Error::InvalidInput { .. }), "{e}");
        assert!(e.to_string().contains(want), "{text:?}: {e}");
    }
}
