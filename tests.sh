#!/usr/bin/env bash
# The tests: the Rust workspace, then the Python package, built from this checkout and
# installed into a virtual environment (.venv, or the one ORBITRI_VENV names; created when
# missing), with pytest: its tests against freud and the command line, and its docstrings.
set -euo pipefail
cd "$(dirname "$0")"
cargo test --workspace --locked
# the Python round-trip test compares with the command's output
cargo build --locked -q -p orbitri-cli
venv=${ORBITRI_VENV:-.venv}
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/python" -m pip install -q --upgrade pip
"$venv/bin/python" -m pip install -q ".[test]"
ORBITRI_BIN="$PWD/target/debug/orbitri" "$venv/bin/python" -m pytest -q python/tests
(cd "$venv" && "$PWD/bin/python" -m pytest -q -p no:cacheprovider --doctest-modules --pyargs orbitri)
