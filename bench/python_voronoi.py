"""One measurement of the Voronoi volumes of N uniform points in a periodic cube, from
Python, end to end (construction and cells): orbitri's ``periodic_voronoi`` or freud's
``Voronoi``; the time, the peak RSS, and the RSS once the objects are dropped and
collected. Prints one ``key=value`` line (bench/python.sh runs it)."""

import gc
import resource
import sys
import time

import numpy as np


def rss_mb():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS"):
                return int(line.split()[1]) // 1024
    return -1


n, tool = int(sys.argv[1]), sys.argv[2]
pts = np.random.default_rng(1).random((n, 3)) * 10.0
base = rss_mb()
t = time.perf_counter()
if tool == "orbitri":
    import orbitri

    result = orbitri.periodic_voronoi(pts, [10.0, 10.0, 10.0])
else:
    import freud

    result = freud.locality.Voronoi()
    result.compute((freud.box.Box.cube(10.0), pts - 5.0))
total = float(result.volumes.sum())
dt = time.perf_counter() - t
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss // 1024
del result
gc.collect()
print(
    f"tool={tool} N={n} time_s={dt:.3f} volume_sum={total:.9f} base_MB={base} "
    f"peak_MB={peak} after_del_MB={rss_mb()}"
)
