"""
The max of curve refits, guarded
================================

A curve refit (:func:`fitting.fits.curves.fit_curves`) with a base has two
candidates: its own objective's fit and the paper's method (plain rgb least
squares on the whole blended target). Kept by the mean alone, the refit
could end with the worse max (5 of 8 edits, one by 3 Delta E).

-   :func:`guard_curve_choice`: the candidates scored on the whole blended
    target on the auditor's dense grid (:data:`AUDIT_SAMPLES` angles times
    as many eta_i, the editor's error map made dense), against the
    paper's method as an auditor runs it there: plain rgb least squares
    from several starts (:data:`AUDIT_STARTS`), the lowest residual kept;
    when the own fit's max is not under it, the fits of least mean with the
    max capped there (:func:`fitting.fits.guarded.constrained_refits`),
    kept only when proven inside [0, 1]; the choice of
    :func:`fitting.fits.worst_case.choose`. A kept twin of the paper's
    method is polished in float16 (:func:`fitting.fits.polish.polish_float16`)
    so that it is ahead of an auditor's rounding of the same optimum on both
    figures, not tied with it.
-   :func:`edit_warnings`: the words of each edited curve the fit cannot
    follow (the model family cannot bend that way): where and by how much.
"""

from __future__ import annotations

import numpy as np

from ..colour.colorimetry import ACEScg_to_Lab
from ..models.coated_conductor import coated_conductor_model
from ..models.pack import to_float16
from .curves_base import edited_target
from .curves_score import check_grid, score_grid
from .guarded import _THREADPOOLS, GuardWork, constrained_refits, guard_report
from .paper_method import paper_fit as paper_method_fit
from .polish import polish_float16
from .result import FitResult
from .solver import fit_coefficients
from .start import initial_guess
from .worst_case import MAX_MARGIN, GuardScore, choose, guard_score

AUDIT_SAMPLES = 100
"""The auditor's grid: 100 angles evenly over [0, 90] degrees times 100
eta_i evenly over the domain, of the whole blended target (the editor's
error map, :data:`fitting.fits.curves_score.SCORE_GRID`, five times as
dense): where the guard scores and caps a curve refit."""

AUDIT_STARTS = ("paper", "own", "guess")
"""The starts of the auditor's paper-method fits: the refit's paper-method
candidate, its own fit, and the variable-projection initial guess on the
audit grid (:func:`fitting.fits.start.initial_guess`); the lowest rgb
residual is the auditor's fit."""

FOLLOW_MEAN = 1.0
"""An edited curve whose fit stays more than this mean Delta E 2000 (one
just-noticeable difference) from it, or :data:`FOLLOW_MAX` at a sample,
is one the model cannot follow: the answer warns (:func:`edit_warnings`)."""

FOLLOW_MAX = 3.0

CHECK_SAMPLES = (19, 7)
"""Where the constrained refits keep the model in [0, 1]: the refit's default check grid."""

GUARD_WORK = 3000
"""The constrained refits' work of one curve refit (SLSQP iterations times
constraint rows, :class:`fitting.fits.guarded.GuardWork`)."""

_FREE_MAX_NFEV = 200  # the unconstrained paper fit's evaluations per channel
_POLISH_MAX_NFEV = 20  # its joint polish from the channels' optimum

__all__ = ["GUARD_WORK", "AUDIT_SAMPLES", "AUDIT_STARTS", "FOLLOW_MEAN", "FOLLOW_MAX", "guard_curve_choice",
           "edit_warnings"]


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
    _, _, M, E = score_grid(eta_i_range, (AUDIT_SAMPLES, AUDIT_SAMPLES))
    gM, gE = M.ravel(), E.ravel()
    gT = edited_target(base, curves, M, E, blend_width).reshape(-1, 3)
    gLab = ACEScg_to_Lab(gT)

    def score(C16) -> GuardScore:
        return guard_score(gLab, coated_conductor_model(gM, gE, C16, eta_i_range), gM, gE)

    scores = {name: score(c.coefficients_float16) for name, c in candidates.items()}
    # The paper's method as an auditor runs it: rgb on the whole dense grid, no [0, 1]
    # constraint, from several starts, the lowest residual kept, float16 as
    # fit_coefficients quantises it: solved channel by channel from each start
    # (paper_fit), then polished and quantised jointly from that optimum. Not a
    # candidate when it leaves [0, 1], but its figures are the bar.
    degree = candidates[own].degree
    audit_starts = {"paper": candidates[paper].coefficients, "own": candidates[own].coefficients,
              "guess": initial_guess(gT, gM, gE, eta_i_range, degree)}
    audits = {}
    for label in AUDIT_STARTS:
        start = candidates[paper].with_coefficients(audit_starts[label], to_float16(audit_starts[label]))
        channels = paper_method_fit(gT, gM, gE, eta_i_range, degree, _FREE_MAX_NFEV, start, boxed=True)
        audits[label] = fit_coefficients(gT, gM, gE, eta_i_range, degree, "rgb", _POLISH_MAX_NFEV,
                                         start=channels.coefficients)
    audit = min(audits.values(), key=lambda fit: fit.cost)
    free = audit
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
    report["audit"] = {"grid": f"{AUDIT_SAMPLES} x {AUDIT_SAMPLES}", "starts": list(AUDIT_STARTS),
                       "costs": {label: float(fit.cost) for label, fit in audits.items()},
                       "in_range": bool(in_range(free.coefficients_float16)),
                       **score(free.coefficients_float16).to_dict()}
    report["work_cut"] = budget.cut
    return chosen, report


def edit_warnings(by_curve, mean: float = FOLLOW_MEAN, most: float = FOLLOW_MAX) -> list[str]:
    """
    A warning for each edited curve the fit does not follow: ``by_curve``
    rows (``eta_i``, ``delta_E_mean``, ``delta_E_max`` and, when known,
    ``max_at`` with ``theta_deg``) whose mean is above ``mean`` or whose max
    is above ``most``.
    """
    out = []
    for row in by_curve:
        if row["delta_E_mean"] > mean or row["delta_E_max"] > most:
            at = row.get("max_at") or {}
            where = f" (max {row['delta_E_max']:.2f}" + (
                f" at {at['theta_deg']:.0f} degrees)" if "theta_deg" in at else ")")
            out.append(
                f"edit not followed: the fit stays {row['delta_E_mean']:.2f} mean Delta E 2000 from the "
                f"edited curve at eta_i {row['eta_i']:g}{where}; the model cannot bend that way"
            )
    return out
