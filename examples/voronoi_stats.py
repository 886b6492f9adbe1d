"""Periodic Voronoi cells of 100 000 random points in a triclinic box, and the statistics a
cosmologist or materials scientist looks at first.

    pip install .            # from the repository root
    python examples/voronoi_stats.py [N]
"""

import sys
import time

import numpy as np

import orbitri

n = int(sys.argv[1]) if len(sys.argv) > 1 else 100_000
box = [1.0, 1.0, 1.0, 0.2, 0.0, 0.1]  # Lx, Ly, Lz and freud's tilt factors xy, xz, yz
rng = np.random.default_rng(2026)
points = rng.random((n, 3)) @ orbitri.lattice_matrix(box, 3)

start = time.perf_counter()
tri = orbitri.PeriodicDelaunay(points, box)
built = time.perf_counter()
vor = tri.voronoi()
done = time.perf_counter()

v = vor.volumes
rel = v / v.mean()
print(f"{n} points: triangulation {built - start:.2f} s, Voronoi cells {done - built:.2f} s")
print(f"volumes sum to {v.sum():.15f} (box volume 1)")
print(f"volume / mean: std {rel.std():.4f}, min {rel.min():.3f}, max {rel.max():.3f}")
print(f"faces per cell: mean {vor.neighbor_counts.mean():.3f} (Poisson: 15.535)")
ij, shifts, areas = vor.neighbors()
print(f"{len(ij)} neighbour pairs, {np.count_nonzero(shifts.any(axis=1))} across the boundary")
