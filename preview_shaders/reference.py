"""
The spectral reference of a preview
===================================

-   :func:`reference_table`: the spectral reference as a function of cos
    theta alone (one table per eta_i).
-   :func:`reference_image`: the spectral reference of a rendered view.
-   :func:`difference_maps`: Delta E 2000 and FLIP maps and means.
"""

from __future__ import annotations

import numpy as np

from fitting.colour.colorimetry import ACEScg_to_Lab
from fitting.colour.delta_e import delta_E_2000
from fitting.colour.reference import reference_ACEScg, reference_ACEScg_grid

from .display import ACEScg_to_sRGB

__all__ = ["REFERENCE_TABLE_SIZE", "REFERENCE_TABLE_TOLERANCE", "reference_table", "reference_image", "difference_maps"]

REFERENCE_TABLE_SIZE = 513
"""Nodes of the cos theta table of the spectral reference (uniform over [0, 1])."""
REFERENCE_TABLE_TOLERANCE = 1e-7
"""Largest error of the table (linear ACEScg) at the check points, below float32 rounding of 1."""


def reference_table(nk, eta_i, step_nm: float = 1.0, nodes: int = REFERENCE_TABLE_SIZE):
    """
    The spectral reference of ``nk`` under the coating ``eta_i`` as a
    function of cos theta alone, a callable ``table(cos_theta) -> (..., 3)``
    (linear ACEScg): a cubic spline (not-a-knot) through the exact values
    (:func:`fitting.colour.reference.reference_ACEScg_grid`) at ``nodes``
    cos theta uniform over [0, 1].

    On a smooth sphere the reference depends on the pixel only through cos
    theta, so one table serves every pixel and its cost does not grow with
    the image. The table checks itself: the exact values at the midpoints
    of its nodes must lie within :data:`REFERENCE_TABLE_TOLERANCE` of the
    spline (they do for every conductor; the error is fourth order in the
    node spacing). Where they do not, which happens for a lossless
    dielectric past its critical angle (a kink in cos theta), the callable
    integrates the exact reference at each distinct cos theta instead.
    """
    from scipy.interpolate import CubicSpline

    fine = np.linspace(0.0, 1.0, 2 * int(nodes) - 1)
    F = reference_ACEScg_grid(nk, fine, [float(eta_i)], step_nm)[0]
    spline = CubicSpline(fine[::2], F[::2], axis=0, extrapolate=False)
    if np.max(np.abs(spline(fine[1::2]) - F[1::2])) <= REFERENCE_TABLE_TOLERANCE:
        return spline

    def exact(cos_theta):
        mu = np.asarray(cos_theta, dtype=np.float64)
        unique, inverse = np.unique(mu, return_inverse=True)
        values = reference_ACEScg_grid(nk, unique, [float(eta_i)], step_nm)[0]
        return values[inverse.reshape(mu.shape)]

    return exact


def reference_image(nk, cos_theta, mask, radiance, eta_i, step_nm: float = 1.0, per_pixel: bool = False) -> np.ndarray:
    """
    The spectral reference of a rendered view: on the sphere, the exact
    reflectance of ``nk`` at each pixel's cos theta times the radiance the
    pixel sees; elsewhere the radiance. float32 linear ACEScg.

    The reflectance comes from :func:`reference_table` (one table per
    eta_i); ``per_pixel=True`` integrates the reference at every pixel
    instead (:func:`fitting.colour.reference.reference_ACEScg`), the
    definition the table is tested against.
    """
    image = np.array(radiance[..., :3], dtype=np.float64)
    mu = np.clip(cos_theta[mask].astype(np.float64), 0.0, 1.0)
    if per_pixel:
        F = reference_ACEScg(nk, mu, eta_i, step_nm)
    else:
        F = reference_table(nk, eta_i, step_nm)(mu)
    image[mask] = F * image[mask]
    return image.astype(np.float32)


def difference_maps(test, reference, mask):
    """
    Per-pixel Delta E 2000 (CIE Lab with the ACES white) and FLIP (LDR,
    flip-evaluator, on the display-encoded sRGB images) between two linear
    ACEScg images, and the mean of each over ``mask``.

    Returns
    -------
    tuple
        (delta_E map, delta_E mean, FLIP map, FLIP mean).
    """
    import flip_evaluator

    delta_E = delta_E_2000(ACEScg_to_Lab(test), ACEScg_to_Lab(reference)).astype(np.float32)
    flip, _, _ = flip_evaluator.evaluate(
        ACEScg_to_sRGB(reference).astype(np.float32),
        ACEScg_to_sRGB(test).astype(np.float32),
        "LDR",
        inputsRGB=True,
        applyMagma=False,
        computeMeanError=False,
    )
    flip = np.asarray(flip, dtype=np.float32).reshape(mask.shape)
    return delta_E, float(delta_E[mask].mean()), flip, float(flip[mask].mean())
