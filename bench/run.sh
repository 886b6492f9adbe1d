#!/usr/bin/env bash
# Side-by-side benchmark of `orbitri triangulate` against the CGAL anchor harness
# (../shared/anchors/cgal): same machine, same points (the harness's generator, seed 1),
# tools alternating within each repetition. Appends raw key=value lines to bench/out/raw.txt
# and prints the summary table (bench/summarize.py) that BENCHMARKS.md reproduces.
#
# usage: bench/run.sh [REPS] [N ...]        default: 5 reps, N = 100 10000 100000 1000000
#        CUBE=0 bench/run.sh ...            skip the uniform unit cube (3D)
#        SQUARE=0 bench/run.sh ...          skip the uniform unit square (2D)
#        CLUSTERED=0 bench/run.sh ...       skip the clustered set
#        CLUSTER_REPS=3 (default)            repetitions of the clustered set: CGAL needs its
#                                            27-sheeted cover there and takes ~75 s per run
#        CUBE_CGAL=dt3 SQUARE_CGAL=dt2 ...  the CGAL commands to compare with (default: the
#                                            periodic classes, stock and fixed, and the
#                                            non-periodic one); the per-point cost from 10⁴
#                                            to 10⁷: CUBE_CGAL=dt3 SQUARE_CGAL=dt2
#                                            CLUSTERED=0 bench/run.sh 3 10000 100000
#                                            1000000 10000000
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
anchor_src=${ANCHOR:-$root/../shared/anchors/cgal}
out=$root/bench/out
mkdir -p "$out"

. "$root/bench/anchor.sh"
cargo build --release -q -p orbitri-cli --manifest-path "$root/Cargo.toml"
orb=$root/target/release/orbitri
cgal=$out/cgal/cgal_anchor

reps=${1:-5}
shift || true
ns=${*:-100 10000 100000 1000000}
raw=$out/raw.txt
stamp="commit=$(git -C "$root" rev-parse --short HEAD) date=$(date -u +%F)"
load() { cut -d' ' -f1 /proc/loadavg; }

# input name, dimension, box, CGAL commands
cases=()
[ "${CUBE:-1}" = 1 ] && cases+=("cube 3 1,1,1 ${CUBE_CGAL:-p3dt3,p3dt3f,dt3}")
[ "${SQUARE:-1}" = 1 ] && cases+=("square 2 1,1 ${SQUARE_CGAL:-p2dt2,p2dt2f,dt2}")
for case in "${cases[@]}"; do
    read -r input dim box cmds <<<"$case"
    for n in $ns; do
        pts=$out/${input}_$n.txt
        [ -f "$pts" ] || "$orb" generate "$n" --seed 1 --dim "$dim" -o "$pts"
        for rep in $(seq "$reps"); do
            line=$("$orb" triangulate "$pts" --box ${box//,/ } --stats --format cells -o /dev/null 2>&1 >/dev/null)
            echo "tool=orbitri input=$input N=$n rep=$rep $line load1=$(load) $stamp" | tee -a "$raw"
            for c in ${cmds//,/ }; do
                echo "tool=cgal input=$input rep=$rep $("$cgal" "$c" "$n" 1) load1=$(load) $stamp" | tee -a "$raw"
            done
        done
    done
done

if [ "${CLUSTERED:-1}" = 1 ]; then
    # 100 Gaussian clusters (sigma 0.01) of 1000 points each, wrapped into the unit cube
    n=100000
    python3 "$root/bench/clustered.py" "$n" "$out/clustered.txt" "$out/clustered_cgal.txt"
    for rep in $(seq "${CLUSTER_REPS:-3}"); do
        line=$("$orb" triangulate "$out/clustered.txt" --box 1 1 1 --stats --format cells -o /dev/null 2>&1 >/dev/null)
        echo "tool=orbitri input=clustered N=$n rep=$rep $line load1=$(load) $stamp" | tee -a "$raw"
        for c in dump3f; do
            echo "tool=cgal input=clustered N=$n rep=$rep $("$cgal" "$c" "$out/clustered_cgal.txt" /dev/null) load1=$(load) $stamp" | tee -a "$raw"
        done
    done
fi
python3 "$root/bench/summarize.py" "$raw"
