#!/usr/bin/env bash
# Weighted points (issue "Weighted points"), side by side in one run, per N and repetition:
# 3D: `orbitri triangulate --weights` on the anchor's `gen3` points with its `genw` weights
# (seed 1, weights in [0, 1e-4)) against CGAL's `rt3` (non-periodic) and `p3rt3f` (its
# periodic class) on the same weighted points; 2D: the `gen2` points with weights u01·1e-6
# drawn after the coordinates (the anchor's `rt2` stream) against `rt2`; the power cells:
# `orbitri voronoi --weights` against pyvoro2's power mode (Voro++) on the 3D points.
# Raw lines go to bench/out/weighted_raw.txt, medians are printed as table rows.
#
# usage: bench/weighted.sh [REPS] [N ...]      default: 3 reps, N = 100000 1000000
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
anchor_src=${ANCHOR:-$root/../shared/anchors/cgal}
out=$root/bench/out
mkdir -p "$out"
. "$root/bench/anchor.sh"
cargo build --release -q -p orbitri-cli --manifest-path "$root/Cargo.toml"
orb=$root/target/release/orbitri
cgal=$out/cgal/cgal_anchor
venv=$out/bench-venv
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/python" -c "import pyvoro2" 2>/dev/null || "$venv/bin/pip" install -q numpy "pyvoro2>=0.8"
reps=${1:-3}
shift || true
ns=${*:-100000 1000000}
raw=$out/weighted_raw.txt
stamp="commit=$(git -C "$root" rev-parse --short HEAD) date=$(date -u +%F)"
for n in $ns; do
    w3=$out/weighted3_$n.txt
    w2=$out/weighted2_$n.txt
    if ! [ -f "$w3" ]; then
        "$cgal" gen3 "$n" 1 "$out/gen3_$n.tmp" >/dev/null
        "$cgal" genw "$n" 1 "$out/genw_$n.tmp" >/dev/null
        tail -n +2 "$out/gen3_$n.tmp" | paste -d' ' - "$out/genw_$n.tmp" >"$w3"
        rm "$out/gen3_$n.tmp" "$out/genw_$n.tmp"
    fi
    if ! [ -f "$w2" ]; then
        PYTHONPATH=$anchor_src python3 - "$n" "$w2" <<'PY'
import sys
from prng_reference import SplitMix64
n, path = int(sys.argv[1]), sys.argv[2]
g = SplitMix64(1)
pts = [(g.u01(), g.u01()) for _ in range(n)]
with open(path, "w") as f:
    for x, y in pts:
        f.write(f"{x!r} {y!r} {g.u01() * 1e-6!r}\n")
PY
    fi
    for rep in $(seq "$reps"); do
        line=$("$orb" triangulate "$w3" --box 1 1 1 --weights --stats --format cells -o /dev/null 2>&1)
        echo "tool=orbitri case=3d N=$n rep=$rep $line $stamp"
        echo "tool=cgal case=3d N=$n rep=$rep $("$cgal" rt3 "$n" 1) $stamp"
        echo "tool=cgal case=3d N=$n rep=$rep $("$cgal" p3rt3f "$n" 1) $stamp"
        line=$("$orb" triangulate "$w2" --box 1 1 --weights --stats --format cells -o /dev/null 2>&1)
        echo "tool=orbitri case=2d N=$n rep=$rep $line $stamp"
        echo "tool=cgal case=2d N=$n rep=$rep $("$cgal" rt2 "$n" 1) $stamp"
        line=$("$orb" voronoi "$w3" --box 1 1 1 --weights --stats --format csv -o /dev/null 2>&1)
        echo "tool=orbitri case=power N=$n rep=$rep $line $stamp"
        line=$("$venv/bin/python" - "$w3" <<'PY'
import resource, sys, time
import numpy as np, pyvoro2 as pv
a = np.loadtxt(sys.argv[1])
dom = pv.OrthorhombicCell(bounds=((0, 1), (0, 1), (0, 1)), periodic=(True, True, True))
t = time.perf_counter()
cells = pv.compute(a[:, :3], domain=dom, mode="power", weights=a[:, 3], include_empty=True,
                   output="cells", return_vertices=False, return_adjacency=False, return_faces=False)
dt = time.perf_counter() - t
vol = sum(c["volume"] for c in cells)
empty = sum(c["volume"] <= 0 for c in cells)
print(f"cmd=pyvoro2_power time_s={dt:.6f} volume_sum={vol!r} empty={empty} "
      f"peak_rss_kB={resource.getrusage(resource.RUSAGE_SELF).ru_maxrss}")
PY
)
        echo "tool=pyvoro2 case=power N=$n rep=$rep $line $stamp"
    done
done | tee -a "$raw"
python3 "$root/bench/medians.py" "$raw" "$(git -C "$root" rev-parse --short HEAD)" --voronoi power --extra hidden,empty
