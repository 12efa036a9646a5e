"""
Fits from edited reflectance curves
===================================

Artistic control over a material (Vernooij 2024, Section 6, "a curve editor,
allowing modifications to the RGB reflectance dataset, and subsequently
fitting coefficients to the adjusted data"): RGB reflectance curves against
cos theta, at one or more coating indices eta_i, in linear ACEScg, fitted by
the coated-conductor model (:mod:`fitting.models.coated_conductor`) or, with
``model="rgb-conductor"``, by the exact Fresnel of a per-channel relative
index (:mod:`fitting.models.rgb_conductor`: always a reflectance in [0, 1],
so it needs no range constraint).

-   The curves: :mod:`fitting.fits.curves_input` (:class:`RGBCurve`,
    :func:`check_curves`).
-   The base and the blending of edits: :mod:`fitting.fits.curves_base`
    (:class:`CurveBase`, :func:`blend_weights`, :func:`edited_target`).
-   :func:`fit_curves`: the fit, its float16 pack and its Delta E 2000
    against the edited curves.
-   :class:`CurveFitSettings`: sampling and solver settings of
    :func:`fit_curves` (defaults measured by ``benchmarks/curves_fit.py``
    and ``benchmarks/curve_edits_vs_paper.py``).
-   :data:`LIVE_SETTINGS`: the editor's warm-started refit while a point is
    dragged.
-   :func:`whole_target_error`: Delta E 2000 over the whole blended target
    on :data:`SCORE_GRID` (:mod:`fitting.fits.curves_score`).

The fit stays a reflectance: [0, 1] is a penalty of the least squares (hinge
residuals at a check grid and where :mod:`fitting.models.range_bound`'s proof
fails), and the kept fit is proven inside over its whole domain, not clipped.
The max is guarded against the paper's method (:mod:`fitting.fits.curves_guard`).

With a base, an edited curve replaces the base's reflectance at its eta_i and
the difference it makes fades smoothly across eta_i (:func:`blend_weights`);
the fit keeps the full quadratic dependence on eta_i. Without a base, the
curves are all there is, and the dependence on eta_i drops to what they
determine: constant for one eta_i, linear for two, quadratic for three or
more (the pack's degree records it).

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics,
Section 6 (future work).
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..domain import DEFAULT_ETA_I_RANGE, check_eta_i_range
from ..models.kinds import DEFAULT_MODEL, model_ACEScg, model_kind
from ..models.pack import PackedMaterial, to_float16
from .curves_base import CurveBase, edited_target
from .curves_guard import edit_warnings, guard_curve_choice
from .curves_input import RGBCurve, check_curves
from .curves_range import EvaluationBudget, escape_points, in_range_fallback, outside_range, proven_in_range
from .curves_range import range_report
from .curves_score import SCORE_GRID, angle_mu, check_grid, score_grid, whole_target_error
from .metrics import curve_metrics
from .kinds import fit_kind
from .result import FitResult
from .curves_settings import LIVE_SETTINGS, CurveFitSettings  # noqa: F401 (re-exported)

__all__ = ["CurveFitSettings", "LIVE_SETTINGS", "SCORE_GRID", "score_grid", "whole_target_error", "fit_curves"]

_RGB_GRID = (24, 16)  # the paper-method candidate's samples: every other angle and eta_i of SCORE_GRID
_RGB_MAX_NFEV = 200  # as the paper-method fits (fit_coefficients' default): rgb solves are cheap
_MIN_ESCALATION_NFEV = 10  # an escalation round with fewer evaluations left is not started

def _describe(curves: Sequence[RGBCurve]) -> str:
    return ", ".join(f"{c.eta_i:g}" for c in sorted(curves, key=lambda c: c.eta_i))


def fit_curves(
    curves: Sequence[RGBCurve | Mapping[str, Any]],
    base: CurveBase | None = None,
    eta_i_range=None,
    name: str = "edited",
    settings: CurveFitSettings | None = None,
    model: str = DEFAULT_MODEL,
    start=None,
    **overrides,
) -> FitResult:
    """
    Fit the coated-conductor model (or another kind, ``model``) to RGB reflectance curves.

    With a ``base``, the target is :func:`edited_target` on ``mu_samples``
    values of cos theta evenly over [0, 1] at ``eta_samples`` rows evenly over
    the base's domain plus one row per edited eta_i; the fit has degree 2 in
    eta_i over the base's domain. Without a base, the target is the curves
    themselves, each resampled to ``mu_samples`` values over its own span of
    cos theta; the degree is the number of distinct eta_i less one, at most 2,
    over ``eta_i_range`` (default [1, 2.5]), which must hold every curve.

    Parameters
    ----------
    curves
        :class:`RGBCurve` or mappings (see :func:`check_curves`), linear ACEScg.
    base
        The material being edited, or None.
    eta_i_range
        The domain of a fit without a base; with a base, None or the base's.
    name
        Name of the packed material.
    settings, overrides
        :class:`CurveFitSettings`, individual fields replaced by ``overrides``.
    start
        Coefficients (3, 3, degree + 1) to start the solve from instead of
        the variable-projection guess (a warm start from the fit on screen,
        see :data:`LIVE_SETTINGS`) for the coated-conductor kind; the
        paper-method candidate always starts from its own guess.
    model
        The model kind (:data:`fitting.models.kinds.MODEL_KINDS`): for
        ``rgb-conductor`` the per-channel n, k are fitted to the same target
        with the same objective, weights and float16-aware rounding
        (:func:`fitting.fits.rgb_conductor.fit_rgb_conductor_coefficients`);
        its n, k do not depend on eta_i, so without a base the degree rule
        does not apply.

    Returns
    -------
    FitResult
        With ``packed`` (the float16 material), ``timings`` (``target``,
        ``fit``, ``quantise``, ``total`` in seconds), ``error`` (the
        :class:`~fitting.fits.metrics.ErrorMetrics` against the curves, one
        row per curve) and ``metrics``, its JSON:
        ``delta_E_mean`` and ``delta_E_max`` (CIE Delta E 2000 of the float16
        model against the curves at their own samples), ``by_curve`` (the same
        per curve, with its ``eta_i``), ``samples`` (the number of fitted
        samples), ``base`` (its name or None), ``objective`` (the one kept),
        ``figure`` (:meth:`fitting.fits.metrics.ErrorMetrics.figure`: with a
        base the whole target's, else the curves') and, with a base, ``target`` (:func:`whole_target_error`: mean and
        max Delta E 2000 over the whole blended target on
        :data:`SCORE_GRID`, where the max is, and the model's range), ``range``
        (the proof of [0, 1], for a kind that can leave it) and ``guard`` (every
        candidate of the worst-case guard, :mod:`fitting.fits.curves_guard`).

    Raises
    ------
    ValueError
        For invalid curves, settings, name or domain, curves outside the
        domain, or a domain other than the base's.
    """
    t0 = time.perf_counter()
    settings = settings or CurveFitSettings()
    if overrides:
        settings = CurveFitSettings(**{**settings.__dict__, **overrides})
    curves = check_curves(curves)
    kind, solver = model_kind(model), fit_kind(model)
    model, solve = kind.name, solver.solve
    if not isinstance(name, str) or not name.strip():
        raise ValueError("`name` must be a non-empty string")
    if base is not None:
        if eta_i_range is not None and check_eta_i_range(eta_i_range) != base.eta_i_range:
            lo, hi = base.eta_i_range
            raise ValueError(
                f"`eta_i_range` must be the base's domain [{lo:g}, {hi:g}] or omitted, "
                f"got {list(eta_i_range)}"
            )
        eta_i_range = base.eta_i_range
    else:
        eta_i_range = check_eta_i_range(DEFAULT_ETA_I_RANGE if eta_i_range is None else eta_i_range)
    lo, hi = eta_i_range
    for i, curve in enumerate(curves):
        if not lo - 1e-9 <= curve.eta_i <= hi + 1e-9:
            raise ValueError(
                f"`curves[{i}].eta_i` must lie in the domain [{lo:g}, {hi:g}], got {curve.eta_i:g}"
            )
    if base is not None:
        mu_row = angle_mu(np.linspace(0.0, 90.0, settings.mu_samples))
        rows = np.linspace(lo, hi, settings.eta_samples) if hi > lo else np.array([lo])
        edited = np.array([c.eta_i for c in curves])
        rows = rows[np.all(np.abs(rows[:, None] - edited[None, :]) > 1e-6, axis=1)]
        rows = np.sort(np.concatenate([rows, edited]))
        E, M = np.meshgrid(rows, mu_row, indexing="ij")
        mu, eta = M.ravel(), E.ravel()
        target = edited_target(base, curves, mu, eta, settings.blend_width)
        is_edit = np.any(np.abs(eta[:, None] - edited[None, :]) <= 1e-6, axis=1)
        weights = np.where(is_edit, settings.edit_weight, 1.0)
        degree = kind.max_degree
        source = f"{base.name} with RGB curves edited at eta_i {_describe(curves)}"
        if base.source:
            source += f"; base: {base.source}"
    else:
        mu = np.concatenate([np.linspace(c.cos_theta[0], c.cos_theta[-1], settings.mu_samples) for c in curves])
        eta = np.repeat([c.eta_i for c in curves], settings.mu_samples)
        target = np.concatenate([c.sampled(np.linspace(c.cos_theta[0], c.cos_theta[-1], settings.mu_samples)) for c in curves])
        degree = min(kind.max_degree, len(curves) - 1)
        weights = None
        source = f"RGB curves at eta_i {_describe(curves)}"
    t_target = time.perf_counter()
    budget = EvaluationBudget(settings.max_evaluations)

    def fit(objective: str, range_weight: float, check_samples: tuple[int, int], dense=None,
            start=start, extra_check=None) -> FitResult:
        range_check = None
        if range_weight > 0:
            CM, CE = check_grid(eta_i_range, *check_samples)
            CM, CE = CM.ravel(), CE.ravel()
            if extra_check is not None:
                CM, CE = np.concatenate([CM, extra_check[0]]), np.concatenate([CE, extra_check[1]])
            range_check = (CM, CE, range_weight)
        if dense is not None:  # the paper's method: rgb on the whole target, unweighted
            # An unbounded and a bounded solve at most (fitting.fits.solver.solve).
            wanted = _RGB_MAX_NFEV
            max_nfev = budget.per_solve(wanted, 2)
            result = solve(*dense, eta_i_range, degree, "rgb", max_nfev,
                           settings.quantise, irls_rounds=0, range_check=range_check)
        else:
            wanted, rounds = settings.max_nfev, 1 + (settings.irls_rounds if objective == "de2000" else 0)
            max_nfev = budget.per_solve(wanted, 2 * rounds)
            result = solve(
                target, mu, eta, eta_i_range, degree, objective, max_nfev,
                settings.quantise, weights=weights, irls_rounds=settings.irls_rounds, range_check=range_check,
                start=start,
            )
        budget.spend(result, max_nfev, wanted)
        return result

    range_M, range_E = check_grid(eta_i_range, *SCORE_GRID)

    seen: dict[bytes, np.ndarray] = {}  # the same candidate is checked again (held, the live fallback)

    def outside(C16) -> np.ndarray:
        """Mask of the range grid's points where the float16 fit leaves [0, 1]."""
        C16 = np.asarray(C16)
        key = C16.dtype.str.encode() + C16.tobytes()
        if key not in seen:
            seen[key] = outside_range(C16, eta_i_range).any(axis=-1).reshape(range_M.shape)
        return seen[key]

    def in_range(C16) -> bool:  # Proven over the whole domain, not the grid only
        return not outside(C16).any() and proven_in_range(C16, eta_i_range, max_cells=settings.proof_cells)

    def constrained(objective: str, dense=None) -> FitResult:
        weight, check, extra = settings.range_weight, settings.check_samples, None
        result = fit(objective, weight, check, dense)
        for _ in range(2):
            if weight == 0:
                break
            if in_range(result.coefficients_float16) or not budget.allows(_MIN_ESCALATION_NFEV):
                break
            C16 = result.coefficients_float16
            points = escape_points(C16, eta_i_range, outside(C16), range_M, range_E, check[1], settings.proof_cells)
            extra = points if extra is None else (
                np.concatenate([extra[0], points[0]]), np.concatenate([extra[1], points[1]]))
            if start is None or dense is not None:
                # A fit from its own guess: stiffer on a finer grid, started
                # again, with the points where it left [0, 1] added.
                weight, check = 10.0 * weight, (max(check[0], 46), max(check[1], 16))
                result = fit(objective, weight, check, dense, extra_check=extra)
            else:
                # A warm-started (live) fit goes on from where it is, stiffer
                # and with the points where it leaves [0, 1] added to its check.
                weight = 10.0 * weight
                result = fit(objective, weight, check, start=result.coefficients, extra_check=extra)
        return result

    def held(result: FitResult) -> FitResult:
        """``result`` with float16 coefficients in [0, 1] (its fallback when the budget left it outside)."""
        if settings.range_weight > 0 and not in_range(result.coefficients_float16):
            result.coefficients_float16 = in_range_fallback(result.coefficients_float16, eta_i_range,
                                                            settings.proof_cells)
            result.best_effort = True
        return result

    chosen = settings.objective
    if solver.bounded:
        # A reflectance by construction: no range constraint, no candidates.
        result = solve(
            target, mu, eta, eta_i_range, degree, settings.objective,
            max(settings.max_nfev, _RGB_MAX_NFEV), settings.quantise, weights=weights,
            irls_rounds=settings.irls_rounds,
        )
    else:
        result = held(constrained(settings.objective))
        if start is not None and result.best_effort and base is not None:
            # A warm-started (live) solve that cannot hold [0, 1] in its
            # short budget (an edit far past what the model can follow):
            # the closer to the edit of its fallback and the fit on screen,
            # at once; the full refit on release replaces it.
            on_screen = to_float16(np.asarray(start, dtype=np.float64))
            if in_range(on_screen) and (
                whole_target_error(base, curves, on_screen, settings.blend_width)["delta_E_mean"]
                < whole_target_error(base, curves, result.coefficients_float16,
                                     settings.blend_width)["delta_E_mean"]):
                result.coefficients_float16 = on_screen
    if not solver.bounded and base is not None and settings.compare_rgb and settings.objective != "rgb":
        # The paper's own method (plain rgb least squares) on the whole
        # blended target (every other point of the scoring grid: the target
        # is smooth, and it halves the cost): kept when it is closer on the
        # scoring grid (an edit the fewer de2000 samples miss).
        _, _, rgb_M, rgb_E = score_grid(eta_i_range, _RGB_GRID)
        dense_target = edited_target(base, curves, rgb_M, rgb_E, settings.blend_width)
        dense = (dense_target.reshape(-1, 3), rgb_M.ravel(), rgb_E.ravel())
        candidates = {settings.objective: result, "rgb": held(constrained("rgb", dense))}
        # Kept by mean and max against the paper method (fitting.fits.curves_guard).
        chosen, guard = guard_curve_choice(base, curves, settings.blend_width, candidates, settings.objective,
                                           "rgb", (target, mu, eta, weights), in_range)
        result = candidates[chosen]
        result.guard, chosen = guard, result.objective
    C16 = result.coefficients_float16
    error = curve_metrics(curves, lambda c: model_ACEScg(model, c.cos_theta, c.eta_i, C16, eta_i_range))
    metrics: dict[str, Any] = {
        **error.to_dict(),
        "samples": int(mu.size),
        "base": None if base is None else base.name,
        "objective": chosen,
        "best_effort": bool(result.best_effort or budget.cut),
    }
    metrics["figure"] = error.figure()
    unfollowed = edit_warnings(metrics.get("by_curve", ()))
    if unfollowed:  # an edit the model family cannot bend to: where and by how much
        metrics["warnings"] = unfollowed
    if base is not None:
        target = metrics["target"] = whole_target_error(base, curves, C16, settings.blend_width, model=model)
        # With a base the figure is the whole edited target's (what the editor's error map shows).
        metrics["figure"] = {key: target[key] for key in ("against", "delta_E_mean", "delta_E_max", "max_at")}
    if result.guard is not None:
        metrics["guard"] = result.guard
    if not solver.bounded:  # [0, 1] proven or not over the whole domain
        metrics["range"] = range_report(C16, eta_i_range, settings.proof_cells)
    result.error = error
    result.metrics = metrics
    result.packed = PackedMaterial(
        name=name, coefficients=C16, eta_i_range=eta_i_range, source=source[:4000], metrics=metrics,
        model=model,
    )
    result.timings["target"] = t_target - t0
    result.timings["total"] = time.perf_counter() - t0
    return result
