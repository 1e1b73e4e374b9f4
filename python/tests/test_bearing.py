"""The air bearing from the slider's geometry through the package: `bearing(geometry, ...)` gives
the same attitude, stiffness and damping as `hdi bearing GEOMETRY` to the bit, balances the
preload, has no roll on a symmetric slider without skew, and names a bad argument."""

import numpy as np
import pytest

import hdi_tribology as hdi
from conftest import REPO

EXAMPLE = REPO / "scenes" / "bearing" / "two_rail_taper_flat.toml"
CELLS = 33


@pytest.fixture(scope="module")
def example():
    return hdi.bearing(EXAMPLE, cells=CELLS)


def test_matches_the_command_line(example, hdi_cli):
    cli = hdi_cli("bearing", str(EXAMPLE), "--cells", str(CELLS))
    for key in ["fly_height_nm", "pitch_urad", "roll_urad", "trailing_edge_spacing_nm",
                "bulge_spacing_nm", "min_spacing_nm", "load_mn", "pitch_moment_un_m",
                "roll_moment_un_m"]:
        assert getattr(example, key) == cli[key], key
    rows = ["force", "pitch_moment", "roll_moment"]
    cols = ["fly_height", "pitch", "roll"]
    for i, r in enumerate(rows):
        for j, c in enumerate(cols):
            assert example.stiffness[i][j] == cli["stiffness_si"][f"{r}_per_{c}"]
            assert example.damping[i][j] == cli["damping_si"][f"{r}_per_{c}"]
    assert [lv["krylov_iterations"] for lv in example.convergence] == \
        [lv["krylov_iterations"] for lv in cli["convergence"]]


def test_balances_the_preload(example):
    assert example.converged
    assert example.imbalance <= example.tolerance
    # The example's preload is 49 mN at the centre, with no static torques.
    assert example.load_mn == pytest.approx(49.0, rel=1e-8)
    assert abs(example.pitch_moment_un_m) < 1e-8 * 49e-3 * 2e-3 * 1e6
    # Symmetric rails, no skew: no roll.
    assert abs(example.roll_urad) < 1e-9 * example.pitch_urad
    k = np.array(example.stiffness)
    assert k.shape == (3, 3) and np.all(np.diag(k) > 0)
    assert example.damping[0][0] > 0


def test_pressure_field(example):
    nx, ny = example.cells
    assert (nx, ny) == (CELLS, CELLS)
    p = example.pressure_pa
    assert p.shape == (ny, nx)
    assert example.x_um.shape == (nx,) and example.y_um.shape == (ny,)
    # The force is the gauge pressure's integral: above ambient on the rails.
    assert p.max() > 101325.0
    assert np.allclose(p, p[::-1, :], rtol=1e-9)


def test_overrides_and_errors():
    heavier = hdi.bearing(EXAMPLE, cells=CELLS, preload_mn=60.0)
    assert heavier.load_mn == pytest.approx(60.0, rel=1e-8)
    assert heavier.fly_height_nm < hdi.bearing(EXAMPLE, cells=CELLS).fly_height_nm
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.bearing(EXAMPLE, cells=CELLS, skew_deg=45.0)
    assert e.value.field == "skew_deg"
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.bearing(EXAMPLE, cells=CELLS, rpm=float("nan"))
    assert e.value.field == "rpm"
    with pytest.raises(hdi.AnalysisError):
        hdi.bearing(EXAMPLE, cells=CELLS, preload_mn=1e6)
