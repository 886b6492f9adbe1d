#!/usr/bin/env bash
# Before and after, side by side in one run: builds the command at BASE (a commit) in a
# scratch worktree and at the working tree, then alternates the two on the same points
# (the harness's uniform points, seed 1: cube and square), REPS runs each, and prints the
# medians of the construction and Voronoi times. Rows go to bench/out/compare_raw.txt.
#
# usage: bench/compare.sh BASE [REPS] [N ...]     default: 5 reps, N = 100000 1000000
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
base=${1:?usage: bench/compare.sh BASE [REPS] [N ...]}
shift
reps=${1:-5}
shift || true
ns=${*:-100000 1000000}
out=$root/bench/out
mkdir -p "$out"
wt=$out/base-worktree
if [ ! -d "$wt" ]; then
    git -C "$root" worktree add -f "$wt" "$base" >/dev/null
fi
git -C "$wt" checkout -q --detach "$base"
cargo build --release -q -p orbitri-cli --manifest-path "$wt/Cargo.toml"
cargo build --release -q -p orbitri-cli --manifest-path "$root/Cargo.toml"
old=$wt/target/release/orbitri
new=$root/target/release/orbitri
raw=$out/compare_raw.txt
stamp="base=$(git -C "$wt" rev-parse --short HEAD) head=$(git -C "$root" rev-parse --short HEAD) date=$(date -u +%F)"
for case in "cube 3 1,1,1" "square 2 1,1"; do
    read -r input dim box <<<"$case"
    for n in $ns; do
        pts=$out/${input}_$n.txt
        [ -f "$pts" ] || "$new" generate "$n" --seed 1 --dim "$dim" -o "$pts"
        for rep in $(seq "$reps"); do
            for which in old new; do
                bin=$old
                [ "$which" = new ] && bin=$new
                line=$(RAYON_NUM_THREADS=1 "$bin" voronoi "$pts" --box ${box//,/ } --stats --format csv -o /dev/null 2>&1 >/dev/null)
                echo "which=$which input=$input N=$n rep=$rep $line $stamp" | tee -a "$raw"
            done
        done
    done
done
python3 - "$raw" "$stamp" <<'PY'
import statistics, sys
from collections import defaultdict
stamp = sys.argv[2]
t = defaultdict(lambda: ([], []))
for line in open(sys.argv[1]):
    if stamp not in line:
        continue
    d = {}
    for kv in line.split():
        if "=" in kv:
            k, v = kv.split("=", 1)
            d.setdefault(k, v)
    key = (d["input"], int(d["N"]), d["which"])
    t[key][0].append(float(d["build_seconds"]))
    t[key][1].append(float(d["voronoi_seconds"]))
print(f"{stamp}, one thread, medians")
print("| input | N | build before | build after | ratio | Voronoi before | Voronoi after | ratio |")
print("|---|---|---|---|---|---|---|---|")
for (inp, n, which) in sorted(t):
    if which != "new":
        continue
    b0, v0 = map(statistics.median, t[(inp, n, "old")])
    b1, v1 = map(statistics.median, t[(inp, n, "new")])
    print(f"| {inp} | {n} | {b0:.3f} s | {b1:.3f} s | {b1/b0:.3f} | {v0:.3f} s | {v1:.3f} s | {v1/v0:.3f} |")
PY
