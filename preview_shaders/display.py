"""
Display transform
=================

Linear ACEScg to 8-bit sRGB for the preview PNGs, and false-colour maps.

The transform: linear ACEScg (AP1 primaries, ACES white ~D60) to linear
sRGB (BT.709 primaries, D65) by the 3 x 3 matrix colour-science gives for
``matrix_RGB_to_RGB(ACEScg, sRGB, chromatic_adaptation_transform="CAT02")``;
then clipping to [0, 1] (no tone mapping: a reflectance under a white sky of
radiance 1 is already in [0, 1]; gold's saturated ACEScg colours fall
slightly outside sRGB and clip); then the sRGB encoding of IEC 61966-2-1
(linear below 0.0031308, else 1.055 x^(1/2.4) - 0.055); then rounding to
8 bits.

-   :func:`ACEScg_to_sRGB_matrix`: the 3 x 3 matrix above.
-   :func:`ACEScg_to_sRGB`: linear ACEScg to encoded sRGB in [0, 1].
-   :func:`to_uint8`, :func:`encode_png`: 8-bit image and PNG bytes.
-   :func:`false_colour`: a scalar map through a matplotlib colour map.
"""

from __future__ import annotations

import functools
import io

import numpy as np
from PIL import Image

__all__ = [
    "ACEScg_to_sRGB_matrix",
    "ACEScg_to_sRGB",
    "to_uint8",
    "encode_png",
    "false_colour",
]


@functools.cache
def ACEScg_to_sRGB_matrix() -> np.ndarray:
    """Linear ACEScg to linear sRGB, CAT02 from the ACES white to D65."""
    from fitting.colour.colorimetry import colour_science

    colour = colour_science()
    M = colour.matrix_RGB_to_RGB(
        colour.RGB_COLOURSPACES["ACEScg"],
        colour.RGB_COLOURSPACES["sRGB"],
        chromatic_adaptation_transform="CAT02",
    )
    M = np.array(M, dtype=np.float64)
    M.setflags(write=False)
    return M


def ACEScg_to_sRGB(RGB) -> np.ndarray:
    """
    Linear ACEScg to sRGB-encoded values in [0, 1] (see the module docstring).
    """
    linear = np.asarray(RGB, dtype=np.float64) @ ACEScg_to_sRGB_matrix().T
    linear = np.clip(linear, 0.0, 1.0)
    return np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * np.power(linear, 1.0 / 2.4) - 0.055)


def to_uint8(encoded) -> np.ndarray:
    """Encoded values in [0, 1] to 8 bits, rounded to nearest."""
    return np.round(np.clip(np.asarray(encoded), 0.0, 1.0) * 255.0).astype(np.uint8)


def encode_png(image_uint8: np.ndarray) -> bytes:
    """PNG bytes of an (H, W, 3) uint8 image stored top row first."""
    buffer = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(image_uint8), mode="RGB").save(buffer, format="PNG")
    return buffer.getvalue()


def false_colour(values, vmax: float, cmap: str = "magma") -> np.ndarray:
    """(H, W) values on [0, vmax] as an (H, W, 3) uint8 image of ``cmap``."""
    from matplotlib import colormaps

    scaled = np.clip(np.asarray(values, dtype=np.float64) / vmax, 0.0, 1.0)
    return to_uint8(colormaps[cmap](scaled)[..., :3])
