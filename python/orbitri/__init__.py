"""Exact periodic Delaunay triangulations and Voronoi cells of 2D and 3D point sets.

The domain is a flat torus, a periodic box of any lattice (``PeriodicDelaunay``), a
closed flat manifold: the Klein bottle or a flat 3-manifold (``Triangulation`` with a
``KleinBottle`` or ``FlatManifold`` space), the sphere (``SphericalDelaunay``) or the real
projective plane (``ProjectivePlane``). Every geometric decision is exact, and
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

import os
import sys
import time

import numpy as np

from ._orbitri import PLATYCOSMS as _PLATYCOSMS
from ._orbitri import Space as _Space
from ._orbitri import Triangulation as _Triangulation
from ._orbitri import __version__
from ._orbitri import cellpar_matrix as _cellpar_matrix
from ._orbitri import set_progress_hook as _set_progress_hook
from ._sphere import ProjectivePlane, SphericalDelaunay, SphericalVoronoi

__all__ = [
    "Box",
    "FlatManifold",
    "KleinBottle",
    "NeighborList",
    "PeriodicDelaunay",
    "ProjectivePlane",
    "SphericalDelaunay",
    "SphericalVoronoi",
    "Triangulation",
    "Voronoi",
    "lattice_matrix",
    "periodic_voronoi",
    "set_progress",
    "__version__",
]


def _interactive() -> bool:
    """True in a terminal session or a Jupyter kernel."""
    if "ipykernel" in sys.modules:
        return True
    try:
        return sys.stderr is not None and sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


class _Bar:
    """Shows the progress of a long computation on ``sys.stderr`` (through ``tqdm.auto``
    when installed: a widget in Jupyter), from one second on: the phase, the percentage and
    the time left, from the rate so far."""

    def __init__(self):
        self._reset()

    def _reset(self):
        self._phase, self._start, self._shown, self._tqdm, self._width = None, 0.0, 0.0, None, 0

    def __call__(self, phase, done, total, finished):
        now = time.monotonic()
        if phase != self._phase:
            self._close()
            self._phase, self._start = phase, now
        if finished:
            self._close()
            self._reset()
            return
        if now - self._start < 1.0 or total <= 0:
            return
        if self._tqdm is None and self._width == 0:
            try:
                from tqdm.auto import tqdm

                self._tqdm = tqdm(total=total, desc=f"orbitri: {phase}", leave=False)
            except ImportError:
                pass
        if self._tqdm is not None:
            self._tqdm.update(done - self._tqdm.n)
            return
        if now - self._shown < 0.25:
            return
        self._shown = now
        fraction = done / total
        left = (now - self._start) * (1 - fraction) / fraction if fraction > 0 else None
        eta = "" if left is None else f", {int(left) // 60}:{int(left) % 60:02d} left"
        line = f"orbitri: {phase} {100 * fraction:3.0f}%{eta}"
        self._width = max(self._width, len(line))
        sys.stderr.write("\r" + line.ljust(self._width))
        sys.stderr.flush()

    def _close(self):
        if self._tqdm is not None:
            self._tqdm.update(self._tqdm.total - self._tqdm.n)
            self._tqdm.close()
        elif self._width:
            sys.stderr.write("\r" + " " * self._width + "\r")
            sys.stderr.flush()
        self._tqdm, self._width = None, 0


def set_progress(show="auto"):
    """Whether long computations (a construction or ``voronoi()`` of 20 000 points or more)
    show their progress: ``"auto"`` (the default) when interactive, in a terminal or a
    Jupyter notebook; ``True`` always; ``False`` never; or a callable
    ``show(phase, done, total, finished)`` of your own, called about every 50 ms while the
    work runs and once with ``finished=True`` at the end (also after Ctrl-C). The bar
    appears after one second, on ``sys.stderr`` (through ``tqdm`` when it is installed),
    with the phase, the percentage and the time left. The environment variable
    ``ORBITRI_PROGRESS=0`` or ``1`` sets the default.

    >>> import orbitri
    >>> seen = []
    >>> orbitri.set_progress(lambda phase, done, total, finished: seen.append((phase, finished)))
    >>> _ = orbitri.PeriodicDelaunay(np.random.default_rng(0).random((30_000, 2)), [1.0, 1.0])
    >>> seen[-1]
    ('triangulating', True)
    >>> orbitri.set_progress(False)
    """
    if callable(show):
        _set_progress_hook(show)
    elif show == "auto":
        _set_progress_hook(_Bar() if _interactive() else None)
    elif show is True or show is False:
        _set_progress_hook(_Bar() if show else None)
    else:
        raise ValueError(f"set_progress takes 'auto', True, False or a callable, not {show!r}")


set_progress({"0": False, "1": True}.get(os.environ.get("ORBITRI_PROGRESS", ""), "auto"))


def _numbers(args, what: str) -> np.ndarray:
    """The numbers of ``f(1, 2, 3)``, ``f([1, 2, 3])`` or ``f("1 2 3")`` as a flat array."""
    if len(args) == 1:
        args = args[0]
        if isinstance(args, str):
            args = args.split()
    a = np.asarray(args, dtype=float).ravel()
    if not np.isfinite(a).all():
        raise ValueError(f"{what}: every number must be finite, got {a.tolist()}")
    return a


class Box:
    """A periodic box: its lattice vectors, the rows of ``matrix`` (D × D, D = 2 or 3). The
    domain is ``{f·M : f ∈ [0, 1)^D}``; points anywhere are wrapped into it. Accepted
    wherever a box is (``PeriodicDelaunay``, ``periodic_voronoi``, ``lattice_matrix``).

    Build one the way your code writes boxes:

    * ``Box.from_cellpar(a, b, c, alpha, beta, gamma)``: lengths and angles in degrees
      (ASE's ``atoms.cell.cellpar()``, MDAnalysis's ``dimensions``, a CIF); 2D ``(a, b,
      gamma)``. ``a`` lies along x and ``b`` in the xy-plane, as ASE and MDAnalysis put them.
    * ``Box.from_lammps(xlo, xhi, ylo, yhi, zlo, zhi, xy=0, xz=0, yz=0)``: a LAMMPS data
      file's box (its tilts are lengths); 2D ``(xlo, xhi, ylo, yhi[, xy])``.
    * ``Box.from_gromacs(…)``: the last line of a ``.gro`` file, 3 or 9 numbers (or the
      line itself, a string): ``v1(x) v2(y) v3(z) v1(y) v1(z) v2(x) v2(z) v3(x) v3(y)``.
    * ``Box.from_freud(box)``: a ``freud.box.Box``, or what ``freud.box.Box.from_box``
      takes: ``[Lx, Ly]``, ``[Lx, Ly, Lz]`` or ``[Lx, Ly, Lz, xy, xz, yz]`` (tilt factors).
    * ``Box.from_matrix(M)``: the lattice vectors as rows (ASE's ``atoms.cell``).

    >>> import orbitri
    >>> orbitri.Box.from_cellpar(10, 10, 10, 90, 90, 90)
    Box.from_matrix([[10.0, 0.0, 0.0], [0.0, 10.0, 0.0], [0.0, 0.0, 10.0]])
    >>> hexagonal = orbitri.Box.from_cellpar(2, 2, 3, 90, 90, 120)
    >>> round(hexagonal.volume, 6), [round(x, 6) for x in hexagonal.cellpar()]
    (10.392305, [2.0, 2.0, 3.0, 90.0, 90.0, 120.0])
    >>> orbitri.Box.from_lammps(0, 10, 0, 10, 0, 10, 2.5, 0, 0).matrix[1].tolist()
    [2.5, 10.0, 0.0]
    >>> orbitri.Box.from_gromacs("3.0 3.0 3.0").dimension
    3
    """

    __slots__ = ("matrix",)

    def __init__(self, matrix):
        m = np.array(matrix, dtype=float)
        if m.shape not in ((2, 2), (3, 3)):
            raise ValueError(f"a box matrix is 2×2 or 3×3 (rows: the lattice vectors), not of shape {m.shape}")
        if not np.isfinite(m).all():
            raise ValueError(f"invalid box: the matrix has a non-finite entry: {m.tolist()}")
        m.flags.writeable = False
        #: The lattice vectors (rows), D × D, read-only.
        self.matrix = m

    @property
    def dimension(self) -> int:
        """2 or 3."""
        return self.matrix.shape[0]

    @property
    def volume(self) -> float:
        """The volume (area in 2D) of the domain."""
        return float(abs(np.linalg.det(self.matrix)))

    def cellpar(self) -> list:
        """Lengths and angles in degrees: ``[a, b, c, alpha, beta, gamma]`` (2D ``[a, b,
        gamma]``), what ``from_cellpar`` takes."""
        m = self.matrix
        lengths = np.linalg.norm(m, axis=1)

        def angle(u, v):
            return float(np.degrees(np.arccos(np.clip(m[u] @ m[v] / (lengths[u] * lengths[v]), -1, 1))))

        if self.dimension == 2:
            return [float(lengths[0]), float(lengths[1]), angle(0, 1)]
        return [float(x) for x in lengths] + [angle(1, 2), angle(0, 2), angle(0, 1)]

    def __repr__(self) -> str:
        return f"Box.from_matrix({self.matrix.tolist()})"

    def __eq__(self, other) -> bool:
        return isinstance(other, Box) and np.array_equal(self.matrix, other.matrix)

    __hash__ = None

    @classmethod
    def from_matrix(cls, matrix) -> "Box":
        """The box whose lattice vectors are the rows of ``matrix`` (ASE's ``cell``).

        >>> import orbitri
        >>> orbitri.Box.from_matrix([[1, 0], [0.5, 1]]).volume
        1.0
        """
        return cls(matrix)

    @classmethod
    def from_cellpar(cls, *cellpar) -> "Box":
        """Lengths and angles in degrees: ``(a, b, c, alpha, beta, gamma)``, or one sequence
        of them (``atoms.cell.cellpar()``, ``universe.dimensions``); 2D ``(a, b, gamma)``.
        ``alpha`` is the angle between ``b`` and ``c``, ``beta`` between ``a`` and ``c``,
        ``gamma`` between ``a`` and ``b``. Angles that make no cell are a ``ValueError``.

        >>> import orbitri
        >>> orbitri.Box.from_cellpar([1, 1, 60]).matrix.round(6).tolist()
        [[1.0, 0.0], [0.5, 0.866025]]
        """
        return cls(_cellpar_matrix(_numbers(cellpar, "cellpar").tolist()))

    @classmethod
    def from_lammps(cls, *bounds) -> "Box":
        """A LAMMPS box: ``xlo xhi ylo yhi zlo zhi`` and optionally the tilts ``xy xz yz``
        (lengths, as in a data file or ``thermo``): ``a = (xhi − xlo, 0, 0)``, ``b = (xy,
        yhi − ylo, 0)``, ``c = (xz, yz, zhi − zlo)``. 2D: ``xlo xhi ylo yhi [xy]``. The
        origin ``(xlo, ylo, zlo)`` changes no volume and no neighbour: points are wrapped.

        >>> import orbitri
        >>> orbitri.Box.from_lammps(-5, 5, -5, 5).matrix.tolist()
        [[10.0, 0.0], [0.0, 10.0]]
        """
        b = _numbers(bounds, "LAMMPS box")
        if b.size in (6, 9):
            xlo, xhi, ylo, yhi, zlo, zhi = b[:6]
            xy, xz, yz = b[6:] if b.size == 9 else (0.0, 0.0, 0.0)
            return cls([[xhi - xlo, 0, 0], [xy, yhi - ylo, 0], [xz, yz, zhi - zlo]])
        if b.size in (4, 5):
            xlo, xhi, ylo, yhi = b[:4]
            xy = b[4] if b.size == 5 else 0.0
            return cls([[xhi - xlo, 0], [xy, yhi - ylo]])
        raise ValueError(
            f"a LAMMPS box is xlo xhi ylo yhi zlo zhi [xy xz yz] (6 or 9 numbers; 2D 4 or 5), not {b.size} numbers"
        )

    @classmethod
    def from_gromacs(cls, *box) -> "Box":
        """A GROMACS box: the last line of a ``.gro`` file (a string, or its numbers): 3
        lengths, or 9 numbers ``v1(x) v2(y) v3(z) v1(y) v1(z) v2(x) v2(z) v3(x) v3(y)``.

        >>> import orbitri
        >>> orbitri.Box.from_gromacs("4 4 4 0 0 2 0 2 2").matrix.tolist()
        [[4.0, 0.0, 0.0], [2.0, 4.0, 0.0], [2.0, 2.0, 4.0]]
        """
        b = _numbers(box, "GROMACS box")
        if b.size == 3:
            return cls(np.diag(b))
        if b.size == 9:
            v1x, v2y, v3z, v1y, v1z, v2x, v2z, v3x, v3y = b
            return cls([[v1x, v1y, v1z], [v2x, v2y, v2z], [v3x, v3y, v3z]])
        raise ValueError(f"a GROMACS box line has 3 or 9 numbers, not {b.size}")

    @classmethod
    def from_freud(cls, box) -> "Box":
        """A ``freud.box.Box`` (its ``is2D`` boxes are 2D), or the numbers
        ``freud.box.Box.from_box`` takes: ``[Lx, Ly]`` (2D), ``[Lx, Ly, Lz]``, or ``[Lx, Ly,
        Lz, xy, xz, yz]`` with freud's tilt factors: ``a = (Lx, 0, 0)``, ``b = (xy·Ly, Ly,
        0)``, ``c = (xz·Lz, yz·Lz, Lz)`` (``Lz = 0``: 2D). Taken as given, large tilts too.

        >>> import orbitri
        >>> orbitri.Box.from_freud([2, 1, 1, 0.5, 0, 0]).matrix[1].tolist()
        [0.5, 1.0, 0.0]
        """
        if hasattr(box, "to_matrix"):
            m = np.asarray(box.to_matrix(), dtype=float).T
            return cls(m[:2, :2] if getattr(box, "is2D", False) else m)
        b = _numbers((box,), "freud box")
        if b.size == 2:
            return cls(np.diag(b))
        if b.size == 3:
            return cls(np.diag(b))
        if b.size == 6:
            lx, ly, lz, xy, xz, yz = b
            if lz == 0:
                return cls([[lx, 0.0], [xy * ly, ly]])
            return cls([[lx, 0.0, 0.0], [xy * ly, ly, 0.0], [xz * lz, yz * lz, lz]])
        raise ValueError(f"a freud box is [Lx, Ly], [Lx, Ly, Lz] or [Lx, Ly, Lz, xy, xz, yz], not {b.size} numbers")


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
      one, ``is2D``, gives its 2 × 2 part);
    * a ``Box``, for every other way of writing one (lengths and angles, LAMMPS, GROMACS).

    Six numbers whose tilts all lie between 30 and 180 look like lengths and angles
    (``[10, 10, 10, 90, 90, 90]``): a ``ValueError`` names ``Box.from_cellpar``, and
    ``Box.from_freud`` takes them as tilts if they are.

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
    if b.size == (6 if dimension == 3 else 3) and ((b[dimension:] >= 30) & (b[dimension:] < 180)).all():
        numbers = ", ".join(f"{x:g}" for x in b)
        names = "a, b, c, alpha, beta, gamma" if dimension == 3 else "a, b, gamma"
        tilts = "[Lx, Ly, Lz, xy, xz, yz]" if dimension == 3 else "[Lx, Ly, xy]"
        raise ValueError(
            f"box [{numbers}]: {b.size} numbers are lengths and freud's tilt factors {tilts}, "
            f"and tilts of {', '.join(f'{x:g}' for x in b[dimension:])} box lengths look like angles; "
            f"for lengths and angles in degrees [{names}] (ASE's cellpar, MDAnalysis's dimensions) "
            f"use orbitri.Box.from_cellpar({numbers}); for tilts that large, orbitri.Box.from_freud([{numbers}])"
        )
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
    if isinstance(box, Box):
        return box.matrix, box.dimension
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


_AXES = "xyz"


def _system(system):
    """The points and the box of a system given without a box: an ASE ``Atoms``, an
    MDAnalysis ``Universe`` or ``AtomGroup`` (its current frame), or freud's ``(box,
    points)``."""
    if hasattr(system, "get_positions") and hasattr(system, "cell") and hasattr(system, "pbc"):
        pbc = np.asarray(system.pbc, dtype=bool)
        if not pbc.all():
            axes = ", ".join(_AXES[k] for k in np.flatnonzero(~pbc))
            raise ValueError(
                f"the ASE Atoms are not periodic along {axes} (pbc={pbc.tolist()}); orbitri "
                f"triangulates periodic boxes: set atoms.pbc = True to make the cell periodic "
                f"along every axis (a vacuum gap in the cell then stays between the images)"
            )
        cell = np.asarray(system.cell, dtype=float)
        if cell.shape != (3, 3) or np.linalg.det(cell) == 0:
            raise ValueError(f"the ASE Atoms have no cell (atoms.cell is {cell.tolist()}): set one")
        return system.get_positions(), Box(cell)
    if hasattr(system, "atoms") and hasattr(system, "dimensions"):
        atoms = system.atoms
        dimensions = atoms.dimensions
        if dimensions is None:
            raise ValueError("the MDAnalysis system has no box (its dimensions are None)")
        # lengths and angles, not freud's tilt factors
        return np.asarray(atoms.positions, dtype=float), Box.from_cellpar(dimensions)
    if isinstance(system, tuple) and len(system) == 2 and np.ndim(system[1]) == 2:
        box, points = system
        return points, box if isinstance(box, Box) else Box.from_freud(box)
    raise TypeError(
        f"no box given, and a {type(system).__name__} is not a system: give the points and "
        f"a box, or an ASE Atoms, an MDAnalysis Universe or AtomGroup, or freud's (box, points)"
    )


def _csr(rows, columns, n):
    """scipy's compressed sparse rows of the pairs ``(rows[k], columns[k])``, rows
    ``0 … n − 1``: ``(indptr, indices)``, each row's columns in the pairs' order."""
    order = np.argsort(rows, kind="stable")
    indptr = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(rows, minlength=n), out=indptr[1:])
    return indptr, np.asarray(columns, dtype=np.int64)[order]


def _weights(weights, radii, n):
    """The weights of ``n`` points from ``weights`` or ``radii`` (weight ``r²``), or None;
    a ``ValueError`` names a bad radius and its row, or both given."""
    if weights is not None and radii is not None:
        raise ValueError("give weights or radii, not both (a radius r is the weight r²)")
    if radii is not None:
        r = np.asarray(radii, dtype=float).reshape(-1)
        bad = np.flatnonzero(~(np.isfinite(r) & (r >= 0)))
        if bad.size:
            raise ValueError(f"point {bad[0]}: radius {r[bad[0]]} is not a finite number ≥ 0")
        weights = r * r
    if weights is None:
        return None
    w = np.ascontiguousarray(weights, dtype=float).reshape(-1)
    if w.shape[0] != n:
        raise ValueError(f"{w.shape[0]} weights for {n} points: give one weight (or radius) per point")
    return w


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
    def weights(self):
        """Each input's weight (a squared length; ``radii**2`` when radii were given), or
        None for unweighted points."""
        return self._tri.weights

    @property
    def hidden(self) -> np.ndarray:
        """The hidden input ids, sorted: weighted points whose power cell is empty. They
        have no vertex and a Voronoi volume of 0, and come back when a removal uncovers
        them."""
        return self._tri.hidden

    @property
    def points(self) -> np.ndarray:
        """The input points wrapped into the domain (N × D), in input order."""
        return self._tri.points

    @property
    def simplices(self) -> np.ndarray:
        """Input ids of the vertices of every simplex of the space (C × (D+1)), one per
        simplex of the space also while the triangulation is stored in a covering
        (``sheets > 1``)."""
        return self._arrays()[0]

    @property
    def neighbors(self) -> np.ndarray:
        """The simplex glued to each facet of every simplex (C × (D+1)): ``neighbors[c,
        i]`` lies across the facet opposite vertex ``i``, through the boundary of the
        domain if need be."""
        return self._arrays()[2]

    @property
    def mirrors(self) -> np.ndarray:
        """For every facet, its position in the neighbour (C × (D+1)): the facet of
        simplex ``c`` opposite vertex ``i`` is the facet of ``neighbors[c, i]`` opposite
        vertex ``mirrors[c, i]`` (CGAL's ``mirror_index``). With few points a simplex
        may meet one neighbour through two facets, or itself, and a vertex may appear in
        it twice (two images of one point): the triangulation is a Δ-complex, which
        ``neighbors``, ``mirrors`` and ``gluings`` describe exactly."""
        return self._arrays()[3]

    @property
    def gluings(self):
        """The element that carries each neighbour onto its simplex (a torus's offsets,
        C × (D+1) × D; a manifold's ``(cosets, offsets)``): the neighbour's vertex with
        element ``g`` on the shared facet is the vertex of simplex ``c`` with element
        ``gluings[c, i]∘g`` (in a torus, its offset plus ``gluings[c, i]``).

        >>> import orbitri
        >>> tri = orbitri.PeriodicDelaunay([[0.2, 0.3], [0.7, 0.6]], [1.0, 1.0])
        >>> tri.sheets, len(tri.simplices)
        (8, 4)
        >>> c, i = 0, 0
        >>> n, j = tri.neighbors[c, i], tri.mirrors[c, i]
        >>> here = {(int(tri.simplices[c, k]), tuple(tri.offsets[c, k].tolist())) for k in range(3) if k != i}
        >>> there = {(int(tri.simplices[n, k]), tuple((tri.offsets[n, k] + tri.gluings[c, i]).tolist())) for k in range(3) if k != j}
        >>> here == there
        True
        """
        return self._arrays()[4]

    @property
    def sheets(self) -> int:
        """How the triangulation is stored: 1 once it is a triangulation of the space
        itself; for too few points, the number of sheets of the covering space it lives
        in. ``simplices`` and the other arrays describe the space either way."""
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

    def insert(self, points, weights=None, radii=None) -> np.ndarray:
        """Inserts more points (their input ids follow the existing ones); returns for each
        the input id of the vertex it became or coincides with, −1 when hidden. A weighted
        triangulation takes ``weights`` or ``radii`` (one per point; 0 if neither).

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
        p = _points(points, self.dimension)
        w = _weights(weights, radii, len(p))
        if w is not None and self._tri.weights is None:
            raise ValueError(
                "this triangulation is unweighted: build it with weights= or radii= to insert weighted points"
            )
        if w is None and self._tri.weights is not None:
            w = np.zeros(len(p))
        return self._tri.insert(p, w)

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

    def voronoi(self) -> "Voronoi":
        """The Voronoi cells (volumes, neighbours with their elements and face areas,
        centroids, and the cells themselves on demand). Computed without holding the
        interpreter; Ctrl-C stops it."""
        return Voronoi(self._tri.voronoi(), self)

    @property
    def vertex_neighbor_vertices(self):
        """The Delaunay neighbours of every input point in scipy's form: ``(indptr,
        indices)``, the neighbours of point ``k`` being ``indices[indptr[k]:indptr[k+1]]``
        (distinct ids, sorted; through any period). As in scipy, a duplicate has none (its
        first occurrence has them); a point is its own neighbour when an edge joins it to
        one of its images (a few points in a small box).

        >>> import numpy as np, orbitri
        >>> tri = orbitri.PeriodicDelaunay(np.random.default_rng(5).random((100, 2)), [1.0, 1.0])
        >>> indptr, indices = tri.vertex_neighbor_vertices
        >>> sorted(indices[indptr[7]:indptr[8]].tolist()) == sorted(set(tri.vertex_neighbors(7)[0].tolist()))
        True
        """
        pairs = self.edges()[0]
        n = self.number_of_input_points
        # each ordered pair once, as one sortable key (sorted, then deduplicated: numpy
        # 2.4's np.unique takes 12 s where this takes 0.2)
        keys = np.sort(np.concatenate([pairs[:, 0] * n + pairs[:, 1], pairs[:, 1] * n + pairs[:, 0]]))
        keys = keys[np.concatenate([[True], keys[1:] != keys[:-1]])]
        rows, columns = np.divmod(keys, n)
        return _csr(rows, columns, n)

    def _describe(self) -> str:
        n = self.number_of_input_points
        sheets = self.sheets
        return f"{n} point{'s' * (n != 1)} in {self.dimension}D, {sheets} sheet{'s' * (sheets != 1)}"


class PeriodicDelaunay(_Delaunay):
    """The Delaunay triangulation of points in a periodic box (2D or 3D, from the points'
    shape), exact for every input.

    ``PeriodicDelaunay(points, box)`` takes a box as ``lattice_matrix`` does (or a ``Box``);
    ``PeriodicDelaunay(system)`` takes the points and the box of an ASE ``Atoms`` (its
    ``cell``; every axis must be periodic, ``pbc``, else a ``ValueError`` says which is
    not), an MDAnalysis ``Universe`` or ``AtomGroup`` (the current frame; its
    ``dimensions`` are lengths and angles) or freud's ``(box, points)``:

    >>> import ase.build, orbitri
    >>> atoms = ase.build.bulk("Cu", "fcc", a=3.6, cubic=True).repeat(3)
    >>> orbitri.PeriodicDelaunay(atoms)
    <orbitri.PeriodicDelaunay: 108 points in 3D, 1 sheet, box Box.from_matrix([[10.8, 0.0, 0.0], [0.0, 10.8, 0.0], [0.0, 0.0, 10.8]])>
    >>> atoms.pbc = [True, True, False]
    >>> orbitri.PeriodicDelaunay(atoms)
    Traceback (most recent call last):
    ...
    ValueError: the ASE Atoms are not periodic along z (pbc=[True, True, False]); orbitri triangulates periodic boxes: set atoms.pbc = True to make the cell periodic along every axis (a vacuum gap in the cell then stays between the images)

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
    simplex opposite each vertex, across the boundary of the box if need be), with
    ``mirrors`` and ``gluings`` for the way each pair is glued. They hold one simplex per
    simplex of the torus, also while the points are too few for a triangulation of the
    torus itself and it is stored in a covering space (``sheets > 1``): the torus's
    triangulation is then a Δ-complex (a simplex may be its own neighbour, and a point may
    be two of its vertices). The elements of ``locate``, ``edges``, ``vertex_neighbors``
    and ``gluings`` are offsets too.

    >>> import orbitri
    >>> tri = orbitri.PeriodicDelaunay([[0.1, 0.2], [0.6, 0.4], [0.3, 0.8], [0.8, 0.9]] * 10
    ...                                + [[0.05 * i, 0.5] for i in range(20)], [1.0, 1.0])
    >>> int(tri.duplicates[4]), tri.simplices.shape[1]
    (0, 3)
    >>> orbitri.PeriodicDelaunay([[0.1, 0.2, 0.0], [0.6, 0.7, 0.0]], [1.0, 1.0]).dimension
    2

    ``threads=N`` builds in parallel on N threads (and runs the construction's other
    steps on N threads); every N gives the same triangulation, stored the same, so every
    array is the same. The default, ``None``, inserts the points one at a time: it takes less
    memory, and two threads take 0.76-0.91x its time on two cores (see the README).

    Weighted points (atoms or grains of given radii): ``weights=`` (squared lengths) or
    ``radii=`` give the regular triangulation, whose ``voronoi()`` cells are the power
    (Laguerre, radical) cells; a point whose power cell is empty is ``hidden``:

    >>> tri = orbitri.PeriodicDelaunay([[0.1, 0.1], [0.6, 0.2], [0.62, 0.21], [0.3, 0.7]],
    ...                                [1.0, 1.0], radii=[0.1, 0.2, 0.0, 0.1])
    >>> tri.hidden.tolist(), round(float(tri.voronoi().volumes.sum()), 12)
    ([2], 1.0)
    """

    def __init__(self, points, box=None, weights=None, radii=None, threads=None):
        if box is None:
            points, box = _system(points)
        p = _points(points, _box(box)[1])
        w = _weights(weights, radii, len(p))
        super().__init__(_Triangulation(p, lattice_matrix(box, p.shape[1]), w, threads))

    def __repr__(self) -> str:
        return f"<orbitri.PeriodicDelaunay: {self._describe()}, box {Box(self.lattice)!r}>"

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

    def __init__(self, points, space: FlatManifold, threads=None):
        if not isinstance(space, FlatManifold):
            raise TypeError(
                f"space must be a FlatManifold or a KleinBottle, not {type(space).__name__} "
                f"(for a periodic box use PeriodicDelaunay)"
            )
        self.space = space
        super().__init__(
            _Triangulation.in_manifold(_points(points, space.dimension), space._space, threads)
        )

    def __repr__(self) -> str:
        return f"<orbitri.Triangulation: {self._describe()}, space {self.space!r}>"

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


def periodic_voronoi(points, box=None, weights=None, radii=None, threads=None) -> "Voronoi":
    """The periodic Voronoi cells of points in a box: ``PeriodicDelaunay(points,
    box).voronoi()``; ``periodic_voronoi(system)`` takes an ASE ``Atoms``, an MDAnalysis
    ``Universe`` or ``AtomGroup``, or freud's ``(box, points)``. With ``weights=`` or
    ``radii=``, the power (Laguerre) cells.

    >>> import numpy as np, orbitri
    >>> vor = orbitri.periodic_voronoi(np.random.default_rng(2).random((500, 2)), [1.0, 1.0])
    >>> len(vor), bool(abs(vor.volumes.sum() - 1.0) < 1e-12)
    (500, True)
    >>> import freud
    >>> box, points = freud.data.make_random_system(10, 200, seed=1)
    >>> round(float(orbitri.periodic_voronoi((box, points)).volumes.sum()), 6)
    1000.0
    """
    return PeriodicDelaunay(points, box, weights=weights, radii=radii, threads=threads).voronoi()


class Voronoi:
    """The periodic Voronoi cells of a triangulation's points (``tri.voronoi()``,
    ``periodic_voronoi``): per input point, in input order, ``volumes`` (areas in 2D),
    ``neighbor_counts`` (faces), ``surface_areas`` (perimeters in 2D) and ``centroids``; a
    duplicate shares its first occurrence's cell. ``neighbors()`` and ``neighbor_list()``
    give the faces, ``cells()`` the cells whole, ``to_dataframe()`` the table and ``plot()``
    a picture (2D).

    The measures are computed at once (about a third of the memory of the whole cells at
    10⁶ points); the neighbour pairs by the same pieces when asked for, and the cells on
    first use, from the same triangulation: once it has changed (an ``insert``, ``remove``
    or ``move``), they are a ``ValueError`` asking for a new ``voronoi()`` rather than the
    cells of another triangulation.

    >>> import numpy as np, orbitri
    >>> vor = orbitri.periodic_voronoi(np.random.default_rng(4).random((200, 2)), [1.0, 1.0])
    >>> vor
    <orbitri.Voronoi: 200 cells of 200 points in 2D, total area 1>
    """

    def __init__(self, core, tri: _Delaunay):
        self._v = core
        # the triangulation as it is now: a later insert does not change these measures
        self._points = tri.points
        self._first = tri.duplicates
        self._lattice = tri.lattice if isinstance(tri, PeriodicDelaunay) else None
        self._space = getattr(tri, "space", None)
        self.dimension = tri.dimension

    @property
    def volumes(self) -> np.ndarray:
        """Volume (area in 2D) of every input point's cell; a duplicate's is its first
        occurrence's, a removed point's NaN."""
        return self._v.volumes

    @property
    def neighbor_counts(self) -> np.ndarray:
        """Number of faces (neighbour images) of every input point's cell (−1 once
        removed)."""
        return self._v.neighbor_counts

    @property
    def surface_areas(self) -> np.ndarray:
        """Surface area (perimeter in 2D) of every input point's cell."""
        return self._v.surface_areas

    @property
    def centroids(self) -> np.ndarray:
        """Centroid of every input point's cell (N × D, Cartesian, near the point)."""
        return self._v.centroids

    def neighbors(self):
        """``(pairs E × 2, elements, face areas E)``: each pair of neighbouring images once;
        in a torus the elements are shifts (E × D) and ``j``'s image is ``points[j] + shift
        @ lattice``; in a manifold they are ``(cosets E, offsets E × D)``."""
        return self._v.neighbors()

    def cells(self) -> list:
        """Every distinct point's cell as a dict: ``id``, ``position``, ``volume``,
        ``centroid``, ``vertices`` (K × D, around the point) and ``faces`` (dicts of
        ``vertices``, ``neighbor``, ``shift`` in a torus or ``element`` ``(coset, offset)``
        in a manifold, and ``area``)."""
        return self._v.cells()

    def __len__(self) -> int:
        return len(self._v)

    def __repr__(self) -> str:
        measure = "area" if self.dimension == 2 else "volume"
        total = np.nansum(self.volumes[self._first == np.arange(len(self._first))])
        return (
            f"<orbitri.Voronoi: {len(self)} cells of {len(self._first)} points in {self.dimension}D, "
            f"total {measure} {total:.6g}>"
        )

    def neighbor_list(self, min_area=None, min_area_fraction=None) -> "NeighborList":
        """The Voronoi neighbours as a ``NeighborList``: each pair of neighbouring images
        once, with face areas, distances and vectors, per-point counts and CSR rows.

        By default every face is kept: the cells are exact, and a crystal whose coordinates
        were rounded (or rattled) has extra faces of area 1e-17 or less. ``min_area`` keeps
        the faces of at least that area; ``min_area_fraction`` those of at least that
        fraction of the surface area (perimeter in 2D) of both cells they bound.

        >>> import numpy as np, orbitri
        >>> basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]])
        >>> cells = np.array([[i, j, k] for i in range(3) for j in range(3) for k in range(3)])
        >>> fcc = ((cells[:, None] + basis).reshape(-1, 3) * 0.1).round(12)  # rounded, not exact
        >>> rattled = fcc + np.random.default_rng(0).normal(0, 1e-6, fcc.shape)
        >>> vor = orbitri.periodic_voronoi(rattled, [0.3, 0.3, 0.3])
        >>> int(vor.neighbor_counts.max()) > 12
        True
        >>> nl = vor.neighbor_list(min_area_fraction=1e-3)
        >>> sorted(set(nl.counts.tolist()))
        [12]
        """
        ij, elements, areas = self._v.neighbors()
        i, j = ij[:, 0], ij[:, 1]
        p = self._points
        if self._lattice is not None:
            images = p[j] + elements @ self._lattice
        else:
            a, t = self._space.isometry(*elements)
            images = np.einsum("eij,ej->ei", a, p[j]) + t
        keep = np.ones(len(areas), dtype=bool)
        if min_area is not None:
            keep &= areas >= float(min_area)
        if min_area_fraction is not None:
            s = self.surface_areas
            keep &= areas >= float(min_area_fraction) * np.maximum(s[i], s[j])
        if self._lattice is not None:
            elements = elements[keep]
        else:
            elements = (elements[0][keep], elements[1][keep])
        return NeighborList(i[keep], j[keep], elements, areas[keep], (images - p[i])[keep], self._first)

    def to_dataframe(self):
        """The per-point table as a ``pandas.DataFrame`` indexed by input id: ``volume``,
        ``neighbours``, ``surface_area``, ``centroid_x``, ``centroid_y`` (, ``centroid_z``)
        and ``duplicate_of`` (−1 for none), the command's CSV columns.

        >>> import numpy as np, orbitri
        >>> df = orbitri.periodic_voronoi(np.random.default_rng(1).random((50, 3)), [1, 1, 1]).to_dataframe()
        >>> list(df.columns), len(df)
        (['volume', 'neighbours', 'surface_area', 'centroid_x', 'centroid_y', 'centroid_z', 'duplicate_of'], 50)
        """
        pd = _pandas()
        n = len(self._first)
        first = self._first
        columns = {
            "volume": self.volumes,
            "neighbours": self.neighbor_counts,
            "surface_area": self.surface_areas,
        }
        for k in range(self.dimension):
            columns[f"centroid_{_AXES[k]}"] = self.centroids[:, k]
        columns["duplicate_of"] = np.where(first == np.arange(n), -1, first)
        return pd.DataFrame(columns, index=pd.RangeIndex(n, name="id"))

    def plot(self, ax=None, copies=False, cmap="viridis", colorbar=True, points=True):
        """Draws the 2D cells with matplotlib, coloured by area, over the domain's outline;
        returns the axes. ``copies=True`` adds the periodic copies around the domain (3 × 3;
        an odd integer ``k`` gives k × k; torus only), ``points`` the points.

        >>> import matplotlib
        >>> matplotlib.use("Agg")
        >>> import numpy as np, orbitri
        >>> vor = orbitri.periodic_voronoi(np.random.default_rng(3).random((60, 2)), [1.0, 1.0])
        >>> ax = vor.plot(copies=True)
        >>> len(ax.collections[0].get_paths())
        540
        """
        import matplotlib.pyplot as plt
        from matplotlib.collections import PolyCollection

        if self.dimension != 2:
            raise ValueError("plot draws 2D cells; for 3D cells write a .vtu with the command (orbitri voronoi … -o cells.vtu) and open it in ParaView")
        k = 3 if copies is True else int(copies or 1)
        if k < 1 or k % 2 == 0:
            raise ValueError(f"copies is True, False or an odd number of copies per direction, not {copies!r}")
        if k > 1 and self._lattice is None:
            raise ValueError("copies are drawn for a torus; a Klein bottle's cells are drawn once")
        cells = self.cells()
        polygons = [c["vertices"] for c in cells]
        areas = np.array([c["volume"] for c in cells])
        lattice = self._lattice if self._lattice is not None else self._space.translations
        shifts = [np.array([a, b]) @ lattice for a in range(-(k // 2), k // 2 + 1) for b in range(-(k // 2), k // 2 + 1)]
        if ax is None:
            ax = plt.figure().add_subplot()
        drawn = PolyCollection(
            [poly + s for s in shifts for poly in polygons],
            array=np.tile(areas, len(shifts)),
            cmap=cmap,
            edgecolors="k",
            linewidths=0.5,
        )
        ax.add_collection(drawn)
        if points:
            p = np.concatenate([self._points[[c["id"] for c in cells]] + s for s in shifts])
            ax.plot(p[:, 0], p[:, 1], ".", color="k", markersize=2)
        # the domain: the torus's cell, or the manifold's standard domain
        domain = lattice if self._lattice is not None else np.diag(self._space._sides)
        corners = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]]) @ domain
        ax.plot(corners[:, 0], corners[:, 1], color="r", linewidth=1.5)
        ax.set_aspect("equal")
        ax.autoscale_view()
        if colorbar:
            ax.figure.colorbar(drawn, ax=ax, label="area")
        return ax


def _pandas():
    try:
        import pandas
    except ImportError as e:  # pragma: no cover - pandas is a test dependency
        raise ImportError("to_dataframe needs pandas: pip install pandas") from e
    return pandas


class NeighborList:
    """Voronoi neighbours (``Voronoi.neighbor_list()``): each pair of neighbouring images
    once, in arrays of length E:

    * ``i``, ``j``: input ids (first occurrences);
    * ``shifts``: in a torus the lattice shifts (E × D) of ``j``'s image, ``points[j] +
      shift @ lattice``; in a manifold the elements ``(cosets, offsets)``;
    * ``areas``: the faces' areas (lengths in 2D);
    * ``vectors`` (E × D) from point ``i`` to ``j``'s image, and their lengths
      ``distances``.

    Per input point (N, input order; a duplicate as its first occurrence): ``counts``, the
    neighbour images of its cell (a pair of a point with its own image counts twice: both
    faces are its), and scipy's compressed sparse rows ``indptr``, ``indices``: the
    neighbours of ``k`` are ``indices[indptr[k]:indptr[k + 1]]``, once per face.
    ``to_freud()`` and ``to_dataframe()`` convert.

    >>> import numpy as np, orbitri
    >>> nl = orbitri.periodic_voronoi(np.random.default_rng(2).random((300, 3)), [1, 1, 1]).neighbor_list()
    >>> bool((nl.counts == np.diff(nl.indptr)).all()), bool(np.allclose(np.linalg.norm(nl.vectors, axis=1), nl.distances))
    (True, True)
    """

    def __init__(self, i, j, shifts, areas, vectors, first):
        self.i, self.j, self.shifts, self.areas = i, j, shifts, areas
        self.vectors = vectors
        self.distances = np.linalg.norm(vectors, axis=1)
        self._first = first
        n = len(first)
        # both directions, then each duplicate takes its first occurrence's row
        rows, columns = np.concatenate([i, j]), np.concatenate([j, i])
        by_first, to = _csr(rows, columns, n)
        source = np.where(first >= 0, first, np.arange(n))
        alive = first >= 0
        self.counts = np.where(alive, np.diff(by_first)[source], 0)
        self.indptr = np.zeros(n + 1, dtype=np.int64)
        np.cumsum(self.counts, out=self.indptr[1:])
        start = np.repeat(by_first[source] - self.indptr[:-1], self.counts)
        self.indices = to[start + np.arange(self.indptr[-1])]

    def __len__(self) -> int:
        return len(self.i)

    def __repr__(self) -> str:
        n = len(self.counts)
        return f"<orbitri.NeighborList: {len(self)} pairs of neighbouring images, {n} points, mean count {self.counts.mean() if n else 0:.4g}>"

    def to_freud(self):
        """A ``freud.locality.NeighborList`` with both directions of every pair (freud
        lists ``(i, j)`` and ``(j, i)``), vectors from the query point ``i`` to the
        neighbour's image and the face areas as weights, sorted by query point; 2D vectors
        get z = 0. Tori only (freud's boxes are tori).

        >>> import numpy as np, orbitri, freud
        >>> vor = orbitri.periodic_voronoi(np.random.default_rng(2).random((100, 3)), [1, 1, 1])
        >>> nl = vor.neighbor_list().to_freud()
        >>> len(nl) == int(vor.neighbor_counts.sum())
        True
        """
        import inspect

        import freud

        if isinstance(self.shifts, tuple):
            raise ValueError("freud's neighbour lists are for tori, and these neighbours are in a manifold")
        n = len(self._first)
        q = np.concatenate([self.i, self.j])
        p = np.concatenate([self.j, self.i])
        v = np.concatenate([self.vectors, -self.vectors])
        if v.shape[1] == 2:
            v = np.column_stack([v, np.zeros(len(v))])
        w = np.concatenate([self.areas, self.areas])
        order = np.lexsort((p, q))
        args = inspect.signature(freud.locality.NeighborList.from_arrays).parameters
        geometry = v[order] if "vectors" in args else np.linalg.norm(v[order], axis=1)
        return freud.locality.NeighborList.from_arrays(n, n, q[order], p[order], geometry, w[order])

    def to_dataframe(self):
        """The pairs as a ``pandas.DataFrame``: ``i``, ``j``, the shift's (or element's)
        columns, ``area``, ``distance`` and the vector's columns.

        >>> import numpy as np, orbitri
        >>> vor = orbitri.periodic_voronoi(np.random.default_rng(2).random((100, 2)), [1, 1])
        >>> list(vor.neighbor_list().to_dataframe().columns)
        ['i', 'j', 'shift_x', 'shift_y', 'area', 'distance', 'vector_x', 'vector_y']
        """
        pd = _pandas()
        d = self.vectors.shape[1]
        columns = {"i": self.i, "j": self.j}
        if isinstance(self.shifts, tuple):
            columns["coset"] = self.shifts[0]
            offsets = self.shifts[1]
            prefix = "offset"
        else:
            offsets, prefix = self.shifts, "shift"
        for k in range(d):
            columns[f"{prefix}_{_AXES[k]}"] = offsets[:, k]
        columns["area"] = self.areas
        columns["distance"] = self.distances
        for k in range(d):
            columns[f"vector_{_AXES[k]}"] = self.vectors[:, k]
        return pd.DataFrame(columns)
