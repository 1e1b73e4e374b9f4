"""Ctrl-C stops a long call: a subprocess running a long sweep gets SIGINT after about a second
and must end with KeyboardInterrupt within a few seconds (the sweep alone runs far longer)."""

import os
import signal
import subprocess
import sys
import time

import pytest

from conftest import REPO

SCRIPT = r"""
import sys, time
import hdi_tribology as hdi
model = hdi.Model(hdi.Scene.paper())
print("ready", flush=True)
t0 = time.perf_counter()
try:
    hdi.{call}
except KeyboardInterrupt:
    print(f"interrupted after {{time.perf_counter() - t0:.3f}} s", flush=True)
    sys.exit(3)
print("finished", flush=True)
"""

CALLS = {
    # 2000 amplitudes at rtol 1e-12 on one thread: about a minute of work on a fast machine
    # (some 35 ms a cycle), so the interrupt after a second always comes mid-call
    "sweep": "ac_sweep(model, [0.0005 * i for i in range(2000)], rtol=1e-12, threads=1)",
    "replay": "replay(model, [0.0, 30.0], [60.0, 60.0], [0.0, 0.0])",
    "forces": "forces(model, [1e6 + i for i in range(10**6)])",
    # the air bearing on 1025 x 1025 control volumes: some 15 s of work on one core
    "bearing": "bearing({!r}, cells=1025)".format(
        str(REPO / "scenes" / "bearing" / "two_rail_taper_flat.toml")),
}


@pytest.mark.skipif(os.name != "posix", reason="SIGINT to a subprocess")
@pytest.mark.parametrize("name", sorted(CALLS))
def test_ctrl_c_interrupts_a_long_call(name):
    p = subprocess.Popen([sys.executable, "-c", SCRIPT.format(call=CALLS[name])],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "ready"
        time.sleep(1.0)
        sent = time.perf_counter()
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=30)
        waited = time.perf_counter() - sent
    finally:
        if p.poll() is None:
            p.kill()
    assert p.returncode == 3, (out, err)
    assert "interrupted after" in out, (out, err)
    assert waited < 5.0, f"{name}: KeyboardInterrupt came {waited:.2f} s after SIGINT"
