"""
Fits that guard the max
=======================

The coated-conductor fit of :func:`fitting.fits.solver.fit_coefficients`
with its worst point guarded (:mod:`fitting.fits.worst_case`):

-   :func:`guarded_fit`: the mean-Delta-E fit, the paper method's fit (plain
    linear-RGB least squares on the guard points, rounded to float16 as the
    paper ships it), and, when the mean fit's max is not under the paper
    method's, SLSQP refits of the least mean with the max capped under the
    paper method's (:func:`constrained_refits`, each solved by
    :func:`fitting.fits.constrained.constrained_mean`); the one
    :func:`fitting.fits.worst_case.choose` picks is returned, with the
    figures of every candidate in ``result.guard``.

References
----------
Vernooij, H. B. (2024). A Fresnel Model for Coated Materials. Eurographics.
"""

from __future__ import annotations

import time

import numpy as np
from threadpoolctl import ThreadpoolController

from ..colour.colorimetry import ACEScg_to_Lab
from ..models.coated_conductor import coated_conductor_model
from ..models.pack import to_float16
from .constrained import GuardWork, constrained_mean
from .objective import Problem
from .quantise import quantise_coefficients
from .result import FitResult
from .paper_method import paper_fit
from .solver import fit_coefficients
from .worst_case import MAX_MARGIN, GuardScore, choose, guard_score

__all__ = [
    "PAPER",
    "MEAN",
    "CAP_FACTORS",
    "GuardWork",
    "constrained_mean",
    "constrained_refits",
    "guarded_fit",
    "guard_report",
]

PAPER = "paper"
"""Name of the paper-method candidate."""

MEAN = "mean"
"""Name of the mean-Delta-E candidate (the fit as it was before the guard)."""

# SLSQP's small dense algebra: BLAS threads only synchronise (6x slower on 2 cores).
_THREADPOOLS = ThreadpoolController()

CAP_FACTORS = (0.9, 1.0 - MAX_MARGIN)
"""Caps of the constrained fits relative to the paper method's max on the
guard, tried in order: the paper method's own fit on the full 100 x 100
grid can end a little lower than its fit on the guard (Na: 0.075 against
0.081), so a cap 10 % under it is tried first, and kept when its mean is
still no worse than the paper's; then the cap of :data:`MAX_MARGIN`."""

_CAP_ROUNDS = 3  # constrained solves of one candidate while its true max reads above the cap


def _candidate(mean_fit: FitResult, C, C16, eta_i_range, degree, objective) -> FitResult:
    return mean_fit.with_coefficients(C, C16)


def _quantise_capped(mean_problem, guard_problem, weights, C, cap, quantise: bool):
    """
    Float16 coefficients of ``C``: of nearest rounding and (with
    ``quantise``) :func:`quantise_coefficients` on the mean's reweighted
    samples and the guard points, the lower mean among those inside the
    cap, else the lower max.
    """
    nearest = to_float16(C)
    if not quantise:
        return nearest
    x = C.ravel()
    dE = np.linalg.norm(mean_problem.residuals(x)[: 3 * mean_problem.mu.size].reshape(-1, 3), axis=1)
    gdE = np.linalg.norm(guard_problem.residuals(x).reshape(-1, 3), axis=1)
    w = np.ravel(weights) / np.mean(weights)
    both = Problem(
        np.concatenate([mean_problem.target, guard_problem.target]),
        np.concatenate([mean_problem.mu, guard_problem.mu]),
        np.concatenate([mean_problem.eta, guard_problem.eta]),
        mean_problem.range,
        C.shape[2] - 1,
        "de2000",
        np.concatenate([w / np.maximum(dE, 0.02), 1.0 / np.maximum(gdE, 0.02)]),
        mean_problem.check,
    )
    options = [nearest, quantise_coefficients(both, C)]

    def figures(C16):
        x16 = C16.astype(np.float64).ravel()
        m = np.linalg.norm(mean_problem.residuals(x16)[: 3 * dE.size].reshape(-1, 3), axis=1)
        g = np.linalg.norm(guard_problem.residuals(x16).reshape(-1, 3), axis=1)
        return float(w @ m) / w.size, float(g.max())

    scored = [figures(C16) for C16 in options]
    inside = [i for i, (_, worst) in enumerate(scored) if worst <= cap]
    if inside:
        return options[min(inside, key=lambda i: scored[i][0])]
    return options[min(range(len(options)), key=lambda i: scored[i][1])]


def guard_report(chosen: str, scores: dict[str, GuardScore]) -> dict:
    """The JSON of a guarded choice: what was kept and every candidate's figures."""
    return {"chosen": chosen, "margin": MAX_MARGIN, "candidates": {name: s.to_dict() for name, s in scores.items()}}


def constrained_refits(
    target,
    mu,
    eta,
    weights,
    guard_target,
    guard_mu,
    guard_eta,
    eta_i_range,
    degree,
    range_check,
    starts,
    paper_max: float,
    quantise: bool,
    score,
    range_points=None,
    work: GuardWork | None = None,
    factors=CAP_FACTORS,
):
    """
    Yield ``(label, C, C16, score(C16))`` of the fits of least mean Delta E
    over (``target``, ``mu``, ``eta``, ``weights``) with the first-order
    Delta E capped at every guard point: the caps of ``factors``
    (:data:`CAP_FACTORS`) times ``paper_max`` in order, from each of ``starts`` (``(suffix,
    coefficients)``); the caller stops when one suits it. ``score`` maps
    float16 coefficients to their :class:`GuardScore` (true CIEDE2000);
    ``range_points``, ``work``: as :func:`constrained_mean` (no refit is
    started once ``work`` is spent).
    """
    base = np.ones(np.ravel(mu).size) if weights is None else np.ravel(weights)
    mean_problem = Problem(target, mu, eta, eta_i_range, degree, "de2000", None, range_check)
    guard_problem = Problem(guard_target, guard_mu, guard_eta, eta_i_range, degree, "de2000")
    for factor in factors:
        for suffix, x0 in starts:
            label = f"constrained{factor:g}{suffix}"
            cap = threshold = paper_max * factor
            found = None
            for _ in range(_CAP_ROUNDS):
                if work is not None and work.left <= 0:
                    return
                # The constraint is on the first-order Delta E (the de2000
                # objective's); the score is the true CIEDE2000, which can
                # read a little higher: the cap is lowered by their ratio.
                C = constrained_mean(
                    mean_problem, guard_problem, base, x0, cap, degree, range_points=range_points, work=work
                )
                if C is None:
                    break
                C16 = _quantise_capped(mean_problem, guard_problem, base, C, cap, quantise)
                found = (label, C, C16, score(C16))
                if found[3].max <= threshold:
                    break
                cap *= 0.995 * threshold / found[3].max
                x0 = C
            if found is not None:
                yield found


@_THREADPOOLS.wrap(limits=1, user_api="blas")
def guarded_fit(
    target,
    mu,
    eta,
    eta_i_range,
    degree,
    objective,
    max_nfev,
    quantise,
    weights,
    irls_rounds,
    guard_target,
    guard_mu,
    guard_eta,
    range_check=None,
    mean_fit: FitResult | None = None,
) -> FitResult:
    """
    The fit of ``target`` at (``mu``, ``eta``) as
    :func:`fitting.fits.solver.fit_coefficients` (its arguments), its max
    guarded on ``guard_target`` at (``guard_mu``, ``guard_eta``).
    ``mean_fit``: that fit when already made. Returns the chosen
    :class:`FitResult` with ``guard`` (:func:`guard_report`) set and its
    ``timings['guard']``.
    """
    t0 = time.perf_counter()
    if mean_fit is None:
        mean_fit = fit_coefficients(
            target,
            mu,
            eta,
            eta_i_range,
            degree,
            objective,
            max_nfev,
            quantise,
            weights=weights,
            irls_rounds=irls_rounds,
            range_check=range_check,
        )
    degree = mean_fit.degree
    gT = np.asarray(guard_target, dtype=np.float64).reshape(-1, 3)
    gM, gE = np.ravel(guard_mu), np.ravel(guard_eta)
    gLab = ACEScg_to_Lab(gT)

    def score(C16) -> GuardScore:
        return guard_score(gLab, coated_conductor_model(gM, gE, C16, eta_i_range), gM, gE)

    paper = paper_fit(gT, gM, gE, eta_i_range, degree, max_nfev, mean_fit, range_check)
    candidates = {MEAN: mean_fit, PAPER: paper}
    scores = {name: score(c.coefficients_float16) for name, c in candidates.items()}
    if choose(scores, PAPER) != MEAN:
        starts = (("", paper.coefficients), ("-from-mean", mean_fit.coefficients))
        for label, C, C16, s_ in constrained_refits(
            target,
            mu,
            eta,
            weights,
            gT,
            gM,
            gE,
            eta_i_range,
            degree,
            range_check,
            starts,
            scores[PAPER].max,
            quantise,
            score,
        ):
            candidates[label] = _candidate(mean_fit, C, C16, eta_i_range, degree, objective)
            scores[label] = s_
            if choose(scores, PAPER) == label:
                break
    chosen = choose(scores, PAPER)
    result = candidates[chosen]
    result.guard = guard_report(chosen, scores)
    result.timings["guard"] = time.perf_counter() - t0
    return result
