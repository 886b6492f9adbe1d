"""Helpers shared by the tests (not collected: no `test_` prefix)."""

import numpy as np


def canonical(simplices, offsets):
    """The simplices as a set, each a sorted tuple of (vertex, *offset) translated to a
    componentwise minimum offset of zero: equal for the same triangulation whatever the
    order of the cells and of the vertices within each."""
    o = offsets - offsets.min(axis=1, keepdims=True)
    rows = np.concatenate([simplices[:, :, None], o], axis=2).tolist()
    return {tuple(sorted(map(tuple, r))) for r in rows}
