"""Triangulations of closed flat manifolds from Python: the Klein bottle and flat
3-manifolds (the Hantzsche–Wendt didicosm, orientable; the first amphicosm, not; the
hexagonal screws), checked by
lifting every simplex with numpy, by Voronoi volumes, and against the command line."""

import json
import subprocess

import numpy as np
import pytest

import orbitri
from test_orbitri import _cli

BOX3 = [1.0, 1.0, 1.25]

# (name, sides, sizes): a few points stay in a covering space, more reach the quotient
SPACES = [
    ("klein", [1.0, 0.75], (3, 1000)),
    ("didicosm", BOX3, (3, 300)),
    ("first-amphicosm", BOX3, (3, 1000)),
]


def _random(sides, n, seed):
    return np.random.default_rng(seed).random((n, len(sides))) * sides


def _apply(a, t, p):
    """``A·p + t`` for stacks of isometries and points."""
    return np.einsum("...ij,...j->...i", a, p) + t


@pytest.mark.parametrize("name, sides, sizes", SPACES)
def test_valid_positively_oriented_and_the_voronoi_cells_fill_the_space(name, sides, sizes):
    space = orbitri.FlatManifold(name, sides)
    d = len(sides)
    assert space.volume == pytest.approx(np.prod(sides), rel=1e-15)
    for n in sizes:
        tri = orbitri.Triangulation(_random(sides, n, n), space=space)
        assert tri.is_valid() and tri.dimension == d
        assert tri.is_one_sheeted == (n == 1000)
        cosets, offsets = tri.elements
        c = len(tri.simplices)
        assert cosets.shape == (c, d + 1) and offsets.shape == (c, d + 1, d)
        assert tri.neighbors.shape == (c, d + 1)
        # lifted by their elements, the simplices are positively oriented and fill the
        # space once (one simplex per simplex of the space, also from a covering)
        a, t = tri.elements_as_isometries()
        assert a.shape == (c, d + 1, d, d) and t.shape == (c, d + 1, d)
        lifted = _apply(a, t, tri.points[tri.simplices])
        vol = np.linalg.det(lifted[:, 1:] - lifted[:, :1]) / (2 if d == 2 else 6)
        assert (vol > 0).all()
        assert abs(vol.sum() - space.volume) <= 1e-9 * space.volume
        vor = tri.voronoi()
        assert len(vor) == n
        assert abs(vor.volumes.sum() - space.volume) <= 1e-12 * space.volume


@pytest.mark.parametrize("name, sides, sizes", SPACES)
def test_edges_neighbours_and_locate_speak_in_elements(name, sides, sizes):
    space = orbitri.FlatManifold(name, sides)
    n = sizes[1]
    tri = orbitri.Triangulation(_random(sides, n, 7), space=space)
    p = tri.points
    # an edge's length is the distance to the element's image of its second point
    ij, (cosets, offsets), lengths = tri.edges()
    far = _apply(*space.isometry(cosets, offsets), p[ij[:, 1]])
    np.testing.assert_allclose(np.linalg.norm(far - p[ij[:, 0]], axis=1), lengths, rtol=1e-12)
    ids, (nc, no) = tri.vertex_neighbors(0)
    assert len(ids) == len(nc) == len(no) == np.count_nonzero(ij == 0)
    # Voronoi neighbours: each pair once, with its element
    vor = tri.voronoi()
    pairs, (vc, vo), areas = vor.neighbors()
    assert 2 * len(pairs) == vor.neighbor_counts.sum() and len(vc) == len(areas)
    face = vor.cells()[0]["faces"][0]
    assert set(face) == {"vertices", "neighbor", "element", "area"}
    coset, offset = face["element"]
    assert 0 <= coset < space.index and len(offset) == len(sides)
    # locate: the point, moved by its element, lies in the simplex
    q = np.array(sides) * 0.37
    verts, (lc, lo), (qc, qo) = tri.locate(q)
    corners = _apply(*space.isometry(lc, lo), p[verts])
    x = _apply(*space.isometry(qc, qo), q)
    lam = np.linalg.solve((corners[1:] - corners[0]).T, x - corners[0])
    assert (lam >= -1e-12).all() and lam.sum() <= 1 + 1e-12
    # insertion: all or nothing, ids follow
    assert tri.insert(_random(sides, 5, 8)).tolist() == list(range(n, n + 5))
    assert tri.is_valid()


def test_the_group_of_a_space():
    k = orbitri.KleinBottle(1.0, 0.5)
    assert (k.name, k.dimension, k.index, k.is_orientable) == ("klein", 2, 2, False)
    assert k.systole == 0.5 and k.volume == 0.5
    np.testing.assert_array_equal(k.translations, [[2.0, 0.0], [0.0, 0.5]])
    a, t = k.generators
    # the translations, then the glide (x, y) ↦ (x + 1, −y)
    np.testing.assert_array_equal(a, [np.eye(2), np.eye(2), [[1, 0], [0, -1]]])
    np.testing.assert_array_equal(t, [[2.0, 0.0], [0.0, 0.5], [1.0, 0.0]])
    # an element's isometry: coset c's representative, then the offset's translation
    a, t = k.isometry([[1, 0]], [[[2, -1], [0, 3]]])
    assert a.shape == (1, 2, 2, 2) and t.shape == (1, 2, 2)
    np.testing.assert_array_equal(t[0], [[5.0, -0.5], [0.0, 1.5]])
    for name in orbitri.FlatManifold.PLATYCOSMS:
        m = orbitri.FlatManifold(name, BOX3)
        a, t = m.generators
        across = 3**0.5 / 2 if name in ("tricosm", "hexacosm") else 1.0
        assert len(a) == 3 + m.index - 1 and m.volume == pytest.approx(1.25 * across, rel=1e-15)
        assert m.is_orientable == (np.linalg.det(a) > 0).all()
        np.testing.assert_array_equal(t[:3], m.translations)
    assert "didicosm" in repr(orbitri.FlatManifold("didicosm", BOX3))
    assert repr(k) == "KleinBottle(1.0, 0.5)"


@pytest.mark.parametrize("name, index", [("tricosm", 3), ("hexacosm", 6)])
def test_the_hexagonal_screws(name, index):
    space = orbitri.FlatManifold(name, BOX3)
    assert space.index == index and space.is_orientable
    # the 60° rhombus of side 1 times 1.25
    assert space.volume == pytest.approx(1.25 * 3**0.5 / 2, rel=1e-15)
    a, _ = space.generators
    # the screw turns by a third or a sixth: its trace in the plane is 2·cos(2π/index)
    np.testing.assert_allclose(np.trace(a[3][:2, :2]), 2 * np.cos(2 * np.pi / index), atol=1e-15)
    for n in (3, 400):
        tri = orbitri.Triangulation(_random(BOX3, n, n), space=space)
        assert tri.is_valid()
        assert abs(tri.voronoi().volumes.sum() - space.volume) <= 1e-12 * space.volume


def test_bad_spaces_boxes_and_elements_are_value_errors():
    with pytest.raises(ValueError, match="unknown flat 3-manifold \"mobius\": one of torocosm, dicosm"):
        orbitri.FlatManifold("mobius", BOX3)
    with pytest.raises(ValueError, match="unknown flat 3-manifold \"mobius\""):
        orbitri.FlatManifold("mobius", [1.0, 1.0])
    for name in ("tricosm", "hexacosm"):
        with pytest.raises(ValueError, match=f"the {name} turns a hexagonal cross-section of side L1: L1 = L2"):
            orbitri.FlatManifold(name, [1.0, 2.0, 1.0])
    with pytest.raises(ValueError, match=r"the Klein bottle takes 2 sides, \[a, b\], not 3"):
        orbitri.FlatManifold("klein", BOX3)
    with pytest.raises(ValueError, match=r"the dicosm takes 3 sides, \[L1, L2, L3\], not 2"):
        orbitri.FlatManifold("dicosm", [1.0, 1.0])
    with pytest.raises(ValueError, match="invalid box: the Klein bottle needs two positive finite sides"):
        orbitri.KleinBottle(1.0, -1.0)
    with pytest.raises(ValueError, match="invalid box: the tetracosm turns a square cross-section: L1 = L2"):
        orbitri.FlatManifold("tetracosm", [1.0, 2.0, 1.0])
    with pytest.raises(ValueError, match="the didicosm needs three positive finite sides"):
        orbitri.FlatManifold("didicosm", [1.0, np.nan, 1.0])
    klein = orbitri.KleinBottle(1.0, 1.0)
    with pytest.raises(ValueError, match="the didicosm is 3-dimensional: points must have 3 columns, not 2"):
        orbitri.Triangulation([[0.1, 0.2]], space=orbitri.FlatManifold("didicosm", BOX3))
    with pytest.raises(ValueError, match="2D points must have 2 columns, or 3 whose last is 0"):
        orbitri.Triangulation(_random(BOX3, 5, 1) + [0, 0, 1], space=klein)
    with pytest.raises(ValueError, match="point 1: coordinate 0 is NaN"):
        orbitri.Triangulation([[0.1, 0.2], [np.nan, 0.3]], space=klein)
    with pytest.raises(TypeError, match="space must be a FlatManifold or a KleinBottle"):
        orbitri.Triangulation([[0.1, 0.2]], space=[1.0, 1.0])
    with pytest.raises(ValueError, match="coset 2 does not exist: the klein has cosets 0 to 1"):
        klein.isometry(2, [0, 0])
    with pytest.raises(ValueError, match="out of range"):
        klein.isometry(0, [300, 0])
    with pytest.raises(ValueError, match="need offsets of shape"):
        klein.isometry([0, 1], [0, 0])


def test_the_command_line_gives_the_same_cells(tmp_path):
    # sizes the unoptimized build of the command (tests.sh's) runs in a second
    for name, sides, n in [("klein", [1.0, 0.75], 1000), ("first-amphicosm", BOX3, 3)]:
        pts = _random(sides, n, 9)
        f = tmp_path / f"{name}.txt"
        f.write_text("\n".join(" ".join(repr(float(x)) for x in p) for p in pts))
        out = subprocess.run(
            [_cli(), "triangulate", str(f), "--space", name, "--box", *map(str, sides), "--format", "json"],
            check=True,
            capture_output=True,
            text=True,
        ).stdout
        cli = json.loads(out)
        tri = orbitri.Triangulation(pts, space=orbitri.FlatManifold(name, sides))
        assert cli["space"] == name and cli["sheets"] == tri.sheets
        a, t = tri.space.generators
        assert np.array_equal([g[0] for g in cli["group"]["generators"]], a)
        assert np.array_equal([g[1] for g in cli["group"]["generators"]], t)
        assert np.array_equal(cli["cells"], tri.simplices)
        a, t = tri.elements_as_isometries()
        assert np.array_equal([[e[0] for e in c] for c in cli["elements"]], a)
        assert np.array_equal([[e[1] for e in c] for c in cli["elements"]], t)
