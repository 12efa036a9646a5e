"""
Fresnel terms of the target tools
=================================

The base-layer Fresnel of each export as its tool evaluates it, in numpy, so
that the loss of each export can be measured against the spectral reference
(:func:`export_fidelity`). All take :math:`\\mu = \\cos\\theta` at the metal,
clamp it to [0, 1] as the tools do, and return linear RGB in the tool's
working space (here linear Rec.709).

-   :func:`mx_fresnel_conductor`: MaterialX ``conductor_bsdf`` and Blender's
    Metallic BSDF in Physical Conductor mode: the exact unpolarised Fresnel
    equations of a conductor of index ``n + i k`` seen from a medium of index 1
    (Lagarde's closed form, as ``mx_fresnel_conductor`` in MaterialX's
    ``mx_microfacet_specular.glsl``), so an export carries the relative index.
-   :func:`f82_tint`: the F82-tint model of OpenPBR's metal and Blender's
    Principled BSDF (Hoffman 2023, as ``mx_fresnel_hoffman_schlick``).
-   :func:`schlick`: Schlick's approximation (glTF's metallic base).
-   :data:`TOOL_MODELS`: the model each export format is evaluated with.
-   :func:`tool_curve`, :func:`export_fidelity`.

The coat is modelled by none of these tools as a change of the metal's
Fresnel: MaterialX ``layer``, OpenPBR's coat, Blender's Principled coat and
glTF's ``KHR_materials_clearcoat`` scale the base by what the coat lets
through and leave its Fresnel as given. That is why every export carries
values fitted to the curve *under* the coat, and why the fidelity compares
the base Fresnel with the reference at the same cos theta in the coating.

References
----------
Lagarde, S. (2013). Memo on Fresnel equations (conductor, closed form).
Hoffman, N. (2023). Generalization of Adobe's Fresnel Model.
Schlick, C. (1994). An Inexpensive BRDF Model for Physically-based Rendering.
"""

from __future__ import annotations

import numpy as np

from ..colour.delta_e import delta_E_map
from .colour_space import working_to_ACEScg

__all__ = [
    "F82_COS_THETA",
    "TOOL_MODELS",
    "mx_fresnel_conductor",
    "f82_tint",
    "schlick",
    "tool_curve",
    "export_fidelity",
]

F82_COS_THETA = 1.0 / 7.0
"""cos theta of the F82-tint model's anchor (theta ~ 82 degrees)."""

TOOL_MODELS = {
    "mtlx": "conductor",
    "blender-conductor": "conductor",
    "openpbr": "f82-tint",
    "blender": "f82-tint",
    "gltf": "schlick",
}
"""Export (and Blender output) -> the Fresnel model its tool evaluates."""


def mx_fresnel_conductor(cos_theta, n, k) -> np.ndarray:
    """
    Exact unpolarised Fresnel reflectance of a conductor ``n + i k`` in air.

    With :math:`c = \\mu^2`, :math:`s = 1 - c`, :math:`t_0 = n^2 - k^2 - s`,
    :math:`a^2 + b^2 = \\sqrt{t_0^2 + 4 n^2 k^2}`,
    :math:`a = \\sqrt{(a^2 + b^2 + t_0)/2}`:

    .. math::

        R_s = \\frac{a^2 + b^2 + c - 2 a \\mu}{a^2 + b^2 + c + 2 a \\mu},\\quad
        R_p = R_s \\frac{c (a^2 + b^2) + s^2 - 2 a \\mu s}{c (a^2 + b^2) + s^2 + 2 a \\mu s},
        \\quad R = (R_s + R_p) / 2.

    Parameters
    ----------
    cos_theta
        mu, shape (S,); clamped to [0, 1].
    n, k
        Per-channel index, shape (3,), n > 0, k >= 0.

    Returns
    -------
    numpy.ndarray
        (S, 3) reflectance in [0, 1]; 1 at grazing incidence.
    """
    mu = np.clip(np.asarray(cos_theta, dtype=np.float64), 0.0, 1.0)[:, None]
    n, k = np.asarray(n, dtype=np.float64), np.asarray(k, dtype=np.float64)
    c = mu * mu
    s = 1.0 - c
    t0 = n * n - k * k - s
    a2b2 = np.sqrt(t0 * t0 + 4.0 * n * n * k * k)
    # max(.., 0): rounding can make (a2b2 + t0) a hair negative when k = 0, n < 1.
    a = np.sqrt(np.maximum(0.5 * (a2b2 + t0), 0.0))
    t1 = a2b2 + c
    t2 = 2.0 * a * mu
    Rs = (t1 - t2) / (t1 + t2)
    t3 = c * a2b2 + s * s
    t4 = t2 * s
    Rp = Rs * (t3 - t4) / (t3 + t4)
    return np.clip(0.5 * (Rs + Rp), 0.0, 1.0)


def schlick(cos_theta, F0) -> np.ndarray:
    """
    Schlick's approximation :math:`F_0 + (1 - F_0)(1 - \\mu)^5`.

    An F0 of shape (3,) gives ``cos_theta.shape + (3,)``; a scalar F0 gives
    ``cos_theta.shape``.
    """
    mu = np.clip(np.asarray(cos_theta, dtype=np.float64), 0.0, 1.0)
    F0 = np.asarray(F0, dtype=np.float64)
    if F0.ndim and mu.ndim:
        mu = mu[..., None]
    return F0 + (1.0 - F0) * (1.0 - mu) ** 5


def f82_tint(cos_theta, F0, tint) -> np.ndarray:
    """
    The F82-tint Fresnel of OpenPBR and Blender (Hoffman 2023), F90 = 1.

    .. math::

        F(\\mu) = S(\\mu) - \\frac{\\mu (1 - \\mu)^6}{\\bar\\mu (1 - \\bar\\mu)^6}
        S(\\bar\\mu) (1 - t), \\qquad \\bar\\mu = 1/7,

    with :math:`S` Schlick's approximation with ``F0`` and :math:`t` the
    tint (``specular_color``, ``Specular Tint``): :math:`F(\\bar\\mu) = t\\,S(\\bar\\mu)`.
    Shapes as :func:`schlick`.
    """
    mu = np.clip(np.asarray(cos_theta, dtype=np.float64), 0.0, 1.0)
    F0, tint = np.asarray(F0, dtype=np.float64), np.asarray(tint, dtype=np.float64)
    if F0.ndim and mu.ndim:
        mu = mu[..., None]
    m = F82_COS_THETA
    a = schlick(m, F0) * (1.0 - tint) / (m * (1.0 - m) ** 6)
    return F0 + (1.0 - F0) * (1.0 - mu) ** 5 - a * mu * (1.0 - mu) ** 6


def tool_curve(values, target: str) -> np.ndarray:
    """
    The base Fresnel of an export as its tool evaluates it at
    ``values.cos_theta``, (S, 3) linear Rec.709.

    Parameters
    ----------
    values
        :class:`fitting.exports.values.ExportValues`.
    target
        A key of :data:`TOOL_MODELS`.
    """
    if target not in TOOL_MODELS:
        raise ValueError(f"`target` must be one of {', '.join(TOOL_MODELS)}, got {target!r}")
    model = TOOL_MODELS[target]
    mu = values.cos_theta
    if model == "conductor":
        return mx_fresnel_conductor(mu, values.n_rel, values.k_rel)
    if model == "f82-tint":
        return f82_tint(mu, values.F0, values.F82_tint)
    return schlick(mu, values.F0_schlick)


def export_fidelity(values, target: str) -> dict:
    """
    Delta E 2000 of an export against the spectral reference under the coat.

    The tool's base Fresnel (:func:`tool_curve`, in the values' working
    space, back to linear ACEScg) against ``values.target_ACEScg`` at the same
    ``values.cos_theta`` in the coating, eta_i = ``values.eta_i``.

    Returns
    -------
    dict
        ``{"delta_E_mean", "delta_E_max"}``.
    """
    dE = delta_E_map(values.target_ACEScg, working_to_ACEScg(tool_curve(values, target), values.working_space))
    return {"delta_E_mean": float(dE.mean()), "delta_E_max": float(dE.max())}
