"""Exact periodic Delaunay triangulations and Voronoi cells of 2D and 3D point sets.

The domain is a flat torus, a periodic box of any lattice (``PeriodicDelaunay``), or a
closed flat manifold: the Klein bottle or a flat 3-manifold (``Triangulation`` with a
``KleinBottle`` or ``FlatManifold`` space). Every geometric decision is exact, and
degenerate inputs (crystals, grids, duplicates) are handled, not rejected.

>>> import numpy as np, orbitri
>>> rng = np.random.default_rng(1)
>>> points = rng.random((1000, 3)) * [2.0, 1.0, 1.0]
>>> tri = orbitri.PeriodicDelaunay(points, [2.0, 1.0, 1.0])
>>> tri.simplices.shape[1], tri.sheets
(4, 1)
>>> vor = tri.voronoi()
>>> bool(abs(vor.volumes.sum() - 2.0) < 1e-12)
True
"""

from __future__ import annotations

import numpy as np

from ._orbitri import PLATYCOSMS as _PLATYCOSMS
from ._orbitri import Space as _Space
from ._orbitri import Triangulation as _Triangulation
from ._orbitri import Voronoi, __version__

__all__ = [
    "FlatManifold",
    "KleinBottle",
    "PeriodicDelaunay",
    "Triangulation",
    "Voronoi",
    "lattice_matrix",
    "periodic_voronoi",
    "__version__",
]


def lattice_matrix(box, dimension: int) -> np.ndarray:
    """The lattice of a box as a ``dimension × dimension`` matrix whose rows are the lattice
    vectors. The domain is ``{f·M : f ∈ [0, 1)^D}``; points outside it are wrapped in.

    ``box`` may be given as freud and ASE users give it:

    * lengths ``[Lx, Ly, Lz]`` (or ``[Lx, Ly]``): an axis-aligned box;
    * a ``D × D`` matrix whose rows are the lattice vectors (ASE's ``cell``);
    * lengths and tilt factors ``[Lx, Ly, Lz, xy, xz, yz]`` (2D: ``[Lx, Ly, xy]``), as freud
      defines them: ``a = (Lx, 0, 0)``, ``b = (xy·Ly, Ly, 0)``, ``c = (xz·Lz, yz·Lz, Lz)``.
      LAMMPS's tilts are lengths: divide them by ``Ly`` (``xy``) or ``Lz`` (``xz``, ``yz``);
    * a ``freud.box.Box`` (anything with ``to_matrix()``, whose columns are the vectors; a 2D
      one, ``is2D``, gives its 2 × 2 part).

    A box that is 2D by itself (``[Lx, Ly]``, a 2 × 2 matrix, a 2D freud box) for
    ``dimension`` 3, or 3D by itself (six numbers, a 3 × 3 matrix, a 3D freud box) for
    ``dimension`` 2, is a ``ValueError``. Three numbers are ``[Lx, Ly, Lz]`` for
    ``dimension`` 3 and ``[Lx, Ly, xy]`` for ``dimension`` 2.

    >>> lattice_matrix([2.0, 1.0, 1.0, 0.5, 0.0, 0.0], 3)[1]
    array([0.5, 1. , 0. ])
    >>> lattice_matrix([2.0, 1.0, 0.5], 2)
    array([[2. , 0. ],
           [0.5, 1. ]])
    """
    b, own = _box(box)
    if own is not None and own != dimension:
        raise ValueError(
            f"a {own}D box for {dimension}D points: the box and the points "
            f"must have the same dimension"
        )
    if b.ndim == 2:
        if b.shape != (dimension, dimension):
            raise ValueError(
                f"a box matrix for {dimension}-dimensional points must be "
                f"{dimension}×{dimension}, not {b.shape[0]}×{b.shape[1]}"
            )
        return np.ascontiguousarray(b)
    if b.ndim != 1:
        raise ValueError(f"a box is lengths, lengths and tilts, or a matrix; got shape {b.shape}")
    lengths = b[:dimension]
    if b.size in (dimension, 2 * dimension if dimension == 3 else 3):
        for k, length in enumerate(lengths):
            if not np.isfinite(length) or length <= 0:
                raise ValueError(f"invalid box: length {k} is {length}; box lengths must be positive and finite")
    if b.size == dimension:
        return np.diag(b)
    if dimension == 3 and b.size == 6:
        lx, ly, lz, xy, xz, yz = b
        return np.array([[lx, 0.0, 0.0], [xy * ly, ly, 0.0], [xz * lz, yz * lz, lz]])
    if dimension == 2 and b.size == 3:
        lx, ly, xy = b
        return np.array([[lx, 0.0], [xy * ly, ly]])
    tilts = "Lx, Ly, Lz, xy, xz, yz" if dimension == 3 else "Lx, Ly, xy"
    raise ValueError(
        f"a box for {dimension}-dimensional points has {dimension} lengths or [{tilts}], "
        f"not {b.size} numbers"
    )


def _box(box):
    """The box as an array of numbers (lengths and tilts) or a matrix of row vectors, and
    the dimension it states by itself: 2, 3, or None for three numbers (``[Lx, Ly, Lz]`` or
    ``[Lx, Ly, xy]``: the points tell) and shapes ``lattice_matrix`` rejects."""
    if hasattr(box, "to_matrix"):
        m = np.asarray(box.to_matrix(), dtype=float).T
        is2d = getattr(box, "is2D", None)
        if is2d is None:  # not freud's: a 2 × 2 matrix, or freud's 2D layout (Lz = 0)
            is2d = m.shape == (2, 2) or (m.shape == (3, 3) and m[2, 2] == 0)
        return (m[:2, :2], 2) if is2d else (m, 3)
    b = np.asarray(box, dtype=float)
    if b.ndim == 2 and b.shape in ((2, 2), (3, 3)):
        return b, b.shape[0]
    if b.ndim == 1 and b.size in (2, 6):
        return b, 2 if b.size == 2 else 3
    return b, None


def _points(points, dimension=None) -> np.ndarray:
    """Points as an (N, 2) or (N, 3) float array. In 2D (``dimension`` 2), freud's (N, 3)
    points give their first two columns; their third must be 0."""
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] not in (2, 3):
        raise ValueError(f"points must be an array of shape (N, 2) or (N, 3), not {p.shape}")
    if dimension == 2 and p.shape[1] == 3:
        nonzero = np.flatnonzero(p[:, 2] != 0)
        if nonzero.size:
            k = nonzero[0]
            raise ValueError(
                f"2D points must have 2 columns, or 3 whose last is 0 (freud's 2D systems): "
                f"point {k} has z = {p[k, 2]}"
            )
        p = p[:, :2]
    return p


class _Delaunay:
    """What every triangulation offers: ``PeriodicDelaunay`` (a torus) and ``Triangulation``
    (a closed flat manifold). Group elements, where they appear, are a torus's offsets (N ×
    D) and a manifold's ``(cosets, offsets)`` (N and N × D)."""

    def __init__(self, core):
        self._tri = core
        self._cells = None

    def _arrays(self):
        # cached with the generation read first: a concurrent insert makes the cache stale
        # by its generation, never fresh-looking
        generation = self._tri.generation
        cached = self._cells
        if cached is None or cached[0] != generation:
            cached = (generation, self._tri.cells())
            self._cells = cached
        return cached[1]

    @property
    def dimension(self) -> int:
        """2 or 3."""
        return self._tri.dimension

    @property
    def points(self) -> np.ndarray:
        """The input points wrapped into the domain (N × D), in input order."""
        return self._tri.points

    @property
    def simplices(self) -> np.ndarray:
        """Input ids of the vertices of every simplex (C × (D+1))."""
        return self._arrays()[0]

    @property
    def neighbors(self) -> np.ndarray:
        """The simplex opposite each vertex of every simplex (C × (D+1))."""
        return self._arrays()[2]

    @property
    def sheets(self) -> int:
        """1 once the triangulation is one of the space; more for too few points."""
        return self._tri.sheets

    @property
    def is_one_sheeted(self) -> bool:
        return self._tri.is_one_sheeted

    def is_valid(self) -> bool:
        """Checks the triangulation exactly: combinatorics, orientation, the empty-sphere
        property and the Euler characteristic (without holding the interpreter). Returns
        ``True``, or raises ``ValueError`` with the reason."""
        return self._tri.is_valid()

    def try_one_sheet(self) -> bool:
        """Moves a triangulation still in a covering space (``sheets > 1``) to the space if
        its projection there is already a simplicial complex; returns ``is_one_sheeted``.

        The construction does this at its end; after ``insert`` it is the caller's choice:
        points inserted a few at a time can stay in the covering although their projection
        is fine, and a 1-sheeted triangulation is smaller. Later insertions stay correct
        either way.

        >>> import numpy as np, orbitri
        >>> rng = np.random.default_rng(0)
        >>> clusters = rng.random((8, 1, 2)) + 0.03 * rng.standard_normal((8, 30, 2))
        >>> pts = clusters.reshape(-1, 2) % 1.0
        >>> tri = orbitri.PeriodicDelaunay(pts[:1], [1.0, 1.0])
        >>> ids = tri.insert(pts[1:])
        >>> tri.sheets, orbitri.PeriodicDelaunay(pts, [1.0, 1.0]).sheets
        (4, 1)
        >>> tri.try_one_sheet(), tri.sheets
        (True, 1)
        """
        return self._tri.try_one_sheet()

    @property
    def number_of_input_points(self) -> int:
        """How many points were given (construction and ``insert``), duplicates included."""
        return self._tri.number_of_input_points

    @property
    def duplicates(self) -> np.ndarray:
        """For every input point, the input id of its first occurrence (itself if none)."""
        return self._tri.duplicates

    @property
    def number_of_duplicates(self) -> int:
        return self._tri.number_of_duplicates

    @property
    def number_of_wrapped(self) -> int:
        """How many input points were outside the domain and wrapped into it."""
        return self._tri.number_of_wrapped

    def insert(self, points) -> np.ndarray:
        """Inserts more points (their input ids follow the existing ones); returns for each
        the input id of the vertex it became or coincides with.

        All or nothing: every point is checked before any is inserted; the batch then goes
        in spatially sorted (BRIO + Hilbert), so a large batch in random order costs about
        what a bulk build does. An error names the point by its row in ``points`` (not by
        the input id it would have had):

        >>> import numpy as np, orbitri
        >>> tri = orbitri.PeriodicDelaunay([[0.1, 0.2], [0.6, 0.7]], [1.0, 1.0])
        >>> tri.insert([[0.3, 0.3], [0.4, 0.9], [0.5, np.nan]])
        Traceback (most recent call last):
        ...
        ValueError: point 2: coordinate 1 is NaN, not a finite number
        >>> tri.number_of_input_points
        2
        """
        return self._tri.insert(_points(points, self.dimension))

    def remove(self, ids) -> int:
        """Removes input points (one id or a sequence of ids), all or none. The other ids
        never change; afterwards the triangulation is the one a fresh build of the remaining
        points gives. A removed id's row of ``points`` is NaN and its ``duplicates`` entry
        -1. An id never given, removed, or repeated is an ``IndexError``; returns 1 when the
        remaining points had to be triangulated again from the covering space, else 0.

        >>> import orbitri
        >>> tri = orbitri.PeriodicDelaunay([[0.1, 0.2], [0.6, 0.7], [0.3, 0.8]], [1.0, 1.0])
        >>> tri.remove([0, 2])
        1
        >>> tri.duplicates.tolist()
        [-1, 1, -1]
        >>> tri.remove(0)
        Traceback (most recent call last):
        ...
        IndexError: input id 0: was removed
        """
        return self._tri.remove(ids)

    def move(self, ids, points) -> np.ndarray:
        """Moves input points ``ids`` to ``points`` (one row each), keeping their ids, all
        or none (ids and coordinates are checked first). Returns per point whether the move
        only changed its coordinates (the cells around it stayed Delaunay; otherwise it was
        removed and inserted again). A move onto another point makes a duplicate.

        >>> import orbitri
        >>> tri = orbitri.PeriodicDelaunay([[0.1, 0.2], [0.6, 0.7], [0.3, 0.8]], [1.0, 1.0])
        >>> tri.move([1], [[0.61, 0.7]]).shape
        (1,)
        >>> tri.points[1].tolist()
        [0.61, 0.7]
        """
        ids = np.atleast_1d(np.asarray(ids))
        return self._tri.move(ids.tolist(), _points(points, self.dimension))

    def find_simplex(self, points) -> np.ndarray:
        """For every query point (rows), the index into ``simplices`` of the simplex that
        contains it (scipy's name), located in parallel. Points anywhere are wrapped into
        the domain first; a non-finite coordinate is a ``ValueError`` naming its row.

        >>> import numpy as np, orbitri
        >>> tri = orbitri.PeriodicDelaunay(np.random.default_rng(0).random((50, 2)), [1.0, 1.0])
        >>> k = tri.find_simplex([[0.5, 0.5], [1.5, -0.5]])
        >>> k.shape, bool(k[0] == k[1])
        ((2,), True)
        """
        return self._tri.find_simplex(_points(points, self.dimension))

    def locate(self, point):
        """The simplex containing ``point``: (vertex ids, their elements, the point's
        element in that simplex's frame)."""
        q = [float(x) for x in point]
        if len(q) == 3 and self.dimension == 2:
            q = _points([q], 2)[0].tolist()
        return self._tri.locate(q)

    def edges(self):
        """The Delaunay edges, each once: (pairs E × 2, elements, lengths E); the second
        point's image is ``points[j]`` moved by the element (in a torus ``points[j] + shift
        @ lattice``)."""
        return self._tri.edges()

    def vertex_neighbors(self, i: int):
        """The Delaunay neighbours of input point ``i``: (ids, elements).

        ``i`` is an integer (Python's or numpy's; a float or a string is a ``TypeError``)
        from 0 to ``number_of_input_points - 1``, else ``IndexError`` (no negative ids)."""
        return self._tri.vertex_neighbors(i)

    def voronoi(self) -> Voronoi:
        """The Voronoi cells (volumes, neighbours with their elements and face areas,
        centroids, and the cells themselves on demand). Computed without holding the
        interpreter; Ctrl-C stops it."""
        return self._tri.voronoi()


class PeriodicDelaunay(_Delaunay):
    """The Delaunay triangulation of points in a periodic box (2D or 3D, from the points'
    shape), exact for every input.

    Points outside the box are wrapped into it; a point that coincides with an earlier one
    (also through a period) is a duplicate: it maps to its first occurrence and is listed in
    ``duplicates``. Construction runs without holding the interpreter, and Ctrl-C stops it
    (``KeyboardInterrupt``) within a fraction of a second.

    freud's 2D systems (a 2D box, N × 3 points whose last column is 0) are 2D: a box that is
    2D by itself (``[Lx, Ly]``, a 2 × 2 matrix, a ``freud.box.Box`` with ``is2D``) takes the
    first two columns of such points; a non-zero third coordinate is an error, and so are 2D
    points in a 3D box.

    One object may be used from several threads: reads run together, ``insert``, ``locate``
    and ``try_one_sheet`` one at a time, each waiting without holding the interpreter.

    Arrays follow ``scipy.spatial.Delaunay``: ``simplices`` (C × (D+1) input ids, positively
    oriented), ``offsets`` (C × (D+1) × D: vertex ``k`` of simplex ``c`` lies at
    ``points[simplices[c, k]] + offsets[c, k] @ lattice``), ``neighbors`` (C × (D+1): the
    simplex opposite each vertex). While the points are too few for the torus
    (``sheets > 1``), these list every simplex of the covering space. The elements of
    ``locate``, ``edges`` and ``vertex_neighbors`` are offsets too.

    >>> import orbitri
    >>> tri = orbitri.PeriodicDelaunay([[0.1, 0.2], [0.6, 0.4], [0.3, 0.8], [0.8, 0.9]] * 10
    ...                                + [[0.05 * i, 0.5] for i in range(20)], [1.0, 1.0])
    >>> int(tri.duplicates[4]), tri.simplices.shape[1]
    (0, 3)
    >>> orbitri.PeriodicDelaunay([[0.1, 0.2, 0.0], [0.6, 0.7, 0.0]], [1.0, 1.0]).dimension
    2
    """

    def __init__(self, points, box):
        p = _points(points, _box(box)[1])
        super().__init__(_Triangulation(p, lattice_matrix(box, p.shape[1])))

    @property
    def lattice(self) -> np.ndarray:
        """The lattice vectors (rows)."""
        return self._tri.lattice

    @property
    def offsets(self) -> np.ndarray:
        """Lattice offsets of the simplices' vertices (C × (D+1) × D)."""
        return self._arrays()[1]


def _of_space(attribute: str, doc: str) -> property:
    """A read-only property of a ``FlatManifold``: its core's."""
    return property(lambda self: getattr(self._space, attribute), doc=doc)


class FlatManifold:
    """A closed flat manifold: ``"klein"``, the Klein bottle of sides ``[a, b]`` (see
    ``KleinBottle``), or a flat 3-manifold of ``PLATYCOSMS`` whose standard domain has
    sides ``[L1, L2, L3]`` (the tetracosm needs ``L1 == L2``). A name or box the library
    cannot take is a ``ValueError`` naming the ones it can.

    Its group acts by isometries ``x ↦ A·x + t``: an element is a coset (of the translations,
    ``0 ≤ coset < index``) and an integer offset (in units of the ``translations``).

    >>> import orbitri
    >>> hw = orbitri.FlatManifold("didicosm", [1.0, 1.0, 1.25])
    >>> hw.index, hw.is_orientable, hw.volume
    (4, True, 1.25)
    >>> A, t = hw.isometry(2, [0, 0, 0])
    >>> A.tolist(), t.tolist()
    ([[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]], [0.0, 0.5, 0.625])
    """

    #: The flat 3-manifolds the library triangulates.
    PLATYCOSMS = tuple(_PLATYCOSMS)

    def __init__(self, name: str, box):
        self._sides = [float(x) for x in np.asarray(box, dtype=float).ravel()]
        self._space = _Space(str(name), self._sides)

    def __repr__(self) -> str:
        return f"FlatManifold({self.name!r}, {self._sides})"

    name = _of_space("name", "``klein`` or the platycosm's name.")
    dimension = _of_space("dimension", "2 (the Klein bottle) or 3.")
    index = _of_space("index", "The number of cosets of the translations in the group.")
    volume = _of_space("volume", "Volume (area in 2D) of the manifold: that of its domain.")
    is_orientable = _of_space("is_orientable", "Whether no element reverses orientation.")
    systole = _of_space("systole", "The least distance between a point and another of its images.")
    translations = _of_space("translations", "The lattice of the group's translations (rows, D × D).")
    generators = _of_space(
        "generators",
        "The group's generators as isometries ``(A, t)``, ``A`` (G × D × D) and ``t`` (G × D): "
        "the ``D`` translations, then the representatives of cosets 1, 2, …",
    )

    def isometry(self, coset, offset):
        """The isometries ``x ↦ A·x + t`` of the elements ``(coset, offset)``: for cosets
        of any shape ``S`` and offsets of shape ``S + (D,)``, ``A`` of shape ``S + (D, D)``
        and ``t`` of shape ``S + (D,)``. A coset or offset that does not exist is a
        ``ValueError``."""
        c = np.asarray(coset, dtype=np.int64)
        o = np.asarray(offset, dtype=np.int64)
        d = self.dimension
        if o.shape != c.shape + (d,):
            raise ValueError(f"cosets of shape {c.shape} need offsets of shape {c.shape + (d,)}, not {o.shape}")
        a, t = self._space.isometries(c.reshape(-1), o.reshape(-1, d))
        return a.reshape(c.shape + (d, d)), t.reshape(c.shape + (d,))


class KleinBottle(FlatManifold):
    """The Klein bottle of the rectangle ``[0, a) × [0, b)``: its group is generated by the
    glide reflection ``(x, y) ↦ (x + a, −y)`` and the translation ``(x, y) ↦ (x, y + b)``.

    >>> import orbitri
    >>> k = orbitri.KleinBottle(1.0, 0.5)
    >>> k.index, k.is_orientable, k.volume, k.translations.tolist()
    (2, False, 0.5, [[2.0, 0.0], [0.0, 0.5]])
    """

    def __init__(self, a: float, b: float):
        super().__init__("klein", [a, b])

    def __repr__(self) -> str:
        return f"KleinBottle({self._sides[0]}, {self._sides[1]})"


class Triangulation(_Delaunay):
    """The Delaunay triangulation of points in a closed flat manifold: a Klein bottle or a
    flat 3-manifold (``space``, a ``KleinBottle`` or a ``FlatManifold``), exact for every
    input.

    It offers what ``PeriodicDelaunay`` offers, with group elements where a torus has
    offsets: ``elements`` is ``(cosets, offsets)``, of shapes C × (D+1) and C × (D+1) × D,
    and vertex ``k`` of simplex ``c`` lies at ``A·points[simplices[c, k]] + t`` for the
    isometry ``(A, t) = space.isometry(cosets[c, k], offsets[c, k])``;
    ``elements_as_isometries()`` gives them all at once. ``locate``, ``edges``,
    ``vertex_neighbors`` and ``voronoi().neighbors()`` give ``(cosets, offsets)`` as their
    elements; a Voronoi face's ``element`` is ``(coset, offset)``. Points are wrapped into
    the space's domain; simplices are positively oriented once lifted (counter-clockwise in
    2D), also through elements that reverse orientation.

    >>> import numpy as np, orbitri
    >>> klein = orbitri.KleinBottle(1.0, 0.5)
    >>> pts = np.random.default_rng(3).random((1000, 2)) * [1.0, 0.5]
    >>> tri = orbitri.Triangulation(pts, space=klein)
    >>> tri.is_valid(), tri.sheets, len(tri.simplices)
    (True, 1, 2000)
    >>> A, t = tri.elements_as_isometries()
    >>> lifted = np.einsum("ckij,ckj->cki", A, tri.points[tri.simplices]) + t
    >>> bool((np.linalg.det(lifted[:, 1:] - lifted[:, :1]) > 0).all())
    True
    >>> bool(abs(tri.voronoi().volumes.sum() - klein.volume) < 1e-12)
    True
    """

    def __init__(self, points, space: FlatManifold):
        if not isinstance(space, FlatManifold):
            raise TypeError(
                f"space must be a FlatManifold or a KleinBottle, not {type(space).__name__} "
                f"(for a periodic box use PeriodicDelaunay)"
            )
        self.space = space
        super().__init__(_Triangulation.in_manifold(_points(points, space.dimension), space._space))

    @property
    def elements(self):
        """The group elements of the simplices' vertices: ``(cosets, offsets)``, C × (D+1)
        and C × (D+1) × D."""
        return self._arrays()[1]

    def elements_as_isometries(self):
        """The elements of the simplices' vertices as isometries ``x ↦ A·x + t``: ``A``
        (C × (D+1) × D × D) and ``t`` (C × (D+1) × D)."""
        return self.space.isometry(*self.elements)

    def locate(self, point):
        """The simplex containing ``point``: (vertex ids, their elements ``(cosets,
        offsets)``, the point's element ``(coset, offset)`` in that simplex's frame)."""
        vertices, elements, (coset, offset) = super().locate(point)
        return vertices, elements, (int(coset), offset)


def periodic_voronoi(points, box) -> Voronoi:
    """The periodic Voronoi cells of points in a box: ``PeriodicDelaunay(points,
    box).voronoi()``.

    >>> import numpy as np, orbitri
    >>> vor = orbitri.periodic_voronoi(np.random.default_rng(2).random((500, 2)), [1.0, 1.0])
    >>> len(vor), bool(abs(vor.volumes.sum() - 1.0) < 1e-12)
    (500, True)
    """
    return PeriodicDelaunay(points, box).voronoi()
