"""
Exact RGB conductor Fresnel
===========================

The "exact" Fresnel term as RGB renderers usually run it: the Fresnel
equations of a conductor evaluated once per RGB channel with one complex
index :math:`n_c + i k_c` per channel (Gulbrandsen 2014 and the
``conductor`` materials of RGB renderers). It is exact for a material whose
index does not vary within a channel, and is the yardstick the speed against
error report (``docs/speed-vs-error.md``) compares the model with. The GLSL
mirror is ``cf_fresnel_conductor`` in
``preview_shaders/glsl/cf_fresnel_baselines.glsl`` (shader variant ``exact``),
fed with the per-channel index of the fit below.

How the per-channel index is chosen from measured data is a fit:
:func:`fitting.fits.rgb_conductor.rgb_nk`.

-   :func:`rgb_fresnel_conductor`: the exact Fresnel equations per channel,
    linear ACEScg.

References
----------
Gulbrandsen, O. (2014). Artist friendly metallic Fresnel. JCGT, 3(4), 64-72.
Hoffman, N. (2019). Fresnel Equations Considered Harmful. MAM workshop.
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics.
"""

from __future__ import annotations

import numpy as np

from ..optics.fresnel import fresnel_conductor

__all__ = ["rgb_fresnel_conductor"]


def rgb_fresnel_conductor(cos_theta, eta_i, n_rgb, k_rgb) -> np.ndarray:
    """
    Exact Fresnel reflectance per RGB channel.

    Parameters
    ----------
    cos_theta
        :math:`\\mu` in the coating, [0, 1] (clamped).
    eta_i
        Real index of the coating, >= 1, broadcast against ``cos_theta``.
    n_rgb, k_rgb
        Per-channel index, shape (3,) each (see :func:`fitting.fits.rgb_conductor.rgb_nk`).

    Returns
    -------
    numpy.ndarray
        ``broadcast(cos_theta, eta_i).shape + (3,)``, linear ACEScg in [0, 1];
        never NaN (see :func:`fitting.optics.fresnel.fresnel_conductor`).
    """
    n_rgb = np.asarray(n_rgb, dtype=np.float64)
    k_rgb = np.asarray(k_rgb, dtype=np.float64)
    if n_rgb.shape != (3,) or k_rgb.shape != (3,):
        raise ValueError(
            f"`n_rgb` and `k_rgb` must have shape (3,), got {n_rgb.shape} and {k_rgb.shape}"
        )
    if not (np.all(np.isfinite(n_rgb)) and np.all(n_rgb > 0)):
        raise ValueError(f"`n_rgb` must be finite and > 0, got {n_rgb.tolist()}")
    if not (np.all(np.isfinite(k_rgb)) and np.all(k_rgb >= 0)):
        raise ValueError(f"`k_rgb` must be finite and >= 0, got {k_rgb.tolist()}")
    mu, eta = np.broadcast_arrays(
        np.asarray(cos_theta, dtype=np.float64), np.asarray(eta_i, dtype=np.float64)
    )
    return fresnel_conductor(mu[..., None], eta[..., None], n_rgb, k_rgb)
