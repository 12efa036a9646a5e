"""
Scene packs: the fits and the degree rule
=========================================

Each material of a scene (:mod:`fitting.fits.scene_schema`) is fitted over
the eta_i the scene uses with every candidate kind and degree, each scored
where the scene looks (its set of eta_i, or its range) beside the general
fit, and the rule of :func:`choose_candidate` picks one; see the module
docstring of :mod:`fitting.fits.scene_schema` for the rule in words.

-   :func:`fit_scene_material`: one material, a :class:`~fitting.fits.scene_report.SceneMaterialResult`.
-   :func:`fit_scene`: every material, a :class:`~fitting.fits.scene_report.SceneResult`.
-   :data:`CANDIDATES`, :data:`GENERAL`, :func:`choose_candidate`: the
    model kind and degree, by default or for a scene's ``max_delta_e`` or
    ``prefer``; :func:`general_domain`: the general fit's domain.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics,
Eq. 1 and 2 (degree 0 is Eq. 1 with constant F0, a, alpha).
"""

from __future__ import annotations

import time

import numpy as np

from ..colour.colorimetry import ACEScg_to_Lab
from ..colour.delta_e import delta_E_2000
from ..colour.reference import reference_ACEScg_grid
from ..domain import DEFAULT_ETA_I_RANGE
from ..models.coated_conductor import coated_conductor_model
from ..models.kinds import DEFAULT_MODEL, model_ACEScg, model_kind
from ..models.pack import PackedMaterial
from .kinds import fit_kind
from .metrics import ErrorMetrics
from .pipeline import FitProblem, finish_fit, fit_problem, guard_problem, solve_problem
from .result import FitResult
from .scene_report import SceneMaterialResult, SceneResult
from .scene_schema import EVALUATION_MU_SAMPLES, EtaSpec, Scene, SceneMaterial
from .settings import FitSettings, fit_grid

__all__ = [
    "CANDIDATES",
    "GENERAL",
    "SCREEN",
    "choose_candidate",
    "general_domain",
    "fit_scene_material",
    "fit_scene",
]

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

GENERAL = ("general fit", 2)
"""The general fit (degree 2 over the default domain) as the dearest
candidate: as dear to shade as degree 2, and what a scene saves against."""


SCREEN = 1.25
"""A candidate whose fit of least mean (before its max is guarded) has a
mean Delta E 2000 on the scene's grid above this factor times the general
fit's is worse than the general fit: its guard is not run (the guard trades
mean for max: on the library's 22 conductors over three scenes each its
mean stayed within 0.4 % of the unguarded fit's, never 20 % under), and it
is reported with the unguarded figures, under ``choice["not_guarded"]``."""


def _label(kind: str, degree: int) -> str:
    if (kind, degree) == GENERAL:
        return kind
    return f"{kind} degree {degree}" if model_kind(kind).polynomial else kind


def _no_worse(a: ErrorMetrics, b: ErrorMetrics) -> bool:
    return a.mean <= b.mean and a.max <= b.max


def choose_candidate(
    errors: dict[tuple[str, int], ErrorMetrics], max_delta_e: float | None, prefer: str | None
) -> tuple[tuple[str, int], str]:
    """
    The (kind, degree) a scene material gets, and why, among ``errors``
    (the candidates of :data:`CANDIDATES` fitted, and :data:`GENERAL` when
    present), all scored on the scene's own evaluation grid. Only candidates
    no worse than the general fit on both mean and max compete (the general
    fit itself always does):

    -   default: the cheapest candidate no worse on mean and on max than
        every dearer candidate (the dearest always qualifies), so no
        candidate is passed over for its cost while it beats the one
        shipped on either figure;
    -   ``max_delta_e``: the cheapest whose mean Delta E 2000 is at most it,
        else as the default;
    -   ``prefer="accuracy"``: the lowest mean (the cheaper on a tie).
    """
    ordered = [c for c in (*CANDIDATES, GENERAL) if c in errors]
    if GENERAL in errors:
        ordered = [c for c in ordered if _no_worse(errors[c], errors[GENERAL])]
    worse = [c for c in errors if c not in ordered]
    note = "" if not worse else "; worse than the general fit on mean or max: " + ", ".join(_label(*c) for c in worse)
    if prefer == "accuracy":
        best = min(ordered, key=lambda c: errors[c].mean)
        return best, (
            f"prefer accuracy: {_label(*best)} has the lowest mean Delta E 2000 "
            f"({errors[best].mean:.4f}) of {len(ordered)} candidates{note}"
        )
    if max_delta_e is not None:
        for candidate in ordered:
            if errors[candidate].mean <= max_delta_e:
                cheaper = ordered[: ordered.index(candidate)]
                why = (
                    ""
                    if not cheaper
                    else "; cheaper candidates miss it: "
                    + ", ".join(f"{_label(*c)} {errors[c].mean:.4f}" for c in cheaper)
                )
                return candidate, (
                    f"max_delta_e {max_delta_e:g}: {_label(*candidate)} is the cheapest candidate "
                    f"within it (mean Delta E 2000 {errors[candidate].mean:.4f}){why}{note}"
                )
    for i, candidate in enumerate(ordered):
        if all(_no_worse(errors[candidate], errors[d]) for d in ordered[i + 1 :]):
            break
    head = f"max_delta_e {max_delta_e:g}: no candidate is within it; " if max_delta_e is not None else ""
    return candidate, (
        f"{head}{_label(*candidate)} is the cheapest candidate no worse on mean and max than every "
        f"dearer one (mean Delta E 2000 {errors[candidate].mean:.4f}, max "
        f"{errors[candidate].max:.4f}){note}"
    )


def _error(ref_Lab: np.ndarray, model: np.ndarray, against: str) -> ErrorMetrics:
    """:func:`fitting.fits.metrics.delta_E_summary` of ``model`` against a reference already in Lab."""
    dE = delta_E_2000(ref_Lab, ACEScg_to_Lab(model))
    return ErrorMetrics(mean=float(dE.mean()), max=float(dE.max()), against=against, layout="summary")


def _candidate_problem(entry: SceneMaterial, kind: str, settings: FitSettings) -> FitProblem:
    """
    The fitting problem of a candidate kind over the scene's eta_i (a set:
    the fitting grid's rows are exactly the scene's values), by the one
    pipeline (:mod:`fitting.fits.pipeline`), shared by the kind's degrees;
    ``settings`` are those of the default kind's fits, any other kind fits
    with its own.
    """
    spec = entry.eta_i
    if kind != DEFAULT_MODEL:
        settings = fit_kind(kind).settings
    samples = None
    if spec.kind == "set":
        rows = [fit_grid((v, v), settings.mu_samples, 1, settings.grid) for v in spec.values]
        samples = tuple(np.concatenate(parts) for parts in zip(*rows))
    return fit_problem(fit_kind(kind), entry.nk, spec.domain, settings, samples)


def general_domain(spec: EtaSpec) -> tuple[float, float]:
    """The default domain [1, 2.5] widened to hold the scene's eta_i."""
    lo, hi = spec.domain
    return (min(DEFAULT_ETA_I_RANGE[0], lo), max(DEFAULT_ETA_I_RANGE[1], hi))


def fit_scene_material(
    entry: SceneMaterial,
    settings: FitSettings | None = None,
    max_delta_e: float | None = None,
    prefer: str | None = None,
) -> SceneMaterialResult:
    """
    Fit one scene material: every candidate of :data:`CANDIDATES` (the
    coated-conductor of each degree the scene's eta_i allow, the
    rgb-conductor) over the scene's eta_i, each scored as shipped on the
    scene's evaluation grid beside the general fit (:data:`GENERAL`), and
    the one :func:`choose_candidate` picks for ``max_delta_e`` / ``prefer``
    shipped (the general fit itself when it is chosen).

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
    ref_Lab = ACEScg_to_Lab(reference_ACEScg_grid(entry.nk, mu, eta_rows, 1.0, settings.min_coverage))
    against = f"spectral reference 1 nm, {M.shape[1]} x {M.shape[0]} (cos theta x the scene's eta_i)"

    def score(fit: FitResult) -> ErrorMetrics:
        # Scored as shipped: float16 coefficients, the pack's float32 domain.
        return _error(ref_Lab, model_ACEScg(fit.model, M, E, fit.packed.coefficients, fit.packed.eta_i_range), against)

    # Every fit is assessed (range proof, data uncertainty) only once shipped.
    problems = {GENERAL: fit_problem(fit_kind(DEFAULT_MODEL), entry.nk, general_domain(spec), settings, degree=2)}
    general_fit = finish_fit(
        problems[GENERAL], guard_problem(problems[GENERAL], solve_problem(problems[GENERAL])), False
    )
    general = PackedMaterial(
        entry.name,
        general_fit.coefficients_float16,
        general_fit.eta_i_range,
        source=entry.nk.source,
    )
    general_model = coated_conductor_model(M, E, general.coefficients, general.eta_i_range)
    general_error = _error(ref_Lab, general_model, against)
    fits, by_degree, errors, not_guarded = {}, {}, {GENERAL: general_error}, []
    shared: dict[str, FitProblem] = {}
    for candidate in CANDIDATES:
        kind, degree = candidate
        polynomial = model_kind(kind).polynomial
        if polynomial and degree > spec.max_degree:
            continue
        if kind not in shared:
            shared[kind] = _candidate_problem(entry, kind, settings)
        problem = problems[candidate] = shared[kind].with_degree(degree) if polynomial else shared[kind]
        fit = finish_fit(problem, solve_problem(problem), False)
        error = score(fit)
        if problem.guarded and error.mean > SCREEN * general_error.mean:
            not_guarded.append(candidate)
        else:
            guarded = finish_fit(problem, guard_problem(problem, fit), False)
            # The guard keeps the mean fit where it is no worse: the same coefficients, the same score.
            if not np.array_equal(guarded.coefficients_float16, fit.coefficients_float16):
                error = score(guarded)
            fit = guarded
        fits[candidate], errors[candidate] = fit, error
        if kind == DEFAULT_MODEL:
            by_degree[degree] = errors[candidate]
    fits[GENERAL] = general_fit
    candidate, reason = choose_candidate(errors, max_delta_e, prefer)
    rule = (
        "prefer accuracy"
        if prefer == "accuracy"
        else f"max_delta_e {max_delta_e:g}"
        if max_delta_e is not None
        else "no dearer one better"
    )
    choice = {
        "rule": rule,
        "model": DEFAULT_MODEL if candidate == GENERAL else candidate[0],
        "degree": candidate[1],
        "from_general_fit": candidate == GENERAL,
        "reason": reason,
        "candidates": {_label(*c): errors[c].to_dict() for c in (*CANDIDATES, GENERAL) if c in errors},
        "not_guarded": [_label(*c) for c in not_guarded],
    }
    scene_error, fit = errors[candidate], finish_fit(problems[candidate], fits[candidate])
    if candidate == GENERAL:
        packed = PackedMaterial(
            entry.name,
            general.coefficients,
            general.eta_i_range,
            source=entry.nk.source,
            metrics={"delta_E_2000": general_error.to_dict(), "eta_i": spec.to_json(), "from_general_fit": True},
        )
    else:
        packed = PackedMaterial(
            entry.name,
            fit.packed.coefficients,
            spec.domain,
            source=entry.nk.source,
            metrics={"delta_E_2000": scene_error.to_dict(), "eta_i": spec.to_json(), "from_general_fit": False},
            model=candidate[0],
        )
    scene_model = model_ACEScg(packed.model, M, E, packed.coefficients, packed.eta_i_range)
    return SceneMaterialResult(
        material=entry,
        packed=packed,
        fit=fit,
        general=general,
        by_degree=by_degree,
        scene=scene_error,
        general_error=general_error,
        scene_vs_general=_error(ACEScg_to_Lab(general_model), scene_model, "the general fit's model"),
        seconds=time.perf_counter() - t0,
        choice=choice,
    )


def fit_scene(scene: Scene, settings: FitSettings | None = None) -> SceneResult:
    """Fit every material of ``scene`` (see :func:`fit_scene_material`)."""
    result = SceneResult(scene)
    for entry in scene.materials:
        try:
            result.materials.append(fit_scene_material(entry, settings, scene.max_delta_e, scene.prefer))
        except ValueError as error:
            raise ValueError(f"material {entry.name!r}: {error}") from None
    return result
