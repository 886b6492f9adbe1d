"""Clustered benchmark input: 100 Gaussian clusters (sigma 0.01) in the unit cube, wrapped.

usage: clustered.py N OUT_ORBITRI OUT_CGAL   (the CGAL file has the period line first)
Deterministic: splitmix64 seeded with 7, Box-Muller for the normal deviates.
"""
import math
import sys

MASK = (1 << 64) - 1


class SplitMix:
    def __init__(self, seed):
        self.state = seed

    def next(self):
        self.state = (self.state + 0x9E3779B97F4A7C15) & MASK
        z = self.state
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
        return z ^ (z >> 31)

    def unit(self):
        return (self.next() >> 11) * 2.0**-53


def main():
    n, out_orb, out_cgal = int(sys.argv[1]), sys.argv[2], sys.argv[3]
    rng = SplitMix(7)
    centers = [(rng.unit(), rng.unit(), rng.unit()) for _ in range(100)]
    lines = []
    for i in range(n):
        c = centers[i % 100]
        p = []
        for k in range(3):
            u1, u2 = rng.unit(), rng.unit()
            g = math.sqrt(-2.0 * math.log(1.0 - u1)) * math.cos(2.0 * math.pi * u2)
            x = (c[k] + 0.01 * g) % 1.0
            p.append(0.0 if x >= 1.0 else x)
        lines.append("%.17g %.17g %.17g\n" % tuple(p))
    with open(out_orb, "w") as f:
        f.writelines(lines)
    with open(out_cgal, "w") as f:
        f.write("1 1 1\n")
        f.writelines(lines)


if __name__ == "__main__":
    main()
