"""
Spectral ground truth from Mitsuba 3
====================================

Rough-sphere images from a spectral renderer no one here wrote, as the
paper's reference images came from pbrt-v4: Mitsuba 3 (variant
``scalar_spectral`` only: its LLVM variants crash on this machine), a
``roughconductor`` sphere (GGX, :math:`\\alpha = r^2`, Mitsuba's separable
Smith masking) with the measured :math:`n/\\eta_i` and :math:`k/\\eta_i` as
spectra (the immersed set-up: everything in the medium of index eta_i),
under a constant environment whose spectrum is the project's reference
illuminant (the CIE D series at the ACES white, D60; see
:mod:`fitting.colour.colorimetry`), rendered to an XYZ film and converted to
linear ACEScg the way the reference pipeline converts (CAT02 from the
illuminant's white to the ACEScg white, then the ACEScg matrix, each row
normalised so that a perfect reflector, here the environment seen directly,
maps to (1, 1, 1)).

-   :func:`mitsuba_rough_sphere`: the image, its sphere mask and the per-pixel
    NdotV.

References
----------
Jakob, W., Speierer, S., Roussel, N., et al. (2022). Mitsuba 3 renderer.
https://mitsuba-renderer.org
"""

from __future__ import annotations

import numpy as np

from ..colour.colorimetry import ACES_WHITE_XY, colour_science
from ..domain import DEFAULT_MIN_COVERAGE, check_eta_i, check_int
from ..optics.nk import SpectralNK, resample_nk

__all__ = ["mitsuba_rough_sphere", "XYZ_to_ACEScg_matrix"]

_LAMBDA = np.arange(360.0, 831.0, 5.0)
"""Nodes of the spectra handed to Mitsuba (it interpolates linearly)."""


def _spectrum(values: np.ndarray) -> dict:
    return {
        "type": "irregular",
        "wavelengths": ",".join(f"{x:g}" for x in _LAMBDA),
        "values": ",".join(f"{v:.9g}" for v in values),
    }


def XYZ_to_ACEScg_matrix(XYZ_white) -> np.ndarray:
    """
    3 x 3 matrix from the renderer's XYZ to linear ACEScg: CAT02 from
    ``XYZ_white`` (the illuminant as the film integrates it) to the ACEScg
    white, the ACEScg matrix, rows scaled so that ``XYZ_white`` maps to
    (1, 1, 1) (as :func:`fitting.colour.colorimetry.spectral_to_ACEScg_weights`).
    """
    colour = colour_science()
    acescg = colour.RGB_COLOURSPACES["ACEScg"]
    XYZ_w = np.asarray(XYZ_white, dtype=np.float64)
    XYZ_wr = acescg.matrix_RGB_to_XYZ @ np.ones(3)
    cat = colour.adaptation.matrix_chromatic_adaptation_VonKries(XYZ_w / XYZ_w[1], XYZ_wr, transform="CAT02")
    M = acescg.matrix_XYZ_to_RGB @ cat
    return M / (M @ XYZ_w)[:, None]


def mitsuba_rough_sphere(
    nk: SpectralNK,
    eta_i: float,
    roughness: float,
    size: int = 32,
    spp: int = 64,
    seed: int = 0,
    min_coverage: float = DEFAULT_MIN_COVERAGE,
):
    """
    A ``size`` x ``size`` orthographic image of a unit sphere filling the
    frame (pixel centres as :func:`fitting.shading.monte_carlo.rough_sphere_image`),
    rendered by Mitsuba 3 ``scalar_spectral`` with ``spp`` samples per pixel,
    a box pixel filter and paths of depth 2 (the sphere is convex: one
    bounce to the environment).

    Returns
    -------
    tuple
        ``image`` (size, size, 3) linear ACEScg, ``mask`` of the pixels whose
        centre is on the sphere, and ``NdotV`` at the pixel centres.
    """
    import mitsuba as mi

    mi.set_variant("scalar_spectral")
    eta_i = check_eta_i(eta_i)
    size = check_int("size", size, 4, 512)
    spp = check_int("spp", spp, 1, 1 << 16)
    r = float(np.clip(roughness, 0.0, 1.0))
    sampled = resample_nk(nk, _LAMBDA, min_coverage)
    colour = colour_science()
    D60 = colour.sd_CIE_illuminant_D_series(ACES_WHITE_XY).copy().align(colour.SpectralShape(360, 830, 5))
    illuminant = D60.values / D60.values.mean()
    scene = mi.load_dict(
        {
            "type": "scene",
            "integrator": {"type": "path", "max_depth": 2},
            "sensor": {
                "type": "orthographic",
                "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 5], target=[0, 0, 0], up=[0, 1, 0]),
                "film": {
                    "type": "hdrfilm",
                    "width": size,
                    "height": size,
                    "pixel_format": "xyz",
                    "rfilter": {"type": "box"},
                },
                "sampler": {"type": "independent", "sample_count": spp, "seed": int(seed)},
            },
            "emitter": {"type": "constant", "radiance": _spectrum(illuminant)},
            "sphere": {
                "type": "sphere",
                "bsdf": {
                    "type": "roughconductor",
                    "distribution": "ggx",
                    "alpha": max(r * r, 1e-4),
                    "eta": _spectrum(sampled.n / eta_i),
                    "k": _spectrum(sampled.k / eta_i),
                },
            },
        }
    )
    XYZ = np.array(mi.render(scene), dtype=np.float64)
    # The environment seen directly is the white of the XYZ film. Each
    # sample has one random wavelength, so the white is averaged over 2^20
    # samples (chromatic noise ~1e-3, below the sphere's own noise).
    white = mi.render(
        mi.load_dict(
            {
                "type": "scene",
                "integrator": {"type": "path", "max_depth": 1},
                "sensor": {
                    "type": "orthographic",
                    "film": {"type": "hdrfilm", "width": 64, "height": 64, "pixel_format": "xyz"},
                    "sampler": {"type": "independent", "sample_count": 256, "seed": int(seed) + 1},
                },
                "emitter": {"type": "constant", "radiance": _spectrum(illuminant)},
            }
        )
    )
    M = XYZ_to_ACEScg_matrix(np.array(white, dtype=np.float64).reshape(-1, 3).mean(axis=0))
    image = XYZ @ M.T
    centres = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    x, y = np.meshgrid(centres, -centres)
    r2 = x * x + y * y
    return image, r2 < 1.0, np.sqrt(np.clip(1.0 - r2, 0.0, 1.0))
