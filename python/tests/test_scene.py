"""Scenes: round trips through dict, TOML, JSON, files and pickle; field access in SI and
engineering units; errors that name the field."""

import json
import pickle

import pytest

import hdi_tribology as hdi
from conftest import REPO


def test_dict_round_trip_is_exact(paper_scene):
    d = paper_scene.to_dict()
    assert isinstance(d, dict) and d["name"] == "paper"
    again = hdi.Scene.from_dict(d)
    assert again == paper_scene
    assert again.to_dict() == d


def test_text_and_pickle_round_trips(paper_scene):
    assert hdi.Scene.from_toml(paper_scene.to_toml()) == paper_scene
    assert hdi.Scene.from_json(paper_scene.to_json()) == paper_scene
    assert pickle.loads(pickle.dumps(paper_scene)) == paper_scene


def test_scene_files_of_the_repository(paper_scene):
    toml_scene = hdi.Scene.from_file(REPO / "scenes" / "paper.toml")
    assert toml_scene == paper_scene
    # the same scene written in engineering units reads to the same SI values
    eng = hdi.Scene.from_file(str(REPO / "scenes" / "paper_engineering.toml"))
    assert eng["surface.height_sigma_m"] == pytest.approx(paper_scene["surface.height_sigma_m"], rel=1e-15)


def test_json_file(tmp_path, paper_scene):
    p = tmp_path / "s.json"
    p.write_text(paper_scene.to_json())
    assert hdi.Scene.from_file(p) == paper_scene


def test_field_access_in_si_and_engineering_units(paper_scene):
    s = hdi.Scene.from_dict(paper_scene.to_dict())
    assert s["nominal_clearance_m"] == paper_scene.to_dict()["nominal_clearance_m"]
    assert s["nominal_clearance_nm"] == pytest.approx(s["nominal_clearance_m"] * 1e9, rel=1e-15)
    # the Rice-maxima peaks belong to the same surface: both σ change together
    s = s.with_values({"surface.height_sigma_nm": 0.5, "surface.peaks.sigma_nm": 0.5})
    assert s["surface.height_sigma_m"] == pytest.approx(0.5e-9, rel=1e-15)
    assert s["surface.height_sigma_nm"] == pytest.approx(0.5, rel=1e-15)
    s["voltage.ac_frequency_khz"] = 20
    assert s["voltage.ac_frequency_hz"] == 20e3
    t = s.with_values({"intermolecular.hamaker_attractive_j": 2e-19, "surface.height_sigma_m": 1e-9,
                       "surface.peaks.sigma_m": 1e-9})
    assert t["intermolecular.hamaker_attractive_j"] == 2e-19
    assert t["surface.height_sigma_m"] == 1e-9
    assert s["surface.height_sigma_m"] == pytest.approx(0.5e-9, rel=1e-15)  # s untouched
    with pytest.raises(KeyError, match="no_such_field"):
        s["surface.no_such_field"]
    with pytest.raises(KeyError, match="nothing"):
        s["nothing.height_sigma_m"]


def test_bad_value_names_the_field_and_leaves_the_scene(paper_scene):
    s = hdi.Scene.from_dict(paper_scene.to_dict())
    with pytest.raises(hdi.InvalidInputError) as e:
        s["surface.height_sigma_nm"] = -0.5
    # named as written, the reason in the unit written
    assert e.value.field == "surface.height_sigma_nm"
    assert "-0.5" in e.value.reason
    assert isinstance(e.value, ValueError)
    assert s == paper_scene
    with pytest.raises(hdi.InvalidInputError) as e:
        s.with_values({"slider.mass_kg": 0.0})
    assert e.value.field == "slider.mass_kg"
    assert "> 0" in e.value.reason


def test_parse_errors_name_the_origin_and_field(tmp_path, paper_scene):
    with pytest.raises(hdi.SceneError) as e:
        hdi.Scene.from_toml("name = ")
    assert e.value.origin == "<string>"
    d = paper_scene.to_dict()
    d["surface"]["roughness_typo_m"] = 1.0
    with pytest.raises(hdi.SceneError, match="roughness_typo_m"):
        hdi.Scene.from_dict(d)
    with pytest.raises(hdi.FileError) as e:
        hdi.Scene.from_file(tmp_path / "missing.toml")
    assert e.value.path.endswith("missing.toml")
    bad = tmp_path / "s.yaml"
    bad.write_text("{}")
    with pytest.raises(hdi.SceneError, match="extension"):
        hdi.Scene.from_file(bad)


def test_scene_and_model_repr(paper_scene, paper_model):
    assert repr(paper_scene) == 'Scene(name="paper")'
    assert repr(paper_model) == 'Model(scene="paper", structure="rigid")'
    assert paper_model.scene == paper_scene
    assert json.loads(paper_scene.to_json())["name"] == "paper"
