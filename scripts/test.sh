#!/usr/bin/env bash
# Every test of the repository: the Rust crate's (with all features: the `hdi` program, plots,
# rayon), then the Python package built into its own virtual environment and its pytest suite.
# A fresh machine needs only Rust and CPython >= 3.9: maturin, numpy and pytest come from PyPI.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
# One build directory for the crate and its Python package.
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$root/target}"

cargo test --all-features

venv="$root/python/.venv"
py="${PYTHON:-python3}"
if [ ! -x "$venv/bin/python" ]; then
  "$py" -m venv "$venv"
fi
if ! "$venv/bin/python" -c "import maturin, numpy, pytest" >/dev/null 2>&1; then
  "$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
    "maturin>=1.5,<2" "numpy>=1.21" "pytest>=7"
fi
# Build the extension in release mode and install it into the environment (editable: the
# package's Python files are used in place).
(cd python && VIRTUAL_ENV="$venv" PATH="$venv/bin:$PATH" maturin develop --release --quiet)
# The bit-for-bit tests run the `hdi` program that `cargo test --all-features` built above.
"$venv/bin/python" -m pytest -q python/tests
