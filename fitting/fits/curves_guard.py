"""
The max of curve refits, guarded
================================

A curve refit (:func:`fitting.fits.curves.fit_curves`) with a base has two
candidates: its own objective's fit and the paper's method (plain rgb least
squares on the whole blended target). Kept by the mean alone, the refit
could end with the worse max (5 of 8 edits, one by 3 Delta E).

-   :func:`guard_curve_choice`: the candidates scored on the whole blended
    target on :data:`fitting.fits.curves_score.SCORE_GRID`; when the own
    fit's max is not under the paper method's, the fits of least mean with
    the max capped there (:func:`fitting.fits.guarded.constrained_refits`),
    kept only when proven inside [0, 1]; the choice of
    :func:`fitting.fits.worst_case.choose`. A kept twin of the paper's
    method is polished in float16 (:func:`fitting.fits.polish.polish_float16`)
    so that it is ahead of an auditor's rounding of the same optimum on both
    figures, not tied with it.
"""

from __future__ import annotations

import numpy as np

from ..colour.colorimetry import ACEScg_to_Lab
from ..models.coated_conductor import coated_conductor_model
from .curves_base import edited_target
from .curves_score import check_grid, score_grid
from .guarded import _THREADPOOLS, GuardWork, constrained_refits, guard_report
from .paper_method import paper_fit as paper_method_fit
from .polish import polish_float16
from .result import FitResult
from .solver import fit_coefficients
from .worst_case import MAX_MARGIN, GuardScore, choose, guard_score

CHECK_SAMPLES = (19, 7)
"""Where the constrained refits keep the model in [0, 1]: the refit's default check grid."""

GUARD_WORK = 3000
"""The constrained refits' work of one curve refit (SLSQP iterations times
constraint rows, :class:`fitting.fits.guarded.GuardWork`)."""

_FREE_MAX_NFEV = 200  # the unconstrained paper fit's evaluations per channel
_POLISH_MAX_NFEV = 20  # its joint polish from the channels' optimum

__all__ = ["GUARD_WORK", "guard_curve_choice"]


@_THREADPOOLS.wrap(limits=1, user_api="blas")
def guard_curve_choice(base, curves, blend_width: float, candidates: dict[str, FitResult], own: str,
                       paper: str, samples, in_range, work: int = GUARD_WORK) -> tuple[str, dict]:
    """
    The name of the candidate to keep, and the guard's report
    (:func:`fitting.fits.guarded.guard_report`). ``candidates`` maps names
    to fits, ``own`` and ``paper`` name the refit's and the paper method's;
    ``samples`` = ``(target, mu, eta, weights)`` of the own fit (where the
    mean is minimised); ``in_range(C16)`` says whether float16
    coefficients are proven inside [0, 1]. Constrained candidates join
    ``candidates``; their SLSQP solves share ``work`` units
    (:class:`fitting.fits.guarded.GuardWork`), and the report's
    ``work_cut`` says whether the budget stopped one.
    """
    budget = GuardWork(work)
    eta_i_range = base.eta_i_range
    _, _, M, E = score_grid(eta_i_range)
    gM, gE = M.ravel(), E.ravel()
    gT = edited_target(base, curves, M, E, blend_width).reshape(-1, 3)
    gLab = ACEScg_to_Lab(gT)

    def score(C16) -> GuardScore:
        return guard_score(gLab, coated_conductor_model(gM, gE, C16, eta_i_range), gM, gE)

    scores = {name: score(c.coefficients_float16) for name, c in candidates.items()}
    # The paper's method as an auditor runs it: rgb on the whole scoring grid, no [0, 1]
    # constraint. Not a candidate when it leaves [0, 1], but its max is the bar.
    # The paper's method as an auditor runs it, float16 as fit_coefficients quantises it: solved
    # channel by channel from the paper candidate (paper_fit), then polished and quantised jointly
    # from that optimum (a few evaluations, where the joint solve from its own guess took seconds).
    channels = paper_method_fit(gT, gM, gE, eta_i_range, candidates[own].degree, _FREE_MAX_NFEV,
                                candidates[paper], boxed=True)
    free = fit_coefficients(gT, gM, gE, eta_i_range, candidates[own].degree, "rgb", _POLISH_MAX_NFEV,
                            start=channels.coefficients)
    bar = min(scores[paper].max, score(free.coefficients_float16).max)
    if in_range(free.coefficients_float16):
        candidates[f"{paper}-free"] = free
        scores[f"{paper}-free"] = score(free.coefficients_float16)
    if scores[own].max > bar * (1.0 - MAX_MARGIN) and scores[own].mean < scores[paper].mean:
        target, mu, eta, weights = samples
        own_fit, paper_fit = candidates[own], candidates[paper]
        starts = (("", paper_fit.coefficients), ("-from-own", own_fit.coefficients))
        CM, CE = check_grid(eta_i_range, *CHECK_SAMPLES)
        # Under the free fit's max; when nothing in [0, 1] gets there, under the in-range paper fit's.
        for level, cap in (("", bar), ("-in-range-bar", scores[paper].max))[: 1 + (bar < scores[paper].max)]:
            found = False
            for label, C, C16, s in constrained_refits(
                    target, mu, eta, weights, gT, gM, gE, eta_i_range, own_fit.degree, None, starts,
                    cap, True, score, range_points=(CM.ravel(), CE.ravel()), work=budget):
                if not in_range(C16):
                    continue
                label += level
                candidates[label] = own_fit.with_coefficients(C, C16)
                scores[label] = s
                if s.mean <= scores[paper].mean and s.max <= cap * (1.0 - MAX_MARGIN):
                    found = True
                    break
            if found:
                break
    # The bar is the lower of the two paper fits' max: choose against a score carrying it.
    reference = GuardScore(scores[paper].mean, bar, scores[paper].eta_i, scores[paper].angle_deg)
    chosen = choose({**scores, "bar": reference}, "bar")
    if chosen == "bar":
        # Nothing under the bar by the margin: the same rule against the free paper fit
        # itself when it is a reflectance (it is the paper's method: no worse on both
        # figures), else against the in-range paper candidate (the free fit cannot ship).
        chosen = choose(scores, f"{paper}-free" if f"{paper}-free" in scores else paper)
    if chosen in (paper, f"{paper}-free"):
        # The paper method's twin: ahead of the auditor's rounding on both figures, not a tie.
        C16, polished = polish_float16(candidates[chosen].coefficients_float16, gT, gM, gE, eta_i_range)
        if (polished.mean < scores[chosen].mean or polished.max < scores[chosen].max) and in_range(C16):
            candidates[f"{chosen}-polished"] = candidates[chosen].with_coefficients(C16.astype(np.float64), C16)
            scores[f"{chosen}-polished"] = polished
            chosen = f"{chosen}-polished"
    report = guard_report(chosen, scores)
    report["bar_max"] = bar
    report["work_cut"] = budget.cut
    return chosen, report
