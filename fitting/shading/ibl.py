"""
Split-sum pre-integration for image-based lighting
==================================================

The specular directional albedo of the GGX BRDF
(:mod:`fitting.shading.microfacet`) with the model's Fresnel, pre-integrated
so that a renderer multiplies it with a prefiltered environment (Karis 2013,
the split-sum approximation). The model,

.. math::

    F(\\mu) = F_0 (1 - (1 - \\mu)^5) + (1 - \\mu)^5 - a\\,\\mu(1 - \\mu)^{\\alpha},

is linear in :math:`F_0` and *a*, so its directional albedo is

.. math::

    E(\\mu_v, r) = F_0 A(\\mu_v, r) + B(\\mu_v, r) - a\\,G(\\mu_v, r, \\alpha)

with, over the GGX lobe of roughness *r* (:math:`h` the microfacet normal,
:math:`x = 1 - \\mathbf{v}\\cdot\\mathbf{h}`),
:math:`A = \\int (1 - x^5)\\,w`, :math:`B = \\int x^5\\,w` (the usual
split-sum terms) and :math:`G = \\int (\\mathbf{v}\\cdot\\mathbf{h})\\,x^{\\alpha}\\,w`,
where :math:`w\\,d\\omega = f_s/F \\cdot \\cos\\theta_l\\,d\\omega_l`. *G* needs
:math:`\\alpha` as a third axis, as Blender EEVEE's F82 channel
(``brdf_f82_tint_lut``, :math:`\\alpha = 6` fixed) does not: here alpha
varies per channel and with eta_i. The slices are spaced evenly in
:math:`\\log(\\alpha + 1)`, where *G* is close to linear.

-   :class:`SplitSumLUT`: the table, its lookup and its binary form.
-   :func:`generate_lut`: deterministic pre-integration (Hammersley points
    through Heitz's visible-normal sampling).
-   :func:`split_sum_model`, :func:`split_sum_schlick`,
    :func:`split_sum_lazanyi`: the albedo of the model and the baselines.
-   :func:`split_sum_coated`: an approximate pre-integrated albedo of the
    ``coated`` mode from the same LUT.
-   :func:`directional_albedo`: the albedo of the GGX lobe with any Fresnel
    function (a tabulated one: the spectral reference), by the LUT's
    quadrature.
-   :func:`average_fresnel`: the closed-form hemispherical average
    :math:`2\\int_0^1 F\\mu\\,d\\mu` of the model.
-   :func:`energy_compensation`: the multiple-scattering factor from it.
-   :func:`encode_lut`, :func:`decode_lut`: the file format (docs/shading.md).
-   :func:`cached_lut`, :func:`default_lut`: the LUT through a deterministic
    on-disk cache (generated once per machine, not per process).

The table, its generation, file format and cache live in
:mod:`fitting.shading.lut`; their names are re-exported here.

References
----------
Karis, B. (2013). Real shading in Unreal Engine 4. SIGGRAPH course.
Heitz, E. (2018). Sampling the GGX distribution of visible normals. JCGT 7(4).
Kulla, C., & Conty, A. (2017). Revisiting physically based shading at
Imageworks. SIGGRAPH course (average Fresnel, energy compensation).
Fdez-Aguera, C. J. (2019). A multiple-scattering microfacet model for
real-time image-based lighting. JCGT 8(1).
Hoffman, N. (2019). Fresnel equations considered harmful (F82).
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics.
"""

from __future__ import annotations

import numpy as np

from ..domain import as_finite_array
from ..models.baselines import external_medium_F0, lazanyi_a
from ..models.coated_conductor import ALPHA_MIN
from ..optics.fresnel import fresnel_dielectric
from .microfacet import alpha_g_from_roughness, sample_visible_normal, smith_G1, smith_G2
from .lut import (  # noqa: F401  (the LUT's names, re-exported from their old home)
    ALPHA_RANGE,
    CACHE_ENV,
    CACHE_FORMAT_VERSION,
    LUT_SAMPLES,
    LUT_SHAPE,
    MAGIC,
    SplitSumLUT,
    _G_FLOOR,
    _hammersley,
    _node_terms,
    cache_dir,
    cached_lut,
    decode_lut,
    default_lut,
    encode_lut,
    generate_lut,
    lut_cache_path,
)

__all__ = [
    "LUT_SHAPE",
    "ALPHA_RANGE",
    "LUT_SAMPLES",
    "SplitSumLUT",
    "generate_lut",
    "default_lut",
    "cached_lut",
    "lut_cache_path",
    "cache_dir",
    "encode_lut",
    "decode_lut",
    "split_sum_model",
    "split_sum_schlick",
    "split_sum_lazanyi",
    "split_sum_coated",
    "directional_albedo",
    "DIRECTIONAL_ALBEDO_SAMPLES",
    "average_fresnel",
    "energy_compensation",
]


def _inputs(NdotV, roughness):
    return as_finite_array("NdotV", NdotV), as_finite_array("roughness", roughness)


def split_sum_model(NdotV, roughness, F0, a, alpha, lut: SplitSumLUT | None = None) -> np.ndarray:
    """
    Directional albedo of the GGX BRDF with the model's Fresnel:
    :math:`F_0 A + B - a\\,G(\\alpha)` per channel, linear ACEScg.

    Parameters
    ----------
    NdotV, roughness
        Broadcast against each other; clamped to [0, 1].
    F0, a, alpha
        Per-channel parameters (3,) of the model at one eta_i
        (:func:`fitting.models.coated_conductor.collapse_to_eta_i`).

    Returns
    -------
    numpy.ndarray
        ``broadcast(NdotV, roughness).shape + (3,)``.
    """
    lut = lut or default_lut()
    mu, r = _inputs(NdotV, roughness)
    F0, a, alpha = (np.asarray(p, dtype=np.float64) for p in (F0, a, alpha))
    terms = lut.lookup(mu[..., None], r[..., None], alpha)
    return F0 * terms[..., 0] + terms[..., 1] - a * terms[..., 2]


def split_sum_schlick(NdotV, roughness, F0, lut: SplitSumLUT | None = None) -> np.ndarray:
    """Directional albedo with Schlick's Fresnel: :math:`F_0 A + B`."""
    lut = lut or default_lut()
    mu, r = _inputs(NdotV, roughness)
    terms = lut.lookup(mu, r, lut.alpha_range[0])
    return np.asarray(F0, dtype=np.float64) * terms[..., 0:1] + terms[..., 1:2]


def split_sum_lazanyi(NdotV, roughness, eta_i, F0_air, F82_air, lut: SplitSumLUT | None = None) -> np.ndarray:
    """
    Directional albedo with adjusted Lazanyi (:func:`fitting.models.baselines.lazanyi_adjusted`):
    the model's form with :math:`F_0'` at ``eta_i`` (scalar), *a* from F0 and
    F82 in air and :math:`\\alpha = 6`.
    """
    F0 = external_medium_F0(F0_air, float(eta_i))
    a = lazanyi_a(F0_air, F82_air)
    return split_sum_model(NdotV, roughness, F0, a, np.full(3, 6.0), lut)


def split_sum_coated(
    NdotV, roughness, F0, a, alpha, eta_i, coat_roughness=0.0, lut: SplitSumLUT | None = None
) -> np.ndarray:
    """
    Approximate directional albedo of the ``coated`` BRDF from the LUT:

    .. math::

        E \\approx F_{0c} A_c + B_c + [1 - F_c(\\mu_v)]^2\\,E_s(\\mu_t)

    with the coat's lobe by Schlick's form at
    :math:`F_{0c} = ((\\eta_i - 1)/(\\eta_i + 1))^2` (:math:`A_c, B_c` at
    ``coat_roughness``), and the base's albedo :math:`E_s` of
    :func:`split_sum_model` at the refracted cosine
    :math:`\\mu_t = \\sqrt{1 - (1 - \\mu_v^2)/\\eta_i^2}`, transmitted in and
    out at the view angle. Exact for a smooth coat over a smooth base (the
    light leaves at the mirror angle); for a rough base it ignores the light
    lost by total internal reflection, so it overestimates (docs/shading.md
    gives its error against Monte Carlo). Equals :func:`split_sum_model` at
    eta_i = 1.
    """
    lut = lut or default_lut()
    mu, r = _inputs(NdotV, roughness)
    eta = max(float(as_finite_array("eta_i", eta_i)), 1.0)
    mu = np.clip(mu, 0.0, 1.0)
    F0c = ((eta - 1.0) / (eta + 1.0)) ** 2
    coat = split_sum_schlick(mu, coat_roughness, np.full(3, F0c), lut) if eta > 1.0 else 0.0
    T = (1.0 - fresnel_dielectric(mu, 1.0, eta))[..., None]
    mu_t = np.sqrt(1.0 - (1.0 - mu * mu) / (eta * eta))
    return coat + T * T * split_sum_model(mu_t, r, F0, a, alpha, lut)


DIRECTIONAL_ALBEDO_SAMPLES = 2048
"""Hammersley points of :func:`directional_albedo` by default."""


def directional_albedo(NdotV, roughness, fresnel, samples: int = DIRECTIONAL_ALBEDO_SAMPLES) -> np.ndarray:
    """
    Directional albedo of the GGX lobe of perceptual ``roughness`` with the
    Fresnel function ``fresnel`` of :math:`\\mathbf{v}\\cdot\\mathbf{h}`,

    .. math::

        E(\\mu_v) = \\frac{1}{n} \\sum_i F(\\mathbf{v}\\cdot\\mathbf{h}_i)\\,
        \\frac{G_2(\\mathbf{v}, \\mathbf{l}_i)}{G_1(\\mathbf{v})}

    over ``samples`` Hammersley points through visible-normal sampling (the
    quadrature of :func:`generate_lut`; a light below the surface scores 0).
    For a Fresnel that is a table rather than the model's form, such as
    the spectral reference; ``cf_reference_albedo.glsl`` is its GLSL twin.

    Parameters
    ----------
    NdotV
        Cosines (n,), clamped to [0, 1]; 0 is taken as the limit from above.
    roughness
        Scalar in [0, 1] (clamped to ``ROUGHNESS_MIN`` as the BRDF is).
    fresnel
        ``fresnel(VdotH) -> (..., 3)`` for VdotH of any shape, linear.

    Returns
    -------
    numpy.ndarray
        (n, 3), linear in the Fresnel's colour space.
    """
    mu = np.clip(as_finite_array("NdotV", NdotV).reshape(-1), 0.0, 1.0)
    samples = int(samples)
    if not 1 <= samples <= 1 << 20:
        raise ValueError(f"`samples` must lie in [1, 1048576], got {samples}")
    alpha_g = alpha_g_from_roughness(float(as_finite_array("roughness", roughness)))
    u1, u2 = _hammersley(samples)
    m = np.maximum(mu, 1.0e-6)  # NdotV = 0: the limit from above (G1 -> 0 cancels)
    v = np.stack([np.sqrt(1.0 - m * m), np.zeros_like(m), m], axis=-1)[:, None, :]
    h = sample_visible_normal(v, alpha_g, u1[None, :], u2[None, :])
    VdotH = np.clip(np.sum(v * h, axis=-1), 0.0, 1.0)
    NdotL = 2.0 * VdotH * h[..., 2] - v[..., 2]
    w = np.where(NdotL > 0.0, smith_G2(m[:, None], NdotL, alpha_g) / smith_G1(m[:, None], alpha_g), 0.0)
    return np.mean(w[..., None] * np.asarray(fresnel(VdotH), dtype=np.float64), axis=1)


def average_fresnel(F0, a, alpha) -> np.ndarray:
    """
    Closed-form hemispherical average of the model,
    :math:`\\bar F = 2\\int_0^1 F(\\mu)\\,\\mu\\,d\\mu`:

    .. math::

        \\bar F = F_0 + \\frac{1 - F_0}{21} - \\frac{4a}{(\\alpha + 1)(\\alpha + 2)(\\alpha + 3)}

    from :math:`2\\int\\mu(1-\\mu)^5 d\\mu = 2B(2, 6) = 1/21` and
    :math:`2\\int\\mu^2(1-\\mu)^\\alpha d\\mu = 2B(3, \\alpha + 1)` with the Beta
    function :math:`B(3, \\alpha+1) = 2/((\\alpha+1)(\\alpha+2)(\\alpha+3))`.
    Alpha is clamped to :data:`fitting.models.coated_conductor.ALPHA_MIN` as the model does.
    """
    F0, a = np.asarray(F0, dtype=np.float64), np.asarray(a, dtype=np.float64)
    alpha = np.maximum(np.asarray(alpha, dtype=np.float64), ALPHA_MIN)
    return F0 + (1.0 - F0) / 21.0 - 4.0 * a / ((alpha + 1.0) * (alpha + 2.0) * (alpha + 3.0))


def energy_compensation(E_white, F_average) -> np.ndarray:
    """
    Multiple-scattering factor of the specular lobe (Kulla & Conty 2017;
    Fdez-Aguera 2019; Filament's form):
    :math:`1 + \\bar F\\,(1 - E)/E` with :math:`E = A + B` the single-scattering
    albedo of a white (F = 1) lobe. Multiply the single-scattering specular
    by it; *E* is floored at 1e-4 (a lobe can never be that dark: E >= 0.45
    for GGX at any roughness with NdotV >= 0.05).
    """
    E = np.maximum(np.asarray(E_white, dtype=np.float64), 1.0e-4)
    return 1.0 + np.asarray(F_average, dtype=np.float64) * (1.0 - E) / E
