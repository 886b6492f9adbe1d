"""The compiled core (Rust, PyO3). Use the classes of `orbitri`, not these directly."""

from typing import Any, SupportsIndex

import numpy as np
import numpy.typing as npt

__version__: str
PLATYCOSMS: list[str]

# A group element array: a torus's offsets (… × D), a manifold's (cosets …, offsets … × D).
_Elements = npt.NDArray[np.int32] | tuple[npt.NDArray[np.int32], npt.NDArray[np.int32]]

class Space:
    """A closed flat manifold: ``"klein"`` (sides [a, b]) or a platycosm ([L1, L2, L3])."""

    def __init__(self, name: str, sides: list[float]) -> None: ...
    @property
    def name(self) -> str: ...
    @property
    def dimension(self) -> int: ...
    @property
    def index(self) -> int: ...
    @property
    def volume(self) -> float: ...
    @property
    def is_orientable(self) -> bool: ...
    @property
    def systole(self) -> float: ...
    @property
    def translations(self) -> npt.NDArray[np.float64]: ...
    @property
    def generators(self) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    def isometries(
        self, cosets: npt.ArrayLike, offsets: npt.ArrayLike
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...

class Triangulation:
    def __init__(self, points: npt.ArrayLike, lattice: npt.ArrayLike) -> None: ...
    @staticmethod
    def in_manifold(points: npt.ArrayLike, space: Space) -> Triangulation: ...
    @property
    def dimension(self) -> int: ...
    @property
    def generation(self) -> int: ...
    @property
    def lattice(self) -> npt.NDArray[np.float64]: ...
    @property
    def points(self) -> npt.NDArray[np.float64]: ...
    def cells(
        self,
    ) -> tuple[npt.NDArray[np.int64], _Elements, npt.NDArray[np.int64]]: ...
    @property
    def sheets(self) -> int: ...
    @property
    def is_one_sheeted(self) -> bool: ...
    def is_valid(self) -> bool: ...
    def try_one_sheet(self) -> bool: ...
    @property
    def number_of_input_points(self) -> int: ...
    @property
    def duplicates(self) -> npt.NDArray[np.int64]: ...
    @property
    def number_of_duplicates(self) -> int: ...
    @property
    def number_of_wrapped(self) -> int: ...
    def insert(self, points: npt.ArrayLike) -> npt.NDArray[np.int64]: ...
    def locate(
        self, point: list[float]
    ) -> tuple[npt.NDArray[np.int64], _Elements, _Elements]: ...
    def edges(
        self,
    ) -> tuple[npt.NDArray[np.int64], _Elements, npt.NDArray[np.float64]]: ...
    def vertex_neighbors(
        self, i: SupportsIndex
    ) -> tuple[npt.NDArray[np.int64], _Elements]: ...
    def voronoi(self) -> Voronoi: ...

class Voronoi:
    """The periodic Voronoi cells of a triangulation."""

    @property
    def volumes(self) -> npt.NDArray[np.float64]:
        """Volume (area in 2D) of every input point's cell; a duplicate's is its first
        occurrence's."""
    @property
    def neighbor_counts(self) -> npt.NDArray[np.int64]:
        """Number of faces (neighbour images) of every input point's cell."""
    @property
    def surface_areas(self) -> npt.NDArray[np.float64]:
        """Surface area (perimeter in 2D) of every input point's cell."""
    @property
    def centroids(self) -> npt.NDArray[np.float64]:
        """Centroid of every input point's cell (N × D, near the point)."""
    def neighbors(
        self,
    ) -> tuple[npt.NDArray[np.int64], _Elements, npt.NDArray[np.float64]]:
        """(pairs E × 2, elements, face areas E): each pair of neighbouring images once;
        in a torus the elements are shifts (E × D) and ``j``'s image is ``points[j] + shift
        @ lattice``; in a manifold they are ``(cosets E, offsets E × D)``."""
    def cells(self) -> list[dict[str, Any]]:
        """Every distinct point's cell: ``id``, ``position``, ``volume``, ``centroid``,
        ``vertices`` (K × D) and ``faces`` (``vertices``, ``neighbor``, ``shift`` in a torus
        or ``element`` ``(coset, offset)`` in a manifold, ``area``)."""
    def __len__(self) -> int: ...
