"""Python's usual protocols: array_like in, results by value, pickle, `to_dict`, the scene as a
mapping of its fields, and arguments checked by the names the caller wrote."""

import math
import pickle

import numpy as np
import pytest

import hdi_tribology as hdi


def test_forces_take_any_array_like(paper_model):
    ref = hdi.forces(paper_model, np.array([1.0, 2.0, 3.0, 4.0]))
    # a list, ints, float32 (which holds 1..4 exactly): the same numbers
    for given in ([1.0, 2.0, 3.0, 4.0], [1, 2, 3, 4], np.arange(1, 5),
                  np.arange(1, 5, dtype=np.float32)):
        f = hdi.forces(paper_model, given)
        for k in ref:
            assert np.array_equal(f[k], ref[k]), k
    # a scalar gives 0-d arrays, an N-D array arrays of its shape
    s = hdi.forces(paper_model, 3.0)
    assert s["total_n"].shape == () and s["total_n"] == ref["total_n"][2]
    m = hdi.forces(paper_model, np.array([[1.0, 2.0], [3.0, 4.0]]))
    for k in ref:
        assert m[k].shape == (2, 2), k
        assert np.array_equal(m[k].ravel(), ref[k]), k


def test_results_compare_pickle_and_convert(paper_model):
    h = hdi.static_hysteresis(paper_model)
    again = hdi.static_hysteresis(paper_model)
    assert h == again and h is not again
    back = pickle.loads(pickle.dumps(h))
    assert back == h and isinstance(back.touchdown, hdi.Transition)
    assert isinstance(back.touchdown.at, hdi.Equilibrium)
    d = h.to_dict()
    assert d["touchdown"]["power_w"] == h.touchdown.power_w
    assert hdi.StaticHysteresis(d) == h
    assert sorted(h.keys()) == sorted(d) and "hysteresis_w" in h
    # engineering views of SI keys
    assert h.hysteresis_mw == h.hysteresis_w * 1e3
    assert h.touchdown.at.d_nm == h.touchdown.at.d_m * 1e9
    assert h.touchdown.at.contact_force_un == h.touchdown.at.contact_force_n * 1e6
    with pytest.raises(AttributeError):
        h.no_such_key
    with pytest.raises(AttributeError):
        h.hysteresis_w = 0.0
    c = hdi.ac_sweep(paper_model, [0.0], threads=1)[0]
    other = hdi.ac_sweep(paper_model, [0.3], threads=1)[0]
    assert c != other and pickle.loads(pickle.dumps(c)) == c
    # the repr shows the real keys, in the crate's order, and nothing else
    text = repr(c)
    assert text.startswith("Cycle(scene='paper', programme='fixed', v_ac_v=0.0, ")
    at = [text.index(f" {k}=") if f" {k}=" in text else text.index(f"({k}=") for k in c.keys()]
    assert at == sorted(at)


def test_scene_is_a_mapping_of_its_fields(paper_scene):
    s = hdi.Scene.paper()
    keys = s.keys()
    assert "surface.height_sigma_m" in keys and len(keys) == len(s) == len(list(s))
    assert "surface.height_sigma_nm" in s and "surface.no_such_field" not in s
    for k in keys[:20]:
        s[k]  # every key reads
    # numpy scalars and arrays are taken as values
    s["voltage.dc_v"] = np.float32(0.75)
    assert s["voltage.dc_v"] == 0.75
    s["nominal_clearance_nm"] = np.int64(5)
    assert s["nominal_clearance_m"] == 5e-9
    # an unknown field is a KeyError, as reading it is, and changes nothing
    before = s.to_dict()
    with pytest.raises(KeyError):
        s["surface.no_such_field"] = 1.0
    with pytest.raises(KeyError):
        s["no_such_section.x"] = 1.0
    assert s.to_dict() == before
    assert pickle.loads(pickle.dumps(s)) == s


def test_python_arguments_are_named_as_written(paper_model):
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.flying_equilibrium(paper_model, -10)
    assert e.value.field == "power_mw" and "mW" in e.value.reason
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.flying_equilibrium(paper_model, 50, v_ac=-0.5)
    assert e.value.field == "v_ac"
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.simulate_cycle(paper_model, -0.5, series=False)
    assert e.value.field == "v_ac"
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.ac_sweep(paper_model, [0.0, -1.0])
    assert e.value.field == "amplitudes_v[1]"
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.Drive(paper_model, radius_mm=1e6)
    assert e.value.field == "radius_mm"
    # negative ints are an InvalidInputError naming the argument, not a bare OverflowError
    for call, name in [
        (lambda: hdi.Drive(paper_model, seed=-1), "seed"),
        (lambda: hdi.ac_sweep(paper_model, [0.0], threads=-2), "threads"),
        (lambda: hdi.ac_sweep_refined(paper_model, 0.06, [0.0], max_runs=-3), "max_runs"),
        (lambda: hdi.simulated_dither(paper_model, 50.0, 0.5, periods=-1), "periods"),
        (lambda: hdi.fit(hdi.Scene.paper(), ["x.csv"], ["height_sigma_nm"], starts=-1), "starts"),
    ]:
        with pytest.raises(hdi.InvalidInputError) as e:
            call()
        assert e.value.field == name
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.ac_sweep_refined(paper_model, -0.06, [0.0])
    assert e.value.field == "power_tol_mw" and "mW" in e.value.reason


def test_drive_step_and_replay_give_the_same_columns(paper_scene):
    """A step's `Sensors` carry the fields of the C `HdiSensors` (the truth in `truth`, as its
    `HdiTruth`) and the harmonic-ratio change; every replay column is one of them, equal."""
    d = hdi.Drive(paper_scene, flat_disk=True)
    s = d.step(60.0)
    assert sorted(s.keys()) == sorted([
        "time_s", "heater_power_mw", "contact_resistance_ohm", "acoustic_v",
        "readback_fundamental_v", "readback_third_v", "hr_clearance_change_nm", "truth"])
    assert all(not math.isnan(s[k]) for k in s if k != "truth")
    assert all(not math.isnan(s.truth[k]) for k in s.truth)
    r = hdi.replay(paper_scene, [0.0, 5e-5], [60.0, 60.0], [0.0, 0.0], flat_disk=True)
    assert list(r) == list(hdi.SENSOR_COLUMNS)
    of_step = {"heater_mw": s.heater_power_mw, "true_gap_nm": s.truth.gap_nm,
               "true_contact_force_un": s.truth.mean_contact_force_un,
               "true_sensor_temperature_k": s.truth.sensor_temperature_k,
               "true_disk_height_nm": s.truth.disk_height_nm,
               "true_ambient_k": s.truth.ambient_k}
    for name in hdi.SENSOR_COLUMNS:
        assert r[name].tolist() == [of_step[name] if name in of_step else s[name]], name
