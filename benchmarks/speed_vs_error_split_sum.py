"""
Speed against error: the split-sum variants
===========================================

The split-sum variants of image-based lighting (``fitting.shading.ibl``, the
default 16 x 64 x 64 LUT; GLSL ``cf_ibl.glsl`` through ``glsl/ibl.frag``) on
the speed-against-error plane, for ``benchmarks/speed_vs_error.py``.

Error: Delta E 2000 of the specular directional albedo E(NdotV) of the GGX
lobe (height-correlated Smith, immersed: the medium of index eta_i above
the metal) against the same albedo with the exact spectral Fresnel of the
measured n, k (:func:`preview_shaders.rough.reference_albedo_table`: 1 nm,
the LUT's quadrature with 2048 Hammersley points, interpolated in NdotV), on
the 22 library conductors, eta_i :data:`SPLIT_ETA_I`, roughness
:data:`SPLIT_ROUGHNESS` and NdotV :data:`SPLIT_NDOTV`. Each variant reads the
LUT as a renderer does; its error is its Fresnel's error seen through the
lobe plus the LUT's interpolation.

Cost: full-screen 2560 x 1440 passes of ``glsl/ibl.frag``
(:func:`preview_shaders.shading.time_split_sum`, variants interleaved) and
numpy per sample.

-   :data:`SPLIT_VARIANTS`: name to (label, ``ibl.frag`` pass, LUT fetches).
-   :data:`KIND_SPLIT_SUM`: each model kind's split-sum variant, or None.
-   :func:`split_sum_albedos`: every variant's albedo and the reference at
    one (eta_i, roughness).
-   :func:`split_sum_errors`: their Delta E 2000 maps for one conductor.
-   :func:`split_sum_table`: the summary over conductors.
-   :func:`split_sum_cpu_ns`, :func:`split_sum_shader_us`: the costs.

The ``coated`` split sum (:func:`fitting.shading.ibl.split_sum_coated`) is an
approximation whose error is against the coated Monte Carlo, not the
spectral reference (docs/shading.md, ``benchmarks/coated_split_sum.py``); it
is not on this plane.
"""

from __future__ import annotations

import time

import numpy as np

from fitting.colour.delta_e import delta_E_map
from fitting.colour.reference import reference_ACEScg
from fitting.fits.kinds import fit_model
from fitting.models.baselines import baseline_inputs, external_medium_F0, lazanyi_a
from fitting.models.coated_conductor import collapse_to_eta_i
from fitting.models.kinds import MODEL_KINDS
from fitting.optics.library import LIBRARY_NAMES, library_material
from fitting.shading.ibl import default_lut, split_sum_lazanyi, split_sum_model, split_sum_schlick
from preview_shaders.rough import reference_albedo_table

from benchmarks.speed_vs_error_report import error_summary

__all__ = [
    "SPLIT_ETA_I",
    "SPLIT_ROUGHNESS",
    "SPLIT_NDOTV",
    "SPLIT_VARIANTS",
    "KIND_SPLIT_SUM",
    "split_sum_albedos",
    "split_sum_errors",
    "split_sum_table",
    "split_sum_cpu_ns",
    "split_sum_shader_us",
]

SPLIT_ETA_I = (1.0, 1.5, 2.0, 2.5)
SPLIT_ROUGHNESS = (0.1, 0.3, 0.6, 1.0)
SPLIT_NDOTV = (np.arange(32) + 0.5) / 32
"""32 NdotV, evenly over (0, 1) as cos theta is on the Fresnel grid."""

SPLIT_VARIANTS = {
    # name: (label, CF_IBL_PASS variant of glsl/ibl.frag, LUT fetches per pixel)
    "split_sum_model": ("split sum, coated-conductor kind (ours, float16)", "split_sum_model", 24),
    "split_sum_lazanyi": ("split sum, adjusted Lazanyi", "split_sum_lazanyi", 8),
    "split_sum_schlick_air": ("split sum, Schlick, air F0", "split_sum_schlick", 8),
    "split_sum_schlick_exact_F0": ("split sum, Schlick, exact F0", "split_sum_schlick", 8),
}

KIND_SPLIT_SUM = {name: "split_sum_model" if kind.split_sum else None for name, kind in MODEL_KINDS.items()}
"""Each model kind's split-sum variant; None: the kind has no split-sum
table (its Fresnel is not linear in a few parameters the LUT could hold;
the rough preview refuses it, docs/shading.md)."""


def split_sum_albedos(
    nk, coefficients, eta_i_range, eta_i: float, roughness: float, NdotV=SPLIT_NDOTV, air=None, lut=None
) -> dict[str, np.ndarray]:
    """
    The directional albedo (len(NdotV), 3), linear ACEScg, of the spectral
    ``reference`` and of every :data:`SPLIT_VARIANTS` entry at one eta_i
    and roughness; ``coefficients``: the coated-conductor kind's float16
    fit over ``eta_i_range``; ``air``: :func:`fitting.models.baselines.baseline_inputs`
    of ``nk`` (computed when None).
    """
    lut = lut or default_lut()
    air = baseline_inputs(nk) if air is None else air
    mu = np.asarray(NdotV, dtype=np.float64)
    nodes, E = reference_albedo_table(nk, eta_i, roughness)
    F0, a, alpha = collapse_to_eta_i(np.asarray(coefficients, dtype=np.float64), eta_i, eta_i_range)[..., 0]
    return {
        "reference": np.stack([np.interp(mu, nodes, E[:, c]) for c in range(3)], axis=-1),
        "split_sum_model": split_sum_model(mu, roughness, F0, a, alpha, lut),
        "split_sum_lazanyi": split_sum_lazanyi(mu, roughness, eta_i, air["F0_air"], air["F82_air"], lut),
        "split_sum_schlick_air": split_sum_schlick(mu, roughness, air["F0_air"], lut),
        "split_sum_schlick_exact_F0": split_sum_schlick(mu, roughness, reference_ACEScg(nk, 1.0, eta_i), lut),
    }


def split_sum_errors(
    name: str, eta_i=SPLIT_ETA_I, roughness=SPLIT_ROUGHNESS, NdotV=SPLIT_NDOTV
) -> dict[str, np.ndarray]:
    """Delta E 2000 of every split-sum variant against the reference for library conductor
    ``name``, each (len(eta_i), len(roughness), len(NdotV))."""
    nk = library_material(name)
    fit = fit_model(nk, model="coated-conductor")
    air = baseline_inputs(nk)
    out = {v: np.empty((len(eta_i), len(roughness), len(NdotV))) for v in SPLIT_VARIANTS}
    for i, eta in enumerate(eta_i):
        for j, r in enumerate(roughness):
            albedo = split_sum_albedos(nk, fit.coefficients_float16, fit.eta_i_range, float(eta), float(r), NdotV, air)
            for v in SPLIT_VARIANTS:
                out[v][i, j] = delta_E_map(albedo["reference"], albedo[v])
    return out


def split_sum_table(
    names=LIBRARY_NAMES, eta_i=SPLIT_ETA_I, roughness=SPLIT_ROUGHNESS, NdotV=SPLIT_NDOTV
) -> dict[str, dict]:
    """Per variant: :func:`error_summary` over the conductors, and
    ``by_roughness`` (the mean over conductors, eta_i and NdotV at each roughness)."""
    errors = {name: split_sum_errors(name, eta_i, roughness, NdotV) for name in names}
    rows = {}
    for v in SPLIT_VARIANTS:
        per_material = {name: errors[name][v] for name in names}
        stacked = np.stack(list(per_material.values()))
        rows[v] = {**error_summary(per_material), "by_roughness": stacked.mean(axis=(0, 1, 3)).tolist()}
    return rows


def _au_inputs():
    nk = library_material("Au")
    fit = fit_model(nk, model="coated-conductor")
    air = baseline_inputs(nk)
    F0, a, alpha = collapse_to_eta_i(fit.coefficients_float16.astype(np.float64), 1.5, fit.eta_i_range)[..., 0]
    return nk, air, (F0, a, alpha)


def split_sum_cpu_ns(repeats: int = 3, count: int = 100_000) -> dict[str, float]:
    """numpy cost (ns) per (NdotV, roughness) sample of each variant, Au at eta_i 1.5, median of
    ``repeats``."""
    nk, air, (F0, a, alpha) = _au_inputs()
    lut = default_lut()
    rng = np.random.default_rng(0)
    mu, r = rng.uniform(0, 1, count), rng.uniform(0, 1, count)
    F0_exact = reference_ACEScg(nk, 1.0, 1.5)
    calls = {
        "split_sum_model": lambda: split_sum_model(mu, r, F0, a, alpha, lut),
        "split_sum_lazanyi": lambda: split_sum_lazanyi(mu, r, 1.5, air["F0_air"], air["F82_air"], lut),
        "split_sum_schlick_air": lambda: split_sum_schlick(mu, r, air["F0_air"], lut),
        "split_sum_schlick_exact_F0": lambda: split_sum_schlick(mu, r, F0_exact, lut),
    }
    out = {}
    for name, call in calls.items():
        times = []
        for _ in range(repeats):
            start = time.perf_counter()
            call()
            times.append(time.perf_counter() - start)
        out[name] = float(np.median(times)) / count * 1e9
    return out


def split_sum_shader_us(repeats: int, width: int, height: int) -> dict[str, float]:
    """Median wall time (us) of each ``glsl/ibl.frag`` timing pass (model, adjusted Lazanyi,
    Schlick, and ``split_sum_fixed``, the pass with no split sum), Au at eta_i 1.5 as
    ``benchmarks/shader_cost.py`` feeds them."""
    from preview_shaders.gl import RenderThread
    from preview_shaders.shading import time_split_sum

    _, air, (F0, a, alpha) = _au_inputs()
    with RenderThread("speed-vs-error-split-sum") as thread:
        samples = time_split_sum(
            thread,
            default_lut(),
            F0,
            a,
            alpha,
            external_medium_F0(air["F0_air"], 1.5),
            lazanyi_a(air["F0_air"], air["F82_air"]),
            air["F0_air"],
            width,
            height,
            repeats,
        )
    return {v: float(np.median(s[:, 1])) * 1e6 for v, s in samples.items()}
