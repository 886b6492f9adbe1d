#!/usr/bin/env bash
# Inputs whose dummy points have large stars: N points on four planes of the unit cube
# (z = 0, 0.25, 0.5, 0.75; x, y uniform, Python's random seeded with 1), where each dummy
# point sits alone in the empty slab between two planes. Per repetition, `orbitri
# triangulate` (build_seconds) and CGAL's `dump3f` (the periodic class with its dummy
# points, time_s) on the same points. Raw lines go to bench/out/large_holes_raw.txt;
# medians are printed.
#
# usage: bench/large_holes.sh [REPS] [N ...]      default: 3 reps, N = 20000 50000 200000
set -euo pipefail
. "$(dirname "$0")/setup.sh"
anchor_src=${ANCHOR:-$root/../shared/anchors/cgal}
. "$root/bench/anchor.sh"
cgal=$out/cgal/cgal_anchor
reps=${1:-3}
shift || true
ns=${*:-20000 50000 200000}
raw=$out/large_holes_raw.txt
stamp="commit=$(git -C "$root" rev-parse --short HEAD) date=$(date -u +%F)"
for n in $ns; do
    pts=$out/planes_$n.txt
    python3 - "$n" "$pts" <<'PY'
import random, sys
n, path = int(sys.argv[1]), sys.argv[2]
rng = random.Random(1)
with open(path, "w") as f:
    for i in range(n):
        f.write("%r %r %r\n" % (rng.random(), rng.random(), 0.25 * (i % 4)))
PY
    (echo "1 1 1"; cat "$pts") > "$pts.cgal"
    for rep in $(seq "$reps"); do
        line=$("$orb" triangulate "$pts" --box 1 1 1 --stats --format cells -o /dev/null 2>&1)
        echo "tool=orbitri input=planes N=$n rep=$rep $line $stamp"
        line=$("$cgal" dump3f "$pts.cgal" /dev/null)
        echo "tool=cgal input=planes N=$n rep=$rep $line $stamp"
    done
done | tee -a "$raw" >/dev/null
python3 - "$raw" "$(git -C "$root" rev-parse --short HEAD)" <<'PY'
import re, statistics, sys
rows = {}
for line in open(sys.argv[1]):
    if "commit=" + sys.argv[2] not in line:
        continue
    f = dict(re.findall(r"(\w+)=(\S+)", line))
    t = float(f.get("build_seconds") or f["time_s"])
    rows.setdefault((int(f["N"]), f["tool"]), []).append(t)
for (n, tool), ts in sorted(rows.items()):
    print(f"planes N={n} {tool}: median {statistics.median(ts):.3f} s of {len(ts)}")
PY
