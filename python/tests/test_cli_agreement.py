"""The same scene through Python and through the `hdi` command line gives the same results, bit
for bit: both are the crate's one representation of each result (its serde form), so a Python
result's `to_dict()` is the JSON object the CLI prints (the CLI prints round-trip floats, so
`==` on floats is the test). Only wall-clock times differ between two runs."""

import numpy as np
import pytest

import hdi_tribology as hdi
from conftest import REPO

SCENE_FILE = str(REPO / "scenes" / "rough_disk.toml")


def _no_wall(d):
    """`d` without its wall-clock times, which no two runs share."""
    if isinstance(d, dict):
        return {k: _no_wall(v) for k, v in d.items() if "wall_seconds" not in k}
    if isinstance(d, list):
        return [_no_wall(v) for v in d]
    return d


def _without(d, keys):
    return {k: v for k, v in d.items() if k not in keys}


def test_forces(paper_model, hdi_cli):
    gaps_nm = [0.25, 0.5, 1.0, 2.5, 7.0]
    cli = hdi_cli("forces", "--paper", "--gaps-nm", ",".join(map(str, gaps_nm)),
                  "--protrusion-nm", "1.5")
    py = hdi.forces(paper_model, gaps_nm, protrusion_nm=1.5)
    # the same keys, the same values
    assert sorted(cli[0]) == sorted(py)
    for k in py:
        assert [row[k] for row in cli] == py[k].tolist(), k


def test_static(paper_model, hdi_cli):
    cli = hdi_cli("static", "--paper")
    h = hdi.static_hysteresis(paper_model)
    d = h.to_dict()
    # Python's equilibria add their coordinates `q` and `stable` (the CLI prints neither)
    for t in ("touchdown", "takeoff"):
        d[t]["at"] = _without(d[t]["at"], {"q", "stable"})
    assert _without(cli, {"pull_in", "folds"}) == d
    assert cli["pull_in"] == hdi.pull_in_voltage(paper_model).to_dict()
    assert cli["folds"] == hdi.s_curve(paper_model)["folds"]
    assert h.status == "converged" and h.scene == "paper"


def test_cycle_of_a_scene_file(hdi_cli):
    cli = hdi_cli("cycle", SCENE_FILE, "--v-ac", "0.4", "--triggered", "--no-refine")
    r = hdi.simulate_cycle(hdi.Scene.from_file(SCENE_FILE), 0.4, triggered=True, series=False)
    assert _no_wall(r["cycle"].to_dict()) == _no_wall(cli)
    assert cli["programme"] == "triggered" and cli["v_ac_v"] == 0.4


def test_cycle_series_against_csv(tmp_path, paper_model, hdi_cli):
    csv = tmp_path / "cycle.csv"
    hdi_cli("cycle", "--paper", "--csv", str(csv), "--no-refine")
    table = np.genfromtxt(csv, delimiter=",", names=True)
    r = hdi.simulate_cycle(paper_model)
    # the CSV's columns are the series' keys, printed at round-trip precision
    assert sorted(table.dtype.names) == sorted(k for k in r if k not in ("cycle", "touchdown", "takeoff"))
    for k in table.dtype.names:
        assert np.array_equal(table[k], r[k], equal_nan=True), k
    # the indicator is missing until the detector's window has filled: NaN in Python, an empty
    # field in the file (never the text NaN), read back as NaN
    text = csv.read_text()
    assert "NaN" not in text and text.splitlines()[1].endswith(",")
    assert np.isnan(r["indicator_n"][0]) and np.isnan(table["indicator_n"][0])


def test_sweeps(paper_model, hdi_cli):
    amps = [0.0, 0.35, 0.7]
    cli = hdi_cli("sweep", "--paper", "--v-ac", ",".join(map(str, amps)), "--method", "rodas5p",
                  "--rtol", "1e-6", "--no-refine")
    py = hdi.ac_sweep(paper_model, amps, method="rodas5p", rtol=1e-6)
    assert [_no_wall(c.to_dict()) for c in py] == _no_wall(cli)
    assert all(r["status"] == "unchecked" for r in cli)
    assert [c.v_ac_v for c in py] == amps


def test_refined_sweep(paper_model, hdi_cli):
    cli = hdi_cli("sweep", "--paper", "--v-ac", "0,0.7,0.9", "--refine-mw", "0.06",
                  "--refine-k", "0.1", "--max-runs", "3")
    py = hdi.ac_sweep_refined(paper_model, 0.06, [0.0, 0.7, 0.9], temperature_tol_k=0.1,
                              max_runs=3)
    assert [_no_wall(c.to_dict()) for c in py] == _no_wall(cli)
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
    assert _no_wall(c.to_dict()) == _no_wall(cli)
    # the detector comes back as it was given
    assert c.detector == "ae" and c.status in ("complete", "incomplete")
