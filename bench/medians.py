"""Medians of a benchmark script's raw lines (`tool=… case=… N=… key=value…`), per (case, N,
command), for one commit: orbitri's `build_seconds` (plus `voronoi_seconds` for the cases
named in --voronoi) and peak memory, the others' `time_s` and `peak_rss_kB`.

usage: medians.py RAW COMMIT [--voronoi CASE,...] [--extra KEY,...]
"""
import statistics
import sys
from collections import defaultdict


def option(name):
    return sys.argv[sys.argv.index(name) + 1].split(",") if name in sys.argv else []


def main():
    raw, commit = sys.argv[1], sys.argv[2]
    voronoi, extra = option("--voronoi"), option("--extra")
    runs = defaultdict(list)
    for line in open(raw):
        d = {}
        for kv in line.split():
            if "=" in kv:
                k, v = kv.split("=", 1)
                d.setdefault(k, v)
        if d.get("commit") != commit:
            continue
        if d["tool"] == "orbitri" and d["case"] in voronoi:
            t = float(d["build_seconds"]) + float(d["voronoi_seconds"])
            mem = d.get("voronoi_peak_rss_kb")
        elif d["tool"] == "orbitri":
            t, mem = float(d["build_seconds"]), d.get("peak_rss_kb")
        else:
            t, mem = float(d["time_s"]), d.get("peak_rss_kB")
        mem = int(mem) if mem and mem.isdigit() else 0
        note = " ".join(f"{k}={d[k]}" for k in extra if k in d)
        runs[(d["case"], int(d["N"]), d.get("cmd", "orbitri"))].append((t, mem, note))
    for key in sorted(runs):
        ts = [r[0] for r in runs[key]]
        note = runs[key][0][2]
        print(f"{key[0]} N={key[1]} {key[2]}: median {statistics.median(ts):.3f} s over {len(ts)} "
              f"(runs {', '.join(f'{t:.3f}' for t in ts)}), peak {max(r[1] for r in runs[key]) / 1024:.0f} MB"
              + (f", {note}" if note else ""))


main()
