#!/usr/bin/env bash
# Builds the Python package as a wheel that installs without Rust: abi3 (one wheel for
# CPython 3.9 and later), manylinux2014 (glibc 2.17 and later), linked with zig through
# the `ziglang` package so that the machine's own glibc does not leak in. Writes
# dist/orbitri-VERSION-cp39-abi3-manylinux_2_17_x86_64.manylinux2014_x86_64.whl (for this
# machine's architecture) and prints its path. maturin checks the wheel's symbols against
# the manylinux policy (its built-in auditwheel) and fails if one is too new.
#
# The build tools go into their own virtual environment (target/wheel-venv, or the one
# ORBITRI_WHEEL_VENV names); extra arguments go to `maturin build`.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=${ORBITRI_WHEEL_VENV:-target/wheel-venv}
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/python" -m pip install -q "maturin>=1.7,<2" "ziglang>=0.11"
# maturin runs zig as `python3 -m ziglang`: the environment's python3 must come first
export PATH="$PWD/$venv/bin:$PATH"
rm -f dist/orbitri-*.whl
maturin build --release --locked --strip --zig --compatibility manylinux2014 --out dist "$@" >&2
ls dist/orbitri-*-cp39-abi3-*manylinux*.whl
