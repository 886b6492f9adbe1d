"""The sphere against Qhull (scipy's ConvexHull) and scipy's SphericalVoronoi, and its
degenerate sets, small sets, hidden points, removals and bad input."""

import numpy as np
import pytest

import orbitri


def unit(n, seed):
    p = np.random.default_rng(seed).normal(size=(n, 3))
    return p / np.linalg.norm(p, axis=1)[:, None]


def triangles(simplices):
    return {tuple(sorted(f)) for f in simplices.tolist()}


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_faces_equal_qhull_and_areas_equal_scipy(seed):
    spatial = pytest.importorskip("scipy.spatial")
    pts = unit(3000, seed)
    tri = orbitri.SphericalDelaunay(pts)
    assert tri.is_valid()
    assert tri.dimension == 2 and tri.covers_sphere
    hull = spatial.ConvexHull(pts)
    assert triangles(tri.simplices) == triangles(hull.simplices)
    # counter-clockwise seen from outside: det[a; b; c] > 0
    a, b, c = (pts[tri.simplices[:, k]] for k in range(3))
    assert (np.einsum("ij,ij->i", a, np.cross(b, c)) > 0).all()
    vor = tri.voronoi()
    sv = spatial.SphericalVoronoi(pts)
    np.testing.assert_allclose(vor.areas, sv.calculate_areas(), rtol=0, atol=1e-9)
    assert abs(vor.areas.sum() - 4 * np.pi) < 1e-12
    # scipy's shape: the same vertices per region, as sets of rounded coordinates
    for k in range(0, 3000, 97):
        ours = {tuple(np.round(v, 9)) for v in vor.vertices[vor.regions[k]]}
        theirs = {tuple(np.round(v, 9)) for v in sv.vertices[sv.regions[k]]}
        assert ours == theirs


def test_hemisphere_ghost_faces_close_the_hull_and_cells_equal_scipy():
    spatial = pytest.importorskip("scipy.spatial")
    pts = unit(2000, 4)
    pts[:, 2] = np.abs(pts[:, 2])
    tri = orbitri.SphericalDelaunay(pts)
    assert tri.dimension == 2 and not tri.covers_sphere
    hull = spatial.ConvexHull(pts)
    assert triangles(np.vstack([tri.simplices, tri.ghost_simplices])) == triangles(
        hull.simplices
    )
    # the ghost faces turn towards the centre
    a, b, c = (pts[tri.ghost_simplices[:, k]] for k in range(3))
    assert (np.einsum("ij,ij->i", a, np.cross(b, c)) < 0).all()
    vor = tri.voronoi()
    sv = spatial.SphericalVoronoi(pts)
    np.testing.assert_allclose(vor.areas, sv.calculate_areas(), rtol=0, atol=1e-9)
    assert abs(vor.areas.sum() - 4 * np.pi) < 1e-12


def test_neighbours_across_faces_are_mutual():
    tri = orbitri.SphericalDelaunay(unit(500, 5))
    s, n = tri.simplices, tri.neighbors
    for f in range(len(s)):
        for k in range(3):
            g = n[f, k]
            assert f in n[g]
            # they share the edge opposite vertex k
            assert set(s[f]) - {s[f, k]} <= set(s[g])


def test_lonlat_grid_with_repeated_poles():
    lonlat = [[lon, lat] for lon in range(0, 360, 10) for lat in range(-90, 91, 10)]
    tri = orbitri.SphericalDelaunay(lonlat=lonlat)
    assert tri.number_of_vertices == 36 * 17 + 2
    assert tri.is_valid()
    first = tri.duplicates
    assert (first[first != np.arange(len(first))] >= 0).all()
    assert len(tri.simplices) == 2 * tri.number_of_vertices - 4
    np.testing.assert_allclose(tri.lonlat[1], lonlat[1], atol=1e-12)
    vor = tri.voronoi()
    distinct = first == np.arange(len(first))
    assert abs(vor.areas[distinct].sum() - 4 * np.pi) < 1e-12
    df = vor.to_dataframe()
    assert (df["duplicate_of"][~distinct] >= 0).all()


def test_small_sets_and_a_hemisphere():
    tri = orbitri.SphericalDelaunay([[1.0, 0.0, 0.0]])
    assert tri.dimension == -1 and len(tri.simplices) == 0
    tri.insert([[0.0, 1.0, 0.0], [0.6, 0.8, 0.0]])
    assert tri.dimension == 1
    with pytest.raises(ValueError, match="no faces"):
        tri.voronoi()
    tri.insert([[0.0, 0.0, 1.0]])
    assert tri.dimension == 2 and not tri.covers_sphere
    # a tetrahedron: two faces hold the centre inside; the equator's and the one facing
    # the centre are ghost faces
    assert len(tri.simplices) == 2 and len(tri.ghost_simplices) == 2
    assert set(tri.neighbors.ravel()) | set(tri.ghost_neighbors.ravel()) == {0, 1, 2, 3}
    assert tri.voronoi().areas.sum() == pytest.approx(4 * np.pi, abs=1e-12)
    tri.insert([[-0.5, -0.5, -(0.5**0.5)]])
    assert tri.covers_sphere and len(tri.simplices) == 6
    assert tri.voronoi().areas.sum() == pytest.approx(4 * np.pi, abs=1e-12)


def test_removals_equal_fresh_builds_and_hidden_points_come_back():
    pts = unit(300, 8)
    cap = np.array([[1e-4, 0, 1], [0, 1e-4, 1], [-1e-4, 0, 1], [0, -1e-4, 1]])
    cap /= np.linalg.norm(cap, axis=1)[:, None]
    pts = np.vstack([pts, cap, [[0, 0, 1 - 4e-7]]])
    tri = orbitri.SphericalDelaunay(pts)
    assert tri.hidden.tolist() == [304]
    tri.remove([300, 301, 302, 303])
    assert len(tri.hidden) == 0
    assert tri.is_valid()
    gone = np.random.default_rng(1).choice(300, 150, replace=False)
    tri.remove(gone)
    keep = np.setdiff1d(np.arange(305), np.concatenate([gone, [300, 301, 302, 303]]))
    fresh = orbitri.SphericalDelaunay(pts[keep])
    ours = {tuple(sorted(keep[np.searchsorted(keep, f)])) for f in tri.simplices.tolist()}
    theirs = {tuple(sorted(keep[f])) for f in fresh.simplices.tolist()}
    assert ours == theirs
    with pytest.raises(IndexError):
        tri.remove(int(gone[0]))


def test_bad_input_is_a_clear_error():
    with pytest.raises(ValueError, match="point 1: its norm is 2"):
        orbitri.SphericalDelaunay([[1.0, 0, 0], [0, 2.0, 0]])
    with pytest.raises(ValueError, match="not a finite number"):
        orbitri.SphericalDelaunay([[np.nan, 0, 1]])
    with pytest.raises(ValueError, match="shape"):
        orbitri.SphericalDelaunay(np.zeros((3, 2)))
    with pytest.raises(ValueError, match="latitude"):
        orbitri.SphericalDelaunay(lonlat=[[0, 95]])
    with pytest.raises(TypeError):
        orbitri.SphericalDelaunay()
    tri = orbitri.SphericalDelaunay([[2.0, 0, 0], [0, 3.0, 0], [0, 0, 0.5]], normalize=True)
    assert tri.dimension == 1
    with pytest.raises(ValueError, match="cannot be normalized"):
        orbitri.SphericalDelaunay([[0.0, 0, 0]], normalize=True)
    # a failed insert changes nothing
    with pytest.raises(ValueError):
        tri.insert([[0, 0, 1.0], [0, 0, 3.0]])
    assert tri.number_of_input_points == 3


def test_projective_plane_is_the_hull_of_both_copies():
    spatial = pytest.importorskip("scipy.spatial")
    pts = unit(1500, 11)
    rp2 = orbitri.ProjectivePlane(pts)
    assert rp2.is_valid()
    assert len(rp2.simplices) == 2 * 1500 - 2
    # each face lifted by its signs is a face of the hull of ±P, counter-clockwise
    both = np.vstack([pts, -pts])
    stored = rp2.points
    faces = rp2.signs[..., None] * stored[rp2.simplices]
    assert (np.einsum("ij,ij->i", faces[:, 0], np.cross(faces[:, 1], faces[:, 2])) > 0).all()
    hull = spatial.ConvexHull(both)

    def key(tri):
        # a face and its antipode as one set of rounded coordinates
        a = tuple(sorted(tuple(np.round(v, 12)) for v in tri))
        b = tuple(sorted(tuple(np.round(-v, 12)) for v in tri))
        return min(a, b)

    ours = {key(f) for f in faces}
    theirs = {key(both[s]) for s in hull.simplices}
    assert ours == theirs
    # a cell of RP² is that of its point in the sphere's diagram of ±P
    vor = rp2.voronoi()
    sv = spatial.SphericalVoronoi(both).calculate_areas()
    np.testing.assert_allclose(vor.areas, sv[:1500], rtol=0, atol=1e-9)
    assert abs(vor.areas.sum() - 2 * np.pi) < 1e-12


def test_projective_plane_small_sets_and_antipodes():
    rp2 = orbitri.ProjectivePlane([[0.0, 0, 1], [0, 0, -1]])
    assert rp2.dimension == -1
    assert rp2.duplicates.tolist() == [0, 0]
    rp2.insert([[1.0, 0, 0], [0, 1.0, 0]])
    assert rp2.dimension == 2 and len(rp2.simplices) == 4
    assert (np.abs(rp2.signs) == 1).all()
    assert rp2.voronoi().areas[[0, 2, 3]].sum() == pytest.approx(2 * np.pi, abs=1e-12)
    assert "ProjectivePlane" in repr(rp2)
