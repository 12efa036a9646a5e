"""
numpy's :func:`numpy.unique`, :func:`numpy.union1d` and :func:`numpy.median`
of plain arrays without NaN, in numpy alone. numpy's own (2.3 on) ask
``numpy.ma`` whether their argument is masked, which imports ``numpy.ma``:
about 15 ms of every start of the command line that fits a material.
"""

from __future__ import annotations

import numpy as np

__all__ = ["median", "union", "unique"]


def unique(values) -> np.ndarray:
    """
    The distinct ``values`` (flattened), sorted: :func:`numpy.unique` of
    values without NaN (NaN is never equal to itself, so each NaN would be
    kept; :func:`numpy.unique` keeps one).
    """
    ordered = np.sort(np.ravel(np.asarray(values)))
    if ordered.size < 2:
        return ordered
    keep = np.empty(ordered.size, dtype=bool)
    keep[0] = True
    np.not_equal(ordered[1:], ordered[:-1], out=keep[1:])
    return ordered[keep]


def union(a, b) -> np.ndarray:
    """The distinct values of ``a`` and ``b`` (flattened), sorted: :func:`numpy.union1d` without NaN."""
    return unique(np.concatenate((np.ravel(a), np.ravel(b))))


def median(values) -> float:
    """The median of ``values`` (flattened, at least one, without NaN): :func:`numpy.median`."""
    ordered = np.sort(np.ravel(np.asarray(values, dtype=np.float64)))
    if ordered.size == 0:
        raise ValueError("`values` must hold at least one value")
    middle = ordered.size // 2
    return float(ordered[middle] if ordered.size % 2 else (ordered[middle - 1] + ordered[middle]) / 2.0)
