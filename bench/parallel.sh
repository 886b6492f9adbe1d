#!/usr/bin/env bash
# The parallel construction (issue "Performance", item 2): `orbitri triangulate` one point
# at a time (the default) against `--threads 1` and `--threads 2` (the parallel build), side
# by side in one run, alternating per repetition, on N uniform points in the unit cube
# (`orbitri generate`, case torus), in the unit square (case square) and on the unit sphere
# (case sphere). Raw lines go to
# bench/out/parallel_raw.txt; medians are printed per case and command.
#
# usage: bench/parallel.sh [REPS] [N ...]      default: 5 reps, N = 1000000
set -euo pipefail
. "$(dirname "$0")/setup.sh"
reps=${1:-5}
shift || true
ns=${*:-1000000}
raw=$out/parallel_raw.txt
commit=$(git -C "$root" rev-parse --short HEAD)
stamp="commit=$commit date=$(date -u +%F)"
for n in $ns; do
    cube=$out/cube_$n.txt
    square=$out/square_$n.txt
    sphere=$out/unit_sphere_$n.txt
    [ -f "$cube" ] || "$orb" generate "$n" --seed 1 -o "$cube"
    [ -f "$square" ] || "$orb" generate "$n" --seed 1 --dim 2 -o "$square"
    [ -f "$sphere" ] || python3 - "$n" "$sphere" <<'PY'
import math, random, sys
n, path = int(sys.argv[1]), sys.argv[2]
rng = random.Random(1)
with open(path, "w") as f:
    for _ in range(n):
        v = [rng.gauss(0.0, 1.0) for _ in range(3)]
        r = math.sqrt(sum(x * x for x in v))
        f.write("%r %r %r\n" % tuple(x / r for x in v))
PY
    for rep in $(seq "$reps"); do
        for threads in none 1 2; do
            flag=()
            [ "$threads" = none ] || flag=(--threads "$threads")
            line=$("$orb" triangulate "$cube" --box 1 1 1 "${flag[@]}" --stats --format cells -o /dev/null 2>&1)
            echo "tool=orbitri case=torus cmd=threads-$threads N=$n rep=$rep $line $stamp"
            line=$("$orb" triangulate "$square" --box 1 1 "${flag[@]}" --stats --format cells -o /dev/null 2>&1)
            echo "tool=orbitri case=square cmd=threads-$threads N=$n rep=$rep $line $stamp"
            line=$("$orb" triangulate "$sphere" --space sphere --normalize "${flag[@]}" --stats --format cells -o /dev/null 2>&1)
            echo "tool=orbitri case=sphere cmd=threads-$threads N=$n rep=$rep $line $stamp"
        done
    done
done | tee -a "$raw" >/dev/null
python3 "$root/bench/medians.py" "$raw" "$commit"
