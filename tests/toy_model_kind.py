"""
A toy model kind, added as this one file: Schlick's approximation with a
constant F0 per channel (3 float16), ``F = F0 + (1 - F0)(1 - mu)^5``,
drawn by the shared ``cf_schlick`` of ``cf_fresnel_baselines.glsl``. It
registers its :class:`~fitting.models.kinds.ModelKind` and its fit when
imported; a test loads it into the CLI and the service with
``COATED_PLUGINS=tests/toy_model_kind.py`` (tests/static/test_toy_model_kind_served.py).
It has no download templates: the GLSL and HLSL snippets are refused for it.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.optimize import least_squares

from fitting.fits.kinds import register_fit_kind
from fitting.fits.pipeline import FitKind
from fitting.fits.result import FitResult
from fitting.fits.settings import FitSettings
from fitting.models.kinds import ModelKind, register_model_kind
from fitting.models.pack import to_float16

NAME = "toy-schlick"


def check_toy(coefficients) -> np.ndarray:
    C = np.asarray(coefficients, dtype=np.float64)
    if C.shape != (1, 3) or not np.all(np.isfinite(C)) or not np.all((C >= 0) & (C <= 1)):
        raise ValueError(f"`coefficients` of a {NAME} must be (1, 3) in [0, 1], got shape {C.shape}")
    return C


def toy_model(cos_theta, eta_i, coefficients, eta_i_range) -> np.ndarray:
    F0 = np.asarray(coefficients, dtype=np.float64)[0]
    mu = np.clip(np.broadcast_arrays(np.asarray(cos_theta, dtype=np.float64), np.asarray(eta_i))[0], 0.0, 1.0)
    return F0 + (1.0 - F0) * (1.0 - mu[..., None]) ** 5


def toy_solve(
    target, mu, eta, eta_i_range, degree, objective, max_nfev, quantise, weights=None, irls_rounds=2, **extra
) -> FitResult:
    """Least squares of F0 in linear ACEScg (the toy ignores the objective and the coating)."""
    t0 = time.perf_counter()
    w = np.sqrt(np.ones(len(mu)) if weights is None else np.asarray(weights))[:, None]
    solution = least_squares(
        lambda x: ((toy_model(mu, eta, x[None, :], eta_i_range) - target) * w).ravel(),
        np.full(3, 0.5),
        bounds=(0.0, 1.0),
        max_nfev=max_nfev,
    )
    C = solution.x[None, :]
    C16 = to_float16(C)
    residual = (toy_model(mu, eta, C16.astype(np.float64), eta_i_range) - target) * w
    return FitResult.from_solve(
        solution,
        C,
        C16,
        eta_i_range,
        0,
        objective,
        solution.nfev,
        solution.njev or 0,
        0.5 * float(np.sum(residual**2)),
        {"fit": time.perf_counter() - t0, "quantise": 0.0},
        model=NAME,
    )


register_model_kind(
    ModelKind(
        name=NAME,
        code=200,
        description="toy: Schlick with a constant F0 per channel",
        parameters=("F0",),
        max_degree=0,
        check=check_toy,
        evaluate=toy_model,
        glsl_file="cf_fresnel_baselines.glsl",
        hlsl_file="cf_toy_schlick.hlsl",
        glsl_function="cf_schlick",
        preview_call="cf_schlick(NdotV, vec3(unpackHalf2x16(words[0]), unpackHalf2x16(words[1]).x))",
        material_template="material_toy_schlick",
    )
)
register_fit_kind(FitKind(name=NAME, settings=FitSettings(), solve=toy_solve, bounded=True))
