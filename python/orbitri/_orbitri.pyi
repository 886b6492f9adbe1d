"""The compiled core (Rust, PyO3). Use the classes of `orbitri`, not these directly."""

from typing import Any, SupportsIndex

import numpy as np
import numpy.typing as npt

__version__: str

class Triangulation:
    def __init__(self, points: npt.ArrayLike, lattice: npt.ArrayLike) -> None: ...
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
    ) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int32], npt.NDArray[np.int64]]: ...
    @property
    def sheets(self) -> int: ...
    @property
    def is_one_sheeted(self) -> bool: ...
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
    ) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int32], npt.NDArray[np.int32]]: ...
    def edges(
        self,
    ) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int32], npt.NDArray[np.float64]]: ...
    def vertex_neighbors(
        self, i: SupportsIndex
    ) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int32]]: ...
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
    ) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int32], npt.NDArray[np.float64]]:
        """(pairs E × 2, shifts E × D, face areas E): each pair of neighbouring images
        once; ``j``'s image is ``points[j] + shift @ lattice``."""
    def cells(self) -> list[dict[str, Any]]:
        """Every distinct point's cell: ``id``, ``position``, ``volume``, ``centroid``,
        ``vertices`` (K × D) and ``faces`` (``vertices``, ``neighbor``, ``shift``,
        ``area``)."""
    def __len__(self) -> int: ...
