#!/usr/bin/env bash
# Issue 13, item 4: the Voronoi volumes of N uniform points from Python, end to end,
# orbitri against freud, alternating, each in a fresh process: time, peak RSS, and RSS
# after `del` and `gc.collect()`. Needs the wheel and freud installed in the Python given
# by $PYTHON (default: the tests' .venv, which tests.sh fills). Raw lines go to
# bench/out/python_raw.txt.
#
# usage: bench/python.sh [REPS] [N ...]      default: 3 reps, N = 1000000
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
python=${PYTHON:-$root/.venv/bin/python}
reps=${1:-3}
shift || true
ns=${*:-1000000}
mkdir -p "$root/bench/out"
stamp="commit=$(git -C "$root" rev-parse --short HEAD) date=$(date -u +%F)"
for n in $ns; do
    for rep in $(seq "$reps"); do
        for tool in orbitri freud; do
            echo "$("$python" "$root/bench/python_voronoi.py" "$n" "$tool") rep=$rep $stamp"
        done
    done
done | tee -a "$root/bench/out/python_raw.txt"
