"""Deformable sliders (`[structure]` presets `bulge` and `pitch`) through the package: scenes
round-trip, the analyses run, and the equilibrium coordinates and the modes of the linear
response agree with the closed forms of the lumped model (MODEL.md: `M q̈ + C q̇ + K q = e₀ F_ab
+ b F_if`, linearised about the static equilibrium)."""

import pickle

import numpy as np
import pytest

import hdi_tribology as hdi
from conftest import REPO

BULGE_FILE = REPO / "scenes" / "paper_bulge.toml"

# A heave-pitch slider: 1 µg, pitch inertia m L²/12 for L = 1 mm, bulge 0.5 mm behind the pivot,
# pitch stiffness k_ab (0.5 mm)², 5 % damping, a small heave-pitch coupling.
PITCH = {
    "preset": "pitch",
    "inertia_kg_m2": 8.3e-14,
    "stiffness_n_m_per_rad": 0.075,
    "coupling_stiffness_n_per_rad": 20.0,
    "damping_n_m_s_per_rad": 7.9e-9,
    "coupling_damping_n_s_per_rad": 1e-6,
    "trailing_edge_m": 5e-4,
}


@pytest.fixture(scope="module")
def bulge_scene():
    return hdi.Scene.from_file(BULGE_FILE)


@pytest.fixture(scope="module")
def pitch_scene(bulge_scene):
    return bulge_scene.with_values({"structure": PITCH})


@pytest.fixture(scope="module")
def bulge_model(bulge_scene):
    return hdi.Model(bulge_scene)


@pytest.fixture(scope="module")
def pitch_model(pitch_scene):
    return hdi.Model(pitch_scene)


@pytest.mark.parametrize("which", ["bulge_scene", "pitch_scene"])
def test_structure_scenes_round_trip(which, request):
    s = request.getfixturevalue(which)
    assert hdi.Scene.from_dict(s.to_dict()) == s
    assert hdi.Scene.from_toml(s.to_toml()) == s
    assert hdi.Scene.from_json(s.to_json()) == s
    assert pickle.loads(pickle.dumps(s)) == s
    assert s["structure.preset"] == which.split("_")[0]
    assert hdi.Scene.from_dict(s.to_dict()).to_dict()["structure"] == s.to_dict()["structure"]


def test_structure_fields(bulge_scene, pitch_scene):
    assert bulge_scene["structure.mass_kg"] == 5e-13
    assert bulge_scene["structure.stiffness_n_per_m"] == 4e5
    assert pitch_scene["structure.trailing_edge_m"] == 5e-4
    assert pitch_scene["structure.trailing_edge_mm"] == pytest.approx(0.5, rel=1e-15)
    s = bulge_scene.with_values({"structure.damping_ratio": 0.2})
    assert s["structure.damping_ratio"] == 0.2
    # the rigid paper scene has no [structure] section to read fields from
    assert "structure" not in hdi.Scene.paper().to_dict()


def test_structure_errors_name_the_field(bulge_scene):
    with pytest.raises(hdi.InvalidInputError) as e:
        bulge_scene.with_values({"structure.mass_kg": -1e-13})
    assert e.value.field == "structure.mass_kg"
    with pytest.raises(hdi.SceneError) as e:
        bulge_scene.with_values({"structure": {"preset": "bulge", "mass_kg": 1e-13}})
    assert "stiffness_n_per_m" in e.value.reason
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.Scene.paper().with_values({"structure": dict(PITCH, inertia_kg_m2=0.0)})
    assert e.value.field == "structure.inertia_kg_m2"


def test_model_reports_its_structure(bulge_model, pitch_model, paper_model):
    assert (bulge_model.structure, bulge_model.dofs) == ("bulge", 2)
    assert (pitch_model.structure, pitch_model.dofs) == ("pitch", 2)
    assert (paper_model.structure, paper_model.dofs) == ("rigid", 1)
    assert "bulge" in repr(bulge_model)


def _interface_stiffness(model, d_m):
    """∂F_if/∂d (N/m) by a central difference of the force tables (h = 1 pm)."""
    d_nm, h = d_m * 1e9, 1e-3
    f = hdi.forces(model, np.array([d_nm - h, d_nm + h]))["total_n"]
    return (f[1] - f[0]) / (2 * h * 1e-9)


def _matrices(scene, which):
    """M, C, K of the structure with the linear air bearing on coordinate 0, and b."""
    m_body = scene["slider.mass_kg"]
    k_ab, c_ab = scene["air_bearing.stiffness_n_per_m"], scene["air_bearing.damping_n_s_per_m"]
    if which == "bulge":
        mb, kb, zb = (scene["structure.mass_kg"], scene["structure.stiffness_n_per_m"],
                      scene["structure.damping_ratio"])
        cb = 2 * zb * np.sqrt(kb * mb)
        m = np.diag([m_body, mb])
        c = np.array([[c_ab + cb, -cb], [-cb, cb]])
        k = np.array([[k_ab + kb, -kb], [-kb, kb]])
        b = np.array([0.0, 1.0])
    else:
        p = PITCH
        m = np.diag([m_body, p["inertia_kg_m2"]])
        c = np.array([[c_ab, p["coupling_damping_n_s_per_rad"]],
                      [p["coupling_damping_n_s_per_rad"], p["damping_n_m_s_per_rad"]]])
        k = np.array([[k_ab, p["coupling_stiffness_n_per_rad"]],
                      [p["coupling_stiffness_n_per_rad"], p["stiffness_n_m_per_rad"]]])
        b = np.array([1.0, p["trailing_edge_m"]])
    return m, c, k, b


@pytest.mark.parametrize("which", ["bulge", "pitch"])
def test_equilibrium_coordinates_closed_form(which, request):
    scene = request.getfixturevalue(f"{which}_scene")
    model = request.getfixturevalue(f"{which}_model")
    e = hdi.flying_equilibrium(model, 60.0)
    assert len(e.q) == 2 and e.stable
    assert e.y_m == e.q[0]
    # static balance K q = b F_if (the air bearing is linear, no voltage in this scene)
    _, _, k, b = _matrices(scene, which)
    q = np.linalg.solve(k, b * e.interface_force_n)
    np.testing.assert_allclose(e.q, q, rtol=1e-9, atol=0)
    # the bulge gap: clearance minus protrusion plus the bulge's displacement bᵀq
    d = scene["nominal_clearance_m"] - scene["heater.efficiency_m_per_w"] * 0.06 + b @ q
    assert e.d_m == pytest.approx(d, rel=1e-9)


@pytest.mark.parametrize("which", ["bulge", "pitch"])
def test_modes_closed_form(which, request):
    """Eigenvalues and shapes of [[0, I], [−M⁻¹K', −M⁻¹C]], K' = K − k_if b bᵀ."""
    scene = request.getfixturevalue(f"{which}_scene")
    model = request.getfixturevalue(f"{which}_model")
    r = hdi.linear_response(model, 60.0)
    assert r.equilibrium.d_m == hdi.flying_equilibrium(model, 60.0).d_m
    m, c, k, b = _matrices(scene, which)
    k_if = _interface_stiffness(model, r.equilibrium.d_m)
    assert abs(k_if) > 1e-3 * k[0, 0], "the interface stiffness should matter in this test"
    k_eff = k - k_if * np.outer(b, b)
    a = np.block([[np.zeros((2, 2)), np.eye(2)],
                  [-np.linalg.solve(m, k_eff), -np.linalg.solve(m, c)]])
    lam, vec = np.linalg.eig(a)
    order = np.argsort(np.abs(lam.imag))
    lam, vec = lam[order], vec[:, order]

    modes = r.modes
    assert len(modes) == 4  # two degrees of freedom, no lags in this scene
    assert [mo.frequency_hz for mo in modes] == r.frequencies_hz
    assert [mo.eigenvalue for mo in modes] == r.eigenvalues
    assert [mo.damping_ratio for mo in modes] == r.damping_ratios
    got = np.array([mo.eigenvalue for mo in modes])
    # the modes come in conjugate pairs; compare |Im| and Re, each pair against its own scale
    np.testing.assert_allclose(np.abs(got.imag), np.abs(lam.imag), rtol=1e-6)
    np.testing.assert_allclose(got.real, lam.real, rtol=1e-5, atol=1e-9 * np.abs(lam).max())
    assert r.stable
    for mo, v in zip(modes, vec.T):
        shape = v[:2]
        shape = shape / shape[np.argmax(np.abs(shape))]
        assert len(mo.shape) == 2
        # with non-proportional damping the eigenvector is complex: the shape is its real part
        np.testing.assert_allclose(mo.shape, shape.real, atol=1e-6)
    assert "frequency_hz" in repr(modes[0])


def test_rigid_equilibrium_has_one_coordinate(paper_model):
    h = hdi.static_hysteresis(paper_model)
    assert h.touchdown.at.q == [h.touchdown.at.y_m]
    r = hdi.linear_response(paper_model, 60.0)
    assert all(len(mo.shape) == 1 for mo in r.modes)


@pytest.mark.parametrize("which", ["bulge", "pitch"])
def test_static_analyses_run_on_structures(which, request):
    model = request.getfixturevalue(f"{which}_model")
    h = hdi.static_hysteresis(model)
    assert h.touchdown.power_w > h.takeoff.power_w > 0
    assert len(h.touchdown.at.q) == 2
    c = hdi.s_curve(model)
    assert c["d_m"].shape == c["power_w"].shape and c["d_m"].dtype == np.float64
    assert any(f["jump_in"] for f in c["folds"])


def test_simulated_dither_matches_linear_prediction(bulge_scene):
    """At a small AC amplitude the simulated bulge dither is the linear response's."""
    model = hdi.Model(bulge_scene.with_values({"voltage.ac_amplitude_v": 0.2}))
    predicted = hdi.linear_response(model, 60.0).dither_amplitude_m
    simulated = hdi.simulated_dither(model, 60.0, settle=20, periods=4)
    assert predicted > 0
    assert simulated == pytest.approx(predicted, rel=0.02)
    with pytest.raises(hdi.AnalysisError):
        hdi.simulated_dither(model, 60.0, v_ac=0.0)
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.flying_equilibrium(model, 60.0, v_ac=float("nan"))
    assert e.value.field == "v_ac"
