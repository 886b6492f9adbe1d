#!/usr/bin/env bash
# Voronoi extraction after triangulation: `orbitri voronoi --stats` on the harness's uniform
# points (cube and square), 1 and 2 threads (RAYON_NUM_THREADS), the measures alone and with
# the neighbour pairs (`--neighbours`, written to /dev/null), REPS runs each, alternating;
# prints the median build and extraction times. Output rows go to bench/out/voronoi_raw.txt.
#
# usage: bench/voronoi.sh [REPS] [N ...]     default: 3 reps, N = 100000 1000000
set -euo pipefail
. "$(dirname "$0")/setup.sh"
reps=${1:-3}
shift || true
ns=${*:-100000 1000000}
raw=$out/voronoi_raw.txt
stamp="commit=$(git -C "$root" rev-parse --short HEAD) date=$(date -u +%F)"
for case in "cube 3 1,1,1" "square 2 1,1"; do
    read -r input dim box <<<"$case"
    for n in $ns; do
        pts=$out/${input}_$n.txt
        [ -f "$pts" ] || "$orb" generate "$n" --seed 1 --dim "$dim" -o "$pts"
        for threads in 1 2; do
            for rep in $(seq "$reps"); do
                for pairs in 0 1; do
                    flag=()
                    [ "$pairs" = 0 ] || flag=(--neighbours /dev/null)
                    line=$(RAYON_NUM_THREADS=$threads "$orb" voronoi "$pts" --box ${box//,/ } "${flag[@]}" --stats --format csv -o /dev/null 2>&1 >/dev/null)
                    echo "input=$input N=$n threads=$threads pairs=$pairs rep=$rep $line $stamp" | tee -a "$raw"
                done
            done
        done
    done
done
python3 - "$raw" "${stamp%% *}" <<'PY'
import statistics, sys
from collections import defaultdict
commit = sys.argv[2].split("=")[1]
t = defaultdict(lambda: ([], [], []))
for line in open(sys.argv[1]):
    # first occurrence wins: the script's own keys come before the tool's (`input=` twice)
    d = {}
    for kv in line.split():
        if "=" in kv:
            k, v = kv.split("=", 1)
            d.setdefault(k, v)
    if d.get("commit") != commit:
        continue
    k = (d["input"], int(d["N"]), int(d["threads"]), d.get("pairs", "0") == "1")
    t[k][0].append(float(d["build_seconds"]))
    t[k][1].append(float(d["voronoi_seconds"]))
    t[k][2].append(int(d.get("voronoi_peak_rss_kb", d["peak_rss_kb"])))
print(f"commit {commit}")
print("| input | N | threads | pairs | runs | build s | Voronoi s | µs/cell | Voronoi / build | peak RSS MiB (after Voronoi) |")
print("|---|---:|---:|---|---:|---:|---:|---:|---:|---:|")
for (inp, n, th, pairs), (b, v, m) in sorted(t.items()):
    mb, mv = statistics.median(b), statistics.median(v)
    print(f"| {inp} | {n} | {th} | {'yes' if pairs else 'no'} | {len(v)} | {mb:.3f} | {mv:.3f} | {mv / n * 1e6:.2f} | {mv / mb:.2f} | {statistics.median(m) / 1024:.0f} |")
PY
