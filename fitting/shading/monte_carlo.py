"""
Monte Carlo ground truth
========================

Seeded, importance-sampled estimates of the specular directional albedo

.. math::

    E(\\mathbf{v}) = \\int_{H^2} f(\\mathbf{l}, \\mathbf{v})\\cos\\theta_l\\,d\\omega_l

of the BRDFs of :mod:`fitting.shading.microfacet` (a white, constant
environment of radiance 1 reflects exactly E), with the model's Fresnel or
with the exact spectral Fresnel of the measured *n*, *k*.

Estimators (Heitz 2018, visible-normal sampling of GGX):

-   ``immersed``: :math:`h \\sim D_{\\mathbf{v}}`, :math:`\\mathbf{l}` the
    mirror of :math:`\\mathbf{v}`, weight :math:`F(\\mathbf{v}\\cdot\\mathbf{h})\\,G_2/G_1(\\mathbf{v})`.
-   ``coated``: the coat's lobe by the same estimator in air with the
    dielectric Fresnel, plus the base by the change of variables to the
    in-coat light direction :math:`\\mathbf{l}_t` (which removes the
    :math:`1/\\eta_i^2`): :math:`h \\sim D_{\\mathbf{v}_t}` inside the coat,
    weight :math:`[1 - F_c(\\mu_v)][1 - F_c(\\mu_l)]\\,F\\,G_2/G_1(\\mathbf{v}_t)`
    when :math:`\\mathbf{l}_t` escapes (:math:`\\sin\\theta_t < 1/\\eta_i`), 0
    when it is totally reflected (lost in the single-scattering layer).

Each estimate is the mean of ``samples`` independent draws (NumPy PCG64
seeded by ``seed``); its standard error is the sample standard deviation
over :math:`\\sqrt{N}`.

-   :data:`MC_SAMPLES`.
-   :class:`AlbedoEstimate`: mean, standard error, sample count.
-   :func:`spectral_fresnel`: the exact Fresnel of *n*, *k* integrated to
    ACEScg as a function of the in-medium cosine.
-   :func:`directional_albedo`: the estimate for any Fresnel, either mode.
-   :func:`model_directional_albedo`: the immersed estimate for many
    parameter sets of the model at once, on shared draws.
-   :func:`rough_sphere_image`: an orthographic image of a rough sphere
    under the white environment (each pixel the albedo at its NdotV).

References
----------
Heitz, E. (2018). Sampling the GGX distribution of visible normals. JCGT 7(4).
Pharr, M., Jakob, W., & Humphreys, G. (2023). Physically Based Rendering,
4th ed., Section 2.1 (Monte Carlo estimators and their variance).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..colour.reference import reference_ACEScg
from ..domain import DEFAULT_MIN_COVERAGE, as_finite_array
from ..models.coated_conductor import ALPHA_MIN
from ..optics.fresnel import fresnel_dielectric
from ..optics.nk import SpectralNK
from .microfacet import (
    alpha_g_from_roughness,
    check_mode,
    refract_into_coat,
    sample_visible_normal,
    smith_G1,
    smith_G2,
    smith_lambda,
)

__all__ = [
    "MC_SAMPLES",
    "MASKING",
    "AlbedoEstimate",
    "spectral_fresnel",
    "directional_albedo",
    "model_directional_albedo",
    "rough_sphere_image",
]

MC_SAMPLES = 65536
"""Default draws per direction: standard error ~1e-3 of the albedo or less."""

MASKING = ("height-correlated", "separable")
"""Shadowing-masking of the estimator: height-correlated Smith (the BRDF of
this package, Heitz 2014 Eq. 99) or separable Smith G1(v) G1(l) (what
Mitsuba 3's ``roughconductor`` uses; only for comparing with it)."""

_TABLE_NODES = 4097
"""Nodes of the spectral Fresnel table over cos theta in [0, 1]: the linear
interpolation between them errs by < 1e-6 (h^2/8 |F''|, |F''| < 50)."""

_CHUNK = 1 << 16


@dataclass(frozen=True)
class AlbedoEstimate:
    """``mean`` and ``stderr`` of shape (..., C) (linear ACEScg for RGB),
    from ``samples`` draws per direction."""

    mean: np.ndarray
    stderr: np.ndarray
    samples: int


def spectral_fresnel(
    nk: SpectralNK, eta_i: float, step_nm: float = 1.0, min_coverage: float = DEFAULT_MIN_COVERAGE
) -> Callable[[np.ndarray], np.ndarray]:
    """
    The exact unpolarised Fresnel of ``nk`` seen from a medium of index
    ``eta_i``, per wavelength, integrated to linear ACEScg
    (:func:`fitting.colour.reference.reference_ACEScg`, 1 nm by default), as a
    callable of the in-medium cosine -> (..., 3). Tabulated at 4097 cosines
    and interpolated linearly (error < 1e-6), so that a million draws cost
    one table.
    """
    nodes = np.linspace(0.0, 1.0, _TABLE_NODES)
    table = reference_ACEScg(nk, nodes, float(eta_i), step_nm, min_coverage)

    def fresnel(cos_theta):
        mu = np.clip(np.asarray(cos_theta, dtype=np.float64), 0.0, 1.0)
        return np.stack([np.interp(mu, nodes, table[:, c]) for c in range(3)], axis=-1)

    return fresnel


def _check_samples(samples) -> int:
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)):
        raise ValueError(f"`samples` must be an integer, got {samples!r}")
    if not 16 <= samples <= 1 << 24:
        raise ValueError(f"`samples` must lie in [16, 16777216], got {samples}")
    return int(samples)


def _masking_weight(mu_v, mu_l, alpha_g, masking):
    """G2 / G1(v) of the visible-normal estimator (0 below the surface)."""
    if masking == "separable":
        return np.where(mu_l > 0.0, 1.0 / (1.0 + smith_lambda(mu_l, alpha_g)), 0.0)
    return np.where(mu_l > 0.0, smith_G2(mu_v, mu_l, alpha_g) / smith_G1(mu_v, alpha_g), 0.0)


def _lobe_draws(v, alpha_g, rng, count, masking):
    """VdotH, the light direction and the masking weight of ``count`` draws."""
    h = sample_visible_normal(v, alpha_g, rng.random(count), rng.random(count))
    VdotH = np.clip(h @ v, 0.0, 1.0)
    l = 2.0 * VdotH[:, None] * h - v
    return VdotH, l, _masking_weight(v[2], l[:, 2], alpha_g, masking)


def _accumulate(weights, sums):
    sums[0] += weights.sum(axis=0)
    sums[1] += (weights * weights).sum(axis=0)


def directional_albedo(
    NdotV,
    roughness: float,
    fresnel: Callable[[np.ndarray], np.ndarray],
    mode: str = "immersed",
    eta_i: float = 1.0,
    coat_roughness: float = 0.0,
    samples: int = MC_SAMPLES,
    seed: int = 0,
    masking: str = "height-correlated",
) -> AlbedoEstimate:
    """
    Monte Carlo directional albedo of the GGX BRDF.

    Parameters
    ----------
    NdotV
        1-D array of view cosines in (0, 1] (clamped to [1e-4, 1]).
    roughness, coat_roughness
        Perceptual roughness of the metal and the coat (clamped as the BRDF).
    fresnel
        The metal's Fresnel as a callable of the (in-medium) VdotH -> (..., C):
        :func:`fitting.shading.microfacet.model_fresnel` or :func:`spectral_fresnel`.
    mode
        ``immersed`` or ``coated``; ``eta_i`` is the coat's index (coated).
    samples, seed
        Draws per direction and the seed of the generator.
    masking
        One of :data:`MASKING`.

    Returns
    -------
    AlbedoEstimate
        Mean and standard error of shape (len(NdotV), C).
    """
    check_mode(mode)
    samples = _check_samples(samples)
    if masking not in MASKING:
        raise ValueError(f"`masking` must be one of {', '.join(MASKING)}, got {masking!r}")
    mu_all = np.clip(np.atleast_1d(as_finite_array("NdotV", NdotV)).ravel(), 1.0e-4, 1.0)
    alpha_g = float(alpha_g_from_roughness(as_finite_array("roughness", roughness)))
    eta = max(float(as_finite_array("eta_i", eta_i)), 1.0)
    coat_alpha = float(alpha_g_from_roughness(as_finite_array("coat_roughness", coat_roughness)))
    rng = np.random.default_rng(int(seed))
    means, errors = [], []
    for mu in mu_all:
        v = np.array([np.sqrt(1.0 - mu * mu), 0.0, mu])
        sums = None
        for start in range(0, samples, _CHUNK):
            count = min(_CHUNK, samples - start)
            if mode == "immersed":
                VdotH, _, w = _lobe_draws(v, alpha_g, rng, count, masking)
                weights = w[:, None] * fresnel(VdotH)
            else:
                # The coat's own lobe, in air, dielectric Fresnel.
                VdotH_c, _, w_c = _lobe_draws(v, coat_alpha, rng, count, masking)
                coat = w_c * fresnel_dielectric(VdotH_c, 1.0, eta)
                # The base inside the coat, its light refracted back out.
                v_t = refract_into_coat(v, eta)
                VdotH, l_t, w = _lobe_draws(v_t, alpha_g, rng, count, masking)
                sin2_out = eta * eta * (l_t[:, 0] ** 2 + l_t[:, 1] ** 2)
                escapes = (sin2_out < 1.0) & (l_t[:, 2] > 0.0)
                mu_l = np.sqrt(np.clip(1.0 - sin2_out, 0.0, 1.0))
                T = (1.0 - fresnel_dielectric(mu, 1.0, eta)) * (1.0 - fresnel_dielectric(mu_l, 1.0, eta))
                base = np.where(escapes, T * w, 0.0)[:, None] * fresnel(VdotH)
                weights = coat[:, None] + base
            if sums is None:
                sums = np.zeros((2, weights.shape[1]))
            _accumulate(weights, sums)
        mean = sums[0] / samples
        variance = np.maximum(sums[1] / samples - mean * mean, 0.0) * samples / (samples - 1)
        means.append(mean)
        errors.append(np.sqrt(variance / samples))
    return AlbedoEstimate(np.array(means), np.array(errors), samples)


def model_directional_albedo(
    NdotV, roughness: float, parameters, samples: int = MC_SAMPLES, seed: int = 0
) -> AlbedoEstimate:
    """
    The ``immersed`` estimate of :func:`directional_albedo` with the model's
    Fresnel for many parameter sets at once: the same draws serve every set
    (each set's estimate is exactly what :func:`directional_albedo` gives
    for it with this seed).

    Parameters
    ----------
    parameters
        (M, 3, C) array of F0, a, alpha rows per set.

    Returns
    -------
    AlbedoEstimate
        Mean and standard error of shape (M, len(NdotV), C).
    """
    samples = _check_samples(samples)
    P = np.asarray(parameters, dtype=np.float64)
    if P.ndim != 3 or P.shape[1] != 3 or not np.all(np.isfinite(P)):
        raise ValueError(f"`parameters` must be finite with shape (M, 3, C), got {P.shape}")
    mu_all = np.clip(np.atleast_1d(as_finite_array("NdotV", NdotV)).ravel(), 1.0e-4, 1.0)
    alpha_g = float(alpha_g_from_roughness(as_finite_array("roughness", roughness)))
    rng = np.random.default_rng(int(seed))
    F0, a, alpha = (P[:, i, :][:, None, :] for i in range(3))
    means, errors = [], []
    for mu in mu_all:
        v = np.array([np.sqrt(1.0 - mu * mu), 0.0, mu])
        sums = np.zeros((2,) + F0.shape[::2])
        for start in range(0, samples, _CHUNK):
            count = min(_CHUNK, samples - start)
            VdotH, _, w = _lobe_draws(v, alpha_g, rng, count, "height-correlated")
            x = (1.0 - VdotH)[None, :, None]
            weights = w[None, :, None] * (
                F0 + (1.0 - F0) * x**5 - a * VdotH[None, :, None] * x ** np.maximum(alpha, ALPHA_MIN)
            )
            sums[0] += weights.sum(axis=1)
            sums[1] += (weights * weights).sum(axis=1)
        mean = sums[0] / samples
        variance = np.maximum(sums[1] / samples - mean * mean, 0.0) * samples / (samples - 1)
        means.append(mean)
        errors.append(np.sqrt(variance / samples))
    return AlbedoEstimate(np.stack(means, axis=1), np.stack(errors, axis=1), samples)


def rough_sphere_image(
    size: int,
    roughness: float,
    fresnel: Callable[[np.ndarray], np.ndarray],
    mode: str = "immersed",
    eta_i: float = 1.0,
    coat_roughness: float = 0.0,
    samples: int = 4096,
    seed: int = 0,
    masking: str = "height-correlated",
    NdotV_bins: int = 256,
) -> tuple[np.ndarray, np.ndarray]:
    """
    A ``size`` x ``size`` orthographic image of a rough sphere filling the
    frame under a white constant environment (radiance 1): each pixel's
    value is the directional albedo at its NdotV. The albedo is estimated at
    ``NdotV_bins`` cosines evenly in (0, 1] and interpolated linearly to the
    pixels (the albedo is smooth in NdotV; this keeps small images cheap).

    Returns
    -------
    tuple
        ``image`` (size, size, C) linear (0 off the sphere) and the boolean
        ``mask`` of the sphere's pixels.
    """
    if isinstance(size, bool) or not isinstance(size, (int, np.integer)) or not 4 <= size <= 1024:
        raise ValueError(f"`size` must be an integer in [4, 1024], got {size!r}")
    centres = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    x, y = np.meshgrid(centres, -centres)
    r2 = x * x + y * y
    mask = r2 < 1.0
    mu_pixels = np.sqrt(np.clip(1.0 - r2, 0.0, 1.0))
    mu_nodes = np.linspace(1.0 / NdotV_bins, 1.0, NdotV_bins)
    estimate = directional_albedo(mu_nodes, roughness, fresnel, mode, eta_i, coat_roughness, samples, seed, masking)
    image = np.zeros((size, size, estimate.mean.shape[1]))
    for c in range(image.shape[2]):
        image[..., c] = np.where(mask, np.interp(mu_pixels, mu_nodes, estimate.mean[:, c]), 0.0)
    return image, mask
