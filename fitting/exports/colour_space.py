"""
Working space of the target tools
=================================

Linear Rec.709 primaries with the D65 white: MaterialX's default
``lin_rec709``, Blender's scene linear, glTF's linear sRGB. The project's
reference is linear ACEScg (ACES white); the two are related by the CAT02
adapted matrix, so that a perfect reflector is (1, 1, 1) in both.

-   :func:`ACEScg_to_lin_rec709`, :func:`lin_rec709_to_ACEScg`.
"""

from __future__ import annotations

import functools

import numpy as np

from ..colour.colorimetry import colour_science

__all__ = ["ACEScg_to_lin_rec709", "lin_rec709_to_ACEScg"]


@functools.cache
def _ACEScg_to_rec709() -> np.ndarray:
    colour = colour_science()
    M = colour.RGB_to_RGB(
        np.eye(3), "ACEScg", "ITU-R BT.709", chromatic_adaptation_transform="CAT02"
    ).T
    M.setflags(write=False)
    return M


def ACEScg_to_lin_rec709(RGB) -> np.ndarray:
    """Linear ACEScg (ACES white) to linear Rec.709 (D65), CAT02; white to white."""
    return np.asarray(RGB, dtype=np.float64) @ _ACEScg_to_rec709().T


def lin_rec709_to_ACEScg(RGB) -> np.ndarray:
    """Inverse of :func:`ACEScg_to_lin_rec709`."""
    return np.asarray(RGB, dtype=np.float64) @ np.linalg.inv(_ACEScg_to_rec709()).T
