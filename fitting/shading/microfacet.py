"""
Microfacet BRDF with the coated-conductor Fresnel
=================================================

A GGX specular BRDF whose Fresnel term is the model of Vernooij (2024),
evaluated at the microfacet's :math:`\\mathbf{v}\\cdot\\mathbf{h}`, in two
set-ups:

-   ``immersed``: the paper's validation set-up. Camera, lights and the
    metal all sit in one medium of index :math:`\\eta_i`; the model at
    :math:`\\eta_i` is the Fresnel of every microfacet.
-   ``coated``: a clear dielectric coat of index :math:`\\eta_i` over the
    metal, seen from air. The coat's top interface reflects with its own GGX
    lobe (roughness ``coat_roughness``, dielectric Fresnel from 1 to
    :math:`\\eta_i`); the light that crosses it is refracted, reflected by the
    metal's rough lobe inside the coat (the model at the in-coat
    :math:`\\mathbf{v}\\cdot\\mathbf{h}`, which is what the model describes),
    and crosses the interface again. At :math:`\\eta_i = 1` the coat
    vanishes and ``coated`` equals ``immersed``.

The BRDF (all directions in the shading frame, normal +z, pointing away
from the surface):

.. math::

    f_s(\\mathbf{l}, \\mathbf{v}) = \\frac{D(\\mathbf{h})\\,G_2(\\mathbf{l},
    \\mathbf{v})\\,F(\\mathbf{v}\\cdot\\mathbf{h})}{4\\,|\\mathbf{n}\\cdot
    \\mathbf{l}|\\,|\\mathbf{n}\\cdot\\mathbf{v}|}

with GGX :math:`D` (Walter et al. 2007, Eq. 33), the height-correlated
Smith :math:`G_2 = 1/(1 + \\Lambda(\\mathbf{v}) + \\Lambda(\\mathbf{l}))`
(Heitz 2014, Eq. 99, :math:`\\Lambda` Eq. 72) and
:math:`\\alpha_g = r^2` from the perceptual roughness *r* (Burley 2012;
Filament; OpenPBR ``specular_roughness``).

The coated BRDF (Weidlich & Wilkie 2007, Eq. 4-6, the layering that the
OpenPBR coat specification describes: the base seen through the coat with
refracted directions, its Fresnel relative to the coat's index, attenuated
by the coat's transmission in and out):

.. math::

    f(\\mathbf{l}, \\mathbf{v}) = f_c(\\mathbf{l}, \\mathbf{v}) +
    \\frac{[1 - F_c(\\mathbf{n}\\cdot\\mathbf{v})][1 - F_c(\\mathbf{n}\\cdot
    \\mathbf{l})]}{\\eta_i^2}\\,f_s(\\mathbf{l}_t, \\mathbf{v}_t)

where :math:`f_c` is the coat's GGX lobe with the dielectric Fresnel
:math:`F_c` (air to :math:`\\eta_i`), :math:`\\mathbf{v}_t, \\mathbf{l}_t`
the directions refracted into the coat through its mean surface, and
:math:`1/\\eta_i^2` the change of projected solid angle across the
interface (:math:`\\eta^2 \\cos\\theta\\,d\\omega` is invariant), which keeps
the layered BRDF energy-conserving. Light the base sends outside the escape
cone is totally reflected inside the coat and, in this single-scattering
form, lost (coat darkening in OpenPBR's terms).

-   :data:`MODES`, :data:`ROUGHNESS_MIN`.
-   :func:`alpha_g_from_roughness`, :func:`ggx_D`, :func:`smith_lambda`,
    :func:`smith_G1`, :func:`smith_G2`.
-   :func:`refract_into_coat`: a direction seen through the coat.
-   :func:`specular_brdf`: :math:`f_s` with any Fresnel function.
-   :func:`coated_brdf`: the layered BRDF with any base Fresnel.
-   :func:`model_fresnel`: the model's F as a function of VdotH.
-   :func:`microfacet_brdf`: the BRDF of the model in either mode.
-   :func:`sample_visible_normal`: Heitz (2018) sampling of the GGX
    distribution of visible normals, for the pre-integration and Monte Carlo.

References
----------
Walter, B., Marschner, S., Li, H., & Torrance, K. (2007). Microfacet models
for refraction through rough surfaces. EGSR.
Heitz, E. (2014). Understanding the masking-shadowing function in
microfacet-based BRDFs. JCGT 3(2).
Heitz, E. (2018). Sampling the GGX distribution of visible normals. JCGT 7(4).
Weidlich, A., & Wilkie, A. (2007). Arbitrarily layered micro-facet surfaces.
GRAPHITE.
Andersson, Z., et al. (2024). OpenPBR Surface specification, v1.1 (coat).
Burley, B. (2012). Physically-based shading at Disney. SIGGRAPH course.
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics.
"""

from __future__ import annotations

import numpy as np

from ..models.coated_conductor import model_from_parameters
from ..optics.fresnel import fresnel_dielectric

__all__ = [
    "MODES",
    "ROUGHNESS_MIN",
    "check_mode",
    "alpha_g_from_roughness",
    "ggx_D",
    "smith_lambda",
    "smith_G1",
    "smith_G2",
    "refract_into_coat",
    "specular_brdf",
    "coated_brdf",
    "model_fresnel",
    "microfacet_brdf",
    "sample_visible_normal",
]

MODES = ("immersed", "coated")

ROUGHNESS_MIN = 0.02
"""Perceptual roughness below this is raised to it: r = 0 is a Dirac lobe
that a BRDF cannot represent, and at alpha_g = 4e-4 GGX's peak (2e6) is
still well inside float32 (Filament clamps likewise, at 0.045 for fp16)."""

_COS_MIN = 1.0e-7
"""Floor of cosines in denominators: a grazing direction gives the limit
(Lambda -> infinity, G -> 0) instead of a division by zero."""


def check_mode(mode: str) -> str:
    """``mode`` if it is one of :data:`MODES`, else ``ValueError``."""
    if mode not in MODES:
        raise ValueError(f"`mode` must be one of {', '.join(MODES)}, got {mode!r}")
    return mode


def alpha_g_from_roughness(roughness) -> np.ndarray:
    """
    GGX :math:`\\alpha_g = r^2` from perceptual roughness *r*, with *r*
    clamped to [:data:`ROUGHNESS_MIN`, 1] (a kernel clamps, it never raises
    on numeric input; NaN gives NaN, as every physics kernel of the house).
    """
    r = np.clip(np.asarray(roughness, dtype=np.float64), ROUGHNESS_MIN, 1.0)
    return r * r


def ggx_D(h, alpha_g) -> np.ndarray:
    """
    GGX normal distribution (Walter et al. 2007, Eq. 33) of unit half vectors
    ``h`` (..., 3) in the shading frame:
    :math:`\\alpha^2 / (\\pi (\\cos^2\\theta_h (\\alpha^2 - 1) + 1)^2)`, with
    :math:`1 - \\cos^2\\theta_h = h_x^2 + h_y^2` (exact near the peak, where
    :math:`1 - \\cos^2` would cancel). Zero for :math:`h_z \\le 0`.
    """
    h = np.asarray(h, dtype=np.float64)
    a2 = np.asarray(alpha_g, dtype=np.float64) ** 2
    sin2 = h[..., 0] ** 2 + h[..., 1] ** 2
    cos2 = h[..., 2] ** 2
    denominator = cos2 * a2 + sin2
    return np.where(h[..., 2] > 0.0, a2 / (np.pi * denominator**2), 0.0)


def smith_lambda(NdotX, alpha_g) -> np.ndarray:
    """
    Smith's :math:`\\Lambda` for GGX (Heitz 2014, Eq. 72):
    :math:`(-1 + \\sqrt{1 + \\alpha^2 \\tan^2\\theta})/2`; the cosine is
    floored at 1e-7 so grazing gives a large finite value (G -> 0).
    """
    mu = np.clip(np.asarray(NdotX, dtype=np.float64), _COS_MIN, 1.0)
    a2 = np.asarray(alpha_g, dtype=np.float64) ** 2
    tan2 = (1.0 - mu * mu) / (mu * mu)
    return 0.5 * (np.sqrt(1.0 + a2 * tan2) - 1.0)


def smith_G1(NdotV, alpha_g) -> np.ndarray:
    """Smith masking :math:`G_1 = 1/(1 + \\Lambda)` (Heitz 2014, Eq. 43)."""
    return 1.0 / (1.0 + smith_lambda(NdotV, alpha_g))


def smith_G2(NdotV, NdotL, alpha_g) -> np.ndarray:
    """
    Height-correlated Smith masking-shadowing (Heitz 2014, Eq. 99):
    :math:`1/(1 + \\Lambda(\\mathbf{v}) + \\Lambda(\\mathbf{l}))`; 0 when either
    direction is below the surface.
    """
    NdotV = np.asarray(NdotV, dtype=np.float64)
    NdotL = np.asarray(NdotL, dtype=np.float64)
    G = 1.0 / (1.0 + smith_lambda(NdotV, alpha_g) + smith_lambda(NdotL, alpha_g))
    return np.where((NdotV > 0.0) & (NdotL > 0.0), G, 0.0)


def refract_into_coat(w, eta_i) -> np.ndarray:
    """
    A direction ``w`` (..., 3) in air, above the surface, seen from inside a
    coat of index ``eta_i`` >= 1 through its flat mean surface (Snell): the
    tangential part divided by eta_i, :math:`z = \\sqrt{1 - (x^2 + y^2)/\\eta_i^2}`.
    Pointing away from the surface, like ``w``. ``eta_i`` below 1 is
    clamped to 1 (no coat).
    """
    w = np.asarray(w, dtype=np.float64)
    eta = np.maximum(np.asarray(eta_i, dtype=np.float64), 1.0)[..., None]
    tangential = w[..., :2] / eta
    # eta_i >= 1 keeps the argument in [0, 1]; the clip absorbs rounding.
    z = np.sqrt(np.clip(1.0 - np.sum(tangential**2, axis=-1, keepdims=True), 0.0, 1.0))
    return np.concatenate([tangential, z], axis=-1)


def _normalise(v: np.ndarray) -> np.ndarray:
    length = np.sqrt(np.sum(v * v, axis=-1, keepdims=True))
    # v + l = 0 only for opposite directions, where the BRDF is 0 anyway.
    return v / np.maximum(length, np.finfo(np.float64).tiny)


def specular_brdf(wo, wi, alpha_g, fresnel) -> np.ndarray:
    """
    The GGX microfacet BRDF :math:`D G_2 F(\\mathbf{v}\\cdot\\mathbf{h}) /
    (4\\,\\mathbf{n}\\cdot\\mathbf{l}\\,\\mathbf{n}\\cdot\\mathbf{v})` in 1/sr.

    Parameters
    ----------
    wo, wi
        View and light unit directions (..., 3) in the shading frame, both
        pointing away from the surface.
    alpha_g
        GGX :math:`\\alpha_g`, broadcast against the directions.
    fresnel
        Callable ``fresnel(VdotH)`` -> (..., C) for VdotH of shape (...).

    Returns
    -------
    numpy.ndarray
        (..., C); 0 where a direction is below the surface.
    """
    wo = np.asarray(wo, dtype=np.float64)
    wi = np.asarray(wi, dtype=np.float64)
    NdotV, NdotL = wo[..., 2], wi[..., 2]
    h = _normalise(wo + wi)
    VdotH = np.clip(np.sum(wo * h, axis=-1), 0.0, 1.0)
    D = ggx_D(h, alpha_g)
    G = smith_G2(NdotV, NdotL, alpha_g)
    denominator = 4.0 * np.maximum(NdotV, _COS_MIN) * np.maximum(NdotL, _COS_MIN)
    return (D * G / denominator)[..., None] * fresnel(VdotH)


def _coat_fresnel(cos_theta, eta_i) -> np.ndarray:
    """Dielectric Fresnel from air into the coat (0 at eta_i = 1)."""
    return fresnel_dielectric(np.clip(cos_theta, 0.0, 1.0), 1.0, eta_i)


def coated_brdf(wo, wi, roughness, base_fresnel, eta_i, coat_roughness=0.0) -> np.ndarray:
    """
    The layered BRDF of the module docstring: the coat's lobe plus the base
    seen through the coat.

    Parameters
    ----------
    wo, wi
        Directions (..., 3) in air, shading frame, away from the surface.
    roughness, coat_roughness
        Perceptual roughness of the metal and of the coat's top surface.
    base_fresnel
        Callable of the in-coat VdotH -> (..., C): the metal seen from the
        coat (the model at eta_i, or the exact Fresnel with eta_i).
    eta_i
        Index of the coat, >= 1 (a smaller value is clamped to 1).

    Returns
    -------
    numpy.ndarray
        (..., C) in 1/sr.
    """
    wo = np.asarray(wo, dtype=np.float64)
    wi = np.asarray(wi, dtype=np.float64)
    # Below 1 there is no coat to speak of: clamped (never raises).
    eta = np.maximum(np.asarray(eta_i, dtype=np.float64), 1.0)
    NdotV, NdotL = wo[..., 2], wi[..., 2]
    coat = specular_brdf(
        wo,
        wi,
        alpha_g_from_roughness(coat_roughness),
        lambda VdotH: _coat_fresnel(VdotH, eta)[..., None],
    )
    transmission = (1.0 - _coat_fresnel(NdotV, eta)) * (1.0 - _coat_fresnel(NdotL, eta))
    base = specular_brdf(
        refract_into_coat(wo, eta),
        refract_into_coat(wi, eta),
        alpha_g_from_roughness(roughness),
        base_fresnel,
    )
    above = ((NdotV > 0.0) & (NdotL > 0.0))[..., None]
    return np.where(above, coat + (transmission / (eta * eta))[..., None] * base, 0.0)


def model_fresnel(F0, a, alpha):
    """The model's Eq. 1 at given per-channel F0, a, alpha (the model
    collapsed at one eta_i) as a callable of VdotH -> (..., 3)."""
    F0, a, alpha = (np.asarray(p, dtype=np.float64) for p in (F0, a, alpha))
    return lambda VdotH: model_from_parameters(np.asarray(VdotH)[..., None], F0, a, alpha)


def microfacet_brdf(wo, wi, roughness, F0, a, alpha, mode="immersed", eta_i=1.0, coat_roughness=0.0) -> np.ndarray:
    """
    The GGX BRDF with the coated-conductor model's Fresnel, linear ACEScg,
    1/sr.

    Parameters
    ----------
    wo, wi
        View and light unit directions (..., 3), shading frame, away from
        the surface.
    roughness
        Perceptual roughness of the metal in [0, 1] (clamped to
        [:data:`ROUGHNESS_MIN`, 1]).
    F0, a, alpha
        The model's parameters per channel (3,) at ``eta_i``
        (:func:`fitting.models.coated_conductor.collapse_to_eta_i`).
    mode
        ``immersed`` or ``coated`` (see the module docstring).
    eta_i
        The coat's index (``coated``); ``immersed`` ignores it, the medium
        is already in F0, a, alpha.
    coat_roughness
        Perceptual roughness of the coat's surface (``coated``).

    Returns
    -------
    numpy.ndarray
        (..., 3).
    """
    check_mode(mode)
    fresnel = model_fresnel(F0, a, alpha)
    if mode == "coated":
        return coated_brdf(wo, wi, roughness, fresnel, eta_i, coat_roughness)
    return specular_brdf(wo, wi, alpha_g_from_roughness(roughness), fresnel)


def sample_visible_normal(wo, alpha_g, u1, u2) -> np.ndarray:
    """
    Heitz (2018), Listing 1: a GGX microfacet normal drawn from the
    distribution of normals visible from ``wo``,
    :math:`D_{\\mathbf{v}}(\\mathbf{h}) = G_1(\\mathbf{v})\\,
    \\max(0, \\mathbf{v}\\cdot\\mathbf{h})\\,D(\\mathbf{h})/(\\mathbf{n}\\cdot
    \\mathbf{v})`, by the uniform numbers ``u1``, ``u2`` in [0, 1).

    With the mirrored light :math:`\\mathbf{l} = 2(\\mathbf{v}\\cdot
    \\mathbf{h})\\mathbf{h} - \\mathbf{v}`, the estimator of the directional
    albedo is :math:`F(\\mathbf{v}\\cdot\\mathbf{h})\\,G_2/G_1(\\mathbf{v})`.

    Returns
    -------
    numpy.ndarray
        Unit normals (..., 3) broadcast over the inputs.
    """
    wo = np.asarray(wo, dtype=np.float64)
    alpha = np.asarray(alpha_g, dtype=np.float64)[..., None]
    u1 = np.asarray(u1, dtype=np.float64)
    u2 = np.asarray(u2, dtype=np.float64)
    # The view direction stretched to the hemisphere configuration.
    Vh = _normalise(np.concatenate([alpha * wo[..., :2], wo[..., 2:]], axis=-1))
    Vh, u1, u2 = np.broadcast_arrays(Vh, u1[..., None], u2[..., None])
    u1, u2 = u1[..., 0], u2[..., 0]
    lensq = Vh[..., 0] ** 2 + Vh[..., 1] ** 2
    safe = np.sqrt(np.where(lensq > 0.0, lensq, 1.0))
    # Normal view (lensq = 0): any tangent will do, take +x.
    T1 = np.where(
        (lensq > 0.0)[..., None],
        np.stack([-Vh[..., 1] / safe, Vh[..., 0] / safe, np.zeros_like(safe)], axis=-1),
        np.array([1.0, 0.0, 0.0]),
    )
    T2 = np.cross(Vh, T1)
    r = np.sqrt(u1)
    phi = 2.0 * np.pi * u2
    t1, t2 = r * np.cos(phi), r * np.sin(phi)
    s = 0.5 * (1.0 + Vh[..., 2])
    t2 = (1.0 - s) * np.sqrt(np.clip(1.0 - t1 * t1, 0.0, 1.0)) + s * t2
    Nh = t1[..., None] * T1 + t2[..., None] * T2 + np.sqrt(np.clip(1.0 - t1 * t1 - t2 * t2, 0.0, 1.0))[..., None] * Vh
    # Back from the hemisphere configuration to the ellipsoid.
    Ne = np.concatenate([alpha * Nh[..., :2], np.maximum(Nh[..., 2:], 0.0)], axis=-1)
    return _normalise(Ne)
