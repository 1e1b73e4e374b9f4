"""The simulated drive: stepped from Python as firmware would, seeded noise reproducible."""

import math

import pytest

import hdi_tribology as hdi


def run(scene, seed, steps=40):
    d = hdi.Drive(scene, seed=seed)
    return d, [d.step(60.0, 50e-6) for _ in range(steps)]


def test_drive_steps_and_sensors(paper_scene):
    d, out = run(paper_scene, 1)
    assert d.time_s == pytest.approx(40 * 50e-6, rel=1e-12)
    last = out[-1]
    assert set(last) >= {"t", "contact_resistance", "acoustic", "readback", "heater_power", "truth"}
    assert last["t"] == d.time_s
    assert last["heater_power"] == pytest.approx(0.06, rel=1e-12)
    # flying at 60 mW on the paper scene: a gap of a few nm, no contact force on average
    assert 1e-9 < last["truth"]["gap"] < 10e-9
    assert all(math.isfinite(v) for v in last["truth"].values())
    assert "Drive(time_s=" in repr(d)


def test_same_seed_same_noise(paper_scene):
    _, a = run(paper_scene, 7)
    _, b = run(paper_scene, 7)
    _, c = run(paper_scene, 8)
    assert a == b
    assert [s["acoustic"] for s in a] != [s["acoustic"] for s in c]


def test_bad_command_names_the_field(paper_scene):
    d = hdi.Drive(paper_scene)
    with pytest.raises(hdi.InvalidInputError) as e:
        d.step(-1.0, 50e-6)
    assert e.value.field == "command.heater_power"
