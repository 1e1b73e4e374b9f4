"""The same scene through Python and through the `hdi` command line gives the same numbers, bit
for bit (the CLI prints JSON with round-trip floats, so `==` on floats is the test)."""

import numpy as np
import pytest

import hdi_tribology as hdi
from conftest import REPO

SCENE_FILE = str(REPO / "scenes" / "rough_disk.toml")


def test_forces(paper_model, hdi_cli):
    gaps_nm = [0.25, 0.5, 1.0, 2.5, 7.0]
    cli = hdi_cli("forces", "--paper", "--gaps-nm", ",".join(map(str, gaps_nm)),
                  "--protrusion-nm", "1.5")
    py = hdi.forces(paper_model, np.array(gaps_nm), protrusion_nm=1.5)
    assert [row["in_table_range"] for row in cli] == py["in_table_range"].tolist()
    for k_cli, k_py in [("d", "d_m"), ("intermolecular", "intermolecular_n"),
                        ("contact", "contact_n"), ("electrostatic", "electrostatic_n"),
                        ("electrostatic_per_volt2", "electrostatic_per_volt2_n_per_v2"),
                        ("other", "other_n"), ("real_contact_area", "real_contact_area_m2"),
                        ("total", "total_n")]:
        assert [row[k_cli] for row in cli] == py[k_py].tolist(), k_cli


def test_static(paper_model, hdi_cli):
    cli = hdi_cli("static", "--paper")
    h = hdi.static_hysteresis(paper_model)
    assert (cli["touchdown_power"], cli["takeoff_power"], cli["hysteresis"]) == \
        (h.touchdown.power_w, h.takeoff.power_w, h.hysteresis_w)
    assert cli["pull_in_voltage"] == hdi.pull_in_voltage(paper_model).voltage_v
    c = hdi.s_curve(paper_model)
    assert [(f["power"], f["d"]) for f in cli["folds"]] == \
        [(f["power_w"], f["d_m"]) for f in c["folds"]]


def _cycle_tuple(c):
    return (c.v_ac_v, c.touchdown.power_w if c.touchdown else None,
            c.takeoff.power_w if c.takeoff else None, c.hysteresis_w,
            c.mean_temperature_rise_k, c.steps, c.flags)


def _cli_tuple(row):
    return (row["v_ac"], row["touchdown_power"], row["takeoff_power"], row["hysteresis"],
            row["mean_temperature_rise"], row["steps"], row["flags"])


def test_cycle_of_a_scene_file(hdi_cli):
    cli = hdi_cli("cycle", SCENE_FILE, "--v-ac", "0.4", "--triggered", "--no-refine")
    r = hdi.simulate_cycle(hdi.Scene.from_file(SCENE_FILE), 0.4, triggered=True, series=False)
    assert _cycle_tuple(r["cycle"]) == _cli_tuple(cli)


def test_cycle_series_against_csv(tmp_path, paper_model, hdi_cli):
    csv = tmp_path / "cycle.csv"
    hdi_cli("cycle", "--paper", "--csv", str(csv), "--no-refine")
    table = np.genfromtxt(csv, delimiter=",", names=True)
    r = hdi.simulate_cycle(paper_model)
    # the CSV's columns are the series' keys, printed at round-trip precision
    assert sorted(table.dtype.names) == sorted(k for k in r if k not in ("cycle", "touchdown", "takeoff"))
    for k in table.dtype.names:
        assert np.array_equal(table[k], r[k], equal_nan=True), k


def test_sweeps(paper_model, hdi_cli):
    amps = [0.0, 0.35, 0.7]
    cli = hdi_cli("sweep", "--paper", "--v-ac", ",".join(map(str, amps)), "--method", "rodas5p",
                  "--rtol", "1e-6", "--no-refine")
    py = hdi.ac_sweep(paper_model, amps, method="rodas5p", rtol=1e-6)
    assert [_cli_tuple(r) for r in cli] == [_cycle_tuple(c) for c in py]
    assert all(r["status"] == "unchecked" for r in cli)


def test_refined_sweep(paper_model, hdi_cli):
    cli = hdi_cli("sweep", "--paper", "--v-ac", "0,0.7,0.9", "--refine-mw", "0.06",
                  "--refine-k", "0.1", "--max-runs", "3")
    py = hdi.ac_sweep_refined(paper_model, 0.06, [0.0, 0.7, 0.9], temperature_tol_k=0.1,
                              max_runs=3)
    for r_cli, r in zip(cli, py):
        # the CLI prints an infinite power change (a detection that came or went) as null
        change = r.power_change_w if np.isfinite(r.power_change_w) else None
        assert (r_cli["rtol"], r_cli["atol_m"], r_cli["power_change"],
                r_cli["temperature_change"], r_cli["status"], r_cli["flags"], r_cli["runs"],
                r_cli["steps"]) == \
            (r.rtol, r.atol_m, change, r.temperature_change_k, r.status, r.flags, r.runs,
             r.steps)
        # steps: the CLI counts those of every run (compared above as r.steps)
        assert _cli_tuple(r_cli)[:5] == _cycle_tuple(r.cycle)[:5]
    assert len(cli) == len(py) == 3


def test_refined_sweep_with_three_agreeing_runs(paper_model, hdi_cli):
    cli = hdi_cli("sweep", "--paper", "--v-ac", "0,0.5", "--refine-mw", "0.06", "--agree", "3")
    py = hdi.ac_sweep_refined(paper_model, 0.06, [0.0, 0.5], max_runs=5, agreeing_runs=3)
    pair = hdi.ac_sweep_refined(paper_model, 0.06, [0.0, 0.5], max_runs=5)
    for r_cli, r, p in zip(cli, py, pair):
        assert (r_cli["rtol"], r_cli["runs"], r_cli["status"]) == (r.rtol, r.runs, r.status)
        assert r.status == "converged" and r.runs >= 3 and r.runs > p.runs
    with pytest.raises(ValueError, match="agreeing_runs"):
        hdi.ac_sweep_refined(paper_model, 0.06, [0.0], max_runs=3, agreeing_runs=4)


def test_calibration(paper_model, hdi_cli):
    cli = hdi_cli("calibrate", "--paper", "--detector", "ae", "--dither-v", "0.5")
    c = hdi.calibrate(paper_model, detector="ae", dither_v=0.5)
    assert (cli["detector"], cli["touchdown_power"], cli["takeoff_power"], cli["set_power"],
            cli["clearance"], cli["contrast"], cli["levels"], cli["simulated_time"]) == \
        (c.detector, c.touchdown_power_w, c.takeoff_power_w, c.set_power_w, c.clearance_m,
         c.contrast, c.levels, c.simulated_time_s)
