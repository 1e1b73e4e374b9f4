"""Every result class compares by value, pickles back equal and has `to_dict`; results whose
shape is a table become pandas DataFrames (`to_dataframe`, pandas optional); values typed come
back as typed."""

import math
import pickle
import sys

import numpy as np
import pytest

import hdi_tribology as hdi
from conftest import REPO

BEARING = REPO / "scenes" / "bearing" / "two_rail_taper_flat.toml"


def _round_trip(x):
    back = pickle.loads(pickle.dumps(x))
    assert back == x and type(back) is type(x)
    assert back is not x
    return back


def test_every_result_class_pickles_back_equal(paper_model):
    h = hdi.static_hysteresis(paper_model)
    c = hdi.ac_sweep(paper_model, [0.0], threads=1)[0]
    r = hdi.linear_response(paper_model, 60.0)
    cal = hdi.calibrate(paper_model, start_mw=70.0, step_mw=1.0, max_mw=80.0)
    sensors = hdi.Drive(hdi.Scene.paper(), flat_disk=True).step(60.0)
    results = [
        h, h.touchdown, h.touchdown.at,
        hdi.pull_in_voltage(paper_model),
        c, c.touchdown,
        hdi.flying_equilibrium(paper_model, 60.0),
        r.modes[0],
        cal,
        sensors, sensors.truth,
    ]
    classes = {type(x) for x in results}
    assert classes == {hdi.StaticHysteresis, hdi.Transition, hdi.Equilibrium, hdi.PullIn,
                       hdi.Cycle, hdi.Detection, hdi.Mode, hdi.Calibration, hdi.Sensors,
                       type(sensors.truth)}
    for x in results:
        back = _round_trip(x)
        assert back.to_dict() == x.to_dict()
    # and a result of other numbers is not equal
    assert hdi.ac_sweep(paper_model, [0.3], threads=1)[0] != c


def test_linear_response_pickles_every_number(paper_model):
    r = hdi.linear_response(paper_model, 60.0)
    back = _round_trip(r)
    assert back.to_dict() == r.to_dict()
    # the state-space matrices came back too: the transfer function is the same to the bit
    w = np.array([0.0, 1e5, 2 * np.pi * 21e3, 1e7])
    assert np.array_equal(back.transfer(w), r.transfer(w))
    assert back.eigenvalues == r.eigenvalues and back.dither_amplitude_m == r.dither_amplitude_m
    assert hdi.linear_response(paper_model, 65.0) != r
    assert r != r.to_dict()


def test_air_bearing_pickles_and_converts():
    b = hdi.bearing(BEARING, cells=17)
    back = _round_trip(b)
    d = b.to_dict()
    assert back.to_dict() == d
    assert np.array_equal(back.pressure_pa, b.pressure_pa) and back.cells == b.cells
    assert d["fly_height_nm"] == b.fly_height_nm and d["converged"] == b.converged
    assert np.array_equal(np.array(d["pressure_pa"]), b.pressure_pa)
    assert d["convergence"] == b.convergence
    assert hdi.bearing(BEARING, cells=17, rpm=10000.0) != b


def test_values_come_back_as_typed(paper_model, paper_scene):
    # an amplitude, a gap in nm, a field in an engineering unit, a tolerance scaled with rtol
    assert [c.v_ac_v for c in hdi.ac_sweep(paper_model, [0.3, 0.7], threads=1)] == [0.3, 0.7]
    assert hdi.forces(paper_model, [1.1, 0.3])["d_m"].tolist() == [1.1e-9, 0.3e-9]
    assert paper_scene["surface.height_sigma_nm"] == 0.7
    s = paper_scene.with_values({"contact.asperity_radius_nm": 100})
    assert s["contact.asperity_radius_m"] == 1e-7
    c = hdi.simulate_cycle(paper_model, rtol=7e-7, series=False)["cycle"]
    assert (c.rtol, c.atol_m) == (7e-7, 7e-15)
    cal = hdi.calibrate(paper_model, start_mw=60.1, step_mw=0.1, max_mw=90.0, margin_mw=0.3)
    up = [s["power_w"] for s in cal.steps if not s["descending"]]
    assert up == [float(f"{601 + k}e-4") for k in range(len(up))]
    assert cal.touchdown_power_w == up[-1]
    assert cal.set_power_w == float(f"{round(up[-1] * 1e4) - 3}e-4")


def test_sweeps_and_series_as_dataframes(paper_model):
    pd = pytest.importorskip("pandas")
    cycles = hdi.ac_sweep(paper_model, [0.0, 0.3], threads=1)
    df = hdi.to_dataframe(cycles)
    assert isinstance(df, pd.DataFrame) and len(df) == 2
    assert df["v_ac_v"].tolist() == [0.0, 0.3]
    assert df["touchdown_power_w"].tolist() == [c.touchdown.power_w for c in cycles]
    assert df["stats_accepted"].tolist() == [c.steps for c in cycles]
    assert df["flags"].tolist() == [c.flags for c in cycles]
    assert list(hdi.to_dataframe(cycles[0]).columns) == list(df.columns)

    r = hdi.simulate_cycle(paper_model, 0.6)
    s = hdi.to_dataframe(r)
    arrays = [k for k, v in r.items() if isinstance(v, np.ndarray)]
    assert list(s.columns) == arrays and len(s) == len(r["t_s"])
    for k in arrays:
        assert np.array_equal(s[k].to_numpy(), r[k], equal_nan=True), k
    assert math.isnan(s["indicator_n"].iloc[0])
    assert s.attrs["cycle"] == r["cycle"] and s.attrs["touchdown"] == r["touchdown"]

    # a record that does not exist leaves its columns missing
    cal = hdi.calibrate(paper_model, start_mw=70.0, step_mw=1.0, max_mw=80.0,
                        find_takeoff=False)
    one = hdi.to_dataframe([cal])
    assert cal.takeoff_power_w is None and one["takeoff_power_w"].isna().all()
    steps = hdi.to_dataframe(cal.steps)
    assert steps["power_w"].tolist() == [s["power_w"] for s in cal.steps]


def test_replay_and_forces_as_dataframes(paper_scene, paper_model):
    pytest.importorskip("pandas")
    py = hdi.replay(paper_scene, [0.0, 0.0005], [60.0, 60.0], [0.0, 0.0], heads=2)
    df = hdi.to_dataframe(py)
    assert list(df.columns) == ["head", *hdi.SENSOR_COLUMNS]
    assert df["head"].tolist() == py["head"].tolist() and df["head"].dtype == np.int64
    for k in hdi.SENSOR_COLUMNS:
        assert df[k].tolist() == py[k].tolist(), k
    f = hdi.forces(paper_model, np.array([[1.0, 2.0], [3.0, 4.0]]))
    table = hdi.to_dataframe(f)
    assert len(table) == 4 and table["total_n"].tolist() == f["total_n"].ravel().tolist()


def test_a_cycle_csv_reads_into_pandas_with_missing_values(tmp_path, paper_model, hdi_cli):
    pd = pytest.importorskip("pandas")
    csv = tmp_path / "cycle.csv"
    hdi_cli("cycle", "--paper", "--csv", str(csv), "--no-refine")
    table = pd.read_csv(csv)
    r = hdi.simulate_cycle(paper_model)
    ours = hdi.to_dataframe(r)
    assert list(table.columns) == [k for k in ours.columns]
    for k in table.columns:
        assert np.array_equal(table[k].to_numpy(), ours[k].to_numpy(), equal_nan=True), k
    assert table["indicator_n"].isna().sum() == np.isnan(r["indicator_n"]).sum() > 0


def test_without_pandas_the_error_names_it(monkeypatch, paper_model):
    monkeypatch.setitem(sys.modules, "pandas", None)  # `import pandas` now fails
    with pytest.raises(ImportError, match="pandas"):
        hdi.to_dataframe(hdi.ac_sweep(paper_model, [0.0], threads=1))
    with pytest.raises(TypeError, match="to_dataframe"):
        hdi.to_dataframe(3.0)
