"""Removing and moving points from Python: against a fresh build of the survivors (cell
sets), Voronoi volumes, and the errors."""

import numpy as np
import pytest

import orbitri


def _cells(tri):
    """The cells as sets of (rounded coordinates, offset) tuples, independent of ids."""
    pts = tri.points
    out = set()
    for simplex, offsets in zip(tri.simplices, tri.offsets):
        lifted = sorted(
            (tuple(np.round(pts[v], 12)), tuple(o)) for v, o in zip(simplex, offsets)
        )
        # translate so the least offset is zero (cells equal up to a lattice translation)
        low = np.min([o for _, o in lifted], axis=0)
        out.add(tuple((p, tuple(np.subtract(o, low))) for p, o in lifted))
    return out


@pytest.mark.parametrize("d", [2, 3])
def test_removal_and_moves_equal_a_fresh_build(d):
    rng = np.random.default_rng(d)
    n = 2000
    pts = rng.random((n, d))
    tri = orbitri.PeriodicDelaunay(pts, np.ones(d))
    gone = np.arange(0, n, 3)
    assert tri.remove(gone) == 0
    assert tri.is_valid()
    assert np.isnan(tri.points[gone]).all()
    assert (tri.duplicates[gone] == -1).all()
    alive = np.setdiff1d(np.arange(n), gone)
    # small moves keep the combinatorics mostly
    moved = tri.points[alive] + (rng.random((len(alive), d)) - 0.5) * 1e-4
    fast = tri.move(alive, moved)
    assert fast.dtype == bool and fast.mean() > 0.5
    assert tri.is_valid()
    fresh = orbitri.PeriodicDelaunay(tri.points[alive], np.ones(d))
    assert len(tri.simplices) == len(fresh.simplices)
    # the fresh build's ids are positions in `alive`
    assert _cells(tri) == _cells(fresh)
    vol = tri.voronoi().volumes
    assert abs(np.nansum(vol) - 1.0) < 1e-12


def test_errors_leave_the_triangulation_unchanged():
    tri = orbitri.PeriodicDelaunay(np.random.default_rng(1).random((50, 3)), [1.0, 1.0, 1.0])
    tri.remove(7)
    before = tri.simplices.copy()
    with pytest.raises(IndexError, match="input id 7: was removed"):
        tri.remove([3, 7])
    with pytest.raises(IndexError, match="input id 50: out of range"):
        tri.remove(50)
    with pytest.raises(IndexError, match="point -1 does not exist"):
        tri.remove(-1)
    with pytest.raises(IndexError, match="given twice"):
        tri.remove([4, 4])
    with pytest.raises(TypeError):
        tri.remove(1.5)
    with pytest.raises(ValueError, match="point 3: coordinate 1 is NaN"):
        tri.move([3], [[0.5, np.nan, 0.5]])
    with pytest.raises(ValueError, match="2 ids need 2 points"):
        tri.move([3, 4], [[0.5, 0.5, 0.5]])
    with pytest.raises(IndexError, match="input id 7"):
        tri.move([7], [[0.5, 0.5, 0.5]])
    with pytest.raises(IndexError, match="point 7 was removed"):
        tri.vertex_neighbors(7)
    np.testing.assert_array_equal(tri.simplices, before)
    assert tri.is_valid()


def test_down_to_nothing_and_back_in_a_manifold():
    space = orbitri.FlatManifold("klein", [1.0, 0.75])
    rng = np.random.default_rng(3)
    tri = orbitri.Triangulation(rng.random((30, 2)) * [1.0, 0.75], space=space)
    for i in range(30):
        tri.remove(i)
        if i < 29:
            assert tri.is_valid()
    assert len(tri.simplices) == 0
    ids = tri.insert(rng.random((10, 2)) * [1.0, 0.75])
    assert ids.tolist() == list(range(30, 40))
    assert tri.is_valid()


@pytest.mark.parametrize("d", [2, 3])
def test_find_simplex_agrees_with_locate_and_barycentric_coordinates(d):
    rng = np.random.default_rng(10 + d)
    tri = orbitri.PeriodicDelaunay(rng.random((500, d)), np.ones(d))
    tri.remove(np.arange(0, 500, 4))
    queries = rng.random((300, d)) * 3 - 1
    rows = tri.find_simplex(queries)
    simplices, offsets = tri.simplices, tri.offsets
    pts = tri.points
    for q, k in zip(queries, rows):
        vertices, _, _ = tri.locate(q)
        assert sorted(vertices) == sorted(simplices[k])
        # the wrapped query has non-negative barycentric coordinates in the lifted simplex
        lifted = pts[simplices[k]] + offsets[k]
        w = np.mod(q, 1.0)
        for shift in np.ndindex(*(3,) * d):
            x = w + np.array(shift) - 1
            lam = np.linalg.solve(np.vstack([lifted.T, np.ones(d + 1)]), np.append(x, 1.0))
            if (lam >= -1e-9).all():
                break
        else:
            raise AssertionError(f"{q} is not in simplex {k}")
    with pytest.raises(ValueError, match="point 1: coordinate 0 is NaN"):
        tri.find_simplex([[0.5] * d, [np.nan] + [0.5] * (d - 1)])
