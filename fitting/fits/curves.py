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
    against the edited curves, in named steps: its problem
    (:mod:`fitting.fits.curves_problem`: the arguments checked, the target
    sampled), then the solves, the range held, the live answer, the guarded
    choice and the scores (:mod:`fitting.fits.curves_steps`).
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

from ..models.kinds import DEFAULT_MODEL
from .curves_base import CurveBase
from .curves_input import RGBCurve
from .curves_problem import curve_problem, refit_settings
from .curves_score import SCORE_GRID, score_grid, whole_target_error
from .curves_steps import Refit, bounded_fit, guarded_choice, held_in_range, in_range_fit, live_answer, scored
from .result import FitResult
from .curves_settings import LIVE_SETTINGS, CurveFitSettings  # noqa: F401 (re-exported)

__all__ = ["CurveFitSettings", "LIVE_SETTINGS", "SCORE_GRID", "score_grid", "whole_target_error", "fit_curves"]


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

    With a ``base``, the target is :func:`edited_target` at ``mu_samples``
    angles evenly over [0, 90] degrees on ``eta_samples`` rows evenly over
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

    Notes
    -----
    The steps, in order: the problem (:func:`~fitting.fits.curves_problem.curve_problem`);
    for a kind that is a reflectance by construction one solve
    (:func:`~fitting.fits.curves_steps.bounded_fit`), else the solve made
    stiffer while it leaves [0, 1] (:func:`~fitting.fits.curves_steps.in_range_fit`),
    its in-range fallback if the budget left it outside
    (:func:`~fitting.fits.curves_steps.held_in_range`), a live step's answer
    (:func:`~fitting.fits.curves_steps.live_answer`) and, with a base, the
    paper's method as a second candidate under the worst-case guard
    (:func:`~fitting.fits.curves_steps.guarded_choice`); then the scores
    and the pack (:func:`~fitting.fits.curves_steps.scored`). Every solve
    shares one evaluation budget (:class:`~fitting.fits.curves_steps.Refit`).
    """
    t0 = time.perf_counter()
    problem = curve_problem(curves, base, eta_i_range, name, refit_settings(settings, overrides), model)
    t_target = time.perf_counter()
    refit = Refit.of(problem, start)
    if problem.solver.bounded:
        result, objective = bounded_fit(problem), problem.settings.objective
    else:
        result = held_in_range(refit, in_range_fit(refit, problem.settings.objective))
        result = live_answer(refit, result)
        result, objective = guarded_choice(refit, result)
    result = scored(problem, result, objective, refit.budget.cut)
    result.timings["target"] = t_target - t0
    result.timings["total"] = time.perf_counter() - t0
    return result
