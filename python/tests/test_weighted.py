"""Weighted points: power (Laguerre) cells against pyvoro2's power mode (Voro++), radii
against weights, hidden points, insertion and bad input."""

import numpy as np
import pytest

import orbitri
from simplices import canonical

pv = pytest.importorskip("pyvoro2")


def _pyvoro2_volumes(points, weights, lengths):
    domain = pv.OrthorhombicCell(bounds=tuple((0.0, L) for L in lengths), periodic=(True,) * 3)
    cells = pv.compute(
        points,
        domain=domain,
        mode="power",
        weights=weights,
        include_empty=True,
        output="cells",
        return_vertices=False,
        return_adjacency=False,
        return_faces=False,
    )
    volumes = np.zeros(len(points))
    for c in cells:
        volumes[c["id"]] = c["volume"]
    return volumes


@pytest.mark.parametrize("n, wmax", [(300, 0.003), (3000, 0.0008)])
def test_power_cells_match_pyvoro2(n, wmax):
    rng = np.random.default_rng(n)
    lengths = [1.0, 1.3, 0.9]
    points = rng.random((n, 3)) * lengths
    weights = rng.random(n) * wmax
    vor = orbitri.periodic_voronoi(points, lengths, weights=weights)
    theirs = _pyvoro2_volumes(points, weights, lengths)
    assert abs(vor.volumes.sum() - np.prod(lengths)) < 1e-12 * np.prod(lengths)
    np.testing.assert_allclose(vor.volumes, theirs, rtol=1e-7, atol=1e-12)
    tri = orbitri.PeriodicDelaunay(points, lengths, weights=weights)
    hidden = tri.hidden
    assert np.all(vor.volumes[hidden] == 0.0)
    # pyvoro2's empty cells are ours
    assert set(np.flatnonzero(theirs <= 1e-15)) == set(hidden.tolist())


def test_radii_are_square_roots_of_weights():
    rng = np.random.default_rng(3)
    points = rng.random((400, 2))
    radii = rng.random(400) * 0.05
    a = orbitri.PeriodicDelaunay(points, [1.0, 1.0], radii=radii)
    b = orbitri.PeriodicDelaunay(points, [1.0, 1.0], weights=radii**2)
    np.testing.assert_array_equal(a.simplices, b.simplices)
    np.testing.assert_array_equal(a.hidden, b.hidden)
    np.testing.assert_array_equal(a.weights, radii**2)
    assert orbitri.PeriodicDelaunay(points, [1.0, 1.0]).weights is None
    # equal weights: the Delaunay triangulation
    c = orbitri.PeriodicDelaunay(points, [1.0, 1.0], weights=np.full(400, 0.3))
    d = orbitri.PeriodicDelaunay(points, [1.0, 1.0])
    # (the same triangles; the weighted build stars each conflict region, the other splits
    # and flips, so their cells come in other orders)
    assert canonical(c.simplices, c.offsets) == canonical(d.simplices, d.offsets)
    assert c.hidden.size == 0


def test_insert_and_remove_weighted_points():
    tri = orbitri.PeriodicDelaunay([[0.1, 0.1], [0.6, 0.2], [0.3, 0.7], [0.8, 0.8]], [1, 1], weights=[0, 0, 0, 0])
    # a point on point 1 with a smaller weight is hidden; a heavier one hides point 1
    assert tri.insert([[0.6, 0.2]], weights=[-0.01]).tolist() == [-1]
    assert tri.insert([[0.6, 0.2]], radii=[0.1]).tolist() == [5]
    assert tri.hidden.tolist() == [1, 4]
    tri.remove(5)
    assert tri.hidden.tolist() == [4]
    assert abs(np.nansum(tri.voronoi().volumes) - 1.0) < 1e-12  # (a removed input: NaN)


def test_bad_weights_are_value_errors():
    p = np.random.default_rng(1).random((10, 3))
    with pytest.raises(ValueError, match="not both"):
        orbitri.PeriodicDelaunay(p, [1, 1, 1], weights=np.zeros(10), radii=np.zeros(10))
    with pytest.raises(ValueError, match="point 3: radius -1.0"):
        orbitri.PeriodicDelaunay(p, [1, 1, 1], radii=[0, 0, 0, -1, 0, 0, 0, 0, 0, 0])
    with pytest.raises(ValueError, match="9 weights for 10 points"):
        orbitri.PeriodicDelaunay(p, [1, 1, 1], weights=np.zeros(9))
    with pytest.raises(ValueError, match="point 2: weight NaN"):
        orbitri.PeriodicDelaunay(p, [1, 1, 1], weights=[0, 0, np.nan, 0, 0, 0, 0, 0, 0, 0])
    with pytest.raises(ValueError, match="point 0: weight"):
        orbitri.PeriodicDelaunay(p, [1, 1, 1], weights=[1e9] + [0] * 9)


def test_weights_need_a_weighted_triangulation():
    tri = orbitri.PeriodicDelaunay(np.random.default_rng(2).random((20, 2)), [1, 1])
    with pytest.raises(ValueError, match="unweighted"):
        tri.insert([[0.5, 0.5]], weights=[0.1])
