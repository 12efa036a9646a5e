"""
Working space of the target tools
=================================

Linear Rec.709 primaries with the D65 white: MaterialX's default
``lin_rec709``, Blender's scene linear, glTF's linear sRGB. The project's
reference is linear ACEScg (ACES white); the two are related by the CAT02
adapted matrix, so that a perfect reflector is (1, 1, 1) in both.

An export is fitted and written in one *working space*
(:data:`WORKING_SPACES`): ``lin_rec709`` (the default of glTF and Blender)
or ``acescg`` (linear ACEScg, AP1 primaries: Blender's "ACEScg" working
space, MaterialX's ``acescg``). The names are MaterialX's colour space names.

-   :data:`WORKING_SPACES`, :data:`DEFAULT_WORKING_SPACE`, :func:`check_working_space`.
-   :func:`ACEScg_to_lin_rec709`, :func:`lin_rec709_to_ACEScg`.
-   :func:`ACEScg_to_working`, :func:`working_to_ACEScg`: the same for any working space.
"""

from __future__ import annotations

import functools

import numpy as np

from ..colour.colorimetry import colour_science
from ..domain import DEFAULT_WORKING_SPACE, WORKING_SPACES

__all__ = [
    "WORKING_SPACES",
    "DEFAULT_WORKING_SPACE",
    "check_working_space",
    "ACEScg_to_lin_rec709",
    "lin_rec709_to_ACEScg",
    "ACEScg_to_working",
    "working_to_ACEScg",
]


def check_working_space(working_space) -> str:
    """``working_space`` if one of :data:`WORKING_SPACES`, else ``ValueError`` naming the rule."""
    if working_space not in WORKING_SPACES:
        raise ValueError(f"`working_space` must be one of {', '.join(WORKING_SPACES)}, got {working_space!r}")
    return working_space


@functools.cache
def _ACEScg_to_rec709() -> np.ndarray:
    colour = colour_science()
    M = colour.RGB_to_RGB(np.eye(3), "ACEScg", "ITU-R BT.709", chromatic_adaptation_transform="CAT02").T
    M.setflags(write=False)
    return M


def ACEScg_to_lin_rec709(RGB) -> np.ndarray:
    """Linear ACEScg (ACES white) to linear Rec.709 (D65), CAT02; white to white."""
    return np.asarray(RGB, dtype=np.float64) @ _ACEScg_to_rec709().T


def lin_rec709_to_ACEScg(RGB) -> np.ndarray:
    """Inverse of :func:`ACEScg_to_lin_rec709`."""
    return np.asarray(RGB, dtype=np.float64) @ np.linalg.inv(_ACEScg_to_rec709()).T


def ACEScg_to_working(RGB, working_space: str) -> np.ndarray:
    """Linear ACEScg to ``working_space`` (:data:`WORKING_SPACES`); ACEScg itself is returned as is."""
    if check_working_space(working_space) == "acescg":
        return np.asarray(RGB, dtype=np.float64)
    return ACEScg_to_lin_rec709(RGB)


def working_to_ACEScg(RGB, working_space: str) -> np.ndarray:
    """Inverse of :func:`ACEScg_to_working`."""
    if check_working_space(working_space) == "acescg":
        return np.asarray(RGB, dtype=np.float64)
    return lin_rec709_to_ACEScg(RGB)
