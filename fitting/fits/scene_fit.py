"""
Scene packs: the fits and the degree rule
=========================================

Each material of a scene (:mod:`fitting.fits.scene_schema`) is fitted over
the eta_i the scene uses, with the lowest polynomial degree that serves them
(:func:`choose_degree`), and compared with the general fit on the same
evaluation grid; see the module docstring of :mod:`fitting.fits.scene_schema`
for the rule in words.

-   :func:`fit_scene_material`: one material, a :class:`~fitting.fits.scene_report.SceneMaterialResult`.
-   :func:`fit_scene`: every material, a :class:`~fitting.fits.scene_report.SceneResult`.
-   :func:`choose_degree`, :func:`general_domain`: the rules.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics,
Eq. 1 and 2 (degree 0 is Eq. 1 with constant F0, a, alpha).
"""

from __future__ import annotations

import time

import numpy as np

from ..colour.reference import reference_ACEScg
from ..domain import DEFAULT_ETA_I_RANGE
from ..models.coated_conductor import coated_conductor_model
from ..models.pack import PackedMaterial
from .material import fit_material
from .metrics import ErrorMetrics, delta_E_summary
from .result import FitResult
from .scene_report import SceneMaterialResult, SceneResult
from .scene_schema import EVALUATION_MU_SAMPLES, EtaSpec, Scene, SceneMaterial
from .settings import FitSettings, fit_grid
from .solver import fit_coefficients

__all__ = [
    "DEGREE_TOLERANCE_MEAN",
    "DEGREE_TOLERANCE_MAX",
    "choose_degree",
    "general_domain",
    "fit_scene_material",
    "fit_scene",
]

DEGREE_TOLERANCE_MEAN = 0.05
"""A lower degree is kept if its mean Delta E 2000 is at most this much above
the highest degree's (a twentieth of a just-noticeable difference)."""


DEGREE_TOLERANCE_MAX = 0.5
"""... and its max Delta E 2000 at most this much above (half a JND)."""


def _error(ref: np.ndarray, model: np.ndarray, against: str) -> ErrorMetrics:
    return delta_E_summary(ref, model, against)


def _fit_degree(entry: SceneMaterial, degree: int, settings: FitSettings) -> FitResult:
    """The float16 fit of one candidate degree over the scene's eta_i."""
    spec = entry.eta_i
    if spec.kind != "set":
        return fit_material(entry.nk, spec.domain, settings, degree=degree)
    # A set: the fitting grid's rows are exactly the scene's values.
    t0 = time.perf_counter()
    rows = [fit_grid((v, v), settings.mu_samples, 1, settings.grid) for v in spec.values]
    mu, eta, weights = (np.concatenate(parts) for parts in zip(*rows))
    target = reference_ACEScg(entry.nk, mu, eta, settings.step_nm, settings.min_coverage)
    result = fit_coefficients(
        target, mu, eta, spec.domain, degree, settings.objective,
        settings.max_nfev, settings.quantise, weights=weights, irls_rounds=settings.irls_rounds,
    )
    result.packed = PackedMaterial(
        entry.name, result.coefficients_float16, spec.domain, source=entry.nk.source
    )
    result.timings["total"] = time.perf_counter() - t0
    return result


def choose_degree(
    by_degree: dict[int, ErrorMetrics], general_error: ErrorMetrics
) -> int:
    """
    The degree rule: the lowest degree whose mean Delta E is at most
    :data:`DEGREE_TOLERANCE_MEAN` above the highest degree's and no worse
    than the general fit's, and whose max is at most
    :data:`DEGREE_TOLERANCE_MAX` above the highest degree's; if none
    qualifies, the degree with the lowest mean.
    """
    top = by_degree[max(by_degree)]
    bound_mean = min(top.mean + DEGREE_TOLERANCE_MEAN, general_error.mean)
    for degree in sorted(by_degree):
        error = by_degree[degree]
        if error.mean <= bound_mean and error.max <= top.max + DEGREE_TOLERANCE_MAX:
            return degree
    return min(by_degree, key=lambda d: (by_degree[d].mean, d))


def general_domain(spec: EtaSpec) -> tuple[float, float]:
    """The default domain [1, 2.5] widened to hold the scene's eta_i."""
    lo, hi = spec.domain
    return (min(DEFAULT_ETA_I_RANGE[0], lo), max(DEFAULT_ETA_I_RANGE[1], hi))


def fit_scene_material(entry: SceneMaterial, settings: FitSettings | None = None) -> SceneMaterialResult:
    """
    Fit one scene material with the degree rule of the module docstring and
    score it against the general fit.

    Raises
    ------
    ValueError
        For data the fit refuses (e.g. too little visible coverage).
    """
    t0 = time.perf_counter()
    settings = settings or FitSettings()
    spec = entry.eta_i
    eta_rows = spec.evaluation_eta_i()
    mu = np.linspace(0.0, 1.0, EVALUATION_MU_SAMPLES)
    E, M = np.meshgrid(eta_rows, mu, indexing="ij")
    ref = reference_ACEScg(entry.nk, M, E, 1.0, settings.min_coverage)
    against = f"spectral reference 1 nm, {M.shape[1]} x {M.shape[0]} (cos theta x the scene's eta_i)"
    general_fit = fit_material(entry.nk, general_domain(spec), settings, degree=2)
    general = PackedMaterial(
        entry.name, general_fit.coefficients_float16, general_fit.eta_i_range,
        source=entry.nk.source,
    )
    general_model = coated_conductor_model(M, E, general.coefficients, general.eta_i_range)
    general_error = _error(ref, general_model, against)
    fits, by_degree = {}, {}
    for degree in range(spec.max_degree + 1):
        fit = _fit_degree(entry, degree, settings)
        fits[degree] = fit
        # Scored as shipped: float16 coefficients, the pack's float32 domain.
        by_degree[degree] = _error(
            ref, coated_conductor_model(M, E, fit.packed.coefficients, fit.packed.eta_i_range), against
        )
    chosen = choose_degree(by_degree, general_error)
    scene_error = by_degree[chosen]
    if scene_error.mean > general_error.mean:
        # No scene fit beats the general fit on the scene's eta_i (a narrow
        # range the general fit already follows as well as its own fit can):
        # the general fit itself serves it, never a worse one.
        packed = PackedMaterial(
            entry.name, general.coefficients, general.eta_i_range, source=entry.nk.source,
            metrics={"delta_E_2000": general_error.to_dict(), "eta_i": spec.to_json(),
                     "from_general_fit": True},
        )
        scene_error = general_error
    else:
        packed = PackedMaterial(
            entry.name, fits[chosen].packed.coefficients, spec.domain, source=entry.nk.source,
            metrics={"delta_E_2000": scene_error.to_dict(), "eta_i": spec.to_json(),
                     "from_general_fit": False},
        )
    fit = fits[chosen]
    scene_model = coated_conductor_model(M, E, packed.coefficients, packed.eta_i_range)
    return SceneMaterialResult(
        material=entry,
        packed=packed,
        fit=fit,
        general=general,
        by_degree=by_degree,
        scene=scene_error,
        general_error=general_error,
        scene_vs_general=_error(general_model, scene_model, "the general fit's model"),
        seconds=time.perf_counter() - t0,
    )


def fit_scene(scene: Scene, settings: FitSettings | None = None) -> SceneResult:
    """Fit every material of ``scene`` (see :func:`fit_scene_material`)."""
    result = SceneResult(scene)
    for entry in scene.materials:
        try:
            result.materials.append(fit_scene_material(entry, settings))
        except ValueError as error:
            raise ValueError(f"material {entry.name!r}: {error}") from None
    return result
