"""The Python package against independent results: freud's Voronoi volumes and neighbour
counts (Voro++ inside), crystal cells, box volumes, and the command line's own output."""

import os
import pathlib
import subprocess

import numpy as np
import pytest

import orbitri
from simplices import canonical

import freud  # noqa: E402  (a test dependency: pip install .[test])

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_volumes_sum_to_the_box_in_2d_and_3d():
    rng = np.random.default_rng(1)
    for box, volume in [
        ([2.0, 1.0, 1.5], 3.0),
        ([1.0, 1.0, 1.0, 0.3, -0.2, 0.1], 1.0),
        ([1.0, 2.0], 2.0),
        (np.array([[1.0, 0.0], [0.5, 0.8]]), 0.8),
    ]:
        m = orbitri.lattice_matrix(box, 3 if len(np.ravel(box)) in (3, 6) else 2)
        pts = rng.random((3000, m.shape[0])) @ m
        vor = orbitri.periodic_voronoi(pts, box)
        assert vor.volumes.shape == (3000,)
        assert abs(vor.volumes.sum() - volume) <= 1e-12 * volume


def test_crystal_cells_are_equal():
    # FCC with an exactly representable lattice constant: every cell is V/N, 12 faces
    basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]])
    cells = np.array([[i, j, k] for i in range(4) for j in range(4) for k in range(4)])
    pts = ((cells[:, None, :] + basis[None, :, :]).reshape(-1, 3)) * 0.25
    vor = orbitri.periodic_voronoi(pts, [1.0, 1.0, 1.0])
    np.testing.assert_allclose(vor.volumes, 1.0 / len(pts), rtol=1e-12)
    assert (vor.neighbor_counts == 12).all()


def _freud_compare(box, n, seed, freud_misses_faces=False):
    """freud (Voro++ inside) stores positions and boxes in single precision, so the points
    (and the boxes below) are exactly representable in float32: both tools then see the same
    input. freud also leaves out some faces smaller than about 3e-5 (of a box of size 1),
    which the exact cells keep: neighbours are compared on the faces above 1e-4.

    In triclinic boxes freud's neighbour list also misses real faces across the tilted
    boundary (its volumes still agree): there every pair freud lists must be ours, and the
    pairs only we list are checked by the midpoint test where it applies."""
    rng = np.random.default_rng(seed)
    pts = box.make_absolute(rng.random((n, 3))).astype(np.float32).astype(np.float64)
    if box.is2D:
        pts[:, 2] = 0.0
    voro = freud.locality.Voronoi()
    voro.compute((box, pts))
    ours = orbitri.periodic_voronoi(pts, box)  # freud's 2D points: N × 3 with z = 0
    np.testing.assert_allclose(ours.volumes, voro.volumes, rtol=1e-9)
    nl = voro.nlist
    theirs = {
        (i, j): w
        for i, j, w in zip(nl.query_point_indices.tolist(), nl.point_indices.tolist(), nl.weights)
    }
    big = 1e-4
    ij, shifts, areas = ours.neighbors()
    mine = {}
    for (i, j), a in zip(ij.tolist(), areas):
        mine[(i, j)] = mine[(j, i)] = a
    big_mine = {k for k, a in mine.items() if a > big}
    big_theirs = {k for k, w in theirs.items() if w > big}
    if freud_misses_faces:
        assert big_theirs < big_mine
        return
    assert big_mine == big_theirs
    counts = np.zeros(n, dtype=int)
    for i, _ in big_theirs:
        counts[i] += 1
    ours_big = np.zeros(n, dtype=int)
    for i, _ in big_mine:
        ours_big[i] += 1
    np.testing.assert_array_equal(ours_big, counts)
    # the shared faces' areas (freud's weights are float32)
    for k in big_mine:
        assert abs(mine[k] - theirs[k]) <= 1e-6 * mine[k]
    # and every face freud reports is one of ours
    assert set(theirs) <= set(mine)


def test_volumes_and_neighbours_equal_freud_orthorhombic():
    _freud_compare(freud.box.Box(2.0, 1.5, 1.0), 400, 3)


def test_volumes_and_neighbours_equal_freud_triclinic():
    box = freud.box.Box(2.0, 1.5, 1.25, 0.25, -0.125, 0.375)
    _freud_compare(box, 400, 4, freud_misses_faces=True)
    # one face freud misses, checked by hand: the midpoint of 71 and 132's image is
    # equidistant from both and farther from every other image, so the face exists
    rng = np.random.default_rng(4)
    pts = box.make_absolute(rng.random((400, 3))).astype(np.float32).astype(np.float64)
    tri = orbitri.PeriodicDelaunay(pts, box)
    p, m = tri.points, tri.lattice
    mid = (p[71] + p[132] + np.array([0, 0, 1]) @ m) / 2
    r = np.linalg.norm(mid - p[71])
    shifts = np.array([[x, y, z] for x in (-2, -1, 0, 1, 2) for y in (-2, -1, 0, 1, 2) for z in (-2, -1, 0, 1, 2)])
    images = (p[None, :, :] + (shifts @ m)[:, None, :]).reshape(-1, 3)
    assert np.linalg.norm(images - mid, axis=1).min() >= r * (1 - 1e-12)
    faces = {(f["neighbor"], tuple(f["shift"])) for c in tri.voronoi().cells() if c["id"] == 71 for f in c["faces"]}
    assert (132, (0, 0, 1)) in faces


def test_volumes_and_neighbours_equal_freud_2d():
    _freud_compare(freud.box.Box(1.5, 1.0, is2D=True), 300, 5)


@pytest.mark.parametrize("dim", [2, 3])
def test_neighbours_by_pieces_equal_those_of_the_cells(dim):
    """``neighbors()`` sums the pairs by pieces, without the cells; once ``cells()`` has built
    them, it lists them from the cells: the same pairs and areas (a grid among random
    points puts cells of one circumsphere side by side, measured on their whole cells)."""
    rng = np.random.default_rng(7)
    grid = np.stack(np.meshgrid(*[np.arange(4) / 4] * dim), -1).reshape(-1, dim)
    pts = np.concatenate([grid, rng.random((300, dim))])
    vor = orbitri.periodic_voronoi(pts, [1.0] * dim)
    by_pieces = vor.neighbors()
    assert len(vor.cells()) == len(pts)
    from_cells = vor.neighbors()

    def table(ij, shifts, areas):
        return sorted(zip(map(tuple, ij.tolist()), map(tuple, shifts.tolist()), areas.tolist()))

    a, b = table(*by_pieces), table(*from_cells)
    assert [x[:2] for x in a] == [x[:2] for x in b] and len(a) > 2 * len(pts)
    np.testing.assert_allclose([x[2] for x in a], [x[2] for x in b], rtol=1e-9, atol=1e-15)


def test_attributes_like_scipy():
    rng = np.random.default_rng(6)
    pts = rng.random((500, 3))
    tri = orbitri.PeriodicDelaunay(pts.tolist(), [1, 1, 1])  # any array-like
    c = len(tri.simplices)
    assert tri.simplices.shape == (c, 4) and tri.offsets.shape == (c, 4, 3)
    assert tri.neighbors.shape == (c, 4)
    # neighbours are symmetric and share a facet
    for k in range(0, c, 37):
        for i in range(4):
            other = tri.neighbors[k, i]
            assert k in tri.neighbors[other]
    # every simplex is positively oriented and the volumes fill the box
    lifted = tri.points[tri.simplices] + tri.offsets @ tri.lattice
    d = lifted[:, 1:] - lifted[:, :1]
    vol = np.linalg.det(d) / 6
    assert (vol > 0).all() and abs(vol.sum() - 1.0) < 1e-12
    assert tri.sheets == 1 and tri.is_one_sheeted
    # edges: E = V + C, lengths are lifted distances
    ij, shifts, lengths = tri.edges()
    assert len(ij) == 500 + c
    a = tri.points[ij[:, 0]]
    b = tri.points[ij[:, 1]] + shifts @ tri.lattice
    np.testing.assert_allclose(np.linalg.norm(b - a, axis=1), lengths, rtol=1e-12)
    ids, sh = tri.vertex_neighbors(0)
    assert len(ids) == np.count_nonzero(ij == 0)
    # locate: the point is inside the simplex (barycentric coordinates ≥ 0)
    q = np.array([0.3, 0.6, 0.9])
    verts, offs, qoff = tri.locate(q)
    corners = tri.points[verts] + offs @ tri.lattice
    lam = np.linalg.solve((corners[1:] - corners[0]).T, q + qoff @ tri.lattice - corners[0])
    assert (lam >= -1e-12).all() and lam.sum() <= 1 + 1e-12


def test_duplicates_wrapping_and_insert():
    tri = orbitri.PeriodicDelaunay([[0.25, 0.5], [1.25, 0.5], [0.7, 0.1]] + np.random.default_rng(7).random((50, 2)).tolist(), [1.0, 1.0])
    assert tri.duplicates[1] == 0 and tri.number_of_duplicates == 1
    assert tri.number_of_wrapped == 1
    np.testing.assert_array_equal(tri.points[1], tri.points[0])
    ids = tri.insert([[0.9, 0.9], [0.7, 0.1]])
    assert ids.tolist() == [53, 2]
    assert tri.duplicates[54] == 2
    vor = tri.voronoi()
    assert vor.volumes[54] == vor.volumes[2]
    assert len(vor) == 53
    cells = vor.cells()
    assert {c["id"] for c in cells} == set(range(55)) - {1, 54}
    face = cells[0]["faces"][0]
    assert set(face) == {"vertices", "neighbor", "shift", "area"}


def test_tiny_sets_stay_correct_in_a_covering():
    tri = orbitri.PeriodicDelaunay([[0.1, 0.2, 0.3]], [1, 1, 1])
    assert tri.sheets == 27 and not tri.is_one_sheeted
    vor = tri.voronoi()
    assert abs(vor.volumes[0] - 1.0) < 1e-12 and vor.neighbor_counts[0] == 6


def _check_glued(tri):
    """Each facet of each simplex is its neighbour's facet at the mirror index, moved by the
    gluing, and the gluings back are the opposites."""
    s, o, n, m, g = tri.simplices, tri.offsets, tri.neighbors, tri.mirrors, tri.gluings
    c, k = s.shape
    for a in range(c):
        for i in range(k):
            b, j = n[a, i], m[a, i]
            assert (n[b, j], m[b, j]) == (a, i)
            np.testing.assert_array_equal(g[b, j], -g[a, i])
            here = {(int(s[a, x]), tuple(o[a, x])) for x in range(k) if x != i}
            there = {(int(s[b, x]), tuple(o[b, x] + g[a, i])) for x in range(k) if x != j}
            assert here == there


@pytest.mark.parametrize("n", [1, 2, 3, 5])
def test_a_covering_is_described_as_the_torus(n):
    # too few points for a simplicial complex on the torus: stored in a covering, described
    # as the torus's own triangulation (a Δ-complex), one simplex per orbit
    rng = np.random.default_rng(n)
    for box in ([1.0, 1.0], [1.0, 1.0, 1.0]):
        d = len(box)
        tri = orbitri.PeriodicDelaunay(rng.random((n, d)), box)
        assert tri.sheets > 1
        lifted = tri.points[tri.simplices] + tri.offsets @ tri.lattice
        vol = np.linalg.det(lifted[:, 1:] - lifted[:, :1]) / (2 if d == 2 else 6)
        assert (vol > 0).all() and abs(vol.sum() - 1.0) < 1e-12
        # Euler: 2D, F = 2V; 3D, E = V + C
        if d == 2:
            assert len(tri.simplices) == 2 * n
        else:
            assert len(tri.edges()[0]) == n + len(tri.simplices)
        _check_glued(tri)
        rows = tri.find_simplex(rng.random((50, d)))
        assert rows.min() >= 0 and rows.max() < len(tri.simplices)


def test_errors_are_value_errors_with_the_place():
    with pytest.raises(ValueError, match="point 1: coordinate 2 is NaN"):
        orbitri.PeriodicDelaunay([[0.1, 0.1, 0.1], [0.2, 0.2, np.nan]], [1, 1, 1])
    with pytest.raises(ValueError, match="no points"):
        orbitri.PeriodicDelaunay(np.zeros((0, 3)), [1, 1, 1])
    with pytest.raises(ValueError, match="length 1 is -1"):
        orbitri.PeriodicDelaunay([[0.1, 0.1, 0.1]], [1, -1, 1])
    with pytest.raises(ValueError, match=r"\(N, 2\) or \(N, 3\)"):
        orbitri.PeriodicDelaunay(np.zeros((5, 4)), [1, 1, 1, 1])
    with pytest.raises(ValueError, match="lengths"):
        orbitri.PeriodicDelaunay(np.zeros((5, 3)), [1, 1, 1, 1])
    tri = orbitri.PeriodicDelaunay([[0.1, 0.2]], [1, 1])
    with pytest.raises(ValueError, match="2 columns, or 3 whose last is 0"):
        tri.insert([[0.1, 0.2, 0.3]])


def _cli():
    exe = os.environ.get("ORBITRI_BIN")
    if exe:
        return exe
    for profile in ("release", "debug"):
        p = ROOT / "target" / profile / "orbitri"
        if p.exists():
            return str(p)
    raise RuntimeError("build the command first: cargo build -p orbitri-cli (or set ORBITRI_BIN)")


def test_round_trip_equals_the_command_line(tmp_path):
    rng = np.random.default_rng(8)
    for dim, box in [(3, ["1.5", "1", "1"]), (2, ["1", "0.5"])]:
        pts = rng.random((800, dim)) * np.array(box, dtype=float)
        f = tmp_path / f"p{dim}.txt"
        f.write_text("\n".join(" ".join(repr(float(x)) for x in p) for p in pts))
        out = subprocess.run(
            [_cli(), "triangulate", str(f), "--box", *box], check=True, capture_output=True, text=True
        ).stdout.splitlines()
        sheets, v, c = map(int, out[0].split())
        rows = np.array([list(map(int, l.split())) for l in out[1:]])
        n = dim + 1
        tri = orbitri.PeriodicDelaunay(pts, [float(b) for b in box])
        assert (sheets, v, c) == (tri.sheets, 800, len(tri.simplices))
        cli = canonical(rows[:, :n], rows[:, n:].reshape(-1, n, dim))
        assert cli == canonical(tri.simplices, tri.offsets)


def test_every_thread_count_gives_the_same_arrays():
    rng = np.random.default_rng(8)
    pts3 = rng.random((6000, 3))
    sph = rng.normal(size=(6000, 3))
    sph /= np.linalg.norm(sph, axis=1)[:, None]

    def flat(threads):
        tri = orbitri.PeriodicDelaunay(pts3, [1.0, 1.0, 1.0], threads=threads)
        return tri.simplices, tri.offsets, tri.neighbors, tri.voronoi().volumes

    def sphere(threads):
        tri = orbitri.SphericalDelaunay(sph, threads=threads)
        return tri.simplices, tri.neighbors, tri.voronoi().areas

    for build in (flat, sphere):
        one = build(1)
        for threads in (2, 3):
            for a, b in zip(one, build(threads)):
                assert np.array_equal(a, b)
    # one at a time (the default): the same simplices, stored in another order
    faces = lambda s: sorted(map(tuple, np.sort(s, axis=1)))
    assert faces(orbitri.SphericalDelaunay(sph).simplices) == faces(sphere(2)[0])
    for bad in (0, 10**6):
        with pytest.raises(ValueError, match="threads must be at least 1 and at most 1024"):
            orbitri.PeriodicDelaunay(pts3, [1.0, 1.0, 1.0], threads=bad)
