"""Sorted distinct values of a float array, as :func:`numpy.unique` gives them for arrays without NaN,
without :func:`numpy.unique`'s import of :mod:`numpy.ma` (~20 ms of every command's start; docs/decisions.md
"Lazy imports")."""
from __future__ import annotations

import numpy as np

__all__ = ["sorted_unique"]


def sorted_unique(values) -> np.ndarray:
    """The distinct values of ``values`` (flattened), increasing — ``np.unique(values)`` for NaN-free input
    (a NaN is kept once per occurrence here)."""
    a = np.sort(np.asarray(values).ravel())
    keep = np.empty(a.shape, dtype=bool)
    keep[:1] = True
    np.not_equal(a[1:], a[:-1], out=keep[1:])
    return a[keep]
