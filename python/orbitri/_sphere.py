"""The sphere and the projective plane: ``SphericalDelaunay``, ``ProjectivePlane`` and
their ``SphericalVoronoi`` cells."""

from __future__ import annotations

import numpy as np

from ._orbitri import SphericalTriangulation as _SphericalTriangulation


def _lonlat_of(points: np.ndarray) -> np.ndarray:
    lon = np.degrees(np.arctan2(points[:, 1], points[:, 0]))
    lat = np.degrees(np.arctan2(points[:, 2], np.hypot(points[:, 0], points[:, 1])))
    return np.column_stack([lon, lat])


class SphericalDelaunay:
    """The exact Delaunay triangulation of points on the unit sphere: the faces of their
    convex hull that have the centre strictly inside, as CGAL's
    ``Delaunay_triangulation_on_sphere_2`` and Qhull (``scipy.spatial.ConvexHull``) give
    them, with four points on one circle decided by a symbolic perturbation (the same
    whatever the insertion order).

    Give ``points`` as unit vectors (N × 3, each to within 1e-6 of norm 1; set
    ``normalize=True`` to project any non-zero vectors), or ``lonlat`` as longitudes and
    latitudes in degrees (N × 2). A point met again is a duplicate of its first occurrence;
    a point strictly inside the hull of the others (only possible off the sphere by
    rounding) is ``hidden``; none is lost. ``threads=N`` builds in parallel on N
    threads, with the same result for every N (default: one point at a time).

    >>> import numpy as np, orbitri
    >>> p = np.random.default_rng(2).normal(size=(1000, 3))
    >>> tri = orbitri.SphericalDelaunay(p / np.linalg.norm(p, axis=1)[:, None])
    >>> tri.simplices.shape, tri.dimension
    ((1996, 3), 2)
    >>> vor = tri.voronoi()
    >>> bool(abs(vor.areas.sum() - 4 * np.pi) < 1e-12)
    True
    >>> grid = orbitri.SphericalDelaunay(lonlat=[[lon, lat] for lon in range(0, 360, 30)
    ...                                          for lat in (-90, -45, 0, 45, 90)])
    >>> grid.number_of_vertices, int((grid.duplicates != np.arange(60)).sum())
    (38, 22)
    """

    _projective = False

    def __init__(self, points=None, lonlat=None, normalize: bool = False, threads=None):
        if (points is None) == (lonlat is None):
            raise TypeError("give either points (N × 3) or lonlat (N × 2)")
        if lonlat is not None:
            self._tri = _SphericalTriangulation(
                np.asarray(lonlat, dtype=float),
                lonlat=True,
                projective=self._projective,
                threads=threads,
            )
        else:
            p = np.asarray(points, dtype=float)
            if normalize:
                p = self._normalized(p)
            self._tri = _SphericalTriangulation(p, projective=self._projective, threads=threads)
        self._faces = None

    @staticmethod
    def _normalized(p: np.ndarray) -> np.ndarray:
        if p.ndim != 2 or p.shape[1] != 3:
            raise ValueError(f"expected an array of shape (N, 3), got {p.shape}")
        norm = np.linalg.norm(p, axis=1)
        bad = np.flatnonzero(~(np.isfinite(norm) & (norm > 0)))
        if len(bad):
            raise ValueError(f"point {bad[0]}: {p[bad[0]]} cannot be normalized")
        return p / norm[:, None]

    def _arrays(self):
        generation = self._tri.generation
        cached = self._faces
        if cached is None or cached[0] != generation:
            cached = (generation, self._tri.faces())
            self._faces = cached
        return cached[1]

    def __repr__(self) -> str:
        return (
            f"<orbitri.{type(self).__name__}: {self.number_of_vertices} vertices, "
            f"{len(self.simplices)} faces, dimension {self.dimension}>"
        )

    @property
    def simplices(self) -> np.ndarray:
        """Input ids of every face's vertices (F × 3), counter-clockwise seen from outside.
        Empty below dimension 2."""
        return self._arrays()[0]

    @property
    def neighbors(self) -> np.ndarray:
        """The face across each edge (F × 3): ``neighbors[f, k]`` is opposite vertex ``k``.
        For points in a closed hemisphere (``covers_sphere`` false) the rim's faces border
        ghost faces: an index ``g ≥ F`` is ``ghost_simplices[g − F]``."""
        faces = self._arrays()
        return faces[1][: len(faces[0])]

    @property
    def ghost_simplices(self) -> np.ndarray:
        """CGAL's ghost faces (G × 3; none when the points enclose the centre): for points
        in a closed hemisphere, the faces of their convex hull that do not hold the centre
        strictly inside, counter-clockwise seen from outside the hull. With ``simplices``
        they close up into the whole hull; the Voronoi cells pass through their poles."""
        return self._arrays()[3]

    @property
    def ghost_neighbors(self) -> np.ndarray:
        """The face across each edge of each ghost face (G × 3), numbered as in
        ``neighbors``: below F a face, from F on a ghost face."""
        faces = self._arrays()
        return faces[1][len(faces[0]) :]

    @property
    def signs(self) -> np.ndarray:
        """Each face vertex's sign (F × 3): −1 where the face uses the antipode of the
        stored point (only on the projective plane, at most one per face), so that
        ``signs[..., None] * points[simplices]`` is the face counter-clockwise from
        outside."""
        return self._arrays()[2]

    @property
    def points(self) -> np.ndarray:
        """The points as stored (N × 3, input order; NaN rows for removed ones; on the
        projective plane the representative of ``±p`` whose last non-zero coordinate, in
        the order z, y, x, is positive)."""
        return self._tri.points

    @property
    def lonlat(self) -> np.ndarray:
        """The points' longitudes and latitudes in degrees (N × 2)."""
        return _lonlat_of(self.points)

    @property
    def dimension(self) -> int:
        """CGAL's dimension: −2 without points, −1 with one, 0 with two, 1 when all lie on one
        circle (one plane), else 2."""
        return self._tri.dimension

    @property
    def covers_sphere(self) -> bool:
        """True when the points enclose the centre: the faces then cover the sphere. False
        for points in one closed hemisphere, whose faces cover the part where the hull turns
        its outer side away from the centre (CGAL's solid faces)."""
        return self._tri.covers_sphere

    @property
    def hidden(self) -> np.ndarray:
        """The hidden input ids, sorted: points strictly inside the hull of the others."""
        return self._tri.hidden

    @property
    def duplicates(self) -> np.ndarray:
        """Per input, the input id of its first occurrence (itself unless a duplicate; −1
        once removed)."""
        return self._tri.duplicates

    @property
    def number_of_vertices(self) -> int:
        """Distinct points that are vertices (not hidden)."""
        return self._tri.number_of_vertices

    @property
    def number_of_input_points(self) -> int:
        return len(self.duplicates)

    def insert(self, points=None, lonlat=None) -> np.ndarray:
        """Inserts more points, all or nothing; their input ids continue the numbering.
        Returns per point its first occurrence's id (its own when new), −1 when hidden."""
        if (points is None) == (lonlat is None):
            raise TypeError("give either points (N × 3) or lonlat (N × 2)")
        if lonlat is not None:
            return self._tri.insert(np.atleast_2d(np.asarray(lonlat, dtype=float)), lonlat=True)
        return self._tri.insert(np.atleast_2d(np.asarray(points, dtype=float)))

    def remove(self, ids) -> None:
        """Removes input ids (one or several), all or nothing; the others keep theirs, and
        hidden points a removal uncovers become vertices."""
        self._tri.remove(ids)

    def locate(self, point):
        """The face (input ids) whose cone from the centre holds the direction ``point``,
        or None outside the faces."""
        f = self._tri.locate([float(x) for x in point])
        return None if f is None else np.array(f)

    def vertex_neighbors(self, i: int) -> np.ndarray:
        """The Delaunay neighbours of input ``i``, sorted."""
        return self._tri.vertex_neighbors(i)

    def is_valid(self) -> bool:
        """Checks the triangulation exactly (orientation, empty circles, Euler
        characteristic); raises ValueError naming the first problem."""
        return self._tri.is_valid()

    def voronoi(self) -> "SphericalVoronoi":
        """The Voronoi cells (points that enclose the centre; ValueError otherwise)."""
        return SphericalVoronoi(self._tri.voronoi(), self)


class ProjectivePlane(SphericalDelaunay):
    """The exact Delaunay triangulation of the real projective plane RP² = S²/{±1}: the
    triangulation of the points and their antipodes on the sphere, each pair one point. It
    is computed in the 2-sheeted covering sphere until Caroli's criterion (every empty
    circle of angular diameter below π/2) lets it switch to RP² itself.

    Points and options as for ``SphericalDelaunay``; ``p`` and ``-p`` are one point (the
    second a duplicate). Faces are ``simplices`` with ``signs``: the face's vertices are
    ``signs * points[simplices]`` (RP² is not orientable: a face is oriented in its own
    frame). The Voronoi cells are those around each stored representative; their areas sum
    to 2π.

    >>> import numpy as np, orbitri
    >>> p = np.random.default_rng(3).normal(size=(500, 3))
    >>> rp2 = orbitri.ProjectivePlane(p / np.linalg.norm(p, axis=1)[:, None])
    >>> len(rp2.simplices), rp2.dimension      # Euler characteristic 1: F = 2V − 2
    (998, 2)
    >>> bool(abs(rp2.voronoi().areas.sum() - 2 * np.pi) < 1e-12)
    True
    """

    _projective = True


class SphericalVoronoi:
    """The Voronoi cells on the sphere (or RP²), per input point in input order: ``areas``
    (steradians, summing to 4π; 2π on RP²), ``neighbor_counts``, ``perimeters`` (radians) and
    ``centroids`` (unit vectors); a duplicate shares its first occurrence's cell, a hidden
    point's is empty. ``vertices`` and ``regions`` are in the shape of
    ``scipy.spatial.SphericalVoronoi`` (regions counter-clockwise seen from outside);
    ``cells()`` gives each cell whole with its neighbours across each arc."""

    def __init__(self, core, tri: SphericalDelaunay):
        self._v = core
        self.areas, self.neighbor_counts, self.perimeters, self.centroids = core.measures()
        self._regions = None
        self._duplicates = tri.duplicates

    def _shape(self):
        if self._regions is None:
            self._regions = self._v.regions()
        return self._regions

    @property
    def vertices(self) -> np.ndarray:
        """The distinct Voronoi vertices (V × 3, unit vectors)."""
        return self._shape()[0]

    @property
    def regions(self) -> list:
        """Per input, the indices into ``vertices`` of its cell, counter-clockwise."""
        return self._shape()[1]

    def calculate_areas(self) -> np.ndarray:
        """``areas``, under scipy's name."""
        return self.areas

    def cells(self) -> list:
        """Every distinct vertex's cell as a dict: ``id``, ``area``, ``centroid``,
        ``vertices`` (K × 3, counter-clockwise), ``neighbors`` (K: the site across the arc
        from vertex k to k + 1) and ``arc_lengths``."""
        return self._v.cells()

    def to_dataframe(self):
        """The per-point table as a pandas DataFrame (pandas required)."""
        import pandas as pd

        dup = self._duplicates
        return pd.DataFrame(
            {
                "area": self.areas,
                "neighbours": self.neighbor_counts,
                "perimeter": self.perimeters,
                "centroid_x": self.centroids[:, 0],
                "centroid_y": self.centroids[:, 1],
                "centroid_z": self.centroids[:, 2],
                "duplicate_of": np.where(dup == np.arange(len(dup)), -1, dup),
            }
        )

    def __len__(self) -> int:
        return len(self._v)

    def __repr__(self) -> str:
        return f"<orbitri.SphericalVoronoi: {len(self)} cells, total area {np.nansum(self.areas):.12g}>"
