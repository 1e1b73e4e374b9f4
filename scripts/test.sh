#!/usr/bin/env bash
# Every test of the repository: the Rust crate's (with all features: the `hdi` program, plots,
# rayon), then the Python package built into its own virtual environment and its pytest suite.
# A fresh machine needs only Rust and CPython >= 3.9: maturin, numpy, pytest and pandas (for the
# tests of `to_dataframe`, an optional dependency of the package) come from PyPI.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
# One build directory for the crate and its Python package.
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$root/target}"
# No incremental caches unless asked for (CARGO_INCREMENTAL=1): on a fresh machine they are
# gigabytes of disk that no later build reads.
export CARGO_INCREMENTAL="${CARGO_INCREMENTAL:-0}"

cargo test --all-features
# The numbers the docs quote against the code (docs/architecture.md, "Numbers in the docs"):
# about 9 s of CPU, mostly the paper example's sweeps; `-- --check --slow` adds the fits.
cargo run --all-features --profile test --example docs_numbers -- --check >/dev/null
# The `hdi` program that run built (the integration tests run it): the Python tests compare
# against that same binary, so nothing is built again for them.
if [ -z "${HDI_BIN:-}" ]; then
  HDI_BIN=$(cargo test --all-features --no-run --message-format=json 2>/dev/null | "${PYTHON:-python3}" -c '
import json, sys
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m["target"]["name"] == "hdi" \
            and "bin" in m["target"]["kind"] and not m["profile"]["test"] and m.get("executable"):
        print(m["executable"])
')
  export HDI_BIN
fi

venv="$root/python/.venv"
py="${PYTHON:-python3}"
if [ ! -x "$venv/bin/python" ]; then
  "$py" -m venv "$venv"
fi
if ! "$venv/bin/python" -c "import maturin, numpy, pytest, pandas" >/dev/null 2>&1; then
  "$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
    "maturin>=1.5,<2" "numpy>=1.21" "pytest>=7" "pandas>=1.3"
fi
# Build and install the package with the README's own command, `pip install ./python`: pip
# fetches maturin into an isolated build environment as a user's pip does, so the build
# requirements, the paths and python/Cargo.lock are checked on every run; the shared target
# directory keeps it to a relink when nothing changed. (A build from a fresh clone costs about
# 3.5 min of CPU: too much for every run; see docs/python.md.)
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check ./python
# The bit-for-bit tests run the `hdi` program that `cargo test --all-features` built above.
"$venv/bin/python" -m pytest -q python/tests

# The C ABI (capi/, a crate of its own with its own Cargo.lock): its tests compile the C
# example and a program of misuses with the system C compiler, compare the example with the
# Rust example to the bit, and run both under valgrind where it is installed
# (docs/firmware.md, "How it is checked").
cargo test --manifest-path capi/Cargo.toml
