"""
The steps of a curve refit
==========================

:func:`fitting.fits.curves.fit_curves` in named steps, after its problem
(:func:`fitting.fits.curves_problem.curve_problem`):

-   :class:`Refit`: what the steps of one refit share: its problem, the fit
    on screen it starts from, its :class:`EvaluationBudget` and its range
    check (:meth:`Refit.outside`, :meth:`Refit.in_range`).
-   :func:`bounded_fit`: the one solve of a kind whose model is a
    reflectance by construction.
-   :func:`one_solve`: one least-squares solve, charged to the budget.
-   :func:`in_range_fit`: a solve, made stiffer at most twice while its
    float16 fit leaves [0, 1].
-   :func:`held_in_range`: its in-range fallback when the budget left it outside.
-   :func:`live_answer`: a live step that could not hold [0, 1] answers the
    closer of its fallback and the fit on screen.
-   :func:`guarded_choice`: with a base, the paper's method as a second
    candidate, kept by the worst-case guard (:mod:`fitting.fits.curves_guard`).
-   :func:`scored`: the kept fit's metrics and float16 pack.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..models.kinds import model_ACEScg
from ..models.pack import PackedMaterial, to_float16
from .curves_base import edited_target
from .curves_guard import edit_warnings, guard_curve_choice
from .curves_problem import CurveProblem
from .curves_range import EvaluationBudget, escape_points, in_range_fallback, outside_range, proven_in_range
from .curves_range import range_report
from .curves_score import SCORE_GRID, check_grid, score_grid, whole_target_error
from .metrics import curve_metrics
from .result import FitResult

__all__ = [
    "Refit",
    "bounded_fit",
    "one_solve",
    "in_range_fit",
    "held_in_range",
    "live_answer",
    "guarded_choice",
    "scored",
]

_RGB_GRID = (24, 16)  # the paper-method candidate's samples: every other angle and eta_i of SCORE_GRID
_RGB_MAX_NFEV = 200  # as the paper-method fits (fit_coefficients' default): rgb solves are cheap
_MIN_ESCALATION_NFEV = 10  # an escalation round with fewer evaluations left is not started


@dataclass
class Refit:
    """
    What the steps of one refit share.

    Attributes
    ----------
    problem
        The :class:`~fitting.fits.curves_problem.CurveProblem`.
    start
        Coefficients to start the own objective's solve from (the fit on
        screen of a live step), or None.
    budget
        The model evaluations left to every solve of the refit (``settings.max_evaluations``).
    range_grid
        (cos theta, eta_i) meshes of :data:`SCORE_GRID` over the domain: where
        a float16 fit is checked inside [0, 1] before its proof is asked.
    seen
        :meth:`outside` by float16 coefficients (a candidate is checked again and again).
    """

    problem: CurveProblem
    start: Any
    budget: EvaluationBudget
    range_grid: tuple[np.ndarray, np.ndarray]
    seen: dict[bytes, np.ndarray] = field(default_factory=dict)

    @classmethod
    def of(cls, problem: CurveProblem, start) -> Refit:
        """The shared state of a refit of ``problem`` from ``start`` (or None), its whole budget left."""
        return cls(
            problem,
            start,
            EvaluationBudget(problem.settings.max_evaluations),
            check_grid(problem.eta_i_range, *SCORE_GRID),
        )

    def outside(self, C16) -> np.ndarray:
        """Mask of the range grid's points where the float16 fit ``C16`` leaves [0, 1]."""
        C16 = np.asarray(C16)
        key = C16.dtype.str.encode() + C16.tobytes()
        if key not in self.seen:
            mask = np.asarray(outside_range(C16, self.problem.eta_i_range)).any(axis=-1)
            self.seen[key] = np.asarray(mask).reshape(self.range_grid[0].shape)
        return self.seen[key]

    def in_range(self, C16) -> bool:
        """Whether ``C16`` is inside [0, 1] on the range grid and proven so over the whole domain."""
        return not self.outside(C16).any() and proven_in_range(
            C16, self.problem.eta_i_range, max_cells=self.problem.settings.proof_cells
        )


def bounded_fit(problem: CurveProblem) -> FitResult:
    """
    The fit of a kind that is a reflectance by construction
    (``solver.bounded``): one solve of the settings' objective, no range
    constraint, no candidates, at least :data:`_RGB_MAX_NFEV` evaluations.
    """
    settings = problem.settings
    return problem.solver.solve(
        problem.target,
        problem.mu,
        problem.eta,
        problem.eta_i_range,
        problem.degree,
        settings.objective,
        max(settings.max_nfev, _RGB_MAX_NFEV),
        settings.quantise,
        weights=problem.weights,
        irls_rounds=settings.irls_rounds,
    )


def one_solve(
    refit: Refit,
    objective: str,
    range_weight: float,
    check_samples: tuple[int, int],
    dense=None,
    start=None,
    extra_check=None,
) -> FitResult:
    """
    One solve of the problem's samples by ``objective`` (or, with ``dense``
    = (target, mu, eta), the paper's method: rgb on those, unweighted, from
    its own guess), with the [0, 1] penalty of ``range_weight`` at the check
    grid of ``check_samples`` plus ``extra_check`` = (mu, eta) points (none
    when the weight is 0), started from ``start`` (None: the
    variable-projection guess). Its ``max_nfev`` is its share of the budget
    (:meth:`EvaluationBudget.per_solve`), and what it used is charged.
    """
    problem, budget, settings = refit.problem, refit.budget, refit.problem.settings
    range_check = None
    if range_weight > 0:
        CM, CE = check_grid(problem.eta_i_range, *check_samples)
        CM, CE = CM.ravel(), CE.ravel()
        if extra_check is not None:
            CM, CE = np.concatenate([CM, extra_check[0]]), np.concatenate([CE, extra_check[1]])
        range_check = (CM, CE, range_weight)
    if dense is not None:  # the paper's method: rgb on the whole target, unweighted
        # An unbounded and a bounded solve at most (fitting.fits.solver.solve).
        wanted = _RGB_MAX_NFEV
        max_nfev = budget.per_solve(wanted, 2)
        result = problem.solver.solve(
            *dense,
            problem.eta_i_range,
            problem.degree,
            "rgb",
            max_nfev,
            settings.quantise,
            irls_rounds=0,
            range_check=range_check,
        )
    else:
        wanted, rounds = settings.max_nfev, 1 + (settings.irls_rounds if objective == "de2000" else 0)
        max_nfev = budget.per_solve(wanted, 2 * rounds)
        result = problem.solver.solve(
            problem.target,
            problem.mu,
            problem.eta,
            problem.eta_i_range,
            problem.degree,
            objective,
            max_nfev,
            settings.quantise,
            weights=problem.weights,
            irls_rounds=settings.irls_rounds,
            range_check=range_check,
            start=start,
        )
    budget.spend(result, max_nfev, wanted)
    return result


def in_range_fit(refit: Refit, objective: str, dense=None) -> FitResult:
    """
    :func:`one_solve` (from ``refit.start`` for the own objective) with the
    settings' range weight and check grid; while its float16 fit is not
    :meth:`Refit.in_range` and the budget allows a round, at most twice,
    solved again ten times stiffer with the points where it left [0, 1]
    (:func:`escape_points`) added to the check: a fit from its own guess
    from that guess on a finer grid (at least 46 x 16), a warm-started
    (live) fit from where it is. Gives the last solve (in range or not).
    """
    problem, settings = refit.problem, refit.problem.settings
    weight, check, extra = settings.range_weight, settings.check_samples, None
    result = one_solve(refit, objective, weight, check, dense, start=refit.start)
    for _ in range(2):
        if weight == 0:
            break
        if refit.in_range(result.coefficients_float16) or not refit.budget.allows(_MIN_ESCALATION_NFEV):
            break
        C16 = result.coefficients_float16
        points = escape_points(
            C16, problem.eta_i_range, refit.outside(C16), *refit.range_grid, check[1], settings.proof_cells
        )
        extra = (
            points if extra is None else (np.concatenate([extra[0], points[0]]), np.concatenate([extra[1], points[1]]))
        )
        if refit.start is None or dense is not None:
            # A fit from its own guess: stiffer on a finer grid, started
            # again, with the points where it left [0, 1] added.
            weight, check = 10.0 * weight, (max(check[0], 46), max(check[1], 16))
            result = one_solve(refit, objective, weight, check, dense, start=refit.start, extra_check=extra)
        else:
            # A warm-started (live) fit goes on from where it is, stiffer
            # and with the points where it leaves [0, 1] added to its check.
            weight = 10.0 * weight
            result = one_solve(refit, objective, weight, check, start=result.coefficients, extra_check=extra)
    return result


def held_in_range(refit: Refit, result: FitResult) -> FitResult:
    """
    ``result`` with float16 coefficients in [0, 1]: unchanged when in range
    (or when the range weight is 0), else its :func:`in_range_fallback`,
    marked ``best_effort``.
    """
    problem = refit.problem
    if problem.settings.range_weight > 0 and not refit.in_range(result.coefficients_float16):
        result.coefficients_float16 = in_range_fallback(
            result.coefficients_float16, problem.eta_i_range, problem.settings.proof_cells
        )
        result.best_effort = True
    return result


def live_answer(refit: Refit, result: FitResult) -> FitResult:
    """
    ``result``, or, for a warm-started (live) step with a base that could
    not hold [0, 1] in its short budget (``best_effort``: an edit far past
    what the model can follow), the closer to the edit (mean Delta E 2000 on
    the whole target) of its fallback and the fit on screen when that is in
    range, at once; the full refit on release replaces it.
    """
    problem = refit.problem
    if refit.start is None or not result.best_effort or problem.base is None:
        return result
    on_screen = to_float16(np.asarray(refit.start, dtype=np.float64))
    base, curves, blend_width = problem.base, problem.curves, problem.settings.blend_width
    if refit.in_range(on_screen) and (
        whole_target_error(base, curves, on_screen, blend_width)["delta_E_mean"]
        < whole_target_error(base, curves, result.coefficients_float16, blend_width)["delta_E_mean"]
    ):
        result.coefficients_float16 = on_screen
    return result


def guarded_choice(refit: Refit, result: FitResult) -> tuple[FitResult, str]:
    """
    The kept fit and its objective. With a base, ``compare_rgb`` and an
    objective other than ``rgb``: the paper's own method (plain rgb least
    squares, :func:`in_range_fit` then :func:`held_in_range`) on the whole
    blended target at every other point of the scoring grid (:data:`_RGB_GRID`:
    the target is smooth, and it halves the cost) is a second candidate,
    and :func:`guard_curve_choice` keeps one by mean and max against the
    paper's method (its report in the kept fit's ``guard``). Otherwise
    ``result`` and the settings' objective.
    """
    problem, settings = refit.problem, refit.problem.settings
    if problem.base is None or not settings.compare_rgb or settings.objective == "rgb":
        return result, settings.objective
    _, _, rgb_M, rgb_E = score_grid(problem.eta_i_range, _RGB_GRID)
    dense_target = edited_target(problem.base, problem.curves, rgb_M, rgb_E, settings.blend_width)
    dense = (dense_target.reshape(-1, 3), rgb_M.ravel(), rgb_E.ravel())
    candidates = {settings.objective: result, "rgb": held_in_range(refit, in_range_fit(refit, "rgb", dense))}
    chosen, guard = guard_curve_choice(
        problem.base,
        problem.curves,
        settings.blend_width,
        candidates,
        settings.objective,
        "rgb",
        (problem.target, problem.mu, problem.eta, problem.weights),
        refit.in_range,
    )
    kept = candidates[chosen]
    kept.guard = guard
    return kept, kept.objective


def scored(problem: CurveProblem, result: FitResult, objective: str, budget_cut: bool) -> FitResult:
    """
    ``result`` with its ``error`` (:func:`curve_metrics` of its float16
    model against the curves at their samples), ``metrics`` (their JSON
    with ``samples``, ``base``, ``objective``, ``best_effort`` (its own, or
    ``budget_cut``), ``figure``, and when they apply ``warnings``
    (:func:`edit_warnings`), ``target`` (with a base, :func:`whole_target_error`,
    then also the figure), ``guard`` and ``range`` (:func:`range_report`, for
    a kind that can leave [0, 1])) and ``packed``.
    """
    C16, eta_i_range, model = result.coefficients_float16, problem.eta_i_range, problem.model
    error = curve_metrics(problem.curves, lambda c: model_ACEScg(model, c.cos_theta, c.eta_i, C16, eta_i_range))
    metrics: dict[str, Any] = {
        **error.to_dict(),
        "samples": int(problem.mu.size),
        "base": None if problem.base is None else problem.base.name,
        "objective": objective,
        "best_effort": bool(result.best_effort or budget_cut),
    }
    metrics["figure"] = error.figure()
    unfollowed = edit_warnings(metrics.get("by_curve", ()))
    if unfollowed:  # an edit the model family cannot bend to: where and by how much
        metrics["warnings"] = unfollowed
    if problem.base is not None:
        target = metrics["target"] = whole_target_error(
            problem.base, problem.curves, C16, problem.settings.blend_width, model=model
        )
        # With a base the figure is the whole edited target's (what the editor's error map shows).
        metrics["figure"] = {key: target[key] for key in ("against", "delta_E_mean", "delta_E_max", "max_at")}
    if result.guard is not None:
        metrics["guard"] = result.guard
    if not problem.solver.bounded:  # [0, 1] proven or not over the whole domain
        metrics["range"] = range_report(C16, eta_i_range, problem.settings.proof_cells)
    result.error = error
    result.metrics = metrics
    result.packed = PackedMaterial(
        name=problem.name,
        coefficients=C16,
        eta_i_range=eta_i_range,
        source=problem.source[:4000],
        metrics=metrics,
        model=model,
    )
    return result
