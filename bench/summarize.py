"""Summarize bench/out/raw.txt: medians per (input, N, tool), ratios, peak memory.

usage: summarize.py RAW [--commit C]   (default: the newest commit in the file)
"""
import statistics
import sys
from collections import defaultdict


def parse(line):
    # first occurrence wins: the harness's own keys come before the tool's output
    d = {}
    for kv in line.split():
        if "=" in kv:
            k, v = kv.split("=", 1)
            d.setdefault(k, v)
    return d


def main():
    rows = [parse(l) for l in open(sys.argv[1]) if l.strip()]
    commit = sys.argv[sys.argv.index("--commit") + 1] if "--commit" in sys.argv else rows[-1]["commit"]
    rows = [r for r in rows if r.get("commit") == commit]
    t = defaultdict(list)
    mem = defaultdict(list)
    meta = {}
    for r in rows:
        if r["tool"] == "orbitri":
            key = (r["input"], int(r["N"]), "orbitri")
            t[key].append(float(r["build_seconds"]))
            mem[key].append(int(r["peak_rss_kb"]))
            meta[(r["input"], int(r["N"]))] = (r["cells"], r["sheets"], r["date"])
        else:
            n = int(r.get("N") or r.get("n_in"))
            key = (r["input"], n, r["cmd"])
            t[key].append(float(r["time_s"]))
            mem[key].append(int(r["peak_rss_kB"]))
    print(f"commit {commit}")
    print("| input | N | tool | runs | median s | min s | max s | µs/point | peak RSS MiB | orbitri / tool |")
    print("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|")
    for (inp, n, tool) in sorted(t, key=lambda k: (k[0], k[1], k[2] != "orbitri", k[2])):
        v = t[(inp, n, tool)]
        med = statistics.median(v)
        ours = statistics.median(t[(inp, n, "orbitri")]) if (inp, n, "orbitri") in t else None
        ratio = "" if tool == "orbitri" or ours is None else f"{ours / med:.2f}"
        rss = statistics.median(mem[(inp, n, tool)]) / 1024
        print(f"| {inp} | {n} | {tool} | {len(v)} | {med:.4f} | {min(v):.4f} | {max(v):.4f} | {med / n * 1e6:.2f} | {rss:.0f} | {ratio} |")


if __name__ == "__main__":
    main()
