"""Shared fixtures: the paper scene's model (built once) and the `hdi` command line of the
same repository, for the bit-for-bit comparisons."""

import json
import os
import pathlib
import subprocess

import pytest

import hdi_tribology as hdi

REPO = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def paper_scene():
    return hdi.Scene.paper()


@pytest.fixture(scope="session")
def paper_model(paper_scene):
    return hdi.Model(paper_scene)


@pytest.fixture(scope="session")
def hdi_cli():
    """A function running the `hdi` program with the given arguments and returning its JSON.

    The program is `$HDI_BIN` when set, else built here with cargo (the `test` profile and
    every feature, as `cargo test --all-features` leaves it, so nothing is rebuilt after it).
    """
    exe = os.environ.get("HDI_BIN")
    if not exe:
        out = subprocess.run(
            ["cargo", "build", "--profile", "test", "--all-features", "--bin", "hdi",
             "--message-format=json"],
            cwd=REPO, check=True, capture_output=True, text=True,
        ).stdout
        for line in out.splitlines():
            msg = json.loads(line)
            if msg.get("reason") == "compiler-artifact" and msg.get("executable") and \
                    msg["target"]["name"] == "hdi":
                exe = msg["executable"]
        assert exe, "cargo built no `hdi` executable"

    def run(*args):
        done = subprocess.run([exe, *args], capture_output=True, text=True, cwd=REPO)
        assert done.returncode == 0, done.stderr
        return json.loads(done.stdout)

    return run
