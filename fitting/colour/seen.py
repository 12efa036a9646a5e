"""
The coated metal as seen from air
=================================

What a viewer in air sees of a conductor under a clear coat: the physical
stack of :func:`fitting.optics.coated_stack.coated_stack` (the coat's
reflection, refraction into the coat, the metal's exact Fresnel at the
refracted angle, the incoherent sum of the bounces between the interfaces,
both polarisations) per wavelength, integrated to linear ACEScg with the
same weights as the spectral reference (:mod:`fitting.colour.reference`).
This is the target every export is fitted to (:mod:`fitting.exports.values`):
the tools evaluate their base at the view angle in air under a coat that
scales it, so what they must reproduce is this curve over the view angle.

-   :data:`SEEN_ANGLES_DEG`: the view angles the exports are fitted and
    scored on, 0 to 83 degrees in steps of 1.
-   :func:`seen_ACEScg`: the stack of measured n, k at any (cos theta in air,
    eta_i), linear ACEScg.

With eta_i = 1 it is :func:`fitting.colour.reference.reference_ACEScg` at
eta_i 1 (the bare metal in air), to rounding.
"""

from __future__ import annotations

import numpy as np

from ..domain import DEFAULT_MIN_COVERAGE
from ..optics.coated_stack import coated_stack
from ..optics.nk import SpectralNK
from .reference import spectral_integral

__all__ = ["SEEN_ANGLES_DEG", "seen_ACEScg"]

SEEN_ANGLES_DEG = np.arange(0.0, 84.0, 1.0)
"""View angles in air (degrees), 0 to 83: where a user sees a coated ball."""
SEEN_ANGLES_DEG.setflags(write=False)


def seen_ACEScg(
    nk: SpectralNK,
    cos_theta,
    eta_i,
    step_nm: float = 1.0,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
) -> np.ndarray:
    """
    Reflectance of air / coat ``eta_i`` / ``nk`` seen from air, linear ACEScg.

    Parameters
    ----------
    nk
        Spectral optical constants of the conductor.
    cos_theta
        mu of the view direction **in air**, [0, 1].
    eta_i
        Real index of the coat, >= 1, broadcast against ``cos_theta``.
    step_nm, min_coverage
        As :func:`fitting.colour.reference.reference_ACEScg`.

    Returns
    -------
    numpy.ndarray
        Shape ``broadcast(cos_theta, eta_i).shape + (3,)``.
    """
    return spectral_integral(coated_stack, nk, cos_theta, eta_i, step_nm, min_coverage)
