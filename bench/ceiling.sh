#!/usr/bin/env bash
# What two cores can give this machine's builds (issue "Performance", item 2): one
# `orbitri triangulate` one point at a time alone, then two of them at once (independent
# processes, nothing shared but the machine), alternating per repetition, on the inputs of
# bench/parallel.sh (run it first: it makes them). A parallel build on two threads cannot
# beat half the time of one of the pair: `pair / alone / 2` is its floor as a fraction of
# one thread, whatever the algorithm (memory bandwidth and the shared cache are the limit).
#
# usage: bench/ceiling.sh [REPS] [N]      default: 5 reps, N = 1000000
set -euo pipefail
. "$(dirname "$0")/setup.sh"
reps=${1:-5}
n=${2:-1000000}
build() {
    "$orb" triangulate "$@" --stats --format cells -o /dev/null 2>&1 |
        grep -o 'build_seconds=[0-9.]*' | cut -d= -f2
}
for case in "torus cube_$n.txt --box 1 1 1" "square square_$n.txt --box 1 1" \
    "sphere unit_sphere_$n.txt --space sphere --normalize"; do
    read -r name file args <<<"$case"
    [ -f "$out/$file" ] || { echo "missing $out/$file: run bench/parallel.sh first" >&2; exit 1; }
    alone=() pair=()
    for _ in $(seq "$reps"); do
        # shellcheck disable=SC2086
        alone+=("$(build "$out/$file" $args)")
        # shellcheck disable=SC2086
        { build "$out/$file" $args >"$out/.pair_a"; } &
        # shellcheck disable=SC2086
        b=$(build "$out/$file" $args)
        wait
        pair+=("$(awk -v a="$(cat "$out/.pair_a")" -v b="$b" 'BEGIN { print (a > b ? a : b) }')")
    done
    rm -f "$out/.pair_a"
    python3 - "$name" "$n" "${alone[*]}" "${pair[*]}" "$(git -C "$root" rev-parse --short HEAD)" <<'PY'
import statistics, sys
name, n, alone, pair, commit = sys.argv[1:]
a = statistics.median(map(float, alone.split()))
p = statistics.median(map(float, pair.split()))
print(f"case={name} N={n} alone={a:.3f} pair={p:.3f} slowdown={p / a:.2f} "
      f"two_thread_floor={p / a / 2:.2f} commit={commit}")
PY
done
