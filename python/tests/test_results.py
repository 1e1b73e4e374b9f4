"""Results: arrays of the right shape and dtype, typed objects with readable reprs, and
errors that name the argument."""

import math

import numpy as np
import pytest

import hdi_tribology as hdi

FORCE_KEYS = [
    "d_m", "intermolecular_n", "contact_n", "electrostatic_per_volt2_n_per_v2",
    "electrostatic_n", "other_n", "real_contact_area_m2", "total_n",
]
SERIES_KEYS = [
    "t_s", "power_w", "d_m", "air_bearing_n", "intermolecular_n", "electrostatic_n",
    "contact_n", "total_n", "temperature_rise_k", "indicator_n",
]


def test_forces_arrays(paper_model):
    gaps = np.linspace(0.3, 5.0, 17)
    f = hdi.forces(paper_model, gaps)
    assert sorted(f) == sorted(FORCE_KEYS + ["in_table_range"])
    assert f["in_table_range"].dtype == np.bool_ and f["in_table_range"].shape == (17,)
    for k in FORCE_KEYS:
        assert f[k].shape == (17,) and f[k].dtype == np.float64, k
    # in metres on the decimal of each gap in nm (1.1 nm is 1.1e-9 m, where 1.1 * 1e-9 is
    # 1.1000000000000001e-9): the shortest text of each, shifted by nine places
    assert f["d_m"].tolist() == [float(f"{g!r}e-9") for g in gaps.tolist()]
    assert np.allclose(f["d_m"], gaps * 1e-9, rtol=2.3e-16, atol=0)
    # the parts add up to the total, and contact pushes away, more at smaller gaps
    parts = f["intermolecular_n"] + f["contact_n"] + f["electrostatic_n"] + f["other_n"]
    assert np.allclose(parts, f["total_n"], rtol=1e-12, atol=1e-18)
    assert np.all(np.diff(f["contact_n"]) <= 0)
    assert np.all(f["intermolecular_n"] < 0)


def test_forces_reject_bad_gaps(paper_model):
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.forces(paper_model, np.array([1.0, np.nan]))
    assert e.value.field == "gaps_nm[1]"
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.forces(paper_model, np.array([1.0]), protrusion_nm=math.inf)
    assert e.value.field == "protrusion_nm"
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.forces(paper_model, np.array([[1.0, 2.0], [np.inf, 1.0]]))
    assert e.value.field == "gaps_nm[1, 0]"
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.forces(paper_model, ["one nm"])
    assert e.value.field == "gaps_nm"
    with pytest.raises(TypeError, match="Model or hdi_tribology.Scene"):
        hdi.forces("paper", np.ones(2))


def test_cycle_series_and_transitions(paper_model):
    r = hdi.simulate_cycle(paper_model)
    c = r["cycle"]
    n = c.steps + 1  # the initial state and every accepted step
    for k in SERIES_KEYS:
        assert r[k].shape == (n,) and r[k].dtype == np.float64, k
    assert np.all(np.diff(r["t_s"]) > 0)
    td, to = r["touchdown"], r["takeoff"]
    assert isinstance(td, hdi.Detection) and isinstance(to, hdi.Detection)
    assert td.time_s < to.time_s
    assert c.hysteresis_w == td.power_w - to.power_w > 0
    assert c.hysteresis_mw == pytest.approx(c.hysteresis_w * 1e3, rel=1e-15)
    assert repr(c).startswith("Cycle(scene='paper', programme='fixed', v_ac_v=0.0, touchdown=Detection(")
    assert c.flags == [] and c.status == "unchecked" and c.runs == 1
    # the running mean has not filled before the detector window: NaN, not a number made up
    assert math.isnan(r["indicator_n"][0])
    no_series = hdi.simulate_cycle(paper_model, series=False)
    assert "t_s" not in no_series and no_series["cycle"].steps == c.steps
    # ended at the take-off: the same detections to the bit, on the steps up to it
    short = hdi.simulate_cycle(paper_model, stop_at_takeoff=True)
    assert short["touchdown"] == td and short["takeoff"] == to
    assert short["cycle"].steps < c.steps
    assert short["t_s"][-1] >= to.time_s and np.array_equal(short["t_s"], r["t_s"][: len(short["t_s"])])
    # without the heat integral: no mean temperature, the powers within the tolerance's power
    cool = hdi.simulate_cycle(paper_model, series=False, mean_temperature=False)
    assert c.mean_temperature_rise_k > 0 and cool["cycle"].mean_temperature_rise_k is None
    assert abs(cool["takeoff"].power_w - to.power_w) < 1e-7
    assert abs(cool["touchdown"].power_w - td.power_w) < 1e-7


def test_static_objects(paper_model):
    h = hdi.static_hysteresis(paper_model)
    assert h.touchdown.power_w > h.takeoff.power_w
    assert h.hysteresis_w == h.touchdown.power_w - h.takeoff.power_w
    assert h.touchdown.cause in ("fold", "threshold")
    assert repr(h).startswith("StaticHysteresis(scene='paper', touchdown=Transition(power_w=0.074")
    assert h.touchdown.at.d_nm == pytest.approx(h.touchdown.at.d_m * 1e9, rel=1e-15)
    p = hdi.pull_in_voltage(paper_model)
    assert p.voltage_v > 0 and p.cause in ("fold", "threshold")
    c = hdi.s_curve(paper_model)
    n = c["d_m"].shape[0]
    assert n > 10 and c["stable"].dtype == np.bool_ and c["stable"].shape == (n,)
    assert any(f["jump_in"] for f in c["folds"])
    cc = hdi.clearance_change(paper_model, [-1.0, 0.0, 1.0])
    assert cc["clearance_change_m"].shape == (3,)


def test_linear_response(paper_model):
    lr = hdi.linear_response(paper_model, 50.0)
    assert lr.stable and all(z.real < 0 for z in lr.eigenvalues)
    assert lr.equilibrium.power_mw == pytest.approx(50.0, rel=1e-12)
    w = np.array([0.0, 1e3, 1e6])
    h = lr.transfer(w)
    assert h.dtype == np.complex128 and h.shape == (3,)
    # at zero frequency the transfer is the static compliance, 1 / stiffness
    assert h[0].real == pytest.approx(1.0 / lr.equilibrium.stiffness_n_per_m, rel=1e-6)


def test_cycle_argument_errors(paper_model):
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.simulate_cycle(paper_model, method="euler")
    assert e.value.field == "method"
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.simulate_cycle(paper_model, rtol=-1.0, series=False)
    assert "rtol" in e.value.field
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.ac_sweep(paper_model, [0.0, math.nan])
    assert e.value.field == "amplitudes_v[1]"
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.ac_sweep(paper_model, [0.0], threads=0)
    assert e.value.field == "threads"
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.calibrate(paper_model, detector="sonar")
    assert e.value.field == "detector" and "sonar" in e.value.reason
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.static_hysteresis(paper_model, contact_threshold_un=-1.0)
    assert e.value.field == "contact_threshold_un"


def test_sweep_does_not_depend_on_threads(paper_model):
    amps = [0.0, 0.3, 0.6]
    one = hdi.ac_sweep(paper_model, amps, threads=1)
    two = hdi.ac_sweep(paper_model, amps, threads=2)
    # equal by value: every key but the wall-clock times
    assert one == two
    assert [c.v_ac_v for c in one] == amps


def test_cycle_reports_the_lag_energy_audit_only_with_a_lag(paper_scene, paper_model):
    lagged = hdi.Model(paper_scene.with_values({"slider.interface_lag_s": 2e-8}))
    c = hdi.simulate_cycle(lagged, series=False)["cycle"]
    # below c/K the lag gives back part of what the damping takes out, never more
    assert 0 < c.lag_work_j < c.damping_work_j
    plain = hdi.simulate_cycle(paper_model, series=False)["cycle"]
    assert "lag_work_j" not in plain and "damping_work_j" not in plain
    # a 20 ns lag is faster than any explicit step follows: "auto" runs Rodas5P from the start
    assert (c.method, plain.method) == ("rodas5p", "auto")
