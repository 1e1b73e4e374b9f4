"""A term with a state of its own rides along in a cycle and in the drive: its closed-form
relaxation comes out of both, through the same library calls as Rust."""

import math

import numpy as np
import pytest

import hdi_tribology as hdi

TAU = 2e-4


@pytest.fixture(scope="module")
def relaxing():
    return hdi.Model(hdi.Scene.paper()).with_relaxing_state(TAU, 1.0)


def test_cycle_carries_the_state_in_closed_form(relaxing):
    c = hdi.simulate_cycle(relaxing)
    t, x = c["t_s"], c["term_states"][0]
    exact = np.exp(-(t - t[0]) / TAU)
    # The state's tolerance: 1e9 per metre of the scene's 0.01 pm, plus the relative one.
    rtol = 1e-6
    assert np.all(np.abs(x - exact) <= 100 * (1e-5 + rtol * exact))
    plain = hdi.simulate_cycle(hdi.Model(hdi.Scene.paper()))
    assert "term_states" not in plain
    assert abs(c["touchdown"].power_w - plain["touchdown"].power_w) < 1e-5


def test_drive_carries_the_state_across_commands(relaxing):
    d = hdi.Drive(relaxing, seed=3, flat_disk=True)
    assert d.term_states == [1.0]
    for k in range(20):
        d.step(60.0 if (k // 5) % 2 == 0 else 62.0)
        exact = math.exp(-d.time_s / TAU)
        assert abs(d.term_states[0] - exact) <= 100 * (1e-5 + 1e-6 * exact)
    assert hdi.Drive(hdi.Scene.paper(), flat_disk=True).term_states == []


def test_bad_relaxing_state_names_the_argument():
    m = hdi.Model(hdi.Scene.paper())
    with pytest.raises(hdi.InvalidInputError, match="tau_s"):
        m.with_relaxing_state(0.0, 1.0)
    with pytest.raises(hdi.InvalidInputError, match="start"):
        m.with_relaxing_state(1e-4, float("nan"))


def test_a_lubricated_cycle_switches_its_branch_and_agrees_with_rust():
    """The paper scene with 0.3 nm of mobile lubricant: the meniscus's closest approach rides
    along as a term state, and its healing/formation branch is switched at located roots."""
    text = hdi.Scene.paper().to_toml() + (
        "\n[lubricant]\ntotal_thickness_m = 1.3e-9\nbonded_thickness_m = 1.0e-9\n"
        "surface_tension_n_per_m = 0.024\ncontact_angle_deg = 30.0\nhealing_time_s = 2e-5\n"
    )
    c = hdi.simulate_cycle(hdi.Model(hdi.Scene.from_toml(text)))
    assert c["cycle"].stats["branch_switches"] > 0
    assert len(c["term_states"]) == 1
    plain = hdi.simulate_cycle(hdi.Model(hdi.Scene.paper()))
    assert plain["cycle"].stats["branch_switches"] == 0
    # Bridges hold the head down: it takes off later (at a lower power) than without them.
    assert c["takeoff"].power_w < plain["takeoff"].power_w - 1e-3


def test_bridges_that_form_at_once_are_the_limit_of_a_short_formation_time():
    """`formation_time_s = 0`: bridges form at once. Touchdown and take-off agree with those of
    a 10 ns formation time within 0.2 µW, and a negative formation time names its field."""
    lub = (
        "\n[lubricant]\ntotal_thickness_m = 1.3e-9\nbonded_thickness_m = 1.0e-9\n"
        "surface_tension_n_per_m = 0.024\ncontact_angle_deg = 30.0\nhealing_time_s = 2e-5\n"
    )
    base = hdi.Scene.paper().to_toml() + lub
    at_once = hdi.simulate_cycle(hdi.Model(hdi.Scene.from_toml(base + "formation_time_s = 0\n")))
    short = hdi.simulate_cycle(hdi.Model(hdi.Scene.from_toml(base + "formation_time_s = 1e-8\n")))
    assert at_once["cycle"].stats["branch_switches"] > 0
    for key in ("touchdown", "takeoff"):
        assert abs(at_once[key].power_w - short[key].power_w) < 2e-7
    with pytest.raises(hdi.InvalidInputError, match="lubricant.formation_time_s"):
        hdi.Scene.from_toml(base + "formation_time_s = -1e-8\n")
