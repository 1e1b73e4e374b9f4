"""The fit: a parameter is recovered from curves the model itself made, and a bad data file is
refused with its line and column."""

import pytest

import hdi_tribology as hdi


def test_fit_recovers_the_contact_potential(tmp_path, paper_scene):
    truth = 0.3
    made = hdi.Model(paper_scene.with_values({"electrostatic.contact_potential_v": truth}))
    volts = [-1.0, -0.5, 0.0, 0.5, 1.0, 1.5]
    td = hdi.clearance_change(made, volts)["touchdown_power_w"]
    csv = tmp_path / "td_vs_vdc.csv"
    csv.write_text("dc_voltage_v,touchdown_power_mw\n" +
                   "".join(f"{v!r},{float(1e3 * p)!r}\n" for v, p in zip(volts, td)))
    r = hdi.fit(paper_scene, [csv], ["contact_potential_v=-1:1"])
    (p,) = r["parameters"]
    assert p["name"] == "contact_potential_v"
    assert p["value"] == pytest.approx(truth, abs=1e-3)
    assert isinstance(r["scene"], hdi.Scene)
    assert r["scene"]["electrostatic.contact_potential_v"] == p["value"]
    assert r["converged"] and r["points"] == len(volts)


def test_bad_data_file(tmp_path, paper_scene):
    csv = tmp_path / "bad.csv"
    csv.write_text("dc_voltage_v,touchdown_power_mw\n0.5,nan\n")
    with pytest.raises(hdi.DataFileError) as e:
        hdi.fit(paper_scene, [csv], ["contact_potential_v"])
    assert (e.value.line, e.value.column, e.value.column_name) == (2, 2, "touchdown_power_mw")
    assert e.value.file.endswith("bad.csv")
    good = tmp_path / "good.csv"
    good.write_text("dc_voltage_v,touchdown_power_mw\n0.5,70\n1.0,69\n")
    with pytest.raises(hdi.InvalidInputError, match="no_such_parameter_v"):
        hdi.fit(paper_scene, [good], ["no_such_parameter_v"])
