"""The simulated drive from Python: one period at a time (`Drive.step`), a whole command list
(`replay`, bit for bit the `hdi drive` program's CSV), a firmware loop written in Python, and
errors naming the argument."""

import threading

import numpy as np
import pytest

import hdi_tribology as hdi

# Two commands on a flat disk: 60 mW, then 66 mW from 1 ms on, to 2 ms (40 periods at 20 kHz).
TIMES = [0.0, 1e-3, 2e-3]
HEATER = [60.0, 66.0, 66.0]
DC = [0.0, 0.0, 0.0]


def test_replay_columns_shape_and_dtype(paper_scene):
    out = hdi.replay(paper_scene, TIMES, HEATER, DC, flat_disk=True)
    assert list(out) == list(hdi.SENSOR_COLUMNS)
    for name, col in out.items():
        assert isinstance(col, np.ndarray) and col.dtype == np.float64 and col.shape == (40,), name
    assert np.all(np.isfinite(np.column_stack(list(out.values()))))
    assert out["heater_mw"][:20].tolist() == [60.0] * 20
    assert out["heater_mw"][20:].tolist() == [66.0] * 20
    # 6 mW more heater brings the bulge closer: the true gap falls, and the harmonic ratio
    # sees it (first period is its reference)
    assert out["hr_clearance_change_nm"][0] == 0.0
    assert out["true_gap_nm"][-1] < out["true_gap_nm"][19] - 0.1


def test_same_seed_same_stream_other_seed_other_noise(paper_scene):
    a = hdi.replay(paper_scene, TIMES, HEATER, DC, seed=7)
    b = hdi.replay(paper_scene, TIMES, HEATER, DC, seed=7)
    c = hdi.replay(paper_scene, TIMES, HEATER, DC, seed=8)
    for name in hdi.SENSOR_COLUMNS:
        assert a[name].tobytes() == b[name].tobytes(), name
    assert a["contact_resistance_ohm"].tobytes() != c["contact_resistance_ohm"].tobytes()


def test_stepping_equals_replay(paper_scene):
    """`Drive.step` with the commands of a command list gives `replay`'s rows, bit for bit."""
    ref = hdi.replay(paper_scene, TIMES, HEATER, DC, seed=3)
    drive = hdi.Drive(paper_scene, seed=3)
    rows = [drive.step(60.0 if k < 20 else 66.0) for k in range(40)]
    # The CSV's columns and the sensors' fields (the Rust `Sensors`, the C `HdiSensors`).
    field = {"heater_mw": lambda s: s.heater_power_mw,
             "true_gap_nm": lambda s: s.truth.gap_nm,
             "true_contact_force_un": lambda s: s.truth.mean_contact_force_un,
             "true_sensor_temperature_k": lambda s: s.truth.sensor_temperature_k,
             "true_disk_height_nm": lambda s: s.truth.disk_height_nm,
             "true_ambient_k": lambda s: s.truth.ambient_k}
    for name in hdi.SENSOR_COLUMNS:
        get = field.get(name, lambda s, name=name: getattr(s, name))
        assert [get(s) for s in rows] == ref[name].tolist(), name
    assert drive.time_s == rows[-1].time_s
    assert drive.stats["accepted"] > 0
    assert "Drive(" in repr(drive) and "Sensors(" in repr(rows[0])


def test_replay_matches_the_cli_bit_for_bit(tmp_path, paper_scene, hdi_cli):
    commands = tmp_path / "commands.csv"
    commands.write_text(
        "time_s,heater_mw,voltage_dc_v,voltage_ac_v,ac_frequency_khz\n"
        "0,60,0,0,0\n0.0005,70,0.2,0.3,10.5\n0.001,70,0,0,0\n"
    )
    csv = tmp_path / "sensors.csv"
    summary = hdi_cli("drive", "--paper", "--commands", str(commands), "--out", str(csv),
                      "--seed", "5")
    assert summary["periods"] == 20
    table = np.genfromtxt(csv, delimiter=",", names=True)
    py = hdi.replay(paper_scene, [0.0, 0.0005, 0.001], [60.0, 70.0, 70.0], [0.0, 0.2, 0.0],
                    [0.0, 0.3, 0.0], [0.0, 10.5, 0.0], seed=5)
    assert list(table.dtype.names) == list(hdi.SENSOR_COLUMNS)
    for name in hdi.SENSOR_COLUMNS:
        assert table[name].tolist() == py[name].tolist(), name


def test_a_firmware_loop_in_python_finds_touchdown(paper_scene):
    """A staircase with an acoustic-emission detector, written in Python against `Drive.step`:
    touchdown within 1 mW of the static touchdown power (74.324 mW)."""
    static_td = hdi.static_hysteresis(paper_scene).touchdown.power_mw
    drive = hdi.Drive(paper_scene, seed=11, flat_disk=True, initial_heater_power_mw=71.0)
    levels = np.arange(71.0, 78.0, 0.5)
    hold, read = 30, 20  # periods per level; the last `read` are averaged
    means, errors, touchdown = [], [], None
    for p in levels:
        ae = [drive.step(p).acoustic_v for _ in range(hold)][-read:]
        means.append(np.mean(ae))
        errors.append(np.std(ae, ddof=1) / np.sqrt(read))
        if len(means) > 3:
            base = np.mean(means[:3])
            se = np.hypot(np.mean(errors[:3]), errors[-1])
            if means[-1] - base > 8.0 * se:
                touchdown = p
                break
    assert touchdown is not None, "no touchdown up to 78 mW"
    assert abs(touchdown - static_td) <= 1.0, (touchdown, static_td)


def test_replay_releases_the_gil(paper_scene):
    times = [0.0, 0.02]
    done = threading.Event()
    ticks = []

    def work():
        hdi.replay(paper_scene, times, [60.0, 60.0], [0.0, 0.0])
        done.set()

    t = threading.Thread(target=work)
    t.start()
    while not done.is_set():
        ticks.append(1)
        done.wait(0.001)
    t.join()
    assert len(ticks) > 3


@pytest.mark.parametrize("kwargs, field", [
    (dict(heater_power_mw=-1.0), "heater_power_mw"),
    (dict(heater_power_mw=float("nan")), "heater_power_mw"),
    (dict(heater_power_mw=60.0, dc_voltage_v=float("inf")), "dc_voltage_v"),
    (dict(heater_power_mw=60.0, ac_frequency_khz=-2.0), "ac_frequency_khz"),
    (dict(heater_power_mw=60.0, period_s=0.0), "period_s"),
])
def test_step_errors_name_the_argument(paper_scene, kwargs, field):
    drive = hdi.Drive(paper_scene)
    with pytest.raises(hdi.InvalidInputError) as e:
        drive.step(**kwargs)
    assert e.value.field == field
    assert drive.time_s == 0.0  # nothing was stepped


@pytest.mark.parametrize("args, kwargs, field", [
    (([0.0, 1e-3], [60.0], [0.0, 0.0]), {}, "heater_mw"),
    (([0.0, 1e-3], [60.0, -5.0], [0.0, 0.0]), {}, "heater_mw[1]"),
    (([0.0, 0.0], [60.0, 60.0], [0.0, 0.0]), {}, "time_s[1]"),
    (([0.0], [60.0], [0.0]), {}, "time_s"),
    (([0.0, 1e-3], [60.0, 60.0], [0.0, 0.0]), dict(rate_khz=0.0), "rate_khz"),
    (([0.0, 1e-3], [60.0, 60.0], [0.0, 0.0]), dict(radius_mm=-1.0), "radius_mm"),
])
def test_replay_errors_name_the_argument(paper_scene, args, kwargs, field):
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.replay(paper_scene, *args, **kwargs)
    assert e.value.field == field


def test_tolerances_match_the_cli_and_name_the_argument(tmp_path, paper_scene, hdi_cli):
    """A looser flight tolerance (0.01 pm near contact, 1 pm in flight): the same columns as the
    CLI with the same flags, bit for bit, and another stream than the default's (one tolerance,
    0.01 pm) on a wavy disk in flight, within ten times the flight tolerance of it; bad
    tolerances name the argument and nothing runs."""
    times, heater, dc = [0.0, 2e-3], [68.0, 68.0], [0.0, 0.0]
    commands = tmp_path / "commands.csv"
    commands.write_text("time_s,heater_mw,voltage_dc_v\n0,68,0\n0.002,68,0\n")
    csv = tmp_path / "sensors.csv"
    hdi_cli("drive", "--paper", "--commands", str(commands), "--out", str(csv),
            "--atol-pm", "0.01", "--atol-flight-pm", "1")
    table = np.genfromtxt(csv, delimiter=",", names=True)
    loose = hdi.replay(paper_scene, times, heater, dc, atol_pm=0.01, atol_flight_pm=1.0)
    for name in hdi.SENSOR_COLUMNS:
        assert table[name].tolist() == loose[name].tolist(), name
    default = hdi.replay(paper_scene, times, heater, dc)
    fixed = hdi.replay(paper_scene, times, heater, dc, atol_pm=0.01, atol_flight_pm=0.01)
    assert default["true_gap_nm"].tobytes() == fixed["true_gap_nm"].tobytes()
    assert default["true_gap_nm"].tobytes() != loose["true_gap_nm"].tobytes()
    assert np.max(np.abs(default["true_gap_nm"] - loose["true_gap_nm"])) < 1e-2
    for kwargs, field in [(dict(atol_pm=0.0), "atol_pm"),
                          (dict(atol_pm=0.1, atol_flight_pm=0.05), "atol_flight_pm"),
                          (dict(atol_flight_pm=float("nan")), "atol_flight_pm")]:
        with pytest.raises(hdi.InvalidInputError) as e:
            hdi.Drive(paper_scene, **kwargs)
        assert e.value.field == field
        with pytest.raises(hdi.InvalidInputError) as e:
            hdi.replay(paper_scene, times, heater, dc, **kwargs)
        assert e.value.field == field


def _fields(s):
    """Every number of a period's sensors (the truth's too), in a fixed order."""
    d = s.to_dict()
    truth = d.pop("truth")
    return [d[k] for k in sorted(d)] + [truth[k] for k in sorted(truth)]


def test_multi_drive_heads_are_one_head_drives_to_the_bit(paper_scene):
    """Three heads of one scene, each its own heater programme: head k equals a one-head
    ``Drive`` seeded ``seeds[k]`` (head 0 by the drive's seed) to the bit; one clock; each
    surface its own."""
    multi = hdi.MultiDrive(paper_scene, heads=3, seed=4)
    assert multi.heads == 3 and multi.seeds[0] == 4 and len(set(multi.seeds)) == 3
    singles = [hdi.Drive(paper_scene, seed=s) for s in multi.seeds]
    for n in range(40):
        powers = [60.0 + 0.1 * n, 62.0, 65.0 + 0.05 * n]
        got = multi.step(powers, dc_voltage_v=[0.0, 0.2, 0.0])
        assert len(got) == 3 and {s.time_s for s in got} == {multi.time_s}
        for k, d in enumerate(singles):
            want = d.step(powers[k], dc_voltage_v=[0.0, 0.2, 0.0][k])
            assert _fields(got[k]) == _fields(want), (n, k)
    heights = {s.truth.disk_height_nm for s in got}
    assert len(heights) == 3
    assert "MultiDrive(heads=3" in repr(multi)


def test_multi_drive_of_several_scenes(paper_scene):
    """A list of scenes is one head each; a head of another slider equals its one-head drive."""
    d = paper_scene.to_dict()
    d["nominal_clearance_m"] *= 1.05
    high = hdi.Scene.from_dict(d)
    multi = hdi.MultiDrive([paper_scene, high], seed=2)
    alone = hdi.Drive(high, seed=multi.seeds[1])
    for _ in range(10):
        got = multi.step(66.0)
        assert _fields(got[1]) == _fields(alone.step(66.0))
    assert got[1].truth.gap_nm > got[0].truth.gap_nm
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.MultiDrive([paper_scene, high], heads=3)
    assert e.value.field == "heads"


def test_multi_drive_errors_name_the_argument_and_head(paper_scene):
    multi = hdi.MultiDrive(paper_scene, heads=2)
    for args, kwargs, field in [
        (([60.0, -1.0],), {}, "heater_power_mw[1]"),
        (([60.0],), {}, "heater_power_mw"),
        ((60.0,), dict(ac_frequency_khz=[0.0, float("nan")]), "ac_frequency_khz[1]"),
        ((60.0,), dict(period_s=2.0), "period_s"),
    ]:
        with pytest.raises(hdi.InvalidInputError) as e:
            multi.step(*args, **kwargs)
        assert e.value.field == field
    assert multi.time_s == 0.0  # nothing was stepped
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.Drive(paper_scene, heads=2)
    assert e.value.field == "heads" and "MultiDrive" in str(e.value)
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.MultiDrive(paper_scene, heads=0)
    assert e.value.field == "heads"


def test_replay_of_several_heads_matches_the_cli(tmp_path, paper_scene, hdi_cli):
    commands = tmp_path / "commands.csv"
    commands.write_text("time_s,heater_mw,voltage_dc_v\n0,60,0\n0.0005,66,0\n0.001,66,0\n")
    csv = tmp_path / "sensors.csv"
    summary = hdi_cli("drive", "--paper", "--commands", str(commands), "--out", str(csv),
                      "--heads", "2", "--seed", "3")
    assert summary["heads"] == 2
    table = np.genfromtxt(csv, delimiter=",", names=True)
    py = hdi.replay(paper_scene, [0.0, 0.0005, 0.001], [60.0, 66.0, 66.0], [0.0] * 3,
                    heads=2, seed=3)
    assert list(py) == ["head"] + list(hdi.SENSOR_COLUMNS)
    assert py["head"].dtype == np.int64 and py["head"][:4].tolist() == [0, 1, 0, 1]
    for name in ["head"] + list(hdi.SENSOR_COLUMNS):
        assert table[name].tolist() == py[name].tolist(), name
    one = hdi.replay(paper_scene, [0.0, 0.0005, 0.001], [60.0, 66.0, 66.0], [0.0] * 3, seed=3)
    for name in hdi.SENSOR_COLUMNS:
        assert py[name][py["head"] == 0].tolist() == one[name].tolist(), name


def test_the_bounded_mode_bounds_the_steps_and_flags_the_misses(paper_scene):
    # A 0.5 V dither at 4 steps a period misses the tolerances, and says so; without the bound
    # the same periods take more steps, each within them.
    bounded = hdi.Drive(paper_scene, steps_per_period=4)
    free = hdi.Drive(paper_scene)
    flags, steps = [], []
    for _ in range(40):
        bounded.step(68.0, ac_amplitude_v=0.5, ac_frequency_khz=10.5)
        free.step(68.0, ac_amplitude_v=0.5, ac_frequency_khz=10.5)
        flags.append(bounded.last_period["error_estimate"])
        steps.append((bounded.last_period["steps"], free.last_period["steps"]))
    assert all(b <= 5 for b, _ in steps)
    assert max(f for _, f in steps) > 8
    assert any(f > 1.0 for f in flags)
    assert free.last_period["error_estimate"] <= 1.0
    for bad in (0, 65):
        with pytest.raises(hdi.InvalidInputError) as e:
            hdi.Drive(paper_scene, steps_per_period=bad)
        assert e.value.field == "steps_per_period"


def test_the_exponential_scheme_steps_its_own_periods_close_to_the_integrator(paper_scene):
    # A command changed every period (the case the scheme is for): its periods are its own
    # (last_period["exponential"]), and the true gap stays within 0.1 pm of the integrator's.
    exp = hdi.Drive(paper_scene, scheme="exponential")
    ref = hdi.Drive(paper_scene)
    own, worst = 0, 0.0
    for k in range(60):
        p = 66.0 + (0.001 if k % 2 else 0.0)
        a, b = exp.step(p), ref.step(p)
        own += exp.last_period["exponential"]
        worst = max(worst, abs(a.truth.gap_nm - b.truth.gap_nm))
    assert own > 30
    assert 0.0 < worst < 1e-4
    with pytest.raises(hdi.InvalidInputError) as e:
        hdi.Drive(paper_scene, scheme="implicit")
    assert e.value.field == "scheme"
