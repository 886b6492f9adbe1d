#!/usr/bin/env bash
# Degenerate inputs, Python's random seeded with 1:
#   planes: N points on four planes of the unit cube (z = 0, 0.25, 0.5, 0.75; x, y
#           uniform), where each dummy point sits alone in the empty slab between two planes;
#   slab:   N uniform points in a slab a tenth of the cube thick (z < 0.1) beside a vacuum,
#           where the last dummy points cannot leave the quotient (the build goes on in the
#           covering of level 0);
#   lines:  N points on 16 lines of the unit cube along x (y, z on a 4 x 4 grid), where
#           each dummy point sits alone in the empty tube between four lines;
#   shell:  N points in a hollow spherical shell (radius 0.3 to 0.31 about the centre),
#           where the dummy points inside have every point of the shell in their link;
#   blob:   N points of a Gaussian blob (sigma 0.05 about the centre) in a vacuum, a
#           molecule or cluster in a large periodic box (the build ends in the covering);
#   sc, bcc, fcc: the simple, body-centred and face-centred cubic crystals filling the
#           unit cube with about N atoms (k³, 2k³, 4k³ for the k nearest), where every
#           Delaunay sphere passes through 8 (sc), 4 (bcc) or 6 (fcc) atoms and most
#           in-sphere tests are exact ties.
# Per repetition, `orbitri triangulate` (build_seconds) and CGAL's `dump3f` (the periodic
# class with its dummy points, time_s) on the same points. Raw lines go to
# bench/out/large_holes_raw.txt; medians are printed.
#
# usage: bench/degenerate.sh [REPS] [N ...]      default: 3 reps, N = 20000 50000 200000
#        INPUTS="planes slab" (default) chooses the inputs, e.g. INPUTS="sc bcc fcc" or
#        INPUTS="lines shell blob".
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
for input in ${INPUTS:-planes slab}; do
for n in $ns; do
    pts=$out/${input}_$n.txt
    python3 - "$input" "$n" "$pts" <<'PY'
import random, sys
input, n, path = sys.argv[1], int(sys.argv[2]), sys.argv[3]
rng = random.Random(1)
basis = {"sc": [(0, 0, 0)], "bcc": [(0, 0, 0), (.5, .5, .5)],
         "fcc": [(0, 0, 0), (.5, .5, 0), (.5, 0, .5), (0, .5, .5)]}
with open(path, "w") as f:
    if input in basis:
        k = round((n / len(basis[input])) ** (1 / 3))
        for i in range(k):
            for j in range(k):
                for l in range(k):
                    for a, b, c in basis[input]:
                        f.write("%r %r %r\n" % ((i + a) / k, (j + b) / k, (l + c) / k))
    for i in range(0 if input in basis else n):
        if input == "lines":
            p = (rng.random(), 0.25 * (i % 4) + 0.1, 0.25 * (i // 4 % 4) + 0.1)
        elif input == "blob":
            p = tuple(0.5 + 0.05 * rng.gauss(0, 1) for _ in range(3))
        elif input == "shell":
            v = [rng.gauss(0, 1) for _ in range(3)]
            r = sum(c * c for c in v) ** 0.5
            p = tuple(0.5 + (0.3 + 0.01 * rng.random()) * c / r for c in v)
        else:
            x, y = rng.random(), rng.random()
            p = (x, y, 0.25 * (i % 4) if input == "planes" else 0.1 * rng.random())
        f.write("%r %r %r\n" % p)
PY
    (echo "1 1 1"; cat "$pts") > "$pts.cgal"
    for rep in $(seq "$reps"); do
        line=$("$orb" triangulate "$pts" --box 1 1 1 --stats --format cells -o /dev/null 2>&1)
        echo "tool=orbitri input=$input N=$n rep=$rep $line $stamp"
        line=$("$cgal" dump3f "$pts.cgal" /dev/null)
        echo "tool=cgal input=$input N=$n rep=$rep $line $stamp"
    done
done
done | tee -a "$raw" >/dev/null
python3 - "$raw" "$(git -C "$root" rev-parse --short HEAD)" <<'PY'
import re, statistics, sys
rows = {}
for line in open(sys.argv[1]):
    if "commit=" + sys.argv[2] not in line:
        continue
    f = {}
    for k, v in re.findall(r"(\w+)=(\S+)", line):
        # (the first of a name: the tool's own `input=` count comes after the script's)
        f.setdefault(k, v)
    t = float(f.get("build_seconds") or f["time_s"])
    rows.setdefault((f["input"], int(f["N"]), f["tool"]), []).append(t)
for (input, n, tool), ts in sorted(rows.items()):
    print(f"{input} N={n} {tool}: median {statistics.median(ts):.3f} s of {len(ts)}")
PY
