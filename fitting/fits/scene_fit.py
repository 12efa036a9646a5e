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
-   :data:`CANDIDATES`, :func:`choose_candidate`: the model kind and degree
    for a scene's ``max_delta_e`` or ``prefer``.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics,
Eq. 1 and 2 (degree 0 is Eq. 1 with constant F0, a, alpha).
"""

from __future__ import annotations

import time

import numpy as np

from ..colour.reference import reference_ACEScg_grid
from ..domain import DEFAULT_ETA_I_RANGE
from ..models.coated_conductor import coated_conductor_model
from ..models.kinds import DEFAULT_MODEL, model_ACEScg, model_kind
from ..models.pack import PackedMaterial
from .kinds import fit_kind, fit_model
from .metrics import ErrorMetrics, delta_E_summary
from .result import FitResult
from .scene_report import SceneMaterialResult, SceneResult
from .scene_schema import EVALUATION_MU_SAMPLES, EtaSpec, Scene, SceneMaterial
from .settings import FitSettings, fit_grid

__all__ = [
    "DEGREE_TOLERANCE_MEAN",
    "DEGREE_TOLERANCE_MAX",
    "CANDIDATES",
    "choose_degree",
    "choose_candidate",
    "general_domain",
    "fit_scene_material",
    "fit_scene",
]

DEGREE_TOLERANCE_MEAN = 0.05
"""A lower degree is kept if its mean Delta E 2000 is at most this much above
the highest degree's (a twentieth of a just-noticeable difference)."""


DEGREE_TOLERANCE_MAX = 0.5
"""... and its max Delta E 2000 at most this much above (half a JND)."""


CANDIDATES = (
    ("coated-conductor", 0),
    ("rgb-conductor", 0),
    ("coated-conductor", 1),
    ("coated-conductor", 2),
)
"""(kind, degree) from the cheapest to the dearest to shade. Shader cost
relative to adjusted Lazanyi on llvmpipe (docs/speed-vs-error.md): a degree-0
coated-conductor is Eq. 1 with constant parameters (9 halves, 1.04x); the
rgb-conductor a complex square root per channel (6 halves, 1.60x); degrees 1
and 2 the general model's polynomial in t (18 and 27 halves, 2.9x), degree 1
first for its fewer bytes."""


def _label(kind: str, degree: int) -> str:
    return f"{kind} degree {degree}" if model_kind(kind).polynomial else kind


def choose_candidate(
    errors: dict[tuple[str, int], ErrorMetrics], max_delta_e: float | None, prefer: str | None
) -> tuple[tuple[str, int], str]:
    """
    The (kind, degree) a scene material gets, and why: with ``max_delta_e``
    the first of :data:`CANDIDATES` (among ``errors``) whose mean Delta E
    2000 is at most it, else the most accurate; with ``prefer="accuracy"``
    the most accurate (lowest mean, the cheaper on a tie).
    """
    ordered = [c for c in CANDIDATES if c in errors]
    best = min(ordered, key=lambda c: errors[c].mean)
    if prefer == "accuracy":
        return best, (
            f"prefer accuracy: {_label(*best)} has the lowest mean Delta E 2000 "
            f"({errors[best].mean:.4f}) of {len(ordered)} candidates"
        )
    for candidate in ordered:
        if errors[candidate].mean <= max_delta_e:
            cheaper = ordered[: ordered.index(candidate)]
            why = "" if not cheaper else "; cheaper candidates miss it: " + ", ".join(
                f"{_label(*c)} {errors[c].mean:.4f}" for c in cheaper
            )
            return candidate, (
                f"max_delta_e {max_delta_e:g}: {_label(*candidate)} is the cheapest candidate within it "
                f"(mean Delta E 2000 {errors[candidate].mean:.4f}){why}"
            )
    return best, (
        f"max_delta_e {max_delta_e:g}: no candidate is within it; {_label(*best)} is the most "
        f"accurate (mean Delta E 2000 {errors[best].mean:.4f})"
    )


def _error(ref: np.ndarray, model: np.ndarray, against: str) -> ErrorMetrics:
    return delta_E_summary(ref, model, against)


def _fit_candidate(entry: SceneMaterial, kind: str, degree: int, settings: FitSettings) -> FitResult:
    """
    The float16 fit of one candidate (kind, degree) over the scene's eta_i
    (a set: the fitting grid's rows are exactly the scene's values), by the
    one pipeline (:func:`fitting.fits.kinds.fit_model`); ``settings`` are
    those of the default kind's fits, any other kind fits with its own.
    """
    spec = entry.eta_i
    if kind != DEFAULT_MODEL:
        settings = fit_kind(kind).settings
    samples = None
    if spec.kind == "set":
        rows = [fit_grid((v, v), settings.mu_samples, 1, settings.grid) for v in spec.values]
        samples = tuple(np.concatenate(parts) for parts in zip(*rows))
    extra = {"degree": degree} if model_kind(kind).polynomial else {}
    return fit_model(entry.nk, spec.domain, kind, settings, samples=samples, **extra)


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


def fit_scene_material(
    entry: SceneMaterial, settings: FitSettings | None = None,
    max_delta_e: float | None = None, prefer: str | None = None,
) -> SceneMaterialResult:
    """
    Fit one scene material with the degree rule of the module docstring, or
    with ``max_delta_e`` / ``prefer`` the kind and degree of
    :func:`choose_candidate`, and score it against the general fit.

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
    # The product-grid kernel of the fits' own reference: the same values as
    # reference_ACEScg sample by sample (to 1e-14), a fraction of the cost.
    ref = reference_ACEScg_grid(entry.nk, mu, eta_rows, 1.0, settings.min_coverage)
    against = f"spectral reference 1 nm, {M.shape[1]} x {M.shape[0]} (cos theta x the scene's eta_i)"
    general_fit = fit_model(entry.nk, general_domain(spec), DEFAULT_MODEL, settings, degree=2)
    general = PackedMaterial(
        entry.name, general_fit.coefficients_float16, general_fit.eta_i_range,
        source=entry.nk.source,
    )
    general_model = coated_conductor_model(M, E, general.coefficients, general.eta_i_range)
    general_error = _error(ref, general_model, against)
    fits, by_degree = {}, {}
    for degree in range(spec.max_degree + 1):
        fit = _fit_candidate(entry, DEFAULT_MODEL, degree, settings)
        fits[degree] = fit
        # Scored as shipped: float16 coefficients, the pack's float32 domain.
        by_degree[degree] = _error(
            ref, coated_conductor_model(M, E, fit.packed.coefficients, fit.packed.eta_i_range), against
        )
    choice, others = None, {}
    if max_delta_e is not None or prefer is not None:
        errors = {(DEFAULT_MODEL, d): e for d, e in by_degree.items()}
        for candidate in CANDIDATES:
            if candidate[0] != DEFAULT_MODEL:
                other = others[candidate] = _fit_candidate(entry, *candidate, settings)
                errors[candidate] = _error(ref, model_ACEScg(
                    candidate[0], M, E, other.packed.coefficients, other.packed.eta_i_range), against)
        (kind, chosen), reason = choose_candidate(errors, max_delta_e, prefer)
        choice = {
            "rule": "prefer accuracy" if prefer == "accuracy" else f"max_delta_e {max_delta_e:g}",
            "model": kind, "degree": chosen, "reason": reason,
            "candidates": {_label(*c): errors[c].to_dict() for c in CANDIDATES if c in errors},
        }
    else:
        chosen = choose_degree(by_degree, general_error)
    scene_error = by_degree[chosen]
    if choice is not None and (kind, chosen) in others:
        fits[chosen] = others[(kind, chosen)]
        scene_error = errors[(kind, chosen)]
        packed = PackedMaterial(
            entry.name, fits[chosen].packed.coefficients, spec.domain, source=entry.nk.source,
            metrics={"delta_E_2000": scene_error.to_dict(), "eta_i": spec.to_json(),
                     "from_general_fit": False},
            model=kind,
        )
    elif choice is None and scene_error.mean > general_error.mean:
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
    scene_model = model_ACEScg(packed.model, M, E, packed.coefficients, packed.eta_i_range)
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
        choice=choice,
    )


def fit_scene(scene: Scene, settings: FitSettings | None = None) -> SceneResult:
    """Fit every material of ``scene`` (see :func:`fit_scene_material`)."""
    result = SceneResult(scene)
    for entry in scene.materials:
        try:
            result.materials.append(
                fit_scene_material(entry, settings, scene.max_delta_e, scene.prefer)
            )
        except ValueError as error:
            raise ValueError(f"material {entry.name!r}: {error}") from None
    return result
