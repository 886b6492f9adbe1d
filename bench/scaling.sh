#!/usr/bin/env bash
# Per-point cost from 10⁴ to 10⁷ (issue "Performance", item 1: flat): `orbitri triangulate`
# one thread against CGAL's non-periodic `dt3`/`dt2`, same points (`orbitri generate`, seed
# 1, the anchor's generator), alternating per repetition. Raw lines go to
# bench/out/scaling_raw.txt; medians per case, N and tool are printed (bench/medians.py).
#
# usage: bench/scaling.sh [REPS] [N ...]      default: 3 reps, N = 10⁴ 10⁵ 10⁶ 10⁷
#        SQUARE=0 / CUBE=0 bench/scaling.sh   skip a case
set -euo pipefail
. "$(dirname "$0")/setup.sh"
anchor_src=${ANCHOR:-$root/../shared/anchors/cgal}
. "$root/bench/anchor.sh"
cgal=$out/cgal/cgal_anchor
reps=${1:-3}
shift || true
ns=${*:-10000 100000 1000000 10000000}
raw=$out/scaling_raw.txt
commit=$(git -C "$root" rev-parse --short HEAD)
stamp="commit=$commit date=$(date -u +%F)"
cases=()
[ "${CUBE:-1}" = 1 ] && cases+=("cube 3 1,1,1 dt3")
[ "${SQUARE:-1}" = 1 ] && cases+=("square 2 1,1 dt2")
for case in "${cases[@]}"; do
    read -r input dim box cmd <<<"$case"
    for n in $ns; do
        pts=$out/${input}_$n.txt
        [ -f "$pts" ] || "$orb" generate "$n" --seed 1 --dim "$dim" -o "$pts"
        for rep in $(seq "$reps"); do
            line=$("$orb" triangulate "$pts" --box ${box//,/ } --stats --format cells -o /dev/null 2>&1)
            echo "tool=orbitri case=$input cmd=orbitri N=$n rep=$rep $line $stamp" | tee -a "$raw"
            echo "tool=cgal case=$input cmd=$cmd N=$n rep=$rep $("$cgal" "$cmd" "$n" 1) $stamp" | tee -a "$raw"
        done
    done
done
python3 "$root/bench/medians.py" "$raw" "$commit"
