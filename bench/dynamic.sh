#!/usr/bin/env bash
# Removal and moving-particle benchmarks of issue "Dynamic triangulations", side by side
# with the CGAL anchor (../shared/anchors/cgal, built by bench/run.sh's recipe if missing):
# per N and repetition, orbitri's removal of input points 0, 2, 4, … (one `remove` each,
# and one `remove_all`), then CGAL's `dt3rm` and `p3dt3rm` on the same points; then the
# moving loop (10 steps of moves by 1% of the spacing against rebuilding each step); then
# insertion one at a time in random order, insert_all and find_simplex against the bulk
# build (examples/batch.rs).
#
# usage: bench/dynamic.sh [REPS] [N ...]      default: 3 reps, N = 100000 1000000
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
anchor_src=${ANCHOR:-$root/../shared/anchors/cgal}
out=$root/bench/out
mkdir -p "$out"
. "$root/bench/anchor.sh"
cargo build --release -q -p orbitri --example dynamic --example batch --manifest-path "$root/Cargo.toml"
dyn=$root/target/release/examples/dynamic
cgal=$out/cgal/cgal_anchor
reps=${1:-3}
shift || true
ns=${*:-100000 1000000}
stamp="commit=$(git -C "$root" rev-parse --short HEAD) date=$(date -u +%F)"
for n in $ns; do
    for rep in $(seq "$reps"); do
        echo "tool=orbitri rep=$rep $("$dyn" remove 1 "$n") $stamp"
        echo "tool=cgal rep=$rep $("$cgal" dt3rm "$n" 1) $stamp"
        echo "tool=cgal rep=$rep $("$cgal" p3dt3rm "$n" 1) $stamp"
    done
done | tee -a "$out/dynamic_raw.txt"
"$dyn" move "$reps" 100000 | tee -a "$out/dynamic_raw.txt"
"$root/target/release/examples/batch" "$reps" $ns | tee -a "$out/dynamic_raw.txt"
