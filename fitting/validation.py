"""
Input checks shared by the public functions of the fitting core: each raises
``ValueError`` naming the argument, the rule and the offending value.
"""

from __future__ import annotations

import numpy as np

__all__ = ["as_finite_array"]


def as_finite_array(name: str, values) -> np.ndarray:
    """``values`` as a float64 array; refuses non-numbers, NaN and infinity."""
    try:
        array = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"`{name}` must be numbers, got {values!r:.60}") from None
    if not np.all(np.isfinite(array)):
        bad = array[~np.isfinite(array)].ravel()[0]
        raise ValueError(f"`{name}` must be finite, got {bad}")
    return array
