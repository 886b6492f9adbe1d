#!/usr/bin/env bash
# The sphere and the projective plane (issue "The sphere and the real projective plane"),
# side by side in one run, per N and repetition, on the CGAL anchor's sphere points
# (`gens N 1`): `orbitri triangulate --space sphere` against CGAL's
# `Delaunay_triangulation_on_sphere_2` (`sphere`) and scipy's `ConvexHull` (Qhull), `orbitri
# triangulate --space projective-plane` on the same points (case rp2), and `orbitri voronoi
# --space sphere` (build and cells) against scipy's `SphericalVoronoi` (with its areas).
# scipy runs once per N (it takes 20–60 s at 10⁶). Raw lines go to
# bench/out/sphere_raw.txt, medians are printed as table rows.
#
# usage: bench/sphere.sh [REPS] [N ...]      default: 5 reps, N = 100000 1000000
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
"$venv/bin/python" -c "import scipy" 2>/dev/null || "$venv/bin/pip" install -q numpy scipy
reps=${1:-5}
shift || true
ns=${*:-100000 1000000}
raw=$out/sphere_raw.txt
stamp="commit=$(git -C "$root" rev-parse --short HEAD) date=$(date -u +%F)"
for n in $ns; do
    pts=$out/sphere_$n.txt
    [ -f "$pts" ] || "$cgal" gens "$n" 1 "$pts" >/dev/null
    for rep in $(seq "$reps"); do
        line=$("$orb" triangulate "$pts" --space sphere --stats --format cells -o /dev/null 2>&1)
        echo "tool=orbitri case=delaunay N=$n rep=$rep $line $stamp"
        echo "tool=cgal case=delaunay N=$n rep=$rep $("$cgal" sphere "$n" 1) $stamp"
        line=$("$orb" triangulate "$pts" --space projective-plane --stats --format cells -o /dev/null 2>&1)
        echo "tool=orbitri case=rp2 N=$n rep=$rep $line $stamp"
        line=$("$orb" voronoi "$pts" --space sphere --stats --format csv -o /dev/null 2>&1)
        echo "tool=orbitri case=voronoi N=$n rep=$rep $line $stamp"
        [ "$rep" = 1 ] || continue
        for mode in hull voronoi; do
            line=$("$venv/bin/python" - "$pts" "$mode" <<'PY'
import resource, sys, time
import numpy as np
from scipy.spatial import ConvexHull, SphericalVoronoi
a = np.loadtxt(sys.argv[1])
t = time.perf_counter()
if sys.argv[2] == "hull":
    faces = len(ConvexHull(a).simplices)
    extra = f"faces={faces}"
else:
    sv = SphericalVoronoi(a)
    sv.sort_vertices_of_regions()
    extra = f"area_sum={sv.calculate_areas().sum()!r}"
dt = time.perf_counter() - t
print(f"cmd=scipy_{sys.argv[2]} time_s={dt:.6f} {extra} "
      f"peak_rss_kB={resource.getrusage(resource.RUSAGE_SELF).ru_maxrss}")
PY
)
            case=$([ "$mode" = hull ] && echo delaunay || echo voronoi)
            echo "tool=scipy case=$case N=$n rep=$rep $line $stamp"
        done
    done
done | tee -a "$raw"
python3 "$root/bench/medians.py" "$raw" "$(git -C "$root" rev-parse --short HEAD)" --voronoi voronoi
