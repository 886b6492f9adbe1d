#!/usr/bin/env bash
# The tests: the Rust workspace, then the Python package: built as the wheel users install
# (python/build_wheel.sh: abi3, manylinux2014), shown to install and import in a fresh
# virtual environment whose PATH has no cargo, then installed with its test dependencies
# into a virtual environment (.venv, or the one ORBITRI_VENV names; created when missing)
# and run with pytest: its tests against freud, ASE, MDAnalysis, pandas, matplotlib, VTK
# and the command line, and its docstrings.
set -euo pipefail
cd "$(dirname "$0")"
cargo test --workspace --locked
# the Python round-trip test compares with the command's output
cargo build --locked -q -p orbitri-cli
wheel=$(bash python/build_wheel.sh | tail -n 1)
echo "wheel: $wheel"
fresh=$(mktemp -d)
trap 'rm -rf "$fresh"' EXIT
python3 -m venv "$fresh/venv"
# no Rust on this PATH: the wheel must install and import without building anything
env PATH="$fresh/venv/bin:/usr/local/bin:/usr/bin:/bin" bash -c '
    set -euo pipefail
    if command -v cargo || command -v rustc; then echo "cargo on the PATH of the no-Rust check" >&2; exit 1; fi
    pip install -q "$1"
    cd "$(mktemp -d)"
    python -c "import orbitri, numpy as np; v = orbitri.periodic_voronoi(np.random.default_rng(0).random((100, 3)), [1, 1, 1]); assert abs(v.volumes.sum() - 1) < 1e-12; print(\"wheel installed without Rust: orbitri\", orbitri.__version__)"
' _ "$PWD/$wheel"
venv=${ORBITRI_VENV:-.venv}
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/python" -m pip install -q --upgrade pip
"$venv/bin/python" -m pip install -q "$wheel[test]"
"$venv/bin/python" -m pip install -q --force-reinstall --no-deps "$wheel"
ORBITRI_BIN="$PWD/target/debug/orbitri" "$venv/bin/python" -m pytest -q python/tests
(cd "$venv" && "$PWD/bin/python" -m pytest -q -p no:cacheprovider --doctest-modules --pyargs orbitri)
