"""
A metal under a smooth coat, seen from air, with the bounces between them
=========================================================================

What ``EXT_materials_coated_conductor`` draws for image-based light
(docs/gltf/EXT_materials_coated_conductor/, the three.js plugin's GLSL is
the twin of this module): the base's share of the white sky's radiance,
the metal's GGX lobe of albedo :math:`E(\\mu_t)` at the cosine inside the
coat seen through a smooth coat of index :math:`\\eta` from air at
:math:`\\mu`, with every bounce between the metal and the coat's underside.

-   A **mirror** metal returns the light to the coat at :math:`\\mu_t`, so
    the sum over bounces is exact per polarisation (the stack of
    :func:`fitting.optics.coated_stack.coated_stack_from_metal`, less the
    coat's own reflection):

    .. math::

        M = \\tfrac12 \\sum_{x \\in \\{s, p\\}} \\frac{(1 - R_x)^2 E}{1 - R_x E}.

-   A **rough** metal scatters the light over its lobe: the fraction
    :math:`q(\\mu_t)` of the lobe's energy leaving through the coat's
    underside at once (weighted by the coat's transmission :math:`1 -
    R_{int}` at each direction, 0 beyond the critical angle) goes out, the
    rest comes back down. That rest returns to the metal spread over the
    hemisphere; taken as cosine-distributed, it leaves after any number of
    bounces with probability :math:`X_d = \\bar E (1 - \\bar r)/(1 - \\bar E
    \\bar r)` (:math:`\\bar E` the metal's hemispherical albedo, :math:`\\bar
    r` the coat's hemispherical reflectance from inside, total internal
    reflection included), against :math:`X_m = (1 - F_d) E/(1 - F_d E)` for
    the mirror. With :math:`w = \\min(r / 0.2, 1)` of the perceptual
    roughness *r*:

    .. math::

        D = (1 - F_d)\\,E\\,[q + (1 - q)\\,((1 - w) X_m + w X_d)],\\qquad
        S = (1 - w)\\,M + w\\,D,

    :math:`F_d = (R_s + R_p)/2` at :math:`\\mu`. At *r* = 0, *S* = *M*.
    ``benchmarks/coated_bounces.py`` measures *S* against a random walk of
    the same layer.

-   :func:`internal_reflectance`: :math:`\\bar r` of a coat of index eta.
-   :func:`escape_fraction`: *q* by quadrature.
-   :func:`hemispherical_albedo`: :math:`\\bar E`.
-   :func:`through_coat`: *S* from its parts.
-   :func:`seen_base`: *S* of a Fresnel function at view cosines.

References
----------
Born, M., & Wolf, E. (1999). Principles of Optics (7th ed.), 1.5 and 1.6.
Heitz, E. (2018). Sampling the GGX distribution of visible normals. JCGT 7(4).
Weidlich, A., & Wilkie, A. (2007). Arbitrarily layered micro-facet surfaces. GRAPHITE.
"""

from __future__ import annotations

import numpy as np

from ..domain import as_finite_array
from ..optics.coated_stack import fresnel_dielectric_sp, refracted_cos
from ..optics.fresnel import fresnel_dielectric
from .ibl import directional_albedo
from .lut import _hammersley
from .microfacet import alpha_g_from_roughness, sample_visible_normal, smith_G1, smith_G2

__all__ = [
    "ROUGH_BLEND",
    "ESCAPE_SAMPLES",
    "HEMISPHERE_SAMPLES",
    "internal_reflectance",
    "escape_fraction",
    "hemispherical_albedo",
    "through_coat",
    "seen_base",
]

ROUGH_BLEND = 0.2
"""Perceptual roughness at and above which the rough form D is used alone."""
ESCAPE_SAMPLES = 256
"""Quadrature points of :func:`escape_fraction` (the plugin's table pass uses as many)."""
HEMISPHERE_SAMPLES = 64
"""Quadrature points a node of :func:`hemispherical_albedo` (the plugin's table pass uses as many)."""
_HEMISPHERE_NODES = 16
"""Cosine nodes (midpoints in cos^2) of :func:`internal_reflectance` and :func:`hemispherical_albedo`."""


def _hemisphere_nodes() -> np.ndarray:
    # Midpoints uniform in s = cos^2: 2 int f(c) c dc = int f(sqrt(s)) ds.
    return np.sqrt((np.arange(_HEMISPHERE_NODES) + 0.5) / _HEMISPHERE_NODES)


def internal_reflectance(eta) -> float:
    """
    :math:`\\bar r = 2 \\int_0^1 R_{int}(c)\\,c\\,dc`: the cosine-weighted
    reflectance of a coat of index ``eta`` >= 1 seen from inside (1 beyond
    the critical angle), by the midpoint rule in :math:`c^2`.
    """
    eta = max(float(as_finite_array("eta", eta)), 1.0)
    c = _hemisphere_nodes()
    return float(np.mean(fresnel_dielectric(c, eta, 1.0)))


def escape_fraction(mu_t, roughness, fresnel, eta, samples: int = ESCAPE_SAMPLES) -> np.ndarray:
    """
    q: the share of the metal's GGX lobe (visible normals, ``fresnel(VdotH)
    -> (..., 3)``) at in-coat cosines ``mu_t`` (n,) that leaves through the
    coat's underside at once, :math:`\\sum F G_2/G_1 (1 - R_{int}) / \\sum F
    G_2/G_1`; (n, 3). 1 where the lobe scores nothing.
    """
    mu = np.clip(as_finite_array("mu_t", mu_t).reshape(-1), 1.0e-6, 1.0)
    alpha_g = alpha_g_from_roughness(float(as_finite_array("roughness", roughness)))
    u1, u2 = _hammersley(int(samples))
    v = np.stack([np.sqrt(1.0 - mu * mu), np.zeros_like(mu), mu], axis=-1)[:, None, :]
    h = sample_visible_normal(v, alpha_g, u1[None, :], u2[None, :])
    VdotH = np.clip(np.sum(v * h, axis=-1), 0.0, 1.0)
    NdotL = 2.0 * VdotH * h[..., 2] - v[..., 2]
    G = np.where(NdotL > 0.0, smith_G2(mu[:, None], NdotL, alpha_g) / smith_G1(mu[:, None], alpha_g), 0.0)
    lobe = G[..., None] * np.asarray(fresnel(VdotH), dtype=np.float64)
    out = 1.0 - fresnel_dielectric(np.clip(NdotL, 0.0, 1.0), max(float(eta), 1.0), 1.0)
    total = lobe.sum(axis=1)
    return np.where(total > 0.0, (lobe * out[..., None]).sum(axis=1) / np.where(total > 0.0, total, 1.0), 1.0)


def hemispherical_albedo(roughness, fresnel) -> np.ndarray:
    """:math:`\\bar E = 2 \\int_0^1 E(c)\\,c\\,dc` of the metal's GGX lobe, (3,)."""
    return directional_albedo(_hemisphere_nodes(), roughness, fresnel, samples=HEMISPHERE_SAMPLES).mean(axis=0)


def through_coat(E, q, E_bar, r_bar, NdotV, eta, roughness) -> np.ndarray:
    """
    S of the module's docstring: the metal's albedo ``E`` (n, 3) at the
    in-coat cosine, its escape fraction ``q`` (n, 3), hemispherical albedo
    ``E_bar`` (3,) and the coat's ``r_bar``, seen from air at ``NdotV``
    (n,) through a smooth coat of index ``eta`` (no coat's own reflection).
    """
    E, q = np.asarray(E, dtype=np.float64), np.asarray(q, dtype=np.float64)
    Rs, Rp = (R[:, None] for R in fresnel_dielectric_sp(np.asarray(NdotV, dtype=np.float64), eta))
    M = 0.5 * sum((1.0 - R) ** 2 * E / (1.0 - R * E) for R in (Rs, Rp))
    Fd = 0.5 * (Rs + Rp)
    w = min(float(roughness) / ROUGH_BLEND, 1.0)
    X_mirror = (1.0 - Fd) * E / (1.0 - Fd * E)
    X_diffuse = E_bar * (1.0 - r_bar) / (1.0 - E_bar * r_bar)
    D = (1.0 - Fd) * E * (q + (1.0 - q) * ((1.0 - w) * X_mirror + w * X_diffuse))
    return (1.0 - w) * M + w * D


def seen_base(NdotV, eta, roughness, fresnel) -> np.ndarray:
    """
    S at view cosines ``NdotV`` (n,) in air for the metal's Fresnel under
    the coat ``fresnel(cos) -> (..., 3)``: at roughness 0 the mirror's
    series of its Fresnel at the in-coat cosine, else the GGX lobe's parts.
    """
    mu = np.asarray(NdotV, dtype=np.float64).reshape(-1)
    mu_t = refracted_cos(mu, eta)
    if roughness <= 0.0:
        return through_coat(fresnel(mu_t), np.ones((mu.size, 3)), np.zeros(3), 0.0, mu, eta, 0.0)
    E = directional_albedo(mu_t, roughness, fresnel)
    q = escape_fraction(mu_t, roughness, fresnel, eta)
    return through_coat(E, q, hemispherical_albedo(roughness, fresnel), internal_reflectance(eta), mu, eta, roughness)
